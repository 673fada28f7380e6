//! Rock generation end to end (paper section 4.1): seeds by eq. 28 → Voronoi cells → eq. 29 shrinking → rocks,
//! numbered along a Z-order curve of their centres ([`super::spatial_order`]).

use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::grading::{
    grade_cells, GradingError, GradingReport, Rock, SizeDistribution, DEFAULT_BINS,
    DEFAULT_RANGE_FRACTION, DEFAULT_SIGMA_FRACTION,
};
use super::seeds::{random_seeds, seed_count, Region, SeedError};
use super::spatial_order::order_rocks_spatially;
use super::voronoi::{tessellate, VoronoiError};
use polydem::math::Real;

/// Default ratio of the mean cell's volume-equivalent diameter 2r (eq. 28) to the largest rock size.
/// Poisson–Voronoi cell volumes follow a gamma law of shape ≈ 5.6 (coefficient of variation 0.42); with
/// 2r = 1.5 d_max a cell is too small for the largest rock when its volume is below 0.30 of the mean, which
/// happens for about 1.5 % of the inner cells (more near the box faces, where cells are clipped). Smaller ratios
/// drop more cells and bias the sizes down; larger ones give looser samples (solid fraction ≈ (d/2r)³).
pub const DEFAULT_CELL_TO_ROCK_RATIO: Real = 1.5;

/// Why generation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerationError {
    #[error(transparent)]
    Seeds(#[from] SeedError),
    #[error(transparent)]
    Voronoi(#[from] VoronoiError),
    #[error(transparent)]
    Grading(#[from] GradingError),
}

/// What to generate.
#[derive(Clone, Debug, PartialEq)]
pub struct GenerationParams {
    pub region: Region,
    /// Mean rock size (m): the paper's 100, 130, 175, 200 or 290 mm.
    pub mean_size: Real,
    /// σ / mean of the size distribution (see [`super::grading`]).
    pub sigma_fraction: Real,
    /// Half-width of the size range / mean (the paper's ±10 %).
    pub range_fraction: Real,
    pub bins: usize,
    /// Mean cell diameter 2r / largest rock size (see [`DEFAULT_CELL_TO_ROCK_RATIO`]).
    pub cell_to_rock_ratio: Real,
    /// Seed of the random generator.
    pub seed: u64,
}

impl GenerationParams {
    /// The paper's grading around `mean_size` in `region`, with the documented defaults.
    pub fn new(region: Region, mean_size: Real, seed: u64) -> Self {
        Self {
            region,
            mean_size,
            sigma_fraction: DEFAULT_SIGMA_FRACTION,
            range_fraction: DEFAULT_RANGE_FRACTION,
            bins: DEFAULT_BINS,
            cell_to_rock_ratio: DEFAULT_CELL_TO_ROCK_RATIO,
            seed,
        }
    }
}

/// A generated sample and how it was made.
#[derive(Clone, Debug)]
pub struct Sample {
    pub rocks: Vec<Rock>,
    pub sizes: SizeDistribution,
    pub seeds: usize,
    /// The mean cell radius r of eq. 28 (m).
    pub cell_radius: Real,
    pub grading: GradingReport,
    /// Wall time of the tessellation and of the grading (polyhedron construction).
    pub tessellation_time: Duration,
    pub grading_time: Duration,
}

/// The size law of `params` and the mean cell radius r of eq. 28 (m) it gives.
pub fn size_law_and_cell_radius(
    params: &GenerationParams,
) -> Result<(SizeDistribution, Real), GenerationError> {
    let sizes = SizeDistribution::truncated_normal(
        params.mean_size,
        params.sigma_fraction,
        params.range_fraction,
        params.bins,
    )?;
    let cell_radius = 0.5 * params.cell_to_rock_ratio * sizes.max_size();
    Ok((sizes, cell_radius))
}

/// Generates a graded sample (see the module docs).
pub fn generate(params: &GenerationParams) -> Result<Sample, GenerationError> {
    let (sizes, cell_radius) = size_law_and_cell_radius(params)?;
    let count = seed_count(params.region.volume(), cell_radius)?;
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let seeds = random_seeds(&params.region, count, &mut rng);
    let start = Instant::now();
    let cells = tessellate(&params.region, &seeds)?;
    let tessellation_time = start.elapsed();
    let start = Instant::now();
    let (mut rocks, grading) = grade_cells(&cells, &sizes, &mut rng)?;
    // One grid cell per largest rock, so that the curve steps from a rock to a neighbour.
    order_rocks_spatially(&mut rocks, &params.region.min, sizes.max_size());
    Ok(Sample {
        rocks,
        sizes,
        seeds: count,
        cell_radius,
        grading,
        tessellation_time,
        grading_time: start.elapsed(),
    })
}
