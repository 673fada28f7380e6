//! The contact list and the walls of a simulation as numpy arrays (copies), and the wall velocity setter.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use polydem::math::{Point, Real, Vector};
use polydem::world::{ContactKey, World};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// An (n, 3) array of vectors.
fn vectors<'py>(py: Python<'py>, rows: &[Vector]) -> PyResult<Bound<'py, PyArray2<Real>>> {
    let flat: Vec<Real> = rows.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), 3])
}

/// The active contacts of the world's contact store, in the store's order (the rows of
/// `contacts.csv`).
pub fn contacts<'py>(py: Python<'py>, world: &World) -> PyResult<Bound<'py, PyDict>> {
    let store = &world.contacts();
    let (mut wall, mut a, mut b) = (Vec::new(), Vec::new(), Vec::new());
    let (mut point, mut normal, mut depth, mut force) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (key, state) in store.keys().iter().zip(store.states()) {
        if !state.is_active() {
            continue;
        }
        let (is_wall, first, second) = match *key {
            ContactKey::Body { a, b } => (false, a, b),
            ContactKey::Wall { body, wall } => (true, wall, body),
        };
        wall.push(is_wall);
        a.push(i64::from(first));
        b.push(i64::from(second));
        let g = &state.geometry;
        point.push(g.point.coords);
        normal.push(g.normal);
        depth.push(g.depth);
        force.push(state.force_on_b);
    }
    let d = PyDict::new(py);
    d.set_item("wall", PyArray1::from_vec(py, wall))?;
    d.set_item("a", PyArray1::from_vec(py, a))?;
    d.set_item("b", PyArray1::from_vec(py, b))?;
    d.set_item("point", vectors(py, &point)?)?;
    d.set_item("normal", vectors(py, &normal)?)?;
    d.set_item("depth", PyArray1::from_vec(py, depth))?;
    d.set_item("force", vectors(py, &force)?)?;
    Ok(d)
}

/// The walls: names, a point of each plane, normals, velocities and the contact force on each.
pub fn walls<'py>(py: Python<'py>, world: &World) -> PyResult<Bound<'py, PyDict>> {
    let names: Vec<&str> = world.walls().iter().map(|w| w.name.as_str()).collect();
    let points: Vec<Vector> = world
        .walls()
        .iter()
        .map(|w| {
            let local = Point::from(w.plane.normal() * w.plane.offset());
            (w.pose * local).coords
        })
        .collect();
    let normals: Vec<Vector> = world.walls().iter().map(|w| w.normal_world()).collect();
    let velocities: Vec<Vector> = world.walls().iter().map(|w| w.velocity).collect();
    let forces: Vec<Vector> = if world.loads().wall_forces().len() == world.walls().len() {
        world.loads().wall_forces().to_vec()
    } else {
        vec![Vector::zeros(); world.walls().len()]
    };
    let d = PyDict::new(py);
    d.set_item("names", names)?;
    d.set_item("point", vectors(py, &points)?)?;
    d.set_item("normal", vectors(py, &normals)?)?;
    d.set_item("velocity", vectors(py, &velocities)?)?;
    d.set_item("force", vectors(py, &forces)?)?;
    Ok(d)
}

/// Sets the prescribed velocity of the wall `name`; a `KeyError` listing the walls if there is none.
pub fn set_wall_velocity(world: &mut World, name: &str, velocity: [Real; 3]) -> PyResult<()> {
    let velocity = Vector::from(velocity);
    match world.wall_index(name) {
        Some(k) => world
            .set_wall_velocity(k, velocity)
            .map_err(|e| PyValueError::new_err(e.to_string())),
        None => {
            let known: Vec<&str> = world.walls().iter().map(|w| w.name.as_str()).collect();
            Err(PyKeyError::new_err(format!(
                "no wall named {name:?}; the walls are {known:?}"
            )))
        }
    }
}
