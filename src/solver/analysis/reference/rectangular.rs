//! Closed forms of a rectangular (square) tube crushed axially. Units: mm, MPa, N, 1/s.
//!
//! - Wierzbicki & Abramowicz (1983), "On the crushing mechanics of thin-walled structures",
//!   J. Appl. Mech. 50: the superfolding element of a square tube of side c and wall t in
//!   rigid–perfectly plastic material of flow stress σ₀ folds in lobes 2H long,
//!   H = 0.99 t^(1/3) c^(2/3), at the mean load P_m = 9.56 σ₀ t^(5/3) c^(1/3) (in Jones's
//!   *Structural Impact*, P_m/M₀ = 38.12 (c/t)^(1/3) with M₀ = σ₀t²/4, that is 9.53).
//! - Abramowicz & Jones (1984), "Dynamic axial crushing of square tubes", Int. J. Impact
//!   Engng 2: a fold does not flatten completely; only its effective crushing distance,
//!   δ_e = 0.73 · 2H, is crushed, so the mean load over the plate's travel is the theory's over
//!   0.73: P_m/M₀ = 52.22 (c/t)^(1/3), P_m = 13.06 σ₀ t^(5/3) c^(1/3). A crush at speed V strains
//!   the folds at about ε̇ = 0.33 V / c, and a rate-sensitive material's flow stress rises by
//!   its rate law's factor there (Cowper–Symonds: 1 + (ε̇/D)^(1/q)).
//!
//! Both theories are for a square of side c with sharp corners; a rectangle a × b enters with
//! its mean side c = (a + b)/2, as Jones does, and the corner radius not at all. The Euler load
//! of the column uses the section's own least second moment of area.

use super::primary::Primary;
use crate::solver::model::case::{Case, LoadingMode, Rectangle};
use crate::solver::model::spec::RateKind;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Wierzbicki & Abramowicz's mean load coefficient: P_m = 9.56 σ₀ t^(5/3) c^(1/3).
pub const WIERZBICKI_ABRAMOWICZ: f64 = 9.56;

/// Wierzbicki & Abramowicz's half fold length coefficient: H = 0.99 t^(1/3) c^(2/3).
pub const HALF_FOLD: f64 = 0.99;

/// Abramowicz & Jones's share of a fold's length that is crushed: δ_e = 0.73 · 2H.
pub const EFFECTIVE_CRUSH: f64 = 0.73;

/// Abramowicz & Jones's mean load coefficient, 52.22 / 4: P_m = 13.06 σ₀ t^(5/3) c^(1/3).
pub const ABRAMOWICZ_JONES: f64 = 13.06;

/// Abramowicz & Jones's mean strain rate of a square tube's folds, ε̇ = 0.33 V / c.
pub const STRAIN_RATE_FACTOR: f64 = 0.33;

/// The closed forms of a rectangular tube.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct RectangularReferences {
    /// The side c of the theories' square: (a + b)/2, mm.
    pub mean_side_mm: f64,
    /// σ₀ = (σy + σu)/2, as for a round tube, MPa.
    pub flow_stress_mpa: f64,
    /// Wierzbicki & Abramowicz (1983): 9.56 σ₀ t^(5/3) c^(1/3), N.
    pub wierzbicki_abramowicz_n: f64,
    /// H = 0.99 t^(1/3) c^(2/3), mm: a fold takes 2H of the tube.
    pub half_fold_length_mm: f64,
    /// δ_e = 0.73 · 2H, mm: the plate's travel per fold.
    pub effective_crush_per_fold_mm: f64,
    /// Abramowicz & Jones (1984), static: 13.06 σ₀ t^(5/3) c^(1/3), N.
    pub abramowicz_jones_n: f64,
    /// The folds' mean strain rate at the plate's speed V, 0.33 V / c, 1/s.
    pub strain_rate_per_s: f64,
    /// σ_d / σ₀ at that rate (1 without a rate law).
    pub rate_factor: f64,
    /// Abramowicz & Jones times the rate factor, where the material names a rate law, N.
    pub abramowicz_jones_dynamic_n: Option<f64>,
    /// Euler load of the whole column with clamped ends, 4π² E I / l², N.
    pub euler_clamped_n: f64,
    /// The reference a report compares the run's mean load with.
    pub primary: Primary,
    /// Value of `primary`, N; null where no closed form covers the loading (lateral).
    pub primary_n: Option<f64>,
}

/// The closed forms of `case`, whose cross-section is `section`.
pub fn references(case: &Case, section: &Rectangle) -> RectangularReferences {
    let spec = case.spec();
    let t = section.thickness_mm;
    let c = 0.5 * (section.side_a_mm + section.side_b_mm);
    // σ₀: the wall's flow stress, as for a round metal tube.
    let sigma = spec.material.flow_stresses().flow();
    let half_fold = half_fold_length(t, c);
    // V in m/s is mm/ms: 1000 V / c per second.
    let strain_rate = STRAIN_RATE_FACTOR * 1000.0 * spec.loading.material_speed_m_s() / c;
    let factor = spec.material.rate_factor(strain_rate);
    let rate_law = spec.material.rate != RateKind::None;
    let aj = abramowicz_jones(t, c, sigma);
    let l = case.geometry().length_mm;
    let euler =
        4.0 * PI * PI * spec.material.youngs_modulus_mpa * section.least_second_moment_mm4()
            / (l * l);
    let (primary, primary_n) = match case.geometry().mode {
        LoadingMode::Axial => (Primary::AbramowiczJones, Some(aj * factor)),
        LoadingMode::Lateral => (Primary::Unavailable, None),
    };
    RectangularReferences {
        mean_side_mm: c,
        flow_stress_mpa: sigma,
        wierzbicki_abramowicz_n: wierzbicki_abramowicz(t, c, sigma),
        half_fold_length_mm: half_fold,
        effective_crush_per_fold_mm: EFFECTIVE_CRUSH * 2.0 * half_fold,
        abramowicz_jones_n: aj,
        strain_rate_per_s: strain_rate,
        rate_factor: factor,
        abramowicz_jones_dynamic_n: rate_law.then_some(aj * factor),
        euler_clamped_n: euler,
        primary,
        primary_n,
    }
}

/// Wierzbicki & Abramowicz's mean load of a square tube of wall t and side c, N.
pub fn wierzbicki_abramowicz(t: f64, c: f64, sigma: f64) -> f64 {
    WIERZBICKI_ABRAMOWICZ * sigma * t.powf(5.0 / 3.0) * c.cbrt()
}

/// Wierzbicki & Abramowicz's half fold length H, mm.
pub fn half_fold_length(t: f64, c: f64) -> f64 {
    HALF_FOLD * t.cbrt() * c.powf(2.0 / 3.0)
}

/// Abramowicz & Jones's static mean load over the effective crushing distance, N.
pub fn abramowicz_jones(t: f64, c: f64, sigma: f64) -> f64 {
    ABRAMOWICZ_JONES * sigma * t.powf(5.0 / 3.0) * c.cbrt()
}

#[cfg(test)]
mod tests {
    use super::super::References;
    use super::*;
    use crate::solver::Limits;

    fn close(got: f64, want: f64, rel: f64) {
        assert!((got / want - 1.0).abs() < rel, "got {got}, want {want}");
    }

    #[test]
    fn the_closed_forms_by_hand() {
        // t 1.5, c 50, σ₀ 65.5: t^(5/3) = 1.96556, c^(1/3) = 3.68403;
        // W&A 9.56·65.5·1.96556·3.68403 = 4 534.2 N; A&J 13.06 / 9.56 of it = 6 194.3 N.
        close(wierzbicki_abramowicz(1.5, 50.0, 65.5), 4_534.2, 1e-4);
        close(abramowicz_jones(1.5, 50.0, 65.5), 6_194.3, 1e-4);
        // H = 0.99·1.14471·13.5721 = 15.381 mm.
        close(half_fold_length(1.5, 50.0), 15.381, 1e-4);
        // A&J's coefficient is W&A's (in Jones's 38.12 / 4) over the effective crush 0.73.
        close(ABRAMOWICZ_JONES, 38.12 / 4.0 / EFFECTIVE_CRUSH, 1e-3);
    }

    #[test]
    fn a_square_case_has_the_square_forms_and_a_rectangle_its_mean_side() {
        let case = Case::from_json(
            r#"{"tube": {"section": "rectangular", "side_a_mm": 50, "thickness_mm": 1.5,
                         "length_mm": 100},
                "loading": {"plate_speed_m_s": 10}}"#,
            &Limits::default(),
        )
        .unwrap();
        let References::Rectangular(r) = super::super::references(&case) else {
            panic!("a rectangular case has rectangular references")
        };
        close(r.abramowicz_jones_n, 6_194.3, 1e-4);
        assert_eq!(r.primary, Primary::AbramowiczJones);
        assert_eq!(r.primary_n, Some(r.abramowicz_jones_n));
        // 0.33 · 10 m/s / 50 mm = 66 /s; PVC has no rate dependence.
        close(r.strain_rate_per_s, 66.0, 1e-12);
        assert_eq!((r.rate_factor, r.abramowicz_jones_dynamic_n), (1.0, None));
        close(r.effective_crush_per_fold_mm, 0.73 * 2.0 * 15.381, 1e-4);
        assert!(r.euler_clamped_n > 10.0 * r.primary_n.unwrap(), "{r:?}");

        let rectangle = Case::from_json(
            r#"{"tube": {"section": "rectangular", "side_a_mm": 40, "side_b_mm": 60,
                         "thickness_mm": 1.5, "length_mm": 100},
                "loading": {"mode": "lateral", "crush_distance_mm": 10}}"#,
            &Limits::default(),
        )
        .unwrap();
        let References::Rectangular(r) = super::super::references(&rectangle) else {
            panic!("a rectangular case has rectangular references")
        };
        assert_eq!(r.mean_side_mm, 50.0);
        assert_eq!((r.primary, r.primary_n), (Primary::Unavailable, None));
    }

    /// A hardening wall's square forms take (σy + σu)/2: stainless 304's Swift law necks at
    /// 636.3 MPa (engineering), so σ₀ = (205 + 636.3)/2 = 420.65 MPa.
    #[test]
    fn a_hardening_square_tube_s_forms_take_the_mean_of_yield_and_ultimate() {
        let case = Case::from_json(
            r#"{"material": {"preset": "stainless_304", "rate": "none"},
                "tube": {"section": "rectangular", "side_a_mm": 50, "thickness_mm": 1.5,
                         "length_mm": 100}}"#,
            &Limits::default(),
        )
        .unwrap();
        let References::Rectangular(r) = super::super::references(&case) else {
            panic!("a rectangular case has rectangular references")
        };
        close(r.flow_stress_mpa, 420.65, 1e-4);
        close(r.abramowicz_jones_n, 6_194.3 * 420.65 / 65.5, 1e-4);
    }
}
