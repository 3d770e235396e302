//! The command line, run as a user would: the real `crush` binary in a temporary directory.

use std::process::Command;

/// A tiny `crush bench` (one size, one thread, two steps of a tube crushed 0.1 mm) finishes,
/// prints its table and writes a CSV whose rows carry plausible, self-consistent numbers.
#[test]
fn bench_writes_a_table_a_csv_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_crush"))
        .args([
            "bench",
            "--n",
            "2",
            "--shape",
            "linear,gimp",
            "--threads",
            "1",
            "--steps",
            "2",
            "--repeats",
            "2",
            "--crushed-mm",
            "0.1",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Mp-steps/s"), "{stdout}");
    let mut csv = csv::Reader::from_path(dir.path().join("bench.csv")).unwrap();
    let header = csv.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = csv.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 4, "two shapes × two repeats");
    for r in &rows {
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        let (particles, steps, wall) = (num("particles"), num("steps"), num("wall_s"));
        assert!(particles > 1000.0 && steps == 2.0 && wall > 0.0);
        let rate = num("particle_steps_per_s");
        assert!((rate - particles * steps / wall).abs() <= 1e-4 * rate);
        let phases: f64 = ["bin_s", "p2g_s", "grid_s", "g2p_s", "stress_s"]
            .iter()
            .map(|p| num(p))
            .sum();
        assert!(
            phases > 0.5 * wall && phases <= 1.01 * wall,
            "phases {phases} s of {wall} s"
        );
        assert!(num("accounted_bytes") / particles > 100.0);
    }
    for plot in ["bench.svg", "bench.png"] {
        let len = std::fs::metadata(dir.path().join(plot)).unwrap().len();
        assert!(len > 1000, "{plot} is {len} bytes");
    }
}

/// Bad arguments are refused with a message, before anything runs.
#[test]
fn bench_refuses_a_bad_shape_zero_threads_and_a_crush_past_the_end() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, value, expect) in [
        ("--shape", "cubic", "shape"),
        ("--threads", "0", "thread"),
        ("--crushed-mm", "NaN", "distance of 0 mm or more"),
        (
            "--crushed-mm",
            "50",
            "not less than the case's crush distance, 50 mm",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_crush"))
            .args(["bench", "--n", "2", flag, value, "--out"])
            .arg(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(stderr.contains(expect), "{flag} {value}: {stderr}");
    }
}

/// `crush run` on a tiny case writes its history, summary, final particles and the picture of
/// the deformed tube; a case that keeps no final state writes neither of the last two.
#[test]
fn run_writes_its_files_and_leaves_out_the_state_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    for (name, keep) in [("keep", true), ("lean", false)] {
        let case = serde_json::json!({
            "tube": {"length_mm": 8},
            "discretization": {"particles_through_thickness": 1},
            "loading": {"crush_distance_mm": 1, "plate_speed_m_s": 20},
            "output": {"history_points": 20, "final_state": keep}
        });
        let path = dir.path().join(format!("{name}.json"));
        std::fs::write(&path, case.to_string()).unwrap();
        let out_dir = dir.path().join(name);
        let out = Command::new(env!("CARGO_BIN_EXE_crush"))
            .arg("run")
            .arg(&path)
            .arg("--out")
            .arg(&out_dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(out_dir.join("history.csv").is_file());
        assert!(out_dir.join("summary.json").is_file());
        let energy = std::fs::read_to_string(out_dir.join("energy.svg")).unwrap();
        assert!(
            energy.contains("<svg") && energy.contains("polyline"),
            "{name}: energy.svg"
        );
        assert_eq!(out_dir.join("particles.csv").is_file(), keep, "{name}");
        assert_eq!(out_dir.join("shape.png").is_file(), keep, "{name}");
        if keep {
            let png = std::fs::read(out_dir.join("shape.png")).unwrap();
            let img = image::load_from_memory(&png).unwrap();
            assert!(img.width() >= 800, "{} px wide", img.width());
        }
    }
}

/// `crush run` of the paper's section at n = 8 over 5 mm of crush, asked for its error bar:
/// the ladder is the run itself and its section at n = 12 and 16, each rung's mean load is the
/// one a separate run at that n gives, and the interval holds the rungs' extrapolation or
/// their spread about the finest rung.
#[test]
fn run_prices_the_error_bar_with_rungs_that_are_runs_of_their_own() {
    let dir = tempfile::tempdir().unwrap();
    let case = |n: u32, error_bar: bool| {
        serde_json::json!({
            "loading": {"crush_distance_mm": 5},
            "discretization": {"model": "axisymmetric", "particles_through_thickness": n},
            "output": {"history_points": 50, "final_state": false, "error_bar": error_bar}
        })
    };
    let run = |name: &str, case: serde_json::Value| -> serde_json::Value {
        let path = dir.path().join(format!("{name}.json"));
        std::fs::write(&path, case.to_string()).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_crush"))
            .args(["run", "--threads", "1", "--out"])
            .arg(dir.path().join(name))
            .arg(&path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(dir.path().join(name).join("summary.json")).unwrap();
        serde_json::from_str(&text).unwrap()
    };
    let s = run("n8", case(8, true));
    let bar = &s["error_bar"];
    assert_eq!(bar["basis"], "reduced_ladder", "{bar}");
    let rungs: Vec<(u64, f64)> = bar["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| (r["n"].as_u64().unwrap(), r["mean_load_n"].as_f64().unwrap()))
        .collect();
    assert_eq!(rungs.iter().map(|r| r.0).collect::<Vec<_>>(), [8, 12, 16]);
    assert_eq!(rungs[0].1, s["mean_load_n"].as_f64().unwrap());
    let twelve = run("n12", case(12, false));
    assert_eq!(rungs[1].1, twelve["mean_load_n"].as_f64().unwrap());
    // Not asked for, and its ladder (n = 12, 18, 24) costs many times the run: not priced,
    // and the summary says so.
    assert_eq!(twelve["error_bar"]["basis"], "unavailable", "{twelve}");
    let why = twelve["error_bar"]["why"].as_str().unwrap();
    assert!(why.starts_with("not priced"), "{why}");
    let (low, high) = (
        bar["low_n"].as_f64().unwrap(),
        bar["high_n"].as_f64().unwrap(),
    );
    let estimate = bar["estimate_n"].as_f64().unwrap();
    assert!(low < estimate && estimate < high, "{bar}");
    // The finest rung is never outside the interval: the half-width includes its distance to
    // the estimate.
    assert!(low <= rungs[2].1 && rungs[2].1 <= high, "{bar}");
    assert!(bar["cost_s"].as_f64().unwrap() > 0.0);
}

/// `crush estimate` answers as `POST /v1/estimate` does, without running: one particle through
/// the wall is foretold not trusted. A rejected case names its field and ends with one line of
/// error, no backtrace, even with `RUST_BACKTRACE` set.
#[test]
fn estimate_tells_the_cost_and_the_verdict_before_a_run_and_errors_carry_no_backtrace() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("coarse.json");
    std::fs::write(
        &path,
        r#"{"discretization": {"particles_through_thickness": 1}}"#,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_crush"))
        .args(["estimate", "--json", "--threads", "2"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let e: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(e["threads"], 2);
    assert!(e["particles"].as_u64().unwrap() > 0, "{e}");
    assert_eq!(e["verdict"]["level"], "not_trusted", "{e}");
    assert_eq!(e["verdict"]["reasons"][0]["rule"], "thin_resolution", "{e}");
    assert!(
        !dir.path().join("coarse").exists(),
        "an estimate writes nothing"
    );

    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, r#"{"tube": {"thickness_mm": -1}}"#).unwrap();
    for command in ["estimate", "run"] {
        let out = Command::new(env!("CARGO_BIN_EXE_crush"))
            .env("RUST_BACKTRACE", "1")
            .arg(command)
            .arg(&bad)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("tube.thickness_mm: must be"), "{stderr}");
        assert!(stderr.trim_end().ends_with("was rejected"), "{stderr}");
        assert!(!stderr.contains("backtrace"), "{stderr}");
    }
}

/// What broke: `crush estimate case.json | head -1` panicked with a backtrace once `head` had
/// its line and closed the pipe. Here the reader closes the pipe before the command writes at
/// all: it ends quietly, killed by SIGPIPE as command-line tools are.
#[cfg(unix)]
#[test]
fn a_reader_that_stops_early_ends_the_command_without_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut child = Command::new(env!("CARGO_BIN_EXE_crush"))
        .arg("estimate")
        .arg(examples.join("axial_t3.2.json"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        out.status.success() || out.status.signal() == Some(libc::SIGPIPE),
        "{:?}: {stderr}",
        out.status
    );
}

/// What broke: `crush run` started a case of 381 000 particles and 15.7 M steps (a thickness
/// in metres typed as millimetres), roughly 316 hours, past every limit the server holds a
/// case to. It refuses it naming the thickness first; `--no-limits` lifts the server's limits
/// (and an explicit `--max-particles` still holds).
#[test]
fn run_refuses_a_case_past_the_servers_cost_limits_unless_told_no_limits() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("thin.json");
    std::fs::write(
        &path,
        r#"{"tube": {"thickness_mm": 0.0032}, "discretization": {"model": "axisymmetric"}}"#,
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_crush"))
            .arg("run")
            .args(extra)
            .arg("--out")
            .arg(&out_dir)
            .arg(&path)
            .output()
            .unwrap()
    };
    let out = run(&[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    let first = stderr.lines().nth(1).unwrap_or_default();
    assert!(
        first.starts_with("  tube.thickness_mm: 0.0032 mm gives 15843860 time steps"),
        "{stderr}"
    );
    assert!(stderr.contains("pass --no-limits"), "{stderr}");
    assert!(
        stderr.trim_end().ends_with("is past the cost limits"),
        "{stderr}"
    );
    assert!(!out_dir.exists(), "a refused case writes nothing");

    // Without the server's limits only the particles asked for hold it back: no step limit.
    let out = run(&["--no-limits", "--max-particles", "1000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("particles, more than this runner's limit of 1000"),
        "{stderr}"
    );
    assert!(!stderr.contains("time steps, more"), "{stderr}");
    assert!(!stderr.contains("--no-limits"), "{stderr}");
}
