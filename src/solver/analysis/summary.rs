//! A finished run in a few numbers: mean collapse load, peak, energy absorbed, folds, energy
//! balance, collapse mode, the closed-form references and the run's cost. Units: N, mm, mJ, s.

use super::curve::{
    count_load_drops, energy_absorbed, energy_balance_error, kinetic_to_internal,
    longest_unloaded_mm, EnergyBooks,
};
use super::error_bar::{ErrorBar, Rung};
use super::expected::{self, ExpectedError};
use super::folds::count_folds;
use super::measures::Measures;
use super::mode::{detect_mode, CollapseMode, ModeDetail};
use super::reference::{references, References};
use super::verdict::{self, RunFigures, Verdict};
use crate::solver::engine::history::HistoryRow;
use crate::solver::engine::{RunCost, Snapshot};
use crate::solver::model::case::{Case, LoadingMode, ShapeChoice};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Summary {
    /// P̄ = TEA / crush distance.
    pub mean_load_n: f64,
    /// The largest load on the moving plate over the whole crush. On a long axial crush this is
    /// the end compaction, not the first collapse: that is `first_peak_load_n`.
    pub peak_load_n: f64,
    /// TEA = ∫ P du by the trapezoid rule over the history.
    pub energy_absorbed_mj: f64,
    pub crush_distance_mm: f64,
    /// Folds of the wall, counted from the final shape as in the sections (axial loading; 0 for
    /// lateral flattening, which does not fold). See [`super::folds`].
    pub folds: u32,
    /// Significant drops of the load on the moving plate (axial loading; 0 for lateral). In the
    /// diamond modes each lobe's peak shows here, about twice the folds.
    pub load_drops: u32,
    /// |W_ext − (E_kin + E_int + W_fric + W_contact)| / max(W_ext, E_int), the largest over
    /// the run (see [`energy_balance_error`]).
    pub energy_balance_error: f64,
    /// Every term of the energy balance at the end of the run.
    pub energy: EnergyBooks,
    /// Mass, specific energy absorption, first collapse peak, mean load after it, crush-force
    /// efficiency, energy dissipated ([`Measures`]).
    #[serde(flatten)]
    pub measures: Measures,
    /// Largest E_kin / E_int over the second half of the crush (quasi-static check).
    pub kinetic_to_internal: f64,
    /// The longest stretch of plate travel over which the load on the moving plate stayed
    /// below `UNLOADED_FRACTION` of the peak load: the tube lost its hold on the plate (it
    /// tipped over, or floats between the plates), mm. See [`longest_unloaded_mm`].
    pub longest_unloaded_mm: f64,
    pub mode: CollapseMode,
    pub references: References,
    pub cost: RunCost,
    /// The shape functions the run used, and why when the case left them to the default.
    pub shape: ShapeChoice,
    /// How far to trust the result, with every reason ([`super::verdict`]).
    pub verdict: Verdict,
    /// The mean load's error bar ([`super::error_bar`]), when the caller priced it; absent
    /// when it was not asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_bar: Option<ErrorBar>,
    /// The error the mean load is expected to carry, from the convergence studies measured
    /// near this case, or why none guides it ([`super::expected`]): a guide at no cost, beside
    /// the priced error bar.
    pub expected_error: ExpectedError,
}

impl Summary {
    /// The figures of the run that its verdict reads.
    pub fn verdict_figures(&self) -> RunFigures {
        RunFigures {
            mode: self.mode,
            longest_unloaded_mm: self.longest_unloaded_mm,
            energy_balance_error: self.energy_balance_error,
            kinetic_to_internal: self.kinetic_to_internal,
        }
    }

    /// The run as the rung at `n` of its error bar's ladder: its mean load, first collapse
    /// peak and wall time.
    pub fn rung(&self, n: u32) -> Rung {
        Rung {
            n,
            mean_load_n: self.mean_load_n,
            first_peak_load_n: self.measures.first_peak_load_n,
            wall_time_s: self.cost.wall_time_s,
        }
    }
}

/// The summary of a finished run, from its history (load on the moving plate) and final shape,
/// and the numbers behind its collapse mode.
pub fn summarize(
    case: &Case,
    history: &[HistoryRow],
    snapshot: &Snapshot,
    cost: RunCost,
) -> (Summary, ModeDetail) {
    let (mode, mode_detail) = detect_mode(case, snapshot);
    let energy_absorbed_mj = energy_absorbed(history);
    let crush_distance_mm = history.last().map_or(0.0, |r| r.displacement_mm);
    let mean_load_n = if crush_distance_mm > 0.0 {
        energy_absorbed_mj / crush_distance_mm
    } else {
        0.0
    };
    let energy = history.last().map(EnergyBooks::of).unwrap_or_default();
    let figures = RunFigures {
        mode,
        longest_unloaded_mm: longest_unloaded_mm(history),
        energy_balance_error: energy_balance_error(history),
        kinetic_to_internal: kinetic_to_internal(history),
    };
    let summary = Summary {
        mean_load_n,
        peak_load_n: history.iter().map(|r| r.load_top_n).fold(0.0, f64::max),
        energy_absorbed_mj,
        crush_distance_mm,
        folds: count_folds(case, snapshot),
        load_drops: match case.spec().loading.mode {
            LoadingMode::Axial => count_load_drops(history),
            LoadingMode::Lateral => 0,
        },
        energy_balance_error: figures.energy_balance_error,
        energy,
        measures: Measures::of(case.spec(), history, mean_load_n, &energy),
        kinetic_to_internal: figures.kinetic_to_internal,
        longest_unloaded_mm: figures.longest_unloaded_mm,
        mode,
        references: references(case),
        cost,
        shape: case.shape_choice().clone(),
        verdict: verdict::of_run(case, &figures, &mode_detail),
        error_bar: None,
        expected_error: expected::of_case(case),
    };
    (summary, mode_detail)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Limits;

    #[test]
    fn a_mode_s_kind_is_its_json_tag() {
        for mode in [
            CollapseMode::Ring,
            CollapseMode::Diamond { lobes: 3 },
            CollapseMode::GlobalBuckling,
            CollapseMode::Flattening,
            CollapseMode::TippedOver,
        ] {
            let json = serde_json::to_value(mode).unwrap();
            assert_eq!(json["kind"], mode.kind(), "{mode:?}");
        }
    }

    fn row(u: f64, p: f64) -> HistoryRow {
        HistoryRow {
            displacement_mm: u,
            load_top_n: p,
            ..Default::default()
        }
    }

    /// Samples a piecewise-linear load curve through `vertices` every `du` mm (from du on).
    fn curve(vertices: &[(f64, f64)], du: f64, noise: f64) -> Vec<HistoryRow> {
        let end = vertices.last().unwrap().0;
        let n = (end / du).round() as usize;
        let mut seed: u64 = 12345;
        (1..=n)
            .map(|i| {
                let u = i as f64 * du;
                let k = vertices
                    .windows(2)
                    .position(|w| u <= w[1].0 + 1e-9)
                    .unwrap();
                let ((u0, p0), (u1, p1)) = (vertices[k], vertices[k + 1]);
                // Deterministic uniform noise in [−noise, noise] (an LCG).
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let r = (seed >> 11) as f64 / (1u64 << 53) as f64;
                row(
                    u,
                    p0 + (p1 - p0) * (u - u0) / (u1 - u0) + noise * (2.0 * r - 1.0),
                )
            })
            .collect()
    }

    /// Initial peak of 2 kN, then three teeth 800 → 1400 N: four drops of 600–1200 N, then a
    /// final rise to 1100 N with no drop after it.
    const TEETH: [(f64, f64); 10] = [
        (0.0, 0.0),
        (1.0, 2000.0),
        (2.0, 800.0),
        (9.0, 1400.0),
        (10.0, 800.0),
        (17.0, 1400.0),
        (18.0, 800.0),
        (25.0, 1400.0),
        (26.0, 800.0),
        (30.0, 1100.0),
    ];

    #[test]
    fn tea_and_mean_of_a_constant_load() {
        // P = 1000 N at u = 1..10: the first interval is (0 + 1000)/2 · 1 = 500, then 9 · 1000.
        let h: Vec<_> = (1..=10).map(|i| row(i as f64, 1000.0)).collect();
        let (s, _) = summarize(&case("{}"), &h, &Snapshot::default(), RunCost::default());
        assert_eq!(s.energy_absorbed_mj, 9500.0);
        assert_eq!(s.crush_distance_mm, 10.0);
        assert_eq!(s.mean_load_n, 950.0);
        assert_eq!(s.peak_load_n, 1000.0);
        assert_eq!(s.folds, 0);
    }

    #[test]
    fn tea_of_a_linear_load_is_exact() {
        // P = 100 u: ∫₀¹⁰ = 50 · 10² = 5000 mJ; the trapezoid rule is exact for a line.
        let h: Vec<_> = (1..=7)
            .map(|i| row(i as f64 * 10.0 / 7.0, 100.0 * i as f64 * 10.0 / 7.0))
            .collect();
        assert!((energy_absorbed(&h) - 5000.0).abs() < 1e-9);
        assert_eq!(energy_absorbed(&[]), 0.0);
    }

    /// What it measures: the tube of the t = 1.27, d = 10 example tipped over and the load fell
    /// to zero from 15 mm of crush on, with brief touches; the longest stretch without load runs
    /// from the first unloaded row after a touch to the last one before the next.
    #[test]
    fn a_load_that_falls_to_zero_shows_its_longest_unloaded_stretch() {
        let mut h = curve(&[(0.0, 0.0), (1.0, 2000.0), (15.0, 1500.0)], 0.1, 50.0);
        // Unloaded from 15.1 to 26 (10.9 mm), a touch of 300 N at 26.1–27, unloaded again from
        // 27.1 to 41 (13.9 mm).
        h.extend((151..=410).map(|i| {
            let u = i as f64 * 0.1;
            row(u, if (261..=270).contains(&i) { 300.0 } else { 0.0 })
        }));
        assert!(
            (longest_unloaded_mm(&h) - 13.9).abs() < 1e-9,
            "{}",
            longest_unloaded_mm(&h)
        );
        // A load that never falls below 1 % of its peak has none, nor has an empty history.
        assert_eq!(longest_unloaded_mm(&curve(&TEETH, 0.1, 5.0)), 0.0);
        assert_eq!(longest_unloaded_mm(&[]), 0.0);
    }

    #[test]
    fn saw_tooth_load_drops_are_counted() {
        assert_eq!(count_load_drops(&curve(&TEETH, 0.1, 0.0)), 4);
        // Five equal teeth 1000 → 1495 N, each ending in a drop; the last drop falls on the last
        // row alone, which the median cannot tell from a spike, so four are counted.
        let h: Vec<_> = (1..=500)
            .map(|i| row(i as f64 * 0.1, 1000.0 + 5.0 * (i % 100) as f64))
            .collect();
        assert_eq!(count_load_drops(&h), 4);
        let longer: Vec<_> = (1..=510)
            .map(|i| row(i as f64 * 0.1, 1000.0 + 5.0 * (i % 100) as f64))
            .collect();
        assert_eq!(count_load_drops(&longer), 5);
    }

    #[test]
    fn noise_does_not_add_load_drops() {
        // ±60 N noise (5 % of the ~1.2 kN mean) on the teeth: still four drops.
        assert_eq!(count_load_drops(&curve(&TEETH, 0.05, 60.0)), 4);
        // Noise alone on a plateau: the 15 % margin (≈ 150 N) exceeds its 120 N peak-to-peak.
        assert_eq!(
            count_load_drops(&curve(&[(0.0, 1000.0), (30.0, 1000.0)], 0.05, 60.0)),
            0
        );
        // A dip of 8 % of the mean on the way up is a wiggle, not a fold.
        let wiggle = [
            (0.0, 1000.0),
            (5.0, 1300.0),
            (5.5, 1200.0),
            (10.0, 1500.0),
            (11.0, 900.0),
        ];
        assert_eq!(count_load_drops(&curve(&wiggle, 0.1, 0.0)), 1);
    }

    #[test]
    fn energy_balance_error_skips_the_start() {
        let e = |u: f64, ext: f64, kin: f64, int: f64, fric: f64| HistoryRow {
            displacement_mm: u,
            external_mj: ext,
            kinetic_mj: kin,
            internal_mj: int,
            friction_mj: fric,
            ..Default::default()
        };
        let h = [
            // W_ext = 0.5 < 1 % of 100: left out although its balance is 100 % off.
            e(0.1, 0.5, 0.0, 0.0, 0.0),
            // |50 − 48| / 50 = 0.04.
            e(1.0, 50.0, 2.0, 45.0, 1.0),
            // |100 − (3 + 90 + 2)| / 100 = 0.05.
            e(2.0, 100.0, 3.0, 90.0, 2.0),
        ];
        assert!((energy_balance_error(&h) - 0.05).abs() < 1e-12);
        // Internal energy above the work done: divide by E_int. |10 − 12.5| / 12.5 = 0.2.
        assert!((energy_balance_error(&[e(1.0, 10.0, 0.0, 12.5, 0.0)]) - 0.2).abs() < 1e-12);
        assert_eq!(energy_balance_error(&[]), 0.0);
    }

    #[test]
    fn kinetic_ratio_looks_at_the_second_half_only() {
        let e = |u: f64, kin: f64, int: f64| HistoryRow {
            displacement_mm: u,
            kinetic_mj: kin,
            internal_mj: int,
            ..Default::default()
        };
        // The first-half ratio 5 is ignored; the second half has 2/40 = 0.05 and 3/100 = 0.03.
        let h = [
            e(1.0, 5.0, 1.0),
            e(4.0, 1.0, 20.0),
            e(5.0, 2.0, 40.0),
            e(10.0, 3.0, 100.0),
        ];
        assert!((kinetic_to_internal(&h) - 0.05).abs() < 1e-12);
    }

    #[test]
    fn summary_carries_mode_and_references() {
        let lateral = case(r#"{"loading": {"mode": "lateral"}}"#);
        let (s, _) = summarize(
            &lateral,
            &curve(&TEETH, 0.1, 0.0),
            &Snapshot::default(),
            RunCost::default(),
        );
        assert_eq!(s.mode, CollapseMode::Flattening);
        assert_eq!(s.references, references(&lateral));
        assert_eq!(s.peak_load_n, 2000.0);
        // Round trip through JSON, as the CLI and the service store it (serde_json's default
        // float parser may be off by one ulp, so compare the re-serialized text).
        let text = serde_json::to_string(&s).unwrap();
        let back: Summary = serde_json::from_str(&text).unwrap();
        assert_eq!(
            (back.mode, back.folds, back.references.primary()),
            (s.mode, s.folds, s.references.primary())
        );
        let (back_n, n) = (back.references.primary_n(), s.references.primary_n());
        assert!((back_n.unwrap() / n.unwrap() - 1.0).abs() < 1e-15);
    }

    /// A summary states what every run produces: JSON without one of the fields a run always
    /// has is not a summary (a store that kept older versions reads them its own way).
    #[test]
    fn a_summary_without_a_field_every_run_has_does_not_read() {
        let (s, _) = summarize(&case("{}"), &[], &Snapshot::default(), RunCost::default());
        let full = serde_json::to_value(&s).unwrap();
        let reads = |json: &serde_json::Value| serde_json::from_value::<Summary>(json.clone());
        assert!(reads(&full).is_ok());
        let fields = full.as_object().unwrap();
        for key in [
            "shape",
            "verdict",
            "expected_error",
            "load_drops",
            "tube_mass_g",
        ] {
            assert!(fields.contains_key(key), "{key}");
        }
        // Every field but the ones a run may leave empty (null: no first peak).
        for (key, _) in fields.iter().filter(|(_, v)| !v.is_null()) {
            let mut less = full.clone();
            less.as_object_mut().unwrap().remove(key);
            assert!(reads(&less).is_err(), "a summary without {key} read");
        }
        for key in ["yield_stress_mpa", "ultimate_stress_mpa"] {
            let mut less = full.clone();
            less["references"]["metal"]
                .as_object_mut()
                .unwrap()
                .remove(key);
            assert!(reads(&less).is_err(), "a summary without metal.{key} read");
        }
    }

    fn case(json: &str) -> Case {
        Case::from_json(json, &Limits::default()).unwrap()
    }
}

#[cfg(test)]
mod spike_tests {
    use super::*;

    /// A regression for what broke on the first n = 4 crush: single-row contact spikes of
    /// +40 % on a flat plateau were counted as folds (9 of them on a curve with one fold).
    #[test]
    fn single_row_spikes_are_not_load_drops() {
        let rows: Vec<HistoryRow> = (1..=300)
            .map(|i| HistoryRow {
                displacement_mm: i as f64 * 0.1,
                load_top_n: if i % 23 == 0 { 14_000.0 } else { 10_000.0 },
                ..Default::default()
            })
            .collect();
        assert_eq!(count_load_drops(&rows), 0);
    }
}
