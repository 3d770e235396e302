//! `/v1/jobs`: submit, list, read, cancel and delete (what a succeeded job leaves is in
//! `results`).

use super::inputs::{body_error, json_text, page_limit, parse_id, search_text};
use super::state::{AppState, HttpLimits};
use crate::service::error::ApiError;
use crate::service::guard::Caller;
use crate::service::store::{CancelOutcome, Deleted, ListFilter, NewJob, Status, Submitted};
use crate::service::views::{JobPage, JobView};
use crate::solver::model::case::{object_from_json, spec_from_value};
use crate::solver::model::input::clip;
use crate::solver::Case;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Extension, Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use base64::engine::general_purpose::URL_SAFE_NO_PAD;
use base64::Engine;
use serde::Deserialize;
use serde_json::Value;
use uuid::Uuid;

const MAX_KEY_CHARS: usize = 200;

/// Case JSON text (one object, every key once) → a job ready to insert, or every reason it is
/// not a case.
fn prepare(text: &str, limits: &HttpLimits, key: Option<String>) -> Result<NewJob, ApiError> {
    let case = Value::Object(object_from_json(text)?);
    let spec = spec_from_value(&case)?;
    let label = spec.label.clone();
    let checked = Case::parse(spec, &limits.case)?;
    Ok(NewJob {
        id: Uuid::new_v4(),
        // Stored as submitted, in a canonical form so that a retried submit compares equal.
        case_json: case.to_string(),
        label,
        particles: checked.particle_count(),
        idempotency_key: key,
    })
}

fn idempotency_key(headers: &HeaderMap) -> Result<Option<String>, ApiError> {
    let Some(value) = headers.get("idempotency-key") else {
        return Ok(None);
    };
    let key = value.to_str().map_err(|_| {
        ApiError::bad_request(
            "Idempotency-Key must be visible ASCII",
            Some("Idempotency-Key"),
        )
    })?;
    let key = key.trim().trim_matches('"');
    if key.is_empty() || key.chars().count() > MAX_KEY_CHARS {
        return Err(ApiError::bad_request(
            format!("Idempotency-Key must be 1 to {MAX_KEY_CHARS} characters"),
            Some("Idempotency-Key"),
        ));
    }
    Ok(Some(key.to_string()))
}

/// `202 Accepted` with `Location` and the job.
fn accepted(view: JobView, replayed: bool) -> Response {
    let location = view.links.this.clone();
    let mut response = (
        StatusCode::ACCEPTED,
        [(header::LOCATION, location)],
        Json(view),
    )
        .into_response();
    if replayed {
        response.headers_mut().insert(
            "idempotent-replayed",
            header::HeaderValue::from_static("true"),
        );
    }
    response
}

pub async fn submit(
    State(s): State<AppState>,
    Extension(caller): Extension<Caller>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let text = json_text(&headers, body, s.limits.max_body_bytes)?;
    let key = idempotency_key(&headers)?;
    let limits = s.limits.clone();
    let job = s.cpu.run(move || prepare(&text, &limits, key)).await??;
    let owner = caller.name.as_deref();
    match s.store.submit_owned(job, owner, s.limits.max_queue).await? {
        Submitted::Created(r) => {
            s.workers.notify();
            Ok(accepted(JobView::new(&r, true), false))
        }
        Submitted::Replayed(r) => Ok(accepted(JobView::new(&r, true), true)),
        Submitted::KeyReused => Err(ApiError::Unprocessable {
            detail: "Idempotency-Key was used before with a different case".into(),
            errors: vec![crate::solver::FieldError {
                field: "Idempotency-Key".into(),
                reason: "was used before with a different case".into(),
            }],
        }),
        Submitted::QueueFull { depth } => Err(ApiError::Unavailable {
            detail: format!("the queue is full ({depth} jobs waiting); try again later"),
            retry_after_s: 10,
        }),
    }
}

#[derive(Debug, Deserialize)]
pub struct ListParams {
    status: Option<String>,
    label: Option<String>,
    search: Option<String>,
    limit: Option<String>,
    cursor: Option<String>,
}

pub async fn list(
    State(s): State<AppState>,
    Query(p): Query<ListParams>,
) -> Result<Response, ApiError> {
    let mut statuses = Vec::new();
    for name in p.status.iter().flat_map(|s| s.split(',')).map(str::trim) {
        // An empty item (`status=` or `status=,`) is refused like any other non-status, as the
        // contract's enum says (schemathesis found `status=,` answered 200).
        let status = Status::parse(name).ok_or_else(|| {
            ApiError::bad_request(
                format!(
                    "status {:?} is not one of queued, running, succeeded, failed, cancelled",
                    clip(name)
                ),
                Some("status"),
            )
        })?;
        statuses.push(status);
    }
    let limit = page_limit(p.limit.as_deref())?;
    let search = search_text(p.search)?;
    let before = match p.cursor.as_deref() {
        None | Some("") => None,
        Some(c) => Some(decode_cursor(c).ok_or_else(|| {
            ApiError::bad_request("cursor is not one this server gave out", Some("cursor"))
        })?),
    };
    let filter = ListFilter {
        statuses,
        label: p.label,
        search,
        before,
        limit: limit + 1,
    };
    let mut records = s.store.list(&filter).await?;
    let next_cursor = if records.len() > limit as usize {
        records.truncate(limit as usize);
        records.last().map(|r| encode_cursor(r.seq))
    } else {
        None
    };
    let jobs: Vec<JobView> = records.iter().map(|r| JobView::new(r, false)).collect();
    let stored = s.store.counts().await?;
    let counts = Status::ALL
        .iter()
        .map(|st| {
            let n = stored.iter().find(|(x, _)| x == st).map_or(0, |(_, n)| *n);
            (st.as_str().to_string(), n)
        })
        .collect();
    let page = JobPage {
        jobs,
        next_cursor,
        counts,
    };
    Ok(Json(page).into_response())
}

/// The list cursor clients get: where the page ended, tagged and base64url-encoded so that it
/// reads as the opaque token the contract promises (and can change form without breaking
/// clients).
fn encode_cursor(seq: i64) -> String {
    URL_SAFE_NO_PAD.encode(format!("{CURSOR_TAG}{seq}"))
}

fn decode_cursor(cursor: &str) -> Option<i64> {
    let bytes = URL_SAFE_NO_PAD.decode(cursor).ok()?;
    let text = std::str::from_utf8(&bytes).ok()?;
    let seq: i64 = text.strip_prefix(CURSOR_TAG)?.parse().ok()?;
    (seq > 0).then_some(seq)
}

const CURSOR_TAG: &str = "jobs-before:";

pub async fn get(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Json<JobView>, ApiError> {
    let uuid = parse_id(&id, "job")?;
    let record = s
        .store
        .job(uuid)
        .await?
        .ok_or_else(|| ApiError::job_not_found(&id))?;
    Ok(Json(JobView::new(&record, true)))
}

/// Cancels a job: its submitter or an admin may. The body is empty or `{}`.
pub async fn cancel(
    State(s): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let uuid = parse_id(&id, "job")?;
    no_fields(body, s.limits.max_body_bytes)?;
    if caller.role < crate::service::guard::Role::Admin {
        let record = s
            .store
            .job(uuid)
            .await?
            .ok_or_else(|| ApiError::job_not_found(&id))?;
        // The owner of a job never changes, so this holds when the cancel below runs.
        if !caller.may_cancel(record.owner.as_deref()) {
            return Err(ApiError::Forbidden {
                detail: format!(
                    "job {id} was submitted by {}; the token {} may cancel only its own jobs \
                     (an admin token may cancel any)",
                    record
                        .owner
                        .as_deref()
                        .unwrap_or("a client without a token"),
                    caller.name.as_deref().unwrap_or("?")
                ),
            });
        }
    }
    match s.store.cancel(uuid).await? {
        CancelOutcome::NotFound => Err(ApiError::job_not_found(&id)),
        CancelOutcome::Finished(status) => Err(ApiError::Conflict {
            detail: format!(
                "job {id} is already {}; only a queued or running job can be cancelled",
                status.as_str()
            ),
        }),
        CancelOutcome::Cancelled(r) => {
            Ok((StatusCode::OK, Json(JobView::new(&r, false))).into_response())
        }
        CancelOutcome::Requested(r) => {
            s.workers.cancel(uuid);
            let body = CancelAccepted {
                job: JobView::new(&r, false),
                note: CANCEL_WINS,
            };
            Ok((StatusCode::ACCEPTED, Json(body)).into_response())
        }
    }
}

/// Deletes a finished job that belongs to no sweep: its row, summary, history and final state.
/// Who may cancel a job may delete it.
pub async fn delete(
    State(s): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let uuid = parse_id(&id, "job")?;
    if caller.role < crate::service::guard::Role::Admin {
        let record = s
            .store
            .job(uuid)
            .await?
            .ok_or_else(|| ApiError::job_not_found(&id))?;
        if !caller.may_cancel(record.owner.as_deref()) {
            return Err(ApiError::Forbidden {
                detail: format!(
                    "job {id} was submitted by {}; the token {} may delete only its own jobs \
                     (an admin token may delete any)",
                    record
                        .owner
                        .as_deref()
                        .unwrap_or("a client without a token"),
                    caller.name.as_deref().unwrap_or("?")
                ),
            });
        }
    }
    match s.store.delete_job(uuid).await? {
        Deleted::NotFound => Err(ApiError::job_not_found(&id)),
        Deleted::Unfinished(status, _) => Err(ApiError::Conflict {
            detail: format!(
                "job {id} is {}; only a finished job can be deleted (cancel it first)",
                status.as_str()
            ),
        }),
        Deleted::InSweep(sweep) => Err(ApiError::Conflict {
            detail: format!(
                "job {id} belongs to sweep {sweep}; it is deleted with its sweep \
                 (DELETE /v1/sweeps/{sweep})"
            ),
        }),
        Deleted::Done { .. } => Ok(StatusCode::NO_CONTENT.into_response()),
    }
}

/// A body that is empty or the empty JSON object: what a cancel takes.
fn no_fields(body: Result<Bytes, BytesRejection>, limit: usize) -> Result<(), ApiError> {
    let bytes = body.map_err(|e| body_error(e, limit))?;
    let text = String::from_utf8_lossy(&bytes);
    let empty = text.trim().is_empty()
        || serde_json::from_str::<serde_json::Map<String, serde_json::Value>>(&text)
            .is_ok_and(|m| m.is_empty());
    if empty {
        Ok(())
    } else {
        Err(ApiError::bad_request(
            "a cancel takes no fields: send an empty body or {}",
            None,
        ))
    }
}

/// What a 202 to a cancel promises. The store makes it true: the result of a run is stored in
/// one transaction that first checks for a cancel, so a cancel answered 202 always comes first.
pub const CANCEL_WINS: &str = "the cancel wins: the job will end cancelled, even if its run \
     completes before the solver stops, and nothing of the run is kept";

/// The 202 answer to a cancel of a running job.
#[derive(Debug, serde::Serialize)]
struct CancelAccepted {
    #[serde(flatten)]
    job: JobView,
    note: &'static str,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cursor_is_opaque_and_round_trips() {
        // What broke: the cursor was the raw row number.
        for seq in [1, 42, i64::MAX] {
            let c = encode_cursor(seq);
            assert!(c.parse::<i64>().is_err(), "{c}");
            assert_eq!(decode_cursor(&c), Some(seq));
        }
        for bad in [
            "42",
            "abc",
            "",
            "!!",
            &URL_SAFE_NO_PAD.encode("jobs-before:0"),
        ] {
            assert_eq!(decode_cursor(bad), None, "{bad}");
        }
    }
}
