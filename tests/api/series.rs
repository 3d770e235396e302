//! A job's time series for ParaView (`output.frames`), through the real server on port 0: the
//! `.pvd`, every frame and the archive of the lot, with the bytes `crush run` writes; 404 for a
//! job that kept none or a frame it does not have; 422 for a series too long.

use crate::common::{tiny_case, TestApp};
use serde_json::{json, Value};
use std::io::Read;
use std::time::Duration;
use vtkio::model::{Attribute, DataSet, UnstructuredGridPiece};

fn piece(bytes: &[u8]) -> UnstructuredGridPiece {
    let vtk = vtkio::Vtk::parse_xml(bytes).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    pieces[0].load_piece_data(None).unwrap()
}

fn point_data(piece: &UnstructuredGridPiece, name: &str) -> (u32, Vec<f32>) {
    let found = piece.data.point.iter().find(|a| a.name() == name);
    let Some(Attribute::DataArray(array)) = found else {
        panic!("no point data {name}")
    };
    (
        array.elem.num_comp(),
        array.data.clone().cast_into().unwrap(),
    )
}

async fn download(app: &TestApp, path: &str) -> (String, Vec<u8>) {
    let r = app.get(path).await;
    assert_eq!(r.status(), 200, "{path}");
    let kind = r.headers()["content-type"].to_str().unwrap().to_string();
    (kind, r.bytes().await.unwrap().to_vec())
}

async fn problem(app: &TestApp, path: &str, status: u16) -> Value {
    let r = app.get(path).await;
    assert_eq!(r.status().as_u16(), status, "{path}");
    assert_eq!(r.headers()["content-type"], "application/problem+json");
    r.json().await.unwrap()
}

/// A tiny case with a series of 3 frames.
fn case_with_frames() -> Value {
    let mut case = tiny_case();
    case["output"]["frames"] = json!(3);
    case
}

#[tokio::test]
async fn a_job_with_three_frames_serves_its_pvd_each_frame_and_the_archive_as_crush_run_writes_them(
) {
    let app = TestApp::start(&[]).await;
    let case = case_with_frames();
    let id = app.submit(&case).await["id"].as_str().unwrap().to_string();
    let job = app
        .wait_for(&id, &["succeeded", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(job["status"], "succeeded", "{job}");
    let particles = job["particles"].as_u64().unwrap() as usize;

    let (kind, pvd) = download(&app, &format!("/v1/jobs/{id}/series.pvd")).await;
    assert_eq!(kind, "application/xml");
    let text = String::from_utf8(pvd.clone()).unwrap();
    let files: Vec<&str> = text
        .split("file=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect();
    assert_eq!(
        files,
        ["frames/0.vtu", "frames/1.vtu", "frames/2.vtu"],
        "{text}"
    );
    assert!(text.contains("timestep=\"0\""), "{text}");

    let (_, state) = download(&app, &format!("/v1/jobs/{id}/state.vtu")).await;
    let final_points: Vec<f32> = piece(&state).points.cast_into().unwrap();
    let mut frames = Vec::new();
    for k in 0..3 {
        let (kind, bytes) = download(&app, &format!("/v1/jobs/{id}/frames/{k}.vtu")).await;
        assert_eq!(kind, "application/xml");
        let p = piece(&bytes);
        assert_eq!(p.num_points(), particles);
        for (name, components) in [
            ("displacement_mm", 3),
            ("plastic_strain", 1),
            ("stress_mpa", 6),
            ("von_mises_mpa", 1),
            ("velocity_m_s", 3),
            ("volume_mm3", 1),
        ] {
            let (c, values) = point_data(&p, name);
            assert_eq!(
                (c, values.len()),
                (components, components as usize * particles)
            );
            assert!(values.iter().all(|v| v.is_finite()), "frame {k} {name}");
        }
        let (_, volume) = point_data(&p, "volume_mm3");
        assert!(volume.iter().all(|v| *v > 0.0), "frame {k}");
        if k == 0 {
            let (_, d) = point_data(&p, "displacement_mm");
            assert!(d.iter().all(|v| *v == 0.0), "frame 0 has moved");
            let (_, vm) = point_data(&p, "von_mises_mpa");
            assert!(vm.iter().all(|v| *v == 0.0), "frame 0 is stressed");
        }
        if k == 2 {
            let points: Vec<f32> = p.points.clone().cast_into().unwrap();
            assert_eq!(
                points, final_points,
                "the last frame is not the final state"
            );
            let (_, vm) = point_data(&p, "von_mises_mpa");
            assert!(vm.iter().any(|v| *v > 0.0), "the last frame is unstressed");
        }
        frames.push(bytes);
    }

    // The archive: the .pvd and the frames beside it, under a folder named for the job.
    let (kind, tar) = download(&app, &format!("/v1/jobs/{id}/series.tar")).await;
    assert_eq!(kind, "application/x-tar");
    let mut archive = tar::Archive::new(&tar[..]);
    let mut files = Vec::new();
    for entry in archive.entries().unwrap() {
        let mut entry = entry.unwrap();
        let path = entry.path().unwrap().display().to_string();
        let mut bytes = Vec::new();
        entry.read_to_end(&mut bytes).unwrap();
        files.push((path, bytes));
    }
    let names: Vec<&str> = files.iter().map(|(p, _)| p.as_str()).collect();
    let folder = |rest: &str| format!("{id}/{rest}");
    let expected = [
        folder(""),
        folder("series.pvd"),
        folder("frames/"),
        folder("frames/0.vtu"),
        folder("frames/1.vtu"),
        folder("frames/2.vtu"),
    ];
    assert_eq!(names, expected);
    assert_eq!(files[1].1, pvd);
    for k in 0..3 {
        assert_eq!(files[3 + k].1, frames[k], "frame {k} in the archive");
    }

    // `crush run` writes the same bytes.
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
    assert_eq!(std::fs::read(out.join("series.pvd")).unwrap(), pvd);
    for (k, bytes) in frames.iter().enumerate() {
        let written = std::fs::read(out.join(format!("frames/{k}.vtu"))).unwrap();
        assert_eq!(&written, bytes, "frame {k}");
    }
}

#[tokio::test]
async fn a_job_without_frames_has_no_series_and_a_frame_not_named_as_the_pvd_names_it_is_404() {
    let app = TestApp::start(&[]).await;
    let without = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let with = app.submit(&case_with_frames()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    for id in [&without, &with] {
        let job = app
            .wait_for(id, &["succeeded", "failed"], Duration::from_secs(60))
            .await;
        assert_eq!(job["status"], "succeeded", "{job}");
    }
    for path in ["series.pvd", "series.tar", "frames/0.vtu"] {
        let p = problem(&app, &format!("/v1/jobs/{without}/{path}"), 404).await;
        let detail = p["detail"].as_str().unwrap();
        assert!(detail.contains("output.frames"), "{path}: {detail}");
    }
    // Frame 1 by its one name only: "+1" and "01" are no frames.
    for name in [
        "3.vtu",
        "x.vtu",
        "0.vtk",
        "-1.vtu",
        "99999999999.vtu",
        "+1.vtu",
        "01.vtu",
        "%2B1.vtu",
    ] {
        let p = problem(&app, &format!("/v1/jobs/{with}/frames/{name}"), 404).await;
        let detail = p["detail"].as_str().unwrap();
        assert!(detail.contains("0.vtu to 2.vtu"), "{name}: {detail}");
    }
}

#[tokio::test]
async fn output_frames_51_and_a_series_over_ten_million_particle_states_are_422_naming_output_frames(
) {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let mut many = tiny_case();
    many["output"]["frames"] = json!(51);
    // 50 frames of 377 710 particles (n = 9 through the default tube's wall).
    let mut heavy = json!({"discretization": {"particles_through_thickness": 9},
                           "output": {"frames": 50}});
    heavy["loading"] = json!({"crush_distance_mm": 1});
    for (case, says) in [(many, "[2, 50]"), (heavy, "at most 26 frames")] {
        for route in ["/v1/jobs", "/v1/estimate"] {
            let r = app.post_json(route, &case).await;
            assert_eq!(r.status(), 422, "{route}");
            let p: Value = r.json().await.unwrap();
            let errors = p["errors"].as_array().unwrap();
            assert_eq!(errors.len(), 1, "{p}");
            assert_eq!(errors[0]["field"], "output.frames", "{p}");
            let reason = errors[0]["reason"].as_str().unwrap();
            assert!(reason.contains(says), "{reason}");
        }
    }
}
