//! The results of a run (`unfold.Results`), as numpy arrays with their
//! times: every output step of the run (the steps the result files hold,
//! docs/results.md), its events, the largest loads of its latches, stops
//! and contacts, and the modes of its modal analyses. Units are the
//! model's; angles are in radians.

use std::path::PathBuf;
use std::sync::Arc;

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::{PyKeyError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use unfold::elements::ElementKind;
use unfold::io::peaks::PeakLoads;
use unfold::io::results::AnalysisEnd;
use unfold::model::{Id, Model};
use unfold::state::State;

use crate::builder::{self, ElementLike, PyNodeHandle};
use crate::observe::{ElementHistory, Recorded};

/// The names of the energies, in the order of [`Recorded::energies`].
pub const ENERGY_NAMES: [&str; 8] = [
    "kinetic",
    "strain",
    "gravity",
    "spring",
    "external_work",
    "dissipated",
    "balance_error",
    "hinge_law_work",
];

/// A `steps × a × b` array from its rows.
fn array3<'py>(py: Python<'py>, values: &[f64], a: usize, b: usize) -> Bound<'py, PyArray3<f64>> {
    let steps = values.len().checked_div(a * b).unwrap_or(0);
    numpy::ndarray::Array3::from_shape_vec((steps, a, b), values.to_vec())
        .expect("steps × a × b values")
        .into_pyarray(py)
}

/// A `rows × cols` array from its rows.
fn array2<'py>(py: Python<'py>, values: &[f64], cols: usize) -> Bound<'py, PyArray2<f64>> {
    let rows = values.len().checked_div(cols).unwrap_or(0);
    numpy::ndarray::Array2::from_shape_vec((rows, cols), values.to_vec())
        .expect("rows × cols values")
        .into_pyarray(py)
}

/// The history of one element over the output steps: `names` (the
/// columns of its result file, docs/results.md) and `values`
/// (steps × names); `history["Fz"]` is one column, `history["angle"]` a
/// joint's angle.
#[pyclass(name = "ElementHistory", module = "unfold", frozen)]
pub struct PyElementHistory {
    history: ElementHistory,
    steps: usize,
}

#[pymethods]
impl PyElementHistory {
    /// The kind of element (`joint`, `latch`...).
    #[getter]
    fn kind(&self) -> String {
        builder::kind_name(self.history.kind)
    }

    /// Its id.
    #[getter]
    fn id(&self) -> u64 {
        self.history.id
    }

    /// A joint's type (`revolute`, `prismatic`...), as the column `type`
    /// of `joints.csv`; `None` for the other elements.
    #[getter]
    fn joint_type(&self) -> Option<&'static str> {
        self.history.joint_type
    }

    /// The names of its results: those of its columns in its result file
    /// (a joint's own coordinates, `angle`, `slide`, `slide1`, `slide2`,
    /// `angle1`, `angle2` or `s`, then its loads `F1` … `Mz`).
    #[getter]
    fn names(&self) -> Vec<&'static str> {
        self.history.names.to_vec()
    }

    /// Steps × names (NaN for a quantity it does not have at a step, as
    /// the empty cells of its result file: the target of a released
    /// driver).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        array2(py, &self.history.values, self.history.names.len())
    }

    fn __getitem__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.history.names.len();
        let k = self
            .history
            .names
            .iter()
            .position(|x| *x == name)
            .ok_or_else(|| {
                PyKeyError::new_err(format!(
                    "{} {} has no result named {name:?} (it has {})",
                    self.history.kind.name(),
                    self.history.id,
                    self.history.names.join(", ")
                ))
            })?;
        let column: Vec<f64> = (0..self.steps)
            .map(|s| self.history.values[s * n + k])
            .collect();
        Ok(column.into_pyarray(py))
    }

    fn __contains__(&self, name: &str) -> bool {
        self.history.names.contains(&name)
    }

    fn __repr__(&self) -> String {
        let joint_type = self
            .history
            .joint_type
            .map_or(String::new(), |t| format!(" ({t})"));
        format!(
            "ElementHistory({} {}{joint_type}: {} steps of {})",
            self.history.kind.name(),
            self.history.id,
            self.steps,
            self.history.names.join(", ")
        )
    }
}

/// The natural modes of one modal analysis.
#[pyclass(name = "Modes", module = "unfold", frozen)]
pub struct PyModes {
    record: crate::observe::ModesRecord,
    nodes: usize,
}

#[pymethods]
impl PyModes {
    /// The analysis (index in the sequence).
    #[getter]
    fn analysis(&self) -> usize {
        self.record.analysis
    }

    /// The load parameter of the state the modes are about.
    #[getter]
    fn time(&self) -> f64 {
        self.record.time
    }

    /// Frequencies (Hz), increasing.
    #[getter]
    fn frequencies<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.record.frequencies.clone().into_pyarray(py)
    }

    /// `ω²` (rad²/s²).
    #[getter]
    fn omega_squared<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.record.omega_squared.clone().into_pyarray(py)
    }

    /// Generalised masses (1: the shapes are mass-normalised).
    #[getter]
    fn generalized_masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.record.generalized_masses.clone().into_pyarray(py)
    }

    /// Effective masses along x, y, z: modes × 3.
    #[getter]
    fn effective_masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let flat: Vec<f64> = self
            .record
            .effective_masses
            .iter()
            .flatten()
            .copied()
            .collect();
        array2(py, &flat, 3)
    }

    /// Shapes: modes × nodes × 6 (translations, then rotations).
    #[getter]
    fn shapes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        array3(py, &self.record.shapes, self.nodes, 6)
    }

    fn __len__(&self) -> usize {
        self.record.frequencies.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Modes(analysis {}, {} modes, {:?} Hz)",
            self.record.analysis,
            self.record.frequencies.len(),
            &self.record.frequencies[..self.record.frequencies.len().min(4)]
        )
    }
}

/// The results of a run: its output steps as numpy arrays with their
/// times, its events, peak loads and modes (docs/python.md, "Results").
#[pyclass(name = "Results", module = "unfold", frozen)]
pub struct PyResults {
    model: Arc<Model>,
    recorded: Recorded,
    peaks: PeakLoads,
    state: State,
    status: &'static str,
    error: Option<String>,
    wall_time: f64,
    analyses: Vec<AnalysisEnd>,
    out: Option<PathBuf>,
}

impl PyResults {
    /// The results of a run.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        model: Arc<Model>,
        recorded: Recorded,
        peaks: PeakLoads,
        state: State,
        status: &'static str,
        error: Option<String>,
        wall_time: f64,
        analyses: Vec<AnalysisEnd>,
        out: Option<PathBuf>,
    ) -> Self {
        Self {
            model,
            recorded,
            peaks,
            state,
            status,
            error,
            wall_time,
            analyses,
            out,
        }
    }

    /// The kind and id of an element handle, or of `(kind, id)`.
    fn key(&self, element: &Bound<'_, PyAny>) -> PyResult<(ElementKind, Id)> {
        macro_rules! handles {
            ($($t:ty),*) => {
                $(if let Ok(h) = element.extract::<$t>() { return Ok(h.key()); })*
            };
        }
        handles!(
            builder::PyBeamHandle,
            builder::PyRigidBodyHandle,
            builder::PyPointMassHandle,
            builder::PySpringHandle,
            builder::PyLoadHandle,
            builder::PyJointHandle,
            builder::PyJointSpringHandle,
            builder::PyHingeLawHandle,
            builder::PyDriverHandle,
            builder::PyLatchHandle,
            builder::PyStopHandle,
            builder::PyContactHandle,
            builder::PyRollingDiscHandle
        );
        if let Ok((kind, id)) = element.extract::<(String, u64)>() {
            return Ok((builder::kind_of(&kind)?, id as Id));
        }
        Err(PyTypeError::new_err(
            "an element: its handle, or (kind, id) such as (\"joint\", 5)",
        ))
    }

    /// The index of node `node` (a handle or an id).
    fn node_index(&self, node: &Bound<'_, PyAny>) -> PyResult<usize> {
        let id = match node.extract::<PyNodeHandle>() {
            Ok(h) => h.0.id(),
            Err(_) => node.extract::<u64>()? as Id,
        };
        self.model
            .node_index(id)
            .ok_or_else(|| PyKeyError::new_err(format!("node {id} is not in the model")))
    }

    fn steps(&self) -> usize {
        self.recorded.steps()
    }
}

#[pymethods]
impl PyResults {
    /// How the run ended: `completed`, `failed` (an analysis stopped
    /// early), `interrupted` or `rejected` (invalid input).
    #[getter]
    fn status(&self) -> &'static str {
        self.status
    }

    /// Why the run stopped early, as `unfold run` says it; `None` if it
    /// completed.
    #[getter]
    fn error(&self) -> Option<String> {
        self.error.clone()
    }

    /// Wall time of the run (s).
    #[getter]
    fn wall_time(&self) -> f64 {
        self.wall_time
    }

    /// The directory of the result files, if written.
    #[getter]
    fn out(&self) -> Option<PathBuf> {
        self.out.clone()
    }

    /// Load parameter (time) of each output step.
    #[getter]
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.recorded.times.clone().into_pyarray(py)
    }

    /// Increment (time step) of each output step, numbered across the run.
    #[getter]
    fn increments<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let v: Vec<u64> = self.recorded.increments.iter().map(|&i| i as u64).collect();
        v.into_pyarray(py)
    }

    /// The analysis (index in the sequence) of each output step.
    #[getter]
    fn analysis<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let v: Vec<u64> = self.recorded.analyses.iter().map(|&i| i as u64).collect();
        v.into_pyarray(py)
    }

    /// Newton iterations of each output step.
    #[getter]
    fn iterations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let v: Vec<u64> = self.recorded.iterations.iter().map(|&i| i as u64).collect();
        v.into_pyarray(py)
    }

    /// Size of the step (increment) of each output step.
    #[getter]
    fn step_sizes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.recorded.step_sizes.clone().into_pyarray(py)
    }

    /// The node ids, in the order of the node axis of the arrays.
    #[getter]
    fn node_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let v: Vec<u64> = self.recorded.node_ids.clone();
        v.into_pyarray(py)
    }

    /// Node positions: steps × nodes × 3 (global frame).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        array3(py, &self.recorded.positions, self.recorded.nodes, 3)
    }

    /// Node displacements from the reference configuration: steps × nodes × 3.
    #[getter]
    fn displacements<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        let n = self.recorded.nodes;
        let mut u = self.recorded.positions.clone();
        for (k, v) in u.iter_mut().enumerate() {
            let x0 = self.model.reference_x[(k / 3) % n];
            *v -= x0[k % 3];
        }
        array3(py, &u, n, 3)
    }

    /// Node orientations as rotation vectors (global frame, rad): steps ×
    /// nodes × 3.
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        array3(py, &self.recorded.rotations, self.recorded.nodes, 3)
    }

    /// Node orientations as unit quaternions `(w, x, y, z)`, material to
    /// global (as `nodes.csv`): steps × nodes × 4.
    #[getter]
    fn quaternions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        array3(py, &self.recorded.quaternions, self.recorded.nodes, 4)
    }

    /// Node velocities and angular velocities (global frame): steps ×
    /// nodes × 6 (zero at the steps of static analyses).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        array3(py, &self.recorded.velocities, self.recorded.nodes, 6)
    }

    /// The energies at each output step, by name (`kinetic`, `strain`,
    /// `gravity`, `spring`, `external_work`, `dissipated`,
    /// `balance_error`, `hinge_law_work`; the last four NaN at the steps
    /// of static analyses), as `energies.csv`.
    #[getter]
    fn energies<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, name) in ENERGY_NAMES.iter().enumerate() {
            let v: Vec<f64> = self.recorded.energies.iter().map(|e| e[k]).collect();
            d.set_item(name, v.into_pyarray(py))?;
        }
        Ok(d)
    }

    /// The history of node `node` (a handle or an id): its positions,
    /// steps × 3.
    fn position<'py>(
        &self,
        py: Python<'py>,
        node: &Bound<'_, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let i = self.node_index(node)?;
        let n = self.recorded.nodes;
        let v: Vec<f64> = (0..self.steps())
            .flat_map(|s| {
                let k = 3 * (s * n + i);
                self.recorded.positions[k..k + 3].to_vec()
            })
            .collect();
        Ok(array2(py, &v, 3))
    }

    /// Positions of the nodes in the final state of the run (nodes × 3),
    /// whatever the output steps.
    #[getter]
    fn final_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let v: Vec<f64> = self.state.x.iter().flat_map(|x| [x.x, x.y, x.z]).collect();
        array2(py, &v, 3)
    }

    /// The time the run reached.
    #[getter]
    fn final_time(&self) -> f64 {
        self.state.time
    }

    /// The elements whose results were kept: `(kind, id)` in the model's
    /// order, of `kind` only if given.
    #[pyo3(signature = (kind=None))]
    fn elements(&self, kind: Option<&str>) -> PyResult<Vec<(String, u64)>> {
        let kind = kind.map(builder::kind_of).transpose()?;
        Ok(self
            .recorded
            .elements
            .iter()
            .filter(|h| kind.is_none_or(|k| h.kind == k))
            .map(|h| (builder::kind_name(h.kind), h.id))
            .collect())
    }

    /// The history of an element (its handle, or `(kind, id)`): its
    /// results at each output step, named as the columns of its result
    /// file (docs/results.md).
    fn element(&self, element: &Bound<'_, PyAny>) -> PyResult<PyElementHistory> {
        let (kind, id) = self.key(element)?;
        let h = self
            .recorded
            .elements
            .iter()
            .find(|h| h.kind == kind && h.id == id)
            .ok_or_else(|| {
                PyKeyError::new_err(format!(
                    "{} {id} has no results kept (not in the model, or left out by `elements`)",
                    builder::kind_name(kind)
                ))
            })?;
        Ok(PyElementHistory {
            history: h.clone(),
            steps: self.steps(),
        })
    }

    /// The results of every element of `kind` kept: `(ids, names,
    /// values)` with values steps × elements × names (NaN where a
    /// quantity is absent: a coordinate the joint does not have), the
    /// names those of the columns of its result file.
    #[allow(clippy::type_complexity)]
    fn table<'py>(
        &self,
        py: Python<'py>,
        kind: &str,
    ) -> PyResult<(Vec<u64>, Vec<&'static str>, Bound<'py, PyArray3<f64>>)> {
        let kind = builder::kind_of(kind)?;
        let hs: Vec<&ElementHistory> = self
            .recorded
            .elements
            .iter()
            .filter(|h| h.kind == kind)
            .collect();
        let names = kind.result_columns(hs.iter().map(|h| h.names));
        let width = names.len();
        let steps = self.steps();
        let mut values = vec![f64::NAN; steps * hs.len() * width];
        for (e, h) in hs.iter().enumerate() {
            let n = h.names.len();
            for s in 0..steps {
                for (k, name) in h.names.iter().enumerate() {
                    let col = names.iter().position(|x| x == name).unwrap_or(k);
                    values[(s * hs.len() + e) * width + col] = h.values[s * n + k];
                }
            }
        }
        let ids = hs.iter().map(|h| h.id).collect();
        Ok((ids, names, array3(py, &values, hs.len(), width)))
    }

    /// The events of the dynamic analyses (as `events.csv`): one
    /// dictionary each with `increment`, `time`, `element_kind`
    /// (`latch`, `stop`, `contact`), `element` (its id), `kind` (`lock`,
    /// `unlatch`, `engage`, `disengage`, `rearm`, `impact`, `contact`,
    /// `release`), `joint`, `coordinate`, `rate_before`, `rate_after`,
    /// `impulse`, `energy_lost`.
    #[getter]
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for e in &self.recorded.events {
            let d = PyDict::new(py);
            d.set_item("increment", e.increment)?;
            d.set_item("time", e.time)?;
            d.set_item("element_kind", e.element_kind)?;
            d.set_item("element", e.element)?;
            d.set_item("kind", e.kind)?;
            d.set_item("joint", e.joint)?;
            d.set_item("coordinate", e.coordinate)?;
            d.set_item("rate_before", e.rate_before)?;
            d.set_item("rate_after", e.rate_after)?;
            d.set_item("impulse", e.impulse)?;
            d.set_item("energy_lost", e.energy_lost)?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The time each latch first locked: `{latch id: time}` (latches that
    /// never locked are absent).
    fn lock_times(&self) -> std::collections::BTreeMap<u64, f64> {
        let mut m = std::collections::BTreeMap::new();
        for e in &self.recorded.events {
            if e.element_kind == "latch" && e.kind == "lock" {
                m.entry(e.element).or_insert(e.time);
            }
        }
        m
    }

    /// The largest load of each latch, stop and contact over the run, as
    /// `summary.json` gives them (docs/results.md, "Peak loads"):
    /// `{"latches": [...], "stops": [...], "contacts": [...]}`, each entry
    /// a dictionary with `peak_load`, `peak_time`, `peak_increment`...
    #[getter]
    fn peaks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let err =
            |e: pythonize::PythonizeError| pyo3::exceptions::PyValueError::new_err(e.to_string());
        d.set_item(
            "latches",
            pythonize::pythonize(py, &self.peaks.latches()).map_err(err)?,
        )?;
        d.set_item(
            "stops",
            pythonize::pythonize(py, &self.peaks.stops()).map_err(err)?,
        )?;
        d.set_item(
            "contacts",
            pythonize::pythonize(py, &self.peaks.contacts()).map_err(err)?,
        )?;
        Ok(d)
    }

    /// The modes of the modal analyses, one `Modes` per analysis.
    #[getter]
    fn modes(&self) -> Vec<PyModes> {
        self.recorded
            .modes
            .iter()
            .map(|r| PyModes {
                record: r.clone(),
                nodes: self.recorded.nodes,
            })
            .collect()
    }

    /// The remarks of the analyses (redundant constraints removed...).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.recorded.notes.clone()
    }

    /// The model's and the analyses' warnings.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.recorded.warnings.clone()
    }

    /// What each analysis did: a dictionary each with `time` reached,
    /// `increments`, `iterations`, `wasted_iterations`, `cutbacks`,
    /// `wall_time` and `error`.
    #[getter]
    fn analyses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for a in &self.analyses {
            let d = PyDict::new(py);
            d.set_item("time", a.time)?;
            d.set_item("increments", a.increments)?;
            d.set_item("iterations", a.iterations)?;
            d.set_item("wasted_iterations", a.wasted_iterations)?;
            d.set_item("cutbacks", a.cutbacks)?;
            d.set_item("wall_time", a.wall_time)?;
            d.set_item("error", a.error.clone())?;
            list.append(d)?;
        }
        Ok(list)
    }

    fn __len__(&self) -> usize {
        self.steps()
    }

    fn __repr__(&self) -> String {
        format!(
            "Results({}: {} output steps to t = {}, {} events, {:.3} s)",
            self.status,
            self.steps(),
            unfold::io::run::format_time(self.state.time),
            self.recorded.events.len(),
            self.wall_time
        )
    }
}

/// Adds the classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyResults>()?;
    m.add_class::<PyElementHistory>()?;
    m.add_class::<PyModes>()?;
    Ok(())
}
