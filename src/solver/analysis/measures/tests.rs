//! The measures against load curves whose answers are known.

use super::*;
use crate::solver::engine::history::HistoryRow;

fn row(u: f64, p: f64) -> HistoryRow {
    HistoryRow {
        displacement_mm: u,
        load_top_n: p,
        ..Default::default()
    }
}

/// A piecewise-linear load through `vertices`, sampled every `du` mm (from du on).
fn curve(vertices: &[(f64, f64)], du: f64) -> Vec<HistoryRow> {
    let n = (vertices.last().unwrap().0 / du).round() as usize;
    (1..=n)
        .map(|i| {
            let u = i as f64 * du;
            let k = vertices
                .windows(2)
                .position(|w| u <= w[1].0 + 1e-9)
                .unwrap();
            let ((u0, p0), (u1, p1)) = (vertices[k], vertices[k + 1]);
            row(u, p0 + (p1 - p0) * (u - u0) / (u1 - u0))
        })
        .collect()
}

/// A long axial crush: a first collapse peak of 20 kN at 1 mm, folds between 8 and 14 kN,
/// then the end compaction climbing to 60 kN. The largest load is the compaction's; the first
/// collapse peak is the first one. A sharp (triangular) peak reads low by one row's rise, as a
/// one-row spike is clipped to its neighbours: 0.6 % on 0.01 mm rows of a 1 mm ramp; 1 %
/// allowed.
const LONG_CRUSH: [(f64, f64); 9] = [
    (0.0, 0.0),
    (1.0, 20_000.0),
    (2.0, 8_000.0),
    (9.0, 14_000.0),
    (10.0, 8_000.0),
    (17.0, 14_000.0),
    (18.0, 8_000.0),
    (25.0, 14_000.0),
    (30.0, 60_000.0),
];

#[test]
fn the_first_collapse_peak_is_not_the_end_compaction() {
    let h = curve(&LONG_CRUSH, 0.01);
    let (i, p) = first_collapse_peak(&h).unwrap();
    assert!((p / 20_000.0 - 1.0).abs() < 0.01, "{p}");
    assert!(
        (h[i].displacement_mm - 1.0).abs() < 0.02,
        "{}",
        h[i].displacement_mm
    );
    let largest = h.iter().map(|r| r.load_top_n).fold(0.0, f64::max);
    assert_eq!(largest, 60_000.0);
}

/// A regression for what a plain maximum reads on a real crush: a one-row contact spike
/// (+60 % on the elastic ramp, before the collapse) is not the first collapse peak.
#[test]
fn a_one_row_contact_spike_is_not_the_first_collapse_peak() {
    let mut h = curve(&LONG_CRUSH, 0.01);
    h[50].load_top_n = 16_000.0; // at 0.51 mm, where the ramp is at 10.2 kN
    h[99].load_top_n = 32_000.0; // beside the true peak
    let (_, p) = first_collapse_peak(&h).unwrap();
    assert!((p / 20_000.0 - 1.0).abs() < 0.01, "{p}");
}

#[test]
fn a_load_that_never_drops_has_no_first_peak() {
    let h = curve(&[(0.0, 0.0), (5.0, 1000.0), (12.0, 3000.0)], 0.01);
    assert_eq!(first_collapse_peak(&h), None);
    let m = Measures::of(&CaseSpec::default(), &h, 1500.0, &EnergyBooks::default());
    assert_eq!(
        (
            m.first_peak_load_n,
            m.mean_load_after_first_peak_n,
            m.crush_force_efficiency
        ),
        (None, None, None)
    );
}

/// The mean load after the first peak is the energy after it over the travel after it; the
/// crush-force efficiency is the whole crush's mean over the first peak; mass and SEA of the
/// paper's PVC tube (ρ 1380 kg/m³, d 22.2, t 3.2, l 76.2 mm: 23.47 g); the dissipated energy
/// is plastic plus friction.
#[test]
fn mean_after_the_peak_efficiency_mass_and_sea() {
    let h = curve(&LONG_CRUSH[..8], 0.01);
    let (i, peak) = first_collapse_peak(&h).unwrap();
    let energy = running_energy(&h);
    let end = h.last().unwrap().displacement_mm;
    let total = *energy.last().unwrap();
    let books = EnergyBooks {
        plastic_mj: 200.0,
        friction_mj: 30.0,
        ..Default::default()
    };
    let m = Measures::of(&CaseSpec::default(), &h, total / end, &books);
    let after = (total - energy[i]) / (end - h[i].displacement_mm);
    assert_eq!(m.mean_load_after_first_peak_n, Some(after));
    // The teeth between 8 and 14 kN after the peak: their mean is 11 kN, the drop from the
    // peak to the first trough (20 → 8 kN over 1 mm) adds 1/24 of (14 − 11) kN.
    assert!((after / 11_125.0 - 1.0).abs() < 0.003, "{after}");
    assert_eq!(m.crush_force_efficiency, Some(total / end / peak));
    let mass = 1380.0 * std::f64::consts::PI * 22.2 * 3.2 * 76.2 * 1e-6;
    assert!(
        (m.tube_mass_g - mass).abs() < 1e-12 && (mass - 23.47).abs() < 0.01,
        "{mass}"
    );
    assert_eq!(m.specific_energy_absorption_j_per_g, total * 1e-3 / mass);
    assert_eq!(m.energy_dissipated_mj, 230.0);
}
