//! A validated model with its analyses (`unfold.Model`), read from a
//! model file (`unfold.load_model`, the library's
//! `io::model_file::read_model`), built (`ModelBuilder.build`) or made
//! from a dictionary of the file schema; and its run: the analyses of the
//! sequence in order, each from the final state of the one before, as
//! `unfold run` runs them (src/main.rs), with the GIL released.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use unfold::analysis::{
    preflight, AnalysisSettings, DynamicAnalysis, DynamicError, ModalAnalysis, ModalError,
    NewtonFailure, StaticAnalysis,
};
use unfold::elements::ElementKind;
use unfold::io::model_file::{parse_model, read_model, ModelFileError};
use unfold::io::restart::RestartWriter;
use unfold::io::results::{write_rejected, AnalysisEnd, Summary};
use unfold::io::run::{
    dynamic_error_message, format_time, Interrupted, Recorder, Silent, StopRequest,
};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

use crate::builder;
use crate::errors::{self, AnalysisError, OutputError};
use crate::observe::{self, Callback, PyObserver, Recorded};
use crate::results::PyResults;

/// A validated model and, beside it, the analyses it asks for.
#[pyclass(name = "Model", module = "unfold", frozen)]
pub struct PyModel {
    /// The model.
    pub model: Arc<Model>,
    /// Its definition, as the file schema holds it.
    pub input: ModelInput,
    /// The analyses, in order.
    pub plan: Vec<AnalysisSettings>,
    /// The file it was read from, if any.
    pub path: Option<PathBuf>,
}

/// The message of a model file error, and its problems one by one.
fn file_error(py: Python<'_>, e: ModelFileError) -> PyErr {
    let pairs = match &e {
        ModelFileError::Invalid { errors, .. } => errors::pairs(errors),
        ModelFileError::Parse { messages, path } => messages
            .iter()
            .map(|m| (path.display().to_string(), m.clone()))
            .collect(),
        ModelFileError::Read { path, source } => {
            vec![(path.display().to_string(), source.to_string())]
        }
    };
    errors::model_error(py, e.to_string(), pairs)
}

impl PyModel {
    /// Validates `input` (read from `path`, if any).
    pub fn from_input(py: Python<'_>, input: ModelInput, path: Option<PathBuf>) -> PyResult<Self> {
        let invalid = |errors: unfold::model::ModelErrors| match &path {
            Some(p) => file_error(
                py,
                ModelFileError::Invalid {
                    path: p.clone(),
                    errors,
                },
            ),
            None => errors::model_error(py, errors.to_string(), errors::pairs(&errors)),
        };
        let model = Model::from_input(&input).map_err(invalid)?;
        let plan = input.analyses().map_err(invalid)?;
        Ok(Self {
            model: Arc::new(model),
            input,
            plan,
            path,
        })
    }

    /// The name of the model in messages and in `summary.json`: its file,
    /// or its title.
    fn label(&self) -> String {
        match &self.path {
            Some(p) => p.display().to_string(),
            None => self.model.title.clone(),
        }
    }
}

/// Reads and validates a model file (docs/model-format.md).
#[pyfunction]
pub fn load_model(py: Python<'_>, path: PathBuf) -> PyResult<PyModel> {
    let file = py.detach(|| read_model(&path));
    let file = file.map_err(|e| file_error(py, e))?;
    Ok(PyModel {
        model: file.model,
        input: file.input,
        plan: file.analyses,
        path: Some(path),
    })
}

/// Reads and validates model-file text (TOML); `name` names it in the
/// messages.
#[pyfunction]
#[pyo3(signature = (text, name="model.toml"))]
pub fn model_from_toml(py: Python<'_>, text: &str, name: &str) -> PyResult<PyModel> {
    let input = parse_model(text, Path::new(name)).map_err(|e| file_error(py, e))?;
    PyModel::from_input(py, input, None)
}

/// Validates a dictionary of the file schema (as `Model.to_dict` gives
/// it).
#[pyfunction]
pub fn model_from_dict(py: Python<'_>, dict: &Bound<'_, PyDict>) -> PyResult<PyModel> {
    let input = builder::from_dict(py, dict)?;
    PyModel::from_input(py, input, None)
}

/// An analysis of the plan, ready to run.
enum Planned {
    Static(Box<StaticAnalysis>),
    Dynamic(Box<DynamicAnalysis>),
    Modal(Box<ModalAnalysis>),
}

/// Why a run stopped early.
enum Failure {
    /// Invalid input (`unfold run` exits with code 2).
    Input(String),
    /// An analysis failed (exit code 1).
    Analysis(String),
    /// Result files could not be written.
    Output(String),
}

/// Sets the velocities and accelerations of `state` to zero (an
/// equilibrium after a motion is at rest), as `unfold run` does.
fn bring_to_rest(state: &mut State) {
    for v in [
        &mut state.velocity,
        &mut state.acceleration,
        &mut state.pseudo_acceleration,
    ] {
        v.fill([0.0; 6]);
    }
    for v in [
        &mut state.coordinate_rates,
        &mut state.coordinate_accelerations,
        &mut state.coordinate_pseudo_accelerations,
    ] {
        v.fill(0.0);
    }
}

/// Whether a dynamic analysis's error is invalid input (exit code 2 of
/// `unfold run`).
fn dynamic_input_error(error: &DynamicError) -> bool {
    matches!(
        error,
        DynamicError::InconsistentVelocity { .. }
            | DynamicError::NoMass
            | DynamicError::StartsBeyondLimit { .. }
            | DynamicError::Initial {
                failure: NewtonFailure::Singular { .. },
                ..
            }
    )
}

/// What a run returns from the thread without the GIL.
struct Outcome {
    recorded: Recorded,
    peaks: unfold::io::peaks::PeakLoads,
    state: State,
    status: &'static str,
    failure: Option<Failure>,
    interrupted: Option<Interrupted>,
    python_error: Option<PyErr>,
    wall_time: f64,
    analyses: Vec<AnalysisEnd>,
}

impl PyModel {
    /// Runs the plan (see [`PyModel::run`]) without the GIL.
    fn run_plan(
        &self,
        out: Option<&Path>,
        callback: Option<&Callback>,
        keep: &(dyn Fn(ElementKind) -> bool + Sync),
    ) -> Outcome {
        let started = std::time::Instant::now();
        let model = &self.model;
        let plan = &self.plan;
        let label = self.label();
        let mut recorded = Recorded::new(model, keep);
        let fail = |failure: Failure, recorded: Recorded| Outcome {
            recorded,
            peaks: unfold::io::peaks::PeakLoads::of(model),
            state: model.initial_state(),
            status: "rejected",
            failure: Some(failure),
            interrupted: None,
            python_error: None,
            wall_time: started.elapsed().as_secs_f64(),
            analyses: Vec::new(),
        };
        // the start-of-run checks of `unfold run` (those of `unfold
        // check`), before any result file
        let first_static = plan.first().and_then(|a| a.as_static());
        let checked = first_static.map(|first| preflight::check(model, first));
        if let (Some(Err(e)), Some(first)) = (&checked, first_static) {
            let message = format!("{label}: {e}");
            if let Some(dir) = out {
                let analysis = StaticAnalysis::new(model.clone(), first.clone());
                let _ = write_rejected(
                    dir,
                    Summary::start(&label, model, &analysis, plan),
                    &e.to_string(),
                    None,
                );
            }
            recorded
                .warnings
                .extend(model.warnings.iter().map(|w| w.to_string()));
            return fail(Failure::Input(message), recorded);
        }
        let first_motion = plan
            .iter()
            .find(|a| a.as_modal().is_none())
            .and_then(|a| a.as_dynamic());
        if let Some(settings) = first_motion {
            if let Err(e) = preflight::check_motion(model, settings) {
                if dynamic_input_error(&e) {
                    let bare = format!(
                        "dynamic analysis at t = 0: {}",
                        dynamic_error_message(model, &model.initial_state(), &e)
                    );
                    let message = format!("{label}: {bare}");
                    if let Some(dir) = out {
                        let analysis = DynamicAnalysis::new(model.clone(), settings.clone());
                        let end_time = plan.last().map_or(settings.end_time, |a| a.end_time());
                        let summary = Summary::start_with(
                            &label,
                            model,
                            analysis.n_equations(),
                            analysis.nnz(),
                            end_time,
                        );
                        let _ = write_rejected(dir, summary, &bare, None);
                    }
                    return fail(Failure::Input(message), recorded);
                }
            }
        }
        let after_motion: Vec<bool> = (0..plan.len())
            .map(|k| plan[..k].iter().any(|a| a.as_dynamic().is_some()))
            .collect();
        let mut analyses = plan.iter().filter_map(|a| {
            if let Some(s) = a.as_static() {
                Some(Planned::Static(Box::new(StaticAnalysis::new(
                    model.clone(),
                    s.clone(),
                ))))
            } else if let Some(d) = a.as_dynamic() {
                Some(Planned::Dynamic(Box::new(DynamicAnalysis::new(
                    model.clone(),
                    d.clone(),
                ))))
            } else {
                a.as_modal()
                    .map(|m| Planned::Modal(Box::new(ModalAnalysis::new(model.clone(), m.clone()))))
            }
        });
        let Some(first_planned) = analyses.next() else {
            return fail(
                Failure::Input(format!(
                    "{label}: an analysis of this model is not one this version runs"
                )),
                recorded,
            );
        };
        let stop = StopRequest::new();
        let recorder = match out {
            None => None,
            Some(dir) => {
                let created = match &first_planned {
                    Planned::Static(a) => Recorder::create_sequence(dir, &label, a, plan, Silent),
                    Planned::Dynamic(a) => {
                        Recorder::create_dynamic_first(dir, &label, a, plan, Silent)
                    }
                    Planned::Modal(a) => Recorder::create_modal_first(dir, &label, a, plan, Silent),
                };
                match created {
                    Ok(r) => Some(
                        r.with_stop(&stop)
                            .with_restart(RestartWriter::new(dir, &self.input), 0),
                    ),
                    Err(e) => {
                        return fail(
                            Failure::Output(format!("cannot write results: {e}")),
                            recorded,
                        )
                    }
                }
            }
        };
        let end_time = plan.last().map_or(1.0, |a| a.end_time());
        let mut observer = PyObserver::new(recorded, model, recorder, stop, callback, end_time);
        let mut state = model.initial_state();
        let start = state.clone();
        let mut last: Option<AnalysisEnd> = None;
        let mut ends = Vec::new();
        let mut failure = None;
        let mut interrupted = None;
        for (k, planned) in std::iter::once(first_planned).chain(analyses).enumerate() {
            match planned {
                Planned::Static(mut analysis) => {
                    let kind = if analysis.settings().kinematic {
                        "kinematic"
                    } else {
                        "static"
                    };
                    observer.start_analysis(k, kind);
                    if k > 0 {
                        if let Some(r) = observer.recorder.as_mut() {
                            r.open_static(&analysis, state.time);
                        }
                    }
                    if after_motion[k] {
                        bring_to_rest(&mut state);
                    }
                    let mut outcome = analysis.run(std::mem::take(&mut state), &mut observer);
                    state = std::mem::take(&mut outcome.state);
                    let end = AnalysisEnd::from(&outcome);
                    if let Some(r) = observer.recorder.as_mut() {
                        r.end_analysis(&end);
                    }
                    observer.end_analysis(end.increments);
                    ends.push(end.clone());
                    last = Some(end);
                    if let Some(e) = outcome.error.take() {
                        interrupted = Interrupted::of(&e);
                        if interrupted.is_none() {
                            let message = format!("{label}: {e}");
                            let input = matches!(
                                e,
                                unfold::analysis::statics::StaticError::Initial {
                                    failure: NewtonFailure::Singular { .. },
                                    ..
                                } | unfold::analysis::statics::StaticError::Indeterminate { .. }
                            );
                            failure = Some(if input {
                                Failure::Input(message)
                            } else {
                                Failure::Analysis(message)
                            });
                        }
                        break;
                    }
                }
                Planned::Dynamic(mut analysis) => {
                    observer.start_analysis(k, "dynamic");
                    if k > 0 {
                        if let Some(r) = observer.recorder.as_mut() {
                            r.open_dynamic(&analysis, state.time);
                        }
                    }
                    let mut outcome = analysis.run(std::mem::take(&mut state), &mut observer);
                    state = std::mem::take(&mut outcome.state);
                    let end = AnalysisEnd::from(&outcome);
                    if let Some(r) = observer.recorder.as_mut() {
                        r.end_analysis(&end);
                    }
                    observer.end_analysis(end.increments);
                    ends.push(end.clone());
                    last = Some(end);
                    if let Some(e) = outcome.error.take() {
                        interrupted = Interrupted::of_dynamic(&e);
                        if interrupted.is_none() {
                            let message = format!(
                                "{label}: dynamic analysis at t = {}: {}",
                                format_time(state.time),
                                dynamic_error_message(model, &state, &e)
                            );
                            failure = Some(if dynamic_input_error(&e) {
                                Failure::Input(message)
                            } else {
                                Failure::Analysis(message)
                            });
                        }
                        break;
                    }
                }
                Planned::Modal(mut analysis) => {
                    observer.start_analysis(k, "modal");
                    let mut outcome = analysis.run(std::mem::take(&mut state), &mut observer);
                    if let Some(r) = observer.recorder.as_mut() {
                        if let Err(e) = r.record_modal(None, &analysis, &outcome) {
                            failure = Some(Failure::Output(format!("cannot write results: {e}")));
                        }
                    }
                    observer.modes(k, &outcome);
                    state = std::mem::take(&mut outcome.state);
                    if let Some(e) = outcome.error.take() {
                        let message = format!("{label}: modal analysis at t = {}: {e}", state.time);
                        failure = Some(match e {
                            ModalError::NoMass => Failure::Input(message),
                            _ => Failure::Analysis(message),
                        });
                        break;
                    }
                    if failure.is_some() {
                        break;
                    }
                }
            }
        }
        let PyObserver {
            mut recorded,
            peaks,
            recorder,
            error: python_error,
            ..
        } = observer;
        // bodies that end inside one another (crate docs: model::overlaps)
        let overlaps: Vec<String> = if failure.is_none() && interrupted.is_none() {
            unfold::model::overlaps::overlap_warnings(model, &start, &state)
        } else {
            Vec::new()
        };
        if let Some(mut r) = recorder {
            for w in &overlaps {
                r.outcome_warning(w);
            }
            let report = r.finish_after(last.as_ref(), &state);
            if let (Some(e), None) = (report.output_errors.first(), &failure) {
                failure = Some(Failure::Output(format!("cannot write results: {e}")));
            }
        }
        recorded.warnings.extend(overlaps);
        recorded
            .warnings
            .splice(0..0, model.warnings.iter().map(|w| w.to_string()));
        let status = if interrupted.is_some() {
            "interrupted"
        } else {
            match &failure {
                None => "completed",
                Some(Failure::Input(_)) => "rejected",
                Some(_) => "failed",
            }
        };
        Outcome {
            recorded,
            peaks,
            state,
            status,
            failure,
            interrupted,
            python_error,
            wall_time: started.elapsed().as_secs_f64(),
            analyses: ends,
        }
    }
}

#[pymethods]
impl PyModel {
    /// Runs the model's analyses in order, each from the final state of
    /// the one before, with the GIL released, and returns the `Results`.
    ///
    /// - `out`: a directory to write the result files of `unfold run`
    ///   into (CSV, VTK, `summary.json`, `restart.json`); none if `None`;
    /// - `progress`: called with a `Progress` (time, step, iterations...)
    ///   every `every_steps` converged steps and/or every `every_seconds`
    ///   of wall time (every step if neither is given), and at the first;
    /// - `elements`: the kinds of element whose results are kept in memory
    ///   (`["joint", "latch"]`; all if `None`, none if `[]`);
    /// - `check`: raise `ModelError` / `AnalysisError` if the run stops
    ///   early (the exception's `results` holds what was reached);
    ///   otherwise return the results with `status` and `error` set.
    ///
    /// A Ctrl-C (or an exception raised by `progress`) stops the run
    /// after the step that has just converged, keeping it: `Interrupted`
    /// (a `KeyboardInterrupt`) is raised, or the callback's exception,
    /// with the results so far in its attribute `results`.
    #[pyo3(signature = (out=None, progress=None, every_steps=None, every_seconds=None, elements=None, check=true))]
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        py: Python<'_>,
        out: Option<PathBuf>,
        progress: Option<Py<PyAny>>,
        every_steps: Option<usize>,
        every_seconds: Option<f64>,
        elements: Option<Vec<String>>,
        check: bool,
    ) -> PyResult<Py<PyResults>> {
        let kinds: Option<Vec<ElementKind>> = match elements {
            None => None,
            Some(names) => Some(
                names
                    .iter()
                    .map(|n| builder::kind_of(n))
                    .collect::<PyResult<_>>()?,
            ),
        };
        let keep = move |k: ElementKind| kinds.as_ref().is_none_or(|ks| ks.contains(&k));
        let callback = progress.map(|function| Callback {
            function,
            every_steps,
            every_seconds,
        });
        let outcome = py.detach(|| self.run_plan(out.as_deref(), callback.as_ref(), &keep));
        let error_message = match &outcome.failure {
            Some(Failure::Input(m) | Failure::Analysis(m) | Failure::Output(m)) => Some(m.clone()),
            None => None,
        };
        let kept = match outcome.recorded.times.last() {
            Some(t) => format!("results up to t = {} are kept", format_time(*t)),
            None => "no result step was kept".to_string(),
        };
        let interrupted_message = outcome.interrupted.map(|i| {
            format!(
                "{}: {i} at t = {}; {kept}",
                self.label(),
                format_time(outcome.state.time)
            )
        });
        let results = PyResults::new(
            self.model.clone(),
            outcome.recorded,
            outcome.peaks,
            outcome.state,
            outcome.status,
            error_message.clone().or(interrupted_message.clone()),
            outcome.wall_time,
            outcome.analyses,
            out,
        );
        let results = Py::new(py, results)?;
        if let Some(e) = outcome.python_error {
            let err = if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                let i = errors::Interrupted::new_err(
                    interrupted_message.unwrap_or_else(|| "interrupted".into()),
                );
                i.set_cause(py, Some(e));
                i
            } else {
                e
            };
            err.value(py).setattr("results", results.clone_ref(py))?;
            return Err(err);
        }
        // a Ctrl-C that came after the run's last look at the signals (a
        // run shorter than SIGNAL_INTERVAL, or during its last step) would
        // otherwise surface as a bare KeyboardInterrupt at the next Python
        // line, losing the results: it is the same `Interrupted`, with the
        // results complete
        if let Err(e) = py.check_signals() {
            let err = if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                let i = errors::Interrupted::new_err(format!(
                    "{}: interrupted after its last step; the results are complete ({kept})",
                    self.label()
                ));
                i.set_cause(py, Some(e));
                i
            } else {
                e
            };
            err.value(py).setattr("results", results.clone_ref(py))?;
            return Err(err);
        }
        if let Some(message) = interrupted_message {
            let err = errors::Interrupted::new_err(message);
            err.value(py).setattr("results", results.clone_ref(py))?;
            return Err(err);
        }
        if check {
            let err = match outcome.failure {
                Some(Failure::Input(m)) => Some(errors::model_error(
                    py,
                    m.clone(),
                    vec![("model".into(), m)],
                )),
                Some(Failure::Analysis(m)) => Some(AnalysisError::new_err(m)),
                Some(Failure::Output(m)) => Some(OutputError::new_err(m)),
                None => None,
            };
            if let Some(err) = err {
                err.value(py).setattr("results", results.clone_ref(py))?;
                return Err(err);
            }
        }
        Ok(results)
    }

    /// The start-of-run checks of `unfold check` (a mechanism in statics,
    /// an undriven kinematic analysis, initial velocities that the joints
    /// forbid): `None`, or a `ModelError` with the message of `unfold
    /// check`.
    fn check(&self, py: Python<'_>) -> PyResult<()> {
        let model = self.model.clone();
        let plan = self.plan.clone();
        let label = self.label();
        let result: Result<(), String> = py.detach(move || {
            if let Some(first) = plan.first().and_then(|a| a.as_static()) {
                preflight::check(&model, first).map_err(|e| format!("{label}: {e}"))?;
            }
            let motion = plan
                .iter()
                .find(|a| a.as_modal().is_none())
                .and_then(|a| a.as_dynamic());
            if let Some(settings) = motion {
                preflight::check_motion(&model, settings).map_err(|e| {
                    format!(
                        "{label}: dynamic analysis at t = 0: {}",
                        dynamic_error_message(&model, &model.initial_state(), &e)
                    )
                })?;
            }
            Ok(())
        });
        result.map_err(|m| errors::model_error(py, m.clone(), vec![("model".into(), m)]))
    }

    /// The title.
    #[getter]
    fn title(&self) -> String {
        self.model.title.clone()
    }

    /// The file it was read from, if any.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// Number of nodes.
    #[getter]
    fn n_nodes(&self) -> usize {
        self.model.n_nodes()
    }

    /// The node ids, in the order of the results' node axis.
    #[getter]
    fn node_ids(&self) -> Vec<u64> {
        self.model.node_ids.clone()
    }

    /// The reference positions of the nodes (nodes × 3).
    #[getter]
    fn reference_positions<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let rows: Vec<Vec<f64>> = self
            .model
            .reference_x
            .iter()
            .map(|x| vec![x.x, x.y, x.z])
            .collect();
        numpy::PyArray2::from_vec2(py, &rows).expect("rows of 3")
    }

    /// The elements: `(kind, id)` in the model's order.
    #[getter]
    fn elements(&self) -> Vec<(String, u64)> {
        self.model
            .elements
            .iter()
            .map(|e| (builder::kind_name(e.kind()), e.id()))
            .collect()
    }

    /// The analyses of the sequence: their types, in order.
    #[getter]
    fn analyses(&self) -> Vec<&'static str> {
        self.plan.iter().map(|a| a.name()).collect()
    }

    /// The model's warnings (input valid but probably not meant).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.model.warnings.iter().map(|w| w.to_string()).collect()
    }

    /// The model's size in one line, as `unfold run` prints it.
    fn describe(&self) -> String {
        unfold::io::run::describe(&self.model)
    }

    /// The model file (TOML).
    fn to_toml(&self) -> PyResult<String> {
        self.input
            .to_toml()
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The model definition as a dictionary of the file schema; change
    /// it and make a model of it again with `unfold.model_from_dict`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        builder::to_dict(py, &self.input)
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let f = py.import("unfold")?.getattr("model_from_toml")?;
        Ok((f, (self.to_toml()?, self.label())))
    }

    fn __repr__(&self) -> String {
        format!("Model({:?}: {})", self.label(), self.describe())
    }
}

/// Adds the class and functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_class::<observe::Progress>()?;
    m.add_function(wrap_pyfunction!(load_model, m)?)?;
    m.add_function(wrap_pyfunction!(model_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(model_from_dict, m)?)?;
    Ok(())
}
