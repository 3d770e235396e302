//! Heavy downloads (a VTU file, a particle table, a frame, a series archive, a long history, the
//! tube's picture): at most [`HEAVY_AT_ONCE`] are built at a time, each holding a [`Slot`], and
//! no client keeps one that it does not use. Rates are in bytes a second, counted as a body
//! hands its bytes to the connection.
//!
//! - **minimum rate**: a download taken slower than `--min-download-bytes-per-s` on average,
//!   checked each second from [`DOWNLOAD_GRACE`] on, closes its connection ([`metered`]).
//! - **fair share**: while a download waits for a slot, it watches the holders; one whose
//!   client took it slower than `--fair-download-bytes-per-s` over a [`FAIR_WINDOW`] of that
//!   wait is closed, and its slot goes to the first in line. Each waiting download closes one
//!   holder at a time, the slowest, so a slow reader with no one waiting keeps its slot. The
//!   time the connection waited for the server to write the next bytes (a frame read from the
//!   store, an archive's entry sized) is the server's, not the client's, and is left out.

use super::connection::Connection;
use axum::body::Body;
use futures::{Stream, StreamExt};
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tokio::time::Instant;

/// Downloads built at a time; the rest wait their turn. Two: a build from a final state holds
/// about 56 B a particle, and with four the allocator kept 147 MB after 20 downloads of a
/// 266 k-particle state (`tests/api/download.rs`), against 92 MB with two. A long history
/// holds its slot while it is sent, so that its text (about 230 B a row, 23 MB for the
/// 100 000 rows a case may ask for) counts among these too.
pub const HEAVY_AT_ONCE: usize = 2;

/// Longest a download waits for its turn. A slot is freed within `--write-timeout-s` of its
/// client no longer reading, once its client takes it slower than `--min-download-bytes-per-s`,
/// or, while this one waits, within a few [`FAIR_WINDOW`]s of its client taking it slower than
/// `--fair-download-bytes-per-s`.
pub const HEAVY_WAIT: Duration = Duration::from_secs(30);

/// How long a heavy download may take before its average rate is checked.
pub const DOWNLOAD_GRACE: Duration = Duration::from_secs(10);

/// The span of its client's time a holder's rate is measured over while another download
/// waits. Three seconds: a download that has just begun fills the socket buffers (a few MB at
/// once) in its first window and is judged on what its client reads in the next.
pub const FAIR_WINDOW: Duration = Duration::from_secs(3);

/// The heavy-download slots: [`HEAVY_AT_ONCE`] of them, and who holds them.
pub struct Slots {
    semaphore: Arc<Semaphore>,
    holders: Mutex<Vec<Weak<Holder>>>,
    /// Bytes a second; 0: a holder is never closed for another.
    fair_rate: u64,
}

/// One download's turn: the slot is free again when this is dropped.
pub struct Slot {
    _permit: OwnedSemaphorePermit,
    holder: Arc<Holder>,
}

/// What the slots know of a download that holds one.
struct Holder {
    /// Bytes its body has handed to the connection.
    sent: AtomicU64,
    /// When it was made: the origin of the times below.
    born: Instant,
    /// Nanoseconds the connection has waited for the body's next bytes, in waits now over.
    building_ns: AtomicU64,
    /// Since when (ns from `born`) the connection waits for the body's next bytes;
    /// [`NOT_WAITING`] when it does not.
    waiting_since_ns: AtomicU64,
    /// Its connection, once its body is being sent ([`metered`]); a download still being
    /// built is never closed for another.
    connection: OnceLock<Connection>,
    /// Closed to free its slot for a waiting download.
    closed: AtomicBool,
    /// Its slot is free.
    released: AtomicBool,
}

const NOT_WAITING: u64 = u64::MAX;

impl Holder {
    fn new() -> Holder {
        Holder {
            sent: AtomicU64::new(0),
            born: Instant::now(),
            building_ns: AtomicU64::new(0),
            waiting_since_ns: AtomicU64::new(NOT_WAITING),
            connection: OnceLock::new(),
            closed: AtomicBool::new(false),
            released: AtomicBool::new(false),
        }
    }

    fn ns(&self, at: Instant) -> u64 {
        u64::try_from((at - self.born).as_nanos()).unwrap_or(u64::MAX - 1)
    }

    /// How long, up to `now`, the connection has waited for the body's next bytes.
    fn building(&self, now: Instant) -> Duration {
        let since = self.waiting_since_ns.load(Ordering::Relaxed);
        let open = match since {
            NOT_WAITING => 0,
            since => self.ns(now).saturating_sub(since),
        };
        Duration::from_nanos(self.building_ns.load(Ordering::Relaxed) + open)
    }
}

/// Counts what a slot's body sends, for the downloads waiting for a slot ([`Slot::meter`]).
pub struct Meter(Arc<Holder>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.holder.released.store(true, Ordering::Relaxed);
    }
}

impl Slot {
    /// The handle [`metered`] counts this slot's body with.
    pub fn meter(&self) -> Meter {
        Meter(self.holder.clone())
    }
}

impl Slots {
    pub fn new(fair_rate: u64) -> Slots {
        Slots {
            semaphore: Arc::new(Semaphore::new(HEAVY_AT_ONCE)),
            holders: Mutex::new(Vec::new()),
            fair_rate,
        }
    }

    /// A slot, in turn (first come, first served); `None` after [`HEAVY_WAIT`] without one.
    /// While it waits, it closes one holder at a time taken slower than the fair rate.
    pub async fn acquire(&self) -> Option<Slot> {
        let acquire = self.semaphore.clone().acquire_owned();
        let deadline = tokio::time::sleep(HEAVY_WAIT);
        tokio::pin!(acquire, deadline);
        let mut tick = tokio::time::interval(Duration::from_secs(1));
        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        let mut watch = Watch::default();
        loop {
            tokio::select! {
                permit = &mut acquire => {
                    // The semaphore is never closed.
                    let permit = permit.ok()?;
                    let holder = Arc::new(Holder::new());
                    let mut holders = self.holders.lock().unwrap_or_else(|e| e.into_inner());
                    holders.retain(|h| h.upgrade().is_some_and(|h| !h.released.load(Ordering::Relaxed)));
                    holders.push(Arc::downgrade(&holder));
                    return Some(Slot { _permit: permit, holder });
                }
                _ = &mut deadline => return None,
                _ = tick.tick(), if self.fair_rate > 0 => self.referee(&mut watch),
            }
        }
    }

    /// One look at the holders by a waiting download: each sending holder's rate over its
    /// current window; when a window is full, a holder slower than the fair rate is a
    /// candidate, and the slowest is closed, unless this waiter's last one is still freeing
    /// its slot.
    fn referee(&self, watch: &mut Watch) {
        if watch
            .victim
            .upgrade()
            .is_some_and(|h| !h.released.load(Ordering::Relaxed))
        {
            return;
        }
        let now = Instant::now();
        let holders: Vec<Arc<Holder>> = {
            let list = self.holders.lock().unwrap_or_else(|e| e.into_inner());
            list.iter().filter_map(Weak::upgrade).collect()
        };
        watch.windows.retain(|w| {
            holders
                .iter()
                .any(|k| std::ptr::eq(w.holder.as_ptr(), Arc::as_ptr(k)))
        });
        let mut slowest: Option<(Arc<Holder>, f64, u64)> = None;
        for holder in holders {
            if holder.connection.get().is_none()
                || holder.released.load(Ordering::Relaxed)
                || holder.closed.load(Ordering::Relaxed)
            {
                continue;
            }
            let (sent, building) = (holder.sent.load(Ordering::Relaxed), holder.building(now));
            let this = Arc::as_ptr(&holder);
            let Some(window) = watch.windows.iter_mut().find(|w| w.holder.as_ptr() == this) else {
                watch.windows.push(Window {
                    holder: Arc::downgrade(&holder),
                    since: now,
                    sent,
                    building,
                });
                continue;
            };
            let client =
                (now - window.since).saturating_sub(building.saturating_sub(window.building));
            if client < FAIR_WINDOW {
                continue;
            }
            let taken = sent.saturating_sub(window.sent);
            let rate = taken as f64 / client.as_secs_f64();
            (window.since, window.sent, window.building) = (now, sent, building);
            if rate < self.fair_rate as f64 && slowest.as_ref().is_none_or(|(_, r, _)| rate < *r) {
                slowest = Some((holder, rate, taken));
            }
        }
        let Some((holder, rate, taken)) = slowest else {
            return;
        };
        if holder.closed.swap(true, Ordering::Relaxed) {
            return;
        }
        if let Some(connection) = holder.connection.get() {
            tracing::warn!(
                peer = %connection.peer,
                bytes = taken,
                bytes_per_s = rate.round(),
                "closing a download taken slower than --fair-download-bytes-per-s while another \
                 waits for its slot"
            );
            connection.close();
        }
        watch.victim = Arc::downgrade(&holder);
    }
}

/// What one waiting download has seen of the holders.
#[derive(Default)]
struct Watch {
    /// Each sending holder's current window.
    windows: Vec<Window>,
    /// The holder it closed last.
    victim: Weak<Holder>,
}

/// A holder's window: since when, and its bytes sent and time building then.
struct Window {
    holder: Weak<Holder>,
    since: Instant,
    sent: u64,
    building: Duration,
}

/// A download's body, counted into `meter` (its slot's, for a heavy one), whose connection is
/// closed once the client has taken it slower than `min_rate` bytes a second on average since
/// it began, checked each second from [`DOWNLOAD_GRACE`] on. Closing the connection drops the
/// body, and with it the slot it holds. Without a connection (a router served some other way),
/// `body` as it is.
pub fn metered(
    body: Body,
    connection: Option<&Connection>,
    min_rate: u64,
    meter: Option<Meter>,
) -> Body {
    let Some(connection) = connection.cloned() else {
        return body;
    };
    if min_rate == 0 && meter.is_none() {
        return body;
    }
    // A heavy body counts into its slot's holder (which the waiting downloads watch); a light
    // one into a holder of its own.
    let counted = match meter {
        Some(Meter(holder)) => {
            let _ = holder.connection.set(connection.clone());
            holder
        }
        None => Arc::new(Holder::new()),
    };
    let alive = Arc::new(());
    let stream = Counted {
        inner: body.into_data_stream(),
        holder: counted.clone(),
        _alive: alive.clone(),
    };
    if min_rate > 0 {
        let watched = Arc::downgrade(&alive);
        tokio::spawn(async move {
            let start = Instant::now();
            let mut tick = tokio::time::interval_at(start + DOWNLOAD_GRACE, Duration::from_secs(1));
            loop {
                tick.tick().await;
                if watched.strong_count() == 0 {
                    return;
                }
                let elapsed = start.elapsed().as_secs_f64();
                let taken = counted.sent.load(Ordering::Relaxed);
                if (taken as f64) < min_rate as f64 * elapsed {
                    tracing::warn!(
                        peer = %connection.peer,
                        bytes = taken,
                        seconds = elapsed,
                        "closing a download taken slower than --min-download-bytes-per-s"
                    );
                    connection.close();
                    return;
                }
            }
        });
    }
    drop(alive);
    Body::from_stream(stream)
}

/// A body's data, counted into its holder as the connection takes it.
struct Counted<S> {
    inner: S,
    holder: Arc<Holder>,
    _alive: Arc<()>,
}

impl<S: Stream<Item = Result<axum::body::Bytes, axum::Error>> + Unpin> Stream for Counted<S> {
    type Item = S::Item;

    fn poll_next(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Self::Item>> {
        let polled = self.inner.poll_next_unpin(cx);
        let holder = &self.holder;
        let now = holder.ns(Instant::now());
        if polled.is_pending() {
            let _ = holder.waiting_since_ns.compare_exchange(
                NOT_WAITING,
                now,
                Ordering::Relaxed,
                Ordering::Relaxed,
            );
        } else {
            let since = holder.waiting_since_ns.swap(NOT_WAITING, Ordering::Relaxed);
            if since != NOT_WAITING {
                holder
                    .building_ns
                    .fetch_add(now.saturating_sub(since), Ordering::Relaxed);
            }
        }
        if let Poll::Ready(Some(Ok(bytes))) = &polled {
            holder.sent.fetch_add(bytes.len() as u64, Ordering::Relaxed);
        }
        polled
    }
}
