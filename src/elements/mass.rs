//! Rigid bodies and point masses carried by a node.
//!
//! A rigid body is a mass `m` with its centre at the offset `c` from its
//! node (node material frame) and an inertia tensor `J` about the centre of
//! mass, also in the node material frame. A point mass is a rigid body with
//! `c = 0` and `J = 0`. In statics the only contribution is the weight
//! `m g` acting at the centre of mass (docs/theory.md §4, eq. M1):
//! `f_x = m g`, `f_Θ = c × (Rᵀ m g)`, with tangent
//! `∂r_Θ/∂Θ = −c~ (Rᵀ m g)~`. Inertia terms belong to dynamics
//! ([`crate::elements::EvalContext::dynamics`]).

use super::{add_block, add_vec, CellShape, Element, ElementKind, ElementOutput, EvalContext};
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
}

impl RigidBody {
    /// A rigid body with mass, inertia about its centre of mass and
    /// centre-of-mass offset (both in the node's material frame).
    pub fn new(id: Id, node: usize, mass: f64, inertia: Mat3, offset: Vec3) -> Self {
        Self {
            id,
            kind: ElementKind::RigidBody,
            node: [node],
            mass,
            inertia,
            offset,
        }
    }

    /// A point mass at the node.
    pub fn point_mass(id: Id, node: usize, mass: f64) -> Self {
        Self {
            kind: ElementKind::PointMass,
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
        if ctx.gravity == Vec3::zeros() {
            return;
        }
        // weight at the centre of mass, eq. M1
        let w = ctx.gravity * self.mass;
        let r = so3::matrix(&state.q[self.node[0]]);
        let w_mat = r.transpose() * w;
        add_vec(out.residual, 0, &(-w));
        add_vec(out.residual, 3, &(-self.offset.cross(&w_mat)));
        if ctx.need_tangent && self.offset != Vec3::zeros() {
            add_block(out.tangent, 6, 3, 3, &(-skew(&self.offset) * skew(&w_mat)));
        }
    }

    fn cell_shape(&self) -> CellShape {
        CellShape::Vertex
    }

    fn mass(&self) -> f64 {
        self.mass
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::{eval, tangent_error};
    use crate::so3::Rotation;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn state(q: Rotation) -> State {
        State {
            time: 0.0,
            x: vec![Vec3::new(1.0, 2.0, 3.0)],
            q: vec![q],
            extra: vec![],
            internal: vec![],
            velocity: vec![],
        }
    }

    fn ctx() -> EvalContext<'static> {
        EvalContext {
            time: 1.0,
            curves: &[],
            gravity: Vec3::new(0.3, -0.2, -9.81),
            need_tangent: true,
            dynamics: None,
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
