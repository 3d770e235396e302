//! The database failing under a running server, through the real server: made read-only
//! (`chattr +i`), filled (a small tmpfs), deleted. While it cannot be written, submits and
//! `/healthz` answer 503 with `Retry-After`; as soon as it can, everything works again on the
//! same connections' pool, with no restart and no wait for a connection to expire.
//!
//! The first two need root (and a filesystem with the immutable flag; the test keeps its files
//! under `CARGO_TARGET_TMPDIR`, not `/tmp`, which is often a tmpfs): without them they print
//! why and return, showing as passed with a `SKIPPED` line on stderr.

use crate::common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// `chattr +i` on the database and its WAL while alive; `chattr -i` when dropped, so the
/// temporary directory can be removed whatever the test did.
struct Immutable(Vec<PathBuf>);

impl Immutable {
    fn set(files: Vec<PathBuf>) -> Result<Immutable, String> {
        let guard = Immutable(files);
        for f in &guard.0 {
            let out = Command::new("chattr").arg("+i").arg(f).output();
            match out {
                Ok(o) if o.status.success() => {}
                Ok(o) => return Err(String::from_utf8_lossy(&o.stderr).trim().to_string()),
                Err(e) => return Err(format!("chattr: {e}")),
            }
        }
        Ok(guard)
    }
}

impl Drop for Immutable {
    fn drop(&mut self) {
        for f in &self.0 {
            let _ = Command::new("chattr").arg("-i").arg(f).status();
        }
    }
}

/// A tmpfs of `size` mounted on a fresh directory; unmounted when dropped.
struct Tmpfs {
    dir: tempfile::TempDir,
}

impl Tmpfs {
    fn mount(size: &str) -> Result<Tmpfs, String> {
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(dir.path())
            .output()
            .map_err(|e| format!("mount: {e}"))?;
        if !out.status.success() {
            return Err(String::from_utf8_lossy(&out.stderr).trim().to_string());
        }
        Ok(Tmpfs { dir })
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount")
            .arg("-l")
            .arg(self.dir.path())
            .status();
    }
}

fn skip(test: &str, why: &str) {
    eprintln!("SKIPPED {test}: {why}");
}

async fn submit(client: &reqwest::Client, url: &str, case: &Value) -> reqwest::Response {
    client
        .post(format!("{url}/v1/jobs"))
        .json(case)
        .send()
        .await
        .unwrap()
}

/// Asserts a 503 problem with `Retry-After`.
async fn assert_unavailable(r: reqwest::Response, what: &str) -> Value {
    assert_eq!(r.status(), 503, "{what}: {}", r.text().await.unwrap());
    assert_eq!(
        r.headers()["content-type"],
        "application/problem+json",
        "{what}"
    );
    assert!(r.headers().contains_key("retry-after"), "{what}");
    r.json().await.unwrap()
}

/// The job's status; `None` while it cannot be read.
async fn status_of(app: &TestApp, id: &str) -> Option<String> {
    let r = app.get(&format!("/v1/jobs/{id}")).await;
    if !r.status().is_success() {
        return None;
    }
    let job: Value = r.json().await.ok()?;
    job["status"].as_str().map(String::from)
}

/// Jobs running in this process, from `/metrics`.
async fn running_here(app: &TestApp) -> Option<u32> {
    let text = app.get("/metrics").await.text().await.ok()?;
    text.lines()
        .find_map(|l| l.strip_prefix("crush_running_jobs "))
        .and_then(|v| v.trim().parse().ok())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_read_only_database_answers_503_then_heals_without_a_restart() {
    const TEST: &str = "a_read_only_database_answers_503_then_heals_without_a_restart";
    // The server's log, shown when the test fails.
    let _ = tracing_subscriber::fmt()
        .with_env_filter("crush=debug,sqlx=warn")
        .with_test_writer()
        .try_init();
    // On the target directory's filesystem: /tmp may be a tmpfs, which has no immutable flag.
    let dir = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let db = sqlite_url(dir.path());
    let flags = [
        "--port",
        "0",
        "--database-url",
        db.as_str(),
        "--threads-per-job",
        "1",
        "--heartbeat-ms",
        "100",
        "--stale-after-s",
        "1",
    ];
    let server = crush::service::start(crush::service::ServeArgs::from_flags(flags).unwrap())
        .await
        .unwrap();
    let app = TestApp {
        url: format!("http://{}", server.addr),
        client: client(),
        server: Some(server),
        dir: tempfile::tempdir().unwrap(),
        db: db.clone(),
    };
    // A job that is running when the disk goes read-only and finishes during the outage.
    let id = app.submit(&medium_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    app.wait_for(&id, &["running"], Duration::from_secs(30))
        .await;
    let file = dir.path().join("crush.db");
    let wal = dir.path().join("crush.db-wal");
    let lock = match Immutable::set(vec![file, wal]) {
        Ok(lock) => lock,
        Err(why) => return skip(TEST, &format!("cannot make the database immutable: {why}")),
    };

    // Several failing writes, each of which used to leave its pooled connection inside a
    // transaction ("attempted to call begin_with at non-zero transaction depth").
    for i in 0..12 {
        let r = submit(&app.client, &app.url, &tiny_case()).await;
        assert_unavailable(r, &format!("submit {i} to a read-only database")).await;
    }
    assert_unavailable(app.get("/healthz").await, "health of a read-only database").await;
    // The run ends during the outage (the medium case takes well under a second); its outcome
    // cannot be stored yet, so the worker retries it: the job stays `running`, and its stale
    // heartbeat does not make the reaper of its own server requeue it.
    tokio::time::sleep(Duration::from_secs(3)).await;
    assert_eq!(
        running_here(&app).await,
        Some(1),
        "the outcome is still retried"
    );
    assert_eq!(status_of(&app, &id).await.as_deref(), Some("running"));

    drop(lock);
    // The very next requests work: no connection is left in a broken transaction.
    let r = app.get("/healthz").await;
    assert_eq!(r.status(), 200, "{}", r.text().await.unwrap());
    let r = submit(&app.client, &app.url, &tiny_case()).await;
    assert_eq!(r.status(), 202, "{}", r.text().await.unwrap());
    let fresh = r.json::<Value>().await.unwrap()["id"]
        .as_str()
        .unwrap()
        .to_string();
    // The retried outcome is stored once the disk heals: the first claim's, not a rerun.
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(90))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["attempts"], 1, "stored by the run that finished: {job}");
    let job = app
        .wait_for(&fresh, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
}

// Regression: once in about six runs under load the first submit after the space was freed
// answered 500 ("non-zero transaction depth"): a connection opened in the same millisecond as
// the failure passed for a newer one (`store::fresh_enough`).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_full_disk_answers_503_then_heals_when_space_is_freed() {
    const TEST: &str = "a_full_disk_answers_503_then_heals_when_space_is_freed";
    let fs = match Tmpfs::mount("4m") {
        Ok(fs) => fs,
        Err(why) => return skip(TEST, &format!("cannot mount a small tmpfs: {why}")),
    };
    let db = sqlite_url(fs.path());
    let flags = [
        "--port",
        "0",
        "--database-url",
        db.as_str(),
        "--concurrent-jobs",
        "0",
    ];
    let server = crush::service::start(crush::service::ServeArgs::from_flags(flags).unwrap())
        .await
        .unwrap();
    let app = TestApp {
        url: format!("http://{}", server.addr),
        client: client(),
        server: Some(server),
        dir: tempfile::tempdir().unwrap(),
        db: db.clone(),
    };
    app.submit(&tiny_case()).await;
    // Fill the filesystem to the last byte.
    let filler = fs.path().join("filler");
    {
        use std::io::Write;
        let mut f = std::fs::File::create(&filler).unwrap();
        let block = vec![0u8; 64 * 1024];
        while f.write_all(&block).is_ok() {}
        let byte = [0u8; 1];
        while f.write_all(&byte).is_ok() {}
    }
    // The WAL has a little room left in pages it already holds: submit until it runs out.
    let mut accepted = 0;
    let problem = loop {
        let mut case = tiny_case();
        case["label"] = json!("x".repeat(100));
        let r = submit(&app.client, &app.url, &case).await;
        if r.status() == 202 {
            accepted += 1;
            assert!(accepted < 500, "500 submits fit on a full 4 MB disk");
            continue;
        }
        break assert_unavailable(r, "submit to a full disk").await;
    };
    assert!(
        problem["detail"].as_str().unwrap().contains("database"),
        "{problem}"
    );
    assert_unavailable(app.get("/healthz").await, "health of a full disk").await;

    std::fs::remove_file(&filler).unwrap();
    let r = app.get("/healthz").await;
    assert_eq!(r.status(), 200, "{}", r.text().await.unwrap());
    let r = submit(&app.client, &app.url, &tiny_case()).await;
    assert_eq!(r.status(), 202, "{}", r.text().await.unwrap());
    drop(app);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_database_file_deleted_while_serving_is_noticed_logged_and_answered_with_503() {
    let dir = tempfile::tempdir().unwrap();
    let db = sqlite_url(dir.path());
    let log_path = dir.path().join("server.log");
    let log = std::fs::File::create(&log_path).unwrap();
    let mut process = Command::new(env!("CARGO_BIN_EXE_crush"))
        .args(["serve", "--port", "0", "--database-url", &db])
        .args(["--threads-per-job", "1", "--stale-after-s", "1"])
        .args(["--heartbeat-ms", "100"])
        .env("RUST_LOG", "error")
        .stdout(std::process::Stdio::piped())
        .stderr(log)
        .spawn()
        .unwrap();
    let url = {
        use std::io::BufRead;
        let stdout = process.stdout.take().unwrap();
        let mut lines = std::io::BufReader::new(stdout).lines();
        let line = lines.next().unwrap().unwrap();
        std::thread::spawn(move || for _ in lines {});
        line.rsplit(' ').next().unwrap().trim().to_string()
    };
    let server = Child {
        process,
        url,
        log: Default::default(),
    };
    let client = client();
    assert_eq!(
        submit(&client, &server.url, &tiny_case()).await.status(),
        202
    );

    std::fs::remove_file(dir.path().join("crush.db")).unwrap();
    let r = submit(&client, &server.url, &tiny_case()).await;
    let problem = assert_unavailable(r, "submit after the file was deleted").await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(detail.contains("was deleted"), "{detail}");
    assert!(
        !detail.contains(dir.path().to_str().unwrap()),
        "the path is for the log, not clients: {detail}"
    );
    let r = client
        .get(format!("{}/healthz", server.url))
        .send()
        .await
        .unwrap();
    // 503 is the claim; the detail may be the probe's time-out on a loaded machine (seen once
    // in 20 runs here), so only the submit above is held to naming the deletion.
    assert_unavailable(r, "health after the file was deleted").await;
    // The periodic check (every quarter of --stale-after-s) keeps saying so in the log.
    tokio::time::sleep(Duration::from_millis(800)).await;
    drop(server);
    let text = std::fs::read_to_string(&log_path).unwrap();
    let db_path = dir.path().join("crush.db");
    let lines: Vec<&str> = text.lines().filter(|l| l.contains("was deleted")).collect();
    assert!(
        lines.len() >= 2,
        "the deletion is logged at once and again by the periodic check:\n{text}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.contains(db_path.to_str().unwrap()) && l.contains("ERROR")),
        "the log names the file:\n{text}"
    );
}

/// What broke: a frame the database refused (here SQLite's write lock, held by another process
/// past the server's 10 s busy timeout) was dropped with a log line, and its job still ended
/// `succeeded` with `frames/k.vtu` missing. The write is retried until the lock is free.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_write_lock_held_past_the_busy_timeout_mid_run_loses_no_frame() {
    use sqlx::{Connection, Executor};
    let dir = tempfile::tempdir().unwrap();
    let db = sqlite_url(dir.path());
    let app = TestApp::start_on(&db, &["--heartbeat-ms", "200"]).await;
    let mut case = killable_case();
    case["output"]["frames"] = serde_json::json!(4);
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let started = Instant::now();
    while app.job(&id).await["progress"].is_null() {
        assert!(started.elapsed() < Duration::from_secs(60), "no progress");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let mut other = sqlx::SqliteConnection::connect(&db).await.unwrap();
    other.execute("BEGIN IMMEDIATE").await.unwrap();
    tokio::time::sleep(Duration::from_secs(12)).await;
    other.execute("COMMIT").await.unwrap();
    other.close().await.unwrap();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(120))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    let status = whole_or_not_succeeded(&app.client, &app.url, &id, 500, 4).await;
    assert_eq!(status, "succeeded");
}

/// What broke: a 26-particle job keeping the most history points allowed (100 000) held
/// SQLite's writer for seconds at a time while it stored them: `/healthz` answered 503 and
/// submits went unanswered for 10 s. The API now answers throughout.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_largest_history_a_job_may_keep_leaves_the_api_answering() {
    let app = TestApp::start(&[]).await;
    let case = serde_json::json!({
        "tube": {"length_mm": 20},
        "loading": {"crush_distance_mm": 5},
        "discretization": {"model": "axisymmetric", "particles_through_thickness": 2},
        "output": {"history_points": 100_000}
    });
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let (mut polls, mut slowest) = (0, Duration::ZERO);
    let started = Instant::now();
    loop {
        let asked = Instant::now();
        let health = app.get("/healthz").await;
        let r = submit(&app.client, &app.url, &tiny_case()).await;
        slowest = slowest.max(asked.elapsed());
        assert_eq!(health.status(), 200, "{}", health.text().await.unwrap());
        assert_eq!(r.status(), 202, "{}", r.text().await.unwrap());
        polls += 1;
        if status_of(&app, &id).await.as_deref() == Some("succeeded") {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "the job did not end"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let history = get_json(&app.client, &app.at(&format!("/v1/jobs/{id}/history"))).await;
    assert_eq!(history["rows"].as_array().unwrap().len(), 100_000);
    // A health check and a submit wait behind one batch of history rows at most: well under
    // the health check's own 3 s limit.
    eprintln!("{polls} polls while the job ran, the slowest {slowest:?}");
    assert!(
        slowest < Duration::from_secs(2),
        "the API waited {slowest:?}"
    );
}
