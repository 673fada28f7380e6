//! Validation of a parsed scene and construction of the [`Simulation`] it describes, one file per table of
//! the scene file: `materials`, `interactions` (the contact laws), `shapes`, `bodies`, `body_files`,
//! `walls` (`[[wall]]` and `[[box]]`), `step_size` (the time step) and `simulation` (the rest of
//! `[simulation]`); `assemble` puts the checked parts into a [`crate::world::World`]. `build` reads as the list of
//! tables, in the order their errors are reported.
//!
//! Every check names the file, the line (from the span toml keeps for each value) and the field, in the
//! form `FILE:LINE: FIELD: what is wrong`, e.g. `scenes/drop.toml:14: interaction[0].normal_stiffness:
//! must be finite and positive, got -1`.

mod assemble;
mod bodies;
mod body_files;
mod ctx;
mod interactions;
mod materials;
mod shapes;
mod simulation;
mod step_size;
mod walls;

use std::path::{Path, PathBuf};

use super::schema::SceneFile;
pub use super::simulation::Simulation;
use ctx::Ctx;

/// Why a scene could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{}: cannot read the scene file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown field, a missing field or a value of the wrong type.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// A value that parses but is not valid.
    #[error("{}:{line}: {field}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// The field at fault.
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// Reads and builds the scene at `path`.
pub fn load_scene(path: &Path) -> Result<Simulation, SceneError> {
    let source = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    parse_scene(&source, path)
}

/// Builds a scene from its text; `path` is used in the messages.
pub fn parse_scene(source: &str, path: &Path) -> Result<Simulation, SceneError> {
    let ctx = Ctx { path, source };
    let file: SceneFile = toml::from_str(source).map_err(|e| {
        let (line, column) = e.span().map(|s| ctx.line_column(s.start)).unwrap_or((0, 0));
        SceneError::Parse {
            path: path.to_owned(),
            line,
            column,
            message: e.message().trim().to_owned(),
        }
    })?;
    build(&ctx, &file)
}

/// The tables in the order their errors are reported; each step checks its table completely.
fn build(ctx: &Ctx, file: &SceneFile) -> Result<Simulation, SceneError> {
    let sim = &file.simulation;
    let run = simulation::RunLength::read(ctx, sim)?;
    let mut materials = materials::Materials::read(ctx, &file.materials)?;
    interactions::read(ctx, file, &mut materials)?;
    let mut shapes = shapes::Shapes::read(ctx, file)?;
    let mut bodies = bodies::read(ctx, file, &shapes, &materials)?;
    body_files::read(ctx, file, &materials, &mut shapes, &mut bodies)?;
    let walls = walls::read(ctx, file, &materials)?;
    let time_step = step_size::choose(ctx, sim, &materials.table, &shapes, &bodies, &walls)?;
    let steps = simulation::step_count(ctx, sim, &run, &time_step)?;
    let damping = simulation::viscous_damping(ctx, sim)?;
    let skin = simulation::skin(ctx, sim, &shapes)?;
    let assembled = assemble::world(
        ctx,
        run.gravity,
        materials.table,
        skin,
        shapes,
        bodies,
        walls,
    )?;
    let params = simulation::step_params(ctx, sim, time_step.dt, damping)?;
    let output_every = ((run.output_interval / time_step.dt).round() as u64).max(1);
    Ok(Simulation {
        world: assembled.world,
        params,
        time_step,
        end_time: run.end_time,
        steps,
        output_every,
        tracked: assembled.tracked,
        frames: assembled.frames,
    })
}
