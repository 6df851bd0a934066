//! Elements: everything that contributes to the residual and the tangent.
//!
//! Beams, rigid bodies, point masses, springs and nodal loads are all
//! elements behind one small trait, [`Element`]; the assembler does not know
//! which is which. The same trait carries what later analyses and joints
//! need:
//! - extra unknowns owned by an element ([`Element::n_extra`]): Lagrange
//!   multipliers of joints, modal amplitudes of superelements. They follow
//!   the node unknowns in the element's local vector;
//! - internal variables ([`Element::n_internal`]): hysteresis, latch states,
//!   read from the last converged state and updated at convergence;
//! - inertia, damping and gyroscopic terms: [`EvalContext::dynamics`]
//!   carries the integrator's coefficients when an analysis needs them
//!   (statics leaves it `None`).
//!
//! ## Local unknowns and sign convention
//! A node contributes 6 local unknowns: the translation increment `Δx`
//! (global frame) and the incremental *material* rotation `ΔΘ`, with the
//! update `R ← R exp(ΔΘ~)` (docs/theory.md §2). An element writes its
//! contribution to the residual `r = f_int − f_ext` (so a load enters with a
//! minus sign) and to the tangent `∂r/∂q`, column-major, derivatives taken
//! along the update above.

pub mod beam;
pub mod inertia;
mod kind;
pub mod load;
pub mod mass;
pub mod spring;

use crate::curves::Curve;
use crate::model::Id;
use crate::so3::Vec3;
use crate::state::State;

pub use kind::{CellField, CellShape, ElementKind};

/// Coefficients of a time integrator, for elements with inertia or damping.
/// Reserved for dynamic analyses; statics passes `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicsCoefficients {
    /// `∂a/∂q`: factor of the mass matrix in the iteration matrix.
    pub mass: f64,
    /// `∂v/∂q`: factor of the damping matrix in the iteration matrix.
    pub damping: f64,
}

/// What every element may read besides the state.
#[derive(Clone, Copy, Debug)]
pub struct EvalContext<'a> {
    /// Load parameter (pseudo-time in statics, time in dynamics).
    pub time: f64,
    /// All load curves of the model.
    pub curves: &'a [Curve],
    /// Gravity acceleration at `time` (already scaled by its curve).
    pub gravity: Vec3,
    /// Whether the tangent is wanted (a residual-only evaluation leaves the
    /// tangent buffer untouched).
    pub need_tangent: bool,
    /// Integrator coefficients in dynamics, `None` in statics.
    pub dynamics: Option<DynamicsCoefficients>,
    /// Scaling and penalty of constraint equations (eq. 17).
    pub scaling: ConstraintScaling,
}

/// Scaling factor `k` and penalty `p` of the augmented Lagrangian
/// `F* = F − k λ·Φ + ½ p |Φ|²` (paper eq. 17), for constraints on
/// distances (`force`) and on angles (`moment`). Defaults are set by the
/// analysis from the stiffness of the model (docs/joints.md §1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstraintScaling {
    /// `(k, p)` of distance constraints.
    pub force: (f64, f64),
    /// `(k, p)` of angle constraints.
    pub moment: (f64, f64),
}

impl Default for ConstraintScaling {
    fn default() -> Self {
        Self {
            force: (1.0, 1.0),
            moment: (1.0, 1.0),
        }
    }
}

/// What an extra unknown is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExtraKind {
    /// A Lagrange multiplier; its equation is `−k Φ = 0` with the constraint
    /// `Φ` a distance or an angle.
    Multiplier {
        /// The scaling `k` of its equation.
        scale: f64,
        /// Whether `Φ` is an angle (else a distance).
        angular: bool,
    },
    /// A generalised coordinate (slider parameter, modal amplitude); its
    /// equation is a generalised force.
    Coordinate,
}

/// A point an element attaches to one of its nodes or to the ground (see
/// [`Element::attachments`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attachment {
    /// The node carrying it; `None` for the ground.
    pub node: Option<usize>,
    /// Where it is, global frame.
    pub point: Vec3,
    /// The axes it carries (columns), global frame.
    pub axes: crate::so3::Mat3,
}

/// Where an element writes its contributions.
pub struct ElementOutput<'a> {
    /// Local residual `f_int − f_ext`, length `n = 6·nodes + extra`.
    pub residual: &'a mut [f64],
    /// Local tangent `∂r/∂q`, `n × n`, column-major.
    pub tangent: &'a mut [f64],
}

/// A finite element of the mechanism.
pub trait Element: Send + Sync {
    /// The element's kind.
    fn kind(&self) -> ElementKind;

    /// The element's id in the model file.
    fn id(&self) -> Id;

    /// Indices of the nodes it connects (into the model's node list).
    fn nodes(&self) -> &[usize];

    /// Number of extra unknowns it owns (multipliers, modal amplitudes).
    fn n_extra(&self) -> usize {
        0
    }

    /// Number of internal variables it keeps between converged states.
    fn n_internal(&self) -> usize {
        0
    }

    /// Tells the element where its extra unknowns and internal variables
    /// start in [`State::extra`] and [`State::internal`] (called once when
    /// the element joins a model).
    fn set_offsets(&mut self, _extra: usize, _internal: usize) {}

    /// Values of the extra unknowns in the reference state (zero by
    /// default; a slider's curve parameter starts where the node is).
    fn initial_extra(&self, _out: &mut [f64]) {}

    /// What extra unknown `k` is, for convergence checks and messages.
    fn extra_kind(&self, _ctx: &EvalContext, _k: usize) -> ExtraKind {
        ExtraKind::Coordinate
    }

    /// New values of the internal variables after the state has converged
    /// (unwrapped joint angles, hysteresis); `internal` holds the old ones.
    fn update_internal(&self, _ctx: &EvalContext, _state: &State, _internal: &mut [f64]) {}

    /// Size of the local vector: 6 per node plus the extra unknowns.
    fn n_local(&self) -> usize {
        6 * self.nodes().len() + self.n_extra()
    }

    /// Adds the residual and (if `ctx.need_tangent`) the tangent for the
    /// current state. Buffers are zeroed by the caller.
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput);

    /// Names of the result quantities reported by [`Element::results`].
    fn result_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// Result quantities (section forces, spring forces...) for the current
    /// state, in the order of [`Element::result_names`].
    fn results(&self, _ctx: &EvalContext, _state: &State, _out: &mut [f64]) {}

    /// Elastic energy stored in the element (beams, springs).
    fn strain_energy(&self, _ctx: &EvalContext, _state: &State) -> f64 {
        0.0
    }

    /// Points of the element carried by its nodes (joint points), for
    /// drawing: each is drawn joined to its node, so that a rigid link is
    /// seen from its node to its joints. Appended to `out`.
    fn attachments(&self, _state: &State, _out: &mut Vec<Attachment>) {}

    /// How the element is drawn in VTK files.
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }

    /// Mass carried by the element (for model summaries and checks).
    fn mass(&self) -> f64 {
        0.0
    }
}

/// Adds a 3×3 block into a column-major `n × n` buffer at (row, col).
#[inline]
pub(crate) fn add_block(buf: &mut [f64], n: usize, row: usize, col: usize, m: &crate::so3::Mat3) {
    for j in 0..3 {
        let base = (col + j) * n + row;
        for i in 0..3 {
            buf[base + i] += m[(i, j)];
        }
    }
}

/// Adds a 3-vector into a buffer at `row`.
#[inline]
pub(crate) fn add_vec(buf: &mut [f64], row: usize, v: &Vec3) {
    buf[row] += v.x;
    buf[row + 1] += v.y;
    buf[row + 2] += v.z;
}

#[cfg(test)]
pub(crate) mod testing {
    //! Finite-difference checks of element tangents, shared by the
    //! element tests.
    use super::*;
    use crate::so3;

    /// Perturbs local unknown `k` of an element by `h` along the update
    /// rule (translation added, rotation composed on the right).
    pub fn perturb(state: &State, nodes: &[usize], k: usize, h: f64) -> State {
        let mut s = state.clone();
        if k >= 6 * nodes.len() {
            // extra unknowns: the element's offset is 0 in these tests
            s.extra[k - 6 * nodes.len()] += h;
            return s;
        }
        let node = nodes[k / 6];
        let c = k % 6;
        if c < 3 {
            s.x[node][c] += h;
        } else {
            let mut d = Vec3::zeros();
            d[c - 3] = h;
            s.q[node] *= so3::exp(&d);
        }
        s
    }

    /// Evaluates residual and tangent of `e`.
    pub fn eval(e: &dyn Element, ctx: &EvalContext, state: &State) -> (Vec<f64>, Vec<f64>) {
        let n = e.n_local();
        let mut r = vec![0.0; n];
        let mut k = vec![0.0; n * n];
        e.evaluate(
            ctx,
            state,
            &mut ElementOutput {
                residual: &mut r,
                tangent: &mut k,
            },
        );
        (r, k)
    }

    /// Largest error between the analytic tangent and central finite
    /// differences of the residual, relative to the largest tangent entry.
    pub fn tangent_error(e: &dyn Element, ctx: &EvalContext, state: &State, h: f64) -> f64 {
        let n = e.n_local();
        let (_, k) = eval(e, ctx, state);
        let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        let mut worst = 0.0f64;
        for j in 0..n {
            let (rp, _) = eval(e, ctx, &perturb(state, e.nodes(), j, h));
            let (rm, _) = eval(e, ctx, &perturb(state, e.nodes(), j, -h));
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                worst = worst.max((fd - k[j * n + i]).abs() / scale);
            }
        }
        worst
    }
}
