//! The HTTP layer: [`app`] builds the router from one route table (which the contract test
//! compares with `api/openapi.yaml`); handlers talk only to the store, the hub and the workers.

mod events;
mod jobs;
mod misc;
mod page;
mod plan;
mod results;
mod series;
mod session;
mod sweeps;

pub(crate) use plan::PlanRequest;
pub(crate) use session::{SessionView, SignIn};

use super::connection::{body_deadline, BodyTimedOut};
use super::error::{ApiError, PROBLEM_JSON};
use super::guard::{self, Guard};
use super::hub::Hub;
use super::store::Store;
use super::worker::Workers;
use crate::solver::model::input::{clip, user_message};
use crate::solver::Limits;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{DefaultBodyLimit, Request};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{delete, get, post, MethodRouter};
use axum::{middleware, Router};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{watch, Semaphore};

/// Limits and settings the handlers apply.
#[derive(Debug, Clone)]
pub struct HttpLimits {
    pub max_body_bytes: usize,
    /// What a case may cost (particles, steps, particle-steps).
    pub case: Limits,
    pub max_queue: u64,
    pub max_sweep_jobs: usize,
    pub max_sse_clients: usize,
    pub keep_alive: Duration,
    /// How often an SSE stream re-reads the job from the store (catches what the hub cannot:
    /// jobs run by another process).
    pub sse_poll: Duration,
    /// Slowest average a heavy download may be taken at, bytes a second (0: any).
    pub min_download_rate: u64,
    /// Longest a request body may take to arrive whole.
    pub body_timeout: Duration,
}

/// What every handler can reach.
#[derive(Clone)]
pub struct AppState {
    pub store: Store,
    pub hub: Arc<Hub>,
    pub workers: Arc<Workers>,
    pub limits: Arc<HttpLimits>,
    /// One permit per open SSE stream.
    pub sse_permits: Arc<Semaphore>,
    /// One slot per heavy answer being built or sent (VTU file, particle table, frames,
    /// archive, picture, long history): they cost memory in proportion to the particles or rows.
    pub heavy: Arc<super::downloads::Slots>,
    /// Turns at the CPU for handlers that read and check cases and sweeps.
    pub cpu: super::cpu::CpuGate,
    /// Becomes true when the server shuts down; open SSE streams end then.
    pub shutdown: watch::Receiver<bool>,
    /// Who may do what.
    pub guard: Arc<Guard>,
}

/// The routes: method, path, handler.
fn table() -> Vec<(&'static str, &'static str, MethodRouter<AppState>)> {
    vec![
        ("GET", "/", get(page::index)),
        ("GET", "/assets/{name}", get(page::asset)),
        ("GET", "/v1/case/fields", get(page::case_fields)),
        ("GET", "/healthz", get(misc::healthz)),
        ("GET", "/metrics", get(misc::metrics)),
        ("POST", "/v1/estimate", post(misc::estimate)),
        ("POST", "/v1/plan", post(plan::plan)),
        ("POST", "/v1/jobs", post(jobs::submit)),
        ("GET", "/v1/jobs", get(jobs::list)),
        ("GET", "/v1/jobs/{id}", get(jobs::get)),
        ("DELETE", "/v1/jobs/{id}", delete(jobs::delete)),
        ("POST", "/v1/jobs/{id}/cancel", post(jobs::cancel)),
        ("GET", "/v1/jobs/{id}/history", get(results::history)),
        ("GET", "/v1/jobs/{id}/summary", get(results::summary)),
        ("GET", "/v1/jobs/{id}/plot.svg", get(results::plot_svg)),
        ("GET", "/v1/jobs/{id}/shape.png", get(results::shape_png)),
        ("GET", "/v1/jobs/{id}/state.vtu", get(results::state_vtu)),
        (
            "GET",
            "/v1/jobs/{id}/particles.csv",
            get(results::particles_csv),
        ),
        ("GET", "/v1/jobs/{id}/series.pvd", get(series::series_pvd)),
        ("GET", "/v1/jobs/{id}/series.tar", get(series::series_tar)),
        ("GET", "/v1/jobs/{id}/frames/{name}", get(series::frame_vtu)),
        ("GET", "/v1/jobs/{id}/events", get(events::events)),
        ("POST", "/v1/sweeps", post(sweeps::create)),
        ("GET", "/v1/sweeps", get(sweeps::list)),
        ("GET", "/v1/sweeps/{id}", get(sweeps::get)),
        ("DELETE", "/v1/sweeps/{id}", delete(sweeps::delete)),
        ("GET", "/v1/session", get(session::show)),
        ("POST", "/v1/session", post(session::sign_in)),
        ("DELETE", "/v1/session", delete(session::sign_out)),
    ]
}

/// Every (method, path) the server answers.
pub fn routes() -> Vec<(&'static str, &'static str)> {
    table().into_iter().map(|(m, p, _)| (m, p)).collect()
}

/// The whole HTTP application.
pub fn app(state: AppState) -> Router {
    let limit = state.limits.max_body_bytes;
    let body_timeout = state.limits.body_timeout;
    let guard = state.guard.clone();
    let mut router = Router::new();
    for (_, path, handler) in table() {
        router = router.route(path, handler);
    }
    router
        .fallback(no_route)
        .layer(DefaultBodyLimit::max(limit))
        .layer(middleware::from_fn_with_state(body_timeout, body_deadline))
        .layer(middleware::from_fn_with_state(guard, guard::check))
        .layer(middleware::map_response(problem_everywhere))
        .layer(middleware::map_response(guard::security_headers))
        .layer(tower_http::trace::TraceLayer::new_for_http())
        .with_state(state)
}

async fn no_route(request: Request) -> ApiError {
    ApiError::NoRoute {
        method: request.method().to_string(),
        path: clip(request.uri().path()).into_owned(),
    }
}

/// Turns any error response not already a problem (axum's own rejections, 405) into one.
async fn problem_everywhere(response: Response) -> Response {
    let status = response.status();
    let is_problem = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(PROBLEM_JSON.as_bytes()));
    if !(status.is_client_error() || status.is_server_error()) || is_problem {
        return response;
    }
    let (parts, body) = response.into_parts();
    let text = axum::body::to_bytes(body, 4096).await.unwrap_or_default();
    let detail = user_message(String::from_utf8_lossy(&text).trim());
    let error = match status {
        StatusCode::METHOD_NOT_ALLOWED => ApiError::MethodNotAllowed,
        StatusCode::PAYLOAD_TOO_LARGE => ApiError::TooLarge { limit: 0 },
        StatusCode::UNSUPPORTED_MEDIA_TYPE => ApiError::UnsupportedMediaType(detail),
        s if s.is_client_error() => ApiError::bad_request(detail, None),
        _ => ApiError::Internal(detail.into()),
    };
    let mut problem = error.into_response();
    *problem.status_mut() = status;
    for name in [header::ALLOW, header::RETRY_AFTER, header::WWW_AUTHENTICATE] {
        if let Some(value) = parts.headers.get(&name) {
            problem.headers_mut().insert(name, value.clone());
        }
    }
    problem
}

/// The body of a JSON request as text, for every route that takes one: checks the content
/// type (a body without one is 415, as for any other type), the size and UTF-8.
pub(crate) fn json_text(
    headers: &HeaderMap,
    body: Result<Bytes, BytesRejection>,
    limit: usize,
) -> Result<String, ApiError> {
    let ct = headers
        .get(header::CONTENT_TYPE)
        .map(|ct| ct.to_str().unwrap_or("").to_ascii_lowercase());
    let essence = ct
        .as_deref()
        .map(|ct| ct.split(';').next().unwrap_or("").trim());
    match essence {
        Some(e) if e == "application/json" || e.ends_with("+json") => {}
        Some(e) => return Err(ApiError::UnsupportedMediaType(clip(e).into_owned())),
        None => return Err(ApiError::UnsupportedMediaType("(none)".into())),
    }
    let bytes = body.map_err(|e| body_error(e, limit))?;
    String::from_utf8(bytes.to_vec())
        .map_err(|_| ApiError::bad_request("the body is not UTF-8", None))
}

/// Why a request body could not be read: it came too late (408), is over `limit` (413), or
/// broke off (400).
pub(crate) fn body_error(e: BytesRejection, limit: usize) -> ApiError {
    if let Some(late) = BodyTimedOut::within(&e) {
        ApiError::BodyTimeout {
            seconds: late.seconds,
        }
    } else if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
        ApiError::TooLarge { limit }
    } else {
        ApiError::bad_request(format!("could not read the body: {e}"), None)
    }
}

/// Jobs or sweeps a list page holds unless `?limit=` says otherwise, and at most.
const DEFAULT_PAGE: u32 = 50;
const MAX_PAGE: u32 = 500;

/// Longest `?search=` text, characters.
pub(crate) const MAX_SEARCH_CHARS: usize = 100;

/// `?limit=` of a list: an integer in [1, 500], 50 when absent.
pub(crate) fn page_limit(raw: Option<&str>) -> Result<u32, ApiError> {
    match raw {
        None => Ok(DEFAULT_PAGE),
        Some(l) => l
            .parse::<u32>()
            .ok()
            .filter(|l| (1..=MAX_PAGE).contains(l))
            .ok_or_else(|| {
                ApiError::bad_request(
                    format!("limit must be an integer in [1, {MAX_PAGE}]"),
                    Some("limit"),
                )
            }),
    }
}

/// `?search=` of a list: text a label must contain, 1 to [`MAX_SEARCH_CHARS`] characters
/// (empty: no filter).
pub(crate) fn search_text(raw: Option<String>) -> Result<Option<String>, ApiError> {
    match raw {
        Some(t) if t.chars().count() > MAX_SEARCH_CHARS => Err(ApiError::bad_request(
            format!("search must be at most {MAX_SEARCH_CHARS} characters"),
            Some("search"),
        )),
        Some(t) if !t.is_empty() => Ok(Some(t)),
        _ => Ok(None),
    }
}

/// Whether the client asked for CSV, by `Accept` or by `?format=csv`.
pub(crate) fn wants_csv(headers: &HeaderMap, format: Option<&str>) -> Result<bool, ApiError> {
    match format {
        Some("csv") => return Ok(true),
        Some("json") => return Ok(false),
        Some(other) => {
            return Err(ApiError::bad_request(
                format!("format must be csv or json, not {:?}", clip(other)),
                Some("format"),
            ))
        }
        None => {}
    }
    let accept = headers
        .get(header::ACCEPT)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("");
    Ok(accept
        .split(',')
        .any(|m| m.split(';').next().unwrap_or("").trim() == "text/csv"))
}

/// `?format=csv|json` of the routes that answer either.
#[derive(Debug, serde::Deserialize)]
pub struct FormatParams {
    pub format: Option<String>,
}

/// A file-like answer: its content type, an optional `Content-Disposition` and an optional
/// `Cache-Control`.
pub(crate) fn file_response(
    content_type: &'static str,
    disposition: Option<String>,
    cache: Option<&'static str>,
    body: impl IntoResponse,
) -> Response {
    let mut response = body.into_response();
    let headers = response.headers_mut();
    headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    // Our file names are built from UUIDs: always a valid header value.
    if let Some(value) = disposition.and_then(|d| HeaderValue::from_str(&d).ok()) {
        headers.insert(header::CONTENT_DISPOSITION, value);
    }
    if let Some(cache) = cache {
        headers.insert(header::CACHE_CONTROL, HeaderValue::from_static(cache));
    }
    response
}

/// A CSV response.
pub(crate) fn csv_response(text: String, filename: &str) -> Response {
    file_response(
        "text/csv; charset=utf-8",
        Some(format!("inline; filename=\"{filename}\"")),
        None,
        text,
    )
}

/// A path id: a UUID in the hyphenated form this server gives out (8-4-4-4-12 hex digits,
/// either case), or the thing is not found. The braced, `urn:uuid:` and plain-hex spellings
/// `Uuid::parse_str` also reads are 404 too: one resource, one URL.
pub(crate) fn parse_id(raw: &str, what: &str) -> Result<uuid::Uuid, ApiError> {
    let not_found = || ApiError::NotFound {
        what: format!("{what} {}", clip(raw)),
    };
    if raw.len() != 36 {
        return Err(not_found());
    }
    uuid::Uuid::parse_str(raw).map_err(|_| not_found())
}
