//! `/healthz`, Prometheus `/metrics`, and `POST /v1/estimate`.

use super::{json_text, AppState};
use crate::service::error::{ApiError, STORE_RETRY_AFTER_S};
use crate::service::store::{Status, StoreError};
use crate::solver::{estimate as solver_estimate, model::case::spec_from_json, Case, Estimate};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::{header, HeaderMap};
use axum::response::{IntoResponse, Response};
use axum::Json;
use std::fmt::Write;
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
    let (running_here, rate) = s.workers.load();
    let sse_open = s.limits_sse_open();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# HELP crush_jobs Jobs in the store, by status.\n# TYPE crush_jobs gauge"
    );
    for status in Status::ALL {
        let n = counts
            .iter()
            .find(|(st, _)| *st == status)
            .map_or(0, |(_, n)| *n);
        let _ = writeln!(out, "crush_jobs{{status=\"{}\"}} {n}", status.as_str());
    }
    let queued = counts
        .iter()
        .find(|(st, _)| *st == Status::Queued)
        .map_or(0, |(_, n)| *n);
    let gauges = [
        ("crush_queue_depth", "Jobs waiting to run.", queued as f64),
        (
            "crush_running_jobs",
            "Jobs running in this process.",
            running_here as f64,
        ),
        (
            "crush_particle_steps_per_second",
            "Current solver throughput of this process.",
            rate,
        ),
        ("crush_sse_clients", "Open event streams.", sse_open as f64),
    ];
    for (name, help, value) in gauges {
        let _ = writeln!(
            out,
            "# HELP {name} {help}\n# TYPE {name} gauge\n{name} {value}"
        );
    }
    // Prometheus' label-value escapes: backslash, quote, newline.
    let node = s
        .workers
        .node()
        .replace('\\', "\\\\")
        .replace('"', "\\\"")
        .replace('\n', "\\n");
    let _ = writeln!(
        out,
        "# HELP crush_node This process: its node name and its store's backend.\n\
         # TYPE crush_node gauge\ncrush_node{{node=\"{node}\",backend=\"{}\"}} 1",
        s.store.backend_name()
    );
    if let Some((values, n)) = s.workers.claim_quantiles(&[0.5, 0.99]) {
        let _ = writeln!(
            out,
            "# HELP crush_claim_seconds Time to claim a job, over this node's last {n} claims \
             that got one (at most {}).\n# TYPE crush_claim_seconds gauge\n\
             crush_claim_seconds{{quantile=\"0.5\"}} {}\n\
             crush_claim_seconds{{quantile=\"0.99\"}} {}",
            crate::service::worker::CLAIM_SAMPLES,
            values[0],
            values[1]
        );
    }
    let total = s.workers.particle_steps_total.load(Ordering::Relaxed);
    let _ = writeln!(
        out,
        "# HELP crush_particle_steps_total Particle-steps of the runs this process finished.\n\
         # TYPE crush_particle_steps_total counter\ncrush_particle_steps_total {total}"
    );
    Ok((
        [(
            header::CONTENT_TYPE,
            "text/plain; version=0.0.4; charset=utf-8",
        )],
        out,
    )
        .into_response())
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
    let estimate = s
        .cpu
        .run(move || -> Result<Estimate, ApiError> {
            let case = Case::parse(spec_from_json(&text)?, &limits)?;
            Ok(solver_estimate(&case, threads))
        })
        .await??;
    Ok(Json(estimate))
}
