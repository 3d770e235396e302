//! Binning: the spill table, `locate` against Euclidean division, and the reach-class order.

use super::*;
use crate::solver::engine::shape::{Gimp, Linear};

/// Positions (mm) scattered over a few blocks on both sides of 0, from a fixed sequence.
fn scattered(n: usize) -> Vec<Vector3<Real>> {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as Real / (1u64 << 53) as Real * 20.0 - 10.0
    };
    (0..n)
        .map(|_| Vector3::new(next(), next(), next()))
        .collect()
}

/// The shifts and masks of `locate` give the blocks, cells and spill bits that Euclidean
/// division gives, negative coordinates included.
fn locate_agrees_with_euclidean_division<S: Stencil>() {
    let (inv, lp) = (1.3, 0.25);
    let x = scattered(2000);
    let mut bins = Bins::default();
    bins.locate::<S>(&x, inv, lp);
    for (q, p) in x.iter().enumerate() {
        let (mut cell, mut spill) = ([0; 3], 0);
        for a in 0..3 {
            let c = (p[a] * inv).floor() as i32;
            let base = S::eval(p[a] * inv, lp).base;
            assert_eq!(bins.own[q][a], c.div_euclid(BLOCK), "particle {q} axis {a}");
            cell[a] = c.rem_euclid(BLOCK);
            spill |= ((base.div_euclid(BLOCK) < bins.own[q][a]) as u8) << a;
            let last = (base + S::N as i32 - 1).div_euclid(BLOCK);
            spill |= ((last > bins.own[q][a]) as u8) << (a + 3);
        }
        assert_eq!(bins.spill[q], spill, "particle {q}");
        let c = (cell[0] * BLOCK + cell[1]) * BLOCK + cell[2];
        assert_eq!(bins.cell_of[q] as i32, c, "particle {q}");
    }
}

#[test]
fn locate_agrees_with_euclidean_division_for_both_shapes() {
    locate_agrees_with_euclidean_division::<Linear>();
    locate_agrees_with_euclidean_division::<Gimp>();
}

/// uGIMP: each block keeps its particles, now by reach class on x and y, and by index
/// within a class. Linear: nothing moves.
#[test]
fn order_by_reach_groups_each_block_by_class() {
    let (inv, lp) = (1.3, 0.25);
    let x = scattered(3000);
    let class = |q: u32| {
        let full = |a: usize| Gimp::reach(&Gimp::eval(x[q as usize][a] * inv, lp)) == Gimp::N;
        full(0) as u8 | (full(1) as u8) << 1
    };
    let mut bins = Bins::default();
    bins.rebuild::<Gimp>(&x, inv, lp);
    let (starts, before) = (bins.starts.clone(), bins.order.clone());
    bins.order_by_reach::<Gimp>(&x, inv, lp);
    assert_eq!(bins.starts, starts);
    let mut classes_seen = [false; 4];
    for b in 0..bins.blocks.len() {
        let (s, e) = (starts[b] as usize, starts[b + 1] as usize);
        let mut mine = bins.order[s..e].to_vec();
        for pair in mine.windows(2) {
            let (one, next) = ((class(pair[0]), pair[0]), (class(pair[1]), pair[1]));
            assert!(
                one < next,
                "block {b}: (class, index) {one:?} before {next:?}"
            );
        }
        mine.iter()
            .for_each(|&q| classes_seen[class(q) as usize] = true);
        mine.sort_unstable();
        assert_eq!(mine, before[s..e], "block {b} lost or gained particles");
    }
    assert_eq!(
        classes_seen, [true; 4],
        "the positions should cover every class"
    );

    let mut bins = Bins::default();
    bins.rebuild::<Linear>(&x, inv, lp);
    let before = bins.order.clone();
    bins.order_by_reach::<Linear>(&x, inv, lp);
    assert_eq!(bins.order, before);
}

/// The neighbours a stencil touches are the box of its spill bits, the block itself always.
#[test]
fn spilled_sets_are_the_boxes_of_the_spill_bits() {
    for (s, &set) in SPILLED.iter().enumerate() {
        let mut expected = 0u32;
        let range = |a: usize| -((s >> a & 1) as i32)..=(s >> (a + 3) & 1) as i32;
        for dx in range(0) {
            for dy in range(1) {
                for dz in range(2) {
                    expected |= 1 << neighbor_index([dx, dy, dz]);
                }
            }
        }
        assert_eq!(set, expected, "spill bits {s:06b}");
    }
    assert_eq!(SPILLED[0], 1 << 13);
    assert_eq!(SPILLED[63].count_ones(), 27);
}
