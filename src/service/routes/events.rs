//! `GET /v1/jobs/{id}/events`: server-sent events from the hub. A stream opens with the job's
//! current state and, for a running job, the events of its run so far (thinned past
//! `hub::REPLAY_CAP`), follows it live, and closes after the final `done`/`failed`/`cancelled`.
//! Ids only increase; a reconnecting client (`Last-Event-ID`) is sent only newer events. A
//! client that connects after the end gets the final event at once (or 204 if it has seen it).

use super::{parse_id, AppState};
use crate::service::error::ApiError;
use crate::service::hub::{event_id, Event, Subscription};
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

/// The state event a stream opens with.
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
    Missed,
    Shutdown,
}

impl Live {
    fn into_stream(self) -> impl Stream<Item = Result<sse::Event, Infallible>> + Send {
        stream::unfold(self, |mut s| async move {
            loop {
                if let Some(event) = s.pending.pop_front() {
                    if s.last_sent.is_some_and(|l| event.id <= l) {
                        continue;
                    }
                    s.last_sent = Some(event.id);
                    s.finished = event.is_final();
                    return Some((Ok(to_sse(&event)), s));
                }
                if s.finished {
                    return None;
                }
                let wake = tokio::select! {
                    r = s.sub.rx.recv() => match r {
                        Ok(event) => Wake::Event(event),
                        Err(RecvError::Lagged(_)) | Err(RecvError::Closed) => Wake::Missed,
                    },
                    _ = s.poll.tick() => Wake::Missed,
                    _ = s.shutdown.wait_for(|down| *down) => Wake::Shutdown,
                };
                match wake {
                    Wake::Event(event) => s.pending.push_back(event),
                    Wake::Shutdown => return None,
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
