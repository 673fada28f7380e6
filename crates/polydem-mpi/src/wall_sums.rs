//! The walls' contact forces of the whole world, summed from the touching body–wall entries the ranks
//! answer for, in key order: the order and the bits of one process's step.

use polydem::math::Vector;
use polydem::world::{ContactKey, ContactState};

/// The touching body–wall entries among `entries`, with the force on the body.
pub(crate) fn touching_walls(entries: &[(ContactKey, ContactState)]) -> Vec<(ContactKey, Vector)> {
    entries
        .iter()
        .filter(|(key, state)| matches!(key, ContactKey::Wall { .. }) && state.is_active())
        .map(|(key, state)| (*key, state.force_on_b))
        .collect()
}

/// The contact force on each of `walls` walls: the opposite of the force on the body of every touching
/// body–wall entry (`touching`, in key order), summed from zero in that order as the step sums them.
pub(crate) fn wall_forces(touching: &[(ContactKey, Vector)], walls: usize) -> Vec<Vector> {
    let mut forces = vec![Vector::zeros(); walls];
    for (key, force_on_b) in touching {
        if let ContactKey::Wall { wall, .. } = key {
            forces[*wall as usize] -= force_on_b;
        }
    }
    forces
}
