//! The block layout the grid and its binning share: how many cells a block edge holds, the
//! "no block" marker, and how a block's 27 neighbours are numbered. Lengths are in cells, not
//! mm. Imports nothing of the grid: [`super`], [`super::bin`] and [`super::slabs`] import it.

/// Cells (and owned nodes) per block edge.
pub const BLOCK: i32 = 4;
/// Owned nodes per block.
pub const OWNED: usize = 64;
pub const NONE: u32 = u32::MAX;

/// Index into the 27-neighbour array of a block offset in {−1, 0, 1}³.
#[inline(always)]
pub fn neighbor_index(d: [i32; 3]) -> usize {
    ((d[0] + 1) * 9 + (d[1] + 1) * 3 + (d[2] + 1)) as usize
}

/// The offset in {−1, 0, 1}³ of neighbour `k` (see [`neighbor_index`]).
#[inline(always)]
pub const fn neighbor_offset(k: usize) -> [i32; 3] {
    let k = k as i32;
    [k / 9 - 1, (k / 3) % 3 - 1, k % 3 - 1]
}
