//! PLACEHOLDER run loop: emits a synthetic history so that the CLI and service can be built
//! against the real signature. Replaced by the MPM engine before anything lands.

use super::*;
use std::sync::atomic::Ordering;

/// Runs a case to the end, reporting through `observer`; stops within a step when `cancel` is set.
pub fn run(case: &Case, observer: &mut dyn Observer, cancel: &AtomicBool) -> Result<RunOutput, SolveError> {
    let points = case.spec().output.history_points as usize;
    let speed = case.spec().loading.plate_speed_m_s;
    let dist = case.crush_distance_mm();
    let start = std::time::Instant::now();
    let mut history = Vec::with_capacity(points);
    for i in 0..points {
        if cancel.load(Ordering::Relaxed) {
            return Err(SolveError::Cancelled { step: i as u64 });
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
        let u = dist * (i + 1) as f64 / points as f64;
        let row = HistoryRow {
            time_ms: u / speed,
            displacement_mm: u,
            load_top_n: 1000.0 + 500.0 * (u * 0.5).sin(),
            ..Default::default()
        };
        observer.on_history(&row);
        observer.on_progress(&Progress {
            step: i as u64,
            time_ms: row.time_ms,
            displacement_mm: u,
            load_n: row.load_top_n,
            fraction: u / dist,
            elapsed_s: start.elapsed().as_secs_f64(),
            eta_s: 0.0,
        });
        history.push(row);
    }
    let summary = Summary {
        mean_load_n: 1000.0,
        peak_load_n: 1500.0,
        energy_absorbed_mj: 1000.0 * dist,
        crush_distance_mm: dist,
        folds: 0,
        energy_balance_error: 0.0,
        kinetic_to_internal: 0.0,
        mode: CollapseMode::Ring,
        references: Default::default(),
        cost: RunCost { particles: case.particle_count(), ..Default::default() },
    };
    Ok(RunOutput { history, summary, snapshot: Snapshot::default() })
}
