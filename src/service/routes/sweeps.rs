//! `/v1/sweeps`: a base case and value lists → one job per combination, all or nothing; and
//! the sweep's table of results as JSON or CSV.

use super::jobs::prepare;
use super::{csv_response, json_text, parse_id, wants_csv, AppState, FormatParams};
use crate::service::error::ApiError;
use crate::service::guard::Caller;
use crate::service::store::{NewSweep, SweepSubmitted};
use crate::service::sweep::{expand, parameters, SweepRequest};
use crate::service::views::SweepView;
use crate::solver::FieldError;
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
    // serde would read the struct from an array too.
    if !text.trim_start().starts_with('{') {
        return Err(ApiError::bad_request(
            "malformed sweep: a sweep must be a JSON object",
            None,
        ));
    }
    let de = &mut serde_json::Deserializer::from_str(&text);
    let req: SweepRequest = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
        let path = e.path().to_string();
        let field = (path != "." && !path.is_empty()).then_some(path);
        ApiError::BadRequest {
            detail: format!("malformed sweep: {}", e.inner()),
            field,
        }
    })?;
    de.end()
        .map_err(|e| ApiError::bad_request(format!("text after the sweep: {e}"), None))?;
    let params = parameters(&req, s.limits.max_sweep_jobs).map_err(unprocessable)?;
    let mut base = req.base.clone();
    if let (Some(label), Some(object)) = (&req.label, base.as_object_mut()) {
        object
            .entry("label")
            .or_insert_with(|| Value::String(label.clone()));
    }
    let combos = expand(&base, &params).map_err(unprocessable)?;

    // Every combination is checked before any job exists.
    let mut jobs = Vec::with_capacity(combos.len());
    let mut errors: Vec<FieldError> = Vec::new();
    for combo in &combos {
        let at = combo
            .values
            .iter()
            .map(|(f, v)| format!("{f} = {v}"))
            .collect::<Vec<_>>()
            .join(", ");
        match prepare(&combo.case.to_string(), &s.limits, None) {
            Ok(job) => jobs.push((job, Value::Object(combo.values.clone()).to_string())),
            Err(ApiError::Unprocessable { errors: found, .. }) => {
                errors.extend(found.into_iter().map(|e| FieldError {
                    reason: format!("{} (with {at})", e.reason),
                    ..e
                }))
            }
            Err(ApiError::BadRequest { detail, field }) => errors.push(FieldError {
                field: field.unwrap_or_else(|| "base".into()),
                reason: format!("{detail} (with {at})"),
            }),
            Err(other) => return Err(other),
        }
    }
    if !errors.is_empty() {
        return Err(unprocessable(errors));
    }
    let parameters_json = Value::Array(
        params
            .iter()
            .map(|(f, v)| serde_json::json!([f, v]))
            .collect(),
    )
    .to_string();
    let sweep = NewSweep {
        id: Uuid::new_v4(),
        label: req.label,
        base_json: req.base.to_string(),
        parameters_json,
        jobs,
        owner: caller.name,
    };
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

fn unprocessable(errors: Vec<FieldError>) -> ApiError {
    let mut unique: Vec<FieldError> = Vec::new();
    for e in errors {
        if !unique.contains(&e) {
            unique.push(e);
        }
    }
    ApiError::Unprocessable {
        detail: unique
            .iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("; "),
        errors: unique,
    }
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
