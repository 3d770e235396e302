//! Problem+json for the answers hyper gives on its own. A request whose head cannot be parsed
//! (a URI over 64 KiB: 414; a malformed header line: 400; headers over hyper's buffer: 431)
//! never reaches the router: hyper writes a bare head with `content-length: 0` and closes.
//! [`ProblemIo`] wraps each connection and rewrites exactly such a head into the problem
//! document every other error gets. The router never answers a 4xx without a body (see
//! `routes::problem_everywhere`), so no answer of ours is mistaken for one of hyper's.

use std::io;
use std::pin::Pin;
use std::task::{ready, Context, Poll};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};

/// One connection whose answers get problem+json instead of hyper's bare error heads. Not
/// vectored, so hyper hands each head to `poll_write` in one piece.
pub struct ProblemIo<I> {
    inner: I,
    /// A rewritten answer still being written: its bytes, how many are out, and the length of
    /// hyper's buffer it stands for.
    pending: Option<(Vec<u8>, usize, usize)>,
}

impl<I> ProblemIo<I> {
    pub fn new(inner: I) -> ProblemIo<I> {
        ProblemIo {
            inner,
            pending: None,
        }
    }
}

/// The problem answer standing for hyper's bare head `buf`, if it is one.
fn rewrite(buf: &[u8]) -> Option<Vec<u8>> {
    // Cheap test first: most writes are bodies or successful heads.
    if !buf.starts_with(b"HTTP/1.1 4") || buf.len() > 4096 {
        return None;
    }
    let head = std::str::from_utf8(buf).ok()?;
    let (status, title, kind) = match head.get(..13)? {
        "HTTP/1.1 400 " => (400, "Bad request", "bad-request"),
        "HTTP/1.1 414 " => (414, "URI too long", "uri-too-long"),
        "HTTP/1.1 431 " => (431, "Request header fields too large", "headers-too-large"),
        _ => return None,
    };
    let lower = head.to_ascii_lowercase();
    if !lower.ends_with("\r\n\r\n") || !lower.contains("\r\ncontent-length: 0\r\n") {
        return None;
    }
    let detail = match status {
        400 => "the request line or a header could not be parsed",
        414 => "the request URI is longer than this server reads (64 KiB)",
        _ => "the request headers are larger than this server reads",
    };
    let body = serde_json::json!({
        "type": format!("urn:crush:problem:{kind}"),
        "title": title,
        "status": status,
        "detail": detail,
    })
    .to_string();
    let status_line = head.split("\r\n").next()?;
    Some(
        format!(
            "{status_line}\r\ncontent-type: {}\r\ncontent-length: {}\r\nconnection: close\r\n\r\n{body}",
            super::error::PROBLEM_JSON,
            body.len()
        )
        .into_bytes(),
    )
}

impl<I: AsyncRead + Unpin> AsyncRead for ProblemIo<I> {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_read(cx, buf)
    }
}

impl<I: AsyncWrite + Unpin> AsyncWrite for ProblemIo<I> {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        let this = &mut *self;
        if this.pending.is_none() {
            match rewrite(buf) {
                Some(answer) => this.pending = Some((answer, 0, buf.len())),
                None => return Pin::new(&mut this.inner).poll_write(cx, buf),
            }
        }
        // Hyper calls again with the same buffer until it is taken whole.
        while let Some((answer, out, stands_for)) = &mut this.pending {
            if *out == answer.len() {
                let n = *stands_for;
                this.pending = None;
                return Poll::Ready(Ok(n));
            }
            let n = ready!(Pin::new(&mut this.inner).poll_write(cx, &answer[*out..]))?;
            if n == 0 {
                return Poll::Ready(Err(io::ErrorKind::WriteZero.into()));
            }
            *out += n;
        }
        Poll::Ready(Ok(0))
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }

    fn is_write_vectored(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::rewrite;

    #[test]
    fn only_bare_error_heads_are_rewritten() {
        let bare = b"HTTP/1.1 414 URI Too Long\r\ncontent-length: 0\r\ndate: x\r\n\r\n";
        let answer = String::from_utf8(rewrite(bare).unwrap()).unwrap();
        assert!(
            answer.starts_with("HTTP/1.1 414 URI Too Long\r\n"),
            "{answer}"
        );
        assert!(answer.contains("application/problem+json"), "{answer}");
        assert!(answer.ends_with('}'), "{answer}");
        // Ours always have a body; successes are never touched.
        let ours = b"HTTP/1.1 400 Bad Request\r\ncontent-length: 80\r\n\r\n";
        assert!(rewrite(ours).is_none());
        assert!(rewrite(b"HTTP/1.1 200 OK\r\ncontent-length: 0\r\n\r\n").is_none());
        assert!(rewrite(b"HTTP/1.1 400 Bad Request\r\ncontent-length: 0\r\n\r\n{}").is_none());
    }
}
