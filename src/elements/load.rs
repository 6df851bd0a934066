//! Nodal forces and moments, dead or follower, scaled by a load curve.
//!
//! Virtual work of a force `F` and moment `M` at a node with material
//! rotation increments (docs/theory.md §6, eqs. L1–L2):
//! - dead load (fixed global components): `F·δx + (Rᵀ M)·δΘ`; the material
//!   components of the moment change with `R`, giving the tangent
//!   `∂r_Θ/∂Θ = −(Rᵀ M)~` (L1);
//! - follower load (components fixed in the node's material frame,
//!   `F = R F_m`, `M = R M_m`): `(R F_m)·δx + M_m·δΘ`, tangent
//!   `∂r_x/∂Θ = R F_m~` (L2).
//!
//! The load is `f(t)` times the given values, `f` a load curve.

use super::{add_block, add_vec, Element, ElementKind, ElementOutput, EvalContext};
use crate::curves::CurveIndex;
use crate::model::Id;
use crate::so3::{self, skew, Vec3};
use crate::state::State;

/// A force and moment applied at a node.
#[derive(Clone, Debug)]
pub struct NodalLoad {
    id: Id,
    node: [usize; 1],
    force: Vec3,
    moment: Vec3,
    follower: bool,
    curve: CurveIndex,
}

impl NodalLoad {
    /// A load on `node`; `force` and `moment` are global components (dead)
    /// or material components (follower), scaled by curve `curve`.
    pub fn new(
        id: Id,
        node: usize,
        force: Vec3,
        moment: Vec3,
        follower: bool,
        curve: CurveIndex,
    ) -> Self {
        Self {
            id,
            node: [node],
            force,
            moment,
            follower,
            curve,
        }
    }

    /// The applied force and moment in the global frame.
    pub fn global_values(&self, ctx: &EvalContext, state: &State) -> (Vec3, Vec3) {
        let s = ctx.curves[self.curve].value(ctx.time);
        if self.follower {
            let r = so3::matrix(&state.q[self.node[0]]);
            (r * self.force * s, r * self.moment * s)
        } else {
            (self.force * s, self.moment * s)
        }
    }
}

impl Element for NodalLoad {
    fn kind(&self) -> ElementKind {
        ElementKind::NodalLoad
    }

    fn id(&self) -> Id {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.node
    }

    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let s = ctx.curves[self.curve].value(ctx.time);
        if s == 0.0 {
            return;
        }
        let r = so3::matrix(&state.q[self.node[0]]);
        let (f, m) = (self.force * s, self.moment * s);
        if self.follower {
            // L2
            add_vec(out.residual, 0, &(-(r * f)));
            add_vec(out.residual, 3, &(-m));
            if let Some(tangent) = out.stiffness.as_deref_mut() {
                add_block(tangent, 6, 0, 3, &(r * skew(&f)));
            }
        } else {
            // L1
            let m_mat = r.transpose() * m;
            add_vec(out.residual, 0, &(-f));
            add_vec(out.residual, 3, &(-m_mat));
            if let Some(tangent) = out.stiffness.as_deref_mut() {
                add_block(tangent, 6, 3, 3, &(-skew(&m_mat)));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curves::Curve;
    use crate::elements::testing::tangent_error;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Tangents of dead and follower loads equal central finite
        /// differences of the residual (relative error ≤ 1e-6, h = 1e-6)
        /// for random orientations and load vectors.
        #[test]
        fn tangents_match_finite_differences(
            r in (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64),
            f in (-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64),
            m in (-5.0..5.0f64, -5.0..5.0f64, -5.0..5.0f64),
        ) {
            let curves = [Curve::ramp()];
            let ctx = EvalContext {
                time: 0.7,
                curves: &curves,
                gravity: Vec3::zeros(),
                need: crate::elements::Need::STIFFNESS,
                dynamics: false,
                scaling: Default::default(),
            };
            let state = State::at_rest(
                0.7,
                vec![Vec3::new(0.3, 0.1, 0.2)],
                vec![so3::exp(&Vec3::new(r.0, r.1, r.2))],
            );
            for follower in [false, true] {
                let l = NodalLoad::new(1, 0, Vec3::new(f.0, f.1, f.2), Vec3::new(m.0, m.1, m.2), follower, 0);
                prop_assert!(tangent_error(&l, &ctx, &state, 1e-6) < 1e-6, "follower = {}", follower);
            }
        }
    }
}
