//! Axis-aligned bounding box.

use crate::math::Point;

/// An axis-aligned box `[mins, maxs]` in the world frame (m).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Aabb {
    /// Lower corner (m).
    pub mins: Point,
    /// Upper corner (m).
    pub maxs: Point,
}

impl Aabb {
    /// Whether the two boxes overlap or touch.
    pub fn intersects(&self, other: &Aabb) -> bool {
        (0..3).all(|k| self.mins[k] <= other.maxs[k] && other.mins[k] <= self.maxs[k])
    }
}
