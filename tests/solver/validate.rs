//! `crush validate` as a user drives it: the CI profile's slice, its report against `crush run`
//! on the same scene's case, the cache that makes a second run free, and the exit status.

use std::path::Path;
use std::process::{Command, Output};

fn crush(args: &[&str], dir: &Path) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_crush"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "crush {args:?}\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn report(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("report/validation.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The CI slice passes its bands, writes the Markdown, the self-contained HTML page and the
/// JSON, and its numbers are those `crush run` gives for the scene's own case; run again, it
/// reads every scene back from the cache.
#[test]
fn the_ci_slice_reports_what_crush_run_prints_and_a_rerun_costs_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = [
        "validate",
        "--profile",
        "ci",
        "--out",
        "report",
        "--cache",
        "cache",
        "--threads",
        "1",
    ];
    crush(&args, d);
    let first = report(d);
    let scene = &first["scenes"][0];
    assert_eq!(scene["id"], "paper-axisym-n2");
    assert_eq!(scene["cached"], false);
    let md = std::fs::read_to_string(d.join("report/validation.md")).unwrap();
    assert!(
        md.contains("## 1. The seed paper") && md.contains("13.200 kN"),
        "{md}"
    );
    let html = std::fs::read_to_string(d.join("report/validation.html")).unwrap();
    assert!(
        html.contains("<table>") && html.contains("<svg"),
        "the figures inline"
    );
    assert!(!html.contains("src=\"img/"), "the page holds its figures");

    let case = crush(
        &["validate", "--profile", "ci", "--case", "paper-axisym-n2"],
        d,
    );
    std::fs::write(d.join("case.json"), &case.stdout).unwrap();
    crush(&["run", "case.json", "--out", "run", "--threads", "1"], d);
    let text = std::fs::read_to_string(d.join("run/summary.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    for field in [
        "mean_load_n",
        "first_peak_load_n",
        "folds",
        "energy_balance_error",
    ] {
        assert_eq!(scene[field], summary[field], "{field}");
    }
    let mean = first["rows"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["scene"] == "paper-axisym-n2" && r["figure"] == "mean load")
        .unwrap();
    assert_eq!(
        mean["ours"].as_f64().unwrap() * 1e3,
        summary["mean_load_n"].as_f64().unwrap()
    );
    assert!(String::from_utf8_lossy(
        &crush(&["run", "case.json", "--out", "run", "--threads", "1"], d).stdout
    )
    .contains(&format!(
        "{:.3}",
        summary["mean_load_n"].as_f64().unwrap() / 1e3
    )));

    crush(&args, d);
    let second = report(d);
    assert_eq!(second["scenes"][0]["cached"], true);
    assert_eq!(second["scenes"][0]["mean_load_n"], scene["mean_load_n"]);
    assert!(
        second["wall_s"].as_f64().unwrap() < 2.0,
        "{}",
        second["wall_s"]
    );
}

/// A scene the profile does not hold is refused by name.
#[test]
fn an_unknown_scene_is_refused_by_name() {
    let out = Command::new(env!("CARGO_BIN_EXE_crush"))
        .args(["validate", "--case", "no-such-scene"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no scene no-such-scene"), "{err}");
}
