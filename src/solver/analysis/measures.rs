//! The measures a crash engineer reads off a crush: the tube's mass, the specific energy
//! absorption, the first collapse peak (apart from the largest load, which on a long axial
//! crush is the end compaction), the mean load after it, the crush-force efficiency and the
//! energy the wall dissipated. Units: g, J/g, N, mm, mJ.

use super::curve::{load_drops, running_energy, EnergyBooks};
use crate::solver::engine::history::HistoryRow;
use crate::solver::model::case::{CrossSection, Outline};
use crate::solver::model::spec::CaseSpec;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The crash measures of a run (in the summary beside its mean and peak loads).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Measures {
    /// The tube's mass, g: ρ times the wall's volume π d t l (d the mean diameter).
    pub tube_mass_g: f64,
    /// Specific energy absorption at the crush distance, J/g: the energy absorbed (the moving
    /// plate's ∫ P du) over the tube's mass.
    pub specific_energy_absorption_j_per_g: f64,
    /// The first collapse peak, N: the highest load before the first significant load drop
    /// ([`super::curve::count_load_drops`]'s rule), a single-row contact spike clipped to its
    /// neighbours. `None` where the load never drops (a lateral flattening, a crush that ends
    /// before the first fold).
    pub first_peak_load_n: Option<f64>,
    /// Where the first collapse peak was, mm of plate travel.
    pub first_peak_displacement_mm: Option<f64>,
    /// The mean load from the first collapse peak to the end, N: the energy absorbed after it
    /// over the travel after it.
    pub mean_load_after_first_peak_n: Option<f64>,
    /// Crush-force efficiency: the mean load over the whole crush over the first collapse peak.
    pub crush_force_efficiency: Option<f64>,
    /// The energy the wall dissipated, mJ: plastic work plus friction at the plates (the rest
    /// of the plates' work is kinetic and elastic energy, the contact's catch and the residual).
    pub energy_dissipated_mj: f64,
    /// The case's mass scaling and the mass it adds; absent from a run without it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_scaling: Option<MassScaling>,
}

/// A mass-scaled run's scaling: the density's factor in the equations of motion, and the
/// mass that adds to the tube's there (every particle alike, since the lattice is uniform).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct MassScaling {
    /// f, the case's `discretization.mass_scaling`.
    pub factor: f64,
    /// (f − 1) times the tube's mass, g.
    pub added_mass_g: f64,
}

impl Measures {
    /// The measures of a run of `spec` with this load history, mean load (N) and energy books.
    pub fn of(
        spec: &CaseSpec,
        history: &[HistoryRow],
        mean_load_n: f64,
        books: &EnergyBooks,
    ) -> Measures {
        let tube_mass_g = tube_mass_g(spec);
        let absorbed_mj = running_energy(history).last().copied().unwrap_or(0.0);
        let first = first_collapse_peak(history);
        let after = first.and_then(|(i, _)| mean_load_after(history, i));
        Measures {
            tube_mass_g,
            specific_energy_absorption_j_per_g: if tube_mass_g > 0.0 {
                absorbed_mj * 1e-3 / tube_mass_g
            } else {
                0.0
            },
            first_peak_load_n: first.map(|(_, p)| p),
            first_peak_displacement_mm: first.map(|(i, _)| history[i].displacement_mm),
            mean_load_after_first_peak_n: after,
            crush_force_efficiency: first.and_then(|(_, p)| (p > 0.0).then_some(mean_load_n / p)),
            energy_dissipated_mj: books.plastic_mj + books.friction_mj,
            mass_scaling: {
                let factor = spec.discretization.mass_scaling;
                (factor != 1.0).then_some(MassScaling {
                    factor,
                    added_mass_g: (factor - 1.0) * tube_mass_g,
                })
            },
        }
    }
}

/// ρ A l, g, with the wall's cross-section area A (π d t for a round tube, t times the
/// mid-line's length for a polygon; ρ in kg/m³ and the volume in mm³:
/// 1 kg/m³ · 1 mm³ = 1e-6 g).
pub fn tube_mass_g(spec: &CaseSpec) -> f64 {
    let area_mm2 = CrossSection::of(&spec.tube).area_mm2();
    spec.material.density_kg_m3 * area_mm2 * spec.tube.length_mm * 1e-6
}

/// The first collapse peak: its row and load. The load is read through the running median
/// that the drop counter reads, the first drop's peak is the highest median load before the
/// drop was confirmed, and the peak's load is the highest raw load near it (within the
/// median's window) that one of its neighbours also reaches, so that a one-row contact spike
/// is not taken for the collapse. `None` where the load never drops.
pub fn first_collapse_peak(history: &[HistoryRow]) -> Option<(usize, f64)> {
    let (smooth, drops) = load_drops(history);
    let confirmed = *drops.first()?;
    let top = (0..=confirmed).max_by(|&a, &b| smooth[a].total_cmp(&smooth[b]))?;
    let half = (history.len() / 200).max(2);
    let load = |i: usize| history[i].load_top_n;
    let held = |i: usize| {
        let left = if i > 0 { load(i - 1) } else { f64::MIN };
        let right = history.get(i + 1).map_or(f64::MIN, |r| r.load_top_n);
        load(i).min(left.max(right))
    };
    (top.saturating_sub(half)..=(top + half).min(history.len() - 1))
        .map(|i| (i, held(i)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// (TEA(end) − TEA(row)) / (u(end) − u(row)), N; `None` where no travel is left after `row`.
fn mean_load_after(history: &[HistoryRow], row: usize) -> Option<f64> {
    let energy = running_energy(history);
    let (last, end) = (history.last()?, *energy.last()?);
    let travel = last.displacement_mm - history[row].displacement_mm;
    (travel > 0.0).then(|| (end - energy[row]) / travel)
}

#[cfg(test)]
mod tests;
