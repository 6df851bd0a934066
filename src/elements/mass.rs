//! Rigid bodies and point masses carried by a node.
//!
//! A rigid body is a mass `m` with its centre at the offset `c` from its
//! node (node material frame) and an inertia tensor `J` about the centre of
//! mass, also in the node material frame. A point mass is a rigid body with
//! `c = 0` and `J = 0`. In statics the only contribution is the weight
//! `m g` acting at the centre of mass (docs/theory.md §4, eq. M1):
//! `f_x = m g`, `f_Θ = c × (Rᵀ m g)`, with tangent
//! `∂r_Θ/∂Θ = −c~ (Rᵀ m g)~`.
//!
//! In dynamics ([`crate::elements::EvalContext::dynamics`]) the inertia
//! forces of docs/theory.md §11.2 (I2) join the residual and their
//! centrifugal stiffness (I5) the stiffness; the mass (I3) and gyroscopic
//! (I4) matrices form the inertia matrix.

use super::inertia::RigidBodyInertia;
use super::shape::BodyShape;
use super::{
    add_block, add_scaled, add_vec, node_motion, CellShape, Element, ElementKind, ElementOutput,
    EvalContext,
};
use crate::model::Id;
use crate::so3::{self, skew, Mat3, Vec3};
use crate::state::State;

/// A rigid body or point mass attached to one node.
#[derive(Clone, Debug)]
pub struct RigidBody {
    id: Id,
    kind: ElementKind,
    node: [usize; 1],
    mass: f64,
    /// Inertia tensor about the centre of mass, node material frame.
    inertia: Mat3,
    /// Centre of mass offset from the node, node material frame.
    offset: Vec3,
    /// The inertia kernel.
    kernel: RigidBodyInertia,
    /// The drawn shape (rigid bodies only).
    shape: Option<BodyShape>,
}

impl RigidBody {
    /// A rigid body with mass, inertia about its centre of mass and
    /// centre-of-mass offset (both in the node's material frame), drawn as
    /// the box of its inertia ([`BodyShape::from_inertia`]).
    pub fn new(id: Id, node: usize, mass: f64, inertia: Mat3, offset: Vec3) -> Self {
        Self {
            id,
            kind: ElementKind::RigidBody,
            node: [node],
            mass,
            inertia,
            offset,
            kernel: RigidBodyInertia::new(mass, inertia, offset),
            shape: Some(BodyShape::from_inertia(mass, &inertia, offset)),
        }
    }

    /// The body drawn as `shape` instead of the box of its inertia.
    pub fn with_shape(mut self, shape: BodyShape) -> Self {
        if self.kind == ElementKind::RigidBody {
            self.shape = Some(shape);
        }
        self
    }

    /// A point mass at the node.
    pub fn point_mass(id: Id, node: usize, mass: f64) -> Self {
        Self {
            kind: ElementKind::PointMass,
            shape: None,
            ..Self::new(id, node, mass, Mat3::zeros(), Vec3::zeros())
        }
    }

    /// Inertia tensor about the centre of mass (node material frame).
    pub fn inertia(&self) -> &Mat3 {
        &self.inertia
    }

    /// Centre-of-mass offset (node material frame).
    pub fn offset(&self) -> &Vec3 {
        &self.offset
    }

    /// The inertia kernel (docs/theory.md §11.2).
    pub fn kernel(&self) -> &RigidBodyInertia {
        &self.kernel
    }
}

impl Element for RigidBody {
    fn kind(&self) -> ElementKind {
        self.kind
    }

    fn id(&self) -> Id {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.node
    }

    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let node = self.node[0];
        if ctx.gravity != Vec3::zeros() {
            // weight at the centre of mass, eq. M1
            let w = ctx.gravity * self.mass;
            let r = so3::matrix(&state.q[node]);
            let w_mat = r.transpose() * w;
            add_vec(out.residual, 0, &(-w));
            add_vec(out.residual, 3, &(-self.offset.cross(&w_mat)));
            if let Some(k) = out.stiffness.as_deref_mut() {
                if self.offset != Vec3::zeros() {
                    add_block(k, 6, 3, 3, &(-skew(&self.offset) * skew(&w_mat)));
                }
            }
        }

        // inertia, I2–I5
        let weights = ctx.need.inertia.filter(|_| out.inertia.is_some());
        if !(ctx.dynamics || weights.is_some()) {
            return;
        }
        let motion = node_motion(state, node);
        let blocks = self.kernel.evaluate(&motion);
        if ctx.dynamics {
            for (o, v) in out.residual.iter_mut().zip(blocks.residual.iter()) {
                *o += v;
            }
            if let Some(k) = out.stiffness.as_deref_mut() {
                add_scaled(k, 6, 0, 1.0, &blocks.stiffness);
            }
        }
        if let (Some(w), Some(d)) = (weights, out.inertia.as_deref_mut()) {
            add_scaled(d, 6, 0, w.mass, &blocks.mass);
            add_scaled(d, 6, 0, w.damping, &blocks.gyroscopic);
        }
    }

    fn kinetic_energy(&self, state: &State) -> f64 {
        self.kernel
            .kinetic_energy(&node_motion(state, self.node[0]))
    }

    fn momenta(&self, state: &State) -> super::inertia::Momenta {
        self.kernel.momenta(&node_motion(state, self.node[0]))
    }

    fn weight_potential(&self, ctx: &EvalContext, state: &State) -> f64 {
        let node = self.node[0];
        let centre = state.x[node] + state.q[node] * self.offset;
        -self.mass * ctx.gravity.dot(&centre)
    }

    fn cell_shape(&self) -> CellShape {
        CellShape::Vertex
    }

    fn body_shape(&self) -> Option<&BodyShape> {
        self.shape.as_ref()
    }

    fn mass(&self) -> f64 {
        self.mass
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::{eval, motion, rate_errors, set_motion, tangent_error};
    use crate::so3::Rotation;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn state(q: Rotation) -> State {
        State::at_rest(0.0, vec![Vec3::new(1.0, 2.0, 3.0)], vec![q])
    }

    fn ctx() -> EvalContext<'static> {
        EvalContext {
            time: 1.0,
            curves: &[],
            gravity: Vec3::new(0.3, -0.2, -9.81),
            need: crate::elements::Need::STIFFNESS,
            dynamics: false,
            scaling: Default::default(),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Tangent equals central finite differences of the residual
        /// (relative error ≤ 1e-6, h = 1e-6) for random orientations and
        /// centre-of-mass offsets.
        #[test]
        fn tangent_matches_finite_differences(
            r in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
            c in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        ) {
            let body = RigidBody::new(1, 0, 2.5, Mat3::identity(), Vec3::new(c.0, c.1, c.2));
            let s = state(so3::exp(&Vec3::new(r.0, r.1, r.2)));
            prop_assert!(tangent_error(&body, &ctx(), &s, 1e-6) < 1e-6);
        }

        /// Acceptance, in dynamics: the full residual (weight at the
        /// offset centre of mass, M1, and the inertia forces, I2) has the
        /// stiffness (with the centrifugal block I5) as its derivative in
        /// q, and the inertia matrix with weights (1, 0) and (0, 1) (I4,
        /// I3) as its derivatives in v and v̇, against central differences
        /// (relative error ≤ 1e-6; steps as for the beam), for random
        /// orientations, offsets, inertia tensors and spins of 20 to
        /// 50 rad/s. A point mass too.
        #[test]
        fn dynamic_matrices_match_finite_differences(
            r in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
            c in (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
            j in (0.05..2.0f64, 0.05..2.0f64, 0.05..2.0f64),
            axes in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
            m in motion(),
        ) {
            let a = so3::exp_matrix(&Vec3::new(axes.0, axes.1, axes.2));
            let inertia = a * Mat3::from_diagonal(&Vec3::new(j.0, j.1, j.2)) * a.transpose();
            let body = RigidBody::new(1, 0, 2.5, inertia, Vec3::new(c.0, c.1, c.2));
            let point = RigidBody::point_mass(2, 0, 1.5);
            let mut s = state(so3::exp(&Vec3::new(r.0, r.1, r.2)));
            set_motion(&mut s, 0, &m);
            let cx = EvalContext { dynamics: true, ..ctx() };
            for (name, e) in [("rigid body", &body), ("point mass", &point)] {
                let eq = tangent_error(e, &cx, &s, 1e-6);
                let (ev, ea) = rate_errors(e, &cx, &s, 1e-3, 1e-3);
                prop_assert!(eq < 1e-6, "{name} ∂r/∂q: {eq:e}");
                prop_assert!(ev < 1e-6, "{name} ∂r/∂v: {ev:e}");
                prop_assert!(ea < 1e-6, "{name} ∂r/∂v̇: {ea:e}");
            }
        }
    }

    #[test]
    fn weight_at_offset_gives_the_lever_arm_moment() {
        // body rotated 90° about z: material offset (1,0,0) points along
        // global y; weight −m g ẑ gives the global moment (0,1,0)×(0,0,−mg)
        let body = RigidBody::new(1, 0, 2.0, Mat3::zeros(), Vec3::x());
        let s = state(so3::exp(&Vec3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2)));
        let c = EvalContext {
            gravity: Vec3::new(0.0, 0.0, -10.0),
            ..ctx()
        };
        let (f, _) = eval(&body, &c, &s);
        // external moment in global frame: (−20, 0, 0); residual is its
        // negative, in material components Rᵀ m
        let m_global = Vec3::new(-20.0, 0.0, 0.0);
        let expected = -(so3::matrix(&s.q[0]).transpose() * m_global);
        assert_relative_eq!(Vec3::new(f[3], f[4], f[5]), expected, epsilon = 1e-12);
        assert_relative_eq!(f[2], 20.0, epsilon = 1e-12);
    }
}
