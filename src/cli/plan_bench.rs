//! `crush bench-plan CASE.json…`: the wall-time guesses against measured runs. For each case in
//! turn, a calibration run of the same case at one particle fewer through the wall (a job of
//! the same model and shape functions the server would have finished before), then the guess —
//! at the assumed rates, and calibrated on every run so far as the server calibrates on its
//! finished jobs — then the case's own run; a table of guessed against measured wall time.

use super::progress::clock;
use super::run::{read_case, thread_count};
use crate::solver::analysis::rates::{LawKind, RateSample, Rates};
use crate::solver::{estimate_with, Case, Limits, Runner};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// Arguments of `crush bench-plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchPlanArgs {
    /// The crush cases, as JSON (see examples/).
    #[arg(required = true)]
    pub cases: Vec<PathBuf>,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
}

pub fn bench_plan(args: BenchPlanArgs) -> anyhow::Result<()> {
    let threads = thread_count(args.threads)?;
    let runner = Runner::new(threads, |i| format!("crush-bench-plan-{i}"))?;
    // Newest first, as the store answers.
    let mut samples: Vec<RateSample> = Vec::new();
    println!(
        "| case | model | shape | n | particles | calibration run (n, s) | assumed guess s | \
         calibrated guess s | measured s | calibrated / measured |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for path in &args.cases {
        let (case, source) = read_case(path, Limits::unbounded().max_particles)?;
        let n = case.spec().discretization.particles_through_thickness;
        let mut before = case.spec().clone();
        before.discretization.particles_through_thickness = (n - 1).max(1);
        let before = Case::parse(before, &Limits::unbounded())
            .map_err(|e| anyhow::anyhow!("{source} at n = {}: {e}", (n - 1).max(1)))?;
        let calibration_s = measure(&runner, &before, &mut samples)?;
        let assumed = estimate_with(&case, threads as u32, &Rates::assumed());
        let calibrated = estimate_with(&case, threads as u32, &Rates::calibrated(&samples));
        let measured_s = measure(&runner, &case, &mut samples)?;
        let name = path
            .file_name()
            .map_or(source.clone(), |f| f.to_string_lossy().into());
        println!(
            "| {name} | {} | {} | {n} | {} | {}, {calibration_s:.1} | {:.1} | {:.1} | {measured_s:.1} ({}) | {:.2} |",
            case.spec().discretization.model.name(),
            case.shape().name(),
            assumed.particles,
            (n - 1).max(1),
            assumed.wall_time_s,
            calibrated.wall_time_s,
            clock(measured_s),
            calibrated.wall_time_s / measured_s,
        );
    }
    Ok(())
}

/// Runs `case` and adds its rate to `samples` (newest first, as the store answers); its wall
/// time, s.
fn measure(runner: &Runner, case: &Case, samples: &mut Vec<RateSample>) -> anyhow::Result<f64> {
    let out = runner.run(case, &mut (), &AtomicBool::new(false))?;
    let cost = &out.summary.cost;
    samples.insert(
        0,
        RateSample {
            model: case.spec().discretization.model,
            shape: case.shape(),
            law: LawKind::of(&case.spec().material),
            particles: cost.particles,
            steps: cost.steps,
            wall_time_s: cost.wall_time_s,
            threads: cost.threads,
        },
    );
    Ok(cost.wall_time_s)
}
