//! The exceptions: one base class and one per kind of failure, as the
//! command line's exit codes tell them apart (docs/results.md, "Exit
//! codes"): invalid input (exit code 2) is a [`ModelError`], an analysis
//! that stopped early (exit code 1) an [`AnalysisError`], result files
//! that cannot be written an [`OutputError`]. Each carries the message
//! `unfold run` prints after `error: `.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;

create_exception!(
    unfold,
    UnfoldError,
    PyException,
    "The base class of the errors of unfold."
);
create_exception!(
    unfold,
    ModelError,
    UnfoldError,
    "An invalid model: a file that cannot be read or parsed, an entity that is inconsistent, or a model that the checks of the start of a run reject (a mechanism in statics, initial velocities that the joints forbid). `unfold run` exits with code 2 on these. `errors` lists the problems found."
);
create_exception!(
    unfold,
    AnalysisError,
    UnfoldError,
    "An analysis that stopped before its end (Newton failed at the smallest step, a singular tangent, inconsistent constraints). `unfold run` exits with code 1 on these. `results` holds the results up to the last converged step."
);
create_exception!(
    unfold,
    OutputError,
    UnfoldError,
    "Result files that cannot be written (a directory locked by another run, a full disk)."
);
create_exception!(
    unfold,
    Interrupted,
    PyKeyboardInterrupt,
    "A run stopped by Ctrl-C (KeyboardInterrupt) between two steps: `results` holds the results up to the last converged step, and the result files, if any, are consistent and say `interrupted`."
);

/// Adds the exceptions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("UnfoldError", py.get_type::<UnfoldError>())?;
    m.add("ModelError", py.get_type::<ModelError>())?;
    m.add("AnalysisError", py.get_type::<AnalysisError>())?;
    m.add("OutputError", py.get_type::<OutputError>())?;
    m.add("Interrupted", py.get_type::<Interrupted>())?;
    Ok(())
}

/// A [`ModelError`] with `message`, and the problems one by one in its
/// attribute `errors` (`(entity, message)` pairs).
pub fn model_error(py: Python<'_>, message: String, errors: Vec<(String, String)>) -> PyErr {
    let err = ModelError::new_err(message);
    let _ = err.value(py).setattr("errors", errors);
    err
}

/// The problems of `errors` as `(entity, message)` pairs.
pub fn pairs(errors: &unfold::model::ModelErrors) -> Vec<(String, String)> {
    errors
        .0
        .iter()
        .map(|e| (e.entity.clone(), e.message.clone()))
        .collect()
}
