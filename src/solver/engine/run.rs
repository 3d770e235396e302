//! The run loop: a case → scene → steps until the plate has travelled the crush distance, with
//! history rows at equal displacement intervals, progress reports, the frames of a time series,
//! checkpoints, cancellation and blow-up detection. A run continued from a checkpoint ([`resume`]) gives the same bits as
//! one that never stopped. Units: mm, ms, N, mJ.

use super::checkpoint::{Checkpoint, Resume, Tally};
use super::frames::Schedule;
use super::history::HistoryRow;
use super::kernel::{Engine, SolveError};
use super::observer::{Observer, Progress};
use super::reduced::{Reduced, Symmetry};
use super::scene::{Scene, BOTTOM, TOP};
use super::shape::{Bspline, Gimp, Linear};
use super::solid::Simulation;
use crate::solver::model::case::Case;
use crate::solver::model::case::{Model, ShapeKind};
use crate::solver::Real;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// What a finished run computed, before any analysis.
#[derive(Debug, Clone)]
pub struct Finished {
    pub history: Vec<HistoryRow>,
    pub snapshot: Snapshot,
    pub cost: RunCost,
}

/// Final particle state, in the scene's particle order.
#[derive(Debug, Clone, Default)]
pub struct Snapshot {
    /// Positions before the crush, mm.
    pub initial_mm: Vec<[Real; 3]>,
    /// Positions at the end, mm.
    pub position_mm: Vec<[Real; 3]>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<Real>,
}

/// What the run cost.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct RunCost {
    pub particles: u64,
    /// Most grid cells active at once.
    pub active_cells_max: u64,
    pub steps: u64,
    pub dt_min_ms: f64,
    pub dt_max_ms: f64,
    pub wall_time_s: f64,
    pub particle_steps_per_s: f64,
    pub threads: u32,
    /// Mean distance between a plate and the nearest particle's edge while in contact, mm.
    pub contact_gap_mm: f64,
}

/// Runs a case to the end on the current rayon pool, reporting through `observer` once per
/// history row; stops within one step once `cancel` is set.
pub fn run(
    case: &Case,
    observer: &mut dyn Observer,
    cancel: &AtomicBool,
) -> Result<Finished, SolveError> {
    run_scene(case, Scene::from_case(case), observer, cancel)
}

/// [`run`] from a checkpoint of the same case (read by [`Resume::read`]): the run goes on from
/// the checkpoint's step and ends with the history, summary and final state the run that wrote
/// it would have ended with (all but the wall-time figures, which add both stretches' times).
pub fn resume(
    case: &Case,
    from: Resume,
    observer: &mut dyn Observer,
    cancel: &AtomicBool,
) -> Result<Finished, SolveError> {
    let run = Run {
        case,
        observer,
        cancel,
        start: Instant::now(),
        from: Some(from),
    };
    simulate(
        case.spec().discretization.model,
        case.shape(),
        Scene::from_case(case),
        run,
    )
}

/// [`run`] on a scene built from `case` and then changed: for checks that must run what no
/// valid case describes (a time step past the stability limit, say) through the same loop and
/// the same blow-up detection.
pub fn run_scene(
    case: &Case,
    scene: Scene,
    observer: &mut dyn Observer,
    cancel: &AtomicBool,
) -> Result<Finished, SolveError> {
    let run = Run {
        case,
        observer,
        cancel,
        start: Instant::now(),
        from: None,
    };
    simulate(case.spec().discretization.model, case.shape(), scene, run)
}

/// The loop of one run, for whichever model and shape function the case chose.
struct Run<'a> {
    case: &'a Case,
    observer: &'a mut dyn Observer,
    cancel: &'a AtomicBool,
    start: Instant,
    /// The checkpoint to continue from.
    from: Option<Resume>,
}

impl Driver for Run<'_> {
    type Output = Result<Finished, SolveError>;

    fn drive<E: Engine>(self, mut sim: E) -> Self::Output {
        let Run {
            case,
            observer,
            cancel,
            start,
            from,
        } = self;
        let spec = case.spec();
        let speed = spec.loading.plate_speed_m_s;
        let crush = case.crush_distance_mm();
        let points = spec.output.history_points as usize;
        let ramp = sim.scene().ramp;
        // The time the plate would take at full speed; the rows are at equal travel.
        let duration = crush / speed;
        let resumed = from.is_some();
        let mut tally = match from {
            Some(from) => from.restore(&mut sim),
            None => Tally::new(points),
        };
        let before_s = tally.elapsed_s;
        let elapsed = |start: Instant| before_s + start.elapsed().as_secs_f64();
        let resumed_at = resumed.then(|| sim.time());
        let rows_at_start = tally.rows.len();
        let mut frames = Schedule::new(case, ramp, duration, resumed_at);
        frames.send_due(case, &sim, observer);
        for k in tally.rows.len() + 1..=points {
            let end = ramp.time_at(duration * k as Real / points as Real);
            while end - sim.time() > 1e-9 * duration {
                if observer.wants_checkpoint() {
                    tally.elapsed_s = elapsed(start);
                    observer.on_checkpoint(Checkpoint::write(case, &sim, &tally, points));
                }
                if cancel.load(Ordering::Relaxed) {
                    if observer.checkpoint_on_stop() {
                        tally.elapsed_s = elapsed(start);
                        observer.on_checkpoint(Checkpoint::write(case, &sim, &tally, points));
                    }
                    return Err(SolveError::Cancelled { step: sim.steps() });
                }
                let info = sim.step(end - sim.time())?;
                tally.impulse[0] += info.contact.impulse[0];
                tally.impulse[1] += info.contact.impulse[1];
                tally.kinetic = info.kinetic;
                tally.dt_min_ms = tally.dt_min_ms.min(info.stable_dt);
                tally.dt_max_ms = tally.dt_max_ms.max(info.stable_dt);
                tally.active_cells_max = tally.active_cells_max.max(sim.active_cells());
                runaway(&sim, tally.kinetic)?;
                frames.send_due(case, &sim, observer);
            }
            let interval = sim.time() - tally.row_start_ms;
            let e = *sim.energy();
            let mut row = HistoryRow {
                time_ms: sim.time(),
                displacement_mm: speed * ramp.full_speed_time(sim.time()),
                load_top_n: tally.impulse[0] / interval,
                load_bottom_n: tally.impulse[1] / interval,
                kinetic_mj: tally.kinetic,
                internal_mj: e.internal,
                plastic_mj: e.plastic,
                external_mj: e.external(),
                friction_mj: e.friction,
                elastic_mj: e.internal - e.plastic,
                work_top_mj: e.work[TOP],
                work_bottom_mj: e.work[BOTTOM],
                contact_mj: e.catch,
                residual_mj: 0.0,
            };
            row.residual_mj = row.external_mj - row.booked_mj();
            if row.load_top_n > 0.0 {
                tally.gap_sum += contact_gap(&sim);
                tally.gap_rows += 1;
            }
            observer.on_history(&row);
            let elapsed = elapsed(start);
            let fraction = k as Real / points as Real;
            observer.on_progress(&Progress {
                step: sim.steps(),
                time_ms: sim.time(),
                displacement_mm: row.displacement_mm,
                load_n: row.load_top_n,
                fraction,
                elapsed_s: elapsed,
                eta_s: elapsed * (1.0 - fraction) / fraction,
                error_bar: None,
            });
            tally.rows.push(row);
            tally.row_start_ms = sim.time();
            tally.impulse = [0.0; 2];
            tally.kinetic = 0.0;
        }
        if (!resumed || tally.rows.len() > rows_at_start) && observer.checkpoint_at_end() {
            tally.elapsed_s = elapsed(start);
            observer.on_checkpoint(Checkpoint::write(case, &sim, &tally, points));
        }
        let p = &sim.scene().particles;
        let geometry = case.geometry();
        let snapshot = Snapshot {
            initial_mm: geometry.positions(),
            position_mm: p.in_original_order(|i| geometry.reported(&p.x[i])),
            plastic_strain: p.in_original_order(|i| p.plastic_strain[i]),
        };
        let mut cost = RunCost {
            particles: p.len() as u64,
            steps: sim.steps(),
            dt_min_ms: tally.dt_min_ms,
            dt_max_ms: tally.dt_max_ms,
            active_cells_max: tally.active_cells_max,
            wall_time_s: elapsed(start),
            threads: rayon::current_num_threads() as u32,
            contact_gap_mm: if tally.gap_rows > 0 {
                tally.gap_sum / tally.gap_rows as Real
            } else {
                0.0
            },
            ..Default::default()
        };
        cost.particle_steps_per_s = cost.particles as Real * cost.steps as Real / cost.wall_time_s;
        Ok(Finished {
            history: tally.rows,
            snapshot,
            cost,
        })
    }
}

/// Kinetic energy can never exceed the work the plates put in (the tube starts at rest);
/// 20 % above it means the integration is creating energy.
fn runaway<E: Engine>(sim: &E, kinetic: Real) -> Result<(), SolveError> {
    let work = sim.energy().external();
    if !kinetic.is_finite() || kinetic > 1.2 * work + 1e-12 {
        return Err(SolveError::Unstable {
            step: sim.steps(),
            time_ms: sim.time(),
            what: format!(
                "kinetic energy {kinetic:.4e} mJ exceeds the work done by the plates {work:.4e} mJ: \
                 the integration is creating energy (time step too large for the stiffness?)"
            ),
        });
    }
    Ok(())
}

/// Mean of the gaps between each plate and the nearest particle edge, mm.
fn contact_gap<E: Engine>(sim: &E) -> Real {
    let scene = sim.scene();
    let p = &scene.particles;
    let h = scene.half_size;
    let top = p.x.iter().map(|x| x.z).fold(Real::MIN, Real::max) + h;
    let bottom = p.x.iter().map(|x| x.z).fold(Real::MAX, Real::min) - h;
    let plates = &scene.plates;
    0.5 * ((plates[TOP].z - top) + (bottom - plates[BOTTOM].z))
}

/// What to do with a simulation once its model and shape function are types: [`simulate`]
/// calls [`Driver::drive`] with the one the case chose.
pub trait Driver {
    type Output;
    fn drive<E: Engine>(self, sim: E) -> Self::Output;
}

/// The one place where the case's [`Model`] and [`ShapeKind`] become a type.
pub fn simulate<D: Driver>(model: Model, shape: ShapeKind, scene: Scene, driver: D) -> D::Output {
    match (Symmetry::of(model), shape) {
        (None, ShapeKind::Linear) => driver.drive(Simulation::<Linear>::new(scene)),
        (None, ShapeKind::Gimp) => driver.drive(Simulation::<Gimp>::new(scene)),
        (Some(sym), ShapeKind::Linear) => driver.drive(Reduced::<Linear>::new(scene, sym)),
        (Some(sym), ShapeKind::Gimp) => driver.drive(Reduced::<Gimp>::new(scene, sym)),
        (None, ShapeKind::Bspline) => driver.drive(Simulation::<Bspline>::new(scene)),
        (Some(sym), ShapeKind::Bspline) => driver.drive(Reduced::<Bspline>::new(scene, sym)),
    }
}
