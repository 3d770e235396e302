//! Discretization error from a set of runs of one case at several resolutions: the error of
//! each run's mean and peak load against the finest run and against a Richardson-extrapolated
//! value, and its difference to the scene's closed-form reference. Pure functions of the runs'
//! figures; the CLI (`crush study convergence`) and the service's sweep table both use them.
//!
//! The mesh size is h = 1/n (n particles through the wall; the cell is a fixed multiple of the
//! particle spacing, so h ∝ cell size).

pub use crate::solver::analysis::richardson::{richardson, Extrapolation, TRUSTED_ORDERS};
use schemars::JsonSchema;
use serde::Serialize;

/// One run's figures, as the analysis needs them.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct RunPoint {
    /// Runs with the same group (e.g. shape function) are compared with each other.
    pub group: String,
    /// Particles through the wall.
    pub n: u32,
    pub particles: u64,
    pub steps: u64,
    pub wall_time_s: f64,
    pub mean_load_n: f64,
    pub peak_load_n: f64,
    /// The scene's primary closed-form load (Alexander's ring for axial, DeRuntz–Hodge's mean
    /// for lateral crush), N; `None` where none reaches the scene.
    pub reference_n: Option<f64>,
}

impl RunPoint {
    /// The point of a finished run with `n` particles through the wall, in `group`.
    pub fn of(group: String, n: u32, s: &super::Figures) -> RunPoint {
        RunPoint {
            group,
            n,
            particles: s.cost.particles,
            steps: s.cost.steps,
            wall_time_s: s.cost.wall_time_s,
            mean_load_n: s.mean_load_n,
            peak_load_n: s.peak_load_n,
            reference_n: s.reference_n,
        }
    }
}

/// One run with its errors (relative, signed: (value − target) / target).
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct ConvergenceRow {
    #[serde(flatten)]
    pub run: RunPoint,
    pub mean_error_vs_finest: f64,
    pub peak_error_vs_finest: f64,
    /// Against the Richardson value, when it is trustworthy.
    pub mean_error_vs_richardson: Option<f64>,
    pub peak_error_vs_richardson: Option<f64>,
    /// (mean − reference) / reference; `None` where no closed form reaches the scene.
    pub mean_vs_reference: Option<f64>,
}

/// The runs of one group with their errors and extrapolations.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct GroupAnalysis {
    pub group: String,
    pub rows: Vec<ConvergenceRow>,
    pub mean_extrapolation: Option<Extrapolation>,
    pub peak_extrapolation: Option<Extrapolation>,
}

impl GroupAnalysis {
    /// The cheapest run whose mean-load error is within `tolerance` (relative) and every finer
    /// run's too — against the trustworthy Richardson value if there is one, else against the
    /// finest run (which then qualifies trivially and is not recommended). A coarse run that
    /// lands within the tolerance by luck, with a finer one outside it, is no recommendation.
    pub fn cheapest_within(&self, tolerance: f64) -> Option<&ConvergenceRow> {
        let trusted = self.mean_extrapolation.is_some_and(|e| e.trustworthy);
        let finest = self.rows.iter().map(|r| r.run.n).max()?;
        let within = |r: &ConvergenceRow| {
            if trusted {
                r.mean_error_vs_richardson
                    .is_some_and(|e| e.abs() <= tolerance)
            } else {
                r.mean_error_vs_finest.abs() <= tolerance
            }
        };
        self.rows
            .iter()
            .filter(|r| trusted || r.run.n != finest)
            .filter(|r| self.rows.iter().filter(|f| f.run.n >= r.run.n).all(&within))
            .min_by(|a, b| a.run.wall_time_s.total_cmp(&b.run.wall_time_s))
    }
}

/// Groups the runs (in order of first appearance) and computes every error.
pub fn analyse(runs: &[RunPoint]) -> Vec<GroupAnalysis> {
    let mut groups: Vec<String> = Vec::new();
    for r in runs {
        if !groups.contains(&r.group) {
            groups.push(r.group.clone());
        }
    }
    groups
        .into_iter()
        .map(|group| {
            let mut members: Vec<&RunPoint> = runs.iter().filter(|r| r.group == group).collect();
            members.sort_by_key(|r| r.n);
            let finest = members.last().expect("a group has a run");
            let h = |r: &RunPoint| 1.0 / r.n as f64;
            let mean_ex = richardson(
                &members
                    .iter()
                    .map(|r| (h(r), r.mean_load_n))
                    .collect::<Vec<_>>(),
            );
            let peak_ex = richardson(
                &members
                    .iter()
                    .map(|r| (h(r), r.peak_load_n))
                    .collect::<Vec<_>>(),
            );
            let rel = |v: f64, target: f64| (v - target) / target;
            let against = |e: Option<Extrapolation>, v: f64| {
                e.filter(|e| e.trustworthy).map(|e| rel(v, e.value))
            };
            let rows = members
                .iter()
                .map(|r| ConvergenceRow {
                    run: (*r).clone(),
                    mean_error_vs_finest: rel(r.mean_load_n, finest.mean_load_n),
                    peak_error_vs_finest: rel(r.peak_load_n, finest.peak_load_n),
                    mean_error_vs_richardson: against(mean_ex, r.mean_load_n),
                    peak_error_vs_richardson: against(peak_ex, r.peak_load_n),
                    mean_vs_reference: r.reference_n.map(|p| rel(r.mean_load_n, p)),
                })
                .collect();
            GroupAnalysis {
                group,
                rows,
                mean_extrapolation: mean_ex,
                peak_extrapolation: peak_ex,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol * b.abs().max(1.0), "{a} vs {b}");
    }

    fn run(group: &str, n: u32, mean: f64, wall: f64) -> RunPoint {
        RunPoint {
            group: group.into(),
            n,
            particles: 1000 * n as u64,
            steps: 100,
            wall_time_s: wall,
            mean_load_n: mean,
            peak_load_n: 2.0 * mean,
            reference_n: Some(100.0),
        }
    }

    #[test]
    fn errors_are_relative_to_the_finest_and_to_the_extrapolation() {
        // mean = 100 + 40 h: n 2 → 120, 4 → 110, 8 → 105; extrapolated 100.
        let runs = vec![
            run("gimp", 4, 110.0, 4.0),
            run("gimp", 2, 120.0, 1.0),
            run("gimp", 8, 105.0, 30.0),
            run("linear", 2, 90.0, 1.0),
        ];
        let a = analyse(&runs);
        assert_eq!(a.len(), 2);
        let g = &a[0];
        assert_eq!(g.group, "gimp");
        assert_eq!(
            g.rows.iter().map(|r| r.run.n).collect::<Vec<_>>(),
            vec![2, 4, 8]
        );
        close(g.rows[0].mean_error_vs_finest, 15.0 / 105.0, 1e-12);
        assert_eq!(g.rows[2].mean_error_vs_finest, 0.0);
        close(g.mean_extrapolation.unwrap().value, 100.0, 1e-9);
        close(g.rows[1].mean_error_vs_richardson.unwrap(), 0.10, 1e-9);
        close(g.rows[2].mean_vs_reference.unwrap(), 0.05, 1e-12);
        // 6 % against the extrapolation: only n = 8 qualifies; 11 %: n = 4 is cheaper.
        assert_eq!(g.cheapest_within(0.06).unwrap().run.n, 8);
        assert_eq!(g.cheapest_within(0.11).unwrap().run.n, 4);
        // What the trilinear runs of docs/studies.md showed: n = 2 within 5 % of the finest
        // (+3.8 %), n = 3 not (−5.3 %), n = 4 within (−0.5 %): n = 2 is no recommendation.
        let lucky = analyse(&[
            run("linear", 2, 14.094, 3.1),
            run("linear", 3, 12.850, 13.3),
            run("linear", 4, 13.509, 42.3),
            run("linear", 6, 13.571, 211.0),
        ]);
        assert!(lucky[0].mean_extrapolation.is_none_or(|e| !e.trustworthy));
        assert_eq!(lucky[0].cheapest_within(0.05).unwrap().run.n, 4);
        // One run alone: its own finest, no extrapolation, nothing cheaper within tolerance.
        let l = &a[1];
        assert!(l.mean_extrapolation.is_none());
        assert!(l.cheapest_within(0.5).is_none());
    }
}
