//! `GET /v1/jobs/{id}/events`: server-sent events from the hub. A stream opens with the job's
//! current state and, for a running job, the events of its run so far (thinned past
//! `hub::REPLAY_CAP`), follows it live, and closes after the final `done`/`failed`/`cancelled`.
//! Ids only increase; a reconnecting client (`Last-Event-ID`) is sent only newer events. An id
//! the job's current claim cannot have sent yet (past its span: `5000000`, `2^64 − 1`) is read
//! as "from now on". A client that connects after the end gets the final event at once (or 204
//! if it has seen it). Every stream ends after the job's final event, whatever the client saw.

use super::inputs::parse_id;
use super::state::AppState;
use crate::service::error::ApiError;
use crate::service::hub::{event_id, last_event_id, Event, Subscription};
use crate::service::store::{Status, Store};
use crate::service::views::final_event;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, StatusCode};
use axum::response::sse::{self, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use futures::stream::{self, Stream};
use std::collections::VecDeque;
use std::convert::Infallible;
use tokio::sync::broadcast::error::RecvError;
use tokio::sync::{watch, OwnedSemaphorePermit};
use uuid::Uuid;

pub async fn events(
    State(s): State<AppState>,
    Path(id): Path<String>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let uuid = parse_id(&id, "job")?;
    let last_seen = headers
        .get("last-event-id")
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().parse::<u64>().ok());
    // Listen before reading the state, so that nothing falls between the two.
    let sub = s.hub.subscribe(uuid);
    let record = s
        .store
        .job(uuid)
        .await?
        .ok_or_else(|| ApiError::job_not_found(&id))?;
    let mut pending = VecDeque::new();
    if let Some(event) = final_event(&record) {
        if last_seen.is_some_and(|l| l >= event.id) {
            return Ok(StatusCode::NO_CONTENT.into_response());
        }
        pending.push_back(event);
    } else {
        let permit =
            s.sse_permits
                .clone()
                .try_acquire_owned()
                .map_err(|_| ApiError::Unavailable {
                    detail: "too many open event streams; try again later".into(),
                    retry_after_s: 5,
                })?;
        pending.push_back(snapshot(record.status, record.attempts));
        if record.status == Status::Running {
            pending.extend(sub.recent.iter().cloned());
        }
        // An id the current claim cannot have sent (the client's own, or one from another
        // server's database) would hide every event up to it, the final one included: read it
        // as "everything so far was seen".
        let last_seen = last_seen.map(|l| {
            if l > last_event_id(record.attempts) {
                pending.back().map_or(0, |e| e.id)
            } else {
                l
            }
        });
        let live = Live {
            id: uuid,
            store: s.store.clone(),
            sub,
            pending,
            last_sent: last_seen,
            finished: false,
            shutdown: s.shutdown.clone(),
            poll: tokio::time::interval(s.limits.sse_poll),
            _permit: permit,
        };
        let keep_alive = KeepAlive::new()
            .interval(s.limits.keep_alive)
            .text("keep-alive");
        return Ok(Sse::new(live.into_stream())
            .keep_alive(keep_alive)
            .into_response());
    }
    let stream = stream::iter(pending.into_iter().map(|e| Ok::<_, Infallible>(to_sse(&e))));
    Ok(Sse::new(stream).into_response())
}

/// The state event a stream opens with. For a running job it is the event the worker sent
/// when the claim started (same id, same data), which the replay then holds too: the stream
/// sends it once.
fn snapshot(status: Status, attempts: i64) -> Event {
    let data = serde_json::json!({ "status": status, "attempt": attempts }).to_string();
    Event {
        id: event_id(attempts, 0),
        name: "status",
        data,
    }
}

fn to_sse(e: &Event) -> sse::Event {
    sse::Event::default()
        .id(e.id.to_string())
        .event(e.name)
        .data(&e.data)
}

/// A stream following a job that has not finished.
struct Live {
    id: Uuid,
    store: Store,
    sub: Subscription,
    pending: VecDeque<Event>,
    last_sent: Option<u64>,
    finished: bool,
    shutdown: watch::Receiver<bool>,
    poll: tokio::time::Interval,
    _permit: OwnedSemaphorePermit,
}

enum Wake {
    Event(Event),
    Lagged,
    Missed,
    Shutdown,
}

impl Live {
    fn into_stream(self) -> impl Stream<Item = Result<sse::Event, Infallible>> + Send {
        stream::unfold(self, |mut s| async move {
            loop {
                if let Some(event) = s.pending.pop_front() {
                    // The final event ends the stream even when the client says it saw it.
                    s.finished |= event.is_final();
                    if s.last_sent.is_some_and(|l| event.id <= l) {
                        continue;
                    }
                    s.last_sent = Some(event.id);
                    return Some((Ok(to_sse(&event)), s));
                }
                if s.finished {
                    return None;
                }
                let wake = tokio::select! {
                    r = s.sub.rx.recv() => match r {
                        Ok(event) => Wake::Event(event),
                        Err(RecvError::Lagged(_)) => Wake::Lagged,
                        Err(RecvError::Closed) => Wake::Missed,
                    },
                    _ = s.poll.tick() => Wake::Missed,
                    _ = s.shutdown.wait_for(|down| *down) => Wake::Shutdown,
                };
                match wake {
                    Wake::Event(event) => s.pending.push_back(event),
                    Wake::Shutdown => return None,
                    // Fell behind the channel: what it dropped is in the claim's replay (older
                    // ids than those already sent are skipped above), then the store, in case
                    // the job ended meanwhile.
                    Wake::Lagged => {
                        s.pending.extend(s.sub.replay());
                        if let Ok(Some(record)) = s.store.job(s.id).await {
                            s.pending.extend(final_event(&record));
                        }
                    }
                    // Re-read the store: the job may have ended where the hub cannot see.
                    Wake::Missed => {
                        if let Ok(Some(record)) = s.store.job(s.id).await {
                            s.pending.extend(final_event(&record));
                        }
                    }
                }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::hub::{final_id, Hub};
    use crate::service::store::NewJob;
    use futures::StreamExt;
    use std::sync::Arc;
    use std::time::Duration;

    #[tokio::test]
    async fn a_listener_that_falls_behind_the_channel_still_gets_every_progress_event_it_missed() {
        let (_dir, store) = crate::service::store::temp_store().await;
        let id = Uuid::new_v4();
        let job = NewJob {
            id,
            case_json: "{}".into(),
            label: None,
            particles: 1,
            idempotency_key: None,
        };
        store.submit(job, 10).await.unwrap();
        store.claim("test").await.unwrap().unwrap();
        // A channel of 4 and 50 events sent before the listener reads any: it lags.
        let hub = Hub::new(4);
        let mut publisher = hub.publisher(id, 1);
        let sub = hub.subscribe(id);
        for k in 0..50 {
            publisher.send("progress", k.to_string());
        }
        publisher.send("done", "{}".into());
        let (_down, shutdown) = watch::channel(false);
        let live = Live {
            id,
            store,
            sub,
            pending: VecDeque::new(),
            last_sent: None,
            finished: false,
            shutdown,
            poll: tokio::time::interval(Duration::from_secs(3600)),
            _permit: Arc::new(tokio::sync::Semaphore::new(1))
                .try_acquire_owned()
                .unwrap(),
        };
        let events: Vec<_> = tokio::time::timeout(
            Duration::from_secs(10),
            live.into_stream().collect::<Vec<_>>(),
        )
        .await
        .expect("the stream ends after the final event");
        let text: Vec<String> = events
            .into_iter()
            .map(|e| format!("{:?}", e.unwrap()))
            .collect();
        let progress = text.iter().filter(|t| t.contains("progress")).count();
        assert_eq!(progress, 50, "every progress event, not only the last few");
        assert!(text.last().unwrap().contains("done"));
        assert!(text.last().unwrap().contains(&final_id(1).to_string()));
    }
}
