//! `crush study stability [CASE]`: stiff and extreme variants of a coarse case. Each must either
//! complete with every history value finite and its energy balance within the tolerance, or
//! stop with a diagnosis, or be refused with the reason; and the time step must stay within the
//! CFL estimate Δt = cfl·h / c of the material at rest.

use super::{read_case, run_case, set, threads, write_report, Failed};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The base case when none is given: the design page's axial PVC tube, one cell through the
/// wall (n = 2), 6 mm of crush (the coarse crush whose energy balance tests/crush.rs checks).
const BASE: &str = r#"{"label": "stability base: PVC t 3.2 d 22.2, axial, n 2",
  "tube": {"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 76.2},
  "loading": {"mode": "axial", "plate_speed_m_s": 10, "crush_distance_mm": 6},
  "discretization": {"particles_through_thickness": 2},
  "output": {"history_points": 30}}"#;

#[derive(Debug, Clone, clap::Args)]
pub struct StabilityArgs {
    /// The base case [default: the axial PVC tube at n = 2, 6 mm of crush].
    pub case: Option<PathBuf>,
    /// Crush distance of every variant, mm [default: the base case's].
    #[arg(long)]
    pub crush_mm: Option<f64>,
    /// Energy-balance error a completed run must stay within.
    #[arg(long, default_value_t = 0.05)]
    pub tolerance: f64,
    /// Only the variants whose names contain one of these (comma-separated).
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    #[arg(long, default_value = "study/stability")]
    pub out: PathBuf,
}

/// A variant: name, what changes, and the changes as (dotted path, value).
type Variant = (&'static str, &'static str, Vec<(&'static str, Value)>);

fn variants(base: &Value) -> Vec<Variant> {
    let get = |path: &str, default: f64| {
        path.split('.')
            .try_fold(base, |v, k| v.get(k))
            .and_then(Value::as_f64)
            .unwrap_or(default)
    };
    let e = get("material.youngs_modulus_mpa", 3378.4);
    let sy = get("material.yield_stress_mpa", 65.5);
    let d = get("tube.mean_diameter_mm", 22.2);
    vec![
        ("base", "as given", vec![]),
        (
            "nu-0.499",
            "ν = 0.499 (nearly incompressible)",
            vec![("material.poisson_ratio", json!(0.499))],
        ),
        (
            "stiff-E-1e4",
            "E × 10⁴",
            vec![("material.youngs_modulus_mpa", json!(e * 1e4))],
        ),
        (
            "speed-100",
            "plate at 100 m/s",
            vec![("loading.plate_speed_m_s", json!(100.0))],
        ),
        (
            "speed-300",
            "plate at 300 m/s",
            vec![("loading.plate_speed_m_s", json!(300.0))],
        ),
        (
            "n-1",
            "one particle through the wall",
            vec![("discretization.particles_through_thickness", json!(1))],
        ),
        (
            "n-2",
            "two particles through the wall",
            vec![("discretization.particles_through_thickness", json!(2))],
        ),
        (
            "slender-l/d-12.5",
            "l/d = 12.5",
            vec![("tube.length_mm", json!(12.5 * d))],
        ),
        (
            "never-yields",
            "elastic material (never yields)",
            vec![("material.model", json!("elastic"))],
        ),
        (
            "low-yield",
            "σy / 100",
            vec![("material.yield_stress_mpa", json!(sy / 100.0))],
        ),
        (
            "friction-0",
            "μ = 0",
            vec![("contact.friction", json!(0.0))],
        ),
        (
            "friction-0.5",
            "μ = 0.5",
            vec![("contact.friction", json!(0.5))],
        ),
        (
            "cfl-0.05",
            "CFL factor 0.05",
            vec![("discretization.cfl", json!(0.05))],
        ),
        (
            "cfl-1.0",
            "CFL factor 1.0 (the largest accepted)",
            vec![("discretization.cfl", json!(1.0))],
        ),
        (
            "cfl-1.5",
            "CFL factor 1.5 (beyond the limit)",
            vec![("discretization.cfl", json!(1.5))],
        ),
    ]
}

/// One variant's outcome.
struct Outcome {
    name: &'static str,
    change: &'static str,
    result: String,
    energy_balance: Option<f64>,
    kinetic_to_internal: Option<f64>,
    /// (Δt min, Δt max) taken, and the CFL estimate at the start, ms.
    dt: Option<(f64, f64, f64)>,
    wall_s: Option<f64>,
    verdict: &'static str,
}

pub fn run(args: StabilityArgs) -> anyhow::Result<()> {
    let mut base: Value = match &args.case {
        Some(p) => read_case(p)?,
        None => serde_json::from_str(BASE)?,
    };
    if let Some(c) = args.crush_mm {
        set(&mut base, "loading.crush_distance_mm", c.into());
    }
    let threads = threads(args.threads)?;
    std::fs::create_dir_all(&args.out)?;
    let mut outcomes = Vec::new();
    for (name, change, edits) in variants(&base) {
        if !args.only.is_empty() && !args.only.iter().any(|o| name.contains(o.as_str())) {
            continue;
        }
        let mut case = base.clone();
        for (path, value) in edits {
            set(&mut case, path, value);
        }
        let mut o = Outcome {
            name,
            change,
            result: String::new(),
            energy_balance: None,
            kinetic_to_internal: None,
            dt: None,
            wall_s: None,
            verdict: "",
        };
        match run_case(name, &case, threads)? {
            Ok(done) => {
                let s = &done.summary;
                let finite = done.history.iter().all(|r| {
                    [
                        r.load_top_n,
                        r.load_bottom_n,
                        r.kinetic_mj,
                        r.internal_mj,
                        r.external_mj,
                    ]
                    .iter()
                    .all(|v| v.is_finite())
                });
                let spec = done.case.spec();
                let cfl_dt =
                    spec.discretization.cfl * done.case.cell_mm() / done.case.wave_speed_m_s();
                o.energy_balance = Some(s.energy_balance_error);
                o.kinetic_to_internal = Some(s.kinetic_to_internal);
                o.dt = Some((s.cost.dt_min_ms, s.cost.dt_max_ms, cfl_dt));
                o.wall_s = Some(s.cost.wall_time_s);
                let dt_ok = s.cost.dt_max_ms <= cfl_dt * 1.000_001;
                o.result = format!("completed, {} steps", s.cost.steps);
                o.verdict = if !finite {
                    "FAIL: a non-finite value in the history"
                } else if !dt_ok {
                    "FAIL: Δt above the CFL estimate"
                } else if s.energy_balance_error.abs() > args.tolerance {
                    "DRIFT: energy balance outside the tolerance"
                } else {
                    "pass"
                };
            }
            Err(Failed::Stopped(e)) => {
                o.result = format!("stopped: {e}");
                o.verdict = "pass (stopped with a diagnosis)";
            }
            Err(Failed::Rejected(e)) => {
                o.result = format!("refused: {e}");
                o.verdict = "pass (refused with the reason)";
            }
        }
        outcomes.push(o);
    }
    write_report(&args.out, &report(&args, &base, &outcomes))?;
    if outcomes.iter().any(|o| o.verdict.starts_with("FAIL")) {
        anyhow::bail!("some variants failed: a non-finite value or a step beyond the CFL limit");
    }
    Ok(())
}

fn report(args: &StabilityArgs, base: &Value, outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Stability study\n");
    let _ = writeln!(
        s,
        "Base case: `{}`. A completed run passes when every history value is finite, the \
         largest Δt taken is within the CFL estimate Δt = cfl·h/c of the material at rest (c the \
         P-wave speed; the solver's step uses the largest c + |v| over the particles, so it \
         shrinks from there as they speed up) and the energy-balance error is within {:.0} %. A run that stops with a diagnosis, or a case \
         refused with the reason, also passes. FAIL (the command exits non-zero): a non-finite \
         value reached the history, or a step beyond the CFL limit. DRIFT: the run completed \
         with finite values but its energy balance is outside the tolerance, so its numbers \
         are not to be trusted in that regime.\n",
        serde_json::to_string(base).unwrap_or_default(),
        100.0 * args.tolerance
    );
    let _ = writeln!(
        s,
        "| variant | change | result | energy balance | E_kin/E_int | Δt min–max (µs) | CFL Δt (µs) | wall s | verdict |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for o in outcomes {
        let num = |x: Option<f64>| x.map_or("–".into(), |x| format!("{:.2} %", 100.0 * x));
        let dt = o.dt.map_or(("–".into(), "–".into()), |(a, b, c)| {
            (
                format!("{:.4}–{:.4}", a * 1e3, b * 1e3),
                format!("{:.4}", c * 1e3),
            )
        });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            o.name,
            o.change,
            o.result.replace('|', "/"),
            num(o.energy_balance),
            num(o.kinetic_to_internal),
            dt.0,
            dt.1,
            o.wall_s.map_or("–".into(), |w| format!("{w:.1}")),
            o.verdict
        );
    }
    s
}
