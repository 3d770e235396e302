//! The metal's law against closed forms: a uniaxial bar follows its hardening curve (tabulated,
//! Swift, Ludwik), the flow stress at a constant plastic strain rate is the rate law's, four
//! lanes give one's bits, and the plastic work is the flow stress times the plastic strain.

use super::flow::{Extrapolation, Hardening, Rate, Table};
use super::*;
use nalgebra::{Matrix3, Vector3};

const E: Real = 70_000.0;
const NU: Real = 0.3;

/// Drives `law` in uniaxial stress along x at a total strain rate `rate` (1/ms) with steps of
/// `dt` ms to the total strain `strain`, the particle's plastic strain advancing with each
/// step; the lateral strain rate found by iterating to σyy = σzz = 0. Returns (ε_p, σxx, the
/// plastic work density booked, ∫σ:dε_p by the trapezoid over the steps) at the end, and the
/// largest relative error of σxx against `expect(ε_p)` once past the first 0.2 % of plastic
/// strain.
fn uniaxial(
    law: &Metal,
    rate: Real,
    dt: Real,
    strain: Real,
    expect: impl Fn(Real) -> Real,
) -> (Real, Real, Real, Real) {
    let mut s = [0.0; 6];
    let mut at = Point::FRESH;
    let (mut work, mut worst) = (0.0, 0.0f64);
    let steps = (strain / (rate * dt)).round() as usize;
    for _ in 0..steps {
        let mut lat = -0.5 * rate;
        for _ in 0..60 {
            let mut trial = s;
            let l = Matrix3::from_diagonal(&Vector3::new(rate, lat, lat));
            law.update(&mut trial, &l, dt, at);
            lat -= trial[1] / (law.p_wave_modulus() * dt) * 0.9;
        }
        let l = Matrix3::from_diagonal(&Vector3::new(rate, lat, lat));
        let inc = law.update(&mut s, &l, dt, at);
        at.plastic_strain += inc.plastic_strain;
        work += inc.plastic_work;
        assert!(s[1].abs() < 1e-6 * s[0].abs().max(1.0), "lateral {s:?}");
        if at.plastic_strain > 2e-3 {
            let want = expect(at.plastic_strain);
            worst = worst.max((s[0] / want - 1.0).abs());
        }
    }
    (at.plastic_strain, s[0], work, worst)
}

/// The bar in tension at 1e-5 /ms (0.01 /s), steps of 1 ms: 1 % in stress along a tabulated
/// curve (flat and continued past its end), Swift and Ludwik. The return is implicit and the
/// Jaumann rate adds nothing in uniaxial tension, so only round-off and the lateral iteration
/// are left: measured at most 1e-12.
#[test]
fn a_uniaxial_bar_follows_its_hardening_curve() {
    let curve = [[0.0, 120.0], [0.02, 150.0], [0.08, 180.0], [0.2, 200.0]];
    let table = |ext| Metal::new(E, NU, Hardening::Table(Table::new(&curve, ext)), Rate::None);
    let along = |e: Real| {
        let k = curve
            .partition_point(|p| p[0] <= e)
            .clamp(1, curve.len() - 1)
            - 1;
        let ([e0, s0], [e1, s1]) = (curve[k], curve[k + 1]);
        s0 + (s1 - s0) / (e1 - e0) * (e - e0)
    };
    let flat = |e: Real| if e >= 0.2 { 200.0 } else { along(e) };
    let (ep, sigma, _, worst) = uniaxial(&table(Extrapolation::Flat), 1e-5, 1.0, 0.3, flat);
    assert!(
        ep > 0.29 && worst < 0.01,
        "flat table: ε_p {ep}, σ {sigma}, worst {worst}"
    );
    let (ep, _, _, worst) = uniaxial(&table(Extrapolation::LastSlope), 1e-5, 1.0, 0.3, along);
    assert!(ep > 0.29 && worst < 0.01, "sloped table: worst {worst}");
    let swift = Hardening::swift(250.0, 600.0, 0.2);
    let law = Metal::new(E, NU, swift, Rate::None);
    let (_, _, _, worst) = uniaxial(&law, 1e-5, 1.0, 0.3, |e| swift.at(e).0);
    assert!(worst < 0.01, "swift: worst {worst}");
    let ludwik = Hardening::Ludwik {
        yield_stress: 324.0,
        k: 114.0,
        n: 0.42,
    };
    let law = Metal::new(E, NU, ludwik, Rate::None);
    let (_, _, _, worst) = uniaxial(&law, 1e-5, 1.0, 0.3, |e| ludwik.at(e).0);
    assert!(worst < 0.01, "ludwik: worst {worst}");
}

/// At a constant total strain rate the plastic strain rate settles at it once the stress
/// stops growing (perfect plasticity): the flow stress is σy R(ε̇) within 1 % from 2 % of
/// plastic strain on, at rates from well below D to well above it (Cowper–Symonds, mild
/// steel's D = 40.4 /s, q = 5) and for Johnson–Cook's term (C = 0.002, ε̇₀ = 1 /s). Steps of
/// 1e-5 to 1 ms keep the strain per step at 1e-4 or less. Measured: 1e-13 at most.
#[test]
fn the_flow_stress_at_a_constant_plastic_strain_rate_is_the_rate_law_s() {
    let flat = Hardening::Table(Table::new(&[[0.0, 250.0]], Extrapolation::Flat));
    for (rate_law, per_s) in [
        (Rate::cowper_symonds(40.4, 5.0), [0.1, 40.4, 1000.0]),
        (Rate::johnson_cook(0.002, 1.0), [0.1, 100.0, 10_000.0]),
    ] {
        let law = Metal::new(210_000.0, NU, flat, rate_law);
        for rate in per_s {
            let per_ms = rate * 1e-3;
            let dt = (1e-4 / per_ms).min(1.0);
            let want = 250.0 * rate_law.at(per_ms).0;
            let (ep, sigma, _, _) = uniaxial(&law, per_ms, dt, 0.05, |_| want);
            assert!(ep > 0.04, "{rate}/s: ε_p {ep}");
            assert!(
                (sigma / want - 1.0).abs() < 0.01,
                "{rate_law:?} at {rate}/s: σ {sigma} vs {want}"
            );
        }
    }
    // The factor itself: Cowper–Symonds doubles the stress at ε̇ = D.
    assert!((Rate::cowper_symonds(40.4, 5.0).at(0.0404).0 - 2.0).abs() < 1e-12);
}

/// Each step books the flow stress at its end times its plastic strain increment, and over a
/// hardening bar that sum is ∫σ:dε_p: the trapezoid of σxx dε_p over the steps agrees within
/// 0.1 % (the steps' own stresses differ by the hardening over one step).
#[test]
fn the_plastic_work_is_the_integral_of_the_hardened_flow_stress() {
    let swift = Hardening::swift(250.0, 600.0, 0.2);
    let law = Metal::new(E, NU, swift, Rate::cowper_symonds(40.4, 5.0));
    let mut s = [0.0; 6];
    let mut at = Point::FRESH;
    let (mut booked, mut integral, mut last_sigma) = (0.0, 0.0, 0.0);
    for _ in 0..3000 {
        let l = Matrix3::from_diagonal(&Vector3::new(-1e-4, 5e-5, 5e-5));
        let inc = law.update(&mut s, &l, 1.0, at);
        at.plastic_strain += inc.plastic_strain;
        booked += inc.plastic_work;
        let sigma = von_mises(&s);
        integral += 0.5 * (sigma + last_sigma) * inc.plastic_strain;
        last_sigma = sigma;
        assert!((inc.plastic_work - sigma * inc.plastic_strain).abs() <= 1e-9 * inc.plastic_work);
    }
    assert!(at.plastic_strain > 0.2, "{}", at.plastic_strain);
    assert!(
        (booked / integral - 1.0).abs() < 1e-3,
        "{booked} vs {integral}"
    );
}

/// Four particles at once give each particle's bits from the scalar update: elastic and
/// plastic lanes mixed, different plastic strains and strength factors, a zero lane; Swift
/// with Cowper–Symonds, and a table with Johnson–Cook.
#[test]
fn four_lanes_of_a_metal_give_the_scalar_bits() {
    let table = Table::new(&[[0.0, 100.0], [0.1, 140.0]], Extrapolation::LastSlope);
    let laws = [
        Metal::new(
            E,
            NU,
            Hardening::swift(100.0, 300.0, 0.25),
            Rate::cowper_symonds(6500.0, 4.0),
        ),
        Metal::new(
            E,
            NU,
            Hardening::Table(table),
            Rate::johnson_cook(0.01, 1.0),
        ),
    ];
    for m in laws {
        for k in 0..100 {
            let f = |j: usize| ((k * 11 + j * 5) as Real * 0.377).sin();
            let ls: [Matrix3<Real>; 4] = std::array::from_fn(|lane| {
                let scale = [1e-3, 3e-2, 1e-4, 0.0][(lane + k) % 4];
                Matrix3::from_fn(|i, j| scale * f(3 * i + j + 9 * lane))
            });
            let starts: [Sym; 4] =
                std::array::from_fn(|lane| std::array::from_fn(|j| 60.0 * f(50 + j + 6 * lane)));
            let points: [Point; 4] = std::array::from_fn(|lane| Point {
                strength_scale: [1.0, 0.01, 1.0, 0.5][lane],
                plastic_strain: 0.3 * f(70 + lane).abs(),
            });
            let mut lanes = starts;
            let four = m.update_four(&mut lanes, &ls, 1e-3, points);
            for lane in 0..4 {
                let mut one = starts[lane];
                let inc = m.update(&mut one, &ls[lane], 1e-3, points[lane]);
                for j in 0..6 {
                    assert_eq!(one[j].to_bits(), lanes[lane][j].to_bits(), "{k} {lane} {j}");
                }
                assert_eq!(
                    inc.plastic_strain.to_bits(),
                    four[lane].plastic_strain.to_bits()
                );
                assert_eq!(
                    inc.stress_power.to_bits(),
                    four[lane].stress_power.to_bits()
                );
                assert_eq!(
                    inc.plastic_work.to_bits(),
                    four[lane].plastic_work.to_bits()
                );
            }
        }
    }
}

/// The return lands on the surface: after a large plastic step the von Mises stress is the
/// flow stress at the end of the step (hardened strain, the step's own rate) to 1e-9, for a
/// weak (triggered) particle too.
#[test]
fn the_return_lands_on_the_hardened_rate_scaled_surface() {
    let swift = Hardening::swift(250.0, 600.0, 0.2);
    let rate = Rate::cowper_symonds(40.4, 5.0);
    let m = Metal::new(210_000.0, NU, swift, rate);
    for scale in [1.0, 0.25] {
        let at = Point {
            strength_scale: scale,
            plastic_strain: 0.1,
        };
        let mut s = [0.0; 6];
        let dt = 1e-3;
        let l = Matrix3::from_diagonal(&Vector3::new(-2.0, 1.0, 1.0));
        let inc = m.update(&mut s, &l, dt, at);
        assert!(inc.plastic_strain > 0.0);
        let flow =
            scale * swift.at(0.1 + inc.plastic_strain).0 * rate.at(inc.plastic_strain / dt).0;
        assert!(
            (von_mises(&s) / flow - 1.0).abs() < 1e-9,
            "{} vs {flow}",
            von_mises(&s)
        );
        assert!((inc.plastic_work / (flow * inc.plastic_strain) - 1.0).abs() < 1e-9);
    }
    // Inside the surface nothing flows and the stress is the trial's.
    let mut s = [0.0; 6];
    let l = Matrix3::from_diagonal(&Vector3::new(-1e-5, 5e-6, 5e-6));
    let inc = m.update(&mut s, &l, 1e-3, Point::FRESH);
    assert_eq!((inc.plastic_strain, inc.plastic_work), (0.0, 0.0));
}
