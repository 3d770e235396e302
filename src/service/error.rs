//! The one error type of the HTTP layer, answered as RFC 9457 `application/problem+json`.
//! Internal failures are logged and answered with a generic detail: nothing internal leaks.

use crate::solver::model::input::clip;
use crate::solver::{CaseError, FieldError};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use schemars::JsonSchema;
use serde::Serialize;

pub const PROBLEM_JSON: &str = "application/problem+json";

#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// Malformed JSON, a wrong type, a bad query parameter or header.
    #[error("{detail}")]
    BadRequest {
        detail: String,
        field: Option<String>,
    },
    #[error("{what} not found")]
    NotFound { what: String },
    #[error("no route {method} {path}")]
    NoRoute { method: String, path: String },
    #[error("method not allowed")]
    MethodNotAllowed,
    #[error("{detail}")]
    Conflict { detail: String },
    #[error("{}", too_large(*limit))]
    TooLarge { limit: usize },
    /// The content type the client sent, quoted at most [`clip`]'s length, whoever refuses it.
    #[error("unsupported content type {:?}; send application/json", clip(.0))]
    UnsupportedMediaType(String),
    /// Parses, but makes no physical or computational sense: every field named.
    #[error("{detail}")]
    Unprocessable {
        detail: String,
        errors: Vec<FieldError>,
    },
    #[error("{detail}")]
    Unavailable { detail: String, retry_after_s: u32 },
    /// No valid token where one is needed (answered with `WWW-Authenticate: Bearer`).
    #[error("{detail}")]
    Unauthorized {
        detail: String,
        /// The token sent was not one of the server's (RFC 6750's `invalid_token`).
        invalid_token: bool,
    },
    /// A token whose role is too low, or a cross-site request.
    #[error("{detail}")]
    Forbidden { detail: String },
    /// A `Host` this server does not answer to (DNS rebinding).
    #[error(
        "this server does not answer to the host {:?}; it answers to {answers}",
        clip(host)
    )]
    UnknownHost { host: String, answers: String },
    /// The request body did not arrive in time.
    #[error("the request body did not arrive within {seconds} s")]
    BodyTimeout { seconds: f64 },
    #[error("{detail}")]
    TooManyRequests { detail: String, retry_after_s: u32 },
    #[error("internal error")]
    Internal(#[source] Box<dyn std::error::Error + Send + Sync>),
}

fn too_large(limit: usize) -> String {
    match limit {
        0 => "the request body is too large".into(),
        n => format!("the request body is larger than {n} bytes"),
    }
}

/// The problem document (RFC 9457) with our two extension members.
#[derive(Debug, Serialize, JsonSchema)]
#[schemars(description = "RFC 9457 problem details")]
pub(crate) struct Problem<'a> {
    #[serde(rename = "type")]
    kind: &'a str,
    title: &'a str,
    status: u16,
    detail: String,
    /// The field of a 400 (dotted path, or a header or query parameter name).
    #[serde(skip_serializing_if = "Option::is_none")]
    field: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    errors: Option<&'a [FieldError]>,
}

impl ApiError {
    pub fn bad_request(detail: impl Into<String>, field: Option<&str>) -> ApiError {
        ApiError::BadRequest {
            detail: detail.into(),
            field: field.map(String::from),
        }
    }

    pub fn job_not_found(id: &str) -> ApiError {
        ApiError::NotFound {
            what: format!("job {id}"),
        }
    }

    pub fn internal(e: impl std::error::Error + Send + Sync + 'static) -> ApiError {
        ApiError::Internal(Box::new(e))
    }

    /// Status, problem type and title.
    fn parts(&self) -> (StatusCode, &'static str, &'static str) {
        match self {
            ApiError::BadRequest { .. } => (
                StatusCode::BAD_REQUEST,
                "urn:crush:problem:bad-request",
                "Bad request",
            ),
            ApiError::NotFound { .. } => (
                StatusCode::NOT_FOUND,
                "urn:crush:problem:not-found",
                "Not found",
            ),
            ApiError::NoRoute { .. } => (
                StatusCode::NOT_FOUND,
                "urn:crush:problem:no-such-route",
                "No such route",
            ),
            ApiError::MethodNotAllowed => (
                StatusCode::METHOD_NOT_ALLOWED,
                "urn:crush:problem:method-not-allowed",
                "Method not allowed",
            ),
            ApiError::Conflict { .. } => (
                StatusCode::CONFLICT,
                "urn:crush:problem:conflict",
                "Conflict",
            ),
            ApiError::TooLarge { .. } => (
                StatusCode::PAYLOAD_TOO_LARGE,
                "urn:crush:problem:too-large",
                "Request body too large",
            ),
            ApiError::UnsupportedMediaType(_) => (
                StatusCode::UNSUPPORTED_MEDIA_TYPE,
                "urn:crush:problem:unsupported-media-type",
                "Unsupported media type",
            ),
            ApiError::Unprocessable { .. } => (
                StatusCode::UNPROCESSABLE_ENTITY,
                "urn:crush:problem:invalid-case",
                "Invalid case",
            ),
            ApiError::Unavailable { .. } => (
                StatusCode::SERVICE_UNAVAILABLE,
                "urn:crush:problem:unavailable",
                "Service unavailable",
            ),
            ApiError::Unauthorized { .. } => (
                StatusCode::UNAUTHORIZED,
                "urn:crush:problem:unauthorized",
                "Unauthorized",
            ),
            ApiError::Forbidden { .. } => (
                StatusCode::FORBIDDEN,
                "urn:crush:problem:forbidden",
                "Forbidden",
            ),
            ApiError::UnknownHost { .. } => (
                StatusCode::MISDIRECTED_REQUEST,
                "urn:crush:problem:unknown-host",
                "Unknown host",
            ),
            ApiError::BodyTimeout { .. } => (
                StatusCode::REQUEST_TIMEOUT,
                "urn:crush:problem:body-timeout",
                "Request body timeout",
            ),
            ApiError::TooManyRequests { .. } => (
                StatusCode::TOO_MANY_REQUESTS,
                "urn:crush:problem:rate-limited",
                "Too many requests",
            ),
            ApiError::Internal(_) => (
                StatusCode::INTERNAL_SERVER_ERROR,
                "urn:crush:problem:internal",
                "Internal server error",
            ),
        }
    }
}

impl From<CaseError> for ApiError {
    fn from(e: CaseError) -> ApiError {
        match e {
            CaseError::Malformed { field, message } => {
                let detail = match &field {
                    Some(f) => format!("malformed case at {f}: {message}"),
                    None => format!("malformed case: {message}"),
                };
                ApiError::BadRequest { detail, field }
            }
            CaseError::Invalid(errors) => ApiError::Unprocessable {
                detail: errors
                    .iter()
                    .map(|e| e.to_string())
                    .collect::<Vec<_>>()
                    .join("; "),
                errors,
            },
        }
    }
}

impl From<super::store::StoreError> for ApiError {
    /// A database that cannot be used now (full or read-only disk, I/O error, lock held too
    /// long, file deleted) is 503 with `Retry-After`, logged; anything else is a 500.
    fn from(e: super::store::StoreError) -> ApiError {
        if e.is_unavailable() {
            tracing::error!(error = %e, "the database cannot be used: answering 503");
            let detail = match e {
                // Says what happened, without the path.
                super::store::StoreError::FileGone(why) => why,
                _ => "the database cannot be written or read right now; try again later".into(),
            };
            return ApiError::Unavailable {
                detail,
                retry_after_s: STORE_RETRY_AFTER_S,
            };
        }
        ApiError::internal(e)
    }
}

/// `Retry-After` of a 503 for a database that cannot be used, s.
pub const STORE_RETRY_AFTER_S: u32 = 5;

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let (status, kind, title) = self.parts();
        if let ApiError::Internal(e) = &self {
            tracing::error!(error = %e, "request failed");
        }
        let (field, errors) = match &self {
            ApiError::BadRequest { field, .. } => (field.as_deref(), None),
            ApiError::Unprocessable { errors, .. } => (None, Some(errors.as_slice())),
            _ => (None, None),
        };
        let body = Problem {
            kind,
            title,
            status: status.as_u16(),
            detail: self.to_string(),
            field,
            errors,
        };
        let mut response =
            (status, serde_json::to_string(&body).unwrap_or_default()).into_response();
        let headers = response.headers_mut();
        headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON));
        match &self {
            ApiError::Unavailable { retry_after_s, .. }
            | ApiError::TooManyRequests { retry_after_s, .. } => {
                headers.insert(header::RETRY_AFTER, HeaderValue::from(*retry_after_s));
            }
            ApiError::Unauthorized { invalid_token, .. } => {
                let challenge = if *invalid_token {
                    "Bearer realm=\"crush\", error=\"invalid_token\""
                } else {
                    "Bearer realm=\"crush\""
                };
                headers.insert(
                    header::WWW_AUTHENTICATE,
                    HeaderValue::from_static(challenge),
                );
            }
            // The connection is closed after a body that did not arrive: what is left of it
            // cannot be told from the next request.
            ApiError::BodyTimeout { .. } => {
                headers.insert(header::CONNECTION, HeaderValue::from_static("close"));
            }
            _ => {}
        }
        response
    }
}
