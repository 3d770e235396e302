//! Closed forms of a regular hexagonal tube. Units: mm, MPa, N.
//!
//! - Euler's load of the whole column with clamped ends, 4π² E I / l², with the wall's own
//!   second moment of area (the same about every axis through the centre: `Hexagon::
//!   second_moment_mm4`).
//! - The squash load σ0·A, the wall yielding all around at once: above any folding load, and
//!   so the load global buckling must undercut to compete with folding when no folding load is
//!   known.
//!
//! No folding mean load. Wierzbicki & Abramowicz's superfolding element has been worked out for
//! corners of other angles than a square's (Abramowicz & Wierzbicki 1989, multicorner
//! columns), but its coefficients for a hexagon's 120° corners are not checked here against
//! their source, and no number stands in for one that is not: the primary reference of a
//! hexagonal tube is `unavailable`, and its run is judged on its own books.

use super::primary::Primary;
use crate::solver::model::case::{Case, Outline};
use crate::solver::model::geometry::Hexagon;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The closed forms of a hexagonal tube.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct HexagonalReferences {
    /// The side s of the mid-line's hexagon, mm.
    pub hexagon_side_mm: f64,
    /// The width across the flats of the mid-line, s·√3, mm.
    pub across_flats_mm: f64,
    /// σ0 = (σy + σu)/2, as for a round tube, MPa.
    pub flow_stress_mpa: f64,
    /// The wall's second moment of area about an axis through the centre, mm⁴.
    pub second_moment_mm4: f64,
    /// The squash load σ0·A, N: the wall yielding all around at once.
    pub squash_n: f64,
    /// Euler load of the whole column with clamped ends, 4π² E I / l², N.
    pub euler_clamped_n: f64,
    /// The reference a report compares the run's mean load with: none for a hexagonal tube.
    pub primary: Primary,
    /// Value of `primary`: null, as no folding closed form is given for a hexagonal tube.
    pub primary_n: Option<f64>,
}

/// The closed forms of `case`, whose cross-section is `section`.
pub fn references(case: &Case, section: &Hexagon) -> HexagonalReferences {
    let spec = case.spec();
    let sigma = spec.material.flow_stresses().flow();
    let i = section.second_moment_mm4();
    let l = case.geometry().length_mm;
    let euler = 4.0 * PI * PI * spec.material.youngs_modulus_mpa * i / (l * l);
    HexagonalReferences {
        hexagon_side_mm: section.side_mm,
        across_flats_mm: section.width_mm(),
        flow_stress_mpa: sigma,
        second_moment_mm4: i,
        squash_n: sigma * section.area_mm2(),
        euler_clamped_n: euler,
        primary: Primary::Unavailable,
        primary_n: None,
    }
}
