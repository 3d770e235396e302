//! `crush bench`: solver throughput in particle-steps per second, time per phase and peak
//! memory per particle, for a case at several resolutions, shape functions and thread counts.
//!
//! Every measurement runs in a child process (`crush bench-one`, hidden), so that its peak
//! resident memory is its own and one run's allocations do not warm the next. A run takes a
//! few untimed warm-up steps (first-touch page faults, grid growth) and then a fixed number of
//! timed steps of the case's initial state, or, with `--crushed-mm`, of the tube after that
//! much crush (untimed): a folding tube costs more than its initial state (more blocks, and
//! uGIMP stencils that reach more nodes). The parent repeats each configuration, reports
//! medians, and writes `bench.csv` (every run) and `bench.svg` / `bench.png` (time per
//! particle-step against particle count).

use crate::plot::{self, Series};
use crate::solver::engine::scene::Scene;
use crate::solver::engine::{simulate, Driver, Engine, PhaseTimes};
use crate::solver::{Case, Limits, Real, Runner};
use anyhow::{bail, Context};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::Instant;

/// The default case: the axial PVC tube of the design page (t 3.2 mm, d 22.2 mm).
const DEFAULT_CASE: &str = include_str!("../../examples/axial_t3.2.json");

/// Arguments of `crush bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// The case to time [default: examples/axial_t3.2.json, built in].
    pub case: Option<PathBuf>,
    /// Particles through the wall, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "2,4,6,8,10")]
    pub n: Vec<u32>,
    /// Shape functions, comma-separated (linear, gimp, bspline).
    #[arg(long, value_delimiter = ',', default_value = "linear,gimp")]
    pub shape: Vec<String>,
    /// Thread counts, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
    /// Timed steps per run (after 3 untimed warm-up steps).
    #[arg(long, default_value_t = 30)]
    pub steps: u64,
    /// Crush the tube this far (mm, untimed) before the timed steps; 0 times its initial state.
    #[arg(long, default_value_t = 0.0)]
    pub crushed_mm: f64,
    /// Runs per configuration; the report gives their median.
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Where bench.csv, bench.svg and bench.png go.
    #[arg(long, default_value = "bench")]
    pub out: PathBuf,
}

/// Arguments of the hidden `crush bench-one`: one timed run of the case JSON on stdin.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchOneArgs {
    #[arg(long)]
    pub threads: usize,
    #[arg(long)]
    pub steps: u64,
    #[arg(long, default_value_t = 0.0)]
    pub crushed_mm: f64,
}

/// What one run measured.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Sample {
    pub particles: usize,
    pub steps: u64,
    pub wall_s: f64,
    pub phases: PhaseTimes,
    /// Peak resident memory of the process over the run, and its resident memory before the
    /// scene was built, bytes (None where /proc is not available).
    pub peak_rss: Option<u64>,
    pub base_rss: Option<u64>,
    /// Bytes the solver's arrays hold at the end (capacity), by its own count.
    pub accounted: usize,
}

impl Sample {
    fn rate(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.wall_s
    }
    /// Peak memory above the process's baseline, per particle.
    fn bytes_per_particle(&self) -> Option<f64> {
        Some((self.peak_rss? - self.base_rss?) as f64 / self.particles as f64)
    }
}

/// `crush bench-one`: reads a case from stdin, runs it, prints one JSON `Sample` on stdout.
pub fn bench_one(args: BenchOneArgs) -> anyhow::Result<()> {
    let mut text = String::new();
    std::io::stdin().read_to_string(&mut text)?;
    let limits = Limits::unbounded();
    let case = Case::from_json(&text, &limits).map_err(|e| anyhow::anyhow!("{e}"))?;
    let runner = Runner::new(args.threads, |i| format!("crush-bench-{i}"))?;
    let base_rss = rss_kib("VmRSS:").map(|k| k * 1024);
    let timing = Timing {
        steps: args.steps,
        base_rss,
        crushed_mm: args.crushed_mm,
        speed: case.spec().loading.plate_speed_m_s,
    };
    let model = case.spec().discretization.model;
    let sample =
        runner.install(|| simulate(model, case.shape(), Scene::from_case(&case), timing))?;
    println!("{}", serde_json::to_string(&sample)?);
    Ok(())
}

/// The timed part of `crush bench-one`, for whichever shape function the case chose.
struct Timing {
    steps: u64,
    base_rss: Option<u64>,
    /// Untimed crush before the timed steps, mm, at plate speed `speed` (mm/ms).
    crushed_mm: f64,
    speed: f64,
}

impl Driver for Timing {
    type Output = anyhow::Result<Sample>;

    fn drive<E: Engine>(self, mut sim: E) -> Self::Output {
        for _ in 0..3 {
            sim.step(Real::INFINITY)?;
        }
        let ramp = sim.scene().ramp;
        while self.speed * ramp.full_speed_time(sim.time()) < self.crushed_mm {
            sim.step(Real::INFINITY)?;
        }
        let warm = *sim.phases();
        let start = Instant::now();
        for _ in 0..self.steps {
            sim.step(Real::INFINITY)?;
        }
        let wall_s = start.elapsed().as_secs_f64();
        Ok(Sample {
            particles: sim.scene().particles.len(),
            steps: self.steps,
            wall_s,
            phases: minus(sim.phases(), &warm),
            peak_rss: rss_kib("VmHWM:").map(|k| k * 1024),
            base_rss: self.base_rss,
            accounted: sim.bytes(),
        })
    }
}

fn minus(a: &PhaseTimes, b: &PhaseTimes) -> PhaseTimes {
    PhaseTimes {
        bin: a.bin - b.bin,
        p2g: a.p2g - b.p2g,
        grid: a.grid - b.grid,
        g2p: a.g2p - b.g2p,
        stress: a.stress - b.stress,
    }
}

/// A `Vm…:` line of /proc/self/status, KiB.
fn rss_kib(key: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// One configuration: its runs and their median.
struct Row {
    shape: String,
    n: u32,
    threads: usize,
    samples: Vec<Sample>,
}

impl Row {
    fn median_by(&self, f: impl Fn(&Sample) -> f64) -> f64 {
        let mut v: Vec<f64> = self.samples.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        let m = v.len() / 2;
        if v.len() % 2 == 1 {
            v[m]
        } else {
            0.5 * (v[m - 1] + v[m])
        }
    }
}

pub fn bench(args: BenchArgs) -> anyhow::Result<()> {
    if args.repeats == 0 || args.steps == 0 {
        bail!("--repeats and --steps must be at least 1");
    }
    if !(args.crushed_mm >= 0.0 && args.crushed_mm.is_finite()) {
        bail!("--crushed-mm must be a distance of 0 mm or more");
    }
    if let Some(t) = args.threads.iter().find(|&&t| t == 0) {
        bail!("--threads {t}: a run needs at least one thread");
    }
    let text = match &args.case {
        Some(path) => {
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?
        }
        None => DEFAULT_CASE.to_string(),
    };
    let base: Value = serde_json::from_str(&text).context("the case is not JSON")?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let exe = std::env::current_exe()?;
    let mut rows = Vec::new();
    for shape in &args.shape {
        for &n in &args.n {
            let mut case = base.clone();
            case["discretization"]["particles_through_thickness"] = n.into();
            case["discretization"]["shape"] = shape.as_str().into();
            let json = serde_json::to_string(&case)?;
            // Parse here too, so a bad shape or n is reported before anything runs.
            let parsed = Case::from_json(&json, &Limits::unbounded())
                .map_err(|e| anyhow::anyhow!("shape {shape}, n {n}: {e}"))?;
            if args.crushed_mm >= parsed.crush_distance_mm() {
                bail!(
                    "--crushed-mm {} is not less than the case's crush distance, {} mm",
                    args.crushed_mm,
                    parsed.crush_distance_mm()
                );
            }
            for &threads in &args.threads {
                let mut row = Row {
                    shape: shape.clone(),
                    n,
                    threads,
                    samples: Vec::new(),
                };
                for _ in 0..args.repeats {
                    let sample = run_child(&exe, &json, threads, args.steps, args.crushed_mm)?;
                    row.samples.push(sample);
                }
                print_row(&row, rows.is_empty());
                rows.push(row);
            }
        }
    }
    print_scaling(&rows);
    write_csv(&args.out.join("bench.csv"), &rows)?;
    let series = plot_series(&rows);
    let titles = (
        "Time per particle-step against particle count",
        "particles",
        "ns per particle-step (median)",
    );
    plot::lines(&args.out.join("bench"), titles, &series, true)?;
    eprintln!(
        "wrote {}/bench.csv and the plot bench.svg / bench.png",
        args.out.display()
    );
    Ok(())
}

/// One `crush bench-one` of `steps` timed steps after `crushed_mm` of untimed crush.
fn run_child(
    exe: &PathBuf,
    json: &str,
    threads: usize,
    steps: u64,
    crushed_mm: f64,
) -> anyhow::Result<Sample> {
    let mut child = Command::new(exe)
        .args([
            "bench-one",
            "--threads",
            &threads.to_string(),
            "--steps",
            &steps.to_string(),
            "--crushed-mm",
            &crushed_mm.to_string(),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("starting a bench run")?;
    child
        .stdin
        .take()
        .context("the bench run's stdin")?
        .write_all(json.as_bytes())?;
    let out = child.wait_with_output()?;
    if !out.status.success() {
        bail!("a bench run failed ({})", out.status);
    }
    serde_json::from_slice(&out.stdout).context("reading a bench run's result")
}

fn print_row(row: &Row, header: bool) {
    if header {
        println!(
            "{:<7} {:>3} {:>9} {:>3} {:>10} {:>10} {:>7} | {:>5} {:>5} {:>5} {:>5} {:>6} | {:>9} {:>9}",
            "shape", "n", "particles", "thr", "Mp-steps/s", "min–max", "ns/p-s",
            "bin%", "p2g%", "grid%", "g2p%", "stress%", "B/p peak", "B/p arrays"
        );
    }
    let rate = row.median_by(Sample::rate);
    let (lo, hi) = row
        .samples
        .iter()
        .map(Sample::rate)
        .fold((f64::MAX, 0.0_f64), |(a, b), r| (a.min(r), b.max(r)));
    let share = |f: fn(&PhaseTimes) -> f64| {
        100.0 * row.median_by(|s| f(&s.phases) / phase_total(&s.phases))
    };
    let peak = if row.samples.iter().all(|s| s.bytes_per_particle().is_some()) {
        format!(
            "{:.0}",
            row.median_by(|s| s.bytes_per_particle().unwrap_or(0.0))
        )
    } else {
        "n/a".into()
    };
    println!(
        "{:<7} {:>3} {:>9} {:>3} {:>10.2} {:>10} {:>7.0} | {:>5.1} {:>5.1} {:>5.1} {:>5.1} {:>6.1} | {:>9} {:>9.0}",
        row.shape,
        row.n,
        row.samples[0].particles,
        row.threads,
        rate / 1e6,
        format!("{:.2}–{:.2}", lo / 1e6, hi / 1e6),
        1e9 / rate,
        share(|p| p.bin),
        share(|p| p.p2g),
        share(|p| p.grid),
        share(|p| p.g2p),
        share(|p| p.stress),
        peak,
        row.median_by(|s| s.accounted as f64 / s.particles as f64),
    );
}

fn phase_total(p: &PhaseTimes) -> f64 {
    (p.bin + p.p2g + p.grid + p.g2p + p.stress).max(f64::MIN_POSITIVE)
}

/// Speed-up from the fewest to the most threads, per shape and n.
fn print_scaling(rows: &[Row]) {
    let threads = rows.iter().map(|r| r.threads);
    let (Some(lo), Some(hi)) = (threads.clone().min(), threads.max()) else {
        return;
    };
    if lo == hi {
        return;
    }
    println!("\nspeed-up from {lo} to {hi} threads (ratio of medians):");
    for a in rows.iter().filter(|r| r.threads == lo) {
        if let Some(b) = rows
            .iter()
            .find(|r| r.threads == hi && r.shape == a.shape && r.n == a.n)
        {
            println!(
                "  {:<7} n {:>2}: {:.2}×",
                a.shape,
                a.n,
                b.median_by(Sample::rate) / a.median_by(Sample::rate)
            );
        }
    }
}

fn write_csv(path: &PathBuf, rows: &[Row]) -> anyhow::Result<()> {
    let mut w =
        csv::Writer::from_path(path).with_context(|| format!("writing {}", path.display()))?;
    w.write_record([
        "shape",
        "n",
        "threads",
        "run",
        "particles",
        "steps",
        "wall_s",
        "particle_steps_per_s",
        "bin_s",
        "p2g_s",
        "grid_s",
        "g2p_s",
        "stress_s",
        "peak_rss_bytes",
        "base_rss_bytes",
        "accounted_bytes",
    ])?;
    for row in rows {
        for (k, s) in row.samples.iter().enumerate() {
            let opt = |v: Option<u64>| v.map_or(String::new(), |v| v.to_string());
            w.write_record([
                row.shape.clone(),
                row.n.to_string(),
                row.threads.to_string(),
                k.to_string(),
                s.particles.to_string(),
                s.steps.to_string(),
                format!("{:.9}", s.wall_s),
                format!("{:.0}", s.rate()),
                format!("{:.6}", s.phases.bin),
                format!("{:.6}", s.phases.p2g),
                format!("{:.6}", s.phases.grid),
                format!("{:.6}", s.phases.g2p),
                format!("{:.6}", s.phases.stress),
                opt(s.peak_rss),
                opt(s.base_rss),
                s.accounted.to_string(),
            ])?;
        }
    }
    w.flush()?;
    Ok(())
}

fn plot_series(rows: &[Row]) -> Vec<Series> {
    let mut series: Vec<Series> = Vec::new();
    for row in rows {
        let name = format!(
            "{}, {} thread{}",
            row.shape,
            row.threads,
            if row.threads == 1 { "" } else { "s" }
        );
        let point = (
            row.samples[0].particles as f64,
            1e9 / row.median_by(Sample::rate),
        );
        match series.iter_mut().find(|s| s.name == name) {
            Some(s) => s.points.push(point),
            None => series.push(Series {
                name,
                points: vec![point],
            }),
        }
    }
    series
}
