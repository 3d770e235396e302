//! `crush study stability [CASE]`: stiff and extreme variants of a coarse case. Each must either
//! complete with every history value finite and its energy balance within the tolerance, or
//! stop with a diagnosis, or be refused with the reason. Two checks can fail the study: a
//! completed run whose books hold more energy than the plates put in (the integration created
//! it: the sign of an unstable step), and a run forced past the stability limit (a CFL factor no
//! case may ask for, set on the scene) that completes instead of being stopped with a diagnosis.

use super::cases::{read_case, run_case, run_case_changed, set, threads, write_report, Failed};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The base case when none is given: the design page's axial PVC tube, one cell through the
/// wall (n = 2), 6 mm of crush (the coarse crush whose energy balance tests/solver/crush.rs checks).
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

/// The CFL factor of the variant forced past the stability limit: the largest a case may ask
/// for is 1; at this factor the explicit step is unstable and the run must be stopped.
const FORCED_CFL: f64 = 2.0;

/// Name of the variant forced past the limit (it has no case edits: its scene is changed).
const FORCED: &str = "cfl-2-forced";

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
        (
            FORCED,
            "CFL factor 2 set on the scene, past the case check (must be stopped)",
            vec![],
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
    /// Energy the books hold beyond the plates' work, as a share of that work (negative: less).
    created: Option<f64>,
    /// (Δt min, Δt max) the CFL condition allowed over the run, ms.
    dt: Option<(f64, f64)>,
    wall_s: Option<f64>,
    verdict: &'static str,
}

pub fn run(args: StabilityArgs) -> anyhow::Result<()> {
    let mut base: Value = match &args.case {
        Some(p) => read_case(p)?,
        None => serde_json::from_str(BASE)?,
    };
    if let Some(c) = args.crush_mm {
        set(&mut base, "loading.crush_distance_mm", c.into())?;
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
            set(&mut case, path, value)?;
        }
        let mut o = Outcome {
            name,
            change,
            result: String::new(),
            energy_balance: None,
            created: None,
            kinetic_to_internal: None,
            dt: None,
            wall_s: None,
            verdict: "",
        };
        let result = if name == FORCED {
            run_case_changed(name, &case, threads, |scene| scene.cfl = FORCED_CFL)?
        } else {
            run_case(name, &case, threads)?
        };
        match result {
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
                let work = s.energy.work_top_mj + s.energy.work_bottom_mj;
                let created = -s.energy.residual_mj / work.max(f64::MIN_POSITIVE);
                o.energy_balance = Some(s.energy_balance_error);
                o.created = Some(created);
                o.kinetic_to_internal = Some(s.kinetic_to_internal);
                o.dt = Some((s.cost.dt_min_ms, s.cost.dt_max_ms));
                o.wall_s = Some(s.cost.wall_time_s);
                o.result = format!("completed, {} steps", s.cost.steps);
                o.verdict = if !finite {
                    "FAIL: a non-finite value in the history"
                } else if name == FORCED {
                    "FAIL: ran past the stability limit and was not stopped"
                } else if created > args.tolerance {
                    "FAIL: the books hold more energy than the plates put in"
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
        anyhow::bail!(
            "some variants failed: a non-finite value, energy created, or a run past the \
             stability limit that was not stopped"
        );
    }
    Ok(())
}

fn report(args: &StabilityArgs, base: &Value, outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Stability study\n");
    let _ = writeln!(
        s,
        "Base case: `{}`. A completed run passes when every history value is finite and its \
         energy-balance error is within {tol:.0} %. A run that stops with a diagnosis, or a case \
         refused with the reason, also passes. FAIL (the command exits non-zero): a non-finite \
         value reached the history; the books (kinetic, internal, friction and contact energy) \
         hold more than {tol:.0} % beyond the plates' work at the end (the integration created \
         energy, the mark of an unstable step); or `{FORCED}`, the base case with a CFL factor \
         of {FORCED_CFL} set on its scene past the case check (no case may ask for more than 1), \
         completed instead of being stopped. DRIFT: the run completed with finite values but its \
         energy balance is outside the tolerance, so its numbers are not to be trusted in that \
         regime.\n",
        serde_json::to_string(base).unwrap_or_default(),
        tol = 100.0 * args.tolerance
    );
    let _ = writeln!(
        s,
        "| variant | change | result | energy balance | energy created | E_kin/E_int | Δt min–max (µs) | wall s | verdict |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for o in outcomes {
        let num = |x: Option<f64>| x.map_or("–".into(), |x| format!("{:.2} %", 100.0 * x));
        let dt = o.dt.map_or("–".into(), |(a, b)| {
            format!("{:.4}–{:.4}", a * 1e3, b * 1e3)
        });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            o.name,
            o.change,
            o.result.replace('|', "/"),
            num(o.energy_balance),
            num(o.created),
            num(o.kinetic_to_internal),
            dt,
            o.wall_s.map_or("–".into(), |w| format!("{w:.1}")),
            o.verdict
        );
    }
    s
}
