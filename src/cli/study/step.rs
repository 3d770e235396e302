//! `crush study step CASE`: the case at several time steps (`discretization.cfl`), everything
//! else the same; the error of the mean and first-peak load against the smallest step and a
//! Richardson value at Δt → 0, the energy books at each step, against run time.

use super::cases::{
    pct, plot_load_curves, read_case, run_case, set, threads, write_extrapolations, write_report,
    Failed,
};
use crate::plot::{self, Series};
use crate::study::ensemble::mode_label;
use crate::study::step::{StepAnalysis, StepPoint, STEP_FIELD};
use crate::study::Figures;
use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The books' share a sound run stays within (the verdict's energy limit).
const BOOKS_LIMIT: f64 = crate::solver::analysis::verdict::BALANCE_CAUTION;

#[derive(Debug, Clone, clap::Args)]
pub struct StepArgs {
    /// The crush case, as JSON.
    pub case: PathBuf,
    /// CFL numbers α (Δt = α · cell / (c + |v|)), comma-separated, each in (0, 1].
    #[arg(long, value_delimiter = ',', default_value = "0.5,0.25,0.125")]
    pub cfl: Vec<f64>,
    /// Relative error of the mean load the summary reads off the cheapest step for.
    #[arg(long, default_value_t = 0.02)]
    pub tolerance: f64,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Where report.md, step.csv and the plots go.
    #[arg(long, default_value = "study/step")]
    pub out: PathBuf,
}

pub fn run(args: StepArgs) -> anyhow::Result<()> {
    if let Some(bad) = args.cfl.iter().find(|a| !(**a > 0.0 && **a <= 1.0)) {
        anyhow::bail!("--cfl {bad}: each CFL number must lie in (0, 1]");
    }
    let base = read_case(&args.case)?;
    let threads = threads(args.threads)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let (mut points, mut curves, mut stopped) = (Vec::new(), Vec::new(), Vec::new());
    for &cfl in &args.cfl {
        let mut case = base.clone();
        set(&mut case, STEP_FIELD, cfl.into())?;
        let name = format!("cfl {cfl}");
        match run_case(&name, &case, threads)? {
            Ok(done) => {
                points.push(StepPoint::of(cfl, &Figures::of(&done.summary)));
                curves.push(done.load_curve(name));
            }
            Err(Failed::Rejected(e)) => anyhow::bail!("{name}: the case was rejected: {e}"),
            Err(Failed::Stopped(e)) => stopped.push(format!("{name}: {e}")),
        }
    }
    plot_load_curves(&args.out, &curves)?;
    let analysis = StepAnalysis::of(&points);
    if let Some(a) = &analysis {
        write_csv(&args.out.join("step.csv"), a)?;
        plot_errors(&args.out, a)?;
    }
    let report = report(&args, analysis.as_ref(), &stopped);
    write_report(&args.out, &report)
}

fn report(args: &StepArgs, a: Option<&StepAnalysis>, stopped: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Time-step study: {}\n", args.case.display());
    let _ = writeln!(
        s,
        "Each run is the case with `discretization.cfl` = α (Δt = α · cell / (c + |v|)), \
         nothing else changed. Errors are relative, (value − target) / target. The Richardson \
         estimate fits f(α) = f* + C·αᵖ through the three smallest steps and is used only when \
         they converge monotonically with p in [0.5, 4]; otherwise the errors are against the \
         smallest step. The energy balance is the books' largest unexplained share of the \
         plates' work over the run.\n"
    );
    let Some(a) = a else {
        let _ = writeln!(s, "No run finished.");
        return with_stopped(s, stopped);
    };
    let _ = writeln!(
        s,
        "| α | steps | wall s | mean kN | mean err vs smallest step | mean err vs Richardson | \
         first peak kN | first peak err vs smallest step | mode | folds | energy balance |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &a.rows {
        let p = &r.run;
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.3} | {} | {} | {} | {} | {} | {} | {:.2} % |",
            p.cfl,
            p.steps,
            p.wall_time_s,
            p.mean_load_n / 1e3,
            pct(Some(r.mean_error_vs_finest)),
            pct(r.mean_error_vs_richardson),
            p.first_peak_n
                .map_or("–".into(), |v| format!("{:.3}", v / 1e3)),
            pct(r.first_peak_error_vs_finest),
            mode_label(&p.mode),
            p.folds,
            100.0 * p.energy_balance_error,
        );
    }
    write_extrapolations(
        &mut s,
        "steps",
        [
            ("mean", a.mean_extrapolation),
            ("first peak", a.first_peak_extrapolation),
        ],
    );
    let tol = args.tolerance;
    let _ = match a.cheapest_within(tol) {
        Some(r) => writeln!(
            s,
            "\n**For {:.0} % error in the mean load: α = {}, {:.1} s** ({}).",
            100.0 * tol,
            r.run.cfl,
            r.run.wall_time_s,
            if a.trusted() {
                "against the Richardson estimate"
            } else {
                "against the smallest step, no trusted extrapolation"
            }
        ),
        None => writeln!(
            s,
            "\n**No step but the smallest is within {:.0} % in mean load**: take smaller steps.",
            100.0 * tol
        ),
    };
    let _ = match a.books_within(BOOKS_LIMIT) {
        Some(r) => writeln!(
            s,
            "\nThe books close within {:.0} % from α = {} down.",
            100.0 * BOOKS_LIMIT,
            r.run.cfl
        ),
        None => writeln!(
            s,
            "\nThe books do not close within {:.0} % at any step run here.",
            100.0 * BOOKS_LIMIT
        ),
    };
    let _ = writeln!(
        s,
        "\nPlots: error_vs_time.svg/.png (|mean-load error| against wall time, log–log), \
         load_curves.svg/.png."
    );
    with_stopped(s, stopped)
}

fn with_stopped(mut s: String, stopped: &[String]) -> String {
    if !stopped.is_empty() {
        let _ = writeln!(s, "\n## Runs that stopped\n");
        for f in stopped {
            let _ = writeln!(s, "- {f}");
        }
    }
    s
}

fn write_csv(path: &Path, a: &StepAnalysis) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record([
        "cfl",
        "steps",
        "wall_time_s",
        "mean_load_n",
        "mean_error_vs_smallest_step",
        "mean_error_vs_richardson",
        "first_peak_load_n",
        "first_peak_error_vs_smallest_step",
        "mode",
        "folds",
        "energy_balance_error",
    ])?;
    let opt = |x: Option<f64>, digits: usize| x.map_or(String::new(), |x| format!("{x:.digits$}"));
    for r in &a.rows {
        let p = &r.run;
        w.write_record([
            p.cfl.to_string(),
            p.steps.to_string(),
            format!("{:.3}", p.wall_time_s),
            format!("{:.3}", p.mean_load_n),
            format!("{:.6}", r.mean_error_vs_finest),
            opt(r.mean_error_vs_richardson, 6),
            opt(p.first_peak_n, 3),
            opt(r.first_peak_error_vs_finest, 6),
            mode_label(&p.mode),
            p.folds.to_string(),
            format!("{:.6}", p.energy_balance_error),
        ])?;
    }
    w.flush()?;
    Ok(())
}

/// |mean-load error| and the books against wall time: the mean against the Richardson value
/// when trusted, else against the smallest step (which is then left out).
fn plot_errors(out: &Path, a: &StepAnalysis) -> anyhow::Result<()> {
    let trusted = a.trusted();
    let mean: Vec<(f64, f64)> = a
        .rows
        .iter()
        .filter_map(|r| {
            let e = if trusted {
                r.mean_error_vs_richardson?
            } else {
                r.mean_error_vs_finest
            };
            (e != 0.0).then_some((r.run.wall_time_s, e.abs()))
        })
        .collect();
    let books: Vec<(f64, f64)> = a
        .rows
        .iter()
        .filter(|r| r.run.energy_balance_error > 0.0)
        .map(|r| (r.run.wall_time_s, r.run.energy_balance_error))
        .collect();
    let against = if trusted {
        "Richardson"
    } else {
        "smallest step"
    };
    let series: Vec<Series> = [
        (format!("mean load vs {against}"), mean),
        ("energy balance".to_string(), books),
    ]
    .into_iter()
    .filter(|(_, p)| !p.is_empty())
    .map(|(name, points)| Series { name, points })
    .collect();
    plot::lines(
        &out.join("error_vs_time"),
        (
            "Time-step error against run time",
            "wall time, s",
            "|relative error|",
        ),
        &series,
        true,
    )
}
