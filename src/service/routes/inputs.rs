//! What a handler reads off a request: a JSON body as text, a page size, a search text, the
//! answer's format (CSV or JSON) and a path id, each refused with the API's error. Sizes in
//! bytes and characters. Imports nothing of the routes; the handler files import it.

use crate::service::connection::BodyTimedOut;
use crate::service::error::ApiError;
use crate::solver::model::input::clip;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::http::{header, HeaderMap, StatusCode};

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
