//! A relative coordinate of a pair of bodies (a joint's angle or stroke, or
//! a node's displacement or rotation relative to the ground), the quantity
//! springs, dampers and drivers act on.

use super::hyperdual::HyperDual;
use super::kinematics::{with_scratch, Conf, Local, Pair, Scratch};
use super::products::CoordinateForm;
use super::types::Coordinate;
use crate::state::State;

/// A coordinate of a pair: which nodes, where the pair sits, which
/// coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct PairCoordinate {
    /// Node A, and node B unless B is the ground.
    pub nodes: Vec<usize>,
    /// The pair's geometry.
    pub pair: Pair,
    /// The coordinate.
    pub coordinate: Coordinate,
}

impl PairCoordinate {
    /// Whether it is an angle (unwrapped with an internal variable).
    pub fn is_angle(&self) -> bool {
        self.coordinate.is_angle()
    }

    /// The coordinate as a function of the configuration, angles on the
    /// branch nearest `reference`.
    pub fn function(&self, reference: f64) -> impl Fn(&Conf, &mut [HyperDual]) + '_ {
        move |c: &Conf, out: &mut [HyperDual]| {
            out[0] = self.coordinate.unwrapped(&self.pair.frames(c), reference);
        }
    }

    /// Value at `state`, angles on the branch nearest `reference`.
    pub fn value(&self, state: &State, reference: f64) -> f64 {
        with_scratch(|sc| {
            sc.local.gather(state, &self.nodes, 0..0);
            let mut v = [0.0];
            sc.local.value(1, &self.function(reference), &mut v);
            v[0]
        })
    }

    /// Gathers the pair's nodes into `sc.local` and returns the coordinate,
    /// with its gradient `g = ∂c/∂q` in `sc.grad` (`n`) and, if `hessian`,
    /// `H = ∂g/∂q` in `sc.hess` (`n × n`, column-major); `n = sc.local.n()`.
    pub fn evaluate_into(
        &self,
        sc: &mut Scratch,
        state: &State,
        reference: f64,
        hessian: bool,
    ) -> f64 {
        sc.local.gather(state, &self.nodes, 0..0);
        let n = sc.local.n();
        sc.grad.clear();
        sc.grad.resize(n, 0.0);
        sc.hess.clear();
        if hessian {
            sc.hess.resize(n * n, 0.0);
        }
        self.derivatives(
            &mut sc.local,
            reference,
            &mut sc.grad,
            hessian.then_some(&mut sc.hess[..]),
        )
    }

    /// The coordinate at `local` (gathered from its nodes), angles on the
    /// branch nearest `reference`, its gradient `grad` over every local
    /// unknown and, with `hessian` (`n × n`, column-major), its second
    /// derivatives added: in closed form ([`CoordinateForm`]), by
    /// hyper-dual numbers for a slider's curve parameter.
    pub fn derivatives(
        &self,
        local: &mut Local,
        reference: f64,
        grad: &mut [f64],
        hessian: Option<&mut [f64]>,
    ) -> f64 {
        if let Some(form) = CoordinateForm::of(self.coordinate, &self.pair) {
            return form.evaluate(local, reference, grad, hessian);
        }
        let n = local.n();
        let active = self.active();
        let f = self.function(reference);
        let mut c = [0.0];
        local.gradient(1, &active, &f, &mut c, grad);
        if let Some(h) = hessian {
            local.add_weighted_hessian(1, &active, &f, &[1.0], grad, true, h, n);
        }
        c[0]
    }

    /// Local unknowns it depends on (all of its nodes' components).
    pub fn active(&self) -> Vec<usize> {
        (0..6 * self.nodes.len()).collect()
    }
}
