//! The worker pool: a fixed number of loops that claim jobs, run each on its own rayon pool in
//! `spawn_blocking`, heartbeat while it runs and store the outcome; a reaper that puts back jobs
//! whose worker died; and a bounded, requeueing drain on shutdown.

use super::hub::{Hub, JobObserver};
use super::state;
use super::store::{Claimed, Status, Store, Succeeded};
use super::views;
use crate::solver::{self, Case, Limits, Progress, SolveError};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::sync::{watch, Notify};
use uuid::Uuid;

/// How the workers run.
#[derive(Debug, Clone)]
pub struct WorkerConfig {
    pub concurrent_jobs: usize,
    pub threads_per_job: usize,
    pub limits: Limits,
    /// Heartbeat and stored-progress interval.
    pub heartbeat: Duration,
    /// A running job whose heartbeat is older than this goes back to the queue.
    pub stale_after: Duration,
    pub max_attempts: u32,
    /// How often an idle worker looks for work another process queued.
    pub poll: Duration,
}

/// A job running in this process.
struct Running {
    cancel: Arc<AtomicBool>,
    /// The client asked for the cancel (as opposed to shutdown or a lost lease).
    user_cancel: AtomicBool,
    particles: u64,
    latest: Arc<Mutex<Option<Progress>>>,
}

/// The pool. Shared by the routes (cancel, metrics) and the worker loops.
pub struct Workers {
    store: Store,
    hub: Arc<Hub>,
    config: WorkerConfig,
    instance: String,
    running: Mutex<HashMap<Uuid, Arc<Running>>>,
    wake: Notify,
    shutdown: watch::Receiver<bool>,
    /// Particle-steps of the runs this process finished.
    pub particle_steps_total: AtomicU64,
}

impl Workers {
    pub fn new(
        store: Store,
        hub: Arc<Hub>,
        config: WorkerConfig,
        shutdown: watch::Receiver<bool>,
    ) -> Arc<Self> {
        Arc::new(Workers {
            store,
            hub,
            config,
            instance: format!("crush-{}", Uuid::new_v4()),
            running: Mutex::new(HashMap::new()),
            wake: Notify::new(),
            shutdown,
            particle_steps_total: AtomicU64::new(0),
        })
    }

    fn running(&self) -> std::sync::MutexGuard<'_, HashMap<Uuid, Arc<Running>>> {
        self.running.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn threads_per_job(&self) -> usize {
        self.config.threads_per_job
    }

    /// Starts the worker loops and the reaper.
    pub fn spawn(self: &Arc<Self>) -> Vec<tokio::task::JoinHandle<()>> {
        let mut handles: Vec<_> = (0..self.config.concurrent_jobs)
            .map(|_| tokio::spawn(self.clone().work()))
            .collect();
        handles.push(tokio::spawn(self.clone().reap()));
        handles
    }

    /// A new job is queued: wake an idle worker.
    pub fn notify(&self) {
        self.wake.notify_waiters();
        self.wake.notify_one();
    }

    /// Asks a job running here to stop. False when it does not run here.
    pub fn cancel(&self, id: Uuid) -> bool {
        match self.running().get(&id) {
            Some(r) => {
                r.user_cancel.store(true, Ordering::Relaxed);
                r.cancel.store(true, Ordering::Relaxed);
                true
            }
            None => false,
        }
    }

    /// Stops every run at its next step, to be requeued (shutdown).
    pub fn stop_all(&self) {
        for r in self.running().values() {
            r.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Jobs running here and their current particle-steps per second.
    pub fn load(&self) -> (usize, f64) {
        let running = self.running();
        let rate = running
            .values()
            .filter_map(|r| {
                let p = (*r.latest.lock().unwrap_or_else(|e| e.into_inner()))?;
                (p.elapsed_s > 0.0).then(|| r.particles as f64 * p.step as f64 / p.elapsed_s)
            })
            .fold(0.0, |sum, r| sum + r);
        (running.len(), rate)
    }

    /// Waits up to `grace` for the running jobs, then stops the rest; they go back to the
    /// queue as their solvers return (within a step).
    pub async fn drain(&self, grace: Duration) {
        let deadline = Instant::now() + grace;
        while !self.running().is_empty() && Instant::now() < deadline {
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        self.stop_all();
        let hard = Instant::now() + Duration::from_secs(5);
        while !self.running().is_empty() && Instant::now() < hard {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }

    async fn work(self: Arc<Self>) {
        let mut shutdown = self.shutdown.clone();
        while !*shutdown.borrow() {
            match self.store.claim(&self.instance).await {
                Ok(Some(job)) => self.run(job).await,
                Ok(None) => {
                    tokio::select! {
                        _ = self.wake.notified() => {}
                        _ = tokio::time::sleep(self.config.poll) => {}
                        _ = shutdown.wait_for(|s| *s) => {}
                    }
                }
                Err(e) => {
                    tracing::error!(error = %e, "claiming a job failed");
                    tokio::time::sleep(self.config.poll).await;
                }
            }
        }
    }

    async fn reap(self: Arc<Self>) {
        let mut shutdown = self.shutdown.clone();
        let every = (self.config.stale_after / 4).max(Duration::from_millis(100));
        while !*shutdown.borrow() {
            let stale = self.config.stale_after.as_millis() as i64;
            match self.store.reap_stale(stale, self.config.max_attempts).await {
                Ok(r) => {
                    for id in &r.requeued {
                        tracing::warn!(job = %id, "worker lost: job requeued");
                    }
                    for id in &r.failed {
                        tracing::warn!(job = %id, "worker lost too often: job failed");
                    }
                    if !r.requeued.is_empty() {
                        self.notify();
                    }
                }
                Err(e) => tracing::error!(error = %e, "reaping stale jobs failed"),
            }
            tokio::select! {
                _ = tokio::time::sleep(every) => {}
                _ = shutdown.wait_for(|s| *s) => {}
            }
        }
    }

    /// Runs one claimed job to its end and stores the outcome.
    async fn run(&self, job: Claimed) {
        let id = job.id;
        let case = match Case::from_json(&job.case_json, &self.config.limits) {
            Ok(case) => case,
            Err(e) => return self.end(&job, Status::Failed, Some(&format!("{e}"))).await,
        };
        let keep_state = case.spec().output.final_state;
        let pool = match rayon::ThreadPoolBuilder::new()
            .num_threads(self.config.threads_per_job)
            .thread_name(move |i| format!("crush-{}-{i}", &id.simple().to_string()[..8]))
            .build()
        {
            Ok(pool) => pool,
            Err(e) => {
                return self
                    .end(
                        &job,
                        Status::Failed,
                        Some(&format!("no solver threads: {e}")),
                    )
                    .await
            }
        };
        let running = Arc::new(Running {
            cancel: Arc::new(AtomicBool::new(false)),
            user_cancel: AtomicBool::new(false),
            particles: case.particle_count(),
            latest: Arc::new(Mutex::new(None)),
        });
        self.running().insert(id, running.clone());
        let mut publisher = self.hub.publisher(id, job.attempt);
        publisher.send(
            "status",
            serde_json::json!({"status": "running", "attempt": job.attempt}).to_string(),
        );
        let mut observer = JobObserver {
            publisher,
            latest: running.latest.clone(),
        };
        tracing::info!(job = %id, attempt = job.attempt, particles = running.particles, "job started");

        let heartbeat = tokio::spawn(heartbeat(
            self.store.clone(),
            job.clone(),
            running.clone(),
            self.config.heartbeat,
        ));
        let cancel = running.cancel.clone();
        let result = tokio::task::spawn_blocking(move || {
            let out = pool.install(|| solver::run(&case, &mut observer, &cancel));
            (out, observer)
        })
        .await;
        heartbeat.abort();
        let latest = *running.latest.lock().unwrap_or_else(|e| e.into_inner());
        let progress_json = latest.map(|p| serde_json::to_string(&p).unwrap_or_default());

        let (status, error, observer) = match result {
            Ok((Ok(out), observer)) => match views::non_finite(&out) {
                Some(what) => (
                    Status::Failed,
                    Some(format!("the solver returned {what}")),
                    Some(observer),
                ),
                None => {
                    let state = keep_state.then(|| state::encode(&out.snapshot));
                    let result = Succeeded {
                        history: &out.history,
                        summary: &out.summary,
                        final_state: state
                            .as_deref()
                            .map(|bytes| (out.snapshot.position_mm.len(), bytes)),
                        progress_json: progress_json.as_deref(),
                    };
                    let stored = self.store.finish_succeeded(id, job.lease, result).await;
                    match stored {
                        Ok(true) => {
                            let steps = out
                                .summary
                                .cost
                                .steps
                                .saturating_mul(out.summary.cost.particles);
                            self.particle_steps_total
                                .fetch_add(steps, Ordering::Relaxed);
                            tracing::info!(job = %id, "job succeeded");
                        }
                        Ok(false) => tracing::warn!(job = %id, "lease lost: result dropped"),
                        Err(e) => {
                            tracing::error!(job = %id, error = %e, "storing the result failed");
                            let _ = self.store.requeue(id, job.lease).await;
                        }
                    }
                    self.running().remove(&id);
                    return self.announce(id, observer).await;
                }
            },
            Ok((Err(SolveError::Cancelled { step }), observer)) => {
                if running.user_cancel.load(Ordering::Relaxed) {
                    (Status::Cancelled, None, Some(observer))
                } else {
                    // Shutdown or a lost lease: leave it for the next worker.
                    self.running().remove(&id);
                    if matches!(self.store.requeue(id, job.lease).await, Ok(true)) {
                        tracing::info!(job = %id, step, "job interrupted: requeued");
                        let mut p = observer.publisher;
                        p.send(
                            "status",
                            serde_json::json!({"status": "queued"}).to_string(),
                        );
                    }
                    return;
                }
            }
            Ok((Err(e @ SolveError::Unstable { .. }), observer)) => {
                (Status::Failed, Some(e.to_string()), Some(observer))
            }
            Err(panic) => {
                tracing::error!(job = %id, error = %panic, "the solver panicked");
                (
                    Status::Failed,
                    Some("the solver stopped with an internal error".to_string()),
                    None,
                )
            }
        };
        self.running().remove(&id);
        self.end(&job, status, error.as_deref()).await;
        if let Some(observer) = observer {
            self.announce(id, observer).await;
        }
    }

    /// Stores a failed or cancelled outcome.
    async fn end(&self, job: &Claimed, status: Status, error: Option<&str>) {
        match self
            .store
            .finish_unsuccessful(job.id, job.lease, status, error)
            .await
        {
            Ok(true) => tracing::info!(job = %job.id, status = status.as_str(), error, "job ended"),
            Ok(false) => tracing::warn!(job = %job.id, "lease lost: outcome dropped"),
            Err(e) => tracing::error!(job = %job.id, error = %e, "storing the outcome failed"),
        }
    }

    /// Sends the job's final event, built from what is now stored.
    async fn announce(&self, id: Uuid, observer: JobObserver) {
        let mut publisher = observer.publisher;
        if let Ok(Some(record)) = self.store.job(id).await {
            if let Some(event) = views::final_event(&record) {
                publisher.send(event.name, event.data);
            }
        }
    }
}

/// Beats while the job runs: stores the latest progress, notices a cancel asked through
/// another process, and stops the run if the lease was lost.
async fn heartbeat(store: Store, job: Claimed, running: Arc<Running>, every: Duration) {
    let mut tick = tokio::time::interval(every);
    tick.tick().await;
    loop {
        tick.tick().await;
        let latest = *running.latest.lock().unwrap_or_else(|e| e.into_inner());
        let json = latest.map(|p| (serde_json::to_string(&p).unwrap_or_default(), p.fraction));
        match store
            .heartbeat(
                job.id,
                job.lease,
                json.as_ref().map(|(j, f)| (j.as_str(), *f)),
            )
            .await
        {
            Ok(Some(true)) => {
                running.user_cancel.store(true, Ordering::Relaxed);
                running.cancel.store(true, Ordering::Relaxed);
            }
            Ok(Some(false)) => {}
            Ok(None) => {
                tracing::warn!(job = %job.id, "lease lost: stopping the run");
                running.cancel.store(true, Ordering::Relaxed);
                return;
            }
            Err(e) => tracing::error!(job = %job.id, error = %e, "heartbeat failed"),
        }
    }
}
