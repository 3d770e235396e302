//! What a case will cost before it runs: particles, cells, steps, memory, wall time.

use super::verdict::{foreseen, Verdict};
use crate::solver::model::case::Case;
use crate::solver::model::ladder::rungs;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::solver::model::case::Limits;
use crate::solver::model::case::{LoadingMode, Model, ShapeChoice, ShapeKind};

/// Throughput assumed for the wall-time guess, particle-steps per second per thread, by shape
/// function: `crush bench` (docs/performance.md) measured medians of 2.8–3.6 M/s for uGIMP and
/// 5.4–6.3 M/s for linear shapes on one thread from n = 2 to 10, and 4.6–5.9 M / 9.4–10.7 M
/// on two from n = 4 to 10; rounded down to allow for a shared machine.
pub fn assumed_particle_steps_per_s_per_thread(shape: ShapeKind) -> f64 {
    match shape {
        ShapeKind::Gimp => 2.5e6,
        ShapeKind::Linear => 4.5e6,
    }
}

/// The same for a reduced model's section, which gains little past two threads (its scatter
/// runs in bands of 1024 particles): `crush bench-one` on the axisymmetric paper case measured
/// 4.4 M (uGIMP) and 6.6 M (linear) particle-steps/s on one thread at n = 16, 7.0 M and 8.1 M
/// on two, and about 5 M on two for the 380 particles of n = 4; rounded down.
fn section_particle_steps_per_s(shape: ShapeKind, threads: u32) -> f64 {
    let one = match shape {
        ShapeKind::Gimp => 3.5e6,
        ShapeKind::Linear => 5.0e6,
    };
    one * (1.0 + 0.5 * (threads.clamp(1, 2) - 1) as f64)
}

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
    pub threads: u32,
    /// The shape functions the case will run with, and why when it named none.
    pub shape: ShapeChoice,
    /// For a 3D case whose scene has a symmetry (no trigger): the reduced model that would run
    /// it, and at what cost.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reduced: Option<Reduced>,
    /// The verdict as far as the case alone tells it: the run's own may add reasons its
    /// numbers show (energy books, inertia), never take these away.
    pub verdict: Verdict,
    /// When the case asks for an error bar (`output.error_bar`): the expected wall time of its
    /// ladder's rungs, s, on top of `wall_time_s`.
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

/// Cost of running `case` on `threads` threads.
pub fn estimate(case: &Case, threads: u32) -> Estimate {
    let mut e = cost(case, threads);
    if case.spec().output.error_bar {
        // `Case::parse` checked that every rung parses and fits the limits.
        let rungs = rungs(case.spec(), case.shape()).unwrap_or_default();
        e.error_bar_wall_time_s = Some(
            rungs
                .into_iter()
                .filter_map(|(_, twin)| Case::parse(twin?, &Limits::unbounded()).ok())
                .map(|twin| cost(&twin, threads).wall_time_s)
                .sum(),
        );
    }
    e.reduced = reduced(case).map(|(model, r)| {
        let c = cost(&r, threads);
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
fn cost(case: &Case, threads: u32) -> Estimate {
    let spec = case.spec();
    let d = &spec.discretization;
    let particles = case.particle_count();
    let k = d.cell_to_particle_ratio;
    let (cells, rate) = match d.model {
        Model::ThreeD => (
            particles as f64 / (k * k * k),
            assumed_particle_steps_per_s_per_thread(case.shape()) * threads.max(1) as f64,
        ),
        _ => (
            particles as f64 / (k * k),
            section_particle_steps_per_s(case.shape(), threads),
        ),
    };
    // Both counts were computed, and held to the caller's limits, by `Case::parse`.
    let steps = case.step_count();
    Estimate {
        particles,
        cells: cells.ceil() as u64,
        steps,
        memory_bytes: particles * ASSUMED_BYTES_PER_PARTICLE,
        wall_time_s: particles as f64 * steps as f64 / rate,
        threads,
        shape: case.shape_choice().clone(),
        reduced: None,
        verdict: Verdict::of(foreseen(case)),
        error_bar_wall_time_s: None,
    }
}
