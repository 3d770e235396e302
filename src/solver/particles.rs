//! Particle state, struct of arrays. Units: mm, m/s (= mm/ms), g, mm³, MPa.

use super::material::Sym;
use super::Real;
use nalgebra::{Matrix3, Vector3};

/// Every particle's state; all vectors have one entry per particle.
#[derive(Debug, Clone, Default)]
pub struct Particles {
    pub x: Vec<Vector3<Real>>,
    pub v: Vec<Vector3<Real>>,
    /// Cauchy stress, MPa.
    pub stress: Vec<Sym>,
    /// Mass, g (constant).
    pub mass: Vec<Real>,
    /// Current volume, mm³.
    pub vol: Vec<Real>,
    /// Equivalent plastic strain.
    pub plastic_strain: Vec<Real>,
    /// Velocity gradient of the current step (1/ms), between kinematics and stress update.
    pub grad: Vec<Matrix3<Real>>,
    /// Yield stress factor per particle; empty when the scene has no weak particles.
    pub yield_scale: Vec<Real>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Adds a particle at rest, unstressed.
    pub fn push(&mut self, x: Vector3<Real>, mass: Real, vol: Real) {
        self.x.push(x);
        self.v.push(Vector3::zeros());
        self.stress.push([0.0; 6]);
        self.mass.push(mass);
        self.vol.push(vol);
        self.plastic_strain.push(0.0);
    }

    /// Total momentum, g·mm/ms.
    pub fn momentum(&self) -> Vector3<Real> {
        self.v.iter().zip(&self.mass).map(|(v, m)| v * *m).sum()
    }

    /// Bytes held per particle by these arrays (capacity, not length).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.x.capacity() * size_of::<Vector3<Real>>()
            + self.v.capacity() * size_of::<Vector3<Real>>()
            + self.stress.capacity() * size_of::<Sym>()
            + (self.mass.capacity() + self.vol.capacity() + self.plastic_strain.capacity())
                * size_of::<Real>()
            + self.grad.capacity() * size_of::<Matrix3<Real>>()
            + self.yield_scale.capacity() * size_of::<Real>()
    }
}
