//! `polydem.contact`: one contact query between two shapes at two poses, through the engine's dispatch
//! (the function a simulation step calls for the pair), answered as a small result object. The answer is
//! the exact Minkowski geometry, as `polydem contact` gives it: the default tolerances without the pair
//! smoothing a simulation hands to its contact law.

use numpy::PyArray1;
use polydem::contact::{
    query_with, ContactError, ContactGeometry, ContactKind, ContactTolerances, EpaScratch,
    PairCache, PairSmoothing, QueryCounters, SolverStatus,
};
use polydem::math::{Pose, Real};
use polydem::shape::Shape;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays;
use crate::shapes::PyShape;

/// The Minkowski contact features of a pair (a, b), in the world frame, SI units: `normal` is a unit
/// vector from a towards b; `depth` ≥ 0 is the overlap (zero unless `status == "overlap"`); `distance` ≥ 0
/// the gap (zero unless `status == "separated"`); `point_a` lies on a's surface, `point_b` on b's, and
/// `point` is their midpoint, where a contact force acts.
#[pyclass(frozen, name = "ContactResult", module = "polydem")]
pub struct PyContactResult {
    geometry: ContactGeometry,
}

pub fn kind_name(kind: ContactKind) -> &'static str {
    match kind {
        ContactKind::Overlap => "overlap",
        ContactKind::Touching => "touching",
        ContactKind::Separated => "separated",
    }
}

pub fn solver_name(status: SolverStatus) -> &'static str {
    match status {
        SolverStatus::Exact => "exact",
        SolverStatus::Converged => "converged",
        SolverStatus::FallbackAfterMaxIterations => "fallback_after_max_iterations",
        SolverStatus::FallbackAfterDegenerate => "fallback_after_degenerate",
    }
}

#[pymethods]
impl PyContactResult {
    /// "overlap", "touching" or "separated".
    #[getter]
    fn status(&self) -> &'static str {
        kind_name(self.geometry.kind)
    }

    /// How the answer was obtained: "exact", "converged", "fallback_after_max_iterations" or
    /// "fallback_after_degenerate".
    #[getter]
    fn solver(&self) -> &'static str {
        solver_name(self.geometry.status)
    }

    /// Minkowski overlap δ_M (m).
    #[getter]
    fn depth(&self) -> Real {
        self.geometry.depth
    }

    /// Gap between the shapes (m).
    #[getter]
    fn distance(&self) -> Real {
        self.geometry.distance
    }

    /// Unit normal from a towards b.
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        PyArray1::from_slice(py, self.geometry.normal.as_slice())
    }

    /// Contact point on a's surface (m).
    #[getter]
    fn point_a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        PyArray1::from_slice(py, self.geometry.point_a.coords.as_slice())
    }

    /// Contact point on b's surface (m).
    #[getter]
    fn point_b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        PyArray1::from_slice(py, self.geometry.point_b.coords.as_slice())
    }

    /// The midpoint of `point_a` and `point_b` (m).
    #[getter]
    fn point<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        PyArray1::from_slice(py, self.geometry.point.coords.as_slice())
    }

    fn __repr__(&self) -> String {
        let g = &self.geometry;
        format!(
            "ContactResult(status={:?}, depth={:e}, distance={:e}, normal=[{}, {}, {}], solver={:?})",
            kind_name(g.kind),
            g.depth,
            g.distance,
            g.normal.x,
            g.normal.y,
            g.normal.z,
            solver_name(g.status)
        )
    }
}

/// The engine pose of a shape placed at the user's `pose`: `pose · frame`; without a pose, the shape's own
/// frame (it sits where its points were given, the pose `polydem contact` gives it).
pub fn engine_pose(pose: Option<&Pose>, frame: &Pose) -> Pose {
    pose.map_or(*frame, |p| p * frame)
}

/// The engine poses of the two shapes.
fn engine_poses(
    a: &PyShape,
    b: &PyShape,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
) -> PyResult<(Pose, Pose)> {
    let user =
        |pose: Option<&Bound<'_, PyAny>>, what| pose.map(|p| arrays::pose(p, what)).transpose();
    Ok((
        engine_pose(user(pose_a, "pose_a")?.as_ref(), &a.frame),
        engine_pose(user(pose_b, "pose_b")?.as_ref(), &b.frame),
    ))
}

/// The contact between shape `a` at `pose_a` and shape `b` at `pose_b`. A pose is
/// `(position[3], quaternion[4] as w, x, y, z)` placing the shape's input frame in the world; `None` is the
/// identity (a polyhedron then sits where its points were given).
#[pyfunction]
#[pyo3(signature = (a, b, pose_a = None, pose_b = None))]
pub fn contact(
    py: Python<'_>,
    a: PyRef<'_, PyShape>,
    b: PyRef<'_, PyShape>,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyContactResult> {
    let (pos1, pos2) = engine_poses(&a, &b, pose_a, pose_b)?;
    let (shape1, shape2) = (&a.shape, &b.shape);
    let geometry = py
        .detach(|| exact_query(&pos1, shape1, &pos2, shape2, &mut EpaScratch::default()))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(PyContactResult { geometry })
}

/// The exact Minkowski geometry of one pair at engine poses: the dispatch with the default tolerances and
/// no pair smoothing, a fresh warm-start cache (a query stands alone).
pub fn exact_query(
    pos1: &Pose,
    shape1: &Shape,
    pos2: &Pose,
    shape2: &Shape,
    scratch: &mut EpaScratch,
) -> Result<ContactGeometry, ContactError> {
    let tolerances = ContactTolerances {
        pair_smoothing: PairSmoothing::Exact,
        ..ContactTolerances::default()
    };
    query_with(
        pos1,
        shape1,
        pos2,
        shape2,
        &tolerances,
        &mut PairCache::default(),
        scratch,
        &mut QueryCounters::default(),
    )
}

/// The exact answer of the separating-axis oracle for two convex polyhedra (every face normal of either
/// and every cross product of an edge of each): the reference the engine's GJK/EPA is verified against.
/// Slow (O(E_a E_b V)); poses as for `contact`. Raises `ValueError` unless both shapes are
/// `ConvexPolyhedron`s.
#[pyfunction]
#[pyo3(signature = (a, b, pose_a = None, pose_b = None))]
pub fn contact_oracle(
    py: Python<'_>,
    a: PyRef<'_, PyShape>,
    b: PyRef<'_, PyShape>,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyContactResult> {
    let (pos1, pos2) = engine_poses(&a, &b, pose_a, pose_b)?;
    let (Shape::Polyhedron(p1), Shape::Polyhedron(p2)) = (&a.shape, &b.shape) else {
        return Err(PyValueError::new_err(
            "contact_oracle: the separating-axis oracle takes two ConvexPolyhedron shapes",
        ));
    };
    let geometry = py.detach(|| polydem::contact::sat_polyhedra(&pos1, p1, &pos2, p2));
    Ok(PyContactResult { geometry })
}
