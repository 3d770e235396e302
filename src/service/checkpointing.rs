//! The worker's side of checkpoints: when a running job hands one over (every
//! `--checkpoint-every-s`, and once more when a shutdown stops it), and the task that stores
//! them under the job's lease while the solver goes on. A checkpoint larger than
//! `--checkpoint-max-mb` is never taken: the job then runs as before, from the start after an
//! interruption.

use super::hub::JobObserver;
use super::series::FrameSink;
use super::store::{Claimed, Store, StoredCheckpoint};
use crate::solver::{Checkpoint, Frame, HistoryRow, Observer, Progress};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::sync::mpsc;

/// When checkpoints are taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Policy {
    /// Time between two checkpoints of a run; `None`: no checkpoints.
    pub every: Option<Duration>,
    /// Largest checkpoint taken, bytes.
    pub max_bytes: u64,
}

/// What a run's observer needs to take checkpoints: the interval, the flags the worker sets,
/// and the channel to the writer.
pub struct Sink {
    every: Duration,
    last: Instant,
    /// A checkpoint is on its way to the store: the next waits for it.
    busy: Arc<AtomicBool>,
    /// The worker stops the run for a shutdown: hand over a checkpoint first.
    stopping: Arc<AtomicBool>,
    /// When the solver was asked for the checkpoint on its way (it pauses to write it).
    asked: Instant,
    tx: mpsc::Sender<(Checkpoint, Duration)>,
}

/// The solver's observer for a job: the hub's, plus checkpoints when the job takes them and
/// frames when its case keeps a series.
pub struct RunObserver {
    pub job: JobObserver,
    pub sink: Option<Sink>,
    pub frames: Option<FrameSink>,
}

impl Observer for RunObserver {
    fn on_progress(&mut self, progress: &Progress) {
        self.job.on_progress(progress);
    }
    fn on_history(&mut self, row: &HistoryRow) {
        self.job.on_history(row);
    }
    fn wants_checkpoint(&mut self) -> bool {
        let Some(s) = &mut self.sink else {
            return false;
        };
        let due = !s.busy.load(Ordering::Relaxed) && s.last.elapsed() >= s.every;
        if due {
            s.asked = Instant::now();
        }
        due
    }
    fn checkpoint_on_stop(&mut self) -> bool {
        let Some(s) = &mut self.sink else {
            return false;
        };
        s.asked = Instant::now();
        s.stopping.load(Ordering::SeqCst)
    }
    fn wants_frames(&self) -> bool {
        self.frames.is_some()
    }
    fn on_frame(&mut self, frame: &Frame) {
        if let Some(frames) = &self.frames {
            frames.send(frame);
        }
    }
    fn on_checkpoint(&mut self, checkpoint: Checkpoint) {
        if let Some(s) = &mut self.sink {
            s.busy.store(true, Ordering::Relaxed);
            s.last = Instant::now();
            // The channel holds the periodic one being written and the one of a stop.
            if s.tx.try_send((checkpoint, s.asked.elapsed())).is_err() {
                s.busy.store(false, Ordering::Relaxed);
            }
        }
    }
}

/// A sink for `job` and its writer: the task that stores each checkpoint it gets, and ends
/// once the sink is dropped and the last is stored. `None` when the policy takes none for a
/// checkpoint of `size` bytes.
pub fn start(
    policy: Policy,
    size: u64,
    stopping: Arc<AtomicBool>,
    store: Store,
    job: Claimed,
) -> Option<(Sink, tokio::task::JoinHandle<()>)> {
    let every = policy.every?;
    if size > policy.max_bytes {
        tracing::info!(
            job = %job.id,
            mb = size as f64 / 1e6,
            max_mb = policy.max_bytes as f64 / 1e6,
            "no checkpoints for this job: each would exceed --checkpoint-max-mb"
        );
        return None;
    }
    let (tx, rx) = mpsc::channel(2);
    let busy = Arc::new(AtomicBool::new(false));
    let sink = Sink {
        every,
        last: Instant::now(),
        busy: busy.clone(),
        stopping,
        asked: Instant::now(),
        tx,
    };
    Some((sink, tokio::spawn(write_each(store, job, rx, busy))))
}

async fn write_each(
    store: Store,
    job: Claimed,
    mut rx: mpsc::Receiver<(Checkpoint, Duration)>,
    busy: Arc<AtomicBool>,
) {
    while let Some((checkpoint, encode)) = rx.recv().await {
        let started = Instant::now();
        let stored = StoredCheckpoint {
            attempt: job.attempt,
            step: checkpoint.step as i64,
            fraction: checkpoint.fraction,
            data: checkpoint.bytes,
        };
        match store.save_checkpoint(job.id, job.lease, &stored).await {
            Ok(true) => tracing::info!(
                job = %job.id,
                step = stored.step,
                fraction = stored.fraction,
                mb = stored.data.len() as f64 / 1e6,
                encode_s = encode.as_secs_f64(),
                store_s = started.elapsed().as_secs_f64(),
                "checkpoint stored"
            ),
            Ok(false) => tracing::warn!(job = %job.id, "lease lost: checkpoint not stored"),
            Err(e) => tracing::error!(job = %job.id, error = %e, "storing a checkpoint failed"),
        }
        busy.store(false, Ordering::Relaxed);
    }
}
