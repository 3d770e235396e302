//! Sweeps: a base case and lists of values, stored with all their jobs in one transaction;
//! read one with its jobs, or list them newest first with their jobs counted by status.

use super::database::{
    job_from_row, now_ms, parse_uuid, JobRecord, Result, Status, Store, StoreError, JOB_COLUMNS,
    JOB_FROM,
};
use super::jobs::{contains, insert_job, like_pattern, queue_depth, NewJob};
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
    /// The name of the token that submitted it; `None` without tokens.
    pub owner: Option<String>,
}

/// Which sweeps to list: newest first, before `before` (created_at, id) in that order.
#[derive(Debug, Clone, Default)]
pub struct SweepFilter {
    /// Sweeps whose label contains this text, ignoring the case of ASCII letters.
    pub search: Option<String>,
    pub before: Option<(i64, Uuid)>,
    pub limit: u32,
}

/// A sweep of a list: the record and how many of its jobs are in each state.
#[derive(Debug, Clone)]
pub struct SweepListed {
    pub record: SweepRecord,
    pub counts: Vec<(Status, i64)>,
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
            "INSERT INTO sweeps (id, created_at, label, base_json, parameters_json, owner) \
             VALUES ($1, $2, $3, $4, $5, $6)",
        )
        .bind(sweep.id.to_string())
        .bind(now_ms())
        .bind(&sweep.label)
        .bind(&sweep.base_json)
        .bind(&sweep.parameters_json)
        .bind(&sweep.owner)
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
        let sql = format!("SELECT {SWEEP_COLUMNS} FROM sweeps WHERE id = $1");
        let row: Option<SweepRow> = sqlx::query_as(&sql)
            .bind(id.to_string())
            .fetch_optional(&self.pool)
            .await?;
        let Some(row) = row else {
            return Ok(None);
        };
        let record = sweep_from_row(row)?;
        let sql = format!(
            "SELECT {JOB_COLUMNS} FROM {JOB_FROM} WHERE j.sweep_id = $1 ORDER BY j.sweep_index"
        );
        let rows = sqlx::query(&sql)
            .bind(id.to_string())
            .fetch_all(&self.pool)
            .await?;
        let jobs = rows.iter().map(job_from_row).collect::<Result<Vec<_>>>()?;
        Ok(Some((record, jobs)))
    }

    /// Sweeps newest first, filtered, each with its jobs counted by status.
    pub async fn list_sweeps(&self, filter: &SweepFilter) -> Result<Vec<SweepListed>> {
        let mut sql = format!("SELECT {SWEEP_COLUMNS} FROM sweeps WHERE 1 = 1");
        let mut n = 0;
        let mut next = || {
            n += 1;
            format!("${n}")
        };
        if filter.search.is_some() {
            sql += &format!(" AND {}", contains("label", &next()));
        }
        if filter.before.is_some() {
            let (at, id) = (next(), next());
            sql += &format!(" AND (created_at < {at} OR (created_at = {at} AND id < {id}))");
        }
        sql += &format!(" ORDER BY created_at DESC, id DESC LIMIT {}", next());
        let mut q = sqlx::query_as::<_, SweepRow>(&sql);
        if let Some(text) = &filter.search {
            q = q.bind(like_pattern(text));
        }
        if let Some((at, id)) = filter.before {
            q = q.bind(at).bind(id.to_string());
        }
        let rows = q.bind(filter.limit as i64).fetch_all(&self.pool).await?;
        let records = rows
            .into_iter()
            .map(sweep_from_row)
            .collect::<Result<Vec<_>>>()?;
        if records.is_empty() {
            return Ok(Vec::new());
        }
        let params: Vec<String> = (1..=records.len()).map(|i| format!("${i}")).collect();
        let sql = format!(
            "SELECT sweep_id, status, COUNT(*) FROM jobs WHERE sweep_id IN ({}) \
             GROUP BY sweep_id, status",
            params.join(", ")
        );
        let mut q = sqlx::query_as::<_, (String, String, i64)>(&sql);
        for r in &records {
            q = q.bind(r.id.to_string());
        }
        let counted = q.fetch_all(&self.pool).await?;
        Ok(records
            .into_iter()
            .map(|record| {
                let id = record.id.to_string();
                let counts = counted
                    .iter()
                    .filter(|(s, _, _)| *s == id)
                    .filter_map(|(_, status, n)| Some((Status::parse(status)?, *n)))
                    .collect();
                SweepListed { record, counts }
            })
            .collect())
    }
}

/// The columns every sweep query selects, in [`SweepRow`]'s order.
const SWEEP_COLUMNS: &str = "id, created_at, label, base_json, parameters_json, owner";

type SweepRow = (String, i64, Option<String>, String, String, Option<String>);

fn sweep_from_row(row: SweepRow) -> Result<SweepRecord> {
    let (id, created_at, label, base_json, parameters_json, owner) = row;
    Ok(SweepRecord {
        id: parse_uuid(&id)?,
        created_at,
        label,
        base_json,
        parameters_json,
        owner,
    })
}
