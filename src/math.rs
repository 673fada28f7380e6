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

// The one place where nalgebra meets glam.
//
// parry3d-f64 ≥ 0.26 and rapier3d-f64 use glam types (through `glamx`). The engine uses parry3d-f64 for one
// job, the triangulated convex hull of a point cloud (`shape::hull`); the harness uses parry3d-f64 and
// rapier3d-f64 as reference codes. Every conversion between the two worlds is below, and nowhere else.

/// Conversions between polydem's nalgebra types and the glam types of parry3d-f64 / rapier3d-f64.
pub mod glam {
    use super::{Point, Pose, Rotation, Vector};
    use parry3d_f64::math::{Pose as GlamPose, Rot3 as GlamRot, Vector as GlamVec};

    /// nalgebra point → glam vector.
    pub fn point_to_glam(p: &Point) -> GlamVec {
        GlamVec::new(p.x, p.y, p.z)
    }

    /// nalgebra vector → glam vector.
    pub fn vector_to_glam(v: &Vector) -> GlamVec {
        GlamVec::new(v.x, v.y, v.z)
    }

    /// glam vector → nalgebra point.
    pub fn glam_to_point(v: GlamVec) -> Point {
        Point::new(v.x, v.y, v.z)
    }

    /// glam vector → nalgebra vector.
    pub fn glam_to_vector(v: GlamVec) -> Vector {
        Vector::new(v.x, v.y, v.z)
    }

    /// nalgebra isometry (unit quaternion + translation) → glam pose. Exact: the quaternion components and the
    /// translation are copied, no re-normalisation.
    pub fn pose_to_glam(p: &Pose) -> GlamPose {
        let q = p.rotation.quaternion();
        let rot = GlamRot::from_xyzw(q.i, q.j, q.k, q.w);
        GlamPose::from_parts(vector_to_glam(&p.translation.vector), rot)
    }

    /// nalgebra unit quaternion → glam quaternion (components copied, no re-normalisation).
    pub fn rotation_to_glam(r: &Rotation) -> GlamRot {
        let q = r.quaternion();
        GlamRot::from_xyzw(q.i, q.j, q.k, q.w)
    }

    /// glam quaternion → nalgebra unit quaternion (components copied; the caller's quaternion is unit up to
    /// round-off, so no re-normalisation is done either).
    pub fn glam_to_rotation(r: GlamRot) -> Rotation {
        Rotation::new_unchecked(nalgebra::Quaternion::new(r.w, r.x, r.y, r.z))
    }
}

#[cfg(test)]
mod tests {
    use super::glam::*;
    use super::*;

    #[test]
    fn pose_conversion_maps_points_identically() {
        let pose = Pose::from_parts(
            nalgebra::Translation3::new(1.0, -2.0, 0.5),
            Rotation::from_scaled_axis(Vector::new(0.3, -0.7, 1.1)),
        );
        let p = Point::new(0.25, 4.0, -3.0);
        let a = pose * p;
        let b = glam_to_point(pose_to_glam(&pose).transform_point(point_to_glam(&p)));
        assert!((a - b).norm() < 1e-14, "nalgebra {a} vs glam {b}");
    }

    #[test]
    fn rotation_conversion_round_trips_and_rotates_identically() {
        let r = Rotation::from_scaled_axis(Vector::new(-0.4, 1.3, 0.2));
        let v = Vector::new(0.3, -1.0, 2.0);
        let a = r.transform_vector(&v);
        let b = glam_to_vector(rotation_to_glam(&r) * vector_to_glam(&v));
        assert!((a - b).norm() < 1e-14, "nalgebra {a} vs glam {b}");
        assert_eq!(glam_to_rotation(rotation_to_glam(&r)), r);
    }
}
