//! The native module of the `polydem` Python package (`polydem._polydem`): shapes and contact queries
//! ([`shapes`], [`contact`]), scenes and simulations ([`simulation`]), with every engine error turned into
//! a Python exception ([`errors`]) and every bad array into a `ValueError` ([`arrays`]). The Python-facing
//! documentation is in the docstrings and `polydem/__init__.pyi`.

mod arrays;
mod contact;
mod contact_batch;
mod errors;
mod interrupt;
mod rockfill;
mod run_loop;
mod scene_dict;
mod shapes;
mod simulation;
mod world_arrays;

use pyo3::prelude::*;

#[pymodule]
fn _polydem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<shapes::PyShape>()?;
    m.add_class::<shapes::PyConvexPolyhedron>()?;
    m.add_class::<shapes::PySphere>()?;
    m.add_class::<shapes::PyEllipsoid>()?;
    m.add_class::<contact::PyContactResult>()?;
    m.add_function(wrap_pyfunction!(contact::contact, m)?)?;
    m.add_function(wrap_pyfunction!(contact::contact_oracle, m)?)?;
    m.add_function(wrap_pyfunction!(contact_batch::contact_batch, m)?)?;
    m.add_class::<simulation::PyScene>()?;
    m.add_function(wrap_pyfunction!(scene_dict::scene_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(rockfill::rockfill, m)?)?;
    m.add_class::<simulation::PySimulation>()?;
    m.add("SceneError", py.get_type::<errors::PyPolydemSceneError>())?;
    m.add(
        "CheckpointError",
        py.get_type::<errors::PyCheckpointError>(),
    )?;
    m.add("StepError", py.get_type::<errors::PyStepError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
