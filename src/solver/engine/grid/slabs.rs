//! The order of a scatter: slab by slab along the axis with the most block layers, so that
//! padded buffers exist for three slabs at a time, not for every block that holds particles.
//!
//! A slab is the layer of blocks at one coordinate of the slab axis. Slab i's blocks scatter
//! into a third of a ring of padded buffers, the one slab i − 3 used; once slab i has scattered,
//! the owned nodes of slab i − 1 are reduced, which reads the buffers of slabs i − 2 to i: the
//! only ones a block's neighbours can be in. The buffers a reduce reads were written one or two
//! slabs before, and the ring is a fraction of the buffers of all blocks (a sixth for the
//! paper's tube at n = 6, whose 432 blocks with particles lie in 18 layers along its axis).
//! Each owned node still adds its copies in neighbour order, so the order of the slabs changes
//! no bit.

use super::bin::Bins;
use super::blocks::NONE;

/// Slabs of padded buffers alive at once: a reduce reads three neighbouring slabs.
pub const RING: usize = 3;

/// One pass of a scatter over the slabs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pass {
    /// Slab i's blocks that hold particles scatter into their padded buffers.
    Scatter(usize),
    /// Slab i's owned nodes sum the padded buffers around them.
    Reduce(usize),
}

/// The passes of a scatter over `slabs` slabs, in order: slab i scatters, then slab i − 1 (whose
/// neighbours have all scattered now) is reduced; the last slab is reduced at the end.
pub fn passes(slabs: usize) -> impl Iterator<Item = Pass> {
    (0..slabs)
        .flat_map(|i| std::iter::once(Pass::Scatter(i)).chain(i.checked_sub(1).map(Pass::Reduce)))
        .chain(slabs.checked_sub(1).map(Pass::Reduce))
}

/// The slabs of the current binning, and each block's buffer in the ring.
#[derive(Debug, Default)]
pub struct Slabs {
    /// Per active block: its slab.
    slab_of: Vec<u32>,
    /// The blocks that hold particles, slab by slab (block order within a slab): slab i's are
    /// `occupied[starts[i]..starts[i + 1]]`.
    starts: Vec<u32>,
    occupied: Vec<u32>,
    /// Per active block: its padded buffer's index in the ring, or `NONE` for a block without
    /// particles.
    buffer: Vec<u32>,
    /// Buffers per slab of the ring: the most any slab holds.
    width: usize,
    /// Scratch of the sort.
    cursor: Vec<u32>,
}

impl Slabs {
    /// Slabs along the axis of `bins`' bounding box with the most block layers.
    pub fn build(&mut self, bins: &Bins) {
        let (lo, dim) = bins.extent();
        let axis = (0..3).max_by_key(|&a| (dim[a], a)).unwrap_or(0);
        let slabs = dim[axis].max(0) as usize;
        self.slab_of.clear();
        self.slab_of
            .extend(bins.blocks.iter().map(|b| (b[axis] - lo[axis]) as u32));
        self.starts.clear();
        self.starts.resize(slabs + 1, 0);
        for &b in &bins.occupied {
            self.starts[self.slab_of[b as usize] as usize + 1] += 1;
        }
        for i in 0..slabs {
            self.starts[i + 1] += self.starts[i];
        }
        self.width = (0..slabs)
            .map(|i| (self.starts[i + 1] - self.starts[i]) as usize)
            .max()
            .unwrap_or(0);
        self.occupied.resize(bins.occupied.len(), 0);
        self.buffer.clear();
        self.buffer.resize(bins.blocks.len(), NONE);
        // Counting sort (blocks keep their order within a slab), placing each in the ring.
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.starts[..slabs]);
        for &b in &bins.occupied {
            let i = self.slab_of[b as usize] as usize;
            let k = self.cursor[i] - self.starts[i];
            self.occupied[self.cursor[i] as usize] = b;
            self.buffer[b as usize] = ((i % RING) * self.width) as u32 + k;
            self.cursor[i] += 1;
        }
    }

    /// Number of slabs.
    pub fn count(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// Block `b`'s slab.
    #[inline(always)]
    pub fn slab_of(&self, b: usize) -> usize {
        self.slab_of[b] as usize
    }

    /// The blocks of slab `i` that hold particles.
    pub fn occupied_of(&self, i: usize) -> &[u32] {
        &self.occupied[self.starts[i] as usize..self.starts[i + 1] as usize]
    }

    /// The ring's buffers for slab `i`: the first, and how many.
    pub fn ring_of(&self, i: usize) -> (usize, usize) {
        (
            (i % RING) * self.width,
            (self.starts[i + 1] - self.starts[i]) as usize,
        )
    }

    /// Block `b`'s padded buffer in the ring, or `NONE` if it holds no particles.
    #[inline(always)]
    pub fn buffer(&self, b: usize) -> u32 {
        self.buffer[b]
    }

    /// Padded buffers the ring holds.
    pub fn ring_len(&self) -> usize {
        RING * self.width
    }

    pub fn bytes(&self) -> usize {
        (self.slab_of.capacity()
            + self.starts.capacity()
            + self.occupied.capacity()
            + self.buffer.capacity()
            + self.cursor.capacity())
            * std::mem::size_of::<u32>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every slab scatters once and is reduced once, after its neighbours on both sides have
    /// scattered and before the ring reuses their buffers (slab i + 2 takes the buffers of
    /// slab i − 1).
    #[test]
    fn each_slab_is_reduced_between_its_neighbours_scatter_and_the_ring_reusing_them() {
        use Pass::{Reduce, Scatter};
        let got: Vec<Pass> = passes(3).collect();
        let want = [
            Scatter(0),
            Scatter(1),
            Reduce(0),
            Scatter(2),
            Reduce(1),
            Reduce(2),
        ];
        assert_eq!(got, want);
        for slabs in 0..8 {
            let order: Vec<Pass> = passes(slabs).collect();
            let at = |p: Pass| order.iter().position(|&q| q == p);
            for i in 0..slabs {
                let reduced = at(Reduce(i)).expect("every slab is reduced");
                for j in i.saturating_sub(1)..(i + 2).min(slabs) {
                    assert!(
                        at(Scatter(j)).unwrap() < reduced,
                        "slab {j} before {i}'s reduce"
                    );
                }
                if i >= 1 && i + 2 < slabs {
                    assert!(
                        reduced < at(Scatter(i + 2)).unwrap(),
                        "ring reused too soon"
                    );
                }
            }
            assert_eq!(order.len(), 2 * slabs);
        }
    }
}
