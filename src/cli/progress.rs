//! Progress on stderr, driven by the solver's [`Observer`] calls: a bar on a terminal, and a
//! plain line every [`LINE_EVERY_S`] seconds of the run where stderr is a file or a pipe (a
//! log, a batch job, a notebook cell), so that a long run is never silent there.

use crate::solver::{HistoryRow, Observer, Progress};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};

/// Bar resolution: positions per whole crush.
const TICKS: u64 = 1000;

/// Seconds of the run between two progress lines where stderr is not a terminal.
pub const LINE_EVERY_S: f64 = 5.0;

/// Where progress lines go when there is no bar, and when the last one went.
struct Lines {
    out: Box<dyn Write + Send>,
    every_s: f64,
    /// The run's seconds and fraction at the last line.
    last: Option<(f64, f64)>,
}

/// Shows progress and keeps the history rows, so that a cancelled run can still write them.
pub struct BarObserver {
    bar: ProgressBar,
    lines: Option<Lines>,
    pub rows: Vec<HistoryRow>,
}

impl BarObserver {
    /// A bar where stderr is a terminal, lines every [`LINE_EVERY_S`] s where it is not.
    pub fn new() -> Self {
        match std::io::stderr().is_terminal() {
            true => Self::bar_only(),
            false => Self::lines(Box::new(std::io::stderr()), LINE_EVERY_S),
        }
    }

    /// Progress lines to `out`, one every `every_s` seconds of the run, and no bar.
    pub fn lines(out: Box<dyn Write + Send>, every_s: f64) -> Self {
        BarObserver {
            lines: Some(Lines {
                out,
                every_s,
                last: None,
            }),
            ..Self::bar_only()
        }
    }

    fn bar_only() -> Self {
        let bar = ProgressBar::new(TICKS);
        let style = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% {msg}",
        )
        .expect("valid template")
        .progress_chars("=> ");
        bar.set_style(style);
        BarObserver {
            bar,
            lines: None,
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
        if let Some(l) = &mut self.lines {
            let due = match l.last {
                None => true,
                Some((s, f)) => p.elapsed_s - s >= l.every_s || (p.fraction >= 1.0 && f < 1.0),
            };
            if due {
                l.last = Some((p.elapsed_s, p.fraction));
                // A lost progress line is not worth stopping the run for.
                let _ = writeln!(
                    l.out,
                    "{:5.1} %  {}",
                    100.0 * p.fraction.clamp(0.0, 1.0),
                    progress_message(p)
                );
            }
        }
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

    /// A writer the test can read back.
    #[derive(Clone, Default)]
    struct Shared(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    /// Without a terminal, a line at the first report, then one per `every_s` seconds of the
    /// run however often the solver reports, and one at the end.
    #[test]
    fn without_a_terminal_a_line_every_few_seconds_and_at_the_end() {
        let out = Shared::default();
        let mut o = BarObserver::lines(Box::new(out.clone()), 5.0);
        let at = |elapsed_s: f64, fraction: f64| Progress {
            step: 1,
            time_ms: 0.0,
            displacement_mm: 50.0 * fraction,
            load_n: 12_000.0,
            fraction,
            elapsed_s,
            eta_s: 0.0,
            error_bar: None,
        };
        for i in 0..=40 {
            // A report every half second for 20 s.
            o.on_progress(&at(0.5 * i as f64, 0.025 * i as f64));
        }
        o.on_progress(&at(20.2, 1.0));
        let text = String::from_utf8(out.0.lock().unwrap().clone()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines.len(),
            5,
            "at 0, 5, 10, 15 and 20 s, the end once: {text}"
        );
        assert!(lines[0].starts_with("  0.0 %  u 0.00 mm"), "{text}");
        assert!(
            lines[1].starts_with(" 25.0 %  u 12.50 mm  P 12.000 kN  ETA 0:15"),
            "{text}"
        );
        assert!(lines[4].starts_with("100.0 %"), "{text}");
    }
}
