//! The run's history: one row per equal step of plate displacement. Units: ms, mm, N, mJ (= N·mm).

use serde::{Deserialize, Serialize};

/// The state of the run at one plate displacement.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct HistoryRow {
    pub time_ms: f64,
    /// Travel of the moving (top) plate, mm.
    pub displacement_mm: f64,
    /// Force of the tube on the moving plate, N (positive in compression).
    pub load_top_n: f64,
    /// Force of the tube on the fixed plate, N (positive in compression).
    pub load_bottom_n: f64,
    pub kinetic_mj: f64,
    /// Elastic energy plus plastic work.
    pub internal_mj: f64,
    pub plastic_mj: f64,
    /// Work done by the moving plate on the tube.
    pub external_mj: f64,
    /// Energy dissipated at the plates by friction.
    pub friction_mj: f64,
}

impl HistoryRow {
    /// Column names, in the order of [`HistoryRow::values`]; used for CSV.
    pub const COLUMNS: [&'static str; 9] = [
        "time_ms",
        "displacement_mm",
        "load_top_n",
        "load_bottom_n",
        "kinetic_mj",
        "internal_mj",
        "plastic_mj",
        "external_mj",
        "friction_mj",
    ];

    pub fn values(&self) -> [f64; 9] {
        [
            self.time_ms,
            self.displacement_mm,
            self.load_top_n,
            self.load_bottom_n,
            self.kinetic_mj,
            self.internal_mj,
            self.plastic_mj,
            self.external_mj,
            self.friction_mj,
        ]
    }
}
