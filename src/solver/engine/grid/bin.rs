//! Binning: which blocks are active and which particles each holds, rebuilt every step from
//! the particle positions (mm) in named steps: [`Bins::locate`] each particle, bound the
//! blocks, [`Bins::mark`] every block a stencil touches, [`Bins::number`] them in table order,
//! [`Bins::sort`] the particles by block (and list the blocks that hold any),
//! [`Bins::link`] each block to its neighbours. Before the particles are reordered,
//! [`Bins::order_by_reach`] groups each block's particles by the shape of their stencils.

use super::blocks::{neighbor_index, neighbor_offset, BLOCK, NONE};
use crate::solver::engine::shape::Stencil;
use crate::solver::Real;
use nalgebra::Vector3;
use rayon::prelude::*;

const MARK: u32 = u32::MAX - 1;

/// log2 of [`BLOCK`].
const SHIFT: u32 = BLOCK.trailing_zeros();
const _: () = assert!(1 << SHIFT == BLOCK);

/// Reach classes of a stencil on the x and y axes ([`Bins::order_by_reach`]).
const REACH_CLASSES: usize = 4;

/// Per stencil spill bits (bit a: below on axis a, bit a + 3: above): the neighbour blocks the
/// stencil touches, as bits by [`neighbor_index`] (the block itself, 13, always).
const SPILLED: [u32; 64] = spilled();

const fn spilled() -> [u32; 64] {
    let mut table = [0; 64];
    let mut s = 0;
    while s < 64 {
        let mut set = 0;
        let mut n = 0;
        while n < 27 {
            let d = neighbor_offset(n);
            let mut inside = true;
            let mut a = 0;
            while a < 3 {
                let (below, above) = ((s >> a) & 1 == 1, (s >> (a + 3)) & 1 == 1);
                inside &= d[a] == 0 || (d[a] == -1 && below) || (d[a] == 1 && above);
                a += 1;
            }
            if inside {
                set |= 1 << n;
            }
            n += 1;
        }
        table[s] = set;
        s += 1;
    }
    table
}

/// Marks the neighbours in `set` (bits by [`neighbor_index`]) of the block at slot `home` of a
/// table of extent `dim`.
fn mark_around(table: &mut [u32], dim: [i32; 3], home: usize, set: u32) {
    let (plane, row) = (dim[1] * dim[2], dim[2]);
    for n in 0..27 {
        if set >> n & 1 == 1 {
            let d = neighbor_offset(n);
            let t = home as i32 + d[0] * plane + d[1] * row + d[2];
            table[t as usize] = MARK;
        }
    }
}

/// Stable counting sort of the particles `0..n` by `key` (each below `keys`): `order` lists
/// them by key, and by index within a key. Leaves `cursor[k]` at the end of key k's run in
/// `order` (the start of key k + 1's).
fn counting_sort(
    n: usize,
    keys: usize,
    key: impl Fn(usize) -> usize,
    cursor: &mut Vec<u32>,
    order: &mut Vec<u32>,
) {
    cursor.clear();
    cursor.resize(keys + 1, 0);
    for p in 0..n {
        cursor[key(p) + 1] += 1;
    }
    for k in 0..keys {
        cursor[k + 1] += cursor[k];
    }
    order.resize(n, 0);
    for p in 0..n {
        let c = &mut cursor[key(p)];
        order[*c as usize] = p as u32;
        *c += 1;
    }
}

/// Index in a dense table of origin `lo` and extent `dim` (blocks) of block `b`.
#[inline(always)]
fn slot(lo: [i32; 3], dim: [i32; 3], b: [i32; 3]) -> usize {
    let r = [b[0] - lo[0], b[1] - lo[1], b[2] - lo[2]];
    ((r[0] * dim[1] + r[1]) * dim[2] + r[2]) as usize
}

/// The active blocks and each particle's place in them.
#[derive(Debug, Default)]
pub struct Bins {
    /// Block coordinates of each active block.
    pub blocks: Vec<[i32; 3]>,
    /// For each active block, its 27 neighbours (itself at index 13) or `u32::MAX`.
    pub neighbors: Vec<[u32; 27]>,
    /// Particles of block b are `order[starts[b]..starts[b + 1]]`.
    pub starts: Vec<u32>,
    pub order: Vec<u32>,
    /// Block of each particle's cell.
    pub home: Vec<u32>,
    /// The blocks that hold particles, in block order: only these scatter and have cell
    /// averages. A block that only receives stencils spilling over from its neighbours has
    /// neither: its padded buffer would stay zero, and on a tube's wall a third to a half of the
    /// active blocks are such.
    pub occupied: Vec<u32>,
    /// Per active block: its place in `occupied` (which indexes its cell averages), or
    /// `u32::MAX` for a block without particles.
    pub buffer: Vec<u32>,
    /// Each particle's cell within its block, 0..64.
    pub cell_of: Vec<u8>,
    /// Block coordinates of the table's first entry, and the table's extent in blocks.
    lo: [i32; 3],
    dim: [i32; 3],
    /// Dense table over the blocks' bounding box: active block id, `MARK` or `NONE`.
    table: Vec<u32>,
    /// Scratch: each particle's block coordinates and stencil spill bits (bit a: below on
    /// axis a, bit a + 3: above), and the sort's cursors.
    own: Vec<[i32; 3]>,
    spill: Vec<u8>,
    cursor: Vec<u32>,
}

impl Bins {
    /// Bins particles at `x` (mm) for stencils of `S`, `inv` the inverse cell size (1/mm) and
    /// `lp` the particle half-size in grid units.
    pub fn rebuild<S: Stencil>(&mut self, x: &[Vector3<Real>], inv: Real, lp: Real) {
        self.locate::<S>(x, inv, lp);
        self.bound();
        self.mark();
        self.number();
        self.sort();
        self.link();
    }

    /// Per particle, in parallel: its block, its cell in the block, and which neighbour blocks
    /// its stencil spills into.
    fn locate<S: Stencil>(&mut self, x: &[Vector3<Real>], inv: Real, lp: Real) {
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
                    // Shifts and masks, not `div_euclid`: the same values for a block of
                    // 2^SHIFT cells per edge, without a branch on the remainder's sign.
                    let (mut cell, mut spill) = ([0; 3], 0);
                    for a in 0..3 {
                        let g = p[a] * inv;
                        let base = S::eval(g, lp).base;
                        let c = g.floor() as i32;
                        o[a] = c >> SHIFT;
                        cell[a] = c & (BLOCK - 1);
                        spill |= (((base >> SHIFT) < o[a]) as u8) << a;
                        spill |= ((((base + S::N as i32 - 1) >> SHIFT) > o[a]) as u8) << (a + 3);
                    }
                    *s = spill;
                    *c = ((cell[0] * BLOCK + cell[1]) * BLOCK + cell[2]) as u8;
                }
            });
    }

    /// The table's box: the particles' blocks, one block of margin for stencils that spill
    /// over and one more for neighbour look-ups.
    fn bound(&mut self) {
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
        self.lo = [bmin[0] - 2, bmin[1] - 2, bmin[2] - 2];
        self.dim = [
            bmax[0] - bmin[0] + 5,
            bmax[1] - bmin[1] + 5,
            bmax[2] - bmin[2] + 5,
        ];
    }

    /// Marks in the table every block a particle's stencil touches; `home` holds each
    /// particle's table slot. Particles of one block mostly follow each other (they are
    /// reordered by block), so the blocks touched by a run of particles with the same home are
    /// gathered as a set of neighbours ([`SPILLED`]) and marked once per run: the one
    /// sequential pass does a look-up and an `or` per particle.
    fn mark(&mut self) {
        let size = (self.dim[0] * self.dim[1] * self.dim[2]) as usize;
        self.table.clear();
        self.table.resize(size, NONE);
        self.home.resize(self.own.len(), 0);
        let (lo, dim) = (self.lo, self.dim);
        (self.home.par_chunks_mut(4096), self.own.par_chunks(4096))
            .into_par_iter()
            .for_each(|(home, own)| {
                for (h, o) in home.iter_mut().zip(own) {
                    *h = slot(lo, dim, *o) as u32;
                }
            });
        let table = &mut self.table;
        let mut run: Option<(usize, u32)> = None;
        for (&h, &s) in self.home.iter().zip(&self.spill) {
            let touched = SPILLED[s as usize];
            match &mut run {
                Some((home, set)) if *home == h as usize => *set |= touched,
                _ => {
                    if let Some((home, set)) = run {
                        mark_around(table, dim, home, set);
                    }
                    run = Some((h as usize, touched));
                }
            }
        }
        if let Some((home, set)) = run {
            mark_around(table, dim, home, set);
        }
    }

    /// Numbers the marked blocks in table order; `home` becomes each particle's block id.
    fn number(&mut self) {
        self.blocks.clear();
        let plane = self.dim[1] * self.dim[2];
        for t in 0..self.table.len() {
            if self.table[t] == MARK {
                self.table[t] = self.blocks.len() as u32;
                let (i, rest) = (t as i32 / plane, t as i32 % plane);
                self.blocks.push([
                    self.lo[0] + i,
                    self.lo[1] + rest / self.dim[2],
                    self.lo[2] + rest % self.dim[2],
                ]);
            }
        }
        let table = &self.table;
        self.home.par_chunks_mut(4096).for_each(|home| {
            for h in home {
                *h = table[*h as usize];
            }
        });
    }

    /// Counting sort of particles by block; within a block, in particle order. The blocks that
    /// hold particles are listed, in block order.
    fn sort(&mut self) {
        let nb = self.blocks.len();
        let home = &self.home;
        counting_sort(
            home.len(),
            nb,
            |p| home[p] as usize,
            &mut self.cursor,
            &mut self.order,
        );
        self.starts.clear();
        self.starts.push(0);
        self.starts.extend_from_slice(&self.cursor[..nb]);
        self.occupied.clear();
        self.buffer.clear();
        for b in 0..nb {
            if self.starts[b + 1] > self.starts[b] {
                self.buffer.push(self.occupied.len() as u32);
                self.occupied.push(b as u32);
            } else {
                self.buffer.push(NONE);
            }
        }
    }

    /// Each block's 27 neighbours.
    fn link(&mut self) {
        let nb = self.blocks.len();
        let mut neighbors = std::mem::take(&mut self.neighbors);
        neighbors.resize(nb, [NONE; 27]);
        neighbors
            .par_iter_mut()
            .zip(&self.blocks)
            .for_each(|(nbs, c)| {
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            let q = [c[0] + dx, c[1] + dy, c[2] + dz];
                            nbs[neighbor_index([dx, dy, dz])] = self.lookup(q);
                        }
                    }
                }
            });
        self.neighbors = neighbors;
    }

    /// Refines `order` so that within each block the particles come by reach class on x and
    /// y (class bit 0: the stencil reaches all `S::N` nodes on x, [`Stencil::reach`]; bit 1:
    /// on y), and within a class in particle order. The transfers' loops over x and y nodes
    /// then take the same branches for runs of particles. This runs once per re-sort; the
    /// binning's stable sort keeps the order until the next one. Blocks and `starts` are
    /// unchanged. Does nothing for a stencil whose reach never varies. `x` are the positions
    /// (mm), `inv` the inverse cell size (1/mm), `lp` the half-size in grid units: the same as
    /// the last [`Bins::rebuild`], whose `home` and `order` it refines (call it before
    /// [`Bins::adopt_order`]).
    pub fn order_by_reach<S: Stencil>(&mut self, x: &[Vector3<Real>], inv: Real, lp: Real) {
        if !S::REACH_VARIES {
            return;
        }
        let class = |q: usize| {
            let full = |a: usize| (S::reach(&S::eval(x[q][a] * inv, lp)) == S::N) as usize;
            full(0) | full(1) << 1
        };
        let home = &self.home;
        let key = |q: usize| home[q] as usize * REACH_CLASSES + class(q);
        let keys = self.blocks.len() * REACH_CLASSES;
        counting_sort(x.len(), keys, key, &mut self.cursor, &mut self.order);
        debug_assert!((0..self.blocks.len())
            .all(|b| self.cursor[b * REACH_CLASSES + REACH_CLASSES - 1] == self.starts[b + 1]));
    }

    /// After the particles were reordered by `order` (`Particles::permute`): carries the
    /// per-particle binning along, so that block b's particles are now `starts[b]..starts[b+1]`.
    pub fn adopt_order(&mut self, seen: &mut Vec<bool>) {
        super::super::particles::permute(&mut self.home, &self.order, seen);
        super::super::particles::permute(&mut self.cell_of, &self.order, seen);
        for (i, o) in self.order.iter_mut().enumerate() {
            *o = i as u32;
        }
    }

    /// Block `b`'s place in `occupied`: its cell averages. The block must hold particles.
    #[inline(always)]
    pub fn place(&self, b: usize) -> usize {
        let s = self.buffer[b];
        debug_assert!(s != NONE, "block {b} holds no particles");
        s as usize
    }

    /// Block coordinates of the bounding box's first block, and its extent in blocks.
    pub fn extent(&self) -> ([i32; 3], [i32; 3]) {
        (self.lo, self.dim)
    }

    /// The particles of block `b`.
    #[inline(always)]
    pub fn particles_of(&self, b: usize) -> &[u32] {
        &self.order[self.starts[b] as usize..self.starts[b + 1] as usize]
    }

    #[inline(always)]
    fn slot(&self, b: [i32; 3]) -> usize {
        slot(self.lo, self.dim, b)
    }

    /// Active block id at block coordinates `b`, or `NONE`.
    pub fn lookup(&self, b: [i32; 3]) -> u32 {
        let inside = (0..3).all(|a| b[a] >= self.lo[a] && b[a] < self.lo[a] + self.dim[a]);
        if inside {
            self.table[self.slot(b)]
        } else {
            NONE
        }
    }

    /// Bytes held by the binning arrays.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.neighbors.capacity() * size_of::<[u32; 27]>()
            + self.blocks.capacity() * size_of::<[i32; 3]>()
            + (self.table.capacity() + self.starts.capacity() + self.order.capacity())
                * size_of::<u32>()
            + (self.occupied.capacity() + self.buffer.capacity()) * size_of::<u32>()
            + (self.home.capacity() + self.cursor.capacity()) * size_of::<u32>()
            + self.cell_of.capacity()
            + self.spill.capacity()
            + self.own.capacity() * size_of::<[i32; 3]>()
    }
}

#[cfg(test)]
mod tests;
