//! Driving the web page in headless Chromium through ChromeDriver (fantoccini), for the browser
//! tests: find the programs, start the driver on a free port, open a session (any extra
//! Chromium flags, such as `--force-dark-mode`), run scripts in the page and wait on them, click,
//! type, and take screenshots.
#![allow(dead_code)]

use fantoccini::{Client, ClientBuilder, Locator};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

pub fn find_program(env: &str, names: &[&str]) -> Option<PathBuf> {
    if let Ok(p) = std::env::var(env) {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in names {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return Some(candidate);
            }
        }
    }
    None
}

/// ChromeDriver on a free port; killed on drop.
pub struct Driver {
    child: Child,
    pub url: String,
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub async fn start_driver(program: &Path) -> Driver {
    start_driver_in_zone(program, None).await
}

/// ChromeDriver, and so the Chromium it starts, in the time zone `zone` (`TZ`, such as
/// "Asia/Kolkata"); the machine's own when `None`.
pub async fn start_driver_in_zone(program: &Path, zone: Option<&str>) -> Driver {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut command = Command::new(program);
    if let Some(zone) = zone {
        command.env("TZ", zone);
    }
    let child = command
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromedriver starts");
    let url = format!("http://127.0.0.1:{port}");
    let deadline = Instant::now() + Duration::from_secs(20);
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(Instant::now() < deadline, "chromedriver did not listen");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    Driver { child, url }
}

pub async fn connect(driver: &Driver, chromium: &Path, profile: &Path) -> Client {
    connect_with(driver, chromium, profile, &[]).await
}

/// A session with more Chromium flags (`--force-dark-mode`, another `--window-size`).
pub async fn connect_with(
    driver: &Driver,
    chromium: &Path,
    profile: &Path,
    extra: &[&str],
) -> Client {
    connect_full(driver, chromium, profile, extra, json!({})).await
}

/// A session with more Chromium flags and more `goog:chromeOptions` (`prefs`, such as where
/// downloads go; `mobileEmulation`, a phone's screen).
pub async fn connect_full(
    driver: &Driver,
    chromium: &Path,
    profile: &Path,
    extra: &[&str],
    options: Value,
) -> Client {
    let mut args: Vec<String> = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-dev-shm-usage",
        "--hide-scrollbars",
    ]
    .iter()
    .map(|a| a.to_string())
    .collect();
    if !extra.iter().any(|a| a.starts_with("--window-size=")) {
        args.push("--window-size=1500,1400".into());
    }
    args.extend(extra.iter().map(|a| a.to_string()));
    args.push(format!("--user-data-dir={}", profile.display()));
    let mut chrome = json!({ "binary": chromium, "args": args });
    for (k, v) in options.as_object().into_iter().flatten() {
        chrome[k] = v.clone();
    }
    let mut caps = serde_json::Map::new();
    caps.insert("goog:chromeOptions".into(), chrome);
    let connector = hyper_util::client::legacy::connect::HttpConnector::new();
    ClientBuilder::new(connector)
        .capabilities(caps)
        .connect(&driver.url)
        .await
        .expect("a Chromium session")
}

/// Chromium and ChromeDriver, as `build.rs` found them; panics when they went missing.
pub fn programs() -> (PathBuf, PathBuf) {
    let chromium = find_program(
        "CRUSH_CHROMIUM",
        &["chromium", "chromium-browser", "google-chrome"],
    );
    let chromedriver = find_program("CRUSH_CHROMEDRIVER", &["chromedriver"]);
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        panic!("chromium or chromedriver is missing (CRUSH_BROWSER_TEST=required or PATH changed since the build)");
    };
    (chromium, chromedriver)
}

/// Where screenshots go: `$CRUSH_SCREENSHOTS`, else `target/browser-screenshots`.
pub fn screenshots() -> PathBuf {
    let dir = std::env::var_os("CRUSH_SCREENSHOTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/browser-screenshots")
        });
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `script` (a function body returning a value) in the page.
pub async fn js(c: &Client, script: &str) -> Value {
    c.execute(script, vec![]).await.unwrap()
}

/// Polls `script` until it returns something truthy; returns that, or panics saying `what`.
pub async fn until(c: &Client, script: &str, timeout: Duration, what: &str) -> Value {
    let deadline = Instant::now() + timeout;
    loop {
        let v = js(c, script).await;
        let truthy = match &v {
            Value::Null => false,
            Value::Bool(b) => *b,
            Value::String(s) => !s.is_empty(),
            Value::Number(n) => n.as_f64() != Some(0.0),
            _ => true,
        };
        if truthy {
            return v;
        }
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

pub async fn shot(c: &Client, dir: &Path, name: &str) {
    let png = c.screenshot().await.unwrap();
    std::fs::write(dir.join(format!("{name}.png")), png).unwrap();
}

pub async fn click(c: &Client, css: &str) {
    c.find(Locator::Css(css))
        .await
        .unwrap()
        .click()
        .await
        .unwrap();
}

pub fn error_beside(field: &str) -> String {
    format!(
        "const e = document.querySelector('.field[data-row=\"{field}\"] .err'); \
         return e ? e.textContent : null;"
    )
}

/// Sets form fields the way typing would (an `input` event each).
pub async fn fill(c: &Client, values: &[(&str, &str)]) {
    for (field, value) in values {
        let script = format!(
            "const i = document.querySelector('[data-field=\"{field}\"]'); \
             i.value = {value:?}; i.dispatchEvent(new Event('input', {{bubbles: true}})); return true;"
        );
        js(c, &script).await;
    }
}
