//! The proof a separated polyhedron pair keeps in the contact store for the motion bound of
//! [`super::skips`]: per-pair state, in a file of its own so that the store and the skips both read it.

use crate::math::{Pose, Real};

/// What a polyhedron pair keeps of the last cached-axis test that proved it separated (see [`super::skips`]):
/// the pose of B relative to A then and the gap along the cached axis. No proof (the default): `gap` = 0.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SeparationBound {
    /// The pose of B in A's frame at the test.
    pub pos12: Pose,
    /// The gap (m) along the cached axis at the test, less the round-off margin; 0 when there is none.
    pub gap: Real,
}

impl SeparationBound {
    /// Drops the proof (the pair went through another query, so its cached axis may have changed).
    #[inline]
    pub fn clear(&mut self) {
        self.gap = 0.0;
    }
}

/// No proof: the check never passes.
impl Default for SeparationBound {
    fn default() -> Self {
        Self {
            pos12: Pose::identity(),
            gap: 0.0,
        }
    }
}
