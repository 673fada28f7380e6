//! `polydem.contact_batch`: many contact queries at once, answered as numpy arrays, computed in parallel
//! (rayon) with the GIL released. Each pair is the query of `polydem.contact`, so a batch equals the
//! single answers bit for bit.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use polydem::contact::{ContactGeometry, ContactKind, EpaScratch};
use polydem::math::{Pose, Real, Vector};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::arrays;
use crate::contact::{exact_query, kind_name, solver_name};
use crate::shapes::PyShape;

/// The shapes of one side: a single shape for every pair, or a sequence of `n` shapes. The Python objects
/// are kept (not their engine shapes copied): the queries borrow them while the GIL is released.
fn side_shapes<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Vec<Bound<'py, PyShape>>> {
    if let Ok(shape) = obj.cast::<PyShape>() {
        return Ok(vec![shape.clone()]);
    }
    obj.try_iter()
        .map_err(|_| {
            PyValueError::new_err(format!("{what}: expected a Shape or a sequence of Shapes"))
        })?
        .enumerate()
        .map(|(i, item)| {
            let item = item?;
            let shape = item.cast::<PyShape>().map_err(|_| {
                PyValueError::new_err(format!(
                    "{what}[{i}]: expected a Shape, got {}",
                    item.get_type()
                ))
            })?;
            Ok(shape.clone())
        })
        .collect()
}

/// The poses of one side: `None` (the identity for every pair) or `(positions (n, 3), quaternions (n, 4))`.
fn side_poses(obj: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Option<Vec<Pose>>> {
    let Some(obj) = obj else { return Ok(None) };
    let (positions, quaternions): (Bound<'_, PyAny>, Bound<'_, PyAny>) =
        obj.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "{what}: expected a pair (positions (n, 3), quaternions (n, 4) as w, x, y, z)"
            ))
        })?;
    let positions = arrays::rows::<3>(&positions, &format!("{what} positions"), "pose")?;
    let quaternions = arrays::rows::<4>(&quaternions, &format!("{what} quaternions"), "pose")?;
    if positions.len() != quaternions.len() {
        return Err(PyValueError::new_err(format!(
            "{what}: {} positions but {} quaternions",
            positions.len(),
            quaternions.len()
        )));
    }
    let poses = positions
        .iter()
        .zip(&quaternions)
        .enumerate()
        .map(|(i, (p, q))| {
            let rotation = arrays::unit_quaternion(*q, &format!("{what} quaternions[{i}]"))?;
            Ok(Pose::from_parts(
                Vector::new(p[0], p[1], p[2]).into(),
                rotation,
            ))
        });
    poses.collect::<PyResult<Vec<_>>>().map(Some)
}

/// Entry `i` of a side given per pair, or its single entry used for every pair.
fn pick<T>(items: &[T], i: usize) -> &T {
    &items[if items.len() == 1 { 0 } else { i }]
}

/// The number of pairs: the length every side given per pair agrees on (1 if none is).
fn pair_count(lengths: &[(usize, &str, bool)]) -> PyResult<usize> {
    let per_pair: Vec<_> = lengths
        .iter()
        .filter(|(_, _, per_pair)| *per_pair)
        .collect();
    let n = per_pair.first().map_or(1, |(len, _, _)| *len);
    match per_pair.iter().find(|(len, _, _)| *len != n) {
        Some((len, name, _)) => Err(PyValueError::new_err(format!(
            "{name} has {len} entries but {} has {n}: every per-pair input needs the same length",
            per_pair[0].1
        ))),
        None => Ok(n),
    }
}

/// The contacts of `n` pairs (a[i] at pose_a[i], b[i] at pose_b[i]), as a dict of arrays: `status` and
/// `solver` (strings, shape (n,)), `depth` and `distance` (n,), `normal`, `point_a`, `point_b`, `point`
/// (n, 3), with the conventions of `polydem.contact`. `a` and `b` are a Shape (used for every pair) or a
/// sequence of n Shapes; `pose_a` and `pose_b` are `None` (identity) or `(positions (n, 3), quaternions
/// (n, 4))`. Computed in parallel with the GIL released.
#[pyfunction]
#[pyo3(signature = (a, b, pose_a = None, pose_b = None))]
pub fn contact_batch<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    pose_a: Option<&Bound<'py, PyAny>>,
    pose_b: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (objects_a, objects_b) = (side_shapes(a, "a")?, side_shapes(b, "b")?);
    let shapes_a: Vec<&PyShape> = objects_a.iter().map(Bound::get).collect();
    let shapes_b: Vec<&PyShape> = objects_b.iter().map(Bound::get).collect();
    let (poses_a, poses_b) = (side_poses(pose_a, "pose_a")?, side_poses(pose_b, "pose_b")?);
    let n = pair_count(&[
        (shapes_a.len(), "a", a.cast::<PyShape>().is_err()),
        (shapes_b.len(), "b", b.cast::<PyShape>().is_err()),
        (
            poses_a.as_ref().map_or(0, Vec::len),
            "pose_a",
            poses_a.is_some(),
        ),
        (
            poses_b.as_ref().map_or(0, Vec::len),
            "pose_b",
            poses_b.is_some(),
        ),
    ])?;
    let engine_pose = |poses: &Option<Vec<Pose>>, frame: &Pose, i: usize| {
        poses.as_ref().map_or(Pose::identity(), |p| p[i]) * frame
    };
    let answers = py.detach(|| {
        (0..n)
            .into_par_iter()
            .map_init(EpaScratch::default, |scratch, i| {
                let (s1, s2) = (pick(&shapes_a, i), pick(&shapes_b, i));
                let p1 = engine_pose(&poses_a, &s1.frame, i);
                let p2 = engine_pose(&poses_b, &s2.frame, i);
                exact_query(&p1, &s1.shape, &p2, &s2.shape, scratch)
                    .map_err(|e| format!("pair {i}: {e}"))
            })
            .collect::<Result<Vec<ContactGeometry>, String>>()
    });
    let answers = answers.map_err(PyValueError::new_err)?;
    batch_dict(py, &answers)
}

/// Strings of a few kinds as a numpy array: the names indexed by each answer's code (one vectorised
/// gather instead of one Python string per answer).
fn names_array<'py>(
    py: Python<'py>,
    names: &[&str],
    codes: Vec<i64>,
) -> PyResult<Bound<'py, PyAny>> {
    let numpy = py.import("numpy")?;
    numpy
        .call_method1("array", (names.to_vec(),))?
        .call_method1("take", (PyArray1::from_vec(py, codes),))
}

fn batch_dict<'py>(py: Python<'py>, answers: &[ContactGeometry]) -> PyResult<Bound<'py, PyDict>> {
    let kinds = [
        ContactKind::Overlap,
        ContactKind::Touching,
        ContactKind::Separated,
    ];
    let kind_code =
        |g: &ContactGeometry| kinds.iter().position(|k| *k == g.kind).unwrap_or(0) as i64;
    let mut solvers: Vec<&'static str> = Vec::new();
    let solver_codes: Vec<i64> = answers
        .iter()
        .map(|g| {
            let name = solver_name(g.status);
            let code = solvers.iter().position(|s| *s == name).unwrap_or_else(|| {
                solvers.push(name);
                solvers.len() - 1
            });
            code as i64
        })
        .collect();
    let scalars =
        |f: fn(&ContactGeometry) -> Real| PyArray1::from_vec(py, answers.iter().map(f).collect());
    let vectors = |f: fn(&ContactGeometry) -> [Real; 3]| -> PyResult<Bound<'py, PyArray2<Real>>> {
        let flat: Vec<Real> = answers.iter().flat_map(f).collect();
        PyArray1::from_vec(py, flat).reshape([answers.len(), 3])
    };
    let d = PyDict::new(py);
    let kind_names: Vec<&str> = kinds.iter().map(|k| kind_name(*k)).collect();
    d.set_item(
        "status",
        names_array(py, &kind_names, answers.iter().map(kind_code).collect())?,
    )?;
    d.set_item("solver", names_array(py, &solvers, solver_codes)?)?;
    d.set_item("depth", scalars(|g| g.depth))?;
    d.set_item("distance", scalars(|g| g.distance))?;
    d.set_item("normal", vectors(|g| g.normal.into())?)?;
    d.set_item("point_a", vectors(|g| g.point_a.coords.into())?)?;
    d.set_item("point_b", vectors(|g| g.point_b.coords.into())?)?;
    d.set_item("point", vectors(|g| g.point.coords.into())?)?;
    Ok(d)
}
