//! Numbering the rocks along a Z-order (Morton) curve of their centres, for memory locality.
//!
//! The seeds of the tessellation are uniform random points, so in seed order two touching rocks are as
//! far apart in memory as any two rocks. The step visits candidate pairs `(i, j)` in index order; at 36 k
//! rocks (100 mm, full scale) every `j` was then a cache miss on its body, its shape and its contacts, and
//! the cost per rock-step was 2–3× that of a 1.5 k-rock bed. Numbered along a Z-order curve, the rocks
//! that touch are mostly close in index, and their shapes are re-allocated in that order so that their
//! vertex and face arrays are close in memory too.
//!
//! Only the numbering changes: the set of rocks, their shapes, poses and sizes are those of the
//! tessellation and the grading (each rock keeps the index of the cell it was cut from).

use std::sync::Arc;

use super::grading::Rock;
use polydem::math::{Point, Real};

/// Bits per axis of the Z-order key (2²¹ cells per axis: far beyond any sample here).
const BITS: u32 = 21;

/// Spreads the low 21 bits of `v` so that bit `k` moves to bit `3k`.
fn spread_bits(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// The Z-order key of grid cell `(i, j, k)` (each below 2²¹).
pub fn morton_key(i: u64, j: u64, k: u64) -> u64 {
    spread_bits(i) | (spread_bits(j) << 1) | (spread_bits(k) << 2)
}

/// The grid cell of `p` (cells of edge `cell` from `origin`), clamped to the key's range.
fn grid_cell(p: &Point, origin: &Point, cell: Real) -> [u64; 3] {
    let max = ((1u64 << BITS) - 1) as Real;
    [0, 1, 2].map(|a| ((p[a] - origin[a]) / cell).floor().clamp(0.0, max) as u64)
}

/// Re-numbers `rocks` along the Z-order curve of their centres on a grid of edge `cell` (m) from
/// `origin`, ties kept in their previous order, and re-allocates their shapes in the new order.
/// A non-positive or non-finite `cell` leaves the rocks as they are.
pub fn order_rocks_spatially(rocks: &mut Vec<Rock>, origin: &Point, cell: Real) {
    if !(cell.is_finite() && cell > 0.0) {
        return;
    }
    let mut keyed: Vec<(u64, Rock)> = rocks
        .drain(..)
        .map(|rock| {
            let [i, j, k] = grid_cell(&Point::from(rock.pose.translation.vector), origin, cell);
            (morton_key(i, j, k), rock)
        })
        .collect();
    // Stable: equal keys keep the seed order, so the numbering is reproducible.
    keyed.sort_by_key(|(key, _)| *key);
    rocks.extend(keyed.into_iter().map(|(_, mut rock)| {
        rock.shape = Arc::new((*rock.shape).clone());
        rock
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_key_interleaves_the_axes() {
        // Bit b of axis a lands at bit 3b + a.
        for b in [0u32, 1, 7, 20] {
            let v = 1u64 << b;
            assert_eq!(morton_key(v, 0, 0), 1 << (3 * b), "x bit {b}");
            assert_eq!(morton_key(0, v, 0), 1 << (3 * b + 1), "y bit {b}");
            assert_eq!(morton_key(0, 0, v), 1 << (3 * b + 2), "z bit {b}");
        }
        let all = (1u64 << BITS) - 1;
        assert_eq!(morton_key(all, all, all), (1u64 << (3 * BITS)) - 1);
    }

    #[test]
    fn morton_order_visits_each_octant_whole() {
        // On a 4³ grid the first 8 keys are the 2³ block at the origin.
        let mut first: Vec<[u64; 3]> = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                for k in 0..4 {
                    if morton_key(i, j, k) < 8 {
                        first.push([i, j, k]);
                    }
                }
            }
        }
        assert_eq!(first.len(), 8);
        assert!(first.iter().all(|c| c.iter().all(|&x| x < 2)), "{first:?}");
    }
}
