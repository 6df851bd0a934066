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

use super::{add_block, add_vec, CellShape, Element, ElementKind, ElementOutput, EvalContext};
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
        })
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

    fn evaluate(&self, _ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let n = self.n_local();
        let b = self.b();
        let grounded = self.grounded();
        match self.kind {
            SpringKind::Translational => {
                // S1
                let (f, _) = self.force_and_deformation(state);
                add_vec(out.residual, b, &f);
                if !grounded {
                    add_vec(out.residual, 0, &(-f));
                }
                if let Some(tangent) = out.stiffness.as_deref_mut() {
                    let k = Mat3::from_diagonal(&self.k);
                    add_block(tangent, n, b, b, &k);
                    if !grounded {
                        add_block(tangent, n, 0, 0, &k);
                        add_block(tangent, n, 0, b, &(-k));
                        add_block(tangent, n, b, 0, &(-k));
                    }
                }
            }
            SpringKind::Rotational => {
                // S2
                let (c0, psi) = self.relative_rotation(state);
                let kmat = Mat3::from_diagonal(&self.k);
                let m = kmat * psi;
                let ti = SkewSeries::new(Operator::TangentInv, &psi);
                let ti_m = ti.matrix();
                let (rb, ra) = (b + 3, 3);
                add_vec(out.residual, rb, &(c0.transpose() * ti.apply_transpose(&m)));
                if !grounded {
                    add_vec(out.residual, ra, &(-ti.apply(&m)));
                }
                if let Some(tangent) = out.stiffness.as_deref_mut() {
                    // ∂(rows)/∂ψ, then ∂ψ/∂Θ_b = T⁻¹ C₀, ∂ψ/∂Θ_a = −T⁻ᵀ
                    let gb = c0.transpose()
                        * (ti.derivative_of_apply_transpose(&m) + ti_m.transpose() * kmat);
                    let dpsi_b = ti_m * c0;
                    add_block(tangent, n, rb, rb, &(gb * dpsi_b));
                    if !grounded {
                        let ga = -(ti.derivative_of_apply(&m) + ti_m * kmat);
                        let dpsi_a = -ti_m.transpose();
                        add_block(tangent, n, rb, ra, &(gb * dpsi_a));
                        add_block(tangent, n, ra, rb, &(ga * dpsi_b));
                        add_block(tangent, n, ra, ra, &(ga * dpsi_a));
                    }
                }
            }
            SpringKind::Axial => {
                // S3
                let (xa, xb) = self.positions(state);
                let d = xb - xa;
                let l = d.norm();
                let e = d / l;
                let k = self.k.x;
                let f = e * (k * (l - self.l0));
                add_vec(out.residual, 6, &f);
                add_vec(out.residual, 0, &(-f));
                if let Some(tangent) = out.stiffness.as_deref_mut() {
                    let ee = e * e.transpose();
                    let kt = ee * k + (Mat3::identity() - ee) * (k * (l - self.l0) / l);
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
    use crate::elements::testing::{eval, tangent_error};
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
