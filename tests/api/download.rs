//! Large downloads through the real server: the final state of a job with 266 000 particles
//! downloaded as `state.vtu` by 20 clients at once, and its time series as frames and archives,
//! by a separate process. The files are streamed and built by at most a few requests at a
//! time, so the server's peak memory stays bounded. Two slow readers that hold both download
//! slots neither delay a history nor keep a third download waiting.

use crate::common::*;
use crate::timeouts::{large_state, request};
use futures::StreamExt;
use serde_json::json;
use std::time::{Duration, Instant};
use tokio::io::AsyncReadExt;

/// Peak resident memory of a process so far, bytes (`VmHWM`).
fn peak_rss(pid: i32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap();
    kb * 1024
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn twenty_concurrent_state_vtu_downloads_stay_under_a_memory_bound() {
    if !std::path::Path::new("/proc/self/status").exists() {
        eprintln!("SKIPPED: no /proc to read the server's peak memory from");
        return;
    }
    let (_dir, db) = temp_db();
    let client = client();
    // 266 254 particles, 16 steps: about a second of solver time.
    let case = json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 8},
        "loading": {"crush_distance_mm": 0.05, "plate_speed_m_s": 20},
        "output": {"history_points": 10}
    });
    let id = {
        let runner = Child::start(&db, &[]);
        let id = submit_to(&client, &runner.url, &case).await;
        let job = wait_for(
            &client,
            &runner.url,
            &id,
            &["succeeded", "failed"],
            Duration::from_secs(120),
        )
        .await;
        assert_eq!(job["status"], "succeeded", "{job}");
        id
    };
    // A fresh server that runs nothing: its peak memory is the downloads'.
    let server = Child::start(&db, &["--concurrent-jobs", "0"]);
    let particles = 266_254u64;
    let url = format!("{}/v1/jobs/{id}/state.vtu", server.url);
    let before = peak_rss(server.pid());
    let downloads = (0..20).map(|_| {
        let (client, url) = (client.clone(), url.clone());
        async move {
            let r = client.get(&url).send().await.unwrap();
            assert_eq!(r.status(), 200);
            let mut body = r.bytes_stream();
            let (mut bytes, mut first) = (0usize, Vec::new());
            while let Some(chunk) = body.next().await {
                let chunk = chunk.unwrap();
                bytes += chunk.len();
                // Keep one whole copy to parse; count the rest.
                if first.len() < 64 << 20 {
                    first.extend_from_slice(&chunk);
                }
            }
            (bytes, first)
        }
    });
    let results = futures::future::join_all(downloads).await;
    let peak = peak_rss(server.pid());
    let size = results[0].0;
    assert!(
        results.iter().all(|(n, _)| *n == size),
        "every download is whole and the same"
    );
    let vtk = vtkio::Vtk::parse_xml(&results[0].1[..]).unwrap();
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("not an unstructured grid")
    };
    let piece = pieces[0].load_piece_data(None).unwrap();
    assert_eq!(piece.num_points() as u64, particles);
    // Bound: at most HEAVY_AT_ONCE downloads are written at once, each holding the stored
    // state twice (blob, then decoded: 16 B a particle each) and the start positions (24 B a
    // particle), plus a few 256 KB chunks per client, plus 96 MB for the runtime, sockets and
    // what the allocator keeps of freed buffers (measured: 92 MB growth with 2 at once; 147 MB
    // with 4; 318 MB when each download rebuilt the whole particle set). Building the 20
    // documents whole (as before) needs at least 20 × the file size, 304 MB here.
    let at_once = crush::service::HEAVY_AT_ONCE as u64;
    let bound = at_once * 56 * particles + 96 * 1024 * 1024;
    let grown = peak.saturating_sub(before);
    eprintln!(
        "20 downloads of {size} bytes: peak RSS {} MB (before {} MB), grew {} MB, bound {} MB; \
         whole documents would need at least {} MB",
        peak >> 20,
        before >> 20,
        grown >> 20,
        bound >> 20,
        (20 * size as u64) >> 20
    );
    assert!(
        grown < bound,
        "peak RSS grew {grown} bytes, over the bound {bound}"
    );
}

/// Ten clients download the last frame of a 266 254-particle series and ten the archive of its
/// two frames, at once: each frame is read from the store and written one at a time, by at most
/// `HEAVY_AT_ONCE` requests, so the server's memory grows by a few frames, not by the files.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn twenty_concurrent_frame_and_series_tar_downloads_stay_under_a_memory_bound() {
    if !std::path::Path::new("/proc/self/status").exists() {
        eprintln!("SKIPPED: no /proc to read the server's peak memory from");
        return;
    }
    let (_dir, db) = temp_db();
    let client = client();
    let case = json!({
        "tube": {"length_mm": 76.2},
        "discretization": {"particles_through_thickness": 8},
        "loading": {"crush_distance_mm": 0.05, "plate_speed_m_s": 20},
        "output": {"history_points": 10, "frames": 2}
    });
    let id = {
        let runner = Child::start(&db, &[]);
        let id = submit_to(&client, &runner.url, &case).await;
        let job = wait_for(
            &client,
            &runner.url,
            &id,
            &["succeeded", "failed"],
            Duration::from_secs(120),
        )
        .await;
        assert_eq!(job["status"], "succeeded", "{job}");
        id
    };
    let server = Child::start(&db, &["--concurrent-jobs", "0"]);
    let particles = 266_254u64;
    let before = peak_rss(server.pid());
    let downloads = (0..20).map(|i| {
        let path = if i % 2 == 0 {
            "frames/1.vtu"
        } else {
            "series.tar"
        };
        let (client, url) = (
            client.clone(),
            format!("{}/v1/jobs/{id}/{path}", server.url),
        );
        async move {
            let r = client.get(&url).send().await.unwrap();
            assert_eq!(r.status(), 200, "{url}");
            let mut body = r.bytes_stream();
            let mut bytes = 0usize;
            while let Some(chunk) = body.next().await {
                bytes += chunk.unwrap().len();
            }
            (path, bytes)
        }
    });
    let results = futures::future::join_all(downloads).await;
    let peak = peak_rss(server.pid());
    let size = |which: &str| {
        let sizes: Vec<usize> = results
            .iter()
            .filter(|(p, _)| *p == which)
            .map(|(_, n)| *n)
            .collect();
        assert!(sizes.iter().all(|n| *n == sizes[0]), "{which}: {sizes:?}");
        sizes[0]
    };
    let (frame, tar) = (size("frames/1.vtu"), size("series.tar"));
    // Two frames of one file size, the .pvd and the tar's headers and padding.
    assert!(
        tar > 2 * frame && tar < 2 * frame + 64 * 1024,
        "{tar} vs {frame}"
    );
    // Bound: at most HEAVY_AT_ONCE downloads written at once, each holding one frame decoded
    // (56 B a particle), the start positions (24 B a particle) and one stored part of the frame
    // in the store's copies (three of 3.5 MB at most), plus the 96 MB that the state.vtu test
    // allows for the runtime, sockets and freed buffers the allocator keeps (measured: 109 to
    // 126 MB of growth; 216 to 257 MB when each frame was read as one blob). Whole files would need at
    // least 10 × (frame + archive).
    let at_once = crush::service::HEAVY_AT_ONCE as u64;
    let part = (crush::service::store::PART_PARTICLES * 56) as u64;
    let bound = at_once * ((56 + 24) * particles + 3 * part) + 96 * 1024 * 1024;
    let grown = peak.saturating_sub(before);
    eprintln!(
        "10 frames of {frame} bytes and 10 archives of {tar} bytes: peak RSS {} MB (before {} MB), \
         grew {} MB, bound {} MB; whole files would need at least {} MB",
        peak >> 20,
        before >> 20,
        grown >> 20,
        bound >> 20,
        (10 * (frame + tar) as u64) >> 20
    );
    assert!(
        grown < bound,
        "peak RSS grew {grown} bytes, over the bound {bound}"
    );
}

/// A client that asks for `path` and reads it at most 6 KB every 100 ms (60 KB/s) until `fast`
/// turns true, then as fast as it can. It ends when the server closes the connection, or once
/// nothing more comes for 3 s (the answer is whole and the connection kept alive), and says how
/// many bytes it read and whether the server closed the connection.
async fn slow_reader(
    app: &TestApp,
    path: &str,
    fast: tokio::sync::watch::Receiver<bool>,
) -> tokio::task::JoinHandle<(usize, bool)> {
    let mut stream = request(app, path).await;
    tokio::spawn(async move {
        let mut buf = vec![0u8; 6 * 1024];
        let (start, mut got) = (Instant::now(), 0);
        while start.elapsed() < Duration::from_secs(60) {
            let read = tokio::time::timeout(Duration::from_secs(3), stream.read(&mut buf));
            match read.await {
                Err(_) => return (got, false),
                Ok(Ok(0) | Err(_)) => return (got, true),
                Ok(Ok(n)) => got += n,
            }
            if !*fast.borrow() {
                tokio::time::sleep(Duration::from_millis(100)).await;
            }
        }
        (got, false)
    })
}

/// Two clients reading a large `state.vtu` at 60 KB/s (above what `--min-download-bytes-per-s`
/// had counted) held both download slots, and a history waited 30 s for one, then got 503.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_history_does_not_wait_for_two_slow_readers_holding_both_slots() {
    let app = TestApp::start(&["--concurrent-jobs", "1"]).await;
    let (id, size) = large_state(&app).await;
    let path = format!("/v1/jobs/{id}/state.vtu");
    let (fast, slow) = tokio::sync::watch::channel(false);
    let readers = [
        slow_reader(&app, &path, slow.clone()).await,
        slow_reader(&app, &path, slow).await,
    ];
    tokio::time::sleep(Duration::from_secs(1)).await;
    for format in ["csv", "json"] {
        let start = Instant::now();
        let r = app
            .get(&format!("/v1/jobs/{id}/history?format={format}"))
            .await;
        assert_eq!(r.status(), 200);
        let text = r.text().await.unwrap();
        let took = start.elapsed();
        assert!(text.contains("time_ms"), "{text}");
        assert!(
            took < Duration::from_secs(2),
            "the {format} history took {took:?}"
        );
    }
    // No download waited for a slot, so both slow readers kept theirs: each reads its file whole.
    fast.send(true).unwrap();
    for reader in readers {
        let (got, closed) = reader.await.unwrap();
        assert!(got > size && !closed, "{got} bytes, closed: {closed}");
    }
}

/// Two clients reading a large `state.vtu` at 60 KB/s held both download slots, and every
/// other VTU file, frame or archive waited 30 s for one, then got 503. Only the fair share
/// frees a slot here (no minimum rate): one slow reader is closed a few seconds into the wait,
/// and the other, with no one waiting any more, keeps its slot.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_third_download_gets_a_slot_from_two_slow_readers_within_seconds() {
    let app = TestApp::start(&["--concurrent-jobs", "1", "--min-download-bytes-per-s", "0"]).await;
    let (id, size) = large_state(&app).await;
    let path = format!("/v1/jobs/{id}/state.vtu");
    let (fast, slow) = tokio::sync::watch::channel(false);
    let readers = [
        slow_reader(&app, &path, slow.clone()).await,
        slow_reader(&app, &path, slow).await,
    ];
    tokio::time::sleep(Duration::from_secs(1)).await;
    let start = Instant::now();
    let r = app.get(&path).await;
    assert_eq!(r.status(), 200);
    let took = start.elapsed();
    assert_eq!(r.bytes().await.unwrap().len(), size);
    eprintln!("the third download waited {took:?} for its slot");
    // A window of 3 s to judge the readers, a second or two to close one.
    assert!(took < Duration::from_secs(12), "it waited {took:?}");
    fast.send(true).unwrap();
    let mut ended = Vec::new();
    for reader in readers {
        ended.push(reader.await.unwrap());
    }
    ended.sort_by_key(|(_, closed)| *closed);
    let [(whole, false), (cut, true)] = ended[..] else {
        panic!("one reader closed, the other whole: {ended:?}");
    };
    assert!(whole > size && cut < size, "{ended:?}");
}
