//! Nonlinear static analysis: Newton–Raphson over increments of the load
//! parameter `t` (load control) or of the arc length of the path
//! (docs/theory.md §9), from a start state to `end_time`.
//!
//! 1. Equilibrium at the start (`t` of the start state: 0 for a first
//!    analysis, the end of the one before in a sequence): increment 0,
//!    after the rank analysis of the constraints.
//! 2. Each increment is a step of the step controller
//!    ([`super::control`]): load control moves `t` by `Δt`, sets prescribed
//!    motions to their values at the new `t`, moves the free unknowns by the
//!    predictor (each node continues the motion of the last increment,
//!    docs/theory.md §7.3) and iterates to equilibrium; arc length finds `t`
//!    with the unknowns. The controller cuts failed steps back, lets easy
//!    ones grow, lands on output times and `end_time`, on events, and has
//!    the constraints' rank analysed again when the set of active
//!    constraints changes.
//!
//! Everything converged before a failure has already been passed to the
//! observer, so result files written so far stay valid.
//!
//! The analysis runs at once ([`StaticAnalysis::run`]) or step by step
//! ([`StaticAnalysis::start`], [`StaticAnalysis::advance`],
//! [`StaticAnalysis::state`], [`StaticAnalysis::finish`]), for programs and
//! bindings that look at every increment.

use std::sync::Arc;
use std::time::Instant;

use super::control::{
    Advance, Attempt, ControlStop, EventFunction, StepBounds, StepController, Stepper,
};
use super::newton::{NewtonFailure, NewtonSolver};
use super::settings::StaticSettings;
use super::{IncrementInfo, Observer, WarningInfo};
use crate::model::Model;
use crate::state::State;

pub use super::control::{CUTBACK, EASY_ITERATIONS, GROWTH};

/// Why a static analysis stopped before `end_time`.
#[derive(Debug, thiserror::Error)]
pub enum StaticError {
    /// An increment failed with the smallest allowed step.
    #[error("no convergence at increment {increment} from t = {time:.6}: the step {step:.3e} failed and half of it would be below min_increment: {reason}")]
    Diverged {
        /// Increment that failed.
        increment: usize,
        /// Last converged load parameter.
        time: f64,
        /// Last step tried.
        step: f64,
        /// Last failure.
        reason: NewtonFailure,
    },
    /// Equilibrium could not be found in the start configuration.
    #[error("no equilibrium in the initial configuration (t = {time}): {failure}")]
    Initial {
        /// Load parameter of the start state.
        time: f64,
        /// Why.
        failure: NewtonFailure,
    },
    /// A kinematic analysis whose joints and drivers leave motions free.
    #[error("the joints and drivers do not make the mechanism determinate: {free} motion(s) are left free (least constrained: {dofs}); add drivers or supports, or run a kinetostatic analysis")]
    Indeterminate {
        /// Number of free motions.
        free: usize,
        /// The least constrained unknowns.
        dofs: String,
    },
    /// Constraints removed as redundant turned out violated: they
    /// contradict the others.
    #[error("inconsistent constraints at t = {time:.6}: {constraint} was found redundant but is now violated ({violation:.1e} × its tolerance); two joints or drivers impose incompatible motions")]
    Inconsistent {
        /// Load parameter.
        time: f64,
        /// The violated constraint.
        constraint: String,
        /// Violation relative to the tolerance.
        violation: f64,
    },
    /// A converged increment took an element where its law does not hold
    /// (a rotational spring or a beam element whose relative rotation
    /// passed half a turn).
    #[error("{element}, between t = {from} and t = {time}: {reason}")]
    LawViolated {
        /// The element, as in messages (`spring 100`, `beam 3`).
        element: String,
        /// Load parameter at the start of the increment.
        from: f64,
        /// Load parameter reached.
        time: f64,
        /// What happened.
        reason: String,
    },
    /// Arc-length control used its increments before reaching `end_time`.
    #[error("arc-length control: end_time not reached in {increments} increments (t = {time:.6}); raise max_increments or the increment sizes")]
    ArcLengthLimit {
        /// Increments allowed.
        increments: usize,
        /// Load parameter reached.
        time: f64,
    },
    /// A result file could not be written.
    #[error("writing results: {0}")]
    Output(#[from] std::io::Error),
}

/// What a static analysis did.
#[derive(Debug)]
pub struct StaticOutcome {
    /// Last converged state.
    pub state: State,
    /// Converged increments after the initial equilibrium.
    pub increments: usize,
    /// Newton iterations in all converged increments (increment 0 included).
    pub iterations: usize,
    /// Newton iterations spent in failed or rejected attempts.
    pub wasted_iterations: usize,
    /// Number of cut-backs.
    pub cutbacks: usize,
    /// Translation corrections (docs/theory.md §7.2): one more assembly and
    /// factorisation each, besides the iterations.
    pub translation_corrections: usize,
    /// Arc-length iterations whose constraint had no real root and took
    /// the increment of closest approach (docs/theory.md §9).
    pub closest_approaches: usize,
    /// Constraint equations removed as redundant (docs/joints.md §5): the
    /// most at any time of the analysis.
    pub redundant_constraints: usize,
    /// Rank analyses of the constraints run again during the analysis,
    /// after a change of the active constraints.
    pub rank_analyses: usize,
    /// Steps retried shortened to land on an event.
    pub event_retries: usize,
    /// Load parameter reached.
    pub time: f64,
    /// Wall-clock time in seconds.
    pub wall_time: f64,
    /// `None` if `end_time` was reached.
    pub error: Option<StaticError>,
}

/// What one call of [`StaticAnalysis::start`] or
/// [`StaticAnalysis::advance`] did.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// An increment converged (increment 0: the equilibrium at the start);
    /// [`StaticAnalysis::state`] is its state.
    Increment(IncrementInfo),
    /// `end_time` has been reached.
    Finished,
    /// The analysis stopped early: [`StaticAnalysis::error`] says why.
    Stopped,
}

/// A nonlinear static analysis of a model (see the module documentation).
pub struct StaticAnalysis {
    model: Arc<Model>,
    settings: StaticSettings,
    solver: NewtonSolver,
    events: Vec<Box<dyn EventFunction>>,
    run: Option<Run>,
}

/// The analysis under way.
struct Run {
    /// The last accepted state.
    accepted: State,
    /// The state being iterated on (equal to `accepted` between steps).
    state: State,
    /// The accepted state before the last one and the step between them,
    /// for the predictor of load control.
    previous: Option<(State, f64)>,
    /// Arc-length control: the previous increment (by equation), its
    /// backup, and `t` of the attempt.
    arc: Option<ArcLength>,
    controller: Option<StepController>,
    /// Counts of increment 0 and of the landings of arc-length control.
    iterations: usize,
    wasted: usize,
    redundant: usize,
    /// Sign of the tangent's determinant at the last accepted state, under
    /// load control (docs/theory.md §9).
    sign: Option<f64>,
    started: Instant,
    finished: bool,
    error: Option<StaticError>,
}

/// State of arc-length control between increments.
struct ArcLength {
    direction: Vec<f64>,
    direction_backup: Vec<f64>,
    time: f64,
}

/// The analysis seen by the step controller.
struct Statics<'a> {
    model: &'a Model,
    settings: &'a StaticSettings,
    solver: &'a mut NewtonSolver,
    run: &'a mut Run,
}

impl StaticAnalysis {
    /// Prepares the analysis of `model` with `settings`: dof numbering,
    /// sparse pattern, buffers.
    pub fn new(model: impl Into<Arc<Model>>, settings: StaticSettings) -> Self {
        let model = model.into();
        let solver = NewtonSolver::new(&model);
        Self {
            model,
            settings,
            solver,
            events: Vec::new(),
            run: None,
        }
    }

    /// Watches `event` during the analysis: a step across which it changes
    /// sign is retried shortened to land on it ([`super::control`]).
    pub fn with_event(mut self, event: Box<dyn EventFunction>) -> Self {
        self.events.push(event);
        self
    }

    /// The model.
    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    /// The settings.
    pub fn settings(&self) -> &StaticSettings {
        &self.settings
    }

    /// Number of free unknowns.
    pub fn n_equations(&self) -> usize {
        self.solver.dofs.n_equations()
    }

    /// The Newton solver (for inspection: dof numbering, residual).
    pub fn solver(&self) -> &NewtonSolver {
        &self.solver
    }

    /// Runs from `start` (the model's initial state, or the final state of
    /// an analysis before) to `end_time`.
    pub fn run(&mut self, start: State, observer: &mut dyn Observer) -> StaticOutcome {
        let mut step = self.start(start, observer);
        while let Step::Increment(_) = step {
            step = self.advance(observer);
        }
        self.finish()
    }

    /// Starts the analysis from `start`: the rank analysis of the
    /// constraints and the equilibrium at the start time (increment 0).
    pub fn start(&mut self, start: State, observer: &mut dyn Observer) -> Step {
        let started = Instant::now();
        let model = &*self.model;
        let s = &self.settings;
        let mut state = start;
        let t0 = state.time;
        model.apply_prescribed(&mut state, t0);
        let mut run = Run {
            accepted: state.clone(),
            state,
            previous: None,
            arc: None,
            controller: None,
            iterations: 0,
            wasted: 0,
            redundant: 0,
            sign: None,
            started,
            finished: false,
            error: None,
        };

        // rank of the constraints: redundant ones out, determinacy
        let rank = self.solver.constraint_rank(model, &run.state, t0);
        run.redundant = rank.redundant.len();
        if !rank.redundant.is_empty() {
            observer.note(&format!(
                "{} redundant constraint equation(s) removed (over-constrained: joints, supports or drivers that repeat one another); their multipliers are zero and the others carry the loads",
                rank.redundant.len()
            ));
        }
        if s.kinematic && rank.degrees_of_freedom() > 0 {
            run.error = Some(self.solver.indeterminate(model, &rank));
            self.run = Some(run);
            return Step::Stopped;
        }

        // equilibrium at the start, increment 0
        let info = match self.solver.solve(model, s, &mut run.state, t0, 0, observer) {
            Ok(r) => {
                model.update_internal(&mut run.state);
                run.iterations += r.iterations;
                IncrementInfo {
                    increment: 0,
                    time: t0,
                    step: 0.0,
                    iterations: r.iterations,
                    residuals: r.residuals,
                    output: true,
                }
            }
            Err(failure) => {
                run.error = Some(StaticError::Initial { time: t0, failure });
                self.run = Some(run);
                return Step::Stopped;
            }
        };
        run.accepted.clone_from(&run.state);
        if watches_stability(s) {
            run.sign = self.solver.tangent_sign();
        }
        let written = observer.increment(&info, model, &run.state, self.solver.residual());

        // the step controller, in units of t or of arc length
        let controller = if s.arc_length {
            // the first arc: the tangent predictor of a load increment
            // initial_increment; its bounds scale like the load increments
            let arc0 = self
                .solver
                .tangent_arc(model, &run.state, t0, s.initial_increment);
            run.arc = Some(ArcLength {
                direction: Vec::new(),
                direction_backup: Vec::new(),
                time: t0,
            });
            let bounds = StepBounds {
                initial: arc0,
                min: arc0 * s.min_increment / s.initial_increment,
                max: arc0 * s.max_increment / s.initial_increment,
            };
            StepController::new(bounds, s.end_time).with_max_increments(s.max_increments)
        } else {
            // no prescribed rotation or driven angle turns by more than a
            // quarter turn in one increment (Model::rotation_step_limit)
            let mut max = s.max_increment;
            if let Some(limit) = model.rotation_step_limit(s.end_time) {
                let limit = limit.max(s.min_increment);
                if limit < s.max_increment || limit < s.initial_increment {
                    observer.note(&format!(
                        "load increments limited to {limit:.4e} so that prescribed rotations and driven angles turn by at most a quarter turn in each"
                    ));
                }
                max = max.min(limit);
            }
            let bounds = StepBounds {
                initial: s.initial_increment.min(max),
                min: s.min_increment,
                max,
            };
            StepController::new(bounds, s.end_time)
        };
        run.controller = Some(
            controller
                .with_output_times(&s.output_times)
                .with_output_every(s.output_every)
                .with_events(std::mem::take(&mut self.events)),
        );
        let stopped = written.is_err();
        if let Err(e) = written {
            run.error = Some(e.into());
        }
        self.run = Some(run);
        if stopped {
            Step::Stopped
        } else {
            Step::Increment(info)
        }
    }

    /// One more converged increment (with the cut-backs and retries it
    /// takes), or the end of the analysis.
    pub fn advance(&mut self, observer: &mut dyn Observer) -> Step {
        let Some(run) = self.run.as_mut() else {
            return Step::Stopped;
        };
        if run.error.is_some() {
            return Step::Stopped;
        }
        if run.finished {
            return Step::Finished;
        }
        let Some(mut controller) = run.controller.take() else {
            return Step::Stopped;
        };
        let mut stepper = Statics {
            model: &self.model,
            settings: &self.settings,
            solver: &mut self.solver,
            run,
        };
        let result = controller.advance(&mut stepper, observer);
        let run = stepper.run;
        run.controller = Some(controller);
        match result {
            Ok(Advance::Accepted(info)) => Step::Increment(info),
            Ok(Advance::Finished) => {
                run.finished = true;
                Step::Finished
            }
            Err(stop) => {
                run.error = Some(match stop {
                    ControlStop::Diverged {
                        increment,
                        time,
                        step,
                        reason,
                    } => StaticError::Diverged {
                        increment,
                        time,
                        step,
                        reason,
                    },
                    ControlStop::Limit { increments, time } => {
                        StaticError::ArcLengthLimit { increments, time }
                    }
                    ControlStop::Stepper(e) => e,
                });
                Step::Stopped
            }
        }
    }

    /// The last converged state (the start state before [`Self::start`]).
    pub fn state(&self) -> Option<&State> {
        self.run.as_ref().map(|r| &r.accepted)
    }

    /// Why the analysis stopped, if it did.
    pub fn error(&self) -> Option<&StaticError> {
        self.run.as_ref().and_then(|r| r.error.as_ref())
    }

    /// Ends the analysis: what it did and its last converged state.
    pub fn finish(&mut self) -> StaticOutcome {
        let run = self.run.take();
        let (state, counts, iterations, wasted, redundant, wall_time, error) = match run {
            Some(r) => (
                r.accepted,
                r.controller.map(|c| c.counts()).unwrap_or_default(),
                r.iterations,
                r.wasted,
                r.redundant,
                r.started.elapsed().as_secs_f64(),
                r.error,
            ),
            None => (State::default(), Default::default(), 0, 0, 0, 0.0, None),
        };
        StaticOutcome {
            time: state.time,
            state,
            increments: counts.increments,
            iterations: iterations + counts.iterations,
            wasted_iterations: wasted + counts.wasted_iterations,
            cutbacks: counts.cutbacks,
            translation_corrections: self.solver.translation_corrections(),
            closest_approaches: self.solver.closest_approaches(),
            redundant_constraints: redundant.max(self.solver.redundant_count()),
            rank_analyses: counts.rank_analyses,
            event_retries: counts.event_retries,
            wall_time,
            error,
        }
    }
}

/// What a change of sign of the tangent's determinant under load control
/// means, and what to do (docs/theory.md §9).
pub const LIMIT_POINT_WARNING: &str = "the determinant of the tangent stiffness changed sign within this increment: the equilibrium path passed a limit point or a bifurcation point, past which load control may follow an unstable branch or jump to a distant one (snap-through) without showing the path between; arc-length control (control = \"arc_length\") follows the path through limit points";

/// Whether the sign of the tangent's determinant is watched: load control
/// of a static analysis with stiffness (not a kinematic one, where the
/// tangent is that of the constraints; arc-length control follows limit
/// points).
fn watches_stability(s: &StaticSettings) -> bool {
    !s.kinematic && !s.arc_length
}

impl Stepper for Statics<'_> {
    type Error = StaticError;

    fn recorded(&self, error: &StaticError) -> bool {
        matches!(error, StaticError::Output(e) if e.kind() == std::io::ErrorKind::Interrupted)
    }

    fn current(&self) -> (&Model, &State) {
        (self.model, &self.run.state)
    }

    fn time(&self) -> f64 {
        self.run.accepted.time
    }

    fn sized_in_time(&self) -> bool {
        self.run.arc.is_none()
    }

    fn update_active_set(
        &mut self,
        time: f64,
        observer: &mut dyn Observer,
    ) -> Result<bool, StaticError> {
        let (model, run) = (self.model, &mut *self.run);
        if !self.solver.active_set_changed(model, &run.accepted, time) {
            return Ok(false);
        }
        let before = self.solver.redundant_count();
        let rank = self.solver.constraint_rank(model, &run.accepted, time);
        // the multipliers of redundant constraints stay at zero
        for &k in &rank.redundant {
            run.accepted.multipliers[k] = 0.0;
            run.state.multipliers[k] = 0.0;
        }
        if let Some(arc) = run.arc.as_mut() {
            // the numbering changed: the previous increment no longer
            // applies
            arc.direction.clear();
        }
        if rank.redundant.len() != before {
            observer.note(&format!(
                "at t = {time}: the active constraints changed; {} redundant constraint equation(s) removed",
                rank.redundant.len()
            ));
        }
        run.redundant = run.redundant.max(rank.redundant.len());
        // another system: its determinant is not compared with the last
        run.sign = None;
        if self.settings.kinematic && rank.degrees_of_freedom() > 0 {
            return Err(self.solver.indeterminate(model, &rank));
        }
        Ok(true)
    }

    fn attempt(
        &mut self,
        size: f64,
        target: f64,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Attempt {
        let (model, s, run) = (self.model, self.settings, &mut *self.run);
        let t = run.accepted.time;
        let result = match run.arc.as_mut() {
            None => {
                let t_new = t + size;
                run.state.time = t_new;
                model.apply_prescribed(&mut run.state, t_new);
                // predictor: each node continues its last increment
                if let Some((p, last_step)) = &run.previous {
                    self.solver
                        .predict(model, &mut run.state, p, size / last_step, t_new);
                }
                self.solver
                    .solve(model, s, &mut run.state, t_new, increment, observer)
            }
            Some(arc) => {
                arc.time = t;
                arc.direction_backup.clone_from(&arc.direction);
                let mut result = self.solver.solve_arc(
                    model,
                    s,
                    &mut run.state,
                    &mut arc.time,
                    size,
                    &mut arc.direction,
                    increment,
                    observer,
                );
                if let (Ok(r), true) = (&result, arc.time >= target) {
                    // land on the target with a load-controlled increment,
                    // from the start of the increment or else from the
                    // arc's end; if neither converges the arc is cut back
                    // like a failure. The arc's own iterations are spent.
                    run.wasted += r.iterations;
                    let arc_end = run.state.clone();
                    for start in [&run.accepted, &arc_end] {
                        let mut landed = start.clone();
                        landed.time = target;
                        match self
                            .solver
                            .solve(model, s, &mut landed, target, increment, observer)
                        {
                            Ok(r) => {
                                run.state = landed;
                                arc.time = target;
                                result = Ok(r);
                                break;
                            }
                            Err(f) => {
                                run.wasted += f.iterations_spent();
                                result = Err(f);
                            }
                        }
                    }
                    if let Err(f) = &result {
                        // the controller counts the last failure
                        run.wasted -= f.iterations_spent();
                    }
                }
                result
            }
        };
        match result {
            Ok(r) => Attempt::Converged {
                iterations: r.iterations,
                residuals: r.residuals,
                error: None,
            },
            Err(f) => Attempt::Failed(f),
        }
    }

    fn attempted_time(&self) -> f64 {
        match &self.run.arc {
            Some(arc) => arc.time,
            None => self.run.state.time,
        }
    }

    fn reject(&mut self) {
        let run = &mut *self.run;
        run.state.clone_from(&run.accepted);
        if let Some(arc) = run.arc.as_mut() {
            arc.time = run.accepted.time;
            std::mem::swap(&mut arc.direction, &mut arc.direction_backup);
        }
    }

    fn accept(
        &mut self,
        info: &IncrementInfo,
        observer: &mut dyn Observer,
    ) -> Result<(), StaticError> {
        let (model, run) = (self.model, &mut *self.run);
        run.state.time = info.time;
        let from = run.accepted.time;
        // laws that hold below half a turn of a relative rotation
        for e in &model.elements {
            if let Some(reason) = e.law_violated(&run.accepted, &run.state) {
                return Err(StaticError::LawViolated {
                    element: format!("{} {}", e.kind().name(), e.id()),
                    from,
                    time: info.time,
                    reason,
                });
            }
        }
        model.update_internal(&mut run.state);
        // a change of sign of the tangent's determinant: an odd number of
        // its eigenvalues crossed zero within the increment
        if watches_stability(self.settings) {
            let sign = self.solver.tangent_sign();
            if let (Some(before), Some(after)) = (run.sign, sign) {
                if before != after {
                    observer.warning(&WarningInfo {
                        increment: info.increment,
                        from,
                        time: info.time,
                        message: LIMIT_POINT_WARNING.to_string(),
                    });
                }
            }
            run.sign = sign;
        }
        if let Some((constraint, violation)) =
            self.solver
                .violated_redundant(model, &run.state, self.settings)
        {
            return Err(StaticError::Inconsistent {
                time: info.time,
                constraint,
                violation,
            });
        }
        if run.arc.is_none() {
            match &mut run.previous {
                Some((p, last_step)) => {
                    p.clone_from(&run.accepted);
                    *last_step = info.step;
                }
                None => run.previous = Some((run.accepted.clone(), info.step)),
            }
        }
        run.accepted.clone_from(&run.state);
        observer.increment(info, model, &run.state, self.solver.residual())?;
        Ok(())
    }
}
