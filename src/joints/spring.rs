//! Springs and dampers on a joint coordinate `c` (hinge angle, stroke):
//! a generalised force `f_s(c) + f_d(ċ)` along `c`, i.e. the residual
//! `(f_s + f_d) ∂c/∂q`, its exact stiffness
//! `f_s' g gᵀ + (f_s + f_d) ∂g/∂q + f_d' g (∂ċ/∂q)ᵀ` and its damping matrix
//! `∂r/∂v = f_d' g gᵀ` (in the inertia matrix, with the damping weight),
//! with `g = ∂c/∂q` and `ċ = g·v` (docs/joints.md §4). The damper acts in
//! dynamics only ([`EvalContext::dynamics`]): in quasi-static analyses
//! `ċ = 0` and its law gives no force at zero rate.

use super::coordinate::PairCoordinate;
use super::kinematics::{with_scratch, Local};
use crate::elements::{CellShape, Element, ElementKind, ElementOutput, EvalContext, Offsets};
use crate::model::Id;
use crate::state::State;

/// A force law `f(x)`: linear, or a table interpolated linearly between
/// its points and extrapolated with the slope of its end segments.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    /// `f = k (x − x₀)`.
    Linear {
        /// Stiffness (or damping coefficient).
        k: f64,
        /// Value of `x` where the force vanishes.
        x0: f64,
    },
    /// Points `(xᵢ, fᵢ)`, at least two, strictly increasing `xᵢ`.
    Table(Vec<(f64, f64)>),
}

impl Law {
    /// `(f(x), f'(x))`; at an interior table point the slope of the
    /// segment to its right is used, at and beyond the end points the
    /// slope of the end segments.
    pub fn eval(&self, x: f64) -> (f64, f64) {
        match self {
            Self::Linear { k, x0 } => (k * (x - x0), *k),
            Self::Table(p) => {
                let n = p.len();
                let k = p.partition_point(|&(xi, _)| xi <= x).clamp(1, n - 1);
                let (x0, f0) = p[k - 1];
                let (x1, f1) = p[k];
                let slope = (f1 - f0) / (x1 - x0);
                (f0 + slope * (x - x0), slope)
            }
        }
    }

    /// Elastic energy at `x`: `½k(x − x₀)²` for a linear law, `∫₀ˣ f`
    /// (exact for the piecewise-linear law) for a table.
    pub fn energy(&self, x: f64) -> f64 {
        match self {
            Self::Linear { k, x0 } => 0.5 * k * (x - x0).powi(2),
            Self::Table(p) => {
                let (lo, hi) = (x.min(0.0), x.max(0.0));
                let mut cuts: Vec<f64> = p
                    .iter()
                    .map(|q| q.0)
                    .filter(|&xi| xi > lo && xi < hi)
                    .collect();
                cuts.push(lo);
                cuts.push(hi);
                cuts.sort_by(f64::total_cmp);
                let integral: f64 = cuts
                    .windows(2)
                    .map(|w| 0.5 * (self.eval(w[0]).0 + self.eval(w[1]).0) * (w[1] - w[0]))
                    .sum();
                if x >= 0.0 {
                    integral
                } else {
                    -integral
                }
            }
        }
    }
}

/// A spring and/or damper acting on a pair coordinate.
#[derive(Clone, Debug)]
pub struct JointSpring {
    id: Id,
    source: PairCoordinate,
    spring: Option<Law>,
    damper: Option<Law>,
    active: Vec<usize>,
    internal: usize,
}

/// Names of joint-spring results.
pub const SPRING_RESULTS: [&str; 4] = ["coordinate", "rate", "spring", "damper"];

impl JointSpring {
    /// A spring law and/or a damper law (force versus rate) on `source`.
    pub fn new(id: Id, source: PairCoordinate, spring: Option<Law>, damper: Option<Law>) -> Self {
        let active = source.active();
        Self {
            id,
            source,
            spring,
            damper,
            active,
            internal: 0,
        }
    }

    fn reference(&self, state: &State) -> f64 {
        if self.source.is_angle() {
            state.internal[self.internal]
        } else {
            0.0
        }
    }

    /// The local velocities `v` of the source's nodes.
    fn velocities(&self, state: &State, v: &mut Vec<f64>) {
        v.clear();
        for &n in &self.source.nodes {
            v.extend_from_slice(&state.velocity[n]);
        }
    }

    /// `(c, ċ, f_s, f_d)` at `state`.
    fn forces(&self, state: &State) -> (f64, f64, f64, f64) {
        let mut local = Local::default();
        local.gather(state, &self.source.nodes, 0..0);
        let n = local.n();
        let mut c = [0.0];
        let mut g = vec![0.0; n];
        local.gradient(
            1,
            &self.active,
            &self.source.function(self.reference(state)),
            &mut c,
            &mut g,
        );
        let mut v = Vec::new();
        self.velocities(state, &mut v);
        let rate: f64 = g.iter().zip(&v).map(|(a, b)| a * b).sum();
        let fs = self.spring.as_ref().map_or(0.0, |l| l.eval(c[0]).0);
        let fd = self.damper.as_ref().map_or(0.0, |l| l.eval(rate).0);
        (c[0], rate, fs, fd)
    }
}

impl Element for JointSpring {
    fn kind(&self) -> ElementKind {
        ElementKind::JointSpring
    }
    fn id(&self) -> Id {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.source.nodes
    }
    fn n_internal(&self) -> usize {
        usize::from(self.source.is_angle())
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.internal = offsets.internal;
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        with_scratch(|sc| {
            // g = ∂c/∂q; H = ∂g/∂q when the stiffness is asked for
            let c = [self.source.evaluate_into(
                sc,
                state,
                self.reference(state),
                out.stiffness.is_some(),
            )];
            let (n, g, h, v) = (sc.local.n(), &sc.grad, &sc.hess, &mut sc.vel);
            self.velocities(state, v);
            let rate: f64 = g.iter().zip(v.iter()).map(|(a, b)| a * b).sum();
            let (fs, ks) = self.spring.as_ref().map_or((0.0, 0.0), |l| l.eval(c[0]));
            // the damper's force in dynamics; its slope for the damping
            // matrix whenever asked
            let (fd, kd) = self.damper.as_ref().map_or((0.0, 0.0), |l| l.eval(rate));
            let fd = if ctx.dynamics { fd } else { 0.0 };
            let total = fs + fd;
            for r in 0..n {
                out.residual[r] += total * g[r];
            }
            if let (Some(w), Some(d)) = (ctx.need.inertia, out.inertia.as_deref_mut()) {
                // ∂r/∂v = f_d' g gᵀ
                let c = w.damping * kd;
                if c != 0.0 {
                    for col in 0..n {
                        for r in 0..n {
                            d[col * n + r] += c * g[r] * g[col];
                        }
                    }
                }
            }
            let Some(stiffness) = out.stiffness.as_deref_mut() else {
                return;
            };
            let kd = if ctx.dynamics { kd } else { 0.0 };
            for col in 0..n {
                // ∂ċ/∂q_col at fixed v: Σ_r v_r H[r, col]
                let dc = if kd != 0.0 {
                    (0..n).map(|r| v[r] * h[col * n + r]).sum::<f64>()
                } else {
                    0.0
                };
                for r in 0..n {
                    stiffness[col * n + r] +=
                        ks * g[r] * g[col] + total * h[col * n + r] + kd * g[r] * dc;
                }
            }
        });
    }
    fn update_internal(&self, _ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        if self.source.is_angle() {
            internal[0] = self.source.value(state, internal[0]);
        }
    }
    fn result_names(&self) -> &'static [&'static str] {
        &SPRING_RESULTS
    }
    fn results(&self, _ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let (c, rate, fs, fd) = self.forces(state);
        out[..4].copy_from_slice(&[c, rate, fs, fd]);
    }
    fn strain_energy(&self, _ctx: &EvalContext, state: &State) -> f64 {
        let c = self.source.value(state, self.reference(state));
        self.spring.as_ref().map_or(0.0, |l| l.energy(c))
    }
    /// `f_d(ċ) ċ`: the power the damper takes out of the motion.
    fn dissipated_power(&self, _ctx: &EvalContext, state: &State) -> f64 {
        let (_, rate, _, fd) = self.forces(state);
        fd * rate
    }
    /// The damper's force `f_d(ċ) g`.
    fn nonconservative_forces(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        if ctx.dynamics && self.damper.is_some() {
            crate::elements::damper_share(self, ctx, state, out);
        }
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}
