//! Requests an attacker would send, through the real server on port 0: each gets a clear,
//! small error at once, and the server keeps answering `/healthz` meanwhile.

use crate::common::*;
use serde_json::{json, Map, Value};
use std::time::{Duration, Instant};

/// The status, the problem+json body and its size in bytes.
async fn answer(r: reqwest::Response) -> (u16, Value, usize) {
    let status = r.status().as_u16();
    let ct = r.headers()["content-type"].to_str().unwrap().to_string();
    assert_eq!(ct, "application/problem+json", "{status}");
    let text = r.text().await.unwrap();
    (status, serde_json::from_str(&text).unwrap(), text.len())
}

/// `POST path` with `body` sent as it is.
async fn post_text(app: &TestApp, path: &str, body: String) -> reqwest::Response {
    app.client
        .post(app.at(path))
        .header("content-type", "application/json")
        .body(body)
        .send()
        .await
        .unwrap()
}

fn fields(p: &Value) -> Vec<String> {
    p["errors"].as_array().map_or(vec![], |a| {
        a.iter()
            .map(|e| e["field"].as_str().unwrap().to_string())
            .collect()
    })
}

async fn healthz_within(app: &TestApp, limit: Duration) {
    let started = Instant::now();
    let r = app
        .client
        .get(app.at("/healthz"))
        .timeout(limit)
        .send()
        .await;
    assert!(
        r.is_ok_and(|r| r.status() == 200),
        "/healthz did not answer within {limit:?} ({:?})",
        started.elapsed()
    );
}

/// `{"parameters":{"a.a.a.…":[1]}}` with 14 000 segments (28 KB), and 12 000 and 60 000: a path
/// that is not a field of the case is 422 before anything is built from it (a case nested
/// 14 000 deep overflows a runtime thread's stack), and the server goes on answering.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn post_sweeps_with_a_14000_segment_path_is_422_and_the_server_still_answers() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    for segments in [12_000, 14_000, 60_000] {
        let path = vec!["a"; segments].join(".");
        let body = json!({ "parameters": { path: [1] } }).to_string();
        let (status, p, size) = answer(post_text(&app, "/v1/sweeps", body).await).await;
        assert_eq!(status, 422, "{segments}: {p}");
        let named = fields(&p);
        assert_eq!(named.len(), 1, "{p}");
        assert!(named[0].starts_with("parameters.a.a.a") && named[0].ends_with('…'));
        assert!(size < 2_000, "{segments} segments: a {size}-byte answer");
        healthz_within(&app, Duration::from_secs(3)).await;
    }
}

/// One combination over 15 000 distinct fields (214 KB), twice at once, and over 50 000 (700 KB):
/// each is refused at once with one error (expanding them costs time quadratic in the fields:
/// seconds to minutes of a thread), while `/healthz` answers throughout.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sweeps_over_15000_and_50000_fields_are_refused_at_once_and_healthz_answers() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let body = |n: usize| {
        let parameters: Map<String, Value> =
            (0..n).map(|i| (format!("f{i}.x"), json!([1]))).collect();
        json!({ "parameters": parameters }).to_string()
    };
    let started = Instant::now();
    let (a, b, c, _) = tokio::join!(
        post_text(&app, "/v1/sweeps", body(15_000)),
        post_text(&app, "/v1/sweeps", body(15_000)),
        post_text(&app, "/v1/sweeps", body(50_000)),
        async {
            for _ in 0..5 {
                healthz_within(&app, Duration::from_secs(3)).await;
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
        }
    );
    for r in [a, b, c] {
        let (status, p, size) = answer(r).await;
        assert_eq!(status, 422, "{p}");
        assert_eq!(fields(&p), ["parameters"], "{p}");
        assert!(size < 1_000, "a {size}-byte answer");
    }
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "{:?}",
        started.elapsed()
    );
    healthz_within(&app, Duration::from_secs(3)).await;
}

/// A crush of 1e-3 mm of the README's tube (run anyway: a mean load of 650 737 N; 1e-100 mm:
/// 6.5e102 N; 1e-200 mm: a non-finite load) is 422 naming crush_distance_mm and the shortest
/// crush the grid resolves, from every route.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn crush_distance_mm_1e_3_is_422_with_the_shortest_crush_the_grid_resolves() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    for crush in [1e-3, 1e-100, 1e-200] {
        let mut case = tiny_case();
        case["loading"]["crush_distance_mm"] = json!(crush);
        for route in ["/v1/jobs", "/v1/estimate"] {
            let (status, p, _) = answer(app.post_json(route, &case).await).await;
            assert_eq!(status, 422, "{route} {crush}: {p}");
            assert_eq!(fields(&p), ["loading.crush_distance_mm"], "{p}");
            let reason = p["errors"][0]["reason"].as_str().unwrap();
            assert!(reason.contains("at least 0.0818 mm"), "{reason}");
        }
        let sweep = json!({"base": tiny_case(),
                           "parameters": {"loading.crush_distance_mm": [1, crush]}});
        let (status, p, _) = answer(app.post_json("/v1/sweeps", &sweep).await).await;
        assert_eq!(status, 422, "{p}");
        assert_eq!(fields(&p), ["loading.crush_distance_mm"], "{p}");
    }
    // The test cases themselves pass the rule.
    for case in [tiny_case(), medium_case(), long_case()] {
        app.estimate(&case).await;
    }
}

/// `"discretization":[1,2]` and `"output":[20,false]`: a section is read from an object only,
/// never by position, and an array is refused naming it, in a case (400) and in a sweep's
/// base (422).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_section_sent_as_an_array_is_400_naming_the_section() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    for (section, array) in [
        ("discretization", json!([1, 2])),
        ("output", json!([20, false])),
    ] {
        let mut case = tiny_case();
        case[section] = array;
        for route in ["/v1/jobs", "/v1/estimate"] {
            let (status, p, _) = answer(app.post_json(route, &case).await).await;
            assert_eq!(status, 400, "{route}: {p}");
            assert_eq!(p["field"], section, "{p}");
            assert!(p["detail"].as_str().unwrap().contains("expected an object"));
        }
        // The contract takes any object as a sweep's base: what is wrong with it is a 422.
        let sweep = json!({"base": case, "parameters": {"tube.length_mm": [8, 9]}});
        let (status, p, _) = answer(app.post_json("/v1/sweeps", &sweep).await).await;
        assert_eq!(status, 422, "{p}");
        assert_eq!(fields(&p), [format!("base.{section}")], "{p}");
        assert!(p["detail"].as_str().unwrap().contains("expected an object"));
    }
    // Nothing was stored.
    let list = get_json(&app.client, &app.at("/v1/jobs")).await;
    assert_eq!(list["jobs"], json!([]));
}

/// Two equal keys in a sweep's `parameters` (serde_json alone keeps the last one): a key given
/// twice anywhere in a body is 400 naming it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_key_given_twice_in_a_sweep_or_a_case_is_400_naming_it() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let base = tiny_case().to_string();
    for (route, body, field) in [
        (
            "/v1/sweeps",
            format!(
                r#"{{"base": {base}, "parameters":
                    {{"tube.length_mm": [8], "tube.length_mm": [9, 10]}}}}"#
            ),
            "parameters.tube.length_mm",
        ),
        (
            "/v1/sweeps",
            r#"{"base": {"tube": {"length_mm": 8, "length_mm": 9}},
                "parameters": {"tube.thickness_mm": [1]}}"#
                .to_string(),
            "base.tube.length_mm",
        ),
        (
            "/v1/jobs",
            r#"{"tube": {}, "tube": {"length_mm": 8}}"#.to_string(),
            "tube",
        ),
        (
            "/v1/estimate",
            r#"{"tube": {"length_mm": 8, "length_mm": 9}}"#.to_string(),
            "tube.length_mm",
        ),
    ] {
        let (status, p, _) = answer(post_text(&app, route, body).await).await;
        assert_eq!(status, 400, "{route}: {p}");
        assert_eq!(p["field"], field, "{p}");
        assert!(p["detail"].as_str().unwrap().contains("more than once"));
    }
}

/// A 200 KB field name (which an error quoting it whole would repeat in a 400 KB answer), and
/// long values, paths and headers: an error quotes at most 100 characters of each.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_200_kb_field_name_is_quoted_clipped_in_a_small_answer() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let long = "a".repeat(200_000);
    let sweep = json!({"base": tiny_case(), "parameters": { long.clone(): [1] }});
    let unknown = json!({ long.clone(): 1 });
    let bad_value = json!({"tube": {"thickness_mm": long.clone()}});
    let bad_variant = json!({"loading": {"mode": long.clone()}});
    let in_base = json!({"base": {"tube": { long.clone(): 1 }}, "parameters": {"label": ["x"]}});
    let labelled = json!({"label": long.clone(), "parameters": {"tube.length_mm": [8]}});
    let plan = json!({"case": tiny_case(), "budget_s": 60, long.clone(): 1});
    let sign_in = json!({"token": "t", long.clone(): 1});
    for (route, body) in [
        ("/v1/plan", plan),
        ("/v1/session", sign_in),
        ("/v1/sweeps", sweep),
        ("/v1/jobs", unknown.clone()),
        ("/v1/estimate", unknown),
        ("/v1/jobs", bad_value),
        ("/v1/jobs", bad_variant),
        ("/v1/sweeps", in_base),
        ("/v1/sweeps", labelled),
    ] {
        let (status, p, size) = answer(app.post_json(route, &body).await).await;
        let start: String = p.to_string().chars().take(300).collect();
        assert!(status == 400 || status == 422, "{route}: {start}");
        assert!(size < 2_000, "{route}: a {size}-byte answer: {start}…");
    }
    // Strings in the path and the query too.
    let long = "b".repeat(20_000);
    for path in [
        format!("/v1/jobs/{long}"),
        format!("/v1/sweeps/{long}"),
        format!("/v1/{long}"),
        format!("/v1/jobs?status={long}"),
        format!("/assets/{long}"),
    ] {
        let (status, p, size) = answer(app.get(&path).await).await;
        let start: String = p.to_string().chars().take(300).collect();
        assert!(status == 400 || status == 404, "{start}");
        assert!(size < 1_000, "a {size}-byte answer: {start}…");
    }
    let r = app
        .client
        .post(app.at("/v1/jobs"))
        .header("content-type", format!("text/{long}"))
        .body("{}")
        .send()
        .await
        .unwrap();
    let (status, _, size) = answer(r).await;
    assert_eq!(status, 415);
    assert!(size < 1_000, "a {size}-byte answer");
}
