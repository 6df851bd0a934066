//! The Rust ERA example (examples/era.rs) compiled into the module, so
//! that the Python version of the cell (python/examples/era_cell.py) is
//! compared with it in one process: the model file the Rust builders
//! write, and the lock instants and the largest latch moment of its
//! deployment (`deploy::run`).

#![allow(missing_docs)]

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

#[allow(dead_code, clippy::all)]
#[path = "../../examples/era.rs"]
mod era;

#[allow(dead_code, clippy::all)]
#[path = "../../examples/mast_cell.rs"]
mod mast_cell;

use era::design::Design;
use era::geometry::{Geometry, Structure};

/// The ERA cell's deployment model with gravity `gravity` (g), as the
/// Rust example builds it: the model file (TOML).
#[pyfunction]
fn era_cell_model(gravity: f64) -> PyResult<String> {
    let geometry = Geometry::new(&Design::default(), Structure::Cell);
    let built = era::deploy::model(&geometry, &era::case(Structure::Cell, gravity));
    built
        .input
        .to_toml()
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// The mast cell's model in `increments` increments, as the Rust example
/// builds it (examples/mast_cell.rs, `build`): the model file (TOML).
#[pyfunction]
fn mast_cell_model(py: Python<'_>, increments: usize) -> PyResult<String> {
    let cell = py.detach(|| mast_cell::build(increments));
    cell.input
        .to_toml()
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// Runs the Rust example's deployment of the ERA cell with gravity
/// `gravity` (g), without result files: a dictionary with `locks` (the
/// lock time of each mid-hinge, top then bottom of each face; `None` if
/// open), `latches` (the latch id of each), `peak_latch_moment` (N·m),
/// `steps`, `iterations`, `time` reached, `wall_time` (s) and `error`.
#[pyfunction]
fn era_cell_deployment<'py>(py: Python<'py>, gravity: f64) -> PyResult<Bound<'py, PyDict>> {
    let run = py.detach(|| {
        let geometry = Geometry::new(&Design::default(), Structure::Cell);
        let built = era::deploy::model(&geometry, &era::case(Structure::Cell, gravity));
        let nominal = era::deploy::nominal(&geometry).map_err(|e| e.to_string())?;
        let run =
            era::deploy::run(&built, &nominal, None, 1.0, false).map_err(|e| e.to_string())?;
        let latches: Vec<Option<u64>> = built
            .parts
            .hinges()
            .map(|h| h.latch.map(|l| l.id()))
            .collect();
        Ok::<_, String>((run, latches))
    });
    let (run, latches) = run.map_err(PyRuntimeError::new_err)?;
    let f = &run.figures;
    let d = PyDict::new(py);
    d.set_item("locks", f.locks.clone())?;
    d.set_item("latches", latches)?;
    d.set_item("peak_latch_moment", f.peak_latch_moment)?;
    d.set_item("steps", f.steps)?;
    d.set_item("iterations", f.iterations)?;
    d.set_item("time", run.outcome.time)?;
    d.set_item("wall_time", f.wall_time)?;
    d.set_item("error", run.outcome.error.as_ref().map(|e| e.to_string()))?;
    Ok(d)
}

/// Adds the functions to the module, in its submodule `_reference`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let r = PyModule::new(m.py(), "_reference")?;
    r.add_function(wrap_pyfunction!(era_cell_model, &r)?)?;
    r.add_function(wrap_pyfunction!(era_cell_deployment, &r)?)?;
    r.add_function(wrap_pyfunction!(mast_cell_model, &r)?)?;
    m.add_submodule(&r)?;
    Ok(())
}
