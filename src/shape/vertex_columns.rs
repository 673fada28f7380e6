//! A polytope's vertices as blocks of coordinate columns, for a support scan the compiler vectorises.
//!
//! The support vertex along `d` is the vertex of largest `d·v`. A scan over `[x, y, z]` points does one
//! vertex per step; here the vertices sit in blocks of [`LANES`] x's, y's and z's, so that one step computes
//! [`LANES`] dot products with packed multiplies and adds. The scan runs twice over the blocks: the first
//! pass keeps a running maximum per lane, the second returns the first vertex whose dot product equals the
//! maximum of the lanes. Each dot product is `dx·x + dy·y + dz·z` evaluated left to right, in both passes
//! and in the plain scan it replaces, so the chosen vertex is exactly the plain scan's: the first index
//! attaining the maximum, NaN products never chosen, vertex 0 when no product exceeds −∞.
//!
//! The last block is padded with copies of vertex 0: a copy ties with vertex 0, which comes first, so
//! padding is never returned.

use crate::math::{Point, Real, Vector};

/// Vertices per block.
pub const LANES: usize = 4;
/// Up to this many vertices the scan goes one vertex at a time: for two blocks or fewer the second pass and
/// the reduction across lanes cost more than they save (callgrind, tetrahedron and box pairs).
const SCALAR_MAX_VERTICES: usize = 8;

/// [`LANES`] vertices as three coordinate columns (m, local frame).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct VertexBlock {
    x: [Real; LANES],
    y: [Real; LANES],
    z: [Real; LANES],
}

impl VertexBlock {
    /// The [`LANES`] dot products `dx·x + dy·y + dz·z`, each evaluated left to right.
    #[inline(always)]
    fn dots(&self, d: &[Real; 3]) -> [Real; LANES] {
        std::array::from_fn(|l| d[0] * self.x[l] + d[1] * self.y[l] + d[2] * self.z[l])
    }
}

/// The vertices of a polytope in blocks of coordinate columns (see the module docs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VertexColumns {
    blocks: Vec<VertexBlock>,
    len: usize,
}

impl VertexColumns {
    /// The columns of `vertices` (padded with copies of the first; empty input gives no blocks).
    pub fn new(vertices: &[Point]) -> Self {
        let Some(first) = vertices.first() else {
            return Self::default();
        };
        let blocks = vertices
            .chunks(LANES)
            .map(|chunk| {
                let at = |l: usize| chunk.get(l).unwrap_or(first);
                VertexBlock {
                    x: std::array::from_fn(|l| at(l).x),
                    y: std::array::from_fn(|l| at(l).y),
                    z: std::array::from_fn(|l| at(l).z),
                }
            })
            .collect();
        Self {
            blocks,
            len: vertices.len(),
        }
    }

    /// Number of vertices (padding excluded).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there is no vertex.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Vertex `i` (must be below [`Self::len`]).
    #[inline]
    pub fn point(&self, i: usize) -> Point {
        let b = &self.blocks[i / LANES];
        let l = i % LANES;
        Point::new(b.x[l], b.y[l], b.z[l])
    }

    /// Index of the first vertex maximising `dir·v` (0 when none exceeds −∞, or when there is no vertex).
    #[inline(always)]
    pub fn support_index(&self, dir: &Vector) -> usize {
        let d = [dir.x, dir.y, dir.z];
        if self.len <= SCALAR_MAX_VERTICES {
            return self.scalar_support_index(&d);
        }
        self.wide_support_index(&d)
    }

    /// [`Self::support_index`] by the two passes, in the widest build the CPU runs. Out of line, so that
    /// the small scan stays inlined into its callers.
    #[inline(never)]
    fn wide_support_index(&self, d: &[Real; 3]) -> usize {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked on the line above).
            return unsafe { self.two_pass_avx(d) };
        }
        self.two_pass(d)
    }

    /// [`Self::two_pass`] compiled with AVX: four lanes per instruction instead of two, and three-operand
    /// forms. The same bits: no multiply and add is fused (Rust fuses none unless asked), and the packed
    /// operations are the IEEE ones of the baseline build.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn two_pass_avx(&self, d: &[Real; 3]) -> usize {
        self.two_pass(d)
    }

    /// The two passes of the module docs.
    #[inline(always)]
    fn two_pass(&self, d: &[Real; 3]) -> usize {
        let mut lane_max = [Real::NEG_INFINITY; LANES];
        for block in &self.blocks {
            let v = block.dots(d);
            for l in 0..LANES {
                // `>` keeps the running maximum on NaN, like the plain scan's comparison.
                lane_max[l] = if v[l] > lane_max[l] {
                    v[l]
                } else {
                    lane_max[l]
                };
            }
        }
        let mut max = lane_max[0];
        for &m in &lane_max[1..] {
            max = if m > max { m } else { max };
        }
        // `max` is never NaN (only values greater than it replace it): −∞ means no product exceeded −∞.
        if max == Real::NEG_INFINITY {
            return 0;
        }
        for (k, block) in self.blocks.iter().enumerate() {
            let v = block.dots(d);
            // A bit mask of the lanes equal to the maximum (packed compares, no branch per lane).
            let mut hits = 0u32;
            for (l, &x) in v.iter().enumerate() {
                hits |= u32::from(x == max) << l;
            }
            if hits != 0 {
                return k * LANES + hits.trailing_zeros() as usize;
            }
        }
        0
    }

    /// [`Self::support_index`] one vertex at a time: the plain scan, cheaper than the two passes for a
    /// block or two.
    #[inline(always)]
    fn scalar_support_index(&self, d: &[Real; 3]) -> usize {
        let mut best = 0;
        let mut best_value = Real::NEG_INFINITY;
        // Padding is scanned too: a copy of vertex 0 never beats vertex 0 under `>`.
        for (k, block) in self.blocks.iter().enumerate() {
            for l in 0..LANES {
                let x = d[0] * block.x[l] + d[1] * block.y[l] + d[2] * block.z[l];
                if x > best_value {
                    best_value = x;
                    best = k * LANES + l;
                }
            }
        }
        best
    }

    /// The vertex [`Self::support_index`] picks.
    #[inline(always)]
    pub fn support_point(&self, dir: &Vector) -> (usize, Point) {
        let i = self.support_index(dir);
        (i, self.point(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The plain scan the columns replace: first index attaining the maximum of `dx·x + dy·y + dz·z`.
    fn plain_scan(vertices: &[Point], dir: &Vector) -> usize {
        let mut best = 0;
        let mut best_value = Real::NEG_INFINITY;
        for (i, p) in vertices.iter().enumerate() {
            let value = dir.x * p.x + dir.y * p.y + dir.z * p.z;
            if value > best_value {
                best_value = value;
                best = i;
            }
        }
        best
    }

    /// Random clouds of every size up to 70 and lattices (ties along axis directions): the same index as
    /// the plain scan, ties included.
    #[test]
    fn support_index_equals_the_plain_scan_with_ties() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for n in 1..=70usize {
            let random: Vec<Point> = (0..n)
                .map(|_| {
                    Point::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    )
                })
                .collect();
            let lattice: Vec<Point> = (0..n)
                .map(|i| Point::new((i % 3) as Real, ((i / 3) % 3) as Real, (i / 9) as Real))
                .collect();
            for cloud in [&random, &lattice] {
                let columns = VertexColumns::new(cloud);
                assert_eq!(columns.len(), n);
                let mut dirs: Vec<Vector> = (0..50)
                    .map(|_| {
                        Vector::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        )
                    })
                    .collect();
                dirs.extend([
                    Vector::x(),
                    -Vector::y(),
                    Vector::z(),
                    Vector::new(1.0, 1.0, 0.0),
                ]);
                for dir in &dirs {
                    let expected = plain_scan(cloud, dir);
                    let got = columns.support_index(dir);
                    assert_eq!(
                        got, expected,
                        "n = {n}, dir = {dir:?}: columns pick {got}, plain scan {expected}"
                    );
                    assert_eq!(columns.point(got), cloud[got]);
                    // Both builds of the two passes, whichever the CPU runs by default.
                    let d = [dir.x, dir.y, dir.z];
                    assert_eq!(
                        columns.two_pass(&d),
                        expected,
                        "baseline passes, n = {n}, dir = {dir:?}"
                    );
                    assert_eq!(
                        columns.scalar_support_index(&d),
                        expected,
                        "scalar, n = {n}, dir = {dir:?}"
                    );
                }
            }
        }
    }

    /// NaN and infinite directions: vertex 0 when no product exceeds −∞, as the plain scan.
    #[test]
    fn non_finite_directions_pick_what_the_plain_scan_picks() {
        let cloud: Vec<Point> = (0..9)
            .map(|i| Point::new(i as Real, -(i as Real), 0.5 * i as Real))
            .collect();
        let columns = VertexColumns::new(&cloud);
        for dir in [
            Vector::new(Real::NAN, 0.0, 0.0),
            Vector::new(Real::INFINITY, 0.0, 0.0),
            Vector::new(Real::NEG_INFINITY, 1.0, 0.0),
            Vector::zeros(),
        ] {
            assert_eq!(
                columns.support_index(&dir),
                plain_scan(&cloud, &dir),
                "dir = {dir:?}"
            );
        }
    }
}
