//! One explicit MUSL step, a function per phase (units: mm, ms, g, N, MPa, mJ):
//!
//! 1. [`Grid::bin`]: particles into blocks (every `RESORT_EVERY` steps they are reordered by
//!    block too, and within a block by their stencils' reach);
//! 2. scatter [`Full`] (`transfer.rs`): mass, momentum, internal force and plate touch, reduced
//!    onto the owned nodes;
//! 3. the grid update with the plates (`nodes.rs`): velocity and velocity change per node;
//! 4. g2p velocity: FLIP, each particle adds its stencil's velocity change;
//! 5. scatter [`Remap`]: the new particle momenta onto the same masses;
//! 6. the remap with the plates (`nodes.rs`): the velocity the particles move and strain with;
//! 7. g2p kinematics: velocity gradient and position;
//! 8. the stress update (`stress.rs`), with cell-averaged dilation and pressure if asked.
//!
//! The velocity gradient always comes from the remapped grid velocities: a node that a particle
//! barely touches gets a huge velocity from f/m in the grid update, and with linear shape
//! functions its gradient weight does not vanish, so a gradient taken from those velocities
//! (USL) blows up at cell crossings. (We tried an APIC transfer without the remap: it blew up
//! exactly so with linear shapes, and with GIMP it was unstable once the material yielded.)
//!
//! The shape function is a type, `S`: [`simulate`] turns the case's choice into it once.
//! What a node holds in each phase is in [`Node`]'s table. What a model carries from step to
//! step is its [`State`] (the scene, the clock, the energy books); everything recomputed within
//! a step is in [`Workspace`]. [`Engine::step`] wraps any model's phases ([`Engine::advance`])
//! in what every step does before and after them.

mod nodes;
mod stress;
mod transfer;
mod workspace;

use super::case::{Model, ShapeKind};
use super::contact::ContactSums;
#[cfg(doc)]
use super::grid::Node;
use super::grid::{Full, Grid, Remap};
use super::scene::Scene;
use super::section::{Section, Symmetry};
use super::shape::{Gimp, Linear, Stencil};
use super::{Real, SolveError};
pub(crate) use stress::{close_books, update_particles, Books, ChunkSums, Deformation};
pub use workspace::Workspace;

/// Every this many steps the particles are reordered block by block, so that the particles a
/// block scatters are neighbours in memory too (measured: without it the time per
/// particle-step grew by half from 110 k to 520 k particles). Particles move a small fraction
/// of a block in this many steps. Within a block they are ordered by their stencils' reach
/// ([`Bins::order_by_reach`](super::grid::bin::Bins::order_by_reach)), and by index within a
/// reach: a transfer's loops then take the same branches for runs of particles (measured on the
/// paper's case, n = 6, uGIMP: the whole run 1.15× as fast). The index order matters too: the
/// particles are built layer by layer, round the tube and through the wall, so neighbours in
/// memory sit alike in their cells (an arbitrary order within the blocks was 20 % slower).
const RESORT_EVERY: u64 = 100;

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

/// A scene advancing in time with shape function `S`.
pub struct Simulation<S: Stencil> {
    pub state: State,
    pub grid: Grid<S>,
    pub workspace: Workspace,
}

impl<S: Stencil> Simulation<S> {
    pub fn new(scene: Scene) -> Simulation<S> {
        Simulation {
            grid: Grid::new(scene.cell),
            workspace: Workspace::new(scene.particles.len(), scene.average_volumetric),
            state: State::new(scene),
        }
    }

    /// Advances one step of at most `dt_cap` ms ([`Engine::step`]).
    pub fn step(&mut self, dt_cap: Real) -> Result<StepInfo, SolveError> {
        Engine::step(self, dt_cap)
    }
}

impl<S: Stencil> Engine for Simulation<S> {
    fn state(&self) -> &State {
        &self.state
    }
    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
    /// The phases in the order of the module doc.
    fn advance(&mut self, dt: Real) -> Result<(ContactSums, Real), SolveError> {
        let lp = self.state.scene.half_size / self.state.scene.cell;
        let mut clock = Clock::start();
        self.grid.bin(&self.state.scene.particles.x, lp);
        if self.state.steps.is_multiple_of(RESORT_EVERY) {
            let (x, inv) = (&self.state.scene.particles.x, self.grid.inv_cell);
            self.grid.bins.order_by_reach::<S>(x, inv, lp);
            let seen = &mut self.workspace.seen;
            self.state
                .scene
                .particles
                .permute(&self.grid.bins.order, seen);
            self.grid.bins.adopt_order(seen);
        }
        clock.lap(&mut self.state.phases.bin);
        self.scatter::<Full>(lp, &mut clock);
        let contact = self.grid_update(dt);
        clock.lap(&mut self.state.phases.grid);
        self.g2p_velocity(lp);
        clock.lap(&mut self.state.phases.g2p);
        self.scatter::<Remap>(lp, &mut clock);
        self.remap();
        clock.lap(&mut self.state.phases.grid);
        self.g2p_kinematics(lp, dt);
        clock.lap(&mut self.state.phases.g2p);
        let kinetic = self.update_stress(dt)?;
        clock.lap(&mut self.state.phases.stress);
        Ok((contact, kinetic))
    }
    fn active_cells(&self) -> u64 {
        self.grid.len() as u64 * 64
    }
    fn bytes(&self) -> usize {
        self.state.scene.particles.bytes() + self.grid.bytes() + self.workspace.bytes()
    }
}
