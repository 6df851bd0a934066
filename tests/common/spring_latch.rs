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

/// The panel spinning into a spring latch: the latch's stiffness
/// (N·m/rad), the dead band of the rattle (rad), the panel's initial rate
/// (rad/s) and the locking value (rad).
pub const K_RATTLE: f64 = 300.0;
pub const BACKLASH: f64 = 0.1;
pub const OMEGA_0: f64 = 2.0;
pub const THETA_R: f64 = 0.5;

/// The panel spinning freely at `OMEGA_0` (no spring, no load) into a
/// spring latch (id 20) of stiffness `K_RATTLE` at `THETA_R`, with the
/// latch's keys `latch` (its dead band `BACKLASH` for the rattle, its side
/// or its damping), then `extra` entries.
pub fn spinning_into_latch(analysis: &str, latch: &str, extra: &str) -> String {
    panel(
        analysis,
        &format!(
            r#"
[[initial_motion]]
nodes = [2]
angular_velocity = [0.0, 0.0, {OMEGA_0}]

[[latches]]
id = 20
joint = 10
value = {THETA_R}
mode = "spring"
stiffness = {K_RATTLE}
{latch}
{extra}"#
        ),
    )
}

/// The release: the latch's stiffness (N·m/rad), the rate of the moment
/// ramp (N·m/s) and the unlatch load (N·m).
pub const K_HOLD: f64 = 100.0;
pub const RAMP: f64 = 2.0;
pub const UNLATCH: f64 = 1.0;

/// The release: the panel, latched at 0 from the start (a latch, id 20,
/// of stiffness `K_HOLD` approached increasing), under the moment
/// `RAMP t` about z until the latch's load reaches `UNLATCH`; `extra`
/// more entries.
pub fn ramp_release(analysis: &str, extra: &str) -> String {
    panel(
        analysis,
        &format!(
            r#"
[[loads]]
node = 2
moment = [0.0, 0.0, {RAMP}]
curve = "ramp"

[[latches]]
id = 20
joint = 10
value = 0.0
approach = "increasing"
mode = "spring"
stiffness = {K_HOLD}
unlatch_load = {UNLATCH}
{extra}"#
        ),
    )
}
