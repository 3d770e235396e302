//! What a succeeded job leaves: the history (JSON or CSV), the summary, the load curve as SVG,
//! the deformed tube as PNG and the final particle state as a VTU file. 404 for an unknown job,
//! 409 for one that has not succeeded.

use super::{csv_response, file_response, parse_id, wants_csv, AppState, FormatParams};
use crate::plot::{self, Series};
use crate::service::error::ApiError;
use crate::service::state::{self, FinalState};
use crate::service::store::{JobRecord, Status};
use crate::solver::{scene::lattice_positions, Case, HistoryRow, Limits};
use axum::extract::{Path, Query, State};
use axum::http::HeaderMap;
use axum::response::{IntoResponse, Response};
use axum::Json;

/// A succeeded job never changes again, so its pictures and files may be cached.
const CACHE: &str = "private, max-age=86400";

/// A succeeded job; 404 for an unknown job, 409 saying `why` for one that has not succeeded.
async fn succeeded(s: &AppState, id: &str, why: &str) -> Result<JobRecord, ApiError> {
    let uuid = parse_id(id, "job")?;
    let record = s
        .store
        .job(uuid)
        .await?
        .ok_or_else(|| ApiError::job_not_found(id))?;
    if record.status != Status::Succeeded {
        return Err(ApiError::Conflict {
            detail: format!("job {id} is {}; {why}", record.status.as_str()),
        });
    }
    Ok(record)
}

/// A succeeded job, its case and its final particle state; 404 when the case kept none.
async fn final_state(
    s: &AppState,
    id: &str,
    what: &str,
) -> Result<(JobRecord, Case, FinalState), ApiError> {
    let why = format!("its {what} is made from the final state stored when it succeeds");
    let record = succeeded(s, id, &why).await?;
    let corrupt = |m: String| ApiError::internal(std::io::Error::other(m));
    let case = Case::from_json(&record.case_json, &Limits::unbounded())
        .map_err(|e| corrupt(format!("stored case of job {id}: {e}")))?;
    let Some((particles, bytes)) = s.store.final_state(record.id).await? else {
        let why = if case.spec().output.final_state {
            "it finished before this server kept final states"
        } else {
            "its case set output.final_state = false, so none was kept"
        };
        return Err(ApiError::NotFound {
            what: format!("the final state of job {id} ({why})"),
        });
    };
    let state = state::decode(particles, &bytes)
        .ok_or_else(|| corrupt(format!("stored final state of job {id} has a wrong length")))?;
    Ok((record, case, state))
}

fn title(record: &JobRecord) -> String {
    record
        .label
        .clone()
        .unwrap_or_else(|| format!("job {}", record.id))
}

/// Runs a CPU-bound rendering off the async threads.
async fn render<T: Send + 'static>(
    f: impl FnOnce() -> anyhow::Result<T> + Send + 'static,
) -> Result<T, ApiError> {
    tokio::task::spawn_blocking(f)
        .await
        .map_err(ApiError::internal)?
        .map_err(|e| ApiError::internal(std::io::Error::other(e.to_string())))
}

/// The load on the moving plate against its travel, as SVG.
pub async fn plot_svg(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let record = succeeded(
        &s,
        &id,
        "its plot is drawn from the history stored when it succeeds",
    )
    .await?;
    let rows = s.store.history(record.id).await?;
    let column = |name: &str| HistoryRow::COLUMNS.iter().position(|c| *c == name);
    let (Some(u), Some(p)) = (column("displacement_mm"), column("load_top_n")) else {
        return Err(ApiError::internal(std::io::Error::other(
            "the history has no displacement or load column",
        )));
    };
    let title = title(&record);
    let svg = render(move || {
        let series = [Series {
            name: "load on the moving plate".into(),
            points: rows.iter().map(|r| (r[u], r[p] / 1000.0)).collect(),
        }];
        plot::lines_svg((&title, "plate travel, mm", "load, kN"), &series, false)
    })
    .await?;
    Ok(file_response("image/svg+xml", None, Some(CACHE), svg))
}

/// The deformed tube coloured by plastic strain, three views, as PNG.
pub async fn shape_png(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let (record, case, state) = final_state(&s, &id, "picture").await?;
    let title = format!("{} — final shape", title(&record));
    let png =
        render(move || plot::tube_png(&case, &title, &state.position_mm, &state.plastic_strain))
            .await?;
    Ok(file_response("image/png", None, Some(CACHE), png))
}

/// The final particle state as a VTK XML unstructured grid (ParaView opens it).
pub async fn state_vtu(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let (record, case, state) = final_state(&s, &id, "VTU file").await?;
    let title = title(&record);
    let vtu = render(move || state::vtu(&title, &lattice_positions(&case), &state)).await?;
    let disposition = format!("attachment; filename=\"{id}.vtu\"");
    Ok(file_response(
        "application/xml",
        Some(disposition),
        Some(CACHE),
        vtu,
    ))
}

/// The summary alone, as JSON, named for saving.
pub async fn summary(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let record = succeeded(&s, &id, "its summary is stored when it succeeds").await?;
    let text = record.summary_json.clone().ok_or_else(|| {
        ApiError::internal(std::io::Error::other(format!(
            "succeeded job {id} has no summary"
        )))
    })?;
    let disposition = format!("inline; filename=\"{id}-summary.json\"");
    Ok(file_response(
        "application/json",
        Some(disposition),
        None,
        text,
    ))
}

pub async fn history(
    State(s): State<AppState>,
    Path(id): Path<String>,
    Query(q): Query<FormatParams>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let csv = wants_csv(&headers, q.format.as_deref())?;
    let record = succeeded(&s, &id, "its history is stored when it succeeds").await?;
    let rows = s.store.history(record.id).await?;
    if csv {
        let write = || -> Result<Vec<u8>, csv::Error> {
            let mut w = csv::Writer::from_writer(Vec::new());
            w.write_record(HistoryRow::COLUMNS)?;
            for row in &rows {
                w.write_record(row.iter().map(|v| v.to_string()))?;
            }
            w.into_inner().map_err(|e| e.into_error().into())
        };
        let bytes = write().map_err(ApiError::internal)?;
        let text = String::from_utf8(bytes).map_err(ApiError::internal)?;
        return Ok(csv_response(text, &format!("{id}-history.csv")));
    }
    Ok(Json(serde_json::json!({
        "job_id": record.id,
        "columns": HistoryRow::COLUMNS,
        "rows": rows,
    }))
    .into_response())
}
