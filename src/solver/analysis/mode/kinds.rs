//! The collapse modes a tube's final shape is named by, and a polygonal tube's folded slices
//! counted by what their faces show. Units: none (names and counts).
//!
//! A leaf of the mode's folder: imports nothing of the analysis.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How the tube collapsed, judged from its final shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CollapseMode {
    /// Axisymmetric concertina folds.
    Ring,
    /// Non-axisymmetric folds with this many lobes around the circumference.
    Diamond { lobes: u32 },
    /// The whole column bowed sideways (Euler buckling).
    GlobalBuckling,
    /// Lateral loading: the tube was flattened across a diameter.
    Flattening,
    /// The whole tube tipped over between the plates: its centre line left the axis but stayed
    /// straight, and an end left its plate (it stands on the edge of its ring, or the tube lies
    /// on its side).
    TippedOver,
    /// A polygonal tube's layers of lobes each fold neighbouring faces opposite ways and faces
    /// two apart alike: a square's two opposite faces out and the other two in (Wierzbicki &
    /// Abramowicz's symmetric mode), a hexagon's alternate faces.
    Symmetric,
    /// A polygonal tube's layers fold in other patterns (a square's three faces out and one in,
    /// or the like) among symmetric ones (Abramowicz & Jones's asymmetric mixed modes).
    AsymmetricMixed,
    /// A polygonal tube's faces fold out together (the extensional mode of thick walls).
    Extensional,
}

impl CollapseMode {
    /// The mode's name as its JSON `kind` spells it (`ring`, `diamond`, …): the stored
    /// `mode` column and the sweep table's `mode`.
    pub fn kind(&self) -> &'static str {
        match self {
            CollapseMode::Ring => "ring",
            CollapseMode::Diamond { .. } => "diamond",
            CollapseMode::GlobalBuckling => "global_buckling",
            CollapseMode::Flattening => "flattening",
            CollapseMode::TippedOver => "tipped_over",
            CollapseMode::Symmetric => "symmetric",
            CollapseMode::AsymmetricMixed => "asymmetric_mixed",
            CollapseMode::Extensional => "extensional",
        }
    }
}

/// A polygonal tube's folded slices, by what their faces show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
pub struct FaceLayers {
    /// Faces two apart alike, neighbours unlike.
    pub symmetric: u32,
    /// Any other pattern but all faces alike.
    pub asymmetric: u32,
    /// Every face out (or in) together.
    pub extensional: u32,
}

impl FaceLayers {
    /// The folded slices the faces were read on.
    pub fn total(&self) -> u32 {
        self.symmetric + self.asymmetric + self.extensional
    }
}
