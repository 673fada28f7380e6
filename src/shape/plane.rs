//! Planes (walls): half-space solids.
//!
//! # Convention
//! A [`Plane`] is the solid half-space `{x : n·x ≤ offset}` in the plane's local frame, with `n` the unit
//! **outward** normal: it points out of the wall's material, into the free side where the particles are.
//! A particle touches the wall where its support point along `−n` reaches the plane. The wall is placed in
//! the world by a pose like any shape; its world normal is `pose.rotation * n` and its world plane passes
//! through `pose * (offset n)`. A half-space is unbounded: it has no support map, no finite mass and no
//! length scale (a pair's tolerances use the other shape's).

use crate::math::{Pose, Real, Vector};

use super::error::ShapeError;

/// A wall: the half-space `n·x ≤ offset` (local frame) with unit outward normal `n` (see the module docs).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    normal: Vector,
    offset: Real,
}

impl Plane {
    /// The half-space `n̂·x ≤ offset/|normal|`, with `n̂ = normal/|normal|`: the normal is normalised and the
    /// plane equation scaled with it, so `Plane::new(2 e_z, 2)` is the half-space z ≤ 1. The normal must be
    /// finite and non-zero, the offset finite.
    pub fn new(normal: Vector, offset: Real) -> Result<Plane, ShapeError> {
        let norm = normal.norm();
        if !norm.is_finite() || norm <= 0.0 {
            return Err(ShapeError::InvalidParameter {
                name: "normal",
                value: format!("[{}, {}, {}]", normal.x, normal.y, normal.z),
                reason: "must be finite and non-zero",
            });
        }
        if !offset.is_finite() {
            return Err(ShapeError::InvalidParameter {
                name: "offset",
                value: offset.to_string(),
                reason: "must be finite",
            });
        }
        Ok(Plane {
            normal: normal / norm,
            offset: offset / norm,
        })
    }

    /// Unit outward normal in the local frame.
    pub fn normal(&self) -> &Vector {
        &self.normal
    }

    /// Plane offset (m): the boundary is `n·x = offset` in the local frame.
    pub fn offset(&self) -> Real {
        self.offset
    }

    /// Signed distance (m) of the world point `x` from the wall placed at `pose`: positive on the free side,
    /// negative inside the wall.
    pub fn signed_distance(&self, pose: &Pose, x: &crate::math::Point) -> Real {
        self.normal.dot(&pose.inverse_transform_point(x).coords) - self.offset
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Point, Rotation};

    #[test]
    fn normal_is_normalised_with_the_equation() {
        let p = Plane::new(Vector::new(0.0, 0.0, 2.0), 2.0).unwrap();
        assert_eq!(*p.normal(), Vector::z());
        assert_eq!(p.offset(), 1.0);
    }

    #[test]
    fn rejects_zero_or_non_finite_parameters() {
        assert!(Plane::new(Vector::zeros(), 0.0).is_err());
        assert!(Plane::new(Vector::new(Real::NAN, 0.0, 1.0), 0.0).is_err());
        assert!(Plane::new(Vector::z(), Real::INFINITY).is_err());
    }

    #[test]
    fn signed_distance_is_positive_on_the_free_side() {
        // Floor z ≤ 0 tilted by 90° about x: its outward normal becomes −y in the world.
        let plane = Plane::new(Vector::z(), 0.0).unwrap();
        let pose = Pose::from_parts(
            Vector::new(0.0, 0.0, 0.0).into(),
            Rotation::from_scaled_axis(Vector::x() * std::f64::consts::FRAC_PI_2),
        );
        let d = plane.signed_distance(&pose, &Point::new(0.0, -3.0, 0.0));
        assert!((d - 3.0).abs() < 1e-12, "signed distance {d}, expected 3");
    }
}
