//! The PostgreSQL server restarted under load, and stopped for a while: nodes keep
//! serving what needs no database, answer 503 with `Retry-After` where they need it (never
//! 500), reconnect by themselves, and every submit answered 202 ends succeeded with one history
//! and one summary. In a test binary of its own, since it stops the server every other
//! PostgreSQL test uses; the two tests here take turns. Needs `eval "$(bash .ci/postgres)"`
//! (CRUSH_TEST_POSTGRES and CRUSH_TEST_PG_CTL).

mod common;

use common::*;
use serde_json::Value;
use sqlx::{Connection, PgConnection};
use std::time::{Duration, Instant};

/// One test at a time stops the server.
static SERVER: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

/// Runs `pg_ctl ACTION` on the test server.
fn control(action: &str) {
    let pg_ctl = std::env::var("CRUSH_TEST_PG_CTL")
        .expect("CRUSH_TEST_PG_CTL: the pg_ctl command of the test server (.ci/postgres)");
    let status = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("{pg_ctl} {action} >/dev/null"))
        .status()
        .unwrap();
    assert!(status.success(), "pg_ctl {action} failed");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn a_node_that_loses_its_database_answers_503_serves_the_rest_and_reconnects() {
    let _turn = SERVER.lock().await;
    let db = fresh_postgres_database();
    let app = TestApp::start_on(&db, &["--node-name", "alone", "--heartbeat-ms", "200"]).await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&id, &["succeeded"], Duration::from_secs(30))
        .await;
    control("stop -m fast -w");
    let down = Instant::now();
    let r = app.get("/healthz").await;
    assert_eq!(r.status(), 503);
    assert!(r.headers().contains_key("retry-after"));
    let r = app
        .client
        .post(app.at("/v1/jobs"))
        .json(&tiny_case())
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 503, "{}", r.text().await.unwrap());
    let r = app.get(&format!("/v1/jobs/{id}")).await;
    assert_eq!(r.status(), 503);
    assert!(r.headers().contains_key("retry-after"));
    // What needs no database goes on: the page and the estimate.
    assert_eq!(app.get("/").await.status(), 200);
    let r = app
        .client
        .post(app.at("/v1/estimate"))
        .json(&tiny_case())
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    eprintln!("503s answered within {:?} of the stop", down.elapsed());
    control("start -w");
    // Back by itself: no restart of the node.
    let deadline = Instant::now() + Duration::from_secs(30);
    while app.get("/healthz").await.status() != 200 {
        assert!(Instant::now() < deadline, "the node did not reconnect");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let again = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let job = app
        .wait_for(&again, &["succeeded"], Duration::from_secs(30))
        .await;
    assert_eq!(job["node"], "alone");
    app.server.unwrap().stop().await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn a_postgres_restart_under_load_loses_nothing_and_stores_nothing_twice() {
    let _turn = SERVER.lock().await;
    let db = fresh_postgres_database();
    let flags = |name| {
        [
            "--node-name",
            name,
            "--heartbeat-ms",
            "200",
            "--stale-after-s",
            "3",
            "--concurrent-jobs",
            "1",
        ]
    };
    let nodes = [
        TestApp::start_on(&db, &flags("n1")).await,
        TestApp::start_on(&db, &flags("n2")).await,
    ];
    let restart = tokio::task::spawn_blocking(|| {
        std::thread::sleep(Duration::from_millis(1500));
        control("restart -m fast -w");
    });
    let case = tiny_case();
    let started = Instant::now();
    let mut accepted = Vec::new();
    let mut refused = 0;
    let mut after_restart = 0;
    let mut k = 0;
    while started.elapsed() < Duration::from_secs(8) {
        let app = &nodes[k % 2];
        k += 1;
        let r = app
            .client
            .post(app.at("/v1/jobs"))
            .json(&case)
            .send()
            .await
            .unwrap();
        match r.status().as_u16() {
            202 => {
                accepted.push(
                    r.json::<Value>().await.unwrap()["id"]
                        .as_str()
                        .unwrap()
                        .to_string(),
                );
                if restart.is_finished() {
                    after_restart += 1;
                }
            }
            503 => {
                assert!(r.headers().contains_key("retry-after"));
                refused += 1;
            }
            other => panic!("submit answered {other}: {}", r.text().await.unwrap()),
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    restart.await.unwrap();
    assert!(
        after_restart > 0,
        "no submit was accepted after the restart"
    );
    eprintln!(
        "{} accepted, {refused} refused (503) around the restart",
        accepted.len()
    );
    let mut c = PgConnection::connect(&db).await.unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    let rows = loop {
        let rows: Vec<(String, String, i64, i64, i64)> = sqlx::query_as(
            "SELECT j.id, j.status, (SELECT COUNT(*) FROM history h WHERE h.job_id = j.id), \
             (SELECT COALESCE(MAX(row) + 1, 0) FROM history h WHERE h.job_id = j.id), \
             (SELECT COUNT(*) FROM summaries s WHERE s.job_id = j.id) FROM jobs j",
        )
        .fetch_all(&mut c)
        .await
        .unwrap();
        if rows.iter().all(|r| r.1 == "succeeded") {
            break rows;
        }
        assert!(
            Instant::now() < deadline,
            "jobs did not all end after the restart"
        );
        tokio::time::sleep(Duration::from_millis(250)).await;
    };
    for id in &accepted {
        assert!(
            rows.iter().any(|r| &r.0 == id),
            "accepted job {id} was lost"
        );
    }
    let history = rows[0].2;
    for (id, _, n, span, summaries) in &rows {
        assert_eq!((*n, *span, *summaries), (history, history, 1), "job {id}");
    }
    for app in &nodes {
        assert_eq!(app.get("/healthz").await.status(), 200);
    }
    for app in nodes {
        app.server.unwrap().stop().await.unwrap();
    }
}

/// What broke: a PostgreSQL outage during a run lost the frame the worker was storing (one
/// ERROR line in the log), and the job still ended `succeeded` with `frames/1.vtu` 404 and its
/// series short. A sweep with frames now runs through three outages: each write is retried until
/// the database is back, and every job ends `succeeded` with all it promised (or, had a write
/// been refused for good, not `succeeded`, saying why).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
#[cfg_attr(
    not(crush_postgres),
    ignore = "needs CRUSH_TEST_POSTGRES (eval \"$(bash .ci/postgres)\")"
)]
async fn a_sweep_with_frames_through_database_outages_ends_every_job_whole() {
    let _turn = SERVER.lock().await;
    let db = fresh_postgres_database();
    let flags = [
        "--node-name",
        "alone",
        "--heartbeat-ms",
        "200",
        "--stale-after-s",
        "2",
        "--checkpoint-every-s",
        "0.5",
        "--concurrent-jobs",
        "2",
    ];
    let app = TestApp::start_on(&db, &flags).await;
    let mut base = killable_case();
    base["output"]["frames"] = serde_json::json!(4);
    let body = serde_json::json!({
        "label": "outages",
        "base": base,
        "parameters": {"loading.plate_speed_m_s": [10, 12, 14]}
    });
    let (_, sweep) = app.create_sweep(&body).await;
    let ids: Vec<String> = sweep["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["job_id"].as_str().unwrap().to_string())
        .collect();
    let started = Instant::now();
    while app.job(&ids[0]).await["progress"].is_null() {
        assert!(started.elapsed() < Duration::from_secs(60), "no progress");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let outages = tokio::task::spawn_blocking(|| {
        for _ in 0..3 {
            control("stop -m fast -w");
            std::thread::sleep(Duration::from_secs(3));
            control("start -w");
            std::thread::sleep(Duration::from_millis(1500));
        }
    });
    outages.await.unwrap();
    for id in &ids {
        let job = app
            .wait_for(
                id,
                &["succeeded", "failed", "cancelled"],
                Duration::from_secs(180),
            )
            .await;
        assert_eq!(job["status"], "succeeded", "{job}");
        whole_or_not_succeeded(&app.client, &app.url, id, 500, 4).await;
    }
    app.server.unwrap().stop().await.unwrap();
}
