//! The reduced models: explicit MPM of a tube's section in the x–z plane, with the step, shape
//! functions, contact law, material and energy books of the 3D model (units: mm, ms, g, N,
//! MPa, mJ). [`Symmetry`] says what the removed direction y does:
//!
//! - **axisymmetric**: x is the radius r. A particle stands for its ring (volume 2π·r·area), the
//!   hoop strain rate is v_r / r, and the hoop stress pulls each node of the particle inward by
//!   V·σ_θθ·N / r. Shear in r–θ and θ–z stays zero.
//! - **plane strain**: x and z span the cross-section; the strain rate along the tube is zero and
//!   σ_yy follows from the return map. A particle stands for the tube's length (volume
//!   area · l), so the loads are those of a tube whose every section deforms alike: the ends'
//!   free edges are left out.
//!
//! Stress stays in the 3D layout (`Sym`: xx, yy, zz, yz, xz, xy), with y the removed direction:
//! σ_yy is the hoop (or axial) stress. The step is the 3D one phase for phase (see
//! `step/mod.rs`): full scatter, grid update with the plates, FLIP velocity, remap scatter, remap
//! with the plates (its catch added to the particles near them), kinematics, stress.

mod grid;
mod passes;
mod patch;

use super::grid::Transfer;
use super::kernel::{Clock, Engine, Phases, SolveError, State};
use super::scene::Scene;
use super::shape::Stencil;
use super::stress::ChunkSums;
use crate::solver::model::case::Model;
use crate::solver::model::contact::{self, ContactSums};
use crate::solver::Real;
use grid::PlaneGrid;
use nalgebra::Matrix3;

/// What the direction a reduced model removes does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symmetry {
    /// x is the radius: hoop strain v_r / r, hoop stress in the radial force.
    Axisymmetric,
    /// No strain along y.
    PlaneStrain,
}

impl Symmetry {
    /// The symmetry of a reduced model; None for 3D.
    pub fn of(model: Model) -> Option<Symmetry> {
        match model {
            Model::ThreeD => None,
            Model::Axisymmetric => Some(Symmetry::Axisymmetric),
            Model::PlaneStrain => Some(Symmetry::PlaneStrain),
        }
    }

    /// A hoop term, `value / r` at radius `r` (x), where the hoop terms act; exactly 0 in
    /// plane strain, where x is no radius and may be 0 (a particle on the middle of a
    /// rectangular tube's face: 0 · (0 / 0) would be NaN).
    #[inline(always)]
    fn hoop_term(self, value: Real, r: Real) -> Real {
        match self {
            Symmetry::Axisymmetric => value / r,
            Symmetry::PlaneStrain => 0.0,
        }
    }
}

/// Working memory of a reduced model's step (none of it state).
#[derive(Debug, Default)]
struct Scratch {
    /// Per particle: its velocity gradient of this step (1/ms), in the 3D layout.
    gradient: Vec<Matrix3<Real>>,
    /// Per particle: the grid cell (index as a node's) it stood in at the start of the step.
    cell_of: Vec<u32>,
    /// Per cell, with volumetric averaging: its particles' volume, then their volume-weighted
    /// mean dilation rate (1/ms) and pressure (MPa).
    averages: Option<Vec<[Real; 3]>>,
    /// The scatter's per-run sums.
    patches: Vec<patch::Patch>,
    /// Per chunk of particles, the stress update's sums.
    chunk_sums: Vec<ChunkSums>,
}

/// A reduced model: the tube's section advancing in time with shape function `S`.
pub struct Reduced<S: Stencil> {
    pub state: State,
    symmetry: Symmetry,
    grid: PlaneGrid<S>,
    scratch: Scratch,
}

impl<S: Stencil> Reduced<S> {
    /// A section scene (built by `Scene::from_case` for a reduced model) under `symmetry`.
    pub fn new(scene: Scene, symmetry: Symmetry) -> Reduced<S> {
        let n = scene.particles.len();
        let scratch = Scratch {
            gradient: vec![Matrix3::zeros(); n],
            cell_of: vec![0; n],
            averages: scene.average_volumetric.then(Vec::new),
            patches: Vec::new(),
            chunk_sums: Vec::new(),
        };
        Reduced {
            grid: PlaneGrid::new(scene.cell),
            state: State::new(scene),
            symmetry,
            scratch,
        }
    }
}

impl<S: Stencil> Phases for Reduced<S> {
    fn bin(&mut self, lp: Real) {
        self.grid.fit(&self.state.scene.particles.x, lp);
    }
    fn scatter<T: Transfer>(&mut self, lp: Real, _clock: &mut Clock) {
        self.scatter_particles::<T>(lp);
    }
    fn grid_update(&mut self, dt: Real) -> ContactSums {
        self.update_nodes(dt)
    }
    fn g2p_velocity(&mut self, lp: Real) {
        self.gather_change(lp, |_| true);
    }
    fn remap(&mut self) -> ContactSums {
        self.remap_nodes()
    }
    fn g2p_catch(&mut self, lp: Real) {
        let (plates, cell) = (self.state.scene.plates.clone(), self.state.scene.cell);
        self.gather_change(lp, contact::near_a_plate(&plates, cell, S::N));
    }
    fn g2p_kinematics(&mut self, lp: Real, dt: Real) {
        self.gather_kinematics(lp, dt);
    }
    fn update_stress(&mut self, dt: Real) -> Result<Real, SolveError> {
        self.stress_update(dt)
    }
}

impl<S: Stencil> Engine for Reduced<S> {
    fn state(&self) -> &State {
        &self.state
    }
    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
    fn active_cells(&self) -> u64 {
        self.grid.len() as u64
    }
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        let s = &self.scratch;
        self.state.scene.particles.bytes()
            + self.grid.bytes()
            + s.gradient.capacity() * size_of::<Matrix3<Real>>()
            + s.cell_of.capacity() * size_of::<u32>()
            + s.averages
                .as_ref()
                .map_or(0, |a| a.capacity() * size_of::<[Real; 3]>())
            + s.patches.iter().map(|p| p.bytes()).sum::<usize>()
    }
}

#[cfg(test)]
mod tests;
