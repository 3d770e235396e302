//! `crush estimate CASE.json`: what the case will cost (particles, steps, memory, wall time, and
//! its error bar's ladder when it asks for one) and what its verdict can say before it runs,
//! without running it. The same answer as `POST /v1/estimate`; `--json` prints that JSON.

use super::args::EstimateArgs;
use super::progress::clock;
use super::run::{read_case, thread_count};
use crate::solver::estimate as solver_estimate;

pub fn estimate(args: EstimateArgs) -> anyhow::Result<()> {
    let (case, source) = read_case(&args.case, args.max_particles)?;
    let threads = thread_count(args.threads)?;
    let e = solver_estimate(&case, threads as u32);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&e)?);
        return Ok(());
    }
    println!("{}", case.spec().label.as_deref().unwrap_or(&source));
    println!(
        "  {} particles, {} cells, about {} steps, {:.0} MiB",
        e.particles,
        e.cells,
        e.steps,
        e.memory_bytes as f64 / (1u64 << 20) as f64
    );
    println!(
        "  roughly {} wall time on {} thread{}",
        clock(e.wall_time_s),
        e.threads,
        if e.threads == 1 { "" } else { "s" }
    );
    match &e.shape.default_reason {
        Some(why) => println!("  shape functions {why}"),
        None => println!("  shape functions {}", e.shape.kind.name()),
    }
    match &e.cfl_default_reason {
        Some(why) => println!("  time step: CFL {why}"),
        None => println!("  time step: CFL {}", e.cfl),
    }
    if let Some(t) = e.error_bar_wall_time_s {
        println!("  error bar: its ladder roughly {} more", clock(t));
    }
    if let Some(r) = &e.reduced {
        println!(
            "  discretization.model \"{}\" would run it in about {}, {:.0}x less; it cannot show {}",
            r.model.name(),
            clock(r.wall_time_s),
            r.speedup,
            r.cannot_show
        );
    }
    println!("  verdict before it runs: {}", e.verdict.level.name());
    for reason in &e.verdict.reasons {
        println!(
            "    {} ({}): {}",
            reason.level.name(),
            reason.rule.name(),
            reason.detail
        );
    }
    Ok(())
}
