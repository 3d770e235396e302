//! What a succeeded job leaves: the history (JSON or CSV), the summary, the load curve as SVG,
//! the deformed tube as PNG and the final particle state as a VTU file. 404 for an unknown job,
//! 409 for one that has not succeeded.

use super::answers::file_response;
use super::inputs::{parse_id, wants_csv, FormatParams};
use super::state::AppState;
use crate::export::{self, FinalState};
use crate::plot;
use crate::service::connection::Connection;
use crate::service::downloads::{metered, Slot, HEAVY_AT_ONCE, HEAVY_WAIT};
use crate::service::error::ApiError;
use crate::service::store::{JobRecord, Status};
use crate::service::views::HistoryView;
use crate::solver::model::case::{spec_from_json, Geometry};
use crate::solver::HistoryRow;
use axum::extract::{Extension, Path, Query, State};
use axum::http::HeaderMap;
use axum::response::Response;
use futures::StreamExt;

/// A succeeded job never changes again, so its pictures and files may be cached.
pub(super) const CACHE: &str = "private, max-age=86400";

/// A succeeded job; 404 for an unknown job, 409 saying `why` for one that has not succeeded.
pub(super) async fn succeeded(s: &AppState, id: &str, why: &str) -> Result<JobRecord, ApiError> {
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

/// What a succeeded job kept of its tube: enough to draw it and export it.
struct Kept {
    record: JobRecord,
    geometry: Geometry,
    /// The crush distance, mm.
    crush_mm: f64,
    state: FinalState,
}

/// A succeeded job, the geometry of its tube and its final particle state; 404 when the case
/// kept none. The stored case was checked when it was submitted: only its text is read here,
/// so a case that later checks refuse still has its pictures.
async fn final_state(s: &AppState, id: &str, what: &str) -> Result<Kept, ApiError> {
    let why = format!("its {what} is made from the final state stored when it succeeds");
    let record = succeeded(s, id, &why).await?;
    let corrupt = |m: String| ApiError::internal(std::io::Error::other(m));
    let spec = spec_from_json(&record.case_json)
        .map_err(|e| corrupt(format!("stored case of job {id}: {e}")))?;
    let geometry = Geometry::of(&spec);
    let Some((particles, bytes)) = s.store.final_state(record.id).await? else {
        let why = if spec.output.final_state {
            "it finished before this server kept final states"
        } else {
            "its case set output.final_state = false, so none was kept"
        };
        return Err(ApiError::NotFound {
            what: format!("the final state of job {id} ({why})"),
        });
    };
    let state = export::vtu::decode(particles, &bytes)
        .ok_or_else(|| corrupt(format!("stored final state of job {id} has a wrong length")))?;
    Ok(Kept {
        crush_mm: spec.loading.crush_distance_or_default(),
        record,
        geometry,
        state,
    })
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
    let mean = record.summary.as_ref().map(|s| s.mean_load_n);
    let svg = render(move || plot::load_curve_svg(&title, rows.iter().map(|r| (r[u], r[p])), mean))
        .await?;
    Ok(file_response("image/svg+xml", None, Some(CACHE), svg))
}

/// The deformed tube coloured by plastic strain, three views, as PNG.
pub async fn shape_png(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let _slot = heavy_slot(&s).await?;
    let kept = final_state(&s, &id, "picture").await?;
    let title = format!("{} — final shape", title(&kept.record));
    let png = render(move || {
        let (position, strain) = (&kept.state.position_mm, &kept.state.plastic_strain);
        plot::tube_png(&kept.geometry, kept.crush_mm, &title, position, strain)
    })
    .await?;
    Ok(file_response("image/png", None, Some(CACHE), png))
}

/// The final particle state as a VTK XML unstructured grid (ParaView opens it), streamed: it
/// is written in chunks as the client reads, by at most [`HEAVY_AT_ONCE`] downloads at a time
/// (others wait), so memory stays about 40 bytes a particle per download written plus a few
/// chunks, whatever the number of clients.
pub async fn state_vtu(
    State(s): State<AppState>,
    Path(id): Path<String>,
    connection: Option<Extension<Connection>>,
) -> Result<Response, ApiError> {
    let slot = heavy_slot(&s).await?;
    let Kept {
        geometry, state, ..
    } = final_state(&s, &id, "VTU file").await?;
    let meter = slot.meter();
    let body = streamed(slot, "a VTU file", move |sink| {
        let note = geometry.symmetry_note();
        export::vtu::write_vtu(sink, &geometry.positions(), &state, note)
    });
    let body = metered(
        body,
        connection.as_deref(),
        s.limits.min_download_rate,
        Some(meter),
    );
    let disposition = format!("attachment; filename=\"{id}.vtu\"");
    Ok(file_response(
        "application/xml",
        Some(disposition),
        Some(CACHE),
        body,
    ))
}

/// The final particle state as CSV, the file `crush run` writes as `particles.csv`: start and
/// final position (mm) and equivalent plastic strain per particle, from the stored state (f32).
/// Streamed as `state.vtu` is.
pub async fn particles_csv(
    State(s): State<AppState>,
    Path(id): Path<String>,
    connection: Option<Extension<Connection>>,
) -> Result<Response, ApiError> {
    let slot = heavy_slot(&s).await?;
    let Kept {
        geometry, state, ..
    } = final_state(&s, &id, "particle table").await?;
    let meter = slot.meter();
    let body = streamed(slot, "a particle table", move |sink| {
        let start = geometry.positions();
        let rows = start
            .iter()
            .zip(&state.position_mm)
            .zip(&state.plastic_strain)
            .map(|((a, b), e)| (*a, b.map(f64::from), f64::from(*e)));
        export::csv::particles(sink, rows)
            .map(|_| ())
            .map_err(std::io::Error::other)
    });
    let body = metered(
        body,
        connection.as_deref(),
        s.limits.min_download_rate,
        Some(meter),
    );
    let disposition = format!("attachment; filename=\"{id}-particles.csv\"");
    Ok(file_response(
        "text/csv; charset=utf-8",
        Some(disposition),
        Some(CACHE),
        body,
    ))
}

/// A body that `write` fills on a blocking thread, in [`CHUNK`]s sent as the client reads,
/// holding `slot` until it is written; an error ends the body cut short (the client sees a
/// cut transfer, not a file) and is logged as failing to write `what`.
pub(super) fn streamed(
    slot: Slot,
    what: &'static str,
    write: impl FnOnce(&mut ChunkSink) -> std::io::Result<()> + Send + 'static,
) -> axum::body::Body {
    let (tx, rx) = tokio::sync::mpsc::channel(2);
    tokio::task::spawn_blocking(move || {
        let _slot = slot;
        let mut sink = ChunkSink {
            tx,
            buffer: Vec::with_capacity(CHUNK),
        };
        let written = write(&mut sink).and_then(|()| std::io::Write::flush(&mut sink));
        if let Err(e) = written {
            if e.kind() != std::io::ErrorKind::BrokenPipe {
                tracing::error!(error = %e, "writing {what} failed");
                let _ = sink.tx.blocking_send(Err(e));
            }
        }
    });
    axum::body::Body::from_stream(tokio_stream::wrappers::ReceiverStream::new(rx))
}

/// A turn at building a large answer (held until it is sent, where the body is streamed);
/// 503 after [`HEAVY_WAIT`] without one.
pub(super) async fn heavy_slot(s: &AppState) -> Result<Slot, ApiError> {
    s.heavy
        .acquire()
        .await
        .ok_or_else(|| ApiError::Unavailable {
            detail: format!(
                "every download slot ({HEAVY_AT_ONCE}) has been busy for {} s; try again later",
                HEAVY_WAIT.as_secs()
            ),
            retry_after_s: 5,
        })
}

/// The longest history built and sent without a download slot, rows: about 0.9 MB of CSV or
/// JSON at the 230 B a row that histories take (116 KB for the default 500 rows), and while it
/// is built another 0.5 MB for the rows read from the store. That is the order of the other
/// answers sent without a slot (a job list, the load curve drawn from the same rows), and at
/// `--min-download-bytes-per-s` (64 KB/s) a client takes it within 15 s or is closed, so
/// these answers need no turn and never wait behind a VTU file.
const LIGHT_HISTORY_ROWS: u64 = 4_000;

/// Bytes sent to the client at a time.
const CHUNK: usize = 256 * 1024;

/// Sends what is written to a response body in [`CHUNK`]s; fails with `BrokenPipe` once the
/// client has gone, which stops the writer.
pub(super) struct ChunkSink {
    tx: tokio::sync::mpsc::Sender<std::io::Result<axum::body::Bytes>>,
    buffer: Vec<u8>,
}

impl std::io::Write for ChunkSink {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.buffer.extend_from_slice(bytes);
        if self.buffer.len() >= CHUNK {
            self.flush()?;
        }
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if self.buffer.is_empty() {
            return Ok(());
        }
        let chunk = std::mem::replace(&mut self.buffer, Vec::with_capacity(CHUNK));
        self.tx
            .blocking_send(Ok(chunk.into()))
            .map_err(|_| std::io::ErrorKind::BrokenPipe.into())
    }
}

/// The summary alone, as JSON, named for saving.
pub async fn summary(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let record = succeeded(&s, &id, "its summary is stored when it succeeds").await?;
    let summary = record.summary.as_ref().ok_or_else(|| {
        ApiError::internal(std::io::Error::other(format!(
            "succeeded job {id} has no summary"
        )))
    })?;
    let text = serde_json::to_string(summary).map_err(ApiError::internal)?;
    let disposition = format!("inline; filename=\"{id}-summary.json\"");
    Ok(file_response(
        "application/json",
        Some(disposition),
        None,
        text,
    ))
}

/// The history as JSON or CSV. One of up to [`LIGHT_HISTORY_ROWS`] rows is built and sent
/// at once; a longer one (up to 100 000 rows, about 23 MB of text) waits for a download slot
/// and holds it until it is sent, so that at most [`HEAVY_AT_ONCE`] are in memory at a time.
pub async fn history(
    State(s): State<AppState>,
    Path(id): Path<String>,
    Query(q): Query<FormatParams>,
    headers: HeaderMap,
    connection: Option<Extension<Connection>>,
) -> Result<Response, ApiError> {
    let csv = wants_csv(&headers, q.format.as_deref())?;
    let record = succeeded(&s, &id, "its history is stored when it succeeds").await?;
    let slot = if s.store.history_len(record.id).await? > LIGHT_HISTORY_ROWS {
        Some(heavy_slot(&s).await?)
    } else {
        None
    };
    let rows = s.store.history(record.id).await?;
    let (content_type, disposition, bytes) = if csv {
        let values = rows
            .iter()
            .map(|r| std::array::from_fn(|k| r.get(k).copied().unwrap_or(f64::NAN)));
        let bytes = export::csv::history(Vec::new(), values).map_err(ApiError::internal)?;
        let disposition = format!("inline; filename=\"{id}-history.csv\"");
        ("text/csv; charset=utf-8", Some(disposition), bytes)
    } else {
        let document = HistoryView {
            job_id: record.id,
            columns: &HistoryRow::COLUMNS,
            rows: &rows,
        };
        let bytes = serde_json::to_vec(&document).map_err(ApiError::internal)?;
        ("application/json", None, bytes)
    };
    drop(rows);
    let meter = slot.as_ref().map(Slot::meter);
    let body = chunked(bytes, slot);
    let body = metered(
        body,
        connection.as_deref(),
        s.limits.min_download_rate,
        meter,
    );
    Ok(file_response(content_type, disposition, None, body))
}

/// `bytes` as a body sent in [`CHUNK`]s, holding `slot` until the body is dropped (sent whole
/// or abandoned by the client).
fn chunked(bytes: Vec<u8>, slot: Option<Slot>) -> axum::body::Body {
    let bytes = axum::body::Bytes::from(bytes);
    let chunks: Vec<axum::body::Bytes> = (0..bytes.len())
        .step_by(CHUNK)
        .map(|i| bytes.slice(i..(i + CHUNK).min(bytes.len())))
        .collect();
    let stream = futures::stream::iter(chunks).map(move |chunk| {
        let _held = &slot;
        Ok::<_, std::convert::Infallible>(chunk)
    });
    axum::body::Body::from_stream(stream)
}
