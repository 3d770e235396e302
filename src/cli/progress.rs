//! A progress bar on stderr, driven by the solver's [`Observer`] calls. It hides itself when
//! stderr is not a terminal.

use crate::solver::{HistoryRow, Observer, Progress};
use indicatif::{ProgressBar, ProgressStyle};

/// Bar resolution: positions per whole crush.
const TICKS: u64 = 1000;

/// Shows progress and keeps the history rows, so that a cancelled run can still write them.
pub struct BarObserver {
    bar: ProgressBar,
    pub rows: Vec<HistoryRow>,
}

impl BarObserver {
    pub fn new() -> Self {
        let bar = ProgressBar::new(TICKS);
        let style = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% {msg}",
        )
        .expect("valid template")
        .progress_chars("=> ");
        bar.set_style(style);
        BarObserver {
            bar,
            rows: Vec::new(),
        }
    }

    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }
}

impl Default for BarObserver {
    fn default() -> Self {
        Self::new()
    }
}

impl Observer for BarObserver {
    fn on_progress(&mut self, p: &Progress) {
        self.bar
            .set_position((p.fraction.clamp(0.0, 1.0) * TICKS as f64).round() as u64);
        self.bar.set_message(progress_message(p));
    }

    fn on_history(&mut self, row: &HistoryRow) {
        self.rows.push(*row);
    }
}

/// "u 12.34 mm  P 10.52 kN  ETA 1:02:03"; the ETA is the solver's, or extrapolated from the
/// elapsed time when the solver gives none.
pub fn progress_message(p: &Progress) -> String {
    let eta = if p.eta_s > 0.0 {
        Some(p.eta_s)
    } else if p.fraction > 0.0 && p.fraction < 1.0 {
        Some(p.elapsed_s * (1.0 - p.fraction) / p.fraction)
    } else {
        None
    };
    let eta = eta.map_or_else(|| "--".to_string(), clock);
    format!(
        "u {:.2} mm  P {:.3} kN  ETA {eta}",
        p.displacement_mm,
        p.load_n / 1000.0
    )
}

/// Seconds as m:ss or h:mm:ss.
pub fn clock(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    let (h, m, s) = (s / 3600, s / 60 % 60, s % 60);
    if h > 0 {
        format!("{h}:{m:02}:{s:02}")
    } else {
        format!("{m}:{s:02}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_shows_displacement_load_and_eta() {
        let p = Progress {
            step: 10,
            time_ms: 1.0,
            displacement_mm: 12.345,
            load_n: 10_520.0,
            fraction: 0.25,
            elapsed_s: 30.0,
            eta_s: 0.0,
            error_bar: None,
        };
        // No solver ETA: 30 s for a quarter → 90 s to go.
        assert_eq!(progress_message(&p), "u 12.35 mm  P 10.520 kN  ETA 1:30");
        assert_eq!(
            progress_message(&Progress { eta_s: 3725.0, ..p }),
            "u 12.35 mm  P 10.520 kN  ETA 1:02:05"
        );
        assert!(progress_message(&Progress { fraction: 0.0, ..p }).ends_with("ETA --"));
    }
}
