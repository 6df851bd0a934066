//! The Python module `unfold._unfold`, re-exported by the package
//! `unfold` (python/unfold/__init__.py): the typed model builders of
//! `unfold::model::builder` as Python classes, models read from files,
//! runs of their analyses with the GIL released, and their results as
//! numpy arrays.
//!
//! - [`builder`]: the builders and the handles they return;
//! - [`model`]: a validated model and its analyses, and their run;
//! - [`observe`]: what a run keeps in memory, its progress callback and
//!   its interruption;
//! - [`results`]: the results of a run, as numpy arrays;
//! - [`errors`]: the exceptions;
//! - [`reference`]: the Rust ERA example compiled in, for comparisons.

#![warn(missing_docs)]

use pyo3::prelude::*;

pub mod builder;
pub mod errors;
pub mod model;
pub mod observe;
pub mod reference;
pub mod results;
pub mod so3;

/// The extension module.
#[pymodule]
fn _unfold(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    builder::register(m)?;
    model::register(m)?;
    results::register(m)?;
    reference::register(m)?;
    so3::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
