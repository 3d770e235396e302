//! The worker's side of a job's time series (`output.frames`): the solver hands each frame to
//! the run's observer on its own thread, which encodes it (56 bytes a particle) and passes it
//! to a task that stores it under the job's lease. The channel holds one frame and the solver
//! waits for room, so a job holds at most three frames at once, whatever the store's pace: one
//! being built, one waiting, one being written.

use super::retry::{self, Trouble};
use super::store::{Claimed, Store, StoredFrame};
use crate::export::series::{self, FrameTime};
use crate::solver::Frame;
use std::time::Duration;
use tokio::sync::mpsc;

/// Where a run's observer sends its frames.
pub struct FrameSink {
    tx: mpsc::Sender<StoredFrame>,
}

impl FrameSink {
    /// Encodes `frame` and queues it for the store, waiting while the one before is queued.
    /// Called on the solver's thread, never on the async runtime's.
    pub fn send(&self, frame: &Frame) {
        let stored = StoredFrame {
            at: FrameTime {
                index: frame.index,
                travel_mm: frame.travel_mm,
                time_ms: frame.time_ms,
            },
            particles: frame.position_mm.len(),
            data: series::encode(frame),
        };
        // The writer ends only once this sink is dropped, or after a frame it could not store:
        // then it has reported the trouble, which stops the run.
        let _ = self.tx.blocking_send(stored);
    }
}

/// A sink for `job`'s frames and its writer, the task that stores each (retrying while the
/// database is away, for at most `patience`) and ends once the sink is dropped and the last is
/// stored, or once a frame could not be stored (reported to `trouble`); `None` when the case
/// keeps no series.
pub fn start(
    frames: u32,
    store: Store,
    job: Claimed,
    patience: Duration,
    trouble: Trouble,
) -> Option<(FrameSink, tokio::task::JoinHandle<()>)> {
    if frames == 0 {
        return None;
    }
    let (tx, rx) = mpsc::channel(1);
    let writer = write_each(store, job, rx, patience, trouble);
    Some((FrameSink { tx }, tokio::spawn(writer)))
}

async fn write_each(
    store: Store,
    job: Claimed,
    mut rx: mpsc::Receiver<StoredFrame>,
    patience: Duration,
    trouble: Trouble,
) {
    while let Some(frame) = rx.recv().await {
        let k = frame.at.index;
        let what = format!("frame {k}");
        let save = || store.save_frame(job.id, job.lease, &frame);
        match retry::until_stored(&what, job.id, patience, save).await {
            Ok(true) => tracing::debug!(job = %job.id, frame = k, "frame stored"),
            Ok(false) => {
                tracing::warn!(job = %job.id, frame = k, "lease lost: frame not stored");
                return;
            }
            Err(e) => {
                tracing::error!(job = %job.id, frame = k, error = %e, "storing a frame failed");
                return trouble.report(retry::reason(&what, &e));
            }
        }
    }
}
