//! `crush study convergence CASE`: the case at several resolutions (and shape functions); the
//! error of mean and peak load against the finest run and a Richardson estimate, against run
//! time; the load curves overlaid.

use super::cases::{
    pct, plot_load_curves, read_case, run_case, set, threads, write_extrapolations, write_report,
    Failed,
};
use crate::plot::{self, Series};
use crate::solver::CollapseMode;
use crate::study::convergence::{analyse, GroupAnalysis, RunPoint, TRUSTED_ORDERS};
use crate::study::Figures;
use anyhow::Context;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Debug, Clone, clap::Args)]
pub struct ConvergenceArgs {
    /// The crush case, as JSON.
    pub case: PathBuf,
    /// Particles through the wall, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "2,3,4,6")]
    pub n: Vec<u32>,
    /// Shape functions, comma-separated (linear, gimp, bspline).
    #[arg(long, value_delimiter = ',', default_value = "gimp")]
    pub shape: Vec<String>,
    /// Relative error of the mean load the summary reads off the cheapest run for.
    #[arg(long, default_value_t = 0.05)]
    pub tolerance: f64,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Where report.md, convergence.csv and the plots go.
    #[arg(long, default_value = "study/convergence")]
    pub out: PathBuf,
}

pub fn run(args: ConvergenceArgs) -> anyhow::Result<()> {
    let base = read_case(&args.case)?;
    let threads = threads(args.threads)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let mut points = Vec::new();
    let mut extra: Vec<(String, u32, u32, String)> = Vec::new();
    let mut curves = Vec::new();
    let mut failures = Vec::new();
    for shape in &args.shape {
        for &n in &args.n {
            let mut case = base.clone();
            set(
                &mut case,
                "discretization.particles_through_thickness",
                n.into(),
            )?;
            set(&mut case, "discretization.shape", shape.as_str().into())?;
            let name = format!("{shape} n={n}");
            match run_case(&name, &case, threads)? {
                Ok(done) => {
                    let s = &done.summary;
                    points.push(RunPoint::of(shape.clone(), n, &Figures::of(s)));
                    extra.push((shape.clone(), n, s.folds, mode_name(&s.mode)));
                    curves.push(done.load_curve(name.clone()));
                }
                Err(Failed::Rejected(e)) => anyhow::bail!("{name}: the case was rejected: {e}"),
                Err(Failed::Stopped(e)) => failures.push(format!("{name}: {e}")),
            }
        }
    }
    let groups = analyse(&points);
    write_csv(&args.out.join("convergence.csv"), &groups, &extra)?;
    plot_errors(&args.out, &groups)?;
    plot_load_curves(&args.out, &curves)?;
    let report = report(&args, &groups, &extra, &failures);
    write_report(&args.out, &report)
}

fn mode_name(m: &CollapseMode) -> String {
    match m {
        CollapseMode::Ring => "ring".into(),
        CollapseMode::Diamond { lobes } => format!("diamond {lobes}"),
        CollapseMode::GlobalBuckling => "global".into(),
        CollapseMode::Flattening => "flattening".into(),
        CollapseMode::TippedOver => "tipped over".into(),
        other => other.kind().replace('_', " "),
    }
}

fn lookup<'a>(extra: &'a [(String, u32, u32, String)], g: &str, n: u32) -> (u32, &'a str) {
    extra
        .iter()
        .find(|e| e.0 == g && e.1 == n)
        .map_or((0, "?"), |e| (e.2, e.3.as_str()))
}

fn report(
    args: &ConvergenceArgs,
    groups: &[GroupAnalysis],
    extra: &[(String, u32, u32, String)],
    failures: &[String],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Convergence: {}\n", args.case.display());
    let _ = writeln!(
        s,
        "Errors are relative, (value − target) / target. h = 1/n. The Richardson estimate fits \
         f(h) = f* + C·hᵖ through the three finest runs of a shape; it is used only when the \
         three values converge monotonically and the observed order p lies in [{}, {}] \
         (otherwise the errors against it are left blank).\n",
        TRUSTED_ORDERS.0, TRUSTED_ORDERS.1
    );
    for g in groups {
        let _ = writeln!(s, "## {}\n", g.group);
        let _ = writeln!(
            s,
            "| n | particles | steps | wall s | M p-steps/s | mean kN | peak kN | folds | mode | \
             mean err vs finest | peak err vs finest | mean err vs Richardson | peak err vs \
             Richardson | mean vs reference |"
        );
        let _ = writeln!(
            s,
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        );
        for r in &g.rows {
            let p = &r.run;
            let (folds, mode) = lookup(extra, &g.group, p.n);
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.1} | {:.2} | {:.3} | {:.3} | {} | {} | {} | {} | {} | {} | {} |",
                p.n,
                p.particles,
                p.steps,
                p.wall_time_s,
                p.particles as f64 * p.steps as f64 / p.wall_time_s / 1e6,
                p.mean_load_n / 1e3,
                p.peak_load_n / 1e3,
                folds,
                mode,
                pct(Some(r.mean_error_vs_finest)),
                pct(Some(r.peak_error_vs_finest)),
                pct(r.mean_error_vs_richardson),
                pct(r.peak_error_vs_richardson),
                pct(r.mean_vs_reference),
            );
        }
        write_extrapolations(
            &mut s,
            "resolutions",
            [
                ("mean", g.mean_extrapolation),
                ("peak", g.peak_extrapolation),
            ],
        );
        let tol = args.tolerance;
        let _ = match g.cheapest_within(tol) {
            Some(r) => writeln!(
                s,
                "\n**For {:.0} % error in the mean load: n = {}, {:.0} s** on {} ({}).\n",
                100.0 * tol,
                r.run.n,
                r.run.wall_time_s,
                threads_note(),
                if g.mean_extrapolation.is_some_and(|e| e.trustworthy) {
                    "against the Richardson estimate"
                } else {
                    "against the finest run, no trusted extrapolation"
                }
            ),
            None => writeln!(
                s,
                "\n**No run but the finest is within {:.0} % in mean load**: refine further.\n",
                100.0 * tol
            ),
        };
    }
    if !failures.is_empty() {
        let _ = writeln!(s, "## Runs that stopped\n");
        for f in failures {
            let _ = writeln!(s, "- {f}");
        }
    }
    let _ = writeln!(
        s,
        "\nPlots: error_vs_time.svg/.png (|mean-load error| against wall time, log–log), \
         load_curves.svg/.png."
    );
    s
}

fn threads_note() -> String {
    format!("this machine ({} cores)", crate::solver::cores())
}

fn write_csv(
    path: &PathBuf,
    groups: &[GroupAnalysis],
    extra: &[(String, u32, u32, String)],
) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record([
        "shape",
        "n",
        "particles",
        "steps",
        "wall_time_s",
        "mean_load_n",
        "peak_load_n",
        "folds",
        "mode",
        "mean_error_vs_finest",
        "peak_error_vs_finest",
        "mean_error_vs_richardson",
        "peak_error_vs_richardson",
        "mean_vs_reference",
    ])?;
    let opt = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x:.6}"));
    for g in groups {
        for r in &g.rows {
            let p = &r.run;
            let (folds, mode) = lookup(extra, &g.group, p.n);
            w.write_record([
                g.group.clone(),
                p.n.to_string(),
                p.particles.to_string(),
                p.steps.to_string(),
                format!("{:.3}", p.wall_time_s),
                format!("{:.3}", p.mean_load_n),
                format!("{:.3}", p.peak_load_n),
                folds.to_string(),
                mode.to_string(),
                format!("{:.6}", r.mean_error_vs_finest),
                format!("{:.6}", r.peak_error_vs_finest),
                opt(r.mean_error_vs_richardson),
                opt(r.peak_error_vs_richardson),
                opt(r.mean_vs_reference),
            ])?;
        }
    }
    w.flush()?;
    Ok(())
}

/// |mean-load error| against wall time per shape, and the same for the peak load: against
/// the Richardson estimate when trusted, else against the finest run (which is then left out).
fn plot_errors(out: &std::path::Path, groups: &[GroupAnalysis]) -> anyhow::Result<()> {
    let mut series = Vec::new();
    for g in groups {
        for (what, trusted) in [
            ("mean", g.mean_extrapolation.is_some_and(|e| e.trustworthy)),
            ("peak", g.peak_extrapolation.is_some_and(|e| e.trustworthy)),
        ] {
            let points: Vec<(f64, f64)> = g
                .rows
                .iter()
                .filter_map(|r| {
                    let e = match (what, trusted) {
                        ("mean", true) => r.mean_error_vs_richardson?,
                        ("mean", false) => r.mean_error_vs_finest,
                        (_, true) => r.peak_error_vs_richardson?,
                        _ => r.peak_error_vs_finest,
                    };
                    (e != 0.0).then_some((r.run.wall_time_s, e.abs()))
                })
                .collect();
            if !points.is_empty() {
                let against = if trusted { "Richardson" } else { "finest" };
                series.push(Series {
                    name: format!("{} {what} load vs {against}", g.group),
                    points,
                });
            }
        }
    }
    plot::lines(
        &out.join("error_vs_time"),
        (
            "Error against run time",
            "wall time, s",
            "|relative error| of the load",
        ),
        &series,
        true,
    )
}
