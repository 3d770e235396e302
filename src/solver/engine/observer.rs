//! How a run reports while it goes: the [`Observer`] trait. The solver calls it on its own
//! thread between steps; `()` ignores everything.

use crate::solver::engine::checkpoint::Checkpoint;
use crate::solver::engine::history::HistoryRow;
use schemars::JsonSchema;

/// A progress report, sent once per history row.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize, JsonSchema)]
pub struct Progress {
    pub step: u64,
    /// Simulated time, ms.
    pub time_ms: f64,
    /// Top-plate travel, mm.
    pub displacement_mm: f64,
    /// Force of the tube on the moving plate, N.
    pub load_n: f64,
    /// Share of the crush distance done, 0..1.
    pub fraction: f64,
    /// Wall time since the run started, s.
    pub elapsed_s: f64,
    /// Wall time still expected at the current pace, s.
    pub eta_s: f64,
}

/// Receives a run's progress and, when it asks for them, its checkpoints. Every method
/// defaults to doing nothing (and asking for nothing).
pub trait Observer {
    fn on_progress(&mut self, _progress: &Progress) {}
    fn on_history(&mut self, _row: &HistoryRow) {}
    /// Asked before every step: whether to hand over a checkpoint now (through
    /// [`Observer::on_checkpoint`]). Called once a step, so it must be cheap.
    fn wants_checkpoint(&mut self) -> bool {
        false
    }
    /// Asked when the run sees its cancel flag: whether to hand over a checkpoint before it
    /// stops (a shutdown that will resume the run elsewhere, not a client's cancel).
    fn checkpoint_on_stop(&mut self) -> bool {
        false
    }
    /// A checkpoint of the run at the current step boundary.
    fn on_checkpoint(&mut self, _checkpoint: Checkpoint) {}
}

impl Observer for () {}

/// Collects everything it is told; handy in tests.
#[derive(Debug, Default)]
pub struct Recorder {
    pub progress: Vec<Progress>,
    pub rows: Vec<HistoryRow>,
}

impl Observer for Recorder {
    fn on_progress(&mut self, p: &Progress) {
        self.progress.push(*p);
    }
    fn on_history(&mut self, row: &HistoryRow) {
        self.rows.push(*row);
    }
}
