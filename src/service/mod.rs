//! The HTTP job service (placeholder: being built).

/// Configuration of `crush serve`.
#[derive(Debug, Clone, clap::Args)]
pub struct ServeArgs {}

pub async fn serve(_args: ServeArgs) -> anyhow::Result<()> {
    anyhow::bail!("not built yet")
}
