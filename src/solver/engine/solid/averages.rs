//! Volumetric averaging in 3D: per grid cell, the volume-weighted mean dilation rate and
//! pressure of the particles in it, which replace each particle's own in the stress update (as
//! in a Q1–P0 element). Units: 1/ms, MPa, mm³.

use super::gradient::Gradient;
use crate::solver::engine::grid::bin::Bins;
use crate::solver::engine::particles::Particles;
use crate::solver::Real;
use rayon::prelude::*;

/// Per block that holds particles (in the order of [`Bins::occupied`]) and cell: the
/// volume-weighted mean dilation rate tr(L) (1/ms) and pressure (MPa) of the particles in the
/// cell.
#[derive(Debug, Default)]
pub struct VolumetricAverages {
    dilation: Vec<[Real; 64]>,
    pressure: Vec<[Real; 64]>,
}

impl VolumetricAverages {
    /// Averages over the cells of `bins`, from the particles' stresses and velocity gradients.
    pub(super) fn compute(&mut self, bins: &Bins, p: &Particles, grad: &[Gradient]) {
        let occupied = bins.occupied.len();
        self.dilation.resize(occupied, [0.0; 64]);
        self.pressure.resize(occupied, [0.0; 64]);
        (self.dilation.par_iter_mut(), self.pressure.par_iter_mut())
            .into_par_iter()
            .zip(&bins.occupied)
            .for_each(|((dil, pre), &b)| {
                let mut vol = [0.0; 64];
                *dil = [0.0; 64];
                *pre = [0.0; 64];
                for &q in bins.particles_of(b as usize) {
                    let q = q as usize;
                    let c = bins.cell_of[q] as usize;
                    let s = &p.stress[q];
                    vol[c] += p.vol[q];
                    dil[c] += p.vol[q] * grad[q].trace() as Real;
                    pre[c] += p.vol[q] * (s[0] + s[1] + s[2]) / 3.0;
                }
                for c in 0..64 {
                    if vol[c] > 0.0 {
                        dil[c] /= vol[c];
                        pre[c] /= vol[c];
                    }
                }
            });
    }

    /// The dilation rate and pressure of particle `q`'s cell.
    #[inline(always)]
    pub(super) fn of(&self, bins: &Bins, q: usize) -> (Real, Real) {
        let (b, cell) = (bins.home[q] as usize, bins.cell_of[q] as usize);
        let s = bins.place(b);
        (self.dilation[s][cell], self.pressure[s][cell])
    }

    pub fn bytes(&self) -> usize {
        (self.dilation.capacity() + self.pressure.capacity()) * std::mem::size_of::<[Real; 64]>()
    }
}
