//! Unilateral stops: limits on a joint coordinate `c_min ≤ c ≤ c_max`
//! (the joint limits of the reference paper, eq. 16; docs/joints.md §6.3,
//! docs/theory.md §16.4), and unilateral contacts, whose "coordinate" is
//! the gap of a sphere on a node against a fixed plane or of two spheres
//! on two nodes, limited below by 0 (docs/joints.md §6.4, docs/theory.md
//! §16.5).
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
use crate::so3::{Mat3, Vec3};
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

/// Names of contact results: the gap `g`, `1` closed (`0` open), and the
/// normal contact force `N ≥ 0` (zero while open).
pub const CONTACT_RESULTS: [&str; 3] = ["gap", "closed", "force"];

/// What a stop watches.
#[derive(Clone, Debug)]
enum Watched {
    /// A coordinate of joint `joint`.
    Joint {
        joint: Id,
        source: Box<PairCoordinate>,
    },
    /// The gap of a sphere against a fixed plane.
    Plane(Plane),
    /// The gap between two spheres.
    Spheres(Spheres),
}

/// A unilateral stop on a joint coordinate, or a unilateral contact (see
/// the module documentation).
#[derive(Clone, Debug)]
pub struct Stop {
    id: Id,
    watched: Watched,
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
/// `p` with unit normal `n` (pointing to the sphere's side): the
/// "coordinate" of the contact is the gap `g = n·(x − p) − r` (reference
/// paper, eq. 16), limited below by 0.
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

impl Plane {
    /// `g = n·(x − p) − r` with the node at `x`.
    pub fn gap(&self, x: &Vec3) -> f64 {
        self.normal.dot(&(x - self.point)) - self.radius
    }
}

/// Two spheres of radii `r_a`, `r_b` centred on nodes `a` and `b`: the
/// "coordinate" of the contact is the gap `g = |x_b − x_a| − r_a − r_b`
/// (reference paper, eq. 16), limited below by 0.
#[derive(Clone, Copy, Debug)]
pub struct Spheres {
    /// The nodes `a`, `b` (distinct).
    pub nodes: [usize; 2],
    /// `r_a`, `r_b ≥ 0`.
    pub radii: [f64; 2],
}

impl Spheres {
    /// `g = |x_b − x_a| − r_a − r_b`.
    pub fn gap(&self, xa: &Vec3, xb: &Vec3) -> f64 {
        (xb - xa).norm() - self.radii[0] - self.radii[1]
    }

    /// `d = |x_b − x_a|` and `u = (x_b − x_a)/d` (zero when the centres
    /// coincide, where the direction is not defined).
    fn direction(state: &State, nodes: [usize; 2]) -> (f64, Vec3) {
        let r = state.x[nodes[1]] - state.x[nodes[0]];
        let d = r.norm();
        if d > 0.0 {
            (d, r / d)
        } else {
            (0.0, Vec3::zeros())
        }
    }
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
            watched: Watched::Joint {
                joint,
                source: Box::new(source),
            },
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
            watched: Watched::Plane(plane),
            nodes: vec![plane.node],
            lower: 0.0,
            upper: f64::INFINITY,
            restitution,
            active: vec![0, 1, 2],
            offsets: Offsets::default(),
        }
    }

    /// A contact between two spheres on two distinct nodes, with
    /// restitution `restitution`: the stop of the gap
    /// `g = |x_b − x_a| − r_a − r_b ≥ 0`.
    pub fn between_spheres(id: Id, spheres: Spheres, restitution: f64) -> Self {
        Self {
            id,
            watched: Watched::Spheres(spheres),
            nodes: spheres.nodes.to_vec(),
            lower: 0.0,
            upper: f64::INFINITY,
            restitution,
            active: vec![0, 1, 2, 6, 7, 8],
            offsets: Offsets::default(),
        }
    }

    /// The joint whose coordinate it limits (`None` for a contact).
    pub fn joint(&self) -> Option<Id> {
        match &self.watched {
            Watched::Joint { joint, .. } => Some(*joint),
            _ => None,
        }
    }

    /// Whether it is a contact (of a sphere with a plane or of two
    /// spheres) rather than a stop on a joint coordinate.
    pub fn is_contact(&self) -> bool {
        self.joint().is_none()
    }

    /// `"stop"` or `"contact"`, for messages.
    pub fn noun(&self) -> &'static str {
        if self.is_contact() {
            "contact"
        } else {
            "stop"
        }
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
        match &self.watched {
            Watched::Joint { source, .. } => source.is_angle(),
            _ => false,
        }
    }

    /// The nodes of its pair.
    pub fn pair_nodes(&self) -> &[usize] {
        &self.nodes
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
        match &self.watched {
            Watched::Joint { source, .. } => source.value(state, self.reference(state)),
            Watched::Plane(p) => p.gap(&state.x[p.node]),
            Watched::Spheres(s) => s.gap(&state.x[s.nodes[0]], &state.x[s.nodes[1]]),
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
        let source = match &self.watched {
            Watched::Plane(p) => {
                // B = [nᵀ 0]: ġ = n·ẋ
                let v = state.velocity[p.node];
                let n = p.normal;
                let grad = vec![n.x, n.y, n.z, 0.0, 0.0, 0.0];
                return (n.dot(&Vec3::new(v[0], v[1], v[2])), grad);
            }
            Watched::Spheres(s) => {
                // B = [−uᵀ 0 uᵀ 0]: ġ = u·(ẋ_b − ẋ_a)
                let (_, u) = Spheres::direction(state, s.nodes);
                let mut grad = vec![0.0; 12];
                let mut rate = 0.0;
                for c in 0..3 {
                    grad[c] = -u[c];
                    grad[6 + c] = u[c];
                    rate += u[c] * (state.velocity[s.nodes[1]][c] - state.velocity[s.nodes[0]][c]);
                }
                return (rate, grad);
            }
            Watched::Joint { source, .. } => source,
        };
        let n = 6 * source.nodes.len();
        let mut grad = vec![0.0; n];
        with_scratch(|sc| {
            sc.local.gather(state, &source.nodes, 0..0);
            let mut v = [0.0];
            let f = source.function(self.reference(state));
            sc.local.gradient(1, &self.active, &f, &mut v, &mut grad);
        });
        let mut rate = 0.0;
        for (k, &node) in source.nodes.iter().enumerate() {
            for c in 0..6 {
                rate += grad[6 * k + c] * state.velocity[node][c];
            }
        }
        (rate, grad)
    }

    /// Adds the closed gap constraint `Φ = g(x) − g_c` of a contact, with
    /// its gradient `B` given by blocks `(first local unknown, ∂g/∂x)` on
    /// the nodes' translations and its curvature `H` (`∂²g/∂x²`, the same
    /// block on each node, `−H` between them): the residual `Bᵀ(pΦ − kλ)`
    /// and `−kΦ` on the multiplier row, the tangent `p BᵀB + (pΦ − kλ) H`
    /// and `−kB` (the augmented Lagrangian of the reference paper, eq. 18).
    fn add_gap_constraint(
        &self,
        ctx: &EvalContext,
        state: &State,
        gradient: &[(usize, Vec3)],
        curvature: Option<Mat3>,
        out: &mut ElementOutput,
    ) {
        let nq = 6 * self.nodes.len();
        let (k, pen) = self.scaling(ctx);
        let phi = self.coordinate(state) - self.held_value(state);
        let lambda = state.multipliers[self.offsets.multipliers];
        let w = pen * phi - k * lambda;
        for &(i, b) in gradient {
            for c in 0..3 {
                out.residual[i + c] += b[c] * w;
            }
        }
        out.residual[nq] += -k * phi;
        let Some(t) = out.stiffness.as_deref_mut() else {
            return;
        };
        let size = nq + 1;
        for (a, &(i, bi)) in gradient.iter().enumerate() {
            for r in 0..3 {
                t[(i + r) * size + nq] += -k * bi[r];
                t[nq * size + i + r] += -k * bi[r];
            }
            for (b, &(j, bj)) in gradient.iter().enumerate() {
                let sign = if a == b { 1.0 } else { -1.0 };
                for r in 0..3 {
                    for c in 0..3 {
                        let h = curvature.map_or(0.0, |h| sign * h[(r, c)]);
                        t[(j + c) * size + i + r] += pen * bi[r] * bj[c] + w * h;
                    }
                }
            }
        }
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
        if self.is_contact() {
            ElementKind::Contact
        } else {
            ElementKind::Stop
        }
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
        let source = match &self.watched {
            Watched::Joint { source, .. } => source,
            Watched::Plane(p) => {
                // closed: Φ = n·(x − p) − r − g_c, linear in x (no
                // curvature term)
                let n = p.normal;
                self.add_gap_constraint(ctx, state, &[(0, n)], None, out);
                return;
            }
            Watched::Spheres(s) => {
                // closed: Φ = |x_b − x_a| − r_a − r_b − g_c, B = [−uᵀ uᵀ],
                // ∂²Φ/∂x_b² = ∂²Φ/∂x_a² = −∂²Φ/∂x_a∂x_b = (I − u uᵀ)/d
                let (d, u) = Spheres::direction(state, s.nodes);
                let curvature = (d > 0.0).then(|| (Mat3::identity() - u * u.transpose()) / d);
                self.add_gap_constraint(ctx, state, &[(0, -u), (6, u)], curvature, out);
                return;
            }
        };
        // closed: Φ = c(q) − c_c
        let c = source.function(self.reference(state));
        let value = self.held_value(state);
        let phi = |conf: &Conf, o: &mut [HyperDual]| {
            c(conf, o);
            o[0] = o[0] + (-value);
        };
        let m = self.offsets.multipliers;
        let lambda = &state.multipliers[m..m + 1];
        with_scratch(|sc| {
            sc.local.gather(state, &source.nodes, 0..0);
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
            if let Watched::Joint { source, .. } = &self.watched {
                internal[0] = source.value(state, internal[0]);
            }
        }
        if self.contact(state) != Contact::Open {
            let n = self.load(ctx, state).abs();
            internal[first + LOAD_SCALE] = internal[first + LOAD_SCALE].max(n);
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        if self.is_contact() {
            &CONTACT_RESULTS
        } else {
            &STOP_RESULTS
        }
    }
    /// Fills the first `out.len()` values of [`STOP_RESULTS`] (of
    /// [`CONTACT_RESULTS`] for a contact).
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        if self.is_contact() {
            let closed = f64::from(u8::from(self.contact(state) != Contact::Open));
            let all = [self.coordinate(state), closed, self.load(ctx, state)];
            let n = out.len().min(all.len());
            out[..n].copy_from_slice(&all[..n]);
            return;
        }
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
