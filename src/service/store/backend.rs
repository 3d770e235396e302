//! The two databases the store runs on, and the few places where their SQL differs.
//!
//! Every statement of the store is written once, in the SQL both engines read (`$1` parameters,
//! `RETURNING`, `COALESCE`, `||`), and runs through sqlx's `Any` driver. What differs is here:
//! how a write transaction begins, the row locks PostgreSQL needs where SQLite's single writer
//! already serialises, which errors mean "the database cannot be used now", and the migrations
//! (`migrations/sqlite`, `migrations/postgres`).
//!
//! - **SQLite** (`sqlite://FILE`, the default): one file, one writer at a time. Every write
//!   transaction is `BEGIN IMMEDIATE`, so it holds the write lock from its first statement and
//!   nothing can interleave with it. The file's identity is watched ([`DbFile`]).
//! - **PostgreSQL** (`postgres://…`): many nodes, many writers. Transactions are
//!   `READ COMMITTED`; a claim takes its row with `FOR UPDATE SKIP LOCKED`; a write that reads a
//!   job before it changes it locks the row (`FOR UPDATE`); submits, whose queue bound and
//!   idempotency check read the whole queue, take one transaction-scoped advisory lock. The
//!   migrator holds PostgreSQL's advisory lock, so nodes starting at once migrate once.

use super::file::DbFile;
use sqlx::migrate::Migrator;
use std::sync::Arc;
use std::time::Duration;

/// Which database, with what only that one needs.
#[derive(Debug)]
pub(super) enum Backend {
    Sqlite {
        /// The database file as opened.
        file: Arc<DbFile>,
        /// This process's turn at the file's one writer, taken before `BEGIN IMMEDIATE`: the
        /// writers of one process then go first come, first served. SQLite's own wait for the
        /// lock polls, so a writer that commits and begins again at once (a long history
        /// stored in batches) would otherwise keep the lock from the others for seconds.
        writer: Arc<tokio::sync::Mutex<()>>,
    },
    Postgres {
        /// The connection URL, for the listener's own connection.
        url: String,
    },
}

impl Backend {
    /// The statement that opens a write transaction.
    pub(super) fn begin(&self) -> &'static str {
        match self {
            Backend::Sqlite { .. } => "BEGIN IMMEDIATE",
            Backend::Postgres { .. } => "BEGIN",
        }
    }

    /// The statement, run first in a transaction, that makes it the only submit at a time
    /// (SQLite: none, its write lock already does). The advisory lock's key is "crush" in
    /// ASCII (0x6372757368).
    pub(super) fn submit_lock(&self) -> Option<&'static str> {
        match self {
            Backend::Sqlite { .. } => None,
            Backend::Postgres { .. } => Some("SELECT pg_advisory_xact_lock(427122062184)"),
        }
    }

    /// Appended to a `SELECT` of rows the transaction is about to change.
    pub(super) fn for_update(&self) -> &'static str {
        match self {
            Backend::Sqlite { .. } => "",
            Backend::Postgres { .. } => " FOR UPDATE",
        }
    }

    /// Appended to the claim's choice of the next queued job: rows another node is claiming
    /// right now are passed over rather than waited for.
    pub(super) fn skip_locked(&self) -> &'static str {
        match self {
            Backend::Sqlite { .. } => "",
            Backend::Postgres { .. } => " FOR UPDATE SKIP LOCKED",
        }
    }

    /// This process's turn at the database's one writer (SQLite), waited for first come,
    /// first served; `None` where writers do not take turns (PostgreSQL).
    pub(super) async fn writer_turn(&self) -> Option<tokio::sync::OwnedMutexGuard<()>> {
        match self {
            Backend::Sqlite { writer, .. } => Some(writer.clone().lock_owned().await),
            Backend::Postgres { .. } => None,
        }
    }

    /// Pooled connections of one node.
    pub(super) fn pool_size(&self) -> u32 {
        match self {
            Backend::Sqlite { .. } => 8,
            Backend::Postgres { .. } => 10,
        }
    }

    /// How long a statement waits for a pooled connection. On SQLite it waits behind other
    /// writers (each waiting for the write lock, up to its busy timeout); on PostgreSQL a
    /// server that is down shows here, and a client should hear 503 soon, not after 10 s.
    pub(super) fn acquire_timeout(&self) -> Duration {
        match self {
            Backend::Sqlite { .. } => Duration::from_secs(10),
            Backend::Postgres { .. } => Duration::from_secs(3),
        }
    }

    /// Run on every new connection. SQLite's WAL mode is not here: it is a property of the
    /// file, set when the store creates it.
    pub(super) fn connection_pragmas(&self) -> &'static [&'static str] {
        match self {
            Backend::Sqlite { .. } => &[
                "PRAGMA synchronous = NORMAL",
                "PRAGMA foreign_keys = ON",
                "PRAGMA busy_timeout = 10000",
            ],
            Backend::Postgres { .. } => &[],
        }
    }

    /// This backend's migrations (`migrations/sqlite` or `migrations/postgres`).
    pub(super) fn migrator(&self) -> Migrator {
        match self {
            Backend::Sqlite { .. } => sqlx::migrate!("./migrations/sqlite"),
            Backend::Postgres { .. } => sqlx::migrate!("./migrations/postgres"),
        }
    }

    pub(super) fn name(&self) -> &'static str {
        match self {
            Backend::Sqlite { .. } => "sqlite",
            Backend::Postgres { .. } => "postgres",
        }
    }

    pub(super) fn file(&self) -> Option<&DbFile> {
        match self {
            Backend::Sqlite { file, .. } => Some(file),
            Backend::Postgres { .. } => None,
        }
    }
}

/// SQLite's primary result codes that say the database cannot be used now, not that the
/// statement was wrong: BUSY 5, LOCKED 6, NOMEM 7, READONLY 8, IOERR 10, CORRUPT 11 (as a
/// disk error reads), FULL 13, CANTOPEN 14, PROTOCOL 15.
const SQLITE_UNAVAILABLE: [i64; 9] = [5, 6, 7, 8, 10, 11, 13, 14, 15];

/// PostgreSQL SQLSTATE classes and codes that say the same: connection exceptions (08),
/// insufficient resources such as a full disk (53), operator intervention such as a shutdown or
/// a server still starting (57P), system and I/O errors (58), a read-only transaction (25006),
/// serialization failures and deadlocks (40001, 40P01), a lock not available (55P03).
const PG_UNAVAILABLE: [&str; 8] = ["08", "53", "57P", "58", "25006", "40001", "40P01", "55P03"];

/// Whether a database error code (SQLite's number, or PostgreSQL's SQLSTATE when `postgres`;
/// many SQLSTATEs are digits only) means the database is unusable for now rather than that
/// the statement was wrong.
pub(super) fn unavailable_code(code: &str, postgres: bool) -> bool {
    if postgres {
        PG_UNAVAILABLE.iter().any(|p| code.starts_with(p))
    } else {
        code.parse::<i64>()
            .is_ok_and(|c| SQLITE_UNAVAILABLE.contains(&(c & 0xff)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_of_both_engines_that_heal_are_told_from_those_that_do_not() {
        // SQLite: SQLITE_FULL, SQLITE_READONLY_DBMOVED (8 | 4 << 8), SQLITE_BUSY; a constraint not.
        let sqlite = |c| unavailable_code(c, false);
        assert!(sqlite("13") && sqlite("1032") && sqlite("5"));
        assert!(!sqlite("19") && !sqlite("2067"));
        // PostgreSQL: admin shutdown, cannot connect now, disk full, connection failure; a
        // unique violation and a syntax error not.
        for c in ["57P01", "57P03", "53100", "08006", "40001"] {
            assert!(unavailable_code(c, true), "{c}");
        }
        for c in ["23505", "42601", "22P02"] {
            assert!(!unavailable_code(c, true), "{c}");
        }
    }
}
