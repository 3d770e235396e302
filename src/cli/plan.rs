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
    for (i, o) in p.options.iter().enumerate() {
        let first = p.options[..i]
            .iter()
            .find(|e| same_guide(e, o))
            .map(|e| e.n);
        match first {
            Some(n) => println!("    {}", line_as_above(o, n)),
            None => println!("    {}", line(o)),
        }
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

/// Whether two options of one model and shape functions have no measured guide for the same
/// reason, which the listing then gives once.
fn same_guide(a: &PlanOption, b: &PlanOption) -> bool {
    a.model == b.model
        && a.shape == b.shape
        && a.expected_error_percent.is_none()
        && b.expected_error_percent.is_none()
        && a.error_guide == b.error_guide
}

/// An option whose reason for no guide the listing gave at n = `first` of the same model and
/// shape functions: the reason named, not repeated.
fn line_as_above(o: &PlanOption, first: u32) -> String {
    format!(
        "{} {} n = {}: no measured guide (as at n = {first}), about {}",
        o.model.name(),
        o.shape.name(),
        o.n,
        clock(o.wall_time_s),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::model::case::Case;

    /// On the d/t 14 tube every uGIMP option has no guide for one reason: the listing gives it
    /// once, at the first n, and names it at the others; the B-spline options keep their
    /// figures.
    #[test]
    fn options_without_a_guide_for_one_reason_give_it_once() {
        let text = std::fs::read_to_string("examples/axial_t3.2_d44.8.json").unwrap();
        let case = Case::from_json(&text, &Limits::unbounded()).unwrap();
        let limits = Limits::unbounded();
        let p = solver_plan(
            &case,
            Goal::TargetErrorPercent(5.0),
            2,
            &Rates::assumed(),
            &limits,
        );
        let gimp: Vec<_> = p
            .options
            .iter()
            .filter(|o| o.shape.name() == "gimp")
            .collect();
        assert!(gimp.len() >= 3, "{:?}", p.options);
        assert!(gimp[1..].iter().all(|o| same_guide(gimp[0], o)));
        let again = line_as_above(gimp[1], gimp[0].n);
        assert!(
            again.contains(&format!("as at n = {}", gimp[0].n)),
            "{again}"
        );
        assert!(again.len() * 3 < line(gimp[1]).len(), "{again}");
        let bspline = p
            .options
            .iter()
            .find(|o| o.shape.name() == "bspline")
            .unwrap();
        assert!(!p.options.iter().any(|o| same_guide(o, bspline)));
    }
}
