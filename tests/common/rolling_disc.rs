//! The upright rolling disc (tests/rolling.rs, tests/cli_start_checks.rs;
//! docs/model-format.md, `[[rolling_discs]]`): a disc of radius 0.5 m and
//! mass 1 kg (inertia 1/16, 1/16, 1/8 kg·m² about its axes, its axis of
//! symmetry the node's third, turned 90° about y to lie along x) on
//! node 1 at (0, 0, 0.5), rolling (id 2) on the plane z = 0 along +y at
//! 2 m/s under a constant gravity of 9.81 m/s² along −z.

/// The model text: `head` (a title and the analysis tables), then the
/// disc spinning at `spin` rad/s about the global x axis (−4 rad/s rolls
/// without slipping, other values slip).
pub fn upright_disc(head: &str, spin: f64) -> String {
    format!(
        r#"{head}

[gravity]
acceleration = [0.0, 0.0, -9.81]
curve = "constant"

[[nodes]]
id = 1
x = [0.0, 0.0, 0.5]
rotation = [0.0, 90.0, 0.0]
unit = "deg"
velocity = [0.0, 2.0, 0.0]
angular_velocity = [{spin:?}, 0.0, 0.0]

[[rigid_bodies]]
id = 1
node = 1
mass = 1.0
inertia = [0.0625, 0.0625, 0.125]

[[rolling_discs]]
id = 2
node = 1
radius = 0.5
axis = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, 1.0]
"#
    )
}
