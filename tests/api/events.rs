//! Event streams joined mid-run, through the real server on port 0: a dashboard that opens a
//! running job sees the load curve from the start of the run, not only from the moment it
//! connected.

use crate::common::{SseReader, TestApp};
use serde_json::json;
use std::time::{Duration, Instant};

#[tokio::test]
async fn a_stream_joined_mid_run_replays_the_run_so_far_then_follows_it() {
    let app = TestApp::start(&["--heartbeat-ms", "100"]).await;
    // A few seconds on one thread.
    let case = json!({
        "discretization": {"particles_through_thickness": 2},
        "loading": {"crush_distance_mm": 20, "plate_speed_m_s": 10},
        "output": {"history_points": 500}
    });
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    // Wait until the run is well under way (the heartbeat stores its progress).
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let job = app.job(&id).await;
        let fraction = job["progress"]["fraction"].as_f64().unwrap_or(0.0);
        if fraction > 0.2 || job["status"] == "succeeded" {
            assert_eq!(
                job["status"], "running",
                "the run ended before the test joined it"
            );
            break;
        }
        assert!(Instant::now() < deadline, "the run did not progress");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let url = app.at(&format!("/v1/jobs/{id}/events"));
    let (status, mut events) = SseReader::open(&app.client, &url, None).await;
    assert_eq!(status, 200);
    let mut fractions = Vec::new();
    let mut ids = Vec::new();
    let end = loop {
        let e = events
            .next(Duration::from_secs(60))
            .await
            .expect("the stream goes on to the end");
        ids.extend(e.id);
        if e.event != "progress" {
            if e.event == "status" {
                continue;
            }
            break e;
        }
        fractions.push(e.json()["fraction"].as_f64().unwrap());
    };
    assert_eq!(end.event, "done", "{}", end.data);
    assert!(ids.windows(2).all(|w| w[0] < w[1]), "ids must increase");
    // The replay starts near the beginning of the run: the first history rows of 500.
    assert!(
        fractions[0] < 0.05,
        "first replayed fraction {}",
        fractions[0]
    );
    assert!(fractions.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(*fractions.last().unwrap(), 1.0);
    // 500 rows, all of which arrive (under the replay cap).
    assert_eq!(fractions.len(), 500);
}

/// The probe: `Last-Event-ID: 5000000` (or 2^64 − 1) on a running job got no events and the
/// stream stayed open after the job had ended.
#[tokio::test]
async fn last_event_id_5000000_on_a_running_job_still_gets_the_final_event_and_the_stream_ends() {
    let app = TestApp::start(&["--heartbeat-ms", "100"]).await;
    let id = app.submit(&crate::common::medium_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&id, &["running"], Duration::from_secs(30))
        .await;
    let url = app.at(&format!("/v1/jobs/{id}/events"));
    // Both open while the job runs.
    let mut streams = Vec::new();
    for last in [5_000_000, u64::MAX] {
        let (status, events) = SseReader::open(&app.client, &url, Some(last)).await;
        assert_eq!(status, 200, "Last-Event-ID {last}");
        streams.push((last, events));
    }
    for (last, mut events) in streams {
        let mut seen = Vec::new();
        let end = loop {
            let e = events
                .next(Duration::from_secs(90))
                .await
                .unwrap_or_else(|| panic!("Last-Event-ID {last}: no final event after {seen:?}"));
            if e.event == "done" || e.event == "failed" || e.event == "cancelled" {
                break e;
            }
            seen.push(e.event);
        };
        assert_eq!(end.event, "done", "{}", end.data);
        assert!(
            events.next(Duration::from_secs(5)).await.is_none(),
            "Last-Event-ID {last}: the stream stays open after the final event"
        );
    }
    // Once the job has ended, such an id has "seen everything": 204.
    let (status, _) = SseReader::open(&app.client, &url, Some(5_000_000)).await;
    assert_eq!(status, 204);
}

/// A running job's stream opens with one `status` event: the state it reads from the store and
/// the worker's own `running` event in the replay are one event with one id.
#[tokio::test]
async fn a_running_jobs_stream_opens_with_one_status_event() {
    let app = TestApp::start(&["--heartbeat-ms", "100"]).await;
    let id = app.submit(&crate::common::long_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&id, &["running"], Duration::from_secs(30))
        .await;
    let url = app.at(&format!("/v1/jobs/{id}/events"));
    // Opened at once, and again once progress events are in the replay.
    for _ in 0..2 {
        let (status, mut events) = SseReader::open(&app.client, &url, None).await;
        assert_eq!(status, 200);
        let mut opening = Vec::new();
        loop {
            let e = events
                .next(Duration::from_secs(60))
                .await
                .expect("a progress event follows");
            if e.event == "progress" {
                break;
            }
            opening.push((e.id, e.event.clone(), e.json()));
        }
        assert_eq!(opening.len(), 1, "{opening:?}");
        assert_eq!(opening[0].1, "status");
        assert_eq!(opening[0].2, json!({"status": "running", "attempt": 1}));
        tokio::time::sleep(Duration::from_millis(500)).await;
    }
    let r = app.post(&format!("/v1/jobs/{id}/cancel")).await;
    assert_eq!(r.status(), 202);
    app.wait_for(&id, &["cancelled"], Duration::from_secs(30))
        .await;
}
