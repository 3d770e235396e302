//! The worker's side of checkpoints: when a running job hands one over (every
//! `--checkpoint-every-s`, once more when a shutdown stops it, and once at the end of the crush
//! when the run goes on to price its error bar), and the task that stores them under the job's
//! lease while the solver goes on, retrying while the database is away. While the error bar is
//! priced, each finished rung of its ladder is stored beside the finished run's checkpoint, so
//! that an interrupted job resumes with the next rung instead of the crush. A checkpoint larger
//! than `--checkpoint-max-mb` is never taken: the job then runs as before, from the start after
//! an interruption.

use super::hub::JobObserver;
use super::retry;
use super::series::FrameSink;
use super::store::{Claimed, Store, StoredCheckpoint};
use crate::solver::analysis::error_bar::Rung;
use crate::solver::{
    Checkpoint, Frame, HistoryRow, LadderObserver, Observer, Progress, RungProgress,
};
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
    /// Hand over the finished run's checkpoint: the run goes on to price its error bar.
    at_end: bool,
    tx: mpsc::Sender<Write>,
}

/// What the writer stores.
enum Write {
    /// A checkpoint, and how long the solver took to encode it.
    Checkpoint(Checkpoint, Duration),
    /// The ladder's finished rungs, as JSON.
    Ladder(String),
}

/// The solver's observer for a job: the hub's, plus checkpoints when the job takes them and
/// frames when its case keeps a series; and its error bar's ladder's, with the rungs an earlier
/// claim finished (`done`).
pub struct RunObserver {
    pub job: JobObserver,
    pub sink: Option<Sink>,
    pub frames: Option<FrameSink>,
    pub done: Vec<Rung>,
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
    fn checkpoint_at_end(&mut self) -> bool {
        let Some(s) = &mut self.sink else {
            return false;
        };
        s.asked = Instant::now();
        s.at_end
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
            // The channel holds the periodic one being written and the one of a stop or of
            // the end (a run asks for no periodic one while one is on its way).
            let write = Write::Checkpoint(checkpoint, s.asked.elapsed());
            if s.tx.try_send(write).is_err() {
                s.busy.store(false, Ordering::Relaxed);
            }
        }
    }
}

impl LadderObserver for RunObserver {
    fn done(&self, index: usize, n: u32) -> Option<Rung> {
        self.done.get(index).filter(|r| r.n == n).cloned()
    }
    fn on_rung_progress(&mut self, rung: &RungProgress) {
        let latest = *self.job.latest.lock().unwrap_or_else(|e| e.into_inner());
        let Some(run) = latest else { return };
        self.job.on_progress(&Progress {
            fraction: 1.0,
            eta_s: 0.0,
            error_bar: Some(*rung),
            ..run
        });
    }
    fn on_rung(&mut self, index: usize, rung: &Rung) {
        self.done.truncate(index);
        self.done.push(rung.clone());
        if let Some(s) = &self.sink {
            let json = serde_json::to_string(&self.done).unwrap_or_default();
            // On the solver's thread: it waits for room rather than drop a rung.
            let _ = s.tx.blocking_send(Write::Ladder(json));
        }
    }
}

/// A sink for `job` and its writer: the task that stores each checkpoint and ladder it gets
/// (retrying while the database is away, for at most `patience`), and ends once the sink is
/// dropped and the last is stored. `at_end`: the run hands over its finished state (it goes on
/// to price its error bar). `None` when the policy takes none for a checkpoint of `size` bytes.
pub fn start(
    policy: Policy,
    size: u64,
    at_end: bool,
    stopping: Arc<AtomicBool>,
    store: Store,
    job: Claimed,
    patience: Duration,
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
        at_end,
        tx,
    };
    let writer = write_each(store, job, rx, busy, patience);
    Some((sink, tokio::spawn(writer)))
}

async fn write_each(
    store: Store,
    job: Claimed,
    mut rx: mpsc::Receiver<Write>,
    busy: Arc<AtomicBool>,
    patience: Duration,
) {
    while let Some(write) = rx.recv().await {
        let (checkpoint, encode) = match write {
            Write::Checkpoint(checkpoint, encode) => (checkpoint, encode),
            Write::Ladder(json) => {
                let save = || store.save_ladder(job.id, job.lease, job.attempt, &json);
                match retry::until_stored("a rung of the error bar", job.id, patience, save).await {
                    Ok(true) => tracing::info!(job = %job.id, "rung of the error bar stored"),
                    Ok(false) => {
                        tracing::warn!(job = %job.id, "rung of the error bar not stored: lease lost or no checkpoint")
                    }
                    Err(e) => {
                        tracing::error!(job = %job.id, error = %e, "storing a rung of the error bar failed")
                    }
                }
                continue;
            }
        };
        let started = Instant::now();
        let stored = StoredCheckpoint {
            attempt: job.attempt,
            step: checkpoint.step as i64,
            fraction: checkpoint.fraction,
            data: checkpoint.bytes,
        };
        let save = || store.save_checkpoint(job.id, job.lease, &stored);
        match retry::until_stored("a checkpoint", job.id, patience, save).await {
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
