//! The server as a separate process: killed with SIGKILL mid-run it leaves no job behind and
//! stores none twice; stopped with SIGTERM it requeues what it was running and does not hang on
//! open event streams.

use crate::common::*;
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
    let id = submit_to(&client, &first.url, &killable_case()).await;
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
    let points = killable_case()["output"]["history_points"]
        .as_u64()
        .unwrap() as usize;
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

/// Flags of a server that notices a lost worker within a second and checkpoints four times a
/// second.
const RESUMING: [&str; 6] = [
    "--heartbeat-ms",
    "200",
    "--stale-after-s",
    "1",
    "--checkpoint-every-s",
    "0.25",
];

/// Polls the job until it has a checkpoint at `at_least` of the crush or beyond; panics if it
/// ends first.
async fn wait_for_checkpoint(client: &reqwest::Client, base: &str, id: &str, at_least: f64) {
    let deadline = std::time::Instant::now() + Duration::from_secs(120);
    loop {
        let job = get_json(client, &format!("{base}/v1/jobs/{id}")).await;
        let status = job["status"].as_str().unwrap_or("");
        assert!(
            ["queued", "running"].contains(&status),
            "the job ended before a checkpoint: {job}"
        );
        if job["checkpoint"]["fraction"].as_f64().unwrap_or(0.0) >= at_least {
            return;
        }
        assert!(std::time::Instant::now() < deadline, "no checkpoint: {job}");
        tokio::time::sleep(Duration::from_millis(25)).await;
    }
}

/// The job's history as CSV text: the shortest text of each stored f64, so equal text means
/// equal bits.
async fn history_csv(client: &reqwest::Client, base: &str, id: &str) -> String {
    let r = client
        .get(format!("{base}/v1/jobs/{id}/history?format=csv"))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    r.text().await.unwrap()
}

/// Submits `case` to `base` again and returns the history of that run, which nothing stops.
async fn uninterrupted(client: &reqwest::Client, base: &str, case: &serde_json::Value) -> String {
    let id = submit_to(client, base, case).await;
    wait_for(client, base, &id, &["succeeded"], Duration::from_secs(180)).await;
    history_csv(client, base, &id).await
}

/// The summary's physics: everything but the wall-time figures.
fn physics(job: &serde_json::Value) -> serde_json::Value {
    let mut s = job["summary"].clone();
    let cost = s["cost"].as_object_mut().unwrap();
    for k in ["wall_time_s", "particle_steps_per_s", "threads"] {
        cost.remove(k);
    }
    s
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_server_killed_at_80_percent_resumes_the_job_from_its_checkpoint_with_the_same_bits() {
    let (_dir, db) = temp_db();
    let client = client();
    // With a time series: the frames before the checkpoint are the first server's, the rest
    // the second's, and the lot is the uninterrupted run's.
    let mut case = resumable_case();
    case["output"]["frames"] = serde_json::json!(6);
    let mut first = Child::start(&db, &RESUMING);
    let id = submit_to(&client, &first.url, &case).await;
    wait_for_checkpoint(&client, &first.url, &id, 0.75).await;
    first.process.kill().unwrap(); // SIGKILL
    first.process.wait().unwrap();

    let second = Child::logged(&db, &RESUMING, "info");
    let job = wait_for(
        &client,
        &second.url,
        &id,
        &["succeeded", "failed"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["attempts"], 2, "{job}");
    assert!(
        job["checkpoint"].is_null(),
        "a finished job keeps no checkpoint: {job}"
    );
    assert!(second.logged_line("resuming from the checkpoint"));
    let resumed = history_csv(&client, &second.url, &id).await;
    let whole = uninterrupted(&client, &second.url, &case).await;
    assert_eq!(
        resumed, whole,
        "the resumed run's history differs from an uninterrupted run's"
    );
    let rows = resumed.lines().count() - 1;
    assert_eq!(rows, 200);
    // The summaries agree too, and the final states byte for byte.
    let list = get_json(&client, &format!("{}/v1/jobs?status=succeeded", second.url)).await;
    let other = list["jobs"][0]["id"].as_str().unwrap().to_string();
    assert_ne!(other, id);
    let (a, b) = (
        second_job(&client, &second.url, &id).await,
        second_job(&client, &second.url, &other).await,
    );
    assert_eq!(physics(&a), physics(&b));
    let state = |job: String| {
        let client = client.clone();
        let url = format!("{}/v1/jobs/{job}/state.vtu", second.url);
        async move { client.get(url).send().await.unwrap().bytes().await.unwrap() }
    };
    assert_eq!(state(id.clone()).await, state(other.clone()).await);
    for file in ["series.pvd", "frames/0.vtu", "frames/2.vtu", "frames/5.vtu"] {
        let download = |job: &str| {
            let url = format!("{}/v1/jobs/{job}/{file}", second.url);
            let client = client.clone();
            async move {
                let r = client.get(url).send().await.unwrap();
                assert_eq!(r.status(), 200, "{file}");
                r.bytes().await.unwrap()
            }
        };
        assert_eq!(download(&id).await, download(&other).await, "{file}");
    }
}

async fn second_job(client: &reqwest::Client, base: &str, id: &str) -> serde_json::Value {
    get_json(client, &format!("{base}/v1/jobs/{id}")).await
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn three_operator_restarts_during_one_job_resume_it_and_do_not_use_up_its_attempts() {
    let (_dir, db) = temp_db();
    let client = client();
    let case = resumable_case();
    // Two attempts allowed: three restarts would fail a job that started over each time.
    let flags = [
        &RESUMING[..],
        &["--shutdown-grace-s", "0.05", "--max-attempts", "2"],
    ]
    .concat();
    let mut id: Option<String> = None;
    for (restart, at_least) in [0.2, 0.4, 0.6].into_iter().enumerate() {
        let mut server = Child::start(&db, &flags);
        let job = match &id {
            None => submit_to(&client, &server.url, &case).await,
            Some(id) => id.clone(),
        };
        wait_for_checkpoint(&client, &server.url, &job, at_least).await;
        // SAFETY: sending a signal to our own child process.
        assert_eq!(unsafe { libc::kill(server.pid(), libc::SIGTERM) }, 0);
        let exit = server
            .exited_within(Duration::from_secs(30))
            .expect("the server stops");
        assert!(exit.success(), "restart {restart}: {exit:?}");
        id = Some(job);
    }
    let id = id.unwrap();
    let server = Child::start(&db, &flags);
    let job = wait_for(
        &client,
        &server.url,
        &id,
        &["succeeded", "failed"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["attempts"], 4, "{job}");
    let resumed = history_csv(&client, &server.url, &id).await;
    assert_eq!(resumed, uninterrupted(&client, &server.url, &case).await);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_damaged_checkpoint_is_discarded_with_a_log_line_and_the_run_starts_over() {
    let (_dir, db) = temp_db();
    let client = client();
    let case = resumable_case();
    let flags = [&RESUMING[..], &["--shutdown-grace-s", "0.05"]].concat();
    let mut server = Child::start(&db, &flags);
    let id = submit_to(&client, &server.url, &case).await;
    wait_for_checkpoint(&client, &server.url, &id, 0.3).await;
    // SAFETY: sending a signal to our own child process.
    assert_eq!(unsafe { libc::kill(server.pid(), libc::SIGTERM) }, 0);
    server
        .exited_within(Duration::from_secs(30))
        .expect("the server stops");

    // One bit of the stored checkpoint flipped, as a bad disk or a bad copy would.
    sqlx::any::install_default_drivers();
    let pool = sqlx::AnyPool::connect(&db).await.unwrap();
    let (data,): (Vec<u8>,) = sqlx::query_as("SELECT data FROM checkpoints WHERE job_id = $1")
        .bind(&id)
        .fetch_one(&pool)
        .await
        .unwrap();
    let mut damaged = data.clone();
    let mid = damaged.len() / 2;
    damaged[mid] ^= 0x10;
    sqlx::query("UPDATE checkpoints SET data = $1 WHERE job_id = $2")
        .bind(damaged)
        .bind(&id)
        .execute(&pool)
        .await
        .unwrap();
    pool.close().await;

    let server = Child::logged(&db, &flags, "warn");
    let job = wait_for(
        &client,
        &server.url,
        &id,
        &["succeeded", "failed"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert!(
        server.logged_line("checkpoint discarded") && server.logged_line("checksum"),
        "the log says why: {:?}",
        server.log.lock().unwrap()
    );
    let history = history_csv(&client, &server.url, &id).await;
    assert_eq!(history, uninterrupted(&client, &server.url, &case).await);
}

/// A case whose run takes a moment and whose error bar (its section at n = 8, 12 and 16) takes
/// seconds: a server stopped while it prices the error bar is stopped between or inside rungs.
fn error_bar_case() -> serde_json::Value {
    serde_json::json!({
        "tube": {"length_mm": 30},
        "discretization": {"model": "axisymmetric", "particles_through_thickness": 2},
        "loading": {"crush_distance_mm": 8, "plate_speed_m_s": 20},
        "output": {"history_points": 100, "error_bar": true}
    })
}

/// Polls the job until its progress shows rung `rung` of its error bar's ladder running.
async fn wait_for_rung(client: &reqwest::Client, base: &str, id: &str, rung: u64) {
    let deadline = std::time::Instant::now() + Duration::from_secs(120);
    loop {
        let job = get_json(client, &format!("{base}/v1/jobs/{id}")).await;
        let status = job["status"].as_str().unwrap_or("");
        assert!(
            ["queued", "running"].contains(&status),
            "the job ended first: {job}"
        );
        if job["progress"]["error_bar"]["rung"].as_u64() >= Some(rung) {
            assert_eq!(job["progress"]["fraction"], 1.0, "{job}");
            return;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "no rung {rung}: {job}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// The error bar without its wall times (a rung run again, or kept, takes its own time).
fn bar_physics(job: &serde_json::Value) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(o) => {
                o.retain(|k, _| !k.contains("wall_time") && !k.contains("cost"));
                o.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut bar = job["summary"]["error_bar"].clone();
    strip(&mut bar);
    bar
}

/// What broke: the error bar's phase was never checkpointed, so a SIGTERM during it stored
/// nothing and the job started over from step 0, and kills during it used up the job's attempts
/// although its run had finished. Now the finished run and each finished rung are kept: with
/// one fruitless claim allowed, a SIGTERM and a SIGKILL during the ladder still finish the job,
/// each later claim resuming with the next rung, and the error bar is the uninterrupted one's.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stops_while_the_error_bar_is_priced_resume_with_the_next_rung_not_the_crush() {
    let (_dir, db) = temp_db();
    let client = client();
    let flags = [
        &RESUMING[..],
        &["--max-attempts", "1", "--shutdown-grace-s", "0.1"],
    ]
    .concat();
    let mut first = Child::start(&db, &flags);
    let id = submit_to(&client, &first.url, &error_bar_case()).await;
    wait_for_rung(&client, &first.url, &id, 2).await;
    // SAFETY: sending a signal to our own child process.
    assert_eq!(unsafe { libc::kill(first.pid(), libc::SIGTERM) }, 0);
    first
        .exited_within(Duration::from_secs(15))
        .expect("the server exits on SIGTERM");

    let mut second = Child::logged(&db, &flags, "info");
    wait_for_rung(&client, &second.url, &id, 3).await;
    assert!(second.logged_line("resuming the error bar's ladder"));
    second.process.kill().unwrap(); // SIGKILL
    second.process.wait().unwrap();

    let third = Child::logged(&db, &flags, "info");
    let job = wait_for(
        &client,
        &third.url,
        &id,
        &["succeeded", "failed"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["attempts"], 3, "{job}");
    let resumed = third
        .log
        .lock()
        .unwrap()
        .iter()
        .any(|l| l.contains("resuming the error bar's ladder") && l.contains("rungs=2"));
    assert!(resumed, "the third claim ran only the last rung");
    assert!(job["summary"]["error_bar"]["rungs"].is_array(), "{job}");
    let whole = submit_to(&client, &third.url, &error_bar_case()).await;
    let whole = wait_for(
        &client,
        &third.url,
        &whole,
        &["succeeded"],
        Duration::from_secs(120),
    )
    .await;
    assert_eq!(bar_physics(&job), bar_physics(&whole));
    assert_eq!(physics(&job)["mean_load_n"], physics(&whole)["mean_load_n"]);
    assert_eq!(
        history_csv(&client, &third.url, &id).await,
        history_csv(&client, &third.url, whole["id"].as_str().unwrap()).await
    );
}
