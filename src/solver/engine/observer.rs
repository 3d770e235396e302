//! How a run reports while it goes: the [`Observer`] trait. The solver calls it on its own
//! thread between steps; `()` ignores everything. Units: mm, ms, m/s, MPa, mm³.

use crate::solver::engine::checkpoint::Checkpoint;
use crate::solver::engine::history::HistoryRow;
use crate::solver::Real;

pub use super::status::{Progress, RungProgress};

/// Every particle's state at one frame of a time series (`output.frames`), in the case's
/// particle order and the frame of the scene (`Geometry::reported`). In the reduced models a
/// particle stands for its ring (axisymmetric) or the tube's length (plane strain), and its
/// volume is that of what it stands for.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Which frame, 0 (the start) to `count - 1` (the end of the crush).
    pub index: u32,
    pub count: u32,
    /// Simulated time, ms.
    pub time_ms: Real,
    /// Top-plate travel, mm.
    pub travel_mm: Real,
    pub position_mm: Vec<[Real; 3]>,
    pub velocity_m_s: Vec<[Real; 3]>,
    /// Cauchy stress, Voigt order xx, yy, zz, yz, xz, xy, MPa.
    pub stress_mpa: Vec<[Real; 6]>,
    pub volume_mm3: Vec<Real>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<Real>,
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
    /// Asked once the run has reached the end of its crush, before it is analysed: whether to
    /// hand over a checkpoint of the finished run (the worker keeps one while it prices the
    /// run's error bar, so that an interruption then does not run the crush again). Not asked
    /// of a run resumed from such a checkpoint, which took no step.
    fn checkpoint_at_end(&mut self) -> bool {
        false
    }
    /// A checkpoint of the run at the current step boundary.
    fn on_checkpoint(&mut self, _checkpoint: Checkpoint) {}
    /// Whether to build the frames of a case that asks for a series (`output.frames`); the run
    /// is the same either way.
    fn wants_frames(&self) -> bool {
        false
    }
    /// One frame of the series, in order; a run continued from a checkpoint sends the frames
    /// after it.
    fn on_frame(&mut self, _frame: &Frame) {}
}

impl Observer for () {}

/// Collects everything it is told; handy in tests.
#[derive(Debug, Default)]
pub struct Recorder {
    pub progress: Vec<Progress>,
    pub rows: Vec<HistoryRow>,
    pub frames: Vec<Frame>,
}

impl Observer for Recorder {
    fn on_progress(&mut self, p: &Progress) {
        self.progress.push(*p);
    }
    fn on_history(&mut self, row: &HistoryRow) {
        self.rows.push(*row);
    }
    fn wants_frames(&self) -> bool {
        true
    }
    fn on_frame(&mut self, frame: &Frame) {
        self.frames.push(frame.clone());
    }
}
