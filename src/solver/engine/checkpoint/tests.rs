//! A run stopped at a checkpoint and resumed must end with the bits of the run that never
//! stopped, on every model and shape function, across thread counts; a damaged, foreign or
//! short checkpoint is refused with the reason.

use super::*;
use crate::solver::engine::observer::Observer;
use crate::solver::model::case::Limits;
use crate::solver::{resume, run, RunOutput, SolveError};
use std::sync::atomic::{AtomicBool, Ordering};

fn case(json: &str) -> Case {
    Case::from_json(json, &Limits::default()).unwrap()
}

/// Short cases of every engine: 3D axial with both shape functions, 3D with the trigger's weak
/// particles, 3D lateral, and both reduced models.
fn cases() -> Vec<(&'static str, Case)> {
    let short = r#""loading": {"crush_distance_mm": 1.5, "plate_speed_m_s": 20},
                   "output": {"history_points": 30}"#;
    vec![
        (
            "3d linear",
            case(&format!(
                r#"{{"tube": {{"length_mm": 10}}, {short},
                "discretization": {{"particles_through_thickness": 2, "shape": "linear"}}}}"#
            )),
        ),
        (
            "3d gimp",
            case(&format!(
                r#"{{"tube": {{"length_mm": 10}}, {short},
                "discretization": {{"particles_through_thickness": 2, "shape": "gimp"}}}}"#
            )),
        ),
        (
            "3d trigger",
            case(&format!(
                r#"{{"tube": {{"thickness_mm": 1.27, "mean_diameter_mm": 20.32, "length_mm": 12}},
                {short}, "discretization": {{"particles_through_thickness": 2}},
                "trigger": {{"weak_fraction": 0.05, "strength_ratio": 0.5}}}}"#
            )),
        ),
        (
            "3d lateral",
            case(
                r#"{"tube": {"length_mm": 6}, "output": {"history_points": 30},
                "loading": {"mode": "lateral", "crush_distance_mm": 3, "plate_speed_m_s": 10},
                "discretization": {"particles_through_thickness": 1}}"#,
            ),
        ),
        (
            "axisymmetric",
            case(
                r#"{"discretization": {"particles_through_thickness": 3, "model": "axisymmetric"},
                "loading": {"crush_distance_mm": 3}, "output": {"history_points": 30}}"#,
            ),
        ),
        (
            "plane strain",
            case(
                r#"{"discretization": {"particles_through_thickness": 3, "model": "plane_strain"},
                "loading": {"mode": "lateral", "crush_distance_mm": 3},
                "output": {"history_points": 30}}"#,
            ),
        ),
    ]
}

/// Takes one checkpoint before step `at` (counting this stretch's steps) and stops the run
/// right after it; the cancel it sets is the run's.
struct StopAt<'a> {
    at: u64,
    asked: u64,
    cancel: &'a AtomicBool,
    taken: Option<Checkpoint>,
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
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Runs `case` on `threads` threads, stopping at a checkpoint before step `at`.
fn stopped_at(case: &Case, at: u64, threads: usize) -> Checkpoint {
    let cancel = AtomicBool::new(false);
    let mut observer = StopAt {
        at,
        asked: 0,
        cancel: &cancel,
        taken: None,
    };
    let out = on_threads(threads, || run(case, &mut observer, &cancel));
    assert!(
        matches!(out, Err(SolveError::Cancelled { .. })),
        "the run was not stopped: {:?}",
        out.err()
    );
    let taken = observer.taken.expect("a checkpoint");
    assert_eq!(
        taken.step,
        at - 1,
        "the checkpoint is taken before step `at`"
    );
    taken
}

fn assert_same_bits(what: &str, a: &RunOutput, b: &RunOutput) {
    let bits = |o: &RunOutput| -> Vec<u64> {
        o.history
            .iter()
            .flat_map(|r| r.values())
            .map(f64::to_bits)
            .collect()
    };
    assert_eq!(bits(a), bits(b), "{what}: history");
    let state = |o: &RunOutput| -> Vec<u64> {
        let s = &o.snapshot;
        s.position_mm
            .iter()
            .flatten()
            .chain(&s.plastic_strain)
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(state(a), state(b), "{what}: final state");
    // The summary with the wall-time figures (which add both stretches' times) left out.
    let physics = |o: &RunOutput| {
        let mut s = o.summary.clone();
        s.cost.wall_time_s = 0.0;
        s.cost.particle_steps_per_s = 0.0;
        s.cost.threads = 0;
        serde_json::to_string(&s).unwrap()
    };
    assert_eq!(physics(a), physics(b), "{what}: summary");
    assert_eq!(a.mode_detail, b.mode_detail, "{what}: mode");
}

#[test]
fn a_resumed_run_ends_with_the_bits_of_the_run_that_never_stopped() {
    for (what, case) in cases() {
        let whole = on_threads(2, || run(&case, &mut (), &AtomicBool::new(false))).unwrap();
        let steps = whole.summary.cost.steps;
        assert!(steps > 150, "{what}: {steps} steps");
        // At a step that re-sorts the particles (3D: every 100) and at ones that do not, early,
        // mid-way and near the end.
        for at in [steps / 3, 101, 137, steps * 4 / 5] {
            for (wrote, resumed) in [(2, 2), (1, 2), (2, 1)] {
                let checkpoint = stopped_at(&case, at, wrote);
                let from = Resume::read(&case, &checkpoint.bytes).unwrap();
                assert_eq!(from.steps(), at - 1);
                let cancel = AtomicBool::new(false);
                let end = on_threads(resumed, || resume(&case, from, &mut (), &cancel)).unwrap();
                assert_same_bits(
                    &format!("{what}, at {at}, {wrote}→{resumed} threads"),
                    &whole,
                    &end,
                );
            }
        }
    }
}

#[test]
fn a_resumed_run_can_be_stopped_and_resumed_again() {
    let (_, case) = cases().remove(1);
    let whole = run(&case, &mut (), &AtomicBool::new(false)).unwrap();
    let first = stopped_at(&case, 60, 2);
    // The second stretch takes a checkpoint 50 of its own steps in.
    let cancel = AtomicBool::new(false);
    let mut observer = StopAt {
        at: 50,
        asked: 0,
        cancel: &cancel,
        taken: None,
    };
    let from = Resume::read(&case, &first.bytes).unwrap();
    assert!(resume(&case, from, &mut observer, &cancel).is_err());
    let second = observer.taken.unwrap();
    assert_eq!(second.step, 59 + 49);
    assert!(second.fraction > first.fraction);
    let from = Resume::read(&case, &second.bytes).unwrap();
    let end = resume(&case, from, &mut (), &AtomicBool::new(false)).unwrap();
    assert_same_bits("twice resumed", &whole, &end);
}

#[test]
fn a_shutdown_hands_over_a_checkpoint_and_a_clients_cancel_does_not() {
    struct Stop {
        shutdown: bool,
        taken: Option<Checkpoint>,
    }
    impl Observer for Stop {
        fn checkpoint_on_stop(&mut self) -> bool {
            self.shutdown
        }
        fn on_checkpoint(&mut self, checkpoint: Checkpoint) {
            self.taken = Some(checkpoint);
        }
    }
    let (_, case) = cases().remove(0);
    for shutdown in [true, false] {
        let mut observer = Stop {
            shutdown,
            taken: None,
        };
        let out = run(&case, &mut observer, &AtomicBool::new(true));
        assert_eq!(out.unwrap_err(), SolveError::Cancelled { step: 0 });
        assert_eq!(observer.taken.is_some(), shutdown);
    }
}

#[test]
fn a_damaged_foreign_or_short_checkpoint_is_refused_with_the_reason() {
    let mut all = cases();
    let (_, other) = all.remove(1);
    let (_, case) = all.remove(0);
    let good = stopped_at(&case, 40, 1).bytes;
    assert!(Resume::read(&case, &good).is_ok());
    let size = Checkpoint::size_for(&case, case.particle_count(), 30);
    assert!(good.len() as u64 <= size, "{} > {size}", good.len());

    let mut flipped = good.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 1;
    assert_eq!(
        Resume::read(&case, &flipped).unwrap_err(),
        CheckpointError::Checksum
    );
    for cut in [3, 20, good.len() / 2, good.len() - 1] {
        assert!(Resume::read(&case, &good[..cut]).is_err(), "cut at {cut}");
    }
    assert_eq!(
        Resume::read(&case, b"not a checkpoint at all").unwrap_err(),
        CheckpointError::NotACheckpoint
    );
    let mut newer = good.clone();
    newer[MAGIC.len()..MAGIC.len() + 4].copy_from_slice(&(VERSION + 1).to_le_bytes());
    assert_eq!(
        Resume::read(&case, &newer).unwrap_err(),
        CheckpointError::Version(VERSION + 1)
    );
    assert_eq!(
        Resume::read(&other, &good).unwrap_err(),
        CheckpointError::OtherCase
    );
    // The label is not physics: the same case under another label resumes.
    let mut spec = case.spec().clone();
    spec.label = Some("renamed".into());
    let relabelled = Case::parse(spec, &Limits::default()).unwrap();
    assert!(Resume::read(&relabelled, &good).is_ok());
}
