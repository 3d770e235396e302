use super::*;
use crate::solver::Limits;
use std::f64::consts::PI;

/// The default tube (t 3.2, d 22.2, l 76.2, n 4 → h 0.8) laid out as the scene does, along z.
fn axial_case() -> Case {
    Case::from_json("{}", &Limits::default()).unwrap()
}

/// A lattice of the case's tube, each particle moved by `deform(z, θ, r) -> (x, y, z)`.
fn tube(case: &Case, deform: impl Fn(Real, Real, Real) -> [Real; 3]) -> Snapshot {
    let spec = case.spec();
    let section = case.geometry().section;
    let (t, d, l) = (
        section.thickness_mm(),
        section.width_mm(),
        spec.tube.length_mm,
    );
    let h = case.spacing_mm();
    let n = spec.discretization.particles_through_thickness;
    let mut snap = Snapshot::default();
    for j in 0..n {
        let r = d / 2.0 - t / 2.0 + (j as Real + 0.5) * h;
        let around = (2.0 * PI * r / h).round() as usize;
        for k in 0..(l / h).round() as usize {
            let z = (k as Real + 0.5) * h;
            for i in 0..around {
                let th = 2.0 * PI * i as Real / around as Real;
                snap.initial_mm.push([r * th.cos(), r * th.sin(), z]);
                snap.position_mm.push(deform(z, th, r));
            }
        }
    }
    snap.plastic_strain = vec![0.0; snap.initial_mm.len()];
    snap
}

/// Moves a particle radially by w.
fn radial(z: Real, th: Real, r: Real, w: Real) -> [Real; 3] {
    [(r + w) * th.cos(), (r + w) * th.sin(), z]
}

/// Folds over the top `zone` mm of a tube of length `l`: 12 mm of wall a fold, pressed to 0.3
/// of its length, as (the share of the fold's amplitude at `z`, the current height). Below the
/// zone the wall is unfolded: (0, z).
fn folded(z: Real, l: Real, zone: Real) -> (Real, Real) {
    let start = l - zone;
    if z <= start {
        return (0.0, z);
    }
    let s = z - start;
    ((2.0 * PI * s / 12.0).sin(), start + 0.3 * s)
}

/// A particle at (z, θ, r) moved radially by `w(θ)` times the fold's share at z, and axially
/// as the folds press the wall, over the top `zone` mm of the default tube.
fn folds(case: &Case, zone: Real, w: impl Fn(Real) -> Real) -> Snapshot {
    let l = case.spec().tube.length_mm;
    tube(case, |z, th, r| {
        let (share, z) = folded(z, l, zone);
        radial(z, th, r, w(th) * share)
    })
}

#[test]
fn axisymmetric_folds_are_ring() {
    let case = axial_case();
    let snap = folds(&case, 36.0, |_| 2.0);
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::Ring, "{detail:?}");
    assert!(detail.harmonic_amplitude_mm[0] > 1.0, "{detail:?}");
    assert!(
        detail.harmonic_amplitude_mm[2..].iter().all(|&a| a < 0.01),
        "{detail:?}"
    );
    assert!(detail.max_drift_mm < 1e-6, "{detail:?}");
    assert!(
        detail.folded_slices > 0 && detail.folded_slices < detail.slices,
        "{detail:?}"
    );
}

#[test]
fn three_lobe_folds_are_diamond_3() {
    let case = axial_case();
    let snap = folds(&case, 36.0, |th| 2.0 * (3.0 * th).cos());
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::Diamond { lobes: 3 }, "{detail:?}");
    let a = &detail.harmonic_amplitude_mm;
    assert!(
        a[3] > 10.0 * a[0] && a[3] > 10.0 * a[2] && a[3] > 10.0 * a[4],
        "{detail:?}"
    );
}

#[test]
fn four_lobes_with_some_ring_content_are_diamond_4() {
    let case = axial_case();
    let snap = folds(&case, 36.0, |th| 0.5 + 2.0 * (4.0 * th).cos());
    assert_eq!(
        detect_mode(&case, &snap).0,
        CollapseMode::Diamond { lobes: 4 }
    );
}

/// What broke: an oval but unfolded part of the tube counted as folded (its radial
/// displacement was large beside the folds'), so its two lobes outvoted the folds' three.
/// Here the top 30 mm folds in three lobes and the 46 mm below are oval by 2 mm, unfolded.
#[test]
fn an_oval_unfolded_part_does_not_outvote_the_folds_lobes() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let snap = tube(&case, |z, th, r| {
        if z <= l - 30.0 {
            return radial(z, th, r, 2.0 * (2.0 * th).cos());
        }
        let (share, z) = folded(z, l, 30.0);
        radial(z, th, r, 2.0 * (3.0 * th).cos() * share)
    });
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::Diamond { lobes: 3 }, "{detail:?}");
    // Only slices in the top 30 mm (a 1.6 mm slice each: at most 19 of them) are folded.
    assert!(
        detail.folded_slices > 0 && detail.folded_slices <= 19,
        "{detail:?}"
    );
}

/// A tube that is oval along its whole length (by 4 mm, more than a wall thickness) but did
/// not fold has no folded slice.
#[test]
fn an_oval_tube_that_did_not_fold_has_no_folded_slice() {
    let case = axial_case();
    let snap = tube(&case, |z, th, r| radial(z, th, r, 4.0 * (2.0 * th).cos()));
    let (_, detail) = detect_mode(&case, &snap);
    assert_eq!(detail.folded_slices, 0, "{detail:?}");
    assert!(
        detail.reason.contains("no slice folded"),
        "{}",
        detail.reason
    );
}

/// A column bent with both ends flat on the plates (the bow of a column with clamped ends,
/// B = 15 mm > 0.5 d = 11.1 mm at mid-length, sections unchanged) is global buckling.
#[test]
fn a_column_bent_with_both_ends_on_the_plates_is_global_buckling() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let snap = tube(&case, |z, th, r| {
        let bow = 7.5 * (1.0 - (2.0 * PI * z / l).cos());
        [r * th.cos() + bow, r * th.sin(), z]
    });
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::GlobalBuckling, "{detail:?}");
    assert!((detail.max_drift_mm - 15.0).abs() < 1.0, "{detail:?}");
    assert!(detail.end_lift_mm.iter().all(|&e| e < 0.1), "{detail:?}");
}

/// What broke: a straight tube lying on its side between the plates (the t = 1.27, d = 10
/// example: turned as a whole, here by 60° about its middle, so that each end's ring stands
/// on edge) was called global buckling, as if it had bent. It is tipped over.
#[test]
fn a_tube_lying_on_its_side_is_tipped_over_not_global_buckling() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let (sin, cos) = (60.0 as Real).to_radians().sin_cos();
    let snap = tube(&case, |z, th, r| {
        let (x, y, z) = (r * th.cos(), r * th.sin(), z - 0.5 * l);
        [x * cos + z * sin, y, -x * sin + z * cos + 0.5 * l]
    });
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::TippedOver, "{detail:?}");
    assert!(detail.bend_mm < 0.01, "{detail:?}");
    // Each end's ring stands (d/2)·sin 60° above (below) its lowest (highest) point, the
    // outermost particle's centre at (d + t − h)/2: (11.1 + 1.2)·0.866 = 10.65 mm.
    for lift in detail.end_lift_mm {
        assert!((lift - 10.65).abs() < 0.05, "{detail:?}");
    }
    assert!(
        detail.reason.contains("left its plate"),
        "{}",
        detail.reason
    );
}

/// A column bent far (a half-sine bow of 15 mm between pinned ends, each section turned square
/// to the centre line) turns its end rings by 32°, past the lift threshold, as the d = 10
/// tube on sticking plates did at 50 mm of crush: it bent, it did not fall, so it is global
/// buckling.
#[test]
fn a_column_bent_far_enough_to_turn_its_ends_is_global_buckling_not_tipped_over() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let bow = 15.0;
    let snap = tube(&case, |z, th, r| {
        let slope = (bow * PI / l * (PI * z / l).cos()).atan();
        let (sin, cos) = slope.sin_cos();
        let across = r * th.cos();
        [
            bow * (PI * z / l).sin() + across * cos,
            r * th.sin(),
            z - across * sin,
        ]
    });
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::GlobalBuckling, "{detail:?}");
    assert!(
        detail
            .end_lift_mm
            .iter()
            .all(|&e| e > detail.end_lift_threshold_mm),
        "{detail:?}"
    );
    assert!(detail.bend_mm > 14.0, "{detail:?}");
}

#[test]
fn a_small_bow_with_ring_folds_stays_ring() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let snap = tube(&case, |z, th, r| {
        let (share, z1) = folded(z, l, 36.0);
        let [x, y, z1] = radial(z1, th, r, 2.0 * share);
        [x + 3.0 * (PI * z / l).sin(), y, z1]
    });
    assert_eq!(detect_mode(&case, &snap).0, CollapseMode::Ring);
}

#[test]
fn an_undeformed_tube_reads_ring_and_says_so() {
    let case = axial_case();
    let snap = tube(&case, |z, th, r| radial(z, th, r, 0.0));
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::Ring);
    assert_eq!(detail.folded_slices, 0);
    assert!(
        detail.reason.contains("no slice folded"),
        "{}",
        detail.reason
    );
}

#[test]
fn empty_snapshot_does_not_panic() {
    let (mode, detail) = detect_mode(&axial_case(), &Snapshot::default());
    assert_eq!(mode, CollapseMode::Ring);
    assert_eq!(detail.slices, 0);
}

#[test]
fn lateral_loading_is_flattening_with_an_oval_section() {
    let case = Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
    // Axis x; the section squashed in z and widened in y: w ≈ −2 cos(2θ) about x.
    let axial = tube(&case, |z, th, r| radial(z, th, r, -2.0 * (2.0 * th).cos()));
    let snap = Snapshot {
        initial_mm: axial
            .initial_mm
            .iter()
            .map(|p| [p[2], p[0], p[1]])
            .collect(),
        position_mm: axial
            .position_mm
            .iter()
            .map(|p| [p[2], p[0], p[1]])
            .collect(),
        plastic_strain: axial.plastic_strain,
    };
    let (mode, detail) = detect_mode(&case, &snap);
    assert_eq!(mode, CollapseMode::Flattening);
    assert!(
        (detail.harmonic_amplitude_mm[2] - 2.0).abs() < 1e-6,
        "{detail:?}"
    );
}

/// The unfolded wall's roundness: the top 30 mm folds in three lobes with its hinges strained
/// (ε_p 0.5 there), the wall below is oval by `oval` mm and unstrained. The oval is read below
/// the folds, half a fold length clear of them; a round wall reads none; a wall whose every
/// slice holds a hinge has no unfolded slice.
#[test]
fn the_unfolded_wall_s_oval_is_read_below_the_folds_and_only_there() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let zone = 30.0;
    let build = |oval: Real, hinges_everywhere: bool| {
        let mut snap = tube(&case, |z, th, r| {
            if z <= l - zone {
                return radial(z, th, r, oval * (2.0 * th).cos());
            }
            let (share, z) = folded(z, l, zone);
            radial(z, th, r, 2.0 * (3.0 * th).cos() * share)
        });
        for (e, p0) in snap.plastic_strain.iter_mut().zip(&snap.initial_mm) {
            let hinge = hinges_everywhere || p0[2] > l - zone;
            *e = if hinge { 0.5 } else { 0.0 };
        }
        snap
    };
    let (_, oval) = detect_mode(&case, &build(2.0, false));
    assert!((oval.unfolded_two_lobe_mm - 2.0).abs() < 0.05, "{oval:?}");
    let clear = 0.5 * fold_length_mm(&case);
    assert!(
        oval.unfolded_two_lobe_at_mm < l - zone - clear && oval.unfolded_slices > 0,
        "{oval:?}"
    );
    // Three-lobe folds carry no oval of their own: the whole oval is beyond them.
    assert!(oval.folds_two_lobe_mm < 0.05, "{oval:?}");
    assert!(
        (oval.unfolded_excess_two_lobe_mm - oval.unfolded_two_lobe_mm).abs() < 0.05,
        "{oval:?}"
    );
    let (_, round) = detect_mode(&case, &build(0.0, false));
    assert!(round.unfolded_two_lobe_mm < 0.01, "{round:?}");
    assert_eq!(round.unfolded_slices, oval.unfolded_slices);
    let (_, strained) = detect_mode(&case, &build(2.0, true));
    assert_eq!(
        (strained.unfolded_slices, strained.unfolded_two_lobe_mm),
        (0, 0.0),
        "{strained:?}"
    );
}

/// The top 30 mm holds two-lobe hinges (oval by 2 mm, ε_p 0.5); the wall below carries that
/// oval down as an elastic tube does, `times` the shell's envelope 2 e^(−x/ℓ) at x below the
/// hinges. At once the envelope, the wall is no more oval than the folds make it; at three
/// times, what it holds beyond the envelope is read, at the slice nearest the folds.
#[test]
fn an_oval_the_folds_carry_down_an_elastic_wall_is_not_beyond_them() {
    let case = axial_case();
    let l = case.spec().tube.length_mm;
    let section = case.geometry().section;
    let (t, d) = (section.thickness_mm(), section.width_mm());
    let decay = lobe_decay_mm(0.5 * d, t, case.spec().material.poisson_ratio, 2);
    let start = l - 30.0;
    let build = |times: Real| {
        let mut snap = tube(&case, |z, th, r| {
            let oval = if z > start {
                2.0
            } else {
                times * 2.0 * (-(start - z) / decay).exp()
            };
            radial(z, th, r, oval * (2.0 * th).cos())
        });
        for (e, p0) in snap.plastic_strain.iter_mut().zip(&snap.initial_mm) {
            *e = if p0[2] > start { 0.5 } else { 0.0 };
        }
        snap
    };
    let (_, carried) = detect_mode(&case, &build(1.0));
    assert!(
        (carried.folds_two_lobe_mm - 2.0).abs() < 0.05,
        "{carried:?}"
    );
    assert_eq!(carried.two_lobe_decay_mm, decay);
    assert!(carried.unfolded_two_lobe_mm > 0.5, "{carried:?}");
    // Only the slices' width (the nearest hinged slice's centre lies above the zone's edge)
    // separates the wall's oval from the envelope: 2 h / ℓ of it at most.
    let slack = 2.0 * case.spacing_mm() / decay * carried.unfolded_two_lobe_mm;
    assert!(
        carried.unfolded_excess_two_lobe_mm <= slack,
        "{carried:?} slack {slack}"
    );
    let (_, beyond) = detect_mode(&case, &build(3.0));
    let clear = 0.5 * fold_length_mm(&case);
    let want = 2.0 * 2.0 * (-clear / decay).exp();
    assert!(
        (beyond.unfolded_excess_two_lobe_mm / want - 1.0).abs() < 0.2,
        "{beyond:?} want {want}"
    );
    assert!(
        beyond.unfolded_excess_two_lobe_at_mm < start - clear
            && beyond.unfolded_excess_two_lobe_at_mm > start - clear - 4.0 * case.spacing_mm(),
        "{beyond:?}"
    );
}

/// An end ring flattened shut on its plate (each particle laid along a line at its arc length,
/// the two halves of the ring pressed together) spreads to π/2 of its radius about its centre;
/// a round end stays at its own radius over d/2.
#[test]
fn an_end_ring_flattened_shut_spreads_to_half_its_perimeter() {
    let case = axial_case();
    let h = case.spacing_mm();
    let d = case.geometry().section.width_mm();
    let flat = tube(&case, |z, th, r| {
        if z > h {
            return radial(z, th, r, 0.0);
        }
        // Arc length from θ = π/2, folded back at θ = 0 and π; the halves 0.1 mm apart.
        let (x, y) = match th <= PI {
            true => (r * (th - PI / 2.0), 0.05),
            false => (r * (1.5 * PI - th), -0.05),
        };
        [x, y, z]
    });
    let (_, detail) = detect_mode(&case, &flat);
    // The outermost layer sets it: r_out = d/2 + t/2 − h/2.
    let t = case.geometry().section.thickness_mm();
    let outer = (0.5 * d + 0.5 * t - 0.5 * h) / (0.5 * d);
    let want = PI / 2.0 * outer;
    assert!(
        (detail.end_spread[0] - want).abs() < 0.02,
        "{detail:?} want {want}"
    );
    assert!((detail.end_spread[1] - outer).abs() < 0.01, "{detail:?}");
}
