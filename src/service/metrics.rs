//! `/metrics` in the OpenMetrics text format, through the `prometheus-client` crate: each scrape
//! fills a registry with what the store and the workers hold now (gauges), the node's running
//! total (a counter) and its claim-latency histogram (kept by the workers, s).

use prometheus_client::encoding::EncodeLabelSet;
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::family::Family;
use prometheus_client::metrics::gauge::Gauge;
use prometheus_client::metrics::histogram::{exponential_buckets, Histogram};
use prometheus_client::registry::Registry;
use std::sync::atomic::AtomicU64;

/// The content type of the answer.
pub const CONTENT_TYPE: &str = "application/openmetrics-text; version=1.0.0; charset=utf-8";

/// The histogram of claim times: buckets from 0.5 ms to about 4 s, doubling.
pub fn claim_histogram() -> Histogram {
    Histogram::new(exponential_buckets(0.0005, 2.0, 14))
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct StatusLabel {
    status: &'static str,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct NodeLabels {
    node: String,
    backend: &'static str,
}

/// What one scrape reports.
pub struct Snapshot<'a> {
    /// Jobs in the store by status name.
    pub jobs: Vec<(&'static str, i64)>,
    pub queued: i64,
    pub running_here: i64,
    pub particle_steps_per_s: f64,
    pub sse_clients: i64,
    pub particle_steps_total: u64,
    pub node: &'a str,
    pub backend: &'static str,
    pub claim_seconds: &'a Histogram,
}

fn gauge(value: i64) -> Gauge {
    let g = Gauge::default();
    g.set(value);
    g
}

/// The scrape as OpenMetrics text.
pub fn encode(s: &Snapshot) -> Result<String, std::fmt::Error> {
    let mut registry = Registry::default();
    let jobs = Family::<StatusLabel, Gauge>::default();
    for (status, n) in &s.jobs {
        jobs.get_or_create(&StatusLabel { status }).set(*n);
    }
    registry.register("crush_jobs", "Jobs in the store, by status", jobs);
    registry.register("crush_queue_depth", "Jobs waiting to run", gauge(s.queued));
    registry.register(
        "crush_running_jobs",
        "Jobs running in this process",
        gauge(s.running_here),
    );
    let rate = Gauge::<f64, AtomicU64>::default();
    rate.set(s.particle_steps_per_s);
    registry.register(
        "crush_particle_steps_per_second",
        "Current solver throughput of this process",
        rate,
    );
    registry.register(
        "crush_sse_clients",
        "Open event streams",
        gauge(s.sse_clients),
    );
    let node = Family::<NodeLabels, Gauge>::default();
    node.get_or_create(&NodeLabels {
        node: s.node.to_string(),
        backend: s.backend,
    })
    .set(1);
    registry.register(
        "crush_node",
        "This process: its node name and its store's backend",
        node,
    );
    registry.register(
        "crush_claim_seconds",
        "Time this node took to claim a job, over the claims that got one",
        s.claim_seconds.clone(),
    );
    let total = Counter::<u64>::default();
    total.inc_by(s.particle_steps_total);
    registry.register(
        "crush_particle_steps",
        "Particle-steps of the runs this process finished",
        total,
    );
    let mut out = String::new();
    prometheus_client::encoding::text::encode(&mut out, &registry)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_metric_has_its_type_and_the_claims_are_a_histogram() {
        let claims = claim_histogram();
        claims.observe(0.002);
        claims.observe(0.3);
        let text = encode(&Snapshot {
            jobs: vec![("queued", 2), ("running", 1)],
            queued: 2,
            running_here: 1,
            particle_steps_per_s: 1.5e6,
            sse_clients: 0,
            particle_steps_total: 42,
            node: "a \"quoted\" node",
            backend: "sqlite",
            claim_seconds: &claims,
        })
        .unwrap();
        for line in [
            "# TYPE crush_jobs gauge",
            "crush_jobs{status=\"queued\"} 2",
            "crush_running_jobs 1",
            "# TYPE crush_claim_seconds histogram",
            "crush_claim_seconds_count 2",
            "crush_claim_seconds_bucket{le=\"0.004\"} 1",
            "# TYPE crush_particle_steps counter",
            "crush_particle_steps_total 42",
            "crush_node{node=\"a \\\"quoted\\\" node\",backend=\"sqlite\"} 1",
            "# EOF",
        ] {
            assert!(
                text.lines().any(|l| l == line),
                "{line:?} missing from\n{text}"
            );
        }
    }
}
