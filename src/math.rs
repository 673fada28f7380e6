//! Linear-algebra aliases over nalgebra, in f64 throughout.
//!
//! Every module of the engine names its math types through this file, so that the scalar type and the
//! library behind it are decided in one place.

/// The engine's scalar: f64 everywhere (SI units).
pub type Real = f64;
/// A free vector (direction, velocity, force).
pub type Vector = nalgebra::Vector3<Real>;
/// A position.
pub type Point = nalgebra::Point3<Real>;
/// A 3×3 matrix (inertia tensors, rotation matrices).
pub type Matrix = nalgebra::Matrix3<Real>;
/// A unit quaternion (orientation).
pub type Rotation = nalgebra::UnitQuaternion<Real>;
/// A rigid pose: rotation then translation. `pos1` maps body-1 coordinates to world coordinates.
pub type Pose = nalgebra::Isometry3<Real>;

// Conversions to the glam-based vector type of parry3d-f64 (used for its convex hull).

/// Converts a point to parry3d-f64's vector type.
pub fn to_parry_vector(p: &Point) -> parry3d_f64::math::Vector3 {
    parry3d_f64::math::Vector3::new(p.x, p.y, p.z)
}

/// Converts parry3d-f64's vector type to a point.
pub fn from_parry_vector(v: parry3d_f64::math::Vector3) -> Point {
    Point::new(v.x, v.y, v.z)
}
