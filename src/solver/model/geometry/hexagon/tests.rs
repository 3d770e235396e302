//! The hexagonal section's geometry, lattice, mass and checks, against closed forms.

use super::*;
use crate::solver::model::case::{Case, CaseError, Limits};
use crate::solver::model::geometry::CrossSection;

fn close(a: Real, b: Real) {
    assert!((a - b).abs() < 1e-9, "{a} vs {b}");
}

/// Side 20, t 1.5, corners of radius 3 at the mid-line.
const HEX: Hexagon = Hexagon {
    thickness_mm: 1.5,
    side_mm: 20.0,
    corner_radius_mm: 3.0,
};

#[test]
fn the_curve_walks_the_perimeter_once_at_its_offset_from_the_mid_line() {
    let (a, c) = (HEX.apothem(), HEX.centre());
    close(a, 10.0 * 3f64.sqrt());
    for e in [-0.5, 0.0, 0.5] {
        let p = HEX.perimeter_at(e);
        let n = 6000;
        let mut length = 0.0;
        let mut last = HEX.point_at(e, 0.0);
        // It starts at the corner at +u, c + r + e out.
        close(last.0, c + 3.0 + e);
        close(last.1, 0.0);
        for i in 1..=n {
            let next = HEX.point_at(e, p * i as Real / n as Real);
            length += (next.0 - last.0).hypot(next.1 - last.1);
            // Every point lies e beyond the mid-line: e − t/2 from the outer surface.
            close(HEX.beyond_outer(next.0, next.1), e - 0.75);
            last = next;
        }
        assert!((length / p - 1.0).abs() < 1e-6, "{length} vs {p}");
        // A flat's middle (a twelfth of the way round) is a + e out, at 30°.
        let (u, v) = HEX.point_at(e, p / 12.0);
        close(u.hypot(v), a + e);
        close(v.atan2(u), PI / 6.0);
    }
}

#[test]
fn the_angle_runs_with_the_arc_length_and_the_faces_follow_it() {
    let p = HEX.perimeter_at(0.0);
    for i in 0..600 {
        let s = p * (i as Real + 0.5) / 600.0;
        let (u, v) = HEX.point_at(0.0, s);
        let want = 2.0 * PI * s / p;
        let want = if want > PI { want - 2.0 * PI } else { want };
        close(HEX.angle(u, v), want);
        // The same angle from points out and in along the normal.
        let (u1, v1) = HEX.point_at(0.0, s + 1e-6);
        let (tu, tv) = ((u1 - u) / 1e-6, (v1 - v) / 1e-6);
        for e in [-0.7, 0.7] {
            let angle = HEX.angle(u + e * tv, v - e * tu);
            assert!((angle - want).abs() < 1e-5, "{angle} vs {want} at {e}");
        }
    }
    // Face k's middle at (2k + 1)·30°; a corner (a multiple of 60°) is on no face.
    for k in 0..6 {
        let middle = (2 * k + 1) as Real * PI / 6.0;
        let (u, v) = (17.0 * middle.cos(), 17.0 * middle.sin());
        assert_eq!(HEX.face(u, v), Some(k), "face {k}");
        let corner = k as Real * PI / 3.0;
        assert_eq!(HEX.face(19.0 * corner.cos(), 19.0 * corner.sin()), None);
    }
    assert_eq!(HEX.faces(), 6);
}

/// The exact second moment reads the thin sharp hexagon's 2.5·t·s³ (J/2 with
/// J = 6·t·s·(a² + s²/12)) as t and r shrink, and a ring's π(d_o⁴ − d_i⁴)/64 when the
/// corners meet (r = a).
#[test]
fn the_second_moment_is_a_thin_hexagons_and_a_rings_at_the_limits() {
    let thin = Hexagon {
        thickness_mm: 1e-3,
        side_mm: 20.0,
        corner_radius_mm: 1e-9,
    };
    let want = 2.5 * 1e-3 * 8000.0;
    assert!((thin.second_moment_mm4() / want - 1.0).abs() < 1e-6);
    let a = 10.0 * 3f64.sqrt();
    let ring = Hexagon {
        corner_radius_mm: a,
        ..HEX
    };
    let (d_o, d_i) = (2.0 * a + 1.5, 2.0 * a - 1.5);
    let want = PI * (d_o.powi(4) - d_i.powi(4)) / 64.0;
    assert!((ring.second_moment_mm4() / want - 1.0).abs() < 1e-12);
    close(ring.area_mm2(), PI * 2.0 * a * 1.5);
}

fn hexagon_case(mode: &str, model: &str, n: u32) -> Case {
    let text = format!(
        r#"{{"tube": {{"section": "hexagonal", "side_mm": 20, "thickness_mm": 1.5,
                      "corner_radius_mm": 3, "length_mm": 40}},
            "loading": {{"mode": "{mode}", "crush_distance_mm": 8}},
            "discretization": {{"model": "{model}", "particles_through_thickness": {n}}}}}"#
    );
    Case::from_json(&text, &Limits::default()).unwrap()
}

/// The wall's area is t·P(0) = t·(6(s − 2r/√3) + 2πr) exactly (each layer's band h·P(e)
/// sums to it, the offsets averaging to 0), so the particles' volumes add up to it times l
/// and their mass to ρ·A·l within rounding (1e-12); the count is the one the checks price,
/// round(P(e)/h) per layer times round(l/h) along; every particle lies in the wall; and the
/// lattice's second moment about x, Σ V·y², matches the closed form within 0.1 % (each
/// particle stands at its piece's centre, off its centroid by O(h²/r) on the corners).
#[test]
fn a_hexagonal_tubes_volumes_and_mass_add_up_to_its_wall_and_its_count_is_exact() {
    let (t, s, r, l) = (1.5, 20.0, 3.0, 40.0);
    let area = t * (6.0 * (s - 2.0 * r / 3f64.sqrt()) + 2.0 * PI * r);
    for (mode, model, n) in [
        ("axial", "3d", 2),
        ("lateral", "3d", 3),
        ("lateral", "plane_strain", 4),
    ] {
        let case = hexagon_case(mode, model, n);
        let geometry = case.geometry();
        let CrossSection::Hexagonal(hex) = geometry.section else {
            panic!("a hexagonal case has a hexagonal section")
        };
        assert!((geometry.section.area_mm2() / area - 1.0).abs() < 1e-12);
        let (mut vol, mut count, mut outside, mut moment) = (0.0, 0u64, 0, 0.0);
        geometry.each_point(|x, v| {
            (vol, count) = (vol + v, count + 1);
            let (u, w) = match (mode, model) {
                ("axial", _) => (x.x, x.y),
                (_, "3d") => (x.y, x.z),
                _ => (x.x, x.z),
            };
            moment += v * w * w;
            let beyond = hex.beyond_outer(u, w);
            if !(-t - 1e-9..=1e-9).contains(&beyond) {
                outside += 1;
            }
        });
        let exact = area * l;
        assert!(
            (vol / exact - 1.0).abs() < 1e-12,
            "{mode} {model}: {vol} vs {exact}"
        );
        let density = case.spec().material.density_kg_m3;
        let mass = crate::solver::analysis::measures::tube_mass_g(case.spec());
        assert!((vol * density * 1e-6 / mass - 1.0).abs() < 1e-12);
        assert!((mass / (density * area * l * 1e-6) - 1.0).abs() < 1e-12);
        assert!(
            (moment / l / hex.second_moment_mm4() - 1.0).abs() < 1e-3,
            "{mode} {model}: {} vs {}",
            moment / l,
            hex.second_moment_mm4()
        );
        assert_eq!(outside, 0, "{mode} {model}: particles outside the wall");
        assert_eq!(count, case.particle_count(), "{mode} {model}");
        assert_eq!(geometry.count_f64(), count as f64, "{mode} {model}");
        let h = t / n as Real;
        let around: u64 = (0..n)
            .map(|j| (hex.perimeter_at(-t / 2.0 + (j as f64 + 0.5) * h) / h).round() as u64)
            .sum();
        let along = if model == "3d" {
            (l / h).round() as u64
        } else {
            1
        };
        assert_eq!(count, around * along, "{mode} {model}");
    }
}

/// The plates start on its ends (axial) or on its flats (lateral), a + t/2 out, and the
/// lateral bore is 2a − t.
#[test]
fn a_hexagonal_tubes_plates_start_on_it() {
    let a = 10.0 * 3f64.sqrt();
    let axial = hexagon_case("axial", "3d", 2);
    assert_eq!(axial.geometry().plates_z(), (40.0, 0.0));
    let lateral = hexagon_case("lateral", "3d", 2);
    let (top, bottom) = lateral.geometry().plates_z();
    close(top, a + 0.75);
    close(bottom, -a - 0.75);
    close(lateral.geometry().section.bore_mm(), 2.0 * a - 1.5);
}

/// The fields a hexagonal case refuses, each named.
fn refused(tube: &str, rest: &str) -> Vec<(String, String)> {
    let text = format!(r#"{{"tube": {{"section": "hexagonal", {tube}}}{rest}}}"#);
    match Case::from_json(&text, &Limits::default()) {
        Err(CaseError::Invalid(errors)) => {
            errors.into_iter().map(|e| (e.field, e.reason)).collect()
        }
        other => panic!("{text}: {other:?}"),
    }
}

#[test]
fn the_checks_name_every_bad_field_of_a_hexagonal_tube() {
    let fields = |tube: &str, rest: &str| -> Vec<String> {
        refused(tube, rest).into_iter().map(|(f, _)| f).collect()
    };
    // No side; a diameter and a rectangle's side that belong to other shapes.
    let named = refused(r#""mean_diameter_mm": 20, "side_a_mm": 3"#, "");
    let names: Vec<&str> = named.iter().map(|(f, _)| f.as_str()).collect();
    assert_eq!(
        names,
        ["tube.mean_diameter_mm", "tube.side_a_mm", "tube.side_mm"]
    );
    assert!(
        named[0].1.contains("applies to a round section only"),
        "{named:?}"
    );
    assert!(named[2].1.contains("required"), "{named:?}");
    // Negative and non-finite sides.
    assert_eq!(fields(r#""side_mm": -1"#, ""), ["tube.side_mm"]);
    // A wall as thick as the apothem (s·√3/2 = 8.66 mm for s 10).
    let thick = refused(r#""side_mm": 10, "thickness_mm": 9"#, "");
    assert_eq!(thick.len(), 1, "{thick:?}");
    assert_eq!(thick[0].0, "tube.thickness_mm");
    assert!(thick[0].1.contains("8.66"), "{}", thick[0].1);
    // Corners sharper than t/2 inside, or past the apothem.
    for r in [0.5, 9.0] {
        let refused = refused(
            &format!(r#""side_mm": 10, "thickness_mm": 2, "corner_radius_mm": {r}"#),
            "",
        );
        assert_eq!(refused.len(), 1, "r {r}: {refused:?}");
        assert_eq!(refused[0].0, "tube.corner_radius_mm");
    }
    // The axisymmetric model has no hexagon to revolve; a lateral crush past the bore
    // between the flats (2a − t = 15.3 mm for s 10, t 2).
    let axisymmetric = fields(
        r#""side_mm": 10, "thickness_mm": 2"#,
        r#", "discretization": {"model": "axisymmetric"}"#,
    );
    assert!(
        axisymmetric.contains(&"discretization.model".to_string())
            && axisymmetric.contains(&"tube.section".to_string()),
        "{axisymmetric:?}"
    );
    let past = refused(
        r#""side_mm": 10, "thickness_mm": 2"#,
        r#", "loading": {"mode": "lateral", "crush_distance_mm": 15}"#,
    );
    assert_eq!(past.len(), 1, "{past:?}");
    assert_eq!(past[0].0, "loading.crush_distance_mm");
    assert!(past[0].1.contains("side_mm"), "{}", past[0].1);
    // A round tube given a hexagon's side.
    let round = Case::from_json(r#"{"tube": {"side_mm": 10}}"#, &Limits::default());
    let Err(CaseError::Invalid(errors)) = round else {
        panic!("{round:?}")
    };
    assert_eq!(errors[0].field, "tube.side_mm");
    assert!(
        errors[0].reason.contains("hexagonal"),
        "{}",
        errors[0].reason
    );
}
