//! The package's exceptions and the conversion of every engine error into one of them, carrying the
//! engine's message.

use polydem::io::checkpoint::CheckpointError;
use polydem::scene::{RunError, SceneError};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    polydem,
    PyPolydemSceneError,
    PyValueError,
    "A scene that cannot be read or built. The message is the engine's (file:line: field: problem); the \
     attributes `path`, `line` and `field` hold its parts (None where the error has no such part)."
);
pyo3::create_exception!(
    polydem,
    PyCheckpointError,
    PyValueError,
    "A checkpoint file that cannot be read (not a checkpoint, another version, truncated, corrupt)."
);
pyo3::create_exception!(
    polydem,
    PyStepError,
    PyRuntimeError,
    "A step that failed (a non-finite state, an invalid time step); the message names the body and step."
);

/// The scene error as `polydem.SceneError` with its parts as attributes.
pub fn scene_error(py: Python<'_>, e: &SceneError) -> PyErr {
    let err = PyPolydemSceneError::new_err(e.to_string());
    let (path, line, field) = match e {
        SceneError::Io { path, .. } => (path, None, None),
        SceneError::Parse { path, line, .. } => (path, Some(*line), None),
        SceneError::Invalid {
            path, line, field, ..
        } => (path, Some(*line), Some(field.clone())),
    };
    let value = err.value(py);
    let set = || -> PyResult<()> {
        value.setattr("path", path.display().to_string())?;
        value.setattr("line", line)?;
        value.setattr("field", field)
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// A checkpoint error: `OSError` for the file system, `polydem.CheckpointError` for the content.
pub fn checkpoint_error(e: &CheckpointError) -> PyErr {
    match e {
        CheckpointError::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyCheckpointError::new_err(e.to_string()),
    }
}

/// A run error: `polydem.StepError` for the engine, `OSError` for an output.
pub fn run_error(e: &RunError) -> PyErr {
    match e {
        RunError::Step(_) => PyStepError::new_err(e.to_string()),
        RunError::Output(_) => PyOSError::new_err(e.to_string()),
    }
}
