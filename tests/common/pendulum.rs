//! Rigid pendulums on a revolute joint about z at the origin to node 1,
//! which is fixed, swinging under gravity along −y.
//!
//! The pendulum (tests/dynamics.rs, tests/iteration_matrix.rs,
//! tests/cli_dynamics.rs, tests/cli_events.rs, tests/stops.rs): a body of
//! mass `MASS` (id 1 on node 2) with inertia `INERTIA` about its centre on
//! every axis, its centre at `(DISTANCE, 0, 0)`, released at rest from the
//! horizontal under gravity `G`. Its inertia about the hinge is
//! `I_O = INERTIA + MASS · DISTANCE² = 0.6 kg·m²`.
//!
//! The hanging pendulum (tests/output_interval.rs,
//! tests/cli_start_checks.rs, tests/spurious_steps.rs): a body of 2 kg
//! (id 1 on node 2) with inertia 0.01 kg·m² about its centre on every
//! axis, its centre at (0, −0.5, 0) below the hinge (id 3), under gravity
//! 9.81 m/s²: `J_O = 0.01 + 2 · 0.5² = 0.51 kg·m²`.

use super::hinged_body::HingedBody;

/// Mass of the body (kg).
pub const MASS: f64 = 2.0;
/// Distance of its centre from the hinge (m).
pub const DISTANCE: f64 = 0.5;
/// Inertia about its centre (kg·m²).
pub const INERTIA: f64 = 0.1;
/// Acceleration of gravity (m/s²).
pub const G: f64 = 9.81;

/// The pendulum's model text: `head` (a title and the analysis tables),
/// the pendulum with its hinge of id `joint`, gravity following the curve
/// `gravity_curve` (its default, `ramp` in a dynamic analysis, where
/// `None`), then the tables `extra`.
pub fn pendulum(head: &str, joint: u64, gravity_curve: Option<&str>, extra: &str) -> String {
    let pendulum = HingedBody {
        centre: [DISTANCE, 0.0, 0.0],
        motion: "",
        body: 1,
        mass: MASS,
        inertia: [INERTIA; 3],
        joint,
    };
    swinging(head, &pendulum, gravity_curve, extra)
}

/// The pendulum falling from the horizontal under constant gravity onto
/// a stop (id 8) of its hinge (id 7) at −60° with restitution
/// `restitution`; `head` a title and the analysis tables.
pub fn onto_a_stop(head: &str, restitution: f64) -> String {
    pendulum(
        head,
        7,
        Some("constant"),
        &format!(
            r#"
[[stops]]
id = 8
joint = 7
lower = -60.0
unit = "deg"
restitution = {restitution:?}"#
        ),
    )
}

/// The hanging pendulum's model text: `head` (a title and the analysis
/// tables), the pendulum, the keys `motion` added to its node 2 (an
/// initial velocity), gravity on its default curve, then the tables
/// `extra`.
pub fn hanging(head: &str, motion: &str, extra: &str) -> String {
    let pendulum = HingedBody {
        centre: [0.0, -0.5, 0.0],
        motion,
        body: 1,
        mass: 2.0,
        inertia: [0.01; 3],
        joint: 3,
    };
    swinging(head, &pendulum, None, extra)
}

/// `head`, the body on its hinge, gravity `G` along −y on the curve
/// `gravity_curve` (the default where `None`), then the tables `extra`.
fn swinging(head: &str, body: &HingedBody, gravity_curve: Option<&str>, extra: &str) -> String {
    let tables = body.tables();
    let curve = gravity_curve.map_or(String::new(), |c| format!("curve = \"{c}\"\n"));
    format!(
        r#"{head}

{tables}

[gravity]
acceleration = [0.0, -{G:?}, 0.0]
{curve}{extra}
"#
    )
}
