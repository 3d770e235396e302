//! Command-line runners around the solver: `crush run CASE.json` runs one case with a progress
//! bar, prints a summary and writes `history.csv` and `summary.json`; `crush estimate
//! CASE.json` prints what a case will cost and what its verdict can say before it runs;
//! `crush plan CASE.json` the runs that reach a target error or fit a budget (`crush
//! bench-plan` holds its wall-time guesses to measured runs); `crush bench` measures the solver's speed and memory; `crush study` runs convergence,
//! stability and plate-speed studies; `crush validate` the validation suite and its report.

mod args;
mod bench;
mod estimate;
mod output;
mod plan;
mod plan_bench;
mod progress;
mod report;
mod run;
mod series;
mod study;
mod validate;

pub use args::{EstimateArgs, RunArgs};
pub use bench::{bench, bench_one, BenchArgs, BenchOneArgs};
pub use estimate::estimate;
pub use output::{write_history_csv, write_summary_json, SummaryFile};
pub use plan::{plan, PlanArgs};
pub use plan_bench::{bench_plan, BenchPlanArgs};
pub use report::format_report;
pub use run::run;
pub use study::{study, StudyArgs};
pub use validate::{validate, ValidateArgs};

#[cfg(test)]
mod tests {
    use crate::solver::{Case, Limits};

    #[test]
    fn every_example_case_parses() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                let text = std::fs::read_to_string(&path).unwrap();
                let case = Case::from_json(&text, &Limits::default())
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                assert!(
                    case.spec().label.is_some(),
                    "{} has no label",
                    path.display()
                );
                seen += 1;
            }
        }
        assert!(
            seen >= 7,
            "found only {seen} example cases in {}",
            dir.display()
        );
    }
}
