//! The engine: how a case is computed. The shared kernel lives here — the [`Engine`] trait
//! every model implements, the [`State`] it carries from step to step, the clock, the energy
//! books and the per-particle stress loop (`stress.rs`) — with the two models beneath it as
//! siblings: [`solid`], the whole tube in 3D, and [`section`], a tube's section on two axes
//! (axisymmetric or plane strain). Beside them: the grid, the shape functions, the particles,
//! the scene a case becomes, the run loop with its observer, history rows and checkpoints.
//! Units: mm, ms, g, N, MPa, mJ.
//!
//! May import the model floor (`super::model`), never the analysis floor. The models import
//! the kernel and the shared pieces here, never each other.
//!
//! The shape function is a type, `S`: [`simulate`] turns the case's choice into it once, and
//! the model with it. What a model carries from step to step is its [`State`] (the scene, the
//! clock, the energy books); everything recomputed within a step is the model's working
//! memory. [`Engine::step`] wraps any model's phases ([`Engine::advance`]) in what every step
//! does before and after them.

pub mod checkpoint;
pub mod grid;
pub mod history;
pub mod observer;
pub mod particles;
mod run;
pub mod scene;
pub mod section;
pub mod shape;
pub mod solid;
pub(crate) mod stress;

pub use run::{resume, run, run_scene, Finished, RunCost, Snapshot};

use super::model::case::{Model, ShapeKind};
use super::model::contact::ContactSums;
use super::Real;
use scene::Scene;
use section::{Section, Symmetry};
use shape::{Gimp, Linear};
use solid::Simulation;

/// Why a run ended without a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    #[error("cancelled at step {step}")]
    Cancelled { step: u64 },
    /// The numbers went bad: which quantity, where and when.
    #[error("unstable at step {step} (t = {time_ms:.6} ms): {what}")]
    Unstable {
        step: u64,
        time_ms: f64,
        what: String,
    },
}

/// Energy integrals since the start, mJ. What the plates put in (`work`) goes to kinetic energy,
/// `internal` energy, the projection's `catch` and `friction`; what is left is numerical.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// ∫ σ:D dV dt: elastic energy plus plastic work.
    pub internal: Real,
    pub plastic: Real,
    /// Work of each plate (top, bottom) on the tube.
    pub work: [Real; 2],
    /// Dissipated by the normal part of the contact projection (nodes caught by a plate).
    pub catch: Real,
    /// Dissipated by friction at the plates.
    pub friction: Real,
}

impl Energies {
    /// Work of both plates on the tube, mJ.
    pub fn external(&self) -> Real {
        self.work[0] + self.work[1]
    }
}

/// What the last step did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepInfo {
    /// The step taken, ms.
    pub dt: Real,
    /// The step the CFL condition allowed (larger than `dt` when a history row was due), ms.
    pub stable_dt: Real,
    pub contact: ContactSums,
    /// Kinetic energy after the step, mJ.
    pub kinetic: Real,
}

/// Wall time spent in each phase since the start, s.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PhaseTimes {
    /// Binning particles into blocks and building the sparse grid.
    pub bin: f64,
    /// Particle → grid transfers (both).
    pub p2g: f64,
    /// Reductions and grid updates with contact.
    pub grid: f64,
    /// Grid → particle transfers (velocity; gradient and position).
    pub g2p: f64,
    /// Cell averages and the stress update.
    pub stress: f64,
}

/// Times the phases of a step.
pub(crate) struct Clock(std::time::Instant);

impl Clock {
    pub(crate) fn start() -> Clock {
        Clock(std::time::Instant::now())
    }
    /// Adds the time since the last lap (or the start) to `into`.
    pub(crate) fn lap(&mut self, into: &mut f64) {
        let now = std::time::Instant::now();
        *into += (now - self.0).as_secs_f64();
        self.0 = now;
    }
}

/// What a model carries from step to step besides its grid: the scene, the clock, the energy
/// books, and the two figures the next step needs (its signal speed and the grid's mass floor).
#[derive(Debug)]
pub struct State {
    pub scene: Scene,
    /// Simulated time, ms.
    pub time: Real,
    pub steps: u64,
    pub energy: Energies,
    pub phases: PhaseTimes,
    /// Largest c + |v| over the particles after the last step, mm/ms.
    pub(crate) signal: Real,
    /// Nodes lighter than this carry no velocity (guards divisions by tiny masses), g.
    pub(crate) mass_floor: Real,
}

impl State {
    /// At time 0, before the first step.
    pub fn new(scene: Scene) -> State {
        let n = scene.particles.len();
        let mean_mass = scene.particles.mass.iter().sum::<Real>() / n.max(1) as Real;
        let vmax = scene
            .particles
            .v
            .iter()
            .map(|v| v.norm())
            .fold(0.0, Real::max);
        State {
            signal: scene.wave_speed() + vmax,
            mass_floor: 1e-14 * mean_mass,
            scene,
            time: 0.0,
            steps: 0,
            energy: Energies::default(),
            phases: PhaseTimes::default(),
        }
    }

    /// The time step the CFL condition allows now, ms.
    pub fn stable_dt(&self) -> Real {
        self.scene.cfl * self.scene.cell / self.signal
    }
}

/// A model's time stepping: the 3D [`Simulation`] or a reduced model's [`Section`]. Each does
/// the phases of a step ([`Engine::advance`]); what comes before and after them (the step's
/// size, the plates, the clock, the contact's books) is [`Engine::step`], the same for all.
pub trait Engine {
    fn state(&self) -> &State;
    fn state_mut(&mut self) -> &mut State;
    /// The phases of one step of `dt` (ms), with the plates' velocities over it set: particles
    /// and grid advance, the state's signal speed, internal energy and phase times are
    /// updated. Returns the contact sums and the kinetic energy after the step. Called by
    /// [`Engine::step`].
    fn advance(&mut self, dt: Real) -> Result<(ContactSums, Real), SolveError>;
    /// Grid cells the last step spanned.
    fn active_cells(&self) -> u64;
    /// Bytes held by the particles, the grid and the working memory.
    fn bytes(&self) -> usize;

    /// Advances one step of at most `dt_cap` ms.
    fn step(&mut self, dt_cap: Real) -> Result<StepInfo, SolveError> {
        let state = self.state_mut();
        let stable_dt = state.stable_dt();
        let dt = stable_dt.min(dt_cap);
        state.scene.set_plate_velocities(state.time, dt);
        let (contact, kinetic) = self.advance(dt)?;
        let state = self.state_mut();
        let energy = &mut state.energy;
        energy.work[0] += contact.work[0];
        energy.work[1] += contact.work[1];
        energy.catch += contact.catch;
        energy.friction += contact.friction;
        state.scene.move_plates(dt);
        state.time += dt;
        state.steps += 1;
        Ok(StepInfo {
            dt,
            stable_dt,
            contact,
            kinetic,
        })
    }
    fn scene(&self) -> &Scene {
        &self.state().scene
    }
    /// Simulated time, ms.
    fn time(&self) -> Real {
        self.state().time
    }
    fn steps(&self) -> u64 {
        self.state().steps
    }
    fn energy(&self) -> &Energies {
        &self.state().energy
    }
    fn phases(&self) -> &PhaseTimes {
        &self.state().phases
    }
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
        (Some(sym), ShapeKind::Linear) => driver.drive(Section::<Linear>::new(scene, sym)),
        (Some(sym), ShapeKind::Gimp) => driver.drive(Section::<Gimp>::new(scene, sym)),
    }
}
