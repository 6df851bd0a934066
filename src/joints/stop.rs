//! Unilateral stops: limits on a joint coordinate `c_min ≤ c ≤ c_max`
//! (the joint limits of the reference paper, eq. 16; docs/joints.md §6.3,
//! docs/theory.md §16.4).
//!
//! The gaps `g_min = c − c_min` and `g_max = c_max − c` are non-negative
//! while the stop is open. Open, a stop applies nothing: its one
//! multiplier equation is `k λ = 0`, as a latch's. A dynamic analysis
//! watches the gaps, lands a step on `g = 0` and applies an impact with
//! restitution `e` ([`crate::analysis::impact`]): the coordinate's rate is
//! reversed and scaled by `e`. When the rebound rate is too slow to leave
//! the event band (below `√(2 g_tol |c̈|)`, docs/theory.md §16.4) the
//! impact is made plastic and the stop closes: it is then the constraint
//! `Φ = c − c_c = 0` (`c_c` where it closed, within the event tolerance of
//! the limit) with its multiplier, whose load `N` (the contact
//! force or moment, positive pushing the coordinate back into its range)
//! is watched in turn; the stop opens again when `N` falls to zero.
//!
//! The state of a stop (open, closed at which limit) is kept in its
//! internal variables, with the number of its events (the parity of which
//! orients its event function, see [`Stop::watch_sign`]) and the largest
//! contact load it has carried (the scale of the release tolerance).

use super::coordinate::PairCoordinate;
use super::hyperdual::HyperDual;
use super::joint::{add_constraints, constraint_kind, scale_of};
use super::kinematics::{with_scratch, Conf};
use super::types::Equation;
use crate::elements::{
    CellShape, ConstraintKind, Element, ElementKind, ElementOutput, EvalContext, Offsets,
};
use crate::model::Id;
use crate::so3::Vec3;
use crate::state::State;

/// Names of stop results: the coordinate, the contact (`−1` closed at the
/// lower limit, `+1` at the upper, `0` open), the smallest gap, and the
/// contact load `N ≥ 0` (zero while open).
pub const STOP_RESULTS: [&str; 4] = ["coordinate", "contact", "gap", "load"];

/// Where a stop is in contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contact {
    /// Not in contact.
    Open,
    /// Closed at `c_min`.
    Lower,
    /// Closed at `c_max`.
    Upper,
}

impl Contact {
    /// `+1` at the lower limit (the load pushes `c` up), `−1` at the upper.
    pub fn side(self) -> f64 {
        match self {
            Self::Upper => -1.0,
            _ => 1.0,
        }
    }

    fn code(self) -> f64 {
        match self {
            Self::Open => 0.0,
            Self::Lower => 1.0,
            Self::Upper => 2.0,
        }
    }

    fn of_code(c: f64) -> Self {
        if c > 1.5 {
            Self::Upper
        } else if c > 0.5 {
            Self::Lower
        } else {
            Self::Open
        }
    }
}

/// A unilateral stop on a joint coordinate (see the module documentation).
#[derive(Clone, Debug)]
pub struct Stop {
    id: Id,
    /// The joint whose coordinate it limits.
    joint: Option<Id>,
    /// The joint coordinate (`None` for a contact with a plane).
    source: Option<PairCoordinate>,
    /// A contact of a node with a plane instead of a joint coordinate.
    plane: Option<Plane>,
    nodes: Vec<usize>,
    /// `c_min`, `c_max` (`±∞` when absent).
    lower: f64,
    upper: f64,
    /// Coefficient of restitution `e ∈ [0, 1]`.
    restitution: f64,
    active: Vec<usize>,
    offsets: Offsets,
}

/// A sphere of radius `r` centred on a node against a fixed plane through
/// `p` with unit normal `n`: the "coordinate" of the stop is the gap
/// `g = n·(x − p) − r` (reference paper, eq. 16), limited below by 0.
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    /// The node.
    pub node: usize,
    /// `n`, unit.
    pub normal: Vec3,
    /// `p`.
    pub point: Vec3,
    /// `r ≥ 0`.
    pub radius: f64,
}

/// Internal variables after the unwrapped angle (angles only).
const CONTACT: usize = 0;
const EVENTS: usize = 1;
const LOAD_SCALE: usize = 2;
const CLOSED_AT: usize = 3;

impl Stop {
    /// Limits `source`, a coordinate of joint `joint`, to
    /// `lower ≤ c ≤ upper` (either may be infinite), with restitution
    /// `restitution`.
    pub fn new(
        id: Id,
        joint: Id,
        source: PairCoordinate,
        lower: f64,
        upper: f64,
        restitution: f64,
    ) -> Self {
        let active = source.active();
        let nodes = source.nodes.clone();
        Self {
            id,
            joint: Some(joint),
            source: Some(source),
            plane: None,
            nodes,
            lower,
            upper,
            restitution,
            active,
            offsets: Offsets::default(),
        }
    }

    /// A contact between a sphere on a node and a fixed plane
    /// (`plane.normal` unit), with restitution `restitution`: the stop of
    /// the gap `g = n·(x − p) − r ≥ 0`.
    pub fn on_plane(id: Id, plane: Plane, restitution: f64) -> Self {
        Self {
            id,
            joint: None,
            source: None,
            plane: Some(plane),
            nodes: vec![plane.node],
            lower: 0.0,
            upper: f64::INFINITY,
            restitution,
            active: vec![0, 1, 2],
            offsets: Offsets::default(),
        }
    }

    /// The joint whose coordinate it limits (`None` for a contact with a
    /// plane).
    pub fn joint(&self) -> Option<Id> {
        self.joint
    }

    /// `(c_min, c_max)`.
    pub fn limits(&self) -> (f64, f64) {
        (self.lower, self.upper)
    }

    /// The coefficient of restitution `e`.
    pub fn restitution(&self) -> f64 {
        self.restitution
    }

    /// Whether the coordinate is an angle.
    pub fn is_angle(&self) -> bool {
        self.source.as_ref().is_some_and(PairCoordinate::is_angle)
    }

    /// The nodes of its pair.
    pub fn pair_nodes(&self) -> &[usize] {
        &self.nodes
    }

    /// The joint coordinate of a stop on one.
    fn src(&self) -> &PairCoordinate {
        self.source
            .as_ref()
            .expect("a stop without a plane is on a joint coordinate")
    }

    fn slot(&self, k: usize) -> usize {
        self.offsets.internal + usize::from(self.is_angle()) + k
    }

    /// Index of its multiplier among the state's multipliers.
    pub fn multiplier(&self) -> usize {
        self.offsets.multipliers
    }

    /// Its contact in `state`.
    pub fn contact(&self, state: &State) -> Contact {
        state
            .internal
            .get(self.slot(CONTACT))
            .map_or(Contact::Open, |&c| Contact::of_code(c))
    }

    /// Sets its contact in `state` and counts the event. A stop that
    /// closes holds the coordinate where it is, within the event tolerance
    /// of its limit (see [`Self::held_value`]).
    pub fn set_contact(&self, state: &mut State, contact: Contact) {
        let c = self.coordinate(state);
        state.internal[self.slot(CLOSED_AT)] = if contact == Contact::Open { 0.0 } else { c };
        state.internal[self.slot(CONTACT)] = contact.code();
        let events = self.slot(EVENTS);
        state.internal[events] = if state.internal[events] > 0.5 {
            0.0
        } else {
            1.0
        };
        state.internal[self.slot(LOAD_SCALE)] = 0.0;
    }

    /// Opens it in `state` without counting an event (the impact that
    /// closed it for its velocity jump was the event).
    pub fn reopen(&self, state: &mut State) {
        state.internal[self.slot(CONTACT)] = Contact::Open.code();
        state.internal[self.slot(LOAD_SCALE)] = 0.0;
    }

    /// `(−1)ⁿ`, `n` the number of its events so far: the sign of its event
    /// function, so that each event leaves the function on the other side
    /// of zero from where it came (as the step controller expects of a
    /// crossing it has landed on).
    pub fn watch_sign(&self, state: &State) -> f64 {
        if state
            .internal
            .get(self.slot(EVENTS))
            .is_some_and(|&n| n > 0.5)
        {
            -1.0
        } else {
            1.0
        }
    }

    /// The largest contact load carried since it closed (0 until a step
    /// in contact has been accepted).
    pub fn load_scale(&self, state: &State) -> f64 {
        state
            .internal
            .get(self.slot(LOAD_SCALE))
            .copied()
            .unwrap_or(0.0)
    }

    fn reference(&self, state: &State) -> f64 {
        if self.is_angle() {
            state.internal[self.offsets.internal]
        } else {
            0.0
        }
    }

    /// The coordinate `c` at `state` (an angle on the branch of the last
    /// converged state).
    pub fn coordinate(&self, state: &State) -> f64 {
        match &self.plane {
            Some(p) => p.normal.dot(&(state.x[p.node] - p.point)) - p.radius,
            None => self.src().value(state, self.reference(state)),
        }
    }

    /// The smaller gap, `min(c − c_min, c_max − c)`, and the limit it is
    /// to (`Lower` or `Upper`).
    pub fn gap(&self, state: &State) -> (f64, Contact) {
        let c = self.coordinate(state);
        let (lo, up) = (c - self.lower, self.upper - c);
        if lo <= up {
            (lo, Contact::Lower)
        } else {
            (up, Contact::Upper)
        }
    }

    /// The value `c_c` a closed stop holds the coordinate at: where the
    /// step that closed it landed, within the event tolerance of the limit
    /// (holding the limit itself would pull the coordinate across the
    /// remaining gap within the next step, with a load of the order of
    /// `m g_tol/h²` that may open the contact again).
    pub fn held_value(&self, state: &State) -> f64 {
        state.internal[self.slot(CLOSED_AT)]
    }

    /// The value of the limit of `contact`.
    pub fn limit(&self, contact: Contact) -> f64 {
        match contact {
            Contact::Upper => self.upper,
            _ => self.lower,
        }
    }

    /// `N`: the contact load (moment or force along the coordinate,
    /// positive pushing it back into its range) while closed, 0 open.
    pub fn load(&self, ctx: &EvalContext, state: &State) -> f64 {
        let contact = self.contact(state);
        if contact == Contact::Open {
            return 0.0;
        }
        let (k, p) = self.scaling(ctx);
        let phi = self.coordinate(state) - self.held_value(state);
        // generalised load along the coordinate: −(pΦ − kλ)
        contact.side() * (k * state.multipliers[self.offsets.multipliers] - p * phi)
    }

    /// `ċ = B v`: the rate of the coordinate at the state's velocities,
    /// and its gradient `B` over the pair's local unknowns (6 per node).
    pub fn rate(&self, state: &State) -> (f64, Vec<f64>) {
        if let Some(p) = &self.plane {
            // B = [nᵀ 0]: ġ = n·ẋ
            let v = state.velocity[p.node];
            let grad = vec![p.normal.x, p.normal.y, p.normal.z, 0.0, 0.0, 0.0];
            return (p.normal.dot(&Vec3::new(v[0], v[1], v[2])), grad);
        }
        let n = 6 * self.src().nodes.len();
        let mut grad = vec![0.0; n];
        with_scratch(|sc| {
            sc.local.gather(state, &self.src().nodes, 0..0);
            let mut v = [0.0];
            let f = self.src().function(self.reference(state));
            sc.local.gradient(1, &self.active, &f, &mut v, &mut grad);
        });
        let mut rate = 0.0;
        for (k, &node) in self.src().nodes.iter().enumerate() {
            for c in 0..6 {
                rate += grad[6 * k + c] * state.velocity[node][c];
            }
        }
        (rate, grad)
    }

    fn kind_of_equation(&self) -> Equation {
        if self.is_angle() {
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

impl Element for Stop {
    fn kind(&self) -> ElementKind {
        ElementKind::Stop
    }
    fn id(&self) -> Id {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.nodes
    }
    fn n_multipliers(&self) -> usize {
        1
    }
    /// The unwrapped angle (angles only), the contact, the parity of the
    /// number of events, the largest load carried, the coordinate where
    /// it closed.
    fn n_internal(&self) -> usize {
        usize::from(self.is_angle()) + 4
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.offsets = offsets;
    }
    fn multiplier_kind(&self, _k: usize) -> ConstraintKind {
        constraint_kind(self.kind_of_equation())
    }
    fn constraints_active(&self, _time: f64, state: &State) -> bool {
        self.contact(state) != Contact::Open
    }
    fn as_stop(&self) -> Option<&Stop> {
        Some(self)
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let nq = 6 * self.nodes.len();
        let contact = self.contact(state);
        if contact == Contact::Open {
            // open: k λ = 0
            let k = self.scaling(ctx).0;
            out.residual[nq] += k * state.multipliers[self.offsets.multipliers];
            if let Some(t) = out.stiffness.as_deref_mut() {
                t[nq * (nq + 1) + nq] += k;
            }
            return;
        }
        if let Some(p) = &self.plane {
            // closed: Φ = n·(x − p) − r − g_c, linear in x: residual
            // nᵀ(pΦ − kλ) on x, −kΦ on the multiplier row; tangent
            // p n nᵀ, −k n (no curvature term)
            let (k, pen) = self.scaling(ctx);
            let phi = self.coordinate(state) - self.held_value(state);
            let lambda = state.multipliers[self.offsets.multipliers];
            let n = [p.normal.x, p.normal.y, p.normal.z];
            let w = pen * phi - k * lambda;
            for (c, nc) in n.iter().enumerate() {
                out.residual[c] += nc * w;
            }
            out.residual[nq] += -k * phi;
            if let Some(t) = out.stiffness.as_deref_mut() {
                let size = nq + 1;
                for (c, nc) in n.iter().enumerate() {
                    t[nq * size + c] += -k * nc;
                    t[c * size + nq] += -k * nc;
                    for (r, nr) in n.iter().enumerate() {
                        t[c * size + r] += pen * nc * nr;
                    }
                }
            }
            return;
        }
        // closed: Φ = c(q) − c_c
        let c = self.src().function(self.reference(state));
        let value = self.held_value(state);
        let phi = |conf: &Conf, o: &mut [HyperDual]| {
            c(conf, o);
            o[0] = o[0] + (-value);
        };
        let m = self.offsets.multipliers;
        let lambda = &state.multipliers[m..m + 1];
        with_scratch(|sc| {
            sc.local.gather(state, &self.src().nodes, 0..0);
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
    fn update_internal(&self, ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        // the contact and the events are set by the analysis
        let first = usize::from(self.is_angle());
        if self.is_angle() {
            internal[0] = self.src().value(state, internal[0]);
        }
        if self.contact(state) != Contact::Open {
            let n = self.load(ctx, state).abs();
            internal[first + LOAD_SCALE] = internal[first + LOAD_SCALE].max(n);
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        &STOP_RESULTS
    }
    /// Fills the first `out.len()` values of [`STOP_RESULTS`].
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let contact = match self.contact(state) {
            Contact::Open => 0.0,
            Contact::Lower => -1.0,
            Contact::Upper => 1.0,
        };
        let all = [
            self.coordinate(state),
            contact,
            self.gap(state).0,
            self.load(ctx, state),
        ];
        let n = out.len().min(all.len());
        out[..n].copy_from_slice(&all[..n]);
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}
