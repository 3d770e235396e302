//! The whole tube in 3D: one explicit MUSL step, a function per phase (units: mm, ms, g, N,
//! MPa, mJ):
//!
//! 1. [`Grid::bin`]: particles into blocks (every `RESORT_EVERY` steps they are reordered by
//!    block too, and within a block by their stencils' reach);
//! 2. scatter [`Full`] (`transfer.rs`): mass, momentum, internal force and plate touch, reduced
//!    onto the owned nodes;
//! 3. the grid update with the plates (`nodes.rs`): velocity and velocity change per node;
//! 4. g2p velocity: FLIP, each particle adds its stencil's velocity change;
//! 5. scatter [`Remap`]: the new particle momenta onto the same masses;
//! 6. the remap with the plates (`nodes.rs`): the velocity the particles move and strain with;
//!    what the plates caught of it goes to the particles near them too (booked, like step 3);
//! 7. g2p kinematics: velocity gradient and position;
//! 8. the stress update (`deformation.rs`, through the engine's shared loop), with
//!    cell-averaged dilation and pressure if asked (`averages.rs`).
//!
//! The velocity gradient always comes from the remapped grid velocities: a node that a particle
//! barely touches gets a huge velocity from f/m in the grid update, and with linear shape
//! functions its gradient weight does not vanish, so a gradient taken from those velocities
//! (USL) blows up at cell crossings. (An APIC transfer without the remap blew up exactly so
//! with linear shapes, and with GIMP it was unstable once the material yielded.)
//!
//! What a node holds in each phase is in [`Node`]'s table; everything recomputed within a step
//! is in [`Workspace`]. Imports the engine's kernel and shared pieces, never `reduced`.

mod averages;
mod deformation;
mod gradient;
mod nodes;
mod transfer;
mod workspace;

#[cfg(doc)]
use super::grid::Node;
use super::grid::{Grid, Transfer, Velocity, VelocityChange};
use super::kernel::{Clock, Engine, Phases, State, StepInfo};
use super::scene::Scene;
use super::shape::Stencil;
use crate::solver::engine::kernel::SolveError;
use crate::solver::model::contact::{self, ContactSums};
use crate::solver::Real;
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

impl<S: Stencil> Phases for Simulation<S> {
    /// The particles into blocks; every [`RESORT_EVERY`] steps reordered by block, and within a
    /// block by their stencils' reach, first.
    fn bin(&mut self, lp: Real) {
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
    }
    fn scatter<T: Transfer>(&mut self, lp: Real, clock: &mut Clock) {
        self.scatter_passes::<T>(lp, clock);
    }
    fn grid_update(&mut self, dt: Real) -> ContactSums {
        self.update_nodes(dt)
    }
    fn g2p_velocity(&mut self, lp: Real) {
        self.gather_change::<Velocity>(lp, |_| true);
    }
    fn remap(&mut self) -> ContactSums {
        self.remap_nodes()
    }
    fn g2p_catch(&mut self, lp: Real) {
        let (plates, cell) = (self.state.scene.plates.clone(), self.state.scene.cell);
        self.gather_change::<VelocityChange>(lp, contact::near_a_plate(&plates, cell, S::N));
    }
    fn g2p_kinematics(&mut self, lp: Real, dt: Real) {
        self.gather_kinematics(lp, dt);
    }
    fn update_stress(&mut self, dt: Real) -> Result<Real, SolveError> {
        self.stress_update(dt)
    }
}

impl<S: Stencil> Engine for Simulation<S> {
    fn state(&self) -> &State {
        &self.state
    }
    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
    fn active_cells(&self) -> u64 {
        self.grid.len() as u64 * 64
    }
    fn bytes(&self) -> usize {
        self.state.scene.particles.bytes() + self.grid.bytes() + self.workspace.bytes()
    }
}
