//! Command-line runners around the solver (placeholder: being built).

/// Arguments of `crush run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {}

pub fn run(_args: RunArgs) -> anyhow::Result<()> {
    anyhow::bail!("not built yet")
}
