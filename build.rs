//! Build-time facts the crate needs.
//!
//! - Rebuild when a migration is added or changed: `sqlx::migrate!` embeds them at compile time.
//! - `cfg(crush_browser)` when headless Chromium and ChromeDriver are on `PATH` (or named by
//!   `CRUSH_CHROMIUM` / `CRUSH_CHROMEDRIVER`), or when `CRUSH_BROWSER_TEST=required`: the browser
//!   test runs then, and is reported as *ignored* otherwise, so a machine without a browser shows
//!   the skip instead of a pass.
//! - `cfg(crush_postgres)` when `CRUSH_TEST_POSTGRES` names a PostgreSQL server for the tests:
//!   the multi-node tests run then, and are reported as ignored otherwise.
use std::path::PathBuf;

fn on_path(env: &str, names: &[&str]) -> bool {
    if let Some(p) = std::env::var_os(env) {
        return PathBuf::from(p).is_file();
    }
    let Some(path) = std::env::var_os("PATH") else {
        return false;
    };
    std::env::split_paths(&path).any(|dir| names.iter().any(|n| dir.join(n).is_file()))
}

fn main() {
    println!("cargo:rerun-if-changed=migrations");
    for var in [
        "PATH",
        "CRUSH_BROWSER_TEST",
        "CRUSH_CHROMIUM",
        "CRUSH_CHROMEDRIVER",
        "CRUSH_TEST_POSTGRES",
    ] {
        println!("cargo:rerun-if-env-changed={var}");
    }
    println!("cargo::rustc-check-cfg=cfg(crush_browser)");
    println!("cargo::rustc-check-cfg=cfg(crush_postgres)");
    if std::env::var_os("CRUSH_TEST_POSTGRES").is_some_and(|v| !v.is_empty()) {
        println!("cargo:rustc-cfg=crush_postgres");
    }
    let required = std::env::var("CRUSH_BROWSER_TEST").as_deref() == Ok("required");
    let browser = on_path(
        "CRUSH_CHROMIUM",
        &["chromium", "chromium-browser", "google-chrome"],
    ) && on_path("CRUSH_CHROMEDRIVER", &["chromedriver"]);
    if required || browser {
        println!("cargo:rustc-cfg=crush_browser");
    }
}
