//! `crush serve | run | estimate | plan | bench | bench-plan | study | validate | openapi`: wires configuration to the library; nothing else lives here.

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
    /// What a case will cost and what its verdict can already say, without running it.
    Estimate(crush::cli::EstimateArgs),
    /// The runs (model, shape functions, n) that reach a target error or fit a time budget,
    /// each with its expected error and wall time, and the one to pick.
    Plan(crush::cli::PlanArgs),
    /// Accuracy and stability studies: convergence, stability, speed.
    Study(crush::cli::StudyArgs),
    /// The validation suite: the seed paper's scenes and the measured tubes beside ours, as a
    /// report (Markdown, HTML, JSON); non-zero when a check leaves its band.
    Validate(crush::cli::ValidateArgs),
    /// Print the HTTP contract (OpenAPI 3.1, YAML): api/paths.yaml's prose with the schemas
    /// generated from the types; `api/openapi.yaml` is this output.
    Openapi,
    /// Measure solver speed (particle-steps/s), time per phase and memory per particle.
    Bench(crush::cli::BenchArgs),
    /// Wall-time guesses (assumed and calibrated rates) against measured runs of the cases.
    BenchPlan(crush::cli::BenchPlanArgs),
    /// One bench measurement (used by `bench`; reads the case on stdin).
    #[command(hide = true)]
    BenchOne(crush::cli::BenchOneArgs),
}

/// Errors are told as their chain of causes, one line (`Error: reading a.json: No such file`):
/// a user's mistake is no place for a backtrace, even with `RUST_BACKTRACE` set. A bug still
/// panics, with its backtrace.
fn main() -> std::process::ExitCode {
    let command = Cli::parse().command;
    if !matches!(command, Command::Serve(_)) {
        quiet_on_a_closed_pipe();
    }
    match run(command) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// A command whose reader stops early (`crush estimate case.json | head -2`) ends there, as
/// command-line tools do, instead of panicking with a backtrace at its next line of output:
/// the Rust runtime ignores SIGPIPE, so every write to the closed pipe fails and `println!`
/// panics. The server keeps it ignored: a client that hangs up must cost one connection, not
/// the process.
fn quiet_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any thread starts; it restores the
    // default disposition of one signal and touches no memory.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Serve(args) => {
            let runtime = tokio::runtime::Builder::new_multi_thread()
                .enable_all()
                .build()?;
            runtime.block_on(crush::service::serve(args))
        }
        Command::Run(args) => crush::cli::run(args),
        Command::Estimate(args) => crush::cli::estimate(args),
        Command::Plan(args) => crush::cli::plan(args),
        Command::BenchPlan(args) => crush::cli::bench_plan(args),
        Command::Bench(args) => crush::cli::bench(args),
        Command::Openapi => {
            print!("{}", crush::service::contract::yaml());
            Ok(())
        }
        Command::Study(args) => crush::cli::study(args),
        Command::Validate(args) => crush::cli::validate(args),
        Command::BenchOne(args) => crush::cli::bench_one(args),
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// Every command and subcommand, as `crush study convergence` (hidden ones too).
    fn paths(command: &clap::Command, prefix: &str, out: &mut Vec<String>) {
        for sub in command.get_subcommands() {
            let path = format!("{prefix} {}", sub.get_name());
            out.push(path.clone());
            paths(sub, &path, out);
        }
    }

    /// CONTRIBUTING.md lists every command of the binary, each as "- `crush NAME…`".
    #[test]
    fn every_subcommand_is_listed_in_contributing() {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("CONTRIBUTING.md"),
        )
        .unwrap();
        let mut all = Vec::new();
        paths(&Cli::command(), "crush", &mut all);
        assert!(all.len() >= 12, "{all:?}");
        let missing: Vec<&String> = all
            .iter()
            .filter(|path| {
                !text.lines().any(|line| {
                    line.trim_start()
                        .strip_prefix(&format!("- `{path}"))
                        .is_some_and(|rest| rest.starts_with('`') || rest.starts_with(' '))
                })
            })
            .collect();
        assert!(
            missing.is_empty(),
            "CONTRIBUTING.md lists no line \"- `COMMAND`: …\" for {missing:?}"
        );
    }
}
