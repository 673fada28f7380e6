//! Shapes: convex polyhedra, spheres, ellipsoids and planes (walls).
//!
//! Every shape is described in its own local frame; a [`Pose`](crate::math::Pose) places it in the world.
//! A polyhedron's local frame is its principal frame (origin at the centroid, axes along the principal axes of
//! inertia), so that the rotation integrator can use the diagonal inertia directly.
//!
//! One job per file: [`error`] (construction errors), `hull` (point cloud → polygonal convex hull),
//! `polygon` (face plane helpers), [`mass`] (exact mass properties), [`polyhedron`] (the polyhedron, its
//! topology and support map), [`sphere`], [`ellipsoid`], [`plane`] (walls), [`aabb`], `support` (the
//! support-map trait), [`vertex_columns`] (vertices laid out for the vectorised support scan), [`convex`] (the convex-shape trait every bounded shape implements).
//!
//! Adding a bounded shape: a file with the shape and its [`ConvexShape`] implementation, a variant here and
//! its arm in [`Shape::convex`]. Code elsewhere reaches a new shape through [`Shape::convex`] (catch-all
//! arms), and the narrow phase through the generic support-map arm.

pub mod aabb;
pub mod convex;
pub mod ellipsoid;
pub mod error;
mod hull;
pub mod mass;
pub mod plane;
mod polygon;
pub mod polyhedron;
pub mod sphere;
mod support;
pub mod surface_mesh;
pub mod vertex_columns;

pub use aabb::Aabb;
pub use convex::{ConvexShape, SurfaceMesh};
pub use ellipsoid::Ellipsoid;
pub use error::ShapeError;
pub use hull::{MAX_EXTENT, MIN_EXTENT};
pub use mass::MassProperties;
pub use plane::Plane;
pub use polyhedron::ConvexPolyhedron;
pub use sphere::Sphere;
pub use support::SupportMap;
pub use vertex_columns::VertexColumns;

use crate::math::Real;

/// Any shape a body or wall can have. Polyhedra are shared (`Arc`) because many bodies use one shape.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    /// A convex polyhedron, shared between the bodies that use it.
    Polyhedron(std::sync::Arc<ConvexPolyhedron>),
    /// A sphere.
    Sphere(Sphere),
    /// A half-space (a wall).
    Plane(Plane),
    /// An ellipsoid.
    Ellipsoid(Ellipsoid),
}

impl Shape {
    /// The characteristic length that tolerances of queries involving this shape are scaled by (m): the
    /// bounding-sphere diameter of a polyhedron, the diameter of a sphere, and `None` for a plane, which is
    /// unbounded (a pair with a plane uses the other shape's length scale).
    pub fn length_scale(&self) -> Option<Real> {
        match self {
            Shape::Polyhedron(p) => Some(p.length_scale()),
            Shape::Sphere(s) => Some(s.length_scale()),
            Shape::Plane(_) => None,
            other => other.convex().map(|c| c.length_scale()),
        }
    }

    /// The shape as a bounded convex solid, `None` for a plane (a wall, unbounded).
    pub fn convex(&self) -> Option<&dyn ConvexShape> {
        match self {
            Shape::Polyhedron(p) => Some(p.as_ref()),
            Shape::Sphere(s) => Some(s),
            Shape::Ellipsoid(e) => Some(e),
            Shape::Plane(_) => None,
        }
    }

    /// The ellipsoid with semi-axes `a`, `b`, `c` (m) along its body x, y, z axes (see [`Ellipsoid::new`]).
    pub fn ellipsoid(a: Real, b: Real, c: Real) -> Result<Shape, ShapeError> {
        Ellipsoid::new(a, b, c).map(Shape::Ellipsoid)
    }
}

#[cfg(test)]
mod tests_ellipsoid;
