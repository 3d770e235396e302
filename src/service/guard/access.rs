//! Who may reach a route that is open by default (`/healthz`, `/metrics`): the [`Access`] a
//! flag of `crush serve` sets. Imports nothing of the guard; `mod.rs` (which re-exports it)
//! and `policy.rs` import it.

/// Who may reach a route that is open by default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Access {
    /// Anyone.
    Open,
    /// A token with the read role (or any, when no tokens are configured).
    Read,
}
