//! What the studies share: running a case (varied as JSON, or its scene changed) on a pool of
//! threads, reading and setting its fields, plotting the runs' load curves (kN against mm) and
//! writing the report. Imports nothing of the study folder; each study imports it.

use crate::plot::{self, Series};
use crate::solver::engine::scene::Scene;
use crate::solver::model::input::set_field;
use crate::solver::Summary;
use crate::solver::{
    self, Case, CaseError, HistoryRow, Limits, Observer, Progress, Runner, SolveError,
};
use anyhow::Context;
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// A finished run of a study.
pub struct Finished {
    pub history: Vec<HistoryRow>,
    pub summary: Summary,
}

impl Finished {
    /// The load on the moving plate (kN) against its travel (mm), as a plot line.
    pub fn load_curve(&self, name: String) -> Series {
        Series {
            name,
            points: self
                .history
                .iter()
                .map(|r| (r.displacement_mm, r.load_top_n / 1000.0))
                .collect(),
        }
    }
}

/// Writes `load_curves.svg` / `.png` in `out`: the runs' load curves overlaid.
pub fn plot_load_curves(out: &Path, curves: &[Series]) -> anyhow::Result<()> {
    plot::lines(
        &out.join("load_curves"),
        ("Load against plate travel", "plate travel, mm", "load, kN"),
        curves,
        false,
    )
}

/// Why a study run has no result.
pub enum Failed {
    /// The case was refused before running (every field named).
    Rejected(CaseError),
    /// The run stopped: cancelled, or unstable with its diagnosis.
    Stopped(SolveError),
}

/// Reads a case file as JSON (the study varies it as JSON before parsing).
pub fn read_case(path: &Path) -> anyhow::Result<Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
}

/// Sets the field at a dotted path (`"tube.length_mm"`) of a study's case.
pub fn set(case: &mut Value, path: &str, value: Value) -> anyhow::Result<()> {
    set_field(case, path, value).map_err(|walked| {
        anyhow::anyhow!("{path} cannot be set: {walked} is not an object in the case")
    })
}

/// One line on stderr per history row fraction decile, so long studies show life.
struct Quiet<'a> {
    name: &'a str,
    next: f64,
}

impl Observer for Quiet<'_> {
    fn on_progress(&mut self, p: &Progress) {
        if p.fraction >= self.next {
            eprint!("\r  {:<28} {:>3.0} %", self.name, 100.0 * p.fraction);
            self.next += 0.1;
        }
    }
    fn on_history(&mut self, _row: &HistoryRow) {}
}

/// Parses and runs a case on a pool of `threads`, with the wall time and throughput filled in.
pub fn run_case(
    name: &str,
    json: &Value,
    threads: usize,
) -> anyhow::Result<Result<Finished, Failed>> {
    run_case_changed(name, json, threads, |_| {})
}

/// [`run_case`] with the scene changed by `change` after it is built from the case: runs what
/// no valid case describes (see `solver::run_scene`).
pub fn run_case_changed(
    name: &str,
    json: &Value,
    threads: usize,
    change: impl FnOnce(&mut Scene) + Send,
) -> anyhow::Result<Result<Finished, Failed>> {
    let text = serde_json::to_string(json)?;
    let case = match Case::from_json(&text, &Limits::default()) {
        Ok(c) => c,
        Err(e) => return Ok(Err(Failed::Rejected(e))),
    };
    let runner = Runner::new(threads, |i| format!("crush-study-{i}"))
        .context("starting the solver's thread pool")?;
    let mut observer = Quiet { name, next: 0.0 };
    let start = Instant::now();
    let result = runner.run_changed(&case, change, &mut observer, &AtomicBool::new(false));
    let wall = start.elapsed().as_secs_f64();
    eprintln!("\r  {name:<28} done in {wall:.1} s");
    Ok(match result {
        Ok(out) => Ok(Finished {
            history: out.history,
            summary: out.summary,
        }),
        Err(e) => Err(Failed::Stopped(e)),
    })
}

/// Threads: the flag, or every core.
pub fn threads(flag: Option<usize>) -> anyhow::Result<usize> {
    match flag {
        Some(0) => anyhow::bail!("--threads must be at least 1"),
        Some(n) => Ok(n),
        None => Ok(solver::cores()),
    }
}

/// Creates the output directory and writes `report.md` there; prints the report.
pub fn write_report(out: &Path, text: &str) -> anyhow::Result<()> {
    let path = out.join("report.md");
    std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    println!("{text}");
    eprintln!("wrote {}", out.display());
    Ok(())
}

/// One line per load of a ladder's Richardson estimate (kN), or why there is none: fewer than
/// three `rungs` (resolutions, steps), or differences that change sign or do not shrink.
pub fn write_extrapolations(
    s: &mut String,
    rungs: &str,
    loads: [(&str, Option<crate::study::convergence::Extrapolation>); 2],
) {
    use std::fmt::Write as _;
    for (what, e) in loads {
        let _ = match e {
            Some(e) => writeln!(
                s,
                "\nRichardson, {what} load: f* = {:.3} kN, observed order p = {:.2}{}.",
                e.value / 1e3,
                e.order,
                if e.trustworthy {
                    ""
                } else {
                    " — not trusted (p outside the accepted range)"
                }
            ),
            None => writeln!(
                s,
                "\nRichardson, {what} load: none (fewer than three {rungs}, or the differences \
                 between successive {rungs} change sign or do not shrink)."
            ),
        };
    }
}

/// `x` as a signed percentage with one decimal, or "–".
pub fn pct(x: Option<f64>) -> String {
    x.map_or("–".into(), |x| format!("{:+.1} %", 100.0 * x))
}
