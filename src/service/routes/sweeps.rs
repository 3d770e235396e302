//! `/v1/sweeps`: a base case and value lists → one job per combination, all or nothing; and
//! the sweep's table of results as JSON or CSV.

use super::{csv_response, json_text, parse_id, wants_csv, AppState, FormatParams, HttpLimits};
use crate::service::error::ApiError;
use crate::service::guard::Caller;
use crate::service::store::{NewJob, NewSweep, SweepSubmitted};
use crate::service::sweep::{plan, Refusal};
use crate::service::views::SweepView;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Extension, Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
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
