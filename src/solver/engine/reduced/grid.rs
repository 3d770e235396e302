//! The background grid of a section: a dense rectangle of nodes over the x–z box the particles'
//! stencils reach this step (a section is a few thousand particles, and its box a few tens of
//! thousands of nodes at most, so no sparse blocks). Units: mm, ms, g, N.
//!
//! What a node holds, by phase (each its own array, so that a name never changes meaning):
//!
//! | phase | arrays written |
//! |---|---|
//! | [`Full`](crate::solver::engine::grid::Full) scatter | `mass`, `momentum`, `force`, `touch` |
//! | grid update | `velocity`, `change` (velocity change of the step), `slip` (the plate's tangential impulse, whose friction the remap finishes booking) |
//! | [`Remap`](crate::solver::engine::grid::Remap) scatter | `momentum` (the particles' new momenta) |
//! | remap | `velocity` (what the particles move and strain with), `change` (the plates' change of it) |

use crate::solver::engine::shape::Stencil;
use crate::solver::Real;
use nalgebra::Vector3;
use std::marker::PhantomData;

/// An (x, z) pair: the section's in-plane components.
pub type Pair = [Real; 2];

/// A particle's stencil in a [`PlaneGrid`]: its first node as offsets from the grid's origin
/// (x, z), and the weights and their derivatives (per grid unit) along x and along z.
#[derive(Debug, Clone, Copy)]
pub struct PlaneStencil {
    pub start: [usize; 2],
    pub w: [[Real; 3]; 2],
    pub g: [[Real; 3]; 2],
}

/// The nodes of one step, shape function `S`.
#[derive(Debug, Default)]
pub struct PlaneGrid<S: Stencil> {
    /// 1 / cell size, 1/mm.
    pub inv_cell: Real,
    /// Node index (x, z) of the first node.
    pub origin: [i32; 2],
    /// Nodes along x and along z.
    pub dims: [usize; 2],
    pub mass: Vec<Real>,
    /// Σ m·N·side of the particles touching a plate (see `contact::plate_of`).
    pub touch: Vec<Real>,
    pub momentum: Vec<Pair>,
    pub force: Vec<Pair>,
    pub velocity: Vec<Pair>,
    pub change: Vec<Pair>,
    /// The grid update's tangential (x) impulse of the plates on the node, N·ms.
    pub slip: Vec<Real>,
    shape: PhantomData<S>,
}

impl<S: Stencil> PlaneGrid<S> {
    pub fn new(cell: Real) -> PlaneGrid<S> {
        PlaneGrid {
            inv_cell: 1.0 / cell,
            origin: [0, 0],
            dims: [0, 0],
            mass: Vec::new(),
            touch: Vec::new(),
            momentum: Vec::new(),
            force: Vec::new(),
            velocity: Vec::new(),
            change: Vec::new(),
            slip: Vec::new(),
            shape: PhantomData,
        }
    }

    /// Places the rectangle over every node the stencils of particles at `x` (half-size `lp`,
    /// grid units) reach, and clears what the full scatter adds to. Allocates only when the
    /// rectangle outgrows every earlier one.
    pub fn fit(&mut self, x: &[Vector3<Real>], lp: Real) {
        let (mut lo, mut hi) = ([Real::MAX; 2], [Real::MIN; 2]);
        for p in x {
            for (a, c) in [p.x, p.z].into_iter().enumerate() {
                lo[a] = lo[a].min(c);
                hi[a] = hi[a].max(c);
            }
        }
        for a in 0..2 {
            let first = S::eval(lo[a] * self.inv_cell, lp).base;
            let last = S::eval(hi[a] * self.inv_cell, lp).base + S::N as i32 - 1;
            self.origin[a] = first;
            self.dims[a] = (last - first + 1).max(1) as usize;
        }
        let len = self.len();
        for v in [&mut self.mass, &mut self.touch] {
            v.clear();
            v.resize(len, 0.0);
        }
        for v in [&mut self.momentum, &mut self.force] {
            v.clear();
            v.resize(len, [0.0; 2]);
        }
        // The node passes write every node's velocity and change: sized, not cleared.
        self.velocity.resize(len, [0.0; 2]);
        self.change.resize(len, [0.0; 2]);
        self.slip.resize(len, 0.0);
    }

    /// Nodes in the rectangle.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1]
    }

    /// Index of node (i, k) given as offsets from the origin (z runs fastest).
    #[inline(always)]
    pub fn index(&self, i: usize, k: usize) -> usize {
        debug_assert!(
            i < self.dims[0] && k < self.dims[1],
            "stencil overran the grid"
        );
        i * self.dims[1] + k
    }

    /// A particle at `x` (mm): its stencil in this grid.
    #[inline(always)]
    pub fn stencil(&self, x: &Vector3<Real>, lp: Real) -> PlaneStencil {
        let ax = S::eval(x.x * self.inv_cell, lp);
        let az = S::eval(x.z * self.inv_cell, lp);
        debug_assert!(ax.base >= self.origin[0] && az.base >= self.origin[1]);
        PlaneStencil {
            start: [
                (ax.base - self.origin[0]) as usize,
                (az.base - self.origin[1]) as usize,
            ],
            w: [ax.w, az.w],
            g: [ax.g, az.g],
        }
    }

    /// Bytes held (capacity).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        (self.mass.capacity() + self.touch.capacity() + self.slip.capacity()) * size_of::<Real>()
            + (self.momentum.capacity()
                + self.force.capacity()
                + self.velocity.capacity()
                + self.change.capacity())
                * size_of::<Pair>()
    }
}
