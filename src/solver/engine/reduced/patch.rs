//! A scatter run's patch: the sums of one band of particles over the section nodes its
//! stencils reach (mass g, momentum g·mm/ms, force N, touch g), before the scatter adds it
//! onto the grid. Imports the section's grid only; `mod.rs` and `passes.rs` import it.

use super::grid::PlaneGrid;
use crate::solver::engine::shape::Stencil;
use crate::solver::Real;
use nalgebra::Vector3;

/// One scatter run's sums over the nodes its stencils reach: per node [mass, momentum x,
/// momentum z, force x, force z, touch] (a remap fills the momentum only).
#[derive(Debug, Default)]
pub(super) struct Patch {
    /// First node, as offsets from the grid's origin.
    pub(super) origin: [usize; 2],
    pub(super) dims: [usize; 2],
    pub(super) nodes: Vec<[Real; 6]>,
}

impl Patch {
    /// Covers the stencils of particles at `x` on grid `g`, cleared.
    pub(super) fn fit<S: Stencil>(&mut self, g: &PlaneGrid<S>, x: &[Vector3<Real>], lp: Real) {
        let (mut lo, mut hi) = (Vector3::repeat(Real::MAX), Vector3::repeat(Real::MIN));
        for p in x {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let (first, last) = (g.stencil(&lo, lp).start, g.stencil(&hi, lp).start);
        self.origin = first;
        self.dims = [last[0] + S::N - first[0], last[1] + S::N - first[1]];
        self.nodes.clear();
        self.nodes.resize(self.dims[0] * self.dims[1], [0.0; 6]);
    }

    #[inline(always)]
    pub(super) fn index(&self, i: usize, k: usize) -> usize {
        debug_assert!(i < self.dims[0] && k < self.dims[1]);
        i * self.dims[1] + k
    }

    pub(super) fn bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<[Real; 6]>()
    }
}
