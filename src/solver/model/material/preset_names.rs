//! The presets a case can name (`material.preset`): the [`Preset`] enum, its names and the
//! order the form lists them in. No values: what each preset fills in, and from which source,
//! is in `preset.rs`. Imports nothing of the material folder; `given.rs` and `preset.rs`
//! import it.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The materials a case can name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
pub enum Preset {
    /// The paper's rigid PVC: elastic–perfectly plastic, rate-independent.
    Pvc,
    /// Aluminium alloy EN AW-6060 in temper T5, extruded, wall ≤ 5 mm: the alloy of Guillow,
    /// Lu & Grzebieta's round tubes. Elastic–perfectly plastic at its 0.2 % proof stress.
    #[serde(rename = "aa6060_t5")]
    Aa6060T5,
    /// Aluminium alloy 6061-T6: Johnson–Cook's strain and rate terms.
    #[serde(rename = "aa6061_t6")]
    Aa6061T6,
    /// Mild steel: perfectly plastic with Cowper–Symonds' rate law of Jones's book.
    MildSteel,
    /// Austenitic stainless steel AISI 304, annealed: Swift hardening from Callister's
    /// strength coefficient and exponent, Cowper–Symonds' rate law of Jones's book.
    #[serde(rename = "stainless_304")]
    Stainless304,
}

impl Preset {
    /// Every preset, in the order the form lists them.
    pub const ALL: [Preset; 5] = [
        Preset::Pvc,
        Preset::Aa6060T5,
        Preset::Aa6061T6,
        Preset::MildSteel,
        Preset::Stainless304,
    ];

    /// The name a case uses.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Pvc => "pvc",
            Preset::Aa6060T5 => "aa6060_t5",
            Preset::Aa6061T6 => "aa6061_t6",
            Preset::MildSteel => "mild_steel",
            Preset::Stainless304 => "stainless_304",
        }
    }
}
