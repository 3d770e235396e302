//! The node's part in a cluster of nodes sharing one PostgreSQL store: a relay that sends the
//! events of runs on this node to the others, and a dispatcher that acts on what the others
//! send (their runs' events to this node's listeners, cancels of jobs running here, wake-ups
//! for queued jobs). Nothing runs on SQLite, where a node is alone.

use super::hub::{Event, Hub};
use super::store::{signals, Signal, Store};
use super::worker::Workers;
use std::sync::Arc;
use tokio::sync::{mpsc, watch};
use tokio::task::JoinHandle;
use uuid::Uuid;

/// Events waiting for the relay: past this the newest progress events are dropped rather than
/// slow the solver (listeners elsewhere catch up from the store's progress).
const RELAY_QUEUE: usize = 4096;

/// Starts the relay and the dispatcher on PostgreSQL; none on SQLite.
pub fn start(
    store: &Store,
    hub: &Arc<Hub>,
    workers: &Arc<Workers>,
    shutdown: watch::Receiver<bool>,
) -> Vec<JoinHandle<()>> {
    let Some(incoming) = store.listen(workers.node().to_string()) else {
        return Vec::new();
    };
    let (tx, outgoing) = mpsc::channel(RELAY_QUEUE);
    hub.relay_to(tx);
    vec![
        tokio::spawn(relay(
            store.clone(),
            workers.node().to_string(),
            outgoing,
            shutdown.clone(),
        )),
        tokio::spawn(dispatch(hub.clone(), workers.clone(), incoming, shutdown)),
    ]
}

/// Sends this node's events to the others, batching whatever accumulated during the last send
/// (one `NOTIFY` per job and about 7 kB).
async fn relay(
    store: Store,
    node: String,
    mut outgoing: mpsc::Receiver<(Uuid, Event)>,
    mut shutdown: watch::Receiver<bool>,
) {
    loop {
        let first = tokio::select! {
            e = outgoing.recv() => e,
            _ = shutdown.wait_for(|s| *s) => None,
        };
        let Some(first) = first else { return };
        let mut by_job: Vec<(Uuid, Vec<signals::WireEvent>)> = Vec::new();
        let mut add = |(job, event): (Uuid, Event)| match by_job.iter_mut().find(|(j, _)| *j == job)
        {
            Some((_, events)) => events.push(event.to_wire()),
            None => by_job.push((job, vec![event.to_wire()])),
        };
        add(first);
        while let Ok(next) = outgoing.try_recv() {
            add(next);
        }
        for (job, events) in by_job {
            for payload in signals::pack(&node, job, events) {
                if let Err(e) = store.notify(&payload).await {
                    tracing::warn!(%job, error = %e, "relaying events to the other nodes failed");
                }
            }
        }
    }
}

/// Acts on the other nodes' signals.
async fn dispatch(
    hub: Arc<Hub>,
    workers: Arc<Workers>,
    mut incoming: mpsc::Receiver<Signal>,
    mut shutdown: watch::Receiver<bool>,
) {
    loop {
        let signal = tokio::select! {
            s = incoming.recv() => s,
            _ = shutdown.wait_for(|s| *s) => None,
        };
        match signal {
            None => return,
            Some(Signal::Events { job, events }) => {
                hub.deliver(
                    job,
                    events.into_iter().filter_map(Event::from_wire).collect(),
                );
            }
            Some(Signal::Cancel { job }) => {
                workers.cancel_here(job);
            }
            Some(Signal::Queued) => workers.wake_here(),
        }
    }
}
