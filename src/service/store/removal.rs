//! Deleting what clients no longer need: a finished job, a sweep whose jobs have all finished,
//! and (retention, `--keep-days`) every finished job and sweep older than a cutoff. A job's
//! summary, history, final state, frames and checkpoint go with its row (`ON DELETE CASCADE`); a
//! sweep's jobs go with it, in the same transaction.

use super::database::{now_ms, Result, Status, Store};
use uuid::Uuid;

/// What a delete did.
#[derive(Debug, PartialEq, Eq)]
pub enum Deleted {
    NotFound,
    /// The job is queued or running (cancel it first); or, for a sweep, this many of its jobs.
    Unfinished(Status, i64),
    /// The job belongs to this sweep: it goes with the sweep, not alone.
    InSweep(Uuid),
    /// Gone, with this many jobs.
    Done {
        jobs: i64,
    },
}

/// What a retention pass deleted.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Pruned {
    pub jobs: u64,
    pub sweeps: u64,
}

/// Rows one retention statement deletes at most, so that no transaction holds the write lock
/// for long; a pass repeats until nothing is left.
const PRUNE_BATCH: i64 = 200;

/// The statuses of a finished job, as SQL.
const FINISHED: &str = "('succeeded', 'failed', 'cancelled')";

impl Store {
    /// Deletes a finished job that belongs to no sweep, with everything stored for it.
    pub async fn delete_job(&self, id: Uuid) -> Result<Deleted> {
        let mut tx = self.write().await?;
        let sql = format!(
            "SELECT status, sweep_id FROM jobs WHERE id = $1{}",
            self.backend.for_update()
        );
        let row: Option<(String, Option<String>)> = sqlx::query_as(&sql)
            .bind(id.to_string())
            .fetch_optional(&mut *tx)
            .await?;
        let Some((status, sweep)) = row else {
            return Ok(Deleted::NotFound);
        };
        let status = Status::parse(&status).ok_or_else(|| {
            super::database::StoreError::Corrupt(format!("job {id} has status {status}"))
        })?;
        if !status.is_terminal() {
            return Ok(Deleted::Unfinished(status, 1));
        }
        if let Some(sweep) = sweep {
            return Ok(Deleted::InSweep(super::database::parse_uuid(&sweep)?));
        }
        delete_jobs(&mut tx, "id = $1", &id.to_string()).await?;
        tx.commit().await?;
        Ok(Deleted::Done { jobs: 1 })
    }

    /// Deletes a sweep and all its jobs, once every one of them has finished.
    pub async fn delete_sweep(&self, id: Uuid) -> Result<Deleted> {
        let mut tx = self.write().await?;
        let key = id.to_string();
        let sql = format!(
            "SELECT id FROM sweeps WHERE id = $1{}",
            self.backend.for_update()
        );
        let found: Option<(String,)> = sqlx::query_as(&sql)
            .bind(&key)
            .fetch_optional(&mut *tx)
            .await?;
        if found.is_none() {
            return Ok(Deleted::NotFound);
        }
        // Locks the sweep's jobs on PostgreSQL, so that none is claimed meanwhile.
        let sql = format!(
            "SELECT status FROM jobs WHERE sweep_id = $1{}",
            self.backend.for_update()
        );
        let statuses: Vec<(String,)> = sqlx::query_as(&sql).bind(&key).fetch_all(&mut *tx).await?;
        let unfinished: Vec<Status> = statuses
            .iter()
            .filter_map(|(s,)| Status::parse(s))
            .filter(|s| !s.is_terminal())
            .collect();
        if let Some(first) = unfinished.first() {
            return Ok(Deleted::Unfinished(*first, unfinished.len() as i64));
        }
        let jobs = delete_jobs(&mut tx, "sweep_id = $1", &key).await?;
        sqlx::query("DELETE FROM sweeps WHERE id = $1")
            .bind(&key)
            .execute(&mut *tx)
            .await?;
        tx.commit().await?;
        Ok(Deleted::Done { jobs: jobs as i64 })
    }

    /// Deletes every finished job of no sweep that finished more than `keep_ms` ago, and every
    /// sweep whose jobs have all finished, the last more than `keep_ms` ago (a sweep without
    /// jobs by when it was made), in batches of [`PRUNE_BATCH`].
    pub async fn prune(&self, keep_ms: i64) -> Result<Pruned> {
        let cutoff = now_ms().saturating_sub(keep_ms);
        let mut pruned = Pruned::default();
        loop {
            let mut tx = self.write().await?;
            let n = sqlx::query(&format!(
                "DELETE FROM jobs WHERE id IN (SELECT id FROM jobs WHERE sweep_id IS NULL \
                 AND status IN {FINISHED} AND finished_at < $1 ORDER BY finished_at LIMIT $2)"
            ))
            .bind(cutoff)
            .bind(PRUNE_BATCH)
            .execute(&mut *tx)
            .await?
            .rows_affected();
            tx.commit().await?;
            pruned.jobs += n;
            if n < PRUNE_BATCH as u64 {
                break;
            }
        }
        loop {
            let old: Vec<(String,)> = sqlx::query_as(&format!(
                "SELECT s.id FROM sweeps s WHERE s.created_at < $1 \
                 AND NOT EXISTS (SELECT 1 FROM jobs j WHERE j.sweep_id = s.id \
                 AND (j.status NOT IN {FINISHED} OR j.finished_at >= $1)) \
                 ORDER BY s.created_at LIMIT $2"
            ))
            .bind(cutoff)
            .bind(PRUNE_BATCH)
            .fetch_all(&self.pool)
            .await?;
            for (id,) in &old {
                // Checked again under the lock: a sweep's job cannot start again, but the
                // sweep may have been deleted by a client or another node meanwhile.
                if let Deleted::Done { jobs } =
                    self.delete_sweep(super::database::parse_uuid(id)?).await?
                {
                    pruned.sweeps += 1;
                    pruned.jobs += jobs as u64;
                }
            }
            if old.len() < PRUNE_BATCH as usize {
                break;
            }
        }
        Ok(pruned)
    }
}

/// Deletes the jobs `condition` (with one parameter, `key`) selects; their summaries,
/// histories, final states and checkpoints go with them.
async fn delete_jobs(tx: &mut super::database::WriteTx, condition: &str, key: &str) -> Result<u64> {
    let done = sqlx::query(&format!("DELETE FROM jobs WHERE {condition}"))
        .bind(key)
        .execute(&mut **tx)
        .await?;
    Ok(done.rows_affected())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::{NewJob, NewSweep, Succeeded};

    async fn store() -> (tempfile::TempDir, Store) {
        crate::service::store::temp_store().await
    }

    fn job() -> NewJob {
        NewJob {
            id: Uuid::new_v4(),
            case_json: "{}".into(),
            label: None,
            particles: 10,
            idempotency_key: Some(Uuid::new_v4().to_string()),
        }
    }

    /// Runs the oldest queued job to success with a history row and a final state.
    async fn succeed(store: &Store) -> Uuid {
        let claim = store.claim("t").await.unwrap().unwrap();
        let frame = crate::service::store::StoredFrame {
            at: crate::export::series::FrameTime {
                index: 0,
                travel_mm: 0.0,
                time_ms: 0.0,
            },
            particles: 1,
            data: vec![0u8; 56],
        };
        assert!(store
            .save_frame(claim.id, claim.lease, &frame)
            .await
            .unwrap());
        let summary = crate::service::store::sample_summary();
        let row = crate::solver::HistoryRow::default();
        let result = Succeeded {
            history: &[row],
            summary: &summary,
            final_state: Some((1, &[0u8; 16])),
            progress_json: None,
            frames: 0,
            particles: 0,
        };
        store
            .finish_succeeded(claim.id, claim.lease, result)
            .await
            .unwrap();
        claim.id
    }

    /// Rows any table holds for the job.
    async fn rows_of(store: &Store, id: Uuid) -> i64 {
        let mut total = 0;
        for (table, column) in [
            ("jobs", "id"),
            ("summaries", "job_id"),
            ("history", "job_id"),
            ("final_states", "job_id"),
            ("frames", "job_id"),
            ("checkpoints", "job_id"),
        ] {
            let (n,): (i64,) =
                sqlx::query_as(&format!("SELECT COUNT(*) FROM {table} WHERE {column} = $1"))
                    .bind(id.to_string())
                    .fetch_one(&store.pool)
                    .await
                    .unwrap();
            total += n;
        }
        total
    }

    #[tokio::test]
    async fn a_deleted_job_leaves_no_row_in_any_table_and_an_unfinished_one_stays() {
        let (_dir, store) = store().await;
        let done = job();
        store.submit(done.clone(), 10).await.unwrap();
        assert_eq!(succeed(&store).await, done.id);
        assert!(
            rows_of(&store, done.id).await >= 5,
            "job, summary, history, state, frame"
        );
        let queued = job();
        store.submit(queued.clone(), 10).await.unwrap();
        assert_eq!(
            store.delete_job(queued.id).await.unwrap(),
            Deleted::Unfinished(Status::Queued, 1)
        );
        assert_eq!(
            store.delete_job(done.id).await.unwrap(),
            Deleted::Done { jobs: 1 }
        );
        assert_eq!(rows_of(&store, done.id).await, 0);
        assert_eq!(store.delete_job(done.id).await.unwrap(), Deleted::NotFound);
        // The idempotency key is free again: a retried submit makes a new job.
        let again = NewJob {
            id: Uuid::new_v4(),
            ..done.clone()
        };
        let submitted = store.submit(again.clone(), 10).await.unwrap();
        assert!(
            matches!(submitted, crate::service::store::Submitted::Created(r) if r.id == again.id)
        );
    }

    #[tokio::test]
    async fn a_sweep_goes_with_its_jobs_once_all_have_finished_and_retention_prunes_old_ones() {
        let (_dir, store) = store().await;
        let sweep = NewSweep {
            id: Uuid::new_v4(),
            label: Some("s".into()),
            base_json: "{}".into(),
            parameters_json: "[]".into(),
            jobs: vec![(job(), "{}".into()), (job(), "{}".into())],
            owner: Some("alice".into()),
        };
        let ids: Vec<Uuid> = sweep.jobs.iter().map(|(j, _)| j.id).collect();
        store.create_sweep(sweep.clone(), 10).await.unwrap();
        let (record, _) = store.sweep(sweep.id).await.unwrap().unwrap();
        assert_eq!(record.owner.as_deref(), Some("alice"));
        succeed(&store).await;
        assert_eq!(
            store.delete_job(ids[0]).await.unwrap(),
            Deleted::InSweep(sweep.id)
        );
        assert_eq!(
            store.delete_sweep(sweep.id).await.unwrap(),
            Deleted::Unfinished(Status::Queued, 1)
        );
        // Retention keeps what is younger than the cutoff, and a sweep with a job unfinished.
        let lone = job();
        store.submit(lone.clone(), 10).await.unwrap();
        assert_eq!(store.prune(0).await.unwrap(), Pruned::default());
        store.cancel(ids[1]).await.unwrap();
        succeed(&store).await;
        assert_eq!(store.prune(60_000).await.unwrap(), Pruned::default());
        tokio::time::sleep(std::time::Duration::from_millis(5)).await;
        let pruned = store.prune(0).await.unwrap();
        assert_eq!(pruned, Pruned { jobs: 3, sweeps: 1 });
        assert!(store.sweep(sweep.id).await.unwrap().is_none());
        for id in ids.iter().chain([&lone.id]) {
            assert_eq!(rows_of(&store, *id).await, 0);
        }
    }
}
