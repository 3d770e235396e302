//! A load history read as curves: the energy absorbed as the plate travels, the load's
//! significant drops, how far the energy books close, how long the plate went unloaded, and the
//! books at a row. Units: N, mm, mJ.
//!
//! A leaf of the analysis: imports the engine's history row and the peak detector alone.

use super::peaks::Peaks;
use crate::solver::engine::history::HistoryRow;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The energy books at the end of a run, mJ: the plates' work went to the other terms but the
/// residual, which is the balance's numerical error (`external − booked`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct EnergyBooks {
    pub work_top_mj: f64,
    pub work_bottom_mj: f64,
    pub kinetic_mj: f64,
    pub elastic_mj: f64,
    pub plastic_mj: f64,
    pub friction_mj: f64,
    /// Dissipated by the contact projection: grid nodes caught by a plate.
    pub contact_mj: f64,
    pub residual_mj: f64,
}

impl EnergyBooks {
    /// The books of a history row.
    pub fn of(r: &HistoryRow) -> EnergyBooks {
        EnergyBooks {
            work_top_mj: r.work_top_mj,
            work_bottom_mj: r.work_bottom_mj,
            kinetic_mj: r.kinetic_mj,
            elastic_mj: r.internal_mj - r.plastic_mj,
            plastic_mj: r.plastic_mj,
            friction_mj: r.friction_mj,
            contact_mj: r.contact_mj,
            residual_mj: r.external_mj - r.booked_mj(),
        }
    }
}

/// A load drop counts when it reaches this fraction of the running mean load.
pub const LOAD_DROP_FRACTION: f64 = 0.15;

/// The load on the moving plate below which it counts as unloaded, as a share of the peak load.
pub const UNLOADED_FRACTION: f64 = 0.01;

/// Rows whose external work is below this share of its final value are left out of the energy
/// balance error (dividing by almost nothing says nothing).
pub const ENERGY_BALANCE_FROM: f64 = 0.01;

/// TEA = Σ (P_{i−1} + P_i)/2 · Δu over the history, starting from (u = 0, P = 0), mJ.
pub fn energy_absorbed(history: &[HistoryRow]) -> f64 {
    running_energy(history).last().copied().unwrap_or(0.0)
}

/// TEA up to and including each row.
pub fn running_energy(history: &[HistoryRow]) -> Vec<f64> {
    let (mut u, mut p, mut e) = (0.0, 0.0, 0.0);
    history
        .iter()
        .map(|r| {
            e += 0.5 * (p + r.load_top_n) * (r.displacement_mm - u);
            (u, p) = (r.displacement_mm, r.load_top_n);
            e
        })
        .collect()
}

/// Number of significant load drops, by a peak detector with hysteresis.
///
/// The rule: walking along the history, the detector is either *rising* (tracking the highest
/// load since the last trough) or *falling* (tracking the lowest load since the last peak). A
/// drop is counted when, while rising, the load falls below the tracked peak by at least
/// [`LOAD_DROP_FRACTION`] of the current reference load; the detector then falls until the load
/// climbs the same margin above the tracked trough. The reference load is the running mean
/// TEA(u)/u, floored at half the final mean so that noise in the first rows of the elastic ramp,
/// where the running mean is still near zero, cannot count. A drop still in progress at the end of
/// the history counts once it reaches the margin; a final rise without a drop does not.
///
/// The load is first passed through a short running median (see `median_filtered`), so that
/// one- or two-row contact spikes are not counted as drops.
pub fn count_load_drops(history: &[HistoryRow]) -> u32 {
    load_drops(history).1.len() as u32
}

/// The load on the moving plate through the running median (see [`count_load_drops`]), and
/// the rows at which each significant drop was confirmed (the load had fallen the margin below
/// the peak before it), in order.
pub fn load_drops(history: &[HistoryRow]) -> (Vec<f64>, Vec<usize>) {
    let energy = running_energy(history);
    let final_mean = match history.last() {
        Some(r) if r.displacement_mm > 0.0 => energy[energy.len() - 1] / r.displacement_mm,
        _ => return (vec![], vec![]),
    };
    let smooth = median_filtered(history);
    let mut drops = Peaks::falls();
    let mut confirmed = vec![];
    for (i, ((r, e), &p)) in history.iter().zip(&energy).zip(&smooth).enumerate() {
        let running = if r.displacement_mm > 0.0 {
            e / r.displacement_mm
        } else {
            0.0
        };
        let margin = LOAD_DROP_FRACTION * running.max(0.5 * final_mean);
        let before = drops.count();
        drops.push(p, margin, f64::MIN);
        if drops.count() > before {
            confirmed.push(i);
        }
    }
    (smooth, confirmed)
}

/// The load on the moving plate through a running median over ±max(2, rows/200) rows: a fold
/// spans tens of rows, while contact noise makes one- or two-row spikes that are no folds.
fn median_filtered(history: &[HistoryRow]) -> Vec<f64> {
    let half = (history.len() / 200).max(2);
    let loads: Vec<f64> = history.iter().map(|r| r.load_top_n).collect();
    (0..loads.len())
        .map(|i| {
            let mut w = loads[i.saturating_sub(half)..(i + half + 1).min(loads.len())].to_vec();
            w.sort_by(f64::total_cmp);
            w[w.len() / 2]
        })
        .collect()
}

/// max |W_ext − (E_kin + E_int + W_fric + W_contact)| / max(W_ext, E_int) over the rows where
/// W_ext has reached [`ENERGY_BALANCE_FROM`] of its final value; 0 when no external work was
/// done.
pub fn energy_balance_error(history: &[HistoryRow]) -> f64 {
    let final_work = history.last().map_or(0.0, |r| r.external_mj);
    if final_work <= 0.0 {
        return 0.0;
    }
    history
        .iter()
        .filter(|r| r.external_mj >= ENERGY_BALANCE_FROM * final_work)
        .map(|r| {
            let gap = r.external_mj - r.booked_mj();
            gap.abs() / r.external_mj.max(r.internal_mj)
        })
        .fold(0.0, f64::max)
}

/// The longest stretch of plate travel between two history rows whose load on the moving plate,
/// and that of every row between them, is below [`UNLOADED_FRACTION`] of the peak load, mm; 0
/// when no two consecutive rows are unloaded.
pub fn longest_unloaded_mm(history: &[HistoryRow]) -> f64 {
    let peak = history.iter().map(|r| r.load_top_n).fold(0.0, f64::max);
    let (mut longest, mut since) = (0.0, None);
    for r in history {
        if r.load_top_n < UNLOADED_FRACTION * peak {
            let start = *since.get_or_insert(r.displacement_mm);
            longest = f64::max(longest, r.displacement_mm - start);
        } else {
            since = None;
        }
    }
    longest
}

/// Largest E_kin / E_int over the second half of the crush (rows with E_int > 0).
pub fn kinetic_to_internal(history: &[HistoryRow]) -> f64 {
    let half = 0.5 * history.last().map_or(0.0, |r| r.displacement_mm);
    history
        .iter()
        .filter(|r| r.displacement_mm >= half && r.internal_mj > 0.0)
        .map(|r| r.kinetic_mj / r.internal_mj)
        .fold(0.0, f64::max)
}
