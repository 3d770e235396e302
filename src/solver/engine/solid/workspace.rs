//! Working memory of a step: everything recomputed within a step, kept between steps only so
//! that the step loop allocates nothing. None of it is simulation state.

use super::averages::VolumetricAverages;
use super::gradient::Gradient;
use crate::solver::engine::stress::ChunkSums;
use crate::solver::model::contact::ContactSums;
use nalgebra::Matrix3;

#[derive(Debug, Default)]
pub struct Workspace {
    /// Each particle's velocity gradient of the current step (1/ms), from the kinematics
    /// gather to the stress update: computed in f64, stored in f32 (see [`Gradient`]).
    pub velocity_gradient: Vec<Gradient>,
    /// Cell averages, when the scene averages dilation and pressure.
    pub averages: Option<VolumetricAverages>,
    /// Per chunk of particles: the stress update's sums.
    pub chunk_sums: Vec<ChunkSums>,
    /// Per block: the grid update's contact sums.
    pub block_sums: Vec<ContactSums>,
    /// Scratch of the particle reordering.
    pub seen: Vec<bool>,
}

impl Workspace {
    /// For `particles` particles, with cell averages when `average_volumetric`.
    pub fn new(particles: usize, average_volumetric: bool) -> Workspace {
        Workspace {
            velocity_gradient: vec![Matrix3::zeros(); particles],
            averages: average_volumetric.then(VolumetricAverages::default),
            ..Default::default()
        }
    }

    /// Bytes held (capacity, not length).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.velocity_gradient.capacity() * size_of::<Gradient>()
            + self.averages.as_ref().map_or(0, VolumetricAverages::bytes)
            + self.chunk_sums.capacity() * size_of::<ChunkSums>()
            + self.block_sums.capacity() * size_of::<ContactSums>()
            + self.seen.capacity()
    }
}
