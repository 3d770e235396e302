//! The worker pool: a fixed number of loops that claim jobs, run each on its own rayon pool in
//! `spawn_blocking`, heartbeat while it runs and store the outcome; a reaper that puts back jobs
//! whose worker died; and a bounded, requeueing drain on shutdown.

use super::checkpointing::{self, RunObserver};
use super::hub::{self, Hub, JobObserver};
use super::retry::{self, Trouble};
use super::series;
use super::store::{signals, Claimed, Result as StoreResult, Signal, Status, Store, Succeeded};
use super::views;
use crate::export;
use crate::solver::analysis::error_bar::Rung;
use crate::solver::{Case, Checkpoint, Limits, Progress, Resume, RunOutput, Runner, SolveError};
use futures::future::OptionFuture;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::sync::{oneshot, watch, Notify};
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
    /// This node's name: stored with each job it claims (`--node-name`).
    pub node: String,
    /// When running jobs store checkpoints.
    pub checkpoints: checkpointing::Policy,
    /// How long a running job retries a write the database refuses for a reason that heals
    /// (its frames, checkpoints, outcome) before the write counts as failed.
    pub store_patience: Duration,
}

/// A job running in this process.
struct Running {
    cancel: Arc<AtomicBool>,
    /// The client asked for the cancel (as opposed to shutdown or a lost lease).
    user_cancel: AtomicBool,
    /// A shutdown stops the run: it hands over a checkpoint before it stops.
    stopping: Arc<AtomicBool>,
    particles: u64,
    latest: Arc<Mutex<Option<Progress>>>,
}

/// The pool. Shared by the routes (cancel, metrics) and the worker loops.
pub struct Workers {
    store: Store,
    hub: Arc<Hub>,
    config: WorkerConfig,
    running: Mutex<HashMap<Uuid, Arc<Running>>>,
    wake: Notify,
    shutdown: watch::Receiver<bool>,
    /// Particle-steps of the runs this process finished.
    pub particle_steps_total: AtomicU64,
    /// How long the claims that got a job took, s.
    pub claim_seconds: prometheus_client::metrics::histogram::Histogram,
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
            running: Mutex::new(HashMap::new()),
            wake: Notify::new(),
            shutdown,
            particle_steps_total: AtomicU64::new(0),
            claim_seconds: super::metrics::claim_histogram(),
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

    /// A new job is queued: wake an idle worker here, and tell the other nodes (PostgreSQL).
    pub fn notify(&self) {
        self.wake_here();
        self.tell_others(Signal::Queued);
    }

    /// Wakes an idle worker of this node.
    pub fn wake_here(&self) {
        self.wake.notify_waiters();
        self.wake.notify_one();
    }

    /// Asks a job to stop: here if it runs here, else the node that runs it is told
    /// (PostgreSQL; its heartbeat would also see the cancel, within a heartbeat).
    pub fn cancel(&self, id: Uuid) {
        if !self.cancel_here(id) {
            self.tell_others(Signal::Cancel { job: id });
        }
    }

    /// Stops a job running here at its next step, as the client's cancel. False when it does
    /// not run here.
    pub fn cancel_here(&self, id: Uuid) -> bool {
        match self.running().get(&id) {
            Some(r) => {
                r.user_cancel.store(true, Ordering::Relaxed);
                r.cancel.store(true, Ordering::Relaxed);
                true
            }
            None => false,
        }
    }

    /// Sends a signal to the other nodes without waiting for it; nothing on SQLite.
    fn tell_others(&self, signal: Signal) {
        if self.store.postgres_url().is_none() {
            return;
        }
        let store = self.store.clone();
        let payload = signals::encode(&self.config.node, signal);
        tokio::spawn(async move {
            if let Err(e) = store.notify(&payload).await {
                tracing::warn!(error = %e, "telling the other nodes failed");
            }
        });
    }

    /// This node's name.
    pub fn node(&self) -> &str {
        &self.config.node
    }

    /// Stops every run at its next step, to be requeued (shutdown): each stores a checkpoint
    /// first, so that the next claim resumes it.
    pub fn stop_all(&self) {
        for r in self.running().values() {
            r.stopping.store(true, Ordering::SeqCst);
            r.cancel.store(true, Ordering::SeqCst);
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

    /// Waits up to `grace` for the running jobs, then stops the rest; they store a checkpoint
    /// and go back to the queue as their solvers return (within a step).
    pub async fn drain(&self, grace: Duration) {
        let deadline = Instant::now() + grace;
        while !self.running().is_empty() && Instant::now() < deadline {
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        self.stop_all();
        // Time for the last checkpoints to reach the store (seconds for the largest).
        let hard = Instant::now() + Duration::from_secs(30);
        while !self.running().is_empty() && Instant::now() < hard {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }

    async fn work(self: Arc<Self>) {
        let mut shutdown = self.shutdown.clone();
        let mut failures = 0u32;
        while !*shutdown.borrow() {
            let asked = Instant::now();
            let claimed = self.store.claim(&self.config.node).await;
            failures = if claimed.is_err() { failures + 1 } else { 0 };
            match claimed {
                Ok(Some(job)) => {
                    self.claim_seconds.observe(asked.elapsed().as_secs_f64());
                    self.run(job).await
                }
                Ok(None) => {
                    tokio::select! {
                        _ = self.wake.notified() => {}
                        _ = tokio::time::sleep(self.config.poll) => {}
                        _ = shutdown.wait_for(|s| *s) => {}
                    }
                }
                Err(e) => {
                    // Back off while the database is unusable (at most 5 s, so a healed disk is
                    // used again soon), logging the first failure and then every 10th.
                    if failures % 10 == 1 {
                        tracing::error!(error = %e, failures, "claiming a job failed");
                    }
                    let wait = self.config.poll * 2u32.pow(failures.min(4));
                    tokio::select! {
                        _ = tokio::time::sleep(wait.min(Duration::from_secs(5))) => {}
                        _ = self.wake.notified() => {}
                        _ = shutdown.wait_for(|s| *s) => {}
                    }
                }
            }
        }
    }

    async fn reap(self: Arc<Self>) {
        let mut shutdown = self.shutdown.clone();
        let every = (self.config.stale_after / 4).max(Duration::from_millis(100));
        while !*shutdown.borrow() {
            if let Err(e) = self.store.check_file() {
                tracing::error!(error = %e, "the database file is gone: no job is claimed or stored");
            }
            let stale = self.config.stale_after.as_millis() as i64;
            let alive: Vec<Uuid> = self.running().keys().copied().collect();
            let reaped = self
                .store
                .reap_stale(stale, self.config.max_attempts, &alive)
                .await;
            match reaped {
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

    /// Runs one claimed job to its end: the run, then its [`Outcome`], then one store step and
    /// one announcement. The job leaves the running map on every path, a panic included.
    async fn run(&self, job: Claimed) {
        let case = Case::from_json(&job.case_json, &self.config.limits);
        let running = Arc::new(Running {
            cancel: Arc::new(AtomicBool::new(false)),
            user_cancel: AtomicBool::new(false),
            stopping: Arc::new(AtomicBool::new(false)),
            particles: case.as_ref().map_or(0, |c| c.particle_count()),
            latest: Arc::new(Mutex::new(None)),
        });
        let _tracked = Tracked::insert(self, job.id, running.clone());
        let (outcome, publisher, promised) = match case {
            Ok(case) => {
                let output = &case.spec().output;
                let promised = Promised {
                    final_state: output.final_state,
                    frames: output.frames,
                };
                let (outcome, publisher) = self.execute(&job, case, &running).await;
                (outcome, publisher, promised)
            }
            Err(e) => (Outcome::Failed(e.to_string()), None, Promised::default()),
        };
        let latest = *running.latest.lock().unwrap_or_else(|e| e.into_inner());
        let progress_json = latest.map(|p| serde_json::to_string(&p).unwrap_or_default());
        let store = || self.store_outcome(&job, &outcome, progress_json.as_deref(), promised);
        let stored = retry::until_stored(
            "the job's outcome",
            job.id,
            self.config.store_patience,
            store,
        )
        .await;
        self.announce(&job, stored, publisher).await;
    }

    /// Runs the solver on the job's own rayon pool, heartbeating meanwhile, from the job's
    /// checkpoint when it has one that fits, storing checkpoints as it goes. Returns the outcome
    /// and, when the run returned (did not panic), its publisher; the last checkpoint is stored
    /// before it returns.
    async fn execute(
        &self,
        job: &Claimed,
        case: Case,
        running: &Arc<Running>,
    ) -> (Outcome, Option<hub::Publisher>) {
        let id = job.id;
        let name = move |i| format!("crush-{}-{i}", &id.simple().to_string()[..8]);
        let runner = match Runner::new(self.config.threads_per_job, name) {
            Ok(runner) => runner,
            Err(e) => return (Outcome::Failed(format!("no solver threads: {e}")), None),
        };
        let particles = running.particles;
        let case = Arc::new(case);
        let from = self.read_checkpoint(job, &case).await;
        let done = match &from {
            Some(_) => self.read_ladder(job).await,
            None => Vec::new(),
        };
        // A resumed run reports where it stands until its next row (or, resumed at its end,
        // while its error bar is priced).
        let points = case.spec().output.history_points as usize;
        if let Some((_, _, from)) = &from {
            *running.latest.lock().unwrap_or_else(|e| e.into_inner()) = from.progress(points);
        }
        let patience = self.config.store_patience;
        let trouble = Trouble::new(running.cancel.clone());
        let mut publisher = self.hub.publisher(id, job.attempt);
        let mut status = serde_json::json!({"status": "running", "attempt": job.attempt});
        if let Some((step, fraction, _)) = &from {
            status["resumes_at"] = serde_json::json!({"step": step, "fraction": fraction});
        }
        publisher.send("status", status.to_string());
        let size = Checkpoint::size_for(&case, particles, case.spec().output.history_points as u64);
        let started = checkpointing::start(
            self.config.checkpoints,
            size,
            Runner::may_price_error_bar(&case),
            running.stopping.clone(),
            self.store.clone(),
            job.clone(),
            patience,
        );
        let (sink, writer) = started.unzip();
        let frames = case.spec().output.frames;
        let series = series::start(
            frames,
            self.store.clone(),
            job.clone(),
            patience,
            trouble.clone(),
        );
        let (frames, frame_writer) = series.unzip();
        let mut observer = RunObserver {
            job: JobObserver {
                publisher,
                latest: running.latest.clone(),
            },
            sink,
            frames,
            done,
        };
        tracing::info!(job = %id, attempt = job.attempt, particles, "job started");
        let (stop_beating, beats_stop) = oneshot::channel::<()>();
        let heartbeat = tokio::spawn(heartbeat(
            self.store.clone(),
            job.clone(),
            running.clone(),
            self.config.heartbeat,
            beats_stop,
        ));
        let cancel = running.cancel.clone();
        let result = tokio::task::spawn_blocking(move || {
            let from = from.map(|(_, _, from)| from);
            let out = runner
                .resume(&case, from, &mut observer, &cancel)
                .and_then(|mut out| {
                    runner.add_error_bar_if_asked(&case, &mut out, &mut observer, &cancel)?;
                    Ok(out)
                });
            // The sinks go with the observer: the writers store what they have and end.
            (out, observer.job.publisher)
        })
        .await;
        // Told, not aborted: a beat in flight finishes its statement first (an abort mid-query
        // can hand its pooled connection back half-way through the protocol). A beat stuck on
        // an unreachable store is left to end on its own after a minute.
        drop(stop_beating);
        let _ = tokio::time::timeout(Duration::from_secs(60), heartbeat).await;
        for (what, writer) in [("checkpoint", writer), ("frame", frame_writer)] {
            if let Some(Err(e)) = OptionFuture::from(writer).await {
                tracing::error!(job = %id, error = %e, "the {what} writer panicked");
            }
        }
        let user_cancel = running.user_cancel.load(Ordering::Relaxed);
        if let Some(why) = trouble.why().filter(|_| !user_cancel) {
            tracing::error!(job = %id, reason = %why, "the job fails: its results could not all be stored");
            let publisher = result.ok().map(|(_, publisher)| publisher);
            return (Outcome::Failed(why), publisher);
        }
        match result {
            Ok((out, publisher)) => (Outcome::of(Ok(out), user_cancel), Some(publisher)),
            Err(e) => {
                let panic = panic_message(e);
                tracing::error!(job = %id, error = %panic, "the solver panicked");
                (Outcome::of(Err(panic), user_cancel), None)
            }
        }
    }

    /// The job's checkpoint, decoded and checked against its case, with the step and share
    /// of the crush it stands at; `None` when it has none. One that cannot be used (damaged,
    /// of another format or case) is deleted with a log line, and the run starts over.
    async fn read_checkpoint(&self, job: &Claimed, case: &Arc<Case>) -> Option<(i64, f64, Resume)> {
        let stored = match self.store.checkpoint(job.id).await {
            Ok(stored) => stored?,
            Err(e) => {
                tracing::error!(job = %job.id, error = %e, "reading the checkpoint failed: the run starts over");
                return None;
            }
        };
        let (step, fraction) = (stored.step, stored.fraction);
        let case = case.clone();
        let read = tokio::task::spawn_blocking(move || Resume::read(&case, &stored.data)).await;
        match read {
            Ok(Ok(from)) => {
                tracing::info!(job = %job.id, step, fraction, "resuming from the checkpoint");
                Some((step, fraction, from))
            }
            Ok(Err(why)) => {
                tracing::warn!(job = %job.id, step, reason = %why, "checkpoint discarded: the run starts over");
                if let Err(e) = self.store.discard_checkpoint(job.id, job.lease).await {
                    tracing::error!(job = %job.id, error = %e, "deleting the checkpoint failed");
                }
                None
            }
            Err(e) => {
                tracing::error!(job = %job.id, error = %e, "reading the checkpoint panicked");
                None
            }
        }
    }

    /// The rungs of the job's error-bar ladder an earlier claim finished (none when it has
    /// none, or they do not read: they are run again).
    async fn read_ladder(&self, job: &Claimed) -> Vec<Rung> {
        let json = match self.store.ladder(job.id).await {
            Ok(json) => json,
            Err(e) => {
                tracing::error!(job = %job.id, error = %e, "reading the error bar's rungs failed: they run again");
                None
            }
        };
        let rungs = json.map(|j| serde_json::from_str::<Vec<Rung>>(&j));
        match rungs {
            Some(Ok(rungs)) => {
                tracing::info!(job = %job.id, rungs = rungs.len(), "resuming the error bar's ladder");
                rungs
            }
            Some(Err(e)) => {
                tracing::warn!(job = %job.id, error = %e, "the error bar's rungs do not read: they run again");
                Vec::new()
            }
            None => Vec::new(),
        }
    }

    /// The one store step of an outcome: the status now stored, or `None` when the lease was
    /// lost (another worker has the job; nothing was written).
    async fn store_outcome(
        &self,
        job: &Claimed,
        outcome: &Outcome,
        progress_json: Option<&str>,
        promised: Promised,
    ) -> StoreResult<Option<Status>> {
        let (id, lease) = (job.id, job.lease);
        match outcome {
            Outcome::Succeeded(out) => {
                let state = promised
                    .final_state
                    .then(|| export::vtu::encode(&out.snapshot));
                let particles = out.snapshot.position_mm.len();
                let result = Succeeded {
                    history: &out.history,
                    summary: &out.summary,
                    final_state: state.as_deref().map(|bytes| (particles, bytes)),
                    progress_json,
                    frames: promised.frames,
                    particles,
                };
                let stored = self.store.finish_succeeded(id, lease, result).await?;
                if stored == Some(Status::Succeeded) {
                    let cost = &out.summary.cost;
                    self.particle_steps_total
                        .fetch_add(cost.steps.saturating_mul(cost.particles), Ordering::Relaxed);
                }
                Ok(stored)
            }
            Outcome::Failed(error) => {
                self.store
                    .finish_unsuccessful(id, lease, Status::Failed, Some(error))
                    .await
            }
            Outcome::Cancelled => {
                self.store
                    .finish_unsuccessful(id, lease, Status::Cancelled, None)
                    .await
            }
            Outcome::Interrupted { step } => {
                tracing::info!(job = %id, step, "job interrupted");
                self.store
                    .requeue(id, lease, self.config.max_attempts)
                    .await
            }
        }
    }

    /// Logs what became of the job and tells its listeners: a `status` event when it went
    /// back to the queue, else the final event built from what is now stored.
    async fn announce(
        &self,
        job: &Claimed,
        stored: StoreResult<Option<Status>>,
        publisher: Option<hub::Publisher>,
    ) {
        let id = job.id;
        let status = match stored {
            Ok(Some(status)) => status,
            Ok(None) => return tracing::warn!(job = %id, "lease lost: outcome dropped"),
            Err(e) => {
                // The job stays `running` with a stale heartbeat: the reaper puts it back once
                // the database can be written again.
                return tracing::error!(job = %id, error = %e, "storing the outcome failed");
            }
        };
        tracing::info!(job = %id, attempt = job.attempt, status = status.as_str(), "job ended");
        if status == Status::Queued {
            if let Some(mut p) = publisher {
                p.send(
                    "status",
                    serde_json::json!({"status": "queued"}).to_string(),
                );
            }
            return;
        }
        drop(publisher);
        // When the job cannot be read back, streams find the end on their next store poll.
        if let Ok(Some(record)) = self.store.job(id).await {
            if let Some(event) = views::final_event(&record) {
                self.hub.announce(id, event);
            }
        }
    }
}

/// What a succeeded run of a case must have stored besides its history and summary.
#[derive(Debug, Clone, Copy, Default)]
struct Promised {
    /// The final particle state (`output.final_state`).
    final_state: bool,
    /// The frames of its series (`output.frames`).
    frames: u32,
}

/// How a claimed run ended.
#[derive(Debug)]
enum Outcome {
    Succeeded(Box<RunOutput>),
    /// The reason, for the client.
    Failed(String),
    /// A client asked.
    Cancelled,
    /// Shutdown or a lost lease stopped it: back to the queue.
    Interrupted {
        step: u64,
    },
}

impl Outcome {
    /// The solver's result, or its panic message, as an outcome. `user_cancel`: a client asked
    /// for the cancel (rather than the shutdown or a lost lease).
    fn of(result: Result<Result<RunOutput, SolveError>, String>, user_cancel: bool) -> Outcome {
        match result {
            Ok(Ok(out)) => match views::non_finite(&out) {
                Some(what) => Outcome::Failed(format!("the solver returned {what}")),
                None => Outcome::Succeeded(Box::new(out)),
            },
            Ok(Err(SolveError::Cancelled { .. })) if user_cancel => Outcome::Cancelled,
            Ok(Err(SolveError::Cancelled { step })) => Outcome::Interrupted { step },
            Ok(Err(e @ SolveError::Unstable { .. })) => Outcome::Failed(e.to_string()),
            // The message stays in the log: it is internal.
            Err(_panic) => Outcome::Failed("the solver stopped with an internal error".into()),
        }
    }
}

/// The text of a solver panic (or why there is none).
fn panic_message(e: tokio::task::JoinError) -> String {
    match e.try_into_panic() {
        Ok(payload) => payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into()),
        Err(e) => e.to_string(),
    }
}

/// A job in the running map while this lives.
struct Tracked<'a> {
    workers: &'a Workers,
    id: Uuid,
}

impl<'a> Tracked<'a> {
    fn insert(workers: &'a Workers, id: Uuid, running: Arc<Running>) -> Tracked<'a> {
        workers.running().insert(id, running);
        Tracked { workers, id }
    }
}

impl Drop for Tracked<'_> {
    fn drop(&mut self) {
        self.workers.running().remove(&self.id);
    }
}

/// Beats while the job runs: stores the latest progress, notices a cancel asked through
/// another process, and stops the run if the lease was lost. Ends between beats once `stop`
/// resolves (its sender sent or dropped), never inside a store call.
async fn heartbeat(
    store: Store,
    job: Claimed,
    running: Arc<Running>,
    every: Duration,
    mut stop: oneshot::Receiver<()>,
) {
    let mut tick = tokio::time::interval(every);
    tick.tick().await;
    loop {
        tokio::select! {
            _ = tick.tick() => {}
            _ = &mut stop => return,
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::NewJob;

    /// What broke: the heartbeat was aborted when its run ended, possibly inside its UPDATE,
    /// and PostgreSQL once answered a later beat with "incorrect binary data format in bind
    /// parameter 3". It now ends between beats when told, after storing what it beat with.
    #[tokio::test]
    async fn a_heartbeat_told_to_stop_ends_between_beats_after_storing_its_progress() {
        let (_dir, store) = crate::service::store::temp_store().await;
        let id = Uuid::new_v4();
        let new = NewJob {
            id,
            case_json: "{}".into(),
            label: None,
            particles: 10,
            idempotency_key: None,
        };
        store.submit(new, 10).await.unwrap();
        let job = store.claim("a").await.unwrap().unwrap();
        let progress = Progress {
            step: 7,
            time_ms: 0.1,
            displacement_mm: 1.0,
            load_n: 5.0,
            fraction: 0.25,
            elapsed_s: 1.0,
            eta_s: 3.0,
            error_bar: None,
        };
        let running = Arc::new(Running {
            cancel: Arc::new(AtomicBool::new(false)),
            user_cancel: AtomicBool::new(false),
            stopping: Arc::new(AtomicBool::new(false)),
            particles: 10,
            latest: Arc::new(Mutex::new(Some(progress))),
        });
        let (stop, stopped) = oneshot::channel();
        let every = Duration::from_millis(5);
        let beating = tokio::spawn(heartbeat(
            store.clone(),
            job,
            running.clone(),
            every,
            stopped,
        ));
        let stored = async {
            loop {
                if let Some(json) = store.job(id).await.unwrap().unwrap().progress_json {
                    return json;
                }
                tokio::time::sleep(every).await;
            }
        };
        let json = tokio::time::timeout(Duration::from_secs(10), stored)
            .await
            .unwrap();
        assert_eq!(serde_json::from_str::<Progress>(&json).unwrap(), progress);
        drop(stop);
        tokio::time::timeout(Duration::from_secs(10), beating)
            .await
            .expect("the heartbeat ends by itself once told")
            .expect("and does not panic");
        assert!(
            !running.cancel.load(Ordering::Relaxed),
            "nothing was cancelled"
        );
    }

    #[test]
    fn a_panic_fails_the_job_and_a_cancel_is_the_clients_or_an_interruption() {
        let panicked = Outcome::of(Err("index out of bounds".into()), false);
        let Outcome::Failed(why) = panicked else {
            panic!("{panicked:?}")
        };
        assert!(!why.contains("index"), "the panic stays in the log: {why}");
        let cancelled = || Ok(Err(SolveError::Cancelled { step: 7 }));
        assert!(matches!(Outcome::of(cancelled(), true), Outcome::Cancelled));
        assert!(matches!(
            Outcome::of(cancelled(), false),
            Outcome::Interrupted { step: 7 }
        ));
        let unstable = Ok(Err(SolveError::Unstable {
            step: 3,
            time_ms: 0.5,
            what: "kinetic energy".into(),
        }));
        assert!(matches!(Outcome::of(unstable, true), Outcome::Failed(w) if w.contains("kinetic")));
    }
}
