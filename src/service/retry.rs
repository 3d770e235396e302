//! Writes of a running job that must not be lost: each is retried while the database refuses
//! it for a reason that heals (down, restarting, locked, full: [`StoreError::is_unavailable`]),
//! for at most the worker's `--store-retry-s`, and then reported as failed. An error that does
//! not heal (a bad statement, corrupt data) is reported at once.

use super::store::{Result, StoreError};
use std::future::Future;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use uuid::Uuid;

/// The first of a running job's writes that could not be stored, shared by its writers: it
/// stops the run (through the run's cancel flag), and the job fails with it instead of
/// succeeding without what it promised.
#[derive(Debug, Clone)]
pub struct Trouble {
    why: Arc<Mutex<Option<String>>>,
    cancel: Arc<AtomicBool>,
}

impl Trouble {
    /// Reports through `cancel`, the run's flag.
    pub fn new(cancel: Arc<AtomicBool>) -> Trouble {
        Trouble {
            why: Arc::new(Mutex::new(None)),
            cancel,
        }
    }

    /// `why` the job cannot succeed; the first report is kept.
    pub fn report(&self, why: String) {
        let mut slot = self.why.lock().unwrap_or_else(|e| e.into_inner());
        if slot.is_none() {
            *slot = Some(why);
        }
        self.cancel.store(true, Ordering::SeqCst);
    }

    /// What was reported, if anything.
    pub fn why(&self) -> Option<String> {
        self.why.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

/// First wait after a refused write; each next one doubles, up to [`LONGEST_WAIT`].
const FIRST_WAIT: Duration = Duration::from_millis(100);
const LONGEST_WAIT: Duration = Duration::from_secs(2);

/// `write` until it is stored, or refused for good, or `patience` has passed since the first
/// refusal. `what` names the write in the log (with `job`): a warning at the first refusal and
/// every tenth, and a line when it got through after refusals.
pub async fn until_stored<T, F, Fut>(
    what: &str,
    job: Uuid,
    patience: Duration,
    mut write: F,
) -> Result<T>
where
    F: FnMut() -> Fut,
    Fut: Future<Output = Result<T>>,
{
    let mut refused = 0u32;
    let mut first_refusal = None;
    let mut wait = FIRST_WAIT;
    loop {
        match write().await {
            Ok(done) => {
                if refused > 0 {
                    tracing::info!(job = %job, refused, "{what}: stored after the database came back");
                }
                return Ok(done);
            }
            Err(e) if e.is_unavailable() => {
                refused += 1;
                let since = *first_refusal.get_or_insert_with(Instant::now);
                if since.elapsed() >= patience {
                    tracing::error!(job = %job, error = %e, refused, "{what}: the database refused it for {:.0} s; giving up", patience.as_secs_f64());
                    return Err(e);
                }
                if refused % 10 == 1 {
                    tracing::warn!(job = %job, error = %e, refused, "{what}: the database refused it; retrying");
                }
                tokio::time::sleep(wait).await;
                wait = (wait * 2).min(LONGEST_WAIT);
            }
            Err(e) => return Err(e),
        }
    }
}

/// Why a job's results could not all be stored, for its error.
pub fn reason(what: &str, e: &StoreError) -> String {
    if e.is_unavailable() {
        format!("{what} could not be stored: the database was unavailable for too long ({e})")
    } else {
        format!("{what} could not be stored ({e})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU32, Ordering};

    fn unavailable() -> StoreError {
        StoreError::Db(sqlx::Error::PoolTimedOut)
    }

    #[tokio::test]
    async fn a_write_refused_while_the_database_is_away_goes_through_once_it_is_back() {
        let tries = AtomicU32::new(0);
        let stored = until_stored("a frame", Uuid::nil(), Duration::from_secs(10), || async {
            match tries.fetch_add(1, Ordering::SeqCst) {
                0..=2 => Err(unavailable()),
                _ => Ok(7),
            }
        })
        .await;
        assert_eq!(stored.unwrap(), 7);
        assert_eq!(tries.load(Ordering::SeqCst), 4);
    }

    #[tokio::test]
    async fn a_write_refused_for_good_or_past_its_patience_is_reported_not_dropped() {
        let tries = AtomicU32::new(0);
        let bad = until_stored("a frame", Uuid::nil(), Duration::from_secs(10), || async {
            tries.fetch_add(1, Ordering::SeqCst);
            Err::<(), _>(StoreError::Corrupt("x".into()))
        })
        .await;
        assert!(matches!(bad, Err(StoreError::Corrupt(_))));
        assert_eq!(
            tries.load(Ordering::SeqCst),
            1,
            "no retry of what cannot heal"
        );
        let started = Instant::now();
        let away = until_stored(
            "a frame",
            Uuid::nil(),
            Duration::from_millis(300),
            || async { Err::<(), _>(unavailable()) },
        )
        .await;
        assert!(away.unwrap_err().is_unavailable());
        assert!(started.elapsed() < Duration::from_secs(5));
    }
}
