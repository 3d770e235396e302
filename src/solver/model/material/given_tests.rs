//! The material section as a case gives it: a preset fills what the section leaves out, a
//! named law drops the preset's constants of that law, the paper's PVC still runs the plain J2
//! law, and every bad law is refused with its field and the reason.

use super::flow::{Extrapolation, Hardening, Rate, Table};
use super::given::{HardeningKind, RateKind};
use super::preset::Preset;
use super::{MaterialLaw, Metal, J2};
use crate::solver::model::case::Case;
use crate::solver::model::limits::{CaseError, FieldError, Limits};

/// The case of `material` (JSON of the section), checked.
fn case(material: &str) -> Result<Case, CaseError> {
    Case::from_json(
        &format!(r#"{{"material": {material}}}"#),
        &Limits::default(),
    )
}

/// The errors of a refused section.
fn refused(material: &str) -> Vec<FieldError> {
    match case(material) {
        Err(CaseError::Invalid(errors)) => errors,
        other => panic!(
            "{material}: not refused field by field: {:?}",
            other.map(|_| ())
        ),
    }
}

/// Whether `errors` name `field` with a reason that contains `reason`.
fn names(errors: &[FieldError], field: &str, reason: &str) -> bool {
    errors
        .iter()
        .any(|e| e.field == field && e.reason.contains(reason))
}

#[test]
fn the_paper_s_pvc_runs_the_perfectly_plastic_j2_law() {
    for section in ["{}", r#"{"preset": "pvc"}"#] {
        let law = MaterialLaw::of(&case(section).unwrap().spec().material);
        assert_eq!(
            law,
            MaterialLaw::J2(J2::new(3378.4, 0.42, 65.5)),
            "{section}"
        );
    }
}

#[test]
fn a_preset_fills_the_section_and_a_field_overrides_it() {
    let m = case(r#"{"preset": "mild_steel", "yield_stress_mpa": 300}"#)
        .unwrap()
        .spec()
        .material
        .clone();
    assert_eq!(
        (m.yield_stress_mpa, m.youngs_modulus_mpa),
        (300.0, 210_000.0)
    );
    assert_eq!(m.rate, RateKind::CowperSymonds);
    assert_eq!(
        (m.cowper_symonds_d_per_s, m.cowper_symonds_q),
        (Some(40.4), Some(5.0))
    );
    let flat = Hardening::Table(Table::new(&[[0.0, 300.0]], Extrapolation::Flat));
    assert_eq!(
        MaterialLaw::of(&m),
        MaterialLaw::Metal(Metal::new(
            210_000.0,
            0.3,
            flat,
            Rate::cowper_symonds(40.4, 5.0)
        ))
    );
    // Changing one constant keeps the preset's law and its other constants.
    let m = case(r#"{"preset": "aa6061_t6", "hardening_n": 0.5}"#).unwrap();
    let m = &m.spec().material;
    assert_eq!(
        (m.hardening, m.hardening_k_mpa, m.hardening_n),
        (HardeningKind::Ludwik, Some(114.0), Some(0.5))
    );
    assert_eq!(m.rate, RateKind::JohnsonCook);
}

#[test]
fn every_preset_passes_its_own_checks() {
    for preset in Preset::ALL {
        let c = case(&format!(r#"{{"preset": "{}"}}"#, preset.name()));
        assert!(c.is_ok(), "{}: {:?}", preset.name(), c.err());
    }
}

#[test]
fn the_stainless_preset_hardens_by_swift_from_its_yield_stress() {
    let c = case(r#"{"preset": "stainless_304"}"#).unwrap();
    let law = MaterialLaw::of(&c.spec().material);
    let MaterialLaw::Metal(metal) = law else {
        panic!("stainless 304 is a hardening metal: {law:?}")
    };
    // σ = K (ε₀ + ε_p)ⁿ with ε₀ = (σy / K)^(1/n): σ(0) = 205 MPa, and by hand at ε_p = 0.2,
    // ε₀ = (205 / 1400)^(1 / 0.44) = 0.012697, σ = 1400 · 0.212697^0.44 = 708.5 MPa.
    let e0 = (205.0_f64 / 1400.0).powf(1.0 / 0.44);
    assert!((e0 - 0.012697).abs() < 1e-5, "{e0}");
    assert!((metal.hardening.at(0.0).0 - 205.0).abs() < 1e-9);
    let at = metal.hardening.at(0.2).0;
    assert!((at - 1400.0 * (e0 + 0.2).powf(0.44)).abs() < 1e-9, "{at}");
    assert!((at - 708.5).abs() < 0.1, "{at}");
    assert_eq!(metal.rate, Rate::cowper_symonds(100.0, 10.0));
}

#[test]
fn naming_a_law_drops_the_preset_s_constants_of_that_law_only() {
    let c = case(
        r#"{"preset": "aa6061_t6", "hardening": "table",
                     "hardening_curve": [[0, 300], [0.1, 350]]}"#,
    )
    .unwrap();
    let m = &c.spec().material;
    assert_eq!((m.hardening_k_mpa, m.hardening_n), (None, None));
    assert_eq!(m.yield_stress_mpa, 300.0, "the curve's first stress");
    assert_eq!(m.rate, RateKind::JohnsonCook);
    assert_eq!(m.johnson_cook_c, Some(0.002));
    let c = case(r#"{"preset": "mild_steel", "rate": "none"}"#).unwrap();
    assert_eq!(c.spec().material.cowper_symonds_d_per_s, None);
    assert!(matches!(
        MaterialLaw::of(&c.spec().material),
        MaterialLaw::J2(_)
    ));
}

#[test]
fn a_curve_not_increasing_in_strain_is_refused_with_the_point() {
    let e =
        refused(r#"{"hardening": "table", "hardening_curve": [[0, 100], [0.1, 120], [0.1, 130]]}"#);
    assert!(
        names(
            &e,
            "material.hardening_curve",
            "not increasing in strain: point 2"
        ),
        "{e:?}"
    );
    let e = refused(r#"{"hardening": "table", "hardening_curve": [[0, 100], [0.1, 90]]}"#);
    assert!(
        names(&e, "material.hardening_curve", "stresses must not decrease"),
        "{e:?}"
    );
    let e = refused(r#"{"hardening": "table", "hardening_curve": [[0, 100], [-0.1, 120]]}"#);
    assert!(names(&e, "material.hardening_curve", "point 1"), "{e:?}");
    let e = refused(r#"{"hardening": "table", "hardening_curve": [[0.01, 100]]}"#);
    assert!(
        names(
            &e,
            "material.hardening_curve",
            "must start at plastic strain 0"
        ),
        "{e:?}"
    );
    let e = refused(r#"{"hardening": "table", "hardening_curve": []}"#);
    assert!(
        names(&e, "material.hardening_curve", "must have 1 to 100"),
        "{e:?}"
    );
    let e =
        refused(r#"{"yield_stress_mpa": 90, "hardening": "table", "hardening_curve": [[0, 100]]}"#);
    assert!(
        names(&e, "material.yield_stress_mpa", "first stress (100 MPa)"),
        "{e:?}"
    );
}

#[test]
fn a_law_without_its_constants_is_refused_naming_each() {
    let e = refused(r#"{"rate": "cowper_symonds"}"#);
    for f in [
        "material.cowper_symonds_d_per_s",
        "material.cowper_symonds_q",
    ] {
        assert!(
            names(&e, f, "is required with rate cowper_symonds"),
            "{f}: {e:?}"
        );
    }
    let e = refused(r#"{"rate": "johnson_cook", "johnson_cook_c": 0.01}"#);
    assert!(
        names(
            &e,
            "material.johnson_cook_reference_rate_per_s",
            "is required"
        ),
        "{e:?}"
    );
    let e = refused(r#"{"hardening": "swift", "hardening_k_mpa": 500}"#);
    assert!(
        names(
            &e,
            "material.hardening_n",
            "is required with hardening swift"
        ),
        "{e:?}"
    );
    let e = refused(r#"{"hardening": "table"}"#);
    assert!(
        names(&e, "material.hardening_curve", "is required"),
        "{e:?}"
    );
}

#[test]
fn negative_or_out_of_range_constants_are_refused_with_the_reason() {
    let e = refused(
        r#"{"rate": "cowper_symonds", "cowper_symonds_d_per_s": -40, "cowper_symonds_q": 0.5,
            "hardening": "ludwik", "hardening_k_mpa": 0, "hardening_n": 2}"#,
    );
    for (f, why) in [
        ("material.cowper_symonds_d_per_s", "> 0"),
        ("material.cowper_symonds_q", "[1, 100]"),
        ("material.hardening_k_mpa", "> 0"),
        ("material.hardening_n", "(0, 1]"),
    ] {
        assert!(names(&e, f, why), "{f}: {e:?}");
    }
}

#[test]
fn a_constant_without_its_law_and_a_law_on_an_elastic_wall_are_refused() {
    let e = refused(r#"{"cowper_symonds_q": 5}"#);
    assert!(
        names(
            &e,
            "material.cowper_symonds_q",
            "used only with rate cowper_symonds"
        ),
        "{e:?}"
    );
    let e = refused(
        r#"{"model": "elastic", "hardening": "swift", "hardening_k_mpa": 500, "hardening_n": 0.2}"#,
    );
    assert!(
        names(&e, "material.hardening", "elastic wall never yields"),
        "{e:?}"
    );
    // An elastic wall of a rate-sensitive preset drops the preset's rate law.
    let c = case(r#"{"preset": "mild_steel", "model": "elastic"}"#).unwrap();
    assert!(matches!(
        MaterialLaw::of(&c.spec().material),
        MaterialLaw::Elastic(_)
    ));
}

#[test]
fn non_finite_constants_are_refused() {
    use super::super::checker::Checker;
    let mut m = super::preset::Preset::MildSteel.material();
    m.cowper_symonds_q = Some(f64::INFINITY);
    m.hardening = HardeningKind::Table;
    m.hardening_curve = Some(vec![[0.0, 250.0], [f64::NAN, 300.0]]);
    let mut c = Checker::default();
    super::checks::rate(&mut c, &m);
    super::checks::hardening(&mut c, &m);
    let e = c.errors;
    assert!(names(&e, "material.cowper_symonds_q", "[1, 100]"), "{e:?}");
    assert!(names(&e, "material.hardening_curve", "finite"), "{e:?}");
}
