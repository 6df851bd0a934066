//! The step controller shared by every incremental analysis: load control
//! and arc length in statics, time steps in dynamics (docs/theory.md §13).
//!
//! An analysis plugs in as a [`Stepper`]: from its last accepted state it
//! attempts one step of a given size and says whether Newton converged
//! (with the iterations, the residual history and optionally an estimate of
//! the local error) or why not. The controller owns everything around it:
//! - the step size: its bounds, its growth after easy steps
//!   ([`EASY_ITERATIONS`], [`GROWTH`]), its cut-back after a failure
//!   ([`CUTBACK`]), or the size an error estimate asks for;
//! - landing exactly on `end_time` and on requested output times (a step
//!   sized in time is shortened to reach them; a stepper whose steps are
//!   not (arc length) lands on them itself when a step passes them);
//! - events: a step across which an [`EventFunction`] changes sign is
//!   rejected and retried shortened to land on the crossing, within the
//!   event's tolerance;
//! - the set of active constraints: before each attempt the stepper is asked
//!   whether it changed (a driver's window opening, a latch locking), so
//!   that the rank analysis of the constraints is run again;
//! - the accept / reject / retry logic (the stepper keeps the backup of its
//!   state), the increment numbering, the counts, and the observer's
//!   cut-back and event reports.

use serde::{Deserialize, Serialize};

use super::newton::NewtonFailure;
use super::{CutbackInfo, EventInfo, IncrementInfo, Observer, RejectionInfo, WarningInfo};
use crate::model::Model;
use crate::state::State;

/// Steps converged in this many iterations or fewer let the step grow.
pub const EASY_ITERATIONS: usize = 5;
/// Growth factor of the step after an easy step.
pub const GROWTH: f64 = 1.5;
/// Reduction factor of the step after a failed step.
pub const CUTBACK: f64 = 0.5;
/// A step that ends within this fraction of `end_time` (or more exactly,
/// of the scale of `t`) from a landing time lands on it: `t` accumulated
/// over many steps is not exact.
pub const LANDING_SNAP: f64 = 1e-9;
/// Safety factor on the step size an error estimate asks for.
pub const ERROR_SAFETY: f64 = 0.9;
/// The error estimate changes the step by at most these factors at once.
pub const ERROR_FACTORS: (f64, f64) = (0.2, 2.0);
/// Integral gain `k_I (p + 1)` of the PI step-size controller (Gustafsson
/// 1991, "Control theoretic techniques for stepsize selection in explicit
/// Runge–Kutta methods", ACM TOMS 17): the step follows the trend of the
/// error estimate rather than each value, which fluctuates from step to
/// step by factors up to 2 on lightly damped multi-mode motions (with the
/// elementary controller every upward fluctuation by 1.23 was a
/// rejection; docs/theory.md §15.5).
pub const PI_INTEGRAL: f64 = 0.3;
/// Proportional gain `k_P (p + 1)` of the PI controller (Gustafsson 1991).
pub const PI_PROPORTIONAL: f64 = 0.4;
/// The previous error estimate enters the PI controller at least as this:
/// after a stretch of steps with nearly no error (at rest, before a load)
/// the first step with a finite error is not taken for a steep trend.
pub const ERROR_MEMORY_FLOOR: f64 = 1e-2;
/// A crossing that an event function's rate at the accepted state puts
/// within this fraction of the last step is anticipated from that rate
/// rather than from the chord of the last step (docs/theory.md §13).
pub const NEAR_CROSSING: f64 = 0.1;
/// Retries of one step to land on an event before the event is taken as
/// happening within the step where it was found.
pub const MAX_EVENT_RETRIES: usize = 30;

/// Landing steps are at least this fraction of the largest step: a
/// crossing nearer than that to a step's start is taken as happening
/// within the step (docs/theory.md §13).
pub const LANDING_FLOOR: f64 = 1e-9;

/// What an attempted step gave.
#[derive(Clone, Debug, PartialEq)]
pub enum Attempt {
    /// Newton converged.
    Converged {
        /// Corrections applied.
        iterations: usize,
        /// Relative residual at each evaluation.
        residuals: Vec<f64>,
        /// Estimate of the local error relative to its tolerance (at most 1
        /// to be accepted), when the stepper makes one.
        error: Option<f64>,
    },
    /// Newton failed; the step is cut back.
    Failed(NewtonFailure),
}

/// An analysis as the controller drives it.
pub trait Stepper {
    /// Why the stepper stops an analysis (an inconsistency found after a
    /// converged step, an observer's error).
    type Error;

    /// Whether `error`, returned by [`Self::accept`], stopped the analysis
    /// after the step was recorded (an observer's interruption: the step
    /// is written and counts), not before.
    fn recorded(&self, _error: &Self::Error) -> bool {
        false
    }

    /// The model and the current state: the last accepted one, or the
    /// attempted one between an attempt and its acceptance or rejection.
    fn current(&self) -> (&Model, &State);

    /// `t` of the last accepted state.
    fn time(&self) -> f64;

    /// Whether step sizes are steps of `t` (load control, time steps).
    fn sized_in_time(&self) -> bool;

    /// Order `p` of the local error estimate, `err ∝ hᵖ⁺¹` (2 for
    /// Newmark-type schemes, whose error is `O(h³)`).
    fn error_order(&self) -> f64 {
        2.0
    }

    /// Called before each attempt with the time the step will reach
    /// (steps sized in time) or the last accepted time: checks whether the
    /// set of active constraints changed there and, if it did, analyses the
    /// rank of the constraints again. Returns whether it changed.
    fn update_active_set(
        &mut self,
        time: f64,
        observer: &mut dyn Observer,
    ) -> Result<bool, Self::Error>;

    /// Attempts one step of size `size` from the last accepted state, as
    /// increment `increment`. A stepper whose steps are not sized in time
    /// lands on `target` when the step passes it.
    fn attempt(
        &mut self,
        size: f64,
        target: f64,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Attempt;

    /// `t` reached by the last attempt.
    fn attempted_time(&self) -> f64;

    /// Where the local error estimate of the last attempt was largest
    /// (`node 12`), for messages.
    fn error_location(&self) -> Option<String> {
        None
    }

    /// Goes back to the last accepted state after a rejected attempt.
    fn reject(&mut self);

    /// Accepts the attempted state as the converged increment `info`
    /// (internal variables updated, checks, the observer told).
    fn accept(
        &mut self,
        info: &IncrementInfo,
        observer: &mut dyn Observer,
    ) -> Result<(), Self::Error>;
}

/// A scalar function of the state whose change of sign is an event: a
/// latch reached, a contact closed, or any predicate of a test ("the tip
/// deflection reaches 1 cm").
pub trait EventFunction: Send {
    /// Name of the event, for reports.
    fn name(&self) -> String;
    /// `g(state)`; the event happens where it changes sign.
    fn value(&self, model: &Model, state: &State) -> f64;
    /// `|g|` at or below which a step has landed on the event.
    fn tolerance(&self) -> f64;
    /// `g` varies smoothly with the motion, so that its rate over the
    /// last accepted step tells when it will cross (docs/theory.md §13,
    /// "Anticipation"); not for a function that jumps (a spring latch's
    /// watch, ±1).
    fn anticipated(&self) -> bool {
        false
    }
    /// `dg/dt` at `state`, for an [`Self::anticipated`] function that
    /// knows it: near its zero, the crossing is anticipated from it
    /// rather than from the rate over the last step (docs/theory.md §13,
    /// "Anticipation").
    fn rate(&self, _model: &Model, _state: &State) -> Option<f64> {
        None
    }
}

/// Why the controller stopped an analysis.
#[derive(Debug)]
pub enum ControlStop<E> {
    /// A step failed with the smallest allowed size.
    Diverged {
        /// Increment that failed.
        increment: usize,
        /// Last accepted `t`.
        time: f64,
        /// Last size tried.
        step: f64,
        /// Last failure.
        reason: NewtonFailure,
    },
    /// The largest number of increments was used before `end_time`.
    Limit {
        /// Increments allowed.
        increments: usize,
        /// `t` reached.
        time: f64,
    },
    /// The stepper stopped the analysis.
    Stepper(E),
}

/// What one call of [`StepController::advance`] did.
#[derive(Clone, Debug, PartialEq)]
pub enum Advance {
    /// An increment was accepted.
    Accepted(IncrementInfo),
    /// `end_time` had already been reached: nothing to do.
    Finished,
}

/// Counts of the controller's work.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepCounts {
    /// Accepted increments.
    pub increments: usize,
    /// Newton iterations of accepted increments.
    pub iterations: usize,
    /// Newton iterations of rejected attempts.
    pub wasted_iterations: usize,
    /// Steps cut back after a failure.
    pub cutbacks: usize,
    /// Steps rejected to land on an event.
    pub event_retries: usize,
    /// Steps rejected by the error estimate.
    pub error_rejections: usize,
    /// Rank analyses of the constraints run again after a change of the
    /// active set.
    pub rank_analyses: usize,
}

/// Bounds of the step size, in the stepper's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepBounds {
    /// First size.
    pub initial: f64,
    /// Smallest size before the analysis gives up.
    pub min: f64,
    /// Largest size.
    pub max: f64,
}

/// A crossing being located (regula falsi with the Illinois modification):
/// the crossing lies within `span` (step units) of the accepted state, where
/// the event function is `g_b` (halved each time this end is kept).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Crossing {
    event: usize,
    span: f64,
    g_b: f64,
    retries: usize,
}

impl Crossing {
    /// The fraction of `span` at the zero of the line from `g0` (accepted
    /// state) to `g_b`.
    fn fraction(&self, g0: f64) -> f64 {
        let d = g0 - self.g_b;
        if d != 0.0 && d.is_finite() {
            (g0 / d).clamp(0.02, 0.98)
        } else {
            0.5
        }
    }
}

/// What the step controller carries from one accepted step to the next
/// besides the stepper's state, as it stands once the next step's size is
/// chosen: kept in restart files, so that a run continued from a step
/// takes the steps the run never stopped would have taken
/// ([`StepController::memory`], [`StepController::resume`]). The output
/// times landed on and the counts are not in it: they follow from the
/// time, and a continued run counts its own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepMemory {
    /// The size the next step will try.
    size: f64,
    /// The error estimate sets the size (no growth by [`GROWTH`]).
    error_controlled: bool,
    /// The PI controller's previous estimate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    last_error: Option<f64>,
    /// The event functions at the accepted state and their sides (a side
    /// is flipped once a step has landed on the event, whatever the sign
    /// of the value landed on).
    event_values: Vec<f64>,
    event_sides: Vec<f64>,
    /// A crossing being located, and the step that first crossed it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    crossing: Option<Crossing>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    approach: Option<f64>,
    /// The time and the event functions of the accepted state before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    previous_events: Option<(f64, Vec<f64>)>,
}

impl StepMemory {
    /// The size the next step will try.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// What is not a value a run writes, if anything: an error estimate
    /// that is negative or not finite, event values that are not finite,
    /// sides other than ±1, or not as many values as sides.
    pub fn invalid(&self) -> Option<String> {
        if let Some(e) = self.last_error {
            if !(e.is_finite() && e >= 0.0) {
                return Some(format!(
                    "last_error = {e} must be zero or positive and finite"
                ));
            }
        }
        if self.event_values.len() != self.event_sides.len() {
            return Some(format!(
                "{} event_values against {} event_sides",
                self.event_values.len(),
                self.event_sides.len()
            ));
        }
        if let Some(v) = self.event_values.iter().find(|v| !v.is_finite()) {
            return Some(format!("event_values holds {v}, not a finite number"));
        }
        if let Some(v) = self.event_sides.iter().find(|&&v| v != 1.0 && v != -1.0) {
            return Some(format!(
                "event_sides holds {}, not 1 or -1",
                crate::io::number::plain(*v)
            ));
        }
        None
    }
}

/// The step controller (see the module documentation).
pub struct StepController {
    bounds: StepBounds,
    size: f64,
    end_time: f64,
    /// Requested output times, increasing; `next_landing` indexes the first
    /// one after the accepted time.
    output_times: Vec<f64>,
    next_landing: usize,
    output_every: usize,
    max_increments: Option<usize>,
    increment: usize,
    counts: StepCounts,
    events: Vec<Box<dyn EventFunction>>,
    /// Value of each event function at the accepted state, and the side of
    /// its zero the accepted state is on (`±1`; the side after the
    /// crossing once a step has landed on it).
    event_values: Vec<f64>,
    event_sides: Vec<f64>,
    crossing: Option<Crossing>,
    /// The size of the step that first crossed the event being located
    /// (or last landed on), before it was shortened to land.
    approach: Option<f64>,
    /// The time and the event functions of the accepted state before the
    /// current one: their rates over the last step.
    previous_events: Option<(f64, Vec<f64>)>,
    /// The size of the next step is set by the error estimate.
    error_controlled: bool,
    /// Error estimate of the last accepted step (at least
    /// [`ERROR_MEMORY_FLOOR`]), for the proportional term of the step
    /// size.
    last_error: Option<f64>,
    /// The last attempt was rejected or cut back: the next accepted step
    /// does not let the size grow.
    rejected: bool,
    /// Accepted steps in a row after which the error estimate planned a
    /// step below [`COLLAPSE_RATIO`] of the first (`None` once warned).
    collapsed_steps: Option<usize>,
}

/// The steps have collapsed when, for [`COLLAPSE_STEPS`] accepted steps in
/// a row, the error estimate plans a step so short that the rest of the
/// analysis would take more than this many steps at that pace, or below
/// [`COLLAPSE_RATIO`] of the first step: a warning then says where the
/// error is largest.
pub const COLLAPSE_REMAINING_STEPS: f64 = 1e5;

/// See [`COLLAPSE_REMAINING_STEPS`].
pub const COLLAPSE_RATIO: f64 = 1e-4;

/// See [`COLLAPSE_REMAINING_STEPS`].
pub const COLLAPSE_STEPS: usize = 50;

impl StepController {
    /// The shortest step that lands on an event, [`LANDING_FLOOR`] of the
    /// largest step.
    fn landing_floor(&self) -> f64 {
        LANDING_FLOOR * self.bounds.max
    }

    /// Counts the accepted steps (of `size`, from `t`) after which the
    /// error estimate plans a collapsed step ([`COLLAPSE_REMAINING_STEPS`])
    /// and warns once, after [`COLLAPSE_STEPS`] in a row, naming where the
    /// error is largest: the steps follow a motion there far faster than
    /// the model's time step asks.
    fn watch_collapse<S: Stepper + ?Sized>(
        &mut self,
        size: f64,
        t: f64,
        increment: usize,
        stepper: &S,
        observer: &mut dyn Observer,
    ) {
        let Some(count) = self.collapsed_steps.as_mut() else {
            return;
        };
        let remaining = (self.end_time - t - size).max(0.0) / self.size;
        if remaining <= COLLAPSE_REMAINING_STEPS
            && self.size >= COLLAPSE_RATIO * self.bounds.initial
        {
            *count = 0;
            return;
        }
        *count += 1;
        if *count < COLLAPSE_STEPS {
            return;
        }
        self.collapsed_steps = None;
        let at = stepper.error_location().map_or(String::new(), |a| {
            format!(" The local error estimate is largest at {a}.")
        });
        observer.warning(&WarningInfo {
            increment,
            from: t,
            time: t + size,
            message: format!(
                "the steps collapsed: for {COLLAPSE_STEPS} steps the error estimate has asked for steps of about {:.3e} (the first was {:.3e}), which would take {:.1e} more steps to the end of the analysis; it stops if they fall below min_step = {:.3e}.{at} The steps follow a motion there far faster than the rest: a stiff and light part (a short beam, a small mass on a stiff spring or latch) vibrating, an impact, or a load or contact switched on at once. Damp it (rayleigh_beta of its section, damping of a spring latch, rho_infinity below 1 to damp the highest modes), make it less stiff or heavier if the model allows, or raise error_tolerance",
                self.size,
                self.bounds.initial,
                remaining,
                self.bounds.min
            ),
        });
    }

    /// A controller for steps within `bounds`, from increment 1 to
    /// `end_time`.
    pub fn new(bounds: StepBounds, end_time: f64) -> Self {
        Self {
            bounds,
            size: bounds.initial,
            end_time,
            output_times: Vec::new(),
            next_landing: 0,
            output_every: 1,
            max_increments: None,
            increment: 1,
            counts: StepCounts::default(),
            events: Vec::new(),
            event_values: Vec::new(),
            event_sides: Vec::new(),
            crossing: None,
            approach: None,
            previous_events: None,
            error_controlled: false,
            last_error: None,
            rejected: false,
            collapsed_steps: Some(0),
        }
    }

    /// Lands on `times` (increasing) and writes results there.
    pub fn with_output_times(mut self, times: &[f64]) -> Self {
        self.output_times = times.to_vec();
        self
    }

    /// Results are written every `n` increments (and at every landing).
    pub fn with_output_every(mut self, n: usize) -> Self {
        self.output_every = n.max(1);
        self
    }

    /// Stops after `n` increments.
    pub fn with_max_increments(mut self, n: usize) -> Self {
        self.max_increments = Some(n);
        self
    }

    /// Watches `events` from now on.
    pub fn with_events(mut self, events: Vec<Box<dyn EventFunction>>) -> Self {
        self.events = events;
        self
    }

    /// The size the next step will try.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// The largest step the controller takes (for fixed steps, the step).
    pub fn largest(&self) -> f64 {
        self.bounds.max
    }

    /// Sets the size the next step will try (within the bounds), as after
    /// an impact whose rebound must be seen at its top (docs/theory.md
    /// §16.4); the error estimate and the events size the steps after it.
    pub fn set_size(&mut self, size: f64) {
        if size.is_finite() && size > 0.0 {
            self.size = size.clamp(self.bounds.min, self.bounds.max);
        }
    }

    /// Resumes, after a step landed on an event, with the size of the step
    /// that first crossed it (if larger than the size the landing step's
    /// error estimate gave): the size the motion allowed before the event
    /// was located, for a restart whose accelerations are consistent
    /// again (a contact that closed, docs/theory.md §16.4).
    pub fn resume_after_landing(&mut self) {
        if let Some(size) = self.approach.take() {
            if size > self.size {
                self.set_size(size);
            }
        }
    }

    /// What the controller carries to the next step ([`StepMemory`]).
    pub fn memory(&self) -> StepMemory {
        StepMemory {
            size: self.size,
            error_controlled: self.error_controlled,
            last_error: self.last_error,
            event_values: self.event_values.clone(),
            event_sides: self.event_sides.clone(),
            crossing: self.crossing,
            approach: self.approach,
            previous_events: self.previous_events.clone(),
        }
    }

    /// Goes on from `memory`, taken from a controller of the same
    /// analysis at an accepted step (a restart): the next size (within
    /// this controller's bounds), the error estimate's memory and the
    /// events' state. Events whose number differs from the memory's are
    /// evaluated again at the first step, as at a start.
    pub fn resume(&mut self, memory: &StepMemory) {
        self.set_size(memory.size);
        self.error_controlled = memory.error_controlled;
        self.last_error = memory.last_error;
        if memory.event_values.len() == self.events.len()
            && memory.event_sides.len() == self.events.len()
        {
            self.event_values.clone_from(&memory.event_values);
            self.event_sides.clone_from(&memory.event_sides);
            self.crossing = memory.crossing.filter(|c| c.event < self.events.len());
            self.approach = memory.approach;
            self.previous_events = memory
                .previous_events
                .clone()
                .filter(|(_, g)| g.len() == self.events.len());
        }
    }

    /// The counts so far.
    pub fn counts(&self) -> StepCounts {
        self.counts
    }

    /// The end of the analysis.
    pub fn end_time(&self) -> f64 {
        self.end_time
    }

    /// Evaluates the event functions at the stepper's state (the start of
    /// the analysis); called by [`StepController::advance`] when needed.
    fn watch_events<S: Stepper + ?Sized>(&mut self, stepper: &S) {
        let (model, state) = stepper.current();
        self.event_values = self.events.iter().map(|e| e.value(model, state)).collect();
        self.event_sides = self
            .event_values
            .iter()
            .map(|&g| if g < 0.0 { -1.0 } else { 1.0 })
            .collect();
        self.previous_events = None;
    }

    /// The time from `t` (the accepted state) to the first crossing that
    /// the event functions' rates over the last step bring, if any: the
    /// zero of the line through their values at the last two accepted
    /// states, for each function moving towards its zero and farther
    /// from it than its tolerance.
    ///
    /// A crossing that the function's own rate at the accepted state
    /// brings within [`NEAR_CROSSING`] of the last step is anticipated
    /// from that rate instead (Newton's step on `g`): so near, the chord
    /// of the last step misses by `½ g̈ d (d + Δt)` where the tangent
    /// misses by `½ g̈ d²`.
    fn anticipated_crossing<S: Stepper + ?Sized>(&self, t: f64, stepper: &S) -> Option<f64> {
        let (t0, before) = self.previous_events.as_ref()?;
        let dt = t - t0;
        if dt <= 0.0 {
            return None;
        }
        let (model, state) = stepper.current();
        self.events
            .iter()
            .zip(&self.event_values)
            .zip(&self.event_sides)
            .zip(before)
            .filter(|(((event, _), _), _)| event.anticipated())
            .filter_map(|(((event, &g), &side), &g0)| {
                if g * side <= event.tolerance() {
                    return None;
                }
                let tangent = event
                    .rate(model, state)
                    .filter(|&r| r * side < 0.0)
                    .map(|r| -g / r)
                    .filter(|&d| d <= NEAR_CROSSING * dt);
                let chord = (g - g0) / dt;
                tangent.or_else(|| (chord * side < 0.0).then(|| -g / chord))
            })
            .filter(|d| d.is_finite())
            .reduce(f64::min)
    }

    /// The next time to land on after `t`: an output time or `end_time`.
    fn target(&mut self, t: f64) -> (f64, bool) {
        let snap = LANDING_SNAP * self.end_time.abs().max(t.abs());
        while self
            .output_times
            .get(self.next_landing)
            .is_some_and(|&o| o <= t + snap)
        {
            self.next_landing += 1;
        }
        match self.output_times.get(self.next_landing) {
            Some(&o) if o < self.end_time => (o, true),
            _ => (self.end_time, false),
        }
    }

    /// The factor on the step size asked by the error estimate `e` of a
    /// step (relative to its tolerance) with `previous` the estimate of the
    /// accepted step before, for an estimate of order `p` (`e ∝ hᵖ⁺¹`,
    /// `k = p + 1`): the PI controller of Gustafsson (1991),
    /// `(θ/e_n)^{k_I} (e_{n−1}/e_n)^{k_P}`, `k_I = 0.3/k`, `k_P = 0.4/k`,
    /// which holds `e` at `θ = ρᵏ` (`ρ` = [`ERROR_SAFETY`]: 0.81 for
    /// `k = 2`); without a previous estimate the elementary `ρ e^{−1/k}`
    /// (the same steady `e`). Within [`ERROR_FACTORS`] (docs/theory.md
    /// §13, §15.5).
    fn error_factor(&self, e: f64, previous: Option<f64>, order: f64) -> f64 {
        let k = order + 1.0;
        let e = e.max(f64::MIN_POSITIVE);
        let factor = match previous {
            Some(before) => {
                let (k_i, k_p) = (PI_INTEGRAL / k, PI_PROPORTIONAL / k);
                let target = ERROR_SAFETY.powf(k);
                (target / e).powf(k_i) * (before / e).powf(k_p)
            }
            None => ERROR_SAFETY * e.powf(-1.0 / k),
        };
        factor.clamp(ERROR_FACTORS.0, ERROR_FACTORS.1)
    }

    /// Attempts steps until one is accepted (cutting back, retrying for
    /// events and error estimates as needed), or stops the analysis.
    pub fn advance<S: Stepper + ?Sized>(
        &mut self,
        stepper: &mut S,
        observer: &mut dyn Observer,
    ) -> Result<Advance, ControlStop<S::Error>> {
        if self.event_values.len() != self.events.len() {
            self.watch_events(stepper);
        }
        loop {
            let t = stepper.time();
            if t >= self.end_time {
                return Ok(Advance::Finished);
            }
            if self.max_increments.is_some_and(|n| self.increment > n) {
                return Err(ControlStop::Limit {
                    increments: self.max_increments.unwrap_or(0),
                    time: t,
                });
            }
            let (target, output_time) = self.target(t);
            let snap = LANDING_SNAP * self.end_time.abs().max(t.abs());
            let mut size = self.size;
            let in_time = stepper.sized_in_time();
            if let Some(c) = self.crossing {
                // never below min_step: a crossing grazed by a slow motion
                // would otherwise shrink each landing step by 1/0.02
                let landing = c.span * c.fraction(self.event_values[c.event]);
                size = size.min(landing.max(self.landing_floor()));
            } else if in_time {
                // a step that the events' rates bring to a crossing ends
                // where they bring it (docs/theory.md §13, "Anticipation")
                if let Some(d) = self.anticipated_crossing(t, stepper) {
                    if d < size {
                        size = d.max(self.landing_floor());
                    }
                }
            }
            let mut lands = false;
            // the size planned before an output time cut it short (None if
            // it did not): the next step goes on from it
            let mut planned = None;
            if in_time {
                let before = size;
                size = size.min(target - t);
                if target - (t + size) <= snap {
                    size = target - t;
                    lands = true;
                }
                if output_time && lands && size < before {
                    planned = Some(before);
                }
            }
            let reach = if in_time { t + size } else { t };
            if stepper
                .update_active_set(reach, observer)
                .map_err(ControlStop::Stepper)?
            {
                self.counts.rank_analyses += 1;
            }

            let increment = self.increment;
            let (iterations, residuals, error) =
                match stepper.attempt(size, target, increment, observer) {
                    Attempt::Converged {
                        iterations,
                        residuals,
                        error,
                    } => (iterations, residuals, error),
                    Attempt::Failed(reason) => {
                        self.counts.wasted_iterations += reason.iterations_spent();
                        stepper.reject();
                        let next = size * CUTBACK;
                        if next < self.bounds.min {
                            return Err(ControlStop::Diverged {
                                increment,
                                time: t,
                                step: size,
                                reason,
                            });
                        }
                        self.counts.cutbacks += 1;
                        self.rejected = true;
                        observer.cutback(&CutbackInfo {
                            increment,
                            time: t,
                            failed_step: size,
                            next_step: next,
                            reason,
                        });
                        self.size = next;
                        continue;
                    }
                };

            // the local error: reject and shrink, or set the next size
            if let Some(e) = error {
                if e > 1.0 {
                    self.counts.wasted_iterations += iterations;
                    self.counts.error_rejections += 1;
                    self.rejected = true;
                    let at = stepper.error_location().unwrap_or_default();
                    stepper.reject();
                    let next = size * self.error_factor(e, None, stepper.error_order()).min(1.0);
                    if next < self.bounds.min {
                        return Err(ControlStop::Diverged {
                            increment,
                            time: t,
                            step: size,
                            reason: NewtonFailure::ErrorEstimate { error: e, at },
                        });
                    }
                    observer.rejected(&RejectionInfo {
                        increment,
                        time: t,
                        step: size,
                        next_step: next,
                        error: e,
                        at,
                    });
                    self.size = next;
                    continue;
                }
                self.error_controlled = true;
                if let Some(planned) = planned {
                    // cut short to land on an output time: its estimate,
                    // scaled to the planned size (e ∝ hᵏ), may shorten the
                    // next step but not lengthen it, and the PI memory
                    // keeps the last full step's (a sliver before an
                    // output time would otherwise make the steps grow back
                    // from it, by at most ERROR_FACTORS.1 a step)
                    let k = stepper.error_order() + 1.0;
                    let scaled = e * (planned / size).powf(k);
                    let factor = self.error_factor(scaled, None, stepper.error_order());
                    self.size = (planned * factor.min(1.0)).clamp(self.bounds.min, self.bounds.max);
                } else {
                    let mut factor = self.error_factor(e, self.last_error, stepper.error_order());
                    if self.rejected {
                        // no growth straight after a rejection or a cut-back
                        factor = factor.min(1.0);
                    }
                    self.last_error = Some(e.max(ERROR_MEMORY_FLOOR));
                    let grown = (size * factor).clamp(self.bounds.min, self.bounds.max);
                    self.size = if iterations <= EASY_ITERATIONS {
                        grown
                    } else {
                        grown.min(size)
                    };
                    self.watch_collapse(size, t, increment, &*stepper, observer);
                }
            }
            self.rejected = false;

            // events: land on the first crossing
            let mut landed = Vec::new();
            if !self.events.is_empty() {
                let (model, state) = stepper.current();
                let values: Vec<f64> = self.events.iter().map(|e| e.value(model, state)).collect();
                // the crossing beyond its tolerance nearest the start
                let mut first: Option<(usize, f64)> = None;
                for (i, (&g1, ev)) in values.iter().zip(&self.events).enumerate() {
                    let (g0, side, tol) =
                        (self.event_values[i], self.event_sides[i], ev.tolerance());
                    if g1.abs() <= tol && g0.abs() > tol {
                        landed.push(i);
                    } else if g1 * side < 0.0 && g1.abs() > tol {
                        let c = Crossing {
                            event: i,
                            span: size,
                            g_b: g1,
                            retries: 0,
                        };
                        let theta = c.fraction(g0);
                        if first.is_none_or(|(_, th)| theta < th) {
                            first = Some((i, theta));
                        }
                    }
                }
                if let Some((i, theta)) = first {
                    let retries = self.crossing.map_or(0, |c| c.retries) + 1;
                    // a crossing nearer than min_step to the start is taken
                    // as happening within this step (the event's own
                    // restart closes what is left of its gap)
                    if retries <= MAX_EVENT_RETRIES && theta * size >= self.landing_floor() {
                        // retried shortened, from the same start
                        if self.crossing.is_none() {
                            self.approach = Some(size);
                        }
                        self.counts.event_retries += 1;
                        self.counts.wasted_iterations += iterations;
                        stepper.reject();
                        self.crossing = Some(Crossing {
                            event: i,
                            span: size,
                            g_b: values[i],
                            retries,
                        });
                        continue;
                    }
                    // not located: taken as happening within this step
                    landed.push(i);
                }
                for &i in &landed {
                    // the accepted state counts as past the crossing
                    self.event_sides[i] = -self.event_sides[i];
                }
                match &mut self.previous_events {
                    Some((t0, before)) => {
                        *t0 = t;
                        before.clone_from(&self.event_values);
                    }
                    None => self.previous_events = Some((t, self.event_values.clone())),
                }
                for (i, &g) in values.iter().enumerate() {
                    self.event_values[i] = g;
                    if !landed.contains(&i) && g != 0.0 {
                        self.event_sides[i] = g.signum();
                    }
                }
                // a step short of the crossing: the crossing is now nearer,
                // and the end kept is weighted down (Illinois)
                self.crossing = match self.crossing {
                    Some(c) if landed.is_empty() && c.span > size => Some(Crossing {
                        span: c.span - size,
                        g_b: 0.5 * c.g_b,
                        ..c
                    }),
                    _ => None,
                };
            }

            // accept
            let mut reached = stepper.attempted_time();
            if lands || reached >= self.end_time {
                reached = if reached >= self.end_time {
                    self.end_time
                } else {
                    target
                };
            }
            let on_output_time = output_time
                && (reached - target).abs() <= LANDING_SNAP * self.end_time.abs().max(1.0);
            let info = IncrementInfo {
                increment,
                time: reached,
                step: reached - t,
                iterations,
                residuals,
                output: increment.is_multiple_of(self.output_every)
                    || reached >= self.end_time
                    || on_output_time
                    || !landed.is_empty(),
            };
            // the next size, before the stepper reports the step
            if error.is_none() && iterations <= EASY_ITERATIONS && !self.error_controlled {
                self.size = (self.size * GROWTH).min(self.bounds.max);
            }
            if let Err(e) = stepper.accept(&info, observer) {
                if stepper.recorded(&e) {
                    self.counts.increments += 1;
                    self.counts.iterations += iterations;
                    self.increment += 1;
                }
                return Err(ControlStop::Stepper(e));
            }
            for &i in &landed {
                observer.event(&EventInfo {
                    increment,
                    time: reached,
                    name: self.events[i].name(),
                    value: self.event_values[i],
                });
            }
            self.counts.increments += 1;
            self.counts.iterations += iterations;
            self.increment += 1;
            return Ok(Advance::Accepted(info));
        }
    }
}

#[cfg(test)]
mod tests {
    //! The controller against steppers written for the tests: a scalar
    //! "analysis" `x(t)` whose Newton fails on steps above a threshold,
    //! whose local error grows as `h³`, or whose state crosses a value.
    use super::*;
    use crate::model::input::ModelInput;
    use crate::so3::Vec3;

    /// The smallest model (its state carries `x` in a node's position).
    fn model() -> Model {
        let mut m = ModelInput::new("point");
        m.add_node(1, [0.0; 3]);
        m.add_node(2, [1.0, 0.0, 0.0]);
        m.add_section("s", [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
        m.add_beam(1, [1, 2], "s", Some([0.0, 0.0, 1.0]));
        m.fix(1, &["all"]);
        Model::from_input(&m).unwrap()
    }

    /// `x(t) = t²` reached in one "iteration" per step, failing on steps
    /// above `fail_above`; an error estimate `(h/h_err)³` if `h_err` is set.
    struct Scalar {
        model: Model,
        accepted: State,
        attempted: State,
        fail_above: f64,
        h_err: Option<f64>,
        sizes: Vec<f64>,
        rank_changes_at: Option<f64>,
        active: bool,
    }

    impl Scalar {
        fn new(fail_above: f64, h_err: Option<f64>) -> Self {
            let model = model();
            // x(0) = 0
            let mut s = model.initial_state();
            s.x[1] = Vec3::zeros();
            Self {
                model,
                accepted: s.clone(),
                attempted: s,
                fail_above,
                h_err,
                sizes: Vec::new(),
                rank_changes_at: None,
                active: false,
            }
        }
    }

    impl Stepper for Scalar {
        type Error = ();
        fn current(&self) -> (&Model, &State) {
            (&self.model, &self.attempted)
        }
        fn time(&self) -> f64 {
            self.accepted.time
        }
        fn sized_in_time(&self) -> bool {
            true
        }
        fn update_active_set(&mut self, time: f64, _: &mut dyn Observer) -> Result<bool, ()> {
            let active = self.rank_changes_at.is_some_and(|t| time >= t);
            let changed = active != self.active;
            self.active = active;
            Ok(changed)
        }
        fn attempt(&mut self, size: f64, _: f64, _: usize, _: &mut dyn Observer) -> Attempt {
            self.sizes.push(size);
            if size > self.fail_above {
                return Attempt::Failed(NewtonFailure::MaxIterations {
                    iterations: 3,
                    relative_residual: 1.0,
                });
            }
            let t = self.accepted.time + size;
            self.attempted.time = t;
            self.attempted.x[1] = Vec3::new(t * t, 0.0, 0.0);
            Attempt::Converged {
                iterations: 1,
                residuals: vec![1.0, 0.0],
                error: self.h_err.map(|h| (size / h).powi(3)),
            }
        }
        fn attempted_time(&self) -> f64 {
            self.attempted.time
        }
        fn reject(&mut self) {
            self.attempted.clone_from(&self.accepted);
        }
        fn accept(&mut self, info: &IncrementInfo, _: &mut dyn Observer) -> Result<(), ()> {
            self.attempted.time = info.time;
            self.accepted.clone_from(&self.attempted);
            Ok(())
        }
    }

    /// Every accepted increment.
    fn run(c: &mut StepController, s: &mut Scalar) -> Vec<IncrementInfo> {
        let mut out = Vec::new();
        loop {
            match c.advance(s, &mut crate::analysis::NoObserver) {
                Ok(Advance::Accepted(i)) => out.push(i),
                Ok(Advance::Finished) => return out,
                Err(ControlStop::Diverged { .. }) => panic!("diverged"),
                Err(_) => panic!("stopped"),
            }
        }
    }

    /// Steps grow by 1.5 after easy steps up to the largest, are halved
    /// after a failure, and the last one lands exactly on end_time.
    #[test]
    fn steps_grow_are_cut_back_and_land_on_the_end() {
        let bounds = StepBounds {
            initial: 0.1,
            min: 1e-6,
            max: 0.4,
        };
        let mut c = StepController::new(bounds, 1.0);
        let mut s = Scalar::new(0.3, None);
        let steps = run(&mut c, &mut s);
        // 0.1, 0.15, 0.225, then 0.3375 fails (> 0.3) and 0.16875 is tried
        let tried: Vec<f64> = s.sizes.iter().map(|h| (h * 1e6).round() / 1e6).collect();
        assert_eq!(&tried[..5], &[0.1, 0.15, 0.225, 0.3375, 0.16875]);
        assert_eq!(c.counts().cutbacks, 1);
        // exactly on the end, every step's t the sum of the steps
        let last = steps.last().unwrap();
        assert_eq!(last.time, 1.0);
        assert!(steps.iter().all(|i| i.step <= 0.3));
        let total: f64 = steps.iter().map(|i| i.step).sum();
        assert!((total - 1.0).abs() < 1e-12);
        // growth never above the largest step
        assert!(s.sizes.iter().all(|&h| h <= 0.4 + 1e-15));
    }

    /// Requested output times are landed on exactly and written.
    #[test]
    fn steps_land_on_output_times() {
        let bounds = StepBounds {
            initial: 0.3,
            min: 1e-6,
            max: 0.3,
        };
        let times = [0.25, 0.5, 0.55];
        let mut c = StepController::new(bounds, 1.0)
            .with_output_times(&times)
            .with_output_every(1000);
        let mut s = Scalar::new(1.0, None);
        let steps = run(&mut c, &mut s);
        let reached: Vec<f64> = steps.iter().map(|i| i.time).collect();
        for t in times {
            let i = reached.iter().position(|&r| r == t).expect("landed on it");
            assert!(steps[i].output, "written at {t}");
        }
        // only the landings and the end are written
        assert_eq!(steps.iter().filter(|i| i.output).count(), 4);
        assert_eq!(*reached.last().unwrap(), 1.0);
    }

    /// With an error estimate `(h/h₀)³`, rejected steps have an error above
    /// 1 and the accepted ones settle at `0.9 h₀`, where the estimate is
    /// `0.9³`, the PI controller's target: the estimate, not the
    /// iterations, sets the step. The deviation from it decays as 0.8ⁿ
    /// (the roots 0.8 and −0.5 of `z² − 0.3 z − 0.4`, the PI recurrence of
    /// `log h`), below 1e-6 after 80 steps.
    #[test]
    fn the_error_estimate_sets_the_step() {
        let bounds = StepBounds {
            initial: 0.2,
            min: 1e-6,
            max: 1.0,
        };
        let h0 = 0.01;
        let mut c = StepController::new(bounds, 1.0);
        let mut s = Scalar::new(1.0, Some(h0));
        let steps = run(&mut c, &mut s);
        assert!(c.counts().error_rejections >= 1);
        // every accepted step has an error of at most 1
        assert!(steps.iter().all(|i| i.step <= h0 * (1.0 + 1e-12)));
        // the steady step (the last one shortened to land on the end)
        let steady = 0.9 * h0;
        let settled = &steps[80..steps.len() - 1];
        assert!(
            settled
                .iter()
                .all(|i| (i.step - steady).abs() < 1e-6 * steady),
            "{:?}",
            settled.iter().map(|i| i.step).collect::<Vec<_>>()
        );
    }

    /// After a rejection the next accepted step is not larger than the one
    /// that passed: an estimate `(h/h₀)³` that jumps to 8 times its value
    /// for one attempt (a step across a sudden load) is rejected, and the
    /// sizes tried after it never exceed the accepted retry until a step
    /// has been accepted without rejection.
    #[test]
    fn no_growth_after_a_rejection() {
        struct Jump(Scalar, usize);
        impl Stepper for Jump {
            type Error = ();
            fn current(&self) -> (&Model, &State) {
                self.0.current()
            }
            fn time(&self) -> f64 {
                self.0.time()
            }
            fn sized_in_time(&self) -> bool {
                true
            }
            fn update_active_set(&mut self, t: f64, o: &mut dyn Observer) -> Result<bool, ()> {
                self.0.update_active_set(t, o)
            }
            fn attempt(&mut self, size: f64, t: f64, i: usize, o: &mut dyn Observer) -> Attempt {
                self.1 += 1;
                match self.0.attempt(size, t, i, o) {
                    Attempt::Converged {
                        iterations,
                        residuals,
                        error,
                    } => Attempt::Converged {
                        iterations,
                        residuals,
                        // the 30th attempt meets the jump
                        error: error.map(|e| if self.1 == 30 { 8.0 * e.max(0.2) } else { e }),
                    },
                    failed => failed,
                }
            }
            fn attempted_time(&self) -> f64 {
                self.0.attempted_time()
            }
            fn reject(&mut self) {
                self.0.reject()
            }
            fn accept(&mut self, info: &IncrementInfo, o: &mut dyn Observer) -> Result<(), ()> {
                self.0.accept(info, o)
            }
        }
        let bounds = StepBounds {
            initial: 0.005,
            min: 1e-6,
            max: 1.0,
        };
        let mut c = StepController::new(bounds, 1.0);
        let mut s = Jump(Scalar::new(1.0, Some(0.01)), 0);
        let mut sizes = Vec::new();
        while let Ok(Advance::Accepted(i)) = c.advance(&mut s, &mut crate::analysis::NoObserver) {
            sizes.push(i.step);
        }
        let tried = &s.0.sizes;
        assert_eq!(c.counts().error_rejections, 1, "{tried:?}");
        // attempt 30 rejected, 31 accepted, 32 not larger than 31
        assert!(tried[30] < tried[29]);
        assert!(tried[31] <= tried[30], "{tried:?}");
    }

    /// `x = t²` crosses 0.3 at `t = √0.3`: the step across it is rejected
    /// and retried until `x` lands within the tolerance 1e-10, the event is
    /// reported once and written, and the run goes on to the end.
    #[test]
    fn a_step_across_an_event_is_retried_to_land_on_it() {
        struct Crosses;
        impl EventFunction for Crosses {
            fn name(&self) -> String {
                "x = 0.3".into()
            }
            fn value(&self, _: &Model, s: &State) -> f64 {
                s.x[1].x - 0.3
            }
            fn tolerance(&self) -> f64 {
                1e-10
            }
        }
        #[derive(Default)]
        struct Events(Vec<EventInfo>);
        impl Observer for Events {
            fn event(&mut self, e: &EventInfo) {
                self.0.push(e.clone());
            }
        }
        let bounds = StepBounds {
            initial: 0.1,
            min: 1e-9,
            max: 0.1,
        };
        let mut c = StepController::new(bounds, 1.0)
            .with_events(vec![Box::new(Crosses)])
            .with_output_every(1000);
        let mut s = Scalar::new(1.0, None);
        let mut events = Events::default();
        let mut steps = Vec::new();
        while let Advance::Accepted(i) = c.advance(&mut s, &mut events).map_err(|_| ()).unwrap() {
            steps.push(i);
        }
        assert_eq!(events.0.len(), 1, "{:?}", events.0);
        let e = &events.0[0];
        assert!((e.time - 0.3f64.sqrt()).abs() < 1e-9, "t = {}", e.time);
        assert!(e.value.abs() <= 1e-10);
        let at = steps.iter().find(|i| i.time == e.time).unwrap();
        assert!(at.output);
        assert!(c.counts().event_retries >= 1);
        assert_eq!(steps.last().unwrap().time, 1.0);
    }

    /// A step that the event's rate over the last step brings to its
    /// zero ends there: `g = √x − 0.55 = t − 0.55` moves at a constant
    /// rate, so the step from t = 0.5 is cut to 0.05 and lands on the
    /// crossing without a retry (docs/theory.md §13, "Anticipation").
    #[test]
    fn a_crossing_the_rates_predict_is_landed_on_without_a_retry() {
        struct Linear;
        impl EventFunction for Linear {
            fn name(&self) -> String {
                "t = 0.55".into()
            }
            fn value(&self, _: &Model, s: &State) -> f64 {
                s.x[1].x.sqrt() - 0.55
            }
            fn tolerance(&self) -> f64 {
                1e-10
            }
            fn anticipated(&self) -> bool {
                true
            }
        }
        let bounds = StepBounds {
            initial: 0.1,
            min: 1e-9,
            max: 0.1,
        };
        let mut c = StepController::new(bounds, 1.0)
            .with_events(vec![Box::new(Linear)])
            .with_output_every(1000);
        let mut s = Scalar::new(1.0, None);
        let steps = run(&mut c, &mut s);
        assert_eq!(c.counts().event_retries, 0);
        let k = steps
            .iter()
            .position(|i| (i.time - 0.55).abs() <= 1e-12)
            .expect("a step ends on the crossing");
        assert!((steps[k].step - 0.05).abs() <= 1e-12, "{}", steps[k].step);
        assert!(steps[k].output, "the landing is written");
        // the steps before it were not shortened: the rate is taken over
        // accepted steps only
        assert!(steps[..k].iter().all(|i| (i.step - 0.1).abs() <= 1e-12));
        assert_eq!(steps.last().unwrap().time, 1.0);
    }

    /// The stepper is asked about its active set before every attempt, at
    /// the time the step reaches; a change is counted.
    #[test]
    fn the_active_set_is_checked_before_each_attempt() {
        let bounds = StepBounds {
            initial: 0.1,
            min: 1e-6,
            max: 0.1,
        };
        let mut c = StepController::new(bounds, 1.0).with_output_times(&[0.45]);
        let mut s = Scalar::new(1.0, None);
        s.rank_changes_at = Some(0.45);
        run(&mut c, &mut s);
        assert_eq!(c.counts().rank_analyses, 1);
    }
}
