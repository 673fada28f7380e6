//! Stage 8's test of one body: the first non-finite quantity of its loads and state.

use crate::math::{Point, Vector};

/// Stage 8 for one body: the first non-finite quantity of its loads and state, if any.
pub(super) fn non_finite_quantity(
    body: &crate::dynamics::RigidBody,
    force: &Vector,
    torque: &Vector,
) -> Option<&'static str> {
    first_non_finite(
        force,
        torque,
        &body.position,
        &body.velocity,
        &body.orientation,
        &body.angular_momentum,
    )
}

/// The first non-finite quantity among a body's loads and state, in the order the step's error names
/// them; shared by the general step and the sphere paths so all report the same quantity.
///
/// First one sum of them all, formed as a tree of vector sums: finite only if every term is (inf − inf
/// and NaN propagate), so a finite sum answers `None` at once; otherwise the quantities are tested one
/// by one (which also clears a sum that overflowed from finite terms). Every body of every step takes
/// the test, so its cost matters: a chain of 18 scalar additions would serialise on the adder
/// (`docs/tuning.md`).
#[inline(always)]
pub(crate) fn first_non_finite(
    force: &Vector,
    torque: &Vector,
    position: &Point,
    velocity: &Vector,
    orientation: &crate::math::Rotation,
    angular_momentum: &Vector,
) -> Option<&'static str> {
    let sum = ((force + torque) + (position.coords + velocity) + angular_momentum).sum()
        + orientation.coords.sum();
    if sum.is_finite() {
        return None;
    }
    first_non_finite_one_by_one(
        force,
        torque,
        position,
        velocity,
        orientation,
        angular_momentum,
    )
}

#[cold]
#[inline(never)]
fn first_non_finite_one_by_one(
    force: &Vector,
    torque: &Vector,
    position: &Point,
    velocity: &Vector,
    orientation: &crate::math::Rotation,
    angular_momentum: &Vector,
) -> Option<&'static str> {
    let finite = |v: &Vector| v.iter().all(|x| x.is_finite());
    if !finite(force) {
        Some("contact force")
    } else if !finite(torque) {
        Some("contact torque")
    } else if !finite(&position.coords) {
        Some("position")
    } else if !finite(velocity) {
        Some("velocity")
    } else if !orientation.coords.iter().all(|x| x.is_finite()) {
        Some("orientation")
    } else if !finite(angular_momentum) {
        Some("angular momentum")
    } else {
        None
    }
}
