//! `polydem.contact_batch`: many contact queries at once, answered as numpy arrays, computed in parallel
//! (rayon) with the GIL released. Each pair is the query of `polydem.contact` at the same engine poses, so
//! a batch equals the single answers bit for bit.
//!
//! What a batch adds to the queries themselves is kept small (about 5 % of a query between random hulls,
//! `python/examples/contact_batch_speed.py`): the shapes are read from a list or tuple without Python's
//! iterator protocol, the engine poses are formed once per shape (or once per pair when poses are
//! given), the answers are written in place (an indexed collect, no allocation per pair) and turned into
//! the result columns in one pass, and the two string columns are filled in Rust and viewed as numpy
//! strings (no Python string per answer).

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use polydem::contact::{ContactError, ContactGeometry, ContactKind, EpaScratch, SolverStatus};
use polydem::math::{Pose, Real, Vector};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use rayon::prelude::*;

use crate::arrays;
use crate::contact::{engine_pose, exact_query, kind_name, solver_name};
use crate::shapes::PyShape;

/// Pairs per rayon task at least: a query costs about a microsecond, so smaller tasks would spend a
/// noticeable share on scheduling and on warming a fresh EPA scratch.
const MIN_PAIRS_PER_TASK: usize = 16;

/// The shapes of one side: a single shape for every pair, or a sequence of `n` shapes. The Python objects
/// are kept (not their engine shapes copied): the queries borrow them while the GIL is released.
fn side_shapes<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Vec<Bound<'py, PyShape>>> {
    if let Ok(shape) = obj.cast::<PyShape>() {
        return Ok(vec![shape.clone()]);
    }
    if let Ok(list) = obj.cast::<PyList>() {
        return shape_items(list.iter().map(Ok), what);
    }
    if let Ok(tuple) = obj.cast::<PyTuple>() {
        return shape_items(tuple.iter().map(Ok), what);
    }
    let items = obj.try_iter().map_err(|_| {
        PyValueError::new_err(format!("{what}: expected a Shape or a sequence of Shapes"))
    })?;
    shape_items(items, what)
}

/// The items of a side's sequence as Shapes, or the error naming the first that is not one.
fn shape_items<'py>(
    items: impl Iterator<Item = PyResult<Bound<'py, PyAny>>>,
    what: &str,
) -> PyResult<Vec<Bound<'py, PyShape>>> {
    items
        .enumerate()
        .map(|(i, item)| {
            item?.cast_into::<PyShape>().map_err(|e| {
                PyValueError::new_err(format!(
                    "{what}[{i}]: expected a Shape, got {}",
                    e.into_inner().get_type()
                ))
            })
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

/// The engine poses of one side, as `polydem.contact` forms them ([`engine_pose`]): one per pair when
/// poses are given, else one per shape.
fn engine_poses(user: Option<Vec<Pose>>, shapes: &[&PyShape]) -> Vec<Pose> {
    match user {
        Some(poses) => (0..poses.len())
            .map(|i| engine_pose(Some(&poses[i]), &pick(shapes, i).frame))
            .collect(),
        None => shapes.iter().map(|s| engine_pose(None, &s.frame)).collect(),
    }
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
/// `solver` (numpy strings, shape (n,)), `depth` and `distance` (n,), `normal`, `point_a`, `point_b`,
/// `point` (n, 3), with the conventions of `polydem.contact`. `a` and `b` are a Shape (used for every
/// pair) or a sequence of n Shapes; `pose_a` and `pose_b` are `None` (identity) or `(positions (n, 3),
/// quaternions (n, 4))`. Computed in parallel with the GIL released.
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
    let (user_a, user_b) = (side_poses(pose_a, "pose_a")?, side_poses(pose_b, "pose_b")?);
    let length = |poses: &Option<Vec<Pose>>| poses.as_ref().map_or(0, Vec::len);
    let n = pair_count(&[
        (shapes_a.len(), "a", a.cast::<PyShape>().is_err()),
        (shapes_b.len(), "b", b.cast::<PyShape>().is_err()),
        (length(&user_a), "pose_a", user_a.is_some()),
        (length(&user_b), "pose_b", user_b.is_some()),
    ])?;
    let (poses_a, poses_b) = (
        engine_poses(user_a, &shapes_a),
        engine_poses(user_b, &shapes_b),
    );
    let mut answers = Vec::new();
    py.detach(|| {
        (0..n)
            .into_par_iter()
            .with_min_len(MIN_PAIRS_PER_TASK)
            .map_init(EpaScratch::default, |scratch, i| {
                let (s1, s2) = (pick(&shapes_a, i), pick(&shapes_b, i));
                let (p1, p2) = (pick(&poses_a, i), pick(&poses_b, i));
                exact_query(p1, &s1.shape, p2, &s2.shape, scratch)
            })
            .collect_into_vec(&mut answers)
    });
    let columns = Columns::of(&answers)?;
    columns.into_dict(py)
}

/// The answers of a batch as the columns of its result: kinds as codes into [`KINDS`], solvers as codes
/// into the statuses met.
struct Columns {
    kinds: Vec<u8>,
    solvers: Vec<u8>,
    /// The solver statuses the codes index, in the order first met.
    solver_statuses: Vec<SolverStatus>,
    depth: Vec<Real>,
    distance: Vec<Real>,
    normal: Vec<Real>,
    point_a: Vec<Real>,
    point_b: Vec<Real>,
    point: Vec<Real>,
}

const KINDS: [ContactKind; 3] = [
    ContactKind::Overlap,
    ContactKind::Touching,
    ContactKind::Separated,
];

impl Columns {
    /// The columns of `answers`, or the error of the first pair that has no answer.
    fn of(answers: &[Result<ContactGeometry, ContactError>]) -> PyResult<Self> {
        let n = answers.len();
        let mut c = Columns {
            kinds: Vec::with_capacity(n),
            solvers: Vec::with_capacity(n),
            solver_statuses: Vec::new(),
            depth: Vec::with_capacity(n),
            distance: Vec::with_capacity(n),
            normal: Vec::with_capacity(3 * n),
            point_a: Vec::with_capacity(3 * n),
            point_b: Vec::with_capacity(3 * n),
            point: Vec::with_capacity(3 * n),
        };
        for (i, answer) in answers.iter().enumerate() {
            let g = answer
                .as_ref()
                .map_err(|e| PyValueError::new_err(format!("pair {i}: {e}")))?;
            c.push(g);
        }
        Ok(c)
    }

    fn push(&mut self, g: &ContactGeometry) {
        // The index of the kind in [`KINDS`].
        let kind = match g.kind {
            ContactKind::Overlap => 0,
            ContactKind::Touching => 1,
            ContactKind::Separated => 2,
        };
        let solver = match self.solver_statuses.iter().position(|s| *s == g.status) {
            Some(code) => code,
            None => {
                self.solver_statuses.push(g.status);
                self.solver_statuses.len() - 1
            }
        };
        self.kinds.push(kind as u8);
        self.solvers.push(solver as u8);
        self.depth.push(g.depth);
        self.distance.push(g.distance);
        self.normal.extend_from_slice(g.normal.as_slice());
        self.point_a.extend_from_slice(g.point_a.coords.as_slice());
        self.point_b.extend_from_slice(g.point_b.coords.as_slice());
        self.point.extend_from_slice(g.point.coords.as_slice());
    }

    fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let n = self.kinds.len();
        let vectors = |flat: Vec<Real>| -> PyResult<Bound<'_, PyArray2<Real>>> {
            PyArray1::from_vec(py, flat).reshape([n, 3])
        };
        let kind_names = KINDS.map(kind_name);
        let solver_names: Vec<&str> = self
            .solver_statuses
            .iter()
            .map(|s| solver_name(*s))
            .collect();
        let d = PyDict::new(py);
        d.set_item("status", names_array(py, &kind_names, &self.kinds)?)?;
        d.set_item("solver", names_array(py, &solver_names, &self.solvers)?)?;
        d.set_item("depth", PyArray1::from_vec(py, self.depth))?;
        d.set_item("distance", PyArray1::from_vec(py, self.distance))?;
        d.set_item("normal", vectors(self.normal)?)?;
        d.set_item("point_a", vectors(self.point_a)?)?;
        d.set_item("point_b", vectors(self.point_b)?)?;
        d.set_item("point", vectors(self.point)?)?;
        Ok(d)
    }
}

/// `names[codes[i]]` for every i as a numpy string array of dtype `<U{w}`, w the longest of `names`
/// (the dtype `numpy.array(names)` has): the UCS-4 code points are written here into one `uint32` array
/// and viewed as strings.
fn names_array<'py>(py: Python<'py>, names: &[&str], codes: &[u8]) -> PyResult<Bound<'py, PyAny>> {
    let width = names
        .iter()
        .map(|s| s.chars().count())
        .max()
        .unwrap_or(0)
        .max(1);
    let padded: Vec<Vec<u32>> = names
        .iter()
        .map(|s| {
            let mut points: Vec<u32> = s.chars().map(u32::from).collect();
            points.resize(width, 0);
            points
        })
        .collect();
    let mut flat = Vec::with_capacity(codes.len() * width);
    for &code in codes {
        flat.extend_from_slice(&padded[code as usize]);
    }
    PyArray1::from_vec(py, flat).call_method1("view", (format!("<U{width}"),))
}
