//! Helpers of the API tests: the real server on port 0 with a fresh database, either
//! in-process ([`TestApp`]) or as a child process of the built binary ([`Child`]); a small SSE
//! reader; and the cases the tests submit.
//!
//! One harness, two backends: every API test runs against SQLite (a temporary file, the
//! default) or, with `CRUSH_TEST_BACKEND=postgres`, against a fresh database of its own on the
//! PostgreSQL server that `CRUSH_TEST_POSTGRES` names (`eval "$(bash .ci/postgres)"` starts a
//! throw-away one). `.ci/run` runs the API suite both ways.
#![allow(dead_code)]

use futures::StreamExt;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Runs in about a second with the real solver (well under with the placeholder).
pub fn tiny_case() -> Value {
    json!({
        "tube": {"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 8},
        "discretization": {"particles_through_thickness": 1},
        "loading": {"crush_distance_mm": 1, "plate_speed_m_s": 20},
        "output": {"history_points": 20}
    })
}

/// Runs for a few seconds: long enough to kill a server under it, short enough to finish.
pub fn medium_case() -> Value {
    json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 1},
        "loading": {"crush_distance_mm": 20, "plate_speed_m_s": 20},
        "output": {"history_points": 500}
    })
}

/// Runs for several seconds on one thread (the medium case takes well under one): a server
/// killed at its first progress is killed mid-run.
pub fn killable_case() -> Value {
    json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 2},
        "loading": {"crush_distance_mm": 30, "plate_speed_m_s": 10},
        "output": {"history_points": 500}
    })
}

/// Runs far longer than any test waits: only ever cancelled or interrupted.
pub fn long_case() -> Value {
    json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 2},
        "loading": {"crush_distance_mm": 40, "plate_speed_m_s": 10},
        "output": {"history_points": 5000}
    })
}

/// Runs for several seconds with many steps per history row: long enough to take checkpoints
/// mid-run and stop the server after one, short enough to run twice in a test.
pub fn resumable_case() -> Value {
    json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 2},
        "loading": {"crush_distance_mm": 40, "plate_speed_m_s": 20},
        "output": {"history_points": 200}
    })
}

pub fn client() -> reqwest::Client {
    reqwest::Client::builder()
        .timeout(Duration::from_secs(30))
        .build()
        .unwrap()
}

/// An in-process server on 127.0.0.1:0 with a fresh database.
pub struct TestApp {
    pub url: String,
    pub client: reqwest::Client,
    pub server: Option<crush::service::Server>,
    pub dir: tempfile::TempDir,
    /// The database the server runs on.
    pub db: String,
}

impl TestApp {
    pub async fn start(flags: &[&str]) -> TestApp {
        let dir = tempfile::tempdir().unwrap();
        let db = database_url(dir.path());
        TestApp::start_in(dir, &db, flags).await
    }

    /// A server on an existing database (another node of a cluster).
    pub async fn start_on(db: &str, flags: &[&str]) -> TestApp {
        TestApp::start_in(tempfile::tempdir().unwrap(), db, flags).await
    }

    async fn start_in(dir: tempfile::TempDir, db: &str, flags: &[&str]) -> TestApp {
        let mut all = vec![
            "--port",
            "0",
            "--database-url",
            db,
            "--threads-per-job",
            "1",
        ];
        all.extend_from_slice(flags);
        let args = crush::service::ServeArgs::from_flags(all).unwrap();
        let server = crush::service::start(args).await.unwrap();
        TestApp {
            url: format!("http://{}", server.addr),
            client: client(),
            server: Some(server),
            dir,
            db: db.to_string(),
        }
    }

    pub fn at(&self, path: &str) -> String {
        format!("{}{path}", self.url)
    }

    /// `GET path`, whatever the answer.
    pub async fn get(&self, path: &str) -> reqwest::Response {
        self.client.get(self.at(path)).send().await.unwrap()
    }

    /// `POST path` with an empty JSON body (a cancel), whatever the answer.
    pub async fn post(&self, path: &str) -> reqwest::Response {
        self.client
            .post(self.at(path))
            .header("content-type", "application/json")
            .send()
            .await
            .unwrap()
    }

    /// `POST path` with a JSON body, whatever the answer.
    pub async fn post_json(&self, path: &str, body: &Value) -> reqwest::Response {
        self.client
            .post(self.at(path))
            .json(body)
            .send()
            .await
            .unwrap()
    }

    /// The estimate of a case; panics unless it is answered (200).
    pub async fn estimate(&self, case: &Value) -> Value {
        let r = self.post_json("/v1/estimate", case).await;
        assert_eq!(r.status(), 200, "{}", r.text().await.unwrap());
        r.json().await.unwrap()
    }

    /// Submits a case; panics unless it is accepted.
    pub async fn submit(&self, case: &Value) -> Value {
        let r = self
            .client
            .post(self.at("/v1/jobs"))
            .json(case)
            .send()
            .await
            .unwrap();
        assert_eq!(r.status(), 202, "{}", r.text().await.unwrap());
        r.json().await.unwrap()
    }

    /// Posts a sweep that must be accepted (202); returns its Location and body.
    pub async fn create_sweep(&self, body: &Value) -> (String, Value) {
        let r = self
            .client
            .post(self.at("/v1/sweeps"))
            .json(body)
            .send()
            .await
            .unwrap();
        assert_eq!(r.status(), 202);
        let location = r.headers()["location"].to_str().unwrap().to_string();
        (location, r.json().await.unwrap())
    }

    pub async fn job(&self, id: &str) -> Value {
        get_json(&self.client, &self.at(&format!("/v1/jobs/{id}"))).await
    }

    /// Polls the job until its status is one of `wanted`.
    pub async fn wait_for(&self, id: &str, wanted: &[&str], timeout: Duration) -> Value {
        wait_for(&self.client, &self.url, id, wanted, timeout).await
    }
}

/// A fresh, empty database for one server (or one cluster of nodes): a SQLite file in `dir`,
/// or a new PostgreSQL database when `CRUSH_TEST_BACKEND=postgres`.
pub fn database_url(dir: &Path) -> String {
    match std::env::var("CRUSH_TEST_BACKEND").as_deref() {
        Ok("postgres") => fresh_postgres_database(),
        Ok("sqlite") | Err(_) => sqlite_url(dir),
        Ok(other) => panic!("CRUSH_TEST_BACKEND is sqlite or postgres, not {other:?}"),
    }
}

/// A SQLite file in `dir`, whatever the backend under test (tests of the file itself).
pub fn sqlite_url(dir: &Path) -> String {
    format!("sqlite://{}", dir.join("crush.db").display())
}

/// The admin URL of the test PostgreSQL server (`CRUSH_TEST_POSTGRES`).
pub fn postgres_admin() -> String {
    std::env::var("CRUSH_TEST_POSTGRES").expect(
        "CRUSH_TEST_POSTGRES names the test PostgreSQL server: eval \"$(bash .ci/postgres)\"",
    )
}

/// Creates an empty database on the test PostgreSQL server and returns its URL.
pub fn fresh_postgres_database() -> String {
    use sqlx::{Connection, Executor};
    let admin = postgres_admin();
    let name = format!("crush_test_{}", uuid::Uuid::new_v4().simple());
    let (base, _) = admin.rsplit_once('/').expect("a URL ending in /DATABASE");
    let url = format!("{base}/{name}");
    // On a thread of its own: the caller may be inside a runtime, which cannot block.
    std::thread::spawn(move || {
        let rt = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        rt.block_on(async {
            let mut c = sqlx::PgConnection::connect(&admin)
                .await
                .expect("the test PostgreSQL server answers");
            c.execute(format!("CREATE DATABASE {name}").as_str())
                .await
                .unwrap();
            c.close().await.unwrap();
        })
    })
    .join()
    .unwrap();
    url
}

pub async fn get_json(client: &reqwest::Client, url: &str) -> Value {
    let r = client.get(url).send().await.unwrap();
    assert!(r.status().is_success(), "GET {url}: {}", r.status());
    r.json().await.unwrap()
}

pub async fn wait_for(
    client: &reqwest::Client,
    base: &str,
    id: &str,
    wanted: &[&str],
    timeout: Duration,
) -> Value {
    let start = Instant::now();
    loop {
        let job = get_json(client, &format!("{base}/v1/jobs/{id}")).await;
        if wanted.contains(&job["status"].as_str().unwrap_or("")) {
            return job;
        }
        assert!(
            start.elapsed() < timeout,
            "job {id} not {wanted:?} after {timeout:?}: {job}"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// One server-sent event.
#[derive(Debug, Clone)]
pub struct SseEvent {
    pub id: Option<u64>,
    pub event: String,
    pub data: String,
}

impl SseEvent {
    pub fn json(&self) -> Value {
        serde_json::from_str(&self.data).unwrap()
    }
}

/// Reads events off an open `text/event-stream` response.
pub struct SseReader {
    stream: futures::stream::BoxStream<'static, reqwest::Result<axum::body::Bytes>>,
    buffer: String,
}

impl SseReader {
    pub async fn open(
        client: &reqwest::Client,
        url: &str,
        last_event_id: Option<u64>,
    ) -> (reqwest::StatusCode, SseReader) {
        let mut req = client
            .get(url)
            .header("accept", "text/event-stream")
            .timeout(Duration::from_secs(120));
        if let Some(id) = last_event_id {
            req = req.header("last-event-id", id.to_string());
        }
        let r = req.send().await.unwrap();
        let status = r.status();
        (
            status,
            SseReader {
                stream: r.bytes_stream().boxed(),
                buffer: String::new(),
            },
        )
    }

    /// The next event (comments skipped); `None` when the stream ends or `timeout` passes.
    pub async fn next(&mut self, timeout: Duration) -> Option<SseEvent> {
        let deadline = tokio::time::Instant::now() + timeout;
        loop {
            while let Some(end) = self.buffer.find("\n\n") {
                let block: String = self.buffer.drain(..end + 2).collect();
                let mut event = SseEvent {
                    id: None,
                    event: "message".into(),
                    data: String::new(),
                };
                let mut any = false;
                for line in block.lines() {
                    if let Some(v) = line.strip_prefix("id:") {
                        event.id = v.trim().parse().ok();
                        any = true;
                    } else if let Some(v) = line.strip_prefix("event:") {
                        event.event = v.trim().to_string();
                        any = true;
                    } else if let Some(v) = line.strip_prefix("data:") {
                        event.data.push_str(v.strip_prefix(' ').unwrap_or(v));
                        any = true;
                    }
                }
                if any {
                    return Some(event);
                }
            }
            match tokio::time::timeout_at(deadline, self.stream.next()).await {
                Ok(Some(Ok(bytes))) => self.buffer.push_str(&String::from_utf8_lossy(&bytes)),
                _ => return None,
            }
        }
    }
}

/// The server as a separate process of the built binary.
pub struct Child {
    pub process: std::process::Child,
    pub url: String,
    /// Its log lines (stderr), when started with [`Child::logged`].
    pub log: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

impl Child {
    /// Starts `crush serve --port 0` on the database and reads the bound address it prints.
    pub fn start(db: &str, flags: &[&str]) -> Child {
        Child::spawn(db, flags, None)
    }

    /// [`Child::start`] keeping its log lines at `level` and above in [`Child::log`] (they are
    /// printed too).
    pub fn logged(db: &str, flags: &[&str], level: &str) -> Child {
        Child::spawn(db, flags, Some(level))
    }

    /// Whether a log line so far contains `text`.
    pub fn logged_line(&self, text: &str) -> bool {
        self.log.lock().unwrap().iter().any(|l| l.contains(text))
    }

    fn spawn(db: &str, flags: &[&str], level: Option<&str>) -> Child {
        let mut process = std::process::Command::new(env!("CARGO_BIN_EXE_crush"))
            .args([
                "serve",
                "--port",
                "0",
                "--database-url",
                db,
                "--threads-per-job",
                "1",
            ])
            .args(flags)
            .env("RUST_LOG", level.unwrap_or("warn"))
            .env("NO_COLOR", "1")
            .stdout(Stdio::piped())
            .stderr(if level.is_some() {
                Stdio::piped()
            } else {
                Stdio::inherit()
            })
            .spawn()
            .expect("the crush binary starts");
        let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        if let Some(stderr) = process.stderr.take() {
            let log = log.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                    eprintln!("{line}");
                    log.lock().unwrap().push(line);
                }
            });
        }
        let stdout = process.stdout.take().unwrap();
        let mut lines = BufReader::new(stdout).lines();
        let line = lines
            .next()
            .expect("the server prints its address")
            .unwrap();
        let url = line.rsplit(' ').next().unwrap().trim().to_string();
        assert!(url.starts_with("http://"), "unexpected first line {line:?}");
        // Keep draining stdout so the server never blocks on a full pipe.
        std::thread::spawn(move || for _ in lines {});
        Child { process, url, log }
    }

    pub fn pid(&self) -> i32 {
        self.process.id() as i32
    }

    /// Waits up to `timeout` for the process to exit by itself.
    pub fn exited_within(&mut self, timeout: Duration) -> Option<std::process::ExitStatus> {
        let start = Instant::now();
        while start.elapsed() < timeout {
            if let Some(status) = self.process.try_wait().unwrap() {
                return Some(status);
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        None
    }
}

impl Drop for Child {
    fn drop(&mut self) {
        let _ = self.process.kill();
        let _ = self.process.wait();
    }
}

pub fn temp_db() -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let url = database_url(dir.path());
    (dir, url)
}

pub fn repo_file(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// Submits a case to the server at `base`; panics unless it is accepted. Returns the job's id.
pub async fn submit_to(client: &reqwest::Client, base: &str, case: &Value) -> String {
    let r = client
        .post(format!("{base}/v1/jobs"))
        .json(case)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 202, "{}", r.text().await.unwrap());
    r.json::<Value>().await.unwrap()["id"]
        .as_str()
        .unwrap()
        .to_string()
}

/// Checks that job `id` on `base` either did not succeed, or succeeded with everything it
/// promised readable: `rows` history rows, its summary, and each of its `frames` frames with
/// the series that lists them. Returns its status.
pub async fn whole_or_not_succeeded(
    client: &reqwest::Client,
    base: &str,
    id: &str,
    rows: usize,
    frames: u32,
) -> String {
    let job = get_json(client, &format!("{base}/v1/jobs/{id}")).await;
    let status = job["status"].as_str().unwrap().to_string();
    if status != "succeeded" {
        assert!(
            job["error"].is_string() || status == "cancelled",
            "a job that did not succeed says why: {job}"
        );
        return status;
    }
    assert!(job["summary"].is_object(), "{job}");
    let history = get_json(client, &format!("{base}/v1/jobs/{id}/history")).await;
    assert_eq!(history["rows"].as_array().unwrap().len(), rows, "job {id}");
    let pvd = client
        .get(format!("{base}/v1/jobs/{id}/series.pvd"))
        .send()
        .await
        .unwrap();
    assert_eq!(pvd.status(), 200, "job {id}: series.pvd");
    let pvd = pvd.text().await.unwrap();
    for k in 0..frames {
        assert!(pvd.contains(&format!("frames/{k}.vtu")), "job {id}: {pvd}");
        let r = client
            .get(format!("{base}/v1/jobs/{id}/frames/{k}.vtu"))
            .send()
            .await
            .unwrap();
        assert_eq!(r.status(), 200, "job {id}: frame {k}");
    }
    status
}
