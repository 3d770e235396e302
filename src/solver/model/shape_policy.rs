//! The shape-function policy: which shape functions a case that names none runs with, and why
//! (`docs/studies.md` §5, "Which shape function for which wall").

use super::geometry::{CrossSection, Outline};
use super::spec::{Model, ShapeKind};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The d/t from which a wall is thin: a 3D case of such a wall on near-frictionless plates
/// runs with linear shapes by default. `docs/studies.md` §5, "Which shape function for
/// which wall", holds the runs behind it: at d/t 6.9 both shapes fold the paper's tube in
/// rings and uGIMP closes its books better; at d/t 9.4 and 26 uGIMP let tubes tip over
/// between the source's plates (μ 0.02) that linear shapes fold progressively.
pub const THIN_WALL_D_OVER_T: f64 = 8.0;

/// The plate friction from which the plates hold a thin wall's ends, so that a 3D case of a
/// thin wall runs with B-splines by default (docs/folding.md §7). The thinnest tube measured (t
/// 0.76, d/t 26, n 2) tips over on μ 0.02, stays loaded on 0.1 but shears its middle 7.3 mm
/// off the axis, and stands upright on 0.2 and 0.3 (drift 2.5 and 1.8 mm); the d = 10 and
/// 12 mm tubes, which tipped over on 0.02, already stand on 0.1.
pub const HOLDING_FRICTION: f64 = 0.2;

/// A section's slenderness: its width over its wall (d/t; b/t for a rectangle, b its larger
/// side).
pub fn slenderness(section: &CrossSection) -> f64 {
    section.width_mm() / section.thickness_mm()
}

/// Whether a wall is thin (slenderness ≥ [`THIN_WALL_D_OVER_T`]).
pub fn is_thin(section: &CrossSection) -> bool {
    slenderness(section) >= THIN_WALL_D_OVER_T
}

/// Whether uGIMP and B-splines can let this wall tip over in 3D between plates of this
/// friction (docs/folding.md §4, §7): a thin wall on plates below [`HOLDING_FRICTION`], where
/// linear shapes are its default.
pub fn may_tip_over(section: &CrossSection, friction: f64) -> bool {
    is_thin(section) && friction < HOLDING_FRICTION
}

/// The shape functions a case runs with, and whether the case named them.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct ShapeChoice {
    pub kind: ShapeKind,
    /// Why the default is this one, when the case named no shape functions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default_reason: Option<String>,
}

impl ShapeKind {
    /// The shape functions for a case that names none, and why: uGIMP, which converges with n
    /// where linear shapes do not (docs/studies.md §1, docs/folding.md §7); for a thin wall
    /// (d/t ≥ [`THIN_WALL_D_OVER_T`]) in 3D, quadratic B-splines on plates that hold its ends
    /// (μ ≥ [`HOLDING_FRICTION`]), where the d/t 14 tube's mean load settles with them and
    /// alternates with the parity of n under uGIMP (docs/studies.md §9), and linear shapes on
    /// near-frictionless plates ([`may_tip_over`]), between which uGIMP and B-splines yield
    /// both ends of such a tube at once and let it tip over; linear shapes' folds there follow
    /// the wall's motion through the grid, and the verdict says so (`frame_dependent`). A
    /// rectangular section's slenderness is its larger side over t (b/t).
    pub fn default_for(section: &CrossSection, model: Model, friction: f64) -> ShapeChoice {
        let slenderness = slenderness(section);
        let w = section.width_symbol();
        let (kind, why) = match model {
            Model::ThreeD if may_tip_over(section, friction) => (
                ShapeKind::Linear,
                format!(
                    "linear: the default for a thin wall ({w}/t = {slenderness:.1} >= \
                     {THIN_WALL_D_OVER_T}) on near-frictionless plates (μ {friction} < \
                     {HOLDING_FRICTION}), between which uGIMP lets such a tube tip over; \
                     where linear shapes fold it first follows the wall's motion through the \
                     grid (docs/folding.md §4)"
                ),
            ),
            Model::ThreeD if is_thin(section) => (
                ShapeKind::Bspline,
                format!(
                    "bspline: the default for a thin wall ({w}/t = {slenderness:.1} >= \
                     {THIN_WALL_D_OVER_T}) on plates that hold its ends (μ {friction} >= \
                     {HOLDING_FRICTION}): on the d/t 14 tube their mean load settles from \
                     n = 4, where uGIMP's alternates with the parity of n (docs/studies.md §9)"
                ),
            ),
            Model::ThreeD => (
                ShapeKind::Gimp,
                format!(
                    "gimp: the default for a wall of {w}/t = {slenderness:.1} < {THIN_WALL_D_OVER_T}"
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
