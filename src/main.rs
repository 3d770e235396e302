//! `crush serve | run | bench | study`: wires configuration to the library; nothing else lives here.

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "crush",
    version,
    about = "MPM crush simulations of thin-walled tubes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Start the HTTP job server.
    Serve(crush::service::ServeArgs),
    /// Run one crush case and write its history and summary.
    Run(crush::cli::RunArgs),
    /// Accuracy and stability studies: convergence, stability, speed.
    Study(crush::cli::StudyArgs),
    /// Measure solver speed (particle-steps/s), time per phase and memory per particle.
    Bench(crush::cli::BenchArgs),
    /// One bench measurement (used by `bench`; reads the case on stdin).
    #[command(hide = true)]
    BenchOne(crush::cli::BenchOneArgs),
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().command {
        Command::Serve(args) => {
            let runtime = tokio::runtime::Builder::new_multi_thread()
                .enable_all()
                .build()?;
            runtime.block_on(crush::service::serve(args))
        }
        Command::Run(args) => crush::cli::run(args),
        Command::Bench(args) => crush::cli::bench(args),
        Command::Study(args) => crush::cli::study(args),
        Command::BenchOne(args) => crush::cli::bench_one(args),
    }
}
