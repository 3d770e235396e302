//! `crush plan CASE.json [--target 5 | --budget 600]`: the ways to run a case, each with its
//! expected error and wall time, and the one to pick; the same answer as `POST /v1/plan`
//! (`--json` prints that JSON), with the wall times at the assumed rates (the CLI has no
//! finished jobs to calibrate on; `crush bench-plan` shows how far they are from measured).

use super::progress::clock;
use super::run::{read_case, thread_count};
use crate::solver::analysis::plan::{plan as solver_plan, Goal, PlanOption};
use crate::solver::analysis::rates::Rates;
use crate::solver::Limits;
use anyhow::bail;
use std::path::PathBuf;

/// Arguments of `crush plan`.
#[derive(Debug, Clone, clap::Args)]
pub struct PlanArgs {
    /// The crush case, as JSON (see examples/).
    pub case: PathBuf,
    /// The largest expected error of the mean load, % [default: 5 when no budget is given].
    #[arg(long, conflicts_with = "budget")]
    pub target: Option<f64>,
    /// The longest wall time, s: the most accurate run that fits.
    #[arg(long)]
    pub budget: Option<f64>,
    /// Solver threads the plan is for [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Leave out options with more tube particles than this.
    #[arg(long, default_value_t = Limits::default().max_particles)]
    pub max_particles: u64,
    /// Print the plan as the JSON `POST /v1/plan` answers.
    #[arg(long)]
    pub json: bool,
}

pub fn plan(args: PlanArgs) -> anyhow::Result<()> {
    let goal = match (args.target, args.budget) {
        (_, Some(b)) if !(b.is_finite() && b > 0.0) => {
            bail!("--budget must be a positive number of seconds")
        }
        (_, Some(b)) => Goal::BudgetS(b),
        (Some(t), _) if !(t.is_finite() && t > 0.0 && t <= 100.0) => {
            bail!("--target must be a percentage in (0, 100]")
        }
        (Some(t), _) => Goal::TargetErrorPercent(t),
        (None, None) => Goal::TargetErrorPercent(5.0),
    };
    let (case, source) = read_case(&args.case, args.max_particles)?;
    let threads = thread_count(args.threads)? as u32;
    let limits = Limits {
        max_particles: args.max_particles,
        ..Limits::unbounded()
    };
    let p = solver_plan(&case, goal, threads, &Rates::assumed(), &limits);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&p)?);
        return Ok(());
    }
    println!("{}", case.spec().label.as_deref().unwrap_or(&source));
    match &p.pick {
        Some(o) => println!("  pick: {}", line(o)),
        None => println!("  no pick"),
    }
    println!("  {}", p.reason);
    println!(
        "  options on {threads} thread{} (wall times at the assumed rates):",
        if threads == 1 { "" } else { "s" }
    );
    for o in &p.options {
        println!("    {}", line(o));
    }
    if p.refused > 0 {
        println!(
            "  {} more refused (--max-particles, or a check at that n)",
            p.refused
        );
    }
    println!("  errors: {}", p.error_basis);
    Ok(())
}

/// One option on a line: model, shape, n, expected error, wall time, what it shows.
fn line(o: &PlanOption) -> String {
    format!(
        "{} {} n = {}: {}, about {}; {}",
        o.model.name(),
        o.shape.name(),
        o.n,
        o.expected_error_percent
            .map_or_else(|| o.error_guide.clone(), |e| format!("±{e:.1} %")),
        clock(o.wall_time_s),
        o.shows
    )
}
