//! Bit-for-bit comparison of two worlds' bodies and loads, shared by the tests that prove two step paths
//! (or thread counts) give the same bits.

use polydem::dynamics::RigidBody;
use polydem::world::World;

/// A body's state as one list: position, velocity, orientation, angular momentum.
fn body_state(b: &RigidBody) -> Vec<f64> {
    [
        b.position.coords.as_slice(),
        b.velocity.as_slice(),
        b.orientation.coords.as_slice(),
        b.angular_momentum.as_slice(),
    ]
    .concat()
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The first body whose state differs in bits between `a` and `b`, described with both states.
pub fn body_difference(a: &World, b: &World) -> Option<String> {
    a.bodies()
        .iter()
        .zip(b.bodies())
        .enumerate()
        .find_map(|(i, (x, y))| {
            let (fx, fy) = (body_state(x), body_state(y));
            (bits(&fx) != bits(&fy)).then(|| format!("body {i}: state {fx:?} against {fy:?}"))
        })
}

/// The loads as one list: body forces, torques, wall forces, elastic potential, external power, then
/// `extra`.
pub fn load_values(w: &World, extra: &[f64]) -> Vec<f64> {
    w.loads()
        .forces()
        .iter()
        .chain(w.loads().torques())
        .chain(w.loads().wall_forces())
        .flat_map(|v| v.iter().copied())
        .chain([w.loads().elastic_potential(), w.loads().external_power()])
        .chain(extra.iter().copied())
        .collect()
}

/// The first value at which two lists differ in bits: (index, value in `a`, value in `b`).
pub fn first_value_difference(a: &[f64], b: &[f64]) -> Option<(usize, f64, f64)> {
    if a.len() != b.len() {
        return Some((a.len().min(b.len()), f64::NAN, f64::NAN));
    }
    (0..a.len())
        .find(|&k| a[k].to_bits() != b[k].to_bits())
        .map(|k| (k, a[k], b[k]))
}
