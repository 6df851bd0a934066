//! Linear springs between two nodes or between a node and the ground.
//!
//! Three kinds (docs/theory.md §5, eqs. S1–S3):
//! - **translational**: `f = K Δu`, `Δu = (x_b − X_b) − (x_a − X_a)`, with
//!   `K = diag(k₁, k₂, k₃)` along the global axes (S1);
//! - **rotational**: `m = K ψ`, `ψ = log(R_aᵀ R_b C₀ᵀ)` the rotation of `b`
//!   relative to `a` since the reference (`C₀ = R_a₀ᵀ R_b₀`), in the
//!   material frame of `a`, or the global frame for a spring to ground.
//!   Energy `½ ψᵀ K ψ`, variation `δψ = T⁻¹(ψ) C₀ δΘ_b − T⁻ᵀ(ψ) δΘ_a` (S2).
//!   Valid for relative rotations below π;
//! - **axial**: `f = k (ℓ − ℓ₀) n` along the line between the nodes (S3).
//!
//! A spring to ground acts between a node and its own reference position
//! and orientation.
//!
//! A linear damper may act in parallel, in dynamics only, on the rate of
//! the same deformation (docs/theory.md §5, S4): `f_d = C Δu̇` with
//! `Δu̇ = ẋ_b − ẋ_a`; `m_d = C ψ̇` with `ψ̇ = T⁻¹(ψ) C₀ Ω_b − T⁻ᵀ(ψ) Ω_a`
//! (the variation of S2 with the material angular velocities in place of
//! `δΘ`); `f_d = c ℓ̇ n` with `ℓ̇ = n·(ẋ_b − ẋ_a)`. The damper's force adds
//! to the spring's in the residual; its derivative in the velocities is
//! the damping matrix, its derivative in `q` at fixed velocities enters the
//! stiffness.

use super::{
    add_block, add_vec, damper_share, CellShape, Element, ElementKind, ElementOutput, EvalContext,
};
use crate::model::Id;
use crate::so3::{self, Mat3, Operator, Rotation, SkewSeries, Vec3};
use crate::state::State;

/// What a spring resists (`kind` in the model file).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SpringKind {
    /// Relative displacement along the global axes: `f = diag(k) Δu`.
    Translational,
    /// Relative rotation, measured in the first node's material frame (or
    /// the global frame for a spring to ground): `m = diag(k) ψ`.
    Rotational,
    /// Change of the distance between the two nodes: `f = k (ℓ − ℓ₀)`.
    Axial,
}

/// A linear spring.
#[derive(Clone, Debug)]
pub struct Spring {
    id: Id,
    kind: SpringKind,
    /// One node (to ground) or two nodes `[a, b]`.
    nodes: Vec<usize>,
    /// Stiffness along the three axes (axial springs use the first).
    k: Vec3,
    /// Reference positions of `a` (or ground anchor) and `b`.
    x0: [Vec3; 2],
    /// Reference relative orientation `C₀ = R_a₀ᵀ R_b₀`.
    c0: Rotation,
    /// Reference length (axial springs).
    l0: f64,
    /// Damper coefficients in parallel, along the same axes (axial dampers
    /// use the first); zero without a damper.
    c: Vec3,
}

impl Spring {
    /// A spring between `nodes` (one node: to ground) with reference poses
    /// `x0`, `r0` of those nodes. Returns `None` for an axial spring whose
    /// nodes coincide or that has only one node.
    pub fn new(
        id: Id,
        kind: SpringKind,
        nodes: &[usize],
        x0: &[Vec3],
        r0: &[Rotation],
        k: Vec3,
    ) -> Option<Self> {
        let grounded = nodes.len() == 1;
        let (xa, xb) = if grounded {
            (x0[0], x0[0])
        } else {
            (x0[0], x0[1])
        };
        let c0 = if grounded {
            r0[0]
        } else {
            r0[0].inverse() * r0[1]
        };
        let l0 = (xb - xa).norm();
        if kind == SpringKind::Axial && (grounded || l0 <= 0.0) {
            return None;
        }
        Some(Self {
            id,
            kind,
            nodes: nodes.to_vec(),
            k,
            x0: [xa, xb],
            c0,
            l0,
            c: Vec3::zeros(),
        })
    }

    /// The spring with a linear damper of coefficients `c` in parallel
    /// (N·s/m, or N·m·s/rad for a rotational spring).
    pub fn with_damping(mut self, c: Vec3) -> Self {
        self.c = c;
        self
    }

    /// Damper coefficients (zero without a damper).
    pub fn damping(&self) -> &Vec3 {
        &self.c
    }

    fn has_damper(&self) -> bool {
        self.c != Vec3::zeros()
    }

    /// Translational and angular velocities of nodes a and b (a at rest
    /// when grounded).
    fn velocities(&self, state: &State) -> [Vec3; 4] {
        let v = |n: usize| {
            let v = &state.velocity[n];
            (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
        };
        let (vb, wb) = v(*self.nodes.last().unwrap());
        let (va, wa) = if self.grounded() {
            (Vec3::zeros(), Vec3::zeros())
        } else {
            v(self.nodes[0])
        };
        [va, wa, vb, wb]
    }

    /// Rate of the deformation (`Δu̇`, `ψ̇` or `(ℓ̇, 0, 0)`) and the damper's
    /// force `C ⊙ rate` (S4).
    fn damper_rate_and_force(&self, state: &State) -> (Vec3, Vec3) {
        let [va, wa, vb, wb] = self.velocities(state);
        let rate = match self.kind {
            SpringKind::Translational => vb - va,
            SpringKind::Rotational => {
                let (c0, psi) = self.relative_rotation(state);
                let ti = SkewSeries::new(Operator::TangentInv, &psi);
                ti.apply(&(c0 * wb)) - ti.apply_transpose(&wa)
            }
            SpringKind::Axial => {
                let (xa, xb) = self.positions(state);
                let e = (xb - xa).normalize();
                Vec3::new(e.dot(&(vb - va)), 0.0, 0.0)
            }
        };
        (rate, self.c.component_mul(&rate))
    }

    fn grounded(&self) -> bool {
        self.nodes.len() == 1
    }

    /// Local offset of node b's unknowns (0 when grounded).
    fn b(&self) -> usize {
        if self.grounded() {
            0
        } else {
            6
        }
    }

    fn positions(&self, state: &State) -> (Vec3, Vec3) {
        if self.grounded() {
            (self.x0[0], state.x[self.nodes[0]])
        } else {
            (state.x[self.nodes[0]], state.x[self.nodes[1]])
        }
    }

    fn relative_rotation(&self, state: &State) -> (Mat3, Vec3) {
        let ra = if self.grounded() {
            Rotation::identity()
        } else {
            state.q[self.nodes[0]]
        };
        let rb = state.q[*self.nodes.last().unwrap()];
        // ψ = log(R_aᵀ R_b C₀ᵀ), S2
        let psi = so3::log(&(ra.inverse() * rb * self.c0.inverse()));
        (so3::matrix(&self.c0), psi)
    }

    /// Generalised force (F₁..F₃) and deformation (D₁..D₃), see
    /// [`Element::result_names`].
    fn force_and_deformation(&self, state: &State) -> (Vec3, Vec3) {
        match self.kind {
            SpringKind::Translational => {
                let (xa, xb) = self.positions(state);
                let du = (xb - self.x0[1]) - (xa - self.x0[0]);
                (self.k.component_mul(&du), du)
            }
            SpringKind::Rotational => {
                let (_, psi) = self.relative_rotation(state);
                (self.k.component_mul(&psi), psi)
            }
            SpringKind::Axial => {
                let (xa, xb) = self.positions(state);
                let dl = (xb - xa).norm() - self.l0;
                (Vec3::new(self.k.x * dl, 0.0, 0.0), Vec3::new(dl, 0.0, 0.0))
            }
        }
    }
}

impl Element for Spring {
    fn kind(&self) -> ElementKind {
        ElementKind::Spring
    }

    /// A rotational spring whose relative rotation passes half a turn:
    /// `ψ = log(…)` jumps there from `π u` to `−π u`, and with it the
    /// moment `K ψ`, which then turns the spring the wrong way (S2 holds
    /// below π). Between two converged states the relative rotation
    /// changes by less than half a turn, so a jump of `ψ` by more than π
    /// is that crossing.
    fn law_violated(&self, before: &State, after: &State) -> Option<String> {
        if self.kind != SpringKind::Rotational {
            return None;
        }
        let (_, a) = self.relative_rotation(before);
        let (_, b) = self.relative_rotation(after);
        ((b - a).norm() > std::f64::consts::PI).then(|| {
            format!(
                "its relative rotation passed half a turn (from {:.4} to {:.4} rad, measured the other way round): a rotational spring's law m = K ψ holds below half a turn only (docs/theory.md §5), beyond it the moment would turn the spring the wrong way; use a joint spring on a revolute joint, whose angle may go any number of turns",
                a.norm(),
                b.norm()
            )
        })
    }

    fn id(&self) -> Id {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let n = self.n_local();
        let b = self.b();
        let grounded = self.grounded();
        // the damper acts in dynamics only (velocities are zero in statics)
        let damped = ctx.dynamics && self.has_damper();
        match self.kind {
            SpringKind::Translational => {
                // S1, with the damper of S4
                let (mut f, _) = self.force_and_deformation(state);
                if damped {
                    f += self.damper_rate_and_force(state).1;
                }
                add_vec(out.residual, b, &f);
                if !grounded {
                    add_vec(out.residual, 0, &(-f));
                }
                let pair = |buf: &mut [f64], k: &Mat3| {
                    add_block(buf, n, b, b, k);
                    if !grounded {
                        add_block(buf, n, 0, 0, k);
                        add_block(buf, n, 0, b, &(-k));
                        add_block(buf, n, b, 0, &(-k));
                    }
                };
                if let Some(tangent) = out.stiffness.as_deref_mut() {
                    pair(tangent, &Mat3::from_diagonal(&self.k));
                }
                if let (Some(w), Some(d)) = (ctx.need.inertia, out.inertia.as_deref_mut()) {
                    // ∂f_d/∂v = C
                    if self.has_damper() {
                        pair(d, &Mat3::from_diagonal(&(self.c * w.damping)));
                    }
                }
            }
            SpringKind::Rotational => {
                // S2, with the damper of S4
                let (c0, psi) = self.relative_rotation(state);
                let kmat = Mat3::from_diagonal(&self.k);
                let cmat = Mat3::from_diagonal(&self.c);
                let ti = SkewSeries::new(Operator::TangentInv, &psi);
                let ti_m = ti.matrix();
                let [_, wa, _, wb] = self.velocities(state);
                let mut m = kmat * psi;
                // ∂m/∂ψ at fixed velocities: K + C ∂ψ̇/∂ψ
                let mut dm = kmat;
                if damped {
                    m += cmat * (ti.apply(&(c0 * wb)) - ti.apply_transpose(&wa));
                    dm += cmat
                        * (ti.derivative_of_apply(&(c0 * wb))
                            - ti.derivative_of_apply_transpose(&wa));
                }
                let (rb, ra) = (b + 3, 3);
                add_vec(out.residual, rb, &(c0.transpose() * ti.apply_transpose(&m)));
                if !grounded {
                    add_vec(out.residual, ra, &(-ti.apply(&m)));
                }
                if let (Some(w), Some(d)) = (ctx.need.inertia, out.inertia.as_deref_mut()) {
                    // ∂m/∂Ω_b = C T⁻¹ C₀, ∂m/∂Ω_a = −C T⁻ᵀ
                    if self.has_damper() {
                        let cw = cmat * w.damping;
                        let (gb, ga) = (c0.transpose() * ti_m.transpose(), -ti_m);
                        let (db, da) = (cw * ti_m * c0, -(cw * ti_m.transpose()));
                        add_block(d, n, rb, rb, &(gb * db));
                        if !grounded {
                            add_block(d, n, rb, ra, &(gb * da));
                            add_block(d, n, ra, rb, &(ga * db));
                            add_block(d, n, ra, ra, &(ga * da));
                        }
                    }
                }
                if let Some(tangent) = out.stiffness.as_deref_mut() {
                    // ∂(rows)/∂ψ, then ∂ψ/∂Θ_b = T⁻¹ C₀, ∂ψ/∂Θ_a = −T⁻ᵀ
                    let gb = c0.transpose()
                        * (ti.derivative_of_apply_transpose(&m) + ti_m.transpose() * dm);
                    let dpsi_b = ti_m * c0;
                    add_block(tangent, n, rb, rb, &(gb * dpsi_b));
                    if !grounded {
                        let ga = -(ti.derivative_of_apply(&m) + ti_m * dm);
                        let dpsi_a = -ti_m.transpose();
                        add_block(tangent, n, rb, ra, &(gb * dpsi_a));
                        add_block(tangent, n, ra, rb, &(ga * dpsi_b));
                        add_block(tangent, n, ra, ra, &(ga * dpsi_a));
                    }
                }
            }
            SpringKind::Axial => {
                // S3, with the damper of S4
                let (xa, xb) = self.positions(state);
                let d = xb - xa;
                let l = d.norm();
                let e = d / l;
                let k = self.k.x;
                let [va, _, vb, _] = self.velocities(state);
                let dv = vb - va;
                let (cd, rate) = if damped {
                    (self.c.x, e.dot(&dv))
                } else {
                    (0.0, 0.0)
                };
                let s = k * (l - self.l0) + cd * rate;
                let f = e * s;
                add_vec(out.residual, 6, &f);
                add_vec(out.residual, 0, &(-f));
                let ee = e * e.transpose();
                if let (Some(w), Some(dm)) = (ctx.need.inertia, out.inertia.as_deref_mut()) {
                    // ∂f_d/∂v_b = c n nᵀ
                    if self.has_damper() {
                        let cd = ee * (self.c.x * w.damping);
                        add_block(dm, n, 6, 6, &cd);
                        add_block(dm, n, 0, 0, &cd);
                        add_block(dm, n, 0, 6, &(-cd));
                        add_block(dm, n, 6, 0, &(-cd));
                    }
                }
                if let Some(tangent) = out.stiffness.as_deref_mut() {
                    // ∂(s n)/∂x_b = k n nᵀ + (s/ℓ)(I − n nᵀ) + c n (∂ℓ̇/∂x_b),
                    // ∂ℓ̇/∂x_b = ((I − n nᵀ) Δẋ)ᵀ/ℓ
                    let p = Mat3::identity() - ee;
                    let kt = ee * k + p * (s / l) + e * (p * dv).transpose() * (cd / l);
                    add_block(tangent, n, 6, 6, &kt);
                    add_block(tangent, n, 0, 0, &kt);
                    add_block(tangent, n, 0, 6, &(-kt));
                    add_block(tangent, n, 6, 0, &(-kt));
                }
            }
        }
    }

    fn result_names(&self) -> &'static [&'static str] {
        &["F1", "F2", "F3", "D1", "D2", "D3"]
    }

    fn results(&self, _ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let (f, d) = self.force_and_deformation(state);
        out[..3].copy_from_slice(f.as_slice());
        out[3..6].copy_from_slice(d.as_slice());
    }

    /// `½ Σ kᵢ dᵢ²` of the spring's deformation.
    fn strain_energy(&self, _ctx: &EvalContext, state: &State) -> f64 {
        let (f, d) = self.force_and_deformation(state);
        0.5 * f.dot(&d)
    }

    /// `f_d · rate`: the power the damper takes out of the motion.
    fn dissipated_power(&self, ctx: &EvalContext, state: &State) -> f64 {
        if !(ctx.dynamics && self.has_damper()) {
            return 0.0;
        }
        let (rate, f) = self.damper_rate_and_force(state);
        f.dot(&rate)
    }

    /// The damper's forces (S4): the residual in dynamics less the
    /// residual in statics, where the damper is the only difference.
    fn nonconservative_forces(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        if !(ctx.dynamics && self.has_damper()) {
            return;
        }
        damper_share(self, ctx, state, out);
    }

    fn cell_shape(&self) -> CellShape {
        if self.grounded() {
            CellShape::Vertex
        } else {
            CellShape::Line
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::{eval, motion, rate_errors, set_motion, tangent_error};
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn ctx() -> EvalContext<'static> {
        EvalContext {
            time: 1.0,
            curves: &[],
            gravity: Vec3::zeros(),
            need: crate::elements::Need::STIFFNESS,
            dynamics: false,
            scaling: Default::default(),
        }
    }

    fn state(x: &[Vec3], q: &[Rotation]) -> State {
        State::at_rest(0.0, x.to_vec(), q.to_vec())
    }

    fn vec3(max: f64) -> impl Strategy<Value = Vec3> {
        (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Tangents equal central finite differences of the residual
        /// (relative error ≤ 1e-6, h = 1e-6) on random configurations:
        /// reference orientations anywhere, relative rotations up to ~2.5
        /// rad (below π, where the rotational spring is defined).
        #[test]
        fn tangents_match_finite_differences(
            ra in vec3(3.0), rb in vec3(3.0), da in vec3(0.7), db in vec3(0.7),
            xa in vec3(0.3), xb in vec3(0.3), k in vec3(1.0),
        ) {
            let x0 = [Vec3::zeros(), Vec3::new(1.0, 0.5, -0.2)];
            let r0 = [so3::exp(&ra), so3::exp(&rb)];
            let x = [x0[0] + xa, x0[1] + xb];
            let q = [r0[0] * so3::exp(&da), r0[1] * so3::exp(&db)];
            let k = k.map(|v| 10.0 + 20.0 * v.abs());
            for kind in [SpringKind::Translational, SpringKind::Rotational, SpringKind::Axial] {
                let s2 = Spring::new(1, kind, &[0, 1], &x0, &r0, k).unwrap();
                let err = tangent_error(&s2, &ctx(), &state(&x, &q), 1e-6);
                prop_assert!(err < 1e-6, "{kind:?} two nodes: {err:e}");
                if kind != SpringKind::Axial {
                    let s1 = Spring::new(2, kind, &[0], &x0[..1], &r0[..1], k).unwrap();
                    let err = tangent_error(&s1, &ctx(), &state(&x[..1], &q[..1]), 1e-6);
                    prop_assert!(err < 1e-6, "{kind:?} grounded: {err:e}");
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// With a damper in parallel and the nodes moving and spinning
        /// (velocities up to 10 m/s, spins 20–50 rad/s): in dynamics the
        /// stiffness (damper terms at fixed velocities), the damping matrix
        /// `∂r/∂v` and the (zero) mass matrix equal central differences of
        /// the residual (h = 1e-6 in q, 1e-3 in v and v̇: the residual is
        /// linear in v), within 1e-6 of the largest entry.
        #[test]
        fn damper_tangents_match_finite_differences(
            ra in vec3(3.0), rb in vec3(3.0), da in vec3(0.7), db in vec3(0.7),
            xa in vec3(0.3), xb in vec3(0.3), k in vec3(1.0), c in vec3(1.0),
            ma in motion(), mb in motion(),
        ) {
            let x0 = [Vec3::zeros(), Vec3::new(1.0, 0.5, -0.2)];
            let r0 = [so3::exp(&ra), so3::exp(&rb)];
            let x = [x0[0] + xa, x0[1] + xb];
            let q = [r0[0] * so3::exp(&da), r0[1] * so3::exp(&db)];
            let k = k.map(|v| 10.0 + 20.0 * v.abs());
            let c = c.map(|v| 0.5 + 2.0 * v.abs());
            let dynamic = EvalContext { dynamics: true, ..ctx() };
            for kind in [SpringKind::Translational, SpringKind::Rotational, SpringKind::Axial] {
                let mut s = state(&x, &q);
                set_motion(&mut s, 0, &ma);
                set_motion(&mut s, 1, &mb);
                let s2 = Spring::new(1, kind, &[0, 1], &x0, &r0, k).unwrap().with_damping(c);
                let err = tangent_error(&s2, &dynamic, &s, 1e-6);
                let (ev, ea) = rate_errors(&s2, &dynamic, &s, 1e-3, 1e-3);
                prop_assert!(err < 1e-6 && ev < 1e-6 && ea < 1e-6,
                    "{kind:?} two nodes: ∂r/∂q {err:e}, ∂r/∂v {ev:e}, ∂r/∂v̇ {ea:e}");
                if kind != SpringKind::Axial {
                    let mut s = state(&x[..1], &q[..1]);
                    set_motion(&mut s, 0, &mb);
                    let s1 = Spring::new(2, kind, &[0], &x0[..1], &r0[..1], k)
                        .unwrap()
                        .with_damping(c);
                    let err = tangent_error(&s1, &dynamic, &s, 1e-6);
                    let (ev, ea) = rate_errors(&s1, &dynamic, &s, 1e-3, 1e-3);
                    prop_assert!(err < 1e-6 && ev < 1e-6 && ea < 1e-6,
                        "{kind:?} grounded: ∂r/∂q {err:e}, ∂r/∂v {ev:e}, ∂r/∂v̇ {ea:e}");
                }
            }
        }
    }

    /// The damper's power `f_d · rate` equals minus the power of its
    /// residual on the velocities, `−r_d · v` (the residual is the internal
    /// force), for a two-node rotational damper with both nodes spinning.
    #[test]
    fn damper_power_is_the_power_of_its_forces() {
        let x0 = [Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)];
        let r0 = [
            so3::exp(&Vec3::new(0.3, -0.2, 0.5)),
            so3::exp(&Vec3::new(-1.0, 0.4, 0.2)),
        ];
        let q = [
            r0[0] * so3::exp(&Vec3::new(0.2, 0.1, -0.4)),
            r0[1] * so3::exp(&Vec3::new(0.5, -0.3, 0.1)),
        ];
        let x = [
            x0[0] + Vec3::new(0.1, 0.0, 0.2),
            x0[1] + Vec3::new(0.0, -0.1, 0.3),
        ];
        for kind in [
            SpringKind::Translational,
            SpringKind::Rotational,
            SpringKind::Axial,
        ] {
            let spring = Spring::new(1, kind, &[0, 1], &x0, &r0, Vec3::zeros())
                .unwrap()
                .with_damping(Vec3::new(1.5, 2.0, 0.7));
            let mut s = state(&x, &q);
            s.velocity = vec![
                [1.0, -2.0, 0.5, 3.0, 1.0, -2.0],
                [-0.5, 1.0, 2.0, -1.0, 4.0, 0.5],
            ];
            let dynamic = EvalContext {
                dynamics: true,
                ..ctx()
            };
            let (r, _) = eval(&spring, &dynamic, &s);
            let v: Vec<f64> = s.velocity.iter().flatten().copied().collect();
            let power: f64 = r.iter().zip(&v).map(|(a, b)| a * b).sum();
            let p = spring.dissipated_power(&dynamic, &s);
            assert!(p > 0.0, "{kind:?}: a damper dissipates");
            assert_relative_eq!(p, power, max_relative = 1e-12);
        }
    }

    #[test]
    fn rotational_spring_to_ground_gives_k_theta() {
        // a node turned by θ about global z against k: moment −kθ about z
        let s = Spring::new(
            1,
            SpringKind::Rotational,
            &[0],
            &[Vec3::zeros()],
            &[Rotation::identity()],
            Vec3::repeat(5.0),
        )
        .unwrap();
        let th = 0.7;
        let (f, _) = eval(
            &s,
            &ctx(),
            &state(&[Vec3::zeros()], &[so3::exp(&Vec3::new(0.0, 0.0, th))]),
        );
        // residual = internal moment in material components; about z, Rᵀ ẑ = ẑ
        assert_relative_eq!(f[5], 5.0 * th, epsilon = 1e-12);
    }

    #[test]
    fn axial_spring_needs_two_distinct_nodes() {
        let r = [Rotation::identity(); 2];
        assert!(Spring::new(
            1,
            SpringKind::Axial,
            &[0, 1],
            &[Vec3::zeros(), Vec3::zeros()],
            &r,
            Vec3::repeat(1.0)
        )
        .is_none());
        assert!(Spring::new(
            1,
            SpringKind::Axial,
            &[0],
            &[Vec3::zeros()],
            &r[..1],
            Vec3::repeat(1.0)
        )
        .is_none());
    }
}
