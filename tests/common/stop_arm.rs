//! The flexible arm on a plastic stop of tests/stop_closure.rs and
//! tests/stop_rest.rs: a tube of 0.2 m in 4 beams (EI = 297 N·m²,
//! 0.0955 kg/m, a tip mass of 0.01 kg), hinged about z at its root and
//! opened from rest by a torsion spring of 0.2 N·m/rad unloaded at 3 rad
//! (work `½ k (3² − 1²) = 0.8 J` up to 2 rad), stopped at 2 rad by a
//! plastic stop (`restitution = 0`) on its hinge.

/// The spring's work up to the stop, `½ k (3² − 1²)` (J).
pub const WORK: f64 = 0.5 * 0.2 * (3.0 * 3.0 - 1.0);

/// The model text: the analysis table `analysis`, the arm, and with
/// `gravity` a gravity of that many m/s² along y, in the plane of the
/// motion.
pub fn arm(analysis: &str, gravity: Option<f64>) -> String {
    let gravity = match gravity {
        Some(g) => format!("\n[gravity]\nacceleration = [0.0, {g:?}, 0.0]\ncurve = \"constant\"\n"),
        None => String::new(),
    };
    format!(
        r#"title = "arm opened by a spring onto a plastic stop"
{analysis}
[[sections]]
name = "tube"
EA = 6.57e6
GA2 = 3.58e5
GA3 = 3.58e5
GJ = 64.8
EI2 = 297.0
EI3 = 297.0
mass_per_length = 0.0955
inertia_per_length = [8.64e-6, 4.32e-6, 4.32e-6]

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[supports]]
node = 1
fixed = ["all"]

[[nodes]]
id = 2
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 3
x = [0.2, 0.0, 0.0]

[[beam_lines]]
nodes = [2, 3]
elements = 4
section = "tube"
orientation = [0.0, 0.0, 1.0]
first_node = 100
first_element = 100

[[point_masses]]
id = 150
node = 3
mass = 0.01

[[joints]]
id = 4
type = "revolute"
nodes = [1, 2]
axis = [0.0, 0.0, 1.0]

[[joint_springs]]
id = 5
joint = 4
stiffness = 0.2
free_value = 3.0

[[stops]]
id = 6
joint = 4
upper = 2.0
restitution = 0.0

{gravity}"#
    )
}
