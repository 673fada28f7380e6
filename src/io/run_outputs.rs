//! The outputs a run writes into its directory, opened the same way by every front door (the `polydem run`
//! command, the Python package): the CSV series always, VTK frames, the contact network and checkpoints
//! when asked for, in the order of [`OutputSet`] (checkpoints last, so that the series on disk reach each
//! checkpoint). Intervals are given in seconds of simulated time and rounded to whole steps.
//!
//! Opening takes the directory's lock before any file is created or rewritten, and records (fresh run) or
//! checks (restart) the directory's run identity.

use std::io;
use std::path::{Path, PathBuf};

use crate::io::checkpoint_series::CheckpointSeries;
use crate::io::contact_network::ContactNetwork;
use crate::io::csv_series::CsvSeries;
use crate::io::output::{OutputSet, Schedule};
use crate::io::output_lock::DirectoryLock;
use crate::io::run_identity;
use crate::io::vtk::{VtkEncoding, VtkWriter};
use crate::io::vtk_frames::VtkFrames;
use crate::math::Real;
use crate::scene::Simulation;

/// What a run writes besides its CSV series, with intervals in seconds of simulated time (`None`: not
/// written).
#[derive(Clone, Debug, Default)]
pub struct OutputPlan {
    /// VTK frames of the bodies and walls, with a `.pvd` series.
    pub vtk_interval: Option<Real>,
    /// Encoding of the VTK frames.
    pub vtk_encoding: VtkEncoding,
    /// The contact network (`contacts.csv`, `contacts.pvd`).
    pub contacts_interval: Option<Real>,
    /// Checkpoints (`checkpoints/*.pdck`), also written at the end.
    pub checkpoint_interval: Option<Real>,
}

/// How a run starts: from its scene, or from a checkpoint (with the identity of the run that wrote it).
#[derive(Clone, Debug)]
pub enum RunStart {
    /// A new run: the directory's series are created afresh.
    Fresh,
    /// A restart: the series an earlier run of the same identity left in the directory are continued.
    Restart {
        /// The checkpoint the run continues from.
        checkpoint: PathBuf,
        /// The identity stored in the checkpoint (`None` for a file without one).
        run: Option<u64>,
    },
}

/// Why a run's outputs cannot be opened.
#[derive(Debug, thiserror::Error)]
pub enum OutputPlanError {
    /// An interval that is not a finite, positive time.
    #[error("{name} must be a finite, positive time in seconds, got {value}")]
    Interval {
        /// The interval's name, as the front door spells it (`--vtk-interval`, `vtk_interval`).
        name: String,
        /// The value given.
        value: Real,
    },
    /// A file of the output directory cannot be created, locked or continued.
    #[error("{what} {}: {source}", path.display())]
    Io {
        /// What was being done.
        what: &'static str,
        /// The directory or file concerned.
        path: PathBuf,
        /// The underlying error (its message names the file where it can).
        source: io::Error,
    },
}

/// The step interval of an output given in seconds: round(T / Δt), at least one step. `name` is used in
/// the error.
pub fn interval_steps(
    name: &str,
    interval: Option<Real>,
    dt: Real,
) -> Result<Option<u64>, OutputPlanError> {
    match interval {
        None => Ok(None),
        Some(t) if t.is_finite() && t > 0.0 => Ok(Some(((t / dt).round() as u64).max(1))),
        Some(value) => Err(OutputPlanError::Interval {
            name: name.to_owned(),
            value,
        }),
    }
}

/// The interval names of a front door, used in its errors (the CLI's flags or Python's keywords).
#[derive(Copy, Clone, Debug)]
pub struct IntervalNames {
    /// Name of [`OutputPlan::vtk_interval`].
    pub vtk: &'static str,
    /// Name of [`OutputPlan::contacts_interval`].
    pub contacts: &'static str,
    /// Name of [`OutputPlan::checkpoint_interval`].
    pub checkpoint: &'static str,
}

/// Opens the outputs of `sim`'s run into `out_dir` (created if missing): locks the directory, records or
/// checks its run identity, and creates (fresh run) or continues (restart) each series. Every series is
/// written at the run's first and last step and every interval in between; checkpoints not at the first.
pub fn open_outputs<'a>(
    out_dir: &Path,
    plan: &OutputPlan,
    names: IntervalNames,
    sim: &Simulation,
    start: &RunStart,
) -> Result<OutputSet<'a>, OutputPlanError> {
    let dt = sim.params.dt;
    let vtk_every = interval_steps(names.vtk, plan.vtk_interval, dt)?;
    let contacts_every = interval_steps(names.contacts, plan.contacts_interval, dt)?;
    let checkpoint_every = interval_steps(names.checkpoint, plan.checkpoint_interval, dt)?;
    let at = |what: &'static str, path: &Path| {
        let path = path.to_owned();
        move |source| OutputPlanError::Io { what, path, source }
    };
    std::fs::create_dir_all(out_dir).map_err(at("cannot create output directory", out_dir))?;
    // Taken before any file of the directory is created or rewritten.
    let lock = DirectoryLock::acquire(out_dir).map_err(at("cannot lock", out_dir))?;
    let (run, restarted) = match start {
        RunStart::Fresh => {
            let run = run_identity::new_run();
            run_identity::record(out_dir, run).map_err(at("cannot record the run in", out_dir))?;
            (run, false)
        }
        RunStart::Restart { checkpoint, run } => {
            let run = run_identity::continue_in(out_dir, *run, checkpoint)
                .map_err(at("cannot restart into", out_dir))?;
            (run, true)
        }
    };
    let schedule = |every: Option<u64>, at_start: bool| Schedule {
        start_step: sim.world.step_index(),
        last_step: sim.steps,
        every,
        at_start,
        at_end: true,
    };
    let mut outputs = OutputSet::new();
    outputs.hold(lock);
    let csv = schedule(Some(sim.output_every), true);
    outputs.push(
        if restarted {
            CsvSeries::continue_at(out_dir, sim.world.time(), csv)
        } else {
            CsvSeries::create(out_dir, csv)
        }
        .map_err(at("cannot open the CSV series in", out_dir))?,
    );
    if let Some(every) = vtk_every {
        let encoding = plan.vtk_encoding;
        let writer = if restarted {
            VtkWriter::resume(out_dir, &sim.world, encoding)
        } else {
            VtkWriter::new(out_dir, &sim.world, encoding)
        }
        .map_err(at("cannot open the VTK series in", out_dir))?;
        outputs.push(VtkFrames::new(writer, schedule(Some(every), true)));
    }
    if let Some(every) = contacts_every {
        let network = schedule(Some(every), true);
        outputs.push(
            if restarted {
                ContactNetwork::continue_at(out_dir, &sim.world, network)
            } else {
                ContactNetwork::create(out_dir, network)
            }
            .map_err(at("cannot open the contact network in", out_dir))?,
        );
    }
    if let Some(every) = checkpoint_every {
        let series = CheckpointSeries::new(out_dir, run, schedule(Some(every), false))
            .map_err(at("cannot open the checkpoints of", out_dir))?;
        outputs.push(series);
    }
    Ok(outputs)
}
