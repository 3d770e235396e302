//! The error a run's mean load is expected to carry against its converged value, before any
//! run and at no cost: read off the convergence studies measured ([`tables`]) for the run's
//! model, shape function, n and loading — where the case is near the tube they were measured
//! on. Where it is not (another section, material or wall, other shape functions), no figure:
//! "no measured guide", and why. Units: %.
//!
//! An expected error is a guide, not a bound: a priced error bar ([`super::error_bar`]) is
//! this run's own. Imports the case, and from the references where a metal's modulus starts.

mod tables;

pub use tables::{error_table, expected_error_percent, ERROR_BASIS, THIN_BSPLINE_3D};

use super::reference::shown::METAL_MODULUS_MPA;
use crate::solver::model::case::{Case, LoadingMode, Model, Outline, ShapeKind, HOLDING_FRICTION};
use crate::solver::model::spec::{HardeningKind, MaterialModel, RateKind};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The d/t of the tube the studies were measured on (the paper's: t 3.2, d 22.2 mm).
pub const STUDIED_D_OVER_T: f64 = 22.2 / 3.2;

/// How far a case's d/t may be from the studied one, as a factor either way, for the studies
/// to guide it: the error at n is that of the bending of a wall n particles thick, which the
/// studies measured on one wall only. Within a quarter either way (d/t 5.5–8.7) a wall is as
/// thick for its tube and folds in rings like it; a chosen margin, not a measured one, until
/// studies of thinner walls are stored beside it.
pub const NEAR_FACTOR: f64 = 1.25;

/// The d/t of the thin wall studied in 3D (t 3.2, d 44.8 mm, docs/studies.md §9). On
/// B-splines its mean load settles from n = 4 ([`THIN_BSPLINE_3D`]), which guides a wall near
/// it on such plates. Its uGIMP mean load alternates with the parity of n through n = 6: 17.10
/// and 17.20 kN at n = 3 and 5, where the tube folds from both ends, 15.54 and 15.57 kN at
/// n = 4 and 6, where it folds from the fixed end. With no converged value there is no error
/// to expect, so a uGIMP run of a wall near it has no measured guide, and the reason says why.
pub const THIN_D_OVER_T: f64 = 44.8 / 3.2;

/// The d/t of the thinner wall studied in 3D (t 1.27, d 20.32 mm, docs/studies.md §10): its
/// uGIMP mean load rose 3 % from n = 2 to 3 and 20 % from n = 3 to 4, so it has no converged
/// value, and the d/t 14 tube's errors do not guide it. A wall nearer it than the d/t 14 tube
/// (d/t above the midpoint, 15) has no measured guide.
pub const UNCONVERGED_D_OVER_T: f64 = 20.32 / 1.27;

/// The plates' speed the d/t 14 tube was studied at, m/s: a faster plate or a mass-scaled run
/// carries more inertia than the runs its table measured, and that wall picks its mode under
/// it. (A thick wall does not: the paper's tube kept its mean load within 2.3 % at 15 m/s and
/// 0.4 % at mass scaling 4, so its tables guide such runs.)
pub const STUDIED_PLATE_SPEED_M_S: f64 = 10.0;

/// A run's expected error: its size where a study guides it, and what it is based on, or why
/// there is none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ExpectedError {
    /// The expected size of the mean load's error against its converged value, % (either
    /// sign); null where no measured study is near the case.
    pub percent: Option<f64>,
    /// The study it is read from, or why no study guides this case ("no measured guide: …").
    pub basis: String,
}

/// The expected error of `case` as it stands (its own model, shape function and n).
pub fn of_case(case: &Case) -> ExpectedError {
    let g = case.geometry();
    at(case, g.model, case.shape(), g.layers)
}

/// The expected error of `case` run with `model`, `shape` and `n` particles through the wall.
pub fn at(case: &Case, model: Model, shape: ShapeKind, n: u32) -> ExpectedError {
    let wall = match guiding_wall(case) {
        Err(why) => {
            return ExpectedError {
                percent: None,
                basis: format!("no measured guide: {why}"),
            }
        }
        Ok(wall) => wall,
    };
    let mode = case.geometry().mode;
    if wall == Wall::Thin {
        return thin_wall(case, mode, model, shape, n);
    }
    if shape != ShapeKind::Gimp {
        return ExpectedError {
            percent: None,
            basis: format!(
                "no measured guide: the paper's tube was studied with uGIMP; {} shape \
                 functions have no converged answer measured on it",
                shape.name()
            ),
        };
    }
    let percent = expected_error_percent(mode, model, shape, n);
    let study = match (mode, model) {
        (LoadingMode::Lateral, _) => "plane-strain",
        (_, Model::ThreeD) => "3D",
        (_, _) => "axisymmetric",
    };
    ExpectedError {
        percent,
        basis: format!(
            "expected, not priced: the {study} study of the paper's tube (PVC, d/t 6.9, uGIMP) \
             at n = {n}, docs/trust.md"
        ),
    }
}

/// The expected error of a run of a wall near the d/t 14 tube: measured for B-splines in 3D
/// axial crushes between plates that hold the ends; none otherwise, and why.
fn thin_wall(
    case: &Case,
    mode: LoadingMode,
    model: Model,
    shape: ShapeKind,
    n: u32,
) -> ExpectedError {
    let none = |why: &str| ExpectedError {
        percent: None,
        basis: format!("no measured guide: {why}"),
    };
    if mode != LoadingMode::Axial || model != Model::ThreeD {
        return none(
            "the d/t 14 wall was studied in 3D axial crushes only, where it folds in lobes no \
             section can hold",
        );
    }
    if let Err(why) = sped_up_beyond_the_study(case) {
        return none(&why);
    }
    let holding = case.spec().contact.friction >= HOLDING_FRICTION;
    match shape {
        ShapeKind::Bspline if holding && case.spec().trigger.weak_fraction <= 0.0 => none(
            "the d/t 14 wall was studied with a 0.3 % trigger; without one it folded in rings \
             on B-splines at n = 4, 18.473 kN against the triggered run's 15.635 kN (+18 %), \
             docs/studies.md §9",
        ),
        ShapeKind::Bspline if holding => ExpectedError {
            percent: tables::interpolated(THIN_BSPLINE_3D, n),
            basis: format!(
                "expected, not priced: the 3D study of the d/t 14 tube (PVC, B-splines, μ 0.3) \
                 at n = {n}, docs/studies.md §9"
            ),
        },
        ShapeKind::Bspline => none(
            "the d/t 14 wall was studied on B-splines between plates that hold its ends (μ 0.3); \
             on near-frictionless plates they splay its far end (docs/folding.md §4)",
        ),
        ShapeKind::Gimp => none(
            "the d/t 14 tube's 3D mean load alternates with the parity of n through n = 6 on \
             uGIMP (17.10 and 17.20 kN at n = 3 and 5, folding from both ends; 15.54 and 15.57 \
             kN at n = 4 and 6, from the fixed end; PVC, docs/studies.md §9), so it has no \
             converged value to measure an error against; B-splines settle on it, or price \
             this run's error bar (output.error_bar)",
        ),
        ShapeKind::Linear => none(
            "the d/t 14 tube's linear-shape runs fold where the grid's frame puts the first \
             ring and were not run past n = 4 (docs/studies.md §9); B-splines settle on it",
        ),
    }
}

/// Which studied wall guides a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Wall {
    /// The paper's tube, d/t 6.9: studied in 3D and in both sections to convergence.
    Thick,
    /// The d/t 14 tube: studied in 3D axial crushes (docs/studies.md §9).
    Thin,
}

/// The studied wall that guides `case`, or why none does.
fn guiding_wall(case: &Case) -> Result<Wall, String> {
    let section = case.geometry().section;
    if !section.revolves() {
        return Err(format!(
            "the studies are of round tubes; no {} tube's is measured",
            section.name()
        ));
    }
    let d_over_t = section.width_mm() / section.thickness_mm();
    let near = |studied: f64| (studied / NEAR_FACTOR..=studied * NEAR_FACTOR).contains(&d_over_t);
    let wall = match (near(STUDIED_D_OVER_T), near(THIN_D_OVER_T)) {
        (true, _) => Wall::Thick,
        (_, true) if d_over_t > 0.5 * (THIN_D_OVER_T + UNCONVERGED_D_OVER_T) => {
            return Err(format!(
                "d/t {d_over_t:.1} is nearer the t 1.27 d 20.32 tube (d/t {:.0}) than the d/t 14 \
                 one, and its 3D mean load rose 20 % from n = 3 to 4 on uGIMP and 12 % on \
                 B-splines, with no converged value (docs/studies.md §10); price this run's \
                 error bar (output.error_bar)",
                UNCONVERGED_D_OVER_T
            ))
        }
        (_, true) => Wall::Thin,
        _ => {
            return Err(format!(
                "d/t {d_over_t:.1} is outside the studied walls' {:.1}-{:.1} and {:.1}-{:.1}; \
                 a wall of another d/t folds otherwise",
                STUDIED_D_OVER_T / NEAR_FACTOR,
                STUDIED_D_OVER_T * NEAR_FACTOR,
                THIN_D_OVER_T / NEAR_FACTOR,
                THIN_D_OVER_T * NEAR_FACTOR,
            ))
        }
    };
    let m = &case.spec().material;
    if m.model != MaterialModel::J2
        || m.youngs_modulus_mpa >= METAL_MODULUS_MPA
        || m.hardening != HardeningKind::None
        || m.rate != RateKind::None
    {
        return Err(
            "the studies' wall is the paper's elastic-perfectly plastic PVC; this material \
             folds otherwise"
                .into(),
        );
    }
    Ok(wall)
}

/// Why the d/t 14 study does not guide a thin-wall run faster than its own, if it is: it ran
/// unscaled at [`STUDIED_PLATE_SPEED_M_S`], and a speed-up moves a thin wall into another mode
/// (docs/performance.md, *Mass scaling and the test speed*).
fn sped_up_beyond_the_study(case: &Case) -> Result<(), String> {
    let spec = case.spec();
    let f = spec.discretization.mass_scaling;
    if f > 1.0 {
        return Err(format!(
            "the d/t 14 wall was studied unscaled, and mass scaling changes a thin wall's \
             collapse: on B-splines at n = 4 it folds in rings at f = 2 to 16, its mean load \
             16-35 % above the unscaled run's (docs/performance.md); this run's \
             discretization.mass_scaling is {f}"
        ));
    }
    let v = spec.loading.plate_speed_m_s;
    if v > STUDIED_PLATE_SPEED_M_S {
        return Err(format!(
            "the d/t 14 wall was studied at {STUDIED_PLATE_SPEED_M_S} m/s, and this plate's {v} \
             m/s loads it with more inertia, which moved it into rings when mass scaling did \
             the same (docs/performance.md)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Limits;

    fn case(json: &str) -> Case {
        Case::from_json(json, &Limits::default()).unwrap()
    }

    /// The paper's tube reads its own study: the default case's n in 3D, the section's table
    /// in the axisymmetric model, the plane-strain one laterally.
    #[test]
    fn the_paper_s_tube_reads_its_own_study() {
        let c = case(r#"{"discretization": {"particles_through_thickness": 6}}"#);
        let e = of_case(&c);
        assert_eq!(e.percent, Some(6.3), "3D uGIMP at n = 6: {e:?}");
        assert!(
            e.basis.starts_with("expected, not priced: the 3D study"),
            "{e:?}"
        );
        let a = case(
            r#"{"discretization": {"model": "axisymmetric", "particles_through_thickness": 16}}"#,
        );
        assert_eq!(of_case(&a).percent, Some(0.4));
        let l = case(
            r#"{"loading": {"mode": "lateral"},
                "discretization": {"model": "plane_strain", "particles_through_thickness": 8}}"#,
        );
        assert_eq!(of_case(&l).percent, Some(0.8));
    }

    /// A thin-wall run faster than its study's (mass-scaled, or its plate faster) gets no
    /// figure, though its wall, shape and n are the study's: on the d/t 14 tube the speed-up
    /// changed the mode and the mean load by a fifth. Nor does one without the study's
    /// trigger, which folded in rings 18 % higher. The paper's thick tube, which kept its
    /// answer sped up, keeps its guide.
    #[test]
    fn a_sped_up_or_untriggered_thin_run_has_no_measured_guide() {
        let tube = r#""tube": {"thickness_mm": 3.2, "mean_diameter_mm": 44.8, "length_mm": 125.4},
            "contact": {"friction": 0.3}"#;
        let thin = format!(r#"{tube}, "trigger": {{"weak_fraction": 0.003}}"#);
        let plain = case(&format!(
            r#"{{{thin}, "discretization": {{"particles_through_thickness": 4}}}}"#
        ));
        assert_eq!(of_case(&plain).percent, Some(0.9), "{:?}", of_case(&plain));
        for (json, why) in [
            (
                format!(
                    r#"{{{thin}, "discretization": {{"particles_through_thickness": 4,
                        "mass_scaling": 4}}}}"#
                ),
                "mass_scaling is 4",
            ),
            (
                format!(
                    r#"{{{thin}, "discretization": {{"particles_through_thickness": 4}},
                        "loading": {{"plate_speed_m_s": 20}}}}"#
                ),
                "20 m/s",
            ),
        ] {
            let e = of_case(&case(&json));
            assert_eq!(e.percent, None, "{json}");
            assert!(e.basis.starts_with("no measured guide: "), "{e:?}");
            assert!(e.basis.contains(why), "{json}: {e:?}");
        }
        let untriggered = case(&format!(
            r#"{{{tube}, "discretization": {{"particles_through_thickness": 4}},
                "trigger": {{"weak_fraction": 0}}}}"#
        ));
        let e = of_case(&untriggered);
        assert_eq!(e.percent, None, "{e:?}");
        assert!(e.basis.contains("0.3 % trigger"), "{e:?}");
        for thick in [
            r#"{"discretization": {"mass_scaling": 4}}"#,
            r#"{"loading": {"plate_speed_m_s": 15}}"#,
        ] {
            assert_eq!(of_case(&case(thick)).percent, Some(11.6), "{thick}");
        }
    }

    /// A case far from the studied tube gets no figure, and the reason names what differs.
    #[test]
    fn a_case_far_from_the_studies_has_no_measured_guide_and_says_why() {
        for (json, why) in [
            (
                r#"{"tube": {"thickness_mm": 1.67, "mean_diameter_mm": 48.33}}"#,
                "d/t 28.9",
            ),
            (r#"{"material": {"preset": "aa6060_t5"}}"#, "PVC"),
            (r#"{"material": {"preset": "stainless_304"}}"#, "PVC"),
            (r#"{"discretization": {"shape": "linear"}}"#, "uGIMP"),
            (
                r#"{"tube": {"section": "rectangular", "thickness_mm": 3.2, "side_a_mm": 22,
                    "side_b_mm": 22, "corner_radius_mm": 2}}"#,
                "round tubes",
            ),
        ] {
            let e = of_case(&case(json));
            assert_eq!(e.percent, None, "{json}");
            assert!(e.basis.starts_with("no measured guide: "), "{e:?}");
            assert!(e.basis.contains(why), "{json}: {e:?}");
        }
    }

    /// The edge of "near": a wall a little thinner than the paper's is guided, one of d/t 10,
    /// between the two studied walls, is not.
    #[test]
    fn near_is_within_a_quarter_of_the_studied_wall() {
        let d = |d_over_t: f64| {
            of_case(&case(&format!(
                r#"{{"tube": {{"thickness_mm": 3.2, "mean_diameter_mm": {}}},
                    "discretization": {{"shape": "gimp"}}}}"#,
                3.2 * d_over_t
            )))
            .percent
        };
        assert!(d(8.5).is_some());
        assert!(d(10.0).is_none());
        assert!(d(5.6).is_some());
        assert!(d(5.4).is_none());
    }

    /// The paper's d/t 16 tube moved 20 % from n = 3 to 4: a wall nearer it than the d/t 14
    /// tube has no measured guide and names that study; one nearer the d/t 14 tube names the
    /// d/t 14 study.
    #[test]
    fn a_wall_nearer_the_unconverged_d_over_t_16_tube_has_no_measured_guide() {
        let d = |d_over_t: f64| {
            of_case(&case(&format!(
                r#"{{"tube": {{"thickness_mm": 1.27, "mean_diameter_mm": {}, "length_mm": 76.2}},
                    "contact": {{"friction": 0.3}},
                    "discretization": {{"particles_through_thickness": 4, "shape": "gimp"}}}}"#,
                1.27 * d_over_t
            )))
        };
        let paper = d(20.32 / 1.27);
        assert_eq!(paper.percent, None, "{paper:?}");
        assert!(paper.basis.starts_with("no measured guide: "), "{paper:?}");
        assert!(paper.basis.contains("§10"), "{paper:?}");
        assert!(d(15.2).basis.contains("§10"), "{:?}", d(15.2));
        let nearer_14 = d(14.8);
        assert_eq!(nearer_14.percent, None, "{nearer_14:?}");
        assert!(nearer_14.basis.contains("§9"), "{nearer_14:?}");
    }

    /// What broke: the d/t 14 wall read the paper's 3D errors as its own (±11.6 % at n = 4), on
    /// the strength of n = 4 and 6 agreeing within 0.3 %; n = 5 then ran 10.4 % above n = 6, so
    /// the wall has no converged value. A 3D axial uGIMP run of it gets no figure and a reason
    /// that says so; its section, a lateral crush or linear shapes get none either.
    #[test]
    fn the_d_over_t_14_wall_has_no_measured_guide_as_its_load_alternates_with_the_parity_of_n() {
        let thin = |extra: &str| {
            of_case(&case(&format!(
                r#"{{"tube": {{"thickness_mm": 3.2, "mean_diameter_mm": 44.8, "length_mm": 125.4}},
                    "contact": {{"friction": 0.3}}{extra}}}"#
            )))
        };
        for n in [4, 5, 6] {
            let e = thin(&format!(
                r#", "discretization": {{"particles_through_thickness": {n}, "shape": "gimp"}}"#
            ));
            assert_eq!(e.percent, None, "n {n}: {e:?}");
            assert!(e.basis.starts_with("no measured guide: "), "{e:?}");
            assert!(e.basis.contains("parity of n"), "{e:?}");
        }
        for extra in [
            r#", "discretization": {"model": "axisymmetric"}"#,
            r#", "loading": {"mode": "lateral"}"#,
            r#", "discretization": {"shape": "linear"}"#,
        ] {
            let e = thin(extra);
            assert_eq!(e.percent, None, "{extra}: {e:?}");
            assert!(e.basis.starts_with("no measured guide: "), "{e:?}");
        }
    }

    /// The d/t 14 wall's B-spline runs settle from n = 4: a 3D axial B-spline run of it on
    /// plates that hold its ends (its default there) reads that study, within 1 % from n = 4
    /// and within 10 % only from n = 3; on near-frictionless plates, or in its section, it has
    /// no guide.
    #[test]
    fn a_thin_wall_on_b_splines_reads_the_d_over_t_14_study() {
        // The study's 0.3 % trigger, where the model can hold one (not in a section).
        let thin = |friction: f64, discretization: &str| {
            let trigger = match discretization.contains("axisymmetric") {
                true => 0.0,
                false => 0.003,
            };
            of_case(&case(&format!(
                r#"{{"tube": {{"thickness_mm": 3.2, "mean_diameter_mm": 44.8, "length_mm": 125.4}},
                    "contact": {{"friction": {friction}}}, "trigger": {{"weak_fraction": {trigger}}},
                    "discretization": {discretization}}}"#
            )))
        };
        let at = |n: u32| thin(0.3, &format!(r#"{{"particles_through_thickness": {n}}}"#));
        for n in [4, 5, 6, 8] {
            let e = at(n);
            let p = e.percent.unwrap_or_else(|| panic!("n {n}: {e:?}"));
            assert!(p < 1.0, "n {n}: {e:?}");
            assert!(e.basis.contains("d/t 14 tube (PVC, B-splines"), "{e:?}");
        }
        let three = at(3).percent.unwrap();
        assert!((5.0..10.0).contains(&three), "{three}");
        assert!(at(2).percent.unwrap() > 10.0);
        for (friction, d) in [
            (0.02, r#"{"shape": "bspline"}"#),
            (0.3, r#"{"shape": "bspline", "model": "axisymmetric"}"#),
        ] {
            let e = thin(friction, d);
            assert_eq!(e.percent, None, "{d}: {e:?}");
            assert!(e.basis.starts_with("no measured guide: "), "{e:?}");
        }
    }
}
