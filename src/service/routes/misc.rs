//! `/healthz`, Prometheus `/metrics`, and `POST /v1/estimate` (its wall times at the rates
//! measured on this server's finished jobs).

use super::inputs::json_text;
use super::state::AppState;
use crate::service::error::{ApiError, STORE_RETRY_AFTER_S};
use crate::service::metrics;
use crate::service::store::{Status, StoreError};
use crate::solver::{estimate_with, model::case::spec_from_json, Case, Estimate};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::{header, HeaderMap};
use axum::response::{IntoResponse, Response};
use axum::Json;
use std::sync::atomic::Ordering;

/// 200 while the database can be written (a one-row write commits in time and the file is the
/// one opened); else 503 naming why, with `Retry-After`.
pub async fn healthz(State(s): State<AppState>) -> Result<Response, ApiError> {
    s.store.probe_write().await.map_err(|e| {
        tracing::error!(error = %e, "health check: the database cannot be written");
        let detail = match &e {
            StoreError::FileGone(why) => why.clone(),
            _ => "the database cannot be written".into(),
        };
        ApiError::Unavailable {
            detail,
            retry_after_s: STORE_RETRY_AFTER_S,
        }
    })?;
    Ok(Json(serde_json::json!({ "status": "ok", "database": "writable" })).into_response())
}

pub async fn metrics(State(s): State<AppState>) -> Result<Response, ApiError> {
    let counts = s.store.counts().await?;
    let of = |status| {
        counts
            .iter()
            .find(|(st, _)| *st == status)
            .map_or(0, |(_, n)| *n)
    };
    let (running_here, rate) = s.workers.load();
    let text = metrics::encode(&metrics::Snapshot {
        jobs: Status::ALL
            .iter()
            .map(|st| (st.as_str(), of(*st)))
            .collect(),
        queued: of(Status::Queued),
        running_here: running_here as i64,
        particle_steps_per_s: rate,
        sse_clients: s.limits_sse_open() as i64,
        particle_steps_total: s.workers.particle_steps_total.load(Ordering::Relaxed),
        node: s.workers.node(),
        backend: s.store.backend_name(),
        claim_seconds: &s.workers.claim_seconds,
    })
    .map_err(ApiError::internal)?;
    Ok(([(header::CONTENT_TYPE, metrics::CONTENT_TYPE)], text).into_response())
}

impl AppState {
    fn limits_sse_open(&self) -> usize {
        self.limits
            .max_sse_clients
            .saturating_sub(self.sse_permits.available_permits())
    }
}

pub async fn estimate(
    State(s): State<AppState>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<Estimate>, ApiError> {
    let text = json_text(&headers, body, s.limits.max_body_bytes)?;
    let limits = s.limits.case;
    let threads = s.workers.threads_per_job() as u32;
    let rates = super::plan::calibrated_rates(&s).await;
    let estimate = s
        .cpu
        .run(move || -> Result<Estimate, ApiError> {
            let case = Case::parse(spec_from_json(&text)?, &limits)?;
            Ok(estimate_with(&case, threads, &rates))
        })
        .await??;
    Ok(Json(estimate))
}
