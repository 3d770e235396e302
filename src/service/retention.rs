//! Retention (`--keep-days`): a task that deletes finished jobs, and sweeps whose jobs have all
//! finished, once they are older than the setting. Every node of a cluster runs it; a delete
//! another node already made is simply not found.

use super::store::Store;
use std::time::Duration;
use tokio::sync::watch;

/// Longest wait between two passes.
const MOST_EVERY: Duration = Duration::from_secs(3600);

/// How often to prune when finished work is kept for `keep`: a tenth of it, between a second
/// and an hour, so that nothing outlives its time by more than a tenth.
pub fn period(keep: Duration) -> Duration {
    (keep / 10).clamp(Duration::from_secs(1), MOST_EVERY)
}

/// Prunes now and then every [`period`] until shutdown.
pub fn spawn(
    store: Store,
    keep: Duration,
    mut shutdown: watch::Receiver<bool>,
) -> tokio::task::JoinHandle<()> {
    tokio::spawn(async move {
        let keep_ms = i64::try_from(keep.as_millis()).unwrap_or(i64::MAX);
        while !*shutdown.borrow() {
            match store.prune(keep_ms).await {
                Ok(p) if p.jobs + p.sweeps > 0 => tracing::info!(
                    jobs = p.jobs,
                    sweeps = p.sweeps,
                    "retention deleted finished work older than --keep-days"
                ),
                Ok(_) => {}
                Err(e) => tracing::warn!(error = %e, "retention pass failed; tried again later"),
            }
            tokio::select! {
                _ = tokio::time::sleep(period(keep)) => {}
                _ = shutdown.wait_for(|s| *s) => {}
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_period_is_a_tenth_of_the_time_kept_within_a_second_and_an_hour() {
        assert_eq!(period(Duration::from_secs(2)), Duration::from_secs(1));
        assert_eq!(period(Duration::from_secs(600)), Duration::from_secs(60));
        assert_eq!(period(Duration::from_secs(30 * 86_400)), MOST_EVERY);
    }
}
