//! The crush solver: explicit MPM of a thin-walled tube crushed between rigid plates.
//!
//! A pure library (std, nalgebra, rayon, serde): no I/O, no async. Results leave through the
//! return value and the [`Observer`] trait. Internal units are consistent: mm, ms, g, so that
//! force is N, stress MPa, velocity m/s (= mm/ms) and energy mJ (= N·mm).
//!
//! Three floors, each importing only from the floors below it:
//!
//! - [`model`]: what the user asked for — the case (its JSON, checks, limits and cost), the
//!   tube's cross-section (lattice, exact particle count, domain, wall-line metric), the
//!   material and contact laws. Imports nothing of the other two.
//! - [`engine`]: how it is computed — the shared kernel (the `Engine` trait, state, clock,
//!   energy books, the per-particle stress loop) with the 3D model (`solid`) and the reduced
//!   models (`reduced`) beneath it, the grid, shape functions and particles, the run loop.
//!   Imports the model.
//! - [`analysis`]: what it means — summary, collapse mode, folds, closed-form references, the
//!   cost estimate. Imports the model and the engine.
//!
//! This module joins them: [`run`] is the engine's run followed by the analysis.

pub mod analysis;
pub mod engine;
pub mod model;
mod runner;

pub use analysis::curve::EnergyBooks;
pub use analysis::estimate::{estimate, estimate_with, Estimate};
pub use analysis::mode::{detect_mode, CollapseMode, ModeDetail};
pub use analysis::reference::{references, References};
pub use analysis::summary::{summarize, Summary};
pub use engine::checkpoint::{Checkpoint, CheckpointError, Resume};
pub use engine::history::HistoryRow;
pub use engine::observer::{Frame, Observer, Progress, Recorder, RungProgress};
pub use engine::{Finished, RunCost, Snapshot, SolveError};
pub use model::case::{Case, CaseError, CaseSpec, FieldError, Limits};
pub use runner::{cores, LadderObserver, Runner};

use engine::scene::Scene;
use std::sync::atomic::AtomicBool;

/// The floating-point type of all solver state.
pub type Real = f64;

/// Everything a finished run produces: what the engine computed and what it means.
#[derive(Debug, Clone)]
pub struct RunOutput {
    pub history: Vec<HistoryRow>,
    pub summary: Summary,
    /// The numbers behind `summary.mode`.
    pub mode_detail: ModeDetail,
    pub snapshot: Snapshot,
}

impl RunOutput {
    /// The analysis of a finished run of `case`.
    pub fn of(case: &Case, run: Finished) -> RunOutput {
        let (summary, mode_detail) = summarize(case, &run.history, &run.snapshot, run.cost);
        RunOutput {
            history: run.history,
            summary,
            mode_detail,
            snapshot: run.snapshot,
        }
    }
}

/// Runs a case to the end on the current rayon pool and analyses it ([`engine::run`]).
pub fn run(
    case: &Case,
    observer: &mut dyn Observer,
    cancel: &AtomicBool,
) -> Result<RunOutput, SolveError> {
    engine::run(case, observer, cancel).map(|r| RunOutput::of(case, r))
}

/// [`run`] from a checkpoint of the same case ([`engine::resume`]).
pub fn resume(
    case: &Case,
    from: Resume,
    observer: &mut dyn Observer,
    cancel: &AtomicBool,
) -> Result<RunOutput, SolveError> {
    engine::resume(case, from, observer, cancel).map(|r| RunOutput::of(case, r))
}

/// [`run`] on a scene built from `case` and then changed ([`engine::run_scene`]).
pub fn run_scene(
    case: &Case,
    scene: Scene,
    observer: &mut dyn Observer,
    cancel: &AtomicBool,
) -> Result<RunOutput, SolveError> {
    engine::run_scene(case, scene, observer, cancel).map(|r| RunOutput::of(case, r))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// Every Rust file under `dir`, with its text.
    fn sources(dir: &Path) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                out.extend(sources(&path));
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                out.push((path.display().to_string(), text));
            }
        }
        out
    }

    /// The floors as the module doc states them: the model imports neither the engine nor the
    /// analysis, the engine not the analysis, and no floor the service's or the CLI's crates.
    /// Every line of code is read, not only `use` lines, so that an inline path upward
    /// (`crate::solver::engine::x()` in the model) fails it too; comments are skipped, and so
    /// are tests (a `tests.rs` or `*_tests.rs` file, or what follows `#[cfg(test)]`), which may
    /// read files and build a scene.
    #[test]
    fn each_floor_imports_only_the_floors_below_it() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/solver");
        let rules: [(&str, &[&str]); 3] = [
            ("model", &["engine::", "analysis::"]),
            ("engine", &["analysis::"]),
            ("analysis", &[]),
        ];
        let everywhere = [
            "tokio",
            "axum",
            "sqlx",
            "crate::service",
            "crate::cli",
            "std::fs",
        ];
        for (floor, forbidden) in rules {
            let files = sources(&root.join(floor));
            assert!(!files.is_empty(), "no files in {floor}");
            for (file, text) in files {
                if file.ends_with("tests.rs") {
                    continue;
                }
                for line in code_lines(&text) {
                    for f in forbidden.iter().chain(&everywhere) {
                        assert!(!line.contains(f), "{file}: `{line}` reaches {f}");
                    }
                }
            }
        }
    }

    /// A file's lines of code before its tests, comments and trailing comments cut.
    fn code_lines(text: &str) -> Vec<&str> {
        text.lines()
            .map(str::trim)
            .take_while(|l| *l != "#[cfg(test)]")
            .filter(|l| !l.starts_with("//"))
            .map(|l| l.split("//").next().unwrap_or("").trim())
            .filter(|l| !l.is_empty())
            .collect()
    }

    /// The floor test reads inline paths, not only `use` lines.
    #[test]
    fn the_floor_test_sees_an_inline_path() {
        let text = "fn f() {\n    let s = crate::solver::engine::scene::Scene::new(); // up\n}\n\
                    #[cfg(test)]\nmod tests { use std::fs; }\n";
        let lines = code_lines(text);
        assert!(lines.iter().any(|l| l.contains("engine::")), "{lines:?}");
        assert!(!lines.iter().any(|l| l.contains("std::fs")), "{lines:?}");
        assert!(!lines.iter().any(|l| l.contains("// up")), "{lines:?}");
    }
}
