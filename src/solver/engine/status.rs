//! What a run reports of how far it is: the [`Progress`] report sent once per history row, and
//! how far the pricing of its error bar is ([`RungProgress`]). Units: ms, mm, N, s. Imports
//! nothing of the engine; `observer.rs` (which re-exports both) and the checkpoint import it.

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
    /// While the run's error bar is priced after it (the run itself done, `fraction` 1): which
    /// rung of its ladder runs and how far that rung is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_bar: Option<RungProgress>,
}

/// How far the pricing of a run's error bar is: rung `rung` of `rungs` (from 1), at `n`
/// particles through the wall, `fraction` (0..1) of its crush done.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize, JsonSchema)]
pub struct RungProgress {
    pub rung: u32,
    pub rungs: u32,
    pub n: u32,
    pub fraction: f64,
}
