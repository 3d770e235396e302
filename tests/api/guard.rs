//! Access control through the real server, on either backend: tokens and their roles, the page's
//! cookie, the owner of a job, the `Host` a request names, cross-site requests, the per-client
//! rate limit and the security headers. The connection time limits are in `api_timeouts.rs`.

use crate::common::*;
use reqwest::header::HeaderMap;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

const ALICE: &str = "alice-admin-0123456789abcdef";
const CI: &str = "ci-submit-0123456789abcdefgh";
const BOB: &str = "bob-submit-0123456789abcdefg";
const GRAFANA: &str = "grafana-read-0123456789abcd";

/// A server with four tokens (admin, two submitters, a reader) that runs nothing, and the
/// folder holding its token file.
async fn with_tokens(extra: &[&str]) -> (TestApp, tempfile::TempDir) {
    let files = tempfile::tempdir().unwrap();
    let path = files.path().join("tokens");
    let text = format!(
        "# name role token\nalice admin {ALICE}\nci submit {CI}\nbob submit {BOB}\n\
         grafana read {GRAFANA}\n"
    );
    std::fs::write(&path, text).unwrap();
    let mut flags = vec![
        "--concurrent-jobs",
        "0",
        "--token-file",
        path.to_str().unwrap(),
    ];
    flags.extend_from_slice(extra);
    (TestApp::start(&flags).await, files)
}

/// Checks a problem answer's status and content type; returns the document.
async fn problem(r: reqwest::Response, status: u16) -> (HeaderMap, Value) {
    assert_eq!(r.status(), status, "{:?}", r.headers());
    let ct = r.headers()["content-type"].to_str().unwrap().to_string();
    assert!(ct.starts_with("application/problem+json"), "{ct}");
    let headers = r.headers().clone();
    let body: Value = r.json().await.unwrap();
    assert_eq!(body["status"], status, "{body}");
    (headers, body)
}

fn as_token(
    app: &TestApp,
    method: reqwest::Method,
    path: &str,
    token: &str,
) -> reqwest::RequestBuilder {
    app.client.request(method, app.at(path)).bearer_auth(token)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_a_token_file_a_non_loopback_host_is_refused_at_start() {
    let dir = tempfile::tempdir().unwrap();
    let db = database_url(dir.path());
    let flags = ["--host", "0.0.0.0", "--port", "0", "--database-url", &db];
    let args = crush::service::ServeArgs::from_flags(flags).unwrap();
    let error = crush::service::start(args).await.err().expect("refused");
    let text = error.to_string();
    assert!(
        text.contains("--token-file") && text.contains("--allow-anonymous-remote"),
        "{text}"
    );
    // A token file with a bad line stops the start too, naming the line.
    let tokens = dir.path().join("tokens");
    std::fs::write(&tokens, format!("alice admin {ALICE}\nci writer {CI}\n")).unwrap();
    let flags = [
        "--port",
        "0",
        "--database-url",
        &db,
        "--token-file",
        tokens.to_str().unwrap(),
    ];
    let args = crush::service::ServeArgs::from_flags(flags).unwrap();
    let error = crush::service::start(args).await.err().expect("refused");
    let text = format!("{error:#}");
    assert!(text.contains("line 2") && text.contains("writer"), "{text}");
    assert!(!text.contains(CI), "the token leaked: {text}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn each_role_may_do_what_it_grants_and_no_more() {
    let (app, _files) = with_tokens(&[]).await;
    use reqwest::Method;

    // No token: 401 with a Bearer challenge; a wrong one: invalid_token.
    let (headers, p) = problem(app.get("/v1/jobs").await, 401).await;
    assert_eq!(headers["www-authenticate"], "Bearer realm=\"crush\"");
    assert!(p["detail"].as_str().unwrap().contains("read"), "{p}");
    let wrong = as_token(
        &app,
        Method::GET,
        "/v1/jobs",
        "not-a-token-of-this-server-at-all",
    );
    let (headers, _) = problem(wrong.send().await.unwrap(), 401).await;
    let challenge = headers["www-authenticate"].to_str().unwrap();
    assert!(challenge.contains("error=\"invalid_token\""), "{challenge}");

    // Read: every GET, nothing else.
    let r = as_token(&app, Method::GET, "/v1/jobs", GRAFANA)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    for path in ["/v1/jobs", "/v1/estimate", "/v1/sweeps"] {
        let r = as_token(&app, Method::POST, path, GRAFANA).json(&tiny_case());
        let (_, p) = problem(r.send().await.unwrap(), 403).await;
        assert!(p["detail"].as_str().unwrap().contains("submit role"), "{p}");
    }

    // Submit: its jobs and sweeps carry its name.
    let submit = |token: &'static str| {
        let app = &app;
        async move {
            let r = as_token(app, Method::POST, "/v1/jobs", token)
                .json(&tiny_case())
                .send()
                .await
                .unwrap();
            assert_eq!(r.status(), 202);
            r.json::<Value>().await.unwrap()
        }
    };
    let mine = submit(CI).await;
    assert_eq!(mine["owner"], "ci", "{mine}");
    let id = mine["id"].as_str().unwrap().to_string();
    let read = as_token(&app, Method::GET, &format!("/v1/jobs/{id}"), GRAFANA);
    let job: Value = read.send().await.unwrap().json().await.unwrap();
    assert_eq!(job["owner"], "ci");
    let sweep = json!({"base": tiny_case(), "parameters": {"tube.thickness_mm": [3.0, 3.2]}});
    let r = as_token(&app, Method::POST, "/v1/sweeps", CI).json(&sweep);
    let r = r.send().await.unwrap();
    assert_eq!(r.status(), 202);
    let sweep: Value = r.json().await.unwrap();
    for row in sweep["rows"].as_array().unwrap() {
        let path = format!("/v1/jobs/{}", row["job_id"].as_str().unwrap());
        let job: Value = as_token(&app, Method::GET, &path, GRAFANA)
            .send()
            .await
            .unwrap()
            .json()
            .await
            .unwrap();
        assert_eq!(job["owner"], "ci", "{job}");
    }

    // Cancel: another submitter and a reader may not; the owner may (with the bearer token, no
    // body needed); an admin may cancel anyone's.
    let cancel = |id: &str| format!("/v1/jobs/{id}/cancel");
    for (token, why) in [(BOB, "submitted by ci"), (GRAFANA, "the submit role")] {
        let r = as_token(&app, Method::POST, &cancel(&id), token).json(&json!({}));
        let (_, p) = problem(r.send().await.unwrap(), 403).await;
        assert!(p["detail"].as_str().unwrap().contains(why), "{p}");
    }
    let r = as_token(&app, Method::POST, &cancel(&id), CI)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200, "{}", r.text().await.unwrap());
    let other = submit(BOB).await;
    let other = other["id"].as_str().unwrap();
    let r = as_token(&app, Method::POST, &cancel(other), ALICE).json(&json!({}));
    assert_eq!(r.send().await.unwrap().status(), 200);
    // A cancel takes no fields.
    let third = submit(CI).await;
    let r = as_token(
        &app,
        Method::POST,
        &cancel(third["id"].as_str().unwrap()),
        CI,
    )
    .json(&json!({"reason": "x"}));
    problem(r.send().await.unwrap(), 400).await;

    // The page is open; /healthz is open and /metrics needs the read role by default.
    for path in ["/", "/assets/app.js", "/healthz", "/v1/session"] {
        assert_eq!(app.get(path).await.status(), 200, "{path}");
    }
    problem(app.get("/metrics").await, 401).await;
    let r = as_token(&app, Method::GET, "/metrics", GRAFANA)
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn healthz_and_metrics_access_follow_their_flags() {
    let flags = ["--healthz-access", "read", "--metrics-access", "open"];
    let (app, _files) = with_tokens(&flags).await;
    problem(app.get("/healthz").await, 401).await;
    assert_eq!(app.get("/metrics").await.status(), 200);
    let r = as_token(&app, reqwest::Method::GET, "/healthz", GRAFANA);
    assert_eq!(r.send().await.unwrap().status(), 200);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_page_cookie_authenticates_like_the_header_and_is_forgotten() {
    let (app, _files) = with_tokens(&[]).await;
    let r = app
        .post_json(
            "/v1/session",
            &json!({"token": "no-such-token-here-at-all"}),
        )
        .await;
    problem(r, 401).await;
    let r = app.post_json("/v1/session", &json!({"token": CI})).await;
    assert_eq!(r.status(), 200);
    let set = r.headers()["set-cookie"].to_str().unwrap().to_string();
    for part in ["crush_token=", "HttpOnly", "SameSite=Strict", "Path=/"] {
        assert!(set.contains(part), "{set}");
    }
    let me: Value = r.json().await.unwrap();
    assert_eq!(
        me,
        json!({"tokens_required": true, "name": "ci", "role": "submit"})
    );
    let cookie = set.split(';').next().unwrap().to_string();

    let with_cookie = |method, path: &str| {
        app.client
            .request(method, app.at(path))
            .header("cookie", cookie.clone())
    };
    let r = with_cookie(reqwest::Method::GET, "/v1/jobs")
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    let r = with_cookie(reqwest::Method::POST, "/v1/jobs").json(&tiny_case());
    let job: Value = r.send().await.unwrap().json().await.unwrap();
    assert_eq!(job["owner"], "ci", "{job}");
    // The cookie is not a bearer token: a POST with it still needs a JSON body.
    let cancel = format!("/v1/jobs/{}/cancel", job["id"].as_str().unwrap());
    let r = with_cookie(reqwest::Method::POST, &cancel)
        .send()
        .await
        .unwrap();
    problem(r, 415).await;
    let r = with_cookie(reqwest::Method::POST, &cancel).json(&json!({}));
    assert_eq!(r.send().await.unwrap().status(), 200);

    let r = app
        .client
        .delete(app.at("/v1/session"))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 204);
    let cleared = r.headers()["set-cookie"].to_str().unwrap();
    assert!(
        cleared.contains("crush_token=;") && cleared.contains("Max-Age=0"),
        "{cleared}"
    );
    let anonymous: Value = app.get("/v1/session").await.json().await.unwrap();
    assert_eq!(
        anonymous,
        json!({"tokens_required": true, "name": null, "role": null})
    );

    // A server without tokens has nothing to sign in to.
    let open = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let r = open.post_json("/v1/session", &json!({"token": CI})).await;
    problem(r, 409).await;
    let me: Value = open.get("/v1/session").await.json().await.unwrap();
    assert_eq!(
        me,
        json!({"tokens_required": false, "name": null, "role": "admin"})
    );
}

/// The request Chromium sends for a plain HTML form on another origin that posts to a job's
/// cancel URL: it cancelled the job.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_cross_site_html_form_post_does_not_cancel_a_job() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let id = app.submit(&tiny_case()).await["id"]
        .as_str()
        .unwrap()
        .to_string();
    let cancel = app.at(&format!("/v1/jobs/{id}/cancel"));
    let form = |extra: &[(&str, &str)]| {
        let mut r = app
            .client
            .post(&cancel)
            .header("content-type", "application/x-www-form-urlencoded")
            .body("");
        for (k, v) in extra {
            r = r.header(*k, *v);
        }
        r
    };
    let browser = [
        ("origin", "http://evil.example"),
        ("sec-fetch-site", "cross-site"),
        ("sec-fetch-mode", "navigate"),
        ("sec-fetch-dest", "document"),
    ];
    let (_, p) = problem(form(&browser).send().await.unwrap(), 403).await;
    assert!(p["detail"].as_str().unwrap().contains("cross-site"), "{p}");
    // Each sign alone is enough: the browser's word, a foreign origin, a form's content type.
    let (_, p) = problem(form(&browser[1..2]).send().await.unwrap(), 403).await;
    assert!(
        p["detail"].as_str().unwrap().contains("Sec-Fetch-Site"),
        "{p}"
    );
    let r = app
        .client
        .post(&cancel)
        .header("origin", "http://evil.example")
        .json(&json!({}));
    problem(r.send().await.unwrap(), 403).await;
    let r = app
        .client
        .post(&cancel)
        .header("sec-fetch-site", "same-site")
        .json(&json!({}));
    problem(r.send().await.unwrap(), 403).await;
    problem(form(&[]).send().await.unwrap(), 415).await;
    let text = app
        .client
        .post(&cancel)
        .header("content-type", "text/plain");
    problem(text.body("{}").send().await.unwrap(), 415).await;
    assert_eq!(app.job(&id).await["status"], "queued");

    // The page's own request (same origin, JSON) cancels it.
    let own = app
        .client
        .post(&cancel)
        .header("origin", app.url.clone())
        .header("sec-fetch-site", "same-origin")
        .json(&json!({}));
    assert_eq!(own.send().await.unwrap().status(), 200);
    assert_eq!(app.job(&id).await["status"], "cancelled");
}

/// DNS rebinding: a page on attacker.example whose name is made to resolve to 127.0.0.1 sends
/// `Host: attacker.example`; the server answered it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_foreign_host_header_is_refused_without_tokens() {
    let app = TestApp::start(&["--concurrent-jobs", "0", "--allowed-host", "crush.lab"]).await;
    let host = |h: &str| {
        app.client
            .get(app.at("/v1/jobs"))
            .header("host", h.to_string())
    };
    let (_, p) = problem(host("attacker.example:8080").send().await.unwrap(), 421).await;
    assert!(
        p["detail"].as_str().unwrap().contains("attacker.example"),
        "{p}"
    );
    for ok in [
        "localhost:1234",
        "127.0.0.1",
        "[::1]:80",
        "crush.lab:8080",
        "CRUSH.LAB",
    ] {
        assert_eq!(host(ok).send().await.unwrap().status(), 200, "{ok}");
    }

    // With tokens any host is answered (the token decides) unless --allowed-host is given.
    let (open, _files) = with_tokens(&[]).await;
    let r = open
        .client
        .get(open.at("/"))
        .header("host", "crush.example.org");
    assert_eq!(r.send().await.unwrap().status(), 200);
    let (listed, _files) = with_tokens(&["--allowed-host", "crush.lab"]).await;
    let r = listed
        .client
        .get(listed.at("/"))
        .header("host", "crush.example.org");
    problem(r.send().await.unwrap(), 421).await;
    let r = listed
        .client
        .get(listed.at("/"))
        .header("host", "crush.lab");
    assert_eq!(r.send().await.unwrap().status(), 200);
}

/// 893 submits in 0.6 s were all accepted.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_flood_of_submits_is_cut_to_the_burst_with_429() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let start = Instant::now();
    let answers: Vec<(u16, Option<String>)> = futures::future::join_all((0..300).map(|_| {
        let (client, url) = (app.client.clone(), app.at("/v1/estimate"));
        async move {
            let r = client.post(url).json(&tiny_case()).send().await.unwrap();
            let retry = r
                .headers()
                .get("retry-after")
                .map(|v| v.to_str().unwrap().to_string());
            (r.status().as_u16(), retry)
        }
    }))
    .await;
    let took = start.elapsed().as_secs_f64();
    let accepted = answers.iter().filter(|(s, _)| *s == 200).count();
    let limited: Vec<_> = answers.iter().filter(|(s, _)| *s == 429).collect();
    // The default burst (120) plus what 20 a second refill meanwhile.
    assert!(accepted >= 120, "{accepted} accepted");
    assert!(
        accepted as f64 <= 121.0 + 20.0 * took,
        "{accepted} in {took} s"
    );
    assert_eq!(accepted + limited.len(), 300);
    for (_, retry) in limited {
        let s: u32 = retry.as_deref().expect("Retry-After").parse().unwrap();
        assert!((1..=60).contains(&s), "{s}");
    }
    // Reading is not limited.
    assert_eq!(app.get("/v1/jobs").await.status(), 200);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn each_client_has_its_own_rate_limit_and_it_refills() {
    let flags = ["--rate-limit-burst", "3", "--rate-limit-per-s", "2"];
    let (app, _files) = with_tokens(&flags).await;
    let estimate = |token: &str| {
        as_token(&app, reqwest::Method::POST, "/v1/estimate", token)
            .json(&tiny_case())
            .send()
    };
    for _ in 0..3 {
        assert_eq!(estimate(CI).await.unwrap().status(), 200);
    }
    let (headers, p) = problem(estimate(CI).await.unwrap(), 429).await;
    assert_eq!(headers["retry-after"], "1");
    assert!(
        p["detail"].as_str().unwrap().contains("the token ci"),
        "{p}"
    );
    // Another token has a bucket of its own; a submit shares the estimate's.
    assert_eq!(estimate(BOB).await.unwrap().status(), 200);
    let r = as_token(&app, reqwest::Method::POST, "/v1/jobs", CI).json(&tiny_case());
    problem(r.send().await.unwrap(), 429).await;
    tokio::time::sleep(Duration::from_millis(1100)).await;
    assert_eq!(estimate(CI).await.unwrap().status(), 200);
    // Guessing tokens counts against the address: past the burst, 429 instead of 401.
    let guess = || {
        as_token(
            &app,
            reqwest::Method::GET,
            "/v1/jobs",
            "guessed-token-0123456789abc",
        )
        .send()
    };
    let mut statuses = Vec::new();
    for _ in 0..5 {
        statuses.push(guess().await.unwrap().status().as_u16());
    }
    assert_eq!(&statuses[..3], &[401, 401, 401], "{statuses:?}");
    assert!(statuses[3..].iter().all(|s| *s == 429), "{statuses:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_answer_carries_the_security_headers() {
    let app = TestApp::start(&["--concurrent-jobs", "0"]).await;
    let (tokens, _files) = with_tokens(&[]).await;
    let answers = [
        app.get("/").await,
        app.get("/assets/app.js").await,
        app.get("/v1/jobs").await,
        app.get("/v1/nothing-here").await,
        app.client
            .get(app.at("/"))
            .header("host", "attacker.example")
            .send()
            .await
            .unwrap(),
        tokens.get("/v1/jobs").await,
    ];
    for r in answers {
        let h = r.headers();
        let csp = h["content-security-policy"].to_str().unwrap();
        for part in [
            "default-src 'self'",
            "script-src 'self'",
            "frame-ancestors 'none'",
            "base-uri 'none'",
            "object-src 'none'",
        ] {
            assert!(csp.contains(part), "{csp}");
        }
        assert!(
            !csp.contains("unsafe-inline") && !csp.contains("unsafe-eval"),
            "{csp}"
        );
        assert_eq!(h["x-content-type-options"], "nosniff");
        assert_eq!(h["x-frame-options"], "DENY");
        assert_eq!(h["referrer-policy"], "no-referrer");
    }
}

/// `compose.yaml` publishes the page on the host's loopback only, and every crush node reads
/// the token file. (Docker is not on the test machines: this reads the file.)
#[test]
fn compose_publishes_on_loopback_only_and_gives_every_node_the_token_file() {
    let text = std::fs::read_to_string(repo_file("compose.yaml")).unwrap();
    let mut doc: serde_yaml_ng::Value = serde_yaml_ng::from_str(&text).unwrap();
    doc.apply_merge().unwrap();
    let secret = doc["secrets"]["crush-tokens"]["file"].as_str();
    assert_eq!(secret, Some("./crush-tokens"));
    let mut nodes = 0;
    for (name, service) in doc["services"].as_mapping().unwrap() {
        for port in service["ports"].as_sequence().into_iter().flatten() {
            let port = port.as_str().unwrap();
            assert!(port.starts_with("127.0.0.1:"), "{name:?} publishes {port}");
        }
        if name.as_str() == Some("postgres") {
            continue;
        }
        nodes += 1;
        let mut env = service["environment"].clone();
        env.apply_merge().unwrap();
        assert_eq!(
            env["CRUSH_TOKEN_FILE"].as_str(),
            Some("/run/secrets/crush-tokens"),
            "{name:?}"
        );
        let secrets = service["secrets"].as_sequence().unwrap();
        assert!(secrets.iter().any(|s| s.as_str() == Some("crush-tokens")));
    }
    assert_eq!(nodes, 3);
}
