//! The arguments of `crush run` and `crush estimate` (clap): the case's path, the threads, the
//! particle limit and the run's options. Imports nothing of the CLI; `mod.rs` re-exports them
//! and `run.rs` and `estimate.rs` read them.

use std::path::PathBuf;

/// Arguments of `crush run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// The crush case, as JSON (see examples/).
    pub case: PathBuf,
    /// Where history.csv and summary.json go [default: out/<case file stem>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Solver threads [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Refuse cases with more tube particles than this [default: the server's, 5000000; none
    /// with --no-limits].
    #[arg(long)]
    pub max_particles: Option<u64>,
    /// Run a case past the cost limits `crush serve` applies by default (particles, time
    /// steps, particle-steps; `crush serve --help`), which `crush run` otherwise holds it to.
    #[arg(long)]
    pub no_limits: bool,
    /// Price the mean load's error bar after the run (the tube's section at three
    /// resolutions), as the case's `output.error_bar` does.
    #[arg(long)]
    pub error_bar: bool,
}

/// Arguments of `crush estimate`.
#[derive(Debug, Clone, clap::Args)]
pub struct EstimateArgs {
    /// The crush case, as JSON (see examples/).
    pub case: PathBuf,
    /// Solver threads the estimate is for [default: all cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Refuse cases with more tube particles than this.
    #[arg(long, default_value_t = crate::solver::Limits::default().max_particles)]
    pub max_particles: u64,
    /// Print the estimate as the JSON `POST /v1/estimate` answers.
    #[arg(long)]
    pub json: bool,
}
