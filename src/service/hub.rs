//! The progress hub: one `tokio::sync::broadcast` channel per job that has a worker or a
//! listener, fed from the solver thread without blocking, read by the SSE streams. Each channel
//! also keeps the current claim's events so far (at most [`REPLAY_CAP`], evenly thinned), for
//! listeners that join mid-run.
//!
//! With a PostgreSQL store, every event also goes to a relay (see [`Hub::relay_to`]) that tells
//! the other nodes, and events relayed from them are delivered here ([`Hub::deliver`]) as if a
//! local run had sent them: same ids, same replay.
//!
//! Event ids increase over a job's whole life, across restarts: an event of claim `a` has id
//! `a · SPAN + k` with `k` counting within the claim, and a job's final event has the largest id
//! its last claim can have. A client resuming with `Last-Event-ID` is sent only newer events.

use crate::service::store::signals::WireEvent;
use crate::solver::{Observer, Progress};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use tokio::sync::{broadcast, mpsc};
use uuid::Uuid;

/// Ids available to one claim of a job.
pub const SPAN: u64 = 1_000_000;

/// Most non-final events of one claim: `k` runs over `0..=LAST_K`, and `SPAN − 1` is the final
/// event's. A run sends one progress event per history row (at most 100 000), so this is never
/// reached; if it were, the publisher drops the excess instead of repeating an id (which
/// de-duplication would take for events already sent).
pub const LAST_K: u64 = SPAN - 2;

/// Id of the `k`-th event of claim `attempt` (`k` at most [`LAST_K`]).
pub fn event_id(attempt: i64, k: u64) -> u64 {
    debug_assert!(k <= LAST_K, "event {k} of a claim is past its span");
    attempt.max(0) as u64 * SPAN + k.min(LAST_K)
}

/// The largest id a claim `attempt` gives an event that is not final: a `Last-Event-ID`
/// beyond it (and below the next claim's ids) was never sent while the claim runs.
pub fn last_event_id(attempt: i64) -> u64 {
    event_id(attempt, LAST_K)
}

/// Id of the final event of a job whose last claim was `attempt`.
pub fn final_id(attempt: i64) -> u64 {
    attempt.max(0) as u64 * SPAN + SPAN - 1
}

/// One server-sent event: its id, its `event:` name and its JSON data.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    pub id: u64,
    pub name: &'static str,
    pub data: String,
}

/// Every event name the hub sends.
pub const EVENT_NAMES: [&str; 5] = ["status", "progress", "done", "failed", "cancelled"];

impl Event {
    /// `done`, `failed` or `cancelled`: the stream ends after it.
    pub fn is_final(&self) -> bool {
        matches!(self.name, "done" | "failed" | "cancelled")
    }

    /// As it crosses to other nodes.
    pub fn to_wire(&self) -> WireEvent {
        WireEvent(self.id, self.name.to_string(), self.data.clone())
    }

    /// An event another node relayed; `None` for a name this hub does not send.
    pub fn from_wire(w: WireEvent) -> Option<Event> {
        let name = EVENT_NAMES.into_iter().find(|n| *n == w.1)?;
        Some(Event {
            id: w.0,
            name,
            data: w.2,
        })
    }
}

/// Events of a claim kept for clients that join mid-run: enough for a load curve on a screen.
/// Past it, the stride between kept events doubles, so the replay still spans the whole run
/// evenly, at a coarser resolution.
pub const REPLAY_CAP: usize = 1024;

struct Channel {
    tx: broadcast::Sender<Event>,
    recent: Mutex<Replay>,
}

/// The current claim's events so far: every `stride`-th, and the newest.
#[derive(Default)]
struct Replay {
    kept: Vec<Event>,
    stride: u64,
    newest: Option<Event>,
}

impl Replay {
    fn push(&mut self, event: Event) {
        let seq = |e: &Event| e.id % SPAN;
        // A newer claim's event (relayed from the node that runs it) starts a new replay, as a
        // local claim's publisher does.
        if self
            .newest
            .as_ref()
            .is_some_and(|n| event.id / SPAN > n.id / SPAN)
        {
            *self = Replay::default();
        }
        self.stride = self.stride.max(1);
        if self.kept.len() >= REPLAY_CAP {
            self.stride *= 2;
            let stride = self.stride;
            self.kept.retain(|e| seq(e).is_multiple_of(stride));
        }
        if seq(&event).is_multiple_of(self.stride) {
            self.kept.push(event.clone());
        }
        self.newest = Some(event);
    }

    /// Oldest first, ending with the newest event.
    fn events(&self) -> Vec<Event> {
        let mut out = self.kept.clone();
        if let Some(newest) = &self.newest {
            if out.last().is_none_or(|e| e.id < newest.id) {
                out.push(newest.clone());
            }
        }
        out
    }
}

/// All live channels, by job.
pub struct Hub {
    channels: Mutex<HashMap<Uuid, Arc<Channel>>>,
    capacity: usize,
    /// Where events of runs on this node go for the other nodes (PostgreSQL only).
    relay: OnceLock<mpsc::Sender<(Uuid, Event)>>,
}

impl Hub {
    pub fn new(capacity: usize) -> Arc<Hub> {
        Arc::new(Hub {
            channels: Mutex::new(HashMap::new()),
            capacity: capacity.max(1),
            relay: OnceLock::new(),
        })
    }

    /// From now on every event published or announced here is also sent to `relay`, which
    /// passes it to the other nodes. Set once; a full relay drops progress events (the other
    /// nodes' streams catch up from the store), never blocks the solver.
    pub fn relay_to(&self, relay: mpsc::Sender<(Uuid, Event)>) {
        let _ = self.relay.set(relay);
    }

    fn forward(&self, id: Uuid, event: &Event) {
        if let Some(relay) = self.relay.get() {
            let _ = relay.try_send((id, event.clone()));
        }
    }

    /// Events of a run on another node, oldest first: to this node's listeners, and into the
    /// replay for those that join later while someone listens.
    pub fn deliver(self: &Arc<Self>, id: Uuid, events: Vec<Event>) {
        let ch = self.channel(id);
        for event in events {
            ch.recent
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(event.clone());
            // An error only means nobody is listening.
            let _ = ch.tx.send(event);
        }
        drop(ch);
        self.release(id);
    }

    fn channel(&self, id: Uuid) -> Arc<Channel> {
        let mut map = self.channels.lock().unwrap_or_else(|e| e.into_inner());
        map.entry(id)
            .or_insert_with(|| {
                Arc::new(Channel {
                    tx: broadcast::channel(self.capacity).0,
                    recent: Mutex::new(Replay::default()),
                })
            })
            .clone()
    }

    /// Drops the job's channel once nobody holds it.
    fn release(&self, id: Uuid) {
        let mut map = self.channels.lock().unwrap_or_else(|e| e.into_inner());
        if map.get(&id).is_some_and(|ch| Arc::strong_count(ch) == 1) {
            map.remove(&id);
        }
    }

    /// Sends a job's final event to its listeners, whoever ran it (the run's own publisher may
    /// be gone, e.g. with a panicking solver).
    pub fn announce(self: &Arc<Self>, id: Uuid, event: Event) {
        self.forward(id, &event);
        self.deliver(id, vec![event]);
    }

    /// Listens to a job; the current claim's events so far come along.
    pub fn subscribe(self: &Arc<Self>, id: Uuid) -> Subscription {
        let ch = self.channel(id);
        let rx = ch.tx.subscribe();
        let recent = ch.recent.lock().unwrap_or_else(|e| e.into_inner()).events();
        Subscription {
            hub: self.clone(),
            id,
            ch: Some(ch),
            rx,
            recent,
        }
    }

    /// The sending end for claim `attempt` of a job. Its first event (the worker's `running`
    /// status) takes `k` = 0, the id of the `status` event a stream opens with while the job
    /// runs (`routes::events`): the two are one event, and a stream that opened with it skips
    /// the replayed copy, as it skips every id it has sent.
    pub fn publisher(self: &Arc<Self>, id: Uuid, attempt: i64) -> Publisher {
        let ch = self.channel(id);
        *ch.recent.lock().unwrap_or_else(|e| e.into_inner()) = Replay::default();
        Publisher {
            hub: self.clone(),
            id,
            ch: Some(ch),
            attempt,
            next: 0,
        }
    }

    /// Jobs with a live channel (for tests and metrics).
    pub fn len(&self) -> usize {
        self.channels
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A listener's end of a job's channel.
pub struct Subscription {
    hub: Arc<Hub>,
    id: Uuid,
    ch: Option<Arc<Channel>>,
    pub rx: broadcast::Receiver<Event>,
    /// The events of the current claim sent before it subscribed (evenly thinned past
    /// [`REPLAY_CAP`]), oldest first, ending with the newest.
    pub recent: Vec<Event>,
}

impl Subscription {
    /// The current claim's events so far (thinned as [`Subscription::recent`]): what a listener
    /// that fell behind the channel missed, at the replay's resolution.
    pub fn replay(&self) -> Vec<Event> {
        self.ch.as_ref().map_or_else(Vec::new, |ch| {
            ch.recent.lock().unwrap_or_else(|e| e.into_inner()).events()
        })
    }
}

impl Drop for Subscription {
    fn drop(&mut self) {
        self.ch.take();
        self.hub.release(self.id);
    }
}

/// A worker's end of a job's channel. Sending never blocks; with no listener it costs a lock.
pub struct Publisher {
    hub: Arc<Hub>,
    id: Uuid,
    ch: Option<Arc<Channel>>,
    attempt: i64,
    next: u64,
}

impl Publisher {
    /// Sends an event of the claim. Past [`LAST_K`] events (never, see there) the rest are
    /// dropped: ids must increase for listeners to tell new from seen.
    pub fn send(&mut self, name: &'static str, data: String) {
        let id = if matches!(name, "done" | "failed" | "cancelled") {
            final_id(self.attempt)
        } else if self.next <= LAST_K {
            self.next += 1;
            event_id(self.attempt, self.next - 1)
        } else {
            if self.next == LAST_K + 1 {
                self.next += 1;
                tracing::warn!(job = %self.id, "more events than a claim has ids: the rest are dropped");
            }
            return;
        };
        let event = Event { id, name, data };
        self.hub.forward(self.id, &event);
        if let Some(ch) = &self.ch {
            ch.recent
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(event.clone());
            // An error only means nobody is listening.
            let _ = ch.tx.send(event);
        }
    }
}

impl Drop for Publisher {
    fn drop(&mut self) {
        self.ch.take();
        self.hub.release(self.id);
    }
}

/// The solver's observer for one job: keeps the latest progress for the heartbeat (which
/// stores it about once a second) and publishes every report to the hub.
pub struct JobObserver {
    pub publisher: Publisher,
    pub latest: Arc<Mutex<Option<Progress>>>,
}

impl Observer for JobObserver {
    fn on_progress(&mut self, progress: &Progress) {
        *self.latest.lock().unwrap_or_else(|e| e.into_inner()) = Some(*progress);
        let data = serde_json::to_string(progress).unwrap_or_else(|_| "{}".into());
        self.publisher.send("progress", data);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_increase_across_claims_and_the_final_event_is_last() {
        let hub = Hub::new(16);
        let id = Uuid::new_v4();
        let mut sub = hub.subscribe(id);
        let mut p = hub.publisher(id, 1);
        p.send("status", "{}".into());
        p.send("progress", "{}".into());
        drop(p);
        let mut p = hub.publisher(id, 2);
        p.send("status", "{}".into());
        p.send("done", "{}".into());
        let ids: Vec<u64> = (0..4).map(|_| sub.rx.try_recv().unwrap().id).collect();
        assert!(ids.windows(2).all(|w| w[0] < w[1]), "{ids:?}");
        assert_eq!(ids[3], final_id(2));
        assert!(final_id(1) < event_id(2, 0));
    }

    #[test]
    fn a_late_listener_gets_the_whole_claim_so_far_thinned_but_ending_with_the_newest() {
        let hub = Hub::new(16);
        let id = Uuid::new_v4();
        let mut old = hub.publisher(id, 1);
        old.send("progress", "old claim".into());
        drop(old);
        let mut p = hub.publisher(id, 2);
        let total = 3 * REPLAY_CAP + 7;
        for k in 0..total {
            p.send("progress", k.to_string());
        }
        let sub = hub.subscribe(id);
        let got = &sub.recent;
        assert!(
            got.len() <= REPLAY_CAP + 1 && got.len() > REPLAY_CAP / 2,
            "{}",
            got.len()
        );
        // Evenly spaced: every gap but the last (to the newest) is the same.
        let gaps: Vec<u64> = got.windows(2).map(|w| w[1].id - w[0].id).collect();
        assert!(
            gaps[..gaps.len() - 1].windows(2).all(|g| g[0] == g[1]),
            "{gaps:?}"
        );
        assert!(got.windows(2).all(|w| w[0].id < w[1].id));
        assert_eq!(got.last().unwrap().data, (total - 1).to_string());
        let first: usize = got[0].data.parse().expect("nothing of the old claim");
        assert!(first < 8, "the replay starts at event {first}");
    }

    #[test]
    fn event_ids_never_repeat_even_past_the_span_of_a_claim() {
        let hub = Hub::new(16);
        let id = Uuid::new_v4();
        let mut p = hub.publisher(id, 1);
        // Start near the end of the span rather than sending a million events.
        p.next = LAST_K - 1;
        let mut sub = hub.subscribe(id);
        for _ in 0..5 {
            p.send("progress", "{}".into());
        }
        p.send("done", "{}".into());
        let mut ids = Vec::new();
        while let Ok(e) = sub.rx.try_recv() {
            ids.push(e.id);
        }
        assert_eq!(
            ids,
            vec![event_id(1, LAST_K - 1), last_event_id(1), final_id(1)],
            "the two events that fit, then nothing until the final one"
        );
    }

    #[test]
    fn a_final_event_announced_without_the_runs_publisher_reaches_listeners() {
        let hub = Hub::new(4);
        let id = Uuid::new_v4();
        let mut sub = hub.subscribe(id);
        let mut p = hub.publisher(id, 1);
        p.send("progress", "{}".into());
        drop(p);
        hub.announce(
            id,
            Event {
                id: final_id(1),
                name: "failed",
                data: "{}".into(),
            },
        );
        assert_eq!(sub.rx.try_recv().unwrap().name, "progress");
        assert_eq!(sub.rx.try_recv().unwrap().name, "failed");
        assert_eq!(sub.replay().last().unwrap().name, "failed");
        drop(sub);
        assert!(hub.is_empty());
    }

    #[test]
    fn events_go_to_the_relay_and_relayed_ones_reach_listeners_with_their_ids() {
        let (tx, mut relayed) = mpsc::channel(16);
        let node_b = Hub::new(16);
        node_b.relay_to(tx);
        let node_a = Hub::new(16);
        let id = Uuid::new_v4();
        let mut sub = node_a.subscribe(id);
        let mut p = node_b.publisher(id, 2);
        p.send("progress", "1".into());
        p.send("done", "{}".into());
        let mut wire = Vec::new();
        while let Ok((job, e)) = relayed.try_recv() {
            assert_eq!(job, id);
            wire.push(e.to_wire());
        }
        let events: Vec<Event> = wire.into_iter().filter_map(Event::from_wire).collect();
        node_a.deliver(id, events);
        let first = sub.rx.try_recv().unwrap();
        assert_eq!((first.id, first.name), (event_id(2, 0), "progress"));
        assert_eq!(sub.rx.try_recv().unwrap().id, final_id(2));
        assert_eq!(sub.replay().len(), 2);
        // A relayed event of a later claim starts a new replay.
        node_a.deliver(
            id,
            vec![Event {
                id: event_id(3, 1),
                name: "progress",
                data: "x".into(),
            }],
        );
        assert_eq!(sub.replay().len(), 1);
        assert!(Event::from_wire(WireEvent(1, "bogus".into(), String::new())).is_none());
    }

    #[test]
    fn channels_are_dropped_when_nobody_holds_them() {
        let hub = Hub::new(4);
        let id = Uuid::new_v4();
        let sub = hub.subscribe(id);
        let publisher = hub.publisher(id, 1);
        assert_eq!(hub.len(), 1);
        drop(sub);
        assert_eq!(hub.len(), 1);
        drop(publisher);
        assert!(hub.is_empty());
    }
}
