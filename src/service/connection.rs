//! Serving connections so that no client holds one, or a download slot, that it does not use.
//! HTTP/1.1 over hyper's connection builder (axum's `serve` exposes none of these settings):
//!
//! - **header read**: a request head must arrive within `--header-read-timeout-s` of the moment
//!   the connection waits for one. Hyper starts that clock on a new connection and again after
//!   each answer, so it also closes a connection that sends nothing, or a keep-alive connection
//!   left idle, after that long.
//! - **request body**: the whole body within `--body-timeout-s` of its head ([`body_deadline`]),
//!   or 408.
//! - **write stall**: a write that makes no progress for `--write-timeout-s` (a client that does
//!   not read) closes the connection. Nothing ever times out a read of an open request, so event
//!   streams, which only write, live as long as their clients read them.
//! - **download rate**: a download taken slower than `--min-download-bytes-per-s` on average,
//!   or, while another waits for its slot, slower than `--fair-download-bytes-per-s`, is closed
//!   through its [`Connection`] (`super::downloads`).
//!
//! Each connection's writes go through [`ProblemIo`] (hyper's bare error heads become
//! problem+json). On shutdown, idle connections close at once and busy ones finish their answer.

use super::bare_errors::ProblemIo;
use axum::body::{Body, Bytes, HttpBody};
use axum::extract::{ConnectInfo, Request, State};
use axum::middleware::Next;
use axum::response::Response;
use axum::Router;
use hyper_util::rt::{TokioIo, TokioTimer};
use std::future::Future;
use std::net::SocketAddr;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::net::TcpListener;
use tokio::sync::{watch, Notify};
use tokio_io_timeout::TimeoutStream;
use tower::ServiceExt;

/// Flags of `crush serve` on connection time limits.
#[derive(Debug, Clone, clap::Args)]
pub struct TimeoutArgs {
    /// A request head must arrive within this of the connection waiting for one (so a new
    /// connection that sends nothing, or an idle keep-alive one, closes after this), s.
    #[arg(long, env = "CRUSH_HEADER_READ_TIMEOUT_S", default_value_t = 30.0)]
    pub header_read_timeout_s: f64,
    /// A request body must arrive whole within this of its head, s (else 408).
    #[arg(long, env = "CRUSH_BODY_TIMEOUT_S", default_value_t = 30.0)]
    pub body_timeout_s: f64,
    /// A write to a client that makes no progress for this long closes the connection, s.
    #[arg(long, env = "CRUSH_WRITE_TIMEOUT_S", default_value_t = 30.0)]
    pub write_timeout_s: f64,
    /// A history or VTU download must average at least this many bytes a second, checked
    /// from its first 10 s on, or its connection is closed; 0: no minimum.
    #[arg(long, env = "CRUSH_MIN_DOWNLOAD_BYTES_PER_S", default_value_t = 65536)]
    pub min_download_bytes_per_s: u64,
    /// While a download waits for a slot, a download holding one that its client took slower
    /// than this over the last 3 s is closed, and its slot goes to the waiting one; 0: never.
    #[arg(long, env = "CRUSH_FAIR_DOWNLOAD_BYTES_PER_S", default_value_t = 1 << 20)]
    pub fair_download_bytes_per_s: u64,
}

/// The time limits of connections, checked.
#[derive(Debug, Clone, Copy)]
pub struct Timeouts {
    pub header_read: Duration,
    pub body: Duration,
    pub write: Duration,
    /// Bytes a second; 0: none.
    pub min_download_rate: u64,
    /// Bytes a second a slot's holder must keep while another download waits; 0: none.
    pub fair_download_rate: u64,
}

impl TimeoutArgs {
    pub fn timeouts(&self) -> anyhow::Result<Timeouts> {
        let seconds = |name: &str, v: f64| {
            anyhow::ensure!(
                v.is_finite() && v > 0.0 && v <= 86_400.0,
                "{name} must be a number of seconds in (0, 86400]"
            );
            Ok(Duration::from_secs_f64(v))
        };
        Ok(Timeouts {
            header_read: seconds("--header-read-timeout-s", self.header_read_timeout_s)?,
            body: seconds("--body-timeout-s", self.body_timeout_s)?,
            write: seconds("--write-timeout-s", self.write_timeout_s)?,
            min_download_rate: self.min_download_bytes_per_s,
            fair_download_rate: self.fair_download_bytes_per_s,
        })
    }
}

/// The connection a request came on (in its extensions): [`Connection::close`] closes it.
#[derive(Debug, Clone)]
pub struct Connection {
    close: Arc<Notify>,
    pub peer: SocketAddr,
}

impl Connection {
    /// Closes the connection now, whatever it is doing.
    pub fn close(&self) {
        self.close.notify_one();
    }
}

/// Accepts connections and serves `router` on each until `shutdown` becomes true; then lets
/// the open ones finish and returns.
pub async fn serve(
    mut listener: TcpListener,
    router: Router,
    timeouts: Timeouts,
    mut shutdown: watch::Receiver<bool>,
) {
    // Every connection task holds a receiver; all are gone when the last connection ends.
    let (done_tx, done_rx) = watch::channel(());
    loop {
        let (tcp, peer) = tokio::select! {
            accepted = axum::serve::Listener::accept(&mut listener) => accepted,
            _ = shutdown.wait_for(|down| *down) => break,
        };
        let task = connection(tcp, peer, router.clone(), timeouts, shutdown.clone());
        let done = done_rx.clone();
        tokio::spawn(async move {
            task.await;
            drop(done);
        });
    }
    drop(listener);
    drop(done_rx);
    done_tx.closed().await;
}

/// Serves one connection until it ends, is closed through its [`Connection`], or the server
/// shuts down (then the request in flight finishes first).
async fn connection(
    tcp: tokio::net::TcpStream,
    peer: SocketAddr,
    router: Router,
    timeouts: Timeouts,
    mut shutdown: watch::Receiver<bool>,
) {
    let mut stream = TimeoutStream::new(tcp);
    stream.set_write_timeout(Some(timeouts.write));
    let io = TokioIo::new(ProblemIo::new(Box::pin(stream)));
    let close = Arc::new(Notify::new());
    let handle = Connection {
        close: close.clone(),
        peer,
    };
    let service = hyper::service::service_fn(move |request: hyper::Request<_>| {
        let mut request = request.map(Body::new);
        request.extensions_mut().insert(ConnectInfo(peer));
        request.extensions_mut().insert(handle.clone());
        router.clone().oneshot(request)
    });
    let mut builder = hyper::server::conn::http1::Builder::new();
    builder
        .timer(TokioTimer::new())
        .header_read_timeout(timeouts.header_read);
    let conn = builder.serve_connection(io, service);
    tokio::pin!(conn);
    let mut draining = false;
    loop {
        tokio::select! {
            result = conn.as_mut() => {
                if let Err(e) = result {
                    tracing::debug!(%peer, error = %e, "connection ended with an error");
                }
                return;
            }
            _ = close.notified() => return,
            _ = shutdown.wait_for(|down| *down), if !draining => {
                conn.as_mut().graceful_shutdown();
                draining = true;
            }
        }
    }
}

/// The error a request body gives when it has not arrived whole by its deadline.
#[derive(Debug, thiserror::Error)]
#[error("the request body did not arrive within {seconds} s")]
pub struct BodyTimedOut {
    pub seconds: f64,
}

impl BodyTimedOut {
    /// The deadline error somewhere in the sources of `error` (a body extractor's rejection).
    pub fn within<'a>(error: &'a (dyn std::error::Error + 'static)) -> Option<&'a BodyTimedOut> {
        let mut next = Some(error);
        while let Some(e) = next {
            if let Some(found) = e.downcast_ref::<BodyTimedOut>() {
                return Some(found);
            }
            next = e.source();
        }
        None
    }
}

/// Gives every request body a deadline: [`Timeouts::body`] after its head.
pub async fn body_deadline(
    State(limit): State<Duration>,
    request: Request,
    next: Next,
) -> Response {
    let (parts, body) = request.into_parts();
    let body = Body::new(Deadline {
        inner: body,
        sleep: Box::pin(tokio::time::sleep(limit)),
        seconds: limit.as_secs_f64(),
    });
    next.run(Request::from_parts(parts, body)).await
}

/// A request body that fails with [`BodyTimedOut`] once its sleep is over while it waits for
/// the client.
struct Deadline {
    inner: Body,
    sleep: Pin<Box<tokio::time::Sleep>>,
    seconds: f64,
}

impl HttpBody for Deadline {
    type Data = Bytes;
    type Error = axum::BoxError;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<http_body::Frame<Bytes>, Self::Error>>> {
        let this = &mut *self;
        match Pin::new(&mut this.inner).poll_frame(cx) {
            Poll::Pending => match this.sleep.as_mut().poll(cx) {
                Poll::Ready(()) => Poll::Ready(Some(Err(Box::new(BodyTimedOut {
                    seconds: this.seconds,
                })))),
                Poll::Pending => Poll::Pending,
            },
            ready => ready.map(|frame| frame.map(|f| f.map_err(Into::into))),
        }
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> http_body::SizeHint {
        self.inner.size_hint()
    }
}
