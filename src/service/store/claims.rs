//! Jobs as workers see them: claim one with a single `UPDATE … RETURNING`, heartbeat, finish
//! (history, summary and state in one transaction), requeue, and reap jobs whose worker died.
//!
//! Every write after the claim names the claim's lease: a worker that lost its job to the
//! reaper can no longer write to it, so a job is never stored twice.

use super::database::{now_ms, Result, Status, Store};
use super::lease::holds;
use crate::solver::{HistoryRow, Summary};
use uuid::Uuid;

/// A job a worker has claimed.
#[derive(Debug, Clone)]
pub struct Claimed {
    pub id: Uuid,
    pub case_json: String,
    /// This claim's number, 1 for the first run.
    pub attempt: i64,
    pub lease: Uuid,
}

/// What a reaper pass did.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Reaped {
    pub requeued: Vec<Uuid>,
    pub failed: Vec<Uuid>,
    pub cancelled: Vec<Uuid>,
}

/// What a succeeded run leaves to store.
#[derive(Debug, Clone, Copy)]
pub struct Succeeded<'a> {
    pub history: &'a [HistoryRow],
    pub summary: &'a Summary,
    /// (particles, stored bytes) of the final state, when the case keeps it.
    pub final_state: Option<(usize, &'a [u8])>,
    /// The last progress report, as JSON.
    pub progress_json: Option<&'a str>,
    /// Frames the run's series promised (`output.frames`; 0: none), each of `particles`.
    pub frames: u32,
    pub particles: usize,
}

/// History rows per INSERT statement (2 + `HistoryRow::COLUMNS.len()` bound values each). The
/// cost of a statement on SQLite grows faster than its rows: 10 000 rows took 2.1 s in
/// statements of 500 rows and 0.27 s in statements of 50 (the test profile, optimized).
const HISTORY_CHUNK: usize = 50;

/// History rows per write transaction: short enough that another writer waits at most some tens
/// of milliseconds behind one.
const HISTORY_BATCH: usize = 2_000;

impl Store {
    /// Claims the oldest queued job for node `worker`, in one statement. On PostgreSQL the
    /// choice skips rows other nodes are claiming at the same moment (`SKIP LOCKED`), and the
    /// `status = 'queued'` test is checked again on the locked row, so two nodes never claim
    /// one job.
    pub async fn claim(&self, worker: &str) -> Result<Option<Claimed>> {
        let lease = Uuid::new_v4();
        let now = now_ms();
        let mut tx = self.write().await?;
        let sql = format!(
            "UPDATE jobs SET status = 'running', attempts = attempts + 1, lease = $1, worker = $2, \
             heartbeat_at = $3, started_at = COALESCE(started_at, $3), progress_json = NULL, \
             progress_fraction = NULL \
             WHERE status = 'queued' AND seq = (SELECT seq FROM jobs WHERE status = 'queued' \
             ORDER BY seq LIMIT 1{}) \
             RETURNING id, case_json, attempts",
            self.backend.skip_locked()
        );
        let row: Option<(String, String, i64)> = sqlx::query_as(&sql)
            .bind(lease.to_string())
            .bind(worker)
            .bind(now)
            .fetch_optional(&mut *tx)
            .await?;
        tx.commit().await?;
        row.map(|(id, case_json, attempt)| {
            Ok(Claimed {
                id: super::database::parse_uuid(&id)?,
                case_json,
                attempt,
                lease,
            })
        })
        .transpose()
    }

    /// Records that the worker holding `lease` is alive, with its latest progress. Returns
    /// whether a cancel was requested, or `None` when the lease is no longer held.
    pub async fn heartbeat(
        &self,
        id: Uuid,
        lease: Uuid,
        progress: Option<(&str, f64)>,
    ) -> Result<Option<bool>> {
        // Two statements rather than one with NULLs for "no progress": sqlx's `Any` driver
        // sends a NULL f64 to PostgreSQL as a float4, and a statement first prepared on a
        // connection with it then takes the next beat's 8-byte float for a 4-byte one
        // ("incorrect binary data format in bind parameter 3").
        let mut tx = self.write().await?;
        let row: Option<(i64,)> = match progress {
            Some((json, fraction)) => {
                sqlx::query_as(
                    "UPDATE jobs SET heartbeat_at = $1, progress_json = $2, \
                     progress_fraction = $3 \
                     WHERE id = $4 AND lease = $5 AND status = 'running' RETURNING cancel_requested",
                )
                .bind(now_ms())
                .bind(json)
                .bind(fraction)
                .bind(id.to_string())
                .bind(lease.to_string())
                .fetch_optional(&mut *tx)
                .await?
            }
            None => {
                sqlx::query_as(
                    "UPDATE jobs SET heartbeat_at = $1 \
                     WHERE id = $2 AND lease = $3 AND status = 'running' RETURNING cancel_requested",
                )
                .bind(now_ms())
                .bind(id.to_string())
                .bind(lease.to_string())
                .fetch_optional(&mut *tx)
                .await?
            }
        };
        tx.commit().await?;
        Ok(row.map(|(c,)| c != 0))
    }

    /// Stores the history of a run under `lease`, replacing any an earlier attempt left, in
    /// transactions of at most [`HISTORY_BATCH`] rows, so that no write waits long behind it
    /// (100 000 rows in one transaction held SQLite's writer for half a minute). False when the
    /// lease was lost: the rest is not written.
    async fn save_history(&self, id: Uuid, lease: Uuid, history: &[HistoryRow]) -> Result<bool> {
        let job = id.to_string();
        let mut tx = self.write().await?;
        if holds(&self.backend, &mut tx, id, lease).await?.is_none() {
            return Ok(false);
        }
        sqlx::query("DELETE FROM history WHERE job_id = $1")
            .bind(&job)
            .execute(&mut *tx)
            .await?;
        tx.commit().await?;
        let width = 2 + HistoryRow::COLUMNS.len();
        for (batch_no, batch) in history.chunks(HISTORY_BATCH).enumerate() {
            let mut tx = self.write().await?;
            if holds(&self.backend, &mut tx, id, lease).await?.is_none() {
                return Ok(false);
            }
            for (chunk_no, chunk) in batch.chunks(HISTORY_CHUNK).enumerate() {
                let first = batch_no * HISTORY_BATCH + chunk_no * HISTORY_CHUNK;
                let sql = history_insert(chunk.len(), width);
                let mut q = sqlx::query(&sql);
                for (i, row) in chunk.iter().enumerate() {
                    q = q.bind(job.clone()).bind((first + i) as i64);
                    for v in row.values() {
                        q = q.bind(v);
                    }
                }
                q.execute(&mut *tx).await?;
            }
            tx.commit().await?;
        }
        Ok(true)
    }

    /// Stores a successful run and returns `Succeeded`: the history first (in batches, see
    /// [`Store::save_history`]), then summary, final particle state (when kept) and job state
    /// together, in one transaction that also checks that everything the run promised is
    /// stored: every history row, and every part of each of its `frames`. A run that left
    /// something out is `Failed`, saying what is missing, never `Succeeded` short. A cancel
    /// accepted while the job ran wins: then nothing of the run is kept and the job is
    /// `Cancelled`. `None` when the lease was lost (nothing more is written).
    pub async fn finish_succeeded(
        &self,
        id: Uuid,
        lease: Uuid,
        result: Succeeded<'_>,
    ) -> Result<Option<Status>> {
        let Succeeded {
            history,
            summary,
            final_state,
            progress_json,
            frames,
            particles,
        } = result;
        let summary_json = serde_json::to_string(summary)
            .map_err(|e| super::database::StoreError::Corrupt(format!("summary: {e}")))?;
        // The queryable columns come from the typed summary: a renamed field fails to compile
        // here instead of storing zeros.
        let mode = summary.mode.kind();
        if !self.save_history(id, lease, history).await? {
            return Ok(None);
        }
        let mut tx = self.write().await?;
        let Some(cancel_requested) = holds(&self.backend, &mut tx, id, lease).await? else {
            return Ok(None);
        };
        if cancel_requested {
            end_run(&mut tx, id, Status::Cancelled, None).await?;
            tx.commit().await?;
            return Ok(Some(Status::Cancelled));
        }
        let job = id.to_string();
        if let Some(missing) = missing(&mut tx, &job, history.len(), frames, particles).await? {
            let error = format!(
                "the run finished but not all of its results could be stored ({missing}); \
                 submit it again"
            );
            end_run(&mut tx, id, Status::Failed, Some(&error)).await?;
            tx.commit().await?;
            return Ok(Some(Status::Failed));
        }
        // A retried job starts from nothing: no row of an earlier attempt survives.
        sqlx::query("DELETE FROM summaries WHERE job_id = $1")
            .bind(&job)
            .execute(&mut *tx)
            .await?;
        sqlx::query("DELETE FROM final_states WHERE job_id = $1")
            .bind(&job)
            .execute(&mut *tx)
            .await?;
        super::checkpoints::forget(&mut tx, &job).await?;
        if let Some((particles, data)) = final_state {
            sqlx::query("INSERT INTO final_states (job_id, particles, data) VALUES ($1, $2, $3)")
                .bind(&job)
                .bind(particles as i64)
                .bind(data)
                .execute(&mut *tx)
                .await?;
        }
        sqlx::query(
            "INSERT INTO summaries (job_id, mean_load_n, peak_load_n, energy_absorbed_mj, \
             crush_distance_mm, folds, mode, energy_balance_error, particles, steps, wall_time_s, \
             summary_json) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)",
        )
        .bind(&job)
        .bind(summary.mean_load_n)
        .bind(summary.peak_load_n)
        .bind(summary.energy_absorbed_mj)
        .bind(summary.crush_distance_mm)
        .bind(summary.folds as i64)
        .bind(mode)
        .bind(summary.energy_balance_error)
        .bind(summary.cost.particles as i64)
        .bind(summary.cost.steps as i64)
        .bind(summary.cost.wall_time_s)
        .bind(summary_json)
        .execute(&mut *tx)
        .await?;
        sqlx::query(
            "UPDATE jobs SET status = 'succeeded', finished_at = $1, lease = NULL, \
             heartbeat_at = NULL, progress_json = COALESCE($2, progress_json), \
             progress_fraction = 1.0, error = NULL WHERE id = $3",
        )
        .bind(now_ms())
        .bind(progress_json)
        .bind(&job)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(Some(Status::Succeeded))
    }

    /// Ends a run as failed (with the reason) or cancelled, and returns the status stored: a
    /// cancel accepted while the job ran wins over a failure (the reason is kept). `None` when
    /// the lease was lost.
    pub async fn finish_unsuccessful(
        &self,
        id: Uuid,
        lease: Uuid,
        status: Status,
        error: Option<&str>,
    ) -> Result<Option<Status>> {
        debug_assert!(matches!(status, Status::Failed | Status::Cancelled));
        let mut tx = self.write().await?;
        let Some(cancel_requested) = holds(&self.backend, &mut tx, id, lease).await? else {
            return Ok(None);
        };
        let status = if cancel_requested {
            Status::Cancelled
        } else {
            status
        };
        end_run(&mut tx, id, status, error).await?;
        tx.commit().await?;
        Ok(Some(status))
    }

    /// Puts a job this worker could not finish (shutdown) back in the queue, and returns
    /// `Queued`; or, when a cancel was asked, `Cancelled`; or, when `max_attempts` of its
    /// claims stored no checkpoint (made no progress that a later claim keeps), `Failed`.
    /// `None` when the lease was lost.
    pub async fn requeue(
        &self,
        id: Uuid,
        lease: Uuid,
        max_attempts: u32,
    ) -> Result<Option<Status>> {
        let mut tx = self.write().await?;
        let Some(cancel_requested) = holds(&self.backend, &mut tx, id, lease).await? else {
            return Ok(None);
        };
        let (attempts, fruitless): (i64, i64) =
            sqlx::query_as("SELECT attempts, attempts - advanced FROM jobs WHERE id = $1")
                .bind(id.to_string())
                .fetch_one(&mut *tx)
                .await?;
        let status = if cancel_requested {
            end_run(&mut tx, id, Status::Cancelled, None).await?;
            Status::Cancelled
        } else if fruitless >= max_attempts as i64 {
            let error = out_of_attempts(attempts, fruitless);
            end_run(&mut tx, id, Status::Failed, Some(&error)).await?;
            Status::Failed
        } else {
            sqlx::query(
                "UPDATE jobs SET status = 'queued', lease = NULL, worker = NULL, \
                 heartbeat_at = NULL, progress_json = NULL, progress_fraction = NULL WHERE id = $1",
            )
            .bind(id.to_string())
            .execute(&mut *tx)
            .await?;
            Status::Queued
        };
        tx.commit().await?;
        Ok(Some(status))
    }

    /// Running jobs whose heartbeat is older than `stale_ms`, but those in `alive` (the ones
    /// the caller's own process is running: a beat the database refused while it was away
    /// does not make them lost): back to the queue, or failed once `max_attempts` of their
    /// claims stored no checkpoint, or cancelled if that was asked.
    pub async fn reap_stale(
        &self,
        stale_ms: i64,
        max_attempts: u32,
        alive: &[Uuid],
    ) -> Result<Reaped> {
        let now = now_ms();
        let cutoff = now - stale_ms;
        // The ids are UUIDs this process made: quoted as they are, they cannot break the SQL.
        let spared = if alive.is_empty() {
            String::new()
        } else {
            let ids: Vec<String> = alive.iter().map(|id| format!("'{id}'")).collect();
            format!(" AND id NOT IN ({})", ids.join(", "))
        };
        let mut tx = self.write().await?;
        let ids = |rows: Vec<(String,)>| -> Result<Vec<Uuid>> {
            rows.iter()
                .map(|(id,)| super::database::parse_uuid(id))
                .collect()
        };
        let sql = format!(
            "UPDATE jobs SET status = 'cancelled', finished_at = $1, lease = NULL, \
             heartbeat_at = NULL, lost = lost + 1 \
             WHERE status = 'running' AND heartbeat_at < $2 AND cancel_requested = 1{spared} \
             RETURNING id"
        );
        let cancelled = sqlx::query_as(&sql)
            .bind(now)
            .bind(cutoff)
            .fetch_all(&mut *tx)
            .await?;
        let sql = format!(
            "UPDATE jobs SET status = 'failed', finished_at = $1, lease = NULL, heartbeat_at = NULL, \
             lost = lost + 1, error = 'started ' || attempts || ' times, ' || (attempts - advanced) \
             || ' of them without storing a checkpoint (the most allowed), and never finished: ' \
             || 'its worker stopped answering ' || (lost + 1) || ' of them' \
             WHERE status = 'running' AND heartbeat_at < $2 AND attempts - advanced >= $3{spared} \
             RETURNING id"
        );
        let failed = sqlx::query_as(&sql)
            .bind(now)
            .bind(cutoff)
            .bind(max_attempts as i64)
            .fetch_all(&mut *tx)
            .await?;
        let sql = format!(
            "UPDATE jobs SET status = 'queued', lease = NULL, worker = NULL, heartbeat_at = NULL, \
             lost = lost + 1, progress_json = NULL, progress_fraction = NULL \
             WHERE status = 'running' AND heartbeat_at < $1{spared} RETURNING id"
        );
        let requeued = sqlx::query_as(&sql)
            .bind(cutoff)
            .fetch_all(&mut *tx)
            .await?;
        let (failed, cancelled) = (ids(failed)?, ids(cancelled)?);
        for id in failed.iter().chain(&cancelled) {
            super::checkpoints::forget(&mut tx, &id.to_string()).await?;
            super::frames::forget(&mut tx, &id.to_string()).await?;
            sqlx::query("DELETE FROM history WHERE job_id = $1")
                .bind(id.to_string())
                .execute(&mut *tx)
                .await?;
        }
        tx.commit().await?;
        Ok(Reaped {
            requeued: ids(requeued)?,
            failed,
            cancelled,
        })
    }
}

/// Ends a held run as `status` (failed or cancelled) with an optional reason; its checkpoint
/// goes.
async fn end_run(
    tx: &mut super::database::WriteTx,
    id: Uuid,
    status: Status,
    error: Option<&str>,
) -> Result<()> {
    super::checkpoints::forget(tx, &id.to_string()).await?;
    super::frames::forget(tx, &id.to_string()).await?;
    sqlx::query("DELETE FROM history WHERE job_id = $1")
        .bind(id.to_string())
        .execute(&mut **tx)
        .await?;
    sqlx::query(
        "UPDATE jobs SET status = $1, error = $2, finished_at = $3, lease = NULL, \
         heartbeat_at = NULL WHERE id = $4",
    )
    .bind(status.as_str())
    .bind(error)
    .bind(now_ms())
    .bind(id.to_string())
    .execute(&mut **tx)
    .await?;
    Ok(())
}

/// What of a succeeded run is not stored: `None` when job `job` holds `rows` history rows
/// numbered 0.., and all `frames` frames (0..frames) in full, each the parts `particles` take.
async fn missing(
    tx: &mut super::database::WriteTx,
    job: &str,
    rows: usize,
    frames: u32,
    particles: usize,
) -> Result<Option<String>> {
    let (count, span): (i64, i64) =
        sqlx::query_as("SELECT COUNT(*), COALESCE(MAX(row) + 1, 0) FROM history WHERE job_id = $1")
            .bind(job)
            .fetch_one(&mut **tx)
            .await?;
    if (count, span) != (rows as i64, rows as i64) {
        return Ok(Some(format!("{count} of its {rows} history rows stored")));
    }
    if frames == 0 {
        return Ok(None);
    }
    let parts = particles.div_ceil(super::frames::PART_PARTICLES).max(1) as i64;
    let stored: Vec<(i64, i64)> =
        sqlx::query_as("SELECT k, COUNT(*) FROM frames WHERE job_id = $1 GROUP BY k ORDER BY k")
            .bind(job)
            .fetch_all(&mut **tx)
            .await?;
    let lost: Vec<String> = (0..frames as i64)
        .filter(|k| !stored.iter().any(|&(s, n)| s == *k && n == parts))
        .map(|k| k.to_string())
        .collect();
    Ok((!lost.is_empty()).then(|| {
        format!(
            "frame{} {} of its {frames} not stored",
            if lost.len() == 1 { "" } else { "s" },
            lost.join(", ")
        )
    }))
}

/// `INSERT INTO history … VALUES ($1, …), (…)` for `rows` rows of `width` values.
fn history_insert(rows: usize, width: usize) -> String {
    let tuples: Vec<String> = (0..rows)
        .map(|r| {
            let params: Vec<String> = (1..=width).map(|c| format!("${}", r * width + c)).collect();
            format!("({})", params.join(", "))
        })
        .collect();
    format!(
        "INSERT INTO history (job_id, row, {}) VALUES {}",
        HistoryRow::COLUMNS.join(", "),
        tuples.join(", ")
    )
}

/// Why a job that used up its attempts failed.
fn out_of_attempts(attempts: i64, fruitless: i64) -> String {
    format!(
        "started {attempts} times, {fruitless} of them without storing a checkpoint (the most \
         allowed), and never finished; not retried again"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::{NewJob, StoreError};

    async fn store() -> (tempfile::TempDir, Store) {
        crate::service::store::temp_store().await
    }

    fn job() -> NewJob {
        NewJob {
            id: Uuid::new_v4(),
            case_json: "{}".into(),
            label: None,
            particles: 10,
            idempotency_key: None,
        }
    }

    fn row(k: usize) -> HistoryRow {
        HistoryRow {
            time_ms: k as f64,
            displacement_mm: 0.01 * k as f64,
            ..HistoryRow::default()
        }
    }

    /// What broke: a frame the database refused during an outage was dropped with a log line,
    /// and the job still ended `succeeded` with one frame of its series missing.
    #[tokio::test]
    async fn a_run_whose_frame_was_not_stored_fails_saying_which_and_is_never_succeeded() {
        use crate::export::series::{FrameTime, FRAME_BYTES_PER_PARTICLE};
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        for k in [0, 2, 3] {
            let frame = crate::service::store::StoredFrame {
                at: FrameTime {
                    index: k,
                    travel_mm: k as f64,
                    time_ms: k as f64,
                },
                particles: 3,
                data: vec![1; 3 * FRAME_BYTES_PER_PARTICLE],
            };
            assert!(store.save_frame(j.id, claim.lease, &frame).await.unwrap());
        }
        let summary = crate::service::store::sample_summary();
        let history: Vec<HistoryRow> = (0..7).map(row).collect();
        let result = Succeeded {
            history: &history,
            summary: &summary,
            final_state: None,
            progress_json: None,
            frames: 4,
            particles: 3,
        };
        let stored = store.finish_succeeded(j.id, claim.lease, result).await;
        assert_eq!(stored.unwrap(), Some(Status::Failed));
        let rec = store.job(j.id).await.unwrap().unwrap();
        assert_eq!(rec.status, Status::Failed);
        let error = rec.error.unwrap();
        assert!(error.contains("frame 1 of its 4 not stored"), "{error}");
        assert!(rec.summary.is_none());
        assert!(store.history(j.id).await.unwrap().is_empty());
        assert!(store.frame_times(j.id).await.unwrap().is_empty());
        // With every frame stored it succeeds, history whole and in order.
        let k = job();
        store.submit(k.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let result = Succeeded {
            history: &history,
            frames: 0,
            ..result
        };
        let stored = store.finish_succeeded(k.id, claim.lease, result).await;
        assert_eq!(stored.unwrap(), Some(Status::Succeeded));
        let back = store.history(k.id).await.unwrap();
        assert_eq!(back.len(), 7);
        assert_eq!(back[6][0], 6.0);
    }

    /// What broke: one job's 100 000 history rows were written in one transaction that held
    /// SQLite's writer for half a minute; health checks, submits and the reaper timed out.
    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn storing_the_largest_history_never_holds_other_writers_back_for_long() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let history: Vec<HistoryRow> = (0..100_000).map(row).collect();
        let finishing = {
            let store = store.clone();
            tokio::spawn(async move {
                let summary = crate::service::store::sample_summary();
                let result = Succeeded {
                    history: &history,
                    summary: &summary,
                    final_state: None,
                    progress_json: None,
                    frames: 0,
                    particles: 0,
                };
                store.finish_succeeded(j.id, claim.lease, result).await
            })
        };
        let mut slowest = std::time::Duration::ZERO;
        let mut probes = 0;
        while !finishing.is_finished() {
            let started = std::time::Instant::now();
            store.probe_write().await.unwrap();
            slowest = slowest.max(started.elapsed());
            probes += 1;
            tokio::time::sleep(std::time::Duration::from_millis(20)).await;
        }
        assert_eq!(finishing.await.unwrap().unwrap(), Some(Status::Succeeded));
        assert_eq!(store.history(j.id).await.unwrap().len(), 100_000);
        // A batch of rows holds the writer for tens of milliseconds in the test profile; a second
        // allows for a loaded machine and is still far below the 3 s health timeout.
        assert!(
            probes > 1,
            "the history was stored before a probe could run"
        );
        assert!(
            slowest < std::time::Duration::from_secs(1),
            "a write waited {slowest:?} behind the history"
        );
    }

    /// What broke: while the database was away the running job's heartbeats failed, and when it
    /// came back the reaper of the very process running the job could requeue it first.
    #[tokio::test]
    async fn the_reaper_spares_the_jobs_its_own_process_runs() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let reaped = store.reap_stale(-1000, 2, &[j.id]).await.unwrap();
        assert_eq!(reaped, Reaped::default());
        assert_eq!(
            store.heartbeat(j.id, claim.lease, None).await.unwrap(),
            Some(false)
        );
        let reaped = store.reap_stale(-1000, 2, &[Uuid::new_v4()]).await.unwrap();
        assert_eq!(reaped.requeued, vec![j.id]);
    }

    #[tokio::test]
    async fn a_lost_lease_writes_nothing_and_a_stale_job_is_requeued_then_failed() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let first = store.claim("a").await.unwrap().unwrap();
        assert_eq!(first.attempt, 1);
        assert!(store.claim("a").await.unwrap().is_none());
        // Heartbeat older than "now": the reaper puts it back.
        let reaped = store.reap_stale(-1000, 2, &[]).await.unwrap();
        assert_eq!(reaped.requeued, vec![j.id]);
        assert_eq!(
            store.heartbeat(j.id, first.lease, None).await.unwrap(),
            None
        );
        let stored = store
            .finish_unsuccessful(j.id, first.lease, Status::Failed, Some("x"))
            .await
            .unwrap();
        assert_eq!(stored, None, "the old lease must not write");
        let second = store.claim("b").await.unwrap().unwrap();
        assert_eq!(second.attempt, 2);
        let reaped = store.reap_stale(-1000, 2, &[]).await.unwrap();
        assert_eq!(reaped.failed, vec![j.id]);
        let rec = store.job(j.id).await.unwrap().unwrap();
        assert_eq!(rec.status, Status::Failed);
        assert!(rec.error.unwrap().contains("started 2 times"));
    }

    #[tokio::test]
    async fn max_attempts_counts_claims_including_requeues_after_a_graceful_shutdown() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        // Two graceful shutdowns: the first puts the job back, the second has used both
        // attempts and fails it.
        let first = store.claim("a").await.unwrap().unwrap();
        let back = store.requeue(j.id, first.lease, 2).await.unwrap();
        assert_eq!(back, Some(Status::Queued));
        let second = store.claim("b").await.unwrap().unwrap();
        assert_eq!(second.attempt, 2);
        let back = store.requeue(j.id, second.lease, 2).await.unwrap();
        assert_eq!(back, Some(Status::Failed));
        let rec = store.job(j.id).await.unwrap().unwrap();
        assert_eq!(rec.status, Status::Failed);
        assert!(rec.error.unwrap().contains("started 2 times"));
        assert!(store.claim("c").await.unwrap().is_none());

        // One graceful requeue, then a lost worker: the second claim was the last.
        let k = job();
        store.submit(k.clone(), 10).await.unwrap();
        let first = store.claim("a").await.unwrap().unwrap();
        store.requeue(k.id, first.lease, 2).await.unwrap();
        store.claim("b").await.unwrap().unwrap();
        let reaped = store.reap_stale(-1000, 2, &[]).await.unwrap();
        assert_eq!(reaped.failed, vec![k.id]);
    }

    #[tokio::test]
    async fn a_cancel_accepted_while_running_wins_over_a_result_stored_after_it() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        assert!(matches!(
            store.cancel(j.id).await.unwrap(),
            crate::service::store::CancelOutcome::Requested(_)
        ));
        let summary = crate::service::store::sample_summary();
        let result = Succeeded {
            history: &[],
            summary: &summary,
            final_state: None,
            progress_json: None,
            frames: 0,
            particles: 0,
        };
        let stored = store.finish_succeeded(j.id, claim.lease, result).await;
        assert_eq!(stored.unwrap(), Some(Status::Cancelled));
        let rec = store.job(j.id).await.unwrap().unwrap();
        assert_eq!(rec.status, Status::Cancelled);
        assert!(rec.summary.is_none(), "nothing of the run is kept");
        // A requeue (shutdown) of a job whose cancel was asked cancels it too.
        let k = job();
        store.submit(k.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        store.cancel(k.id).await.unwrap();
        let back = store.requeue(k.id, claim.lease, 3).await.unwrap();
        assert_eq!(back, Some(Status::Cancelled));
    }

    #[tokio::test]
    async fn the_summary_columns_hold_the_typed_summary_s_numbers() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let summary = crate::service::store::sample_summary();
        let result = Succeeded {
            history: &[],
            summary: &summary,
            final_state: None,
            progress_json: None,
            frames: 0,
            particles: 0,
        };
        let stored = store.finish_succeeded(j.id, claim.lease, result).await;
        assert_eq!(stored.unwrap(), Some(Status::Succeeded));
        let row: (f64, f64, f64, f64, i64, String, f64, i64, i64, f64) = sqlx::query_as(
            "SELECT mean_load_n, peak_load_n, energy_absorbed_mj, crush_distance_mm, folds, mode, \
             energy_balance_error, particles, steps, wall_time_s FROM summaries WHERE job_id = $1",
        )
        .bind(j.id.to_string())
        .fetch_one(&store.pool)
        .await
        .unwrap();
        let s = &summary;
        assert_eq!(
            row,
            (
                s.mean_load_n,
                s.peak_load_n,
                s.energy_absorbed_mj,
                s.crush_distance_mm,
                s.folds as i64,
                s.mode.kind().to_string(),
                s.energy_balance_error,
                s.cost.particles as i64,
                s.cost.steps as i64,
                s.cost.wall_time_s
            )
        );
        assert!(!row.5.is_empty(), "a mode name");
        // And the JSON kept beside them reads back as a summary with the same numbers (the
        // references may differ in the last bit: serde_json's float parsing is not exact).
        let rec = store.job(j.id).await.unwrap().unwrap();
        let back = rec.summary.unwrap();
        assert_eq!(
            (back.mean_load_n, back.folds, back.mode, back.cost),
            (s.mean_load_n, s.folds, s.mode, s.cost)
        );
    }

    #[tokio::test]
    async fn a_stored_summary_that_does_not_read_is_corrupt_not_zeros() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let summary = crate::service::store::sample_summary();
        let result = Succeeded {
            history: &[],
            summary: &summary,
            final_state: None,
            progress_json: None,
            frames: 0,
            particles: 0,
        };
        store
            .finish_succeeded(j.id, claim.lease, result)
            .await
            .unwrap();
        // A summary written under another name of a field (as a rename in the solver would
        // leave the older rows): reading it must say so, not show zeros.
        let mut json = serde_json::to_value(&summary).unwrap();
        let o = json.as_object_mut().unwrap();
        let mean = o.remove("mean_load_n").unwrap();
        o.insert("mean_load".into(), mean);
        sqlx::query("UPDATE summaries SET summary_json = $1 WHERE job_id = $2")
            .bind(json.to_string())
            .bind(j.id.to_string())
            .execute(&store.pool)
            .await
            .unwrap();
        let err = store.job(j.id).await.unwrap_err();
        assert!(matches!(err, StoreError::Corrupt(_)), "{err:?}");
        let text = err.to_string();
        assert!(
            text.contains("mean_load_n") && text.contains(&j.id.to_string()),
            "{text}"
        );
    }

    #[test]
    fn history_columns_match_the_migration() {
        let sqlite = [
            include_str!("../../../migrations/sqlite/0001_jobs.sql"),
            include_str!("../../../migrations/sqlite/0004_energy_terms.sql"),
        ]
        .map(|s| s.replace("ADD COLUMN ", "    "))
        .concat();
        let postgres = include_str!("../../../migrations/postgres/0001_jobs.sql");
        for (backend, sql) in [("sqlite", sqlite.as_str()), ("postgres", postgres)] {
            for c in HistoryRow::COLUMNS {
                assert!(
                    sql.contains(&format!("    {c} ")),
                    "history column {c} missing from the {backend} migrations"
                );
            }
        }
    }
}
