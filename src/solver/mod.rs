//! The crush solver: explicit 3D MPM of a thin-walled tube between rigid plates.
//!
//! A pure library (std, nalgebra, rayon, serde): no I/O, no async. Results leave through the
//! return value and the [`Observer`] trait. Internal units are consistent: mm, ms, g, so that
//! force is N, stress MPa, velocity m/s (= mm/ms) and energy mJ (= N·mm).

pub mod case;
pub mod checkpoint;
pub mod contact;
pub mod estimate;
pub mod folds;
pub mod grid;
pub mod history;
pub mod input;
pub mod material;
pub mod mode;
pub mod observer;
pub mod particles;
pub mod reference;
pub mod scene;
pub mod section;
pub mod shape;
pub mod step;
pub mod summary;

pub use case::{Case, CaseError, CaseSpec, FieldError, Limits};
pub use checkpoint::{Checkpoint, CheckpointError, Resume};
pub use estimate::{estimate, Estimate};
pub use history::HistoryRow;
pub use mode::{detect_mode, ModeDetail};
pub use observer::{Observer, Progress, Recorder};
pub use reference::{references, References};
pub use summary::{summarize, CollapseMode, EnergyBooks, RunCost, Summary};

/// The floating-point type of all solver state.
pub type Real = f64;

/// Everything a finished run produces.
#[derive(Debug, Clone)]
pub struct RunOutput {
    pub history: Vec<HistoryRow>,
    pub summary: Summary,
    /// The numbers behind `summary.mode`.
    pub mode_detail: ModeDetail,
    pub snapshot: Snapshot,
}

/// Final particle state, in the scene's particle order.
#[derive(Debug, Clone, Default)]
pub struct Snapshot {
    /// Positions before the crush, mm.
    pub initial_mm: Vec<[Real; 3]>,
    /// Positions at the end, mm.
    pub position_mm: Vec<[Real; 3]>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<Real>,
}

/// Why a run ended without a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    #[error("cancelled at step {step}")]
    Cancelled { step: u64 },
    /// The numbers went bad: which quantity, where and when.
    #[error("unstable at step {step} (t = {time_ms:.6} ms): {what}")]
    Unstable {
        step: u64,
        time_ms: f64,
        what: String,
    },
}

mod run;
pub use run::{resume, run, run_scene};
