//! The file-like answers of the handlers: a body with its content type, disposition and cache
//! header, and a CSV answer. Imports nothing of the routes; the handler files import it.

use axum::http::{header, HeaderValue};
use axum::response::{IntoResponse, Response};

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
