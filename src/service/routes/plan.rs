//! `POST /v1/plan`: a case and a goal (`target_error_percent` or `budget_s`) → the ways to run
//! it, each with its expected error and wall time, and the one to pick. Wall times are
//! calibrated on this server's finished jobs; nothing is run, so a plan costs a database read
//! of
//! [`RATE_JOBS_READ`](crate::service::store::RATE_JOBS_READ) rows and one case check per option.

use super::inputs::json_text;
use super::state::AppState;
use crate::service::error::ApiError;
use crate::solver::analysis::plan::{plan as solver_plan, Goal, Plan};
use crate::solver::analysis::rates::Rates;
use crate::solver::model::case::{spec_from_value, CaseError, CaseSpec};
use crate::solver::model::input::{clip, object_from_str};
use crate::solver::{Case, FieldError};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::HeaderMap;
use axum::Json;
use schemars::JsonSchema;
use serde_json::{Map, Value};

/// Largest target error accepted, %: a mean load off by more is no answer.
pub const MAX_TARGET_ERROR_PERCENT: f64 = 100.0;
/// Longest budget accepted, s (a year).
pub const MAX_BUDGET_S: f64 = 3.2e7;

/// The body of `POST /v1/plan` as the contract describes it: the route reads the body field by
/// field ([`read`]) so that it can name each wrong field with its reason, and this type is that
/// reading's schema.
#[derive(JsonSchema)]
#[allow(dead_code)]
#[schemars(
    deny_unknown_fields,
    description = "The case and one goal (422 on both fields when neither or both are given).",
    extend("oneOf" = [{"required": ["target_error_percent"]}, {"required": ["budget_s"]}])
)]
pub(crate) struct PlanRequest {
    case: CaseSpec,
    /// The largest expected error of the mean load, %.
    #[schemars(default, with = "f64", range(max = 100), extend("exclusiveMinimum" = 0))]
    target_error_percent: Option<f64>,
    /// The longest wall time, s.
    #[schemars(default, with = "f64", range(max = 3.2e7), extend("exclusiveMinimum" = 0))]
    budget_s: Option<f64>,
}

pub async fn plan(
    State(s): State<AppState>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<Plan>, ApiError> {
    let text = json_text(&headers, body, s.limits.max_body_bytes)?;
    let limits = s.limits.case;
    let threads = s.workers.threads_per_job() as u32;
    let rates = calibrated_rates(&s).await;
    let plan = s
        .cpu
        .run(move || -> Result<Plan, ApiError> {
            let (spec, goal) = read(&text)?;
            let case = Case::parse(spec, &limits).map_err(|e| unprocessable(prefixed(e)))?;
            Ok(solver_plan(&case, goal, threads, &rates, &limits))
        })
        .await??;
    Ok(Json(plan))
}

/// The rates measured on this server's latest succeeded jobs; the assumed ones when the
/// database cannot be read (the answer then says `assumed`, and the error is logged).
pub(super) async fn calibrated_rates(s: &AppState) -> Rates {
    match s.store.rate_samples().await {
        Ok(samples) => Rates::calibrated(&samples),
        Err(e) => {
            tracing::warn!(error = %e, "no measured rates: wall times at the assumed rates");
            Rates::assumed()
        }
    }
}

/// The body → the case's fields and the goal, or every field that is wrong: 400 for a body
/// that is not one object with every key once and a case object, as for a sweep; else 422.
fn read(text: &str) -> Result<(CaseSpec, Goal), ApiError> {
    let body = object_from_str(text).map_err(|e| ApiError::BadRequest {
        detail: match &e.field {
            Some(f) => format!("malformed plan request at {f}: {}", e.message),
            None => format!("malformed plan request: {}", e.message),
        },
        field: e.field,
    })?;
    if body.get("case").is_some_and(|case| !case.is_object()) {
        return Err(ApiError::bad_request(
            "malformed plan request at case: must be a case object",
            Some("case"),
        ));
    }
    let mut errors = Vec::new();
    for key in body.keys() {
        if !["case", "target_error_percent", "budget_s"].contains(&key.as_str()) {
            errors.push(fail(
                &clip(key),
                "unknown field: a plan takes case and one of target_error_percent, budget_s",
            ));
        }
    }
    let target = number(
        &body,
        "target_error_percent",
        MAX_TARGET_ERROR_PERCENT,
        &mut errors,
    );
    let budget = number(&body, "budget_s", MAX_BUDGET_S, &mut errors);
    let goal = match (target, budget) {
        (Some(t), None) => Some(Goal::TargetErrorPercent(t)),
        (None, Some(b)) => Some(Goal::BudgetS(b)),
        (Some(_), Some(_)) => {
            for f in ["target_error_percent", "budget_s"] {
                errors.push(fail(
                    f,
                    "give one of target_error_percent and budget_s, not both",
                ));
            }
            None
        }
        (None, None) => {
            if !body.contains_key("target_error_percent") && !body.contains_key("budget_s") {
                for f in ["target_error_percent", "budget_s"] {
                    errors.push(fail(
                        f,
                        "give one: the error to reach, or the time to spend",
                    ));
                }
            }
            None
        }
    };
    let spec = match body.get("case") {
        None => {
            errors.push(fail(
                "case",
                "required: the case to plan, as for POST /v1/jobs",
            ));
            None
        }
        Some(case) => match spec_from_value(case) {
            Ok(spec) => Some(spec),
            Err(e) => {
                errors.extend(prefixed(e));
                None
            }
        },
    };
    match (spec, goal) {
        (Some(spec), Some(goal)) if errors.is_empty() => Ok((spec, goal)),
        _ => Err(unprocessable(errors)),
    }
}

/// `body[field]` when it is a number in (0, max]; else none, with the reason in `errors` when
/// the field is there.
fn number(
    body: &Map<String, Value>,
    field: &str,
    max: f64,
    errors: &mut Vec<FieldError>,
) -> Option<f64> {
    let value = body.get(field)?;
    match value.as_f64() {
        Some(x) if x > 0.0 && x <= max => Some(x),
        Some(x) => {
            errors.push(fail(
                field,
                &format!("must be > 0 and at most {max}, not {x}"),
            ));
            None
        }
        None => {
            errors.push(fail(field, "must be a number"));
            None
        }
    }
}

/// The case's errors with their fields named from the body's root (`case.tube.…`).
fn prefixed(e: CaseError) -> Vec<FieldError> {
    match e {
        CaseError::Malformed { field, message } => vec![fail(
            &field.map_or_else(|| "case".into(), |f| format!("case.{f}")),
            &message,
        )],
        CaseError::Invalid(found) => found
            .into_iter()
            .map(|e| fail(&format!("case.{}", e.field), &e.reason))
            .collect(),
    }
}

fn fail(field: &str, reason: &str) -> FieldError {
    FieldError {
        field: field.into(),
        reason: reason.into(),
    }
}

fn unprocessable(errors: Vec<FieldError>) -> ApiError {
    ApiError::Unprocessable {
        detail: errors
            .iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("; "),
        errors,
    }
}
