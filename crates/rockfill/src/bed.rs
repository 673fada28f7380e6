//! The packed bed as an engine checkpoint (`bed.pdck`, format of [`polydem::io::checkpoint`]), so that every
//! penetration run of a study starts from the same packed state.
//!
//! # Why the checkpoint and not only the CSV files
//! [`super::packing::save_bed`] writes the rocks' vertices and poses as CSV (readable, and portable to other
//! codes), but a bed reloaded from it starts with an empty contact store: the tangential springs of the
//! packed contacts, their warm-start caches and the broad phase's pair list are lost, and the rebuilt hull
//! reorders the vertices. The penetration run from a CSV bed is therefore a different (equally valid) run.
//! The checkpoint holds the whole [`World`] bit for bit, so the penetration run from it is the run straight
//! after packing, step for step (`tests/rockfill_bed.rs` checks that every monitor row is bitwise equal).
//! Both are written; `--bed` reads the checkpoint when the directory has one, else the CSV files.
//!
//! # Files
//! `bed.pdck`: a [`Simulation`] holding the packed world, the packing step parameters and Δt; `tracked` is
//! empty and `frames` are identities (the rocks have no input frame of their own). `bed_info.json`: what
//! generating and packing the bed cost ([`BedInfo`]), so a study that reuses a bed still reports it.

use std::path::Path;
use std::time::Duration;

use super::packing::PackingReport;
use polydem::io::checkpoint::{self, CheckpointError};
use polydem::math::{Pose, Real};
use polydem::scene::time_step::TimeStepInfo;
use polydem::scene::Simulation;
use polydem::world::{StepParams, World};

/// The checkpoint's file name inside a bed directory.
pub const BED_CHECKPOINT: &str = "bed.pdck";
/// The bed's facts, next to the checkpoint.
pub const BED_INFO: &str = "bed_info.json";

/// Why a bed could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum BedError {
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error("bed info {path}: {message}")]
    Info { path: String, message: String },
}

/// What making the bed cost and gave (written as `bed_info.json`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BedInfo {
    pub mean_size: Real,
    pub seed: u64,
    pub rocks: usize,
    pub generation_s: Real,
    pub packing_s: Real,
    pub packing_dt: Real,
    pub solid_fraction: Real,
    pub top_wall: Real,
    pub compaction_stalled: bool,
    /// polydem version and git description of the build that made the bed (provenance).
    pub engine_version: String,
}

impl BedInfo {
    pub fn new(
        mean_size: Real,
        seed: u64,
        generation_time: Duration,
        packing: &PackingReport,
    ) -> Self {
        Self {
            mean_size,
            seed,
            rocks: packing.rocks,
            generation_s: generation_time.as_secs_f64(),
            packing_s: packing.wall_time.as_secs_f64(),
            packing_dt: packing.dt,
            solid_fraction: packing.solid_fraction,
            top_wall: packing.top_wall,
            compaction_stalled: packing.compaction_stalled,
            engine_version: env!("CARGO_PKG_VERSION").to_owned(),
        }
    }
}

/// Writes the packed `world` as `dir/bed.pdck` (and `info` as `dir/bed_info.json`). Returns the checkpoint's
/// size in bytes.
pub fn save_bed_checkpoint(
    world: &World,
    packing: &PackingReport,
    info: &BedInfo,
    dir: &Path,
) -> Result<u64, BedError> {
    let info_path = dir.join(BED_INFO);
    let info_error = |message: String| BedError::Info {
        path: info_path.display().to_string(),
        message,
    };
    std::fs::create_dir_all(dir).map_err(|e| info_error(e.to_string()))?;
    let sim = Simulation {
        world: world.clone(),
        params: StepParams::new(packing.dt),
        time_step: TimeStepInfo {
            dt: packing.dt,
            derived: true,
            contact_time: packing.contact_time,
            stability_limit: packing.dt,
        },
        end_time: world.time(),
        steps: 0,
        output_every: 1,
        tracked: Vec::new(),
        frames: vec![Pose::identity(); world.bodies().len()],
    };
    let bytes = checkpoint::save(&dir.join(BED_CHECKPOINT), &sim)?;
    let text = serde_json::to_string_pretty(info).map_err(|e| info_error(e.to_string()))?;
    std::fs::write(&info_path, text).map_err(|e| info_error(e.to_string()))?;
    Ok(bytes)
}

/// Reads the world of `dir/bed.pdck`.
pub fn load_bed_checkpoint(dir: &Path) -> Result<World, BedError> {
    Ok(checkpoint::load(&dir.join(BED_CHECKPOINT))?
        .simulation
        .world)
}

/// Reads `dir/bed_info.json`, if there is one.
pub fn load_bed_info(dir: &Path) -> Result<Option<BedInfo>, BedError> {
    let path = dir.join(BED_INFO);
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).map_err(|e| BedError::Info {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| BedError::Info {
            path: path.display().to_string(),
            message: e.to_string(),
        })
}

/// Whether `dir` holds a bed checkpoint.
pub fn has_checkpoint(dir: &Path) -> bool {
    dir.join(BED_CHECKPOINT).is_file()
}
