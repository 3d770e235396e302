//! Particle ↔ grid transfers: the scatter of a [`Transfer`] and the two gathers (velocity
//! change for FLIP; velocity and its gradient for the kinematics). Units: mm, ms, g, N.

use super::Simulation;
use crate::solver::engine::grid::slabs::{self, Pass};
use crate::solver::engine::grid::{Gathered, Grid, Transfer, Velocity, NONE};
use crate::solver::engine::kernel::Clock;
use crate::solver::engine::shape::{Axis, Gimp, Linear, Stencil};
use crate::solver::model::contact::{self, CONTACT_TOLERANCE};
use crate::solver::model::material::to_matrix;
use crate::solver::Real;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::marker::PhantomData;
use wide::f64x4;

/// Particles per parallel work item in particle-order passes.
pub const CHUNK: usize = 1024;

impl<S: Stencil> Simulation<S> {
    /// Particle → grid for transfer `T`, slab by slab ([`Grid::slabs`]): each slab's blocks
    /// onto their padded buffers (timed as p2g), then the owned nodes of the slab before it
    /// reduced (timed with the grid phase).
    pub(super) fn scatter_passes<T: Transfer>(&mut self, lp: Real, clock: &mut Clock) {
        for pass in slabs::passes(self.grid.slabs.count()) {
            match pass {
                Pass::Scatter(i) => {
                    self.p2g::<T>(i, lp);
                    clock.lap(&mut self.state.phases.p2g);
                }
                Pass::Reduce(i) => {
                    self.grid.reduce::<T>(i);
                    clock.lap(&mut self.state.phases.grid);
                }
            }
        }
    }

    /// The blocks of slab `i` that hold particles, onto their padded buffers.
    fn p2g<T: Transfer>(&mut self, i: usize, lp: Real) {
        let mut padded = std::mem::take(&mut self.grid.padded);
        let len = Grid::<S>::PADDED_LEN;
        let p = &self.state.scene.particles;
        let (plates, half) = (&self.state.scene.plates, self.state.scene.half_size);
        let tolerance = CONTACT_TOLERANCE * half;
        let g = &self.grid;
        let inv = g.inv_cell;
        let (first, count) = g.slabs.ring_of(i);
        let ring = first * len..(first + count) * len;
        (
            padded.lo[ring.clone()].par_chunks_mut(len),
            padded.hi[ring].par_chunks_mut(len),
        )
            .into_par_iter()
            .zip(g.slabs.occupied_of(i))
            .for_each(|((lo, hi), &b)| {
                let b = b as usize;
                // A `Remap` scatter zeroes the mass lane too: `Grid::reduce` then adds only
                // momentum to the owned nodes. It leaves `hi` alone.
                let zero = f64x4::splat(0.0);
                lo.fill(zero);
                if T::FULL {
                    hi.fill(zero);
                }
                let o = g.padded_origin(b);
                for &q in g.bins.particles_of(b) {
                    let q = q as usize;
                    let [ax, ay, az] = S::eval3((p.x[q] * inv).into(), lp);
                    let (wx, wy, wz) = (&ax.w, &ay.w, &az.w);
                    let (gx, gy, gz) = (&ax.g, &ay.g, &az.g);
                    let (ox, oy, oz) = (
                        (ax.base - o[0]) as usize,
                        (ay.base - o[1]) as usize,
                        (az.base - o[2]) as usize,
                    );
                    debug_assert!([ox, oy, oz].iter().all(|&o| o + S::N <= S::PAD));
                    let (m, v) = (p.mass[q], p.v[q]);
                    // [mass, momentum] (no mass in the remap).
                    let mv = f64x4::new([if T::FULL { m } else { 0.0 }, m * v.x, m * v.y, m * v.z]);
                    // Particles touching a plate put their mass, signed by the plate's side, in
                    // the touch lane (see `contact::plate_of`).
                    let touch = if T::FULL {
                        m * contact::touching(plates, p.x[q].z, half, tolerance)
                    } else {
                        0.0
                    };
                    // −σ·V/h by columns, as [force lanes, 0]: the force on node (i, j, k) is
                    // −(c0·∂x + c1·∂y + c2·∂z) of its weight, = fa·N_z + fb·N_z′ per (i, j) row;
                    // the touch lane rides along in `fa`. (Built as vectors once per particle,
                    // not per row: the same products and sums lane by lane.)
                    let vs = to_matrix(&p.stress[q]) * (-p.vol[q] * inv);
                    let col = |c: usize| f64x4::new([vs[(0, c)], vs[(1, c)], vs[(2, c)], 0.0]);
                    let (c0, c1, c2) = (col(0), col(1), col(2));
                    let t = f64x4::new([0.0, 0.0, 0.0, touch]);
                    // Only the x and y nodes that carry weight (z rows stay whole: they are
                    // contiguous).
                    let (nx, ny) = (S::reach(&ax), S::reach(&ay));
                    for i in 0..nx {
                        for j in 0..ny {
                            let (wxy, gxy, wgxy) = (wx[i] * wy[j], gx[i] * wy[j], wx[i] * gy[j]);
                            let row = Grid::<S>::padded_index(ox + i, oy + j, oz);
                            let wv = f64x4::splat(wxy);
                            let m = mv * wv;
                            if T::FULL {
                                let fa = c0 * f64x4::splat(gxy) + c1 * f64x4::splat(wgxy) + t * wv;
                                let fb = c2 * wv;
                                for k in 0..S::N {
                                    let n = row + k;
                                    let w = f64x4::splat(wz[k]);
                                    lo[n] = m.mul_add(w, lo[n]);
                                    hi[n] = fb.mul_add(f64x4::splat(gz[k]), fa.mul_add(w, hi[n]));
                                }
                            } else {
                                for (n, w) in lo[row..row + S::N].iter_mut().zip(wz) {
                                    *n = m.mul_add(f64x4::splat(*w), *n);
                                }
                            }
                        }
                    }
                }
            });
        self.grid.padded = padded;
    }

    /// Grid → particle velocity: add the interpolated velocity change of the nodes to the
    /// particles for which `near(z)` holds, z their height (mm). After the grid update this is
    /// FLIP (every particle; the change in `lo`, `G` = [`Velocity`]); after the remap, the
    /// plates' catch of the remapped velocities (only particles whose stencils can reach a
    /// contact node; the change in `hi`, `G` =
    /// [`VelocityChange`](crate::solver::engine::grid::VelocityChange)).
    pub(super) fn gather_change<G: Gathered>(
        &mut self,
        lp: Real,
        near: impl Fn(Real) -> bool + Sync,
    ) {
        let g = &self.grid;
        let inv = g.inv_cell;
        let p = &mut self.state.scene.particles;
        let x = &p.x;
        // The change's first lane: `lo` is [mass, change], `hi` [change, touch or 0].
        let first = usize::from(G::LO);
        p.v.par_chunks_mut(CHUNK).enumerate().for_each(|(c, vs)| {
            let mut halo = Halo::<G>::new();
            for (i, v) in vs.iter_mut().enumerate() {
                let q = c * CHUNK + i;
                if !near(x[q].z) {
                    continue;
                }
                let Held {
                    nodes,
                    start,
                    axes: [ax, ay, az],
                } = halo.stencil(g, q, x[q] * inv, lp);
                let (nx, ny) = (S::reach(&ax), S::reach(&ay));
                let mut acc = f64x4::splat(0.0);
                for i in 0..nx {
                    for j in 0..ny {
                        let wxy = ax.w[i] * ay.w[j];
                        let row = Grid::<S>::padded_index(start[0] + i, start[1] + j, start[2]);
                        let mut s = f64x4::splat(0.0);
                        for k in 0..S::N {
                            s = nodes[row + k].mul_add(f64x4::splat(az.w[k]), s);
                        }
                        acc = s.mul_add(f64x4::splat(wxy), acc);
                    }
                }
                let a = acc.as_array();
                let dv = Vector3::new(a[first], a[first + 1], a[first + 2]);
                *v += dv;
            }
        });
    }

    /// Grid → particle kinematics: velocity gradient (into the workspace) and position from
    /// the remapped nodal velocities.
    pub(super) fn gather_kinematics(&mut self, lp: Real, dt: Real) {
        let g = &self.grid;
        let inv = g.inv_cell;
        let xs = &mut self.state.scene.particles.x;
        let grads = &mut self.workspace.velocity_gradient;
        (xs.par_chunks_mut(CHUNK), grads.par_chunks_mut(CHUNK))
            .into_par_iter()
            .enumerate()
            .for_each(|(c, (xs, ls))| {
                let mut halo = Halo::<Velocity>::new();
                for (i, (x, grad)) in xs.iter_mut().zip(ls.iter_mut()).enumerate() {
                    let q = c * CHUNK + i;
                    let Held {
                        nodes,
                        start,
                        axes: [ax, ay, az],
                    } = halo.stencil(g, q, *x * inv, lp);
                    // Lanes 1..4 of `lo` are the velocity. Per (i, j) row, s = Σ v·N_z and
                    // t = Σ v·N_z′; then the velocity and the columns of L = Σ v ⊗ ∇N.
                    let zero = f64x4::splat(0.0);
                    let (mut vel, mut l0, mut l1, mut l2) = (zero, zero, zero, zero);
                    let (nx, ny) = (S::reach(&ax), S::reach(&ay));
                    for i in 0..nx {
                        for j in 0..ny {
                            let (wx, wy) = (ax.w[i], ay.w[j]);
                            let (wxy, gxy, wgxy) = (wx * wy, ax.g[i] * wy, wx * ay.g[j]);
                            let row = Grid::<S>::padded_index(start[0] + i, start[1] + j, start[2]);
                            let (mut s, mut t) = (zero, zero);
                            for k in 0..S::N {
                                let vn = nodes[row + k];
                                s = vn.mul_add(f64x4::splat(az.w[k]), s);
                                t = vn.mul_add(f64x4::splat(az.g[k]), t);
                            }
                            vel = s.mul_add(f64x4::splat(wxy), vel);
                            l0 = s.mul_add(f64x4::splat(gxy), l0);
                            l1 = s.mul_add(f64x4::splat(wgxy), l1);
                            l2 = t.mul_add(f64x4::splat(wxy), l2);
                        }
                    }
                    let (c0, c1, c2) = (l0.as_array(), l1.as_array(), l2.as_array());
                    let l = Matrix3::new(
                        c0[1], c1[1], c2[1], c0[2], c1[2], c2[2], c0[3], c1[3], c2[3],
                    );
                    let vel = vel.as_array();
                    let vel = Vector3::new(vel[1], vel[2], vel[3]);
                    *grad = (l * inv).cast();
                    *x += vel * dt;
                }
            });
    }
}

/// Nodes per padded buffer of the widest stencil (uGIMP's 7³).
const MAX_PADDED: usize = {
    let pad = if Gimp::PAD > Linear::PAD {
        Gimp::PAD
    } else {
        Linear::PAD
    };
    pad * pad * pad
};

/// A gather's copy of half `G` of the nodes around one block (its padded buffer's nodes), in
/// working memory: it is filled from the owned nodes when the gather reaches a particle whose
/// stencil it does not hold, for that particle's block. Particles are kept in block order
/// ([`super::RESORT_EVERY`]), so a chunk of particles fills it about once per block it spans.
struct Halo<G: Gathered> {
    block: u32,
    nodes: [f64x4; MAX_PADDED],
    half: PhantomData<G>,
}

impl<G: Gathered> Halo<G> {
    fn new() -> Self {
        Halo {
            block: NONE,
            nodes: [f64x4::splat(0.0); MAX_PADDED],
            half: PhantomData,
        }
    }

    /// Particle `q`'s stencil (`xg` its position in grid units) in padded nodes that hold it:
    /// those around its block, or around the block held if they hold it too.
    #[inline(always)]
    fn stencil<S: Stencil>(
        &mut self,
        g: &Grid<S>,
        q: usize,
        xg: Vector3<Real>,
        lp: Real,
    ) -> Held<'_> {
        let e = S::eval3(xg.into(), lp);
        let nodes = &mut self.nodes[..Grid::<S>::PADDED_LEN];
        // The nodes held serve any stencil inside them: a particle that drifted into the next
        // block since the last reordering often still is.
        let inside = |o: [i32; 3]| {
            (0..3).all(|a| (0..=(S::PAD - S::N) as i32).contains(&(e[a].base - o[a])))
        };
        if self.block == NONE || !inside(g.padded_origin(self.block as usize)) {
            let b = g.bins.home[q];
            g.halo::<G>(b as usize, nodes);
            self.block = b;
        }
        let o = g.padded_origin(self.block as usize);
        Held {
            nodes,
            start: [
                (e[0].base - o[0]) as usize,
                (e[1].base - o[1]) as usize,
                (e[2].base - o[2]) as usize,
            ],
            axes: e,
        }
    }
}

/// A particle's stencil in a [`Halo`]: the padded nodes, the stencil's first node in them
/// (per axis) and its weights per axis.
struct Held<'a> {
    nodes: &'a [f64x4],
    start: [usize; 3],
    axes: [Axis; 3],
}
