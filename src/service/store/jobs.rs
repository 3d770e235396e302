//! Jobs as clients see them: submit (with idempotency keys and the queue limit), read, list,
//! cancel, and read a history back.

use super::database::{
    job_from_row, now_ms, JobRecord, Result, Status, Store, JOB_COLUMNS, JOB_FROM,
};
use crate::solver::HistoryRow;
use uuid::Uuid;

/// A job to insert.
#[derive(Debug, Clone)]
pub struct NewJob {
    pub id: Uuid,
    /// The case as submitted (normalised JSON).
    pub case_json: String,
    pub label: Option<String>,
    pub particles: u64,
    pub idempotency_key: Option<String>,
}

/// What a submit did.
#[derive(Debug)]
pub enum Submitted {
    Created(JobRecord),
    /// The idempotency key was seen before with the same case: that job.
    Replayed(JobRecord),
    /// The idempotency key was seen before with a different case.
    KeyReused,
    /// The queue already holds `depth` jobs.
    QueueFull {
        depth: i64,
    },
}

/// Which jobs to list: newest first, `seq < before`.
#[derive(Debug, Clone, Default)]
pub struct ListFilter {
    pub statuses: Vec<Status>,
    pub label: Option<String>,
    /// Jobs whose label contains this text, ignoring the case of ASCII letters.
    pub search: Option<String>,
    pub before: Option<i64>,
    pub limit: u32,
}

/// What a cancel did.
#[derive(Debug)]
pub enum CancelOutcome {
    NotFound,
    /// Already succeeded, failed or cancelled.
    Finished(Status),
    /// It was queued and is now cancelled.
    Cancelled(JobRecord),
    /// It is running; its worker has been asked to stop.
    Requested(JobRecord),
}

impl Store {
    /// Inserts a job with no owner (a server without tokens) unless the queue is full or the
    /// idempotency key was used before.
    pub async fn submit(&self, job: NewJob, max_queue: u64) -> Result<Submitted> {
        self.submit_owned(job, None, max_queue).await
    }

    /// Inserts a job submitted by the token named `owner`, unless the queue is full or the
    /// idempotency key was used before.
    pub async fn submit_owned(
        &self,
        job: NewJob,
        owner: Option<&str>,
        max_queue: u64,
    ) -> Result<Submitted> {
        let mut tx = self.write_submit().await?;
        if let Some(key) = &job.idempotency_key {
            let seen: Option<(String, String)> =
                sqlx::query_as("SELECT id, case_json FROM jobs WHERE idempotency_key = $1")
                    .bind(key)
                    .fetch_optional(&mut *tx)
                    .await?;
            if let Some((id, case_json)) = seen {
                tx.rollback().await?;
                if case_json != job.case_json {
                    return Ok(Submitted::KeyReused);
                }
                let id = super::database::parse_uuid(&id)?;
                let record = self.job(id).await?;
                return Ok(record
                    .map(Submitted::Replayed)
                    .unwrap_or(Submitted::KeyReused));
            }
        }
        let depth = queue_depth(&mut tx).await?;
        if depth as u64 >= max_queue {
            return Ok(Submitted::QueueFull { depth });
        }
        insert_job(&mut tx, &job, owner, None).await?;
        tx.commit().await?;
        let record = self.job(job.id).await?;
        record
            .map(Submitted::Created)
            .ok_or_else(|| super::database::StoreError::Corrupt("lost a job".into()))
    }

    pub async fn job(&self, id: Uuid) -> Result<Option<JobRecord>> {
        let sql = format!("SELECT {JOB_COLUMNS} FROM {JOB_FROM} WHERE j.id = $1");
        let row = sqlx::query(&sql)
            .bind(id.to_string())
            .fetch_optional(&self.pool)
            .await?;
        row.as_ref().map(job_from_row).transpose()
    }

    /// Jobs newest first, filtered.
    pub async fn list(&self, filter: &ListFilter) -> Result<Vec<JobRecord>> {
        // Placeholders are numbered by hand: sqlx's query builder writes `?` for the `Any`
        // driver, which only SQLite reads.
        let mut sql = format!("SELECT {JOB_COLUMNS} FROM {JOB_FROM} WHERE 1 = 1");
        let mut n = 0;
        let mut next = || {
            n += 1;
            format!("${n}")
        };
        if !filter.statuses.is_empty() {
            let list: Vec<String> = filter.statuses.iter().map(|_| next()).collect();
            sql += &format!(" AND j.status IN ({})", list.join(", "));
        }
        if filter.label.is_some() {
            sql += &format!(" AND j.label = {}", next());
        }
        if filter.search.is_some() {
            sql += &format!(" AND {}", contains("j.label", &next()));
        }
        if filter.before.is_some() {
            sql += &format!(" AND j.seq < {}", next());
        }
        sql += &format!(" ORDER BY j.seq DESC LIMIT {}", next());
        let mut q = sqlx::query(&sql);
        for s in &filter.statuses {
            q = q.bind(s.as_str());
        }
        if let Some(label) = &filter.label {
            q = q.bind(label.clone());
        }
        if let Some(text) = &filter.search {
            q = q.bind(like_pattern(text));
        }
        if let Some(before) = filter.before {
            q = q.bind(before);
        }
        let rows = q.bind(filter.limit as i64).fetch_all(&self.pool).await?;
        rows.iter().map(job_from_row).collect()
    }

    /// Cancels a queued job at once, or asks the worker of a running one to stop.
    pub async fn cancel(&self, id: Uuid) -> Result<CancelOutcome> {
        let mut tx = self.write().await?;
        let sql = format!(
            "SELECT status FROM jobs WHERE id = $1{}",
            self.backend.for_update()
        );
        let status: Option<(String,)> = sqlx::query_as(&sql)
            .bind(id.to_string())
            .fetch_optional(&mut *tx)
            .await?;
        let Some(status) = status.and_then(|(s,)| Status::parse(&s)) else {
            return Ok(CancelOutcome::NotFound);
        };
        let outcome = match status {
            Status::Queued => {
                sqlx::query(
                    "UPDATE jobs SET status = 'cancelled', cancel_requested = 1, finished_at = $1 \
                     WHERE id = $2",
                )
                .bind(now_ms())
                .bind(id.to_string())
                .execute(&mut *tx)
                .await?;
                super::checkpoints::forget(&mut tx, &id.to_string()).await?;
                super::frames::forget(&mut tx, &id.to_string()).await?;
                Status::Cancelled
            }
            Status::Running => {
                sqlx::query("UPDATE jobs SET cancel_requested = 1 WHERE id = $1")
                    .bind(id.to_string())
                    .execute(&mut *tx)
                    .await?;
                Status::Running
            }
            done => return Ok(CancelOutcome::Finished(done)),
        };
        tx.commit().await?;
        let record = self
            .job(id)
            .await?
            .ok_or_else(|| super::database::StoreError::Corrupt("lost a job".into()))?;
        Ok(if outcome == Status::Cancelled {
            CancelOutcome::Cancelled(record)
        } else {
            CancelOutcome::Requested(record)
        })
    }

    /// How many rows a job's stored history has. They are numbered from 0 without gaps (all
    /// stored in one transaction), so the largest number, read from the key, tells.
    pub async fn history_len(&self, id: Uuid) -> Result<u64> {
        let (next,): (i64,) =
            sqlx::query_as("SELECT COALESCE(MAX(row) + 1, 0) FROM history WHERE job_id = $1")
                .bind(id.to_string())
                .fetch_one(&self.pool)
                .await?;
        Ok(next.max(0) as u64)
    }

    /// The stored history of a job, each row's values in [`HistoryRow::COLUMNS`] order.
    pub async fn history(&self, id: Uuid) -> Result<Vec<Vec<f64>>> {
        let sql = format!(
            "SELECT {} FROM history WHERE job_id = $1 ORDER BY row",
            HistoryRow::COLUMNS.join(", ")
        );
        let rows = sqlx::query(&sql)
            .bind(id.to_string())
            .fetch_all(&self.pool)
            .await?;
        rows.iter()
            .map(|row| {
                use sqlx::Row;
                (0..HistoryRow::COLUMNS.len())
                    .map(|i| Ok(row.try_get::<f64, _>(i)?))
                    .collect()
            })
            .collect()
    }
}

impl Store {
    /// The stored final particle state of a job: (particles, bytes); `None` when none was kept.
    pub async fn final_state(&self, id: Uuid) -> Result<Option<(usize, Vec<u8>)>> {
        let row: Option<(i64, Vec<u8>)> =
            sqlx::query_as("SELECT particles, data FROM final_states WHERE job_id = $1")
                .bind(id.to_string())
                .fetch_optional(&self.pool)
                .await?;
        Ok(row.map(|(n, data)| (n.max(0) as usize, data)))
    }
}

/// The SQL condition "`column` contains the text bound at `param`", ignoring the case of ASCII
/// letters on both backends (each lowers both sides its own way); bind [`like_pattern`].
pub(super) fn contains(column: &str, param: &str) -> String {
    format!("LOWER({column}) LIKE LOWER({param}) ESCAPE '\\'")
}

/// `%text%` with LIKE's wildcards in `text` escaped, so that they match themselves.
pub(super) fn like_pattern(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('%');
    for c in text.chars() {
        if matches!(c, '%' | '_' | '\\') {
            out.push('\\');
        }
        out.push(c);
    }
    out.push('%');
    out
}

/// Jobs waiting to run.
pub(super) async fn queue_depth(tx: &mut super::database::WriteTx) -> Result<i64> {
    let (n,): (i64,) = sqlx::query_as("SELECT COUNT(*) FROM jobs WHERE status = 'queued'")
        .fetch_one(&mut **tx)
        .await?;
    Ok(n)
}

/// Inserts a queued job submitted by `owner`; `sweep` is (sweep id, index, swept values as
/// JSON).
pub(super) async fn insert_job(
    tx: &mut super::database::WriteTx,
    job: &NewJob,
    owner: Option<&str>,
    sweep: Option<(Uuid, i64, &str)>,
) -> Result<()> {
    sqlx::query(
        "INSERT INTO jobs (id, status, label, case_json, particles, idempotency_key, sweep_id, \
         sweep_index, sweep_values_json, created_at, owner) \
         VALUES ($1, 'queued', $2, $3, $4, $5, $6, $7, $8, $9, $10)",
    )
    .bind(job.id.to_string())
    .bind(&job.label)
    .bind(&job.case_json)
    .bind(job.particles as i64)
    .bind(&job.idempotency_key)
    .bind(sweep.map(|s| s.0.to_string()))
    .bind(sweep.map(|s| s.1))
    .bind(sweep.map(|s| s.2))
    .bind(now_ms())
    .bind(owner)
    .execute(&mut **tx)
    .await?;
    Ok(())
}
