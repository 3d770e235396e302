//! Which closed form a run's mean load is compared with, by name. Units: none.
//!
//! A leaf of the references' folder: imports nothing of the analysis.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Which reference a run's mean load should be compared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Primary {
    /// Axial loading: Alexander's ring-mode mean load.
    #[default]
    AlexanderRing,
    /// Lateral loading: DeRuntz & Hodge's load averaged over the crush.
    DeruntzHodgeMean,
    /// Axial loading of a rectangular tube: Abramowicz & Jones's mean load over the effective
    /// crushing distance, with the rate law's factor where the material names one.
    AbramowiczJones,
    /// A loading no closed form here covers (a rectangular tube crushed laterally).
    Unavailable,
}

impl Primary {
    /// Short human name, for reports.
    pub fn name(self) -> &'static str {
        match self {
            Primary::AlexanderRing => "Alexander ring",
            Primary::DeruntzHodgeMean => "DeRuntz-Hodge mean",
            Primary::AbramowiczJones => "Abramowicz-Jones",
            Primary::Unavailable => "no closed form",
        }
    }
}
