//! The checks of the material section's laws ([`super::super::checks::material`] calls them):
//! a hardening law and a rate law with every constant they need, in range, and none they do
//! not read; a curve that starts at the yield stress, increases in strain and does not soften.

use super::super::checker::Checker;
use super::flow::MAX_CURVE_POINTS;
use super::given::{HardeningKind, Material, RateKind};

/// A constant a law needs: given, finite and in `range` (`reason` says which).
fn constant(c: &mut Checker, field: &str, v: Option<f64>, law: &str, ok: bool, reason: &str) {
    match v {
        None => c.fail(field, &format!("is required with {law}")),
        Some(v) if !(v.is_finite() && ok) => c.fail(field, reason),
        Some(_) => {}
    }
}

/// A constant the section gave that its law does not read.
fn unused(c: &mut Checker, field: &str, given: bool, which: &str) {
    if given {
        c.fail(
            field,
            &format!("is used only with {which}; leave it out or set that law"),
        );
    }
}

/// The hardening law: a curve from ε_p = 0 whose strains increase and whose stresses do not
/// decrease (a softening wall is not modelled), starting at the yield stress; or Swift's and
/// Ludwik's K and n.
pub(in crate::solver::model) fn hardening(c: &mut Checker, m: &Material) {
    let table = m.hardening == HardeningKind::Table;
    let power = matches!(m.hardening, HardeningKind::Swift | HardeningKind::Ludwik);
    let curve = "material.hardening_curve";
    unused(
        c,
        curve,
        !table && m.hardening_curve.is_some(),
        "hardening table",
    );
    unused(
        c,
        "material.hardening_extrapolation",
        !table && m.hardening_extrapolation.is_some(),
        "hardening table",
    );
    for (field, v) in [
        ("material.hardening_k_mpa", m.hardening_k_mpa),
        ("material.hardening_n", m.hardening_n),
    ] {
        unused(c, field, !power && v.is_some(), "hardening swift or ludwik");
    }
    if table {
        match m.hardening_curve.as_deref() {
            None => c.fail(curve, "is required with hardening table"),
            Some(points) => curve_points(c, points, m.yield_stress_mpa),
        }
    }
    if power {
        let law = format!("hardening {}", hardening_name(m.hardening));
        let k = m.hardening_k_mpa;
        let n = m.hardening_n;
        let k_ok = k.is_some_and(|k| k > 0.0);
        constant(
            c,
            "material.hardening_k_mpa",
            k,
            &law,
            k_ok,
            "must be a finite number > 0",
        );
        let n_ok = n.is_some_and(|n| n > 0.0 && n <= 1.0);
        constant(
            c,
            "material.hardening_n",
            n,
            &law,
            n_ok,
            "must be in (0, 1]",
        );
        if let (HardeningKind::Swift, Some(k), Some(n)) = (m.hardening, k, n) {
            let sy = m.yield_stress_mpa;
            let e0 = (sy / k).powf(1.0 / n);
            if k_ok && n_ok && sy.is_finite() && sy > 0.0 && !(e0.is_finite() && e0 > 0.0) {
                c.fail(
                    "material.hardening_n",
                    "gives Swift's offset strain (yield_stress_mpa / hardening_k_mpa)^(1/n) \
                     too large or too small to compute",
                );
            }
        }
    }
}

fn hardening_name(h: HardeningKind) -> &'static str {
    match h {
        HardeningKind::None => "none",
        HardeningKind::Table => "table",
        HardeningKind::Swift => "swift",
        HardeningKind::Ludwik => "ludwik",
    }
}

/// A tabulated curve: 1 to [`MAX_CURVE_POINTS`] points of finite, non-negative strain and
/// positive stress; the first at ε_p = 0 with the yield stress; strains increasing, stresses
/// not decreasing.
fn curve_points(c: &mut Checker, points: &[[f64; 2]], yield_stress: f64) {
    let curve = "material.hardening_curve";
    if points.is_empty() || points.len() > MAX_CURVE_POINTS {
        c.fail(
            curve,
            &format!("must have 1 to {MAX_CURVE_POINTS} [plastic strain, stress MPa] points"),
        );
        return;
    }
    for (i, [e, s]) in points.iter().enumerate() {
        if !(e.is_finite() && *e >= 0.0 && s.is_finite() && *s > 0.0) {
            c.fail(
                curve,
                &format!(
                    "point {i}: the plastic strain must be a finite number >= 0 and the stress \
                     a finite number > 0 (MPa)"
                ),
            );
            return;
        }
    }
    if points[0][0] != 0.0 {
        c.fail(
            curve,
            "must start at plastic strain 0 (its stress is the yield stress)",
        );
    }
    for (i, w) in points.windows(2).enumerate() {
        if w[1][0] <= w[0][0] {
            c.fail(
                curve,
                &format!(
                    "is not increasing in strain: point {} is not past point {i}",
                    i + 1
                ),
            );
            return;
        }
        if w[1][1] < w[0][1] {
            c.fail(
                curve,
                &format!(
                    "falls from point {i} to point {}: stresses must not decrease (softening \
                     is not modelled)",
                    i + 1
                ),
            );
            return;
        }
    }
    if yield_stress.is_finite() && points[0][1] != yield_stress {
        c.fail(
            "material.yield_stress_mpa",
            &format!(
                "must equal the curve's first stress ({} MPa) when a hardening curve is given; \
                 leave it out to take the curve's",
                points[0][1]
            ),
        );
    }
}

/// The rate law: Cowper–Symonds' D and q, or Johnson–Cook's C and reference rate.
pub(in crate::solver::model) fn rate(c: &mut Checker, m: &Material) {
    let cs = m.rate == RateKind::CowperSymonds;
    let jc = m.rate == RateKind::JohnsonCook;
    for (field, v) in [
        ("material.cowper_symonds_d_per_s", m.cowper_symonds_d_per_s),
        ("material.cowper_symonds_q", m.cowper_symonds_q),
    ] {
        unused(c, field, !cs && v.is_some(), "rate cowper_symonds");
    }
    for (field, v) in [
        ("material.johnson_cook_c", m.johnson_cook_c),
        (
            "material.johnson_cook_reference_rate_per_s",
            m.johnson_cook_reference_rate_per_s,
        ),
    ] {
        unused(c, field, !jc && v.is_some(), "rate johnson_cook");
    }
    let positive = |v: Option<f64>| v.is_some_and(|v| v > 0.0);
    if cs {
        let law = "rate cowper_symonds";
        let d = m.cowper_symonds_d_per_s;
        constant(
            c,
            "material.cowper_symonds_d_per_s",
            d,
            law,
            positive(d),
            "must be a finite number > 0 (1/s)",
        );
        let q = m.cowper_symonds_q;
        let q_ok = q.is_some_and(|q| (1.0..=100.0).contains(&q));
        constant(
            c,
            "material.cowper_symonds_q",
            q,
            law,
            q_ok,
            "must be in [1, 100]",
        );
    }
    if jc {
        let law = "rate johnson_cook";
        let cc = m.johnson_cook_c;
        let c_ok = cc.is_some_and(|v| (0.0..=1.0).contains(&v));
        constant(
            c,
            "material.johnson_cook_c",
            cc,
            law,
            c_ok,
            "must be in [0, 1]",
        );
        let r = m.johnson_cook_reference_rate_per_s;
        constant(
            c,
            "material.johnson_cook_reference_rate_per_s",
            r,
            law,
            positive(r),
            "must be a finite number > 0 (1/s)",
        );
    }
}
