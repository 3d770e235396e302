//! What a succeeded job leaves, through the real server on port 0: the summary, the deformed
//! tube as PNG, the final state as VTU, and a case that keeps no state; and the web page's own
//! routes (the page, its assets, the form's fields).

use crate::common::{get_json, tiny_case, TestApp};
use serde_json::Value;
use std::time::Duration;

#[tokio::test]
async fn a_succeeded_job_gives_its_summary_picture_and_vtu() {
    let app = TestApp::start(&[]).await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    let particles = job["particles"].as_u64().unwrap() as usize;

    let summary = get_json(&app.client, &app.at(&format!("/v1/jobs/{id}/summary"))).await;
    assert_eq!(summary, job["summary"]);
    // One particle through an 8 mm tube's wall crushed 1 mm at 20 m/s: the job says not to
    // trust it, and why; its summary carries the same verdict.
    assert_eq!(job["verdict"], summary["verdict"]);
    assert_eq!(job["verdict"]["level"], "not_trusted", "{job}");
    let rules: Vec<&str> = job["verdict"]["reasons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["rule"].as_str().unwrap())
        .collect();
    assert!(rules.contains(&"thin_resolution"), "{rules:?}");
    assert!(rules.contains(&"too_short_to_fold"), "{rules:?}");

    let r = app.get(&format!("/v1/jobs/{id}/shape.png")).await;
    assert_eq!(r.status(), 200);
    assert_eq!(r.headers()["content-type"], "image/png");
    let png = r.bytes().await.unwrap();
    let img = image::load_from_memory(&png).unwrap().to_rgb8();
    let (w, h) = img.dimensions();
    assert!(w >= 800 && h >= 300, "{w}×{h}");
    let drawn = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    assert!(drawn > 1000, "only {drawn} pixels drawn");

    let r = app.get(&format!("/v1/jobs/{id}/state.vtu")).await;
    assert_eq!(r.status(), 200);
    assert!(r.headers()["content-disposition"]
        .to_str()
        .unwrap()
        .contains(".vtu"));
    let bytes = r.bytes().await.unwrap();
    let vtk = vtkio::Vtk::parse_xml(&bytes[..]).unwrap();
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let piece = pieces[0].load_piece_data(None).unwrap();
    assert_eq!(piece.num_points(), particles);
    let strain = piece
        .data
        .point
        .iter()
        .find(|a| a.name() == "plastic_strain")
        .expect("plastic_strain point data");
    let vtkio::model::Attribute::DataArray(array) = strain else {
        panic!("plastic_strain is not a data array")
    };
    let e: Vec<f32> = array.data.clone().cast_into().unwrap();
    assert_eq!(e.len(), particles);
    assert!(e.iter().all(|v| v.is_finite() && *v >= 0.0));
    // The top plate moved 1 mm: the highest particle ends about that much lower.
    let Some(points) = piece.points.cast_into::<f32>() else {
        panic!("points are not f32")
    };
    let top = points.chunks(3).map(|p| p[2]).fold(f32::MIN, f32::max);
    assert!(
        top < 8.0 - 0.5,
        "top of the tube at {top} mm after a 1 mm crush"
    );
}

/// A reduced model runs through the service like 3D: summary (mode ring), picture, and a VTU
/// that holds the section's particles with a note of the symmetry.
#[tokio::test]
async fn an_axisymmetric_job_gives_the_section_with_its_symmetry_named() {
    let app = TestApp::start(&[]).await;
    let mut case = tiny_case();
    case["discretization"]["model"] = "axisymmetric".into();
    case["trigger"] = serde_json::json!({"weak_fraction": 0});
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    assert_eq!(job["summary"]["mode"]["kind"], "ring", "{job}");
    // The summary names the shape functions that ran; this case names none, so the reason
    // for the section's default comes with it.
    let shape = &job["summary"]["shape"];
    assert_eq!(shape["kind"], "gimp", "{job}");
    assert!(
        shape["default_reason"]
            .as_str()
            .unwrap()
            .contains("reduced models"),
        "{job}"
    );
    let r = app.get(&format!("/v1/jobs/{id}/shape.png")).await;
    assert_eq!(r.status(), 200);
    let r = app.get(&format!("/v1/jobs/{id}/state.vtu")).await;
    assert_eq!(r.status(), 200);
    let text = String::from_utf8(r.bytes().await.unwrap().to_vec()).unwrap();
    assert!(text.contains("<!-- axisymmetric model"), "{}", &text[..300]);
    let vtk = vtkio::Vtk::parse_xml(text.as_bytes()).unwrap();
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let piece = pieces[0].load_piece_data(None).unwrap();
    assert_eq!(
        piece.num_points(),
        job["particles"].as_u64().unwrap() as usize
    );
}

#[tokio::test]
async fn a_case_that_keeps_no_state_has_numbers_but_no_picture() {
    let app = TestApp::start(&[]).await;
    let mut case = tiny_case();
    case["output"]["final_state"] = Value::Bool(false);
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    for path in ["shape.png", "state.vtu"] {
        let r = app.get(&format!("/v1/jobs/{id}/{path}")).await;
        assert_eq!(r.status(), 404, "{path}");
        let problem: Value = r.json().await.unwrap();
        assert!(
            problem["detail"]
                .as_str()
                .unwrap()
                .contains("output.final_state"),
            "{problem}"
        );
    }
    assert_eq!(
        app.get(&format!("/v1/jobs/{id}/history")).await.status(),
        200
    );
}

#[tokio::test]
async fn unfinished_and_unknown_jobs_have_no_results() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    for path in ["summary", "shape.png", "state.vtu"] {
        assert_eq!(
            app.get(&format!("/v1/jobs/{id}/{path}")).await.status(),
            409
        );
        let unknown = format!("/v1/jobs/00000000-0000-4000-8000-000000000000/{path}");
        assert_eq!(app.get(&unknown).await.status(), 404);
    }
}

#[tokio::test]
async fn the_page_and_its_assets_are_served_from_the_binary() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let page = app.get("/").await;
    assert_eq!(page.status(), 200);
    assert!(page.headers()["content-type"]
        .to_str()
        .unwrap()
        .starts_with("text/html"));
    let html = page.text().await.unwrap();
    // Every script and stylesheet the page names is served here: nothing from elsewhere.
    let mut named = 0;
    for attr in ["src=\"", "href=\""] {
        for part in html.split(attr).skip(1) {
            let target = &part[..part.find('"').unwrap()];
            if target.starts_with('#') {
                continue;
            }
            assert!(target.starts_with("/assets/"), "{target} is not ours");
            let r = app.get(target).await;
            assert_eq!(r.status(), 200, "{target}");
            assert!(!r.bytes().await.unwrap().is_empty());
            named += 1;
        }
    }
    assert!(named >= 4, "{named} assets named");
    // app.js imports the page's other modules: each is served, and none reaches elsewhere.
    let app_js = app.get("/assets/app.js").await.text().await.unwrap();
    let modules: Vec<String> = app_js
        .split("from \"./")
        .skip(1)
        .map(|rest| rest[..rest.find('"').unwrap()].to_string())
        .collect();
    assert!(modules.len() >= 4, "{modules:?}");
    for name in std::iter::once("app.js".to_string()).chain(modules) {
        let r = app.get(&format!("/assets/{name}")).await;
        assert_eq!(r.status(), 200, "{name}");
        // The SVG namespace names a vocabulary, not a place: the overlay's SVG download
        // declares it, and nothing is fetched from it.
        let js = r
            .text()
            .await
            .unwrap()
            .replace("http://www.w3.org/2000/svg", "");
        assert!(
            !js.contains("http://") && !js.contains("https://"),
            "{name}"
        );
        for import in js.split("from \"").skip(1) {
            assert!(import.starts_with("./"), "{name} imports {import:.40}");
        }
    }
    assert_eq!(app.get("/assets/nothing.js").await.status(), 404);

    let fields = get_json(&app.client, &app.at("/v1/case/fields")).await;
    let thickness = fields
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["field"] == "tube.thickness_mm")
        .unwrap();
    assert_eq!(thickness["unit"], "mm");
    assert_eq!(thickness["default"], 3.2);
    assert_eq!(thickness["min"], 0.0);
    assert_eq!(thickness["min_exclusive"], true);
}

/// `crush run` and the server export a run alike: the same case run by the CLI and by the
/// server gives the same history and VTU bytes, and the server's particle table holds the CLI's
/// rows (its final positions as stored, in f32).
#[tokio::test]
async fn the_server_gives_the_files_crush_run_writes() {
    let app = TestApp::start(&[]).await;
    let case = tiny_case();
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("case.json");
    std::fs::write(&file, case.to_string()).unwrap();
    let out = dir.path().join("out");
    let ran = std::process::Command::new(env!("CARGO_BIN_EXE_crush"))
        .args(["run", file.to_str().unwrap(), "--threads", "1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        ran.status.success(),
        "{}",
        String::from_utf8_lossy(&ran.stderr)
    );
    for name in [
        "history.csv",
        "load.svg",
        "summary.json",
        "particles.csv",
        "state.vtu",
        "shape.png",
    ] {
        assert!(out.join(name).is_file(), "crush run wrote no {name}");
    }

    let download = |path: String| {
        let (client, url) = (app.client.clone(), app.at(&path));
        async move {
            let r = client.get(url).send().await.unwrap();
            assert_eq!(r.status(), 200, "{path}");
            r.bytes().await.unwrap().to_vec()
        }
    };
    let history = download(format!("/v1/jobs/{id}/history?format=csv")).await;
    assert_eq!(history, std::fs::read(out.join("history.csv")).unwrap());
    let vtu = download(format!("/v1/jobs/{id}/state.vtu")).await;
    assert_eq!(vtu, std::fs::read(out.join("state.vtu")).unwrap());

    let served = download(format!("/v1/jobs/{id}/particles.csv")).await;
    let rows = |bytes: &[u8]| -> Vec<Vec<f64>> {
        let mut r = csv::Reader::from_reader(bytes);
        assert_eq!(
            r.headers().unwrap().iter().collect::<Vec<_>>(),
            [
                "x0_mm",
                "y0_mm",
                "z0_mm",
                "x_mm",
                "y_mm",
                "z_mm",
                "plastic_strain"
            ]
        );
        r.records()
            .map(|rec| rec.unwrap().iter().map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let (served, written) = (
        rows(&served),
        rows(&std::fs::read(out.join("particles.csv")).unwrap()),
    );
    assert_eq!(served.len(), job["particles"].as_u64().unwrap() as usize);
    assert_eq!(served.len(), written.len());
    for (s, w) in served.iter().zip(&written) {
        assert_eq!(s[..3], w[..3], "start positions");
        for k in 3..7 {
            assert_eq!(s[k], f64::from(w[k] as f32), "column {k}");
        }
    }
}

/// A succeeded job whose case a check added later refuses (here a crush shorter than the grid
/// resolves) still gives its picture and its files: a download reads the stored case's geometry
/// without checking the case again.
#[tokio::test]
async fn a_succeeded_job_whose_case_a_later_check_refuses_still_gives_its_files() {
    let app = TestApp::start(&[]).await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    let mut refused = tiny_case();
    refused["loading"]["crush_distance_mm"] = 1e-3.into();
    assert_eq!(app.post_json("/v1/jobs", &refused).await.status(), 422);
    sqlx::any::install_default_drivers();
    let pool = sqlx::AnyPool::connect(&app.db).await.unwrap();
    sqlx::query("UPDATE jobs SET case_json = $1 WHERE id = $2")
        .bind(refused.to_string())
        .bind(&id)
        .execute(&pool)
        .await
        .unwrap();
    pool.close().await;
    for path in [
        "shape.png",
        "state.vtu",
        "particles.csv",
        "history",
        "plot.svg",
    ] {
        let r = app.get(&format!("/v1/jobs/{id}/{path}")).await;
        assert_eq!(r.status(), 200, "{path}");
    }
}
