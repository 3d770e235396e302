//! What a case will cost before it runs: particles, cells, steps, memory, wall time.

use super::Case;
use serde::{Deserialize, Serialize};

use super::case::ShapeKind;

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

/// Bytes of solver state per particle, grid included (an upper bound used for the estimate:
/// measured peaks are 270–480 B per particle from n = 4 up, and up to 850 B for the smallest
/// cases, where the grid's padded blocks dominate).
pub const ASSUMED_BYTES_PER_PARTICLE: u64 = 500;

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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
}

/// Cost of running `case` on `threads` threads.
pub fn estimate(case: &Case, threads: u32) -> Estimate {
    let spec = case.spec();
    let particles = case.particle_count();
    let k = spec.discretization.cell_to_particle_ratio;
    let cells = (particles as f64 / (k * k * k)).ceil() as u64;
    // Both counts were computed, and held to the caller's limits, by `Case::parse`.
    let steps = case.step_count();
    let rate =
        assumed_particle_steps_per_s_per_thread(spec.discretization.shape) * threads.max(1) as f64;
    Estimate {
        particles,
        cells,
        steps,
        memory_bytes: particles * ASSUMED_BYTES_PER_PARTICLE,
        wall_time_s: particles as f64 * steps as f64 / rate,
        threads,
    }
}
