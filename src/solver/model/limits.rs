//! What a caller is willing to run ([`Limits`]) and how a case is refused: each rejected field
//! named with its reason ([`FieldError`], [`CaseError`]).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Limits a caller puts on what it is willing to run. Every count is computed in floating
/// point before it is compared, so no case can overflow its way past a limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Tube particles (never more than [`PARTICLE_ID_LIMIT`], whatever this says).
    pub max_particles: u64,
    /// Explicit steps at the initial time step.
    pub max_steps: u64,
    /// Particles × steps: the work of the run, which sets its wall time.
    pub max_particle_steps: u64,
}

/// The solver numbers particles with `u32` ids: no case may have more, whatever the limits.
pub const PARTICLE_ID_LIMIT: u64 = u32::MAX as u64;

impl Default for Limits {
    /// The server's defaults. Each admits every case in `examples/` at its own resolution with
    /// room: the costliest there, axial_t0.76_d19.81 (n = 4), needs 525 310 particles, 66 051
    /// steps and 3.47e10 particle-steps, so the margins are 9.5× on particles, 151× on steps
    /// and 14× on particle-steps (`every_example_case_fits_the_default_limits_with_room` holds
    /// them). 5e11 particle-steps is about 56 h on one thread at the estimate's 2.5 M/s; 1e7
    /// steps bounds the per-step overhead of a small case that creeps.
    fn default() -> Self {
        Limits {
            max_particles: 5_000_000,
            max_steps: 10_000_000,
            max_particle_steps: 500_000_000_000,
        }
    }
}

impl Limits {
    /// No limit but the particle ids' (bench runs, and re-reading a job that already ran).
    pub const fn unbounded() -> Limits {
        Limits {
            max_particles: PARTICLE_ID_LIMIT,
            max_steps: u64::MAX,
            max_particle_steps: u64::MAX,
        }
    }
}

/// One rejected field: its dotted path and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct FieldError {
    pub field: String,
    pub reason: String,
}

/// Everything wrong with a case, every field named.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CaseError {
    /// The text is not JSON, or a field has the wrong type or an unknown name.
    #[error("malformed case: {message}")]
    Malformed {
        field: Option<String>,
        message: String,
    },
    /// The JSON parses but makes no physical or computational sense.
    #[error("invalid case: {}", list(.0))]
    Invalid(Vec<FieldError>),
}

fn list(errors: &[FieldError]) -> String {
    errors
        .iter()
        .map(|e| format!("{} {}", e.field, e.reason))
        .collect::<Vec<_>>()
        .join("; ")
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.field, self.reason)
    }
}
