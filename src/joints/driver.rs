//! Drivers: a prescribed history `c(t) = value·f(t)` of a joint
//! coordinate or of a node's displacement or rotation along an axis
//! (measured from the reference configuration), enforced as one more
//! constraint `Φ = c(q) − value·f(t)` with its own multiplier (the
//! "additional constraints that control the motion" of the paper, section
//! 6.1). The multiplier gives the force or moment the driver applies: the
//! actuator load.
//!
//! A driver may act during a window `[start, end]` of `t` only
//! (docs/joints.md §6.1). Outside it the constraint is released: its
//! equation becomes `k λ = 0`, so it applies no load. A driver that starts
//! at `start > 0` takes over the coordinate where it is then,
//! `Φ = c(q) − c_start − value·(f(t) − f(start))`, with `c_start` the value
//! at the last converged state before `start` (an internal variable).

use super::coordinate::PairCoordinate;
use super::joint::{add_constraints, constraint_kind, scale_of};
use super::kinematics::{with_scratch, Conf};
use super::types::Equation;
use crate::curves::CurveIndex;
use crate::elements::{
    CellShape, ConstraintKind, Element, ElementKind, ElementOutput, EvalContext, Need, Offsets,
};
use crate::model::Id;
use crate::so3::{self, Vec3};
use crate::state::State;

/// A driven coordinate.
#[derive(Clone, Debug)]
pub struct Driver {
    id: Id,
    source: PairCoordinate,
    value: f64,
    curve: CurveIndex,
    active: Vec<usize>,
    /// Acting window `[start, end]` of `t`.
    window: (f64, f64),
    /// Where its multiplier and internal variables are in the state.
    offsets: Offsets,
}

/// Names of driver results: the coordinate, its target and the load along
/// it, then the load on the driven body (body B, or the node of a node
/// driver) as a force and a moment about its joint point, global axes.
pub const DRIVER_RESULTS: [&str; 9] = [
    "coordinate",
    "target",
    "load",
    "Fx",
    "Fy",
    "Fz",
    "Mx",
    "My",
    "Mz",
];

impl Driver {
    /// Drives `source` to `value·curves[curve](t)` (relative to the
    /// reference configuration).
    pub fn new(id: Id, source: PairCoordinate, value: f64, curve: CurveIndex) -> Self {
        let active = source.active();
        Self {
            id,
            source,
            value,
            curve,
            active,
            window: (f64::NEG_INFINITY, f64::INFINITY),
            offsets: Offsets::default(),
        }
    }

    /// Acts only while `start ≤ t ≤ end` (see the module documentation).
    pub fn with_window(mut self, start: f64, end: f64) -> Self {
        self.window = (start, end);
        self
    }

    /// Whether the driver acts at `t`.
    pub fn is_active(&self, t: f64) -> bool {
        t >= self.window.0 && t <= self.window.1
    }

    /// Whether it takes over the coordinate where it finds it.
    fn takes_over(&self) -> bool {
        self.window.0 > 0.0
    }

    /// Index of `c_start` in the internal variables.
    fn start_slot(&self) -> usize {
        self.offsets.internal + usize::from(self.source.is_angle())
    }

    fn kind_of_equation(&self) -> Equation {
        if self.source.is_angle() {
            Equation::Moment
        } else {
            Equation::Force
        }
    }

    fn reference(&self, state: &State) -> f64 {
        if self.source.is_angle() {
            state.internal[self.offsets.internal]
        } else {
            0.0
        }
    }

    /// Load the driver applies to the driven body (body B of the pair, or
    /// the node of a node driver): force, and moment about B's joint
    /// point, global frame. It is `−r_B`, the element's residual at B's
    /// node, equal to `−Bᵀ(pΦ − kλ)` there.
    pub fn load_on_driven_body(&self, ctx: &EvalContext, state: &State) -> (Vec3, Vec3) {
        let mut r = vec![0.0; self.n_local()];
        let c = EvalContext {
            dynamics: false,
            ..ctx.with_need(Need::RESIDUAL)
        };
        self.evaluate(&c, state, &mut ElementOutput::residual(&mut r));
        let nb = self.source.pair.node_b();
        let node = self.source.nodes[nb];
        let rb = so3::matrix(&state.q[node]);
        let f = -Vec3::new(r[6 * nb], r[6 * nb + 1], r[6 * nb + 2]);
        // the rotational residual is conjugate to material rotations
        let m_node = rb * -Vec3::new(r[6 * nb + 3], r[6 * nb + 4], r[6 * nb + 5]);
        let arm = rb * self.source.pair.b;
        (f, m_node - arm.cross(&f))
    }

    /// Target value of the coordinate at `ctx.time` (while active).
    pub fn target(&self, ctx: &EvalContext, state: &State) -> f64 {
        let f = &ctx.curves[self.curve];
        if self.takes_over() {
            state.internal[self.start_slot()]
                + self.value * (f.value(ctx.time) - f.value(self.window.0))
        } else {
            self.value * f.value(ctx.time)
        }
    }
}

impl Element for Driver {
    fn kind(&self) -> ElementKind {
        ElementKind::Driver
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
    fn n_internal(&self) -> usize {
        usize::from(self.source.is_angle()) + 1
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.offsets = offsets;
    }
    fn multiplier_kind(&self, _k: usize) -> ConstraintKind {
        constraint_kind(self.kind_of_equation())
    }
    fn constraints_active(&self, time: f64, _state: &State) -> bool {
        self.is_active(time)
    }
    fn imposed_angle(&self) -> Option<(f64, CurveIndex)> {
        self.source.is_angle().then_some((self.value, self.curve))
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        if !self.is_active(ctx.time) {
            // released: k λ = 0
            let k = scale_of(&ctx.scaling, self.kind_of_equation()).0;
            let nq = 6 * self.source.nodes.len();
            out.residual[nq] += k * state.multipliers[self.offsets.multipliers];
            if let Some(t) = out.stiffness.as_deref_mut() {
                t[nq * (nq + 1) + nq] += k;
            }
            return;
        }
        let target = self.target(ctx, state);
        let c = self.source.function(self.reference(state));
        let phi = |conf: &Conf, o: &mut [super::hyperdual::HyperDual]| {
            c(conf, o);
            o[0] = o[0] + (-target);
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
        let mut c = 0.0;
        if self.source.is_angle() {
            c = self.source.value(state, internal[0]);
            internal[0] = c;
        } else if state.time < self.window.0 {
            c = self.source.value(state, 0.0);
        }
        if state.time < self.window.0 {
            internal[internal.len() - 1] = c;
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        &DRIVER_RESULTS
    }
    /// Fills the first `out.len()` values of [`DRIVER_RESULTS`].
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let mut all = [0.0; DRIVER_RESULTS.len()];
        all[0] = self.source.value(state, self.reference(state));
        if self.is_active(ctx.time) {
            let target = self.target(ctx, state);
            let (k, p) = scale_of(&ctx.scaling, self.kind_of_equation());
            all[1] = target;
            // generalised load applied along the coordinate: −(pΦ − kλ)
            all[2] = k * state.multipliers[self.offsets.multipliers] - p * (all[0] - target);
            let (f, m) = self.load_on_driven_body(ctx, state);
            all[3..6].copy_from_slice(f.as_slice());
            all[6..9].copy_from_slice(m.as_slice());
        } else {
            // released: no target, no load
            all[1] = f64::NAN;
        }
        let n = out.len().min(all.len());
        out[..n].copy_from_slice(&all[..n]);
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}
