//! The shape-function policy: which shape functions a case that names none runs with, and why
//! (`docs/validation.md` §4, "Which shape function for which wall").

use super::geometry::CrossSection;
use super::spec::{Model, ShapeKind};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The d/t from which a 3D case that names no shape function runs with linear shapes.
/// `docs/validation.md` §4, "Which shape function for which wall", holds the runs behind it:
/// at d/t 6.9 both shapes fold the paper's tube in rings and uGIMP closes its books better; at
/// d/t 9.4 and 26 uGIMP let tubes tip over that linear shapes fold progressively.
pub const LINEAR_FROM_D_OVER_T: f64 = 8.0;

/// The shape functions a case runs with, and whether the case named them.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct ShapeChoice {
    pub kind: ShapeKind,
    /// Why the default is this one, when the case named no shape functions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default_reason: Option<String>,
}

impl ShapeKind {
    /// The shape functions for a case that names none, and why. In 3D a thin wall
    /// (d/t ≥ [`LINEAR_FROM_D_OVER_T`]) gets linear shapes: with uGIMP some such tubes fold at
    /// both plates and then tip over between the near-frictionless plates of the source, where
    /// linear shapes fold them progressively from one plate, as the source's tubes did;
    /// quadratic B-splines converge where linear shapes do not, but fold the thin tubes at both
    /// plates on a platen's friction and squash an end into a pouch on near-frictionless plates
    /// (docs/folding.md §4), so they are not the default either. Linear shapes' one-ended
    /// folds are the grid's, not the load's: the same crush seen from a moving frame folds
    /// from the other end or from both (§4), and the verdict says so (`frame_dependent`).
    /// Every other case gets
    /// uGIMP, which converges with n where linear shapes do not (the reduced models, §7). A
    /// rectangular section's slenderness is its larger side over t (b/t).
    pub fn default_for(section: &CrossSection, model: Model) -> ShapeChoice {
        let slenderness = section.width_mm() / section.thickness_mm();
        let w = section.width_symbol();
        let (kind, why) = match model {
            Model::ThreeD if slenderness >= LINEAR_FROM_D_OVER_T => (
                ShapeKind::Linear,
                format!(
                    "linear: the default for a thin wall ({w}/t = {slenderness:.1} >= \
                     {LINEAR_FROM_D_OVER_T}); uGIMP and B-splines converge but yield both ends \
                     of such a tube at once: they fold it from both plates, or let it tip over \
                     on near-frictionless ones; where linear shapes fold it first follows the \
                     wall's motion through the grid (docs/folding.md §4)"
                ),
            ),
            Model::ThreeD => (
                ShapeKind::Gimp,
                format!(
                    "gimp: the default for a wall of {w}/t = {slenderness:.1} < {LINEAR_FROM_D_OVER_T}"
                ),
            ),
            _ => (
                ShapeKind::Gimp,
                "gimp: the default of the reduced models, where it converges".into(),
            ),
        };
        ShapeChoice {
            kind,
            default_reason: Some(why),
        }
    }
}
