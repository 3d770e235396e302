//! `crush study speed CASE`: the case at several plate speeds. The material is rate
//! independent, so the mean load should barely change; the kinetic-to-internal energy ratio
//! says how close each run is to quasi-static.

use super::cases::{plot_load_curves, read_case, run_case, set, threads, write_report, Failed};
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Debug, Clone, clap::Args)]
pub struct SpeedArgs {
    /// The crush case, as JSON.
    pub case: PathBuf,
    /// Plate speeds, m/s, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "5,10,15")]
    pub speeds: Vec<f64>,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    #[arg(long, default_value = "study/speed")]
    pub out: PathBuf,
}

struct Row {
    speed: f64,
    mean_n: f64,
    peak_n: f64,
    ke_ie: f64,
    energy_balance: f64,
    wall_s: f64,
}

pub fn run(args: SpeedArgs) -> anyhow::Result<()> {
    let base = read_case(&args.case)?;
    let threads = threads(args.threads)?;
    std::fs::create_dir_all(&args.out)?;
    let (mut rows, mut curves, mut stopped) = (Vec::new(), Vec::new(), Vec::new());
    for &speed in &args.speeds {
        let mut case = base.clone();
        set(&mut case, "loading.plate_speed_m_s", speed.into())?;
        let name = format!("{speed} m/s");
        match run_case(&name, &case, threads)? {
            Ok(done) => {
                let s = &done.summary;
                rows.push(Row {
                    speed,
                    mean_n: s.mean_load_n,
                    peak_n: s.peak_load_n,
                    ke_ie: s.kinetic_to_internal,
                    energy_balance: s.energy_balance_error,
                    wall_s: s.cost.wall_time_s,
                });
                curves.push(done.load_curve(name));
            }
            Err(Failed::Rejected(e)) => anyhow::bail!("{name}: the case was rejected: {e}"),
            Err(Failed::Stopped(e)) => stopped.push(format!("{name}: {e}")),
        }
    }
    plot_load_curves(&args.out, &curves)?;
    let mut s = String::new();
    let _ = writeln!(s, "# Plate-speed study: {}\n", args.case.display());
    let _ = writeln!(
        s,
        "| speed m/s | mean kN | peak kN | E_kin/E_int (max, 2nd half) | energy balance | wall s |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for r in &rows {
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} | {:.2} % | {:.2} % | {:.1} |",
            r.speed,
            r.mean_n / 1e3,
            r.peak_n / 1e3,
            100.0 * r.ke_ie,
            100.0 * r.energy_balance,
            r.wall_s
        );
    }
    if rows.len() >= 2 {
        let means: Vec<f64> = rows.iter().map(|r| r.mean_n).collect();
        let lo = means.iter().copied().fold(f64::MAX, f64::min);
        let hi = means.iter().copied().fold(f64::MIN, f64::max);
        let avg = means.iter().sum::<f64>() / means.len() as f64;
        let _ = writeln!(
            s,
            "\nSpread of the mean load: (max − min) / average = {:.1} % (the material is rate \
             independent: what spread there is comes from inertia, and shows in E_kin/E_int).",
            100.0 * (hi - lo) / avg
        );
    }
    for f in &stopped {
        let _ = writeln!(s, "\n- stopped: {f}");
    }
    write_report(&args.out, &s)
}
