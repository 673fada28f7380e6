//! The shapes of the Python package: one base class `Shape` holding the engine's [`Shape`] and the pose of
//! its principal frame in the frame the user described it in, and one small subclass per kind
//! (`ConvexPolyhedron`, `Sphere`, `Ellipsoid`) that constructs it and answers what is particular to it. Mass properties and contact
//! queries go through the base class, so a new shape kind is one constructor here.

use std::sync::Arc;

use numpy::{PyArray1, PyArray2};
use polydem::math::{Pose, Real};
use polydem::shape::{self, ConvexShape, MassProperties, Shape, ShapeError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays;

fn shape_error(what: &str, e: ShapeError) -> PyErr {
    PyValueError::new_err(format!("{what}: {e}"))
}

/// A bounded convex shape. Lengths in metres; mass properties per unit density (multiply by a density in
/// kg/m³ for kg·m²), in the frame the shape was described in.
#[pyclass(subclass, frozen, name = "Shape", module = "polydem")]
pub struct PyShape {
    pub shape: Shape,
    /// The pose of the engine shape's own frame in the user's frame: the engine pose of a body placed at
    /// `pose` by the user is `pose · frame`.
    pub frame: Pose,
}

impl PyShape {
    fn convex(&self) -> &dyn ConvexShape {
        self.shape
            .convex()
            .expect("every Python shape class builds a bounded shape")
    }

    fn mass_properties(&self) -> MassProperties {
        self.convex().mass_properties()
    }
}

#[pymethods]
impl PyShape {
    /// Volume (m³).
    #[getter]
    fn volume(&self) -> Real {
        self.mass_properties().volume
    }

    /// Centroid in the shape's input frame (m), a new array.
    #[getter]
    fn centroid<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        let c = self.frame * self.mass_properties().centroid;
        PyArray1::from_slice(py, c.coords.as_slice())
    }

    /// Principal moments of inertia per unit density about the centroid (m⁵), ascending, a new array.
    #[getter]
    fn principal_moments<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        PyArray1::from_slice(py, self.mass_properties().principal_moments.as_slice())
    }

    /// Principal axes in the shape's input frame: a 3×3 array whose column k is the axis of
    /// `principal_moments[k]`.
    #[getter]
    fn principal_axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let axes =
            (self.frame.rotation * self.mass_properties().principal_axes).to_rotation_matrix();
        let m = axes.matrix();
        let rows: Vec<Vec<Real>> = (0..3)
            .map(|r| (0..3).map(|c| m[(r, c)]).collect())
            .collect();
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    /// Radius of the bounding sphere about the centroid (m).
    #[getter]
    fn bounding_radius(&self) -> Real {
        self.convex().bounding_radius()
    }
}

/// A convex polyhedron: the convex hull of a point cloud.
#[pyclass(extends = PyShape, frozen, name = "ConvexPolyhedron", module = "polydem")]
pub struct PyConvexPolyhedron {
    polyhedron: Arc<shape::ConvexPolyhedron>,
}

#[pymethods]
impl PyConvexPolyhedron {
    /// The convex hull of `points`, an (N, 3) array (N ≥ 4, not all coplanar, all finite), in metres.
    /// The polyhedron keeps the points' frame: at the identity pose it occupies the hull of the points.
    #[staticmethod]
    fn from_points<'py>(
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyConvexPolyhedron>> {
        let points = arrays::points(points, "points")?;
        let (polyhedron, frame) =
            shape::ConvexPolyhedron::from_points(&points).map_err(|e| shape_error("points", e))?;
        let polyhedron = Arc::new(polyhedron);
        let base = PyShape {
            shape: Shape::Polyhedron(polyhedron.clone()),
            frame,
        };
        let initializer =
            PyClassInitializer::from(base).add_subclass(PyConvexPolyhedron { polyhedron });
        Bound::new(py, initializer)
    }

    /// The hull's vertices in the input frame, an (N, 3) array (a new array).
    #[getter]
    fn vertices<'py>(slf: PyRef<'py, Self>) -> PyResult<Bound<'py, PyArray2<Real>>> {
        let frame = slf.as_super().frame;
        let rows: Vec<Vec<Real>> = slf
            .polyhedron
            .vertices()
            .iter()
            .map(|v| (frame * v).coords.as_slice().to_vec())
            .collect();
        Ok(PyArray2::from_vec2(slf.py(), &rows)?)
    }

    /// Number of faces of the hull (coplanar triangles merged into polygons).
    #[getter]
    fn num_faces(&self) -> usize {
        self.polyhedron.num_faces()
    }
}

/// A sphere of radius `radius` (m) centred at its origin.
#[pyclass(extends = PyShape, frozen, name = "Sphere", module = "polydem")]
pub struct PySphere {
    radius: Real,
}

#[pymethods]
impl PySphere {
    #[new]
    fn new(radius: Real) -> PyResult<PyClassInitializer<Self>> {
        let sphere = shape::Sphere::new(radius).map_err(|e| shape_error("radius", e))?;
        let radius = sphere.radius();
        let base = PyShape {
            shape: Shape::Sphere(sphere),
            frame: Pose::identity(),
        };
        Ok(PyClassInitializer::from(base).add_subclass(PySphere { radius }))
    }

    /// Radius (m).
    #[getter]
    fn radius(&self) -> Real {
        self.radius
    }
}

/// An ellipsoid with semi-axes `a`, `b`, `c` (m) along its x, y, z axes, centred at its origin.
#[pyclass(extends = PyShape, frozen, name = "Ellipsoid", module = "polydem")]
pub struct PyEllipsoid {
    semi_axes: [Real; 3],
}

#[pymethods]
impl PyEllipsoid {
    #[new]
    fn new(a: Real, b: Real, c: Real) -> PyResult<PyClassInitializer<Self>> {
        let ellipsoid = shape::Ellipsoid::new(a, b, c).map_err(|e| shape_error("semi-axes", e))?;
        let axes = ellipsoid.semi_axes();
        let base = PyShape {
            shape: Shape::Ellipsoid(ellipsoid),
            frame: Pose::identity(),
        };
        let semi_axes = [axes.x, axes.y, axes.z];
        Ok(PyClassInitializer::from(base).add_subclass(PyEllipsoid { semi_axes }))
    }

    /// Semi-axes (a, b, c) in metres, a new array.
    #[getter]
    fn semi_axes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<Real>> {
        PyArray1::from_slice(py, &self.semi_axes)
    }
}
