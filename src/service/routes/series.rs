//! A succeeded job's time series (`output.frames`) for ParaView: the `.pvd` collection, each
//! frame as a `.vtu` under the relative name the `.pvd` gives it (`frames/{k}.vtu`), and the
//! lot as one tar archive, what a user downloads and opens. 404 for a job that kept no series,
//! 409 for one that has not succeeded. Frames are read from the store one at a time, each a
//! part at a time, and written as the client reads (see `results::streamed`), so a download
//! holds one frame's state (80 bytes a particle with the start positions) and one stored part
//! (3.5 MB), whatever the series' length.

use super::answers::file_response;
use super::results::{heavy_slot, streamed, succeeded, CACHE};
use super::state::AppState;
use crate::export::series::{self, FrameState, FrameTime};
use crate::service::connection::Connection;
use crate::service::downloads::metered;
use crate::service::error::ApiError;
use crate::service::store::{JobRecord, Store};
use crate::solver::model::case::{spec_from_json, Geometry};
use crate::solver::model::input::clip;
use axum::extract::{Extension, Path, State};
use axum::response::Response;
use std::io::{self, Write};
use uuid::Uuid;

/// A succeeded job's series: its record, its tube's geometry, the frame count its case asked
/// for and where each stored frame stands; 404 when it kept none.
struct Kept {
    record: JobRecord,
    geometry: Geometry,
    count: u32,
    frames: Vec<FrameTime>,
}

async fn kept(s: &AppState, id: &str) -> Result<Kept, ApiError> {
    let record = succeeded(s, id, "its time series is served once it has succeeded").await?;
    let spec = spec_from_json(&record.case_json).map_err(|e| {
        ApiError::internal(io::Error::other(format!("stored case of job {id}: {e}")))
    })?;
    let frames = s.store.frame_times(record.id).await?;
    if frames.is_empty() {
        let why = if spec.output.frames == 0 {
            "its case left output.frames at 0, so none was kept"
        } else {
            "it finished before this server kept time series"
        };
        return Err(ApiError::NotFound {
            what: format!("the time series of job {id} ({why})"),
        });
    }
    Ok(Kept {
        geometry: Geometry::of(&spec),
        count: spec.output.frames,
        record,
        frames,
    })
}

/// The `.pvd` collection: one data set per frame, its time the top plate's travel (mm).
pub async fn series_pvd(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Response, ApiError> {
    let kept = kept(&s, &id).await?;
    let mut pvd = Vec::new();
    series::write_pvd(&mut pvd, &kept.frames).map_err(ApiError::internal)?;
    let disposition = "inline; filename=\"series.pvd\"".to_string();
    Ok(file_response(
        "application/xml",
        Some(disposition),
        Some(CACHE),
        pvd,
    ))
}

/// Frame `k` as a VTK XML unstructured grid (`{k}.vtu`), streamed as `state.vtu` is.
pub async fn frame_vtu(
    State(s): State<AppState>,
    Path((id, name)): Path<(String, String)>,
    connection: Option<Extension<Connection>>,
) -> Result<Response, ApiError> {
    let slot = heavy_slot(&s).await?;
    let kept = kept(&s, &id).await?;
    let last = kept.frames.last().map_or(0, |f| f.index);
    let no_frame = || ApiError::NotFound {
        what: format!(
            "frame file {:?} of job {id} (its frames are 0.vtu to {last}.vtu)",
            clip(&name)
        ),
    };
    let k = series::frame_index(&name).ok_or_else(no_frame)?;
    let (at, state) = read_frame(&s.store, kept.record.id, k)
        .await?
        .ok_or_else(no_frame)?;
    let (geometry, count) = (kept.geometry, kept.count);
    let meter = slot.meter();
    let body = streamed(slot, "a frame", move |sink| {
        let note = series::frame_note(&at, count, geometry.symmetry_note());
        series::write_frame_vtu(sink, &geometry.positions(), &state, Some(&note))
    });
    let body = metered(
        body,
        connection.as_deref(),
        s.limits.min_download_rate,
        Some(meter),
    );
    let disposition = format!("attachment; filename=\"{k}.vtu\"");
    Ok(file_response(
        "application/xml",
        Some(disposition),
        Some(CACHE),
        body,
    ))
}

/// The whole series as one tar archive: `{id}/series.pvd` and `{id}/frames/{k}.vtu`, each
/// frame read from the store and written in turn.
pub async fn series_tar(
    State(s): State<AppState>,
    Path(id): Path<String>,
    connection: Option<Extension<Connection>>,
) -> Result<Response, ApiError> {
    let slot = heavy_slot(&s).await?;
    let kept = kept(&s, &id).await?;
    let (store, runtime) = (s.store.clone(), tokio::runtime::Handle::current());
    let job = kept.record.id;
    // The entries' time: when the job finished, s.
    let mtime = kept.record.finished_at.unwrap_or(0).max(0) as u64 / 1000;
    let meter = slot.meter();
    let body = streamed(slot, "a series archive", move |sink| {
        let start = kept.geometry.positions();
        let note = kept.geometry.symmetry_note();
        let folder = job.to_string();
        directory(sink, &format!("{folder}/"), mtime)?;
        let mut pvd = Vec::new();
        series::write_pvd(&mut pvd, &kept.frames)?;
        entry(
            sink,
            &format!("{folder}/series.pvd"),
            mtime,
            pvd.len() as u64,
            |w| w.write_all(&pvd),
        )?;
        directory(sink, &format!("{folder}/frames/"), mtime)?;
        for f in &kept.frames {
            let read = runtime.block_on(read_frame(&store, job, f.index));
            let Some((at, state)) = read.map_err(|e| io::Error::other(e.to_string()))? else {
                return Err(io::Error::other(format!(
                    "frame {} of job {job} is gone",
                    f.index
                )));
            };
            let note = series::frame_note(&at, kept.count, note);
            let write = |mut w: &mut dyn Write| {
                series::write_frame_vtu(&mut w, &start, &state, Some(&note))
            };
            let mut counted = Counter(0);
            write(&mut counted)?;
            let path = format!("{folder}/{}", series::frame_file(f.index));
            entry(sink, &path, mtime, counted.0, write)?;
        }
        // The end of the archive: two empty blocks.
        sink.write_all(&[0; 1024])
    });
    let body = metered(
        body,
        connection.as_deref(),
        s.limits.min_download_rate,
        Some(meter),
    );
    let disposition = format!("attachment; filename=\"{id}-series.tar\"");
    Ok(file_response(
        "application/x-tar",
        Some(disposition),
        Some(CACHE),
        body,
    ))
}

/// Frame `k` of job `job`, decoded part by part, with where it stands; `None` when it is not
/// stored.
async fn read_frame(
    store: &Store,
    job: Uuid,
    k: u32,
) -> Result<Option<(FrameTime, FrameState)>, ApiError> {
    let (mut state, mut whole) = (FrameState::default(), true);
    let found = store
        .frame(job, k, |particles, part| {
            if state.is_empty() {
                state.reserve(particles);
            }
            whole &= state.extend_from(part);
        })
        .await?;
    let Some((at, particles)) = found else {
        return Ok(None);
    };
    if !whole || state.len() != particles {
        return Err(ApiError::internal(io::Error::other(format!(
            "stored frame {k} of job {job} does not hold its {particles} particles"
        ))));
    }
    Ok(Some((at, state)))
}

/// A tar directory entry.
fn directory(out: &mut impl Write, path: &str, mtime: u64) -> io::Result<()> {
    let mut header = tar::Header::new_ustar();
    header.set_entry_type(tar::EntryType::Directory);
    header.set_path(path)?;
    header.set_mode(0o755);
    header.set_size(0);
    header.set_mtime(mtime);
    header.set_cksum();
    out.write_all(header.as_bytes())
}

/// A tar file entry of `size` bytes that `write` writes (exactly those, or the archive is cut
/// with an error).
fn entry<W: Write>(
    out: &mut W,
    path: &str,
    mtime: u64,
    size: u64,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let mut header = tar::Header::new_ustar();
    header.set_entry_type(tar::EntryType::Regular);
    header.set_path(path)?;
    header.set_mode(0o644);
    header.set_size(size);
    header.set_mtime(mtime);
    header.set_cksum();
    out.write_all(header.as_bytes())?;
    let mut counted = Counting {
        inner: &mut *out,
        written: 0,
    };
    write(&mut counted)?;
    if counted.written != size {
        return Err(io::Error::other(format!(
            "{path}: wrote {} bytes, not the {size} its header gives",
            counted.written
        )));
    }
    let padding = (512 - size % 512) % 512;
    out.write_all(&[0; 512][..padding as usize])
}

/// Counts what is written to it and keeps nothing.
struct Counter(u64);

impl Write for Counter {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.0 += bytes.len() as u64;
        Ok(bytes.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Passes writes on to `inner`, counting them.
struct Counting<'a, W: Write> {
    inner: &'a mut W,
    written: u64,
}

impl<W: Write> Write for Counting<'_, W> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(bytes)?;
        self.written += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}
