//! The job store: every SQL statement of the service lives under this module, behind the methods
//! of [`Store`], so that routes and workers never see a query and a second backend can come
//! later. SQLite in WAL mode; every write transaction is `BEGIN IMMEDIATE`, so a writer takes the
//! lock up front instead of failing on upgrade. Times are unix milliseconds.

mod jobs;
mod sweeps;
mod worker;

pub use jobs::{CancelOutcome, ListFilter, NewJob, Submitted};
pub use sweeps::{NewSweep, SweepRecord, SweepSubmitted};
pub use worker::{Claimed, Reaped, Succeeded};

use serde::{Deserialize, Serialize};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};
use std::str::FromStr;
use std::time::Duration;
use uuid::Uuid;

/// What can go wrong in the store.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("database error: {0}")]
    Db(#[from] sqlx::Error),
    #[error("migration failed: {0}")]
    Migrate(#[from] sqlx::migrate::MigrateError),
    #[error("stored data is not what it should be: {0}")]
    Corrupt(String),
}

pub type Result<T> = std::result::Result<T, StoreError>;

/// A job's state: `queued → running → succeeded | failed | cancelled`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
}

impl Status {
    pub const ALL: [Status; 5] = [
        Status::Queued,
        Status::Running,
        Status::Succeeded,
        Status::Failed,
        Status::Cancelled,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            Status::Queued => "queued",
            Status::Running => "running",
            Status::Succeeded => "succeeded",
            Status::Failed => "failed",
            Status::Cancelled => "cancelled",
        }
    }

    pub fn parse(s: &str) -> Option<Status> {
        Status::ALL.into_iter().find(|x| x.as_str() == s)
    }

    /// Succeeded, failed or cancelled: nothing more will happen to the job.
    pub fn is_terminal(self) -> bool {
        matches!(self, Status::Succeeded | Status::Failed | Status::Cancelled)
    }
}

/// One job as stored.
#[derive(Debug, Clone)]
pub struct JobRecord {
    pub seq: i64,
    pub id: Uuid,
    pub status: Status,
    pub label: Option<String>,
    pub case_json: String,
    pub particles: i64,
    pub sweep_id: Option<Uuid>,
    pub sweep_values_json: Option<String>,
    pub created_at: i64,
    pub started_at: Option<i64>,
    pub finished_at: Option<i64>,
    pub attempts: i64,
    pub cancel_requested: bool,
    pub progress_json: Option<String>,
    pub error: Option<String>,
    pub summary_json: Option<String>,
}

/// The store. Cheap to clone (a pool handle).
#[derive(Debug, Clone)]
pub struct Store {
    pool: SqlitePool,
}

impl Store {
    /// Opens (creating if missing) the database at `url` and runs the migrations.
    pub async fn open(url: &str) -> Result<Store> {
        let options = SqliteConnectOptions::from_str(url)?
            .create_if_missing(true)
            .journal_mode(SqliteJournalMode::Wal)
            .synchronous(SqliteSynchronous::Normal)
            .foreign_keys(true)
            .busy_timeout(Duration::from_secs(10));
        let pool = SqlitePoolOptions::new()
            .max_connections(8)
            .connect_with(options)
            .await?;
        sqlx::migrate!("./migrations").run(&pool).await?;
        Ok(Store { pool })
    }

    /// A write transaction that holds the write lock from its first statement.
    async fn write(&self) -> Result<sqlx::Transaction<'static, sqlx::Sqlite>> {
        Ok(self.pool.begin_with("BEGIN IMMEDIATE").await?)
    }

    /// Whether the database answers.
    pub async fn ping(&self) -> Result<()> {
        sqlx::query("SELECT 1").execute(&self.pool).await?;
        Ok(())
    }

    /// Number of jobs in each state.
    pub async fn counts(&self) -> Result<Vec<(Status, i64)>> {
        let rows: Vec<(String, i64)> =
            sqlx::query_as("SELECT status, COUNT(*) FROM jobs GROUP BY status")
                .fetch_all(&self.pool)
                .await?;
        Ok(rows
            .into_iter()
            .filter_map(|(s, n)| Some((Status::parse(&s)?, n)))
            .collect())
    }

    pub async fn close(&self) {
        self.pool.close().await;
    }
}

/// Unix time now, ms.
pub fn now_ms() -> i64 {
    let d = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    d.as_millis() as i64
}

/// The columns every job query selects, in the order [`job_from_row`] reads them.
const JOB_COLUMNS: &str = "j.seq, j.id, j.status, j.label, j.case_json, j.particles, j.sweep_id, \
     j.sweep_values_json, j.created_at, j.started_at, j.finished_at, j.attempts, \
     j.cancel_requested, j.progress_json, j.error, s.summary_json";

/// `FROM` clause matching [`JOB_COLUMNS`].
const JOB_FROM: &str = "jobs j LEFT JOIN summaries s ON s.job_id = j.id";

fn job_from_row(row: &sqlx::sqlite::SqliteRow) -> Result<JobRecord> {
    use sqlx::Row;
    let id: String = row.try_get(1)?;
    let status: String = row.try_get(2)?;
    let sweep_id: Option<String> = row.try_get(6)?;
    Ok(JobRecord {
        seq: row.try_get(0)?,
        id: parse_uuid(&id)?,
        status: Status::parse(&status)
            .ok_or_else(|| StoreError::Corrupt(format!("job {id} has status {status:?}")))?,
        label: row.try_get(3)?,
        case_json: row.try_get(4)?,
        particles: row.try_get(5)?,
        sweep_id: sweep_id.as_deref().map(parse_uuid).transpose()?,
        sweep_values_json: row.try_get(7)?,
        created_at: row.try_get(8)?,
        started_at: row.try_get(9)?,
        finished_at: row.try_get(10)?,
        attempts: row.try_get(11)?,
        cancel_requested: row.try_get::<i64, _>(12)? != 0,
        progress_json: row.try_get(13)?,
        error: row.try_get(14)?,
        summary_json: row.try_get(15)?,
    })
}

fn parse_uuid(s: &str) -> Result<Uuid> {
    Uuid::parse_str(s).map_err(|_| StoreError::Corrupt(format!("{s:?} is not a UUID")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_names_round_trip() {
        for s in Status::ALL {
            assert_eq!(Status::parse(s.as_str()), Some(s));
        }
        assert_eq!(Status::parse("Running"), None);
    }
}
