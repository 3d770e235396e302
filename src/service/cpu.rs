//! The CPU work of request handlers (reading and checking a case or a sweep), off the
//! runtime's worker threads: each piece runs on tokio's blocking pool, at most
//! [`CPU_AT_ONCE`] at a time. A request that finds every turn taken waits up to
//! [`CPU_WAIT`], then gets 503 with `Retry-After`. The work of one request is bounded before
//! it gets here (the body's size, a sweep's combinations), so a turn is short; a client that
//! leaves does not stop its turn, which ends by itself.

use super::error::ApiError;
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::Semaphore;

/// Request handlers' CPU work at once. Two: a sweep and the estimates of a form being typed
/// in go on together, and however many requests come, their checks take at most two cores'
/// time from the solver (the runtime's threads, which hold none of this work, answer
/// `/healthz` and the event streams meanwhile).
pub const CPU_AT_ONCE: usize = 2;

/// How long a request waits for a turn before it is answered 503.
pub const CPU_WAIT: Duration = Duration::from_secs(5);

/// `Retry-After` of that 503, s.
const RETRY_AFTER_S: u32 = 2;

/// Turns at the CPU for request handlers.
#[derive(Debug, Clone)]
pub struct CpuGate {
    turns: Arc<Semaphore>,
    wait: Duration,
}

impl CpuGate {
    pub fn new(at_once: usize, wait: Duration) -> CpuGate {
        CpuGate {
            turns: Arc::new(Semaphore::new(at_once.max(1))),
            wait,
        }
    }

    /// Runs `work` on the blocking pool when a turn is free; 503 if none frees in time.
    pub async fn run<T, F>(&self, work: F) -> Result<T, ApiError>
    where
        T: Send + 'static,
        F: FnOnce() -> T + Send + 'static,
    {
        let turn = match tokio::time::timeout(self.wait, self.turns.clone().acquire_owned()).await {
            Ok(turn) => turn.map_err(ApiError::internal)?,
            Err(_) => {
                return Err(ApiError::Unavailable {
                    detail: "the server is busy checking other requests; try again shortly".into(),
                    retry_after_s: RETRY_AFTER_S,
                })
            }
        };
        tokio::task::spawn_blocking(move || {
            let _turn = turn;
            work()
        })
        .await
        .map_err(ApiError::internal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;

    #[tokio::test]
    async fn work_runs_off_the_runtime_and_a_full_gate_answers_503_in_bounded_time() {
        let gate = CpuGate::new(1, Duration::from_millis(200));
        let runtime_thread = std::thread::current().id();
        let thread = gate.run(|| std::thread::current().id()).await.unwrap();
        assert_ne!(thread, runtime_thread);
        // One long turn holds the gate; the next request waits its bound, then gets 503.
        let (release, hold) = mpsc::channel::<()>();
        let busy = gate.clone();
        let long = tokio::spawn(async move { busy.run(move || hold.recv()).await });
        tokio::time::sleep(Duration::from_millis(50)).await;
        let started = std::time::Instant::now();
        let refused = gate.run(|| ()).await.unwrap_err();
        assert!(matches!(
            refused,
            ApiError::Unavailable {
                retry_after_s: RETRY_AFTER_S,
                ..
            }
        ));
        assert!(started.elapsed() < Duration::from_secs(2));
        release.send(()).unwrap();
        long.await.unwrap().unwrap().unwrap();
        // The turn came back.
        gate.run(|| ()).await.unwrap();
    }
}
