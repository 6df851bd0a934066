//! Drivers: a prescribed history `c(t) = c_ref + value·f(t)` of a joint
//! coordinate or of a node's displacement or rotation along an axis,
//! enforced as one more constraint `Φ = c(q) − value·f(t)` with its own
//! multiplier (the "additional constraints that control the motion" of the
//! paper, section 6.1). The multiplier gives the force or moment the driver
//! applies: the actuator load.

use super::coordinate::PairCoordinate;
use super::joint::{add_constraints, scale_of};
use super::kinematics::{with_scratch, Conf};
use super::types::Equation;
use crate::curves::CurveIndex;
use crate::elements::{CellShape, Element, ElementKind, ElementOutput, EvalContext, ExtraKind};
use crate::model::input::Id;
use crate::state::State;

/// A driven coordinate.
#[derive(Clone, Debug)]
pub struct Driver {
    id: Id,
    source: PairCoordinate,
    value: f64,
    curve: CurveIndex,
    active: Vec<usize>,
    extra: usize,
    internal: usize,
}

/// Names of driver results.
pub const DRIVER_RESULTS: [&str; 3] = ["coordinate", "target", "load"];

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
            extra: 0,
            internal: 0,
        }
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
            state.internal[self.internal]
        } else {
            0.0
        }
    }

    /// Target value at `ctx.time`.
    pub fn target(&self, ctx: &EvalContext) -> f64 {
        self.value * ctx.curves[self.curve].value(ctx.time)
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
    fn n_extra(&self) -> usize {
        1
    }
    fn n_internal(&self) -> usize {
        usize::from(self.source.is_angle())
    }
    fn set_offsets(&mut self, extra: usize, internal: usize) {
        self.extra = extra;
        self.internal = internal;
    }
    fn extra_kind(&self, ctx: &EvalContext, _k: usize) -> ExtraKind {
        let e = self.kind_of_equation();
        ExtraKind::Multiplier {
            scale: scale_of(&ctx.scaling, e).0,
            angular: e == Equation::Moment,
        }
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let target = self.target(ctx);
        let c = self.source.function(self.reference(state));
        let phi = |conf: &Conf, o: &mut [super::hyperdual::HyperDual]| {
            c(conf, o);
            o[0] = o[0] + (-target);
        };
        let lambda = &state.extra[self.extra..self.extra + 1];
        with_scratch(|sc| {
            sc.local.gather(state, &self.source.nodes, 0..0);
            add_constraints(
                ctx,
                &mut sc.local,
                &mut sc.grad,
                &self.active,
                &[self.kind_of_equation()],
                &phi,
                lambda,
                out,
            );
        });
    }
    fn update_internal(&self, _ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        if self.source.is_angle() {
            internal[0] = self.source.value(state, internal[0]);
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        &DRIVER_RESULTS
    }
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let c = self.source.value(state, self.reference(state));
        let target = self.target(ctx);
        let (k, p) = scale_of(&ctx.scaling, self.kind_of_equation());
        out[0] = c;
        out[1] = target;
        // generalised load applied along the coordinate: −(pΦ − kλ)
        out[2] = k * state.extra[self.extra] - p * (c - target);
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}
