//! The hinged panel of the latch and driver tests (tests/cli_events.rs,
//! tests/cli_dynamics.rs, tests/index3_transients.rs): a rigid body of
//! 1 kg (id 12 on node 2, inertia diag(0.001, 1/12, 1/12) kg·m² about its
//! centre) 0.5 m from node 1, which is fixed, on a revolute joint (id 3)
//! about z at the origin, so that its inertia about the hinge is
//! `J_O = 1/12 + 0.5² = 1/3 kg·m²`; no gravity.

use super::hinged_body::HingedBody;

/// The panel's model text: `title`, the analysis tables `analysis`, the
/// panel, then the tables `rest` (acting on joint 3).
fn hinged_panel(title: &str, analysis: &str, rest: &str) -> String {
    let panel = HingedBody {
        centre: [0.5, 0.0, 0.0],
        motion: "",
        body: 12,
        mass: 1.0,
        inertia: [0.001, 0.0833333333333333, 0.0833333333333333],
        joint: 3,
    };
    let tables = panel.tables();
    format!(
        r#"title = "{title}"
{analysis}

{tables}

{rest}
"#
    )
}

/// The panel opened from θ = 0 by a torsion spring (id 4) of 2 N·m/rad
/// unloaded at 180° and stopped by a latch (id 5) at `latch` degrees:
/// `θ(t) = π(1 − cos ωt)`, `ω = √(k/J_O)`; then the tables `extra`.
pub fn latched_panel(title: &str, analysis: &str, latch: f64, extra: &str) -> String {
    hinged_panel(
        title,
        analysis,
        &format!(
            r#"[[joint_springs]]
id = 4
joint = 3
stiffness = 2.0
free_value = 3.141592653589793

[[latches]]
id = 5
joint = 3
value = {latch:?}
unit = "deg"
{extra}"#
        ),
    )
}

/// The panel turned by a driver (id 4) of its hinge through 90° along the
/// curve `stroke`, a smooth step from t = 0 to 1 s:
/// `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`.
pub fn driven_hinge(title: &str, analysis: &str) -> String {
    hinged_panel(
        title,
        analysis,
        r#"[[curves]]
name = "stroke"
function = "smooth_step"
start = 0.0
end = 1.0

[[drivers]]
id = 4
joint = 3
value = 90.0
unit = "deg"
curve = "stroke""#,
    )
}
