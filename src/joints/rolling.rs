//! Rolling disc: a rigid disc rolling without slipping on a fixed plane,
//! the non-holonomic constraint of paper section 4, eq. 15
//! (docs/joints.md §3.8).
//!
//! The disc's node is at its centre; its axis is the material axis `e_a`
//! of the node (`a = R e_a`, global). The plane passes through `p` with
//! unit normal `n` (pointing to the side of the disc), spanned by the
//! fixed unit tangents `t₁`, `t₂`. The contact point is the lowest point
//! of the rim,
//!
//! ```text
//! ρ = r u,   u = −(n − (n·a) a)/|n − (n·a) a|,   c = x + ρ,
//! ```
//!
//! (singular only when the disc lies flat, `a ∥ n`). Three equations,
//! each with its multiplier, scaled as distance constraints (`k`, `p` of
//! forces):
//!
//! ```text
//! Φ   = n·(x − p) + n·ρ = n·(x − p) − r √(1 − (n·a)²) = 0     (R1, holonomic)
//! Ψᵢ  = tᵢ·(ẋ + ω × ρ) = Aᵢ(q) v = 0,  i = 1, 2             (R2, eq. 15)
//! Aᵢ  = [tᵢᵀ, (Rᵀ(ρ × tᵢ))ᵀ]   over v = (ẋ, Ω),  ω = R Ω
//! ```
//!
//! (R2) is the velocity of the material point of the disc at the contact,
//! in the plane; its normal component is `Φ̇` (the contact point is the
//! lowest point, so `n` is normal to the rim there). The velocity
//! equations enter the residual as lengths, `Ψ̂ = A(q) m` with
//!
//! - in dynamics, `m = τ v`, `τ = ConstraintScaling::rate_time` (`1/γ′`
//!   in the generalised-α iteration, so that their rows of the iteration
//!   matrix, `γ′ ∂Ψ̂/∂v + ∂Ψ̂/∂q T = A + τ ∂(Av)/∂q T`, are of the order of
//!   a holonomic constraint's `B`, docs/theory.md D8);
//! - in statics and kinematic analyses, where there are no velocities,
//!   `m = q ⊖ q_n = (x − x_n, log(R_nᵀ R))`, the increment from the last
//!   converged state: `A(q)(q ⊖ q_n) = 0` is the rolling condition
//!   integrated over the increment by the backward Euler rule in the load
//!   parameter (first order in the increment: the contact point does not
//!   slide, the disc may roll and pivot).
//!
//! With `Ψ̂₀ = Φ`, `A₀ = ∂Φ/∂q`, `wᵢ = pΨ̂ᵢ − kμᵢ`, the residual and its
//! derivatives (`G = ∂Ψ̂/∂q`, taken along the update of the unknowns):
//!
//! ```text
//! r_q = Σᵢ Aᵢᵀ wᵢ                 r_μ = −k Ψ̂
//! ∂r_q/∂q = p Σ Aᵢᵀ Gᵢ + Σ wᵢ ∂Aᵢ/∂q      ∂r_q/∂μ = −k Aᵀ     ∂r_μ/∂q = −k G
//! ∂r_q/∂v = p τ Σᵢ₌₁,₂ Aᵢᵀ Aᵢ            ∂r_μ/∂v = −k τ A    (dynamics)
//! ```
//!
//! The constraint force on the disc at convergence is `k Aᵀ μ`: a normal
//! force `k μ₀` and the friction `k (μ₁ t₁ + μ₂ t₂)` at the contact; it
//! does no work on a motion that satisfies (R2).

use super::hyperdual::{HyperDual, Real, M3, V3};
use super::kinematics::{with_scratch, Conf};
use crate::elements::{
    Attachment, CellShape, ConstraintKind, Element, ElementKind, ElementOutput, EvalContext,
    Offsets,
};
use crate::model::Id;
use crate::so3::{self, Mat3, Vec3};
use crate::state::State;

/// Names of rolling-disc results: the contact point (global), the slip
/// velocity of the disc's material point there along `t₁`, `t₂`, the
/// normal force the plane applies to the disc and the friction force
/// along `t₁`, `t₂`.
pub const ROLLING_RESULTS: [&str; 8] = ["cx", "cy", "cz", "slip1", "slip2", "N", "F1", "F2"];

/// The node's local unknowns, all of which the constraints depend on.
const ACTIVE: [usize; 6] = [0, 1, 2, 3, 4, 5];

/// Below this `sin²ψ` the rotation increment of the static form is taken
/// from the series of `ψ/sin ψ` (truncation `~ sin⁶ψ`, far below
/// round-off).
const SERIES: f64 = 1e-8;

/// A disc rolling without slipping on a fixed plane (see the module
/// documentation).
#[derive(Clone, Debug)]
pub struct RollingDisc {
    id: Id,
    node: [usize; 1],
    /// `r`.
    radius: f64,
    /// `e_a`, unit, material frame.
    axis: Vec3,
    /// `p`.
    point: Vec3,
    /// `n`, unit.
    normal: Vec3,
    /// `t₁`, `t₂`: unit, orthogonal, `t₁ × t₂ = n`.
    tangents: [Vec3; 2],
    /// The node's reference position and orientation: the internal
    /// variables (the last converged configuration, for the static form)
    /// are stored relative to them.
    reference: (Vec3, Mat3),
    offsets: Offsets,
}

/// `Rᵀ v` for a hyper-dual `R`.
fn transpose_apply(r: &M3<HyperDual>, v: &V3<HyperDual>) -> V3<HyperDual> {
    V3([r.col(0).dot(v), r.col(1).dot(v), r.col(2).dot(v)])
}

/// `R v` for hyper-dual `R` and `v`.
fn apply(r: &M3<HyperDual>, v: &V3<HyperDual>) -> V3<HyperDual> {
    r.col(0)
        .scale(v.0[0])
        .add(&r.col(1).scale(v.0[1]))
        .add(&r.col(2).scale(v.0[2]))
}

/// `log(R₀ᵀ R)` (the rotation vector), for `R₀ᵀR` less than half a turn.
fn rotation_increment(r0: &Mat3, r: &M3<HyperDual>) -> V3<HyperDual> {
    // Q = R₀ᵀ R, column by column
    let q: [V3<HyperDual>; 3] = std::array::from_fn(|j| {
        let c = r.col(j);
        V3(std::array::from_fn(|i| {
            c.0[0] * r0[(0, i)] + c.0[1] * r0[(1, i)] + c.0[2] * r0[(2, i)]
        }))
    });
    let at = |i: usize, j: usize| q[j].0[i];
    // sin ψ n = vee(Q − Qᵀ)/2, cos ψ = (tr Q − 1)/2
    let s = V3([
        (at(2, 1) - at(1, 2)) * 0.5,
        (at(0, 2) - at(2, 0)) * 0.5,
        (at(1, 0) - at(0, 1)) * 0.5,
    ]);
    let c = (at(0, 0) + at(1, 1) + at(2, 2) + (-1.0)) * 0.5;
    let s2 = s.dot(&s);
    // ψ/sin ψ = asin(σ)/σ = 1 + σ²/6 + 3σ⁴/40 + …, σ = sin ψ
    let factor = if s2.re < SERIES && c.re > 0.0 {
        s2 * (1.0 / 6.0) + s2 * s2 * (3.0 / 40.0) + 1.0
    } else {
        let sin = s2.sqrt();
        sin.atan2(c) / sin
    };
    s.scale(factor)
}

impl RollingDisc {
    /// A disc of radius `radius` centred on node `node` (reference
    /// position and orientation `reference`), its axis the material
    /// direction `axis`, rolling on the plane through `point` with normal
    /// `normal` (pointing to the disc's side). `axis` and `normal` are
    /// normalised; the caller checks that they are not zero and that the
    /// radius is positive.
    pub fn new(
        id: Id,
        node: usize,
        radius: f64,
        axis: Vec3,
        point: Vec3,
        normal: Vec3,
        reference: (Vec3, Mat3),
    ) -> Self {
        let n = normal.normalize();
        // the global axis least aligned with n, made orthogonal to it
        let k = (0..3)
            .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
            .unwrap_or(0);
        let e = Vec3::ith(k, 1.0);
        let t1 = (e - n * n.dot(&e)).normalize();
        let t2 = n.cross(&t1);
        Self {
            id,
            node: [node],
            radius,
            axis: axis.normalize(),
            point,
            normal: n,
            tangents: [t1, t2],
            reference,
            offsets: Offsets::default(),
        }
    }

    /// `r`.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The plane's unit normal `n`.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// The plane's unit tangents `t₁`, `t₂` (`t₁ × t₂ = n`).
    pub fn tangents(&self) -> [Vec3; 2] {
        self.tangents
    }

    /// `ρ = r u`, from the centre to the contact point (global), for the
    /// node orientation `r`.
    fn arm(&self, r: &M3<HyperDual>) -> V3<HyperDual> {
        let a = r.apply(&self.axis);
        let n = V3::cst(&self.normal);
        let w = n.sub(&a.scale(n.dot(&a)));
        w.scale(HyperDual::cst(-self.radius) / w.norm())
    }

    /// `Φ` (R1).
    fn height(&self, c: &Conf) -> HyperDual {
        let n = V3::cst(&self.normal);
        n.dot(&c.x[0].sub(&V3::cst(&self.point))) + n.dot(&self.arm(&c.r[0]))
    }

    /// `tᵢ·(m_x + (R m_θ) × ρ)` (R2 applied to `m`).
    fn slip(&self, c: &Conf, mx: &V3<HyperDual>, mth: &V3<HyperDual>) -> [HyperDual; 2] {
        let r = &c.r[0];
        let vc = mx.add(&apply(r, mth).cross(&self.arm(r)));
        [
            V3::cst(&self.tangents[0]).dot(&vc),
            V3::cst(&self.tangents[1]).dot(&vc),
        ]
    }

    /// The last converged configuration `(x_n, R_n)` (from the internal
    /// variables `[x_n − x₀, log(R₀ᵀ R_n)]`).
    fn last_converged(&self, internal: &[f64]) -> (Vec3, Mat3) {
        let (x0, r0) = &self.reference;
        let dx = Vec3::new(internal[0], internal[1], internal[2]);
        let th = Vec3::new(internal[3], internal[4], internal[5]);
        (x0 + dx, r0 * so3::exp_matrix(&th))
    }

    fn internal<'s>(&self, state: &'s State) -> &'s [f64] {
        let i = self.offsets.internal;
        &state.internal[i..i + 6]
    }

    /// The contact point `c = x + ρ` at `state`.
    pub fn contact_point(&self, state: &State) -> Vec3 {
        let node = self.node[0];
        let rho = self.arm(&M3::cst(&so3::matrix(&state.q[node]))).re();
        state.x[node] + rho
    }

    /// The velocity of the disc's material point at the contact,
    /// `ẋ + ω × ρ` (global).
    pub fn contact_velocity(&self, state: &State) -> Vec3 {
        let node = self.node[0];
        let r = so3::matrix(&state.q[node]);
        let rho = self.arm(&M3::cst(&r)).re();
        let v = &state.velocity[node];
        let w = r * Vec3::new(v[3], v[4], v[5]);
        Vec3::new(v[0], v[1], v[2]) + w.cross(&rho)
    }
}

impl Element for RollingDisc {
    fn kind(&self) -> ElementKind {
        ElementKind::RollingDisc
    }
    fn id(&self) -> Id {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.node
    }
    /// `μ₀` of the contact (R1), `μ₁`, `μ₂` of rolling (R2).
    fn n_multipliers(&self) -> usize {
        3
    }
    /// The last converged configuration relative to the reference:
    /// `x_n − x₀`, `log(R₀ᵀ R_n)`.
    fn n_internal(&self) -> usize {
        6
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.offsets = offsets;
    }
    fn multiplier_kind(&self, _k: usize) -> ConstraintKind {
        ConstraintKind::Distance
    }
    fn velocity_constraint(&self, k: usize) -> bool {
        k > 0
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        const N: usize = 9;
        let node = self.node[0];
        let m0 = self.offsets.multipliers;
        let mu = &state.multipliers[m0..m0 + 3];
        let (k, p) = ctx.scaling.force;
        let tau = ctx.scaling.rate_time;
        // what A is applied to: τ v in dynamics, q ⊖ q_n in statics
        let velocity = state.velocity[node];
        let (xn, rn) = self.last_converged(self.internal(state));
        let moving = |c: &Conf| -> (V3<HyperDual>, V3<HyperDual>) {
            if ctx.dynamics {
                let v = Vec3::new(velocity[0], velocity[1], velocity[2]) * tau;
                let w = Vec3::new(velocity[3], velocity[4], velocity[5]) * tau;
                (V3::cst(&v), V3::cst(&w))
            } else {
                (c.x[0].sub(&V3::cst(&xn)), rotation_increment(&rn, &c.r[0]))
            }
        };
        let psi = |c: &Conf, o: &mut [HyperDual]| {
            o[0] = self.height(c);
            let (mx, mth) = moving(c);
            let s = self.slip(c, &mx, &mth);
            o[1] = s[0];
            o[2] = s[1];
        };
        let height = |c: &Conf, o: &mut [HyperDual]| o[0] = self.height(c);
        with_scratch(|sc| {
            sc.local.gather(state, &self.node, 0..0);
            // Ψ̂ and G = ∂Ψ̂/∂q
            let mut value = [0.0; 3];
            sc.grad.clear();
            sc.grad.resize(3 * 6, 0.0);
            sc.local
                .gradient(3, &ACTIVE, &psi, &mut value, &mut sc.grad);
            // A: row 0 the gradient of Φ, rows 1–2 from ρ at q
            let r = so3::matrix(&state.q[node]);
            let rho = self.arm(&M3::cst(&r)).re();
            let mut a = [[0.0; 6]; 3];
            a[0].copy_from_slice(&sc.grad[..6]);
            for i in 0..2 {
                let t = self.tangents[i];
                let rot = r.transpose() * rho.cross(&t);
                a[i + 1] = [t.x, t.y, t.z, rot.x, rot.y, rot.z];
            }
            let w: [f64; 3] = std::array::from_fn(|i| p * value[i] - k * mu[i]);
            for i in 0..3 {
                out.residual[6 + i] += -k * value[i];
                for c in 0..6 {
                    out.residual[c] += a[i][c] * w[i];
                }
            }
            if let Some(t) = out.stiffness.as_deref_mut() {
                for i in 0..3 {
                    let g = &sc.grad[i * 6..(i + 1) * 6];
                    for c in 0..6 {
                        t[c * N + 6 + i] += -k * g[c];
                        t[(6 + i) * N + c] += -k * a[i][c];
                        for row in 0..6 {
                            t[c * N + row] += p * a[i][row] * g[c];
                        }
                    }
                }
                // w₀ ∂A₀/∂q: the second derivative of Φ
                let mut g0 = [0.0; 6];
                g0.copy_from_slice(&sc.grad[..6]);
                sc.local
                    .add_weighted_hessian(1, &ACTIVE, &height, &w[..1], &g0, true, t, N);
                // ∂(w₁A₁ + w₂A₂)/∂q: only the rotation part depends on q,
                // Rᵀ(ρ × (w₁t₁ + w₂t₂))
                if w[1] != 0.0 || w[2] != 0.0 {
                    let tw = self.tangents[0] * w[1] + self.tangents[1] * w[2];
                    let weighted = |c: &Conf, o: &mut [HyperDual]| {
                        let rc = &c.r[0];
                        let v = transpose_apply(rc, &self.arm(rc).cross(&V3::cst(&tw)));
                        o[..3].copy_from_slice(&v.0);
                    };
                    let mut v3 = [0.0; 3];
                    sc.hess.clear();
                    sc.hess.resize(3 * 6, 0.0);
                    sc.local
                        .gradient(3, &ACTIVE, &weighted, &mut v3, &mut sc.hess);
                    for c in 0..6 {
                        for i in 0..3 {
                            t[c * N + 3 + i] += sc.hess[i * 6 + c];
                        }
                    }
                }
            }
            // ∂r/∂v in dynamics (the residual does not depend on v̇)
            if let (true, Some(d), Some(wts)) =
                (ctx.dynamics, out.inertia.as_deref_mut(), ctx.need.inertia)
            {
                let wd = wts.damping;
                for i in 1..3 {
                    for c in 0..6 {
                        d[c * N + 6 + i] += -wd * k * tau * a[i][c];
                        for row in 0..6 {
                            d[c * N + row] += wd * p * tau * a[i][row] * a[i][c];
                        }
                    }
                }
            }
        });
    }
    fn update_internal(&self, _ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        let node = self.node[0];
        let (x0, r0) = &self.reference;
        let dx = state.x[node] - x0;
        let th = so3::log(&so3::from_matrix(
            &(r0.transpose() * so3::matrix(&state.q[node])),
        ));
        internal[..3].copy_from_slice(dx.as_slice());
        internal[3..6].copy_from_slice(th.as_slice());
    }
    fn result_names(&self) -> &'static [&'static str] {
        &ROLLING_RESULTS
    }
    /// Fills the first `out.len()` values of [`ROLLING_RESULTS`]; the
    /// forces from the residual (`kμ − pΨ̂`).
    fn results(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let c = self.contact_point(state);
        let v = self.contact_velocity(state);
        let mut r = [0.0; 9];
        self.evaluate(
            &ctx.with_need(crate::elements::Need::RESIDUAL),
            state,
            &mut ElementOutput::residual(&mut r),
        );
        // r_μ = −kΨ̂: the load kμ − pΨ̂ from the multipliers
        let (k, p) = ctx.scaling.force;
        let m0 = self.offsets.multipliers;
        let load = |i: usize| k * state.multipliers[m0 + i] + p * r[6 + i] / k;
        let all = [
            c.x,
            c.y,
            c.z,
            self.tangents[0].dot(&v),
            self.tangents[1].dot(&v),
            load(0),
            load(1),
            load(2),
        ];
        let n = out.len().min(all.len());
        out[..n].copy_from_slice(&all[..n]);
    }
    /// The contact point, carried by the disc's node.
    fn attachments(&self, state: &State, out: &mut Vec<Attachment>) {
        out.push(Attachment {
            node: Some(self.node[0]),
            point: self.contact_point(state),
            axes: Mat3::from_columns(&[self.tangents[0], self.tangents[1], self.normal]),
        });
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::Vertex
    }
}

#[cfg(test)]
mod tests {
    //! The rolling disc's tangent, `∂r/∂v` and `∂r/∂v̇` against central
    //! finite differences of its residual (`crate::elements::testing`), on
    //! random configurations with large rotations, in statics (the
    //! increment form) and in dynamics (the velocity form).
    use super::*;
    use crate::elements::testing::{rate_errors, tangent_error};
    use crate::elements::{ConstraintScaling, Need};
    use crate::joints::tests::Lcg;

    fn ctx(dynamics: bool) -> EvalContext<'static> {
        EvalContext {
            time: 0.0,
            curves: &[],
            gravity: Vec3::zeros(),
            need: Need::STIFFNESS,
            dynamics,
            scaling: ConstraintScaling {
                force: (3.0, 2.0),
                moment: (5.0, 1.5),
                rate_time: 0.37,
            },
        }
    }

    /// A disc with a random axis, plane and reference, and a state with
    /// its node turned up to ~1.7 rad from the reference, random
    /// velocities (spins up to 20 rad/s), accelerations, multipliers and
    /// last converged configuration (up to ~0.7 rad from the reference;
    /// or at the state itself when `at_state`).
    fn sample(rng: &mut Lcg, at_state: bool) -> (RollingDisc, State) {
        let x0 = rng.vec(1.0);
        let r0 = so3::exp(&rng.vec(2.0));
        let d = RollingDisc::new(
            7,
            0,
            0.3 + rng.next().abs(),
            rng.vec(1.0),
            rng.vec(1.0),
            rng.vec(1.0),
            (x0, so3::matrix(&r0)),
        );
        let mut d = d;
        d.set_offsets(Offsets::default());
        let x = x0 + rng.vec(0.5);
        let q = r0 * so3::exp(&rng.vec(1.0));
        let mut s = State::at_rest(0.0, vec![x], vec![q]).with_unknowns(Vec::new(), 3, 6);
        s.multipliers.iter_mut().for_each(|v| *v = rng.next());
        s.velocity[0] = std::array::from_fn(|k| if k < 3 { 3.0 } else { 20.0 } * rng.next());
        s.acceleration[0] = std::array::from_fn(|_| 100.0 * rng.next());
        if at_state {
            let c = ctx(false);
            let mut internal = [0.0; 6];
            d.update_internal(&c, &s, &mut internal);
            s.internal = internal.to_vec();
        } else {
            s.internal = (0..6).map(|_| 0.4 * rng.next()).collect();
        }
        (d, s)
    }

    /// Tolerance 1e-6 of the largest entry (h = 1e-6: truncation
    /// ~1e-12·|third derivative|, round-off ~1e-10), as for the joints
    /// (src/joints/tests.rs); the residual is linear in v, so the steps
    /// in v and v̇ are 1e-3.
    #[test]
    fn tangents_match_finite_differences() {
        let mut rng = Lcg(17);
        let mut worst = [0.0f64; 4];
        for case in 0..48 {
            let (d, s) = sample(&mut rng, case % 4 == 0);
            let es = tangent_error(&d, &ctx(false), &s, 1e-6);
            let ed = tangent_error(&d, &ctx(true), &s, 1e-6);
            let (ev, ea) = rate_errors(&d, &ctx(true), &s, 1e-3, 1e-3);
            assert!(es < 1e-6, "statics ∂r/∂q: {es:.3e}");
            assert!(ed < 1e-6, "dynamics ∂r/∂q: {ed:.3e}");
            assert!(ev < 1e-6, "∂r/∂v: {ev:.3e}");
            assert!(ea < 1e-6, "∂r/∂v̇: {ea:.3e}");
            for (w, e) in worst.iter_mut().zip([es, ed, ev, ea]) {
                *w = w.max(e);
            }
        }
        println!(
            "worst errors (statics q, dynamics q, v, v̇): {:.2e} {:.2e} {:.2e} {:.2e}",
            worst[0], worst[1], worst[2], worst[3]
        );
    }

    /// The contact geometry: the contact point is the lowest point of the
    /// rim (its height is the minimum over 3600 rim points to 1e-12) and
    /// the normal component of the contact velocity is `Φ̇` (central
    /// difference of Φ along the motion, step 1e-6: ~1e-9).
    #[test]
    fn contact_point_is_the_lowest_point_of_the_rim() {
        let mut rng = Lcg(3);
        for _ in 0..16 {
            let (d, s) = sample(&mut rng, false);
            let c = d.contact_point(&s);
            let r = so3::matrix(&s.q[0]);
            let a = r * d.axis;
            let b1 = so3::frame_from_axis_and_vector(&a, &rng.vec(1.0)).expect("frame");
            let (u, w) = (b1.column(1).into_owned(), b1.column(2).into_owned());
            let lowest = (0..3600)
                .map(|k| {
                    let t = k as f64 * std::f64::consts::TAU / 3600.0;
                    let p = s.x[0] + (u * t.cos() + w * t.sin()) * d.radius;
                    d.normal.dot(&(p - d.point))
                })
                .fold(f64::INFINITY, f64::min);
            let h = d.normal.dot(&(c - d.point));
            assert!(h <= lowest + 1e-12 && lowest - h < 1e-5 * d.radius);
            // Φ̇ = n·v_c
            let e = 1e-6;
            let at = |e: f64| {
                let mut m = s.clone();
                let v = s.velocity[0];
                m.displace_node(
                    0,
                    &(Vec3::new(v[0], v[1], v[2]) * e),
                    &(Vec3::new(v[3], v[4], v[5]) * e),
                );
                d.normal.dot(&(d.contact_point(&m) - d.point))
            };
            let rate = (at(e) - at(-e)) / (2.0 * e);
            let vc = d.contact_velocity(&s);
            assert!((rate - d.normal.dot(&vc)).abs() < 1e-7 * (1.0 + vc.norm()));
        }
    }
}
