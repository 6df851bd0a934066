//! Analyses: algorithms that take a [`crate::model::Model`] (shared,
//! `Arc<Model>`), their settings ([`AnalysisSettings`], beside the model)
//! and a start [`crate::state::State`], and return a sequence of converged
//! states and the final one. A first analysis starts from
//! [`crate::model::Model::initial_state`], a later one from the final state
//! of the one before (a preload, then a deployment, then ...).
//!
//! Every incremental analysis is driven by the one step controller of
//! [`control`]: step sizes, landing on output times and on `end_time`,
//! cut-backs, events, changes of the active constraints.
//!
//! An analysis reports its progress to an [`Observer`]: every Newton
//! iteration, every converged increment (with the state, for output), every
//! cut-back and every event. The library never prints; the command-line
//! tool turns these events into log lines, a progress bar and result files.

pub mod constraints;
pub mod control;
pub mod dynamics;
pub mod energy;
pub mod impact;
pub mod modal;
pub mod newton;
pub mod observers;
pub mod preflight;
pub mod settings;
pub mod statics;

pub use control::EventFunction;
pub use dynamics::{
    Continuation, DynamicAnalysis, DynamicError, DynamicOutcome, GeneralizedAlpha,
    LinearSolverCounts,
};
pub use energy::{Energies, EnergyBalance};
pub use impact::{ContactInfo, ContactKind, LatchEventKind, LockInfo};
pub use modal::{ModalAnalysis, ModalError, ModalOutcome, NaturalMode};
pub use newton::{ConvergenceNorms, NewtonFailure};
pub use settings::{
    AnalysisSettings, AngularVelocities, DynamicSettings, ModalSettings, NewtonMethod,
    StaticSettings,
};
pub use statics::{StaticAnalysis, StaticOutcome, Step, LIMIT_POINT_WARNING};

use crate::model::Model;
use crate::state::State;

/// One Newton iteration.
#[derive(Clone, Debug, PartialEq)]
pub struct IterationInfo {
    /// Increment number (0 is the initial equilibrium at `t = 0`).
    pub increment: usize,
    /// Iteration number within the increment (0: before any correction).
    pub iteration: usize,
    /// Load parameter.
    pub time: f64,
    /// Norms measured at this iteration.
    pub norms: ConvergenceNorms,
}

/// A converged increment.
#[derive(Clone, Debug, PartialEq)]
pub struct IncrementInfo {
    /// Increment number (0 is the initial equilibrium at `t = 0`).
    pub increment: usize,
    /// Load parameter reached.
    pub time: f64,
    /// Size of the increment.
    pub step: f64,
    /// Newton iterations (corrections) it took.
    pub iterations: usize,
    /// Relative residual at each iteration, from the first evaluation to
    /// the converged one.
    pub residuals: Vec<f64>,
    /// Whether results are to be written for this increment.
    pub output: bool,
}

/// An increment that failed and is retried with a smaller step.
#[derive(Clone, Debug, PartialEq)]
pub struct CutbackInfo {
    /// Increment number being attempted.
    pub increment: usize,
    /// Load parameter at the start of the increment.
    pub time: f64,
    /// Step that failed.
    pub failed_step: f64,
    /// Step that will be tried next.
    pub next_step: f64,
    /// Why it failed.
    pub reason: NewtonFailure,
}

/// A converged step rejected by its local error estimate, retried shorter
/// ([`Observer::rejected`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RejectionInfo {
    /// Increment number being attempted.
    pub increment: usize,
    /// Time at the start of the step.
    pub time: f64,
    /// The step rejected.
    pub step: f64,
    /// The step tried next.
    pub next_step: f64,
    /// Its error estimate relative to the tolerance (above 1).
    pub error: f64,
    /// Where the estimate was largest (`node 12`; empty if unknown).
    pub at: String,
}

/// A step that landed on an event ([`EventFunction`]).
#[derive(Clone, Debug, PartialEq)]
pub struct EventInfo {
    /// Increment that landed on it.
    pub increment: usize,
    /// Load parameter (time) of the event.
    pub time: f64,
    /// The event's name.
    pub name: String,
    /// The event function there (within its tolerance of zero).
    pub value: f64,
}

/// Receives the events of an analysis. Every method has an empty default.
pub trait Observer {
    /// After each residual evaluation of a Newton iteration.
    fn iteration(&mut self, _info: &IterationInfo) {}

    /// After each converged increment, with the converged state and the
    /// residual at every dof (at fixed dofs: the support reactions);
    /// returning an error stops the analysis (used by result writers when a
    /// file cannot be written).
    fn increment(
        &mut self,
        _info: &IncrementInfo,
        _model: &Model,
        _state: &State,
        _residual: &[f64],
    ) -> std::io::Result<()> {
        Ok(())
    }

    /// The energies of a dynamic analysis at its converged step, just
    /// before that step is reported to [`Observer::increment`].
    fn energies(&mut self, _energies: &energy::Energies) {}

    /// After each converged step of a dynamic analysis (and after its
    /// start), once the size of the next step is chosen: the state and what
    /// a run continued from it needs besides (restart files); returning an
    /// error stops the analysis, as for [`Observer::increment`].
    fn continuation(
        &mut self,
        _state: &State,
        _continuation: &dynamics::Continuation,
    ) -> std::io::Result<()> {
        Ok(())
    }

    /// When an increment is cut back.
    fn cutback(&mut self, _info: &CutbackInfo) {}

    /// After a converged step rejected by its error estimate, before the
    /// shorter one is tried.
    fn rejected(&mut self, _info: &RejectionInfo) {}

    /// After the increment that landed on an event (reported to
    /// [`Observer::increment`] first).
    fn event(&mut self, _info: &EventInfo) {}

    /// After the step on which a latch locked, or a spring latch released
    /// ([`LockInfo::kind`]; reported to [`Observer::increment`], with the
    /// post-event state, first).
    fn lock(&mut self, _info: &LockInfo) {}

    /// After the step on which a spring latch's spring engaged or
    /// disengaged at an edge of its dead band, or a spring latch released
    /// beyond its value came back to it ([`LockInfo::kind`]: `Engage`,
    /// `Disengage`, `Rearm`; after [`Observer::lock`] for the same step).
    fn band_crossing(&mut self, _info: &LockInfo) {}

    /// After the step on which a stop was struck, closed or released
    /// (reported to [`Observer::increment`], with the post-event state,
    /// first).
    fn contact(&mut self, _info: &ContactInfo) {}

    /// A remark worth showing the user (redundant constraints removed).
    fn note(&mut self, _text: &str) {}

    /// After a converged increment that the analysis finds suspect (a
    /// limit or bifurcation point passed under load control, docs/theory.md
    /// §9): the analysis goes on, but its results may not be those
    /// meant.
    fn warning(&mut self, _info: &WarningInfo) {}
}

/// A suspect converged increment ([`Observer::warning`]).
#[derive(Clone, Debug, PartialEq)]
pub struct WarningInfo {
    /// The increment.
    pub increment: usize,
    /// Load parameter at its start.
    pub from: f64,
    /// Load parameter reached.
    pub time: f64,
    /// What is suspect, and what to do.
    pub message: String,
}

/// An observer that ignores everything.
pub struct NoObserver;

impl Observer for NoObserver {}
