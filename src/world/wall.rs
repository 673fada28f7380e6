//! A wall: a plane placed by a pose that moves with a prescribed constant velocity. Walls are not bodies
//! (a half-space has no bounding sphere and no mass); the broad phase pairs them with bodies by distance.

use crate::math::{Point, Pose, Real, Vector};
use crate::shape::Plane;

/// A wall: a half-space (see [`Plane`] for its convention) placed by a pose that moves with a prescribed
/// constant velocity (zero for a fixed wall).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Wall {
    /// Name of the wall.
    pub name: String,
    /// The half-space in the wall's own frame.
    pub plane: Plane,
    /// Places the plane in the world (m).
    pub pose: Pose,
    /// Prescribed velocity (m/s), world frame; zero for a fixed wall.
    pub velocity: Vector,
    /// Material id.
    pub material: u32,
}

impl Wall {
    /// Unit outward normal in the world frame (points to the free side).
    pub fn normal_world(&self) -> Vector {
        self.pose.rotation * self.plane.normal()
    }

    /// Signed distance (m) of `x` from the wall, positive on the free side.
    pub fn signed_distance(&self, x: &Point) -> Real {
        self.plane.signed_distance(&self.pose, x)
    }
}
