//! Limits on the size of an experiment, checked before the work starts: the number of rocks generation
//! would make (and the memory they need), checked before any seed is drawn, and the number of steps of the
//! packing and of the penetration run, checked when their Δt is known (and, for the penetration, bounded
//! from below before generation already: Δt ≤ `travel_per_step` × `mean_size` / `speed`).
//!
//! A run beyond a limit is refused with what it would need and how to raise the limit: the experiment
//! file's `[limits]` section or `--max-rocks` / `--max-steps` on the command line. The limits bound the
//! work, they do not change it: a run within them is the same run.
//!
//! The penetration's step check, which counts its monitor rows, is
//! [`super::penetration::check_penetration_steps`], built on [`within`].

use super::config::ExperimentConfig;
pub use super::config::{RunLimits, DEFAULT_MAX_ROCKS, DEFAULT_MAX_STEPS};
use super::generation::{size_law_and_cell_radius, GenerationParams};
use polydem::math::Real;

/// Memory per rock of generating and packing a bed (bytes), the estimate of the refusal message: the peak
/// resident set of `polydem rockfill --size 100` (quick layer, 8 626 rocks) was 94 MB after 100 s of
/// deposition, 11 kB per rock, rounded up for the contacts of the packed bed.
pub const BYTES_PER_ROCK: u64 = 12_000;

/// A run beyond its limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitError {
    #[error("rock.mean_size = {size_mm} mm in the generation region {:.4} × {:.4} × {:.4} m ({volume:.4} m³) means about {rocks:.0} rocks (eq. 28), about {gigabytes:.2} GB at {BYTES_PER_ROCK} bytes per rock, above the limit of {limit} rocks; raise it with --max-rocks {rocks:.0} (or limits.max_rocks in the experiment file) to run it", extent[0], extent[1], extent[2])]
    TooManyRocks {
        size_mm: Real,
        volume: Real,
        /// The generation region's edges (m).
        extent: [Real; 3],
        rocks: Real,
        gigabytes: Real,
        limit: usize,
    },
    #[error("{stage}: {steps:.4e} steps of Δt = {dt:e} s ({reason}), above the limit of {limit} steps; raise it with --max-steps (or limits.max_steps in the experiment file) to run it")]
    TooManySteps {
        stage: &'static str,
        steps: Real,
        dt: Real,
        reason: String,
        limit: u64,
    },
}

/// The rock count generation would make from `params` (eq. 28: the seed count), refused above `limit`.
/// Cheap: no seed is drawn. A size law that cannot be formed is generation's own error, reported there.
pub fn check_rock_count(params: &GenerationParams, limit: usize) -> Result<(), LimitError> {
    let Ok((_, radius)) = size_law_and_cell_radius(params) else {
        return Ok(());
    };
    let volume = params.region.volume();
    // The unrounded count of eq. 28: above the generator's own cap too, when the limit is raised past it.
    let rocks = (volume / (4.0 * std::f64::consts::PI / 3.0 * radius.powi(3))).round();
    if rocks <= limit as Real {
        return Ok(());
    }
    let e = params.region.extent();
    Err(LimitError::TooManyRocks {
        size_mm: params.mean_size * 1e3,
        volume,
        extent: [e.x, e.y, e.z],
        rocks,
        gigabytes: rocks * BYTES_PER_ROCK as Real / 1e9,
        limit,
    })
}

/// The packing's steps at `dt`: at most `max_deposition_time`, the wall's travel from the generation height
/// to the layer at `compaction_speed`, `hold_time` and `restore_time`, over Δt; refused above the limit.
pub fn check_packing_steps(config: &ExperimentConfig, dt: Real) -> Result<(), LimitError> {
    let p = &config.packing;
    let compaction = (p.generation_height_factor - 1.0) * config.layer.height / p.compaction_speed;
    let restore = p.restore_time.unwrap_or(0.0);
    let time = p.max_deposition_time + compaction + p.hold_time + restore;
    let reason = format!(
        "packing.max_deposition_time {} s + compaction {compaction:.4} s at packing.compaction_speed + packing.hold_time {} s + packing.restore_time {restore} s, Δt from the lightest rock's contact time",
        p.max_deposition_time, p.hold_time
    );
    within(config, "packing", time / dt, dt, reason)
}

pub(crate) fn within(
    config: &ExperimentConfig,
    stage: &'static str,
    steps: Real,
    dt: Real,
    reason: String,
) -> Result<(), LimitError> {
    let limit = config.limits.max_steps;
    if steps <= limit as Real {
        return Ok(());
    }
    Err(LimitError::TooManySteps {
        stage,
        steps,
        dt,
        reason,
        limit,
    })
}
