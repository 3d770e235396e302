//! The time-step policy: the CFL number α (Δt = α · cell / max(c + |v|), dimensionless) a case
//! that names none runs with, and why. Imports the spec, the geometry and the shape policy.

use super::geometry::Geometry;
use super::shape_policy::is_thin;
use super::spec::{CaseSpec, LoadingMode, Model, ShapeKind};

/// The CFL number of a case that names none: its energy books close to 0.45–1.04 % on the
/// examples (docs/studies.md §4, §7), and halving it roughly halves their error.
pub const DEFAULT_CFL: f64 = 0.5;

/// The CFL number of a thin wall (d/t ≥ 8) crushed axially in 3D on B-splines that names none.
/// Measured with `crush run` against 0.5 on the same code (docs/performance.md, *A longer time
/// step*), each pair the same two-lobe diamond with the same first peak: the d/t 14 PVC tube at
/// n 4 and 6 15.795 and 15.743 kN against 15.635 and 15.767 (+1.0, −0.15 %); the d20 tube
/// (d/t 16) at n 3 and 4 2.419 and 2.668 against 2.331 and 2.629 (+3.8, +1.5 %; at n 4 in four
/// folds against three, its mean over the first 30 mm 4.5 % lower), a third of its 13 % from
/// n 3 to 4; the t 0.76 tube (d/t 26) at n 2 0.857 against 0.846 (+1.3 %). 62–67 % of the
/// steps, the books at 0.95–1.90 % against 0.45–0.92 % (the d20 tube at n 2 the most open).
/// At 1.0 the d/t 14 tube's books opened to 7.7 % (not trusted) for 10 % fewer steps than 0.8.
pub const THIN_WALL_BSPLINE_CFL: f64 = 0.8;

/// The CFL number for a case that names none, and why: [`THIN_WALL_BSPLINE_CFL`] for a thin
/// wall crushed axially in 3D on B-splines (`shape`, the case's own or its default), else
/// [`DEFAULT_CFL`].
pub fn default_cfl(geometry: &Geometry, shape: ShapeKind) -> (f64, &'static str) {
    let thin_bspline = geometry.model == Model::ThreeD
        && geometry.mode == LoadingMode::Axial
        && shape == ShapeKind::Bspline
        && is_thin(&geometry.section);
    match thin_bspline {
        true => (
            THIN_WALL_BSPLINE_CFL,
            "0.8: the default for a thin wall crushed axially in 3D on B-splines, where it kept \
             0.5's mode and its mean load within 1 % on the d/t 14 tube and 0.8-3.8 % on \
             thinner walls in 62-67 % of the steps (docs/performance.md)",
        ),
        false => (DEFAULT_CFL, "0.5: the default"),
    }
}

/// The CFL number a spec runs with: its own, or [`default_cfl`] for its wall and its shape
/// functions (its own, or their default). Meaningful for a spec whose tube and discretization
/// passed their checks.
pub fn cfl_of(spec: &CaseSpec) -> f64 {
    spec.discretization.cfl.unwrap_or_else(|| {
        let geometry = Geometry::of(spec);
        let shape = spec.discretization.shape.unwrap_or_else(|| {
            ShapeKind::default_for(&geometry.section, geometry.model, spec.contact.friction).kind
        });
        default_cfl(&geometry, shape).0
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::model::case::spec_from_json;

    fn cfl(json: &str) -> f64 {
        cfl_of(&spec_from_json(json).unwrap())
    }

    /// The longer step is the thin wall's on B-splines in an axial 3D crush, where it was
    /// measured, and no other case's: not the paper's thick tube, not the thin wall's section,
    /// its lateral crush, its linear or uGIMP shapes; a case's own α always wins.
    #[test]
    fn a_thin_axial_3d_wall_on_b_splines_steps_at_0_8_and_every_other_case_at_0_5() {
        let thin = r#""tube": {"thickness_mm": 3.2, "mean_diameter_mm": 44.8, "length_mm": 125.4},
                      "contact": {"friction": 0.3}"#;
        assert_eq!(cfl(&format!("{{{thin}}}")), 0.8, "B-splines by default");
        assert_eq!(
            cfl(&format!(
                r#"{{{thin}, "discretization": {{"shape": "bspline"}}}}"#
            )),
            0.8
        );
        for other in [
            r#""discretization": {"shape": "gimp"}"#,
            r#""discretization": {"shape": "linear"}"#,
            r#""discretization": {"model": "axisymmetric"}"#,
            r#""loading": {"mode": "lateral"}"#,
        ] {
            assert_eq!(cfl(&format!("{{{thin}, {other}}}")), 0.5, "{other}");
        }
        assert_eq!(
            cfl(&format!(r#"{{{thin}, "discretization": {{"cfl": 0.3}}}}"#)),
            0.3
        );
        assert_eq!(cfl(r#"{"discretization": {"shape": "bspline"}}"#), 0.5);
        assert_eq!(cfl("{}"), 0.5);
        // On near-frictionless plates a thin wall's default is linear shapes: 0.5.
        assert_eq!(
            cfl(r#"{"tube": {"thickness_mm": 3.2, "mean_diameter_mm": 44.8}}"#),
            0.5
        );
    }
}
