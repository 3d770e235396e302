//! The per-client rate limit of the routes that cost work, those the route table declares
//! `Cost::RateLimited` (submits, sweeps, estimates, plans and sign-ins): a token bucket
//! per client (governor's GCRA), keyed by token name, or by the peer's address for a client
//! without one.

use crate::service::error::ApiError;
use governor::clock::{Clock, DefaultClock};
use governor::{DefaultKeyedRateLimiter, Quota, RateLimiter};
use std::net::{IpAddr, SocketAddr};
use std::num::NonZeroU32;
use std::sync::atomic::{AtomicU64, Ordering};

/// Forgets clients whose buckets are full again every this many checks, so the table holds
/// only the clients of the last burst's worth of time, however many addresses come and go.
const SWEEP_EVERY: u64 = 1024;

pub struct Limiter {
    buckets: DefaultKeyedRateLimiter<String>,
    checks: AtomicU64,
    per_s: u32,
}

impl Limiter {
    /// `per_s` requests a second on average, `burst` at once after a pause.
    pub fn new(per_s: NonZeroU32, burst: NonZeroU32) -> Limiter {
        Limiter {
            buckets: RateLimiter::keyed(Quota::per_second(per_s).allow_burst(burst)),
            checks: AtomicU64::new(0),
            per_s: per_s.get(),
        }
    }

    /// Takes one request from `client`'s bucket, or says when to come back (429).
    pub fn check(&self, client: &str) -> Result<(), ApiError> {
        if self.checks.fetch_add(1, Ordering::Relaxed) % SWEEP_EVERY == SWEEP_EVERY - 1 {
            self.buckets.retain_recent();
            self.buckets.shrink_to_fit();
        }
        let key = client.to_string();
        self.buckets.check_key(&key).map_err(|not_until| {
            let wait = not_until.wait_time_from(DefaultClock::default().now());
            ApiError::TooManyRequests {
                detail: format!(
                    "too many submits, sweeps, estimates, plans or sign-ins from {client} (at most {} a \
                     second on average); try again in {:.1} s",
                    self.per_s,
                    wait.as_secs_f64()
                ),
                retry_after_s: wait.as_secs_f64().ceil().max(1.0) as u32,
            }
        })
    }

    /// Clients with a bucket now.
    #[cfg(test)]
    fn clients(&self) -> usize {
        self.buckets.len()
    }
}

/// The key of a client without a token: its address; for IPv6 its /64, which one host
/// usually holds whole.
pub fn peer_key(peer: Option<SocketAddr>) -> String {
    match peer.map(|p| p.ip()) {
        Some(IpAddr::V4(ip)) => ip.to_string(),
        Some(IpAddr::V6(ip)) => match ip.to_ipv4_mapped() {
            Some(v4) => v4.to_string(),
            None => {
                let s = ip.segments();
                format!("{:x}:{:x}:{:x}:{:x}::/64", s[0], s[1], s[2], s[3])
            }
        },
        None => "an unknown address".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nz(n: u32) -> NonZeroU32 {
        NonZeroU32::new(n).unwrap()
    }

    #[test]
    fn a_client_past_its_burst_is_told_when_to_come_back_and_others_are_not() {
        let limiter = Limiter::new(nz(1), nz(3));
        for _ in 0..3 {
            limiter.check("a").unwrap();
        }
        match limiter.check("a") {
            Err(ApiError::TooManyRequests { retry_after_s, .. }) => assert_eq!(retry_after_s, 1),
            other => panic!("{other:?}"),
        }
        limiter.check("b").unwrap();
        assert_eq!(limiter.clients(), 2);
    }

    #[test]
    fn an_ipv6_client_is_keyed_by_its_64_and_a_mapped_ipv4_by_its_address() {
        let a: SocketAddr = "[2001:db8:1:2:aaaa::1]:5000".parse().unwrap();
        let b: SocketAddr = "[2001:db8:1:2:bbbb::9]:6000".parse().unwrap();
        assert_eq!(peer_key(Some(a)), peer_key(Some(b)));
        assert_eq!(peer_key(Some(a)), "2001:db8:1:2::/64");
        let mapped: SocketAddr = "[::ffff:10.0.0.7]:1".parse().unwrap();
        assert_eq!(peer_key(Some(mapped)), "10.0.0.7");
        assert_eq!(peer_key(Some("127.0.0.1:9".parse().unwrap())), "127.0.0.1");
    }
}
