//! `polydem.rockfill`: the paper's experiment (generation, packing, penetration) run by the same function
//! as `polydem rockfill`, with the GIL released, its monitors returned as numpy arrays.

use std::path::{Path, PathBuf};

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use polydem::math::{Real, Vector};
use polydem_rockfill::config::ExperimentConfig;
use polydem_rockfill::experiment::ExperimentResult;
use polydem_rockfill::penetration::{MonitorRow, Outcome, PenetrationReport};
use polydem_rockfill::study::run_one_with_stop;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::interrupt;

/// The experiment file: "quick", "paper" (full scale) or a path to a file of that format.
fn config_of(config: &Bound<'_, PyAny>) -> PyResult<ExperimentConfig> {
    if let Ok(name) = config.extract::<String>() {
        match name.as_str() {
            "quick" => return Ok(ExperimentConfig::quick()),
            "paper" => return Ok(ExperimentConfig::paper()),
            _ => {}
        }
    }
    let path: PathBuf = config.extract().map_err(|_| {
        PyValueError::new_err(
            "config: expected \"quick\", \"paper\" or the path of an experiment file",
        )
    })?;
    ExperimentConfig::load(&path).map_err(|e| PyValueError::new_err(e.to_string()))
}

fn vectors<'py>(
    py: Python<'py>,
    rows: &[MonitorRow],
    of: impl Fn(&MonitorRow) -> Vector,
) -> PyResult<Bound<'py, PyArray2<Real>>> {
    let flat: Vec<Real> = rows
        .iter()
        .flat_map(|r| {
            let v = of(r);
            [v.x, v.y, v.z]
        })
        .collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), 3])
}

fn scalars<'py>(
    py: Python<'py>,
    rows: &[MonitorRow],
    of: impl Fn(&MonitorRow) -> Real,
) -> Bound<'py, PyArray1<Real>> {
    PyArray1::from_vec(py, rows.iter().map(of).collect())
}

/// The monitor series as arrays, one row per step (the columns of `monitors.csv`).
fn monitors<'py>(py: Python<'py>, rows: &[MonitorRow]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("time", scalars(py, rows, |r| r.time))?;
    d.set_item("position", vectors(py, rows, |r| r.position.coords)?)?;
    d.set_item("tip", vectors(py, rows, |r| r.tip.coords)?)?;
    d.set_item("velocity", vectors(py, rows, |r| r.velocity)?)?;
    d.set_item("speed", scalars(py, rows, |r| r.velocity.norm()))?;
    d.set_item("force", vectors(py, rows, |r| r.force)?)?;
    d.set_item("axial_force", scalars(py, rows, |r| r.axial_force))?;
    d.set_item(
        "velocity_deflection",
        scalars(py, rows, |r| r.velocity_deflection),
    )?;
    d.set_item("axis_deflection", scalars(py, rows, |r| r.axis_deflection))?;
    let contacts: Vec<i64> = rows.iter().map(|r| r.contacts as i64).collect();
    d.set_item("contacts", PyArray1::from_vec(py, contacts))?;
    Ok(d)
}

/// The run's figures (the penetration summary of `polydem rockfill`) with its monitors.
fn report<'py>(py: Python<'py>, p: &PenetrationReport) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let outcome = match p.outcome {
        Outcome::Exited => "exited",
        Outcome::Stopped => "stopped",
        Outcome::TimeLimit => "time_limit",
        Outcome::StepLimit => "step_limit",
    };
    d.set_item("outcome", outcome)?;
    d.set_item("residual_speed", p.residual_speed)?;
    d.set_item("residual_axial_velocity", p.residual_axial_velocity)?;
    d.set_item("exit_time", p.exit_time)?;
    d.set_item("dt", p.dt)?;
    d.set_item("steps", p.steps)?;
    d.set_item("rocks", p.rocks)?;
    d.set_item("projectile_mass", p.projectile_mass)?;
    d.set_item("final_velocity_deflection", p.final_velocity_deflection)?;
    d.set_item("final_axis_deflection", p.final_axis_deflection)?;
    d.set_item("max_axial_force", p.max_axial_force)?;
    d.set_item("disturbed_rocks", p.disturbed_rocks)?;
    d.set_item("disturbed_width", p.disturbed_width)?;
    d.set_item("disturbed_width_sizes", p.disturbed_width_sizes)?;
    d.set_item("ledger_balance_relative", p.ledger_balance_relative)?;
    d.set_item("wall_time", p.wall_time.as_secs_f64())?;
    d.set_item("monitors", monitors(py, &p.rows)?)?;
    Ok(d)
}

/// Runs the rockfill experiment of the paper (`polydem rockfill`): `config` is "quick" (the quick
/// variant), "paper" (full scale) or the path of an experiment file; `size_mm` and `seed` override its
/// sample; `bed` starts the penetration from a bed saved by an earlier run (its directory), else one is
/// generated and packed and saved into `out`, where the run writes the command's outputs. Returns a dict
/// of the penetration's figures (`outcome`, `residual_speed` in m/s, `dt`, `steps`, `rocks`, deflections
/// in degrees, …) with `monitors`, a dict of arrays with one row per step (`time`, `position`, `tip`,
/// `velocity`, `speed`, `force`, `axial_force`, `velocity_deflection`, `axis_deflection`, `contacts`).
/// `progress(stage, text)` receives the experiment's progress messages. `max_rocks` and `max_steps` raise
/// the experiment's limits (rocks generated; steps of the packing and of the penetration), beyond which
/// a run is refused before it starts, with what it would need. The run holds no GIL. Ctrl-C (a signal
/// whose handler raises, `KeyboardInterrupt`) is seen within about 0.1 s during the packing and the
/// penetration (the generation of the rocks before them runs to its end first), and an exception raised
/// by `progress` as soon as it is raised: either stops the run between two steps and is raised, and the
/// outputs of a finished run (monitors, summary, picture; the bed of a finished packing) are not written.
#[pyfunction]
#[pyo3(signature = (out, config = None, *, size_mm = None, seed = None, bed = None, progress = None,
                    max_rocks = None, max_steps = None))]
#[allow(clippy::too_many_arguments)] // Python keywords, each optional
pub fn rockfill<'py>(
    py: Python<'py>,
    out: PathBuf,
    config: Option<Bound<'py, PyAny>>,
    size_mm: Option<Real>,
    seed: Option<u64>,
    bed: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
    max_rocks: Option<usize>,
    max_steps: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut config = match &config {
        Some(c) => config_of(c)?,
        None => ExperimentConfig::quick(),
    };
    if let Some(mm) = size_mm {
        if !(mm.is_finite() && mm > 0.0) {
            return Err(PyValueError::new_err(format!(
                "size_mm: must be a positive size in mm, got {mm}"
            )));
        }
        config.rock.mean_size = mm * 1e-3;
    }
    if let Some(seed) = seed {
        config.rock.seed = seed;
    }
    if let Some(max) = max_rocks {
        config.limits.max_rocks = max;
    }
    if let Some(max) = max_steps {
        config.limits.max_steps = max;
    }
    let title = format!(
        "{} mm rocks, seed {}",
        config.rock.mean_size * 1e3,
        config.rock.seed
    );
    let result = run_stoppable(py, &config, &out, bed.as_deref(), &title, progress)?;
    report(py, &result.penetration)
}

/// The run of `polydem rockfill` with the GIL released, stopped between two steps by an exception: a
/// signal handler's (Ctrl-C) or the progress callback's, which is then raised.
fn run_stoppable(
    py: Python<'_>,
    config: &ExperimentConfig,
    out: &Path,
    bed: Option<&Path>,
    title: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<ExperimentResult> {
    let (stop, signals) = interrupt::stop_check(py);
    let result = py.detach(|| {
        let mut report_progress = |stage: &str, text: String| {
            let Some(callback) = &progress else { return };
            if interrupt::raised_already(&signals) {
                return;
            }
            if let Err(e) = Python::attach(|py| callback.call1(py, (stage, text)).map(|_| ())) {
                interrupt::record(&signals, e);
            }
        };
        run_one_with_stop(config, out, bed, title, Some(stop), &mut report_progress)
    });
    if let Some(e) = interrupt::raised(&signals) {
        return Err(e);
    }
    result.map_err(|e| PyRuntimeError::new_err(e.to_string()))
}
