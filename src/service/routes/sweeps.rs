//! `/v1/sweeps`: a base case and value lists → one job per combination, all or nothing; the
//! sweep's table of results as JSON or CSV; the list of sweeps, newest first; and deleting a
//! finished sweep with its jobs.

use super::answers::csv_response;
use super::inputs::{json_text, page_limit, parse_id, search_text, wants_csv, FormatParams};
use super::state::{AppState, HttpLimits};
use crate::service::error::ApiError;
use crate::service::guard::{Caller, Role};
use crate::service::store::{Deleted, NewJob, NewSweep, SweepFilter, SweepSubmitted};
use crate::service::sweep::{plan, Refusal};
use crate::service::views::{SweepListItem, SweepPage, SweepView};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Extension, Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use base64::engine::general_purpose::URL_SAFE_NO_PAD;
use base64::Engine;
use serde_json::Value;
use uuid::Uuid;

pub async fn create(
    State(s): State<AppState>,
    Extension(caller): Extension<Caller>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let text = json_text(&headers, body, s.limits.max_body_bytes)?;
    let limits = s.limits.clone();
    let mut sweep = s.cpu.run(move || check(&text, &limits)).await??;
    sweep.owner = caller.name;
    match s.store.create_sweep(sweep, s.limits.max_queue).await? {
        SweepSubmitted::Created(record, jobs) => {
            s.workers.notify();
            let view = SweepView::new(&record, &jobs);
            let location = format!("/v1/sweeps/{}", record.id);
            Ok((
                StatusCode::ACCEPTED,
                [(header::LOCATION, location)],
                Json(view),
            )
                .into_response())
        }
        SweepSubmitted::QueueFull { depth } => Err(ApiError::Unavailable {
            detail: format!(
                "the queue has no room for this sweep ({depth} jobs waiting); try again later"
            ),
            retry_after_s: 10,
        }),
    }
}

/// The body → a sweep with one checked job per combination (every combination is checked
/// before any job exists), or every reason it is not one. CPU work, bounded by the body's size
/// and `--max-sweep-jobs`.
fn check(text: &str, limits: &HttpLimits) -> Result<NewSweep, ApiError> {
    let plan =
        plan(text, &limits.case, limits.max_sweep_jobs).map_err(|refusal| match refusal {
            Refusal::Malformed(e) => ApiError::BadRequest {
                detail: match &e.field {
                    Some(f) => format!("malformed sweep at {f}: {}", e.message),
                    None => format!("malformed sweep: {}", e.message),
                },
                field: e.field,
            },
            Refusal::Invalid(errors) => ApiError::Unprocessable {
                detail: errors
                    .iter()
                    .map(|e| e.to_string())
                    .collect::<Vec<_>>()
                    .join("; "),
                errors,
            },
        })?;
    let parameters_json = Value::Array(
        plan.parameters
            .iter()
            .map(|(f, v)| serde_json::json!([f, v]))
            .collect(),
    )
    .to_string();
    let jobs = plan
        .jobs
        .into_iter()
        .map(|job| {
            let new = NewJob {
                id: Uuid::new_v4(),
                case_json: job.case.to_string(),
                label: job.label,
                particles: job.particles,
                idempotency_key: None,
            };
            (new, Value::Object(job.values).to_string())
        })
        .collect();
    Ok(NewSweep {
        id: Uuid::new_v4(),
        label: plan.label,
        base_json: plan.base.to_string(),
        parameters_json,
        jobs,
        owner: None,
    })
}

pub async fn get(
    State(s): State<AppState>,
    Path(id): Path<String>,
    Query(q): Query<FormatParams>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let uuid = parse_id(&id, "sweep")?;
    let csv = wants_csv(&headers, q.format.as_deref())?;
    let (record, jobs) = s
        .store
        .sweep(uuid)
        .await?
        .ok_or_else(|| ApiError::NotFound {
            what: format!("sweep {id}"),
        })?;
    let view = SweepView::new(&record, &jobs);
    if csv {
        let text = view.csv().map_err(ApiError::internal)?;
        return Ok(csv_response(text, &format!("{id}-sweep.csv")));
    }
    Ok(Json(view).into_response())
}

#[derive(Debug, serde::Deserialize)]
pub struct ListParams {
    search: Option<String>,
    limit: Option<String>,
    cursor: Option<String>,
}

/// Sweeps newest first, each with its jobs counted by status; paged like the jobs.
pub async fn list(
    State(s): State<AppState>,
    Query(p): Query<ListParams>,
) -> Result<Response, ApiError> {
    let limit = page_limit(p.limit.as_deref())?;
    let search = search_text(p.search)?;
    let before = match p.cursor.as_deref() {
        None | Some("") => None,
        Some(c) => Some(decode_cursor(c).ok_or_else(|| {
            ApiError::bad_request("cursor is not one this server gave out", Some("cursor"))
        })?),
    };
    let filter = SweepFilter {
        search,
        before,
        limit: limit + 1,
    };
    let mut listed = s.store.list_sweeps(&filter).await?;
    let next_cursor = if listed.len() > limit as usize {
        listed.truncate(limit as usize);
        listed
            .last()
            .map(|l| encode_cursor(l.record.created_at, l.record.id))
    } else {
        None
    };
    let sweeps: Vec<SweepListItem> = listed.iter().map(SweepListItem::new).collect();
    Ok(Json(SweepPage {
        sweeps,
        next_cursor,
    })
    .into_response())
}

const CURSOR_TAG: &str = "sweeps-before:";

/// Where a page of sweeps ended, as an opaque token.
fn encode_cursor(created_at: i64, id: Uuid) -> String {
    URL_SAFE_NO_PAD.encode(format!("{CURSOR_TAG}{created_at}:{id}"))
}

fn decode_cursor(cursor: &str) -> Option<(i64, Uuid)> {
    let bytes = URL_SAFE_NO_PAD.decode(cursor).ok()?;
    let text = std::str::from_utf8(&bytes).ok()?;
    let (at, id) = text.strip_prefix(CURSOR_TAG)?.split_once(':')?;
    Some((at.parse().ok()?, Uuid::parse_str(id).ok()?))
}

/// Deletes a sweep whose jobs have all finished, with its jobs and everything stored for them.
/// Who may cancel the sweep's jobs may delete it.
pub async fn delete(
    State(s): State<AppState>,
    Extension(caller): Extension<Caller>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let uuid = parse_id(&id, "sweep")?;
    let not_found = || ApiError::NotFound {
        what: format!("sweep {id}"),
    };
    if caller.role < Role::Admin {
        let (record, _) = s.store.sweep(uuid).await?.ok_or_else(not_found)?;
        if !caller.may_cancel(record.owner.as_deref()) {
            return Err(ApiError::Forbidden {
                detail: format!(
                    "sweep {id} was submitted by {}; the token {} may delete only its own \
                     sweeps (an admin token may delete any)",
                    record
                        .owner
                        .as_deref()
                        .unwrap_or("a client without a token"),
                    caller.name.as_deref().unwrap_or("?")
                ),
            });
        }
    }
    match s.store.delete_sweep(uuid).await? {
        Deleted::NotFound => Err(not_found()),
        Deleted::Unfinished(_, n) => Err(ApiError::Conflict {
            detail: format!(
                "{n} of the jobs of sweep {id} are queued or running; a sweep can be deleted \
                 once all its jobs have finished (cancel them first)"
            ),
        }),
        Deleted::InSweep(_) | Deleted::Done { .. } => Ok(StatusCode::NO_CONTENT.into_response()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_cursor_is_opaque_and_round_trips() {
        let id = Uuid::new_v4();
        let c = encode_cursor(1_700_000_000_123, id);
        assert!(!c.contains(&id.to_string()));
        assert_eq!(decode_cursor(&c), Some((1_700_000_000_123, id)));
        for bad in ["", "abc", &URL_SAFE_NO_PAD.encode("jobs-before:5")] {
            assert_eq!(decode_cursor(bad), None, "{bad}");
        }
    }
}
