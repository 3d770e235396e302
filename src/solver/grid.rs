//! Block-sparse background grid that follows the particles.
//!
//! Nodes sit at integer multiples of the cell size (mm). They are grouped in blocks of 4×4×4
//! owned nodes; only blocks whose nodes some particle's stencil touches exist, so memory follows
//! the tube, not its bounding box, and is rebuilt from the particles every step.
//!
//! Parallel scatter without atomics or aliasing: each block also has a *padded* buffer covering
//! its nodes −1..+5 per axis, which holds the whole stencil of every particle whose cell lies in
//! the block. Particle→grid writes only the padded buffer of the particle's block; [`Grid::reduce`]
//! sums the padded buffers into the owned nodes in a fixed order, and [`Grid::broadcast`] copies
//! owned values back into the padded buffers for grid→particle reads. Results are independent of
//! the thread count.

use super::shape::Stencil;
use super::Real;
use nalgebra::Vector3;
use rayon::prelude::*;
use wide::f64x4;

/// Cells (and owned nodes) per block edge.
pub const BLOCK: i32 = 4;
/// Owned nodes per block.
pub const OWNED: usize = 64;
const NONE: u32 = u32::MAX;
const MARK: u32 = u32::MAX - 1;

/// One node's accumulators, as two four-lane vectors: `lo` = [mass, a₀, a₁, a₂] and
/// `hi` = [b₀, b₁, b₂, touch]. What `a` and `b` hold depends on the phase (see `step.rs`);
/// `touch` is the mass contributed by particles that touch a plate: > 0 puts the node in contact.
/// One node is one cache line, and every update of it is a few vector instructions.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub struct Node {
    pub lo: f64x4,
    pub hi: f64x4,
}

impl Node {
    /// Zeroes every accumulator when `all`, else only `a` (the momentum of the MUSL remap).
    #[inline(always)]
    pub fn clear(&mut self, all: bool) {
        if all {
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
    pub fn a(&self) -> Vector3<Real> {
        let l = self.lo.as_array();
        Vector3::new(l[1], l[2], l[3])
    }

    #[inline(always)]
    pub fn b(&self) -> Vector3<Real> {
        let h = self.hi.as_array();
        Vector3::new(h[0], h[1], h[2])
    }

    #[inline(always)]
    pub fn set_a(&mut self, a: &Vector3<Real>) {
        self.lo = f64x4::new([self.mass(), a.x, a.y, a.z]);
    }

    #[inline(always)]
    pub fn set_b(&mut self, b: &Vector3<Real>) {
        self.hi = f64x4::new([b.x, b.y, b.z, self.touch()]);
    }
}

/// The sparse grid and the binning of particles into its blocks.
#[derive(Debug, Default)]
pub struct Grid {
    pub cell: Real,
    pub inv_cell: Real,
    /// Block coordinates of the table's first entry, and the table's extent in blocks.
    lo: [i32; 3],
    dim: [i32; 3],
    /// Dense table over the blocks' bounding box: active block id or NONE.
    table: Vec<u32>,
    /// Block coordinates of each active block.
    pub blocks: Vec<[i32; 3]>,
    /// For each active block, its 27 neighbours (itself at index 13) or `u32::MAX`.
    pub neighbors: Vec<[u32; 27]>,
    /// Particles of block b are `order[starts[b]..starts[b + 1]]`.
    pub starts: Vec<u32>,
    pub order: Vec<u32>,
    /// Block of each particle's cell.
    pub home: Vec<u32>,
    /// Each particle's cell within its block, 0..64.
    pub cell_of: Vec<u8>,
    /// Binning scratch: each particle's block coordinates and stencil spill bits.
    own: Vec<[i32; 3]>,
    spill: Vec<u8>,
    /// Per block and cell: volume-weighted dilation rate (1/ms) and pressure (MPa) averages.
    pub cell_dilation: Vec<[Real; 64]>,
    pub cell_pressure: Vec<[Real; 64]>,
    pub padded: Vec<Node>,
    pub owned: Vec<Node>,
    /// Padded geometry of the shape function in use: first padded node relative to the block's
    /// first owned node, and padded nodes per edge (`Stencil::PAD_LO`, `Stencil::PAD`).
    pub pad_lo: i32,
    pub pad: usize,
    cursor: Vec<u32>,
}

/// Index into the 27-neighbour array of a block offset in {−1, 0, 1}³.
#[inline(always)]
pub fn neighbor_index(d: [i32; 3]) -> usize {
    ((d[0] + 1) * 9 + (d[1] + 1) * 3 + (d[2] + 1)) as usize
}

/// Index of padded node (i, j, k) in a buffer of `pad` nodes per edge.
#[inline(always)]
pub fn padded_index(pad: usize, i: usize, j: usize, k: usize) -> usize {
    (i * pad + j) * pad + k
}

impl Grid {
    /// An empty grid of cell size `cell` (mm) for the stencils of shape `S`.
    pub fn new<S: Stencil>(cell: Real) -> Grid {
        Grid {
            cell,
            inv_cell: 1.0 / cell,
            pad_lo: S::PAD_LO,
            pad: S::PAD,
            ..Default::default()
        }
    }

    /// Nodes per padded buffer.
    #[inline(always)]
    pub fn padded_len(&self) -> usize {
        self.pad * self.pad * self.pad
    }

    /// After the particles were reordered by `order` (`Particles::permute`): carries the
    /// per-particle binning along, so that block b's particles are now `starts[b]..starts[b+1]`.
    pub fn adopt_order(&mut self, seen: &mut Vec<bool>) {
        super::particles::permute(&mut self.home, &self.order, seen);
        super::particles::permute(&mut self.cell_of, &self.order, seen);
        for (i, o) in self.order.iter_mut().enumerate() {
            *o = i as u32;
        }
    }

    /// Number of active blocks.
    pub fn len(&self) -> usize {
        self.blocks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Node coordinates of the padded origin of block `b`.
    #[inline(always)]
    pub fn padded_origin(&self, b: usize) -> [i32; 3] {
        let c = self.blocks[b];
        c.map(|c| c * BLOCK + self.pad_lo)
    }

    /// Sorts particles into blocks and activates every block a stencil touches.
    /// `lp` is the particle half-size in grid units.
    pub fn bin<S: Stencil>(&mut self, x: &[Vector3<Real>], lp: Real) {
        let inv = self.inv_cell;
        // Per particle, in parallel: its block, its cell in the block, and which neighbour
        // blocks its stencil spills into (bit a: below on axis a, bit a + 3: above).
        self.own.resize(x.len(), [0; 3]);
        self.cell_of.resize(x.len(), 0);
        self.spill.resize(x.len(), 0);
        (
            self.own.par_chunks_mut(4096),
            self.cell_of.par_chunks_mut(4096),
            self.spill.par_chunks_mut(4096),
            x.par_chunks(4096),
        )
            .into_par_iter()
            .for_each(|(own, cell_of, spill, x)| {
                for (((o, c), s), p) in own.iter_mut().zip(cell_of).zip(spill).zip(x) {
                    let mut cell = [0; 3];
                    *s = 0;
                    for a in 0..3 {
                        let g = p[a] * inv;
                        let (base, _, _) = S::eval(g, lp);
                        let c = g.floor() as i32;
                        o[a] = c.div_euclid(BLOCK);
                        cell[a] = c.rem_euclid(BLOCK);
                        if base.div_euclid(BLOCK) < o[a] {
                            *s |= 1 << a;
                        }
                        if (base + S::N as i32 - 1).div_euclid(BLOCK) > o[a] {
                            *s |= 1 << (a + 3);
                        }
                    }
                    *c = ((cell[0] * 4 + cell[1]) * 4 + cell[2]) as u8;
                }
            });
        let (bmin, bmax) = self
            .own
            .par_chunks(4096)
            .map(|own| {
                own.iter()
                    .fold(([i32::MAX; 3], [i32::MIN; 3]), |(lo, hi), o| {
                        (
                            [lo[0].min(o[0]), lo[1].min(o[1]), lo[2].min(o[2])],
                            [hi[0].max(o[0]), hi[1].max(o[1]), hi[2].max(o[2])],
                        )
                    })
            })
            .reduce(
                || ([i32::MAX; 3], [i32::MIN; 3]),
                |(a, b), (c, d)| {
                    (
                        [a[0].min(c[0]), a[1].min(c[1]), a[2].min(c[2])],
                        [b[0].max(d[0]), b[1].max(d[1]), b[2].max(d[2])],
                    )
                },
            );
        // One block of margin for stencils that spill over, one more for neighbour look-ups.
        self.lo = [bmin[0] - 2, bmin[1] - 2, bmin[2] - 2];
        self.dim = [
            bmax[0] - bmin[0] + 5,
            bmax[1] - bmin[1] + 5,
            bmax[2] - bmin[2] + 5,
        ];
        let size = (self.dim[0] * self.dim[1] * self.dim[2]) as usize;
        self.table.clear();
        self.table.resize(size, NONE);
        self.home.resize(x.len(), 0);
        let mut last = usize::MAX;
        for q in 0..x.len() {
            let (o, s) = (self.own[q], self.spill[q]);
            let home = self.slot(o);
            self.home[q] = home as u32;
            if s == 0 {
                if home != last {
                    self.table[home] = MARK;
                    last = home;
                }
                continue;
            }
            let range = |a: usize| (o[a] - (s >> a & 1) as i32, o[a] + (s >> (a + 3) & 1) as i32);
            let (rx, ry, rz) = (range(0), range(1), range(2));
            for i in rx.0..=rx.1 {
                for j in ry.0..=ry.1 {
                    for k in rz.0..=rz.1 {
                        let t = self.slot([i, j, k]);
                        self.table[t] = MARK;
                    }
                }
            }
        }
        self.blocks.clear();
        for t in 0..size {
            if self.table[t] == MARK {
                self.table[t] = self.blocks.len() as u32;
                let (i, rest) = (
                    t as i32 / (self.dim[1] * self.dim[2]),
                    t as i32 % (self.dim[1] * self.dim[2]),
                );
                self.blocks.push([
                    self.lo[0] + i,
                    self.lo[1] + rest / self.dim[2],
                    self.lo[2] + rest % self.dim[2],
                ]);
            }
        }
        let nb = self.blocks.len();
        for h in self.home.iter_mut() {
            *h = self.table[*h as usize];
        }
        // Counting sort of particles by block; within a block, in particle order.
        self.starts.clear();
        self.starts.resize(nb + 1, 0);
        for &h in &self.home {
            self.starts[h as usize + 1] += 1;
        }
        for b in 0..nb {
            self.starts[b + 1] += self.starts[b];
        }
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.starts[..nb]);
        self.order.resize(x.len(), 0);
        for (p, &h) in self.home.iter().enumerate() {
            let c = &mut self.cursor[h as usize];
            self.order[*c as usize] = p as u32;
            *c += 1;
        }
        self.neighbors.resize(nb, [NONE; 27]);
        for b in 0..nb {
            let c = self.blocks[b];
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let q = [c[0] + dx, c[1] + dy, c[2] + dz];
                        self.neighbors[b][neighbor_index([dx, dy, dz])] = self.lookup(q);
                    }
                }
            }
        }
        self.cell_dilation.resize(nb, [0.0; 64]);
        self.cell_pressure.resize(nb, [0.0; 64]);
        self.padded.resize(nb * self.padded_len(), Node::default());
        self.owned.resize(nb * OWNED, Node::default());
    }

    #[inline(always)]
    fn slot(&self, b: [i32; 3]) -> usize {
        let r = [b[0] - self.lo[0], b[1] - self.lo[1], b[2] - self.lo[2]];
        ((r[0] * self.dim[1] + r[1]) * self.dim[2] + r[2]) as usize
    }

    fn lookup(&self, b: [i32; 3]) -> u32 {
        let inside = (0..3).all(|a| b[a] >= self.lo[a] && b[a] < self.lo[a] + self.dim[a]);
        if inside {
            self.table[self.slot(b)]
        } else {
            NONE
        }
    }

    /// Sums the padded buffers into the owned nodes: mass, `a` and `b` when `all`, else `a` only.
    pub fn reduce(&mut self, all: bool) {
        let (padded, neighbors) = (&self.padded, &self.neighbors);
        let (pad, lo, len) = (self.pad, self.pad_lo, self.padded_len());
        self.owned
            .par_chunks_mut(OWNED)
            .enumerate()
            .for_each(|(b, own)| {
                own.iter_mut().for_each(|n| n.clear(all));
                for (k, &nb) in neighbors[b].iter().enumerate() {
                    // The neighbour at offset d holds our nodes as its neighbour at −d.
                    let e = neighbor_offset(k).map(|d| -d);
                    let (true, Some([x, y, z])) = (nb != NONE, overlap3(e, lo, pad)) else {
                        continue;
                    };
                    let src = &padded[nb as usize * len..(nb as usize + 1) * len];
                    for i in 0..x.2 {
                        for j in 0..y.2 {
                            for k in 0..z.2 {
                                let s = &src[padded_index(pad, x.0 + i, y.0 + j, z.0 + k)];
                                let o = &mut own[((x.1 + i) * 4 + y.1 + j) * 4 + z.1 + k];
                                // Without `all` the padded mass lane is 0 (see the remap's
                                // p2g), so adding `lo` adds only momentum.
                                o.lo += s.lo;
                                if all {
                                    o.hi += s.hi;
                                }
                            }
                        }
                    }
                }
            });
    }

    /// Copies the owned nodes into every padded buffer that holds them.
    pub fn broadcast(&mut self) {
        let (owned, neighbors) = (&self.owned, &self.neighbors);
        let (pad, lo, len) = (self.pad, self.pad_lo, self.padded_len());
        self.padded
            .par_chunks_mut(len)
            .enumerate()
            .for_each(|(b, buf)| {
                for (k, &nb) in neighbors[b].iter().enumerate() {
                    let Some([x, y, z]) = overlap3(neighbor_offset(k), lo, pad) else {
                        continue;
                    };
                    for i in 0..x.2 {
                        for j in 0..y.2 {
                            for k in 0..z.2 {
                                buf[padded_index(pad, x.0 + i, y.0 + j, z.0 + k)] = if nb == NONE {
                                    Node::default()
                                } else {
                                    let local = ((x.1 + i) * 4 + y.1 + j) * 4 + z.1 + k;
                                    owned[nb as usize * OWNED + local]
                                };
                            }
                        }
                    }
                }
            });
    }

    /// Node position of owned node `local` of block `b`, mm.
    #[inline(always)]
    pub fn owned_position(&self, b: usize, local: usize) -> Vector3<Real> {
        let c = self.blocks[b];
        let (i, j, k) = (
            (local / 16) as i32,
            ((local / 4) % 4) as i32,
            (local % 4) as i32,
        );
        Vector3::new(
            (c[0] * BLOCK + i) as Real * self.cell,
            (c[1] * BLOCK + j) as Real * self.cell,
            (c[2] * BLOCK + k) as Real * self.cell,
        )
    }

    /// Bytes held by the grid and the binning arrays.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        (self.padded.capacity() + self.owned.capacity()) * size_of::<Node>()
            + self.neighbors.capacity() * size_of::<[u32; 27]>()
            + self.blocks.capacity() * size_of::<[i32; 3]>()
            + (self.table.capacity() + self.starts.capacity() + self.order.capacity())
                * size_of::<u32>()
            + (self.home.capacity() + self.cursor.capacity()) * size_of::<u32>()
            + self.cell_of.capacity()
            + self.spill.capacity()
            + self.own.capacity() * size_of::<[i32; 3]>()
            + (self.cell_dilation.capacity() + self.cell_pressure.capacity())
                * size_of::<[Real; 64]>()
    }
}

/// [`overlap`] on all three axes, for a neighbour offset `e`; None if any axis has none.
#[inline(always)]
fn overlap3(e: [i32; 3], lo: i32, pad: usize) -> Option<[(usize, usize, usize); 3]> {
    Some([
        overlap(e[0], lo, pad)?,
        overlap(e[1], lo, pad)?,
        overlap(e[2], lo, pad)?,
    ])
}

/// The offset in {−1, 0, 1}³ of neighbour `k` (see [`neighbor_index`]).
#[inline(always)]
fn neighbor_offset(k: usize) -> [i32; 3] {
    let k = k as i32;
    [k / 9 - 1, (k / 3) % 3 - 1, k % 3 - 1]
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
    use crate::solver::shape::{Gimp, Linear};

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
        let mut g = Grid::new::<S>(0.5);
        let lp = 0.25;
        g.bin::<S>(&x, lp);
        for b in 0..g.len() {
            let o = g.padded_origin(b);
            let (len, pad) = (g.padded_len(), g.pad);
            let buf = &mut g.padded[b * len..(b + 1) * len];
            buf.iter_mut().for_each(|n| *n = Node::default());
            for &p in &g.order[g.starts[b] as usize..g.starts[b + 1] as usize] {
                let e: Vec<_> = (0..3)
                    .map(|a| S::eval(x[p as usize][a] * 2.0, lp))
                    .collect();
                for i in 0..S::N {
                    for j in 0..S::N {
                        for k in 0..S::N {
                            let idx = padded_index(
                                pad,
                                (e[0].0 + i as i32 - o[0]) as usize,
                                (e[1].0 + j as i32 - o[1]) as usize,
                                (e[2].0 + k as i32 - o[2]) as usize,
                            );
                            let w = e[0].1[i] * e[1].1[j] * e[2].1[k];
                            buf[idx].lo += f64x4::new([w, 0.0, 0.0, 0.0]);
                        }
                    }
                }
            }
        }
        g.reduce(true);
        let total: Real = g.owned.iter().map(|n| n.mass()).sum();
        assert!((total - x.len() as Real).abs() < 1e-9, "{total}");
        g.broadcast();
        // Every padded node now equals its owner.
        for b in 0..g.len() {
            let o = g.padded_origin(b);
            let (len, pad) = (g.padded_len(), g.pad);
            for (q, n) in g.padded[b * len..(b + 1) * len].iter().enumerate() {
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
                let owner = g.lookup(blk);
                if owner != NONE {
                    let l = [
                        node[0].rem_euclid(4),
                        node[1].rem_euclid(4),
                        node[2].rem_euclid(4),
                    ];
                    let on =
                        g.owned[owner as usize * OWNED + ((l[0] * 4 + l[1]) * 4 + l[2]) as usize];
                    assert_eq!(n.mass(), on.mass());
                }
            }
        }
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
