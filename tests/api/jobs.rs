//! Jobs, sweeps and the estimate through the real HTTP API (server on port 0, temp SQLite).

use crate::common::*;
use serde_json::{json, Value};
use std::collections::HashSet;
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn small_case_streams_rising_progress_then_succeeds_with_history_and_summary() {
    let app = TestApp::start(&["--concurrent-jobs", "1"]).await;
    // A long job holds the only worker, so the small one is still queued when we listen.
    let blocker = app.submit(&long_case()).await;
    let blocker_id = blocker["id"].as_str().unwrap().to_string();
    // Wait until a worker holds it, so its cancel below is the running-job kind (202).
    app.wait_for(&blocker_id, &["running"], Duration::from_secs(30))
        .await;
    let mut case = tiny_case();
    case["label"] = json!("sse-test");
    let r = app
        .client
        .post(app.at("/v1/jobs"))
        .json(&case)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 202);
    let location = r.headers()["location"].to_str().unwrap().to_string();
    let job: Value = r.json().await.unwrap();
    let id = job["id"].as_str().unwrap().to_string();
    assert_eq!(location, format!("/v1/jobs/{id}"));
    assert_eq!(job["status"], "queued");
    assert_eq!(job["case"], case);

    let (status, mut events) =
        SseReader::open(&app.client, &app.at(&format!("/v1/jobs/{id}/events")), None).await;
    assert_eq!(status, 200);
    let first = events
        .next(Duration::from_secs(10))
        .await
        .expect("a first event");
    assert_eq!(
        (first.event.as_str(), first.json()["status"].as_str()),
        ("status", Some("queued"))
    );
    let r = app.post(&format!("/v1/jobs/{blocker_id}/cancel")).await;
    assert_eq!(r.status(), 202);

    let mut ids = vec![first.id.unwrap()];
    let mut fractions = Vec::new();
    let last = loop {
        let e = events
            .next(Duration::from_secs(60))
            .await
            .expect("the stream goes on to the end");
        ids.push(e.id.expect("every event has an id"));
        match e.event.as_str() {
            "progress" => fractions.push(e.json()["fraction"].as_f64().unwrap()),
            "status" => assert_eq!(e.json()["status"], "running"),
            _ => break e,
        }
    };
    assert_eq!(last.event, "done", "{}", last.data);
    assert!(
        events.next(Duration::from_secs(5)).await.is_none(),
        "the stream ends after done"
    );
    assert!(
        ids.windows(2).all(|w| w[0] < w[1]),
        "event ids increase: {ids:?}"
    );
    assert!(fractions.len() >= 2, "progress events: {fractions:?}");
    assert!(
        fractions.windows(2).all(|w| w[0] <= w[1]),
        "progress rises: {fractions:?}"
    );
    assert!(fractions.last().unwrap() > fractions.first().unwrap());

    let job = app.job(&id).await;
    assert_eq!(job["status"], "succeeded");
    assert_eq!(job["attempts"], 1);
    for key in [
        "mean_load_n",
        "peak_load_n",
        "energy_absorbed_mj",
        "mode",
        "cost",
    ] {
        assert!(
            !job["summary"][key].is_null(),
            "summary lacks {key}: {}",
            job["summary"]
        );
    }
    let history = get_json(&app.client, &app.at(&format!("/v1/jobs/{id}/history"))).await;
    let rows = history["rows"].as_array().unwrap();
    assert!(
        (19..=21).contains(&rows.len()),
        "{} history rows",
        rows.len()
    );
    assert_eq!(
        history["columns"].as_array().unwrap().len(),
        rows[0].as_array().unwrap().len()
    );
    let csv = app
        .client
        .get(app.at(&format!("/v1/jobs/{id}/history")))
        .header("accept", "text/csv")
        .send()
        .await
        .unwrap();
    assert!(csv.headers()["content-type"]
        .to_str()
        .unwrap()
        .starts_with("text/csv"));
    let text = csv.text().await.unwrap();
    assert!(text.starts_with("time_ms,displacement_mm,"), "{text}");
    assert_eq!(text.lines().count(), rows.len() + 1);
    // The load curve as SVG, drawn by the server: an SVG document with a line in it.
    let plot = app.get(&format!("/v1/jobs/{id}/plot.svg")).await;
    assert_eq!(plot.status(), 200);
    assert_eq!(plot.headers()["content-type"], "image/svg+xml");
    let svg = plot.text().await.unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("<polyline"), "no line drawn");

    // A client that connects after the end gets the final state at once; one that saw it, 204.
    let url = app.at(&format!("/v1/jobs/{id}/events"));
    let (_, mut late) = SseReader::open(&app.client, &url, None).await;
    let end = late.next(Duration::from_secs(5)).await.unwrap();
    assert_eq!((end.event.as_str(), end.id), ("done", last.id));
    let (status, _) = SseReader::open(&app.client, &url, last.id).await;
    assert_eq!(status, 204);
    // The label filter finds it, and the blocker was cancelled.
    let list = get_json(&app.client, &app.at("/v1/jobs?label=sse-test")).await;
    assert_eq!(list["jobs"].as_array().unwrap().len(), 1);
    app.wait_for(&blocker_id, &["cancelled"], Duration::from_secs(10))
        .await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_running_job_is_cancelled_within_a_step() {
    let app = TestApp::start(&["--concurrent-jobs", "1"]).await;
    let id = app.submit(&long_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let events_url = app.at(&format!("/v1/jobs/{id}/events"));
    let (_, mut events) = SseReader::open(&app.client, &events_url, None).await;
    let seen = loop {
        let e = events
            .next(Duration::from_secs(30))
            .await
            .expect("the job starts");
        if e.event == "progress" {
            break e.id.unwrap();
        }
    };
    // A client that reconnects with Last-Event-ID is sent only newer events.
    let (status, mut resumed) = SseReader::open(&app.client, &events_url, Some(seen)).await;
    assert_eq!(status, 200);
    let next = resumed
        .next(Duration::from_secs(10))
        .await
        .expect("the stream goes on");
    assert!(
        next.id.unwrap() > seen,
        "resumed at {:?} after {seen}",
        next.id
    );
    drop(resumed);
    let r = app.post(&format!("/v1/jobs/{id}/cancel")).await;
    assert_eq!(r.status(), 202);
    let body: Value = r.json().await.unwrap();
    assert_eq!(body["cancel_requested"], true);
    assert!(
        body["note"].as_str().unwrap().contains("the cancel wins"),
        "the 202 says the cancel wins over a run that completes meanwhile: {body}"
    );
    let end = loop {
        let e = events
            .next(Duration::from_secs(10))
            .await
            .expect("the run stops promptly");
        if e.event != "progress" {
            break e;
        }
    };
    assert_eq!(end.event, "cancelled", "{}", end.data);
    let job = app.job(&id).await;
    assert_eq!(job["status"], "cancelled");
    assert!(job["summary"].is_null());
    // Cancelling again, or asking for a history, conflicts with the finished state.
    let again = app.post(&format!("/v1/jobs/{id}/cancel")).await;
    assert_eq!(again.status(), 409);
    let history = app.get(&format!("/v1/jobs/{id}/history")).await;
    assert_eq!(history.status(), 409);
    let plot = app.get(&format!("/v1/jobs/{id}/plot.svg")).await;
    assert_eq!(plot.status(), 409);
    // A queued job is cancelled at once.
    let app0 = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let queued = app0.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let r = app0.post(&format!("/v1/jobs/{queued}/cancel")).await;
    assert_eq!(r.status(), 200);
    assert_eq!(r.json::<Value>().await.unwrap()["status"], "cancelled");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn fifty_concurrent_submissions_are_all_accounted_for() {
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let mut case = tiny_case();
    case["label"] = json!("fifty");
    let submits = (0..50).map(|_| {
        let (client, url, case) = (app.client.clone(), app.at("/v1/jobs"), case.clone());
        tokio::spawn(async move {
            let r = client.post(url).json(&case).send().await.unwrap();
            assert_eq!(r.status(), 202);
            r.json::<Value>().await.unwrap()["id"]
                .as_str()
                .unwrap()
                .to_string()
        })
    });
    let submitted: Vec<String> = futures::future::join_all(submits)
        .await
        .into_iter()
        .map(|r| r.unwrap())
        .collect();
    let submitted: HashSet<String> = submitted.into_iter().collect();
    assert_eq!(submitted.len(), 50, "every submit made its own job");

    // Page through the list 20 at a time; newest first, no job twice, none missing.
    let mut listed = Vec::new();
    let mut cursor: Option<String> = None;
    loop {
        let mut url = app.at("/v1/jobs?label=fifty&limit=20");
        if let Some(c) = &cursor {
            url.push_str(&format!("&cursor={c}"));
        }
        let page = get_json(&app.client, &url).await;
        for job in page["jobs"].as_array().unwrap() {
            assert!(
                job["attempts"].as_i64().unwrap() <= 1,
                "claimed twice: {job}"
            );
            listed.push(job["id"].as_str().unwrap().to_string());
        }
        match page["next_cursor"].as_str() {
            Some(c) => cursor = Some(c.to_string()),
            None => break,
        }
    }
    assert_eq!(listed.len(), 50);
    assert_eq!(listed.iter().cloned().collect::<HashSet<_>>(), submitted);
    let metrics = app.get("/metrics").await.text().await.unwrap();
    let total: i64 = metrics
        .lines()
        .filter(|l| l.starts_with("crush_jobs{"))
        .map(|l| l.rsplit(' ').next().unwrap().parse::<i64>().unwrap())
        .sum();
    assert_eq!(total, 50, "{metrics}");
    let running = get_json(
        &app.client,
        &app.at("/v1/jobs?status=queued,running,succeeded&limit=500"),
    )
    .await;
    assert_eq!(running["jobs"].as_array().unwrap().len(), 50);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_retried_submit_with_an_idempotency_key_returns_the_same_job() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let send = |case: Value| {
        app.client
            .post(app.at("/v1/jobs"))
            .header("idempotency-key", "run-42")
            .json(&case)
            .send()
    };
    let first = send(tiny_case()).await.unwrap();
    assert_eq!(first.status(), 202);
    let first: Value = first.json().await.unwrap();
    let again = send(tiny_case()).await.unwrap();
    assert_eq!(again.status(), 202);
    assert_eq!(again.headers()["idempotent-replayed"], "true");
    assert_eq!(again.json::<Value>().await.unwrap()["id"], first["id"]);
    let mut other = tiny_case();
    other["tube"]["length_mm"] = json!(9);
    let clash = send(other).await.unwrap();
    assert_eq!(clash.status(), 422);
    let list = get_json(&app.client, &app.at("/v1/jobs")).await;
    assert_eq!(list["jobs"].as_array().unwrap().len(), 1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_sweep_of_three_thicknesses_makes_three_jobs_and_a_table() {
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let body = json!({
        "label": "thickness",
        "base": tiny_case(),
        "parameters": {"tube.thickness_mm": [1.27, 2.0, 3.2]}
    });
    let (location, sweep) = app.create_sweep(&body).await;
    let rows = sweep["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    for row in rows {
        let id = row["job_id"].as_str().unwrap();
        app.wait_for(id, &["succeeded"], Duration::from_secs(60))
            .await;
    }
    let table = get_json(&app.client, &app.at(&location)).await;
    let thicknesses: Vec<f64> = table["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["tube.thickness_mm"].as_f64().unwrap())
        .collect();
    assert_eq!(thicknesses, vec![1.27, 2.0, 3.2]);
    for row in table["rows"].as_array().unwrap() {
        assert_eq!(row["status"], "succeeded");
        assert!(row["mean_load_n"].is_number(), "{row}");
        // One particle through the wall: each run's verdict says so, in the table as in its job.
        assert_eq!(row["verdict"], "not_trusted", "{row}");
        assert!(
            row["verdict_reasons"]
                .as_str()
                .unwrap()
                .contains("thin_resolution"),
            "{row}"
        );
    }
    assert_eq!(table["counts"]["succeeded"], 3);
    let csv = app
        .get(&format!("{location}?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 4, "{csv}");
    assert!(
        lines[0].starts_with("job_id,tube.thickness_mm,status,mean_load_n"),
        "{csv}"
    );
    let header: Vec<&str> = lines[0].split(',').collect();
    let at = header
        .iter()
        .position(|c| *c == "verdict")
        .expect("a verdict column");
    for line in &lines[1..] {
        assert_eq!(line.split(',').nth(at), Some("not_trusted"), "{csv}");
    }
    let jobs = get_json(&app.client, &app.at("/v1/jobs?label=thickness")).await;
    assert_eq!(jobs["jobs"].as_array().unwrap().len(), 3);

    // One bad combination: no job at all, and the field named with the value that broke it.
    let bad = json!({"base": tiny_case(), "parameters": {"tube.thickness_mm": [2.0, 20.0]}});
    let r = app
        .client
        .post(app.at("/v1/sweeps"))
        .json(&bad)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 422);
    let problem: Value = r.json().await.unwrap();
    assert_eq!(
        problem["errors"][0]["field"], "tube.thickness_mm",
        "{problem}"
    );
    assert!(
        problem["errors"][0]["reason"]
            .as_str()
            .unwrap()
            .contains("20"),
        "{problem}"
    );
    let all = get_json(&app.client, &app.at("/v1/jobs")).await;
    assert_eq!(all["jobs"].as_array().unwrap().len(), 3);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_estimate_gives_the_cost_of_a_case() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let e = app.estimate(&tiny_case()).await;
    for key in ["particles", "cells", "steps", "memory_bytes", "wall_time_s"] {
        assert!(e[key].as_f64().unwrap() > 0.0, "{key} in {e}");
    }
    // What the case alone tells of the verdict: one particle through the wall and 1 mm of
    // crush; the paper's own case foretells nothing against it.
    assert_eq!(e["verdict"]["level"], "not_trusted", "{e}");
    let rules: Vec<&str> = e["verdict"]["reasons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["rule"].as_str().unwrap())
        .collect();
    assert_eq!(rules, ["thin_resolution", "too_short_to_fold"], "{e}");
    let paper = app.estimate(&json!({})).await;
    assert_eq!(paper["verdict"], json!({"level": "trusted", "reasons": []}));
    let health = app.client.get(app.at("/healthz")).send().await.unwrap();
    assert_eq!(health.status(), 200);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn openapi_describes_exactly_the_routes_the_server_answers() {
    let text = std::fs::read_to_string(repo_file("api/openapi.yaml")).unwrap();
    let doc: serde_yaml_ng::Value = serde_yaml_ng::from_str(&text).unwrap();
    let mut documented = HashSet::new();
    for (path, item) in doc["paths"].as_mapping().unwrap() {
        for (method, op) in item.as_mapping().unwrap() {
            let method = method.as_str().unwrap();
            if !["get", "post", "put", "patch", "delete"].contains(&method) {
                continue;
            }
            let responses = op["responses"]
                .as_mapping()
                .expect("every operation lists its responses");
            for (code, _) in responses {
                let code = code
                    .as_str()
                    .map(String::from)
                    .unwrap_or_else(|| format!("{}", code.as_u64().unwrap()));
                assert!(
                    code.len() == 3 || code == "default",
                    "{path:?} {method}: response {code}"
                );
            }
            documented.insert((method.to_uppercase(), path.as_str().unwrap().to_string()));
        }
    }
    let served: HashSet<(String, String)> = crush::service::routes()
        .into_iter()
        .map(|(m, p)| (m.to_string(), p.to_string()))
        .collect();
    assert_eq!(
        documented, served,
        "api/openapi.yaml and the router disagree"
    );

    // Every documented operation reaches a handler (an unknown id is a 404 from the handler,
    // not from the router's fallback).
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let id = "00000000-0000-4000-8000-000000000000";
    for (method, path) in &served {
        let url = app.at(&path.replace("{id}", id));
        let r = match method.as_str() {
            "GET" => app.client.get(url),
            "DELETE" => app.client.delete(url),
            _ => app.client.post(url).json(&json!({})),
        }
        .send()
        .await
        .unwrap();
        assert_ne!(r.status(), 405, "{method} {path}");
        let ct = r
            .headers()
            .get("content-type")
            .map(|v| v.to_str().unwrap().to_string())
            .unwrap_or_default();
        if ct.starts_with("application/problem+json") {
            let p: Value = r.json().await.unwrap();
            assert_ne!(
                p["type"], "urn:crush:problem:no-such-route",
                "{method} {path}"
            );
        }
    }
    // Schemas named by references exist.
    for cap in text.match_indices("#/components/schemas/") {
        let name: String = text[cap.0 + cap.1.len()..]
            .chars()
            .take_while(|c| c.is_alphanumeric())
            .collect();
        assert!(
            !doc["components"]["schemas"][name.as_str()].is_null(),
            "schema {name} is referenced but missing"
        );
    }
}

/// A sweep over the resolution (and a second field) gets error columns computed within each
/// group of runs that share the other swept values, and the per-group convergence analysis.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_resolution_sweep_carries_error_and_run_time_columns() {
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let body = json!({
        "label": "resolution",
        "base": tiny_case(),
        "parameters": {
            "discretization.shape": ["linear", "gimp"],
            "discretization.particles_through_thickness": [1, 2, 3]
        }
    });
    let (location, sweep) = app.create_sweep(&body).await;
    for row in sweep["rows"].as_array().unwrap() {
        app.wait_for(
            row["job_id"].as_str().unwrap(),
            &["succeeded"],
            Duration::from_secs(120),
        )
        .await;
    }
    let table = get_json(&app.client, &app.at(&location)).await;
    let columns: Vec<&str> = table["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    for c in [
        "particle_steps_per_s",
        "mean_error_vs_finest",
        "mean_error_vs_richardson",
        "mean_vs_reference",
    ] {
        assert!(columns.contains(&c), "{columns:?}");
    }
    let rows = table["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    for shape in ["linear", "gimp"] {
        let group: Vec<&Value> = rows
            .iter()
            .filter(|r| r["discretization.shape"] == shape)
            .collect();
        let finest = group
            .iter()
            .find(|r| r["discretization.particles_through_thickness"] == 3)
            .unwrap();
        assert_eq!(finest["mean_error_vs_finest"], 0.0);
        let fine_mean = finest["mean_load_n"].as_f64().unwrap();
        for r in &group {
            let mean = r["mean_load_n"].as_f64().unwrap();
            let err = r["mean_error_vs_finest"].as_f64().unwrap();
            assert!((err - (mean / fine_mean - 1.0)).abs() < 1e-12, "{r}");
            assert!(r["particle_steps_per_s"].as_f64().unwrap() > 0.0);
        }
    }
    let groups = table["convergence"].as_array().unwrap();
    assert_eq!(groups.len(), 2);
    // What the view reads off: a run of the group whose error is within 5 %, or null.
    for g in groups {
        let pick = &g["within_5_percent"];
        assert!(g.get("within_5_percent").is_some(), "{g}");
        if pick.is_null() {
            continue;
        }
        let row = g["rows"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["n"] == pick["n"])
            .expect("the pick is one of the group's runs");
        let column = match pick["against"].as_str().unwrap() {
            "richardson" => "mean_error_vs_richardson",
            _ => "mean_error_vs_finest",
        };
        assert!(row[column].as_f64().unwrap().abs() <= 0.05, "{g}");
        assert_eq!(row["wall_time_s"], pick["wall_time_s"]);
    }
    // A sweep that does not vary the resolution has no error columns.
    let plain = json!({"base": tiny_case(), "parameters": {"contact.friction": [0.0]}});
    let r: Value = app
        .client
        .post(app.at("/v1/sweeps"))
        .json(&plain)
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    let columns = r["columns"].as_array().unwrap();
    assert!(!columns.iter().any(|c| c == "mean_error_vs_finest"));
    assert!(r.get("convergence").is_none());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_ensemble_over_three_seeds_gives_the_distribution_of_its_runs() {
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let mut base = tiny_case();
    base["trigger"] = json!({"weak_fraction": 0.05, "seed": 4});
    let body = json!({"label": "seeds", "base": base, "ensemble": {"seeds": 3}});
    let (location, sweep) = app.create_sweep(&body).await;
    let seeds: Vec<u64> = sweep["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["trigger.seed"].as_u64().unwrap())
        .collect();
    assert_eq!(seeds, [4, 5, 6]);
    for row in sweep["rows"].as_array().unwrap() {
        let id = row["job_id"].as_str().unwrap();
        app.wait_for(id, &["succeeded"], Duration::from_secs(60))
            .await;
    }
    let table = get_json(&app.client, &app.at(&location)).await;
    let groups = table["ensemble"].as_array().unwrap();
    assert_eq!(groups.len(), 1, "{table}");
    let d = &groups[0]["distribution"];
    assert_eq!(d["runs"], 3, "{d}");
    // The distribution is that of the runs in the table.
    let loads: Vec<f64> = table["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["mean_load_n"].as_f64().unwrap())
        .collect();
    let mean = loads.iter().sum::<f64>() / 3.0;
    assert!((d["mean_load_n"]["mean"].as_f64().unwrap() - mean).abs() <= 1e-9 * mean);
    let min = loads.iter().copied().fold(f64::INFINITY, f64::min);
    assert_eq!(d["mean_load_n"]["min"].as_f64().unwrap(), min);
    let counted: u64 = d["modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["runs"].as_u64().unwrap())
        .sum();
    assert_eq!(counted, 3);
    // The CSV carries each row's group distribution.
    let csv = app
        .get(&format!("{location}?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for column in ["ensemble_runs", "ensemble_modes", "ensemble_sd_load_n"] {
        assert!(header.contains(&column), "{column} in {csv}");
    }
    let runs_at = header.iter().position(|c| *c == "ensemble_runs").unwrap();
    assert!(
        csv.lines()
            .skip(1)
            .all(|l| l.split(',').nth(runs_at) == Some("3")),
        "{csv}"
    );

    // Without a trigger every seed is the same run: refused, nothing stored.
    let flat = json!({"base": tiny_case(), "ensemble": {"seeds": 3}});
    let r = app.post_json("/v1/sweeps", &flat).await;
    assert_eq!(r.status(), 422);
    let problem: Value = r.json().await.unwrap();
    assert_eq!(problem["errors"][0]["field"], "ensemble", "{problem}");
    let all = get_json(&app.client, &app.at("/v1/jobs")).await;
    assert_eq!(all["jobs"].as_array().unwrap().len(), 3);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_square_tube_runs_and_reports_its_own_closed_forms_mass_and_mode() {
    let app = TestApp::start(&[]).await;
    // Missing its side, and with a round tube's diameter: both named.
    let r = app
        .post_json(
            "/v1/jobs",
            &json!({"tube": {"section": "rectangular", "mean_diameter_mm": 20}}),
        )
        .await;
    assert_eq!(r.status(), 422);
    let problem: Value = r.json().await.unwrap();
    let fields: HashSet<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["field"].as_str().unwrap())
        .collect();
    assert_eq!(
        fields,
        HashSet::from(["tube.side_a_mm", "tube.mean_diameter_mm"]),
        "{problem}"
    );

    let case = json!({
        "tube": {"section": "rectangular", "thickness_mm": 2, "side_a_mm": 12,
                 "corner_radius_mm": 2, "length_mm": 6},
        "discretization": {"particles_through_thickness": 1},
        "loading": {"crush_distance_mm": 1, "plate_speed_m_s": 20},
        "output": {"history_points": 20}
    });
    let job = app.submit(&case).await;
    let id = job["id"].as_str().unwrap();
    let job = app
        .wait_for(id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["case"], case);
    let s = &job["summary"];
    // Abramowicz & Jones's square tube is the primary reference, by hand:
    // 13.06 σ₀ t^(5/3) c^(1/3) = 13.06 · 65.5 · 2^(5/3) · 12^(1/3) = 6 213 N.
    let r = &s["references"];
    assert_eq!(r["primary"], "abramowicz_jones");
    let want = 13.06 * 65.5 * 2f64.powf(5.0 / 3.0) * 12f64.cbrt();
    assert!(
        (r["primary_n"].as_f64().unwrap() / want - 1.0).abs() < 1e-9,
        "{r}"
    );
    assert!(r.get("alexander_ring_n").is_none(), "{r}");
    // The mass is ρ t P l with the mid-line's P = 4 (a − 2r) + 2π r.
    let perimeter = 4.0 * (12.0 - 4.0) + 2.0 * std::f64::consts::PI * 2.0;
    let mass = 1380.0 * 2.0 * perimeter * 6.0 * 1e-6;
    let got = s["tube_mass_g"].as_f64().unwrap();
    assert!((got / mass - 1.0).abs() < 1e-9, "{got} g vs {mass} g");
    let kind = s["mode"]["kind"].as_str().unwrap();
    assert!(
        [
            "symmetric",
            "asymmetric_mixed",
            "extensional",
            "global_buckling",
            "tipped_over"
        ]
        .contains(&kind),
        "{kind}"
    );
}
