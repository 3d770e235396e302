//! What the studies read of a finished run: a few figures of its summary, taken from the
//! solver's [`Summary`] or from a summary the service's store read back. Units: N, mJ, s.

use crate::solver::analysis::verdict::{Level, Verdict};
use crate::solver::{CollapseMode, RunCost, Summary};

/// A finished run's figures, as the studies read them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figures {
    pub cost: RunCost,
    pub mean_load_n: f64,
    pub peak_load_n: f64,
    pub energy_absorbed_mj: f64,
    /// The first collapse peak; `None` where the load never dropped.
    pub first_peak_load_n: Option<f64>,
    pub energy_balance_error: f64,
    pub mode: CollapseMode,
    pub folds: u32,
    /// The scene's primary closed-form load; `None` where none reaches the scene.
    pub reference_n: Option<f64>,
    /// Whether the run's verdict was not trusted (false for a run without a verdict).
    pub not_trusted: bool,
}

impl Figures {
    /// The figures of the run that `s` sums up.
    pub fn of(s: &Summary) -> Figures {
        Figures {
            cost: s.cost,
            mean_load_n: s.mean_load_n,
            peak_load_n: s.peak_load_n,
            energy_absorbed_mj: s.energy_absorbed_mj,
            first_peak_load_n: s.measures.first_peak_load_n,
            energy_balance_error: s.energy_balance_error,
            mode: s.mode,
            folds: s.folds,
            reference_n: s.references.primary_n(),
            not_trusted: not_trusted(Some(&s.verdict)),
        }
    }
}

/// Whether `verdict` says not trusted; false for none.
pub fn not_trusted(verdict: Option<&Verdict>) -> bool {
    verdict.is_some_and(|v| v.level == Level::NotTrusted)
}
