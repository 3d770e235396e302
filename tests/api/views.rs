//! The page's lists and views in a real browser (headless Chromium through ChromeDriver,
//! against the real server on port 0): the job list's label search and counts per state, the
//! list of sweeps, jobs picked from a sweep and from outside it overlaid (and the overlay
//! downloaded as CSV and SVG, its legend under the curves), a job run again and deleted, the case
//! table of a job that left the shape functions to the code, the sweep table's headers, its
//! curves and jobs named by value and unit, and the cost of a whole sweep in
//! the form; then the page with the system in dark mode, and every view at a phone's width
//! without sideways scrolling. Screenshots go where `tests/browser.rs` puts them.
//!
//! Needs `chromium` and `chromedriver`; skipped (ignored) without them, as `tests/browser.rs`.

use crate::browser_kit::*;
use crate::common::{get_json, tiny_case, TestApp};
use fantoccini::{Client, Locator};
use serde_json::json;
use std::time::Duration;

const LONG: Duration = Duration::from_secs(120);

/// Three labelled jobs and a sweep of two, all succeeded: (job ids by label, sweep id).
async fn fill_store(app: &TestApp) -> (Vec<(String, String)>, String) {
    let mut jobs = Vec::new();
    for label in ["alpha one", "alpha two", "beta"] {
        let mut case = tiny_case();
        case["label"] = json!(label);
        let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
        jobs.push((label.to_string(), id));
    }
    let body = json!({"label": "gamma sweep", "base": tiny_case(),
                      "parameters": {"tube.thickness_mm": [2.0, 3.2]}});
    let (_, sweep) = app.create_sweep(&body).await;
    let mut ids: Vec<String> = jobs.iter().map(|(_, id)| id.clone()).collect();
    for row in sweep["rows"].as_array().unwrap() {
        ids.push(row["job_id"].as_str().unwrap().to_string());
    }
    for id in &ids {
        app.wait_for(id, &["succeeded"], LONG).await;
    }
    (jobs, sweep["id"].as_str().unwrap().to_string())
}

async fn rows(c: &Client, table: &str) -> u64 {
    js(
        c,
        &format!("return document.querySelectorAll('#{table} tbody tr').length;"),
    )
    .await
    .as_u64()
    .unwrap()
}

/// Clicks the element `css` from inside the page, in one step: the side lists are redrawn every
/// few seconds, and an element found by WebDriver may be replaced before its click arrives.
async fn click_in_page(c: &Client, css: &str) {
    let script = format!(
        "const e = document.querySelector({css:?}); if (!e) return false; e.click(); return true;"
    );
    until(c, &script, LONG, css).await;
}

/// Clicks a download link and reads the file the browser saved in `dir` as `name`.
async fn downloaded(c: &Client, css: &str, dir: &std::path::Path, name: &str) -> String {
    click(c, css).await;
    let path = dir.join(name);
    let deadline = std::time::Instant::now() + LONG;
    let mut last: Option<String> = None;
    loop {
        // Chromium writes a `.crdownload` file and renames it when the download is complete,
        // but it may also create the final name empty first: a download is done when its file
        // is not empty, no `.crdownload` is left beside it, and two reads 50 ms apart agree.
        let pending = std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .flatten()
                    .any(|e| e.file_name().to_string_lossy().ends_with(".crdownload"))
            })
            .unwrap_or(true);
        let text = std::fs::read_to_string(&path).ok();
        if let Some(text) = text.as_ref().filter(|t| !t.is_empty() && !pending) {
            if last.as_ref() == Some(text) {
                return text.clone();
            }
        }
        last = text;
        assert!(
            std::time::Instant::now() < deadline,
            "{name} was not downloaded"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

#[tokio::test]
#[cfg_attr(
    not(crush_browser),
    ignore = "needs chromium and chromedriver on PATH when the tests are built \
              (apt-get install chromium chromium-driver), or CRUSH_BROWSER_TEST=required"
)]
async fn the_page_searches_lists_sweeps_overlays_reruns_and_deletes() {
    let (chromium, chromedriver) = programs();
    let shots = screenshots();
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let (jobs, sweep) = fill_store(&app).await;
    let driver = start_driver(&chromedriver).await;
    let profile = tempfile::tempdir().unwrap();
    let downloads = tempfile::tempdir().unwrap();
    let prefs = json!({"prefs": {
        "download.default_directory": downloads.path(),
        "download.prompt_for_download": false,
    }});
    let c = connect_full(&driver, &chromium, profile.path(), &[], prefs).await;

    // Counts per state, and the label search (any case, any part of the label).
    c.goto(&app.url).await.unwrap();
    until(
        &c,
        "return document.querySelectorAll('#job-list tbody tr').length === 5;",
        LONG,
        "five jobs",
    )
    .await;
    until(
        &c,
        "return document.getElementById('job-counts').textContent === '5 succeeded';",
        LONG,
        "the counts",
    )
    .await;
    c.find(Locator::Css("#search"))
        .await
        .unwrap()
        .send_keys("ALPHA")
        .await
        .unwrap();
    until(
        &c,
        "return document.querySelectorAll('#job-list tbody tr').length === 2;",
        LONG,
        "the search",
    )
    .await;
    let listed = js(
        &c,
        "return document.querySelector('#job-list tbody').textContent;",
    )
    .await;
    assert!(
        listed.as_str().unwrap().contains("alpha one")
            && !listed.as_str().unwrap().contains("beta"),
        "{listed}"
    );
    shot(&c, &shots, "8-search").await;

    // The sweeps list: its label, what it varies and its jobs' states.
    click(&c, "#tab-sweeps").await;
    until(
        &c,
        "return document.querySelectorAll('#sweep-list tbody tr').length === 0;",
        LONG,
        "no sweep labelled alpha",
    )
    .await;
    js(&c, "const s = document.getElementById('search'); s.value = 'gamma'; s.dispatchEvent(new Event('input')); return true;").await;
    until(
        &c,
        "return document.querySelectorAll('#sweep-list tbody tr').length === 1;",
        LONG,
        "the sweep",
    )
    .await;
    let text = js(
        &c,
        "return document.querySelector('#sweep-list tbody').textContent;",
    )
    .await;
    let text = text.as_str().unwrap();
    assert!(
        text.contains("gamma sweep") && text.contains("t × 2") && text.contains("2 succeeded"),
        "{text}"
    );
    shot(&c, &shots, "9-sweeps").await;

    // The sweep's table names its columns with their units.
    click_in_page(&c, "#sweep-list tbody a").await;
    until(
        &c,
        &format!("return location.hash === '#/sweeps/{sweep}';"),
        LONG,
        "the sweep view",
    )
    .await;
    until(
        &c,
        "return document.querySelectorAll('#sweep-table tbody tr').length === 2;",
        LONG,
        "the sweep table",
    )
    .await;
    let heads = js(
        &c,
        "return [...document.querySelectorAll('#sweep-table th')].map(h => h.textContent);",
    )
    .await;
    let heads: Vec<&str> = heads
        .as_array()
        .unwrap()
        .iter()
        .map(|h| h.as_str().unwrap())
        .collect();
    for h in ["mean load, kN", "energy absorbed, J", "t, mm", "wall time"] {
        assert!(heads.contains(&h), "{heads:?}");
    }
    assert!(
        !heads
            .iter()
            .any(|h| h.ends_with(" n") || h.ends_with(" mj")),
        "{heads:?}"
    );
    assert_eq!(rows(&c, "sweep-table").await, 2);
    // The sweep's curves are named by the value each ran at, with its unit.
    let names = until(
        &c,
        "const s = [...document.querySelectorAll('#sweep-curves .u-legend .u-series')].map(e => e.textContent);          return s.length === 2 ? s : null;",
        LONG,
        "the sweep's curves",
    )
    .await;
    assert_eq!(names, json!(["t = 2 mm", "t = 3.2 mm"]));

    // Pick two jobs outside the sweep and one of it, and overlay them.
    click(&c, "#tab-jobs").await;
    js(&c, "const s = document.getElementById('search'); s.value = ''; s.dispatchEvent(new Event('input')); return true;").await;
    until(
        &c,
        "return document.querySelectorAll('#job-list tbody tr').length === 5;",
        LONG,
        "all jobs again",
    )
    .await;
    // A sweep's job in the list says its value with the unit.
    let listed = js(
        &c,
        "return document.querySelector('#job-list tbody').textContent;",
    )
    .await;
    assert!(
        listed.as_str().unwrap().contains("sweep · t = 3.2 mm"),
        "{listed}"
    );
    let sweep_job = get_json(&app.client, &app.at(&format!("/v1/sweeps/{sweep}"))).await["rows"][0]
        ["job_id"]
        .as_str()
        .unwrap()
        .to_string();
    for id in [&jobs[0].1, &jobs[2].1, &sweep_job] {
        click_in_page(&c, &format!("input[data-pick='{id}']")).await;
    }
    until(
        &c,
        "return document.getElementById('compare').textContent === 'Overlay 3 picked';",
        LONG,
        "three picked",
    )
    .await;
    click(&c, "#compare").await;
    until(&c, "const c = document.getElementById('overlay-curves'); return c && c.dataset.series === '3' && Number(c.dataset.points) > 0;", LONG, "the overlay").await;
    assert_eq!(rows(&c, "overlay-table").await, 3);
    let csv = downloaded(&c, "#overlay-csv", downloads.path(), "overlay.csv").await;
    let head = csv.lines().next().unwrap();
    assert!(
        head.starts_with("displacement_mm,")
            && head.contains("alpha one")
            && head.contains("t = 2"),
        "{head}"
    );
    assert!(csv.lines().count() > 10, "{csv}");
    for line in csv.lines().skip(1) {
        assert_eq!(line.split(',').count(), 4, "{line}");
    }
    let svg = downloaded(&c, "#overlay-svg", downloads.path(), "overlay.svg").await;
    assert!(
        svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
        "{svg}"
    );
    assert_eq!(svg.matches("<polyline").count(), 3, "{svg}");
    // Its legend lies under the plot, below every point of every curve.
    let lowest = svg
        .split("points=\"")
        .skip(1)
        .flat_map(|p| p[..p.find('"').unwrap()].split_whitespace())
        .map(|xy| xy.split_once(',').unwrap().1.parse::<f64>().unwrap())
        .fold(f64::MIN, f64::max);
    let legend: Vec<f64> = svg
        .split("<text class=\"legend\"")
        .skip(1)
        .map(|t| {
            let y = t.split(" y=\"").nth(1).unwrap();
            y[..y.find('"').unwrap()].parse().unwrap()
        })
        .collect();
    assert_eq!(legend.len(), 3, "{svg}");
    assert!(
        legend.iter().all(|y| *y > lowest + 20.0),
        "legend at {legend:?}, curves down to {lowest}"
    );
    shot(&c, &shots, "10-overlay").await;

    // A job that left the shape functions to the code says which it got, never "null".
    let beta = &jobs[2].1;
    c.goto(&format!("{}/#/jobs/{beta}", app.url)).await.unwrap();
    until(&c, "const t = document.getElementById('case-table'); return t && document.getElementById('summary') ? t.textContent : null;", LONG, "the case table").await;
    let table = js(
        &c,
        "return document.getElementById('case-table').textContent;",
    )
    .await;
    let table = table.as_str().unwrap();
    assert!(
        table.contains("chosen by the code") && !table.contains("null"),
        "{table}"
    );

    // Run it again: a new job of the same case; then delete the new one.
    click(&c, "#rerun").await;
    let hash = until(&c, &format!("return location.hash.startsWith('#/jobs/') && !location.hash.endsWith('{beta}') ? location.hash : null;"), LONG, "the new job").await;
    let again = hash
        .as_str()
        .unwrap()
        .trim_start_matches("#/jobs/")
        .to_string();
    let job = app.job(&again).await;
    assert_eq!(job["case"], app.job(beta).await["case"]);
    until(&c, "const s = document.getElementById('job-status'); return s && s.textContent === 'succeeded' && document.getElementById('delete');", LONG, "the rerun to finish").await;
    click(&c, "#delete").await;
    assert_eq!(
        app.get(&format!("/v1/jobs/{again}")).await.status(),
        200,
        "the first click only asks"
    );
    click(&c, "#delete").await;
    until(
        &c,
        "return location.hash === '#/';",
        LONG,
        "back to the form",
    )
    .await;
    assert_eq!(app.get(&format!("/v1/jobs/{again}")).await.status(), 404);

    // The form's sweep line costs the whole sweep.
    until(
        &c,
        "return document.getElementById('sweep-field') !== null;",
        LONG,
        "the form",
    )
    .await;
    js(
        &c,
        "document.getElementById('sweep-field').value = 'tube.thickness_mm'; \
            const v = document.getElementById('sweep-values'); v.value = '1.5, 2, 3'; \
            v.dispatchEvent(new Event('input', {bubbles: true})); return true;",
    )
    .await;
    let line = until(
        &c,
        "return document.getElementById('sweep-estimate').textContent;",
        LONG,
        "the sweep's cost",
    )
    .await;
    assert!(
        line.as_str()
            .unwrap()
            .starts_with("The sweep: 3 jobs, about "),
        "{line}"
    );
    assert!(line.as_str().unwrap().contains("in all"), "{line}");

    let errors = js(&c, "return window.__errors;").await;
    assert_eq!(
        errors,
        json!([]),
        "uncaught errors or CSP violations in the page"
    );
    c.close().await.unwrap();
}

#[tokio::test]
#[cfg_attr(
    not(crush_browser),
    ignore = "needs chromium and chromedriver on PATH when the tests are built \
              (apt-get install chromium chromium-driver), or CRUSH_BROWSER_TEST=required"
)]
async fn the_page_follows_the_system_s_dark_mode_and_fits_a_phone_s_width() {
    let (chromium, chromedriver) = programs();
    let shots = screenshots();
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    let (jobs, sweep) = fill_store(&app).await;
    let job = &jobs[0].1;
    let driver = start_driver(&chromedriver).await;

    // Dark mode: the page's own colours change with the system's.
    let profile = tempfile::tempdir().unwrap();
    let c = connect_with(&driver, &chromium, profile.path(), &["--force-dark-mode"]).await;
    c.goto(&format!("{}/#/jobs/{job}", app.url)).await.unwrap();
    until(
        &c,
        "const i = document.getElementById('shape'); return i && i.complete && i.naturalWidth > 0;",
        LONG,
        "the job",
    )
    .await;
    let dark = js(
        &c,
        "return matchMedia('(prefers-color-scheme: dark)').matches;",
    )
    .await;
    assert_eq!(dark, true);
    let bg = js(
        &c,
        "return getComputedStyle(document.body).backgroundColor;",
    )
    .await;
    assert_eq!(bg, "rgb(15, 20, 28)");
    let card = js(
        &c,
        "return getComputedStyle(document.querySelector('main')).backgroundColor;",
    )
    .await;
    assert_eq!(card, "rgb(24, 32, 43)");
    c.set_window_size(1500, 2300).await.unwrap();
    shot(&c, &shots, "11-dark").await;
    c.close().await.unwrap();

    // A phone: no view is wider than the screen.
    let profile = tempfile::tempdir().unwrap();
    // Headless Chromium's windows are at least 500 px wide: a phone's screen is emulated.
    let phone = json!({"mobileEmulation": {
        "deviceMetrics": {"width": 390, "height": 844, "pixelRatio": 2.0}
    }});
    let c = connect_full(&driver, &chromium, profile.path(), &[], phone).await;
    let views = [
        ("form", "#/".to_string(), "return document.getElementById('submit') !== null;"),
        ("job", format!("#/jobs/{job}"), "const i = document.getElementById('shape'); return i && i.complete && i.naturalWidth > 0;"),
        ("sweep", format!("#/sweeps/{sweep}"), "return document.querySelectorAll('#sweep-table tbody tr').length === 2 && Number(document.getElementById('sweep-curves').dataset.points) > 0;"),
        ("overlay", format!("#/compare/{},{}", jobs[0].1, jobs[1].1), "const c = document.getElementById('overlay-curves'); return c && Number(c.dataset.points) > 0;"),
    ];
    for (name, hash, ready) in views {
        c.goto(&format!("{}/{hash}", app.url)).await.unwrap();
        until(&c, ready, LONG, name).await;
        until(
            &c,
            "return document.querySelectorAll('#job-list tbody tr').length === 5;",
            LONG,
            "the job list",
        )
        .await;
        let (page, screen) = {
            let v = js(
                &c,
                "return [document.documentElement.scrollWidth, window.innerWidth];",
            )
            .await;
            (v[0].as_u64().unwrap(), v[1].as_u64().unwrap())
        };
        assert_eq!(screen, 390, "the page's viewport is the phone's");
        assert!(
            page <= screen,
            "the {name} view is {page} px wide on a {screen} px screen"
        );
        if name == "job" {
            shot(&c, &shots, "12-phone-job").await;
        }
    }
    let errors = js(&c, "return window.__errors;").await;
    assert_eq!(
        errors,
        json!([]),
        "uncaught errors or CSP violations in the page"
    );
    c.close().await.unwrap();
}
