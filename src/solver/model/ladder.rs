//! The resolutions of a run's error-bar ladder (`analysis::error_bar` prices it): the tube's
//! section at m, 1.5 m and 2 m particles through the wall, m = max(n, [`LOWEST_RUNG`]), and for
//! a 3D run its section at its own n too; or, for a 3D run its section cannot price, the same
//! 3D case at n − 2 and n − 1 below the run, with its own shape functions ([`three_d_rungs`]).
//! A section ladder runs uGIMP; a 3D ladder uGIMP or B-splines. The model owns the rungs so
//! that a case asking for an error bar is held, with its rungs, to the runner's limits before
//! it runs.

use super::geometry::{CrossSection, Outline};
use super::spec::{CaseSpec, LoadingMode, Model, ShapeKind};

/// The coarsest rung of a ladder. The paper's section converges smoothly (order about 3) from
/// n = 8 on, but not below: 13.648, 13.283 and 12.649 kN at n = 4, 6 and 8, where the steps
/// grow; a ladder at n = 3, 4, 6 extrapolates to 13.12 kN at order 2.9 against the converged
/// 12.45 kN (measured with `crush run`). No ladder can see a jump beyond its finest rung.
pub const LOWEST_RUNG: u32 = 8;

/// The rungs of `spec`'s ladder, coarsest first: n and the section's case at that n (`None`
/// for the rung that is the run itself, a section's own n); or why a ladder cannot price it.
/// `shape`: the shape functions the case runs with.
pub fn rungs(spec: &CaseSpec, shape: ShapeKind) -> Result<Vec<(u32, Option<CaseSpec>)>, String> {
    let model = spec.discretization.model;
    let n = spec.discretization.particles_through_thickness;
    gimp_only(shape)?;
    let section = CrossSection::of(&spec.tube);
    if spec.loading.mode == LoadingMode::Axial && !section.revolves() {
        return Err(format!(
            "a {} tube crushed axially has no section to climb (the section ladder runs the \
             axisymmetric section, and only a round tube has an axis of symmetry)",
            section.name()
        ));
    }
    let twin_model = match spec.loading.mode {
        LoadingMode::Axial => Model::Axisymmetric,
        LoadingMode::Lateral => Model::PlaneStrain,
    };
    let m = n.max(LOWEST_RUNG);
    let mut ns = vec![m, (3 * m).div_ceil(2), 2 * m];
    if model == Model::ThreeD && n < m {
        ns.insert(0, n);
    }
    let max = twin_model.max_particles_through_thickness();
    if ns[ns.len() - 1] > max {
        return Err(format!(
            "the ladder would need n = {} in the {} section, past its {max}",
            ns[ns.len() - 1],
            twin_model.name().replace('_', " ")
        ));
    }
    Ok(ns
        .into_iter()
        .map(|k| {
            if model != Model::ThreeD && k == n {
                return (k, None);
            }
            let mut twin = spec.clone();
            twin.discretization.model = twin_model;
            twin.discretization.particles_through_thickness = k;
            twin.discretization.shape = Some(ShapeKind::Gimp);
            twin.trigger.weak_fraction = 0.0;
            quiet(&mut twin);
            (k, Some(twin))
        })
        .collect())
}

/// The coarsest run a 3D ladder prices: its rungs are the run at n − 2 and n − 1.
pub const THREE_D_LOWEST_N: u32 = 3;

/// Why a 3D run at `n` below [`THREE_D_LOWEST_N`] has no 3D ladder.
pub fn three_d_too_coarse(n: u32) -> String {
    format!(
        "a 3D ladder needs n ≥ {THREE_D_LOWEST_N}: rungs at n − 2 and n − 1 below the run \
         (this run has n = {n})"
    )
}

/// The 3D ladder of a 3D `spec` run with `shape` (uGIMP or B-splines): the same case, shape
/// functions and all, at n − 2 and n − 1, and `None` for the run itself at n; or why it has
/// none (its model, linear shapes, or n below 3). It needs no table of another tube's
/// convergence: its rungs are this case's own runs.
pub fn three_d_rungs(
    spec: &CaseSpec,
    shape: ShapeKind,
) -> Result<Vec<(u32, Option<CaseSpec>)>, String> {
    if shape == ShapeKind::Linear {
        return Err(LINEAR_HAS_NO_LADDER.into());
    }
    if spec.discretization.model != Model::ThreeD {
        return Err("a 3D ladder climbs 3D runs: this run is a section".into());
    }
    let n = spec.discretization.particles_through_thickness;
    if n < THREE_D_LOWEST_N {
        return Err(three_d_too_coarse(n));
    }
    let rung = |k: u32| {
        let mut coarser = spec.clone();
        coarser.discretization.particles_through_thickness = k;
        coarser.discretization.shape = Some(shape);
        quiet(&mut coarser);
        (k, Some(coarser))
    };
    Ok(vec![rung(n - 2), rung(n - 1), (n, None)])
}

/// A rung reports its summary only: no final state, no frames, no error bar of its own.
fn quiet(spec: &mut CaseSpec) {
    spec.output.final_state = false;
    spec.output.frames = 0;
    spec.output.error_bar = false;
}

/// Why linear shape functions have no ladder, of either kind.
const LINEAR_HAS_NO_LADDER: &str = "linear shape functions (the default for a thin wall in 3D on \
     near-frictionless plates) have no converged answer on thin walls to measure the error \
     against yet (docs/studies.md §5); run with discretization.shape \"gimp\" for an error bar";

/// Why shape functions other than uGIMP have no section ladder.
fn gimp_only(shape: ShapeKind) -> Result<(), String> {
    match shape {
        ShapeKind::Gimp => Ok(()),
        ShapeKind::Linear => Err(LINEAR_HAS_NO_LADDER.into()),
        ShapeKind::Bspline => Err("B-splines have no section ladder (the section's rungs run \
             uGIMP, whose error is not a B-spline run's); a 3D run of them climbs its own 3D \
             ladder, a section run of them has none: run it with discretization.shape \"gimp\" \
             for an error bar"
            .into()),
    }
}
