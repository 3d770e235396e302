//! The HTTP layer: [`app`] builds the router from one route table (which the contract test
//! compares with `api/openapi.yaml`); handlers talk only to the store, the hub and the workers.

mod answers;
mod events;
mod inputs;
mod jobs;
mod misc;
mod page;
mod plan;
mod results;
mod series;
mod session;
mod state;
mod sweeps;

pub(crate) use plan::PlanRequest;
pub(crate) use session::{SessionView, SignIn};
pub use state::{AppState, HttpLimits};

use super::connection::body_deadline;
use super::error::{ApiError, PROBLEM_JSON};
use super::guard::{self, Cost, Policies, Policy, Role, Who};
use crate::solver::model::input::{clip, user_message};
use axum::extract::{DefaultBodyLimit, Request};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{delete, get, post, MethodRouter};
use axum::{middleware, Router};

/// One route: method, path, who may call it and what a call costs (its policy, which the
/// guard applies), and its handler. Every route declares its policy here, beside itself.
struct Route {
    method: &'static str,
    path: &'static str,
    policy: Policy,
    handler: MethodRouter<AppState>,
}

/// Anyone, light.
const OPEN: Policy = Policy {
    who: Who::Anyone,
    cost: Cost::Light,
};
/// A reader's token, light.
const READ: Policy = Policy {
    who: Who::Role(Role::Read),
    cost: Cost::Light,
};
/// A submitter's token, light (cancel, delete: the handler checks the caller owns it).
const SUBMIT: Policy = Policy {
    who: Who::Role(Role::Submit),
    cost: Cost::Light,
};
/// A submitter's token; each call checks a case or stores work, and is rate-limited.
const SUBMIT_LIMITED: Policy = Policy {
    who: Who::Role(Role::Submit),
    cost: Cost::RateLimited,
};

/// The routes.
fn table() -> Vec<Route> {
    let r = |method, path, policy, handler| Route {
        method,
        path,
        policy,
        handler,
    };
    let flag = |who| Policy {
        who,
        cost: Cost::Light,
    };
    vec![
        r("GET", "/", OPEN, get(page::index)),
        r("GET", "/assets/{name}", OPEN, get(page::asset)),
        r("GET", "/v1/case/fields", READ, get(page::case_fields)),
        r(
            "GET",
            "/healthz",
            flag(Who::HealthzFlag),
            get(misc::healthz),
        ),
        r(
            "GET",
            "/metrics",
            flag(Who::MetricsFlag),
            get(misc::metrics),
        ),
        // An estimate and a plan store nothing, but each checks a case: limited as a submit.
        r("POST", "/v1/estimate", SUBMIT_LIMITED, post(misc::estimate)),
        r("POST", "/v1/plan", SUBMIT_LIMITED, post(plan::plan)),
        r("POST", "/v1/jobs", SUBMIT_LIMITED, post(jobs::submit)),
        r("GET", "/v1/jobs", READ, get(jobs::list)),
        r("GET", "/v1/jobs/{id}", READ, get(jobs::get)),
        r("DELETE", "/v1/jobs/{id}", SUBMIT, delete(jobs::delete)),
        r("POST", "/v1/jobs/{id}/cancel", SUBMIT, post(jobs::cancel)),
        r("GET", "/v1/jobs/{id}/history", READ, get(results::history)),
        r("GET", "/v1/jobs/{id}/summary", READ, get(results::summary)),
        r(
            "GET",
            "/v1/jobs/{id}/plot.svg",
            READ,
            get(results::plot_svg),
        ),
        r(
            "GET",
            "/v1/jobs/{id}/shape.png",
            READ,
            get(results::shape_png),
        ),
        r(
            "GET",
            "/v1/jobs/{id}/state.vtu",
            READ,
            get(results::state_vtu),
        ),
        r(
            "GET",
            "/v1/jobs/{id}/particles.csv",
            READ,
            get(results::particles_csv),
        ),
        r(
            "GET",
            "/v1/jobs/{id}/series.pvd",
            READ,
            get(series::series_pvd),
        ),
        r(
            "GET",
            "/v1/jobs/{id}/series.tar",
            READ,
            get(series::series_tar),
        ),
        r(
            "GET",
            "/v1/jobs/{id}/frames/{name}",
            READ,
            get(series::frame_vtu),
        ),
        r("GET", "/v1/jobs/{id}/events", READ, get(events::events)),
        r("POST", "/v1/sweeps", SUBMIT_LIMITED, post(sweeps::create)),
        r("GET", "/v1/sweeps", READ, get(sweeps::list)),
        r("GET", "/v1/sweeps/{id}", READ, get(sweeps::get)),
        r("DELETE", "/v1/sweeps/{id}", SUBMIT, delete(sweeps::delete)),
        r("GET", "/v1/session", OPEN, get(session::show)),
        // Signing in needs no token, and each try compares one: rate-limited.
        r(
            "POST",
            "/v1/session",
            Policy {
                cost: Cost::RateLimited,
                ..OPEN
            },
            post(session::sign_in),
        ),
        r("DELETE", "/v1/session", OPEN, delete(session::sign_out)),
    ]
}

/// Every (method, path) the server answers.
pub fn routes() -> Vec<(&'static str, &'static str)> {
    table().into_iter().map(|r| (r.method, r.path)).collect()
}

/// Every route's declared policy, for the guard.
pub fn policies() -> Policies {
    let declared: Vec<_> = table()
        .into_iter()
        .map(|r| (r.method, r.path, r.policy))
        .collect();
    Policies::new(&declared)
}

/// The whole HTTP application.
pub fn app(state: AppState) -> Router {
    let limit = state.limits.max_body_bytes;
    let body_timeout = state.limits.body_timeout;
    let guard = state.guard.clone();
    let mut router = Router::new();
    for route in table() {
        router = router.route(route.path, route.handler);
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

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::Method;

    /// A concrete path of a route's pattern: each `{parameter}` filled.
    fn concrete(pattern: &str) -> String {
        pattern
            .split('/')
            .map(|s| match s.starts_with('{') {
                true => "x1",
                false => s,
            })
            .collect::<Vec<_>>()
            .join("/")
    }

    /// Every route's policy is what the guard applies to a request of it, and the policies
    /// keep their rules: the page, its assets and the session open; every other read a
    /// reader's; every other write a submitter's; exactly the calls that check a case, store
    /// work or compare a token rate-limited. A new route declared with a wrong policy fails
    /// here.
    #[test]
    fn every_route_declares_its_policy_and_the_guard_applies_it() {
        let policies = policies();
        let mut limited = Vec::new();
        for route in table() {
            let method = Method::from_bytes(route.method.as_bytes()).unwrap();
            let path = concrete(route.path);
            assert_eq!(
                policies.of(&method, &path),
                route.policy,
                "{} {}",
                route.method,
                route.path
            );
            let open = route.path == "/"
                || route.path.starts_with("/assets/")
                || route.path == "/v1/session";
            let flagged = matches!(route.path, "/healthz" | "/metrics");
            let want = match (open, flagged, route.method) {
                (true, _, _) => Who::Anyone,
                (_, true, "GET") if route.path == "/healthz" => Who::HealthzFlag,
                (_, true, "GET") => Who::MetricsFlag,
                (_, _, "GET") => Who::Role(Role::Read),
                _ => Who::Role(Role::Submit),
            };
            assert_eq!(route.policy.who, want, "{} {}", route.method, route.path);
            if route.policy.cost == Cost::RateLimited {
                limited.push(format!("{} {}", route.method, route.path));
            }
        }
        assert_eq!(
            limited,
            [
                "POST /v1/estimate",
                "POST /v1/plan",
                "POST /v1/jobs",
                "POST /v1/sweeps",
                "POST /v1/session"
            ]
        );
    }
}
