//! Checkpoints of running jobs: stored under the claim's lease (a worker that lost its job
//! cannot write one), read by whichever node claims the job next, and gone once the job ends.
//! A claim that stores a checkpoint has moved the job on: it does not count against
//! `--max-attempts` (see `claims::Store::requeue` and `reap_stale`).

use super::database::{now_ms, Result, Store};
use super::lease::holds;
use uuid::Uuid;

/// A job's stored checkpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredCheckpoint {
    /// The claim that wrote it.
    pub attempt: i64,
    /// Solver steps it stands at.
    pub step: i64,
    /// Share of the crush distance done, 0..1.
    pub fraction: f64,
    pub data: Vec<u8>,
}

impl Store {
    /// Stores `checkpoint` as job `id`'s (replacing an older one) while `lease` holds the job,
    /// and counts claim `attempt` as one that moved the job on. False when the lease was lost:
    /// nothing is written.
    pub async fn save_checkpoint(
        &self,
        id: Uuid,
        lease: Uuid,
        checkpoint: &StoredCheckpoint,
    ) -> Result<bool> {
        let mut tx = self.write().await?;
        if holds(&self.backend, &mut tx, id, lease).await?.is_none() {
            return Ok(false);
        }
        let now = now_ms();
        sqlx::query(
            "INSERT INTO checkpoints (job_id, attempt, step, fraction, written_at, data) \
             VALUES ($1, $2, $3, $4, $5, $6) ON CONFLICT (job_id) DO UPDATE SET \
             attempt = excluded.attempt, step = excluded.step, fraction = excluded.fraction, \
             written_at = excluded.written_at, data = excluded.data, ladder_json = NULL",
        )
        .bind(id.to_string())
        .bind(checkpoint.attempt)
        .bind(checkpoint.step)
        .bind(checkpoint.fraction)
        .bind(now)
        .bind(checkpoint.data.as_slice())
        .execute(&mut *tx)
        .await?;
        advanced(&mut tx, id, checkpoint.attempt).await?;
        sqlx::query(
            "UPDATE jobs SET checkpoint_step = $1, checkpoint_fraction = $2, checkpoint_at = $3 \
             WHERE id = $4",
        )
        .bind(checkpoint.step)
        .bind(checkpoint.fraction)
        .bind(now)
        .bind(id.to_string())
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(true)
    }

    /// Stores the rungs of job `id`'s error-bar ladder that claim `attempt` has finished
    /// (`ladder_json`, beside the checkpoint of the finished run), while `lease` holds the job,
    /// and counts the claim as one that moved the job on. False when the lease was lost or the
    /// job has no checkpoint to keep them beside: nothing is written.
    pub async fn save_ladder(
        &self,
        id: Uuid,
        lease: Uuid,
        attempt: i64,
        ladder_json: &str,
    ) -> Result<bool> {
        let mut tx = self.write().await?;
        if holds(&self.backend, &mut tx, id, lease).await?.is_none() {
            return Ok(false);
        }
        let kept = sqlx::query("UPDATE checkpoints SET ladder_json = $1 WHERE job_id = $2")
            .bind(ladder_json)
            .bind(id.to_string())
            .execute(&mut *tx)
            .await?
            .rows_affected();
        if kept == 0 {
            return Ok(false);
        }
        advanced(&mut tx, id, attempt).await?;
        tx.commit().await?;
        Ok(true)
    }

    /// The rungs of job `id`'s ladder stored so far, as JSON; `None` when it has none.
    pub async fn ladder(&self, id: Uuid) -> Result<Option<String>> {
        let row: Option<(Option<String>,)> =
            sqlx::query_as("SELECT ladder_json FROM checkpoints WHERE job_id = $1")
                .bind(id.to_string())
                .fetch_optional(&self.pool)
                .await?;
        Ok(row.and_then(|(json,)| json))
    }

    /// Job `id`'s checkpoint, if it has one.
    pub async fn checkpoint(&self, id: Uuid) -> Result<Option<StoredCheckpoint>> {
        let row: Option<(i64, i64, f64, Vec<u8>)> = sqlx::query_as(
            "SELECT attempt, step, fraction, data FROM checkpoints WHERE job_id = $1",
        )
        .bind(id.to_string())
        .fetch_optional(&self.pool)
        .await?;
        Ok(row.map(|(attempt, step, fraction, data)| StoredCheckpoint {
            attempt,
            step,
            fraction,
            data,
        }))
    }

    /// Deletes job `id`'s checkpoint (one that could not be used), if `lease` still holds it.
    pub async fn discard_checkpoint(&self, id: Uuid, lease: Uuid) -> Result<()> {
        let mut tx = self.write().await?;
        if holds(&self.backend, &mut tx, id, lease).await?.is_some() {
            forget(&mut tx, &id.to_string()).await?;
        }
        tx.commit().await?;
        Ok(())
    }
}

/// Counts claim `attempt` of job `id` as one that moved the job on (once per claim).
async fn advanced(tx: &mut super::database::WriteTx, id: Uuid, attempt: i64) -> Result<()> {
    sqlx::query(
        "UPDATE jobs SET advanced = advanced + \
         (CASE WHEN COALESCE(checkpoint_attempt, 0) = $1 THEN 0 ELSE 1 END), \
         checkpoint_attempt = $1 WHERE id = $2",
    )
    .bind(attempt)
    .bind(id.to_string())
    .execute(&mut **tx)
    .await?;
    Ok(())
}

/// Deletes job `job`'s checkpoint and its place in the job's row: the job has ended (or its
/// checkpoint cannot be used).
pub(super) async fn forget(tx: &mut super::database::WriteTx, job: &str) -> Result<()> {
    sqlx::query("DELETE FROM checkpoints WHERE job_id = $1")
        .bind(job)
        .execute(&mut **tx)
        .await?;
    sqlx::query(
        "UPDATE jobs SET checkpoint_step = NULL, checkpoint_fraction = NULL, \
         checkpoint_at = NULL WHERE id = $1",
    )
    .bind(job)
    .execute(&mut **tx)
    .await?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::{NewJob, Status};

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

    fn checkpoint(attempt: i64, step: i64) -> StoredCheckpoint {
        StoredCheckpoint {
            attempt,
            step,
            fraction: step as f64 / 100.0,
            data: vec![step as u8; 64],
        }
    }

    #[tokio::test]
    async fn a_claim_that_stored_a_checkpoint_does_not_count_against_max_attempts() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        // One attempt allowed. The first claim stores two checkpoints (counted once) and is
        // lost: the job goes back to the queue, not to failed.
        let first = store.claim("a").await.unwrap().unwrap();
        assert!(store
            .save_checkpoint(j.id, first.lease, &checkpoint(1, 10))
            .await
            .unwrap());
        assert!(store
            .save_checkpoint(j.id, first.lease, &checkpoint(1, 20))
            .await
            .unwrap());
        assert_eq!(
            store.reap_stale(-1000, 1, &[]).await.unwrap().requeued,
            vec![j.id]
        );
        let rec = store.job(j.id).await.unwrap().unwrap();
        assert_eq!(rec.checkpoint.map(|c| c.step), Some(20));
        // A graceful requeue after a checkpoint does not count either.
        let second = store.claim("b").await.unwrap().unwrap();
        assert_eq!(
            store.checkpoint(j.id).await.unwrap(),
            Some(checkpoint(1, 20))
        );
        assert!(store
            .save_checkpoint(j.id, second.lease, &checkpoint(2, 30))
            .await
            .unwrap());
        assert_eq!(
            store.requeue(j.id, second.lease, 1).await.unwrap(),
            Some(Status::Queued)
        );
        // A claim that stores nothing counts: the one attempt allowed is used up.
        store.claim("c").await.unwrap().unwrap();
        let reaped = store.reap_stale(-1000, 1, &[]).await.unwrap();
        assert_eq!(reaped.failed, vec![j.id]);
        let rec = store.job(j.id).await.unwrap().unwrap();
        let error = rec.error.unwrap();
        assert!(
            error.contains("started 3 times, 1 of them without"),
            "{error}"
        );
        assert_eq!(rec.checkpoint, None, "an ended job keeps no checkpoint");
        assert_eq!(store.checkpoint(j.id).await.unwrap(), None);
    }

    #[tokio::test]
    async fn a_lost_lease_stores_no_checkpoint_and_a_finished_job_keeps_none() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let first = store.claim("a").await.unwrap().unwrap();
        store.reap_stale(-1000, 5, &[]).await.unwrap();
        assert!(!store
            .save_checkpoint(j.id, first.lease, &checkpoint(1, 10))
            .await
            .unwrap());
        assert_eq!(store.checkpoint(j.id).await.unwrap(), None);

        let second = store.claim("b").await.unwrap().unwrap();
        assert!(store
            .save_checkpoint(j.id, second.lease, &checkpoint(2, 10))
            .await
            .unwrap());
        store.discard_checkpoint(j.id, second.lease).await.unwrap();
        assert_eq!(store.checkpoint(j.id).await.unwrap(), None);
        assert!(store
            .save_checkpoint(j.id, second.lease, &checkpoint(2, 20))
            .await
            .unwrap());
        let summary = crate::service::store::sample_summary();
        let result = crate::service::store::Succeeded {
            history: &[],
            summary: &summary,
            final_state: None,
            progress_json: None,
            frames: 0,
            particles: 0,
        };
        store
            .finish_succeeded(j.id, second.lease, result)
            .await
            .unwrap();
        assert_eq!(store.checkpoint(j.id).await.unwrap(), None);
        assert_eq!(store.job(j.id).await.unwrap().unwrap().checkpoint, None);
    }

    /// What broke: an interruption while the error bar was priced recomputed the crush and
    /// every rung, and used up the job's attempts although its run had finished.
    #[tokio::test]
    async fn the_rungs_of_a_ladder_are_kept_beside_the_finished_run_and_move_the_job_on() {
        let (_dir, store) = store().await;
        let j = job();
        store.submit(j.clone(), 10).await.unwrap();
        let first = store.claim("a").await.unwrap().unwrap();
        assert!(
            !store.save_ladder(j.id, first.lease, 1, "[]").await.unwrap(),
            "no ladder without the finished run's checkpoint"
        );
        assert!(store
            .save_checkpoint(j.id, first.lease, &checkpoint(1, 100))
            .await
            .unwrap());
        assert!(store
            .save_ladder(j.id, first.lease, 1, "[1]")
            .await
            .unwrap());
        assert_eq!(store.ladder(j.id).await.unwrap().as_deref(), Some("[1]"));
        assert_eq!(
            store.requeue(j.id, first.lease, 1).await.unwrap(),
            Some(Status::Queued)
        );
        // The next claim finishes a rung and nothing else: it moved the job on, so with one
        // fruitless claim allowed the job is requeued again, not failed.
        let second = store.claim("a").await.unwrap().unwrap();
        assert!(store
            .save_ladder(j.id, second.lease, 2, "[1,2]")
            .await
            .unwrap());
        assert_eq!(
            store.requeue(j.id, second.lease, 1).await.unwrap(),
            Some(Status::Queued)
        );
        assert_eq!(store.ladder(j.id).await.unwrap().as_deref(), Some("[1,2]"));
        // A new checkpoint of the run (another run's state) clears the rungs it had.
        let third = store.claim("a").await.unwrap().unwrap();
        assert!(store
            .save_checkpoint(j.id, third.lease, &checkpoint(3, 50))
            .await
            .unwrap());
        assert_eq!(store.ladder(j.id).await.unwrap(), None);
    }
}
