//! Several nodes on one PostgreSQL database, against a real server: three nodes share
//! 300 jobs, each run exactly once; a client of one node follows a run on another and a cancel
//! sent to a third stops it; a node killed mid-run loses its job to another, which finishes it
//! once, and the killed node rejoins. Run with `eval "$(bash .ci/postgres)"` (or any server
//! named by `CRUSH_TEST_POSTGRES`); without one the tests show as ignored.

use crate::common::*;
use futures::StreamExt;
use serde_json::Value;
use sqlx::{Connection, PgConnection};
use std::collections::{HashMap, HashSet};
use std::time::{Duration, Instant};

async fn connect(db: &str) -> PgConnection {
    PgConnection::connect(db).await.unwrap()
}

/// One job as the database holds it.
#[derive(Debug, sqlx::FromRow)]
struct Entry {
    status: String,
    attempts: i64,
    /// Times its worker was lost.
    lost: i64,
    worker: Option<String>,
    history: i64,
    summaries: i64,
}

/// Every job of the database, by id.
async fn ledger(db: &str) -> HashMap<String, Entry> {
    let mut c = connect(db).await;
    let rows: Vec<(String,)> = sqlx::query_as("SELECT id FROM jobs")
        .fetch_all(&mut c)
        .await
        .unwrap();
    let mut out = HashMap::new();
    for (id,) in rows {
        let entry: Entry = sqlx::query_as(
            "SELECT status, attempts, lost, worker, \
             (SELECT COUNT(*) FROM history h WHERE h.job_id = j.id) AS history, \
             (SELECT COUNT(*) FROM summaries s WHERE s.job_id = j.id) AS summaries \
             FROM jobs j WHERE id = $1",
        )
        .bind(&id)
        .fetch_one(&mut c)
        .await
        .unwrap();
        out.insert(id, entry);
    }
    out
}

async fn node(db: &str, name: &str, flags: &[&str]) -> TestApp {
    let mut all = vec!["--node-name", name, "--heartbeat-ms", "200"];
    all.extend_from_slice(flags);
    TestApp::start_on(db, &all).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn three_nodes_run_300_jobs_each_exactly_once_and_share_the_work() {
    let db = fresh_postgres_database();
    let flags = ["--concurrent-jobs", "1", "--max-queue", "1000"];
    // All three start at once on the empty database: the migrations run once, under
    // PostgreSQL's advisory lock, whichever node gets it first.
    let (n1, n2, n3) = tokio::join!(
        node(&db, "n1", &flags),
        node(&db, "n2", &flags),
        node(&db, "n3", &flags)
    );
    let nodes = [n1, n2, n3];
    let case = tiny_case();
    let submitted: Vec<String> = futures::stream::iter(0..300)
        .map(|k| {
            let app = &nodes[k % 3];
            let case = &case;
            async move { app.submit(case).await["id"].as_str().unwrap().to_string() }
        })
        .buffer_unordered(48)
        .collect()
        .await;
    assert_eq!(submitted.iter().collect::<HashSet<_>>().len(), 300);
    let deadline = Instant::now() + Duration::from_secs(300);
    let ledger = loop {
        let ledger = ledger(&db).await;
        if ledger.values().all(|j| j.status == "succeeded") {
            break ledger;
        }
        assert!(
            Instant::now() < deadline,
            "not all jobs ended: {:?}",
            ledger
                .values()
                .filter(|j| j.status != "succeeded")
                .take(3)
                .collect::<Vec<_>>()
        );
        tokio::time::sleep(Duration::from_millis(250)).await;
    };
    assert_eq!(ledger.len(), 300);
    let rows = ledger.values().next().unwrap().history;
    assert!(rows > 10, "{rows} history rows");
    let mut per_node: HashMap<String, usize> = HashMap::new();
    for (id, job) in &ledger {
        // One claim (a second would need the first lost or taken): no job ran on two nodes.
        assert_eq!(
            (job.attempts, job.lost),
            (1, 0),
            "job {id} was claimed more than once"
        );
        assert_eq!(
            (job.history, job.summaries),
            (rows, 1),
            "job {id} stored other than once"
        );
        *per_node.entry(job.worker.clone().unwrap()).or_default() += 1;
    }
    assert_eq!(per_node.len(), 3, "every node ran jobs: {per_node:?}");
    // Spread, not one node doing nearly all: each ran at least a tenth.
    assert!(per_node.values().all(|n| *n >= 30), "{per_node:?}");
    for app in nodes {
        app.server.unwrap().stop().await.unwrap();
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn a_client_of_node_a_follows_a_run_on_node_b_and_a_cancel_sent_to_node_c_stops_it() {
    let db = fresh_postgres_database();
    let a = node(&db, "a", &["--concurrent-jobs", "0"]).await;
    let b = node(&db, "b", &["--concurrent-jobs", "1"]).await;
    let c = node(&db, "c", &["--concurrent-jobs", "0"]).await;

    // A run of 500 history rows on B, followed from A from before it starts.
    let id = a.submit(&medium_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let url = a.at(&format!("/v1/jobs/{id}/events"));
    let (status, mut events) = SseReader::open(&a.client, &url, None).await;
    assert_eq!(status, 200);
    let mut progress = Vec::new();
    let end = loop {
        let e = events
            .next(Duration::from_secs(60))
            .await
            .expect("the stream goes on to the final event");
        match e.event.as_str() {
            "progress" => progress.push(e.id.unwrap()),
            "status" => {}
            _ => break e,
        }
    };
    assert_eq!(end.event, "done", "{}", end.data);
    assert_eq!(end.json()["node"], "b");
    assert_eq!(
        progress.len(),
        500,
        "every progress event of the run on B reached A"
    );
    assert!(
        progress.windows(2).all(|w| w[1] == w[0] + 1),
        "consecutive ids, none lost or repeated"
    );

    // A long run on B, followed from A, cancelled through C.
    let id = a.submit(&long_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let url = a.at(&format!("/v1/jobs/{id}/events"));
    let (_, mut events) = SseReader::open(&a.client, &url, None).await;
    loop {
        let e = events.next(Duration::from_secs(60)).await.expect("events");
        if e.event == "progress" {
            break;
        }
    }
    let asked = Instant::now();
    let r = c.post(&format!("/v1/jobs/{id}/cancel")).await;
    assert_eq!(r.status(), 202);
    let end = loop {
        let e = events
            .next(Duration::from_secs(30))
            .await
            .expect("the stream ends with the cancel");
        if e.event != "progress" {
            break e;
        }
    };
    let took = asked.elapsed();
    assert_eq!(end.event, "cancelled", "{}", end.data);
    // The signal reaches B at once; B's heartbeat (200 ms here) would see it too.
    assert!(took < Duration::from_secs(3), "the cancel took {took:?}");
    let job: Value = c.job(&id).await;
    assert_eq!(
        (job["status"].as_str(), job["node"].as_str()),
        (Some("cancelled"), Some("b"))
    );
    // /metrics names the node and its store; b, which ran both jobs, has a histogram of its
    // two claims' latencies.
    let metrics = c.get("/metrics").await.text().await.unwrap();
    assert!(
        metrics.contains("crush_node{node=\"c\",backend=\"postgres\"} 1"),
        "{metrics}"
    );
    let metrics = b.get("/metrics").await.text().await.unwrap();
    assert!(
        metrics.lines().any(|l| l == "crush_claim_seconds_count 2")
            && metrics.contains("crush_claim_seconds_bucket{le=\"+Inf\"} 2"),
        "{metrics}"
    );
    for app in [a, b, c] {
        app.server.unwrap().stop().await.unwrap();
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn a_node_killed_mid_run_loses_its_job_to_another_that_finishes_it_once_and_it_rejoins() {
    let db = fresh_postgres_database();
    let flags = |name: &'static str| {
        vec![
            "--node-name",
            name,
            "--heartbeat-ms",
            "200",
            "--stale-after-s",
            "2",
        ]
    };
    let mut one = Child::start(&db, &flags("one"));
    let client = client();
    let id = submit_to(&client, &one.url, &killable_case()).await;
    // Running on `one`, with progress stored.
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let job = get_json(&client, &format!("{}/v1/jobs/{id}", one.url)).await;
        if job["progress"]["fraction"].as_f64().unwrap_or(0.0) > 0.0 {
            assert_eq!(
                (job["status"].as_str(), job["node"].as_str()),
                (Some("running"), Some("one"))
            );
            break;
        }
        assert!(Instant::now() < deadline, "the run did not start: {job}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // Killed at once, mid-run; the second node starts after.
    unsafe { libc::kill(one.pid(), libc::SIGKILL) };
    one.exited_within(Duration::from_secs(5)).expect("killed");
    let two = Child::start(&db, &flags("two"));
    let job = wait_for(
        &client,
        &two.url,
        &id,
        &["succeeded"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(job["node"], "two");
    assert_eq!(job["attempts"], 2);
    let ledger = ledger(&db).await;
    let entry = &ledger[&id];
    let history = entry.history;
    assert_eq!((entry.lost, entry.summaries), (1, 1));
    let (span,): (i64,) =
        sqlx::query_as("SELECT COALESCE(MAX(row) + 1, 0) FROM history WHERE job_id = $1")
            .bind(&id)
            .fetch_one(&mut connect(&db).await)
            .await
            .unwrap();
    assert!(
        history >= 500 && history == span,
        "one history of the 500 points asked: {history} rows numbered 0..{span}"
    );

    // The killed node comes back under its name and runs jobs again.
    let one = Child::start(&db, &flags("one"));
    assert_eq!(
        client
            .get(format!("{}/healthz", one.url))
            .send()
            .await
            .unwrap()
            .status(),
        200
    );
    let mut ran_on_one = false;
    for _ in 0..6 {
        let id = submit_to(&client, &one.url, &tiny_case()).await;
        let job = wait_for(
            &client,
            &one.url,
            &id,
            &["succeeded"],
            Duration::from_secs(60),
        )
        .await;
        ran_on_one |= job["node"] == "one";
    }
    assert!(ran_on_one, "the restarted node took part in the work");
}

/// `compose.yaml` starts what docs/operations.md says: PostgreSQL and three crush nodes on it,
/// each with a name of its own, and one published port. (Docker is not on the test machines, so
/// this reads the file; it does not start it.)
#[test]
fn compose_starts_postgres_and_three_named_nodes_behind_one_port() {
    let text = std::fs::read_to_string(repo_file("compose.yaml")).unwrap();
    let mut doc: serde_yaml_ng::Value = serde_yaml_ng::from_str(&text).unwrap();
    doc.apply_merge().unwrap();
    let services = doc["services"].as_mapping().unwrap();
    let mut names = HashSet::new();
    let mut published = 0;
    let (mut images, mut builds) = (HashSet::new(), 0);
    for (name, service) in services {
        let name = name.as_str().unwrap();
        published += service["ports"].as_sequence().map_or(0, |p| p.len());
        if name == "postgres" {
            continue;
        }
        images.insert(service["image"].as_str().unwrap().to_string());
        builds += usize::from(!service["build"].is_null());
        let mut env = service["environment"].clone();
        env.apply_merge().unwrap();
        // Docker must wait longer than the server's shutdown: the grace for the running job,
        // then up to 30 s to checkpoint and requeue it (`Workers::drain`).
        let grace: f64 = env["CRUSH_SHUTDOWN_GRACE_S"]
            .as_str()
            .unwrap()
            .parse()
            .unwrap();
        let stop = service["stop_grace_period"].as_str().unwrap();
        let stop: f64 = stop.strip_suffix('s').unwrap().parse().unwrap();
        assert!(stop > grace + 30.0, "{name}: stop_grace_period {stop} s");
        let url = env["DATABASE_URL"].as_str().unwrap();
        assert!(
            url.starts_with("postgres://") && url.contains("@postgres:"),
            "{url}"
        );
        assert!(names.insert(env["CRUSH_NODE_NAME"].as_str().unwrap().to_string()));
        assert_eq!(
            service["depends_on"]["postgres"]["condition"].as_str(),
            Some("service_healthy")
        );
    }
    assert!(services.contains_key("postgres"));
    assert_eq!(names.len(), 3, "three crush nodes with names of their own");
    assert_eq!(published, 1, "one port for the page");
    assert_eq!(images.len(), 1, "one image for every node: {images:?}");
    assert_eq!(builds, 1, "built once");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn a_node_killed_at_80_percent_hands_its_job_to_another_that_resumes_it_with_the_same_bits() {
    let db = fresh_postgres_database();
    let flags = |name: &'static str, jobs: &'static str| {
        vec![
            "--node-name",
            name,
            "--heartbeat-ms",
            "200",
            "--stale-after-s",
            "1",
            "--checkpoint-every-s",
            "0.25",
            "--concurrent-jobs",
            jobs,
        ]
    };
    let client = client();
    let case = resumable_case();
    // `two` starts only once `one` is killed: the job runs on `one` first.
    let mut one = Child::start(&db, &flags("one", "1"));
    let id = submit_to(&client, &one.url, &case).await;
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let job = get_json(&client, &format!("{}/v1/jobs/{id}", one.url)).await;
        assert_eq!(
            job["status"].as_str().map(|s| s == "succeeded"),
            Some(false),
            "{job}"
        );
        if job["checkpoint"]["fraction"].as_f64().unwrap_or(0.0) >= 0.75 {
            assert_eq!(job["node"], "one");
            break;
        }
        assert!(Instant::now() < deadline, "no checkpoint: {job}");
        tokio::time::sleep(Duration::from_millis(25)).await;
    }
    unsafe { libc::kill(one.pid(), libc::SIGKILL) };
    one.exited_within(Duration::from_secs(5)).expect("killed");
    let two = Child::logged(&db, &flags("two", "1"), "info");
    let job = wait_for(
        &client,
        &two.url,
        &id,
        &["succeeded"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(
        (job["node"].as_str(), job["attempts"].as_i64()),
        (Some("two"), Some(2))
    );
    assert!(two.logged_line("resuming from the checkpoint"));

    let csv = |id: String| {
        let (client, url) = (client.clone(), two.url.clone());
        async move {
            let r = client
                .get(format!("{url}/v1/jobs/{id}/history?format=csv"))
                .send()
                .await
                .unwrap();
            r.text().await.unwrap()
        }
    };
    let whole = submit_to(&client, &two.url, &case).await;
    wait_for(
        &client,
        &two.url,
        &whole,
        &["succeeded"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(csv(id).await, csv(whole).await);
}

/// What broke: sqlx's `Any` driver sends a NULL f64 to PostgreSQL as a float4, so a heartbeat
/// without progress prepared the statement with a 4-byte parameter on its connection, and the
/// next beat with progress on that connection failed with "incorrect binary data format in bind
/// parameter 3" (one beat in three on a node; gaps near the stale limit).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn heartbeats_with_and_without_progress_share_a_pooled_connection() {
    use crush::service::store::{NewJob, Store};
    let store = Store::open(&fresh_postgres_database()).await.unwrap();
    let id = uuid::Uuid::new_v4();
    let job = NewJob {
        id,
        case_json: "{}".into(),
        label: None,
        particles: 10,
        idempotency_key: None,
    };
    store.submit(job, 10).await.unwrap();
    let claim = store.claim("n1").await.unwrap().unwrap();
    // One after another, so that the pool hands every beat the same connection.
    for k in 0..12 {
        let json = format!("{{\"step\":{k}}}");
        let progress = (k % 3 != 0).then(|| (json.as_str(), k as f64 / 12.0));
        let beat = store.heartbeat(id, claim.lease, progress).await;
        assert_eq!(
            beat.unwrap(),
            Some(false),
            "beat {k}, progress {progress:?}"
        );
    }
    let stored = store.job(id).await.unwrap().unwrap();
    assert_eq!(stored.progress_json.as_deref(), Some("{\"step\":11}"));
    store.close().await;
}
