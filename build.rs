//! Build-time facts the crate needs.
//!
//! - Rebuild when a migration is added or changed: `sqlx::migrate!` embeds them at compile time.
//! - `cfg(crush_browser)` when headless Chromium and ChromeDriver are on `PATH` (or named by
//!   `CRUSH_CHROMIUM` / `CRUSH_CHROMEDRIVER`), or when `CRUSH_BROWSER_TEST=required`: the browser
//!   test runs then, and is reported as *ignored* otherwise, so a machine without a browser shows
//!   the skip instead of a pass.
//! - `cfg(crush_postgres)` when `CRUSH_TEST_POSTGRES` names a PostgreSQL server for the tests:
//!   the multi-node tests run then, and are reported as ignored otherwise.
//! - `CRUSH_SOLVER_SOURCE`: a 64-bit FNV-1a hash of every file under `src/solver` and of
//!   `Cargo.lock`, so that `crush validate` can key its cache by the solver that ran a scene (a
//!   change to the docs, the service or the CLI leaves it, and the cache, as it was).
use std::path::{Path, PathBuf};

fn on_path(env: &str, names: &[&str]) -> bool {
    if let Some(p) = std::env::var_os(env) {
        return PathBuf::from(p).is_file();
    }
    let Some(path) = std::env::var_os("PATH") else {
        return false;
    };
    std::env::split_paths(&path).any(|dir| names.iter().any(|n| dir.join(n).is_file()))
}

/// Folds the file at `path`, or every file under it in path order, into the FNV-1a hash `h`.
fn hash_tree(path: &Path, h: &mut u64) {
    if path.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        entries.sort();
        for entry in entries {
            hash_tree(&entry, h);
        }
    } else if let Ok(bytes) = std::fs::read(path) {
        let name = path.to_string_lossy().into_owned();
        for b in name.bytes().chain(bytes) {
            *h = (*h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

fn main() {
    println!("cargo:rerun-if-changed=migrations");
    println!("cargo:rerun-if-changed=src/solver");
    println!("cargo:rerun-if-changed=Cargo.lock");
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    hash_tree(Path::new("src/solver"), &mut h);
    hash_tree(Path::new("Cargo.lock"), &mut h);
    println!("cargo:rustc-env=CRUSH_SOLVER_SOURCE={h:016x}");
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
