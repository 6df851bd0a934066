//! What a run from Python keeps and how it is steered: an [`Observer`]
//! that records the output steps in memory ([`Recorded`]), passes every
//! report on to the result files' [`Recorder`] when the run writes them,
//! calls the progress callback and looks at Python's signals.
//!
//! The analysis runs with the GIL released. The observer takes the GIL
//! back only when the progress callback is due (every `every_steps`
//! converged steps or `every_seconds` of wall time) or, without one, at
//! most every [`SIGNAL_INTERVAL`], to run Python's signal handlers
//! (`Python::check_signals`): a Ctrl-C then raises `KeyboardInterrupt`
//! there. An exception from the callback or from the signal handlers
//! stops the run as `unfold run` stops on SIGINT (src/io/run.rs): the
//! step that has just converged is kept (written as an output step into
//! the result files, recorded in memory), then the analysis stops with
//! an [`Interrupted`] error and the run's record says `interrupted`.

use std::io;
use std::time::{Duration, Instant};

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

use unfold::analysis::{
    ContactInfo, Continuation, CutbackInfo, Energies, EventInfo, IncrementInfo, IterationInfo,
    LockInfo, Observer, WarningInfo,
};
use unfold::elements::{ElementKind, Need};
use unfold::io::peaks::PeakLoads;
use unfold::io::run::{Interrupted, Recorder, StopRequest};
use unfold::model::{Id, Model};
use unfold::state::State;

/// How often, at most, a run without a progress callback looks at
/// Python's signals: a Ctrl-C stops it within this time after the step
/// it interrupts, and a run of short steps does not take the GIL at each.
pub const SIGNAL_INTERVAL: Duration = Duration::from_millis(50);

/// The history of one element over the output steps.
#[derive(Clone, Debug)]
pub struct ElementHistory {
    /// Its kind.
    pub kind: ElementKind,
    /// Its id.
    pub id: Id,
    /// Its index among the model's elements.
    pub index: usize,
    /// A joint's type (`revolute`...), as the column `type` of
    /// `joints.csv`; `None` for other elements.
    pub joint_type: Option<&'static str>,
    /// The names of its results (columns of its result file: a joint's
    /// coordinates by name, `angle`, `slide`..., then its loads).
    pub names: &'static [&'static str],
    /// Steps × names, by rows.
    pub values: Vec<f64>,
}

/// An event of a dynamic analysis, as a row of `events.csv`.
#[derive(Clone, Debug)]
pub struct EventRecord {
    /// Increment (time step), numbered across the run.
    pub increment: usize,
    /// Time.
    pub time: f64,
    /// The latch, stop or contact.
    pub element: Id,
    /// `latch`, `stop` or `contact`.
    pub element_kind: &'static str,
    /// What happened (`lock`, `unlatch`, `engage`, `impact`, `contact`...).
    pub kind: &'static str,
    /// The joint (if any).
    pub joint: Option<Id>,
    /// The coordinate at the event.
    pub coordinate: f64,
    /// Rate before.
    pub rate_before: f64,
    /// Rate after.
    pub rate_after: f64,
    /// Impulse.
    pub impulse: f64,
    /// Energy lost.
    pub energy_lost: f64,
}

/// The natural modes of a modal analysis.
#[derive(Clone, Debug)]
pub struct ModesRecord {
    /// The analysis (index in the sequence).
    pub analysis: usize,
    /// The load parameter of the state it linearised about.
    pub time: f64,
    /// Frequencies (Hz).
    pub frequencies: Vec<f64>,
    /// `ω²` (rad²/s²).
    pub omega_squared: Vec<f64>,
    /// Generalised masses.
    pub generalized_masses: Vec<f64>,
    /// Effective masses along x, y, z.
    pub effective_masses: Vec<[f64; 3]>,
    /// Shapes: modes × nodes × 6 (translations, then rotations).
    pub shapes: Vec<f64>,
}

/// What a run keeps in memory: its output steps and events.
#[derive(Clone, Debug, Default)]
pub struct Recorded {
    /// Number of nodes.
    pub nodes: usize,
    /// Node ids, in the model's order.
    pub node_ids: Vec<Id>,
    /// Load parameter (time) of each output step.
    pub times: Vec<f64>,
    /// Increment of each output step, numbered across the run.
    pub increments: Vec<usize>,
    /// Index of the analysis of each output step.
    pub analyses: Vec<usize>,
    /// Newton iterations of each output step.
    pub iterations: Vec<usize>,
    /// Step size of each output step.
    pub step_sizes: Vec<f64>,
    /// Positions: steps × nodes × 3.
    pub positions: Vec<f64>,
    /// Orientations as unit quaternions `(w, x, y, z)`: steps × nodes × 4.
    pub quaternions: Vec<f64>,
    /// Rotation vectors (global frame): steps × nodes × 3.
    pub rotations: Vec<f64>,
    /// Velocities and angular velocities (global): steps × nodes × 6
    /// (zero at the steps of static analyses).
    pub velocities: Vec<f64>,
    /// Energies at each output step: kinetic, strain, gravity, spring,
    /// external work, dissipated, balance error, hinge-law work (the last
    /// four NaN at the steps of static analyses).
    pub energies: Vec<[f64; 8]>,
    /// The elements kept.
    pub elements: Vec<ElementHistory>,
    /// The events of dynamic analyses.
    pub events: Vec<EventRecord>,
    /// The modes of modal analyses.
    pub modes: Vec<ModesRecord>,
    /// The remarks of the analyses (redundant constraints removed...).
    pub notes: Vec<String>,
    /// The warnings of the analyses.
    pub warnings: Vec<String>,
}

impl Recorded {
    /// An empty record of `model`, keeping the elements whose kind
    /// `keep` accepts.
    pub fn new(model: &Model, keep: impl Fn(ElementKind) -> bool) -> Self {
        let elements = model
            .elements
            .iter()
            .enumerate()
            .filter(|(_, e)| keep(e.kind()) && !e.result_names().is_empty())
            .map(|(index, e)| ElementHistory {
                kind: e.kind(),
                id: e.id(),
                index,
                joint_type: e.as_joint().map(|j| j.joint_type().name()),
                names: e.result_names(),
                values: Vec::new(),
            })
            .collect();
        Self {
            nodes: model.n_nodes(),
            node_ids: model.node_ids.clone(),
            elements,
            ..Self::default()
        }
    }

    /// Number of output steps.
    pub fn steps(&self) -> usize {
        self.times.len()
    }

    /// Records the output step `info` (numbered across the run) at
    /// `state`, in analysis `analysis`.
    fn record(
        &mut self,
        info: &IncrementInfo,
        analysis: usize,
        model: &Model,
        state: &State,
        dynamic: Option<&Energies>,
    ) {
        self.times.push(info.time);
        self.increments.push(info.increment);
        self.analyses.push(analysis);
        self.iterations.push(info.iterations);
        self.step_sizes.push(info.step);
        for i in 0..model.n_nodes() {
            let x = state.x[i];
            self.positions.extend([x.x, x.y, x.z]);
            let q = state.q[i].quaternion();
            self.quaternions.extend([q.w, q.i, q.j, q.k]);
            let psi = state.q[i].scaled_axis();
            self.rotations.extend([psi.x, psi.y, psi.z]);
            let (v, w) = match dynamic {
                Some(_) => {
                    let v = state.velocity.get(i).copied().unwrap_or([0.0; 6]);
                    let w = state.q[i] * unfold::so3::Vec3::new(v[3], v[4], v[5]);
                    ([v[0], v[1], v[2]], [w.x, w.y, w.z])
                }
                None => ([0.0; 3], [0.0; 3]),
            };
            self.velocities.extend(v);
            self.velocities.extend(w);
        }
        self.energies.push(match dynamic {
            Some(e) => [
                e.kinetic,
                e.strain,
                e.gravity,
                e.spring,
                e.external_work,
                e.dissipated,
                e.balance_error,
                e.hinge_law_work,
            ],
            None => {
                let e = unfold::analysis::energy::energies(model, state);
                [
                    0.0,
                    e.strain,
                    e.gravity,
                    e.spring,
                    f64::NAN,
                    f64::NAN,
                    f64::NAN,
                    f64::NAN,
                ]
            }
        });
        let ctx = model.context(info.time, Need::RESIDUAL);
        for h in &mut self.elements {
            let start = h.values.len();
            h.values.resize(start + h.names.len(), 0.0);
            model.elements[h.index].results(&ctx, state, &mut h.values[start..]);
        }
    }
}

/// The progress of a run, as the callback receives it.
#[pyclass(name = "Progress", module = "unfold", frozen, get_all)]
#[derive(Clone, Debug)]
pub struct Progress {
    /// Load parameter (time) reached.
    pub time: f64,
    /// Converged increments (time steps) so far, numbered across the run.
    pub step: usize,
    /// Newton iterations of the last step.
    pub iterations: usize,
    /// Size of the last step.
    pub step_size: f64,
    /// The analysis running (index in the sequence, from 0).
    pub analysis: usize,
    /// Its type (`static`, `kinematic`, `dynamic`).
    pub analysis_type: &'static str,
    /// The end time of the run's last analysis.
    pub end_time: f64,
    /// Wall time since the run started (s).
    pub wall_time: f64,
}

#[pymethods]
impl Progress {
    fn __repr__(&self) -> String {
        format!(
            "Progress(time={}, step={}, iterations={}, analysis={} ({}), wall_time={:.3})",
            self.time,
            self.step,
            self.iterations,
            self.analysis,
            self.analysis_type,
            self.wall_time
        )
    }
}

/// The progress callback and when to call it.
pub struct Callback {
    /// The callable.
    pub function: Py<PyAny>,
    /// Every this many converged steps (if given).
    pub every_steps: Option<usize>,
    /// Every this much wall time (if given).
    pub every_seconds: Option<f64>,
}

/// The observer of a run from Python (see the module documentation).
pub struct PyObserver<'a> {
    /// What is kept.
    pub recorded: Recorded,
    /// Largest loads of latches, stops and contacts.
    pub peaks: PeakLoads,
    /// The result files, if written.
    pub recorder: Option<Recorder>,
    /// The stop request shared with the recorder.
    pub stop: StopRequest,
    /// The exception that stopped the run (from the callback or a signal).
    pub error: Option<PyErr>,
    callback: Option<&'a Callback>,
    /// Index of the analysis running, its type, and whether a step was
    /// written before it.
    analysis: usize,
    kind: &'static str,
    /// Increments of the analyses before the running one.
    offset: usize,
    end_time: f64,
    energies: Option<Energies>,
    started: Instant,
    last_python: Instant,
    last_call: Option<Instant>,
    steps_since_call: usize,
}

impl<'a> PyObserver<'a> {
    /// An observer of a run of `model` to `end_time`.
    pub fn new(
        recorded: Recorded,
        model: &Model,
        recorder: Option<Recorder>,
        stop: StopRequest,
        callback: Option<&'a Callback>,
        end_time: f64,
    ) -> Self {
        Self {
            recorded,
            peaks: PeakLoads::of(model),
            recorder,
            stop,
            error: None,
            callback,
            analysis: 0,
            kind: "static",
            offset: 0,
            end_time,
            energies: None,
            started: Instant::now(),
            last_python: Instant::now(),
            last_call: None,
            steps_since_call: 0,
        }
    }

    /// The start of analysis `index` of type `kind`.
    pub fn start_analysis(&mut self, index: usize, kind: &'static str) {
        self.analysis = index;
        self.kind = kind;
        self.energies = None;
    }

    /// The end of the running analysis, after `increments` converged
    /// increments (steps).
    pub fn end_analysis(&mut self, increments: usize) {
        self.offset += increments;
    }

    /// The modes of modal analysis `analysis`.
    pub fn modes(&mut self, analysis: usize, outcome: &unfold::analysis::ModalOutcome) {
        let modes = &outcome.modes;
        self.recorded.modes.push(ModesRecord {
            analysis,
            time: outcome.time,
            frequencies: modes.iter().map(|m| m.frequency).collect(),
            omega_squared: modes.iter().map(|m| m.omega_squared).collect(),
            generalized_masses: modes.iter().map(|m| m.generalized_mass).collect(),
            effective_masses: modes.iter().map(|m| m.effective_mass).collect(),
            shapes: modes
                .iter()
                .flat_map(|m| m.shape.iter().flat_map(|s| s.iter().copied()))
                .collect(),
        });
    }

    /// Calls the progress callback if due, and looks at the signals if
    /// due; asks the run to stop on an exception.
    fn python(&mut self, info: &IncrementInfo) {
        self.steps_since_call += 1;
        let now = Instant::now();
        let call = self.callback.filter(|c| {
            let steps = c
                .every_steps
                .is_some_and(|n| self.steps_since_call >= n.max(1));
            let seconds = c.every_seconds.is_some_and(|s| {
                self.last_call
                    .is_none_or(|t| now.duration_since(t).as_secs_f64() >= s)
            });
            let first = self.last_call.is_none();
            first || steps || seconds || (c.every_steps.is_none() && c.every_seconds.is_none())
        });
        if call.is_none() && now.duration_since(self.last_python) < SIGNAL_INTERVAL {
            return;
        }
        self.last_python = now;
        let progress = Progress {
            time: info.time,
            step: info.increment + self.offset,
            iterations: info.iterations,
            step_size: info.step,
            analysis: self.analysis,
            analysis_type: self.kind,
            end_time: self.end_time,
            wall_time: self.started.elapsed().as_secs_f64(),
        };
        let result = Python::attach(|py| -> PyResult<()> {
            py.check_signals()?;
            if let Some(c) = call {
                c.function.call1(py, (progress,))?;
            }
            Ok(())
        });
        if call.is_some() {
            self.last_call = Some(now);
            self.steps_since_call = 0;
        }
        if let Err(e) = result {
            let signal = Python::attach(|py| e.is_instance_of::<PyKeyboardInterrupt>(py));
            self.stop.request(signal.then_some(2));
            if self.error.is_none() {
                self.error = Some(e);
            }
        }
    }
}

impl Observer for PyObserver<'_> {
    fn iteration(&mut self, info: &IterationInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.iteration(info);
        }
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> io::Result<()> {
        // the callback and the signals first: a stop they ask for makes
        // the recorder write this step
        self.python(info);
        let written = match self.recorder.as_mut() {
            Some(r) => r.increment(info, model, state, residual),
            None => Ok(()),
        };
        let global = IncrementInfo {
            increment: info.increment + self.offset,
            ..info.clone()
        };
        self.peaks.sample(model, state, global.increment);
        let stopping = self.stop.requested();
        // a later analysis starts at the final state of the one before,
        // recorded already
        let restart = info.increment == 0 && self.analysis > 0 && self.recorded.steps() > 0;
        if (info.output || stopping.is_some()) && !restart {
            let dynamic = (self.kind == "dynamic").then(|| self.energies.unwrap_or_default());
            self.recorded
                .record(&global, self.analysis, model, state, dynamic.as_ref());
        }
        written?;
        match (stopping, &self.recorder) {
            (Some(i), None) => Err(io::Error::other(i)),
            _ => Ok(()),
        }
    }

    fn energies(&mut self, energies: &Energies) {
        self.energies = Some(*energies);
        if let Some(r) = self.recorder.as_mut() {
            r.energies(energies);
        }
    }

    fn continuation(&mut self, state: &State, continuation: &Continuation) -> io::Result<()> {
        match self.recorder.as_mut() {
            Some(r) => r.continuation(state, continuation),
            None => Ok(()),
        }
    }

    fn cutback(&mut self, info: &CutbackInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.cutback(info);
        }
    }

    fn event(&mut self, info: &EventInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.event(info);
        }
    }

    fn lock(&mut self, info: &LockInfo) {
        self.peaks.unlatched(info, info.increment + self.offset);
        self.recorded.events.push(latch_event(info, self.offset));
        if let Some(r) = self.recorder.as_mut() {
            r.lock(info);
        }
    }

    fn band_crossing(&mut self, info: &LockInfo) {
        self.recorded.events.push(latch_event(info, self.offset));
        if let Some(r) = self.recorder.as_mut() {
            r.band_crossing(info);
        }
    }

    fn contact(&mut self, info: &ContactInfo) {
        self.recorded.events.push(EventRecord {
            increment: info.increment + self.offset,
            time: info.time,
            element: info.stop,
            element_kind: if info.joint.is_some() {
                "stop"
            } else {
                "contact"
            },
            kind: info.kind.name(),
            joint: info.joint,
            coordinate: info.coordinate,
            rate_before: info.rate_before,
            rate_after: info.rate_after,
            impulse: info.impulse,
            energy_lost: info.energy_lost,
        });
        if let Some(r) = self.recorder.as_mut() {
            r.contact(info);
        }
    }

    fn note(&mut self, text: &str) {
        self.recorded.notes.push(text.to_string());
        if let Some(r) = self.recorder.as_mut() {
            r.note(text);
        }
    }

    fn warning(&mut self, info: &WarningInfo) {
        self.recorded.warnings.push(info.message.clone());
        if let Some(r) = self.recorder.as_mut() {
            r.warning(info);
        }
    }
}

/// A latch's event as a row.
fn latch_event(info: &LockInfo, offset: usize) -> EventRecord {
    EventRecord {
        increment: info.increment + offset,
        time: info.time,
        element: info.latch,
        element_kind: "latch",
        kind: info.kind.name(),
        joint: Some(info.joint),
        coordinate: info.coordinate,
        rate_before: info.rate_before,
        rate_after: info.rate_after,
        impulse: info.impulse,
        energy_lost: info.energy_lost,
    }
}

/// Whether `error` (an analysis's output error) is an interruption.
pub fn interrupted(error: &io::Error) -> Option<Interrupted> {
    error.get_ref()?.downcast_ref::<Interrupted>().copied()
}
