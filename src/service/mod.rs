//! The HTTP job service around the solver: routes ([`app`]), the job store (all SQL), the
//! worker pool, the progress hub and SSE. `crush serve` calls [`serve`]; tests call [`start`].

mod bare_errors;
mod checkpointing;
mod cluster;
mod connection;
pub mod contract;
mod cpu;
mod downloads;
mod error;
mod form;
pub mod guard;
pub mod hub;
mod metrics;
mod retention;
mod retry;
mod routes;
mod series;
pub mod store;
pub mod sweep;
mod views;
mod worker;

pub use connection::TimeoutArgs;
pub use downloads::HEAVY_AT_ONCE;
pub use error::ApiError;
pub use guard::AccessArgs;
pub use routes::{app, routes, AppState, HttpLimits};
pub use worker::{WorkerConfig, Workers};

use anyhow::Context;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{watch, Semaphore};

/// Configuration of `crush serve`: flags, each also read from the environment.
#[derive(Debug, Clone, clap::Args)]
pub struct ServeArgs {
    /// Address to listen on (0.0.0.0 for every interface).
    #[arg(long, env = "CRUSH_HOST", default_value = "127.0.0.1")]
    pub host: String,
    /// Port to listen on; 0 picks a free one. The bound address is printed on stdout.
    #[arg(long, env = "CRUSH_PORT", default_value_t = 8080)]
    pub port: u16,
    /// The store: `sqlite://FILE` (created if missing; one node) or `postgres://USER@HOST/DB`
    /// (any number of nodes sharing one queue).
    #[arg(long, env = "DATABASE_URL", default_value = "sqlite://crush.db")]
    pub database_url: String,
    /// This node's name, stored with each job it runs and shown by `/v1/jobs/{id}` and
    /// `/metrics`; unique among the nodes of one database (default: host name and process id).
    #[arg(long, env = "CRUSH_NODE_NAME")]
    pub node_name: Option<String>,
    /// Jobs run at the same time by this process (0: accept and serve jobs, run none).
    #[arg(long, env = "CRUSH_CONCURRENT_JOBS", default_value_t = 1)]
    pub concurrent_jobs: usize,
    /// Solver threads of each job (0: the machine's cores divided among the concurrent jobs).
    #[arg(long, env = "CRUSH_THREADS_PER_JOB", default_value_t = 0)]
    pub threads_per_job: usize,
    /// Largest request body, bytes.
    #[arg(long, env = "CRUSH_MAX_BODY_BYTES", default_value_t = 1 << 20)]
    pub max_body_bytes: usize,
    /// Largest case, particles.
    #[arg(long, env = "CRUSH_MAX_PARTICLES", default_value_t = crate::solver::Limits::default().max_particles)]
    pub max_particles: u64,
    /// Longest case, explicit steps (estimated at the initial time step).
    #[arg(long, env = "CRUSH_MAX_STEPS", default_value_t = crate::solver::Limits::default().max_steps)]
    pub max_steps: u64,
    /// Costliest case, particles × steps (sets the wall time).
    #[arg(long, env = "CRUSH_MAX_PARTICLE_STEPS", default_value_t = crate::solver::Limits::default().max_particle_steps)]
    pub max_particle_steps: u64,
    /// Most jobs waiting in the queue; a submit beyond it gets 503.
    #[arg(long, env = "CRUSH_MAX_QUEUE", default_value_t = 1000)]
    pub max_queue: u64,
    /// Most event streams open at once; one more gets 503.
    #[arg(long, env = "CRUSH_MAX_SSE_CLIENTS", default_value_t = 256)]
    pub max_sse_clients: usize,
    /// Most jobs one sweep may create.
    #[arg(long, env = "CRUSH_MAX_SWEEP_JOBS", default_value_t = 100)]
    pub max_sweep_jobs: usize,
    /// Heartbeat of a running job, which also stores its progress, ms.
    #[arg(long, env = "CRUSH_HEARTBEAT_MS", default_value_t = 1000)]
    pub heartbeat_ms: u64,
    /// A running job whose heartbeat is older than this goes back to the queue, s.
    #[arg(long, env = "CRUSH_STALE_AFTER_S", default_value_t = 30.0)]
    pub stale_after_s: f64,
    /// Times a job's worker may be lost before the job is failed.
    #[arg(long, env = "CRUSH_MAX_ATTEMPTS", default_value_t = 3)]
    pub max_attempts: u32,
    /// On SIGINT/SIGTERM, how long running jobs may finish before they are requeued, s.
    #[arg(long, env = "CRUSH_SHUTDOWN_GRACE_S", default_value_t = 10.0)]
    pub shutdown_grace_s: f64,
    /// Interval of keep-alive comments on event streams, s.
    #[arg(long, env = "CRUSH_SSE_KEEP_ALIVE_S", default_value_t = 15.0)]
    pub sse_keep_alive_s: f64,
    /// A running job stores a checkpoint this often, s (0: never); a requeued job resumes from
    /// its last one on any node. A shutdown stores one before it requeues.
    #[arg(long, env = "CRUSH_CHECKPOINT_EVERY_S", default_value_t = 60.0)]
    pub checkpoint_every_s: f64,
    /// Largest checkpoint stored, MB (about 116 bytes a particle): a larger job stores none.
    #[arg(long, env = "CRUSH_CHECKPOINT_MAX_MB", default_value_t = 256)]
    pub checkpoint_max_mb: u64,
    /// How long a running job retries a write the database refuses while it is away (down,
    /// restarting, locked, full), s: its frames, checkpoints and outcome. A frame still refused
    /// then fails the job, saying why; a job never ends `succeeded` without all it promised.
    #[arg(long, env = "CRUSH_STORE_RETRY_S", default_value_t = 600.0)]
    pub store_retry_s: f64,
    /// Delete finished jobs, and sweeps whose jobs have all finished, this many days after they
    /// finished (fractions allowed; 0: keep everything).
    #[arg(long, env = "CRUSH_KEEP_DAYS", default_value_t = 0.0)]
    pub keep_days: f64,
    #[command(flatten)]
    pub access: AccessArgs,
    #[command(flatten)]
    pub timeouts: TimeoutArgs,
}

impl ServeArgs {
    /// Parses flags as `crush serve` would (the environment fills what they omit).
    pub fn from_flags<I, T>(flags: I) -> Result<ServeArgs, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        #[derive(clap::Parser)]
        struct Wrapper {
            #[command(flatten)]
            args: ServeArgs,
        }
        let argv = std::iter::once(std::ffi::OsString::from("serve"))
            .chain(flags.into_iter().map(Into::into));
        <Wrapper as clap::Parser>::try_parse_from(argv).map(|w| w.args)
    }

    fn seconds(&self, name: &str, v: f64) -> anyhow::Result<Duration> {
        anyhow::ensure!(
            v.is_finite() && v > 0.0,
            "{name} must be a positive number of seconds"
        );
        Duration::try_from_secs_f64(v).map_err(|_| anyhow::anyhow!("{name} is too large"))
    }
}

/// A running server.
pub struct Server {
    /// The address it listens on.
    pub addr: SocketAddr,
    /// Who may do what, in words.
    pub access: String,
    shutdown: watch::Sender<bool>,
    workers: Arc<Workers>,
    task: Option<tokio::task::JoinHandle<anyhow::Result<()>>>,
}

impl Server {
    /// A handle that starts the graceful shutdown when sent `true`.
    pub fn trigger(&self) -> watch::Sender<bool> {
        self.shutdown.clone()
    }

    /// Runs until shut down.
    pub async fn wait(mut self) -> anyhow::Result<()> {
        match self.task.take() {
            Some(task) => task.await.context("the server task failed")?,
            None => Ok(()),
        }
    }

    /// Shuts down gracefully and waits for it.
    pub async fn stop(self) -> anyhow::Result<()> {
        let _ = self.shutdown.send(true);
        self.wait().await
    }
}

impl Drop for Server {
    /// A server dropped without `stop` still stops its solvers, so no blocking thread outlives it.
    fn drop(&mut self) {
        let _ = self.shutdown.send(true);
        if self.task.is_some() {
            self.workers.stop_all();
        }
    }
}

/// Opens the store, binds, starts the workers and serves until the trigger fires.
pub async fn start(args: ServeArgs) -> anyhow::Result<Server> {
    let stale_after = args.seconds("--stale-after-s", args.stale_after_s)?;
    let grace = args.seconds("--shutdown-grace-s", args.shutdown_grace_s)?;
    let keep_alive = args.seconds("--sse-keep-alive-s", args.sse_keep_alive_s)?;
    let heartbeat = Duration::from_millis(args.heartbeat_ms.max(1));
    anyhow::ensure!(
        stale_after >= heartbeat * 2,
        "--stale-after-s must be at least two heartbeats (--heartbeat-ms)"
    );
    anyhow::ensure!(args.max_attempts >= 1, "--max-attempts must be at least 1");
    anyhow::ensure!(
        args.keep_days.is_finite() && args.keep_days >= 0.0,
        "--keep-days must be 0 (keep everything) or a positive number of days"
    );
    let keep = if args.keep_days == 0.0 {
        None
    } else {
        Some(args.seconds("--keep-days", args.keep_days * 86_400.0)?)
    };
    let timeouts = args.timeouts.timeouts()?;
    let guard = Arc::new(guard::Guard::new(&args.access, routes::policies())?);
    anyhow::ensure!(
        guard.has_tokens() || args.access.allow_anonymous_remote || is_loopback(&args.host),
        "--host {} is not a loopback address and there is no --token-file: anyone who can \
         reach the port could read, submit and cancel every job. Give a token file, or \
         --allow-anonymous-remote to serve so anyway",
        args.host
    );
    let cores = crate::solver::cores();
    let threads = match args.threads_per_job {
        0 => (cores / args.concurrent_jobs.max(1)).max(1),
        n => n,
    };
    let store = store::Store::open(&args.database_url)
        .await
        .with_context(|| format!("opening the database {}", args.database_url))?;
    let listener = tokio::net::TcpListener::bind((args.host.as_str(), args.port))
        .await
        .with_context(|| format!("binding {}:{}", args.host, args.port))?;
    let addr = listener.local_addr()?;

    let (shutdown, shutdown_rx) = watch::channel(false);
    let hub = hub::Hub::new(1024);
    let case_limits = crate::solver::Limits {
        max_particles: args.max_particles,
        max_steps: args.max_steps,
        max_particle_steps: args.max_particle_steps,
    };
    let config = WorkerConfig {
        concurrent_jobs: args.concurrent_jobs,
        threads_per_job: threads,
        // The worker checks each claimed case again: a job stored by an older version, or
        // under larger limits, fails with the reason instead of running.
        limits: case_limits,
        heartbeat,
        stale_after,
        max_attempts: args.max_attempts,
        poll: Duration::from_millis(500),
        node: args.node_name.clone().unwrap_or_else(default_node_name),
        checkpoints: checkpointing::Policy {
            every: if args.checkpoint_every_s == 0.0 {
                None
            } else {
                Some(args.seconds("--checkpoint-every-s", args.checkpoint_every_s)?)
            },
            max_bytes: args.checkpoint_max_mb.saturating_mul(1_000_000),
        },
        store_patience: args.seconds("--store-retry-s", args.store_retry_s)?,
    };
    let workers = Workers::new(store.clone(), hub.clone(), config, shutdown_rx.clone());
    let limits = HttpLimits {
        max_body_bytes: args.max_body_bytes,
        case: case_limits,
        max_queue: args.max_queue,
        max_sweep_jobs: args.max_sweep_jobs,
        max_sse_clients: args.max_sse_clients,
        keep_alive,
        sse_poll: Duration::from_secs(2),
        min_download_rate: timeouts.min_download_rate,
        body_timeout: timeouts.body,
    };
    let state = AppState {
        store: store.clone(),
        hub: hub.clone(),
        workers: workers.clone(),
        limits: Arc::new(limits),
        sse_permits: Arc::new(Semaphore::new(args.max_sse_clients)),
        heavy: Arc::new(downloads::Slots::new(timeouts.fair_download_rate)),
        cpu: cpu::CpuGate::new(cpu::CPU_AT_ONCE, cpu::CPU_WAIT),
        shutdown: shutdown_rx.clone(),
        guard: guard.clone(),
    };
    let mut handles = workers.spawn();
    handles.extend(cluster::start(&store, &hub, &workers, shutdown_rx.clone()));
    if let Some(keep) = keep {
        handles.push(retention::spawn(store.clone(), keep, shutdown_rx.clone()));
    }
    let router = app(state);
    let drain = workers.clone();
    let down = shutdown_rx;
    let task = tokio::spawn(async move {
        connection::serve(listener, router, timeouts, down).await;
        tracing::info!("shutting down: waiting for running jobs");
        drain.drain(grace).await;
        for handle in handles {
            let _ = tokio::time::timeout(Duration::from_secs(5), handle).await;
        }
        store.close().await;
        tracing::info!("stopped");
        Ok(())
    });
    tracing::info!(%addr, threads_per_job = threads, concurrent_jobs = args.concurrent_jobs, "crush listening");
    tracing::info!("access: {}", guard.describe());
    Ok(Server {
        addr,
        access: guard.describe(),
        shutdown,
        workers,
        task: Some(task),
    })
}

/// Whether `--host` names only this machine: a loopback address, or `localhost`.
fn is_loopback(host: &str) -> bool {
    host.eq_ignore_ascii_case("localhost")
        || host
            .trim_start_matches('[')
            .trim_end_matches(']')
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

/// The host name and the process id: unique among nodes on different hosts, and among
/// processes on one host.
fn default_node_name() -> String {
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "crush".into());
    format!("{host}-{}", std::process::id())
}

/// `crush serve`: runs the server until SIGINT or SIGTERM.
pub async fn serve(args: ServeArgs) -> anyhow::Result<()> {
    let _ = tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .with_writer(std::io::stderr)
        .try_init();
    let server = start(args).await?;
    // Scripts and tests read the port from this line when they asked for port 0.
    println!("crush listening on http://{}", server.addr);
    println!("access: {}", server.access);
    use std::io::Write;
    let _ = std::io::stdout().flush();
    let trigger = server.trigger();
    tokio::spawn(async move {
        shutdown_signal().await;
        tracing::info!("signal received");
        let _ = trigger.send(true);
    });
    server.wait().await
}

async fn shutdown_signal() {
    let interrupt = tokio::signal::ctrl_c();
    #[cfg(unix)]
    {
        let mut term =
            match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
                Ok(term) => term,
                Err(_) => {
                    let _ = interrupt.await;
                    return;
                }
            };
        tokio::select! {
            _ = interrupt => {}
            _ = term.recv() => {}
        }
    }
    #[cfg(not(unix))]
    {
        let _ = interrupt.await;
    }
}
