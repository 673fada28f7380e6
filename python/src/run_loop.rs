//! `Simulation.run`: the engine's run loop driven in stretches, with the GIL released inside each stretch
//! and taken again between them for the user's callback and the progress callback, and within them for
//! Ctrl-C ([`crate::interrupt`]). The outputs
//! (CSV series, VTK frames, contact network, checkpoints) are the engine's, opened by the same function
//! as `polydem run`'s, so a directory written from Python is the one the command writes.

use std::path::PathBuf;

use polydem::io::output::OutputSet;
use polydem::io::run_outputs::{open_outputs, IntervalNames, OutputPlan, RunStart};
use polydem::math::Real;
use polydem::scene::{self, RunObserver, Simulation};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

use crate::errors::run_error;
use crate::interrupt::{Interruptible, SignalCheck};

/// What a `run` call asked for.
pub struct RunRequest<'py> {
    /// The step the run ends at.
    pub last: u64,
    /// Steps between calls of `callback` (`u64::MAX`: only at the end).
    pub callback_every: u64,
    pub callback: Option<Bound<'py, PyAny>>,
    /// `progress(step, last)` about every hundredth of the run.
    pub progress: Option<Bound<'py, PyAny>>,
    /// The output directory and what to write there.
    pub out: Option<(PathBuf, OutputPlan)>,
}

const PYTHON_NAMES: IntervalNames = IntervalNames {
    vtk: "vtk_interval",
    contacts: "contacts_interval",
    checkpoint: "checkpoint_interval",
};

/// An observer of one stretch of a longer run: it hands the outputs every state they are due except the
/// stretch's first, which the previous stretch already handed them.
struct Stretch<'s, 'a> {
    outputs: &'s mut OutputSet<'a>,
    skip: Option<u64>,
}

impl RunObserver for Stretch<'_, '_> {
    fn wants_state(&self, step: u64) -> bool {
        self.outputs.wants_state(step)
    }
    fn observe(&mut self, sim: &Simulation, step: u64) -> std::io::Result<()> {
        if self.skip == Some(step) {
            return Ok(());
        }
        self.outputs.observe(sim, step)
    }
    fn reads_contacts(&self, step: u64) -> bool {
        self.outputs.reads_contacts(step)
    }
}

/// The Python object that owns the simulation a run steps (`polydem.Simulation`): a trait, so that the
/// loop is written without the class that calls it.
pub trait OwnsSimulation: pyo3::PyClass<Frozen = pyo3::pyclass::boolean_struct::False> {
    fn simulation(&self) -> &Simulation;
    fn simulation_mut(&mut self) -> &mut Simulation;
}

/// Runs the simulation `owner` to `request.last`. It is borrowed mutably for one stretch at a time, so
/// callbacks between stretches see the simulation object as usual.
pub fn run<'py, O: OwnsSimulation>(
    owner: &Bound<'py, O>,
    request: RunRequest<'py>,
) -> PyResult<()> {
    let py = owner.py();
    let mut outputs = match &request.out {
        None => None,
        Some((dir, plan)) => {
            let mut this = owner.borrow_mut();
            let sim = this.simulation_mut();
            Some(open_for(sim, dir, plan, request.last)?)
        }
    };
    let start = owner.borrow().simulation().world.step_index();
    let progress_every = ((request.last.saturating_sub(start)) / 100).max(scene::PROGRESS_STEPS);
    let chunk = if request.progress.is_some() {
        request.callback_every.min(progress_every)
    } else {
        request.callback_every
    };
    let mut next_callback = start.saturating_add(request.callback_every);
    let mut signals = SignalCheck::new(py);
    loop {
        let done = owner.borrow().simulation().world.step_index();
        if done >= request.last {
            break;
        }
        let end = done
            .saturating_add(chunk)
            .min(request.last)
            .min(next_callback);
        {
            let mut this = owner.borrow_mut();
            let sim = this.simulation_mut();
            let skip = (done != start).then_some(done);
            let result = py.detach(|| stretch(sim, end, outputs.as_mut(), skip, &mut signals));
            if let Some(interrupt) = signals.take_raised() {
                // What was written up to the interrupt is flushed: the files end at the state where the
                // simulation stopped.
                outputs
                    .map(OutputSet::finish)
                    .transpose()
                    .map_err(os_error)?;
                return Err(interrupt);
            }
            result.map_err(|e| run_error(&e))?;
        }
        py.check_signals()?;
        if let Some(progress) = &request.progress {
            progress.call1((end, request.last))?;
        }
        if end == next_callback || end == request.last {
            next_callback = end.saturating_add(request.callback_every);
            if let Some(callback) = &request.callback {
                callback.call1((owner,))?;
            }
        }
    }
    outputs
        .map(OutputSet::finish)
        .transpose()
        .map_err(os_error)?;
    Ok(())
}

fn os_error(e: std::io::Error) -> PyErr {
    PyOSError::new_err(e.to_string())
}

/// The outputs of a run from `sim`'s state to step `last`, in `dir`.
fn open_for<'a>(
    sim: &mut Simulation,
    dir: &std::path::Path,
    plan: &OutputPlan,
    last: u64,
) -> PyResult<OutputSet<'a>> {
    let end = sim.steps;
    sim.steps = last;
    let opened = open_outputs(dir, plan, PYTHON_NAMES, sim, &RunStart::Fresh);
    sim.steps = end;
    opened.map_err(|e| match e {
        polydem::io::run_outputs::OutputPlanError::Interval { .. } => {
            PyValueError::new_err(e.to_string())
        }
        polydem::io::run_outputs::OutputPlanError::Io { .. } => PyOSError::new_err(e.to_string()),
    })
}

/// Steps `sim` to step `end` through the engine's run loop, handing the outputs (if any) their states,
/// and stops early at a step boundary if a signal handler raises ([`Interruptible`]).
fn stretch(
    sim: &mut Simulation,
    end: u64,
    outputs: Option<&mut OutputSet<'_>>,
    skip: Option<u64>,
    signals: &mut SignalCheck,
) -> Result<(), scene::RunError> {
    let scene_end = sim.steps;
    sim.steps = end;
    let result = match outputs {
        Some(outputs) => sim.run_observed(&mut Interruptible {
            inner: Stretch { outputs, skip },
            signals,
        }),
        None => sim.run_observed(&mut Interruptible {
            inner: Unobserved,
            signals,
        }),
    };
    sim.steps = scene_end;
    result.map(|_| ())
}

/// An observer that reads nothing: the run loop then chooses its stepping path freely (the flat sphere
/// layout where it applies) and writes the state back at the end.
pub struct Unobserved;

impl RunObserver for Unobserved {
    fn wants_state(&self, _step: u64) -> bool {
        false
    }
    fn observe(&mut self, _sim: &Simulation, _step: u64) -> std::io::Result<()> {
        Ok(())
    }
    fn reads_contacts(&self, _step: u64) -> bool {
        false
    }
}

/// An output interval keyword's value in seconds, checked by the engine when the outputs are opened.
pub fn plan(
    vtk_interval: Option<Real>,
    contacts_interval: Option<Real>,
    checkpoint_interval: Option<Real>,
) -> OutputPlan {
    OutputPlan {
        vtk_interval,
        contacts_interval,
        checkpoint_interval,
        ..OutputPlan::default()
    }
}
