//! The planner: for a case and a goal (a target error of the mean load, or a time budget), the
//! runs that could answer it — model, shape function, n — each with its expected
//! discretization error and wall time, and the one to pick. Units: %, s.
//!
//! The expected error at n is read off the error-vs-n tables measured on the paper's tube
//! ([`super::expected`], docs/trust.md "Planning a run"), or "no measured guide" in the
//! option itself where the case is far from the studied tube; no solver runs, so a plan costs a few
//! case checks and is answered in milliseconds. The wall times are the estimate's, at the
//! caller's [`Rates`].

pub use super::expected::{error_table, expected_error_percent, ERROR_BASIS};

use super::estimate::cost;
use super::rates::{RateBasis, Rates};
use crate::solver::model::case::{is_thin, may_tip_over, slenderness};
use crate::solver::model::case::{
    Case, CaseSpec, CrossSection, Limits, LoadingMode, Model, Outline, ShapeKind,
};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What the run is for: the error to reach, or the wall time to spend.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Goal {
    /// The largest expected error of the mean load, %.
    TargetErrorPercent(f64),
    /// The longest wall time, s.
    BudgetS(f64),
}

/// One way to run the case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PlanOption {
    pub model: Model,
    pub shape: ShapeKind,
    /// Particles through the wall.
    pub n: u32,
    pub particles: u64,
    pub steps: u64,
    /// Expected error of the mean load against the converged value, % (its size, either
    /// sign); null where no measured study guides this option (`error_guide` says why).
    pub expected_error_percent: Option<f64>,
    /// The study the expected error is read from, or "no measured guide: " and why.
    #[serde(default)]
    pub error_guide: String,
    /// Expected wall time on the plan's threads, s.
    pub wall_time_s: f64,
    pub wall_time_basis: RateBasis,
    /// What a run of this model can show, and what it cannot.
    pub shows: String,
}

/// The options and the pick.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Plan {
    /// The goal, as asked: one of the two is set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_error_percent: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget_s: Option<f64>,
    pub threads: u32,
    /// Every option within the runner's limits: the case's own model first, by shape and n.
    pub options: Vec<PlanOption>,
    /// The option to run: of the case's own model, the cheapest that meets the target, or the
    /// most accurate that fits the budget; null when none does (`reason` says why).
    pub pick: Option<PlanOption>,
    /// Why the pick, or why none.
    pub reason: String,
    /// How the expected errors are predicted.
    pub error_basis: String,
    /// Options left out because the case is refused at that model, shape and n: over the
    /// runner's limits (particles, steps), or a check that depends on the resolution.
    pub refused: u32,
}

/// The plan for `case` towards `goal` on `threads` threads, wall times at `rates`, options held
/// to `limits`. Cost: one case check per option (at most 30).
pub fn plan(case: &Case, goal: Goal, threads: u32, rates: &Rates, limits: &Limits) -> Plan {
    let spec = case.spec();
    let own = spec.discretization.model;
    let mode = spec.loading.mode;
    let mut options = Vec::new();
    let mut refused = 0;
    let mut candidates: Vec<(Model, ShapeKind, u32)> = Vec::new();
    // B-splines are offered where a study measured them: a thin wall in 3D.
    let thin_3d = own == Model::ThreeD && is_thin(&case.geometry().section);
    let shapes: &[ShapeKind] = match thin_3d {
        true => &[ShapeKind::Gimp, ShapeKind::Linear, ShapeKind::Bspline],
        false => &[ShapeKind::Gimp, ShapeKind::Linear],
    };
    for &shape in shapes {
        for (n, _) in error_table(mode, own) {
            candidates.push((own, shape, *n));
        }
    }
    if let Some(reduced) = reduced_model(spec) {
        for (n, _) in error_table(mode, reduced) {
            candidates.push((reduced, ShapeKind::Gimp, *n));
        }
    }
    for (model, shape, n) in candidates {
        if n > model.max_particles_through_thickness() {
            continue;
        }
        let mut s = spec.clone();
        s.discretization.model = model;
        s.discretization.shape = Some(shape);
        s.discretization.particles_through_thickness = n;
        s.output.error_bar = false;
        if model != Model::ThreeD {
            s.trigger.weak_fraction = 0.0;
        }
        let Ok(option) = Case::parse(s, limits) else {
            refused += 1;
            continue;
        };
        let c = cost(&option, threads, rates);
        let expected = super::expected::at(&option, model, shape, n);
        options.push(PlanOption {
            model,
            shape,
            n,
            particles: c.particles,
            steps: c.steps,
            expected_error_percent: expected.percent,
            error_guide: expected.basis,
            wall_time_s: c.wall_time_s,
            wall_time_basis: c.wall_time_basis,
            shows: shows(spec, model, shape),
        });
    }
    let (pick, reason) = pick(&options, own, goal);
    let (target_error_percent, budget_s) = match goal {
        Goal::TargetErrorPercent(t) => (Some(t), None),
        Goal::BudgetS(b) => (None, Some(b)),
    };
    Plan {
        target_error_percent,
        budget_s,
        threads,
        pick: pick.cloned(),
        options,
        reason,
        error_basis: ERROR_BASIS.into(),
        refused,
    }
}

/// The reduced model that can run a 3D case (none with a trigger: a section has no weak
/// particles to place; none for a tube crushed axially whose section has no axis to revolve).
fn reduced_model(spec: &CaseSpec) -> Option<Model> {
    if spec.discretization.model != Model::ThreeD || spec.trigger.weak_fraction > 0.0 {
        return None;
    }
    if spec.loading.mode == LoadingMode::Axial && !CrossSection::of(&spec.tube).revolves() {
        return None;
    }
    Some(match spec.loading.mode {
        LoadingMode::Axial => Model::Axisymmetric,
        LoadingMode::Lateral => Model::PlaneStrain,
    })
}

/// What a run of `model` with `shape` can show of `spec`'s tube.
fn shows(spec: &CaseSpec, model: Model, shape: ShapeKind) -> String {
    let section = CrossSection::of(&spec.tube);
    let mut s = match (model, spec.loading.mode) {
        (Model::ThreeD, LoadingMode::Axial) if section.faces() > 0 => {
            "every mode: symmetric, asymmetric mixed, extensional, global bending, end effects"
        }
        (Model::ThreeD, LoadingMode::Axial) => {
            "every mode: rings, lobes (diamond), global buckling, end effects"
        }
        (Model::ThreeD, LoadingMode::Lateral) => "the whole tube, end effects included",
        (Model::Axisymmetric, _) => "rings only: no lobes, no global buckling",
        (Model::PlaneStrain, _) => "the section's flattening only: no end effects",
    }
    .to_string();
    if model == Model::ThreeD
        && shape != ShapeKind::Linear
        && may_tip_over(&section, spec.contact.friction)
    {
        let who = match shape {
            ShapeKind::Bspline => "B-splines",
            _ => "uGIMP",
        };
        s.push_str(&format!(
            "; {who} can let a wall this thin ({}/t = {:.1}) tip over on plates this \
             slippery (μ {})",
            section.width_symbol(),
            slenderness(&section),
            spec.contact.friction
        ));
    }
    if !section.revolves() {
        s.push_str(&format!(
            "; the error is not known (no convergence study of a {} tube yet)",
            section.name()
        ));
    } else {
        match shape {
            ShapeKind::Linear => s.push_str(
                "; linear shapes: the error is not known (they do not converge on thin walls)",
            ),
            ShapeKind::Bspline => s.push_str(
                "; B-splines: the error is measured on the d/t 14 tube in 3D only \
                 (docs/studies.md §9)",
            ),
            ShapeKind::Gimp => {}
        }
    }
    s
}

/// The option to run among those of the case's own model `own`, and why; or none, and why.
pub fn pick(options: &[PlanOption], own: Model, goal: Goal) -> (Option<&PlanOption>, String) {
    let known: Vec<(&PlanOption, f64)> = options
        .iter()
        .filter(|o| o.model == own)
        .filter_map(|o| o.expected_error_percent.map(|e| (o, e)))
        .collect();
    let model = match own {
        Model::ThreeD => "3D".to_string(),
        other => other.name().replace('_', " "),
    };
    if known.is_empty() {
        let why = if options.iter().any(|o| o.model == own) {
            "none of its options has a known error (the options below say why)"
        } else {
            "none is within this runner's limits"
        };
        return (None, format!("no {model} pick: {why}"));
    }
    match goal {
        Goal::TargetErrorPercent(target) => {
            let best = known
                .iter()
                .filter(|(_, e)| *e <= target)
                .min_by(|a, b| a.0.wall_time_s.total_cmp(&b.0.wall_time_s));
            match best {
                Some((o, e)) => (
                    Some(*o),
                    format!(
                        "the cheapest {model} run expected within ±{target} %: n = {} ({}), \
                         ±{e:.1} %, about {:.0} s",
                        o.n,
                        o.shape.name(),
                        o.wall_time_s
                    ),
                ),
                None => {
                    let (o, e) = most_accurate(&known);
                    (
                        None,
                        format!(
                            "no {model} run within this runner's limits is expected within \
                             ±{target} %: the most accurate, n = {} ({}), is expected within \
                             ±{e:.1} % in about {:.0} s",
                            o.n,
                            o.shape.name(),
                            o.wall_time_s
                        ),
                    )
                }
            }
        }
        Goal::BudgetS(budget) => {
            let fits: Vec<(&PlanOption, f64)> = known
                .iter()
                .copied()
                .filter(|(o, _)| o.wall_time_s <= budget)
                .collect();
            if fits.is_empty() {
                let o = known
                    .iter()
                    .map(|(o, _)| *o)
                    .min_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s))
                    .expect("known is not empty");
                return (
                    None,
                    format!(
                        "no {model} run fits in {budget} s: the cheapest, n = {} ({}), takes \
                         about {:.0} s",
                        o.n,
                        o.shape.name(),
                        o.wall_time_s
                    ),
                );
            }
            let (o, e) = most_accurate(&fits);
            (
                Some(o),
                format!(
                    "the most accurate {model} run that fits in {budget} s: n = {} ({}), \
                     ±{e:.1} %, about {:.0} s",
                    o.n,
                    o.shape.name(),
                    o.wall_time_s
                ),
            )
        }
    }
}

/// The option with the smallest expected error; the cheaper of equals.
fn most_accurate<'a>(options: &[(&'a PlanOption, f64)]) -> (&'a PlanOption, f64) {
    *options
        .iter()
        .min_by(|a, b| {
            a.1.total_cmp(&b.1)
                .then(a.0.wall_time_s.total_cmp(&b.0.wall_time_s))
        })
        .expect("called with options")
}

#[cfg(test)]
mod tests;
