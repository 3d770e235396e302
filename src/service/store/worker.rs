//! Jobs as workers see them: claim one with a single `UPDATE … RETURNING`, heartbeat, finish
//! (history, summary and state in one transaction), requeue, and reap jobs whose worker died.
//!
//! Every write after the claim names the claim's lease: a worker that lost its job to the
//! reaper can no longer write to it, so a job is never stored twice.

use super::{now_ms, Result, Status, Store};
use crate::solver::{HistoryRow, Summary};
use sqlx::Sqlite;
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
}

/// History rows per INSERT statement (2 + `HistoryRow::COLUMNS.len()` bound values each, far
/// below SQLite's limit of 32 766).
const HISTORY_CHUNK: usize = 500;

impl Store {
    /// Claims the oldest queued job for `worker`.
    pub async fn claim(&self, worker: &str) -> Result<Option<Claimed>> {
        let lease = Uuid::new_v4();
        let now = now_ms();
        let mut tx = self.write().await?;
        let row: Option<(String, String, i64)> = sqlx::query_as(
            "UPDATE jobs SET status = 'running', attempts = attempts + 1, lease = ?1, worker = ?2, \
             heartbeat_at = ?3, started_at = COALESCE(started_at, ?3), progress_json = NULL, \
             progress_fraction = NULL \
             WHERE seq = (SELECT seq FROM jobs WHERE status = 'queued' ORDER BY seq LIMIT 1) \
             RETURNING id, case_json, attempts",
        )
        .bind(lease.to_string())
        .bind(worker)
        .bind(now)
        .fetch_optional(&mut *tx)
        .await?;
        tx.commit().await?;
        row.map(|(id, case_json, attempt)| {
            Ok(Claimed {
                id: super::parse_uuid(&id)?,
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
        let mut tx = self.write().await?;
        let row: Option<(i64,)> = sqlx::query_as(
            "UPDATE jobs SET heartbeat_at = ?, progress_json = COALESCE(?, progress_json), \
             progress_fraction = COALESCE(?, progress_fraction) \
             WHERE id = ? AND lease = ? AND status = 'running' RETURNING cancel_requested",
        )
        .bind(now_ms())
        .bind(progress.map(|p| p.0))
        .bind(progress.map(|p| p.1))
        .bind(id.to_string())
        .bind(lease.to_string())
        .fetch_optional(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(row.map(|(c,)| c != 0))
    }

    /// Stores a successful run: history, summary, final particle state (when kept) and job
    /// state together. False when the lease was lost (nothing is written).
    pub async fn finish_succeeded(
        &self,
        id: Uuid,
        lease: Uuid,
        result: Succeeded<'_>,
    ) -> Result<bool> {
        let Succeeded {
            history,
            summary,
            final_state,
            progress_json,
        } = result;
        let summary_value = serde_json::to_value(summary)
            .map_err(|e| super::StoreError::Corrupt(format!("summary: {e}")))?;
        let num = |ptr: &str| {
            summary_value
                .pointer(ptr)
                .and_then(|v| v.as_f64())
                .unwrap_or(0.0)
        };
        let mode = summary_value
            .pointer("/mode/kind")
            .and_then(|v| v.as_str())
            .unwrap_or("unknown");
        let mut tx = self.write().await?;
        if !holds(&mut tx, id, lease).await? {
            return Ok(false);
        }
        let job = id.to_string();
        // A retried job starts from nothing: no row of an earlier attempt survives.
        sqlx::query("DELETE FROM history WHERE job_id = ?")
            .bind(&job)
            .execute(&mut *tx)
            .await?;
        sqlx::query("DELETE FROM summaries WHERE job_id = ?")
            .bind(&job)
            .execute(&mut *tx)
            .await?;
        sqlx::query("DELETE FROM final_states WHERE job_id = ?")
            .bind(&job)
            .execute(&mut *tx)
            .await?;
        if let Some((particles, data)) = final_state {
            sqlx::query("INSERT INTO final_states (job_id, particles, data) VALUES (?, ?, ?)")
                .bind(&job)
                .bind(particles as i64)
                .bind(data)
                .execute(&mut *tx)
                .await?;
        }
        for (chunk_no, chunk) in history.chunks(HISTORY_CHUNK).enumerate() {
            let mut q = sqlx::QueryBuilder::<Sqlite>::new(format!(
                "INSERT INTO history (job_id, row, {}) ",
                HistoryRow::COLUMNS.join(", ")
            ));
            q.push_values(chunk.iter().enumerate(), |mut b, (i, row)| {
                b.push_bind(&job)
                    .push_bind((chunk_no * HISTORY_CHUNK + i) as i64);
                for v in row.values() {
                    b.push_bind(v);
                }
            });
            q.build().execute(&mut *tx).await?;
        }
        sqlx::query(
            "INSERT INTO summaries (job_id, mean_load_n, peak_load_n, energy_absorbed_mj, \
             crush_distance_mm, folds, mode, energy_balance_error, particles, steps, wall_time_s, \
             summary_json) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
        )
        .bind(&job)
        .bind(num("/mean_load_n"))
        .bind(num("/peak_load_n"))
        .bind(num("/energy_absorbed_mj"))
        .bind(num("/crush_distance_mm"))
        .bind(num("/folds") as i64)
        .bind(mode)
        .bind(num("/energy_balance_error"))
        .bind(num("/cost/particles") as i64)
        .bind(num("/cost/steps") as i64)
        .bind(num("/cost/wall_time_s"))
        .bind(summary_value.to_string())
        .execute(&mut *tx)
        .await?;
        sqlx::query(
            "UPDATE jobs SET status = 'succeeded', finished_at = ?, lease = NULL, heartbeat_at = NULL, \
             progress_json = COALESCE(?, progress_json), progress_fraction = 1.0, error = NULL \
             WHERE id = ?",
        )
        .bind(now_ms())
        .bind(progress_json)
        .bind(&job)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(true)
    }

    /// Ends a run as failed (with the reason) or cancelled. False when the lease was lost.
    pub async fn finish_unsuccessful(
        &self,
        id: Uuid,
        lease: Uuid,
        status: Status,
        error: Option<&str>,
    ) -> Result<bool> {
        debug_assert!(matches!(status, Status::Failed | Status::Cancelled));
        let mut tx = self.write().await?;
        let done = sqlx::query(
            "UPDATE jobs SET status = ?, error = ?, finished_at = ?, lease = NULL, heartbeat_at = NULL \
             WHERE id = ? AND lease = ? AND status = 'running'",
        )
        .bind(status.as_str())
        .bind(error)
        .bind(now_ms())
        .bind(id.to_string())
        .bind(lease.to_string())
        .execute(&mut *tx)
        .await?
        .rows_affected();
        tx.commit().await?;
        Ok(done == 1)
    }

    /// Puts a job this worker could not finish (shutdown) back in the queue.
    pub async fn requeue(&self, id: Uuid, lease: Uuid) -> Result<bool> {
        let mut tx = self.write().await?;
        let done = sqlx::query(
            "UPDATE jobs SET status = 'queued', lease = NULL, worker = NULL, heartbeat_at = NULL, \
             progress_json = NULL, progress_fraction = NULL \
             WHERE id = ? AND lease = ? AND status = 'running'",
        )
        .bind(id.to_string())
        .bind(lease.to_string())
        .execute(&mut *tx)
        .await?
        .rows_affected();
        tx.commit().await?;
        Ok(done == 1)
    }

    /// Running jobs whose heartbeat is older than `stale_ms`: back to the queue, or failed
    /// once their worker has been lost `max_attempts` times, or cancelled if that was asked.
    pub async fn reap_stale(&self, stale_ms: i64, max_attempts: u32) -> Result<Reaped> {
        let now = now_ms();
        let cutoff = now - stale_ms;
        let mut tx = self.write().await?;
        let ids = |rows: Vec<(String,)>| -> Result<Vec<Uuid>> {
            rows.iter().map(|(id,)| super::parse_uuid(id)).collect()
        };
        let cancelled = sqlx::query_as(
            "UPDATE jobs SET status = 'cancelled', finished_at = ?1, lease = NULL, \
             heartbeat_at = NULL, lost = lost + 1 \
             WHERE status = 'running' AND heartbeat_at < ?2 AND cancel_requested = 1 RETURNING id",
        )
        .bind(now)
        .bind(cutoff)
        .fetch_all(&mut *tx)
        .await?;
        let failed = sqlx::query_as(
            "UPDATE jobs SET status = 'failed', finished_at = ?1, lease = NULL, heartbeat_at = NULL, \
             lost = lost + 1, error = 'the worker running this job stopped answering ' \
             || (lost + 1) || ' times; not retried again' \
             WHERE status = 'running' AND heartbeat_at < ?2 AND lost + 1 >= ?3 RETURNING id",
        )
        .bind(now)
        .bind(cutoff)
        .bind(max_attempts as i64)
        .fetch_all(&mut *tx)
        .await?;
        let requeued = sqlx::query_as(
            "UPDATE jobs SET status = 'queued', lease = NULL, worker = NULL, heartbeat_at = NULL, \
             lost = lost + 1, progress_json = NULL, progress_fraction = NULL \
             WHERE status = 'running' AND heartbeat_at < ?1 RETURNING id",
        )
        .bind(cutoff)
        .fetch_all(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(Reaped {
            requeued: ids(requeued)?,
            failed: ids(failed)?,
            cancelled: ids(cancelled)?,
        })
    }
}

/// Whether `lease` still holds the running job `id`.
async fn holds(tx: &mut sqlx::Transaction<'static, Sqlite>, id: Uuid, lease: Uuid) -> Result<bool> {
    let row: Option<(i64,)> =
        sqlx::query_as("SELECT 1 FROM jobs WHERE id = ? AND lease = ? AND status = 'running'")
            .bind(id.to_string())
            .bind(lease.to_string())
            .fetch_optional(&mut **tx)
            .await?;
    Ok(row.is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::NewJob;

    async fn store() -> (tempfile::TempDir, Store) {
        let dir = tempfile::tempdir().unwrap();
        let url = format!("sqlite://{}", dir.path().join("t.db").display());
        let store = Store::open(&url).await.unwrap();
        (dir, store)
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

    #[tokio::test]
    async fn a_lost_lease_writes_nothing_and_a_stale_job_is_requeued_then_failed() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let first = store.claim("a").await.unwrap().unwrap();
        assert_eq!(first.attempt, 1);
        assert!(store.claim("a").await.unwrap().is_none());
        // Heartbeat older than "now": the reaper puts it back.
        let reaped = store.reap_stale(-1000, 2).await.unwrap();
        assert_eq!(reaped.requeued, vec![j.id]);
        assert_eq!(
            store.heartbeat(j.id, first.lease, None).await.unwrap(),
            None
        );
        let summary_free = store
            .finish_unsuccessful(j.id, first.lease, Status::Failed, Some("x"))
            .await
            .unwrap();
        assert!(!summary_free, "the old lease must not write");
        let second = store.claim("b").await.unwrap().unwrap();
        assert_eq!(second.attempt, 2);
        let reaped = store.reap_stale(-1000, 2).await.unwrap();
        assert_eq!(reaped.failed, vec![j.id]);
        let rec = store.job(j.id).await.unwrap().unwrap();
        assert_eq!(rec.status, Status::Failed);
        assert!(rec.error.unwrap().contains("stopped answering 2 times"));
    }

    #[test]
    fn history_columns_match_the_migration() {
        let sql = [
            include_str!("../../../migrations/0001_jobs.sql"),
            include_str!("../../../migrations/0004_energy_terms.sql"),
        ]
        .map(|s| s.replace("ADD COLUMN ", "    "))
        .concat();
        for c in HistoryRow::COLUMNS {
            assert!(
                sql.contains(&format!("    {c} ")),
                "history column {c} missing from the migrations"
            );
        }
    }
}
