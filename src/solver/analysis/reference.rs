//! Closed-form reference loads for a case, to judge a run against (design page, section 6).
//! Units: mm, MPa, N.
//!
//! d (or D) is the mean diameter, t the wall thickness, l the length, σy the yield stress and U the
//! crush distance of the case. Each formula is the textbook one; none depends on the run.
//!
//! The round metal tube's axial references ([`MetalTube`]): Abramowicz & Jones's modified
//! Alexander with the effective crushing distance, and Guillow, Lu & Grzebieta's empirical fit
//! for 6060-T5, each static and with the rate law's factor at the wall's mean strain rate V/(4R)
//! where the material names a rate law.
//!
//! Every closed form here takes the wall's flow stress σ0 = (σy + σu)/2
//! ([`FlowStresses::flow`]), σu the engineering ultimate stress of the static hardening curve:
//! σy for a perfectly plastic wall such as the paper's PVC.
//!
//! A rectangular tube has its own ([`rectangular`]: Wierzbicki & Abramowicz, Abramowicz &
//! Jones), and so has a hexagonal one ([`hexagonal`]: Euler's load and the squash load; no
//! folding mean load).

pub mod hexagonal;
mod primary;
pub mod rectangular;
pub mod shell;
pub mod shown;

pub use hexagonal::HexagonalReferences;
pub use primary::Primary;
pub use rectangular::RectangularReferences;

use crate::solver::model::case::{Case, CrossSection, LoadingMode, Outline};
use crate::solver::model::material::given::FlowStresses;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Lobe counts for which the diamond-mode reference is reported.
pub const DIAMOND_LOBES: std::ops::RangeInclusive<u32> = 2..=5;

/// Johnson, Soden & Al-Hassani's mean load for one lobe count.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct DiamondReference {
    pub lobes: u32,
    /// A = 1 + n cosec(π/2n) + n cot(π/2n).
    pub a: f64,
    /// Travelling-hinge radius r*, mm.
    pub hinge_radius_mm: f64,
    /// Stationary-hinge bound: σ̄ = σy (t/D) A / √3, load σ̄ π D t.
    pub stationary_n: f64,
    /// With the travelling-hinge term: σ̄ = σy (t/D)(A + D/r*) / √3, load σ̄ π D t.
    pub travelling_n: f64,
}

/// The closed forms of a case's cross-section. Each serializes as its own fields alone.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum References {
    Round(RoundReferences),
    Rectangular(RectangularReferences),
    Hexagonal(HexagonalReferences),
}

impl Default for References {
    fn default() -> Self {
        References::Round(RoundReferences::default())
    }
}

impl References {
    /// The reference a report compares the run's mean load with.
    pub fn primary(&self) -> Primary {
        match self {
            References::Round(r) => r.primary,
            References::Rectangular(r) => r.primary,
            References::Hexagonal(r) => r.primary,
        }
    }

    /// Value of [`References::primary`], N; `None` where the form does not reach this case (a
    /// lateral crush to the diameter, where DeRuntz & Hodge's load ends; a rectangular tube
    /// crushed laterally). A summary stored with 0 there reads as `None` too.
    pub fn primary_n(&self) -> Option<f64> {
        match self {
            References::Round(r) => r.primary_n,
            References::Rectangular(r) => r.primary_n,
            References::Hexagonal(r) => r.primary_n,
        }
        .filter(|p| *p > 0.0)
    }
}

/// The closed-form loads of a round tube.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct RoundReferences {
    /// Alexander (1960) ring-mode mean load P̄ = π t σy √(2π t d / √3), N.
    pub alexander_ring_n: f64,
    /// Johnson, Soden & Al-Hassani (1977) diamond mode, n = 2..=5.
    pub diamond: Vec<DiamondReference>,
    /// DeRuntz & Hodge (1963) lateral load at δ = 0: 4 σy t² l / (√3 d), N.
    pub deruntz_hodge_initial_n: f64,
    /// DeRuntz & Hodge load averaged over δ ∈ [0, U]; `None` when U ≥ d (the formula ends there).
    pub deruntz_hodge_mean_n: Option<f64>,
    /// Euler load of the whole column with clamped ends, 4π² E I / l², N.
    pub euler_clamped_n: f64,
    /// The round metal tube's axial closed forms.
    pub metal: MetalTube,
    /// The reference a report compares the run's mean load with.
    pub primary: Primary,
    /// Value of `primary`, N; null where it does not reach the case (a lateral crush to the
    /// diameter): no number stands in for a load the formula does not give.
    pub primary_n: Option<f64>,
}

/// Every reference load for `case`, from its cross-section.
pub fn references(case: &Case) -> References {
    match case.geometry().section {
        CrossSection::Round(c) => {
            References::Round(round(case, c.thickness_mm, c.mean_diameter_mm))
        }
        CrossSection::Rectangular(r) => References::Rectangular(rectangular::references(case, &r)),
        CrossSection::Hexagonal(h) => References::Hexagonal(hexagonal::references(case, &h)),
    }
}

/// The closed forms of a round tube of wall t and mean diameter d.
fn round(case: &Case, t: f64, d: f64) -> RoundReferences {
    let spec = case.spec();
    let geometry = case.geometry();
    let l = geometry.length_mm;
    let stresses = spec.material.flow_stresses();
    let sy = stresses.flow();
    let e = spec.material.youngs_modulus_mpa;
    let u = case.crush_distance_mm();

    let alexander_ring_n = alexander_ring(t, d, sy);
    let diamond = DIAMOND_LOBES
        .map(|n| johnson_diamond(t, d, sy, n))
        .collect();
    let deruntz_hodge_initial_n = deruntz_hodge(t, d, l, sy, 0.0);
    let deruntz_hodge_mean_n = deruntz_hodge_mean(t, d, l, sy, u);
    let euler_clamped_n = euler_clamped(t, d, l, e);
    let strain_rate_per_s = mean_strain_rate_per_s(spec.loading.material_speed_m_s(), d);
    let metal = MetalTube::of(
        t,
        d,
        stresses,
        spec.material.rate_factor(strain_rate_per_s),
        strain_rate_per_s,
        spec.material.rate != crate::solver::model::spec::RateKind::None,
    );
    let (primary, primary_n) = match geometry.mode {
        LoadingMode::Axial => (Primary::AlexanderRing, Some(alexander_ring_n)),
        LoadingMode::Lateral => (Primary::DeruntzHodgeMean, deruntz_hodge_mean_n),
    };
    RoundReferences {
        alexander_ring_n,
        diamond,
        deruntz_hodge_initial_n,
        deruntz_hodge_mean_n,
        euler_clamped_n,
        metal,
        primary,
        primary_n,
    }
}

/// The axial closed forms of a round metal tube: static, and dynamic where the material names
/// a rate law (`None` otherwise). N, mm, 1/s.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct MetalTube {
    /// The flow stress σ0 both take, (σy + σu)/2, MPa.
    pub flow_stress_mpa: f64,
    /// The yield stress σy, MPa.
    pub yield_stress_mpa: f64,
    /// The engineering ultimate stress σu of the static hardening curve, where a bar of it
    /// necks, MPa.
    pub ultimate_stress_mpa: f64,
    /// Abramowicz & Jones (1984): P = M0 (22.27 √(D/t) + 5.632) / (0.86 − 0.568 √(t/D)),
    /// M0 = (2/√3) σ0 t²/4: Alexander's ring mode with the fold's eccentricity, over the
    /// effective crushing distance δe/2H = 0.86 − 0.568 √(t/D), N.
    pub abramowicz_jones_n: f64,
    /// The same times the rate factor at the mean strain rate, N.
    pub abramowicz_jones_dynamic_n: Option<f64>,
    /// Guillow, Lu & Grzebieta (2001), 6060-T5, D/t 10–450, quasi-static:
    /// F = 72.3 M_P (D/t)^0.32, M_P = σ0 t²/4, N.
    pub guillow_n: f64,
    /// The same times the rate factor at the mean strain rate, N.
    pub guillow_dynamic_n: Option<f64>,
    /// Whether D/t lies in the range Guillow's fit was made on (10–450).
    pub guillow_in_range: bool,
    /// Alexander's fold wavelength 2H, H = √(π D t / (2√3)), mm.
    pub fold_wavelength_mm: f64,
    /// The wall's mean strain rate in the folds, V/(4R) (Abramowicz & Jones), 1/s.
    pub strain_rate_per_s: f64,
    /// The material's rate factor at that strain rate (1 without a rate law).
    pub rate_factor: f64,
}

impl MetalTube {
    /// Of the wall t, the mean diameter d (mm), the wall's stresses, the rate factor at the
    /// mean strain rate and whether the material has a rate law.
    pub fn of(
        t: f64,
        d: f64,
        stresses: FlowStresses,
        rate_factor: f64,
        strain_rate_per_s: f64,
        rate_law: bool,
    ) -> MetalTube {
        let sigma0 = stresses.flow();
        let abramowicz_jones_n = abramowicz_jones(t, d, sigma0);
        let guillow_n = guillow(t, d, sigma0);
        let dynamic = |p: f64| rate_law.then_some(p * rate_factor);
        let d_over_t = d / t;
        MetalTube {
            flow_stress_mpa: sigma0,
            yield_stress_mpa: stresses.yield_stress,
            ultimate_stress_mpa: stresses.ultimate,
            abramowicz_jones_n,
            abramowicz_jones_dynamic_n: dynamic(abramowicz_jones_n),
            guillow_n,
            guillow_dynamic_n: dynamic(guillow_n),
            guillow_in_range: (10.0..=450.0).contains(&d_over_t),
            fold_wavelength_mm: 2.0 * alexander_half_fold(t, d),
            strain_rate_per_s,
            rate_factor,
        }
    }
}

/// Abramowicz & Jones's modified Alexander with the effective crushing distance, N.
pub fn abramowicz_jones(t: f64, d: f64, sigma0: f64) -> f64 {
    let m0 = 2.0 / 3f64.sqrt() * sigma0 * t * t / 4.0;
    m0 * (22.27 * (d / t).sqrt() + 5.632) / (0.86 - 0.568 * (t / d).sqrt())
}

/// Guillow, Lu & Grzebieta's fit F = 72.3 M_P (D/t)^0.32, M_P = σ0 t²/4, N.
pub fn guillow(t: f64, d: f64, sigma0: f64) -> f64 {
    72.3 * sigma0 * t * t / 4.0 * (d / t).powf(0.32)
}

/// Alexander's half fold length H = √(π D t / (2√3)), mm: the H at which his mean load is
/// least (bending 2π² R M0 / H, stretching π σ0 t H, M0 = σ0 t² / (2√3)).
pub fn alexander_half_fold(t: f64, d: f64) -> f64 {
    (PI * d * t / (2.0 * 3f64.sqrt())).sqrt()
}

/// Alexander's fold length 2H of the case's wall, mm: twice [`alexander_half_fold`] of its
/// mean width and wall thickness (the paper's tube: 2H = 16.1 mm; its 50 mm crush makes three
/// folds and a fourth).
pub fn fold_length_mm(case: &Case) -> f64 {
    let section = case.geometry().section;
    let (d, t) = (section.width_mm(), section.thickness_mm());
    2.0 * alexander_half_fold(t, d)
}

/// The mean strain rate of the folds, V/(4R), of the plate speed V (m/s) and the mean
/// diameter d (mm), 1/s.
pub fn mean_strain_rate_per_s(speed_m_s: f64, d: f64) -> f64 {
    speed_m_s * 1e3 / (2.0 * d)
}

/// Alexander's axisymmetric mean load, N.
pub fn alexander_ring(t: f64, d: f64, sy: f64) -> f64 {
    PI * t * sy * (2.0 * PI * t * d / 3f64.sqrt()).sqrt()
}

/// Johnson, Soden & Al-Hassani's n-lobe diamond mode.
pub fn johnson_diamond(t: f64, d: f64, sy: f64, lobes: u32) -> DiamondReference {
    let n = lobes as f64;
    let half = PI / (2.0 * n);
    let a = 1.0 + n / half.sin() + n / half.tan();
    let hinge_radius_mm = (d / a) * ((1.0 + 0.5 * a * half * half.tan()).sqrt() - 1.0);
    let area = PI * d * t;
    let stress = |bracket: f64| sy * (t / d) * bracket / 3f64.sqrt();
    DiamondReference {
        lobes,
        a,
        hinge_radius_mm,
        stationary_n: stress(a) * area,
        travelling_n: stress(a + d / hinge_radius_mm) * area,
    }
}

/// DeRuntz & Hodge's lateral load at deflection δ < d, N.
pub fn deruntz_hodge(t: f64, d: f64, l: f64, sy: f64, delta: f64) -> f64 {
    4.0 * sy * t * t * l / (3f64.sqrt() * d * (1.0 - delta / d).sqrt())
}

/// Mean of DeRuntz & Hodge's load over δ ∈ [0, U]: with P(δ) = P₀ / √(1 − δ/d),
/// (1/U) ∫₀ᵁ P dδ = 2 P₀ d (1 − √(1 − U/d)) / U. `None` for U ≥ d; P₀ for U = 0.
pub fn deruntz_hodge_mean(t: f64, d: f64, l: f64, sy: f64, u: f64) -> Option<f64> {
    let p0 = deruntz_hodge(t, d, l, sy, 0.0);
    if u >= d {
        None
    } else if u <= 0.0 {
        Some(p0)
    } else {
        Some(2.0 * p0 * d * (1.0 - (1.0 - u / d).sqrt()) / u)
    }
}

/// Euler load of a clamped–clamped tube, N; I = π(d_o⁴ − d_i⁴)/64 with d_o,i = d ± t.
pub fn euler_clamped(t: f64, d: f64, l: f64, e: f64) -> f64 {
    let (d_o, d_i) = (d + t, d - t);
    let i = PI * (d_o.powi(4) - d_i.powi(4)) / 64.0;
    4.0 * PI * PI * e * i / (l * l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Limits;

    fn close(got: f64, want: f64, rel: f64) {
        assert!((got / want - 1.0).abs() < rel, "got {got}, want {want}");
    }

    #[test]
    fn alexander_for_the_pvc_tube() {
        // π·3.2·65.5 = 658.47; 2π·3.2·22.2/√3 = 257.70, √ = 16.053; product 10 570.7 N.
        close(alexander_ring(3.2, 22.2, 65.5), 10_570.7, 1e-4);
    }

    #[test]
    fn johnson_two_lobes() {
        // n = 2: π/4, cosec = √2, cot = 1 → A = 1 + 2√2 + 2 = 5.8284.
        // r* = (22.2/5.8284)(√(1 + 2.9142·0.7854·1) − 1) = 3.8089·(1.81349 − 1) = 3.0986 mm.
        // σ̄ = 65.5·(3.2/22.2)/√3 = 5.4510 MPa per unit bracket; π D t = 223.18 mm².
        // stationary 5.4510·5.8284·223.18 = 7 090.6 N; travelling ·(5.8284 + 7.1646) = 15 806.6 N.
        let r = johnson_diamond(3.2, 22.2, 65.5, 2);
        close(r.a, 5.828_427, 1e-6);
        close(r.hinge_radius_mm, 3.0986, 1e-4);
        close(r.stationary_n, 7_090.6, 1e-4);
        close(r.travelling_n, 15_806.6, 1e-4);
        // n = 3: π/6, cosec = 2, cot = √3 → A = 1 + 6 + 3√3 = 12.196.
        close(johnson_diamond(3.2, 22.2, 65.5, 3).a, 12.196_152, 1e-6);
    }

    #[test]
    fn deruntz_hodge_start_and_mean() {
        // P₀ = 4·65.5·3.2²·76.2 / (√3·22.2) = 204 372.5 / 38.451 = 5 316.7 N.
        close(deruntz_hodge(3.2, 22.2, 76.2, 65.5, 0.0), 5_316.7, 1e-4);
        // U = 12.5: 2·5316.7·22.2·(1 − √(1 − 12.5/22.2))/12.5 = 18 885.0·(1 − 0.66097) = 6 401.8 N.
        let mean = deruntz_hodge_mean(3.2, 22.2, 76.2, 65.5, 12.5).unwrap();
        close(mean, 6_401.8, 1e-4);
        // The closed form agrees with a fine midpoint sum of P(δ).
        let n = 100_000;
        let sum: f64 = (0..n)
            .map(|i| deruntz_hodge(3.2, 22.2, 76.2, 65.5, 12.5 * (i as f64 + 0.5) / n as f64))
            .sum();
        close(mean, sum / n as f64, 1e-6);
        assert_eq!(deruntz_hodge_mean(3.2, 22.2, 76.2, 65.5, 30.0), None);
    }

    #[test]
    fn euler_for_the_pvc_tube() {
        // I = π(25.4⁴ − 19⁴)/64 = π(416 231.4 − 130 321)/64 = 14 034.6 mm⁴;
        // P = 4π²·3378.4·14 034.6 / 76.2² = 322 375 N.
        close(euler_clamped(3.2, 22.2, 76.2, 3378.4), 322_375.0, 1e-5);
    }

    /// Alexander's load is 2π σ0 t H at his fold length H: the fold length is the one his
    /// load is least at.
    #[test]
    fn alexander_s_fold_is_where_his_load_is_least() {
        let (t, d, sy) = (2.0, 50.0, 120.0);
        let h = alexander_half_fold(t, d);
        close(2.0 * PI * sy * t * h, alexander_ring(t, d, sy), 1e-12);
        let m0 = sy * t * t / (2.0 * 3f64.sqrt());
        let load = |h: f64| 2.0 * PI * PI * (d / 2.0) * m0 / h + PI * sy * t * h;
        close(load(h), alexander_ring(t, d, sy), 1e-12);
        assert!(load(0.99 * h) > load(h) && load(1.01 * h) > load(h));
    }

    /// By hand: t 2, D 50 mm, σ0 120 MPa (D/t 25).
    /// Abramowicz & Jones: M0 = 2/√3 · 120 · 4/4 = 138.564 N·mm/mm;
    /// (22.27 · 5 + 5.632) / (0.86 − 0.568 · 0.2) = 116.982 / 0.7464 = 156.729; P = 21 717 N.
    /// Guillow: 72.3 · 120 · 4/4 · 25^0.32 = 8 676 · 2.80115 = 24 303 N.
    /// Mild steel at 10 m/s: V/(4R) = 10 000 / 100 = 100 /s, R = 1 + (100/40.4)^(1/5) = 2.198736.
    #[test]
    fn metal_tube_closed_forms_by_hand() {
        close(abramowicz_jones(2.0, 50.0, 120.0), 21_717.0, 1e-4);
        close(guillow(2.0, 50.0, 120.0), 24_303.0, 1e-4);
        assert_eq!(mean_strain_rate_per_s(10.0, 50.0), 100.0);
        let steel = Case::from_json(
            r#"{"material": {"preset": "mild_steel"},
                "tube": {"thickness_mm": 2, "mean_diameter_mm": 50, "length_mm": 150},
                "loading": {"plate_speed_m_s": 10}}"#,
            &Limits::default(),
        )
        .unwrap();
        let m = round_of(&steel).metal;
        close(m.rate_factor, 2.198_736, 1e-6);
        close(
            m.abramowicz_jones_dynamic_n.unwrap(),
            m.abramowicz_jones_n * m.rate_factor,
            1e-12,
        );
        assert!(m.guillow_in_range);
        // No rate law: no dynamic value, a factor of 1.
        let pvc = round_of(&Case::from_json("{}", &Limits::default()).unwrap()).metal;
        assert_eq!(
            (pvc.abramowicz_jones_dynamic_n, pvc.rate_factor),
            (None, 1.0)
        );
        assert!(!pvc.guillow_in_range, "d/t 6.9");
    }

    /// A hardening wall's closed forms take (σy + σu)/2, a perfectly plastic one's σy.
    /// Stainless 304 (Swift K 1400, n 0.44 from σy 205): necks at ε₀ + ε_p = n, σu = 636.3 MPa
    /// engineering (by hand in the hardening law's tests), σ₀ = 420.65 MPa.
    #[test]
    fn a_hardening_wall_s_closed_forms_take_the_mean_of_yield_and_ultimate() {
        let stainless = Case::from_json(
            r#"{"material": {"preset": "stainless_304"},
                "tube": {"thickness_mm": 1.5, "mean_diameter_mm": 50, "length_mm": 100}}"#,
            &Limits::default(),
        )
        .unwrap();
        let r = round_of(&stainless);
        let m = r.metal;
        assert_eq!(m.yield_stress_mpa, 205.0);
        close(m.ultimate_stress_mpa, 636.3, 1e-4);
        close(m.flow_stress_mpa, 420.65, 1e-4);
        close(
            m.abramowicz_jones_n,
            abramowicz_jones(1.5, 50.0, 420.65),
            1e-4,
        );
        close(m.guillow_n, guillow(1.5, 50.0, 420.65), 1e-4);
        close(r.alexander_ring_n, alexander_ring(1.5, 50.0, 420.65), 1e-4);
        let pvc = round_of(&Case::from_json("{}", &Limits::default()).unwrap());
        assert_eq!(
            (
                pvc.metal.flow_stress_mpa,
                pvc.metal.yield_stress_mpa,
                pvc.metal.ultimate_stress_mpa
            ),
            (65.5, 65.5, 65.5)
        );
        close(pvc.alexander_ring_n, alexander_ring(3.2, 22.2, 65.5), 1e-12);
    }

    /// A round case's references.
    fn round_of(case: &Case) -> RoundReferences {
        match references(case) {
            References::Round(r) => r,
            other => panic!("a round case has round references, not {other:?}"),
        }
    }

    #[test]
    fn primary_follows_the_loading() {
        let axial = Case::from_json("{}", &Limits::default()).unwrap();
        let r = round_of(&axial);
        assert_eq!(r.primary, Primary::AlexanderRing);
        assert_eq!(r.primary_n, Some(r.alexander_ring_n));
        assert_eq!(
            r.diamond.iter().map(|d| d.lobes).collect::<Vec<_>>(),
            vec![2, 3, 4, 5]
        );
        // Axial crush of 50 mm is past the lateral formula's range.
        assert_eq!(r.deruntz_hodge_mean_n, None);

        let lateral =
            Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
        let r = round_of(&lateral);
        assert_eq!(r.primary, Primary::DeruntzHodgeMean);
        close(r.primary_n.unwrap(), 6_401.8, 1e-4);
        // A summary stored with 0 for a primary that did not exist reads as none.
        let mut stored = r.clone();
        stored.primary_n = Some(0.0);
        assert_eq!(References::Round(stored).primary_n(), None);
    }
}
