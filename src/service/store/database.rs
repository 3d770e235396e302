//! The store's handle on its database: [`Store`] and how it opens either backend, its write
//! transactions ([`WriteTx`]), what can go wrong ([`StoreError`], and when a connection is too
//! old to trust after a failure), a job's [`Status`] and how a job row reads into a
//! [`JobRecord`]. Times are unix milliseconds. Imports the backend, the database file and the
//! stored summary of the store, nothing else of it; every other file of the store imports it.

use super::backend::{self, Backend};
use super::file;
use super::summary::StoredSummary;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use sqlx::any::AnyPoolOptions;
use sqlx::sqlite::{SqliteConnectOptions, SqliteJournalMode};
use sqlx::AnyPool;
use sqlx::{ConnectOptions, Connection, Executor};
use std::str::FromStr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::sync::OnceLock;
use std::time::{Duration, Instant};
use uuid::Uuid;

/// What can go wrong in the store.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("database error: {0}")]
    Db(sqlx::Error),
    #[error("migration failed: {0}")]
    Migrate(#[from] sqlx::migrate::MigrateError),
    #[error("stored data is not what it should be: {0}")]
    Corrupt(String),
    /// The database file this server opened is no longer at its path (deleted, or replaced by
    /// another file): anything written now would be lost.
    #[error("{0}")]
    FileGone(String),
    /// The database URL names no database this server can use.
    #[error("{0}")]
    Url(String),
}

impl StoreError {
    /// Whether the error is the database's state rather than a bug: a full or read-only disk,
    /// an I/O error, a lock held too long, a file deleted under the server. These heal (or
    /// need an operator), so clients are told to come back (503), not that the server broke.
    pub fn is_unavailable(&self) -> bool {
        match self {
            StoreError::FileGone(_) => true,
            StoreError::Db(e) => transient(e),
            StoreError::Migrate(_) | StoreError::Corrupt(_) | StoreError::Url(_) => false,
        }
    }
}

fn transient(e: &sqlx::Error) -> bool {
    match e {
        sqlx::Error::Database(db) => {
            let postgres = db
                .try_downcast_ref::<sqlx::postgres::PgDatabaseError>()
                .is_some();
            db.code()
                .is_some_and(|c| backend::unavailable_code(&c, postgres))
        }
        sqlx::Error::Io(_)
        | sqlx::Error::PoolTimedOut
        | sqlx::Error::PoolClosed
        | sqlx::Error::WorkerCrashed => true,
        _ => false,
    }
}

pub type Result<T> = std::result::Result<T, StoreError>;

/// A job's state: `queued → running → succeeded | failed | cancelled`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
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
    /// The node that runs the job, or that ran its last claim (`--node-name`).
    pub node: Option<String>,
    /// Where its checkpoint stands, while it has one: a requeued job resumes there.
    pub checkpoint: Option<CheckpointMark>,
    /// The name of the token that submitted it; `None` without tokens.
    pub owner: Option<String>,
    /// The run's summary, once it succeeded: read back typed, in whichever version it was
    /// stored, so that a field the solver renames is a [`StoreError::Corrupt`] here, not a
    /// silent gap in the views.
    pub summary: Option<StoredSummary>,
}

/// Where a job's checkpoint stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckpointMark {
    /// Solver steps done.
    pub step: i64,
    /// Share of the crush distance done, 0..1.
    pub fraction: f64,
    /// When it was stored, unix ms.
    pub written_at: i64,
}

/// The store. Cheap to clone (a pool handle).
#[derive(Debug, Clone)]
pub struct Store {
    pub(super) pool: AnyPool,
    pub(super) backend: Arc<Backend>,
}

/// How long the health probe may wait for the write lock before it calls the database
/// unavailable: a finishing job holds it for well under a second.
pub const HEALTH_TIMEOUT: Duration = Duration::from_secs(3);

impl Store {
    /// Opens the database at `url` (`sqlite://FILE`, created if missing, or `postgres://…`)
    /// and runs its backend's migrations.
    pub async fn open(url: &str) -> Result<Store> {
        sqlx::any::install_default_drivers();
        let backend = if url.starts_with("postgres://") || url.starts_with("postgresql://") {
            Backend::Postgres {
                url: url.to_string(),
            }
        } else if url.starts_with("sqlite:") {
            Backend::Sqlite {
                file: Arc::new(create_sqlite(url).await?),
                writer: Arc::new(tokio::sync::Mutex::new(())),
            }
        } else {
            return Err(StoreError::Url(format!(
                "the database URL must start with sqlite:// or postgres://, not {:?}",
                url.split(':').next().unwrap_or("")
            )));
        };
        let pragmas = backend.connection_pragmas();
        let file = backend.file().map(|f| f.path().to_path_buf());
        let pool = AnyPoolOptions::new()
            .max_connections(backend.pool_size())
            .acquire_timeout(backend.acquire_timeout())
            .after_connect(move |conn, _| {
                let file = file.clone();
                Box::pin(async move {
                    for pragma in pragmas {
                        conn.execute(*pragma).await?;
                    }
                    // SQLite opens a file it cannot write read-only, and the connection stays
                    // so: one made while the disk was read-only counts as made before a
                    // failure, and is replaced at its next use (`fresh_enough`).
                    let writable = |f: &std::path::Path| {
                        std::fs::OpenOptions::new().write(true).open(f).is_ok()
                    };
                    if file.as_deref().is_some_and(|f| !writable(f)) {
                        TROUBLE_AT_NS.store(trouble_clock(), Ordering::Relaxed);
                    }
                    Ok(())
                })
            })
            // A connection a failure may have broken is closed, not reused: see `fresh_enough`.
            .before_acquire(|_, meta| Box::pin(async move { Ok(fresh_enough(meta.age)) }))
            .connect(url)
            .await?;
        backend.migrator().run(&pool).await?;
        Ok(Store {
            pool,
            backend: Arc::new(backend),
        })
    }

    /// `sqlite` or `postgres`.
    pub fn backend_name(&self) -> &'static str {
        self.backend.name()
    }

    /// The PostgreSQL URL, for a listener's own connection; `None` on SQLite.
    pub fn postgres_url(&self) -> Option<&str> {
        match &*self.backend {
            Backend::Postgres { url } => Some(url),
            Backend::Sqlite { .. } => None,
        }
    }

    /// A write transaction: on SQLite it holds the write lock from its first statement; on
    /// PostgreSQL its statements lock what they change. Refused when the SQLite file is no
    /// longer the one opened: a write there would be lost.
    pub(super) async fn write(&self) -> Result<WriteTx> {
        self.check_file()?;
        let turn = self.backend.writer_turn().await;
        let tx = self.pool.begin_with(self.backend.begin()).await?;
        Ok(WriteTx { tx, _turn: turn })
    }

    /// A write transaction that is the only submit at a time, so that the queue bound and the
    /// idempotency check see every submit before it.
    pub(super) async fn write_submit(&self) -> Result<WriteTx> {
        let mut tx = self.write().await?;
        if let Some(lock) = self.backend.submit_lock() {
            sqlx::query(lock).execute(&mut *tx).await?;
        }
        Ok(tx)
    }

    /// Whether the database file at the path is still the one this store opened; logs loudly
    /// the first time it is not. Always fine on PostgreSQL.
    pub fn check_file(&self) -> Result<()> {
        match self.backend.file() {
            Some(f) => f.check().map_err(StoreError::FileGone),
            None => Ok(()),
        }
    }

    /// Whether the database can be written now: the file is the one opened and a one-row
    /// write commits within [`HEALTH_TIMEOUT`].
    pub async fn probe_write(&self) -> Result<()> {
        let probe = async {
            let mut tx = self.write().await?;
            sqlx::query("UPDATE health SET checked_at = $1 WHERE id = 1")
                .bind(now_ms())
                .execute(&mut *tx)
                .await?;
            tx.commit().await?;
            Ok(())
        };
        match tokio::time::timeout(HEALTH_TIMEOUT, probe).await {
            Ok(result) => result,
            // The probe was dropped, perhaps inside its transaction: through `From`, so that
            // the connection it held counts as one a failure may have broken.
            Err(_) => Err(sqlx::Error::PoolTimedOut.into()),
        }
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

/// A write transaction ([`Store::write`]) with this process's turn at the writer, given back
/// when it ends. Statements run on it as on the transaction (`&mut *tx`).
pub(super) struct WriteTx {
    tx: sqlx::Transaction<'static, sqlx::Any>,
    _turn: Option<tokio::sync::OwnedMutexGuard<()>>,
}

impl WriteTx {
    pub(super) async fn commit(self) -> std::result::Result<(), sqlx::Error> {
        self.tx.commit().await
    }

    pub(super) async fn rollback(self) -> std::result::Result<(), sqlx::Error> {
        self.tx.rollback().await
    }
}

impl std::ops::Deref for WriteTx {
    type Target = sqlx::AnyConnection;
    fn deref(&self) -> &sqlx::AnyConnection {
        &self.tx
    }
}

impl std::ops::DerefMut for WriteTx {
    fn deref_mut(&mut self) -> &mut sqlx::AnyConnection {
        &mut self.tx
    }
}

/// When the database last failed in a way that can leave a connection unusable, as ns since
/// [`trouble_clock`]'s start; 0: never. Process-wide: a failure of one store only makes
/// another recycle its connections, which costs a reconnect.
static TROUBLE_AT_NS: AtomicU64 = AtomicU64::new(0);

fn trouble_clock() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_nanos() as u64 + 1
}

/// Margin for the two clock reads behind a connection's creation time (sqlx's when it measures
/// the age, ours after). With whole milliseconds and no margin, a connection opened in the same
/// millisecond as the failure that broke it could pass for a newer one (seen: the first submit
/// after a full disk was freed failed with "non-zero transaction depth", once in six runs).
const CLOCK_SLACK_NS: u64 = 1_000_000;

impl From<sqlx::Error> for StoreError {
    fn from(e: sqlx::Error) -> StoreError {
        if transient(&e) {
            TROUBLE_AT_NS.store(trouble_clock(), Ordering::Relaxed);
        }
        StoreError::Db(e)
    }
}

/// Whether a pooled connection may serve a request: not if it existed when the database last
/// failed. A full or read-only disk leaves connections that cannot write again: a transaction
/// SQLite rolled back by itself while sqlx still counts it open (every later `BEGIN` then fails
/// with "attempted to call begin_with at non-zero transaction depth"), and files SQLite opened
/// read-only while they could not be written, which stay so for the connection's life. A
/// fresh connection has neither, so the first request after the disk heals works.
fn fresh_enough(age: Duration) -> bool {
    let trouble = TROUBLE_AT_NS.load(Ordering::Relaxed);
    let created = trouble_clock().saturating_sub(age.as_nanos() as u64);
    trouble == 0 || created > trouble + CLOCK_SLACK_NS
}

/// Creates the SQLite file if it is missing and puts it in WAL mode (a property of the file,
/// kept by every later connection), and returns its identity. An in-memory database is
/// refused: each pooled connection would see its own, and a job submitted on one would be lost.
async fn create_sqlite(url: &str) -> Result<file::DbFile> {
    let options = SqliteConnectOptions::from_str(url)?
        .create_if_missing(true)
        .journal_mode(SqliteJournalMode::Wal)
        .busy_timeout(Duration::from_secs(10));
    if url.contains(":memory:") || url.contains("mode=memory") {
        return Err(StoreError::Url(
            "an in-memory SQLite database would lose its jobs between connections; name a file"
                .into(),
        ));
    }
    let path = options.get_filename().to_path_buf();
    options.connect().await?.close().await?;
    file::DbFile::opened(path).map_err(|e| sqlx::Error::Io(e).into())
}

/// Unix time now, ms.
pub fn now_ms() -> i64 {
    let d = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    d.as_millis() as i64
}

/// The columns every job query selects ([`job_from_row`] reads them by name).
pub(super) const JOB_COLUMNS: &str =
    "j.seq, j.id, j.status, j.label, j.case_json, j.particles, j.sweep_id, \
     j.sweep_values_json, j.created_at, j.started_at, j.finished_at, j.attempts, \
     j.cancel_requested, j.progress_json, j.error, j.worker, j.owner, j.checkpoint_step, \
     j.checkpoint_fraction, j.checkpoint_at, s.summary_json";

/// `FROM` clause matching [`JOB_COLUMNS`].
pub(super) const JOB_FROM: &str = "jobs j LEFT JOIN summaries s ON s.job_id = j.id";

pub(super) fn job_from_row(row: &sqlx::any::AnyRow) -> Result<JobRecord> {
    use sqlx::Row;
    // By name: a column added to or moved in JOB_COLUMNS cannot shift the others.
    let id: String = row.try_get("id")?;
    let status: String = row.try_get("status")?;
    let sweep_id: Option<String> = row.try_get("sweep_id")?;
    Ok(JobRecord {
        seq: row.try_get("seq")?,
        id: parse_uuid(&id)?,
        status: Status::parse(&status)
            .ok_or_else(|| StoreError::Corrupt(format!("job {id} has status {status:?}")))?,
        label: row.try_get("label")?,
        case_json: row.try_get("case_json")?,
        particles: row.try_get("particles")?,
        sweep_id: sweep_id.as_deref().map(parse_uuid).transpose()?,
        sweep_values_json: row.try_get("sweep_values_json")?,
        created_at: row.try_get("created_at")?,
        started_at: row.try_get("started_at")?,
        finished_at: row.try_get("finished_at")?,
        attempts: row.try_get("attempts")?,
        cancel_requested: row.try_get::<i64, _>("cancel_requested")? != 0,
        progress_json: row.try_get("progress_json")?,
        error: row.try_get("error")?,
        node: row.try_get("worker")?,
        checkpoint: match (
            row.try_get::<Option<i64>, _>("checkpoint_step")?,
            row.try_get::<Option<f64>, _>("checkpoint_fraction")?,
            row.try_get::<Option<i64>, _>("checkpoint_at")?,
        ) {
            (Some(step), Some(fraction), Some(written_at)) => Some(CheckpointMark {
                step,
                fraction,
                written_at,
            }),
            _ => None,
        },
        owner: row.try_get("owner")?,
        summary: read_summary(&id, row.try_get("summary_json")?)?,
    })
}

/// A stored summary's JSON, typed; a summary that does not read is corrupt, never zeros.
fn read_summary(job: &str, text: Option<String>) -> Result<Option<StoredSummary>> {
    text.map(|t| {
        StoredSummary::read(&t)
            .map_err(|why| StoreError::Corrupt(format!("the summary of job {job} {why}")))
    })
    .transpose()
}

pub(super) fn parse_uuid(s: &str) -> Result<Uuid> {
    Uuid::parse_str(s).map_err(|_| StoreError::Corrupt(format!("{s:?} is not a UUID")))
}
