//! `Scene` and `Simulation`: a scene read from TOML by the engine's scene builder, and its run, stepped by
//! the engine's run loop with the GIL released. State is handed out as numpy copies.

use std::path::PathBuf;

use numpy::PyArray2;
use polydem::io::checkpoint;
use polydem::math::Real;
use polydem::scene::{self, Simulation};
use polydem::world::Loads;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyType};

use crate::errors::{checkpoint_error, run_error, scene_error};
use crate::interrupt::{Interruptible, SignalCheck};
use crate::run_loop::{self, OwnsSimulation, RunRequest, Unobserved};
use crate::world_arrays;

/// A scene read and validated by the engine (materials, laws, shapes, bodies, walls, time step). Build a
/// `Simulation` from it to run it; the scene itself never changes.
#[pyclass(frozen, name = "Scene", module = "polydem")]
pub struct PyScene {
    sim: Simulation,
}

#[pymethods]
impl PyScene {
    /// Reads the scene file at `path` (the format of `docs/scene-format.md`). Raises `polydem.SceneError`
    /// with the engine's message (file, line, field) when it cannot be read or built.
    #[staticmethod]
    fn from_toml(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let sim = py
            .detach(|| scene::load_scene(&path))
            .map_err(|e| scene_error(py, &e))?;
        Ok(Self { sim })
    }

    /// Builds a scene from TOML text; `path` is the name used in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, path = PathBuf::from("<string>")))]
    fn from_string(py: Python<'_>, text: &str, path: PathBuf) -> PyResult<Self> {
        let sim = py
            .detach(|| scene::parse_scene(text, &path))
            .map_err(|e| scene_error(py, &e))?;
        Ok(Self { sim })
    }

    /// Builds a scene from a dict shaped like the scene file (`{"simulation": {...}, "material": [{...}],
    /// "body": [{...}], ...}`; numpy arrays and scalars are accepted wherever the file has numbers). It is
    /// written out as TOML text (`polydem.scene_to_toml(scene)`) and read by the engine's scene builder, so
    /// the validation and the error messages are those of a scene file, with line numbers in that text;
    /// `path` names it in errors, and relative paths in the scene (`[[body_file]]`) are taken from its
    /// directory.
    #[staticmethod]
    #[pyo3(signature = (scene, path = PathBuf::from("<dict>")))]
    fn from_dict(py: Python<'_>, scene: &Bound<'_, PyDict>, path: PathBuf) -> PyResult<Self> {
        let text = crate::scene_dict::scene_to_toml(scene)?;
        Self::from_string(py, &text, path)
    }

    /// Number of bodies.
    #[getter]
    fn num_bodies(&self) -> usize {
        self.sim.world.bodies().len()
    }

    /// Time step (s), given or derived from the contact time.
    #[getter]
    fn dt(&self) -> Real {
        self.sim.params.dt
    }

    /// End time of the scene (s).
    #[getter]
    fn end_time(&self) -> Real {
        self.sim.end_time
    }
}

/// Advances `sim` by `n` steps through the engine's run loop, whatever the scene's end time; a signal
/// handler that raises stops it early, at a step boundary ([`Interruptible`]).
fn advance(sim: &mut Simulation, n: u64, signals: &mut SignalCheck) -> Result<(), scene::RunError> {
    let end = sim.steps;
    sim.steps = sim.world.step_index().saturating_add(n);
    let result = sim.run_observed(&mut Interruptible {
        inner: Unobserved,
        signals,
    });
    sim.steps = end;
    result.map(|_| ())
}

/// The step index at time `t` (s) by the engine's rounding ([`Simulation::set_end_time`]), the
/// simulation left as it was.
/// `max_steps` bounds the run's total step count (the engine's default limit when `None`).
fn step_at(sim: &mut Simulation, t: Real, max_steps: Option<u64>) -> PyResult<u64> {
    let (end_time, steps) = (sim.end_time, sim.steps);
    let result = match max_steps {
        Some(max) => sim.set_end_time_within(t, max),
        None => sim.set_end_time(t),
    }
    .map(|()| sim.steps);
    (sim.end_time, sim.steps) = (end_time, steps);
    result.map_err(|e| PyValueError::new_err(format!("until: {e}")))
}

/// A callback interval (s) as a whole number of steps, at least one (the rounding of the scene's
/// `output_interval`).
fn interval_steps(every: Real, dt: Real) -> PyResult<u64> {
    if !(every.is_finite() && every > 0.0) {
        return Err(PyValueError::new_err(format!(
            "every: expected a finite positive time in seconds, got {every}"
        )));
    }
    Ok(((every / dt).round() as u64).max(1))
}

/// A running simulation. The state lives in the engine: every array this class returns is a **copy**
/// taken when it is called (a view would change under the caller at the next step, and would dangle if
/// the simulation were dropped). Body rows are in the scene's body order.
#[pyclass(name = "Simulation", module = "polydem")]
pub struct PySimulation {
    pub(crate) sim: Simulation,
}

impl OwnsSimulation for PySimulation {
    fn simulation(&self) -> &Simulation {
        &self.sim
    }
    fn simulation_mut(&mut self) -> &mut Simulation {
        &mut self.sim
    }
}

impl PySimulation {
    fn rows<'py>(
        &self,
        py: Python<'py>,
        width: usize,
        row: impl Fn(usize) -> Vec<Real>,
    ) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let rows: Vec<Vec<Real>> = (0..self.sim.world.bodies().len()).map(row).collect();
        if rows.is_empty() {
            return Ok(PyArray2::zeros(py, [0, width], false));
        }
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    fn current_loads(&self) -> PyResult<&Loads> {
        let loads = &self.sim.world.loads();
        if loads.is_current() && loads.forces().len() == self.sim.world.bodies().len() {
            Ok(loads)
        } else {
            Err(PyRuntimeError::new_err(
                "no contact forces yet: they are evaluated at the first step",
            ))
        }
    }
}

#[pymethods]
impl PySimulation {
    /// A simulation at the start of `scene` (the scene is copied; it can start other simulations).
    #[new]
    fn new(scene: &PyScene) -> Self {
        Self {
            sim: scene.sim.clone(),
        }
    }

    /// Reads the scene at `path` and starts a simulation of it (as `Simulation(Scene.from_toml(path))`).
    #[staticmethod]
    fn from_toml(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let sim = py
            .detach(|| scene::load_scene(&path))
            .map_err(|e| scene_error(py, &e))?;
        Ok(Self { sim })
    }

    /// Advances the simulation by `n` steps in the engine, with the GIL released (other Python threads
    /// run meanwhile). The steps are the same bits as `polydem run`'s. Raises `polydem.StepError` if a
    /// step fails (the state is then that of the failed step). Ctrl-C (or any signal whose handler
    /// raises) is seen within about 0.1 s (the engine's run loop looks at most 64 steps later) and stops
    /// the stepping at a step boundary: the exception (`KeyboardInterrupt`) is raised, `step_index`
    /// tells how far it got, and the simulation is consistent and can go on (the steps after it are the
    /// bits of an uninterrupted run).
    #[pyo3(signature = (n = 1))]
    fn step(&mut self, py: Python<'_>, n: u64) -> PyResult<()> {
        let sim = &mut self.sim;
        let mut signals = SignalCheck::new(py);
        let result = py.detach(|| advance(sim, n, &mut signals));
        if let Some(interrupt) = signals.take_raised() {
            return Err(interrupt);
        }
        result.map_err(|e| run_error(&e))
    }

    /// Runs to the time `until` (s; default: the scene's end time), calling `callback(sim)` every
    /// `every` seconds of simulated time (rounded to whole steps, at least one) and at the end; without
    /// `every`, once at the end. `progress(step, last_step)` is called about every hundredth of the run
    /// (for a progress bar). With `out`, the run writes the outputs of `polydem run --out` there: the CSV
    /// series at the scene's output interval, and VTK frames, the contact network and checkpoints at the
    /// given intervals (s); the directory is locked for the run and its series start afresh. The steps
    /// run in Rust with the GIL released; it is taken again between stretches for the callbacks, and
    /// about every 0.1 s (64 steps at most past that) for Ctrl-C: a signal whose handler raises
    /// (`KeyboardInterrupt`) stops the run at a step boundary, with the outputs flushed up to there, and
    /// the exception is raised; the simulation is consistent there and can go on (as `step`). An
    /// exception raised by a callback stops the run and propagates. A run to `until` longer than the engine's step limit (10⁹ steps) is refused unless
    /// `max_steps` raises it.
    #[pyo3(signature = (until = None, every = None, callback = None, *, progress = None, out = None,
                        vtk_interval = None, contacts_interval = None, checkpoint_interval = None,
                        max_steps = None))]
    #[allow(clippy::too_many_arguments)] // Python keywords, each optional
    fn run<'py>(
        slf: &Bound<'py, Self>,
        until: Option<Real>,
        every: Option<Real>,
        callback: Option<Bound<'py, PyAny>>,
        progress: Option<Bound<'py, PyAny>>,
        out: Option<PathBuf>,
        vtk_interval: Option<Real>,
        contacts_interval: Option<Real>,
        checkpoint_interval: Option<Real>,
        max_steps: Option<u64>,
    ) -> PyResult<()> {
        let (last, callback_every) = {
            let mut this = slf.borrow_mut();
            let dt = this.sim.params.dt;
            let last = match until {
                Some(t) => step_at(&mut this.sim, t, max_steps)?,
                None => this.sim.steps,
            };
            let every = every.map(|t| interval_steps(t, dt)).transpose()?;
            (last, every.unwrap_or(u64::MAX))
        };
        if out.is_none()
            && (vtk_interval, contacts_interval, checkpoint_interval) != (None, None, None)
        {
            return Err(PyValueError::new_err(
                "vtk_interval, contacts_interval and checkpoint_interval need an output directory: give out=",
            ));
        }
        let plan = run_loop::plan(vtk_interval, contacts_interval, checkpoint_interval);
        let request = RunRequest {
            last,
            callback_every,
            callback,
            progress,
            out: out.map(|dir| (dir, plan)),
        };
        run_loop::run(slf, request)
    }

    /// The active contacts after the last step, as a dict of new arrays (copies), one row per contact in
    /// the engine's contact order: `wall` (bool; True for a body–wall contact), `a` and `b` (int64: the
    /// indices of the two bodies, a < b; for a wall contact `a` is the wall's index in `walls()` and `b`
    /// the body's), `point` (the contact point c_M, m), `normal` (unit, from a towards b), `depth` (the
    /// overlap, m) and `force` (the contact force on b, N; a receives its opposite), world frame — the
    /// rows `contacts.csv` writes.
    fn contacts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        world_arrays::contacts(py, &self.sim.world)
    }

    /// The walls, as a dict: `names` (a list), and new arrays (copies) `point` (a point of each plane now,
    /// m), `normal` (the unit normal towards the free side), `velocity` (the prescribed velocity, m/s) and
    /// `force` (the total contact force on the wall from the last evaluation, N; zeros before the first
    /// step), world frame.
    fn walls<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        world_arrays::walls(py, &self.sim.world)
    }

    /// Sets the prescribed velocity (m/s, world frame) of the wall `name` from the next step on: the wall
    /// moves with it at constant velocity, and the energy ledger books the work its contact forces do.
    fn set_wall_velocity(&mut self, name: &str, velocity: Bound<'_, PyAny>) -> PyResult<()> {
        let velocity = crate::arrays::fixed::<3>(&velocity, "velocity")?;
        world_arrays::set_wall_velocity(&mut self.sim.world, name, velocity)
    }

    /// Simulated time (s).
    #[getter]
    fn time(&self) -> Real {
        self.sim.world.time()
    }

    /// Number of steps done since the start of the scene.
    #[getter]
    fn step_index(&self) -> u64 {
        self.sim.world.step_index()
    }

    /// Time step (s).
    #[getter]
    fn dt(&self) -> Real {
        self.sim.params.dt
    }

    /// Number of bodies.
    #[getter]
    fn num_bodies(&self) -> usize {
        self.sim.world.bodies().len()
    }

    /// End time of the scene (s); `step` may go past it.
    #[getter]
    fn end_time(&self) -> Real {
        self.sim.end_time
    }

    /// The step index at the scene's end time (the steps `polydem run` does).
    #[getter]
    fn end_step(&self) -> u64 {
        self.sim.steps
    }

    /// Body names in body order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.sim.world.names().to_vec()
    }

    /// Centre-of-mass positions (m), a new (N, 3) array (a copy of the engine's state).
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let bodies = &self.sim.world.bodies();
        self.rows(py, 3, |i| bodies[i].position.coords.as_slice().to_vec())
    }

    /// Velocities of the centres of mass (m/s), a new (N, 3) array (a copy).
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let bodies = &self.sim.world.bodies();
        self.rows(py, 3, |i| bodies[i].velocity.as_slice().to_vec())
    }

    /// Orientations of the bodies' input frames (as the scene gave them, as `bodies.csv` writes them), unit
    /// quaternions (w, x, y, z), a new (N, 4) array (a copy).
    fn orientations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let sim = &self.sim;
        self.rows(py, 4, |i| {
            let q = sim.input_orientation(i);
            vec![q.w, q.i, q.j, q.k]
        })
    }

    /// Angular velocities in the world frame (rad/s), a new (N, 3) array (a copy).
    fn angular_velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let bodies = &self.sim.world.bodies();
        self.rows(py, 3, |i| bodies[i].angular_velocity().as_slice().to_vec())
    }

    /// Contact forces on the bodies (N, world frame; gravity not included) from the last evaluation, a
    /// new (N, 3) array (a copy). Raises `RuntimeError` before the first step, when none was evaluated.
    fn forces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let loads = self.current_loads()?;
        self.rows(py, 3, |i| loads.forces()[i].as_slice().to_vec())
    }

    /// Contact torques about the centres of mass (N·m, world frame) from the last evaluation, a new
    /// (N, 3) array (a copy). Raises `RuntimeError` before the first step.
    fn torques<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let loads = self.current_loads()?;
        self.rows(py, 3, |i| loads.torques()[i].as_slice().to_vec())
    }

    /// The energy ledger now (J), as a dict: kinetic (translational, rotational), elastic and
    /// gravitational potential, the dissipated and external terms, `mechanical` (T + U) and `balance`
    /// (zero for exact dynamics), and `time` (s).
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = self.sim.world.energy();
        let d = PyDict::new(py);
        let terms = [
            ("time", e.time),
            ("translational_kinetic", e.translational_kinetic),
            ("rotational_kinetic", e.rotational_kinetic),
            ("elastic_potential", e.elastic_potential),
            ("gravitational_potential", e.gravitational_potential),
            ("dissipated_damping", e.dissipated_damping),
            ("dissipated_friction", e.dissipated_friction),
            ("dissipated_viscous", e.dissipated_viscous),
            ("external_work", e.external_work),
            ("tangential_stiffness_work", e.tangential_stiffness_work),
            ("mechanical", e.mechanical()),
            ("balance", e.balance),
        ];
        for (name, value) in terms {
            d.set_item(name, value)?;
        }
        Ok(d)
    }

    /// Writes a checkpoint of the whole state to `path` (the format of `polydem run`'s checkpoints); a run
    /// loaded from it continues bit for bit. Returns the number of bytes written.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<u64> {
        let sim = &self.sim;
        py.detach(|| checkpoint::save(&path, sim))
            .map_err(|e| checkpoint_error(&e))
    }

    /// A simulation restored from the checkpoint at `path` (written by `save` or by `polydem run`).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let payload = py
            .detach(|| checkpoint::load(&path))
            .map_err(|e| checkpoint_error(&e))?;
        Ok(Self {
            sim: payload.simulation,
        })
    }

    /// The checkpoint bytes of the state (what `save` writes).
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = checkpoint::encode(&self.sim).map_err(|e| checkpoint_error(&e))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// A simulation restored from checkpoint bytes (what `to_bytes` returns).
    #[classmethod]
    fn from_bytes(_cls: &Bound<'_, PyType>, data: &[u8]) -> PyResult<Self> {
        let payload = checkpoint::decode(data).map_err(|e| checkpoint_error(&e))?;
        Ok(Self {
            sim: payload.simulation,
        })
    }

    /// Pickling goes through the checkpoint bytes, so an unpickled simulation continues bit for bit.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let from_bytes = slf.get_type().getattr("from_bytes")?;
        let bytes = slf.borrow().to_bytes(slf.py())?;
        Ok((from_bytes, (bytes,)))
    }
}
