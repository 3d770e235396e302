//! The 3D model's side of the stress update: each particle's velocity gradient from the
//! kinematics gather and, with volumetric averaging, its cell's mean dilation and pressure;
//! the shared loop (`engine/stress.rs`) does the rest.

use super::averages::VolumetricAverages;
use super::gradient::Gradient;
use super::transfer::CHUNK;
use super::Simulation;
use crate::solver::engine::grid::bin::Bins;
use crate::solver::engine::kernel::SolveError;
use crate::solver::engine::shape::Stencil;
use crate::solver::engine::stress::{close_books, update_particles, Books, Deformation};
use crate::solver::Real;
use nalgebra::Matrix3;

/// The 3D simulation's [`Deformation`]: gradients from the kinematics gather, averages per
/// block and cell.
struct Solid<'a> {
    grads: &'a [Gradient],
    averages: Option<(&'a VolumetricAverages, &'a Bins)>,
}

impl Deformation for Solid<'_> {
    #[inline(always)]
    fn gradient(&self, q: usize) -> (Matrix3<Real>, Option<(Real, Real)>) {
        let averages = self.averages.map(|(a, bins)| a.of(bins, q));
        (self.grads[q].cast(), averages)
    }
    #[inline(always)]
    fn volume_factor(&self, l: &Matrix3<Real>, dt: Real) -> Real {
        (Matrix3::identity() + l * dt).determinant()
    }
}

impl<S: Stencil> Simulation<S> {
    /// Stress, volume and energy update from the velocity gradients of `g2p_kinematics`, with
    /// the cell-averaged dilation and pressure when the scene asks for them. Finds the next
    /// step's signal speed and any particle that went bad. Returns the kinetic energy, mJ.
    pub(super) fn stress_update(&mut self, dt: Real) -> Result<Real, SolveError> {
        let work = &mut self.workspace;
        let bins = &self.grid.bins;
        let averages = work.averages.as_mut().map(|a| {
            a.compute(bins, &self.state.scene.particles, &work.velocity_gradient);
            &*a
        });
        let books = Books::of(&self.state.scene, dt);
        let material = self.state.scene.material;
        let solid = Solid {
            grads: &work.velocity_gradient,
            averages: averages.map(|a| (a, bins)),
        };
        update_particles(
            &mut self.state.scene.particles,
            (&material, &books),
            (CHUNK, &mut work.chunk_sums),
            &solid,
        );
        let x = &self.state.scene.particles.x;
        let id = &self.state.scene.particles.id;
        let (kinetic, signal) = close_books(
            &work.chunk_sums,
            &mut self.state.energy,
            (self.state.steps + 1, self.state.time + dt),
            |q| {
                let (x, id) = (x[q], id[q]);
                format!("particle {id} at ({:.4}, {:.4}, {:.4}) mm", x.x, x.y, x.z)
            },
        )?;
        self.state.signal = signal;
        Ok(kinetic)
    }
}
