//! Keeping the store tidy through the real server, on either backend: the list of sweeps, label
//! search, deleting a finished job or sweep (with the token roles of a cancel), and retention
//! (`--keep-days`).

use crate::common::*;
use serde_json::{json, Value};
use std::collections::HashSet;
use std::time::{Duration, Instant};

const ALICE: &str = "alice-admin-0123456789abcdef";
const CI: &str = "ci-submit-0123456789abcdefgh";
const BOB: &str = "bob-submit-0123456789abcdefg";
const GRAFANA: &str = "grafana-read-0123456789abcd";

/// A server with an admin, two submitters and a reader that runs jobs, and the folder holding
/// its token file.
async fn with_tokens() -> (TestApp, tempfile::TempDir) {
    let files = tempfile::tempdir().unwrap();
    let path = files.path().join("tokens");
    let text =
        format!("alice admin {ALICE}\nci submit {CI}\nbob submit {BOB}\ngrafana read {GRAFANA}\n");
    std::fs::write(&path, text).unwrap();
    let flags = [
        "--concurrent-jobs",
        "1",
        "--token-file",
        path.to_str().unwrap(),
    ];
    (TestApp::start(&flags).await, files)
}

fn sweep_body(label: &str) -> Value {
    json!({"label": label, "base": tiny_case(), "parameters": {"tube.thickness_mm": [2.0, 3.2]}})
}

async fn wait_all(app: &TestApp, sweep: &Value, token: Option<&str>) {
    for row in sweep["rows"].as_array().unwrap() {
        let id = row["job_id"].as_str().unwrap();
        let start = Instant::now();
        loop {
            let mut r = app.client.get(app.at(&format!("/v1/jobs/{id}")));
            if let Some(t) = token {
                r = r.bearer_auth(t);
            }
            let job: Value = r.send().await.unwrap().json().await.unwrap();
            if job["status"] == "succeeded" {
                break;
            }
            assert!(start.elapsed() < Duration::from_secs(60), "{job}");
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sweeps_are_listed_newest_first_page_by_page_with_their_counts() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let mut made = Vec::new();
    for i in 0..5 {
        let (_, sweep) = app.create_sweep(&sweep_body(&format!("wall {i}"))).await;
        made.push(sweep["id"].as_str().unwrap().to_string());
        // Sweeps are ordered by when they were made, to the millisecond.
        tokio::time::sleep(Duration::from_millis(3)).await;
    }
    let mut listed = Vec::new();
    let mut cursor: Option<String> = None;
    loop {
        let mut url = app.at("/v1/sweeps?limit=2");
        if let Some(c) = &cursor {
            url.push_str(&format!("&cursor={c}"));
        }
        let page = get_json(&app.client, &url).await;
        let sweeps = page["sweeps"].as_array().unwrap();
        assert!(sweeps.len() <= 2, "{page}");
        for s in sweeps {
            assert_eq!(s["jobs"], 2, "{s}");
            assert_eq!(s["counts"]["queued"], 2, "{s}");
            assert_eq!(s["counts"]["succeeded"], 0, "{s}");
            assert_eq!(s["parameters"][0][0], "tube.thickness_mm", "{s}");
            let id = s["id"].as_str().unwrap();
            assert_eq!(s["links"]["self"], format!("/v1/sweeps/{id}"));
            listed.push(id.to_string());
        }
        match page["next_cursor"].as_str() {
            Some(c) => cursor = Some(c.to_string()),
            None => break,
        }
    }
    made.reverse();
    assert_eq!(listed, made, "newest first, each once");
    let found = get_json(&app.client, &app.at("/v1/sweeps?search=ALL%203")).await;
    let found = found["sweeps"].as_array().unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0]["label"], "wall 3");
    for bad in [
        "limit=0",
        "limit=501",
        "cursor=abc",
        &format!("search={}", "x".repeat(101)),
    ] {
        let r = app.get(&format!("/v1/sweeps?{bad}")).await;
        assert_eq!(r.status(), 400, "{bad}");
    }
}

/// `GET /v1/jobs?search=` matches part of a label, whatever the case of its ASCII letters, and
/// LIKE's wildcards in the text match only themselves.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn label_search_finds_part_of_a_label_and_wildcards_match_themselves() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    for label in [
        "Paper axial n4",
        "paper lateral",
        "speed_10",
        "speed 100%",
        "other",
    ] {
        let mut case = tiny_case();
        case["label"] = json!(label);
        app.submit(&case).await;
    }
    let labels = |page: Value| -> HashSet<String> {
        page["jobs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j["label"].as_str().unwrap().to_string())
            .collect()
    };
    let search = |q: &'static str| {
        let url = app.at(&format!("/v1/jobs?search={q}"));
        let client = app.client.clone();
        async move { get_json(&client, &url).await }
    };
    let set = |l: &[&str]| l.iter().map(|s| s.to_string()).collect::<HashSet<_>>();
    assert_eq!(
        labels(search("PAPER").await),
        set(&["Paper axial n4", "paper lateral"])
    );
    assert_eq!(labels(search("_1").await), set(&["speed_10"]));
    assert_eq!(labels(search("100%25").await), set(&["speed 100%"]));
    assert_eq!(labels(search("%25").await), set(&["speed 100%"]));
    assert_eq!(labels(search("nothing").await), set(&[]));
    // With a status filter and paging.
    let page = search("e").await;
    assert_eq!(page["jobs"].as_array().unwrap().len(), 5);
    let first = get_json(
        &app.client,
        &app.at("/v1/jobs?search=speed&status=queued&limit=1"),
    )
    .await;
    assert_eq!(labels(first.clone()), set(&["speed 100%"]));
    let cursor = first["next_cursor"].as_str().unwrap();
    let next = get_json(
        &app.client,
        &app.at(&format!(
            "/v1/jobs?search=speed&status=queued&limit=1&cursor={cursor}"
        )),
    )
    .await;
    assert_eq!(labels(next), set(&["speed_10"]));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_finished_job_is_deleted_with_its_results_and_an_unfinished_one_is_409() {
    let app = TestApp::start(&["--concurrent-jobs", "1"]).await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&id, &["succeeded"], Duration::from_secs(60))
        .await;
    let blocker = app.submit(&long_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&blocker, &["running"], Duration::from_secs(30))
        .await;
    let r = app
        .client
        .delete(app.at(&format!("/v1/jobs/{blocker}")))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 409);
    let p: Value = r.json().await.unwrap();
    assert!(p["detail"].as_str().unwrap().contains("running"), "{p}");

    let r = app
        .client
        .delete(app.at(&format!("/v1/jobs/{id}")))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 204);
    for path in [
        "",
        "/history",
        "/summary",
        "/shape.png",
        "/state.vtu",
        "/events",
    ] {
        let r = app.get(&format!("/v1/jobs/{id}{path}")).await;
        assert_eq!(r.status(), 404, "{path}");
    }
    let listed = get_json(&app.client, &app.at("/v1/jobs")).await;
    assert!(!listed.to_string().contains(&id), "{listed}");
    let again = app
        .client
        .delete(app.at(&format!("/v1/jobs/{id}")))
        .send()
        .await
        .unwrap();
    assert_eq!(again.status(), 404);
    app.post(&format!("/v1/jobs/{blocker}/cancel")).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_sweep_is_deleted_whole_once_its_jobs_have_finished_and_not_one_job_at_a_time() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let (location, sweep) = app.create_sweep(&sweep_body("to delete")).await;
    let rows = sweep["rows"].as_array().unwrap();
    let jobs: Vec<String> = rows
        .iter()
        .map(|r| r["job_id"].as_str().unwrap().to_string())
        .collect();
    let r = app.client.delete(app.at(&location)).send().await.unwrap();
    assert_eq!(r.status(), 409);
    let p: Value = r.json().await.unwrap();
    assert!(
        p["detail"].as_str().unwrap().starts_with("2 of the jobs"),
        "{p}"
    );
    for id in &jobs {
        assert_eq!(
            app.post(&format!("/v1/jobs/{id}/cancel")).await.status(),
            200
        );
    }
    let r = app
        .client
        .delete(app.at(&format!("/v1/jobs/{}", jobs[0])))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 409, "a job of a sweep goes with its sweep");
    let p: Value = r.json().await.unwrap();
    assert!(p["detail"].as_str().unwrap().contains(&location), "{p}");
    let r = app.client.delete(app.at(&location)).send().await.unwrap();
    assert_eq!(r.status(), 204);
    assert_eq!(app.get(&location).await.status(), 404);
    for id in &jobs {
        assert_eq!(app.get(&format!("/v1/jobs/{id}")).await.status(), 404);
    }
    let list = get_json(&app.client, &app.at("/v1/sweeps")).await;
    assert_eq!(list["sweeps"].as_array().unwrap().len(), 0, "{list}");
}

/// Deleting follows the cancel rules: a reader may not, a submitter only its own jobs and
/// sweeps, an admin any.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_submitter_deletes_only_its_own_jobs_and_sweeps_and_an_admin_any() {
    let (app, _files) = with_tokens().await;
    let submit = |token: &'static str, case: Value| {
        let r = app
            .client
            .post(app.at("/v1/jobs"))
            .bearer_auth(token)
            .json(&case);
        async move {
            let r = r.send().await.unwrap();
            assert_eq!(r.status(), 202);
            r.json::<Value>().await.unwrap()["id"]
                .as_str()
                .unwrap()
                .to_string()
        }
    };
    let delete = |token: &'static str, path: String| {
        let r = app.client.delete(app.at(&path)).bearer_auth(token);
        async move { r.send().await.unwrap().status().as_u16() }
    };
    let ci_job = submit(CI, tiny_case()).await;
    let bob_job = submit(BOB, tiny_case()).await;
    let r = app
        .client
        .post(app.at("/v1/sweeps"))
        .bearer_auth(CI)
        .json(&sweep_body("ci's"))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 202);
    let sweep: Value = r.json().await.unwrap();
    assert_eq!(sweep["owner"], "ci");
    let sweep_path = format!("/v1/sweeps/{}", sweep["id"].as_str().unwrap());
    for id in [&ci_job, &bob_job] {
        let start = Instant::now();
        loop {
            let r = app
                .client
                .get(app.at(&format!("/v1/jobs/{id}")))
                .bearer_auth(GRAFANA);
            let job: Value = r.send().await.unwrap().json().await.unwrap();
            if job["status"] == "succeeded" {
                break;
            }
            assert!(start.elapsed() < Duration::from_secs(60), "{job}");
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    }
    wait_all(&app, &sweep, Some(GRAFANA)).await;
    let listed = app
        .client
        .get(app.at("/v1/sweeps"))
        .bearer_auth(GRAFANA)
        .send()
        .await
        .unwrap();
    let listed: Value = listed.json().await.unwrap();
    assert_eq!(listed["sweeps"][0]["owner"], "ci");
    assert_eq!(listed["sweeps"][0]["counts"]["succeeded"], 2);

    assert_eq!(delete(GRAFANA, format!("/v1/jobs/{ci_job}")).await, 403);
    assert_eq!(delete(BOB, format!("/v1/jobs/{ci_job}")).await, 403);
    assert_eq!(delete(BOB, sweep_path.clone()).await, 403);
    let r = app
        .client
        .delete(app.at(&format!("/v1/jobs/{ci_job}")))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 401);
    assert_eq!(delete(CI, format!("/v1/jobs/{ci_job}")).await, 204);
    assert_eq!(delete(CI, sweep_path.clone()).await, 204);
    assert_eq!(delete(ALICE, format!("/v1/jobs/{bob_job}")).await, 204);
    assert_eq!(delete(ALICE, sweep_path).await, 404);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn keep_days_prunes_finished_jobs_and_sweeps_and_keeps_unfinished_ones() {
    // 0.00003 days is 2.6 s: the pass runs every second.
    let app = TestApp::start(&["--concurrent-jobs", "1", "--keep-days", "0.00003"]).await;
    let done = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&done, &["succeeded"], Duration::from_secs(60))
        .await;
    let (location, sweep) = app.create_sweep(&sweep_body("kept a while")).await;
    wait_all(&app, &sweep, None).await;
    // Queued behind a job that runs until it is cancelled: never finished, never pruned.
    let blocker = app.submit(&long_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let waiting = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let start = Instant::now();
    while app.get(&format!("/v1/jobs/{done}")).await.status() != 404
        || app.get(&location).await.status() != 404
    {
        assert!(start.elapsed() < Duration::from_secs(30), "not pruned");
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    for row in sweep["rows"].as_array().unwrap() {
        let id = row["job_id"].as_str().unwrap();
        assert_eq!(app.get(&format!("/v1/jobs/{id}")).await.status(), 404);
    }
    for id in [&blocker, &waiting] {
        assert_eq!(app.get(&format!("/v1/jobs/{id}")).await.status(), 200);
    }
    app.post(&format!("/v1/jobs/{blocker}/cancel")).await;
    // A negative or non-finite setting is refused at start.
    for bad in ["-1", "NaN", "1e300"] {
        let bad_flag = format!("--keep-days={bad}");
        let dir = tempfile::tempdir().unwrap();
        let db = database_url(dir.path());
        let flags = ["--port", "0", "--database-url", &db, &bad_flag];
        let args = crush::service::ServeArgs::from_flags(flags).unwrap();
        let error = crush::service::start(args).await.err().expect(bad);
        assert!(error.to_string().contains("--keep-days"), "{error}");
    }
}
