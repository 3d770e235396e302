//! The runner prices a 3D ladder for a run its section cannot price, only when asked.

use super::*;
use crate::solver::analysis::error_bar::ErrorBar;
use crate::solver::model::case::Limits;

/// A square tube (t 1, a 10, l 10 mm) with a trigger, crushed 2 mm at n = 3: no section can
/// price an axial crush of a rectangle, so its error bar climbs the same case at n = 1 and 2.
fn tiny_square(error_bar: bool) -> Case {
    let json = format!(
        r#"{{"tube": {{"section": "rectangular", "thickness_mm": 1, "side_a_mm": 10,
                       "corner_radius_mm": 2, "length_mm": 10}},
            "loading": {{"crush_distance_mm": 2, "plate_speed_m_s": 20}},
            "discretization": {{"shape": "gimp", "particles_through_thickness": 3}},
            "trigger": {{"weak_fraction": 0.003, "seed": 3}},
            "output": {{"history_points": 20, "final_state": false, "error_bar": {error_bar}}}}}"#
    );
    Case::from_json(&json, &Limits::default()).unwrap()
}

#[derive(Default)]
struct Rungs(Vec<(usize, Rung)>);

impl LadderObserver for Rungs {
    fn on_rung(&mut self, index: usize, rung: &Rung) {
        self.0.push((index, rung.clone()));
    }
}

#[test]
fn a_tiny_square_tube_asked_for_its_error_bar_gets_a_3d_ladder_holding_its_rungs() {
    let runner = Runner::new(2, |i| format!("test-{i}")).unwrap();
    let cancel = AtomicBool::new(false);
    let case = tiny_square(true);
    let mut out = runner.run(&case, &mut (), &cancel).unwrap();
    let mut seen = Rungs::default();
    runner
        .add_error_bar_if_asked(&case, &mut out, &mut seen, &cancel)
        .unwrap();
    let Some(ErrorBar::ThreeDLadder(l)) = &out.summary.error_bar else {
        panic!("{:?}", out.summary.error_bar)
    };
    let ns: Vec<u32> = l.rungs.iter().map(|r| r.n).collect();
    assert_eq!(ns, [1, 2, 3]);
    // The rungs run for it went through the ladder's observer; the run is the third.
    let told: Vec<(usize, u32)> = seen.0.iter().map(|(i, r)| (*i, r.n)).collect();
    assert_eq!(told, [(0, 1), (1, 2)]);
    assert_eq!(l.rungs[2].mean_load_n, out.summary.mean_load_n);
    // The interval holds its estimate and the run; where the rungs are read as a noise band
    // (not extrapolated), every rung. Here they fall monotonically (3.87, 2.56, 2.06 kN at
    // n = 1, 2, 3) at order 0.76, in Richardson's range: the extrapolation (0.67 kN) is taken,
    // and n = 1 and 2 lie above the interval.
    let holds = |v: f64| l.low_n <= v && v <= l.high_n;
    assert!(
        holds(l.estimate_n) && holds(out.summary.mean_load_n),
        "{l:?}"
    );
    if !l.extrapolated {
        for r in &l.rungs {
            assert!(holds(r.mean_load_n), "n = {}: {l:?}", r.n);
        }
    }
    // Unasked, the same run says how to get it instead of pricing it.
    let unasked = tiny_square(false);
    out.summary.error_bar = None;
    runner
        .add_error_bar_if_asked(&unasked, &mut out, &mut (), &cancel)
        .unwrap();
    let Some(ErrorBar::Unavailable { why }) = &out.summary.error_bar else {
        panic!("{:?}", out.summary.error_bar)
    };
    assert!(
        why.contains("output.error_bar") && why.contains("3D ladder"),
        "{why}"
    );
}
