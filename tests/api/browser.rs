//! The web page in a real browser: headless Chromium driven through ChromeDriver (fantoccini)
//! against the real server on port 0. It finds the page's icon served, types letters and a bad
//! value and sees the browser's error beside the field, types a value only the server can
//! refuse and sees the server's error beside the field (and no job stored), submits a small
//! case, reads its case as given and its time in the browser's zone, sees the progress bar move
//! and the load curve (with its mean-load line and first-peak mark) and the deformed tube
//! appear, and the chart span a 1280 px screen; then runs a resolution sweep from the form and
//! sees the overlaid curves, the table's CSV and key columns, and the convergence view; last,
//! runs whose labels differ only at the end listed whole, and a case that leaves its crush
//! distance out and names a material preset described as the server runs it. Screenshots of
//! each view are written to `target/browser-screenshots/` (or `$CRUSH_SCREENSHOTS`).
//!
//! Needs `chromium` and `chromedriver` (Debian: `apt-get install chromium chromium-driver`).
//! `build.rs` looks for them when the tests are built: without them the test is reported as
//! *ignored*, unless `CRUSH_BROWSER_TEST=required` (as CI sets), which makes it run and fail
//! when they are missing.

use crate::browser_kit::*;
use crate::common::TestApp;
use fantoccini::Locator;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[tokio::test]
#[cfg_attr(
    not(crush_browser),
    ignore = "needs chromium and chromedriver on PATH when the tests are built \
              (apt-get install chromium chromium-driver), or CRUSH_BROWSER_TEST=required"
)]
async fn the_page_submits_watches_and_shows_runs_in_a_real_browser() {
    let chromium = find_program(
        "CRUSH_CHROMIUM",
        &["chromium", "chromium-browser", "google-chrome"],
    );
    let chromedriver = find_program("CRUSH_CHROMEDRIVER", &["chromedriver"]);
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        panic!("chromium or chromedriver is missing (CRUSH_BROWSER_TEST=required or PATH changed since the build)");
    };
    let shots = std::env::var_os("CRUSH_SCREENSHOTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::common::repo_file("target/browser-screenshots"));
    std::fs::create_dir_all(&shots).unwrap();
    let app = TestApp::start(&["--concurrent-jobs", "2"]).await;
    // A zone half an hour off a whole hour from UTC: local times cannot pass for UTC ones.
    let driver = start_driver_in_zone(&chromedriver, Some(ZONE.0)).await;
    let profile = tempfile::tempdir().unwrap();
    let c = connect(&driver, &chromium, profile.path()).await;
    let long = Duration::from_secs(180);

    // The form, built from the server's field list.
    c.goto(&app.url).await.unwrap();
    until(
        &c,
        "return document.querySelector('#f-tube-thickness_mm') !== null;",
        long,
        "the form",
    )
    .await;
    let unit = js(&c, "return document.querySelector('.field[data-row=\"tube.thickness_mm\"] .unit').textContent;").await;
    assert_eq!(unit, "mm");
    shot(&c, &shots, "1-form").await;

    // The page names its icon, and the server has it (no 404 in the browser's console).
    let icon = js(
        &c,
        "const l = document.querySelector('link[rel=icon]'); return l ? new URL(l.href).pathname : null;",
    )
    .await;
    let icon = app
        .get(icon.as_str().expect("the page names an icon"))
        .await;
    assert_eq!(icon.status(), 200);
    assert_eq!(icon.headers()["content-type"], "image/svg+xml");
    assert!(icon.text().await.unwrap().starts_with("<svg"));

    // Letters in a number field: named beside it, and kept where they were typed.
    let thickness = c.find(Locator::Css("#f-tube-thickness_mm")).await.unwrap();
    thickness.clear().await.unwrap();
    thickness.send_keys("abc").await.unwrap();
    let err = until(
        &c,
        &error_beside("tube.thickness_mm"),
        long,
        "the error for letters",
    )
    .await;
    assert_eq!(err, "not a number");
    assert_eq!(
        js(
            &c,
            "return document.getElementById('f-tube-thickness_mm').value;"
        )
        .await,
        "abc"
    );

    // A bad value: the browser says why, beside the field, as it is typed.
    thickness.clear().await.unwrap();
    thickness.send_keys("-1").await.unwrap();
    let err = until(
        &c,
        &error_beside("tube.thickness_mm"),
        long,
        "the browser's error",
    )
    .await;
    assert!(err.as_str().unwrap().contains("must be > 0"), "{err}");

    // A value only the server can refuse (the wall would close the bore): its error appears
    // beside the field, and submitting stores nothing.
    thickness.clear().await.unwrap();
    thickness.send_keys("15").await.unwrap();
    let err = until(
        &c,
        &format!("const t = (function(){{{}}})(); return t && t.includes('mean_diameter_mm') ? t : null;", error_beside("tube.thickness_mm")),
        long,
        "the server's error beside the field",
    )
    .await;
    assert!(
        err.as_str().unwrap().contains("< mean_diameter_mm / 2"),
        "{err}"
    );
    click(&c, "#submit").await;
    tokio::time::sleep(Duration::from_millis(500)).await;
    let hash = js(&c, "return location.hash;").await;
    assert!(
        hash == "" || hash == "#/",
        "navigated to {hash} after a refused case"
    );
    let jobs = crate::common::get_json(&app.client, &app.at("/v1/jobs")).await;
    assert_eq!(
        jobs["jobs"].as_array().unwrap().len(),
        0,
        "a refused case was stored"
    );
    js(&c, "window.scrollTo(0, 0); return true;").await;
    shot(&c, &shots, "2-form-errors").await;

    // A preset shows its own values in the material fields, and the form sends none of them:
    // a preset picked over the PVC values shown before ran PVC.
    let pick = |preset: &str| {
        format!(
            "const s = document.getElementById('f-material-preset'); s.value = '{preset}'; \
             s.dispatchEvent(new Event('change', {{bubbles: true}})); \
             return document.getElementById('f-material-youngs_modulus_mpa').value;"
        )
    };
    assert_eq!(js(&c, &pick("mild_steel")).await, "210000");
    assert_eq!(js(&c, &pick("")).await, "3378.4");

    // A small case: submit, watch the progress bar move, see the curve and the tube.
    fill(
        &c,
        &[
            ("label", "browser: axial t3.2 n2"),
            ("tube.thickness_mm", "3.2"),
            ("tube.length_mm", "40"),
            ("loading.crush_distance_mm", "24"),
            ("loading.plate_speed_m_s", "5"),
            ("discretization.particles_through_thickness", "2"),
            ("output.history_points", "200"),
        ],
    )
    .await;
    until(
        &c,
        &format!(
            "return (function(){{{}}})() === '';",
            error_beside("tube.thickness_mm")
        ),
        long,
        "the error to clear",
    )
    .await;
    until(
        &c,
        "return document.getElementById('estimate').textContent;",
        long,
        "the estimate",
    )
    .await;
    // The planner's line beside Run: the cheapest run for ±5 %, and the section's.
    let plan = until(
        &c,
        "const t = document.getElementById('plan').textContent; return t.includes('±5 %') ? t : null;",
        long,
        "the plan",
    )
    .await;
    assert!(
        plan.as_str().unwrap().contains("axisymmetric n = "),
        "{plan}"
    );
    // Two particles through the wall: the form says, before the run, why the result will be
    // read with caution.
    let foreseen = until(
        &c,
        "return document.querySelector('#foreseen li[data-rule=\"thin_resolution\"]') ? document.getElementById('foreseen').textContent : null;",
        long,
        "the foreseen verdict",
    )
    .await;
    assert!(foreseen.as_str().unwrap().contains("caution"), "{foreseen}");
    click(&c, "#submit").await;
    until(
        &c,
        "return document.getElementById('job-progress') !== null;",
        long,
        "the job view",
    )
    .await;
    // While it runs, the case reads as it was given: the n the user set is theirs, not the
    // code's; the crush distance in mm; the material by name.
    until(
        &c,
        "return document.getElementById('case-n') !== null;",
        long,
        "the case table",
    )
    .await;
    let case = js(
        &c,
        "return ['case-n', 'crush-distance', 'material-name'].map(i => document.getElementById(i).textContent);",
    )
    .await;
    assert_eq!(case, json!(["2", "24 mm", "PVC"]));
    // The time it was submitted, in the browser's zone, not the server's UTC.
    let job_id = js(&c, "return location.hash.split('/').pop();").await;
    // The case stored is what the user set, not every default the form showed.
    let stored = app.job(job_id.as_str().unwrap()).await["case"].clone();
    assert!(stored.get("material").is_none(), "{stored}");
    assert_eq!(stored["tube"]["length_mm"].as_f64(), Some(40.0), "{stored}");
    let created = app.job(job_id.as_str().unwrap()).await["created_at"].clone();
    let shown = js(
        &c,
        "const t = document.querySelector('#job-meta time'); return [t.textContent, t.getAttribute('datetime')];",
    )
    .await;
    assert_eq!(shown[1], created);
    assert_eq!(
        shown[0],
        local_minute(created.as_str().unwrap()),
        "{created}"
    );
    let mut seen: Vec<f64> = Vec::new();
    let deadline = Instant::now() + long;
    let mut running_shot = false;
    loop {
        let v = js(&c, "const b = document.getElementById('job-progress'); const s = document.getElementById('job-status'); return [b ? b.value : 0, s ? s.textContent : ''];").await;
        let fraction = v[0].as_f64().unwrap_or(0.0);
        if seen.last() != Some(&fraction) {
            seen.push(fraction);
        }
        if !running_shot && fraction > 0.3 && fraction < 0.8 {
            shot(&c, &shots, "3-job-running").await;
            running_shot = true;
        }
        if v[1] == "succeeded" || v[1] == "failed" {
            assert_eq!(v[1], "succeeded");
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the job did not finish; progress seen {seen:?}"
        );
        tokio::time::sleep(Duration::from_millis(40)).await;
    }
    let moving: Vec<f64> = seen
        .iter()
        .copied()
        .filter(|f| *f > 0.0 && *f < 1.0)
        .collect();
    assert!(
        moving.len() >= 2 && moving[moving.len() - 1] > moving[0],
        "the progress bar did not move forward: {seen:?}"
    );
    // The curve holds the whole history; the tube picture has loaded; the summary is there.
    let points = until(&c, "const p = Number(document.getElementById('curve').dataset.points); return p >= 200 ? p : 0;", long, "the full curve").await;
    assert!(points.as_f64().unwrap() >= 200.0);
    // The energy curve beside it: the plates' work and what the wall dissipated, every row.
    until(&c, "const p = Number((document.getElementById('energy-curve') || {dataset: {}}).dataset.points); return p >= 200 ? p : 0;", long, "the energy curve").await;
    assert_eq!(
        js(
            &c,
            "return document.querySelectorAll('#curve canvas').length > 0;"
        )
        .await,
        true
    );
    until(
        &c,
        "const i = document.getElementById('shape'); return i && i.complete && i.naturalWidth > 0;",
        long,
        "the deformed-tube picture",
    )
    .await;
    let summary = js(&c, "return document.getElementById('summary').textContent;").await;
    assert!(summary.as_str().unwrap().contains("kN"), "{summary}");
    // The expected error beside the numbers: the paper's tube at n = 2 reads its study.
    let expected = js(
        &c,
        "return document.getElementById('expected-error').textContent;",
    )
    .await;
    assert!(
        expected
            .as_str()
            .unwrap()
            .starts_with("±22.9 % (expected, not priced"),
        "{expected}"
    );
    // The verdict beside the numbers: a badge of the job's level and its thin-wall reason.
    let job_id = js(&c, "return location.hash.split('/').pop();").await;
    let served = crate::common::get_json(
        &app.client,
        &app.at(&format!("/v1/jobs/{}", job_id.as_str().unwrap())),
    )
    .await;
    let level = js(
        &c,
        "return document.querySelector('#verdict .badge').dataset.level;",
    )
    .await;
    assert_eq!(level, served["verdict"]["level"]);
    assert_eq!(
        js(
            &c,
            "return document.querySelector('#verdict li[data-rule=\"thin_resolution\"]') !== null;"
        )
        .await,
        true
    );
    let refs = js(
        &c,
        "return document.getElementById('references').textContent;",
    )
    .await;
    assert!(refs.as_str().unwrap().contains("Alexander"), "{refs}");
    // The finished curve carries the mean load as a line and the first collapse peak as a
    // mark, each named in the legend with the summary's value; the legend lies under the plot,
    // clear of every curve's end.
    let summary = &served["summary"];
    let kn = |n: &Value| format!("{:.2} kN", n.as_f64().unwrap() / 1000.0);
    let legend = until(
        &c,
        "const c = document.getElementById('curve'); return c.dataset.series === '4' ? [...c.querySelectorAll('.u-legend .u-series')].map(s => s.textContent) : null;",
        long,
        "the mean-load line and the first-peak mark",
    )
    .await;
    let legend: Vec<&str> = legend
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert!(
        legend.contains(&format!("mean load {}", kn(&summary["mean_load_n"])).as_str()),
        "{legend:?}"
    );
    assert!(
        legend.iter().any(|s| s.starts_with(&format!(
            "first peak {} at ",
            kn(&summary["first_peak_load_n"])
        ))),
        "{legend:?}"
    );
    let clear = js(
        &c,
        "const plot = document.querySelector('#curve .u-over').getBoundingClientRect();          const legend = document.querySelector('#curve .u-legend').getBoundingClientRect();          return legend.top >= plot.bottom;",
    )
    .await;
    assert_eq!(clear, true, "the legend overlaps the plot");
    // Every download link answers with a file.
    let downloads = js(
        &c,
        "const links = [...document.querySelectorAll('.downloads a')]; \
         window.__downloads = null; \
         Promise.all(links.map(a => fetch(a.href).then(r => r.status + ' ' + a.textContent))) \
           .then(s => { window.__downloads = s; }); return links.length;",
    )
    .await;
    assert_eq!(downloads.as_u64(), Some(5));
    let statuses = until(&c, "return window.__downloads;", long, "the downloads").await;
    for s in statuses.as_array().unwrap() {
        assert!(s.as_str().unwrap().starts_with("200 "), "{s}");
    }
    // The deformed tube's picture among them, as the PNG it is.
    let png = js(
        &c,
        "return new URL(document.getElementById('shape-png').href).pathname;",
    )
    .await;
    let png = app.get(png.as_str().unwrap()).await;
    assert_eq!(png.status(), 200);
    assert_eq!(png.headers()["content-type"], "image/png");
    let list = js(
        &c,
        "return document.querySelector('#job-list tbody').textContent;",
    )
    .await;
    assert!(
        list.as_str().unwrap().contains("browser: axial t3.2 n2"),
        "{list}"
    );
    c.set_window_size(1500, 2300).await.unwrap();
    shot(&c, &shots, "4-job-done").await;
    // On a 1280 px screen the chart spans the view's width, the tables below it, not beside.
    c.set_window_size(1280, 1400).await.unwrap();
    c.refresh().await.unwrap();
    until(&c, "const c = document.getElementById('curve'); return c && c.dataset.series === '4' && document.getElementById('summary');", long, "the job again").await;
    let (chart, screen, side_below) = {
        let v = js(
            &c,
            "const c = document.querySelector('#curve .uplot').getBoundingClientRect();              const side = document.getElementById('job-side').getBoundingClientRect();              return [c.width, window.innerWidth, side.top >= c.bottom];",
        )
        .await;
        (v[0].as_f64().unwrap(), v[1].as_f64().unwrap(), v[2].clone())
    };
    assert_eq!(screen, 1280.0);
    assert!(
        chart >= 0.6 * screen,
        "the chart is {chart} px wide on a {screen} px screen"
    );
    assert_eq!(side_below, true, "the tables sit beside the chart");
    shot(&c, &shots, "4b-job-1280").await;
    // A narrower window, not reloaded: the chart follows its box and the page does not scroll
    // sideways.
    c.set_window_size(700, 1400).await.unwrap();
    until(
        &c,
        "const c = document.querySelector('#curve .uplot').getBoundingClientRect();          return c.width < 700 && document.documentElement.scrollWidth <= window.innerWidth;",
        long,
        "the chart narrowed with the window",
    )
    .await;
    c.set_window_size(1500, 1400).await.unwrap();

    let errors = js(&c, "return window.__errors;").await;
    assert_eq!(errors, json!([]), "uncaught errors in the page");

    // "New case from this one" opens the form filled with this job's case.
    click(&c, "#reuse").await;
    until(
        &c,
        "const i = document.querySelector('#f-tube-length_mm'); return i && i.value === '40';",
        long,
        "the form filled from the job",
    )
    .await;
    let label = js(&c, "return document.querySelector('#f-label').value;").await;
    assert_eq!(label, "browser: axial t3.2 n2");

    // A resolution sweep from the form: overlaid curves, the table, and the convergence view.
    c.goto(&format!("{}/#/", app.url)).await.unwrap();
    until(
        &c,
        "return document.querySelector('#f-tube-thickness_mm') !== null;",
        long,
        "the form again",
    )
    .await;
    fill(
        &c,
        &[
            ("label", "browser: resolution sweep"),
            ("tube.length_mm", "12"),
            ("loading.crush_distance_mm", "4"),
            ("loading.plate_speed_m_s", "20"),
            ("output.history_points", "40"),
        ],
    )
    .await;
    js(&c, "document.getElementById('sweep-field').value = 'discretization.particles_through_thickness'; document.getElementById('sweep-values').value = '1, 2, 3'; return true;").await;
    click(&c, "#submit").await;
    until(
        &c,
        "return location.hash.startsWith('#/sweeps/');",
        long,
        "the sweep view",
    )
    .await;
    until(&c, "const t = document.getElementById('sweep-counts'); return t && t.textContent === '3 succeeded';", long, "the sweep to finish").await;
    until(&c, "const c = document.getElementById('sweep-curves'); return c && Number(c.dataset.points) > 0;", long, "the overlaid curves").await;
    until(&c, "const c = document.getElementById('sweep-curves'); return c.dataset.series === '3' && document.querySelectorAll('#sweep-curves .u-legend .u-series').length >= 3;", long, "three curves").await;
    let rows = js(
        &c,
        "return document.querySelectorAll('#sweep-table tbody tr').length;",
    )
    .await;
    assert_eq!(rows.as_u64(), Some(3));
    // The table as CSV, from the button beside it: the server's, a header and a row per run.
    let csv = js(
        &c,
        "const a = document.getElementById('sweep-csv'); const u = new URL(a.href); return u.pathname + u.search;",
    )
    .await;
    let csv = app.get(csv.as_str().unwrap()).await;
    assert_eq!(csv.status(), 200);
    assert!(csv.headers()["content-type"]
        .to_str()
        .unwrap()
        .starts_with("text/csv"));
    let csv = csv.text().await.unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    // On a 1280 px screen the first peak, CFE and SEA show without scrolling sideways.
    c.set_window_size(1280, 1400).await.unwrap();
    let seen = until(
        &c,
        "const box = document.querySelector('#sweep-table .scroll');          if (!box || document.querySelectorAll('#sweep-table tbody tr').length !== 3) return null;          const edge = box.getBoundingClientRect().right;          return ['first_peak_load_n', 'crush_force_efficiency', 'specific_energy_absorption_j_per_g'].map(c => {            const h = box.querySelector(`th[data-column=\"${c}\"]`);            return h ? [h.textContent, h.getBoundingClientRect().right <= edge + 0.5 && box.scrollLeft === 0] : [c, false]; });",
        long,
        "the sweep table at 1280 px",
    )
    .await;
    assert_eq!(
        seen,
        json!([["first peak, kN", true], ["CFE", true], ["SEA, J/g", true]])
    );
    c.set_window_size(1500, 1800).await.unwrap();
    shot(&c, &shots, "5-sweep").await;
    until(&c, "const c = document.getElementById('convergence-chart'); return c && Number(c.dataset.points) > 0;", long, "the convergence chart").await;
    js(
        &c,
        "document.getElementById('convergence').scrollIntoView(); return true;",
    )
    .await;
    shot(&c, &shots, "6-convergence").await;
    // The page threw nothing along the way (on this page load: the sweep's).
    let errors = js(&c, "return window.__errors;").await;
    assert_eq!(errors, json!([]), "uncaught errors in the page");

    // Three runs whose labels differ only near their end: the list shows each label whole.
    let prefix = "browser: tiny PVC t 3.2 d 22.2 l 8, axial 20 m/s, n 1, friction";
    for friction in ["0.1", "0.2", "0.3"] {
        let mut case = crate::common::tiny_case();
        case["label"] = json!(format!("{prefix} {friction}"));
        case["contact"] = json!({"friction": friction.parse::<f64>().unwrap()});
        app.submit(&case).await;
    }
    c.set_window_size(1280, 1400).await.unwrap();
    c.goto(&format!("{}/#/", app.url)).await.unwrap();
    let labels = until(
        &c,
        &format!(
            "const cells = [...document.querySelectorAll('#job-list td.name')].filter(t => t.textContent.startsWith({prefix:?}));              if (cells.length !== 3) return null;              return cells.map(t => [t.textContent, t.scrollWidth <= t.clientWidth && t.scrollHeight <= t.clientHeight]);"
        ),
        long,
        "the three runs in the list",
    )
    .await;
    let mut shown: Vec<String> = Vec::new();
    for cell in labels.as_array().unwrap() {
        assert_eq!(cell[1], true, "the label is cut: {cell}");
        shown.push(cell[0].as_str().unwrap().to_string());
    }
    shown.sort();
    assert_eq!(
        shown,
        ["0.1", "0.2", "0.3"].map(|f| format!("{prefix} {f}")),
        "{labels}"
    );
    let wide = js(
        &c,
        "const s = document.querySelector('#jobs-pane .scroll'); return s.scrollWidth <= s.clientWidth;",
    )
    .await;
    assert_eq!(wide, true, "the job list scrolls sideways");
    shot(&c, &shots, "6b-list-1280").await;

    // A case that leaves the crush distance to the server and names a material preset: the job
    // says the distance in mm, the preset by name and the preset's values. (It is cancelled
    // once read: only its page is wanted.)
    let case = json!({
        "label": "browser: mild steel, default distance",
        "tube": {"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 76.2},
        "material": {"preset": "mild_steel"},
        "loading": {"mode": "axial", "plate_speed_m_s": 10.0},
        "discretization": {"particles_through_thickness": 6, "model": "axisymmetric"},
    });
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    c.goto(&format!("{}/#/jobs/{id}", app.url)).await.unwrap();
    let table = until(
        &c,
        "const t = document.getElementById('case-table'); return t ? t.textContent : null;",
        long,
        "the preset job's case",
    )
    .await;
    let case = js(
        &c,
        "return ['case-n', 'crush-distance', 'material-name'].map(i => document.getElementById(i).textContent);",
    )
    .await;
    assert_eq!(case, json!(["6", "50 mm (default)", "mild steel (preset)"]));
    assert!(table.as_str().unwrap().contains("E 210000 MPa"), "{table}");
    app.post(&format!("/v1/jobs/{id}/cancel")).await;
    let errors = js(&c, "return window.__errors;").await;
    assert_eq!(errors, json!([]), "uncaught errors in the page");
    c.close().await.unwrap();
}

/// The browser's time zone in the first test, and its offset as the page writes it.
const ZONE: (&str, &str, i64) = ("Asia/Kolkata", "UTC+5:30", 330);

/// A server timestamp as the page shows it in [`ZONE`]: "2026-11-29 01:08 UTC+5:30".
fn local_minute(iso: &str) -> String {
    let utc =
        time::OffsetDateTime::parse(iso, &time::format_description::well_known::Rfc3339).unwrap();
    let t = utc + time::Duration::minutes(ZONE.2);
    format!(
        "{:04}-{:02}-{:02} {:02}:{:02} {}",
        t.year(),
        u8::from(t.month()),
        t.day(),
        t.hour(),
        t.minute(),
        ZONE.1
    )
}

/// A server with tokens: the page asks for one once, keeps it in a cookie no script can read
/// (so event streams, pictures and download links carry it), shows who is signed in, and
/// forgets it on request; the content security policy blocks nothing the page uses.
#[tokio::test]
#[cfg_attr(
    not(crush_browser),
    ignore = "needs chromium and chromedriver on PATH when the tests are built \
              (apt-get install chromium chromium-driver), or CRUSH_BROWSER_TEST=required"
)]
async fn the_page_asks_for_a_token_once_and_keeps_it_in_a_cookie() {
    let chromium = find_program(
        "CRUSH_CHROMIUM",
        &["chromium", "chromium-browser", "google-chrome"],
    );
    let chromedriver = find_program("CRUSH_CHROMEDRIVER", &["chromedriver"]);
    let (Some(chromium), Some(chromedriver)) = (chromium, chromedriver) else {
        panic!("chromium or chromedriver is missing (CRUSH_BROWSER_TEST=required or PATH changed since the build)");
    };
    let token = "lab-token-0123456789abcdef";
    let files = tempfile::tempdir().unwrap();
    let token_file = files.path().join("tokens");
    std::fs::write(&token_file, format!("lab submit {token}\n")).unwrap();
    let app = TestApp::start(&[
        "--concurrent-jobs",
        "1",
        "--token-file",
        token_file.to_str().unwrap(),
    ])
    .await;
    let job = app
        .client
        .post(app.at("/v1/jobs"))
        .bearer_auth(token)
        .json(&crate::common::tiny_case())
        .send()
        .await
        .unwrap();
    assert_eq!(job.status(), 202);
    let id = job.json::<Value>().await.unwrap()["id"]
        .as_str()
        .unwrap()
        .to_string();
    let driver = start_driver(&chromedriver).await;
    let profile = tempfile::tempdir().unwrap();
    let c = connect(&driver, &chromium, profile.path()).await;
    let long = Duration::from_secs(120);

    c.goto(&format!("{}/#/jobs/{id}", app.url)).await.unwrap();
    until(
        &c,
        "return !document.getElementById('signin').hidden;",
        long,
        "the sign-in bar",
    )
    .await;
    let bars = js(&c, "return document.querySelectorAll('#signin').length;").await;
    assert_eq!(bars.as_u64(), Some(1));
    let shots = std::env::var_os("CRUSH_SCREENSHOTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate::common::repo_file("target/browser-screenshots"));
    std::fs::create_dir_all(&shots).unwrap();
    shot(&c, &shots, "7-token").await;
    // A wrong token is refused where it was typed.
    let input = c.find(Locator::Css("#token-input")).await.unwrap();
    input.send_keys("not-a-token-of-this-server").await.unwrap();
    click(&c, "#signin button").await;
    let refused = until(
        &c,
        "return document.getElementById('signin-error').textContent;",
        long,
        "the refusal",
    )
    .await;
    assert!(
        refused.as_str().unwrap().contains("not a token"),
        "{refused}"
    );
    input.clear().await.unwrap();
    input.send_keys(token).await.unwrap();
    click(&c, "#signin button").await;
    // The page reloads signed in: the job's stream, its picture and its downloads all work.
    until(
        &c,
        "const s = document.getElementById('session'); return s && s.textContent.includes('lab (submit)');",
        long,
        "who is signed in",
    )
    .await;
    until(
        &c,
        "const b = document.getElementById('job-status'); return b && b.textContent === 'succeeded';",
        long,
        "the job to succeed",
    )
    .await;
    until(
        &c,
        "const i = document.getElementById('shape'); return i && i.complete && i.naturalWidth > 0;",
        long,
        "the deformed-tube picture",
    )
    .await;
    js(
        &c,
        "window.__downloads = null; \
         Promise.all([...document.querySelectorAll('.downloads a')].map(a => fetch(a.href).then(r => r.status))) \
           .then(s => { window.__downloads = s; }); return true;",
    )
    .await;
    let statuses = until(&c, "return window.__downloads;", long, "the downloads").await;
    assert_eq!(statuses, json!([200, 200, 200, 200, 200]));
    let hidden = js(&c, "return document.getElementById('signin').hidden;").await;
    assert_eq!(hidden, true);
    // No script can read the token back.
    let cookies = js(&c, "return document.cookie;").await;
    assert_eq!(cookies, "");
    let errors = js(&c, "return window.__errors;").await;
    assert_eq!(
        errors,
        json!([]),
        "uncaught errors or CSP violations in the page"
    );

    // Forgetting the token brings the sign-in bar back.
    click(&c, "#forget-token").await;
    until(
        &c,
        "const f = document.getElementById('signin'); return f && !f.hidden && !document.getElementById('forget-token');",
        long,
        "the sign-in bar after forgetting",
    )
    .await;
    c.close().await.unwrap();
}
