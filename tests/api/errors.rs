//! Every class of bad input gets its status and an RFC 9457 problem naming the field, and the
//! server stays up.

use crate::common::*;
use serde_json::{json, Value};
use std::time::Duration;

/// Checks the status and the problem+json body; returns the body.
async fn problem(r: reqwest::Response, status: u16) -> Value {
    assert_eq!(r.status(), status, "{:?}", r.headers());
    let ct = r.headers()["content-type"].to_str().unwrap().to_string();
    assert_eq!(ct, "application/problem+json");
    let p: Value = r.json().await.unwrap();
    assert_eq!(p["status"], status);
    assert!(
        p["type"].is_string() && p["title"].is_string() && p["detail"].is_string(),
        "{p}"
    );
    p
}

fn fields(p: &Value) -> Vec<String> {
    p["errors"].as_array().map_or(vec![], |a| {
        a.iter()
            .map(|e| e["field"].as_str().unwrap().to_string())
            .collect()
    })
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn each_class_of_bad_input_gets_its_status_and_a_problem_naming_the_field() {
    let app = TestApp::start(&[
        "--concurrent-jobs",
        "0",
        "--max-particles",
        "20000",
        "--max-body-bytes",
        "65536",
        "--max-queue",
        "3",
        "--max-sse-clients",
        "1",
    ])
    .await;
    let c = &app.client;
    let jobs = app.at("/v1/jobs");
    let post_text = |body: &'static str| {
        c.post(&jobs)
            .header("content-type", "application/json")
            .body(body)
            .send()
    };

    // 400: not JSON, a wrong type, an unknown field.
    let p = problem(post_text("{\"tube\": ").await.unwrap(), 400).await;
    assert!(p["detail"].as_str().unwrap().contains("malformed"), "{p}");
    let p = problem(
        post_text(r#"{"tube": {"thickness_mm": "thick"}}"#)
            .await
            .unwrap(),
        400,
    )
    .await;
    assert_eq!(p["field"], "tube.thickness_mm");
    let p = problem(post_text(r#"{"tube": {"wall_mm": 1}}"#).await.unwrap(), 400).await;
    assert!(p["detail"].as_str().unwrap().contains("wall_mm"), "{p}");
    let p = problem(
        c.post(&jobs)
            .header("content-type", "application/json")
            .body(vec![0xff, 0xfe])
            .send()
            .await
            .unwrap(),
        400,
    )
    .await;
    assert!(p["detail"].as_str().unwrap().contains("UTF-8"));

    // 422: a case that parses but makes no sense, every field named.
    let bad = json!({"tube": {"thickness_mm": 12}, "material": {"poisson_ratio": 0.5},
                     "loading": {"plate_speed_m_s": -1}, "output": {"history_points": 1}});
    let p = problem(c.post(&jobs).json(&bad).send().await.unwrap(), 422).await;
    let named = fields(&p);
    for f in [
        "tube.thickness_mm",
        "material.poisson_ratio",
        "loading.plate_speed_m_s",
        "output.history_points",
    ] {
        assert!(named.contains(&f.to_string()), "{f} not in {named:?}");
    }
    // 422: a hardening curve not increasing in strain and a rate law without its constants,
    // each field named with its reason.
    let bad = json!({"material": {"preset": "aa6060_t5", "hardening": "table",
                                  "hardening_curve": [[0, 120], [0.1, 150], [0.05, 160]],
                                  "rate": "cowper_symonds"}});
    let p = problem(c.post(&jobs).json(&bad).send().await.unwrap(), 422).await;
    let reasons: Vec<(String, String)> = p["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e["field"].as_str().unwrap().into(), e.to_string()))
        .collect();
    for (f, why) in [
        ("material.hardening_curve", "not increasing in strain"),
        (
            "material.cowper_symonds_d_per_s",
            "is required with rate cowper_symonds",
        ),
        (
            "material.cowper_symonds_q",
            "is required with rate cowper_symonds",
        ),
    ] {
        assert!(
            reasons.iter().any(|(k, e)| k == f && e.contains(why)),
            "{f}: {why} not in {reasons:?}"
        );
    }
    // 422: too large for this server, the field that drives the count (n, off its default)
    // first.
    let big = json!({"discretization": {"particles_through_thickness": 6}});
    let p = problem(c.post(&jobs).json(&big).send().await.unwrap(), 422).await;
    assert_eq!(
        fields(&p),
        vec![
            "discretization.particles_through_thickness",
            "tube.thickness_mm",
            "tube.mean_diameter_mm",
            "tube.length_mm",
        ]
    );
    assert!(p["detail"].as_str().unwrap().contains("20000"), "{p}");
    let p = problem(
        c.post(app.at("/v1/estimate"))
            .json(&big)
            .send()
            .await
            .unwrap(),
        422,
    )
    .await;
    assert!(fields(&p).contains(&"discretization.particles_through_thickness".to_string()));

    // 413: a body over the limit, whether announced or streamed. The server closes such a
    // connection, so these requests go through a client that keeps no idle connection: a
    // pooled one could be handed to the next request just as the server closes it.
    let huge = format!("{{\"label\": \"{}\"}}", "x".repeat(200_000));
    let once = reqwest::Client::builder()
        .pool_max_idle_per_host(0)
        .build()
        .unwrap();
    problem(
        once.post(&jobs)
            .header("content-type", "application/json")
            .body(huge.clone())
            .send()
            .await
            .unwrap(),
        413,
    )
    .await;
    let chunks = futures::stream::iter((0..50).map(|_| Ok::<_, std::io::Error>(vec![b' '; 4096])));
    let streamed = once
        .post(&jobs)
        .header("content-type", "application/json")
        .body(reqwest::Body::wrap_stream(chunks));
    // The server answers 413 as soon as the limit is passed and closes the connection; a client
    // still writing may see that as a broken pipe instead of reading the answer.
    match streamed.send().await {
        Ok(r) => drop(problem(r, 413).await),
        Err(e) => assert!(e.is_request(), "{e}"),
    }

    // 415: not JSON by its content type.
    problem(
        c.post(&jobs)
            .header("content-type", "text/plain")
            .body("{}")
            .send()
            .await
            .unwrap(),
        415,
    )
    .await;

    // 404: unknown ids, ids that are not UUIDs, unknown routes; 405 a wrong method.
    let unknown = "3f2b7d1e-0000-4000-8000-000000000000";
    for path in [
        format!("/v1/jobs/{unknown}"),
        format!("/v1/jobs/{unknown}/history"),
        format!("/v1/jobs/{unknown}/events"),
        "/v1/jobs/not-a-uuid".to_string(),
        "/v1/jobs/%20bad%3F/history".to_string(),
        format!("/v1/sweeps/{unknown}"),
        "/v1/nothing-here".to_string(),
    ] {
        problem(c.get(app.at(&path)).send().await.unwrap(), 404).await;
    }
    problem(
        c.post(app.at(&format!("/v1/jobs/{unknown}/cancel")))
            .json(&json!({}))
            .send()
            .await
            .unwrap(),
        404,
    )
    .await;
    problem(c.delete(app.at("/v1/jobs")).send().await.unwrap(), 405).await;

    // 400: bad list parameters and headers.
    for (query, field) in [
        ("status=done", "status"),
        // schemathesis: an empty item was skipped and answered 200.
        ("status=,", "status"),
        ("status=", "status"),
        ("limit=0", "limit"),
        ("limit=x", "limit"),
        ("cursor=abc", "cursor"),
    ] {
        let p = problem(
            c.get(app.at(&format!("/v1/jobs?{query}")))
                .send()
                .await
                .unwrap(),
            400,
        )
        .await;
        assert_eq!(p["field"], field, "{query}: {p}");
    }
    let long_key = "k".repeat(300);
    let p = problem(
        c.post(&jobs)
            .header("idempotency-key", long_key)
            .json(&tiny_case())
            .send()
            .await
            .unwrap(),
        400,
    )
    .await;
    assert_eq!(p["field"], "Idempotency-Key");

    // 422 for sweeps: nothing to vary (neither parameters nor an ensemble), an empty list.
    let p = problem(
        c.post(app.at("/v1/sweeps"))
            .json(&json!({"base": {}}))
            .send()
            .await
            .unwrap(),
        422,
    )
    .await;
    assert_eq!(fields(&p), vec!["parameters"]);
    assert!(
        p["errors"][0]["reason"]
            .as_str()
            .unwrap()
            .contains("ensemble"),
        "{p}"
    );
    let body = json!({"base": tiny_case(), "parameters": {"tube.length_mm": []}});
    let p = problem(
        c.post(app.at("/v1/sweeps"))
            .json(&body)
            .send()
            .await
            .unwrap(),
        422,
    )
    .await;
    assert_eq!(fields(&p), vec!["parameters.tube.length_mm"]);

    // 503: the queue is full (3 jobs here), with Retry-After.
    for _ in 0..3 {
        app.submit(&tiny_case()).await;
    }
    let r = c.post(&jobs).json(&tiny_case()).send().await.unwrap();
    assert!(r.headers().contains_key("retry-after"));
    problem(r, 503).await;
    let body = json!({"base": tiny_case(), "parameters": {"tube.length_mm": [8, 9]}});
    problem(
        c.post(app.at("/v1/sweeps"))
            .json(&body)
            .send()
            .await
            .unwrap(),
        503,
    )
    .await;

    // 503: too many event streams (1 here).
    let list = get_json(c, &app.at("/v1/jobs?status=queued&limit=1")).await;
    let id = list["jobs"][0]["id"].as_str().unwrap().to_string();
    let url = app.at(&format!("/v1/jobs/{id}/events"));
    let (status, mut open) = SseReader::open(c, &url, None).await;
    assert_eq!(status, 200);
    assert!(open.next(Duration::from_secs(5)).await.is_some());
    problem(c.get(&url).send().await.unwrap(), 503).await;
    drop(open);

    // 409: cancelling a finished job.
    let r = c
        .post(app.at(&format!("/v1/jobs/{id}/cancel")))
        .header("content-type", "application/json")
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    problem(
        c.post(app.at(&format!("/v1/jobs/{id}/cancel")))
            .json(&json!({}))
            .send()
            .await
            .unwrap(),
        409,
    )
    .await;

    // Still standing.
    assert_eq!(
        c.get(app.at("/healthz")).send().await.unwrap().status(),
        200
    );
}

/// The three requests whose particle count overflowed: each is a 422 naming the tube's
/// fields, from `/v1/jobs` and `/v1/estimate` alike, and the server stays up.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn particle_counts_that_overflowed_u64_are_refused_not_run() {
    let app = TestApp::start(&["--concurrent-jobs", "1"]).await;
    let c = &app.client;
    for (body, field) in [
        (r#"{"tube":{"thickness_mm":1e-300}}"#, "tube.thickness_mm"),
        (
            r#"{"tube":{"thickness_mm":1,"mean_diameter_mm":1367130551.2,"length_mm":4294967296},"discretization":{"particles_through_thickness":1}}"#,
            "tube.mean_diameter_mm",
        ),
        (r#"{"tube":{"length_mm":1e300}}"#, "tube.length_mm"),
    ] {
        for route in ["/v1/jobs", "/v1/estimate"] {
            let r = c
                .post(app.at(route))
                .header("content-type", "application/json")
                .body(body)
                .send()
                .await
                .unwrap();
            let p = problem(r, 422).await;
            assert!(fields(&p).contains(&field.to_string()), "{body}: {p}");
            let detail = p["detail"].as_str().unwrap();
            assert!(detail.contains("particles"), "{detail}");
            assert!(!detail.contains("18446744073709551"), "{detail}");
        }
    }
    let list = get_json(c, &app.at("/v1/jobs")).await;
    assert_eq!(list["jobs"].as_array().unwrap().len(), 0, "{list}");
    assert_eq!(app.get("/healthz").await.status(), 200);
}

/// What broke: a plate speed of 1e-300 m/s was accepted with an estimate of 1.8e19 steps.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cases_over_the_step_limits_are_refused_with_the_estimate() {
    let app = TestApp::start(&[
        "--concurrent-jobs",
        "0",
        "--max-steps",
        "100000",
        "--max-particle-steps",
        "1000000000",
    ])
    .await;
    let c = &app.client;
    for route in ["/v1/jobs", "/v1/estimate"] {
        let r = c
            .post(app.at(route))
            .json(&json!({"loading": {"plate_speed_m_s": 1e-300}}))
            .send()
            .await
            .unwrap();
        let p = problem(r, 422).await;
        let named = fields(&p);
        for f in [
            "loading.plate_speed_m_s",
            "loading.crush_distance_mm",
            "discretization.cfl",
            "material.youngs_modulus_mpa",
            "material.density_kg_m3",
            "discretization.particles_through_thickness",
        ] {
            assert!(named.contains(&f.to_string()), "{f} not in {named:?}");
        }
        assert!(
            p["detail"].as_str().unwrap().contains("limit of 100000"),
            "{p}"
        );
        // The default case: 33 155 particles × 15 844 steps = 5.3e8 particle-steps, under
        // 1e9; at n = 6 (examples/axial_t3.2.json), 112 112 × 23 766 = 2.7e9, over.
        let fine = json!({"discretization": {"particles_through_thickness": 6}});
        let p = problem(c.post(app.at(route)).json(&fine).send().await.unwrap(), 422).await;
        assert!(
            p["detail"].as_str().unwrap().contains("particle-steps"),
            "{p}"
        );
    }
    let estimate = app.estimate(&json!({})).await;
    assert_eq!(estimate["steps"], 15844, "{estimate}");
    // The default case (axial, no trigger) qualifies for the axisymmetric model: the estimate
    // says what it would cost and what it cannot show; a triggered case does not qualify.
    let reduced = &estimate["reduced"];
    assert_eq!(reduced["model"], "axisymmetric", "{estimate}");
    assert!(reduced["speedup"].as_f64().unwrap() > 10.0, "{estimate}");
    assert!(reduced["cannot_show"].as_str().unwrap().contains("lobes"));
    let triggered = json!({"trigger": {"weak_fraction": 0.003}});
    let e = app.estimate(&triggered).await;
    assert!(e.get("reduced").is_none(), "{e}");
    // The estimate names the shape functions: the default one with why (uGIMP for the thick
    // default tube, linear for a thin wall in 3D on the default near-frictionless plates), a
    // named one bare.
    assert_eq!(estimate["shape"]["kind"], "gimp", "{estimate}");
    assert!(
        estimate["shape"]["default_reason"].is_string(),
        "{estimate}"
    );
    let thin = json!({"tube": {"thickness_mm": 0.76, "mean_diameter_mm": 19.81, "length_mm": 20},
                      "loading": {"crush_distance_mm": 5}});
    let e = app.estimate(&thin).await;
    assert_eq!(e["shape"]["kind"], "linear", "{e}");
    let why = e["shape"]["default_reason"].as_str().unwrap();
    assert!(why.contains("d/t = 26.1"), "{why}");
    // The same wall on a platen's friction, which holds its ends: B-splines, and why.
    let mut held = thin.clone();
    held["contact"] = json!({"friction": 0.3});
    let e = app.estimate(&held).await;
    assert_eq!(e["shape"]["kind"], "bspline", "{e}");
    let why = e["shape"]["default_reason"].as_str().unwrap();
    assert!(why.contains("plates that hold its ends (μ 0.3"), "{why}");
    // There the time step is 0.8's, and why; on linear shapes 0.5's; a case's own is its own
    // (a longer one here: this runner's step limit is low).
    assert_eq!(e["cfl"], 0.8, "{e}");
    let why = e["cfl_default_reason"].as_str().unwrap();
    assert!(
        why.contains("thin wall crushed axially in 3D on B-splines"),
        "{why}"
    );
    assert_eq!(app.estimate(&thin).await["cfl"], 0.5);
    held["discretization"] = json!({"cfl": 0.9});
    let e = app.estimate(&held).await;
    assert_eq!(
        (&e["cfl"], e.get("cfl_default_reason")),
        (&json!(0.9), None),
        "{e}"
    );
    let mut named = thin.clone();
    named["discretization"] = json!({"shape": "gimp"});
    let e = app.estimate(&named).await;
    assert_eq!(e["shape"], json!({"kind": "gimp"}), "{e}");
    // A model that does not fit the scene is refused with the field named.
    let wrong =
        json!({"loading": {"mode": "lateral"}, "discretization": {"model": "axisymmetric"}});
    let p = problem(
        c.post(app.at("/v1/jobs"))
            .json(&wrong)
            .send()
            .await
            .unwrap(),
        422,
    )
    .await;
    assert_eq!(fields(&p), vec!["discretization.model"]);
}

/// What broke: a thickness in metres typed as millimetres (0.0032 for 3.2 mm) was refused for
/// its steps with `loading.plate_speed_m_s` named first, and on a server that admits its cost
/// the estimate called it trusted. The refusal names the thickness first with its value; past
/// the limits, the estimate is not trusted and names the slip.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_thickness_in_metres_is_refused_naming_it_and_its_estimate_names_the_slip() {
    let thin =
        json!({"tube": {"thickness_mm": 0.0032}, "discretization": {"model": "axisymmetric"}});
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let c = &app.client;
    for route in ["/v1/jobs", "/v1/estimate"] {
        let r = c.post(app.at(route)).json(&thin).send().await.unwrap();
        let p = problem(r, 422).await;
        assert_eq!(fields(&p)[0], "tube.thickness_mm", "{p}");
        let lead = p["errors"][0]["reason"].as_str().unwrap();
        assert!(
            lead.starts_with("0.0032 mm gives 15843860 time steps"),
            "{p}"
        );
    }
    let roomy = TestApp::start(&[
        "--concurrent-jobs",
        "0",
        "--max-steps",
        "100000000",
        "--max-particle-steps",
        "10000000000000",
    ])
    .await;
    let e = roomy.estimate(&thin).await;
    assert_eq!(e["verdict"]["level"], "not_trusted", "{e}");
    let reason = &e["verdict"]["reasons"][0];
    assert_eq!(reason["rule"], "implausible_geometry", "{e}");
    assert_eq!(reason["level"], "not_trusted", "{e}");
    let detail = reason["detail"].as_str().unwrap();
    assert!(
        detail.contains("did you mean 3.2 mm (metres typed as millimetres)?"),
        "{detail}"
    );
}

/// What broke: a job stored by an older version whose count had wrapped crashed the server when
/// the worker built its scene, at every restart. Now the worker checks the case again and
/// fails the job with the reason.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_stored_job_that_would_overflow_fails_with_the_reason_instead_of_crashing() {
    use crush::service::store::{NewJob, Store};
    let dir = tempfile::tempdir().unwrap();
    let db = database_url(dir.path());
    let store = Store::open(&db).await.unwrap();
    let id = uuid::Uuid::new_v4();
    let case = r#"{"discretization":{"particles_through_thickness":1},"tube":{"length_mm":4294967296,"mean_diameter_mm":1367130551.2,"thickness_mm":1}}"#;
    store
        .submit(
            NewJob {
                id,
                case_json: case.into(),
                label: None,
                particles: 0,
                idempotency_key: None,
            },
            10,
        )
        .await
        .unwrap();
    store.close().await;
    let args = crush::service::ServeArgs::from_flags([
        "--port",
        "0",
        "--database-url",
        db.as_str(),
        "--threads-per-job",
        "1",
    ])
    .unwrap();
    let server = crush::service::start(args).await.unwrap();
    let url = format!("http://{}", server.addr);
    let c = client();
    let job = wait_for(
        &c,
        &url,
        &id.to_string(),
        &["failed"],
        Duration::from_secs(20),
    )
    .await;
    let error = job["error"].as_str().unwrap();
    assert!(
        error.contains("tube.mean_diameter_mm") && error.contains("particles"),
        "{error}"
    );
    assert_eq!(
        c.get(format!("{url}/healthz"))
            .send()
            .await
            .unwrap()
            .status(),
        200
    );
    server.stop().await.unwrap();
}

/// Smaller things that broke: a body that is not one JSON object, a body without a content type,
/// ids in other spellings, and a cursor that was a row number.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bodies_ids_and_cursors_are_read_one_way_only() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let c = &app.client;
    let send = |route: &str, ct: Option<&str>, body: &'static str| {
        let mut r = c.post(app.at(route)).body(body);
        if let Some(ct) = ct {
            r = r.header("content-type", ct);
        }
        r.send()
    };
    // `[]` was a default case; `/v1/estimate` took trailing text and two documents. Every
    // route that takes a body now reads it the same way.
    for route in ["/v1/jobs", "/v1/estimate", "/v1/sweeps"] {
        for body in ["[]", "[{}]", "{} x", "{}{}", "{} {}", "null", "\"{}\""] {
            let r = send(route, Some("application/json"), body).await.unwrap();
            problem(r, 400).await;
        }
        // A missing content type is 415, as the README promises.
        let r = send(route, None, "{}").await.unwrap();
        let p = problem(r, 415).await;
        assert!(
            p["detail"].as_str().unwrap().contains("application/json"),
            "{p}"
        );
    }
    let r = send("/v1/estimate", Some("application/json"), " {}\n")
        .await
        .unwrap();
    assert_eq!(r.status(), 200);

    // Ids: only the hyphenated form (either case); braced, URN and plain hex are 404.
    let first = app.submit(&tiny_case()).await;
    let second = app.submit(&tiny_case()).await;
    let id = first["id"].as_str().unwrap().to_string();
    let uuid = uuid::Uuid::parse_str(&id).unwrap();
    assert_eq!(app.get(&format!("/v1/jobs/{id}")).await.status(), 200);
    let upper = id.to_uppercase();
    assert_eq!(app.get(&format!("/v1/jobs/{upper}")).await.status(), 200);
    for other in [
        uuid.braced().to_string(),
        uuid.urn().to_string(),
        uuid.simple().to_string(),
    ] {
        let path = format!("/v1/jobs/{other}");
        problem(app.get(&path).await, 404).await;
        problem(app.get(&format!("{path}/history")).await, 404).await;
        problem(app.post(&format!("{path}/cancel")).await, 404).await;
    }

    // The cursor is opaque (not a row number) and still pages; a made-up one is 400.
    let page = get_json(c, &app.at("/v1/jobs?limit=1")).await;
    assert_eq!(page["jobs"][0]["id"], second["id"]);
    let cursor = page["next_cursor"].as_str().unwrap().to_string();
    assert!(cursor.parse::<i64>().is_err(), "{cursor}");
    let page = get_json(c, &app.at(&format!("/v1/jobs?limit=1&cursor={cursor}"))).await;
    assert_eq!(page["jobs"][0]["id"], first["id"]);
    assert!(page["next_cursor"].is_null(), "{page}");
    for bad in ["1", "2", "999", "a%2Fb"] {
        let p = problem(app.get(&format!("/v1/jobs?cursor={bad}")).await, 400).await;
        assert_eq!(p["field"], "cursor", "{p}");
    }
}

/// What broke: a 414 and the 400s of a malformed header came from hyper with no body; now they
/// are problem+json like every other error.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn errors_hyper_answers_itself_are_problem_json_too() {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let addr = app.url.trim_start_matches("http://").to_string();
    let long = format!(
        "GET /v1/jobs?label={} HTTP/1.1\r\nhost: x\r\n\r\n",
        "a".repeat(70_000)
    );
    for (request, status) in [
        (long, "414"),
        (
            "GET /healthz HTTP/1.1\r\nhost: x\r\nbad header line\r\n\r\n".to_string(),
            "400",
        ),
    ] {
        let mut tcp = tokio::net::TcpStream::connect(&addr).await.unwrap();
        // The server may answer and close before it has read the whole request.
        let _ = tcp.write_all(request.as_bytes()).await;
        let mut answer = Vec::new();
        let _ = tokio::time::timeout(Duration::from_secs(10), tcp.read_to_end(&mut answer)).await;
        let answer = String::from_utf8_lossy(&answer).to_string();
        assert!(
            answer.starts_with(&format!("HTTP/1.1 {status} ")),
            "{answer}"
        );
        assert!(answer.contains("application/problem+json"), "{answer}");
        let body: Value = serde_json::from_str(answer.split("\r\n\r\n").nth(1).unwrap()).unwrap();
        assert_eq!(body["status"].to_string(), status, "{body}");
    }
    // Ordinary answers pass untouched.
    assert_eq!(app.get("/healthz").await.status(), 200);
    problem(app.get("/v1/nothing").await, 404).await;
}
