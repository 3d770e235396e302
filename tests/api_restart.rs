//! The server as a separate process: killed with SIGKILL mid-run it leaves no job behind and
//! stores none twice; stopped with SIGTERM it requeues what it was running and does not hang on
//! open event streams.

mod common;

use common::*;
use std::time::Duration;

/// Waits on the event stream until the job reports progress.
async fn wait_for_progress(client: &reqwest::Client, base: &str, id: &str) {
    let (_, mut events) =
        SseReader::open(client, &format!("{base}/v1/jobs/{id}/events"), None).await;
    loop {
        let e = events
            .next(Duration::from_secs(30))
            .await
            .expect("the job starts");
        assert!(
            !e.event.starts_with("done"),
            "the job finished before the test could interrupt it"
        );
        if e.event == "progress" {
            return;
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_killed_mid_run_finishes_the_job_exactly_once_after_restart() {
    let (_dir, db) = temp_db();
    let client = client();
    let quick = ["--heartbeat-ms", "200", "--stale-after-s", "1"];
    let mut first = Child::start(&db, &quick);
    let id = submit_to(&client, &first.url, &medium_case()).await;
    wait_for_progress(&client, &first.url, &id).await;
    first.process.kill().unwrap(); // SIGKILL
    first.process.wait().unwrap();

    let second = Child::start(&db, &quick);
    let job = wait_for(
        &client,
        &second.url,
        &id,
        &["succeeded", "failed"],
        Duration::from_secs(90),
    )
    .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(
        job["attempts"], 2,
        "run once before the kill and once after: {job}"
    );
    let history = get_json(&client, &format!("{}/v1/jobs/{id}/history", second.url)).await;
    let rows = history["rows"].as_array().unwrap();
    let points = medium_case()["output"]["history_points"].as_u64().unwrap() as usize;
    assert!(
        (points - 1..=points + 1).contains(&rows.len()),
        "{} rows for {points} points",
        rows.len()
    );
    let times: Vec<f64> = rows.iter().map(|r| r[0].as_f64().unwrap()).collect();
    assert!(
        times.windows(2).all(|w| w[0] < w[1]),
        "history rows repeat or go back in time"
    );
    let list = get_json(&client, &format!("{}/v1/jobs", second.url)).await;
    assert_eq!(list["jobs"].as_array().unwrap().len(), 1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sigterm_requeues_the_running_job_and_does_not_hang_on_event_streams() {
    let (_dir, db) = temp_db();
    let client = client();
    let mut server = Child::start(
        &db,
        &["--shutdown-grace-s", "0.3", "--sse-keep-alive-s", "60"],
    );
    let id = submit_to(&client, &server.url, &long_case()).await;
    wait_for_progress(&client, &server.url, &id).await;
    let (status, mut stream) = SseReader::open(
        &client,
        &format!("{}/v1/jobs/{id}/events", server.url),
        None,
    )
    .await;
    assert_eq!(status, 200);
    assert!(stream.next(Duration::from_secs(5)).await.is_some());

    // SAFETY: sending a signal to our own child process.
    assert_eq!(unsafe { libc::kill(server.pid(), libc::SIGTERM) }, 0);
    let exit = server
        .exited_within(Duration::from_secs(15))
        .expect("the server exits on SIGTERM");
    assert!(exit.success(), "{exit:?}");
    // The open stream ended instead of holding the server up.
    while stream.next(Duration::from_secs(5)).await.is_some() {}

    let api_only = Child::start(&db, &["--concurrent-jobs", "0"]);
    let job = get_json(&client, &format!("{}/v1/jobs/{id}", api_only.url)).await;
    assert_eq!(job["status"], "queued", "{job}");
    assert_eq!(job["attempts"], 1);
    assert!(job["progress"].is_null());
}
