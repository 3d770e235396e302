//! `/v1/session`: the web page's token. A browser cannot add an `Authorization` header to an
//! event stream, a picture or a download link, so the page trades its token once for an
//! `HttpOnly; SameSite=Strict` cookie that the guard reads like the header.

use super::inputs::json_text;
use super::state::AppState;
use crate::service::error::ApiError;
use crate::service::guard::{Caller, Role, COOKIE};
use crate::solver::model::input::user_message;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Extension, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How long the page keeps its token: a lab's browser signs in once a month.
const KEEP_DAYS: i64 = 30;

/// Who the caller is.
#[derive(Debug, Serialize, JsonSchema)]
#[schemars(rename = "Session")]
pub struct SessionView {
    /// Whether this server asks for tokens at all.
    tokens_required: bool,
    /// The caller's token name; null without one (or without tokens).
    name: Option<String>,
    /// What the caller may do; null when it may do nothing but open the page.
    role: Option<Role>,
}

impl SessionView {
    fn new(s: &AppState, caller: Option<&Caller>) -> SessionView {
        SessionView {
            tokens_required: s.guard.has_tokens(),
            name: caller.and_then(|c| c.name.clone()),
            role: caller.map(|c| c.role),
        }
    }
}

pub async fn show(
    State(s): State<AppState>,
    caller: Option<Extension<Caller>>,
) -> Json<SessionView> {
    Json(SessionView::new(&s, caller.as_deref()))
}

#[derive(Debug, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub(crate) struct SignIn {
    /// The token, as the token file holds it.
    token: String,
}

/// Checks a token and hands it back as the page's cookie.
pub async fn sign_in(
    State(s): State<AppState>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let text = json_text(&headers, body, s.limits.max_body_bytes)?;
    let request: SignIn = serde_json::from_str(&text).map_err(|e| {
        ApiError::bad_request(
            format!(
                "a sign-in is {{\"token\": \"…\"}}: {}",
                user_message(&e.to_string())
            ),
            Some("token"),
        )
    })?;
    if !s.guard.has_tokens() {
        return Err(ApiError::Conflict {
            detail: "this server has no tokens (no --token-file): every request is allowed \
                     without one"
                .into(),
        });
    }
    let caller = s
        .guard
        .sign_in(request.token.trim())
        .ok_or_else(|| ApiError::Unauthorized {
            detail: "that is not a token of this server".into(),
            invalid_token: true,
        })?;
    let cookie = cookie::Cookie::build((COOKIE, request.token.trim().to_string()))
        .http_only(true)
        .same_site(cookie::SameSite::Strict)
        .path("/")
        .max_age(cookie::time::Duration::days(KEEP_DAYS));
    with_cookie(Json(SessionView::new(&s, Some(&caller))), cookie.build())
}

/// Forgets the page's token.
pub async fn sign_out() -> Result<Response, ApiError> {
    let cookie = cookie::Cookie::build((COOKIE, ""))
        .http_only(true)
        .same_site(cookie::SameSite::Strict)
        .path("/")
        .max_age(cookie::time::Duration::ZERO);
    with_cookie(StatusCode::NO_CONTENT, cookie.build())
}

fn with_cookie(
    answer: impl IntoResponse,
    cookie: cookie::Cookie<'_>,
) -> Result<Response, ApiError> {
    let mut response = answer.into_response();
    // A token holds only header-safe characters (see `tokens`).
    let value = HeaderValue::from_str(&cookie.to_string()).map_err(ApiError::internal)?;
    response.headers_mut().insert(header::SET_COOKIE, value);
    response
        .headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(response)
}
