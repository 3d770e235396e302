//! The job store: every SQL statement of the service lives under this module, behind the methods
//! of [`Store`], so that routes and workers never see a query or which database answers it.
//! Two backends, chosen by the URL: SQLite (`sqlite://FILE`, WAL mode, the zero-setup default)
//! and PostgreSQL (`postgres://…`, many nodes on one queue); [`backend`] says where they differ
//! and [`signals`] carries PostgreSQL's notifications between nodes. Times are unix
//! milliseconds.

mod backend;
mod checkpoints;
mod claims;
mod database;
mod file;
mod frames;
mod jobs;
mod lease;
mod rates;
mod removal;
pub mod signals;
mod summary;
mod sweeps;

pub use checkpoints::StoredCheckpoint;
pub use claims::{Claimed, Reaped, Succeeded};
pub use database::{
    now_ms, CheckpointMark, JobRecord, Result, Status, Store, StoreError, HEALTH_TIMEOUT,
};
pub use frames::{StoredFrame, PART_PARTICLES};
pub use jobs::{CancelOutcome, ListFilter, NewJob, Submitted};
pub use rates::RATE_JOBS_READ;
pub use removal::{Deleted, Pruned};
pub use signals::Signal;
pub use summary::StoredSummary;
pub use sweeps::{NewSweep, SweepFilter, SweepListed, SweepRecord, SweepSubmitted};

/// A store on a fresh SQLite file, for tests; the folder holding it goes when the first is
/// dropped.
#[cfg(test)]
pub(crate) async fn temp_store() -> (tempfile::TempDir, Store) {
    let dir = tempfile::tempdir().unwrap();
    let url = format!("sqlite://{}", dir.path().join("t.db").display());
    let store = Store::open(&url).await.unwrap();
    (dir, store)
}

/// A summary of the default case with no history (every field filled by the solver's own
/// `summarize`, so it keeps up with new fields), for tests of what the store keeps.
#[cfg(test)]
pub(crate) fn sample_summary() -> crate::solver::Summary {
    use crate::solver::{summarize, Case, Limits, RunCost, Snapshot};
    let case = Case::from_json("{}", &Limits::default()).unwrap();
    let at_rest = case.geometry().positions();
    let snapshot = Snapshot {
        plastic_strain: vec![0.0; at_rest.len()],
        position_mm: at_rest.clone(),
        initial_mm: at_rest,
    };
    let cost = RunCost {
        particles: 1234,
        steps: 567,
        wall_time_s: 8.5,
        ..RunCost::default()
    };
    let (mut summary, _) = summarize(&case, &[], &snapshot, cost);
    summary.mean_load_n = 1.5e4;
    summary.peak_load_n = 2.5e4;
    summary.energy_absorbed_mj = 3.25e5;
    summary.crush_distance_mm = 21.5;
    summary.folds = 3;
    summary.energy_balance_error = 0.0125;
    summary.error_bar = Some(crate::solver::analysis::error_bar::ErrorBar::Unavailable {
        why: "a sample".into(),
    });
    summary
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_or_read_only_disk_is_unavailable_and_a_bad_statement_is_not() {
        assert!(StoreError::Db(sqlx::Error::PoolTimedOut).is_unavailable());
        assert!(StoreError::FileGone("gone".into()).is_unavailable());
        assert!(!StoreError::Corrupt("x".into()).is_unavailable());
        assert!(!StoreError::Db(sqlx::Error::RowNotFound).is_unavailable());
    }

    #[test]
    fn status_names_round_trip() {
        for s in Status::ALL {
            assert_eq!(Status::parse(s.as_str()), Some(s));
        }
        assert_eq!(Status::parse("Running"), None);
    }
}
