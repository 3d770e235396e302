//! Block-sparse background grid that follows the particles, for one shape function `S`.
//!
//! Nodes sit at integer multiples of the cell size (mm). They are grouped in blocks of 4×4×4
//! owned nodes; only blocks whose nodes some particle's stencil touches exist, so memory follows
//! the tube, not its bounding box, and is rebuilt from the particles every step ([`bin`]).
//!
//! Parallel scatter without atomics or aliasing: each block that holds particles scatters them
//! into a *padded* buffer covering its nodes `S::PAD_LO`.. (`S::PAD` per axis), which holds
//! the whole stencil of every particle whose cell lies in the block (blocks that only receive
//! spilled stencils have none: [`bin::Bins::occupied`]); [`Grid::reduce`] sums the padded
//! buffers into the owned nodes in a fixed order, so results are independent of the thread
//! count. The scatter goes slab by slab ([`slabs`]), so the padded buffers of three slabs of
//! blocks are alive at a time. Grid→particle reads copies of the owned nodes around a block
//! ([`Grid::halo`]) that the gather keeps in working memory.
//!
//! What a node holds changes by phase of the step; [`Node`]'s accessors are named by phase and
//! [`Transfer`] says which lanes a scatter fills, reduces and clears.

pub mod bin;
pub mod blocks;
pub mod slabs;

pub use blocks::{neighbor_index, neighbor_offset, BLOCK, NONE, OWNED};

use crate::solver::engine::shape::Stencil;
use crate::solver::Real;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::marker::PhantomData;
use wide::f64x4;

/// Which particle→grid transfer a scatter is; one type drives what the scatter writes, what
/// [`Grid::reduce`] sums and what it clears, so that the three cannot disagree.
pub trait Transfer: Send + Sync + 'static {
    /// Mass, momentum, internal force and plate touch; else momentum only, over the mass and
    /// touch of the last full transfer.
    const FULL: bool;
}

/// The step's first transfer: mass, momentum, internal force and plate touch.
pub enum Full {}
/// MUSL's second transfer: the updated particle momenta, onto the same masses.
pub enum Remap {}

impl Transfer for Full {
    const FULL: bool = true;
}
impl Transfer for Remap {
    const FULL: bool = false;
}

/// One node's accumulators, as two four-lane vectors: `lo` = [mass, a₀, a₁, a₂] and
/// `hi` = [b₀, b₁, b₂, touch]. `touch` is the mass contributed by particles that touch a plate
/// (> 0 puts the node in contact). One node is one cache line, and every update of it is a few
/// vector instructions. By phase (each accessor says which):
///
/// | after | `a` | `b` |
/// |---|---|---|
/// | [`Full`] scatter + reduce | momentum | internal force |
/// | the grid update | velocity change | the plate's tangential impulse (b₀, b₁) |
/// | [`Remap`] scatter + reduce | momentum | the grid update's tangential impulse, for its books |
/// | the remap | velocity | the plates' change of it |
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub struct Node {
    pub lo: f64x4,
    pub hi: f64x4,
}

impl Node {
    /// Before a reduce of transfer `T`: zeroes what `T` sums.
    #[inline(always)]
    pub fn clear<T: Transfer>(&mut self) {
        if T::FULL {
            *self = Node::default();
        } else {
            self.lo = f64x4::new([self.mass(), 0.0, 0.0, 0.0]);
        }
    }

    #[inline(always)]
    pub fn mass(&self) -> Real {
        self.lo.as_array()[0]
    }

    #[inline(always)]
    pub fn touch(&self) -> Real {
        self.hi.as_array()[3]
    }

    #[inline(always)]
    fn a(&self) -> Vector3<Real> {
        let l = self.lo.as_array();
        Vector3::new(l[1], l[2], l[3])
    }

    /// After a scatter and reduce: the momentum, g·mm/ms.
    #[inline(always)]
    pub fn momentum(&self) -> Vector3<Real> {
        self.a()
    }

    /// After a [`Full`] scatter and reduce: the internal force, N.
    #[inline(always)]
    pub fn force(&self) -> Vector3<Real> {
        let h = self.hi.as_array();
        Vector3::new(h[0], h[1], h[2])
    }

    /// The grid update's result: the velocity change, mm/ms (in `a`, for the FLIP gather, so
    /// that the [`Remap`] scatter, which sums `a` only, keeps `b`), and the plate's tangential
    /// impulse on the node, N·ms (in `b`, for the friction's end half, booked in the remap).
    #[inline(always)]
    pub fn set_stepped(&mut self, change: &Vector3<Real>, slip_impulse: [Real; 2]) {
        self.lo = f64x4::new([self.mass(), change.x, change.y, change.z]);
        let [jx, jy] = slip_impulse;
        self.hi = f64x4::new([jx, jy, 0.0, self.touch()]);
    }

    /// After the [`Remap`] scatter and reduce: the grid update's tangential impulse on the
    /// node, N·ms ([`Node::set_stepped`]).
    #[inline(always)]
    pub fn slip_impulse(&self) -> [Real; 2] {
        let h = self.hi.as_array();
        [h[0], h[1]]
    }

    /// The remap's result: the new velocity and the plates' change of it, mm/ms.
    #[inline(always)]
    pub fn set_updated(&mut self, velocity: &Vector3<Real>, change: &Vector3<Real>) {
        let v = velocity;
        self.lo = f64x4::new([self.mass(), v.x, v.y, v.z]);
        self.hi = f64x4::new([change.x, change.y, change.z, self.touch()]);
    }
}

/// Which half of the nodes a [`Grid::halo`] copies: what the gather that follows reads, and no
/// more.
pub trait Gathered: Send + Sync + 'static {
    /// `lo` ([mass, a]); else `hi` ([b, touch]).
    const LO: bool;
}

/// After the remap: the plates' change of the velocity, for the catch's gather (`hi`).
pub enum VelocityChange {}
/// After the grid update, the velocity change, for the FLIP gather; after the remap, the
/// velocity, for the kinematics gather (`lo`).
pub enum Velocity {}

impl Gathered for VelocityChange {
    const LO: bool = false;
}
impl Gathered for Velocity {
    const LO: bool = true;
}

/// The ring of padded buffers of the slabs ([`Grid::PADDED_LEN`] nodes each, a block's
/// at [`slabs::Slabs::buffer`]), as two arrays: the `lo` and the `hi` half of each [`Node`].
/// Two arrays and not one of nodes, because only the [`Full`] scatter and its reduce need both
/// halves: the [`Remap`] scatter and its reduce stream half the bytes.
#[derive(Debug, Default)]
pub struct Padded {
    pub lo: Vec<f64x4>,
    pub hi: Vec<f64x4>,
}

/// The sparse grid and the binning of particles into its blocks, for shape function `S`.
#[derive(Debug)]
pub struct Grid<S: Stencil> {
    pub cell: Real,
    pub inv_cell: Real,
    /// The active blocks and each particle's place in them, rebuilt by [`Grid::bin`].
    pub bins: bin::Bins,
    /// The scatter's order: slab by slab, and each block's buffer in the ring.
    pub slabs: slabs::Slabs,
    pub padded: Padded,
    pub owned: Vec<Node>,
    /// Which padded node is which owned node, the same for every block.
    links: Links,
    shape: PhantomData<S>,
}

impl<S: Stencil> Grid<S> {
    /// Nodes per padded buffer.
    pub const PADDED_LEN: usize = S::PAD * S::PAD * S::PAD;

    /// An empty grid of cell size `cell` (mm).
    pub fn new(cell: Real) -> Grid<S> {
        Grid {
            cell,
            inv_cell: 1.0 / cell,
            bins: bin::Bins::default(),
            slabs: slabs::Slabs::default(),
            padded: Padded::default(),
            owned: Vec::new(),
            links: Links::new::<S>(),
            shape: PhantomData,
        }
    }

    /// Index of padded node (i, j, k) in a block's padded buffer. A stencil that overran the
    /// buffer would wrap into the next row silently; debug builds stop there.
    #[inline(always)]
    pub fn padded_index(i: usize, j: usize, k: usize) -> usize {
        debug_assert!(
            i < S::PAD && j < S::PAD && k < S::PAD,
            "padded node ({i}, {j}, {k}) outside a buffer of {} per edge",
            S::PAD
        );
        (i * S::PAD + j) * S::PAD + k
    }

    /// Number of active blocks.
    pub fn len(&self) -> usize {
        self.bins.blocks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bins.blocks.is_empty()
    }

    /// Node coordinates of the padded origin of block `b`.
    #[inline(always)]
    pub fn padded_origin(&self, b: usize) -> [i32; 3] {
        self.bins.blocks[b].map(|c| c * BLOCK + S::PAD_LO)
    }

    /// Padded buffer `s`'s part of a padded half (`self.padded.lo` or `.hi`).
    #[inline(always)]
    pub fn buffer_of(half: &[f64x4], s: usize) -> &[f64x4] {
        &half[s * Self::PADDED_LEN..(s + 1) * Self::PADDED_LEN]
    }

    /// Sorts particles into blocks, activates every block a stencil touches and sizes the
    /// node buffers for them. `lp` is the particle half-size in grid units.
    pub fn bin(&mut self, x: &[Vector3<Real>], lp: Real) {
        self.bins.rebuild::<S>(x, self.inv_cell, lp);
        self.slabs.build(&self.bins);
        let buffers = self.slabs.ring_len() * Self::PADDED_LEN;
        let zero = f64x4::splat(0.0);
        self.padded.lo.resize(buffers, zero);
        self.padded.hi.resize(buffers, zero);
        self.owned.resize(self.len() * OWNED, Node::default());
    }

    /// Sums the padded buffers into the owned nodes of slab `i`: what transfer
    /// `T` scattered. Each owned node adds its padded copies in the order of the neighbours
    /// that hold them (box by box, [`Links::received`]), whatever the thread count. Neighbours
    /// without particles have no buffer and are skipped: their copies would be zeros, and
    /// adding +0 to a sum begun at +0 changes no bit. The slabs next to `i` must have scattered.
    pub fn reduce<T: Transfer>(&mut self, i: usize) {
        let (padded, neighbors, links) = (&self.padded, &self.bins.neighbors, &self.links);
        let slabs = &self.slabs;
        self.owned
            .par_chunks_mut(OWNED)
            .enumerate()
            .filter(|(b, _)| slabs.slab_of(*b) == i)
            .for_each(|(b, own)| {
                own.iter_mut().for_each(Node::clear::<T>);
                for &(n, [x, y, z]) in &links.received {
                    let s = match neighbors[b][n as usize] {
                        NONE => continue,
                        nb => slabs.buffer(nb as usize),
                    };
                    if s == NONE {
                        continue;
                    }
                    let lo = Self::buffer_of(&padded.lo, s as usize);
                    let hi = if T::FULL {
                        Self::buffer_of(&padded.hi, s as usize)
                    } else {
                        &[]
                    };
                    for i in 0..x.2 {
                        for j in 0..y.2 {
                            let from = Self::padded_index(x.0 + i, y.0 + j, z.0);
                            let to = owned_index(x.1 + i, y.1 + j, z.1);
                            let own = &mut own[to..to + z.2];
                            // A `Remap` scatter leaves the padded mass lane 0, so adding `lo`
                            // adds only momentum.
                            for (o, l) in own.iter_mut().zip(&lo[from..from + z.2]) {
                                o.lo += *l;
                            }
                            if T::FULL {
                                for (o, h) in own.iter_mut().zip(&hi[from..from + z.2]) {
                                    o.hi += *h;
                                }
                            }
                        }
                    }
                }
            });
    }

    /// Copies half `G` of the owned nodes that block `b`'s padded buffer covers into `buf`
    /// (its first [`Grid::PADDED_LEN`] nodes), box by box ([`Links::owned_by`]); the nodes of
    /// a neighbour that is not active are zero.
    pub fn halo<G: Gathered>(&self, b: usize, buf: &mut [f64x4]) {
        let nbs = &self.bins.neighbors[b];
        for &(n, [x, y, z]) in &self.links.owned_by {
            let nb = nbs[n as usize];
            for i in 0..x.2 {
                for j in 0..y.2 {
                    let to = Self::padded_index(x.0 + i, y.0 + j, z.0);
                    let buf = &mut buf[to..to + z.2];
                    if nb == NONE {
                        buf.fill(f64x4::splat(0.0));
                        continue;
                    }
                    let from = nb as usize * OWNED + owned_index(x.1 + i, y.1 + j, z.1);
                    for (n, o) in buf.iter_mut().zip(&self.owned[from..from + z.2]) {
                        *n = if G::LO { o.lo } else { o.hi };
                    }
                }
            }
        }
    }

    /// Bytes held by the grid and the binning arrays.
    pub fn bytes(&self) -> usize {
        (self.padded.lo.capacity() + self.padded.hi.capacity()) * std::mem::size_of::<f64x4>()
            + self.owned.capacity() * std::mem::size_of::<Node>()
            + self.bins.bytes()
            + self.slabs.bytes()
    }
}

/// The map between a block's padded nodes and the owned nodes they copy, built once per shape
/// function: the same for every block, with neighbours named by [`neighbor_index`], as boxes of
/// nodes: per axis (first padded coordinate, first owned coordinate, count).
#[derive(Debug)]
struct Links {
    /// Per neighbour whose padded buffer holds some of our owned nodes, in neighbour order:
    /// where they are in its buffer, and which of ours they are.
    received: Vec<(u8, Shared)>,
    /// Per neighbour that owns some of our padded nodes: which of ours they are, and where they
    /// are among its owned nodes. The boxes tile our padded buffer.
    owned_by: Vec<(u8, Shared)>,
}

/// A box of nodes that a padded buffer and a block's owned nodes share: per axis (first padded
/// coordinate, first owned coordinate, count).
type Shared = [(usize, usize, usize); 3];

/// Index of owned node (i, j, k) of a block.
#[inline(always)]
fn owned_index(i: usize, j: usize, k: usize) -> usize {
    (i * BLOCK as usize + j) * BLOCK as usize + k
}

impl Links {
    fn new<S: Stencil>() -> Links {
        let mut received = Vec::new();
        let mut owned_by = Vec::new();
        for n in 0..27 {
            // Our padded nodes owned by neighbour n.
            if let Some(shared) = overlap3::<S>(neighbor_offset(n)) {
                owned_by.push((n as u8, shared));
            }
            // Our owned nodes in neighbour n's padded buffer: it holds them as its neighbour
            // at the opposite offset.
            if let Some(shared) = overlap3::<S>(neighbor_offset(n).map(|d| -d)) {
                received.push((n as u8, shared));
            }
        }
        let volume =
            |l: &[(u8, Shared)]| -> usize { l.iter().map(|(_, [x, y, z])| x.2 * y.2 * z.2).sum() };
        debug_assert_eq!(volume(&owned_by), S::PAD * S::PAD * S::PAD);
        debug_assert_eq!(volume(&received), S::PAD * S::PAD * S::PAD);
        Links { received, owned_by }
    }
}

/// [`overlap`] on all three axes, for a neighbour offset `e`; None if any axis has none.
#[inline(always)]
fn overlap3<S: Stencil>(e: [i32; 3]) -> Option<[(usize, usize, usize); 3]> {
    Some([
        overlap(e[0], S::PAD_LO, S::PAD)?,
        overlap(e[1], S::PAD_LO, S::PAD)?,
        overlap(e[2], S::PAD_LO, S::PAD)?,
    ])
}

/// Along one axis: which padded nodes of a block (padded origin `lo` nodes from its first owned
/// node, `pad` nodes) are owned by the block `e` blocks further on, as (first padded
/// coordinate, first owned coordinate in that block, count); None if none are.
#[inline(always)]
fn overlap(e: i32, lo: i32, pad: usize) -> Option<(usize, usize, usize)> {
    let p0 = (BLOCK * e - lo).max(0);
    let p1 = (BLOCK * e - lo + BLOCK - 1).min(pad as i32 - 1);
    (p1 >= p0).then(|| {
        (
            p0 as usize,
            (p0 + lo - BLOCK * e) as usize,
            (p1 - p0 + 1) as usize,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::engine::shape::{Gimp, Linear};
    use slabs::Pass;

    /// Scatter mass 1 per particle with partition-of-unity weights into padded buffers, reduce:
    /// the owned nodes must hold the total mass exactly once, whatever block boundaries cut it.
    fn mass_is_conserved<S: Stencil>() {
        let mut x = Vec::new();
        for i in 0..40 {
            for j in 0..7 {
                x.push(Vector3::new(
                    -3.1 + 0.37 * i as Real,
                    0.29 * j as Real,
                    1.7 - 0.41 * j as Real,
                ));
            }
        }
        let mut g = Grid::<S>::new(0.5);
        let lp = 0.25;
        g.bin(&x, lp);
        let (len, pad) = (Grid::<S>::PADDED_LEN, S::PAD);
        let count = g.slabs.count();
        assert!(count > 3, "the slabs reuse the ring");
        for pass in slabs::passes(count) {
            let i = match pass {
                Pass::Reduce(i) => {
                    g.reduce::<Full>(i);
                    continue;
                }
                Pass::Scatter(i) => i,
            };
            for (k, &b) in g.slabs.occupied_of(i).to_vec().iter().enumerate() {
                let b = b as usize;
                let s = g.slabs.ring_of(i).0 + k;
                assert_eq!(g.slabs.buffer(b) as usize, s);
                let o = g.padded_origin(b);
                let mine: Vec<u32> = g.bins.particles_of(b).to_vec();
                let buf = &mut g.padded.lo[s * len..(s + 1) * len];
                buf.iter_mut().for_each(|n| *n = f64x4::splat(0.0));
                for p in mine {
                    let e: Vec<_> = (0..3)
                        .map(|a| S::eval(x[p as usize][a] * 2.0, lp))
                        .collect();
                    for i in 0..S::N {
                        for j in 0..S::N {
                            for k in 0..S::N {
                                let idx = Grid::<S>::padded_index(
                                    (e[0].base + i as i32 - o[0]) as usize,
                                    (e[1].base + j as i32 - o[1]) as usize,
                                    (e[2].base + k as i32 - o[2]) as usize,
                                );
                                let w = e[0].w[i] * e[1].w[j] * e[2].w[k];
                                buf[idx] += f64x4::new([w, 0.0, 0.0, 0.0]);
                            }
                        }
                    }
                }
            }
        }
        let total: Real = g.owned.iter().map(|n| n.mass()).sum();
        assert!((total - x.len() as Real).abs() < 1e-9, "{total}");
        // A halo holds every owned node its block's padded buffer covers.
        assert!(
            g.bins.occupied.len() < g.len(),
            "some blocks only receive spilled stencils"
        );
        let mut halo = vec![f64x4::splat(-1.0); len];
        for &b in &g.bins.occupied {
            let o = g.padded_origin(b as usize);
            g.halo::<Velocity>(b as usize, &mut halo);
            for (q, n) in halo.iter().enumerate() {
                let node = [
                    o[0] + (q / (pad * pad)) as i32,
                    o[1] + ((q / pad) % pad) as i32,
                    o[2] + (q % pad) as i32,
                ];
                let blk = [
                    node[0].div_euclid(4),
                    node[1].div_euclid(4),
                    node[2].div_euclid(4),
                ];
                let owner = g.bins.lookup(blk);
                if owner != NONE {
                    let l = [
                        node[0].rem_euclid(4),
                        node[1].rem_euclid(4),
                        node[2].rem_euclid(4),
                    ];
                    let on =
                        g.owned[owner as usize * OWNED + ((l[0] * 4 + l[1]) * 4 + l[2]) as usize];
                    assert_eq!(n.as_array()[0], on.mass());
                } else {
                    assert_eq!(n.as_array(), &[0.0; 4], "a node no block owns is zero");
                }
            }
        }
    }

    /// A stencil that overran its padded buffer would wrap into the next row; debug builds
    /// stop at the index instead.
    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "outside a buffer")]
    fn a_stencil_past_the_padded_buffer_is_caught() {
        Grid::<Linear>::padded_index(0, Linear::PAD, 0);
    }

    #[test]
    fn linear_scatter_reduce_conserves_mass() {
        mass_is_conserved::<Linear>();
    }

    #[test]
    fn gimp_scatter_reduce_conserves_mass() {
        mass_is_conserved::<Gimp>();
    }
}
