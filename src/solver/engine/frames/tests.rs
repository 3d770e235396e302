//! A series starts at rest at the start positions, ends at the final state, stands at equal
//! travel, leaves the run's bits alone, and goes on across a checkpoint.

use crate::solver::engine::checkpoint::{Checkpoint, Resume};
use crate::solver::engine::observer::{Observer, Recorder};
use crate::solver::engine::{resume, run, Finished};
use crate::solver::model::case::{Case, Limits};
use std::sync::atomic::{AtomicBool, Ordering};

fn case(json: &str) -> Case {
    Case::from_json(json, &Limits::default()).unwrap()
}

/// Short cases of the three models, each with a series of 4 frames.
fn cases() -> Vec<(&'static str, Case)> {
    vec![
        (
            "3d",
            case(
                r#"{"tube": {"length_mm": 10}, "output": {"history_points": 30, "frames": 4},
                "loading": {"crush_distance_mm": 1.5, "plate_speed_m_s": 20},
                "discretization": {"particles_through_thickness": 1}}"#,
            ),
        ),
        (
            "axisymmetric",
            case(
                r#"{"discretization": {"particles_through_thickness": 2, "model": "axisymmetric"},
                "loading": {"crush_distance_mm": 3}, "output": {"history_points": 30, "frames": 4}}"#,
            ),
        ),
        (
            "plane strain",
            case(
                r#"{"discretization": {"particles_through_thickness": 2, "model": "plane_strain"},
                "loading": {"mode": "lateral", "crush_distance_mm": 3},
                "output": {"history_points": 30, "frames": 4}}"#,
            ),
        ),
    ]
}

fn bits(done: &Finished) -> Vec<u64> {
    let s = &done.snapshot;
    let rows = done.history.iter().flat_map(|r| r.values());
    let state = s
        .position_mm
        .iter()
        .flatten()
        .chain(&s.plastic_strain)
        .copied();
    rows.chain(state).map(f64::to_bits).collect()
}

#[test]
fn frame_zero_is_the_start_at_rest_and_the_last_is_the_final_state() {
    for (what, case) in cases() {
        let mut seen = Recorder::default();
        let done = run(&case, &mut seen, &AtomicBool::new(false)).unwrap();
        let frames = &seen.frames;
        let indices: Vec<u32> = frames.iter().map(|f| f.index).collect();
        assert_eq!(indices, [0, 1, 2, 3], "{what}");
        let n = done.snapshot.position_mm.len();
        for f in frames {
            assert_eq!(f.count, 4);
            for len in [
                f.position_mm.len(),
                f.velocity_m_s.len(),
                f.stress_mpa.len(),
                f.volume_mm3.len(),
                f.plastic_strain.len(),
            ] {
                assert_eq!(len, n, "{what}, frame {}", f.index);
            }
            assert!(f.volume_mm3.iter().all(|v| *v > 0.0), "{what}");
        }
        let first = &frames[0];
        assert_eq!((first.time_ms, first.travel_mm), (0.0, 0.0), "{what}");
        assert_eq!(first.position_mm, done.snapshot.initial_mm, "{what}");
        assert!(first.velocity_m_s.iter().flatten().all(|v| *v == 0.0));
        assert!(first.stress_mpa.iter().flatten().all(|s| *s == 0.0));
        let last = &frames[3];
        assert_eq!(last.position_mm, done.snapshot.position_mm, "{what}");
        assert_eq!(last.plastic_strain, done.snapshot.plastic_strain, "{what}");
        assert!(last.stress_mpa.iter().flatten().any(|s| *s != 0.0));
        // At equal travel, within a step's travel (the last row's end is exact).
        let crush = case.crush_distance_mm();
        let step_mm = case.spec().loading.plate_speed_m_s * done.cost.dt_max_ms;
        for f in frames {
            let nominal = crush * f.index as f64 / 3.0;
            assert!(
                f.travel_mm >= nominal - 1e-9 && f.travel_mm <= nominal + step_mm,
                "{what}: frame {} at {} mm, not {nominal} mm",
                f.index,
                f.travel_mm
            );
        }
        assert!((last.travel_mm - crush).abs() < 1e-9 * crush, "{what}");
        assert_eq!(last.time_ms, done.history.last().unwrap().time_ms, "{what}");
    }
}

#[test]
fn a_series_leaves_the_run_bit_for_bit_as_it_is_without() {
    for (what, with) in cases() {
        let mut spec = with.spec().clone();
        spec.output.frames = 0;
        let without = Case::parse(spec, &Limits::default()).unwrap();
        let cancel = AtomicBool::new(false);
        let a = run(&with, &mut Recorder::default(), &cancel).unwrap();
        let b = run(&without, &mut (), &cancel).unwrap();
        assert_eq!(bits(&a), bits(&b), "{what}");
    }
}

/// Records frames, takes one checkpoint before step `at` and stops the run after it.
struct StopAt<'a> {
    at: u64,
    asked: u64,
    cancel: &'a AtomicBool,
    taken: Option<Checkpoint>,
    seen: Recorder,
}

impl Observer for StopAt<'_> {
    fn wants_checkpoint(&mut self) -> bool {
        self.asked += 1;
        self.asked == self.at
    }
    fn on_checkpoint(&mut self, checkpoint: Checkpoint) {
        self.taken = Some(checkpoint);
        self.cancel.store(true, Ordering::Relaxed);
    }
    fn wants_frames(&self) -> bool {
        true
    }
    fn on_frame(&mut self, frame: &crate::solver::Frame) {
        self.seen.on_frame(frame);
    }
}

#[test]
fn a_resumed_run_sends_the_frames_after_its_checkpoint_with_the_whole_runs_bits() {
    let (_, case) = cases().remove(0);
    let mut whole = Recorder::default();
    let done = run(&case, &mut whole, &AtomicBool::new(false)).unwrap();
    let steps = done.cost.steps;
    for at in [1, steps / 2, steps] {
        let cancel = AtomicBool::new(false);
        let mut first = StopAt {
            at,
            asked: 0,
            cancel: &cancel,
            taken: None,
            seen: Recorder::default(),
        };
        assert!(run(&case, &mut first, &cancel).is_err());
        let from = Resume::read(&case, &first.taken.unwrap().bytes).unwrap();
        let mut rest = Recorder::default();
        resume(&case, from, &mut rest, &AtomicBool::new(false)).unwrap();
        let mut both = first.seen.frames;
        both.extend(rest.frames);
        assert_eq!(both, whole.frames, "checkpoint before step {at}");
    }
}
