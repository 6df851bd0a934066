//! The panel of the spring-latch tests (tests/latch_spring.rs,
//! tests/latch_restart.rs): a rigid body of mass `m = 1` and inertia
//! `J_c = 1/12` about its centre (node 2) at (0.5, 0, 0), on a revolute
//! joint (id 10) about z at the origin to node 1, which is fixed, so that
//! its inertia about the hinge is `J = J_c + m/4 = 1/3` and its equation
//! of motion in the hinge angle `θ` is linear: `J θ̈ = M(θ, t)`; no
//! gravity.

use super::hinged_body::HingedBody;

/// The model: the panel, `analysis` lines in `[analysis]` (a dynamic
/// analysis), and `extra` entries.
pub fn panel(analysis: &str, extra: &str) -> String {
    let panel = HingedBody {
        centre: [0.5, 0.0, 0.0],
        motion: "",
        body: 1,
        mass: 1.0,
        inertia: [0.08333333333333333; 3],
        joint: 10,
    };
    let tables = panel.tables();
    format!(
        r#"
[analysis]
type = "dynamic"
{analysis}

{tables}

{extra}
"#
    )
}
