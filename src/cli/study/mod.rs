//! `crush study convergence | step | stability | speed`: sets of runs of one case, varied, and what
//! they say about accuracy, cost and robustness. Each writes a markdown report, CSV and plots
//! into its output directory and prints the report.

mod cases;
mod convergence;
mod speed;
mod stability;
mod step;

pub use convergence::ConvergenceArgs;
pub use speed::SpeedArgs;
pub use stability::StabilityArgs;
pub use step::StepArgs;

/// Arguments of `crush study`.
#[derive(Debug, Clone, clap::Args)]
pub struct StudyArgs {
    #[command(subcommand)]
    pub kind: StudyKind,
}

#[derive(Debug, Clone, clap::Subcommand)]
pub enum StudyKind {
    /// Error of mean and peak load against resolution and run time.
    Convergence(ConvergenceArgs),
    /// Error of mean and first-peak load and the energy books against the time step and run time.
    Step(StepArgs),
    /// Stiff and extreme variants of a case: completes cleanly or stops with a diagnosis.
    Stability(StabilityArgs),
    /// The case at several plate speeds: rate independence and the quasi-static check.
    Speed(SpeedArgs),
}

pub fn study(args: StudyArgs) -> anyhow::Result<()> {
    match args.kind {
        StudyKind::Convergence(a) => convergence::run(a),
        StudyKind::Step(a) => step::run(a),
        StudyKind::Stability(a) => stability::run(a),
        StudyKind::Speed(a) => speed::run(a),
    }
}
