//! Time-step error from a set of runs of one case at several CFL numbers (α in
//! Δt = α · cell / (c + |v|)), everything else the same: each run's mean and first-peak load
//! against the smallest step's and against a Richardson value extrapolated to Δt → 0, its energy
//! books, and the cheapest step within a tolerance. Pure functions of the runs' figures; the
//! command line (`crush study step`) uses them.
//!
//! The step is h = α: the cell and the signal speed are the case's, so Δt ∝ α. The explicit
//! update is first order in Δt where contact projects node velocities, so an observed order near
//! 1 is what a sound ladder shows; the books' residual is expected to shrink with α as well.

use super::convergence::{richardson, Extrapolation};
use crate::solver::CollapseMode;
use schemars::JsonSchema;
use serde::Serialize;

/// The swept field that sets the time step.
pub const STEP_FIELD: &str = "discretization.cfl";

/// One run's figures, as the analysis needs them. Loads in N, time in s.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct StepPoint {
    /// The CFL number α of the run.
    pub cfl: f64,
    pub steps: u64,
    pub wall_time_s: f64,
    pub mean_load_n: f64,
    /// The first collapse peak; None when the run found none.
    pub first_peak_n: Option<f64>,
    /// The books' largest share of the plates' work left unexplained over the run.
    pub energy_balance_error: f64,
    /// The collapse mode and folds the run ended in: a step that changes them changes the
    /// answer's kind, not its digits.
    pub mode: CollapseMode,
    pub folds: u32,
}

impl StepPoint {
    /// The point of a finished run at step `cfl`.
    pub fn of(cfl: f64, s: &super::Figures) -> StepPoint {
        StepPoint {
            cfl,
            steps: s.cost.steps,
            wall_time_s: s.cost.wall_time_s,
            mean_load_n: s.mean_load_n,
            first_peak_n: s.first_peak_load_n,
            energy_balance_error: s.energy_balance_error,
            mode: s.mode,
            folds: s.folds,
        }
    }
}

/// One run with its errors (relative, signed: (value − target) / target).
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct StepRow {
    #[serde(flatten)]
    pub run: StepPoint,
    pub mean_error_vs_finest: f64,
    /// Against the Richardson value, when it is trustworthy.
    pub mean_error_vs_richardson: Option<f64>,
    pub first_peak_error_vs_finest: Option<f64>,
}

/// The ladder's runs, smallest step last, with the extrapolations.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct StepAnalysis {
    /// Largest α first.
    pub rows: Vec<StepRow>,
    pub mean_extrapolation: Option<Extrapolation>,
    pub first_peak_extrapolation: Option<Extrapolation>,
}

impl StepAnalysis {
    /// Sorts the runs by step (largest first) and computes every error. None for no runs.
    pub fn of(runs: &[StepPoint]) -> Option<StepAnalysis> {
        let mut runs = runs.to_vec();
        runs.sort_by(|a, b| b.cfl.total_cmp(&a.cfl));
        let finest = runs.last()?.clone();
        let mean_ex = richardson(
            &runs
                .iter()
                .map(|r| (r.cfl, r.mean_load_n))
                .collect::<Vec<_>>(),
        );
        let peaks: Option<Vec<(f64, f64)>> = runs
            .iter()
            .map(|r| r.first_peak_n.map(|p| (r.cfl, p)))
            .collect();
        let first_peak_ex = peaks.and_then(|p| richardson(&p));
        let rel = |v: f64, target: f64| (v - target) / target;
        let rows = runs
            .into_iter()
            .map(|r| StepRow {
                mean_error_vs_finest: rel(r.mean_load_n, finest.mean_load_n),
                mean_error_vs_richardson: mean_ex
                    .filter(|e| e.trustworthy)
                    .map(|e| rel(r.mean_load_n, e.value)),
                first_peak_error_vs_finest: r
                    .first_peak_n
                    .zip(finest.first_peak_n)
                    .map(|(p, f)| rel(p, f)),
                run: r,
            })
            .collect();
        Some(StepAnalysis {
            rows,
            mean_extrapolation: mean_ex,
            first_peak_extrapolation: first_peak_ex,
        })
    }

    /// Whether the errors are read against the Richardson value (else the smallest step's).
    pub fn trusted(&self) -> bool {
        self.mean_extrapolation.is_some_and(|e| e.trustworthy)
    }

    fn mean_error(&self, r: &StepRow) -> f64 {
        match r.mean_error_vs_richardson {
            Some(e) if self.trusted() => e,
            _ => r.mean_error_vs_finest,
        }
    }

    /// The cheapest run whose mean load is within `tolerance` (relative) and every smaller
    /// step's too, against the trusted Richardson value, else against the smallest step (which
    /// then qualifies trivially and is not offered). A large step that lands within the
    /// tolerance by luck, with a smaller one outside it, is no recommendation.
    pub fn cheapest_within(&self, tolerance: f64) -> Option<&StepRow> {
        let trusted = self.trusted();
        let finest = self.rows.last()?.run.cfl;
        let within = |r: &StepRow| self.mean_error(r).abs() <= tolerance;
        self.rows
            .iter()
            .filter(|r| trusted || r.run.cfl != finest)
            .filter(|r| {
                self.rows
                    .iter()
                    .filter(|s| s.run.cfl <= r.run.cfl)
                    .all(within)
            })
            .min_by(|a, b| a.run.wall_time_s.total_cmp(&b.run.wall_time_s))
    }

    /// The largest step from which on (it and every smaller one) the books close within
    /// `limit`; None when even the smallest does not.
    pub fn books_within(&self, limit: f64) -> Option<&StepRow> {
        self.rows
            .iter()
            .enumerate()
            .find(|(i, _)| {
                self.rows[*i..]
                    .iter()
                    .all(|s| s.run.energy_balance_error <= limit)
            })
            .map(|(_, r)| r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run at step `cfl` whose mean load is f* + c·α (first order), wall time ∝ 1/α.
    fn point(cfl: f64, f_star: f64, c: f64, books: f64) -> StepPoint {
        StepPoint {
            cfl,
            steps: (1000.0 / cfl) as u64,
            wall_time_s: 10.0 / cfl,
            mean_load_n: f_star + c * cfl,
            first_peak_n: Some(2.0 * f_star + 0.5 * c * cfl),
            energy_balance_error: books,
            mode: CollapseMode::Ring,
            folds: 3,
        }
    }

    #[test]
    fn a_first_order_ladder_extrapolates_to_its_limit_with_order_one() {
        let runs = [
            point(0.125, 2000.0, 400.0, 0.006),
            point(0.5, 2000.0, 400.0, 0.024),
            point(0.25, 2000.0, 400.0, 0.012),
        ];
        let a = StepAnalysis::of(&runs).unwrap();
        // sorted largest step first
        let cfls: Vec<f64> = a.rows.iter().map(|r| r.run.cfl).collect();
        assert_eq!(cfls, [0.5, 0.25, 0.125]);
        let e = a.mean_extrapolation.unwrap();
        assert!((e.order - 1.0).abs() < 1e-6, "{e:?}");
        assert!((e.value - 2000.0).abs() < 1e-6, "{e:?}");
        assert!(a.trusted());
        // α 0.5: 2200 against 2000, +10 %; α 0.125: +2.5 %
        let r = &a.rows[0];
        assert!((r.mean_error_vs_richardson.unwrap() - 0.1).abs() < 1e-9);
        assert!((a.rows[2].mean_error_vs_richardson.unwrap() - 0.025).abs() < 1e-9);
        // against the smallest step: 2200 / 2050 − 1
        assert!((r.mean_error_vs_finest - (2200.0 / 2050.0 - 1.0)).abs() < 1e-12);
        let p = a.first_peak_extrapolation.unwrap();
        assert!((p.value - 4000.0).abs() < 1e-6 && (p.order - 1.0).abs() < 1e-6);
    }

    #[test]
    fn the_cheapest_step_within_a_tolerance_needs_every_smaller_one_within_it_too() {
        let runs = [
            point(0.5, 2000.0, 400.0, 0.024),
            point(0.25, 2000.0, 400.0, 0.012),
            point(0.125, 2000.0, 400.0, 0.006),
        ];
        let a = StepAnalysis::of(&runs).unwrap();
        // errors +10, +5, +2.5 %: 5 % admits α 0.25, not 0.5
        assert_eq!(a.cheapest_within(0.05).unwrap().run.cfl, 0.25);
        assert_eq!(a.cheapest_within(0.1).unwrap().run.cfl, 0.5);
        assert!(a.cheapest_within(0.01).is_none());
        // books 2.4, 1.2, 0.6 %: within 2 % from α 0.25 on, within 1 % only at 0.125
        assert_eq!(a.books_within(0.02).unwrap().run.cfl, 0.25);
        assert_eq!(a.books_within(0.01).unwrap().run.cfl, 0.125);
        assert!(a.books_within(0.005).is_none());
    }

    /// What a ladder that does not converge monotonically gives: no extrapolation, errors
    /// against the smallest step, and that step never offered as the cheapest.
    #[test]
    fn an_oscillating_ladder_is_not_extrapolated() {
        let mut runs = vec![
            point(0.5, 2000.0, 400.0, 0.01),
            point(0.25, 2000.0, 400.0, 0.01),
            point(0.125, 2000.0, 400.0, 0.01),
        ];
        runs[1].mean_load_n = 1990.0;
        let a = StepAnalysis::of(&runs).unwrap();
        assert!(a.mean_extrapolation.is_none());
        assert!(!a.trusted());
        assert!(a.rows.iter().all(|r| r.mean_error_vs_richardson.is_none()));
        // 2200 vs 2050 is +7.3 %, 1990 vs 2050 −2.9 %: within 5 % only α 0.25 and below
        assert_eq!(a.cheapest_within(0.05).unwrap().run.cfl, 0.25);
        assert!(a.cheapest_within(0.01).is_none());
    }

    #[test]
    fn a_run_without_a_first_peak_leaves_the_peak_unextrapolated() {
        let mut runs = vec![
            point(0.5, 2000.0, 400.0, 0.01),
            point(0.25, 2000.0, 400.0, 0.01),
            point(0.125, 2000.0, 400.0, 0.01),
        ];
        runs[0].first_peak_n = None;
        let a = StepAnalysis::of(&runs).unwrap();
        assert!(a.first_peak_extrapolation.is_none());
        assert_eq!(a.rows[0].first_peak_error_vs_finest, None);
        assert!(a.rows[1].first_peak_error_vs_finest.is_some());
        assert!(StepAnalysis::of(&[]).is_none());
    }
}
