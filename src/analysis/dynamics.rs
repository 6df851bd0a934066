//! Implicit dynamics: the Lie-group generalised-α method (Arnold & Brüls
//! 2007; Brüls, Cardona & Arnold 2012, "Lie group generalized-α time
//! integration of constrained flexible multibody systems", Mech. Mach.
//! Theory 48) for the index-3 equations of motion
//!
//! ```text
//! M(q) v̇ + g(q, v, t) + Bᵀ(pΦ − kλ) = 0,     −kΦ(q, t) = 0
//! ```
//!
//! with the joints' augmented Lagrangian (docs/theory.md §15, equation
//! labels D1–D15 there):
//! - parameters from the spectral radius `ρ∞` (D1);
//! - the step `q_{n+1} = q_n ∘ exp(h Δq_n)` on the nodes' group, with
//!   the velocity, acceleration and pseudo-acceleration updates (D2–D4),
//!   from a predictor at `v̇_{n+1} = 0` (D5);
//! - Newton on the correction `x = h δΔq` with the iteration matrix
//!   `S = β′M + γ′C + K T(hΔq)` (D6–D7), whose constraint rows and
//!   multiplier columns are scaled so that it stays well conditioned as
//!   `h → 0` (D8); each iterate's residual is assembled first and `S`
//!   only for a correction that needs new factors, which modified Newton
//!   keeps across iterations and steps while they serve
//!   ([`NewtonMethod`], docs/theory.md §15.1);
//! - consistent initial accelerations and multipliers (D9), initial
//!   velocities checked against the constraints (D10);
//! - a local error estimate `(β − 1/6) h² (a_{n+1} − a_n)` for the step
//!   controller (D11), filtered by the iteration matrix to leave out the
//!   vibrations the step does not resolve (D11a) and measured node by
//!   node in the metric of the mass (D11b);
//! - the energy balance of every step ([`super::energy`], D12);
//! - after every step, the projection of the converged velocities on the
//!   velocity constraints (D13), with the accelerations and multipliers
//!   along the method's relations (D13a), or consistent with the
//!   projected state on a very short step (D13b): without it the index-3
//!   scheme is unstable on turning constraints once `hω` exceeds a bound
//!   that vanishes as `ρ∞ → 1` (docs/theory.md §15.7);
//! - the positions projected on the constraints before the restart after
//!   an impact (D14), and `a − v̇` not enlarged when the step grows (D15),
//!   so that neither kicks the multipliers into the alternating transient
//!   of the index-3 scheme.
//!
//! Node velocities are `(ẋ, Ω)`, `ẋ` global and `Ω` material, as in the
//! inertia kernels (docs/theory.md §11.1). Multipliers are kept in the
//! scaling of the model (`k λ` the force with the model's `k`), whatever
//! the step: a state passes from statics to dynamics and back unchanged.
//!
//! The analysis is a [`Stepper`] of the shared [`StepController`]: time
//! steps are cut back when Newton fails, sized by the error estimate
//! (unless `adaptive = false`), and land on output times, events and
//! `end_time`. It runs at once ([`DynamicAnalysis::run`]) or step by step
//! ([`DynamicAnalysis::start`], [`DynamicAnalysis::advance`],
//! [`DynamicAnalysis::state`], [`DynamicAnalysis::finish`]).

use std::sync::Arc;
use std::time::Instant;

use super::constraints::ConstraintRows;
use super::control::{
    Advance, Attempt, ControlStop, EventFunction, StepBounds, StepController, StepMemory, Stepper,
};
use super::energy::{Energies, EnergyBalance};
use super::impact::{self, ContactInfo, ContactKind, LockInfo};
use super::newton::{non_finite_origin, NewtonFailure, NewtonSolver, SINGULAR_PIVOT};
use super::settings::{AngularVelocities, DynamicSettings, NewtonMethod};
use super::{ConvergenceNorms, IncrementInfo, IterationInfo, Observer, WarningInfo};
use crate::assembly::SpatialColumns;
use crate::dofs::{DofKind, DofMap, NO_EQUATION};
use crate::elements::{ConstraintKind, ConstraintScaling, EvalContext, Need};
use crate::io::number::plain;
use crate::linalg::{
    smallest_relative_pivot, SolveError, SolverCounts, SparseMatrix, SymmetricFirst,
};
use crate::model::{Id, Model, Prescribed};
use crate::so3::{self, Mat3, Vec3};
use crate::state::State;

/// `c`: a residual within `c ε` of the force flux through its dof, or a
/// correction within `c ε` of the size of its unknown, is round-off (as in
/// statics, docs/theory.md §7.1).
const FLOOR_FACTOR: f64 = 4.0;

/// A residual that has stopped decreasing (by less than half in an
/// iteration) while within this many `ε·flux` of zero is at its round-off
/// plateau and accepted (as [`super::newton`]'s plateau).
const PLATEAU_FACTOR: f64 = 1024.0;

/// Unknowns whose diagonal mass is below this fraction of the largest of
/// their kind have no mass: their initial acceleration is taken from their
/// stiffness row (D9).
const MASSLESS: f64 = 1e-12;

/// Relative step of the finite differences along the motion that give the
/// constraints' first and second time derivatives at the start (D9, D10):
/// the motion over the step is 1e-3 of the model's size (or of the span of
/// the analysis); with Richardson extrapolation the truncation error is
/// ~1e-12 and the round-off ~1e-10 of the derivatives.
const MOTION_STEP: f64 = 1e-3;

/// Relative step of the central difference that gives `Φ̇` for the
/// velocity projection (D13): the motion over the step is 1e-5 of the
/// model's size, the truncation error `e²Φ⃛/6` ~2e-11 and the round-off
/// `ε/1e-5` ~2e-11 of the velocities.
const PROJECTION_STEP: f64 = 1e-5;

/// Steps shorter than this fraction of the motion time `T_m` (D13) take
/// the accelerations and multipliers consistent with their projected
/// state (D9) instead of D13a (D13b): there `δv/(γh)` would pass the
/// round-off of `Φ̇`, ~2e-11 of the velocities, on to `a` as more than
/// ~4e-3 of the accelerations (docs/theory.md §15.7).
const SHORT_STEP: f64 = 1e-8;

/// Applications of the filter of the local error estimate (D11a): the
/// first cancels the growth `∝ (ωh)²` of the estimate of a vibration the
/// step does not resolve, the second makes it decay as `(ωh)⁻²`.
const FILTER_PASSES: usize = 2;

/// Modified Newton (docs/theory.md §15.1) makes new factors of the
/// iteration matrix at an iterate whose progress measure (the relative
/// residual over its tolerance, or the constraint violation over its,
/// whichever is larger) is more than this fraction of the last iterate's.
/// An iteration with kept factors costs a residual assembly and two
/// triangular solves, about a fifth of one that assembles and factors `S`
/// (the pendulum of bench/peer); at a contraction of 0.1 the kept factors
/// gain a decade of the residual per iteration, and from 1e-6 of the flux
/// to 1e-8 (the default tolerance) they take two iterations, less than one
/// new factorisation. Poorer contractions mean the factors are far from
/// the tangent (a sudden load, a joint's law changing branch, a large
/// rotation): new ones restore Newton's quadratic convergence.
const POOR_CONTRACTION: f64 = 0.1;

/// Longest wait, in steps, before factors are carried into a step again
/// after carried factors served poorly: the waits double from one step,
/// so that a motion where they never serve pays for a trial at most every
/// this many steps (a residual assembly and a solve).
const CARRY_WAIT: usize = 64;

/// Initial velocities whose constraint rates exceed this fraction of the
/// velocity scale violate the joints (D10).
const VELOCITY_TOLERANCE: f64 = 1e-6;

/// Normwise backward error of the solves of the Newton corrections by
/// GMRES (docs/theory.md §8, "Inexact corrections"), relative to Newton's
/// residual tolerance: the linearised residual a correction leaves is
/// then a hundredth of what Newton accepts; at most 10⁻¹⁰, at least the
/// solver's default 10⁻¹⁴.
const CORRECTION_BACKWARD_ERROR: f64 = 1e-2;

/// Corrections larger than this times the model size, or than this in
/// radians, mean the iteration matrix is singular or nearly so.
const RUNAWAY_CORRECTION: f64 = 1e6;

/// A step whose linear solve fails, or whose correction runs away, after
/// iterations that raised the force or moment residual above this times
/// the predictor's, diverged ([`NewtonFailure::Diverged`]): the matrix is
/// singular at an iterate far from the motion, which says nothing of the
/// structure's supports.
const DIVERGED_GROWTH: f64 = 1e3;

/// Largest rotation of a node in one converged step, in radians: the
/// incremental rotation vector `h |Δq_θ|` or the turn at the end
/// velocity `h |Ω_{n+1}|`. A rotation vector of `2π` is the identity:
/// beyond half a turn an increment cannot tell its turn from a shorter one
/// the other way (as the joint angles, docs/joints.md §3.3), and Newton
/// may converge to a spurious root where a light node spins whole turns
/// per step while its positions look right (docs/theory.md §15.5). 1 rad
/// keeps a margin of π; the step is cut back.
pub const MAX_ROTATION_STEP: f64 = 1.0;

/// Largest change of a node's rotation increment from the predictor to the
/// converged step (rad): Newton carried the node more than half a turn
/// from where the step started it, past the turn an increment can tell
/// (docs/theory.md §15.5); the step is cut back.
pub const MAX_ROTATION_CORRECTION: f64 = std::f64::consts::PI;

/// Largest change of a node's translation from the predictor to the
/// converged step, as a multiple of the model's size.
pub const MAX_TRANSLATION_CORRECTION: f64 = 1.0;

/// A change of the energy balance error `E` in one step by more than this
/// fraction of the largest energy of the motion so far is reported as a
/// warning (docs/theory.md §15.6).
pub const ENERGY_JUMP: f64 = 0.05;

/// After a latch's lock, the steps grow back from the step that landed on
/// it by at most this factor a step (docs/theory.md §16, "Restart"): the
/// generalised-α method at `ρ∞ = 0.5` starting from consistent
/// accelerations multiplies the energy of a mode displaced from its
/// equilibrium by up to `0.004 (hω)²` in one step of `hω ≫ 1`, and by at most
/// 1 when each step is at most 4 times the one before.
pub const LOCK_REGROWTH: f64 = 4.0;

/// The steps after a restart grow back from at least this fraction of
/// the largest step (the step, with fixed steps), however short the step
/// that landed on the event (docs/theory.md §16, "Regrowth"): with steps
/// of 0.01 s the first step after a lock is then at least 4e-5 s, 1/28 of
/// the half period of the ringing of tests/latch_peaks.rs, whose peak it
/// follows within 0.2 % (at 1e-2 the peak falls 18 % short).
pub const RESTART_FLOOR: f64 = 1e-3;

/// The first step of an analysis is at most the one over which the
/// initial angular accelerations turn a node by this (rad; docs/theory.md
/// §15.5, "First step").
pub const START_ROTATION: f64 = 0.1;

/// With fixed steps, a local error estimate above this fraction of the
/// step's motion is noted once (docs/theory.md §15.5).
pub const FIXED_STEP_ERROR_NOTE: f64 = 1e-2;

/// With fixed steps, the local error estimate is made on the first this
/// many steps and then on one step in this many (docs/theory.md §15.5).
pub const FIXED_STEP_CHECKS: usize = 10;

/// The constants of the generalised-α method (D1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralizedAlpha {
    /// `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`.
    pub alpha_m: f64,
    /// `α_f = ρ∞/(ρ∞ + 1)`.
    pub alpha_f: f64,
    /// `γ = ½ + α_f − α_m`.
    pub gamma: f64,
    /// `β = ¼ (γ + ½)²`.
    pub beta: f64,
}

impl GeneralizedAlpha {
    /// The second-order, unconditionally stable set for the spectral
    /// radius `rho_infinity` ∈ [0, 1] at infinite frequency (Chung &
    /// Hulbert 1993; D1).
    pub fn new(rho_infinity: f64) -> Self {
        let r = rho_infinity;
        let alpha_m = (2.0 * r - 1.0) / (r + 1.0);
        let alpha_f = r / (r + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta: 0.25 * (gamma + 0.5).powi(2),
        }
    }

    /// `β′ = (1 − α_m)/((1 − α_f) β h²)`: `δv̇ = β′ x` (D6).
    pub fn beta_prime(&self, h: f64) -> f64 {
        (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.beta * h * h)
    }

    /// `(1/(γh), c)`, `c = (1 − α_m)/((1 − α_f) γ h)`: a change `δv` of
    /// the velocities made along the method's relations (D6 with
    /// `x = (βh/γ) δv`, positions kept) changes `a` by `δv/(γh)` and `v̇`
    /// by `c δv` (D13a).
    pub fn velocity_to_accelerations(&self, h: f64) -> (f64, f64) {
        (
            1.0 / (self.gamma * h),
            (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.gamma * h),
        )
    }

    /// `γ′ = γ/(β h)`: `δv = γ′ x` (D6).
    pub fn gamma_prime(&self, h: f64) -> f64 {
        self.gamma / (self.beta * h)
    }
}

/// Why a dynamic analysis stopped before `end_time`.
#[derive(Debug, thiserror::Error)]
pub enum DynamicError {
    /// A step failed with the smallest allowed size.
    #[error("no convergence at step {step} from t = {time:.6}: the step {size:.3e} failed and a smaller one would be below min_step: {reason}; largest residual at {location}")]
    Diverged {
        /// Step that failed.
        step: usize,
        /// Last converged time.
        time: f64,
        /// Last size tried.
        size: f64,
        /// Last failure.
        reason: NewtonFailure,
        /// The unknown with the largest residual (relative to its group's
        /// flux) at the last iteration, with its element.
        location: String,
    },
    /// No free unknown has mass: the equations of motion have no inertia
    /// to integrate (a static or kinematic analysis is what such a model
    /// takes).
    #[error("the model has no mass on its free unknowns, so a dynamic analysis has no motion to follow: give its beam sections a mass_per_length (and inertia_per_length), or add rigid bodies or point masses; for a load history without inertia run a static analysis")]
    NoMass,
    /// Constraints removed as redundant turned out violated: they
    /// contradict the others (a driver pushing a joint through a locked
    /// latch, two drivers of one coordinate).
    #[error("inconsistent constraints at t = {time:.6}: {constraint} was found redundant but is now violated ({violation:.1e} × its tolerance); two joints, drivers or latches impose incompatible motions")]
    Inconsistent {
        /// Time of the step that violated it (not kept).
        time: f64,
        /// The violated constraint.
        constraint: String,
        /// Violation relative to the tolerance.
        violation: f64,
    },
    /// A converged step took an element where its law does not hold (a
    /// shell turned past the rotations of its linear theory, a beam or a
    /// rotational spring past half a turn of a relative rotation).
    #[error("{element}, between t = {from} and t = {time}: {reason}")]
    LawViolated {
        /// The element, as in messages (`shell 12`, `beam 3`).
        element: String,
        /// Time at the start of the step.
        from: f64,
        /// Time reached.
        time: f64,
        /// What happened.
        reason: String,
    },
    /// The initial velocities move the joints apart.
    #[error("the initial velocities violate {constraint}: its rate is {rate:.3e} (tolerance {tolerance:.1e}); give the connected nodes velocities of one rigid motion, or velocities the joint allows")]
    InconsistentVelocity {
        /// The constraint (`joint 3 equation 2`).
        constraint: String,
        /// `Φ̇` there.
        rate: f64,
        /// Its tolerance.
        tolerance: f64,
    },
    /// The initial accelerations could not be found.
    #[error("no initial accelerations at t = {time}: {failure}")]
    Initial {
        /// Start time.
        time: f64,
        /// Why.
        failure: NewtonFailure,
    },
    /// A stop or contact starts beyond its limit: its coordinate is on the
    /// wrong side of it, which no impact law can resolve.
    #[error("{what} starts beyond its limit at t = {time}: {detail}")]
    StartsBeyondLimit {
        /// The stop or contact (`stop 3`, `contact 30`).
        what: String,
        /// Start time.
        time: f64,
        /// The coordinate, the limit, by how much, and what to check.
        detail: String,
    },
    /// The impact of a latch locking could not be computed.
    #[error("at t = {time}: the lock of {latches}: {reason}")]
    Impact {
        /// The latches locking (`latch 4`).
        latches: String,
        /// Time of the lock.
        time: f64,
        /// Why.
        reason: String,
    },
    /// A result file could not be written.
    #[error("writing results: {0}")]
    Output(#[from] std::io::Error),
}

/// Factorisations, solves and GMRES iterations of the two sparse solvers
/// of a dynamic analysis ([`SymmetricFirst`], docs/theory.md §8).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct LinearSolverCounts {
    /// The iteration matrix `S` (D7).
    pub iteration_matrix: SolverCounts,
    /// The constrained mass system (D9, D13).
    pub mass_system: SolverCounts,
}

/// What a dynamic analysis did.
#[derive(Debug)]
pub struct DynamicOutcome {
    /// Last converged state.
    pub state: State,
    /// Accepted time steps.
    pub steps: usize,
    /// Steps rejected: cut back after Newton failed, or rejected by the
    /// error estimate.
    pub rejected_steps: usize,
    /// Of which rejected by the error estimate.
    pub error_rejections: usize,
    /// Newton iterations of the accepted steps.
    pub iterations: usize,
    /// Newton iterations of rejected steps.
    pub wasted_iterations: usize,
    /// Steps cut back after Newton failed.
    pub cutbacks: usize,
    /// Numeric factorisations of the iteration matrix (at most one per
    /// iteration; with modified Newton, fewer: docs/theory.md §15.1).
    pub factorisations: usize,
    /// Numeric factorisations of the constrained mass system (D9, D13,
    /// D14): one per step with constraints, and one per restart.
    pub mass_factorisations: usize,
    /// Steps whose modified Newton iterations failed with kept factors and
    /// were retried with fresh ones.
    pub newton_retries: usize,
    /// What the sparse solvers of the iteration matrix and of the
    /// constrained mass system did.
    pub linear_solver: LinearSolverCounts,
    /// Constraint equations removed as redundant (the most at any time).
    pub redundant_constraints: usize,
    /// Rank analyses of the constraints run again during the analysis.
    pub rank_analyses: usize,
    /// Steps retried shortened to land on an event.
    pub event_retries: usize,
    /// The latches that locked, in order (docs/joints.md §6.2).
    pub locks: Vec<LockInfo>,
    /// The events of the stops, in order (docs/joints.md §6.3).
    pub contacts: Vec<ContactInfo>,
    /// Time reached.
    pub time: f64,
    /// Energies at the last converged state.
    pub energies: Energies,
    /// Wall-clock time in seconds.
    pub wall_time: f64,
    /// `None` if `end_time` was reached.
    pub error: Option<DynamicError>,
}

pub use super::statics::Step;

/// What a motion's state alone does not hold and a dynamic analysis
/// continued from one of its converged steps needs to go on as if never
/// stopped ([`DynamicAnalysis::continued`]; kept in restart files), taken
/// once the size of the next step is chosen
/// ([`DynamicAnalysis::continuation`], [`Observer::continuation`]). The
/// fields after `last_step` are absent from files of version 1 of the
/// restart format: a run continued from those starts its steps again
/// from `time_step`, with a first error estimate over one step
/// (docs/results.md, "Restart files").
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Continuation {
    /// The energy balance at the step: work, dissipation and `T₀ + V₀`
    /// go on from it.
    pub energies: Energies,
    /// Size of the step that ended there (`None` after an impact or any
    /// other restart of the accelerations): the predictor of the next step
    /// scales `a − v̇` with the ratio of the sizes (D5), and the error
    /// estimate weighs its difference with it (D11).
    pub last_step: Option<f64>,
    /// The step controller's memory: the size of the next step, the error
    /// estimate's memory, the events' values and sides.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<StepMemory>,
    /// The steps are growing back after a lock, a closure or a very short
    /// step, by at most [`LOCK_REGROWTH`] a step (docs/theory.md §16).
    #[serde(default)]
    pub regrowing: bool,
    /// `a_{n−1}`, the pseudo-accelerations of the step before, by node and
    /// by coordinate, for the difference of the error estimate (D11);
    /// empty when the accelerations were restarted at the step.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub previous_pseudo_acceleration: Vec<[f64; 6]>,
    /// `a_{n−1}` of the coordinates.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub previous_coordinate_pseudo_accelerations: Vec<f64>,
    /// The mass scales of translations and rotations of D8, as last set by
    /// the consistent accelerations (D9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_scale: Option<[f64; 2]>,
}

impl Continuation {
    /// What makes this continuation of an analysis from `start` to `end`
    /// not one its run could have written, if anything (a restart file
    /// edited or damaged): a step size that is not positive and finite or
    /// longer than the analysis, a controller memory or a mass scale that
    /// is not finite and positive.
    pub fn invalid(&self, start: f64, end: f64) -> Option<String> {
        let span = (end - start).abs();
        let step = |what: &str, h: f64| {
            (!(h.is_finite() && h > 0.0 && h <= span * (1.0 + 1e-9))).then(|| {
                format!(
                    "motion.{what} = {} is not a step of the analysis (positive, at most its span {})",
                    plain(h),
                    plain(span)
                )
            })
        };
        if let Some(h) = self.last_step {
            if let Some(e) = step("last_step", h) {
                return Some(e);
            }
        }
        if let Some(c) = &self.control {
            if let Some(e) = step("control.size", c.size()) {
                return Some(e);
            }
            if let Some(e) = c.invalid() {
                return Some(format!("motion.control: {e}"));
            }
        }
        if let Some(m) = self.mass_scale {
            if !m.iter().all(|v| v.is_finite() && *v > 0.0) {
                return Some(format!(
                    "motion.mass_scale = [{}, {}] must be positive and finite",
                    plain(m[0]),
                    plain(m[1])
                ));
            }
        }
        None
    }
}

/// An implicit dynamic analysis of a model (see the module documentation).
pub struct DynamicAnalysis {
    model: Arc<Model>,
    settings: DynamicSettings,
    scheme: GeneralizedAlpha,
    solver: NewtonSolver,
    events: Vec<Box<dyn EventFunction>>,
    /// The start state is a converged step of this analysis (a restart):
    /// its velocities, accelerations and multipliers are kept.
    continued: bool,
    /// What the run that wrote it knew besides, if given.
    continuation: Option<Continuation>,
    run: Option<Run>,
}

/// The analysis under way.
struct Run {
    accepted: State,
    state: State,
    /// `Δq_n` of the attempted step, per node (by component) and per
    /// coordinate.
    dq: Vec<[f64; 6]>,
    dq_coordinates: Vec<f64>,
    /// `Δq_n` of the attempted step at its predictor (D5), for the checks
    /// of the converged step ([`Dynamics::spurious`]).
    dq_predicted: Vec<[f64; 6]>,
    /// The checks of the run: energies at the start, largest energy so
    /// far, notes already given.
    watch: Watch,
    /// `a_n` for the attempted step, adjusted to its size (D5).
    a_start: Vec<[f64; 6]>,
    a_start_coordinates: Vec<f64>,
    /// Size of the last accepted step.
    last_step: Option<f64>,
    /// `a_{n−1}` (empty before the second step), its rotation part, at a
    /// node of the spatial scheme, turned into the frame of `R_n`.
    a_before: Vec<[f64; 6]>,
    a_before_coordinates: Vec<f64>,
    /// The spatial scheme (§15.9): whether each node's rotation rates are
    /// combined in the frame of `R_n` in the attempted step, and there
    /// `(Ω′, Ω̇′, a′)`, which the state holds turned into the frame of
    /// `R_{n+1}`: `Ω = Λ Ω′`, `Λ = exp(−hΔΘ~)`.
    spatial: Vec<bool>,
    turned: Vec<[Vec3; 3]>,
    controller: Option<StepController>,
    work: Work,
    balance: EnergyBalance,
    energies: Energies,
    /// Largest diagonal mass of translations and of rotations (`m_scale`
    /// of D8).
    mass_scale: [f64; 2],
    /// The matrices of the constrained mass system (D9, D13), and of the
    /// mass matrix of the error estimate (D11a).
    mass_system: MassSystem,
    /// The factors of the iteration matrix and what they were made for.
    factors: IterationFactors,
    /// The span of the analysis, `end_time − t₀` (D13).
    span: f64,
    rates: RateWork,
    redundant: usize,
    /// The unknown with the largest residual at the last failed attempt.
    location: String,
    /// The latches locked so far, and the rank analyses their locks ran.
    locks: Vec<LockInfo>,
    lock_rank_analyses: usize,
    /// The events of the stops so far.
    contacts: Vec<ContactInfo>,
    /// The size of the step after a rebound from a stop: the time its
    /// coordinate takes to rise to the top of its flight (§16.4).
    rebound_step: Option<f64>,
    /// A stop closed at the last step: the steps resume with the size they
    /// had before landing on it (§16.4).
    closed: bool,
    /// A latch locked at a step not yet followed by a step of the
    /// controller's own size: the steps grow back by at most
    /// [`LOCK_REGROWTH`] a step (§16).
    regrowing: bool,
    started: Instant,
    finished: bool,
    error: Option<DynamicError>,
}

/// Work space of the iterations, allocated once per numbering.
#[derive(Default)]
struct Work {
    /// `T(hΔθ)` of every node (D7).
    factors: Vec<Mat3>,
    /// The spatial scheme's columns of every node in it (§15.9).
    spatial: Vec<Option<SpatialColumns>>,
    rhs: Vec<f64>,
    /// The force flux of the step, by dof: the larger of the flux at the
    /// predictor and at the iterate (see [`Dynamics::norms`]).
    flux: Vec<f64>,
    /// Matrix entries in a constraint row or multiplier column, with the
    /// kinds of their row and column (0 none, 1 distance, 2 angle).
    scaled: Vec<(usize, u8, u8)>,
    /// Equations numbered when `scaled` was built (`None` before; a model
    /// without constraints leaves `scaled` empty once built).
    n_equations: Option<usize>,
    /// The local error `e` of the step by equation (D11), its filtered
    /// `ê` (D11a), a matrix product, and the solver's residual and flux
    /// kept across the assembly of the mass matrix.
    error: Vec<f64>,
    filtered: Vec<f64>,
    product: Vec<f64>,
    spare: Vec<f64>,
    node_sums: Vec<[f64; 5]>,
    kept: Vec<f64>,
    kept_flux: Vec<f64>,
    /// Where the last error estimate was largest: a node's index, or an
    /// element coordinate's equation.
    error_peak: Option<ErrorPeak>,
}

/// Where a step's local error estimate was largest.
#[derive(Clone, Copy, Debug, Default)]
enum ErrorPeak {
    /// At a node (its index).
    Node(usize),
    /// At an element coordinate (its equation).
    #[default]
    Coordinate,
}

impl Work {
    /// Rebuilds the lists for the numbering `dofs` and the pattern
    /// `matrix`, if it changed.
    fn prepare(&mut self, dofs: &DofMap, matrix: &SparseMatrix, n_nodes: usize) {
        self.factors.resize(n_nodes, Mat3::identity());
        self.flux.resize(6 * n_nodes, 0.0);
        if self.n_equations == Some(dofs.n_equations()) {
            return;
        }
        let code = |eq: usize| match dofs.equation_kind(eq) {
            DofKind::Multiplier(ConstraintKind::Distance) => 1u8,
            DofKind::Multiplier(ConstraintKind::Angle) => 2u8,
            _ => 0u8,
        };
        self.scaled.clear();
        for (k, (row, col, _)) in matrix.entries().enumerate() {
            let (a, b) = (code(row), code(col));
            if a != 0 || b != 0 {
                self.scaled.push((k, a, b));
            }
        }
        self.n_equations = Some(dofs.n_equations());
        self.rhs.clear();
        self.rhs.resize(dofs.n_equations(), 0.0);
    }
}

/// The right factors of the rotation columns of the iteration matrix at
/// the nodes of the spatial scheme (docs/theory.md §15.9), from the
/// attempted step's `ΔΘ`, its factors `T(hΔΘ)` (set already) and the
/// state's `Ω`, `Ω̇`.
fn spatial_columns(run: &mut Run, h: f64) {
    let work = &mut run.work;
    work.spatial.resize(run.spatial.len(), None);
    for (node, c) in work.spatial.iter_mut().enumerate() {
        *c = run.spatial[node].then(|| {
            let (dq, v, a) = (
                &run.dq[node],
                &run.state.velocity[node],
                &run.state.acceleration[node],
            );
            let t = work.factors[node];
            SpatialColumns {
                turn: so3::exp_matrix(&(Vec3::new(dq[3], dq[4], dq[5]) * h)).transpose(),
                damping: so3::skew(&Vec3::new(v[3], v[4], v[5])) * t,
                mass: so3::skew(&Vec3::new(a[3], a[4], a[5])) * t,
            }
        });
    }
}

/// The factors of the iteration matrix `S` (D7–D8) that the Newton
/// iterations solve with, and what they were made for: kept across
/// iterations and steps by modified Newton (docs/theory.md §15.1), and
/// used by the error estimate's filter (D11a).
#[derive(Default)]
struct IterationFactors {
    /// The factors of [`Self::matrix`] (its symmetric part, or its LU:
    /// [`SymmetricFirst`], docs/theory.md §8), the symbolic analysis made
    /// once per numbering.
    lu: Option<SymmetricFirst>,
    /// The matrix factored, scaled (D8), on the solver's pattern.
    matrix: Option<SparseMatrix>,
    /// The solver's numbering of the symbolic analysis.
    numbering: usize,
    /// The step size and the scaling of the factors; `None` when there are
    /// none to keep (none yet, a failed solve, a restart).
    made_for: Option<(f64, Scale)>,
    /// Numeric factorisations so far.
    count: usize,
    /// What the solvers of earlier symbolic analyses did (the current
    /// one's are in [`Self::lu`]).
    retired: SolverCounts,
    /// Modified Newton attempts retried with fresh factors so far.
    retries: usize,
    /// Steps still to start from fresh factors after carried ones served
    /// poorly, and the wait after the next such step (doubled each time,
    /// up to [`CARRY_WAIT`]; back to 0 when carried factors serve well).
    carry_wait: usize,
    carry_backoff: usize,
    /// Iterations of the last converged step that started from new
    /// factors: factors carried into a step serve if it converges in as
    /// many.
    fresh_iterations: usize,
}

/// The stiffness and the mass matrix of the constrained mass system (D9,
/// D13), kept from one step to the next while the pattern is unchanged.
#[derive(Default)]
struct MassSystem {
    stiffness: Option<SparseMatrix>,
    mass: Option<SparseMatrix>,
    /// `∂r/∂v` and the rest of the split, for the rows of velocity
    /// constraints (D13).
    damping: Option<SparseMatrix>,
    damping_rest: Option<SparseMatrix>,
    /// By equation: the diagonal of the mass matrix, the kind, whether
    /// the unknown has no mass, whether a constraint holds it, and the
    /// scale of the multiplier rows and columns (D8 with `β′ = 1`).
    diagonal: Vec<f64>,
    kinds: Vec<EquationKind>,
    light: Vec<bool>,
    held: Vec<bool>,
    s_eq: Vec<f64>,
    /// The elements with multipliers, for the stiffness of the
    /// projections (D13–D14).
    constraints: Option<ConstraintRows>,
    /// The constrained mass system's matrix (scaled), and its own factors,
    /// so that its factorisation leaves the iteration matrix's alone.
    system: Option<SparseMatrix>,
    lu: Option<SymmetricFirst>,
    /// Numeric factorisations so far.
    factorisations: usize,
    /// What the solvers of earlier symbolic analyses did.
    retired: SolverCounts,
}

/// Work space of `Φ̇` for the velocity projection (D13), kept from one
/// step to the next.
struct RateWork {
    /// The elements with multipliers, which write the rows of `Φ`.
    rows: ConstraintRows,
    /// The state moved along its velocities.
    moved: State,
    /// `−kΦ` ahead along the motion, by dof.
    plus: Vec<f64>,
    /// `−kΦ̇`, by dof.
    rate: Vec<f64>,
}

/// The scale factors `s` of distance and angle constraints (D8): rows
/// and multiplier columns of the iteration matrix are multiplied by them,
/// and the multiplier corrections solved for are `δλ/s`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Scale([f64; 3]);

impl Scale {
    /// `s = max(k, β′ m_scale)/k` per kind, `k` the model's scaling.
    fn new(model: &ConstraintScaling, beta_prime: f64, mass: [f64; 2]) -> Self {
        let s = |k: f64, m: f64| (k.max(beta_prime * m) / k).max(1.0);
        Self([1.0, s(model.force.0, mass[0]), s(model.moment.0, mass[1])])
    }

    /// Multiplies the constraint rows and multiplier columns of `matrix`.
    fn apply(&self, work: &Work, matrix: &mut SparseMatrix) {
        let values = matrix.values_mut();
        for &(k, a, b) in &work.scaled {
            values[k] *= self.0[a as usize] * self.0[b as usize];
        }
    }

    fn of(&self, kind: DofKind) -> f64 {
        match kind {
            DofKind::Multiplier(ConstraintKind::Distance) => self.0[1],
            DofKind::Multiplier(ConstraintKind::Angle) => self.0[2],
            _ => 1.0,
        }
    }
}

/// The analysis seen by the step controller.
struct Dynamics<'a> {
    model: &'a Model,
    settings: &'a DynamicSettings,
    scheme: GeneralizedAlpha,
    solver: &'a mut NewtonSolver,
    run: &'a mut Run,
}

impl DynamicAnalysis {
    /// Prepares the analysis of `model` with `settings`: dof numbering,
    /// sparse pattern, buffers.
    pub fn new(model: impl Into<Arc<Model>>, settings: DynamicSettings) -> Self {
        let model = model.into();
        let solver = NewtonSolver::new(&model);
        Self {
            scheme: GeneralizedAlpha::new(settings.rho_infinity),
            model,
            settings,
            solver,
            events: Vec::new(),
            continued: false,
            continuation: None,
            run: None,
        }
    }

    /// Starts from a converged step of this analysis (a restart file's
    /// state) rather than from rest or the end of another analysis: the
    /// start keeps the state's velocities, accelerations,
    /// pseudo-accelerations, multipliers and internal variables instead
    /// of solving for consistent ones (D9–D10) or locking latches and
    /// closing stops at their limits, so that the steps repeat those of
    /// the run that wrote the state. With `from` (what that run knew at
    /// the state) the energy balance goes on, and the first step is
    /// sized, predicted and its error estimated as they were there (the
    /// step controller's memory, the regrowth after a lock, `a_{n−1}`);
    /// without, work and dissipation count from the state and the steps
    /// start from `time_step`.
    pub fn continued(mut self, from: Option<Continuation>) -> Self {
        self.continued = true;
        self.continuation = from;
        self
    }

    /// Watches `event` during the analysis ([`super::control`]).
    pub fn with_event(mut self, event: Box<dyn EventFunction>) -> Self {
        self.events.push(event);
        self
    }

    /// The model.
    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    /// The settings.
    pub fn settings(&self) -> &DynamicSettings {
        &self.settings
    }

    /// The constants of the method.
    pub fn scheme(&self) -> GeneralizedAlpha {
        self.scheme
    }

    /// Number of free unknowns.
    pub fn n_equations(&self) -> usize {
        self.solver.dofs.n_equations()
    }

    /// Number of stored entries of the iteration matrix.
    pub fn nnz(&self) -> usize {
        self.solver.nnz()
    }

    /// Runs from `start` (the model's initial state, or the final state of
    /// an analysis before) to `end_time`.
    pub fn run(&mut self, start: State, observer: &mut dyn Observer) -> DynamicOutcome {
        let mut step = self.start(start, observer);
        while let Step::Increment(_) = step {
            step = self.advance(observer);
        }
        self.finish()
    }

    /// Starts the analysis from `start`: the rank analysis of the
    /// constraints, the check of the initial velocities and the consistent
    /// initial accelerations and multipliers (step 0).
    pub fn start(&mut self, start: State, observer: &mut dyn Observer) -> Step {
        let started = Instant::now();
        let model = &*self.model;
        let s = &self.settings;
        let mut state = start;
        let t0 = state.time;
        model.apply_prescribed(&mut state, t0);
        prescribed_rates(model, &mut state, t0);
        let mut run = Run {
            accepted: state.clone(),
            dq: vec![[0.0; 6]; model.n_nodes()],
            dq_coordinates: vec![0.0; state.coordinates.len()],
            dq_predicted: vec![[0.0; 6]; model.n_nodes()],
            watch: Watch::default(),
            a_start: vec![[0.0; 6]; model.n_nodes()],
            a_start_coordinates: vec![0.0; state.coordinates.len()],
            last_step: self.continuation.as_ref().and_then(|c| c.last_step),
            a_before: Vec::new(),
            a_before_coordinates: Vec::new(),
            spatial: vec![false; model.n_nodes()],
            turned: vec![[Vec3::zeros(); 3]; model.n_nodes()],
            state,
            controller: None,
            work: Work::default(),
            balance: self
                .continuation
                .as_ref()
                .map_or_else(EnergyBalance::new, |c| {
                    EnergyBalance::continuing(&c.energies)
                })
                .with_alpha_f(self.scheme.alpha_f),
            energies: Energies::default(),
            mass_scale: [0.0; 2],
            mass_system: MassSystem::default(),
            factors: IterationFactors::default(),
            // a continued run (a restart within the analysis) keeps the
            // span of the analysis, as the run never stopped did
            span: (s.end_time - if self.continued { s.start_time } else { t0 }).abs(),
            rates: RateWork {
                rows: ConstraintRows::new(model, &self.solver.dofs),
                moved: State::default(),
                plus: Vec::new(),
                rate: Vec::new(),
            },
            redundant: 0,
            location: String::new(),
            locks: Vec::new(),
            lock_rank_analyses: 0,
            contacts: Vec::new(),
            rebound_step: None,
            closed: false,
            regrowing: false,
            started,
            finished: false,
            error: None,
        };

        // latches at their value lock, without impact (docs/joints.md §6.2),
        // and stops at a limit close; a continued run's state is a
        // converged step whose latches and stops are as its events left
        // them (a rebound leaves a stop open at its limit)
        if !self.continued {
            impact::lock_at_start(model, &mut run.state);
            impact::close_at_start(model, &mut run.state);
        }
        if let Some(e) = impact::beyond_limit_at_start(model, &run.state) {
            run.error = Some(e);
            self.run = Some(run);
            return Step::Stopped;
        }

        // rank of the constraints: redundant ones out
        let rank = self.solver.constraint_rank(model, &run.state, t0);
        run.redundant = rank.redundant.len();
        for &k in &rank.redundant {
            run.state.multipliers[k] = 0.0;
        }
        if !rank.redundant.is_empty() {
            observer.note(&format!(
                "{} redundant constraint equation(s) removed (over-constrained: joints, supports or drivers that repeat one another); their multipliers are zero and the others carry the loads",
                rank.redundant.len()
            ));
        }

        // initial velocities against the constraints, D10 (a continued
        // run's were checked when it started)
        if !self.continued {
            if let Err(e) = check_velocities(model, &mut self.solver, &run.state, s.end_time) {
                run.error = Some(e);
                self.run = Some(run);
                return Step::Stopped;
            }
        }

        // consistent initial accelerations and multipliers, D9; a
        // continued run keeps its own (the solve still gives the mass
        // scales of D8)
        let kept = self.continued.then(|| run.state.clone());
        match initial_accelerations(model, &mut self.solver, &mut run, s.end_time) {
            Ok(()) => {}
            Err(failure) => {
                run.error = Some(DynamicError::Initial { time: t0, failure });
                self.run = Some(run);
                return Step::Stopped;
            }
        }
        if run.mass_scale == [0.0; 2] {
            run.error = Some(DynamicError::NoMass);
            self.run = Some(run);
            return Step::Stopped;
        }
        if let Some(kept) = kept {
            run.state = kept;
            let (_, assembler, _) = self.solver.system();
            let ctx = EvalContext {
                dynamics: true,
                ..model.context(t0, Need::RESIDUAL)
            };
            assembler.assemble(model, &ctx, &run.state);
        }
        // a continued run's internal variables are those its step was
        // accepted with, after its events (a stop closed there takes the
        // scale of its load at the next step, as in the run never stopped)
        if !self.continued {
            model.update_internal(&mut run.state);
        }
        run.accepted.clone_from(&run.state);
        let residual = self.solver.residual().to_vec();
        run.energies = run.balance.record(model, &run.state, Some(&residual));
        run.watch.start = run.energies;
        observer.energies(&run.energies);
        let info = IncrementInfo {
            increment: 0,
            time: t0,
            step: 0.0,
            iterations: 0,
            residuals: Vec::new(),
            output: true,
        };
        let written = observer.increment(&info, model, &run.state, &residual);

        // fixed steps grow back after a cut-back to time_step, no further
        let bounds = StepBounds {
            initial: s.time_step,
            min: s.min_step,
            max: if s.adaptive {
                s.max_step
            } else {
                s.time_step.min(s.max_step)
            },
        };
        run.controller = Some(
            StepController::new(bounds, s.end_time)
                .with_output_times(&s.output_times)
                .with_output_every(s.output_every)
                .with_events(
                    impact::latch_events(model)
                        .into_iter()
                        .chain(impact::stop_events(model))
                        .chain(std::mem::take(&mut self.events))
                        .collect(),
                ),
        );
        if !self.continued {
            if let (Some(h), Some(c)) = (
                start_step(&self.solver.dofs, &run.state),
                run.controller.as_mut(),
            ) {
                if h < c.size() {
                    c.set_size(h);
                }
            }
        }
        // a continued run goes on with what the run that wrote its state
        // knew there: the controller's next size and memory, the regrowth
        // after a lock, a_{n−1} and the mass scales
        if let Some(c) = self.continuation.as_ref().filter(|_| self.continued) {
            if let (Some(memory), Some(controller)) = (&c.control, run.controller.as_mut()) {
                controller.resume(memory);
            }
            run.regrowing = c.regrowing;
            if c.previous_pseudo_acceleration.len() == model.n_nodes()
                && c.previous_coordinate_pseudo_accelerations.len() == run.state.coordinates.len()
            {
                run.a_before.clone_from(&c.previous_pseudo_acceleration);
                run.a_before_coordinates
                    .clone_from(&c.previous_coordinate_pseudo_accelerations);
            }
            if let Some(scale) = c.mass_scale {
                run.mass_scale = scale;
            }
        }
        let continuation = observer.continuation(&run.accepted, &Self::continuation_of(&run));
        let written = written.and(continuation);
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

    /// What a run continued from the last accepted step needs besides its
    /// state ([`Continuation`]), once the next step's size is chosen
    /// (`None` before [`Self::start`]).
    pub fn continuation(&self) -> Option<Continuation> {
        self.run.as_ref().map(Self::continuation_of)
    }

    fn continuation_of(run: &Run) -> Continuation {
        Continuation {
            energies: run.energies,
            last_step: run.last_step,
            control: run.controller.as_ref().map(StepController::memory),
            regrowing: run.regrowing,
            previous_pseudo_acceleration: run.a_before.clone(),
            previous_coordinate_pseudo_accelerations: run.a_before_coordinates.clone(),
            mass_scale: Some(run.mass_scale),
        }
    }

    /// One more accepted time step (with the cut-backs and retries it
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
        let mut stepper = Dynamics {
            model: &self.model,
            settings: &self.settings,
            scheme: self.scheme,
            solver: &mut self.solver,
            run,
        };
        let before = stepper.run.accepted.time;
        let result = controller.advance(&mut stepper, observer);
        let run = stepper.run;
        // a step accepted (reported to the observer, even if the observer
        // then stopped the analysis), of this size
        let step = (run.accepted.time > before).then_some(run.accepted.time - before);
        if let Some(size) = run.rebound_step.take() {
            controller.set_size(size);
        } else if std::mem::take(&mut run.closed) {
            controller.resume_after_landing();
        }
        if let (true, Some(step)) = (run.regrowing, step) {
            // after a lock, at most LOCK_REGROWTH times the step accepted,
            // or than RESTART_FLOOR of the largest step
            let cap = LOCK_REGROWTH * step.max(RESTART_FLOOR * controller.largest());
            if controller.size() > cap {
                controller.set_size(cap);
            } else {
                run.regrowing = false;
            }
        }
        run.controller = Some(controller);
        // the step's continuation, for restart files
        let result = match (step, result) {
            (Some(_), Ok(advance)) => observer
                .continuation(&run.accepted, &Self::continuation_of(run))
                .map(|()| advance)
                .map_err(|e| ControlStop::Stepper(e.into())),
            (Some(_), Err(stop)) => {
                // the observer stopped the analysis at the step it was
                // told of (an interruption): its continuation is still
                // given, and the stop is the error reported
                let _ = observer.continuation(&run.accepted, &Self::continuation_of(run));
                Err(stop)
            }
            (None, result) => result,
        };
        if !matches!(result, Ok(Advance::Accepted(_))) {
            for w in run.watch.warnings(self.settings.rho_infinity) {
                observer.warning(&w);
            }
        }
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
                    } => DynamicError::Diverged {
                        step: increment,
                        time,
                        size: step,
                        reason,
                        location: std::mem::take(&mut run.location),
                    },
                    // no increment limit is set
                    ControlStop::Limit { time, .. } => DynamicError::Diverged {
                        step: 0,
                        time,
                        size: 0.0,
                        reason: NewtonFailure::MaxIterations {
                            iterations: 0,
                            relative_residual: 0.0,
                        },
                        location: String::new(),
                    },
                    ControlStop::Stepper(e) => e,
                });
                Step::Stopped
            }
        }
    }

    /// The last converged state (`None` before [`Self::start`]).
    pub fn state(&self) -> Option<&State> {
        self.run.as_ref().map(|r| &r.accepted)
    }

    /// The energies at the last converged state.
    pub fn energies(&self) -> Option<&Energies> {
        self.run.as_ref().map(|r| &r.energies)
    }

    /// The size the next step will try.
    pub fn next_step_size(&self) -> Option<f64> {
        self.run
            .as_ref()
            .and_then(|r| r.controller.as_ref())
            .map(|c| c.size())
    }

    /// Why the analysis stopped, if it did.
    pub fn error(&self) -> Option<&DynamicError> {
        self.run.as_ref().and_then(|r| r.error.as_ref())
    }

    /// The iteration matrix `S` (D7–D8) at the last converged state, for
    /// a step of size `h`, with its constraint rows and multiplier columns
    /// scaled (D8) if `scaled`: a copy in equation numbering, for studies
    /// of its conditioning. Its rotation columns are those of the material
    /// scheme (D7), whichever scheme the analysis runs (§15.9).
    pub fn iteration_matrix(&mut self, h: f64, scaled: bool) -> Option<SparseMatrix> {
        let run = self.run.as_mut()?;
        let model = &*self.model;
        let scale = Scale::new(&model.scaling, self.scheme.beta_prime(h), run.mass_scale);
        let (dofs, assembler, _) = self.solver.system();
        run.work.prepare(dofs, &assembler.matrix, model.n_nodes());
        let ctx = dynamic_context(model, run.accepted.time, &self.scheme, h);
        for (node, f) in run.work.factors.iter_mut().enumerate() {
            *f = so3::tangent(&Vec3::new(
                h * run.dq[node][3],
                h * run.dq[node][4],
                h * run.dq[node][5],
            ));
        }
        assembler.assemble_factored(model, &ctx, &run.accepted, &run.work.factors);
        if scaled {
            scale.apply(&run.work, &mut assembler.matrix);
        }
        Some(assembler.matrix.clone())
    }

    /// Ends the analysis: what it did and its last converged state.
    pub fn finish(&mut self) -> DynamicOutcome {
        let run = self.run.take();
        let wall_time = run
            .as_ref()
            .map_or(0.0, |r| r.started.elapsed().as_secs_f64());
        let contacts = run.as_ref().map_or(Vec::new(), |r| r.contacts.clone());
        let factored = run.as_ref().map_or([0; 3], |r| {
            [
                r.factors.count,
                r.mass_system.factorisations,
                r.factors.retries,
            ]
        });
        let solvers = run.as_ref().map_or(Default::default(), |r| {
            let total = |retired: SolverCounts, lu: &Option<SymmetricFirst>| {
                let mut c = retired;
                if let Some(lu) = lu {
                    c += lu.counts();
                }
                c
            };
            LinearSolverCounts {
                iteration_matrix: total(r.factors.retired, &r.factors.lu),
                mass_system: total(r.mass_system.retired, &r.mass_system.lu),
            }
        });
        let (state, counts, redundant, energies, error, locks) = match run {
            Some(r) => {
                let mut counts = r.controller.map(|c| c.counts()).unwrap_or_default();
                counts.rank_analyses += r.lock_rank_analyses;
                (
                    r.accepted,
                    counts,
                    r.redundant,
                    r.energies,
                    r.error,
                    r.locks,
                )
            }
            None => (
                State::default(),
                Default::default(),
                0,
                Energies::default(),
                None,
                Vec::new(),
            ),
        };
        DynamicOutcome {
            time: state.time,
            state,
            steps: counts.increments,
            rejected_steps: counts.cutbacks + counts.error_rejections,
            error_rejections: counts.error_rejections,
            iterations: counts.iterations,
            wasted_iterations: counts.wasted_iterations,
            cutbacks: counts.cutbacks,
            factorisations: factored[0],
            mass_factorisations: factored[1],
            newton_retries: factored[2],
            linear_solver: solvers,
            redundant_constraints: redundant.max(self.solver.redundant_count()),
            rank_analyses: counts.rank_analyses,
            event_retries: counts.event_retries,
            locks,
            contacts,
            energies,
            wall_time,
            error,
        }
    }
}

/// The evaluation context of a step of size `h` ending at `time`: inertia
/// forces in the residual, the stiffness and the inertia matrix with
/// weights `(γ′, β′)` (D7). The scaling `k` and penalty `p` are the
/// model's: the penalty is not raised with `β′`, since `p Bᵀ Φ` would then
/// amplify the round-off of `Φ` into spurious forces as `h → 0`.
fn dynamic_context<'a>(
    model: &'a Model,
    time: f64,
    scheme: &GeneralizedAlpha,
    h: f64,
) -> EvalContext<'a> {
    let ctx = model.context(
        time,
        Need::with_inertia(scheme.gamma_prime(h), scheme.beta_prime(h)),
    );
    // velocity constraints as lengths τ A v, τ = 1/γ′: their rows of S are
    // A + τ ∂(Av)/∂q T, scaled by D8 as the distance constraints' B T
    EvalContext {
        dynamics: true,
        scaling: ConstraintScaling {
            rate_time: 1.0 / scheme.gamma_prime(h),
            ..ctx.scaling
        },
        ..ctx
    }
}

/// Whether an element has a velocity constraint (rolling discs).
fn has_velocity_constraints(model: &Model) -> bool {
    model
        .elements
        .iter()
        .any(|e| (0..e.n_multipliers()).any(|k| e.velocity_constraint(k)))
}

/// Which dofs are the multipliers of velocity constraints
/// ([`crate::elements::Element::velocity_constraint`]), by dof.
fn velocity_rows(model: &Model, dofs: &DofMap) -> Vec<bool> {
    let mut rows = vec![false; dofs.n_dofs()];
    for (i, e) in model.elements.iter().enumerate() {
        let o = dofs.first_multiplier() + model.offsets(i).multipliers;
        for k in 0..e.n_multipliers() {
            rows[o + k] = e.velocity_constraint(k);
        }
    }
    rows
}

/// The residual of velocity constraints, `−kτ A v` (τ = 1), at `state`
/// and its derivative along the motion at `v̇ = 0` (`−kτ Ȧ v`, central
/// differences with Richardson extrapolation as in D9), by dof.
fn velocity_constraint_rates(
    model: &Model,
    solver: &mut NewtonSolver,
    state: &State,
    end_time: f64,
) -> (Vec<f64>, Vec<f64>) {
    let e = motion_step(model, state, end_time);
    let mut residual = |s: &State| {
        let (_, assembler, _) = solver.system();
        let ctx = EvalContext {
            dynamics: true,
            ..model.context(s.time, Need::RESIDUAL)
        };
        assembler.assemble(model, &ctx, s);
        assembler.residual.clone()
    };
    let r0 = residual(state);
    let mut first = Vec::new();
    for h in [e, 0.5 * e] {
        let rp = residual(&moved(model, state, h));
        let rm = residual(&moved(model, state, -h));
        first.push(
            rp.iter()
                .zip(&rm)
                .map(|(p, m)| (p - m) / (2.0 * h))
                .collect::<Vec<f64>>(),
        );
    }
    let rate = first[0]
        .iter()
        .zip(&first[1])
        .map(|(a, b)| (4.0 * b - a) / 3.0)
        .collect();
    (r0, rate)
}

/// Velocities and accelerations of the prescribed components at `t`, from
/// central differences of their curves: `ẋ = f′(t) value`; for a
/// prescribed rotation `R = exp(f ψ~) R₀`, `Ω = Rᵀψ f′` and `Ω̇ = Rᵀψ f″`.
fn prescribed_rates(model: &Model, state: &mut State, t: f64) {
    let d = 1e-5 * t.abs().max(1.0);
    for p in &model.prescribed {
        let curve = match *p {
            Prescribed::Translation { curve, .. } | Prescribed::Rotation { curve, .. } => curve,
        };
        let c = &model.curves[curve];
        let (cm, c0, cp) = (c.value(t - d), c.value(t), c.value(t + d));
        let (rate, second) = ((cp - cm) / (2.0 * d), (cp - 2.0 * c0 + cm) / (d * d));
        match *p {
            Prescribed::Translation {
                node, axis, value, ..
            } => {
                state.velocity[node][axis] = value * rate;
                state.acceleration[node][axis] = value * second;
                state.pseudo_acceleration[node][axis] = value * second;
            }
            Prescribed::Rotation { node, psi, .. } => {
                let w = state.q[node].inverse() * psi;
                for k in 0..3 {
                    state.velocity[node][3 + k] = w[k] * rate;
                    state.acceleration[node][3 + k] = w[k] * second;
                    state.pseudo_acceleration[node][3 + k] = w[k] * second;
                }
            }
        }
    }
}

/// The state moved along its velocities for a time `e` (nodes on the
/// group, coordinates additively), at time `t + e` with the prescribed
/// motions there: the motion `q ∘ exp(e v)` along which the derivatives of
/// D9–D10 are taken.
fn moved(model: &Model, state: &State, e: f64) -> State {
    let mut s = state.clone();
    move_along(model, state, e, &mut s);
    s
}

/// [`moved`] into `s`, whose vectors are reused (no allocation once they
/// have their lengths).
fn move_along(model: &Model, state: &State, e: f64, s: &mut State) {
    s.clone_from(state);
    for node in 0..s.n_nodes() {
        let v = state.velocity[node];
        s.displace_node(
            node,
            &(Vec3::new(v[0], v[1], v[2]) * e),
            &(Vec3::new(v[3], v[4], v[5]) * e),
        );
    }
    for (c, r) in s.coordinates.iter_mut().zip(&state.coordinate_rates) {
        *c += e * r;
    }
    s.time = state.time + e;
    let t = s.time;
    model.apply_prescribed(s, t);
}

/// The time step of the differences of D9–D10: the motion over it is
/// [`MOTION_STEP`] of the model's size, or of the span of the analysis.
fn motion_step(model: &Model, state: &State, end_time: f64) -> f64 {
    MOTION_STEP * motion_time(model, state, (end_time - state.time).abs())
}

/// The time for the fastest node to cover the model's size, for the
/// fastest spin to turn one radian, or `span`, whichever is shortest.
fn motion_time(model: &Model, state: &State, span: f64) -> f64 {
    let l = model.length_scale;
    let (mut v, mut w) = (0.0f64, 0.0f64);
    for r in &state.velocity {
        v = v.max(Vec3::new(r[0], r[1], r[2]).norm());
        w = w.max(Vec3::new(r[3], r[4], r[5]).norm());
    }
    let mut e = span.max(f64::MIN_POSITIVE);
    if v > 0.0 {
        e = e.min(l / v);
    }
    if w > 0.0 {
        e = e.min(1.0 / w);
    }
    e
}

/// The multiplier rows of the residual (`−kΦ`) at `state`, by dof.
fn constraint_residual(model: &Model, solver: &mut NewtonSolver, state: &State) -> Vec<f64> {
    let (_, assembler, _) = solver.system();
    let ctx = model.context(state.time, Need::RESIDUAL);
    assembler.assemble(model, &ctx, state);
    assembler.residual.clone()
}

/// First and second derivatives of the residual of the multiplier rows
/// along the motion (`−k Φ̇` and `−k Φ̈` at `v̇ = 0`), by Richardson
/// extrapolation of central differences (D9–D10).
pub(super) fn constraint_rates(
    model: &Model,
    solver: &mut NewtonSolver,
    state: &State,
    end_time: f64,
) -> (Vec<f64>, Vec<f64>) {
    let e = motion_step(model, state, end_time);
    let r0 = constraint_residual(model, solver, state);
    let mut diffs = Vec::new();
    for h in [e, 0.5 * e] {
        let rp = constraint_residual(model, solver, &moved(model, state, h));
        let rm = constraint_residual(model, solver, &moved(model, state, -h));
        let first: Vec<f64> = rp
            .iter()
            .zip(&rm)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let second: Vec<f64> = (0..r0.len())
            .map(|d| (rp[d] - 2.0 * r0[d] + rm[d]) / (h * h))
            .collect();
        diffs.push((first, second));
    }
    let rich = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(a, b)| (4.0 * b - a) / 3.0).collect()
    };
    (
        rich(&diffs[0].0, &diffs[1].0),
        rich(&diffs[0].1, &diffs[1].1),
    )
}

/// `−k Φ̇` of the multiplier rows along the motion, by one central
/// difference over [`PROJECTION_STEP`] of the motion time (with the span
/// of the whole analysis, `span`, for a model at rest) (D13), into
/// `rates.rate` (by dof, zero off the multiplier rows). Only the elements
/// with multipliers are evaluated, at states moved into `rates.moved`.
fn constraint_rate(model: &Model, state: &State, span: f64, n: usize, rates: &mut RateWork) {
    let e = PROJECTION_STEP * motion_time(model, state, span);
    let RateWork {
        rows,
        moved,
        plus,
        rate,
    } = rates;
    plus.clear();
    plus.resize(n, 0.0);
    rate.clear();
    rate.resize(n, 0.0);
    move_along(model, state, e, moved);
    rows.evaluate(
        model,
        &model.context(moved.time, Need::RESIDUAL),
        moved,
        plus,
    );
    move_along(model, state, -e, moved);
    rows.evaluate(
        model,
        &model.context(moved.time, Need::RESIDUAL),
        moved,
        rate,
    );
    for (r, p) in rate.iter_mut().zip(plus.iter()) {
        *r = (p - *r) / (2.0 * e);
    }
}

/// D10: the initial velocities must satisfy `Φ̇ = B v + ∂Φ/∂t = 0`, to
/// `1e-6` of the velocity scale ([`VELOCITY_TOLERANCE`]).
fn check_velocities(
    model: &Model,
    solver: &mut NewtonSolver,
    state: &State,
    end_time: f64,
) -> Result<(), DynamicError> {
    if solver.dofs.first_multiplier() == solver.dofs.n_dofs() {
        return Ok(());
    }
    let (mut rate, _) = constraint_rates(model, solver, state, end_time);
    // a velocity constraint's own residual −kA v is its violation
    let rows = velocity_rows(model, &solver.dofs);
    if rows.contains(&true) {
        let (value, _) = velocity_constraint_rates(model, solver, state, end_time);
        for (d, _) in rows.iter().enumerate().filter(|(_, &r)| r) {
            rate[d] = value[d];
        }
    }
    let l = model.length_scale;
    let (mut v, mut w) = (0.0f64, 0.0f64);
    for r in &state.velocity {
        v = v.max(Vec3::new(r[0], r[1], r[2]).norm());
        w = w.max(Vec3::new(r[3], r[4], r[5]).norm());
    }
    let span = (end_time - state.time).abs().max(f64::MIN_POSITIVE);
    let dofs = &solver.dofs;
    for eq in 0..dofs.n_equations() {
        let DofKind::Multiplier(kind) = dofs.equation_kind(eq) else {
            continue;
        };
        let d = dofs.dof(eq);
        let k = model.scaling.of(kind).0;
        let phi_dot = rate[d] / k;
        let tolerance = VELOCITY_TOLERANCE
            * match kind {
                ConstraintKind::Distance => v + w * l + l / span,
                ConstraintKind::Angle => w + v / l + 1.0 / span,
            };
        if phi_dot.abs() > tolerance {
            return Err(DynamicError::InconsistentVelocity {
                constraint: constraint_name(model, solver, d),
                rate: phi_dot,
                tolerance,
            });
        }
    }
    Ok(())
}

/// `joint 3 equation 2` for the multiplier dof `dof`.
fn constraint_name(model: &Model, solver: &NewtonSolver, dof: usize) -> String {
    let k = dof - solver.dofs.first_multiplier();
    for (i, e) in model.elements.iter().enumerate() {
        let o = model.offsets(i).multipliers;
        if k >= o && k < o + e.n_multipliers() {
            return format!("{} {} equation {}", e.kind().name(), e.id(), k - o + 1);
        }
    }
    solver.dof_label(model, dof)
}

/// Weight of the unknowns without mass in the metric of the projections
/// (D13–D14), relative to the largest mass of their kind: small enough that
/// the projections move them rather than the unknowns with mass (with
/// their stiffness rows as weight, a massless hinge node joined rigidly to
/// a panel shared each correction with the panel: an energy error of
/// first order in `h` at ρ∞ = 1, 2e-2 J of 4 J at `h = 0.01`), large
/// enough to keep the pivots of the matrix far from round-off.
const LIGHT_WEIGHT: f64 = 1e-8;

/// What the rows of unknowns without mass take in
/// [`constrained_mass_system`].
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum MasslessRows {
    /// Their rows of `K + M` (D9), unless a constraint holds them (then
    /// the light weight): the accelerations of unknowns without mass that
    /// nothing holds follow from their equilibrium.
    Stiffness,
    /// [`LIGHT_WEIGHT`] times the mass scale of their kind on the diagonal
    /// (D13–D14): the `M`-orthogonal projections, whose metric `M` alone
    /// would be singular there, move them first.
    Light,
}

/// The matrix of the constrained mass system at `state`,
///
/// ```text
/// [ M    −kBᵀ ]
/// [ −kB   0   ]
/// ```
///
/// with the rows of unknowns without mass taken from `K + M` instead of
/// `M` (or a light diagonal weight, `massless`), and the multiplier rows and columns scaled by `m_s/k` (D8 with
/// `β′ = 1`, without the lower bound 1), left in the solver's matrix: the
/// matrix of the initial accelerations (D9) and of the velocity projection
/// (D13). Returns the mass scales `m_s` of translations and rotations,
/// and leaves the scale of each equation in `buffers.s_eq`.
///
/// With the light weight and no velocity constraints (the projections,
/// D13–D14) the stiffness enters the multiplier rows and columns alone:
/// it is that of the elements with multipliers ([`ConstraintRows`]), and
/// the mass matrix is assembled without the stiffness of the others, or
/// taken as it is in `buffers.mass` when `mass_assembled` says it is that
/// of `state` (the error estimate's, D11a).
fn constrained_mass_system(
    model: &Model,
    solver: &mut NewtonSolver,
    state: &State,
    buffers: &mut MassSystem,
    velocity_rows: Option<(&[bool], &SparseMatrix)>,
    massless: MasslessRows,
    mass_assembled: bool,
) -> Result<[f64; 2], NewtonFailure> {
    let t = state.time;
    let (dofs, assembler, _) = solver.system();
    let same = |m: &SparseMatrix| m.same_pattern(&assembler.matrix);
    let mut mass_assembled = mass_assembled;
    if !buffers.stiffness.as_ref().is_some_and(same) {
        buffers.stiffness = Some(assembler.matrix.clone());
        buffers.mass = Some(assembler.matrix.clone());
        mass_assembled = false;
    }
    if !buffers.system.as_ref().is_some_and(same) {
        buffers.system = Some(assembler.matrix.clone());
        if let Some(lu) = buffers.lu.take() {
            buffers.retired += lu.counts();
        }
    }
    let (stiffness, mass) = (
        buffers.stiffness.as_mut().expect("set above"),
        buffers.mass.as_mut().expect("set above"),
    );
    let ctx = EvalContext {
        dynamics: true,
        ..model.context(t, Need::with_inertia(0.0, 1.0))
    };
    if massless == MasslessRows::Light && velocity_rows.is_none() {
        // the stiffness is used in the multiplier rows and columns alone:
        // that of the elements with multipliers, with the mass matrix of
        // all, unless it was just assembled at this state (D11a)
        if !mass_assembled {
            assembler.assemble_inertia(model, &ctx, state, mass);
        }
        let rows = buffers
            .constraints
            .get_or_insert_with(|| ConstraintRows::new(model, dofs));
        rows.stiffness(model, dofs, &ctx, state, stiffness);
    } else {
        assembler.assemble_split(model, &ctx, state, stiffness, mass);
    }
    if !assembler.residual.iter().all(|r| r.is_finite()) {
        return Err(NewtonFailure::NonFinite {
            iteration: 0,
            origin: non_finite_origin(model, state, t),
        });
    }

    // mass scales and the massless rows; the entries visited column by
    // column (`col`, `row_of[i]`), the per-equation lists in `buffers`
    let n = dofs.n_equations();
    let row_of = stiffness.row_indices();
    let columns = |col: usize| stiffness.column_start(col)..stiffness.column_start(col + 1);
    let MassSystem {
        diagonal,
        kinds,
        light,
        held,
        s_eq,
        system,
        ..
    } = buffers;
    kinds.clear();
    kinds.extend((0..n).map(|eq| match dofs.equation_kind(eq) {
        DofKind::Translation | DofKind::Coordinate { .. } => EquationKind::Translation,
        DofKind::Rotation => EquationKind::Rotation,
        DofKind::Multiplier(ConstraintKind::Distance) => EquationKind::Distance,
        DofKind::Multiplier(ConstraintKind::Angle) => EquationKind::Angle,
    }));
    let m = mass.values();
    diagonal.clear();
    diagonal.resize(n, 0.0);
    for col in 0..n {
        for i in columns(col) {
            if row_of[i] == col {
                diagonal[col] = m[i];
            }
        }
    }
    let mut scale = [0.0f64; 2];
    for (&kind, &m) in kinds.iter().zip(diagonal.iter()) {
        match kind {
            EquationKind::Translation => scale[0] = scale[0].max(m),
            EquationKind::Rotation => scale[1] = scale[1].max(m),
            _ => {}
        }
    }
    // the light weight of a massless unknown: the mass scale of its kind,
    // or of the other kind through the model's size if it has none
    let length2 = model.length_scale * model.length_scale;
    let light_weight = |kind: EquationKind| {
        let m = match kind {
            EquationKind::Rotation if scale[1] > 0.0 => scale[1],
            EquationKind::Rotation => scale[0] * length2,
            _ if scale[0] > 0.0 => scale[0],
            _ => scale[1] / length2,
        };
        LIGHT_WEIGHT * if m > 0.0 { m } else { 1.0 }
    };
    light.clear();
    light.extend(
        kinds
            .iter()
            .zip(diagonal.iter())
            .map(|(&kind, &m)| match kind {
                EquationKind::Translation => m <= MASSLESS * scale[0],
                EquationKind::Rotation => m <= MASSLESS * scale[1],
                _ => false,
            }),
    );
    // massless rows held by a constraint take the light weight in every
    // use: the constraints carry them, and a stiffness row there (the
    // penalty p BᵀB of the joints) would pass the constraints' rates on
    // to the bodies they hold (as in the impact, docs/theory.md §16)
    let k = stiffness.values();
    held.clear();
    held.resize(n, false);
    for col in (0..n).filter(|&col| kinds[col].is_multiplier()) {
        for i in columns(col) {
            if k[i] != 0.0 && light[row_of[i]] {
                held[row_of[i]] = true;
            }
        }
    }
    // multiplier rows and columns scaled to the mass (D8 with β′ = 1)
    s_eq.clear();
    s_eq.extend(kinds.iter().map(|&kind| {
        let (m, k) = match kind {
            EquationKind::Distance => (scale[0], model.scaling.force.0),
            EquationKind::Angle => (scale[1], model.scaling.moment.0),
            _ => return 1.0,
        };
        if m > 0.0 {
            m / k
        } else {
            1.0
        }
    }));
    let velocity_rows = velocity_rows.map(|(r, c)| (r, c.values()));
    let values = system.as_mut().expect("set above").values_mut();
    for col in 0..n {
        let multiplier_col = kinds[col].is_multiplier();
        for i in columns(col) {
            let row = row_of[i];
            // the rows of velocity constraints take their ∂r/∂v
            let v = match velocity_rows {
                Some((r, c)) if r[dofs.dof(row)] => c[i],
                _ if multiplier_col || kinds[row].is_multiplier() => k[i] + m[i],
                _ if light[row] => match massless {
                    MasslessRows::Stiffness if !held[row] => k[i] + m[i],
                    _ if row == col => light_weight(kinds[row]),
                    _ => 0.0,
                },
                _ => m[i],
            };
            values[i] = v * s_eq[row] * s_eq[col];
        }
    }
    Ok(scale)
}

/// The kind of an equation, as the constrained mass system sorts them.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum EquationKind {
    /// A translation or a coordinate (a length).
    Translation,
    Rotation,
    /// The multiplier of a distance constraint.
    Distance,
    /// The multiplier of an angle constraint.
    Angle,
}

impl EquationKind {
    fn is_multiplier(self) -> bool {
        matches!(self, Self::Distance | Self::Angle)
    }
}

/// Solves the constrained mass system left in `buffers` by
/// [`constrained_mass_system`] for the right-hand side `rhs` (in place),
/// with factors of its own (the iteration matrix's are kept).
fn solve_mass_system(
    model: &Model,
    solver: &NewtonSolver,
    buffers: &mut MassSystem,
    state: &State,
    rhs: &mut [f64],
) -> Result<(), NewtonFailure> {
    let matrix = buffers
        .system
        .as_ref()
        .expect("formed by constrained_mass_system");
    let lu = &mut buffers.lu;
    let count = &mut buffers.factorisations;
    let solved = (|| {
        if lu.is_none() {
            *lu = Some(SymmetricFirst::analyze(matrix)?);
        }
        let lu = lu.as_mut().expect("analysed above");
        *count += 1;
        lu.factor(matrix)?;
        lu.solve_in_place(rhs)
    })();
    if solved.is_err() || !rhs.iter().all(|v| v.is_finite()) {
        return Err(singular(model, solver, matrix, state, 0));
    }
    Ok(())
}

/// D9: consistent initial accelerations and multipliers. Solves
///
/// ```text
/// [ M    −kBᵀ ] [ v̇  ]     [ g(q, v, t) + Bᵀ(pΦ − kλ) ]
/// [ −kB   0   ] [ δλ ] = − [ −k Φ̈|_{v̇=0}              ]
/// ```
///
/// (rows of unknowns without mass take their stiffness row instead of
/// `M`), and starts with `a₀ = v̇₀`. Also sets the mass scales of D8.
fn initial_accelerations(
    model: &Model,
    solver: &mut NewtonSolver,
    run: &mut Run,
    end_time: f64,
) -> Result<(), NewtonFailure> {
    let state = &mut run.state;
    let t0 = state.time;
    for a in state.acceleration.iter_mut() {
        *a = [0.0; 6];
    }
    state.coordinate_accelerations.fill(0.0);
    let has_constraints = solver.dofs.first_multiplier() < solver.dofs.n_dofs();
    let mut second = if has_constraints {
        constraint_rates(model, solver, state, end_time).1
    } else {
        Vec::new()
    };
    // velocity constraints (rolling): A v̇ = −Ȧ v, their rows from ∂r/∂v (τ = 1)
    let by_dof = velocity_rows(model, &solver.dofs);
    let damping = if by_dof.contains(&true) {
        let (_, rate) = velocity_constraint_rates(model, solver, state, end_time);
        for (d, _) in by_dof.iter().enumerate().filter(|(_, &r)| r) {
            second[d] = rate[d];
        }
        let (_, assembler, _) = solver.system();
        let (mut k, mut c) = (assembler.matrix.clone(), assembler.matrix.clone());
        let ctx = EvalContext {
            dynamics: true,
            ..model.context(t0, Need::with_inertia(1.0, 0.0))
        };
        assembler.assemble_split(model, &ctx, state, &mut k, &mut c);
        Some(c)
    } else {
        None
    };
    let rows = damping.as_ref().map(|c| (by_dof.as_slice(), c));
    let scale = constrained_mass_system(
        model,
        solver,
        state,
        &mut run.mass_system,
        rows,
        MasslessRows::Stiffness,
        false,
    )?;
    run.mass_scale = scale;
    let s_eq = &run.mass_system.s_eq;
    let (dofs, assembler, _) = solver.system();
    let mut rhs: Vec<f64> = (0..dofs.n_equations())
        .map(|eq| {
            let d = dofs.dof(eq);
            if matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)) {
                -second[d] * s_eq[eq]
            } else {
                -assembler.residual[d]
            }
        })
        .collect();
    solve_mass_system(model, solver, &mut run.mass_system, state, &mut rhs)?;
    let s_eq = &run.mass_system.s_eq;
    let (dofs, _, _) = solver.system();
    for (eq, z) in rhs.iter().enumerate() {
        let d = dofs.dof(eq);
        if let Some((node, c)) = dofs.node_component(d) {
            state.acceleration[node][c] = *z;
        } else if d < dofs.first_multiplier() {
            state.coordinate_accelerations[d - dofs.first_coordinate()] = *z;
        } else {
            state.multipliers[d - dofs.first_multiplier()] += z * s_eq[eq];
        }
    }
    state.pseudo_acceleration.clone_from(&state.acceleration);
    state
        .coordinate_pseudo_accelerations
        .clone_from(&state.coordinate_accelerations);
    // the residual at the start, for the observer (reactions)
    let (_, assembler, _) = solver.system();
    let ctx = EvalContext {
        dynamics: true,
        ..model.context(t0, Need::RESIDUAL)
    };
    assembler.assemble(model, &ctx, state);
    Ok(())
}

/// D14: closes the position constraints of `state` before a restart,
/// `q ← q ∘ exp(δq)` with the smallest correction in the metric of the
/// mass that satisfies `Φ(q) + B δq = 0`,
///
/// ```text
/// [ M    −kBᵀ ] [ δq ]     [ 0    ]
/// [ −kB   0   ] [ μ  ] = − [ −k Φ ]
/// ```
///
/// (the matrix of D9 and D13). A latch or a stop is detected within its
/// event tolerance of its value, and without the correction the first
/// step after the restart would close that gap `Φ₀` alone: `a₁` takes
/// `−Φ₀/(βh²)` (D2), a kick of the multipliers that the index-3 scheme
/// then carries as its alternating transient (docs/theory.md §15.8).
/// One linear solve: `Φ₀` is within the event tolerance (≤ 1e-8 of the
/// model size), so the residual left is `O(Φ₀²)`. Models with velocity
/// constraints (rolling) are left as they are.
fn project_positions(
    model: &Model,
    solver: &mut NewtonSolver,
    run: &mut Run,
) -> Result<(), NewtonFailure> {
    let dofs = &solver.dofs;
    if dofs.first_multiplier() == dofs.n_dofs() || has_velocity_constraints(model) {
        return Ok(());
    }
    let state = &mut run.state;
    let residual = constraint_residual(model, solver, state);
    constrained_mass_system(
        model,
        solver,
        state,
        &mut run.mass_system,
        None,
        MasslessRows::Light,
        false,
    )?;
    let s_eq = &run.mass_system.s_eq;
    let dofs = &solver.dofs;
    let mut rhs: Vec<f64> = (0..dofs.n_equations())
        .map(|eq| {
            if matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)) {
                -residual[dofs.dof(eq)] * s_eq[eq]
            } else {
                0.0
            }
        })
        .collect();
    solve_mass_system(model, solver, &mut run.mass_system, state, &mut rhs)?;
    let dofs = &solver.dofs;
    for (eq, z) in rhs.iter_mut().enumerate() {
        if matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)) {
            *z = 0.0;
        }
    }
    state.update(dofs, &rhs);
    let t = state.time;
    model.apply_prescribed(state, t);
    Ok(())
}

/// The restart after an impact (a latch locking, a stop closing or
/// opening): the positions projected on the constraints (D14), then
/// consistent accelerations and multipliers (D9), `a = v̇`.
fn restart_after_impact(
    model: &Model,
    solver: &mut NewtonSolver,
    run: &mut Run,
    end_time: f64,
) -> Result<(), NewtonFailure> {
    project_positions(model, solver, run)?;
    initial_accelerations(model, solver, run, end_time)
}

/// The step whose rotations the initial angular accelerations predict,
/// `½ |Ω̇₀| h²`, reach [`START_ROTATION`]: `None` when no free node turns.
fn start_step(dofs: &DofMap, state: &State) -> Option<f64> {
    let largest = (0..state.n_nodes())
        .filter(|&node| (3..6).any(|c| dofs.equation(6 * node + c) != NO_EQUATION))
        .map(|node| {
            let a = &state.acceleration[node];
            (a[3] * a[3] + a[4] * a[4] + a[5] * a[5]).sqrt()
        })
        .fold(0.0f64, f64::max);
    (largest > 0.0 && largest.is_finite()).then(|| (2.0 * START_ROTATION / largest).sqrt())
}

/// The failure of a singular or nearly singular iteration matrix: the
/// unknown without stiffness or mass.
/// `matrix` is the one that failed to factor or solve.
fn singular(
    model: &Model,
    solver: &NewtonSolver,
    matrix: &SparseMatrix,
    state: &State,
    iteration: usize,
) -> NewtonFailure {
    if !(matrix.values().iter().all(|v| v.is_finite())
        && solver.residual().iter().all(|v| v.is_finite()))
    {
        return NewtonFailure::NonFinite {
            iteration,
            origin: non_finite_origin(model, state, state.time),
        };
    }
    match smallest_relative_pivot(matrix) {
        Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => {
            let d = solver.dofs.dof(eq);
            NewtonFailure::Singular {
                dof: solver.dof_label(model, d),
                pivot,
            }
        }
        _ => NewtonFailure::NonFinite {
            iteration,
            origin: "in the solution of the linear system (a nearly singular iteration matrix)"
                .into(),
        },
    }
}

impl Dynamics<'_> {
    /// The predictor (D5): `v̇_{n+1} = 0`, `λ_{n+1} = λ_n`,
    /// `a_{n+1} = (α_f v̇_n − α_m a_n)/(1 − α_m)`, then `v`, `Δq`, `q`.
    fn predict(&mut self, h: f64) {
        let (sc, run) = (self.scheme, &mut *self.run);
        let dofs = &self.solver.dofs;
        let n = &run.accepted;
        let s = &mut run.state;
        s.clone_from(n);
        s.time = n.time + h;
        // a_n − v̇_n is O(h) (a is the acceleration at t_n + (α_m − α_f)h
        // to first order): scaled with the step when it shrinks, kept when
        // it grows, so that growing steps do not amplify the transient of
        // the multipliers it also holds (D15)
        let ratio_a = run.last_step.map_or(1.0, |hp| (h / hp).min(1.0));
        let predict = |vn: f64, vdn: f64, an: f64| -> (f64, f64, f64, f64) {
            let an = vdn + (an - vdn) * ratio_a;
            let a = (sc.alpha_f * vdn - sc.alpha_m * an) / (1.0 - sc.alpha_m);
            let v = vn + h * (1.0 - sc.gamma) * an + h * sc.gamma * a;
            let dq = vn + h * (0.5 - sc.beta) * an + h * sc.beta * a;
            (an, a, v, dq)
        };
        let spatial = self.settings.angular_velocities == AngularVelocities::Spatial;
        for node in 0..s.n_nodes() {
            run.dq[node] = [0.0; 6];
            // the spatial scheme where the node's rotation is free: its
            // rates of step n are combined in the frame of R_n (§15.9)
            run.spatial[node] =
                spatial && (3..6).all(|c| dofs.equation(6 * node + c) != NO_EQUATION);
            for c in 0..6 {
                if dofs.equation(6 * node + c) == NO_EQUATION {
                    continue;
                }
                let (an, a, v, dq) = predict(
                    n.velocity[node][c],
                    n.acceleration[node][c],
                    n.pseudo_acceleration[node][c],
                );
                run.a_start[node][c] = an;
                if run.spatial[node] && c >= 3 {
                    run.turned[node][0][c - 3] = v;
                    run.turned[node][1][c - 3] = 0.0;
                    run.turned[node][2][c - 3] = a;
                } else {
                    s.pseudo_acceleration[node][c] = a;
                    s.velocity[node][c] = v;
                    s.acceleration[node][c] = 0.0;
                }
                run.dq[node][c] = dq;
            }
        }
        let first = dofs.first_coordinate();
        for k in 0..s.coordinates.len() {
            run.dq_coordinates[k] = 0.0;
            if dofs.equation(first + k) == NO_EQUATION {
                continue;
            }
            let (an, a, v, dq) = predict(
                n.coordinate_rates[k],
                n.coordinate_accelerations[k],
                n.coordinate_pseudo_accelerations[k],
            );
            run.a_start_coordinates[k] = an;
            s.coordinate_pseudo_accelerations[k] = a;
            s.coordinate_rates[k] = v;
            s.coordinate_accelerations[k] = 0.0;
            run.dq_coordinates[k] = dq;
        }
        self.place(h);
    }

    /// `q_{n+1} = q_n ∘ exp(h Δq_n)` (D2) for the free unknowns; the
    /// prescribed ones at their values and rates at `t_{n+1}`.
    fn place(&mut self, h: f64) {
        let run = &mut *self.run;
        let dofs = &self.solver.dofs;
        let (n, s) = (&run.accepted, &mut run.state);
        for node in 0..s.n_nodes() {
            let dq = &run.dq[node];
            if run.spatial[node] {
                // Ω = Λ Ω′, Ω̇ = Λ Ω̇′, a = Λ a′, Λ = exp(−hΔΘ~) = R_{n+1}ᵀ R_n
                let turn = so3::exp_matrix(&(Vec3::new(dq[3], dq[4], dq[5]) * h)).transpose();
                let [w, wd, a] = run.turned[node].map(|v| turn * v);
                for k in 0..3 {
                    s.velocity[node][3 + k] = w[k];
                    s.acceleration[node][3 + k] = wd[k];
                    s.pseudo_acceleration[node][3 + k] = a[k];
                }
            }
            if dq.iter().all(|&d| d == 0.0) {
                continue;
            }
            s.x[node] = n.x[node];
            s.q[node] = n.q[node];
            s.displace_node(
                node,
                &(Vec3::new(dq[0], dq[1], dq[2]) * h),
                &(Vec3::new(dq[3], dq[4], dq[5]) * h),
            );
        }
        let first = dofs.first_coordinate();
        for k in 0..s.coordinates.len() {
            if dofs.equation(first + k) != NO_EQUATION {
                s.coordinates[k] = n.coordinates[k] + h * run.dq_coordinates[k];
            }
        }
        let t = s.time;
        self.model.apply_prescribed(s, t);
        prescribed_rates(self.model, s, t);
    }

    /// Applies the Newton correction `x` (by equation; multipliers already
    /// unscaled): `Δq += x/h`, `a += x/(βh²)`, `v += γ′x`, `v̇ += β′x`
    /// (D6), `λ += δλ`, and places the nodes again.
    fn correct(&mut self, h: f64, x: &[f64]) {
        let sc = self.scheme;
        let (gp, bp, ba) = (sc.gamma_prime(h), sc.beta_prime(h), 1.0 / (sc.beta * h * h));
        let run = &mut *self.run;
        let dofs = &self.solver.dofs;
        let s = &mut run.state;
        for (eq, &xe) in x.iter().enumerate() {
            let d = dofs.dof(eq);
            if let Some((node, c)) = dofs.node_component(d) {
                run.dq[node][c] += xe / h;
                if run.spatial[node] && c >= 3 {
                    let t = &mut run.turned[node];
                    t[0][c - 3] += gp * xe;
                    t[1][c - 3] += bp * xe;
                    t[2][c - 3] += ba * xe;
                } else {
                    s.pseudo_acceleration[node][c] += ba * xe;
                    s.velocity[node][c] += gp * xe;
                    s.acceleration[node][c] += bp * xe;
                }
            } else if d < dofs.first_multiplier() {
                let k = d - dofs.first_coordinate();
                run.dq_coordinates[k] += xe / h;
                s.coordinate_pseudo_accelerations[k] += ba * xe;
                s.coordinate_rates[k] += gp * xe;
                s.coordinate_accelerations[k] += bp * xe;
            } else {
                s.multipliers[d - dofs.first_multiplier()] += xe;
            }
        }
        self.place(h);
    }

    /// D13: projects the converged velocities on the velocity constraints
    /// `Φ̇ = B v + ∂Φ/∂t = 0` in the metric of the mass,
    ///
    /// ```text
    /// [ M    −kBᵀ ] [ δv ]     [ 0     ]
    /// [ −kB   0   ] [ μ  ] = − [ −k Φ̇  ]
    /// ```
    ///
    /// (the matrix of D9), then assembles the residual again at the
    /// projected state for the observer (reactions, energy balance).
    /// `mass_assembled`: the mass matrix of [`MassSystem`] is that of the
    /// converged state (the error estimate, D11a, has just assembled it).
    fn project_velocities(&mut self, h: f64, mass_assembled: bool) -> Result<(), NewtonFailure> {
        let (model, run) = (self.model, &mut *self.run);
        let dofs = &self.solver.dofs;
        if dofs.first_multiplier() == dofs.n_dofs() {
            return Ok(());
        }
        let state = &mut run.state;
        constraint_rate(model, state, run.span, dofs.n_dofs(), &mut run.rates);
        let rate = &mut run.rates.rate;
        // velocity constraints (rolling discs): their rows of the matrix are
        // ∂r/∂v = −kA, their right-hand side their own residual −kA v, so
        // that A(v + δv) = 0 (docs/theory.md §15.7)
        let rows = has_velocity_constraints(model).then(|| velocity_rows(model, &self.solver.dofs));
        let mut damping = None;
        if let Some(rows) = &rows {
            let (_, assembler, _) = self.solver.system();
            let buffers = &mut run.mass_system;
            if buffers
                .damping
                .as_ref()
                .is_none_or(|c| !c.same_pattern(&assembler.matrix))
            {
                buffers.damping = Some(assembler.matrix.clone());
                buffers.damping_rest = Some(assembler.matrix.clone());
            }
            let (mut c, mut rest) = (
                buffers.damping.take().expect("set above"),
                buffers.damping_rest.take().expect("set above"),
            );
            let ctx = EvalContext {
                dynamics: true,
                ..model.context(state.time, Need::with_inertia(1.0, 0.0))
            };
            assembler.assemble_split(model, &ctx, state, &mut rest, &mut c);
            for (d, _) in rows.iter().enumerate().filter(|(_, &r)| r) {
                rate[d] = assembler.residual[d];
            }
            buffers.damping_rest = Some(rest);
            damping = Some(c);
        }
        let velocity_rows = rows.as_deref().zip(damping.as_ref());
        let scaled = constrained_mass_system(
            model,
            self.solver,
            state,
            &mut run.mass_system,
            velocity_rows,
            MasslessRows::Light,
            mass_assembled,
        );
        run.mass_system.damping = damping;
        scaled?;
        let s_eq = &run.mass_system.s_eq;
        let dofs = &self.solver.dofs;
        let rhs = &mut run.work.rhs;
        rhs.clear();
        rhs.extend((0..dofs.n_equations()).map(|eq| {
            if matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)) {
                -rate[dofs.dof(eq)] * s_eq[eq]
            } else {
                0.0
            }
        }));
        solve_mass_system(model, self.solver, &mut run.mass_system, state, rhs)?;
        let s_eq = &run.mass_system.s_eq;
        let dofs = &self.solver.dofs;
        // D13a: a, v̇ and λ follow δv as a Newton correction would (D6),
        // so that the next step starts from a state whose equations of
        // motion hold and whose pseudo-acceleration matches the projected
        // velocities; on a short step, D13b below instead
        let short = h < SHORT_STEP * motion_time(model, state, run.span);
        let (da, dvd) = if short {
            (0.0, 0.0)
        } else {
            self.scheme.velocity_to_accelerations(h)
        };
        for (eq, z) in rhs.iter().enumerate() {
            let d = dofs.dof(eq);
            if let Some((node, c)) = dofs.node_component(d) {
                state.velocity[node][c] += z;
                state.pseudo_acceleration[node][c] += da * z;
                state.acceleration[node][c] += dvd * z;
            } else if d < dofs.first_multiplier() {
                let k = d - dofs.first_coordinate();
                state.coordinate_rates[k] += z;
                state.coordinate_pseudo_accelerations[k] += da * z;
                state.coordinate_accelerations[k] += dvd * z;
            } else {
                // M δv = kBᵀμ: M δv̇ = c kBᵀμ is balanced by δλ = c μ
                state.multipliers[d - dofs.first_multiplier()] += dvd * z * s_eq[eq];
            }
        }
        if short {
            // D13b: Newton's a carries the round-off of q over βh², and
            // D13a would leave that of δv over γh; a, v̇ and λ consistent
            // with the projected q and v (D9) instead, a = v̇ being the
            // steady a − v̇ ≈ (α_m − α_f) h g⃛ of so short a step; from
            // such a restart the steps grow back by at most LOCK_REGROWTH
            // a step, as after a lock (§16)
            run.regrowing = true;
            return initial_accelerations(model, self.solver, run, self.settings.end_time);
        }
        let (_, assembler, _) = self.solver.system();
        let ctx = EvalContext {
            dynamics: true,
            ..model.context(state.time, Need::RESIDUAL)
        };
        assembler.assemble(model, &ctx, state);
        Ok(())
    }

    /// Largest translation and rotation of the step, `h|Δq|`.
    fn step_motion(&self, h: f64) -> (f64, f64) {
        let run = &*self.run;
        let (mut dx, mut dth) = (0.0f64, 0.0f64);
        for dq in &run.dq {
            dx = dx.max(h * Vec3::new(dq[0], dq[1], dq[2]).norm());
            dth = dth.max(h * Vec3::new(dq[3], dq[4], dq[5]).norm());
        }
        let lengths = &run.dq_coordinates;
        for (k, d) in lengths.iter().enumerate() {
            let first = self.solver.dofs.first_coordinate();
            if let DofKind::Coordinate { length } = self.solver.dofs.kind(first + k) {
                dx = dx.max(h * d.abs() * length);
            }
        }
        (dx, dth)
    }

    /// The convergence measures of the current iterate (the assembler
    /// holds its residual): norms, and the unknown with the largest
    /// residual relative to its group's flux.
    ///
    /// The flux of a node is that of the step ([`Work::flux`]): the larger,
    /// dof by dof, of `Σₑ |rₑ|` at the predictor and at the iterate. The
    /// inertia force `M v̇` is part of each element's own residual, so at
    /// the iterate it cancels inside the element and leaves no trace in
    /// `Σₑ |rₑ|`: on a node carried by a single body (a free rigid body)
    /// the flux would be the residual itself and the relative residual 1
    /// whatever its size. At the predictor `v̇ = 0` (D5), and `Σₑ |rₑ|` there
    /// is the force that `M v̇` balances at the solution.
    fn norms(&self, floor: f64, motion: (f64, f64)) -> (ConvergenceNorms, usize) {
        let (dofs, assembler) = (&self.solver.dofs, self.solver_assembler());
        let step_flux = &self.run.work.flux;
        let flux_of = |d: usize| {
            let f = assembler.flux[d];
            step_flux.get(d).map_or(f, |&g| f.max(g))
        };
        let (mut rf, mut rm, mut rq, mut ef, mut em, mut eq_c) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut ff, mut fm) = (0.0, 0.0);
        for d in 0..6 * dofs.n_nodes() {
            let f = flux_of(d);
            if d % 6 < 3 {
                ff += f * f;
            } else {
                fm += f * f;
            }
        }
        let (ff, fm) = (ff.sqrt(), fm.sqrt());
        let settings = self.settings;
        let mut constraint = 0.0f64;
        let mut worst = (0usize, -1.0f64);
        let eps = f64::EPSILON * floor;
        for eq in 0..dofs.n_equations() {
            let d = dofs.dof(eq);
            let r = assembler.residual[d];
            let excess = (r.abs() - eps * flux_of(d)).max(0.0);
            let relative = match dofs.kind(d) {
                DofKind::Translation => {
                    rf += r * r;
                    ef += excess * excess;
                    excess / ff.max(f64::MIN_POSITIVE)
                }
                DofKind::Rotation => {
                    rm += r * r;
                    em += excess * excess;
                    excess / fm.max(f64::MIN_POSITIVE)
                }
                DofKind::Coordinate { length } => {
                    rq += (r / length).powi(2);
                    eq_c += (excess / length).powi(2);
                    excess / length / ff.max(f64::MIN_POSITIVE)
                }
                DofKind::Multiplier(kind) => {
                    let (k, round_off, tol) = match kind {
                        ConstraintKind::Distance => (
                            self.model.scaling.force.0,
                            eps * self.model.length_scale,
                            settings.displacement_tolerance * motion.0,
                        ),
                        ConstraintKind::Angle => (
                            self.model.scaling.moment.0,
                            eps,
                            settings.rotation_tolerance,
                        ),
                    };
                    let violation = (r.abs() / k - round_off).max(0.0);
                    if violation > 0.0 {
                        constraint = constraint.max(violation / tol.max(f64::MIN_POSITIVE));
                    }
                    0.0
                }
            };
            if relative > worst.1 {
                worst = (d, relative);
            }
        }
        let rel = |e: f64, f: f64| if e == 0.0 { 0.0 } else { e / f };
        let norms = ConvergenceNorms {
            residual_force: rf.sqrt(),
            residual_moment: rm.sqrt(),
            flux_force: ff,
            flux_moment: fm,
            residual_coordinate: rq.sqrt(),
            relative_residual: rel(ef.sqrt(), ff)
                .max(rel(em.sqrt(), fm))
                .max(rel(eq_c.sqrt(), ff)),
            residual_constraint: constraint,
            displacement_correction: 0.0,
            rotation_correction: 0.0,
        };
        (norms, worst.0)
    }

    /// Whether corrections `dx` (translations) and `dth` (rotations) are
    /// within [`PLATEAU_FACTOR`] ε of the unknowns they correct (the
    /// largest node position plus the model size, and 1 rad): the state
    /// can be made no closer to the solution in floating point.
    fn at_round_off(&self, dx: f64, dth: f64) -> bool {
        let state = &self.run.state;
        let size = self.model.length_scale + state.x.iter().map(|x| x.norm()).fold(0.0, f64::max);
        let round = PLATEAU_FACTOR * f64::EPSILON;
        dx <= round * size && dth <= round
    }

    fn solver_assembler(&self) -> &crate::assembly::Assembler {
        self.solver.assembler()
    }

    /// Whether the next correction, estimated as the last one (`x`) times
    /// `ratio`, is below the tolerances: `ε_u` times the step's largest
    /// translation, `ε_θ` times its largest rotation (relative in
    /// dynamics), `ε_r` of the flux for the force `k δλ` of a multiplier,
    /// each above round-off.
    fn correction_converged(
        &self,
        x: &[f64],
        ratio: f64,
        motion: (f64, f64),
        norms: &ConvergenceNorms,
    ) -> bool {
        let s = self.settings;
        let dofs = &self.solver.dofs;
        let state = &self.run.state;
        let round = FLOOR_FACTOR * f64::EPSILON;
        let l = self.model.length_scale;
        x.iter().enumerate().all(|(eq, &delta)| {
            let d = dofs.dof(eq);
            let next = delta.abs() * ratio;
            match dofs.kind(d) {
                DofKind::Translation => {
                    next <= s.displacement_tolerance * motion.0
                        + round * (state.x[d / 6].norm() + l)
                }
                DofKind::Rotation => next <= s.rotation_tolerance * motion.1 + round,
                DofKind::Coordinate { length } => {
                    let c = state.coordinates[d - dofs.first_coordinate()];
                    next * length
                        <= s.displacement_tolerance * motion.0 + round * (c.abs() + 1.0) * length
                }
                DofKind::Multiplier(kind) => {
                    let (k, flux) = match kind {
                        ConstraintKind::Distance => (self.model.scaling.force.0, norms.flux_force),
                        ConstraintKind::Angle => (self.model.scaling.moment.0, norms.flux_moment),
                    };
                    let lambda = state.multipliers[d - dofs.first_multiplier()];
                    (next - round * lambda.abs()) * k <= s.residual_tolerance * flux
                }
            }
        })
    }

    /// One step of size `h` from the accepted state: predictor, then
    /// Newton on `S x = −r` (D6–D8) with the settings' method. A modified
    /// Newton attempt that fails after solving with factors made at an
    /// earlier iterate is retried from the predictor with fresh factors at
    /// every iteration (full Newton) before the step is given up: the step
    /// is cut back only where full Newton fails too. The iterations
    /// reported are those of both attempts.
    fn newton(
        &mut self,
        h: f64,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Result<(usize, Vec<f64>), NewtonFailure> {
        let scale = Scale::new(
            &self.model.scaling,
            self.scheme.beta_prime(h),
            self.run.mass_scale,
        );
        // the factors kept hold for the same step size and scaling, in
        // the same numbering, and not across a restart (an impact, a lock,
        // a contact: `last_step` is cleared) nor a change of the active
        // set ([`Stepper::update_active_set`])
        let factors = &mut self.run.factors;
        if factors.made_for != Some((h, scale))
            || factors.numbering != self.solver.numbering()
            || self.run.last_step.is_none()
        {
            factors.made_for = None;
        }
        // after factors carried into a step served poorly, the next steps
        // start from fresh ones for a while
        if factors.made_for.is_some() && factors.carry_wait > 0 {
            factors.carry_wait -= 1;
            factors.made_for = None;
        }
        let method = self.settings.newton;
        match self.iterate(h, scale, 0, method, increment, observer) {
            Err((failure, true)) if method == NewtonMethod::Modified => {
                let spent = failure.iterations_spent() + 1;
                self.run.factors.made_for = None;
                self.run.factors.retries += 1;
                self.iterate(h, scale, spent, NewtonMethod::Full, increment, observer)
                    .map(|(iterations, residuals)| (spent + iterations, residuals))
                    .map_err(|(failure, _)| failure)
            }
            other => other.map_err(|(failure, _)| failure),
        }
    }

    /// Factors `S`, assembled unscaled in the solver's matrix, after
    /// scaling it (D8), into the run's [`IterationFactors`], made for
    /// `(h, scale)`.
    fn factor_iteration_matrix(&mut self, h: f64, scale: Scale) -> Result<(), SolveError> {
        let numbering = self.solver.numbering();
        let run = &mut *self.run;
        let (_, assembler, _) = self.solver.system();
        scale.apply(&run.work, &mut assembler.matrix);
        let factors = &mut run.factors;
        factors.made_for = None;
        let same = |m: &SparseMatrix| m.same_pattern(&assembler.matrix);
        if factors.numbering != numbering || !factors.matrix.as_ref().is_some_and(same) {
            factors.matrix = Some(assembler.matrix.clone());
            if let Some(lu) = factors.lu.take() {
                factors.retired += lu.counts();
            }
            factors.numbering = numbering;
        }
        let matrix = factors.matrix.as_mut().expect("set above");
        matrix
            .values_mut()
            .copy_from_slice(assembler.matrix.values());
        if factors.lu.is_none() {
            let mut lu = SymmetricFirst::analyze(matrix)?;
            lu.set_backward_error(
                (CORRECTION_BACKWARD_ERROR * self.settings.residual_tolerance).min(1e-10),
            );
            factors.lu = Some(lu);
        }
        let lu = factors.lu.as_mut().expect("analysed above");
        factors.count += 1;
        lu.factor(matrix)?;
        factors.made_for = Some((h, scale));
        Ok(())
    }

    /// The iterations of [`Self::newton`] from the predictor, numbered from
    /// `first`. Each iterate's residual (and the flux of the norms) is
    /// assembled first; `S` is assembled and factored only for a
    /// correction that needs new factors: at every iteration with
    /// [`NewtonMethod::Full`]; with [`NewtonMethod::Modified`] when there
    /// are none for this step size and scaling, or when the last
    /// correction reduced the residual by less than [`POOR_CONTRACTION`].
    /// A failure comes with whether a correction was solved with factors
    /// made at an earlier iterate.
    fn iterate(
        &mut self,
        h: f64,
        scale: Scale,
        first: usize,
        method: NewtonMethod,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Result<(usize, Vec<f64>), (NewtonFailure, bool)> {
        let model = self.model;
        self.predict(h);
        self.run.dq_predicted.clone_from(&self.run.dq);
        self.run.watch.round_off = None;
        let t = self.run.state.time;
        let mut residuals = Vec::new();
        // |r_F|, |r_M| of each iterate, whose growth from the predictor's
        // tells a divergence
        let mut forces: Vec<[f64; 2]> = Vec::new();
        // the progress measure of each iterate: the larger of the relative
        // residual over its tolerance and the constraint violation over its
        let mut progress: Vec<f64> = Vec::new();
        let mut last: Option<(f64, f64)> = None;
        let free_size = model.length_scale;
        let mut x = Vec::new();
        let mut stale_used = false;
        let carried = method == NewtonMethod::Modified && self.run.factors.made_for.is_some();
        // whether new factors were made in this attempt
        let mut refreshed = false;
        let tol = self.settings.residual_tolerance;
        for iteration in 0..=self.settings.max_iterations {
            let numbered = first + iteration;
            // S with the residual where a correction with new factors is
            // sure to follow (the predictor without factors kept), or
            // expected to (full Newton whose last contraction, repeated,
            // leaves the residual above tolerance, or at the first
            // corrected iterate when the last step needed more than one
            // correction); else the residual alone, S assembled after it
            // if needed
            let expected = match progress[..] {
                [.., previous, now] if previous > 0.0 => now * now / previous,
                _ => 0.0,
            };
            let with_tangent = match method {
                NewtonMethod::Full => {
                    iteration == 0
                        || expected > 1.0
                        || (iteration == 1 && self.run.factors.fresh_iterations >= 2)
                }
                NewtonMethod::Modified => iteration == 0 && self.run.factors.made_for.is_none(),
            };
            self.assemble_iterate(h, with_tangent, iteration == 0);
            let motion = self.step_motion(h);
            let (mut norms, worst) = self.norms(FLOOR_FACTOR, motion);
            if let Some((dx, dth)) = last {
                norms.displacement_correction = dx;
                norms.rotation_correction = dth;
            }
            residuals.push(norms.relative_residual);
            forces.push([norms.residual_force, norms.residual_moment]);
            progress.push(
                (norms.relative_residual / tol.max(f64::MIN_POSITIVE))
                    .max(norms.residual_constraint),
            );
            observer.iteration(&IterationInfo {
                increment,
                iteration: numbered,
                time: t,
                norms,
            });
            let finite = norms.residual_force.is_finite()
                && norms.residual_moment.is_finite()
                && norms.residual_coordinate.is_finite()
                && norms.residual_constraint.is_finite();
            if !finite {
                self.run.location = self.solver.dof_label(model, worst);
                let origin = non_finite_origin(model, &self.run.state, t);
                return Err((
                    NewtonFailure::NonFinite {
                        iteration: numbered,
                        origin,
                    },
                    stale_used,
                ));
            }
            if last.is_some() {
                let ratio = match residuals[..] {
                    [.., previous, now] if previous > 0.0 => (now / previous).min(1.0),
                    _ => 1.0,
                };
                let converged = norms.relative_residual <= tol
                    && norms.residual_constraint <= 1.0
                    && self.correction_converged(&x, ratio, motion, &norms);
                // the residual stopped decreasing at its round-off: within
                // PLATEAU_FACTOR ε of the flux, or left by a correction
                // that no longer changes the unknowns (the round-off of a
                // stiff element's force is ε E A |x|/L, not ε of the
                // force: a stiff beam's residual stops at ~1e-8 of the
                // flux)
                let plateau = || {
                    let (loose, _) = self.norms(PLATEAU_FACTOR, motion);
                    let (dx, dth) = last.unwrap_or_default();
                    ratio > 0.5
                        && loose.residual_constraint <= 1.0
                        && (loose.relative_residual <= tol || self.at_round_off(dx, dth))
                };
                if converged || plateau() {
                    if !converged && norms.relative_residual > tol {
                        let (dx, dth) = last.unwrap_or_default();
                        self.run.watch.round_off = Some((norms.relative_residual, dx, dth));
                    }
                    let factors = &mut self.run.factors;
                    if !carried {
                        factors.fresh_iterations = iteration;
                    } else if !refreshed {
                        factors.carry_backoff = 0;
                    }
                    return Ok((iteration, residuals));
                }
            }
            if iteration == self.settings.max_iterations {
                self.run.location = format!(
                    "{} (relative residual {:.3e})",
                    self.solver.dof_label(model, worst),
                    norms.relative_residual
                );
                return Err((
                    NewtonFailure::MaxIterations {
                        iterations: numbered,
                        relative_residual: norms.relative_residual,
                    },
                    stale_used,
                ));
            }

            // the factors for this iterate's correction: new ones unless
            // those kept reduced the progress measure by POOR_CONTRACTION
            // at the last correction (CARRY_CONTRACTION at the first
            // correction of factors carried from an earlier step)
            let contraction = match progress[..] {
                [.., previous, now] if previous > 0.0 => now / previous,
                _ => 0.0,
            };
            let refactor = match method {
                NewtonMethod::Full => true,
                NewtonMethod::Modified => {
                    let factors = &mut self.run.factors;
                    // factors carried from an earlier step that have not
                    // converged the step in the iterations new ones took:
                    // new ones, and the next steps wait before carrying
                    let carried_poorly =
                        carried && !refreshed && iteration >= factors.fresh_iterations.max(1);
                    if carried_poorly {
                        factors.carry_backoff = (2 * factors.carry_backoff).clamp(1, CARRY_WAIT);
                        factors.carry_wait = factors.carry_backoff;
                    }
                    factors.made_for.is_none() || carried_poorly || contraction > POOR_CONTRACTION
                }
            };
            // new factors of S at this iterate if needed, then S x = −r
            // with the constraint rows and multipliers scaled (D8)
            let mut solved = Ok(());
            if refactor {
                if !with_tangent {
                    self.assemble_iterate(h, true, false);
                }
                solved = self.factor_iteration_matrix(h, scale);
                refreshed = true;
            } else {
                stale_used = true;
            }
            let solved = solved.and_then(|()| {
                let run = &mut *self.run;
                let (dofs, assembler, _) = self.solver.system();
                for (eq, r) in run.work.rhs.iter_mut().enumerate() {
                    *r = -assembler.residual[dofs.dof(eq)] * scale.of(dofs.equation_kind(eq));
                }
                let lu = run.factors.lu.as_mut().expect("factored above or before");
                lu.solve_in_place(&mut run.work.rhs)
            });
            x.clone_from(&self.run.work.rhs);
            let dofs = &self.solver.dofs;
            let (mut dx, mut dth) = (0.0f64, 0.0f64);
            for (eq, v) in x.iter_mut().enumerate() {
                let kind = dofs.equation_kind(eq);
                *v *= scale.of(kind);
                let a = if v.is_finite() {
                    v.abs()
                } else {
                    f64::INFINITY
                };
                match kind {
                    DofKind::Translation => dx = dx.max(a),
                    DofKind::Rotation => dth = dth.max(a),
                    DofKind::Coordinate { length } => dx = dx.max(a * length),
                    DofKind::Multiplier(_) => {}
                }
            }
            if solved.is_err()
                || !(dx <= RUNAWAY_CORRECTION * free_size && dth <= RUNAWAY_CORRECTION)
            {
                // after iterations that drove the residual up, a singular
                // matrix or a runaway correction is the divergence's
                // doing, not a mechanism's
                let growth = match (forces.first(), forces.last()) {
                    (Some(a), Some(b)) => (0..2)
                        .filter(|&k| a[k] > 0.0)
                        .map(|k| b[k] / a[k])
                        .fold(0.0f64, f64::max),
                    _ => 0.0,
                };
                let diverged = numbered > 0 && growth > DIVERGED_GROWTH;
                // the matrix of the factors names the singular unknown (a
                // factorisation of its own: not for a correction that was
                // solved and ran away from a diverging iterate, which a
                // matrix singular there would not explain, docs/results.md)
                let run = &*self.run;
                let failure = match &run.factors.matrix {
                    Some(_) if diverged && solved.is_ok() => NewtonFailure::NonFinite {
                        iteration: numbered,
                        origin: "in a diverging iterate".into(),
                    },
                    Some(matrix) => singular(model, self.solver, matrix, &run.state, numbered),
                    None => NewtonFailure::NonFinite {
                        iteration: numbered,
                        origin: "in the solution of the linear system".into(),
                    },
                };
                let failure = match forces.first().zip(forces.last()) {
                    Some((from, to)) if diverged => {
                        let (from, to) = (from[0].max(from[1]), to[0].max(to[1]));
                        let what = match &failure {
                            NewtonFailure::Singular { dof, .. } => {
                                format!("the iteration matrix singular there, at {dof}")
                            }
                            _ if solved.is_ok() => format!(
                                "a correction of {dx:.1e} in translation, {dth:.1e} rad in rotation"
                            ),
                            other => other.to_string(),
                        };
                        NewtonFailure::Diverged {
                            iteration: numbered,
                            from,
                            to,
                            what,
                        }
                    }
                    _ => failure,
                };
                self.run.location = match &failure {
                    NewtonFailure::Singular { dof, .. } => dof.clone(),
                    _ => self.solver.dof_label(model, worst),
                };
                self.run.factors.made_for = None;
                return Err((failure, stale_used));
            }
            self.correct(h, &x);
            last = Some((dx, dth));
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Assembles at the current iterate the residual and the flux, with
    /// `S = β′M + γ′C + K T(hΔq)` (D7, unscaled) if `with_tangent`; at the
    /// predictor (`predictor`) keeps the flux of the step.
    fn assemble_iterate(&mut self, h: f64, with_tangent: bool, predictor: bool) {
        let model = self.model;
        let run = &mut *self.run;
        let (dofs, assembler, _) = self.solver.system();
        run.work.prepare(dofs, &assembler.matrix, model.n_nodes());
        let ctx = dynamic_context(model, run.state.time, &self.scheme, h);
        if with_tangent {
            for (node, f) in run.work.factors.iter_mut().enumerate() {
                let dq = &run.dq[node];
                *f = so3::tangent(&(Vec3::new(dq[3], dq[4], dq[5]) * h));
            }
            if run.spatial.iter().any(|&s| s) {
                spatial_columns(run, h);
                let (factors, spatial) = (&run.work.factors, &run.work.spatial);
                assembler.assemble_spatial(model, &ctx, &run.state, factors, spatial);
            } else {
                assembler.assemble_factored(model, &ctx, &run.state, &run.work.factors);
            }
        } else {
            assembler.assemble(model, &ctx.with_need(Need::RESIDUAL), &run.state);
        }
        // the flux of the step: Σₑ |rₑ| at the predictor (v̇ = 0)
        if predictor {
            let n = run.work.flux.len();
            run.work.flux.copy_from_slice(&assembler.flux[..n]);
        }
    }

    /// D11: the local error estimate `e = (β − 1/6) h² (a_{n+1} − a_n)`,
    /// the difference taken over the last two steps,
    /// `h (a_{n+1} − a_{n−1})/(h + h_{n−1})`, which cancels the alternating
    /// transient that index-3 constraints and changes of step excite in `a`
    /// (decaying as `ρ∞ⁿ`), and which is not an error of the positions.
    /// Left by equation in `Work::error` (zero on the multipliers).
    fn local_error(&mut self, h: f64) {
        let run = &mut *self.run;
        let c = (self.scheme.beta - 1.0 / 6.0).abs() * h * h;
        let s = &run.state;
        let dofs = &self.solver.dofs;
        let w = run.last_step.map(|hp| h / (h + hp));
        let difference = |a1: f64, a0: f64, before: Option<f64>| match (w, before) {
            (Some(w), Some(am)) => w * (a1 - am),
            _ => a1 - a0,
        };
        let first = dofs.first_coordinate();
        run.work.error.clear();
        run.work.error.extend((0..dofs.n_equations()).map(|eq| {
            let d = dofs.dof(eq);
            if let Some((node, k)) = dofs.node_component(d) {
                // the spatial scheme's rates in the frame of R_n, where
                // a_n and a_{n−1} are
                let a1 = if run.spatial[node] && k >= 3 {
                    run.turned[node][2][k - 3]
                } else {
                    s.pseudo_acceleration[node][k]
                };
                c * difference(
                    a1,
                    run.a_start[node][k],
                    run.a_before.get(node).map(|a| a[k]),
                )
            } else if d < dofs.first_multiplier() {
                let k = d - first;
                c * difference(
                    s.coordinate_pseudo_accelerations[k],
                    run.a_start_coordinates[k],
                    run.a_before_coordinates.get(k).copied(),
                )
            } else {
                0.0
            }
        }));
    }

    /// The error measure of the step (docs/theory.md §15.5): the local
    /// error `e` (D11) filtered by the iteration matrix (D11a),
    ///
    /// ```text
    /// [ S        −kBᵀ ] [ ê ]   [ β′ M u  ]
    /// [ −kB T     0   ] [ μ ] = [ −kB T u ],   u = e, then u = ê,
    /// ```
    ///
    /// which keeps the error of the motions the step resolves
    /// (`ωh ≪ 1`: `ê ≈ e`) and removes that of the vibrations it does not
    /// (`ωh ≫ 1`, damped by `ρ∞ < 1`: `e` grows as `(ωh)²`, `ê` decays as
    /// `(ωh)⁻²`), the part of `e` across the constraints kept; then, for
    /// each node, `ê` in the metric of its mass block against a motion of
    /// `Δx` in every direction of translation and `Δθ` in every direction
    /// of rotation (D11b),
    ///
    /// ```text
    /// ‖ê_i‖_{M_ii} / (tol · √(Δx² tr M_xx/3 + Δθ² tr M_θθ/3)),
    /// ```
    ///
    /// `Δx`, `Δθ` the largest translation and rotation of the step, at
    /// least 1e-3 of the model size and 1e-3 rad; the largest over the
    /// nodes (Euclidean norms for a node without mass; a coordinate's
    /// `|ê| ℓ` against `Δx`). `S` is the one the step's last correction
    /// was solved with ([`IterationFactors`]: with modified Newton made at
    /// an earlier iterate of this step or at an earlier step of the same
    /// size, docs/theory.md §15.1), scaled (D8): its factors, and its
    /// constraint rows for the right-hand side (`−kB T` times the row
    /// scale); `M` is assembled at the converged state in the buffers of
    /// [`MassSystem`], the solver's residual and flux kept. Without
    /// factors, or if a solve fails, `ê = e`.
    fn error_estimate(&mut self, h: f64) -> f64 {
        self.local_error(h);
        let (dx, dth) = self.step_motion(h);
        let (model, sc) = (self.model, self.scheme);
        let run = &mut *self.run;
        let t = run.state.time;
        let (dofs, assembler, _) = self.solver.system();
        let n = dofs.n_equations();
        // M at the converged state, the solver's residual and flux kept
        let work = &mut run.work;
        work.kept.clone_from(&assembler.residual);
        work.kept_flux.clone_from(&assembler.flux);
        let buffers = &mut run.mass_system;
        let same = |m: &SparseMatrix| m.same_pattern(&assembler.matrix);
        if !buffers.stiffness.as_ref().is_some_and(same) {
            buffers.stiffness = Some(assembler.matrix.clone());
            buffers.mass = Some(assembler.matrix.clone());
        }
        let mass = buffers.mass.as_mut().expect("set above");
        let ctx = dynamic_context(model, t, &sc, h).with_need(Need::with_inertia(0.0, 1.0));
        assembler.assemble_inertia(model, &ctx, &run.state, mass);
        std::mem::swap(&mut assembler.residual, &mut work.kept);
        std::mem::swap(&mut assembler.flux, &mut work.kept_flux);

        // D11a, applied FILTER_PASSES times: right-hand side β′ M u, and
        // −kB T u on the constraint rows, scaled by D8 (those of the
        // matrix factored, scaled already)
        let bp = sc.beta_prime(h);
        work.filtered.clone_from(&work.error);
        work.product.resize(n, 0.0);
        work.spare.resize(n, 0.0);
        let factors = &mut run.factors;
        let mut filtered = factors.made_for.is_some() && factors.lu.is_some();
        for _ in 0..FILTER_PASSES {
            let (Some(lu), Some(matrix)) = (
                factors.lu.as_mut().filter(|_| filtered),
                factors.matrix.as_ref(),
            ) else {
                break;
            };
            mass.mul_vec(&work.filtered, &mut work.product);
            matrix.mul_vec(&work.filtered, &mut work.spare);
            for (eq, f) in work.product.iter_mut().enumerate() {
                *f = match dofs.equation_kind(eq) {
                    DofKind::Multiplier(_) => work.spare[eq],
                    _ => bp * *f,
                };
            }
            filtered = lu.solve_in_place(&mut work.product).is_ok()
                && work.product.iter().all(|v| v.is_finite());
            std::mem::swap(&mut work.filtered, &mut work.product);
        }
        if !filtered {
            work.filtered.clone_from(&work.error);
        }
        for (eq, u) in work.filtered.iter_mut().enumerate() {
            if matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)) {
                *u = 0.0;
            }
        }

        // D11b: per node, ê in the metric of its mass block against a
        // motion of (Δx, Δθ) in every direction
        let l = model.length_scale;
        let (x_ref, th_ref) = (dx.max(1e-3 * l), dth.max(1e-3));
        let nodes = run.state.n_nodes();
        let e = &work.filtered;
        let sums = &mut work.node_sums;
        sums.clear();
        sums.resize(nodes, [0.0; 5]);
        for (row, col, m) in mass.entries() {
            let (Some((a, i)), Some((b, _))) = (
                dofs.node_component(dofs.dof(row)),
                dofs.node_component(dofs.dof(col)),
            ) else {
                continue;
            };
            if a != b {
                continue;
            }
            sums[a][0] += e[row] * m * e[col];
            if row == col {
                sums[a][if i < 3 { 1 } else { 2 }] += m;
            }
        }
        let mut measure = 0.0f64;
        let mut peak = None;
        for (eq, &v) in e.iter().enumerate() {
            let d = dofs.dof(eq);
            if let Some((node, k)) = dofs.node_component(d) {
                sums[node][3 + k / 3] += v * v;
            } else if let DofKind::Coordinate { length } = dofs.kind(d) {
                let ratio = v.abs() * length / x_ref;
                if ratio > measure {
                    measure = ratio;
                    peak = Some(ErrorPeak::Coordinate);
                }
            }
        }
        for (node, &[error, mx, mth, ex, eth]) in sums.iter().enumerate() {
            let reference = x_ref * x_ref * mx / 3.0 + th_ref * th_ref * mth / 3.0;
            let ratio = if reference > 0.0 {
                (error.max(0.0) / reference).sqrt()
            } else {
                // no mass: the Euclidean norms, as lengths and angles
                (ex.sqrt() / x_ref).max(eth.sqrt() / th_ref)
            };
            if ratio > measure {
                measure = ratio;
                peak = Some(ErrorPeak::Node(node));
            }
        }
        work.error_peak = peak;
        measure / self.settings.error_tolerance
    }
}

impl Stepper for Dynamics<'_> {
    type Error = DynamicError;

    fn recorded(&self, error: &DynamicError) -> bool {
        matches!(error, DynamicError::Output(e) if e.kind() == std::io::ErrorKind::Interrupted)
    }

    fn current(&self) -> (&Model, &State) {
        (self.model, &self.run.state)
    }

    fn time(&self) -> f64 {
        self.run.accepted.time
    }

    fn sized_in_time(&self) -> bool {
        true
    }

    /// The estimate is relative to the step's motion (`∝ h`), so it grows
    /// as `h²`.
    fn error_order(&self) -> f64 {
        1.0
    }

    fn update_active_set(
        &mut self,
        time: f64,
        observer: &mut dyn Observer,
    ) -> Result<bool, DynamicError> {
        let (model, run) = (self.model, &mut *self.run);
        if !self.solver.active_set_changed(model, &run.accepted, time) {
            return Ok(false);
        }
        // the constraints of the factors are no longer those acting
        run.factors.made_for = None;
        let before = self.solver.redundant_count();
        let rank = self.solver.constraint_rank(model, &run.accepted, time);
        for &k in &rank.redundant {
            run.accepted.multipliers[k] = 0.0;
            run.state.multipliers[k] = 0.0;
        }
        if rank.redundant.len() != before {
            observer.note(&format!(
                "at t = {time}: the active constraints changed; {} redundant constraint equation(s) removed",
                rank.redundant.len()
            ));
        }
        run.redundant = run.redundant.max(rank.redundant.len());
        Ok(true)
    }

    fn attempt(
        &mut self,
        size: f64,
        _target: f64,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Attempt {
        match self
            .newton(size, increment, observer)
            .and_then(|converged| {
                // before the projection, which replaces the factors of S
                // the estimate uses (D11a); with fixed steps, on the first
                // steps and then on one step in FIXED_STEP_CHECKS, until
                // the note on a long step has been given
                let sampled =
                    increment <= FIXED_STEP_CHECKS || increment.is_multiple_of(FIXED_STEP_CHECKS);
                let error = (self.settings.adaptive
                    || (sampled && !self.run.watch.fixed_step_noted))
                    .then(|| self.error_estimate(size));
                self.project_velocities(size, error.is_some())
                    .map(|()| (converged, error))
            }) {
            Ok(((iterations, residuals), error)) => {
                if let Some(what) = self.spurious(size) {
                    return Attempt::Failed(NewtonFailure::Spurious { iterations, what });
                }
                self.notes(size, error, increment, observer);
                Attempt::Converged {
                    iterations,
                    residuals,
                    error: error.filter(|_| self.settings.adaptive),
                }
            }
            Err(f) => Attempt::Failed(f),
        }
    }

    fn attempted_time(&self) -> f64 {
        self.run.state.time
    }

    fn error_location(&self) -> Option<String> {
        Some(match self.run.work.error_peak? {
            ErrorPeak::Node(i) => format!("node {}", self.model.node_ids[i]),
            ErrorPeak::Coordinate => {
                "an element coordinate (a slider's curve parameter or a superelement's mode)".into()
            }
        })
    }

    fn reject(&mut self) {
        let run = &mut *self.run;
        run.state.clone_from(&run.accepted);
    }

    fn accept(
        &mut self,
        info: &IncrementInfo,
        observer: &mut dyn Observer,
    ) -> Result<(), DynamicError> {
        // a constraint left out as redundant and violated by the step: the
        // constraints contradict each other, and the step is not kept
        // (docs/joints.md §5, "Consistency")
        let motion = self.step_motion(info.step).0;
        if let Some((constraint, violation)) = self.solver.violated_redundant_within(
            self.model,
            &self.run.state,
            self.settings.displacement_tolerance * motion,
            self.settings.rotation_tolerance,
        ) {
            return Err(DynamicError::Inconsistent {
                time: info.time,
                constraint,
                violation,
            });
        }
        // laws that hold within bounds (docs/theory.md §3.1, §17.5)
        for e in &self.model.elements {
            if let Some(reason) = e.law_violated(&self.run.accepted, &self.run.state) {
                return Err(DynamicError::LawViolated {
                    element: format!("{} {}", e.kind().name(), e.id()),
                    from: self.run.accepted.time,
                    time: info.time,
                    reason,
                });
            }
        }
        let (model, run) = (self.model, &mut *self.run);
        // the controller may snap t onto a landing time within round-off
        run.state.time = info.time;
        run.last_step = Some(info.step);
        run.a_before.clone_from(&run.accepted.pseudo_acceleration);
        run.a_before_coordinates
            .clone_from(&run.accepted.coordinate_pseudo_accelerations);
        // the spatial scheme's a_n into the frame of R_{n+1}, where the
        // next step compares its rates
        for (node, a) in run.a_before.iter_mut().enumerate() {
            if run.spatial[node] {
                let dq = &run.dq[node];
                let turn =
                    so3::exp_matrix(&(Vec3::new(dq[3], dq[4], dq[5]) * info.step)).transpose();
                let v = turn * Vec3::new(a[3], a[4], a[5]);
                a[3..6].copy_from_slice(v.as_slice());
            }
        }
        model.update_internal(&mut run.state);
        // the work of dampers and hinge laws over the step, with their
        // forces at the step's solution, before an impact changes the
        // velocities (docs/theory.md D12a)
        run.balance.close_step(model, &run.state);
        // latches reached lock: impact, then a restart (docs/theory.md §16)
        let locks = match impact::lock_latches(
            model,
            self.solver,
            &run.accepted,
            &mut run.state,
            info.increment,
        )? {
            Some(i) => {
                run.lock_rank_analyses += 1;
                run.redundant = run.redundant.max(i.redundant);
                restart_after_impact(model, self.solver, run, self.settings.end_time).map_err(
                    |failure| DynamicError::Initial {
                        time: info.time,
                        failure,
                    },
                )?;
                run.last_step = None;
                run.a_before.clear();
                run.a_before_coordinates.clear();
                run.balance.impact(i.locks[0].energy_lost, i.work);
                run.regrowing = true;
                i.locks
            }
            None => Vec::new(),
        };
        // spring latches latching or releasing (docs/theory.md §16.5)
        let mut locks = locks;
        let springs =
            impact::spring_latch_events_at(model, &run.accepted, &mut run.state, info.increment);
        if springs.restart {
            initial_accelerations(model, self.solver, run, self.settings.end_time).map_err(
                |failure| DynamicError::Initial {
                    time: info.time,
                    failure,
                },
            )?;
            run.last_step = None;
            run.a_before.clear();
            run.a_before_coordinates.clear();
            // from consistent accelerations, as after a lock (§16)
            run.regrowing = true;
        }
        run.balance.impact(springs.released, 0.0);
        locks.extend(springs.events);
        let crossings = springs.crossings;
        // stops reached or released: impact, then a restart (§16.4)
        let contacts = self.stop_events(info)?;
        let run = &mut *self.run;
        run.accepted.clone_from(&run.state);
        let residual = self.solver.residual();
        let before = run.energies;
        run.energies = run.balance.record(model, &run.state, Some(residual));
        run.watch.energy_jump(info, &before, &run.energies);
        observer.energies(&run.energies);
        observer.increment(info, model, &run.state, residual)?;
        for l in &locks {
            observer.lock(l);
        }
        for l in &crossings {
            observer.band_crossing(l);
        }
        for c in &contacts {
            observer.contact(c);
        }
        run.locks.extend(locks);
        run.contacts.extend(contacts);
        Ok(())
    }
}

impl Dynamics<'_> {
    /// The events of the stops at the accepted step `info`
    /// ([`impact::stop_events_at`]), and the restart after them.
    fn stop_events(&mut self, info: &IncrementInfo) -> Result<Vec<ContactInfo>, DynamicError> {
        let (model, run) = (self.model, &mut *self.run);
        let end_time = self.settings.end_time;
        let Some(i) = impact::stop_events_at(
            model,
            self.solver,
            &run.accepted,
            &mut run.state,
            info.increment,
            end_time,
        )?
        else {
            return Ok(Vec::new());
        };
        run.lock_rank_analyses += 1;
        run.redundant = run.redundant.max(i.redundant);
        let restart = |solver: &mut NewtonSolver, run: &mut Run| {
            restart_after_impact(model, solver, run, end_time).map_err(|failure| {
                DynamicError::Initial {
                    time: info.time,
                    failure,
                }
            })
        };
        restart(self.solver, run)?;
        // a contact that closed with a pulling load opens again
        let closed: Vec<Id> = i
            .events
            .iter()
            .filter(|c| c.kind == ContactKind::Close)
            .map(|c| c.stop)
            .collect();
        if impact::release_pulling(model, &mut run.state, &closed) {
            let rank = self.solver.constraint_rank(model, &run.state, info.time);
            for &k in &rank.redundant {
                run.state.multipliers[k] = 0.0;
            }
            restart(self.solver, run)?;
        }
        run.last_step = None;
        run.a_before.clear();
        run.a_before_coordinates.clear();
        run.balance.impact(i.energy_lost, i.work);
        run.rebound_step = i.rebound_step;
        run.closed = i.events.iter().any(|c| c.kind == ContactKind::Close);
        // after a release the steps grow back from the landing step, as
        // after a lock (docs/theory.md §16.4, "Resuming after a release")
        if i.events.iter().any(|c| c.kind == ContactKind::Release) {
            run.regrowing = true;
        }
        Ok(i.events)
    }
}

/// What the checks of the converged steps keep (docs/theory.md §15.5,
/// §15.6).
#[derive(Default)]
struct Watch {
    /// The energies at the start of the analysis.
    start: Energies,
    /// The largest energy of the motion so far ([`Watch::scale`]).
    largest: f64,
    /// The attempted step was accepted at the round-off plateau of its
    /// residual above the residual tolerance: the relative residual and
    /// the last corrections (translation, rotation).
    round_off: Option<(f64, f64, f64)>,
    /// The steps whose change of `E` was above [`ENERGY_JUMP`] of the
    /// largest energy when they were taken: the step, `E` before and
    /// after. Reported at the end of the analysis against the largest
    /// energy of the whole motion ([`Watch::warnings`]).
    jumps: Vec<(IncrementInfo, f64, f64)>,
    /// Notes given once per analysis: a step accepted at its round-off
    /// plateau, a fixed step with a large error estimate.
    round_off_noted: bool,
    fixed_step_noted: bool,
}

impl Watch {
    /// The size of the energies of the motion at `e`: the largest of `T`,
    /// the strain and spring energies, the change of the weight's
    /// potential since the start, the work and the dissipation.
    fn scale(&self, e: &Energies) -> f64 {
        [
            e.kinetic,
            e.strain.abs(),
            e.spring.abs(),
            (e.gravity - self.start.gravity).abs(),
            e.external_work.abs(),
            e.dissipated.abs(),
            e.hinge_law_work.abs(),
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }

    /// D12 checked step by step: the balance error `E` should change by
    /// the integrator's error of one step, a small fraction of the
    /// energies in play; a change by more than [`ENERGY_JUMP`] of the
    /// largest energy of the motion is a step that created or lost energy
    /// (a spurious root, a step far too long for the motion). The step
    /// `info` is kept if its change is above that fraction of the largest
    /// energy so far; [`Watch::warnings`] keeps those above it for the
    /// whole motion (from rest, the first steps' errors are large next to
    /// the energies reached so far, and small next to those reached
    /// later).
    fn energy_jump(&mut self, info: &IncrementInfo, before: &Energies, after: &Energies) {
        self.largest = self.largest.max(self.scale(before)).max(self.scale(after));
        let jump = after.balance_error - before.balance_error;
        if jump.abs() > ENERGY_JUMP * self.largest {
            self.jumps
                .push((info.clone(), before.balance_error, after.balance_error));
        }
    }

    /// The warnings of the steps kept by [`Watch::energy_jump`] whose
    /// change of `E` is above [`ENERGY_JUMP`] of the largest energy of the
    /// motion (once, at the end of the analysis). A loss is said to be
    /// numerical damping only where the integrator damps (`ρ∞ < 1`).
    fn warnings(&mut self, rho_infinity: f64) -> Vec<WarningInfo> {
        let largest = self.largest;
        std::mem::take(&mut self.jumps)
            .into_iter()
            .filter(|(_, before, after)| (after - before).abs() > ENERGY_JUMP * largest)
            .map(|(info, before, after)| WarningInfo {
                increment: info.increment,
                from: info.time - info.step,
                time: info.time,
                message: if after > before {
                    format!(
                        "the energy balance error changed by {:.3e} in one step (from {before:.3e} to {after:.3e}), more than {} % of the largest energy of the motion ({largest:.3e}): the step created energy; its results are suspect (shorten time_step, or use adaptive steps)",
                        after - before,
                        ENERGY_JUMP * 100.0,
                    )
                } else if rho_infinity >= 1.0 {
                    format!(
                        "the energy balance error changed by {:.3e} in one step (from {before:.3e} to {after:.3e}), more than {} % of the largest energy of the motion ({largest:.3e}): the step lost energy, and with rho_infinity = 1 the integrator damps nothing: the step is too long for the motion (a corner of a spring law, or a load that changes, inside it); its results are suspect (shorten time_step, or use adaptive steps)",
                        after - before,
                        ENERGY_JUMP * 100.0,
                    )
                } else {
                    format!(
                        "the energy balance error changed by {:.3e} in one step (from {before:.3e} to {after:.3e}), more than {} % of the largest energy of the motion ({largest:.3e}): the step lost energy, through the numerical damping of vibrations faster than the step (rho_infinity < 1; after a lock or an impact, the structure's ringing) or a step far too long for the motion; the loads of the vibrations it damped are not in the results (shorten time_step, or raise rho_infinity, to follow them)",
                        after - before,
                        ENERGY_JUMP * 100.0,
                    )
                },
            })
            .collect()
    }
}

impl Dynamics<'_> {
    /// The checks of a converged step that its residual cannot make
    /// (docs/theory.md §15.5): the node that turned by more than
    /// [`MAX_ROTATION_STEP`] in the step, or that Newton carried more than
    /// [`MAX_ROTATION_CORRECTION`] or [`MAX_TRANSLATION_CORRECTION`] times
    /// the model's size from the predictor. Such a step solves the
    /// equations of the step but is no motion a step of its size can
    /// follow: it is cut back.
    fn spurious(&mut self, h: f64) -> Option<String> {
        let (model, run) = (self.model, &mut *self.run);
        let dofs = &self.solver.dofs;
        let norm = |v: &[f64]| h * Vec3::new(v[0], v[1], v[2]).norm();
        let l = model.length_scale;
        for node in 0..model.n_nodes() {
            let free = |c: usize| dofs.equation(6 * node + c) != NO_EQUATION;
            let (dq, pred) = (&run.dq[node], &run.dq_predicted[node]);
            let change = |k: usize| {
                norm(&[
                    dq[k] - pred[k],
                    dq[k + 1] - pred[k + 1],
                    dq[k + 2] - pred[k + 2],
                ])
            };
            let id = model.node_ids[node];
            let found = if (3..6).any(free) {
                let turn = norm(&dq[3..6]);
                let spin = norm(&run.state.velocity[node][3..6]);
                if turn.max(spin) > MAX_ROTATION_STEP {
                    Some(format!(
                        "node {id} turned by {:.3e} rad in one step (h |Δq| = {turn:.3e}, h |Ω| = {spin:.3e}), more than the {MAX_ROTATION_STEP} rad a step may follow",
                        turn.max(spin)
                    ))
                } else if change(3) > MAX_ROTATION_CORRECTION {
                    Some(format!(
                        "Newton turned node {id} by {:.3e} rad away from the predictor, more than half a turn",
                        change(3)
                    ))
                } else {
                    None
                }
            } else {
                None
            };
            let found = found.or_else(|| {
                ((0..3).any(free) && change(0) > MAX_TRANSLATION_CORRECTION * l).then(|| {
                    format!(
                        "Newton moved node {id} by {:.3e} away from the predictor, more than the model's size {l:.3e}",
                        change(0)
                    )
                })
            });
            if let Some(what) = found {
                run.location = format!("node {id}");
                return Some(what);
            }
        }
        None
    }

    /// The notes of a converged step, each given once per analysis: a step
    /// accepted at the round-off plateau of its residual with the relative
    /// residual above `residual_tolerance` (its log line ends above the
    /// tolerance), and a fixed step whose local error estimate (D11) is
    /// above [`FIXED_STEP_ERROR_NOTE`] of its motion.
    fn notes(&mut self, h: f64, error: Option<f64>, increment: usize, observer: &mut dyn Observer) {
        let t = self.run.state.time;
        if let Some((relative, dx, dth)) = self.run.watch.round_off {
            if !self.run.watch.round_off_noted {
                self.run.watch.round_off_noted = true;
                observer.note(&format!(
                    "step {increment} (t = {t}) converged at the round-off of its residual: the relative residual {relative:.1e} is above residual_tolerance {:e} but stopped decreasing at its floating-point floor (last correction max|dx| {dx:.1e}, max|dθ| {dth:.1e}); such steps are accepted, and their log lines end above the tolerance (docs/results.md, log.txt)",
                    self.settings.residual_tolerance
                ));
            }
        }
        if let (false, false, Some(error)) = (
            self.settings.adaptive,
            self.run.watch.fixed_step_noted,
            error,
        ) {
            let error = error * self.settings.error_tolerance;
            if error > FIXED_STEP_ERROR_NOTE {
                self.run.watch.fixed_step_noted = true;
                observer.note(&format!(
                    "step {increment} (t = {t}): the local error estimate of the fixed step {h:e} is {error:.1e} times the step's motion (noted above {FIXED_STEP_ERROR_NOTE:e}): the step is long for the motion; shorten time_step, or use adaptive steps (docs/theory.md §15.5)"
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Quiet;
    impl Observer for Quiet {}

    /// A spinning rigid body on a spherical joint at a point off its centre
    /// of mass (the heavy top of bench/peer at a fifth of its spin), with
    /// a rotary damper to the ground, so that `C` and `M` both have
    /// rotation columns.
    fn spinning_top() -> (Arc<Model>, State) {
        use crate::model::builder::*;
        let mut m = ModelBuilder::new("top");
        let node = m.node([0.0, 1.0, 0.0]);
        m.add(RigidBody::at(node, 15.0).inertia([0.234375, 0.46875, 0.234375]));
        m.add(Joint::spherical(node, Ground).at([0.0, 0.0, 0.0]));
        m.add(Gravity::of([0.0, 0.0, -9.81]).curve(CurveHandle::CONSTANT));
        let model = Arc::new(m.build().expect("a valid model"));
        let mut s = model.initial_state();
        let n = model.node(node);
        let w = Vec3::new(0.3, 30.0, -4.6);
        let v = w.cross(&Vec3::new(0.0, 1.0, 0.0));
        s.velocity[n] = [v.x, v.y, v.z, w.x, w.y, w.z];
        (model, s)
    }

    /// The iteration matrix `S` (D7) of a step against central differences
    /// of the residual along Newton's corrections (`correct`: `Δq += x/h`,
    /// the rates and, in the spatial scheme, `Λ = exp(−hΔΘ~)` with them),
    /// columns of the node's unknowns, at a corrected iterate away from
    /// the predictor, `h|Ω| = 0.06`. Tolerance 1e-9 of the largest entry
    /// of `S` (`β′M`; measured: 2.6e-15 in both schemes; in the spatial
    /// scheme without its term `C Ω~T` 1.4e-5, without `M Ω̇~T` 2.6e-6,
    /// with `I` for `Λ` 9.4e-4).
    #[test]
    fn iteration_matrix_is_the_derivative_along_the_corrections() {
        for frame in [AngularVelocities::Material, AngularVelocities::Spatial] {
            let (model, start) = spinning_top();
            let h = 2e-3;
            let mut settings = DynamicSettings::new(0.1, h).fixed_step();
            settings.angular_velocities = frame;
            let mut analysis = DynamicAnalysis::new(model.clone(), settings);
            analysis.start(start, &mut Quiet);
            let mut d = Dynamics {
                model: &analysis.model,
                settings: &analysis.settings,
                scheme: analysis.scheme,
                solver: &mut analysis.solver,
                run: analysis.run.as_mut().expect("started"),
            };
            d.predict(h);
            let n = d.solver.dofs.n_equations();
            let away: Vec<f64> = (0..n)
                .map(|k| 1e-4 * (1.0 + 0.37 * k as f64).sin())
                .collect();
            d.correct(h, &away);
            d.assemble_iterate(h, true, false);
            let s = d.solver.system().1.matrix.clone();
            let mut dense = vec![vec![0.0; n]; n];
            for (r, c, v) in s.entries() {
                dense[r][c] += v;
            }
            let largest = dense.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let residual = |d: &mut Dynamics, x: &[f64]| {
                d.correct(h, x);
                d.assemble_iterate(h, false, false);
                let r = d.solver.system().1.residual.clone();
                let back: Vec<f64> = x.iter().map(|v| -v).collect();
                d.correct(h, &back);
                r
            };
            let eps = 1e-6;
            let mut worst = 0.0f64;
            for j in 0..n {
                if d.solver.dofs.node_component(d.solver.dofs.dof(j)).is_none() {
                    continue;
                }
                let mut x = vec![0.0; n];
                x[j] = eps;
                let plus = residual(&mut d, &x);
                x[j] = -eps;
                let minus = residual(&mut d, &x);
                for i in 0..n {
                    let di = d.solver.dofs.dof(i);
                    let fd = (plus[di] - minus[di]) / (2.0 * eps);
                    worst = worst.max((fd - dense[i][j]).abs());
                }
            }
            eprintln!(
                "{}: |S − FD| = {:.2e} of max |S| = {largest:.3e}",
                frame.name(),
                worst / largest
            );
            assert!(
                worst < 1e-9 * largest,
                "{}: {worst:e} against {largest:e}",
                frame.name()
            );
        }
    }

    /// The energies of step 24 and 25 of the spurious root of
    /// tests/data/flexible_hinge_fixed_step.toml (energies.csv of the run
    /// without the checks of §15.5): the balance error jumps from −3.5e-3
    /// to 166 with a spring energy of 9.87 at the start, and is reported;
    /// the step before, changing it by 8.6e-5, is not.
    #[test]
    fn an_energy_jump_is_reported() {
        let at = |kinetic: f64, strain: f64, spring: f64, balance_error: f64| Energies {
            kinetic,
            strain,
            spring,
            balance_error,
            ..Energies::default()
        };
        let step = |increment: usize| IncrementInfo {
            increment,
            time: 1e-3 * increment as f64,
            step: 1e-3,
            iterations: 1,
            residuals: Vec::new(),
            output: true,
        };
        let mut watch = Watch {
            start: at(0.0, 0.0, 9.869604401089, 0.0),
            ..Watch::default()
        };
        let start = watch.start;
        let step23 = at(
            1.314608087748e-1,
            7.981515779887e-2,
            9.654877834098,
            -3.450600e-3,
        );
        let step24 = at(
            1.342314668733e-1,
            7.277050670905e-2,
            9.659065747507,
            -3.536680e-3,
        );
        let step25 = at(
            1.664593631505e2,
            1.390957047884e-1,
            9.743204174856,
            1.664721e2,
        );
        watch.energy_jump(&step(23), &start, &step23);
        watch.energy_jump(&step(24), &step23, &step24);
        watch.energy_jump(&step(25), &step24, &step25);
        let warnings = watch.warnings(0.9);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert_eq!(warnings[0].increment, 25);
        let message = &warnings[0].message;
        assert!(message.contains("changed by 1.665e2"), "{message}");
        assert!(message.contains("more than 5 %"), "{message}");
        assert!(message.contains("the step created energy"), "{message}");
        // the same jump downwards, numerical damping of the ringing: said
        // to be a loss, with the way to follow it
        let mut watch = Watch {
            start: at(0.0, 0.0, 9.869604401089, 0.0),
            ..Watch::default()
        };
        let step25 = Energies {
            balance_error: -1.664721e2,
            ..step25
        };
        watch.energy_jump(&step(24), &start, &step24);
        watch.energy_jump(&step(25), &step24, &step25);
        let kept = watch.jumps.clone();
        let warnings = watch.warnings(0.5);
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let message = &warnings[0].message;
        assert!(message.contains("changed by -1.665e2"), "{message}");
        assert!(message.contains("the step lost energy"), "{message}");
        assert!(message.contains("raise rho_infinity"), "{message}");
        // at ρ∞ = 1 nothing damps: the loss is the step's error, suspect
        watch.jumps = kept;
        let warnings = watch.warnings(1.0);
        let message = &warnings[0].message;
        assert!(message.contains("the step lost energy"), "{message}");
        assert!(!message.contains("numerical damping"), "{message}");
        assert!(message.contains("results are suspect"), "{message}");
    }

    /// From rest, the first steps' balance errors are large next to the
    /// energies reached so far (a driven body: −1.2e-10 with a kinetic
    /// energy of 2.8e-10 after the first step) and small next to those of
    /// the motion (1.4): not reported.
    #[test]
    fn the_errors_of_the_first_steps_from_rest_are_not_reported() {
        let at = |kinetic: f64, balance_error: f64| Energies {
            kinetic,
            balance_error,
            ..Energies::default()
        };
        let step = |increment: usize| IncrementInfo {
            increment,
            time: 1e-3 * increment as f64,
            step: 1e-3,
            iterations: 1,
            residuals: Vec::new(),
            output: true,
        };
        let mut watch = Watch::default();
        let (e0, e1, e2) = (at(0.0, 0.0), at(2.846e-10, -1.212e-10), at(1.4, -1.3e-8));
        watch.energy_jump(&step(1), &e0, &e1);
        assert_eq!(watch.jumps.len(), 1);
        watch.energy_jump(&step(2), &e1, &e2);
        assert!(watch.warnings(0.9).is_empty());
    }
}
