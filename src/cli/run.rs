//! `crush run CASE.json`: parse the case, run it on its own rayon pool with a progress bar,
//! stop cleanly on Ctrl-C, print the summary and write the files the server gives for a job
//! (`cli/output.rs`, and the time series in `cli/series.rs`).
//!
//! What it prints and writes is the solver's own summary and mode detail: one source.

use super::args::RunArgs;
use super::output::{
    write_energy_svg, write_history_csv, write_load_svg, write_particles_csv, write_shape_png,
    write_state_vtu, write_summary_json, SummaryFile,
};
use super::progress::{clock, BarObserver};
use super::report::{format_case_error, format_report};
use super::series::{RunObserver, SeriesFiles};
use crate::solver::analysis::error_bar::{self, Climb};
use crate::solver::model::step_policy::DEFAULT_CFL;
use crate::solver::{cores, estimate, Case, Limits, Runner, SolveError};
use anyhow::{bail, Context};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// The case file at `path`, checked (no limit but `max_particles`), with its name for messages;
/// a rejected case prints every field and why.
pub fn read_case(path: &Path, max_particles: u64) -> anyhow::Result<(Case, String)> {
    let limits = Limits {
        max_particles,
        ..Limits::unbounded()
    };
    read_case_within(path, &limits, None)
}

/// The case file at `path`, checked against `limits`; a rejected case prints every field and
/// why, and `past_limits` after them when the limits alone refuse it (it parses without them).
fn read_case_within(
    path: &Path,
    limits: &Limits,
    past_limits: Option<&str>,
) -> anyhow::Result<(Case, String)> {
    let source = path.display().to_string();
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {source}"))?;
    match Case::from_json(&text, limits) {
        Ok(case) => Ok((case, source)),
        Err(e) => {
            eprintln!("{}", format_case_error(&source, &e));
            match past_limits {
                Some(hint) if Case::from_json(&text, &Limits::unbounded()).is_ok() => {
                    eprintln!("{hint}");
                    bail!("{source} is past the cost limits");
                }
                _ => bail!("{source} was rejected"),
            }
        }
    }
}

/// What `crush run` holds a case to: the server's default cost limits, or with `--no-limits`
/// none; `--max-particles` either way.
fn run_limits(args: &RunArgs) -> Limits {
    let base = match args.no_limits {
        true => Limits::unbounded(),
        false => Limits::default(),
    };
    Limits {
        max_particles: args.max_particles.unwrap_or(base.max_particles),
        ..base
    }
}

/// `--threads`, or every core.
pub fn thread_count(threads: Option<usize>) -> anyhow::Result<usize> {
    match threads {
        Some(0) => bail!("--threads must be at least 1"),
        Some(n) => Ok(n),
        None => Ok(cores()),
    }
}

pub fn run(args: RunArgs) -> anyhow::Result<()> {
    let limits = run_limits(&args);
    let hint = format!(
        "  past the cost limits (at most {} particles, {} time steps, {:.0e} particle-steps: \
         `crush serve`'s defaults): check the field named first, or pass --no-limits to run it \
         anyway",
        limits.max_particles, limits.max_steps, limits.max_particle_steps as f64
    );
    let past_limits = (!args.no_limits).then_some(hint.as_str());
    let (case, source) = read_case_within(&args.case, &limits, past_limits)?;
    let threads = thread_count(args.threads)?;
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&args.case));
    std::fs::create_dir_all(&out_dir).with_context(|| format!("creating {}", out_dir.display()))?;

    let guess = estimate(&case, threads as u32);
    eprintln!(
        "{}: {} shapes, {} particles, about {} steps, {} threads, roughly {} wall time",
        case.spec().label.as_deref().unwrap_or(&source),
        case.shape().name(),
        guess.particles,
        guess.steps,
        threads,
        clock(guess.wall_time_s)
    );
    if let Some(why) = &guess.shape.default_reason {
        eprintln!("  (shape functions {why})");
    }
    if let (Some(why), true) = (&guess.cfl_default_reason, guess.cfl != DEFAULT_CFL) {
        eprintln!("  (time step: CFL {why})");
    }
    if let Some(r) = &guess.reduced {
        eprintln!(
            "  (discretization.model \"{}\" would run it in about {}, {:.0}x less; it cannot show {})",
            r.model.name(),
            clock(r.wall_time_s),
            r.speedup,
            r.cannot_show
        );
    }

    let cancel = Arc::new(AtomicBool::new(false));
    install_ctrl_c(cancel.clone());
    let runner = Runner::new(threads, |i| format!("crush-{i}"))
        .context("starting the solver's thread pool")?;
    let mut observer = RunObserver {
        bar: BarObserver::new(),
        series: SeriesFiles::new(&out_dir, &case)?,
    };
    let result = runner.run(&case, &mut observer, &cancel);
    observer.bar.bar().finish_and_clear();
    // The frames reached, whether the run ended or stopped.
    let series = observer.series.take().map(SeriesFiles::finish).transpose();

    let history_path = out_dir.join("history.csv");
    let result = result.and_then(|mut output| {
        if args.error_bar {
            let rungs = match error_bar::ladder(&case, output.summary.mode) {
                Ok(error_bar::Rungs {
                    climb: Climb::ThreeD { .. },
                    rungs,
                }) => {
                    let n: Vec<String> = rungs.iter().map(|(n, _)| n.to_string()).collect();
                    format!("this case in 3D at n = {}", n.join(", "))
                }
                _ => "its section at three resolutions".into(),
            };
            eprintln!("pricing the mean load's error bar ({rungs})");
            runner.add_error_bar(&case, &mut output, &mut (), &cancel)?;
        } else {
            runner.add_error_bar_if_asked(&case, &mut output, &mut (), &cancel)?;
        }
        Ok(output)
    });
    let output = match result {
        Ok(output) => output,
        Err(e) => {
            // Keep what was computed: the rows reported before the run stopped.
            write_history_csv(&history_path, &observer.bar.rows)?;
            eprintln!(
                "partial history ({} rows) in {}",
                observer.bar.rows.len(),
                history_path.display()
            );
            match series {
                Ok(Some((path, frames))) => {
                    eprintln!("partial series ({frames} frames) in {}", path.display())
                }
                Ok(None) => {}
                Err(why) => eprintln!("no series: {why:#}"),
            }
            return Err(match e {
                SolveError::Cancelled { step } => anyhow::anyhow!("cancelled at step {step}"),
                other => anyhow::Error::new(other).context(format!("{source} failed")),
            });
        }
    };

    print!(
        "{}",
        format_report(&case, &output.summary, &output.mode_detail)
    );

    write_history_csv(&history_path, &output.history)?;
    let load_path = out_dir.join("load.svg");
    write_load_svg(&load_path, &case, &output)?;
    let energy_path = out_dir.join("energy.svg");
    write_energy_svg(&energy_path, &case, &output.history)?;
    let summary_path = out_dir.join("summary.json");
    let file = SummaryFile {
        label: case.spec().label.clone(),
        summary: output.summary.clone(),
        mode_detail: output.mode_detail.clone(),
    };
    write_summary_json(&summary_path, &file)?;
    let mut written = vec![history_path, load_path, energy_path, summary_path];
    if case.spec().output.final_state {
        let particles_path = out_dir.join("particles.csv");
        write_particles_csv(&particles_path, &output.snapshot)?;
        let state_path = out_dir.join("state.vtu");
        write_state_vtu(&state_path, &case, &output.snapshot)?;
        let shape_path = out_dir.join("shape.png");
        write_shape_png(&shape_path, &case, &output.snapshot)?;
        written.extend([particles_path, state_path, shape_path]);
    }
    if let Some((path, _)) = series? {
        written.extend([path, out_dir.join("frames")]);
    }
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    eprintln!("wrote {}", names.join(", "));
    Ok(())
}

/// `out/<case file stem>`.
fn default_out_dir(case: &Path) -> PathBuf {
    let stem = case
        .file_stem()
        .map_or_else(|| "case".into(), |s| s.to_string_lossy().into_owned());
    Path::new("out").join(stem)
}

/// First Ctrl-C: ask the solver to stop after its current step. Second: quit at once.
fn install_ctrl_c(cancel: Arc<AtomicBool>) {
    let presses = AtomicUsize::new(0);
    let installed = ctrlc::set_handler(move || {
        if presses.fetch_add(1, Ordering::SeqCst) == 0 {
            cancel.store(true, Ordering::SeqCst);
            eprintln!("\nstopping after this step (Ctrl-C again to quit at once)");
        } else {
            std::process::exit(130);
        }
    });
    if let Err(e) = installed {
        eprintln!("warning: Ctrl-C will not stop the run cleanly: {e}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_defaults_to_out_and_the_case_stem() {
        assert_eq!(
            default_out_dir(Path::new("examples/axial_t3.2.json")),
            Path::new("out/axial_t3.2")
        );
        assert_eq!(
            default_out_dir(Path::new("lateral")),
            Path::new("out/lateral")
        );
    }
}
