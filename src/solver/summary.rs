//! A finished run in a few numbers: mean collapse load, peak, energy absorbed, folds, energy
//! balance, collapse mode, the closed-form references and the run's cost. Units: N, mm, mJ, s.

use super::history::HistoryRow;
use super::reference::References;
use super::{Case, Snapshot};
use serde::{Deserialize, Serialize};

/// How the tube collapsed, judged from its final shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CollapseMode {
    /// Axisymmetric concertina folds.
    Ring,
    /// Non-axisymmetric folds with this many lobes around the circumference.
    Diamond { lobes: u32 },
    /// The whole column bowed sideways (Euler buckling).
    GlobalBuckling,
    /// Lateral loading: the tube was flattened across a diameter.
    Flattening,
}

/// What the run cost.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RunCost {
    pub particles: u64,
    /// Most grid cells active at once.
    pub active_cells_max: u64,
    pub steps: u64,
    pub dt_min_ms: f64,
    pub dt_max_ms: f64,
    pub wall_time_s: f64,
    pub particle_steps_per_s: f64,
    pub threads: u32,
    /// Mean distance between a plate and the nearest particle's edge while in contact, mm.
    pub contact_gap_mm: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// P̄ = TEA / crush distance.
    pub mean_load_n: f64,
    pub peak_load_n: f64,
    /// TEA = ∫ P du by the trapezoid rule over the history.
    pub energy_absorbed_mj: f64,
    pub crush_distance_mm: f64,
    /// Number of significant load drops.
    pub folds: u32,
    /// |W_ext − (E_kin + E_int + W_fric)| / max(W_ext, E_int) over the run.
    pub energy_balance_error: f64,
    /// Largest E_kin / E_int over the second half of the crush (quasi-static check).
    pub kinetic_to_internal: f64,
    pub mode: CollapseMode,
    pub references: References,
    pub cost: RunCost,
}

/// TEMPORARY minimal summary until the post-processing lands.
pub fn summarize(case: &Case, history: &[HistoryRow], _snapshot: &Snapshot, cost: RunCost) -> Summary {
    let mut tea = 0.0;
    let (mut u0, mut p0) = (0.0, 0.0);
    for r in history {
        tea += 0.5 * (p0 + r.load_top_n) * (r.displacement_mm - u0);
        u0 = r.displacement_mm;
        p0 = r.load_top_n;
    }
    let last = history.last().copied().unwrap_or_default();
    let err = (last.external_mj - (last.kinetic_mj + last.internal_mj + last.friction_mj)).abs()
        / last.external_mj.max(last.internal_mj).max(1e-30);
    Summary {
        mean_load_n: tea / u0.max(1e-30),
        peak_load_n: history.iter().map(|r| r.load_top_n).fold(0.0, f64::max),
        energy_absorbed_mj: tea,
        crush_distance_mm: case.crush_distance_mm(),
        folds: 0,
        energy_balance_error: err,
        kinetic_to_internal: last.kinetic_mj / last.internal_mj.max(1e-30),
        mode: CollapseMode::Ring,
        references: Default::default(),
        cost,
    }
}
