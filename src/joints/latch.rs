//! Latches: a joint coordinate `c` that locks when it reaches its locking
//! value `c_L` moving in the direction of approach (the lock at the end of
//! a hinge's travel of the reference paper, section 6.2; docs/joints.md
//! §6.2).
//!
//! Until it locks a latch applies nothing: its one multiplier equation is
//! `k λ = 0`, as a released driver's. A dynamic analysis watches the event
//! function `g = s (c − c_L)` (`s = ±1` the direction of approach, so that
//! `g < 0` before the lock), lands a step on `g = 0` within
//! [`EVENT_TOLERANCE`], applies the impact of the lock
//! ([`crate::analysis::impact`], docs/theory.md §16) and sets the latch's
//! lock flag, an internal variable. From then on (also in any later
//! analysis that starts from that state) it is the rigid constraint
//! `Φ = c(q) − c_L = 0` with its multiplier, whose load `kλ − pΦ` is the
//! moment (or force) that holds the lock.

use super::coordinate::PairCoordinate;
use super::hyperdual::HyperDual;
use super::joint::{add_constraints, constraint_kind, scale_of};
use super::kinematics::{with_scratch, Conf};
use super::types::Equation;
use crate::elements::{
    CellShape, ConstraintKind, Element, ElementKind, ElementOutput, EvalContext, Offsets,
};
use crate::model::Id;
use crate::state::State;

/// `|g|` at or below which a step has landed on the lock: 1e-8 rad for an
/// angle; for a length, 1e-8 of the model's size (the diagonal of the
/// bounding box of its nodes). About a hundredth of the default constraint
/// tolerance (1e-6 rad, 1e-6 of the step's motion), so that the lock is
/// found more accurately than the constraints are satisfied.
pub const EVENT_TOLERANCE: f64 = 1e-8;

/// Names of latch results: the coordinate, the lock flag (0 or 1), the
/// event function `g = s (c − c_L)` and the load holding the lock (moment
/// or force along the coordinate, zero while open).
pub const LATCH_RESULTS: [&str; 4] = ["coordinate", "locked", "gap", "load"];

/// A latch on a joint coordinate (see the module documentation).
#[derive(Clone, Debug)]
pub struct Latch {
    id: Id,
    /// The joint whose coordinate it locks.
    joint: Id,
    source: PairCoordinate,
    /// `c_L`.
    value: f64,
    /// `s`: +1 if it locks with `c` increasing, −1 decreasing.
    approach: f64,
    active: Vec<usize>,
    /// Where its multiplier and internal variables are in the state.
    offsets: Offsets,
}

impl Latch {
    /// Locks `source`, a coordinate of joint `joint`, at `value`, reached
    /// with the coordinate increasing (`approach > 0`) or decreasing.
    pub fn new(id: Id, joint: Id, source: PairCoordinate, value: f64, approach: f64) -> Self {
        let active = source.active();
        Self {
            id,
            joint,
            source,
            value,
            approach: if approach < 0.0 { -1.0 } else { 1.0 },
            active,
            offsets: Offsets::default(),
        }
    }

    /// The joint whose coordinate it locks.
    pub fn joint(&self) -> Id {
        self.joint
    }

    /// `c_L`.
    pub fn value(&self) -> f64 {
        self.value
    }

    /// `s = ±1`, the direction of approach.
    pub fn approach(&self) -> f64 {
        self.approach
    }

    /// Whether the coordinate is an angle.
    pub fn is_angle(&self) -> bool {
        self.source.is_angle()
    }

    /// The nodes of its pair.
    pub fn pair_nodes(&self) -> &[usize] {
        &self.source.nodes
    }

    /// Index of the lock flag in the state's internal variables.
    fn lock_slot(&self) -> usize {
        self.offsets.internal + usize::from(self.source.is_angle())
    }

    /// Index of its multiplier among the state's multipliers.
    pub fn multiplier(&self) -> usize {
        self.offsets.multipliers
    }

    /// Whether it is locked in `state`.
    pub fn is_locked(&self, state: &State) -> bool {
        state
            .internal
            .get(self.lock_slot())
            .is_some_and(|&f| f > 0.5)
    }

    /// Locks it in `state` (sets the lock flag).
    pub fn lock(&self, state: &mut State) {
        let slot = self.lock_slot();
        state.internal[slot] = 1.0;
    }

    fn reference(&self, state: &State) -> f64 {
        if self.source.is_angle() {
            state.internal[self.offsets.internal]
        } else {
            0.0
        }
    }

    /// The coordinate `c` at `state` (an angle on the branch of the last
    /// converged state).
    pub fn coordinate(&self, state: &State) -> f64 {
        self.source.value(state, self.reference(state))
    }

    /// The event function `g = s (c − c_L)`: negative before the lock.
    pub fn gap(&self, state: &State) -> f64 {
        self.approach * (self.coordinate(state) - self.value)
    }

    /// `ċ = B v`: the rate of the coordinate at the state's velocities,
    /// and its gradient `B` over the pair's local unknowns (6 per node:
    /// `Δx` global, `ΔΘ` material, conjugate to `(ẋ, Ω)`).
    pub fn rate(&self, state: &State) -> (f64, Vec<f64>) {
        let n = 6 * self.source.nodes.len();
        let mut grad = vec![0.0; n];
        with_scratch(|sc| {
            sc.local.gather(state, &self.source.nodes, 0..0);
            let mut v = [0.0];
            let f = self.source.function(self.reference(state));
            sc.local.gradient(1, &self.active, &f, &mut v, &mut grad);
        });
        let mut rate = 0.0;
        for (k, &node) in self.source.nodes.iter().enumerate() {
            for c in 0..6 {
                rate += grad[6 * k + c] * state.velocity[node][c];
            }
        }
        (rate, grad)
    }

    fn kind_of_equation(&self) -> Equation {
        if self.source.is_angle() {
            Equation::Moment
        } else {
            Equation::Force
        }
    }

    /// `(k, p)` of its equation.
    pub fn scaling(&self, ctx: &EvalContext) -> (f64, f64) {
        scale_of(&ctx.scaling, self.kind_of_equation())
    }
}

impl Element for Latch {
    fn kind(&self) -> ElementKind {
        ElementKind::Latch
    }
    fn id(&self) -> Id {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.source.nodes
    }
    fn n_multipliers(&self) -> usize {
        1
    }
    /// The unwrapped angle (angles only), then the lock flag.
    fn n_internal(&self) -> usize {
        usize::from(self.source.is_angle()) + 1
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.offsets = offsets;
    }
    fn multiplier_kind(&self, _k: usize) -> ConstraintKind {
        constraint_kind(self.kind_of_equation())
    }
    fn constraints_active(&self, _time: f64, state: &State) -> bool {
        self.is_locked(state)
    }
    fn as_latch(&self) -> Option<&Latch> {
        Some(self)
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let nq = 6 * self.source.nodes.len();
        if !self.is_locked(state) {
            // open: k λ = 0
            let k = self.scaling(ctx).0;
            out.residual[nq] += k * state.multipliers[self.offsets.multipliers];
            if let Some(t) = out.stiffness.as_deref_mut() {
                t[nq * (nq + 1) + nq] += k;
            }
            return;
        }
        // locked: Φ = c(q) − c_L
        let c = self.source.function(self.reference(state));
        let value = self.value;
        let phi = |conf: &Conf, o: &mut [HyperDual]| {
            c(conf, o);
            o[0] = o[0] + (-value);
        };
        let m = self.offsets.multipliers;
        let lambda = &state.multipliers[m..m + 1];
        with_scratch(|sc| {
            sc.local.gather(state, &self.source.nodes, 0..0);
            add_constraints(
                ctx,
                &mut sc.local,
                &mut sc.grad,
                &self.active,
                true,
                &[self.kind_of_equation()],
                &phi,
                lambda,
                out,
            );
        });
    }
    fn update_internal(&self, _ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        // the lock flag is set by the analysis that locks it
        if self.source.is_angle() {
            internal[0] = self.source.value(state, internal[0]);
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        &LATCH_RESULTS
    }
    /// Fills the first `out.len()` values of [`LATCH_RESULTS`].
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let c = self.coordinate(state);
        let locked = self.is_locked(state);
        let mut all = [c, 0.0, self.approach * (c - self.value), 0.0];
        if locked {
            let (k, p) = self.scaling(ctx);
            all[1] = 1.0;
            // generalised load along the coordinate: −(pΦ − kλ)
            all[3] = k * state.multipliers[self.offsets.multipliers] - p * (c - self.value);
        }
        let n = out.len().min(all.len());
        out[..n].copy_from_slice(&all[..n]);
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}
