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
//!
//! A spring latch (`mode = "spring"`, [`SpringLatch`]) locks without an
//! impact: once latched it applies the generalised force of a stiff spring
//! about `c_L` with a dead band of total width `b` (backlash) and an
//! optional dashpot, `f = f_s(x) + d ċ` with `x = c − c_L` and
//!
//! ```text
//! f_s = k (x − b/2) for x > b/2,   0 for |x| ≤ b/2,   k (x + b/2) for x < −b/2,
//! ```
//!
//! added to the residual as `f ∂c/∂q` (the sign of joint springs,
//! docs/joints.md §4: a positive `f` pushes `c` down). The law is that of
//! the current coordinate, with the tangent of the branch it is on; the
//! branch kept in the internal variables only tells the analysis which
//! event to watch next (a band edge, the unlatch load): the analysis lands
//! steps on the edges of the band, where the law has its corners, and on
//! the load `|f|` reaching `unlatch_load`, where the latch releases.

use super::coordinate::PairCoordinate;
use super::joint::{add_first_order, constraint_kind, scale_of, ALL_DOFS};
use super::kinematics::with_scratch;
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

/// A latched spring latch releases when its load reaches its unlatch load
/// within this fraction of it (the tolerance of the unlatch event).
pub const UNLATCH_TOLERANCE: f64 = 1e-6;

/// The watched quantity of a spring latch that has no event to come (no
/// dead band and no unlatch load): far from the events' band `|w| ≤ 1`.
const NOTHING_TO_WATCH: f64 = 1e12;

/// Names of latch results: the coordinate, the lock flag (0 or 1), the
/// event function `g = s (c − c_L)`, the load holding the lock (moment
/// or force along the coordinate, positive pushing it up, zero while
/// open) and, for a spring latch, the side of its dead band where its
/// spring is engaged (`1` above, `−1` below, `0` within the band, open,
/// or a rigid latch).
pub const LATCH_RESULTS: [&str; 5] = ["coordinate", "locked", "gap", "load", "contact"];

/// The compliant lock of a spring latch (see the module documentation):
/// all in the units of the coordinate (rad or m) and of its generalised
/// force (N·m or N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringLatch {
    /// `k > 0` (N·m/rad or N/m).
    pub stiffness: f64,
    /// `b ≥ 0`: the total width of the dead band about `c_L`.
    pub backlash: f64,
    /// `d ≥ 0` (N·m·s/rad or N·s/m): the dashpot acting while latched.
    pub damping: f64,
    /// `F_u > 0`: the load `|f|` at which the latch releases (none: never).
    pub unlatch_load: Option<f64>,
    /// The sign of `x = c − c_L` on which the spring acts (a one-sided
    /// latch: free on the other side of `c_L`); `None`: both.
    pub side: Option<f64>,
}

impl SpringLatch {
    /// `(f_s, ∂f_s/∂c)` at `x = c − c_L`: zero within the dead band, the
    /// slope of the branch it is on (`k` outside, 0 inside, 0 on an edge).
    pub fn spring_force(&self, x: f64) -> (f64, f64) {
        let h = 0.5 * self.backlash;
        if !self.acts_at(x) {
            (0.0, 0.0)
        } else if x > h {
            (self.stiffness * (x - h), self.stiffness)
        } else if x < -h {
            (self.stiffness * (x + h), self.stiffness)
        } else {
            (0.0, 0.0)
        }
    }

    /// Whether the spring acts at `x` (on its side of `c_L`, if one-sided).
    pub fn acts_at(&self, x: f64) -> bool {
        self.side.is_none_or(|s| s * x > 0.0)
    }

    /// The dashpot's coefficient at `x`: `d` where the spring acts (or
    /// within the band of a two-sided latch), 0 on the free side of a
    /// one-sided one.
    pub fn dashpot(&self, x: f64) -> f64 {
        if self.acts_at(x) {
            self.damping
        } else {
            0.0
        }
    }

    /// `½ k (|x| − b/2)²` outside the band (on the spring's side), 0
    /// inside.
    pub fn energy(&self, x: f64) -> f64 {
        if !self.acts_at(x) {
            return 0.0;
        }
        let over = (x.abs() - 0.5 * self.backlash).max(0.0);
        0.5 * self.stiffness * over * over
    }
}

/// What happened to a spring latch at an event ([`Latch::spring_transition`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringEvent {
    /// The coordinate reached `c_L` from the side of approach: latched.
    Lock,
    /// The load reached the unlatch load: released.
    Unlatch,
    /// The coordinate of a released latch came back to `c_L` from beyond
    /// it: it may lock again the next time it reaches it.
    Rearm,
    /// The coordinate left the dead band across an edge beyond which the
    /// spring acts: the spring engages.
    Engage,
    /// The coordinate came back into the dead band from beyond an edge
    /// where the spring acted: the spring disengages.
    Disengage,
    /// An edge of the dead band where nothing changes: the coordinate
    /// grazes the edge and turns back, or crosses an edge on the free side
    /// of a one-sided latch.
    Band,
}

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
    /// Where its multiplier and internal variables are in the state.
    offsets: Offsets,
    /// The compliant lock; `None`: rigid.
    spring: Option<SpringLatch>,
}

impl Latch {
    /// Locks `source`, a coordinate of joint `joint`, at `value`, reached
    /// with the coordinate increasing (`approach > 0`) or decreasing.
    pub fn new(id: Id, joint: Id, source: PairCoordinate, value: f64, approach: f64) -> Self {
        Self {
            id,
            joint,
            source,
            value,
            approach: if approach < 0.0 { -1.0 } else { 1.0 },
            offsets: Offsets::default(),
            spring: None,
        }
    }

    /// The latch with a compliant lock instead of a rigid one.
    pub fn with_spring(mut self, spring: SpringLatch) -> Self {
        self.spring = Some(spring);
        self
    }

    /// Its compliant lock, if it is a spring latch.
    pub fn spring(&self) -> Option<&SpringLatch> {
        self.spring.as_ref()
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

    /// Locks it in `state` (sets the lock flag; a spring latch starts
    /// within its dead band).
    pub fn lock(&self, state: &mut State) {
        let slot = self.lock_slot();
        state.internal[slot] = 1.0;
        if self.spring.is_some() {
            state.internal[slot + SIDE] = 0.0;
        }
    }

    /// A spring latch's side: latched, the branch of its law it was last
    /// found on (`±1` outside the dead band, 0 within it); released, 1 if
    /// it was released beyond `c_L` (it must come back before it can lock
    /// again), 0 otherwise.
    fn side(&self, state: &State) -> f64 {
        state.internal[self.lock_slot() + SIDE]
    }

    /// `(−1)ⁿ`, `n` the number of a spring latch's events so far: the sign
    /// of its event function, so that each event leaves the function on
    /// the other side of zero from where it came (as for stops).
    pub fn watch_sign(&self, state: &State) -> f64 {
        if self.spring.is_some()
            && state
                .internal
                .get(self.lock_slot() + PARITY)
                .is_some_and(|&n| n > 0.5)
        {
            -1.0
        } else {
            1.0
        }
    }

    /// `x = c − c_L`, `ċ` and the generalised force `f = f_s(x) + d ċ` of
    /// a latched spring latch (0 released or rigid), positive pushing `c`
    /// down.
    pub fn spring_state(&self, state: &State) -> (f64, f64, f64) {
        let x = self.coordinate(state) - self.value;
        match self.spring {
            Some(s) if self.is_locked(state) => {
                let rate = self.rate(state).0;
                (x, rate, s.spring_force(x).0 + s.dashpot(x) * rate)
            }
            _ => (x, 0.0, 0.0),
        }
    }

    /// The watched quantity `w` of a spring latch (docs/joints.md §6.2),
    /// positive while nothing happens and reaching 0 at its next event;
    /// `tol` the event tolerance of the coordinate. Released: `−g/tol`
    /// (or `g/tol` beyond `c_L` after a release there); latched: the
    /// distance to the next edge of the dead band over `tol`, or the
    /// margin to the unlatch load over its tolerance, whichever is less.
    pub fn watch(&self, state: &State, tol: f64) -> f64 {
        let Some(s) = self.spring else {
            return NOTHING_TO_WATCH;
        };
        if !self.is_locked(state) {
            let g = self.gap(state);
            return if self.side(state) > 0.5 {
                g / tol
            } else {
                -g / tol
            };
        }
        let (x, _, f) = self.spring_state(state);
        let h = 0.5 * s.backlash;
        let band = if s.backlash > 0.0 || s.side.is_some() {
            let side = self.side(state);
            if side == 0.0 {
                (h - x.abs()) / tol
            } else {
                (side * x - h) / tol
            }
        } else {
            NOTHING_TO_WATCH
        };
        let unlatch = s.unlatch_load.map_or(NOTHING_TO_WATCH, |fu| {
            (fu - f.abs()) / (UNLATCH_TOLERANCE * fu)
        });
        band.min(unlatch)
    }

    /// Changes the state of a spring latch whose watched quantity has
    /// reached its event ([`Self::watch`] at most 1): latches a released
    /// latch at `c_L`, releases a latched one whose load has reached the
    /// unlatch load, or follows the coordinate across an edge of the dead
    /// band (the branch from the direction of the motion: a coordinate at
    /// an edge that turns back stays on its branch). The caller flips the
    /// sign of the event function ([`Self::flip_watch_sign`]). `None` for a
    /// rigid latch.
    pub fn spring_transition(&self, state: &mut State) -> Option<SpringEvent> {
        let s = self.spring?;
        let slot = self.lock_slot();
        let event = if !self.is_locked(state) {
            if self.side(state) > 0.5 {
                state.internal[slot + SIDE] = 0.0;
                SpringEvent::Rearm
            } else {
                self.lock(state);
                SpringEvent::Lock
            }
        } else {
            let (x, rate, f) = self.spring_state(state);
            // the load at its unlatch load releases the latch, whatever
            // the band (both may land on one step)
            if s.unlatch_load
                .is_some_and(|fu| (fu - f.abs()) / (UNLATCH_TOLERANCE * fu) <= 1.0)
            {
                state.internal[slot] = 0.0;
                state.internal[slot + SIDE] = if self.gap(state) > 0.0 { 1.0 } else { 0.0 };
                SpringEvent::Unlatch
            } else {
                let side = self.side(state);
                let next = if side == 0.0 {
                    // the edge reached; without a dead band both edges are
                    // at c_L, where the sign of x is round-off (a landing
                    // within the event tolerance): the motion leaves by the
                    // side it moves to
                    let out = match (s.backlash > 0.0, x >= 0.0, rate >= 0.0) {
                        (true, true, _) | (false, _, true) => 1.0,
                        _ => -1.0,
                    };
                    if out * rate > 0.0 {
                        out
                    } else {
                        side
                    }
                } else if side * rate < 0.0 {
                    // back across the edge: into the band, or, without a
                    // dead band (both edges at c_L, a band of no width
                    // whose event function would touch zero without
                    // crossing it), straight to the other side
                    if s.backlash > 0.0 {
                        0.0
                    } else {
                        -side
                    }
                } else {
                    side
                };
                state.internal[slot + SIDE] = next;
                // the side's sign stands for x: whether the spring acts there
                let acts = |side: f64| side != 0.0 && s.acts_at(side);
                if next != side && acts(next) && !acts(side) {
                    SpringEvent::Engage
                } else if next != side && acts(side) && !acts(next) {
                    SpringEvent::Disengage
                } else {
                    SpringEvent::Band
                }
            }
        };
        Some(event)
    }

    /// Counts an event of a spring latch: flips the sign of its event
    /// function ([`Self::watch_sign`]).
    pub fn flip_watch_sign(&self, state: &mut State) {
        if self.spring.is_some() {
            let parity = &mut state.internal[self.lock_slot() + PARITY];
            *parity = if *parity > 0.5 { 0.0 } else { 1.0 };
        }
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

    /// `ġ = s ċ`, the rate of [`Self::gap`].
    pub fn gap_rate(&self, state: &State) -> f64 {
        self.approach * self.rate(state).0
    }

    /// `ċ = B v`: the rate of the coordinate at the state's velocities,
    /// and its gradient `B` over the pair's local unknowns (6 per node:
    /// `Δx` global, `ΔΘ` material, conjugate to `(ẋ, Ω)`).
    pub fn rate(&self, state: &State) -> (f64, Vec<f64>) {
        let n = 6 * self.source.nodes.len();
        let mut grad = vec![0.0; n];
        with_scratch(|sc| {
            sc.local.gather(state, &self.source.nodes, 0..0);
            self.source
                .derivatives(&mut sc.local, self.reference(state), &mut grad, None);
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

/// Internal variables of a spring latch after the lock flag.
const SIDE: usize = 1;
const PARITY: usize = 2;

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
    /// One for a rigid latch, none for a spring latch.
    fn n_multipliers(&self) -> usize {
        usize::from(self.spring.is_none())
    }
    /// The unwrapped angle (angles only), then the lock flag; a spring
    /// latch adds its side and the parity of the number of its events.
    fn n_internal(&self) -> usize {
        usize::from(self.source.is_angle()) + if self.spring.is_some() { 3 } else { 1 }
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
        if let Some(s) = &self.spring {
            if self.is_locked(state) {
                self.evaluate_spring(s, ctx, state, out);
            }
            return;
        }
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
        let m = self.offsets.multipliers;
        let lambda = &state.multipliers[m..m + 1];
        with_scratch(|sc| {
            let c = self.source.evaluate_into(
                sc,
                state,
                self.reference(state),
                out.stiffness.is_some(),
            );
            debug_assert_eq!(sc.local.n(), nq);
            let (g, h) = (&sc.grad, &sc.hess);
            let kinds = [self.kind_of_equation()];
            let w = add_first_order(
                ctx,
                nq,
                &ALL_DOFS[..nq],
                &kinds,
                &[c - self.value],
                g,
                lambda,
                out,
            );
            if let Some(t) = out.stiffness.as_deref_mut() {
                // w ∂²Φ/∂q², the second-derivative term of add_constraints
                for col in 0..nq {
                    for row in 0..nq {
                        t[col * (nq + 1) + row] += w[0] * h[col * nq + row];
                    }
                }
            }
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
        let mut all = [c, 0.0, self.approach * (c - self.value), 0.0, 0.0];
        if let (Some(s), true) = (&self.spring, locked) {
            let (x, _, f) = self.spring_state(state);
            all[1] = 1.0;
            all[3] = -f;
            let h = 0.5 * s.backlash;
            all[4] = if !s.acts_at(x) {
                0.0
            } else if x > h {
                1.0
            } else if x < -h {
                -1.0
            } else {
                0.0
            };
        } else if locked {
            let (k, p) = self.scaling(ctx);
            all[1] = 1.0;
            // generalised load along the coordinate: −(pΦ − kλ)
            all[3] = k * state.multipliers[self.offsets.multipliers] - p * (c - self.value);
        }
        let n = out.len().min(all.len());
        out[..n].copy_from_slice(&all[..n]);
    }
    /// `½ k (|x| − b/2)²` of a latched spring latch.
    fn strain_energy(&self, _ctx: &EvalContext, state: &State) -> f64 {
        match &self.spring {
            Some(s) if self.is_locked(state) => s.energy(self.coordinate(state) - self.value),
            _ => 0.0,
        }
    }
    /// `d ċ²`: the power the dashpot of a latched spring latch takes out.
    fn dissipated_power(&self, _ctx: &EvalContext, state: &State) -> f64 {
        match &self.spring {
            Some(s) if self.is_locked(state) && s.damping > 0.0 => {
                let rate = self.rate(state).0;
                s.dashpot(self.coordinate(state) - self.value) * rate * rate
            }
            _ => 0.0,
        }
    }
    /// The force `d ċ g` of the dashpot of a latched spring latch.
    fn nonconservative_forces(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        match &self.spring {
            Some(s) if ctx.dynamics && self.is_locked(state) && s.damping > 0.0 => {
                crate::elements::damper_share(self, ctx, state, out)
            }
            _ => {}
        }
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}

impl Latch {
    /// A latched spring latch: the residual `f g`, `f = f_s(x) + d ċ`,
    /// `g = ∂c/∂q`; the stiffness `f_s' g gᵀ + f ∂g/∂q + d g (∂ċ/∂q)ᵀ`
    /// (`∂ċ/∂q = (∂g/∂q) v` at fixed velocities) and the damping matrix
    /// `∂r/∂v = d g gᵀ`, as a joint spring's (docs/joints.md §4). The
    /// dashpot acts in dynamic evaluations only.
    fn evaluate_spring(
        &self,
        s: &SpringLatch,
        ctx: &EvalContext,
        state: &State,
        out: &mut ElementOutput,
    ) {
        with_scratch(|sc| {
            // g = ∂c/∂q; H = ∂g/∂q when the stiffness is asked for
            let c = [self.source.evaluate_into(
                sc,
                state,
                self.reference(state),
                out.stiffness.is_some(),
            )];
            let (n, g, h, v) = (sc.local.n(), &sc.grad, &sc.hess, &mut sc.vel);
            v.clear();
            for &node in &self.source.nodes {
                v.extend_from_slice(&state.velocity[node]);
            }
            let rate: f64 = g.iter().zip(v.iter()).map(|(a, b)| a * b).sum();
            let (fs, ks) = s.spring_force(c[0] - self.value);
            let d = if ctx.dynamics {
                s.dashpot(c[0] - self.value)
            } else {
                0.0
            };
            let total = fs + d * rate;
            for r in 0..n {
                out.residual[r] += total * g[r];
            }
            if let (Some(w), Some(m)) = (ctx.need.inertia, out.inertia.as_deref_mut()) {
                // ∂r/∂v = d g gᵀ
                let cd = w.damping * d;
                if cd != 0.0 {
                    for col in 0..n {
                        for r in 0..n {
                            m[col * n + r] += cd * g[r] * g[col];
                        }
                    }
                }
            }
            let Some(stiffness) = out.stiffness.as_deref_mut() else {
                return;
            };
            for col in 0..n {
                // ∂ċ/∂q_col at fixed v: Σ_r v_r H[r, col]
                let dc = if d != 0.0 {
                    (0..n).map(|r| v[r] * h[col * n + r]).sum::<f64>()
                } else {
                    0.0
                };
                for r in 0..n {
                    stiffness[col * n + r] +=
                        ks * g[r] * g[col] + total * h[col * n + r] + d * g[r] * dc;
                }
            }
        });
    }
}
