//! What a case will cost before it runs: particles, cells, steps, memory, wall time.

use super::Case;
use serde::{Deserialize, Serialize};

/// Throughput assumed for the wall-time guess, particle-steps per second per thread: measured
/// 3.3 M/s on 2 threads for GIMP at n = 4 (linear shapes run about 1.5 times faster), rounded
/// down.
pub const ASSUMED_PARTICLE_STEPS_PER_S_PER_THREAD: f64 = 1.5e6;

/// Bytes of solver state per particle, grid included (an upper bound used for the estimate).
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
    let speed = spec.loading.plate_speed_m_s;
    let dt = spec.discretization.cfl * case.cell_mm() / (case.wave_speed_m_s() + speed);
    let steps = (case.crush_distance_mm() / speed / dt).ceil() as u64;
    let rate = ASSUMED_PARTICLE_STEPS_PER_S_PER_THREAD * threads.max(1) as f64;
    Estimate {
        particles,
        cells,
        steps,
        memory_bytes: particles * ASSUMED_BYTES_PER_PARTICLE,
        wall_time_s: particles as f64 * steps as f64 / rate,
        threads,
    }
}
