//! The uniform grid of the neighbour searches: cell binning and neighbour-cell iteration.
//!
//! Both neighbour searches of the engine bin bodies here: the general step's broad phase
//! ([`super::broad_phase`]) and the flat sphere layout's half neighbour list
//! ([`super::sphere_flat::NeighbourList`]). Each decides what it lists and how large a cell is; the grid
//! holds the cell geometry and the bodies of every cell, and walks cells for them.
//!
//! - **Geometry.** Cells of side `cell` from `origin` (the low corner of the box the caller gives), `dims`
//!   cells per axis. A coordinate beyond the grid is clamped to the edge cell. Clamping is monotone and
//!   never moves two coordinates further apart, so a search that is complete on the unclamped grid stays
//!   complete: only slower when many bodies share an edge cell.
//! - **Cell count.** The box may need more cells than the caller allows ([`Grid::shape`]); [`Oversize`]
//!   says how to shrink: grow the cells (the resolution drops everywhere; bodies spread evenly over a
//!   large box) or cut the longest axis (the resolution is kept where the box starts, and bodies beyond
//!   the cut clamp into its edge cells; a few far outliers).
//! - **Binning.** A body is entered in every cell of an inclusive [`CellRange`] (one cell for a point,
//!   the cells its box covers for a box) by a counting sort into compressed rows: the bodies of cell k are
//!   `bodies[start[k]..start[k + 1]]`, in the order they were given.
//! - **Iteration.** [`Grid::for_each_cell`] hands the bodies of each cell of a range with the cell's
//!   coordinates; [`Grid::for_each_row`] hands, per row (y, z) of a range, the bodies of its consecutive x
//!   cells as one slice (adjacent cells are adjacent in the rows), which is what a search that does not need
//!   to know the cell of a body uses.
//!
//! Reference: the linked-cell method (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed., §5.3).

use crate::math::{Point, Real};

/// An inclusive range of grid cells, per axis.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct CellRange {
    pub(crate) lo: [u32; 3],
    pub(crate) hi: [u32; 3],
}

impl CellRange {
    /// The range of the one cell `c`.
    #[inline(always)]
    pub(crate) fn cell(c: [u32; 3]) -> Self {
        Self { lo: c, hi: c }
    }
}

/// How [`Grid::shape`] brings a box that needs too many cells within the limit.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Oversize {
    /// Double the cell side until the box fits: the grid still covers the whole box.
    GrowCells,
    /// Halve the cell count of the longest axis until the count fits, keeping the cell side: the grid
    /// covers the low part of the box, and what lies beyond clamps into its edge cells.
    CutLongestAxis,
}

/// At most this many cells along one axis (the count must stay well inside `u32`, and a longer axis than
/// this is the mark of an outlier, which clamping handles).
const MAX_AXIS_CELLS: u64 = 1_000_000;

/// A uniform grid and the bodies binned in it; kept between builds for its capacity (see the module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct Grid {
    origin: [Real; 3],
    inv_cell: Real,
    dims: [u32; 3],
    /// Bodies of cell k: `bodies[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    bodies: Vec<u32>,
}

impl Grid {
    /// Sets the geometry for the box `lo..hi` with cells of side `cell` (m, positive), at most
    /// `max_cells` cells, shrunk by `oversize` if the box needs more. Empties the bins.
    pub(crate) fn shape(
        &mut self,
        lo: [Real; 3],
        hi: [Real; 3],
        mut cell: Real,
        max_cells: usize,
        oversize: Oversize,
    ) {
        let extent = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        // `as u64` maps NaN to 0 and saturates at infinity: one cell for a degenerate axis.
        let dims_for = |cell: Real| {
            extent.map(|e| {
                ((e / cell).floor() as u64)
                    .saturating_add(1)
                    .min(MAX_AXIS_CELLS)
            })
        };
        let count = |d: [u64; 3]| (d[0] as u128) * (d[1] as u128) * (d[2] as u128);
        let mut dims = dims_for(cell);
        while count(dims) > max_cells.max(1) as u128 {
            match oversize {
                Oversize::GrowCells => {
                    cell *= 2.0;
                    dims = dims_for(cell);
                }
                Oversize::CutLongestAxis => {
                    let k = (0..3).max_by_key(|&k| dims[k]).unwrap_or(0);
                    dims[k] = (dims[k] / 2).max(1);
                }
            }
        }
        self.origin = lo;
        self.inv_cell = 1.0 / cell;
        self.dims = dims.map(|d| d as u32);
        self.start.clear();
        self.bodies.clear();
    }

    /// The cell coordinate of `x` along `axis`, clamped into the grid (0 for NaN).
    #[inline(always)]
    pub(crate) fn coord(&self, x: Real, axis: usize) -> u32 {
        let f = ((x - self.origin[axis]) * self.inv_cell).floor();
        if f > 0.0 {
            (f as u32).min(self.dims[axis] - 1)
        } else {
            0
        }
    }

    /// The cell of the point `x`.
    #[inline(always)]
    pub(crate) fn cell_of(&self, x: &Point) -> [u32; 3] {
        [
            self.coord(x[0], 0),
            self.coord(x[1], 1),
            self.coord(x[2], 2),
        ]
    }

    /// The cells of the box `x ± reach`.
    #[inline(always)]
    pub(crate) fn cells_of_box(&self, x: &Point, reach: Real) -> CellRange {
        let mut range = CellRange::default();
        for axis in 0..3 {
            range.lo[axis] = self.coord(x[axis] - reach, axis);
            range.hi[axis] = self.coord(x[axis] + reach, axis);
        }
        range
    }

    /// The cell `c` and its neighbours (3 × 3 × 3, fewer at the edges of the grid).
    #[inline(always)]
    pub(crate) fn neighbourhood(&self, c: [u32; 3]) -> CellRange {
        CellRange {
            lo: c.map(|x| x.saturating_sub(1)),
            hi: [0, 1, 2].map(|k| (c[k] + 1).min(self.dims[k] - 1)),
        }
    }

    #[inline(always)]
    fn index(&self, c: [u32; 3]) -> usize {
        let [dx, dy] = [self.dims[0] as usize, self.dims[1] as usize];
        (c[2] as usize * dy + c[1] as usize) * dx + c[0] as usize
    }

    /// Bins body `body(k)` in every cell of `ranges[k]`, for every k (a counting sort: the bodies of a
    /// cell keep the order of `ranges`).
    pub(crate) fn bin(&mut self, ranges: &[CellRange], body: impl Fn(usize) -> u32) {
        let cells = self.dims.iter().map(|&d| d as usize).product::<usize>();
        let mut start = std::mem::take(&mut self.start);
        start.clear();
        start.resize(cells + 1, 0);
        for range in ranges {
            cells_of(range, |c| start[self.index(c) + 1] += 1);
        }
        for k in 0..cells {
            start[k + 1] += start[k];
        }
        let mut bodies = std::mem::take(&mut self.bodies);
        bodies.clear();
        bodies.resize(start[cells] as usize, 0);
        let mut fill = start.clone();
        for (k, range) in ranges.iter().enumerate() {
            let id = body(k);
            cells_of(range, |c| {
                let cell = self.index(c);
                bodies[fill[cell] as usize] = id;
                fill[cell] += 1;
            });
        }
        self.start = start;
        self.bodies = bodies;
    }

    /// Calls `f` with the coordinates and the bodies of every cell of `range` (x fastest, then y, z).
    #[inline(always)]
    pub(crate) fn for_each_cell(&self, range: &CellRange, mut f: impl FnMut([u32; 3], &[u32])) {
        cells_of(range, |c| {
            let k = self.index(c);
            f(
                c,
                &self.bodies[self.start[k] as usize..self.start[k + 1] as usize],
            );
        });
    }

    /// Calls `f` with the bodies of each row (y, z) of `range`: those of its cells `range.lo[0]..=
    /// range.hi[0]`, one slice (the cells of a row are consecutive in the bins).
    #[inline(always)]
    pub(crate) fn for_each_row(&self, range: &CellRange, mut f: impl FnMut(&[u32])) {
        for z in range.lo[2]..=range.hi[2] {
            for y in range.lo[1]..=range.hi[1] {
                let first = self.index([range.lo[0], y, z]);
                let last = self.index([range.hi[0], y, z]);
                f(&self.bodies[self.start[first] as usize..self.start[last + 1] as usize]);
            }
        }
    }
}

/// Calls `f` with every cell of an inclusive range (x fastest, then y, z).
#[inline(always)]
fn cells_of(range: &CellRange, mut f: impl FnMut([u32; 3])) {
    for z in range.lo[2]..=range.hi[2] {
        for y in range.lo[1]..=range.hi[1] {
            for x in range.lo[0]..=range.hi[0] {
                f([x, y, z]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_body_is_binned_in_every_cell_of_its_range_in_the_order_given() {
        let mut grid = Grid::default();
        grid.shape([0.0; 3], [3.9, 1.9, 0.5], 1.0, 64, Oversize::GrowCells);
        assert_eq!(
            grid.dims,
            [4, 2, 1],
            "cells for a 3.9 × 1.9 × 0.5 box of side 1"
        );
        let ranges = [
            CellRange::cell([1, 0, 0]),
            CellRange {
                lo: [0, 0, 0],
                hi: [1, 1, 0],
            },
            CellRange::cell([1, 0, 0]),
        ];
        grid.bin(&ranges, |k| 10 + k as u32);
        let mut seen = Vec::new();
        grid.for_each_cell(
            &CellRange {
                lo: [0, 0, 0],
                hi: [3, 1, 0],
            },
            |c, bodies| seen.push((c, bodies.to_vec())),
        );
        let expect = |c: [u32; 3], b: &[u32]| (c, b.to_vec());
        assert_eq!(
            seen,
            vec![
                expect([0, 0, 0], &[11]),
                expect([1, 0, 0], &[10, 11, 12]),
                expect([2, 0, 0], &[]),
                expect([3, 0, 0], &[]),
                expect([0, 1, 0], &[11]),
                expect([1, 1, 0], &[11]),
                expect([2, 1, 0], &[]),
                expect([3, 1, 0], &[]),
            ]
        );
        let mut rows = Vec::new();
        grid.for_each_row(&grid.neighbourhood([0, 0, 0]), |b| rows.push(b.to_vec()));
        assert_eq!(rows, vec![vec![11, 10, 11, 12], vec![11, 11]]);
    }

    #[test]
    fn coordinates_clamp_into_the_grid_and_nan_goes_to_the_first_cell() {
        let mut grid = Grid::default();
        grid.shape([0.0; 3], [9.5; 3], 1.0, 1000, Oversize::GrowCells);
        assert_eq!(grid.cell_of(&Point::new(-3.0, 4.5, 1e30)), [0, 4, 9]);
        assert_eq!(grid.coord(Real::NAN, 1), 0);
        assert_eq!(
            grid.cells_of_box(&Point::new(0.5, 5.0, 9.4), 1.0),
            CellRange {
                lo: [0, 4, 8],
                hi: [1, 6, 9]
            }
        );
    }

    #[test]
    fn a_box_beyond_the_cell_limit_grows_its_cells_or_cuts_its_longest_axis() {
        let mut grid = Grid::default();
        grid.shape([0.0; 3], [99.5, 9.5, 0.0], 1.0, 250, Oversize::GrowCells);
        assert_eq!(
            (grid.dims, grid.inv_cell),
            ([50, 5, 1], 0.5),
            "100 × 10 cells of side 1 limited to 250: side 2"
        );
        grid.shape(
            [0.0; 3],
            [99.5, 9.5, 0.0],
            1.0,
            250,
            Oversize::CutLongestAxis,
        );
        assert_eq!(
            (grid.dims, grid.inv_cell),
            ([25, 10, 1], 1.0),
            "100 × 10 cells of side 1 limited to 250: x cut to 25"
        );
        grid.shape(
            [0.0; 3],
            [Real::INFINITY, 1e300, 0.0],
            1.0,
            1 << 22,
            Oversize::GrowCells,
        );
        assert!(
            grid.dims.iter().map(|&d| d as u64).product::<u64>() <= 1 << 22,
            "an infinite extent within the limit: {:?}",
            grid.dims
        );
    }
}
