//! The experiment end to end: generate the sample, pack it (or load a packed bed), run the impact.

use std::path::Path;
use std::time::Duration;

use super::bed::{
    has_checkpoint, load_bed_checkpoint, load_bed_info, save_bed_checkpoint, BedError, BedInfo,
};
use super::collapse::{collapse, CollapseParams, CollapseReport};
use super::config::ExperimentConfig;
use super::generation::{generate, GenerationError, GenerationParams, Sample};
use super::grading::Rock;
use super::limits::{check_rock_count, LimitError};
use super::packing::{empty_world, load_bed, loose_world, save_bed, PackingError, PackingReport};
use super::packing_run::pack_with_stop;
use super::penetration::{
    add_projectile, check_penetration_steps, penetrate_with, MonitorRow, PenetrationError,
    PenetrationOptions, PenetrationReport,
};
use super::projectile::{Projectile, ProjectileError};
use super::seeds::{Region, SeedError};
use super::statistics::{sample_statistics, SampleStatistics};
use polydem::io::checkpoint::CheckpointError;
use polydem::math::{Point, Real};
use polydem::world::World;

/// Why the experiment failed.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    #[error(transparent)]
    Seeds(#[from] SeedError),
    #[error(transparent)]
    Generation(#[from] GenerationError),
    #[error(transparent)]
    Projectile(#[from] ProjectileError),
    #[error(transparent)]
    Packing(#[from] PackingError),
    #[error(transparent)]
    Penetration(#[from] PenetrationError),
    #[error(transparent)]
    Bed(#[from] BedError),
    #[error(
        "bed {dir}: rock {rock} has density {bed} kg/m³ (mass over volume), the experiment file's rock.density \
         is {config} kg/m³; pack a new bed, or set rock.density to the bed's"
    )]
    BedDensity {
        dir: String,
        rock: usize,
        bed: Real,
        config: Real,
    },
    #[error(
        "bed {dir} was packed from {bed_mm} mm rocks (its bed_info.json), but the run asks for {config_mm} mm \
         (--size or rock.mean_size): the size sets the penetration's time step and the unit of the disturbed \
         zone, so the run would be labelled and stepped as another bed; run with --size {bed_mm}, or pack a new bed"
    )]
    BedSize {
        dir: String,
        bed_mm: Real,
        config_mm: Real,
    },
    #[error(transparent)]
    Limit(#[from] LimitError),
}

/// Where the bed comes from.
#[derive(Clone, Copy, Debug)]
pub enum BedSource<'a> {
    /// Generate and pack; save the packed bed into the directory if one is given (the checkpoint
    /// `bed.pdck` with `bed_info.json`, and the CSV files; see [`super::bed`]).
    Generate { save: Option<&'a Path> },
    /// Load a bed saved earlier: its checkpoint when the directory has one (its CSV files when the checkpoint
    /// is of another format version), else its CSV files.
    Load(&'a Path),
}

/// Generation facts (absent when the bed was loaded).
#[derive(Clone, Debug)]
pub struct GenerationSummary {
    pub seeds: usize,
    pub rocks: usize,
    pub dropped_small_cells: usize,
    pub cell_radius: Real,
    pub statistics: SampleStatistics,
    /// Mean and standard deviation of the size law eq. 29 samples (m).
    pub requested_mean: Real,
    pub requested_std: Real,
    pub wall_time: Duration,
}

/// Everything the experiment measured.
#[derive(Clone, Debug)]
pub struct ExperimentResult {
    pub generation: Option<GenerationSummary>,
    pub packing: Option<PackingReport>,
    /// The bed's facts: written with a generated bed, read with a loaded one (absent for a CSV bed
    /// without `bed_info.json`).
    pub bed: Option<BedInfo>,
    /// Whether the bed was read from a checkpoint (false: generated, or read from CSV).
    pub bed_from_checkpoint: bool,
    pub projectile: Projectile,
    pub penetration: PenetrationReport,
    /// The world at the end of the run (the projectile is the last body).
    pub world: World,
}

/// Progress messages: (stage, text).
pub type Progress<'a> = &'a mut dyn FnMut(&str, String);

/// Generates the graded sample of `config` in the region above the layer (x ∈ [0, L], y ∈ [0, W],
/// z ∈ [0, H · generation_height_factor]).
pub fn generate_sample(config: &ExperimentConfig) -> Result<Sample, ExperimentError> {
    Ok(generate(&generation_params(config)?)?)
}

/// What [`generate_sample`] generates from `config`.
pub fn generation_params(config: &ExperimentConfig) -> Result<GenerationParams, ExperimentError> {
    let l = &config.layer;
    let region = Region::new(
        Point::origin(),
        Point::new(
            l.length,
            l.width,
            l.height * config.packing.generation_height_factor,
        ),
    )?;
    let mut params = GenerationParams::new(region, config.rock.mean_size, config.rock.seed);
    params.sigma_fraction = config.rock.sigma_fraction;
    params.range_fraction = config.rock.range_fraction;
    Ok(params)
}

/// The limits that can be checked before any rock is generated: the rock count, and the penetration's
/// steps at the largest Δt the projectile's travel per step allows.
pub fn check_limits_before_generation(config: &ExperimentConfig) -> Result<(), ExperimentError> {
    check_rock_count(&generation_params(config)?, config.limits.max_rocks)?;
    let imp = &config.impact;
    let dt_bound = imp.travel_per_step * config.rock.mean_size / imp.speed;
    check_penetration_steps(config, dt_bound, true)?;
    Ok(())
}

/// A bed recorded at one rock size is refused for a run at another (a bed without `bed_info.json` has no
/// recorded size).
fn check_bed_size(
    config: &ExperimentConfig,
    dir: &Path,
    info: Option<&BedInfo>,
) -> Result<(), ExperimentError> {
    let Some(info) = info else { return Ok(()) };
    let (bed, asked) = (info.mean_size, config.rock.mean_size);
    if (bed - asked).abs() > 1e-9 * bed.abs().max(asked.abs()) {
        return Err(ExperimentError::BedSize {
            dir: dir.display().to_string(),
            bed_mm: bed * 1e3,
            config_mm: asked * 1e3,
        });
    }
    Ok(())
}

/// A bed read from its checkpoint keeps its rocks (shapes, masses, state) and takes the contact laws of
/// the experiment file, as a bed read from its CSV files does: the checkpoint also stores the laws it was
/// packed with, and a file changed since (a stiffness study from one bed) must not be silently overruled.
/// A changed rock density cannot be applied to packed rocks (their weights set the bed): an error.
fn apply_experiment_laws(
    config: &ExperimentConfig,
    dir: &Path,
    world: &mut World,
    progress: Progress,
) -> Result<(), ExperimentError> {
    for i in 0..world.bodies().len() {
        if let polydem::shape::Shape::Polyhedron(p) = world.shape(i) {
            let bed = world.bodies()[i].mass / p.mass_properties().volume;
            if (bed - config.rock.density).abs() > 1e-9 * config.rock.density {
                return Err(ExperimentError::BedDensity {
                    dir: dir.display().to_string(),
                    rock: i,
                    bed,
                    config: config.rock.density,
                });
            }
        }
    }
    let laws = empty_world(config, world.broad_phase().skin())?
        .materials()
        .clone();
    if *world.materials() != laws {
        progress(
            "bed",
            "the experiment file's contact laws differ from those the bed was packed with: the run uses the file's"
                .into(),
        );
        world.set_materials(laws).map_err(PackingError::from)?;
    }
    Ok(())
}

/// Runs the experiment (see the module docs).
pub fn run_experiment(
    config: &ExperimentConfig,
    bed: BedSource,
    progress: Progress,
) -> Result<ExperimentResult, ExperimentError> {
    run_experiment_with(config, bed, &PenetrationOptions::default(), progress)
}

/// [`run_experiment`] with options for the penetration run.
pub fn run_experiment_with(
    config: &ExperimentConfig,
    bed: BedSource,
    options: &PenetrationOptions,
    progress: Progress,
) -> Result<ExperimentResult, ExperimentError> {
    let projectile = Projectile::new(config.projectile)?;
    let PreparedBed {
        mut world,
        generation,
        packing,
        info: bed_info,
        from_checkpoint,
    } = match bed {
        BedSource::Load(dir) => loaded_bed(config, dir, &mut *progress)?,
        BedSource::Generate { save } => generated_bed(config, save, options, &mut *progress)?,
    };
    let index = add_projectile(config, &mut world, &projectile)?;
    if options.start_offset != polydem::math::Vector::zeros() {
        let position = world.body(index).position + options.start_offset;
        world
            .set_body_position(index, position)
            .map_err(PackingError::from)?;
    }
    let penetration = penetrate_with(
        config,
        &mut world,
        &projectile,
        index,
        options,
        |row: &MonitorRow| {
            progress(
                "penetration",
                format!(
                    "t = {:.3} ms, x = {:.3} m, v = {:.1} m/s, contacts {}",
                    row.time * 1e3,
                    row.position.x,
                    row.velocity.norm(),
                    row.contacts
                ),
            )
        },
    )?;
    Ok(ExperimentResult {
        generation,
        packing,
        bed: bed_info,
        bed_from_checkpoint: from_checkpoint,
        projectile,
        penetration,
        world,
    })
}

/// The bed the penetration starts from, and how it came to be.
struct PreparedBed {
    world: World,
    generation: Option<GenerationSummary>,
    packing: Option<PackingReport>,
    info: Option<BedInfo>,
    from_checkpoint: bool,
}

/// A bed saved earlier in `dir`: its checkpoint (with the experiment's laws applied) when it has one of this
/// build's format, else its CSV files.
fn loaded_bed(
    config: &ExperimentConfig,
    dir: &Path,
    progress: Progress,
) -> Result<PreparedBed, ExperimentError> {
    let info = load_bed_info(dir)?;
    check_bed_size(config, dir, info.as_ref())?;
    let (mut world, checkpoint) = if has_checkpoint(dir) {
        match load_bed_checkpoint(dir) {
            Ok(world) => (world, true),
            // A checkpoint of another format version (written by another build): the CSV files of
            // the same bed are version-free.
            Err(BedError::Checkpoint(CheckpointError::UnsupportedVersion { found, supported }))
                if dir.join("bed_rocks.csv").is_file() =>
            {
                progress(
                    "bed",
                    format!(
                        "checkpoint format {found} is not this build's ({supported}): reading the CSV bed"
                    ),
                );
                (load_bed(config, dir)?, false)
            }
            Err(e) => return Err(e.into()),
        }
    } else {
        (load_bed(config, dir)?, false)
    };
    if checkpoint {
        apply_experiment_laws(config, dir, &mut world, &mut *progress)?;
    }
    progress(
        "bed",
        format!(
            "{} bodies from {} ({})",
            world.bodies().len(),
            dir.display(),
            if checkpoint { "checkpoint" } else { "CSV" }
        ),
    );
    Ok(PreparedBed {
        world,
        generation: None,
        packing: None,
        info,
        from_checkpoint: checkpoint,
    })
}

/// A bed generated, pre-collapsed when asked, packed, and saved into `save` when given.
fn generated_bed(
    config: &ExperimentConfig,
    save: Option<&Path>,
    options: &PenetrationOptions,
    progress: Progress,
) -> Result<PreparedBed, ExperimentError> {
    check_limits_before_generation(config)?;
    let start = std::time::Instant::now();
    let sample = generate_sample(config)?;
    let generation = generation_summary(&sample, start);
    progress(
        "generation",
        format!(
            "{} seeds, {} rocks ({} cells too small), {:.2} s",
            generation.seeds,
            generation.rocks,
            generation.dropped_small_cells,
            generation.wall_time.as_secs_f64()
        ),
    );
    let top = config.layer.height * config.packing.generation_height_factor;
    let mut rocks = sample.rocks;
    let collapsed = config
        .packing
        .collapse_gap
        .map(|gap| collapse_rocks(config, &mut rocks, gap, &mut *progress));
    let mut world = loose_world(config, &rocks, top)?;
    let stop = options.stop.as_ref();
    let mut packing = pack_with_stop(config, &mut world, stop, |stage, t, h| {
        progress(stage, format!("t = {t:.3} s, height {h:.3} m"))
    })?;
    packing.collapse = collapsed;
    let info = BedInfo::new(
        config.rock.mean_size,
        config.rock.seed,
        generation.wall_time,
        &packing,
    );
    if let Some(dir) = save {
        save_bed(&world, dir)?;
        save_bed_checkpoint(&world, &packing, &info, dir)?;
    }
    Ok(PreparedBed {
        world,
        generation: Some(generation),
        packing: Some(packing),
        info: Some(info),
        from_checkpoint: false,
    })
}

/// What generation made of `sample`, begun at `start`.
fn generation_summary(sample: &Sample, start: std::time::Instant) -> GenerationSummary {
    let (requested_mean, var) = sample.sizes.bin_mean_and_variance();
    GenerationSummary {
        seeds: sample.seeds,
        rocks: sample.rocks.len(),
        dropped_small_cells: sample.grading.dropped_small_cells,
        cell_radius: sample.cell_radius,
        statistics: sample_statistics(&sample.rocks),
        requested_mean,
        requested_std: var.sqrt(),
        wall_time: start.elapsed(),
    }
}

/// Moves every rock straight down until it nearly touches (gap `gap` mean sizes; see [`super::collapse`]).
fn collapse_rocks(
    config: &ExperimentConfig,
    rocks: &mut [Rock],
    gap: Real,
    progress: Progress,
) -> CollapseReport {
    let params = CollapseParams::new(
        config.layer.length,
        config.layer.width,
        config.rock.mean_size,
        gap,
    );
    let report = collapse(rocks, &params);
    progress(
        "collapse",
        format!(
            "top {:.3} m -> {:.3} m, mean descent {:.3} m, {} moves, {} held by three, {} distance queries, {:.2} s",
            report.top_before,
            report.top_after,
            report.mean_descent,
            report.moves,
            report.held_by_three,
            report.queries,
            report.wall_time.as_secs_f64()
        ),
    );
    report
}
