//! What a case will cost before it runs: particles, cells, steps, memory, wall time.

use super::rates::{LawKind, RateBasis, Rates};
use super::verdict::{foreseen, Verdict};
use crate::solver::model::case::Case;
use crate::solver::model::case::CaseSpec;
use crate::solver::model::ladder::{rungs, three_d_rungs};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::solver::model::case::Limits;
use crate::solver::model::case::{LoadingMode, Model, ShapeChoice};

/// Bytes of solver state per particle, grid included (an upper bound used for the estimate:
/// measured peaks are 270–480 B per particle from n = 4 up, and up to 850 B for the smallest
/// cases, where the grid's padded blocks dominate).
pub const ASSUMED_BYTES_PER_PARTICLE: u64 = 500;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Estimate {
    pub particles: u64,
    /// Background cells holding tube material at the start.
    pub cells: u64,
    /// Explicit steps at the initial time step.
    pub steps: u64,
    pub memory_bytes: u64,
    /// Expected wall time on `threads` threads, s.
    pub wall_time_s: f64,
    /// The throughput the wall times assume: measured on this machine's finished runs of the
    /// same model and shape function, or the fixed default.
    #[serde(default)]
    pub wall_time_basis: RateBasis,
    pub threads: u32,
    /// The shape functions the case will run with, and why when it named none.
    pub shape: ShapeChoice,
    /// The CFL number α the case will run with (Δt = α · cell / max(c + |v|)).
    pub cfl: f64,
    /// Why the case runs with `cfl`, when it named none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cfl_default_reason: Option<String>,
    /// For a 3D case whose scene has a symmetry (no trigger): the reduced model that would run
    /// it, and at what cost.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reduced: Option<Reduced>,
    /// The verdict as far as the case alone tells it: the run's own may add reasons its
    /// numbers show (energy books, inertia), never take these away.
    pub verdict: Verdict,
    /// When the run will price an error bar (`output.error_bar`, or unasked when it costs at
    /// most [`UNASKED_ERROR_BAR_FRACTION`] of the run): the expected wall time of its ladder's
    /// rungs, s, on top of `wall_time_s`: its section's, or, asked for a 3D case with no
    /// section ladder, the 3D ladder's (a 3D run whose collapse its section cannot fold is
    /// priced with the 3D ladder as it runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_bar_wall_time_s: Option<f64>,
}

/// What the reduced model would cost against 3D, and what it cannot show.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Reduced {
    pub model: Model,
    pub particles: u64,
    pub wall_time_s: f64,
    /// 3D wall time over the reduced model's.
    pub speedup: f64,
    pub cannot_show: String,
}

/// Cost of running `case` on `threads` threads, at the assumed rates.
pub fn estimate(case: &Case, threads: u32) -> Estimate {
    estimate_with(case, threads, &Rates::assumed())
}

/// Cost of running `case` on `threads` threads, its wall times at `rates`.
pub fn estimate_with(case: &Case, threads: u32, rates: &Rates) -> Estimate {
    let mut e = cost(case, threads, rates);
    let ladder_s = ladder_wall_time_s(case, threads, rates);
    let unasked = ladder_s.is_some_and(|s| s <= UNASKED_ERROR_BAR_FRACTION * e.wall_time_s);
    if unasked {
        e.error_bar_wall_time_s = ladder_s;
    } else if case.spec().output.error_bar {
        e.error_bar_wall_time_s =
            ladder_s.or_else(|| three_d_ladder_wall_time_s(case, threads, rates));
    }
    e.reduced = reduced(case).map(|(model, r)| {
        let c = cost(&r, threads, rates);
        Reduced {
            model,
            particles: c.particles,
            wall_time_s: c.wall_time_s,
            speedup: e.wall_time_s / c.wall_time_s.max(1e-9),
            cannot_show: match model {
                Model::Axisymmetric => {
                    "lobes (diamond modes) and global buckling: the section \
                                        can fold only as rings"
                }
                _ => "end effects: every section of the tube deforms alike",
            }
            .into(),
        }
    });
    e
}

/// The most an error bar may add to a run's own expected wall time, as a share of it, to be
/// priced without being asked (`output.error_bar` false): the ladder of a 3D run at n = 8 of
/// the paper's tube costs about a seventh of the run, at n = 6 half, at n = 4 two and a half
/// times (docs/trust.md).
pub const UNASKED_ERROR_BAR_FRACTION: f64 = 0.25;

/// The expected wall time of the case's error-bar ladder of its section (its rungs that are
/// runs of their own), s; `None` when the case has no such ladder (its shape functions, its
/// section, or a rung the limits refuse).
pub fn ladder_wall_time_s(case: &Case, threads: u32, rates: &Rates) -> Option<f64> {
    rungs_wall_time_s(rungs(case.spec(), case.shape()).ok()?, threads, rates)
}

/// The expected wall time of the case's 3D ladder (the case at n − 2 and n − 1), s; `None`
/// when it has none. Priced only when asked: it costs ((n − 2)/n)⁴ + ((n − 1)/n)⁴ of the run.
pub fn three_d_ladder_wall_time_s(case: &Case, threads: u32, rates: &Rates) -> Option<f64> {
    rungs_wall_time_s(
        three_d_rungs(case.spec(), case.shape()).ok()?,
        threads,
        rates,
    )
}

fn rungs_wall_time_s(
    rungs: Vec<(u32, Option<CaseSpec>)>,
    threads: u32,
    rates: &Rates,
) -> Option<f64> {
    rungs
        .into_iter()
        .filter_map(|(_, twin)| twin)
        .map(|twin| {
            Case::parse(twin, &Limits::unbounded())
                .ok()
                .map(|twin| cost(&twin, threads, rates).wall_time_s)
        })
        .sum()
}

/// The error bar's expected cost over the run's own, at the same rates (so independent of
/// them but for the model and shape): `None` when the case has no ladder of its section.
pub fn error_bar_cost_fraction(case: &Case) -> Option<f64> {
    let rates = Rates::assumed();
    let ladder = ladder_wall_time_s(case, 1, &rates)?;
    Some(ladder / cost(case, 1, &rates).wall_time_s.max(1e-12))
}

/// The 3D ladder's expected cost over the run's own: `None` when the case has none.
pub fn three_d_ladder_cost_fraction(case: &Case) -> Option<f64> {
    let rates = Rates::assumed();
    let ladder = three_d_ladder_wall_time_s(case, 1, &rates)?;
    Some(ladder / cost(case, 1, &rates).wall_time_s.max(1e-12))
}

/// The reduced model that fits a 3D case, as a case of its own.
fn reduced(case: &Case) -> Option<(Model, Case)> {
    let spec = case.spec();
    if spec.discretization.model != Model::ThreeD || spec.trigger.weak_fraction > 0.0 {
        return None;
    }
    let model = match spec.loading.mode {
        LoadingMode::Axial => Model::Axisymmetric,
        LoadingMode::Lateral => Model::PlaneStrain,
    };
    let mut spec = spec.clone();
    spec.discretization.model = model;
    // Fewer particles and the same steps as a case that passed: no limit can refuse it.
    Some((model, Case::parse(spec, &Limits::unbounded()).ok()?))
}

/// Particles, cells, steps, memory and wall time of `case` alone.
pub(super) fn cost(case: &Case, threads: u32, rates: &Rates) -> Estimate {
    let spec = case.spec();
    let d = &spec.discretization;
    let particles = case.particle_count();
    let k = d.cell_to_particle_ratio;
    let cells = match d.model {
        Model::ThreeD => particles as f64 / (k * k * k),
        _ => particles as f64 / (k * k),
    };
    let law = LawKind::of(&spec.material);
    let (rate, basis) = rates.rate(d.model, case.shape(), law, threads);
    // Both counts were computed, and held to the caller's limits, by `Case::parse`.
    let steps = case.step_count();
    Estimate {
        particles,
        cells: cells.ceil() as u64,
        steps,
        memory_bytes: particles * ASSUMED_BYTES_PER_PARTICLE,
        wall_time_s: particles as f64 * steps as f64 / rate,
        wall_time_basis: basis,
        threads,
        shape: case.shape_choice().clone(),
        cfl: case.cfl(),
        cfl_default_reason: case.cfl_default_reason().map(String::from),
        reduced: None,
        verdict: Verdict::of(foreseen(case)),
        error_bar_wall_time_s: None,
    }
}
