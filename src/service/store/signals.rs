//! Signals between nodes that share a PostgreSQL store, over `LISTEN`/`NOTIFY` on one channel
//! ([`CHANNEL`]): the events of a run (so that a client of any node follows a job running on
//! another), a cancel (so that the node running the job stops it at its next step), and "a job
//! was queued" (so that an idle node claims it now rather than at its next poll).
//!
//! A notification is a JSON object `{"from": node, "signal": …}` of at most [`MAX_PAYLOAD`]
//! bytes (PostgreSQL's limit is 8 000); a node ignores its own. Notifications are not stored:
//! one sent while a node's listening connection is down is lost to that node, which then
//! catches up from the store (the event stream's poll, the worker's poll, the heartbeat's
//! cancel flag). SQLite has one node and needs none of this.

use super::database::{Result, Store};
use serde::{Deserialize, Serialize};
use std::time::Duration;
use tokio::sync::mpsc;
use uuid::Uuid;

/// The notification channel.
pub const CHANNEL: &str = "crush";

/// Largest payload sent: PostgreSQL refuses more than 8 000 bytes.
pub const MAX_PAYLOAD: usize = 7_000;

/// One server-sent event as it crosses between nodes: id, event name, JSON data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WireEvent(pub u64, pub String, pub String);

/// What one node tells the others.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    /// Events of a job's run, oldest first.
    Events { job: Uuid, events: Vec<WireEvent> },
    /// A client asked to cancel the job: the node running it stops it.
    Cancel { job: Uuid },
    /// Jobs were queued: idle workers claim now.
    Queued,
}

#[derive(Serialize, Deserialize)]
struct Envelope {
    from: String,
    signal: Signal,
}

/// Packs `events` of `job` into as few signals as fit [`MAX_PAYLOAD`] each. An event too large
/// for a payload of its own is left out (a progress report is about 300 bytes).
pub fn pack(from: &str, job: Uuid, events: Vec<WireEvent>) -> Vec<String> {
    let encode = |events: Vec<WireEvent>| {
        serde_json::to_string(&Envelope {
            from: from.to_string(),
            signal: Signal::Events { job, events },
        })
        .unwrap_or_default()
    };
    let overhead = encode(Vec::new()).len();
    let mut out = Vec::new();
    let mut batch = Vec::new();
    let mut size = overhead;
    for e in events {
        let len = serde_json::to_string(&e).map_or(usize::MAX, |s| s.len() + 1);
        if overhead + len > MAX_PAYLOAD {
            tracing::warn!(%job, id = e.0, "an event too large to relay to other nodes was dropped");
            continue;
        }
        if size + len > MAX_PAYLOAD {
            out.push(encode(std::mem::take(&mut batch)));
            size = overhead;
        }
        size += len;
        batch.push(e);
    }
    if !batch.is_empty() {
        out.push(encode(batch));
    }
    out
}

/// A signal other than events, ready to send.
pub fn encode(from: &str, signal: Signal) -> String {
    serde_json::to_string(&Envelope {
        from: from.to_string(),
        signal,
    })
    .unwrap_or_default()
}

/// Reads a notification; `None` for one this node sent, or one it cannot read.
pub fn decode(me: &str, payload: &str) -> Option<Signal> {
    let envelope: Envelope = serde_json::from_str(payload).ok()?;
    (envelope.from != me).then_some(envelope.signal)
}

impl Store {
    /// Sends a payload made by [`pack`] or [`encode`] to every listening node. Nothing on
    /// SQLite.
    pub async fn notify(&self, payload: &str) -> Result<()> {
        if self.postgres_url().is_none() {
            return Ok(());
        }
        sqlx::query("SELECT pg_notify($1, $2)")
            .bind(CHANNEL)
            .bind(payload)
            .execute(&self.pool)
            .await?;
        Ok(())
    }

    /// Listens for other nodes' signals on a connection of its own, reconnecting by itself
    /// when it is lost (what was sent meanwhile is missed, see the module's doc). `None` on
    /// SQLite. The task ends when the receiver is dropped.
    pub fn listen(&self, me: String) -> Option<mpsc::Receiver<Signal>> {
        let url = self.postgres_url()?.to_string();
        let (tx, rx) = mpsc::channel(4096);
        tokio::spawn(async move {
            let mut failures = 0u32;
            while !tx.is_closed() {
                match listen_until_lost(&url, &me, &tx).await {
                    Ok(()) => return,
                    Err(e) => {
                        failures += 1;
                        if failures % 10 == 1 {
                            tracing::warn!(error = %e, failures, "listening for other nodes failed; retrying");
                        }
                        tokio::time::sleep(Duration::from_millis(250 * failures.min(8) as u64))
                            .await;
                    }
                }
            }
        });
        Some(rx)
    }
}

/// Forwards notifications until the connection fails (`Err`) or the receiver is gone (`Ok`).
async fn listen_until_lost(
    url: &str,
    me: &str,
    tx: &mpsc::Sender<Signal>,
) -> std::result::Result<(), sqlx::Error> {
    let mut listener = sqlx::postgres::PgListener::connect(url).await?;
    listener.listen(CHANNEL).await?;
    loop {
        let received = tokio::select! {
            r = listener.try_recv() => r?,
            // The node stopped: close the connection rather than wait for a notification.
            _ = tx.closed() => return Ok(()),
        };
        // `None`: the connection was lost and has been made again (and listens again).
        let Some(n) = received else {
            tracing::warn!("the connection listening for other nodes was lost and made again");
            continue;
        };
        if let Some(signal) = decode(me, n.payload()) {
            // Full: this node is far behind; a lost progress event is caught up by the poll.
            match tx.try_send(signal) {
                Ok(()) | Err(mpsc::error::TrySendError::Full(_)) => {}
                Err(mpsc::error::TrySendError::Closed(_)) => return Ok(()),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_are_packed_into_payloads_postgres_accepts_and_read_back_in_order() {
        let job = Uuid::new_v4();
        let events: Vec<WireEvent> = (0..200)
            .map(|k| {
                WireEvent(
                    k,
                    "progress".into(),
                    format!("{{\"step\":{k},\"pad\":\"{}\"}}", "x".repeat(100)),
                )
            })
            .collect();
        let payloads = pack("a", job, events.clone());
        assert!(payloads.len() > 1);
        assert!(payloads.iter().all(|p| p.len() <= MAX_PAYLOAD));
        let mut back = Vec::new();
        for p in &payloads {
            assert_eq!(decode("a", p), None, "a node ignores its own signals");
            match decode("b", p) {
                Some(Signal::Events { job: j, events }) => {
                    assert_eq!(j, job);
                    back.extend(events);
                }
                other => panic!("{other:?}"),
            }
        }
        assert_eq!(back, events);
        let huge = vec![WireEvent(1, "progress".into(), "y".repeat(MAX_PAYLOAD))];
        assert!(
            pack("a", job, huge).is_empty(),
            "too large: dropped, not sent"
        );
        let cancel = encode("a", Signal::Cancel { job });
        assert_eq!(decode("c", &cancel), Some(Signal::Cancel { job }));
    }
}
