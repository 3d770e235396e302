//! The connection time limits through the real server, on either backend, each test named after
//! what a client could do before them: hold a connection by sending nothing, half a head or
//! part of a body; fill a small open-file limit with idle sockets; hold both download slots by
//! not reading, or by reading a trickle. Event streams, which only write, still live as long as
//! their clients read.

use crate::common::*;
use futures::StreamExt;
use serde_json::json;
use std::time::{Duration, Instant};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

/// Reads until the server closes the connection (end of stream or reset); `None` if it is
/// still open after `within`.
async fn until_closed(stream: &mut TcpStream, within: Duration) -> Option<Vec<u8>> {
    let mut got = Vec::new();
    let mut buf = [0u8; 4096];
    let deadline = tokio::time::Instant::now() + within;
    loop {
        match tokio::time::timeout_at(deadline, stream.read(&mut buf)).await {
            Err(_) => return None,
            Ok(Ok(0)) | Ok(Err(_)) => return Some(got),
            Ok(Ok(n)) => got.extend_from_slice(&buf[..n]),
        }
    }
}

async fn connect(app: &TestApp) -> TcpStream {
    TcpStream::connect(app.url.trim_start_matches("http://"))
        .await
        .unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_that_sends_nothing_or_half_its_headers_is_disconnected() {
    let app = TestApp::start(&["--concurrent-jobs", "0", "--header-read-timeout-s", "1"]).await;
    let start = Instant::now();
    let mut silent = connect(&app).await;
    let mut half = connect(&app).await;
    half.write_all(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept: ")
        .await
        .unwrap();
    for stream in [&mut silent, &mut half] {
        let got = until_closed(stream, Duration::from_secs(10)).await;
        assert!(got.is_some(), "still connected after {:?}", start.elapsed());
    }
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    assert!(
        start.elapsed() >= Duration::from_millis(900),
        "{:?}",
        start.elapsed()
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_idle_keep_alive_connection_is_closed_after_the_header_timeout() {
    let app = TestApp::start(&["--concurrent-jobs", "0", "--header-read-timeout-s", "1"]).await;
    let mut stream = connect(&app).await;
    stream
        .write_all(b"GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        .await
        .unwrap();
    let start = Instant::now();
    let got = until_closed(&mut stream, Duration::from_secs(10))
        .await
        .expect("the idle connection is closed");
    let text = String::from_utf8_lossy(&got);
    assert!(text.starts_with("HTTP/1.1 200"), "{text}");
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_request_body_that_stops_is_answered_408_and_closed() {
    let app = TestApp::start(&["--concurrent-jobs", "0", "--body-timeout-s", "1"]).await;
    let mut stream = connect(&app).await;
    stream
        .write_all(
            b"POST /v1/estimate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n\
              Content-Length: 100\r\n\r\n{\"tube\": ",
        )
        .await
        .unwrap();
    let start = Instant::now();
    let got = until_closed(&mut stream, Duration::from_secs(10))
        .await
        .expect("the connection is closed");
    let text = String::from_utf8_lossy(&got);
    assert!(text.starts_with("HTTP/1.1 408"), "{text}");
    assert!(text.contains("application/problem+json"), "{text}");
    assert!(text.contains("did not arrive within 1 s"), "{text}");
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    // A body that arrives in pieces, each in time, is read whole.
    let mut stream = connect(&app).await;
    stream
        .write_all(
            b"POST /v1/estimate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n\
              Content-Length: 2\r\nConnection: close\r\n\r\n{",
        )
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    stream.write_all(b"}").await.unwrap();
    let got = until_closed(&mut stream, Duration::from_secs(10))
        .await
        .unwrap();
    let text = String::from_utf8_lossy(&got);
    assert!(text.starts_with("HTTP/1.1 200"), "{text}");
}

/// With a low open-file limit, 300 idle sockets stopped the server from accepting anyone.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn idle_sockets_no_longer_stop_a_server_with_a_low_open_file_limit_from_accepting() {
    let (_dir, db) = temp_db();
    // The shell sets the limit, then becomes the server.
    let mut process = std::process::Command::new("sh")
        .args(["-c", "ulimit -n 128 && exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_crush"))
        .args(["serve", "--port", "0", "--database-url", &db])
        .args(["--concurrent-jobs", "0", "--header-read-timeout-s", "1"])
        // It logs each accept refused for want of a file descriptor, as it should.
        .stderr(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = process.stdout.take().unwrap();
    let mut lines = std::io::BufRead::lines(std::io::BufReader::new(stdout));
    let first = lines.next().unwrap().unwrap();
    std::thread::spawn(move || for _ in lines {});
    let url = first.rsplit(' ').next().unwrap().to_string();
    let server = Child {
        process,
        url,
        log: Default::default(),
    };
    let addr = server.url.trim_start_matches("http://").to_string();
    let mut idle = Vec::new();
    for _ in 0..300 {
        idle.push(TcpStream::connect(&addr).await.unwrap());
    }
    tokio::time::sleep(Duration::from_millis(200)).await;
    let start = Instant::now();
    let r = client()
        .get(format!("{}/healthz", server.url))
        .send()
        .await
        .expect("the server accepts again once the idle sockets are closed");
    assert_eq!(r.status(), 200);
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "{:?}",
        start.elapsed()
    );
    // The idle sockets were closed by the server.
    for stream in idle.iter_mut().take(10) {
        assert!(until_closed(stream, Duration::from_secs(10))
            .await
            .is_some());
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_event_stream_outlives_the_header_and_write_timeouts() {
    let app = TestApp::start(&[
        "--concurrent-jobs",
        "0",
        "--header-read-timeout-s",
        "1",
        "--write-timeout-s",
        "1",
        "--sse-keep-alive-s",
        "0.25",
    ])
    .await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let r = app
        .client
        .get(app.at(&format!("/v1/jobs/{id}/events")))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    let mut body = r.bytes_stream();
    let start = Instant::now();
    let mut last = Duration::ZERO;
    while start.elapsed() < Duration::from_secs(3) {
        match tokio::time::timeout(Duration::from_secs(2), body.next()).await {
            Ok(Some(Ok(_))) => last = start.elapsed(),
            other => panic!("the stream ended after {:?}: {other:?}", start.elapsed()),
        }
    }
    assert!(last >= Duration::from_millis(2500), "{last:?}");
}

/// A succeeded job of 266 254 particles, whose `state.vtu` is about 16 MB: more than the
/// socket buffers between a server and a client that does not read.
pub(super) async fn large_state(app: &TestApp) -> (String, usize) {
    let case = json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 8},
        "loading": {"crush_distance_mm": 0.05, "plate_speed_m_s": 20},
        "output": {"history_points": 10}
    });
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(300))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    let whole = app.get(&format!("/v1/jobs/{id}/state.vtu")).await;
    assert_eq!(whole.status(), 200);
    let size = whole.bytes().await.unwrap().len();
    assert!(size > 12 << 20, "{size} bytes");
    (id, size)
}

/// Sends a GET for `path` on a socket with a small receive buffer.
pub(super) async fn request(app: &TestApp, path: &str) -> TcpStream {
    let socket = tokio::net::TcpSocket::new_v4().unwrap();
    socket.set_recv_buffer_size(4096).unwrap();
    let addr = app.url.trim_start_matches("http://").parse().unwrap();
    let mut stream = socket.connect(addr).await.unwrap();
    let head = format!("GET {path} HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
    stream.write_all(head.as_bytes()).await.unwrap();
    stream
}

/// Two clients that asked for a large `state.vtu` and never read held both download slots, and
/// every history, picture and VTU download of every job waited as long as they stayed
/// connected (200 s tried). Only the write timeout frees the slots here (no rate is asked).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_clients_that_never_read_a_large_state_vtu_no_longer_block_every_download() {
    let app = TestApp::start(&[
        "--concurrent-jobs",
        "1",
        "--write-timeout-s",
        "2",
        "--min-download-bytes-per-s",
        "0",
        "--fair-download-bytes-per-s",
        "0",
    ])
    .await;
    let (id, _) = large_state(&app).await;
    let path = format!("/v1/jobs/{id}/state.vtu");
    let _stalled = [request(&app, &path).await, request(&app, &path).await];
    tokio::time::sleep(Duration::from_secs(1)).await;
    let start = Instant::now();
    let r = app.get(&format!("/v1/jobs/{id}/particles.csv")).await;
    assert_eq!(r.status(), 200);
    let took = start.elapsed();
    assert!(
        took < Duration::from_secs(20),
        "the download waited {took:?}"
    );
}

/// Two clients that read a large download a trickle at a time held both slots for as long as
/// the trickle lasted (16 MB at 160 KB/s: 100 s). Only the minimum rate frees the slots here
/// (`tests/api/download.rs` has the fair share).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn downloads_taken_slower_than_the_minimum_rate_are_cut_and_free_their_slots() {
    let app = TestApp::start(&[
        "--concurrent-jobs",
        "1",
        "--write-timeout-s",
        "60",
        "--min-download-bytes-per-s",
        "2500000",
        "--fair-download-bytes-per-s",
        "0",
    ])
    .await;
    // The whole file at full speed is within the rate (`large_state` downloads it once).
    let (id, _) = large_state(&app).await;
    let path = format!("/v1/jobs/{id}/state.vtu");
    let mut readers = Vec::new();
    for _ in 0..2 {
        let mut stream = request(&app, &path).await;
        readers.push(tokio::spawn(async move {
            let mut buf = [0u8; 8192];
            let start = Instant::now();
            while start.elapsed() < Duration::from_secs(120) {
                match stream.read(&mut buf).await {
                    Ok(0) | Err(_) => return,
                    Ok(_) => tokio::time::sleep(Duration::from_millis(50)).await,
                }
            }
        }));
    }
    tokio::time::sleep(Duration::from_secs(1)).await;
    let start = Instant::now();
    let r = app.get(&format!("/v1/jobs/{id}/particles.csv")).await;
    assert_eq!(r.status(), 200);
    let took = start.elapsed();
    // The slots are freed once the rate is first checked, 10 s after each download began.
    assert!(
        took >= Duration::from_secs(7) && took < Duration::from_secs(25),
        "the download waited {took:?}"
    );
    for reader in readers {
        reader.abort();
    }
}
