//! Ensembles: the same case run over several trigger seeds, read as a distribution. A thin
//! triggered tube folds in a number of lobes that depends on where the weak particles fall, so
//! one run's mode is one draw; the ensemble says how often each mode came out and how far the
//! loads spread (mean, sample standard deviation, min, max; N, mJ).
//!
//! Pure analysis of finished runs' figures ([`super::Figures`]), shared by the sweep table (a
//! sweep that varies `trigger.seed`) and its CSV.

use super::Figures;
use crate::solver::CollapseMode;
use schemars::JsonSchema;
use serde::Serialize;

/// The field an ensemble varies.
pub const SEED_FIELD: &str = "trigger.seed";

/// Mean, sample standard deviation (n − 1; 0 for one run), min and max of one figure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, JsonSchema)]
pub struct Spread {
    pub mean: f64,
    pub sd: f64,
    pub min: f64,
    pub max: f64,
}

impl Spread {
    /// The spread of these values; none for no values.
    pub fn of(values: &[f64]) -> Option<Spread> {
        let n = values.len();
        if n == 0 {
            return None;
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let sd = if n > 1 {
            let ss: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
            (ss / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        Some(Spread {
            mean,
            sd,
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        })
    }
}

/// How many runs came out in one mode.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct ModeCount {
    pub mode: CollapseMode,
    pub runs: usize,
    /// Share of the ensemble's runs, 0 to 1.
    pub share: f64,
}

/// The distribution of an ensemble's finished runs.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
pub struct Distribution {
    /// Finished runs read.
    pub runs: usize,
    /// Every mode that came out, the most frequent first (ties in order of first appearance).
    pub modes: Vec<ModeCount>,
    pub mean_load_n: Spread,
    pub peak_load_n: Spread,
    pub energy_absorbed_mj: Spread,
    /// Runs whose own verdict was not trusted: read the spread without them if there are any.
    pub not_trusted_runs: usize,
}

impl Distribution {
    /// The distribution of these runs; none for no runs.
    pub fn of(runs: &[Figures]) -> Option<Distribution> {
        let figure = |f: fn(&Figures) -> f64| -> Vec<f64> { runs.iter().map(f).collect() };
        let mean_load_n = Spread::of(&figure(|s| s.mean_load_n))?;
        let mut modes: Vec<ModeCount> = Vec::new();
        for s in runs {
            match modes.iter_mut().find(|m| m.mode == s.mode) {
                Some(m) => m.runs += 1,
                None => modes.push(ModeCount {
                    mode: s.mode,
                    runs: 1,
                    share: 0.0,
                }),
            }
        }
        // A stable sort keeps ties in order of first appearance.
        modes.sort_by_key(|m| std::cmp::Reverse(m.runs));
        for m in &mut modes {
            m.share = m.runs as f64 / runs.len() as f64;
        }
        Some(Distribution {
            runs: runs.len(),
            modes,
            mean_load_n,
            peak_load_n: Spread::of(&figure(|s| s.peak_load_n))?,
            energy_absorbed_mj: Spread::of(&figure(|s| s.energy_absorbed_mj))?,
            not_trusted_runs: runs.iter().filter(|s| s.not_trusted).count(),
        })
    }

    /// The mode counts in one line: `diamond-3:3 diamond-2:1 global_buckling:1`.
    pub fn modes_line(&self) -> String {
        self.modes
            .iter()
            .map(|m| format!("{}:{}", mode_label(&m.mode), m.runs))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// A mode in one word: its kind, and for a diamond its lobes (`diamond-3`).
pub fn mode_label(mode: &CollapseMode) -> String {
    match mode {
        CollapseMode::Diamond { lobes } => format!("diamond-{lobes}"),
        other => other.kind().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::analysis::verdict::Verdict;

    fn run(mean: f64, mode: CollapseMode) -> Figures {
        let mut s = crate::service::store::sample_summary();
        s.mean_load_n = mean;
        s.peak_load_n = 2.0 * mean;
        s.energy_absorbed_mj = 50.0 * mean;
        s.mode = mode;
        Figures::of(&s)
    }

    #[test]
    fn the_spread_is_the_sample_mean_and_standard_deviation_with_the_extremes() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, Σ(x − 5)² = 32, sample sd √(32/7).
        let s = Spread::of(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]).unwrap();
        assert_eq!(s.mean, 5.0);
        assert!((s.sd - (32.0f64 / 7.0).sqrt()).abs() < 1e-12, "{}", s.sd);
        assert_eq!((s.min, s.max), (2.0, 9.0));
        assert_eq!(Spread::of(&[3.0]).unwrap().sd, 0.0);
        assert_eq!(Spread::of(&[]), None);
    }

    #[test]
    fn five_seeds_count_their_modes_most_frequent_first() {
        let three = CollapseMode::Diamond { lobes: 3 };
        let two = CollapseMode::Diamond { lobes: 2 };
        let mut runs = vec![
            run(1000.0, three),
            run(1100.0, three),
            run(900.0, CollapseMode::GlobalBuckling),
            run(1200.0, two),
            run(1300.0, two),
        ];
        let d = Distribution::of(&runs).unwrap();
        assert_eq!(d.runs, 5);
        assert_eq!(d.modes_line(), "diamond-3:2 diamond-2:2 global_buckling:1");
        assert_eq!(d.modes[0].share, 0.4);
        assert_eq!(d.mean_load_n.mean, 1100.0);
        assert_eq!((d.mean_load_n.min, d.mean_load_n.max), (900.0, 1300.0));
        assert_eq!(d.peak_load_n.mean, 2200.0);
        assert_eq!(d.energy_absorbed_mj.max, 65_000.0);
        assert_eq!(d.not_trusted_runs, 0);
        let mut blown = crate::service::store::sample_summary();
        blown.mean_load_n = 1.0e9;
        blown.verdict = Verdict::unstable("a blow-up");
        runs.push(Figures::of(&blown));
        assert_eq!(Distribution::of(&runs).unwrap().not_trusted_runs, 1);
        assert_eq!(Distribution::of(&[]), None);
    }
}
