//! Sweeps: a base case and lists of values, stored with all their jobs in one transaction.

use super::jobs::{insert_job, queue_depth, NewJob};
use super::{job_from_row, now_ms, JobRecord, Result, Store, StoreError, JOB_COLUMNS, JOB_FROM};
use uuid::Uuid;

/// A sweep to insert, with one job per combination.
#[derive(Debug, Clone)]
pub struct NewSweep {
    pub id: Uuid,
    pub label: Option<String>,
    pub base_json: String,
    /// `[[field, [values]], ...]`.
    pub parameters_json: String,
    /// Each job with its swept values as a JSON object.
    pub jobs: Vec<(NewJob, String)>,
    /// The name of the token that submitted the sweep, stored as each job's owner.
    pub owner: Option<String>,
}

/// A sweep as stored.
#[derive(Debug, Clone)]
pub struct SweepRecord {
    pub id: Uuid,
    pub created_at: i64,
    pub label: Option<String>,
    pub base_json: String,
    pub parameters_json: String,
}

#[derive(Debug)]
pub enum SweepSubmitted {
    Created(SweepRecord, Vec<JobRecord>),
    /// The queue holds `depth` jobs; the sweep's would pass the limit.
    QueueFull {
        depth: i64,
    },
}

impl Store {
    /// Inserts the sweep and all its jobs, or nothing.
    pub async fn create_sweep(&self, sweep: NewSweep, max_queue: u64) -> Result<SweepSubmitted> {
        let mut tx = self.write_submit().await?;
        let depth = queue_depth(&mut tx).await?;
        if depth as u64 + sweep.jobs.len() as u64 > max_queue {
            return Ok(SweepSubmitted::QueueFull { depth });
        }
        sqlx::query(
            "INSERT INTO sweeps (id, created_at, label, base_json, parameters_json) \
             VALUES ($1, $2, $3, $4, $5)",
        )
        .bind(sweep.id.to_string())
        .bind(now_ms())
        .bind(&sweep.label)
        .bind(&sweep.base_json)
        .bind(&sweep.parameters_json)
        .execute(&mut *tx)
        .await?;
        for (index, (job, values)) in sweep.jobs.iter().enumerate() {
            let at = Some((sweep.id, index as i64, values.as_str()));
            insert_job(&mut tx, job, sweep.owner.as_deref(), at).await?;
        }
        tx.commit().await?;
        let (record, jobs) = self
            .sweep(sweep.id)
            .await?
            .ok_or_else(|| StoreError::Corrupt("lost a sweep".into()))?;
        Ok(SweepSubmitted::Created(record, jobs))
    }

    /// A sweep and its jobs in combination order.
    pub async fn sweep(&self, id: Uuid) -> Result<Option<(SweepRecord, Vec<JobRecord>)>> {
        let row: Option<(String, i64, Option<String>, String, String)> = sqlx::query_as(
            "SELECT id, created_at, label, base_json, parameters_json FROM sweeps WHERE id = $1",
        )
        .bind(id.to_string())
        .fetch_optional(&self.pool)
        .await?;
        let Some((_, created_at, label, base_json, parameters_json)) = row else {
            return Ok(None);
        };
        let sql = format!(
            "SELECT {JOB_COLUMNS} FROM {JOB_FROM} WHERE j.sweep_id = $1 ORDER BY j.sweep_index"
        );
        let rows = sqlx::query(&sql)
            .bind(id.to_string())
            .fetch_all(&self.pool)
            .await?;
        let jobs = rows.iter().map(job_from_row).collect::<Result<Vec<_>>>()?;
        Ok(Some((
            SweepRecord {
                id,
                created_at,
                label,
                base_json,
                parameters_json,
            },
            jobs,
        )))
    }
}
