//! A scene built in Python: a dict shaped like the scene file (`[simulation]` a dict, `[[body]]` a list of
//! dicts, …) written out as TOML text, which the engine's scene builder then reads exactly as it reads a
//! file. The validation and the error messages are therefore those of the TOML path, with line numbers
//! in the text [`scene_to_toml`] returns.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

fn type_error(at: &str, message: impl std::fmt::Display) -> PyErr {
    PyTypeError::new_err(format!("{at}: {message}"))
}

/// One Python value as a TOML value; `at` names it in errors (`body[3].position`).
fn value(obj: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    if obj.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        let v: i64 = obj
            .extract()
            .map_err(|_| type_error(at, format!("integer {obj} does not fit in 64 bits")))?;
        return Ok(toml::Value::Integer(v));
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(obj.extract()?));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return table(d, at).map(toml::Value::Table);
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let items = obj
            .try_iter()?
            .enumerate()
            .map(|(i, item)| value(&item?, &format!("{at}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    let py = obj.py();
    let numpy = py.import("numpy")?;
    if obj.is_instance(&numpy.getattr("ndarray")?)?
        || obj.is_instance(&numpy.getattr("generic")?)?
    {
        // An array becomes nested lists, a numpy scalar the Python number it holds.
        let plain = obj.call_method0(if obj.is_instance(&numpy.getattr("ndarray")?)? {
            "tolist"
        } else {
            "item"
        })?;
        return value(&plain, at);
    }
    if obj.hasattr("__fspath__")? {
        let os = py.import("os")?;
        return value(&os.call_method1("fspath", (obj,))?, at);
    }
    Err(type_error(
        at,
        format!(
            "a {} is not a scene value (use numbers, strings, booleans, lists, numpy arrays, dicts)",
            obj.get_type().name()?
        ),
    ))
}

/// A dict with string keys as a TOML table.
fn table(d: &Bound<'_, PyDict>, at: &str) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let key: String = k
            .extract()
            .map_err(|_| type_error(at, format!("key {k} is not a string")))?;
        let here = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        if v.is_none() {
            continue; // an absent optional field
        }
        t.insert(key, value(&v, &here)?);
    }
    Ok(t)
}

/// The TOML text of a scene given as a dict shaped like the scene file; keys whose value is `None` are
/// left out (an optional field not given). Raises `TypeError` naming the key of a value TOML cannot
/// hold.
#[pyfunction]
pub fn scene_to_toml(scene: &Bound<'_, PyDict>) -> PyResult<String> {
    let t = table(scene, "")?;
    toml::to_string(&t).map_err(|e| type_error("scene", e))
}
