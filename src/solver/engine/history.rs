//! The run's history: one row per equal step of plate displacement. Units: ms, mm, N, mJ (= N·mm).
//!
//! Energy books, all since the start: the plates' work (`work_top_mj` + `work_bottom_mj` =
//! `external_mj`) goes to kinetic energy, internal energy (`elastic_mj` + `plastic_mj` =
//! `internal_mj`), friction (`friction_mj`) and the inelastic catch of grid nodes by a plate
//! (`contact_mj`); `residual_mj` is what is left, the numerical error of the balance.

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
    /// Work done by both plates on the tube.
    pub external_mj: f64,
    /// Energy dissipated at the plates by friction.
    pub friction_mj: f64,
    /// Elastic energy: internal energy less plastic work.
    #[serde(default)]
    pub elastic_mj: f64,
    /// Work done by the moving (top) plate.
    #[serde(default)]
    pub work_top_mj: f64,
    /// Work done by the fixed (bottom) plate (zero while it stays fixed; booked all the same).
    #[serde(default)]
    pub work_bottom_mj: f64,
    /// Energy dissipated by the contact projection's normal part: grid nodes caught by a plate.
    #[serde(default)]
    pub contact_mj: f64,
    /// external − (kinetic + internal + friction + contact): the balance's numerical error.
    #[serde(default)]
    pub residual_mj: f64,
}

impl HistoryRow {
    /// Column names, in the order of [`HistoryRow::values`]; used for CSV and the store.
    pub const COLUMNS: [&'static str; 14] = [
        "time_ms",
        "displacement_mm",
        "load_top_n",
        "load_bottom_n",
        "kinetic_mj",
        "internal_mj",
        "plastic_mj",
        "external_mj",
        "friction_mj",
        "elastic_mj",
        "work_top_mj",
        "work_bottom_mj",
        "contact_mj",
        "residual_mj",
    ];

    pub fn values(&self) -> [f64; 14] {
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
            self.elastic_mj,
            self.work_top_mj,
            self.work_bottom_mj,
            self.contact_mj,
            self.residual_mj,
        ]
    }

    /// The row whose [`HistoryRow::values`] are `v`.
    pub fn from_values(v: [f64; 14]) -> HistoryRow {
        HistoryRow {
            time_ms: v[0],
            displacement_mm: v[1],
            load_top_n: v[2],
            load_bottom_n: v[3],
            kinetic_mj: v[4],
            internal_mj: v[5],
            plastic_mj: v[6],
            external_mj: v[7],
            friction_mj: v[8],
            elastic_mj: v[9],
            work_top_mj: v[10],
            work_bottom_mj: v[11],
            contact_mj: v[12],
            residual_mj: v[13],
        }
    }

    /// Everything the plates' work went to that the books name, mJ.
    pub fn booked_mj(&self) -> f64 {
        self.kinetic_mj + self.internal_mj + self.friction_mj + self.contact_mj
    }
}
