//! Grading: each Voronoi cell is shrunk toward its seed by the factor of eq. 29 to give a rock of a
//! prescribed size, so that the sample follows the requested size distribution.
//!
//! # Eq. 29 and how it is read here
//! For a size bin [d_i, d_{i+1}], q = 1 − d_{i+1}/d_max + ω (d_{i+1} − d_i)/d_max with ω uniform in [0, 1],
//! and every vertex–seed vector of the cell is shortened by q: v' = S + (1 − q)(v − S). Writing
//! d = d_{i+1} − ω (d_{i+1} − d_i), a size uniform in the bin, eq. 29 is q = 1 − d/d_max: the rock keeps the
//! fraction d/d_max of the cell's linear size. The paper's d_max is the size of the cell being shrunk; here it
//! is the cell's own volume-equivalent diameter d_cell = (6 V_cell/π)^{1/3}, which makes the rock's
//! volume-equivalent diameter exactly d (the shrink is a homothety of ratio 1 − q about the seed, which lies in
//! the convex cell, so the rock stays inside its cell and rocks are disjoint).
//! A cell smaller than its drawn size (q < 0: it would have to grow and overlap its neighbours) is dropped
//! and counted in [`GradingReport::dropped_small_cells`]; the seed spacing of eq. 28 is chosen large enough
//! that this is rare (see [`GenerationParams::cell_to_rock_ratio`](super::GenerationParams)).
//!
//! # The size distribution
//! The paper: "the particle size obeys a normal distribution within the range of ±10 % of the mean size".
//! It does not give the standard deviation; here σ = 5 % of the mean (the ±10 % range is ±2σ), truncated to
//! the range. The range is cut into equal bins; a rock draws its bin with the truncated normal's probability
//! of the bin, then ω uniformly, as eq. 29 prescribes. The realised sizes therefore follow the piecewise
//! uniform approximation of the truncated normal whose exact mean and variance
//! [`SizeDistribution::bin_mean_and_variance`] gives (the tests compare the sample with them).

use std::sync::Arc;

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::voronoi::VoronoiCell;
use polydem::math::{Point, Pose, Real};
use polydem::shape::{ConvexPolyhedron, ShapeError};
use polydem::special_functions::gauss_legendre;

/// Default σ / mean: the paper's ±10 % range taken as ±2σ.
pub const DEFAULT_SIGMA_FRACTION: Real = 0.05;
/// Default half-width of the size range / mean (the paper's ±10 %).
pub const DEFAULT_RANGE_FRACTION: Real = 0.10;
/// Default number of size bins of eq. 29 over the range: ten bins of 2 % of the mean each resolve the normal
/// shape (σ spans 2.5 bins).
pub const DEFAULT_BINS: usize = 10;

/// Why a grading could not be built or applied.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GradingError {
    #[error("size distribution: {what} = {value} is invalid ({reason})")]
    InvalidParameter {
        what: &'static str,
        value: Real,
        reason: &'static str,
    },
    #[error("cell {cell}: the shrunk rock is not a valid polyhedron: {source}")]
    Shape {
        cell: usize,
        #[source]
        source: ShapeError,
    },
}

/// Eq. 29: the shrinking factor q for the bin [d_lo, d_hi], the reference size d_max and ω ∈ [0, 1].
pub fn shrink_factor(d_lo: Real, d_hi: Real, d_max: Real, omega: Real) -> Real {
    1.0 - d_hi / d_max + omega * (d_hi - d_lo) / d_max
}

/// The diameter of the sphere of volume `volume` (m).
pub fn equivalent_diameter(volume: Real) -> Real {
    (6.0 * volume / std::f64::consts::PI).cbrt()
}

/// The vertices of a cell shrunk toward its seed by q: S + (1 − q)(v − S).
pub fn shrink_toward_seed(vertices: &[Point], seed: &Point, q: Real) -> Vec<Point> {
    vertices
        .iter()
        .map(|v| seed + (v - seed) * (1.0 - q))
        .collect()
}

/// A truncated normal size distribution cut into equal bins.
#[derive(Clone, Debug, PartialEq)]
pub struct SizeDistribution {
    /// Mean size (m).
    pub mean: Real,
    /// σ (m).
    pub sigma: Real,
    /// Bin edges d_0 < … < d_K (m).
    pub edges: Vec<Real>,
    /// Probability of each bin (sums to 1).
    pub probabilities: Vec<Real>,
}

impl SizeDistribution {
    /// Normal(mean, (sigma_fraction·mean)²) truncated to mean·(1 ± range_fraction), in `bins` equal bins.
    pub fn truncated_normal(
        mean: Real,
        sigma_fraction: Real,
        range_fraction: Real,
        bins: usize,
    ) -> Result<Self, GradingError> {
        let bad = |what, value, reason| GradingError::InvalidParameter {
            what,
            value,
            reason,
        };
        if !(mean.is_finite() && mean > 0.0) {
            return Err(bad("mean size", mean, "must be finite and positive"));
        }
        if !(sigma_fraction.is_finite() && sigma_fraction > 0.0) {
            return Err(bad("sigma fraction", sigma_fraction, "must be positive"));
        }
        if !(range_fraction.is_finite() && range_fraction > 0.0 && range_fraction < 1.0) {
            return Err(bad("range fraction", range_fraction, "must be in (0, 1)"));
        }
        if bins == 0 || bins > 1000 {
            return Err(bad("bins", bins as Real, "must be 1…1000"));
        }
        let sigma = sigma_fraction * mean;
        let (lo, hi) = (mean * (1.0 - range_fraction), mean * (1.0 + range_fraction));
        let edges: Vec<Real> = (0..=bins)
            .map(|i| lo + (hi - lo) * i as Real / bins as Real)
            .collect();
        // Bin masses of the Gaussian density by a 20-point Gauss–Legendre rule per bin (a bin spans at most
        // 4σ/… of a smooth integrand: the rule is exact to round-off here).
        let (x, w) = gauss_legendre(20);
        let density = |d: Real| (-0.5 * ((d - mean) / sigma).powi(2)).exp();
        let mut masses: Vec<Real> = edges
            .windows(2)
            .map(|e| {
                let (a, b) = (e[0], e[1]);
                let h = 0.5 * (b - a);
                x.iter()
                    .zip(&w)
                    .map(|(xi, wi)| wi * density(a + h * (xi + 1.0)))
                    .sum::<Real>()
                    * h
            })
            .collect();
        let total: Real = masses.iter().sum();
        masses.iter_mut().for_each(|m| *m /= total);
        Ok(Self {
            mean,
            sigma,
            edges,
            probabilities: masses,
        })
    }

    /// Largest size of the range (m).
    pub fn max_size(&self) -> Real {
        *self.edges.last().unwrap_or(&self.mean)
    }

    /// Draws a bin by its probability and ω uniformly: (bin index, ω).
    pub fn draw(&self, rng: &mut ChaCha8Rng) -> (usize, Real) {
        let u: Real = rng.random();
        let mut acc = 0.0;
        let mut bin = self.probabilities.len() - 1;
        for (i, p) in self.probabilities.iter().enumerate() {
            acc += p;
            if u < acc {
                bin = i;
                break;
            }
        }
        (bin, rng.random())
    }

    /// The size d = d_{i+1} − ω (d_{i+1} − d_i) of eq. 29 for bin i.
    pub fn size(&self, bin: usize, omega: Real) -> Real {
        let (lo, hi) = (self.edges[bin], self.edges[bin + 1]);
        hi - omega * (hi - lo)
    }

    /// Exact mean and variance (m, m²) of the piecewise uniform distribution that eq. 29 samples.
    pub fn bin_mean_and_variance(&self) -> (Real, Real) {
        let mut m1 = 0.0;
        let mut m2 = 0.0;
        for (e, p) in self.edges.windows(2).zip(&self.probabilities) {
            let (a, b) = (e[0], e[1]);
            m1 += p * 0.5 * (a + b);
            m2 += p * (a * a + a * b + b * b) / 3.0;
        }
        (m1, m2 - m1 * m1)
    }
}

/// One rock: a shrunk cell as a polyhedron in its principal frame, and its pose in the world.
#[derive(Clone, Debug)]
pub struct Rock {
    pub shape: Arc<ConvexPolyhedron>,
    /// Principal frame → world (m).
    pub pose: Pose,
    /// The drawn size d = volume-equivalent diameter of the rock (m).
    pub diameter: Real,
    /// Eq. 29's q for this rock.
    pub shrink_factor: Real,
    /// Index of the cell (= seed) it was cut from.
    pub cell: usize,
}

/// What grading did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GradingReport {
    pub cells: usize,
    pub rocks: usize,
    /// Cells smaller than their drawn size (q < 0), dropped.
    pub dropped_small_cells: usize,
}

/// Shrinks every cell by eq. 29 with a size drawn from `sizes` (see the module docs).
pub fn grade_cells(
    cells: &[VoronoiCell],
    sizes: &SizeDistribution,
    rng: &mut ChaCha8Rng,
) -> Result<(Vec<Rock>, GradingReport), GradingError> {
    let mut rocks = Vec::with_capacity(cells.len());
    let mut report = GradingReport {
        cells: cells.len(),
        ..Default::default()
    };
    for (c, cell) in cells.iter().enumerate() {
        let (bin, omega) = sizes.draw(rng);
        let d_cell = equivalent_diameter(cell.volume);
        let q = shrink_factor(sizes.edges[bin], sizes.edges[bin + 1], d_cell, omega);
        if q < 0.0 {
            report.dropped_small_cells += 1;
            continue;
        }
        let points = shrink_toward_seed(&cell.vertices, &cell.seed, q);
        let (shape, pose) = ConvexPolyhedron::from_points(&points)
            .map_err(|source| GradingError::Shape { cell: c, source })?;
        rocks.push(Rock {
            shape: Arc::new(shape),
            pose,
            diameter: sizes.size(bin, omega),
            shrink_factor: q,
            cell: c,
        });
    }
    report.rocks = rocks.len();
    Ok((rocks, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq29_spans_the_bin() {
        // ω = 0 gives q = 1 − d_hi/d_max (the largest rock of the bin), ω = 1 gives q = 1 − d_lo/d_max
        // (the smallest).
        let (lo, hi, dmax) = (0.09, 0.11, 0.2);
        assert!((shrink_factor(lo, hi, dmax, 0.0) - (1.0 - hi / dmax)).abs() < 1e-15);
        assert!((shrink_factor(lo, hi, dmax, 1.0) - (1.0 - lo / dmax)).abs() < 1e-15);
    }

    #[test]
    fn bin_probabilities_match_the_normal_cdf() {
        // One bin per σ on ±2σ: the standard normal masses of [0,1σ] and [1σ,2σ] are 0.341345 and 0.135905
        // (A&S table 26.1), renormalised by their sum 0.954500 over ±2σ.
        let s = SizeDistribution::truncated_normal(1.0, 0.05, 0.10, 4).unwrap();
        let total = 0.954_499_736;
        let expected = [0.135_905_122, 0.341_344_746, 0.341_344_746, 0.135_905_122];
        for (p, e) in s.probabilities.iter().zip(expected) {
            assert!(
                (p - e / total).abs() < 1e-8,
                "bin mass {p}, expected {}, tol 1e-8",
                e / total
            );
        }
    }
}
