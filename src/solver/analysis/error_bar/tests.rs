//! The error bar's ladder and its interval, on ladders whose answer is known.

use super::*;
use crate::solver::Summary;

fn case(json: &str) -> Case {
    Case::from_json(json, &Limits::default()).unwrap()
}

fn summary(mean: f64, mode: CollapseMode) -> Summary {
    let mut s = crate::solver::summarize(
        &case("{}"),
        &[],
        &crate::solver::Snapshot::default(),
        Default::default(),
    )
    .0;
    s.mean_load_n = mean;
    s.mode = mode;
    s.cost.wall_time_s = 100.0;
    s
}

fn rungs(points: &[(u32, f64)]) -> Vec<Rung> {
    points
        .iter()
        .map(|&(n, mean_load_n)| Rung {
            n,
            mean_load_n,
            first_peak_load_n: None,
            wall_time_s: 1.0,
        })
        .collect()
}

fn ladder_of(bar: ErrorBar) -> Ladder {
    match bar {
        ErrorBar::ReducedLadder(l) => l,
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_exact_power_law_ladder_extrapolates_to_its_limit_and_holds_it() {
    // f(n) = 12 000 + 30 000 / n²: the section converges at order 2 to 12 kN.
    let f = |n: f64| 12_000.0 + 30_000.0 / (n * n);
    let points: Vec<(u32, f64)> = [4, 6, 8].iter().map(|&n| (n, f(n as f64))).collect();
    let run = summary(f(4.0) + 100.0, CollapseMode::Ring);
    let l = ladder_of(from_rungs(
        Model::Axisymmetric,
        rungs(&points),
        &run.rung(4),
        true,
    ));
    assert!(l.extrapolated);
    assert!((l.estimate_n - 12_000.0).abs() < 1e-6, "{}", l.estimate_n);
    assert!((l.order.unwrap() - 2.0).abs() < 1e-6);
    assert!(l.low_n <= 12_000.0 && 12_000.0 <= l.high_n, "{l:?}");
    // The half-width: the finest rung's distance to the limit, the 3D-to-section gap at the
    // same n, and the floor for what no ladder of the section can see.
    let half = (f(8.0) - 12_000.0) + 100.0 + MODEL_GAP_FLOOR * 12_000.0;
    assert!((l.high_n - l.low_n - 2.0 * half).abs() < 1e-6, "{l:?}");
    assert!((l.error - (run.mean_load_n / 12_000.0 - 1.0)).abs() < 1e-12);
    assert!(l.error_low <= l.error && Some(l.error) <= l.error_high);
    assert_eq!((l.cost_s, l.cost_fraction), (3.0, 0.03));
}

/// The paper's axial case (uGIMP, 50 mm) as docs/studies.md §1 measured it: 3D at n = 4,
/// 6, 8 and 10 gave 13.902, 13.233, 12.715 and 12.591 kN; the axisymmetric section 13.648,
/// 13.283, 12.649, 12.566, 12.561 and 12.499 kN at n = 4, 6, 8, 10, 12 and 16 (15 and 20 below).
/// Each run's ladder must hold the converged 12.454 kN (the section's Richardson value
/// through n = 4 to 24), and its error range the run's measured error.
#[test]
fn the_paper_case_intervals_hold_the_converged_load_at_n_4_6_8_and_10() {
    let section = |n: u32| match n {
        4 => 13_648.0,
        6 => 13_283.0,
        8 => 12_649.0,
        10 => 12_566.0,
        12 => 12_561.0,
        15 => SECTION_15,
        16 => 12_499.0,
        20 => SECTION_20,
        _ => unreachable!("no measured section at n = {n}"),
    };
    let gimp = case(r#"{"discretization": {"shape": "gimp"}}"#);
    for (n, three_d) in [(4, 13_902.0), (6, 13_233.0), (8, 12_715.0), (10, 12_591.0)] {
        let run = summary(three_d, CollapseMode::Ring);
        let mut spec = gimp.spec().clone();
        spec.discretization.particles_through_thickness = n;
        let c = Case::parse(spec, &Limits::default()).unwrap();
        let points: Vec<(u32, f64)> = ladder(&c, run.mode)
            .unwrap()
            .rungs
            .iter()
            .map(|(k, _)| (*k, section(*k)))
            .collect();
        let l = ladder_of(from_rungs(
            Model::Axisymmetric,
            rungs(&points),
            &run.rung(n),
            true,
        ));
        assert!(
            l.low_n <= 12_454.0 && 12_454.0 <= l.high_n,
            "n = {n}: {l:?}"
        );
        let measured = three_d / 12_454.0 - 1.0;
        assert!(
            l.error_low <= measured && measured <= l.error_high.unwrap(),
            "n = {n}: {l:?}"
        );
    }
}

/// The section at n = 15 and 20, measured with `crush run` (one thread).
const SECTION_15: f64 = 12_508.0;
const SECTION_20: f64 = 12_499.0;

#[test]
fn a_ladder_climbs_from_n_or_8_to_twice_that_and_a_3d_run_adds_its_own_n() {
    let ring = summary(1.0, CollapseMode::Ring);
    let three_d = ladder(&case(r#"{"discretization": {"shape": "gimp"}}"#), ring.mode)
        .unwrap()
        .rungs;
    let ns: Vec<u32> = three_d.iter().map(|(n, _)| *n).collect();
    assert_eq!(ns, [4, 8, 12, 16]);
    for (n, twin) in &three_d {
        let twin = twin.as_ref().unwrap().spec();
        assert_eq!(twin.discretization.model, Model::Axisymmetric);
        assert_eq!(twin.discretization.particles_through_thickness, *n);
        assert_eq!(twin.trigger.weak_fraction, 0.0);
    }
    let fine = case(r#"{"discretization": {"shape": "gimp", "particles_through_thickness": 10}}"#);
    let ns: Vec<u32> = ladder(&fine, ring.mode)
        .unwrap()
        .rungs
        .iter()
        .map(|(n, _)| *n)
        .collect();
    assert_eq!(ns, [10, 15, 20]);
    let section =
        case(r#"{"discretization": {"model": "axisymmetric", "particles_through_thickness": 12}}"#);
    let rungs = ladder(&section, ring.mode).unwrap().rungs;
    let ns: Vec<(u32, bool)> = rungs.iter().map(|(n, c)| (*n, c.is_some())).collect();
    assert_eq!(ns, [(12, false), (18, true), (24, true)]);
    let coarse =
        case(r#"{"discretization": {"model": "axisymmetric", "particles_through_thickness": 6}}"#);
    let ns: Vec<(u32, bool)> = ladder(&coarse, ring.mode)
        .unwrap()
        .rungs
        .iter()
        .map(|(n, c)| (*n, c.is_some()))
        .collect();
    assert_eq!(ns, [(8, true), (12, true), (16, true)]);
    let lateral = case(r#"{"loading": {"mode": "lateral"}}"#);
    let flat = summary(1.0, CollapseMode::Flattening);
    let rungs = ladder(&lateral, flat.mode).unwrap().rungs;
    assert_eq!(
        rungs[0].1.as_ref().unwrap().spec().discretization.model,
        Model::PlaneStrain
    );
}

#[test]
fn linear_shapes_b_splines_lobes_below_n_3_and_too_fine_a_section_have_no_error_bar_and_say_why() {
    let ring = summary(1.0, CollapseMode::Ring);
    let linear = case(r#"{"discretization": {"shape": "linear"}}"#);
    assert!(ladder(&linear, ring.mode).unwrap_err().contains("linear"));
    let bspline = case(r#"{"discretization": {"shape": "bspline", "model": "axisymmetric"}}"#);
    assert!(ladder(&bspline, ring.mode)
        .unwrap_err()
        .contains("B-splines have no section ladder"));
    let diamond = summary(1.0, CollapseMode::Diamond { lobes: 3 });
    let coarse = case(r#"{"discretization": {"shape": "gimp", "particles_through_thickness": 2}}"#);
    let why = ladder(&coarse, diamond.mode).unwrap_err();
    assert!(why.contains("diamond") && why.contains("n ≥ 3"), "{why}");
    let fine =
        case(r#"{"discretization": {"model": "axisymmetric", "particles_through_thickness": 40}}"#);
    assert!(ladder(&fine, ring.mode)
        .unwrap_err()
        .contains("past its 64"));
}

/// The paper's axial case (uGIMP, 50 mm): first collapse peaks (`first_peak_load_n`, N) of the
/// axisymmetric section at n = 4 to 20 and of 3D at n = 4 and 6, measured with `crush run` on
/// the cases of `docs/trust.md` (section: one thread; 3D: two threads). The section's peak has
/// settled from n = 10 on, to within 10 N of 15 378 N.
const SECTION_PEAKS: [(u32, f64); 8] = [
    (4, 15_240.9),
    (6, 15_373.8),
    (8, 15_360.7),
    (10, 15_376.7),
    (12, 15_378.0),
    (15, 15_375.3),
    (16, 15_383.1),
    (20, 15_373.2),
];

#[test]
fn the_paper_case_first_peak_intervals_hold_the_sections_settled_peak_at_n_4_and_6() {
    let peak = |n: u32| SECTION_PEAKS.iter().find(|p| p.0 == n).unwrap().1;
    let settled = SECTION_PEAKS.iter().filter(|p| p.0 >= 10).map(|p| p.1);
    let (lowest, highest) = settled.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let gimp = case(r#"{"discretization": {"shape": "gimp"}}"#);
    for (n, three_d_peak) in [(4, 15_294.3), (6, 15_352.6)] {
        let mut run = summary(13_000.0, CollapseMode::Ring);
        run.measures.first_peak_load_n = Some(three_d_peak);
        let mut spec = gimp.spec().clone();
        spec.discretization.particles_through_thickness = n;
        let c = Case::parse(spec, &Limits::default()).unwrap();
        let rungs: Vec<Rung> = ladder(&c, run.mode)
            .unwrap()
            .rungs
            .iter()
            .map(|(k, _)| Rung {
                n: *k,
                mean_load_n: 13_000.0,
                first_peak_load_n: Some(peak(*k)),
                wall_time_s: 1.0,
            })
            .collect();
        let l = ladder_of(from_rungs(Model::Axisymmetric, rungs, &run.rung(n), true));
        let p = l.first_peak.expect("every rung has a first peak");
        assert!(
            p.low_n <= lowest && highest <= p.high_n,
            "n = {n}: {p:?} against {lowest}..{highest}"
        );
        // The twin gap is the 3D run's distance from its section at the same n.
        let gap = (three_d_peak - peak(n)).abs() / p.estimate_n;
        assert!((p.twin_gap - gap).abs() < 1e-12, "{p:?}");
        assert!((p.error - (three_d_peak / p.estimate_n - 1.0)).abs() < 1e-12);
    }
}

#[test]
fn a_rung_without_a_first_peak_leaves_the_first_peak_without_an_interval() {
    let mut run = summary(13_000.0, CollapseMode::Ring);
    run.measures.first_peak_load_n = Some(15_000.0);
    let mut points = rungs(&[(8, 13_000.0), (12, 12_900.0), (16, 12_850.0)]);
    for (r, p) in points.iter_mut().zip([15_100.0, 15_050.0, 15_020.0]) {
        r.first_peak_load_n = Some(p);
    }
    let with = ladder_of(from_rungs(
        Model::Axisymmetric,
        points.clone(),
        &run.rung(8),
        false,
    ));
    assert!(with.first_peak.is_some());
    points[1].first_peak_load_n = None;
    let without = ladder_of(from_rungs(Model::Axisymmetric, points, &run.rung(8), false));
    assert_eq!(without.first_peak, None);
}

#[test]
fn an_error_bar_is_priced_unasked_only_where_it_costs_at_most_a_quarter_of_the_run() {
    use crate::solver::analysis::estimate::{
        error_bar_cost_fraction, estimate, UNASKED_ERROR_BAR_FRACTION,
    };
    let at = |n: u32| {
        case(&format!(
            r#"{{"discretization": {{"shape": "gimp", "particles_through_thickness": {n}}}}}"#
        ))
    };
    let fraction = |n| error_bar_cost_fraction(&at(n)).unwrap();
    // The paper's tube in 3D: the ladder (8, 12, 16 and the run's own n) against the run.
    assert!(fraction(4) > 1.0, "{}", fraction(4));
    assert!(fraction(6) > UNASKED_ERROR_BAR_FRACTION, "{}", fraction(6));
    assert!(fraction(8) < UNASKED_ERROR_BAR_FRACTION, "{}", fraction(8));
    // The estimate foretells it: the ladder's time where it will run unasked, none elsewhere.
    assert!(estimate(&at(8), 2).error_bar_wall_time_s.is_some());
    assert_eq!(estimate(&at(4), 2).error_bar_wall_time_s, None);
    // Linear shape functions have no ladder at all.
    let linear = case(r#"{"discretization": {"shape": "linear"}}"#);
    assert_eq!(error_bar_cost_fraction(&linear), None);
}

/// The lateral example (t 3.2, d 22.2, l 76.2, 12.5 mm, uGIMP) in 3D at n = 4: 5 297.2 N; its
/// plane-strain section at n = 4, 8, 12, 16: 5 323.1, 5 452.4, 5 489.1, 5 502.7 N (`crush run
/// --error-bar`, two threads). The section settles at 5.489–5.503 kN from n = 12 to 24
/// (docs/studies.md §8): the interval must hold that plateau, and its error range the run's
/// error against it.
#[test]
fn the_lateral_interval_at_n_4_holds_the_converged_plane_strain_plateau() {
    let lateral = case(
        r#"{"loading": {"mode": "lateral", "crush_distance_mm": 12.5},
            "discretization": {"shape": "gimp"}}"#,
    );
    let run = summary(5_297.2, CollapseMode::Flattening);
    let section = [(4, 5_323.1), (8, 5_452.4), (12, 5_489.1), (16, 5_502.7)];
    let ks: Vec<u32> = ladder(&lateral, run.mode)
        .unwrap()
        .rungs
        .iter()
        .map(|r| r.0)
        .collect();
    assert_eq!(ks, [4, 8, 12, 16]);
    let l = ladder_of(from_rungs(
        Model::PlaneStrain,
        rungs(&section),
        &run.rung(4),
        true,
    ));
    assert!(l.low_n <= 5_489.0 && 5_503.0 <= l.high_n, "{l:?}");
    for converged in [5_489.0, 5_503.0] {
        let error = 5_297.2 / converged - 1.0;
        assert!(
            l.error_low <= error && error <= l.error_high.unwrap(),
            "{l:?}"
        );
    }
}

fn three_d_ladder_of(bar: ErrorBar) -> Ladder {
    match bar {
        ErrorBar::ThreeDLadder(l) => l,
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_3d_run_its_section_cannot_fold_climbs_the_same_case_at_n_minus_2_and_n_minus_1() {
    let diamond = CollapseMode::Diamond { lobes: 3 };
    let gimp = case(
        r#"{"discretization": {"shape": "gimp", "particles_through_thickness": 6},
            "trigger": {"weak_fraction": 0.003, "seed": 7}}"#,
    );
    for mode in [
        diamond,
        CollapseMode::GlobalBuckling,
        CollapseMode::TippedOver,
    ] {
        let r = ladder(&gimp, mode).unwrap();
        assert!(
            matches!(&r.climb, Climb::ThreeD { why_not_section } if why_not_section.contains(mode.kind().replace('_', " ").as_str())),
            "{:?}",
            r.climb
        );
        let ns: Vec<(u32, bool)> = r.rungs.iter().map(|(n, c)| (*n, c.is_some())).collect();
        assert_eq!(ns, [(4, true), (5, true), (6, false)]);
        for (n, rung) in r.rungs.iter().filter_map(|(n, c)| Some((n, c.as_ref()?))) {
            // The same case, trigger and all, at a coarser n.
            let s = rung.spec();
            assert_eq!(s.discretization.model, Model::ThreeD);
            assert_eq!(s.discretization.particles_through_thickness, *n);
            assert_eq!(rung.shape(), ShapeKind::Gimp);
            assert_eq!((s.trigger.weak_fraction, s.trigger.seed), (0.003, 7));
            assert!(!s.output.error_bar);
        }
    }
    // A ring climbs its section, as before.
    assert_eq!(
        ladder(&gimp, CollapseMode::Ring).unwrap().climb,
        Climb::Section
    );
    // A rectangular tube crushed axially has no section, whatever its mode.
    let square = case(
        r#"{"tube": {"section": "rectangular", "thickness_mm": 1.5, "side_a_mm": 40,
                     "corner_radius_mm": 3, "length_mm": 80},
            "discretization": {"shape": "gimp", "particles_through_thickness": 3}}"#,
    );
    let r = ladder(&square, CollapseMode::Symmetric).unwrap();
    assert!(matches!(r.climb, Climb::ThreeD { .. }));
    assert_eq!(r.rungs.iter().map(|r| r.0).collect::<Vec<_>>(), [1, 2, 3]);
}

/// A 3D B-spline run has no section ladder (the section's rungs run uGIMP), so whatever its
/// mode it climbs its own case at n − 2 and n − 1, on B-splines: the configuration that folded
/// the d/t 14 tube from one end at n 4, 5 and 6 (docs/folding.md §4) gets an interval instead
/// of `unavailable`. Linear shapes still get none.
#[test]
fn a_3d_b_spline_run_climbs_its_own_3d_ladder_on_b_splines_whatever_its_mode() {
    let bspline = case(
        r#"{"discretization": {"shape": "bspline", "particles_through_thickness": 5},
            "contact": {"friction": 0.3}}"#,
    );
    for mode in [CollapseMode::Ring, CollapseMode::Diamond { lobes: 2 }] {
        let r = ladder(&bspline, mode).unwrap();
        assert!(
            matches!(&r.climb, Climb::ThreeD { why_not_section } if why_not_section.contains("B-splines")),
            "{:?}",
            r.climb
        );
        let ns: Vec<(u32, bool)> = r.rungs.iter().map(|(n, c)| (*n, c.is_some())).collect();
        assert_eq!(ns, [(3, true), (4, true), (5, false)]);
        for rung in r.rungs.iter().filter_map(|(_, c)| c.as_ref()) {
            assert_eq!(rung.shape(), ShapeKind::Bspline);
            assert_eq!(rung.spec().discretization.model, Model::ThreeD);
        }
    }
    let linear =
        case(r#"{"discretization": {"shape": "linear", "particles_through_thickness": 5}}"#);
    let why = ladder(&linear, CollapseMode::Diamond { lobes: 2 }).unwrap_err();
    assert!(why.contains("linear"), "{why}");
    assert_eq!(why.matches("linear shape functions").count(), 1, "{why}");
}

/// f(n) = 15 000 + 20 000 / n² at n = 4, 5 and 6, the run at n = 6 its own finest rung: the
/// reading extrapolates to 15 kN at order 2, with the finest rung's way to it and the floor
/// as the half-width, no twin gap, and the two coarser rungs as its cost.
#[test]
fn a_monotone_3d_ladder_extrapolates_and_holds_its_limit() {
    let f = |n: f64| 15_000.0 + 20_000.0 / (n * n);
    let points: Vec<(u32, f64)> = [4, 5, 6].iter().map(|&n| (n, f(n as f64))).collect();
    let run = summary(f(6.0), CollapseMode::Diamond { lobes: 3 });
    let l = three_d_ladder_of(from_rungs(
        Model::ThreeD,
        rungs(&points),
        &run.rung(6),
        true,
    ));
    assert_eq!(l.model, Model::ThreeD);
    assert!(l.extrapolated);
    assert!((l.estimate_n - 15_000.0).abs() < 1e-6, "{}", l.estimate_n);
    assert!((l.order.unwrap() - 2.0).abs() < 1e-6);
    let half = (f(6.0) - 15_000.0) + MODEL_GAP_FLOOR * 15_000.0;
    assert!((l.high_n - l.low_n - 2.0 * half).abs() < 1e-6, "{l:?}");
    assert!(l.low_n <= 15_000.0 && f(6.0) <= l.high_n, "{l:?}");
    assert_eq!(l.twin_gap, 0.0);
    // The run is its own rung: only n = 4 and 5 were run for the error bar.
    assert_eq!((l.cost_s, l.cost_fraction), (2.0, 0.02));
    assert!(l.covers.contains("3D runs") && l.covers.contains("trigger.seed"));
    let json = serde_json::to_value(ErrorBar::ThreeDLadder(l)).unwrap();
    assert_eq!(json["basis"], "three_d_ladder");
    assert_eq!(json["model"], "3d");
}

/// Rungs that wobble (up, then down) have no order: the interval is the run's value with the
/// ladder's whole spread and the floor, and holds every rung; the first peak likewise.
#[test]
fn a_wobbling_3d_ladder_is_a_noise_band_around_the_run_holding_every_rung() {
    let points = [(4, 15_537.0), (5, 15_700.0), (6, 15_574.0)];
    let mut ladder_rungs = rungs(&points);
    for (r, p) in ladder_rungs.iter_mut().zip([20_100.0, 19_800.0, 19_950.0]) {
        r.first_peak_load_n = Some(p);
    }
    let mut run = summary(15_574.0, CollapseMode::GlobalBuckling);
    run.measures.first_peak_load_n = Some(19_950.0);
    let l = three_d_ladder_of(from_rungs(Model::ThreeD, ladder_rungs, &run.rung(6), true));
    assert!(!l.extrapolated && l.order.is_none(), "{l:?}");
    assert_eq!(l.estimate_n, 15_574.0);
    let half = (15_700.0 - 15_574.0) + MODEL_GAP_FLOOR * 15_574.0;
    assert!((l.high_n - 15_574.0 - half).abs() < 1e-9, "{l:?}");
    for (_, v) in points {
        assert!(l.low_n <= v && v <= l.high_n, "{v}: {l:?}");
    }
    assert!(l.covers.contains("not monotone"), "{}", l.covers);
    let p = l.first_peak.unwrap();
    assert_eq!((p.estimate_n, p.twin_gap), (19_950.0, 0.0));
    for v in [20_100.0, 19_800.0, 19_950.0] {
        assert!(p.low_n <= v && v <= p.high_n, "{v}: {p:?}");
    }
}

#[test]
fn a_3d_run_below_n_3_has_no_3d_ladder_and_says_why() {
    let run = summary(15_000.0, CollapseMode::Diamond { lobes: 3 });
    let bar = from_rungs(
        Model::ThreeD,
        rungs(&[(1, 16_000.0), (2, 15_500.0)]),
        &run.rung(2),
        true,
    );
    let ErrorBar::Unavailable { why } = bar else {
        panic!("{bar:?}")
    };
    assert!(why.contains("n ≥ 3") && why.contains("n − 2"), "{why}");
}

/// What broke: the d/t 14 tube at n 3 on B-splines climbs n 1, 2, 3 (33.220, 14.100, 16.643
/// kN), whose spread is wider than the run's own load, and its interval reached down to
/// −0.017 kN: a negative crush load. The interval now stops at zero load, and the run's error
/// against that end is unbounded (none).
#[test]
fn an_interval_wider_than_the_load_stops_at_zero_load() {
    let points = [(1, 33_219.5), (2, 14_099.9), (3, 16_642.9)];
    let mut all = rungs(&points);
    for r in &mut all {
        r.first_peak_load_n = Some(r.mean_load_n);
    }
    let run = all[2].clone();
    let l = three_d_ladder_of(from_rungs(Model::ThreeD, all, &run, true));
    assert_eq!(l.low_n, 0.0, "{l:?}");
    assert_eq!(l.error_high, None, "{l:?}");
    assert!(l.high_n > 33_219.5, "{l:?}");
    let p = l.first_peak.expect("a first-peak interval");
    assert_eq!(p.low_n, 0.0, "{p:?}");
}
