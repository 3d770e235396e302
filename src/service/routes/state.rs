//! What every handler can reach ([`AppState`]: the store, the hub, the workers, the guard) and
//! the limits they apply ([`HttpLimits`]: bytes, durations, counts). Imports nothing of the
//! routes; `mod.rs` (which re-exports both) and every handler file import it.

use crate::service::guard::Guard;
use crate::service::hub::Hub;
use crate::service::store::Store;
use crate::service::worker::Workers;
use crate::solver::Limits;
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{watch, Semaphore};

/// Limits and settings the handlers apply.
#[derive(Debug, Clone)]
pub struct HttpLimits {
    pub max_body_bytes: usize,
    /// What a case may cost (particles, steps, particle-steps).
    pub case: Limits,
    pub max_queue: u64,
    pub max_sweep_jobs: usize,
    pub max_sse_clients: usize,
    pub keep_alive: Duration,
    /// How often an SSE stream re-reads the job from the store (catches what the hub cannot:
    /// jobs run by another process).
    pub sse_poll: Duration,
    /// Slowest average a heavy download may be taken at, bytes a second (0: any).
    pub min_download_rate: u64,
    /// Longest a request body may take to arrive whole.
    pub body_timeout: Duration,
}

/// What every handler can reach.
#[derive(Clone)]
pub struct AppState {
    pub store: Store,
    pub hub: Arc<Hub>,
    pub workers: Arc<Workers>,
    pub limits: Arc<HttpLimits>,
    /// One permit per open SSE stream.
    pub sse_permits: Arc<Semaphore>,
    /// One slot per heavy answer being built or sent (VTU file, particle table, frames,
    /// archive, picture, long history): they cost memory in proportion to the particles or rows.
    pub heavy: Arc<crate::service::downloads::Slots>,
    /// Turns at the CPU for handlers that read and check cases and sweeps.
    pub cpu: crate::service::cpu::CpuGate,
    /// Becomes true when the server shuts down; open SSE streams end then.
    pub shutdown: watch::Receiver<bool>,
    /// Who may do what.
    pub guard: Arc<Guard>,
}
