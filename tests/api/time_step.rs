//! A sweep over the time step (`discretization.cfl`) through the real HTTP API: the table's
//! `time_step` block is the runs' own figures, read as `crush study step` reads them.

use crate::common::*;
use serde_json::{json, Value};
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_sweep_over_the_step_reads_the_time_step_error_and_the_books() {
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let body = json!({"label": "steps", "base": tiny_case(),
        "parameters": {"discretization.cfl": [0.5, 0.25, 0.125]}});
    let (location, sweep) = app.create_sweep(&body).await;
    for row in sweep["rows"].as_array().unwrap() {
        let id = row["job_id"].as_str().unwrap();
        app.wait_for(id, &["succeeded"], Duration::from_secs(60))
            .await;
    }
    let table = get_json(&app.client, &app.at(&location)).await;
    let groups = table["time_step"].as_array().unwrap();
    assert_eq!(groups.len(), 1, "{table}");
    assert_eq!(groups[0]["group"], "");
    let rows = groups[0]["analysis"]["rows"].as_array().unwrap();
    let cfl: Vec<f64> = rows.iter().map(|r| r["cfl"].as_f64().unwrap()).collect();
    assert_eq!(cfl, [0.5, 0.25, 0.125], "largest step first");
    // Each row is its job's figures, and its error is what those figures say.
    let table_rows = table["rows"].as_array().unwrap();
    let of = |c: f64| -> &Value {
        table_rows
            .iter()
            .find(|r| r["discretization.cfl"].as_f64() == Some(c))
            .unwrap()
    };
    let smallest = rows[2]["mean_load_n"].as_f64().unwrap();
    for r in rows {
        let job = of(r["cfl"].as_f64().unwrap());
        assert_eq!(r["mean_load_n"], job["mean_load_n"]);
        assert_eq!(r["steps"], job["steps"]);
        assert_eq!(r["mode"]["kind"], job["mode"], "{r}");
        assert_eq!(r["folds"], job["folds"]);
        let expect = r["mean_load_n"].as_f64().unwrap() / smallest - 1.0;
        let got = r["mean_error_vs_finest"].as_f64().unwrap();
        assert!((got - expect).abs() < 1e-12, "{r}");
    }
    // Halving the step about doubles the steps.
    for w in rows.windows(2) {
        let ratio = w[1]["steps"].as_f64().unwrap() / w[0]["steps"].as_f64().unwrap();
        assert!((1.8..=2.2).contains(&ratio), "{ratio}");
    }
    // The read-offs are steps of the sweep, or null.
    for key in ["cfl_within_2_percent", "cfl_books_within_2_percent"] {
        let v = &groups[0][key];
        assert!(
            v.is_null() || cfl.contains(&v.as_f64().unwrap()),
            "{key}: {v}"
        );
    }
    // A sweep that does not vary the step has no such block.
    let plain = json!({"base": tiny_case(), "parameters": {"contact.friction": [0.0]}});
    let (_, r) = app.create_sweep(&plain).await;
    assert!(r.get("time_step").is_none(), "{r}");
}
