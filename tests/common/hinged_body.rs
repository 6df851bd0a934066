//! A rigid body on a ground hinge, the part that the hinged fixtures
//! (tests/common/hinged_panel.rs, spring_latch.rs, pendulum.rs) share:
//! node 1 at the origin, fixed; the body on node 2 at its centre; a
//! revolute joint about z at the origin between them.

/// The body and its hinge.
pub struct HingedBody<'a> {
    /// The body's centre, node 2 (m).
    pub centre: [f64; 3],
    /// Keys added to node 2 (an initial velocity), or nothing.
    pub motion: &'a str,
    /// The id of the rigid body.
    pub body: u64,
    /// Its mass (kg).
    pub mass: f64,
    /// Its principal inertias about its centre (kg·m²).
    pub inertia: [f64; 3],
    /// The id of the revolute joint.
    pub joint: u64,
}

impl HingedBody<'_> {
    /// The nodes, support, rigid body and joint tables.
    pub fn tables(&self) -> String {
        let Self {
            centre,
            motion,
            body,
            mass,
            inertia,
            joint,
        } = self;
        format!(
            r#"[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = {centre:?}
{motion}

[[supports]]
node = 1
fixed = ["all"]

[[rigid_bodies]]
id = {body}
node = 2
mass = {mass:?}
inertia = {inertia:?}

[[joints]]
id = {joint}
type = "revolute"
nodes = [1, 2]
axis = [0.0, 0.0, 1.0]
position = [0.0, 0.0, 0.0]"#
        )
    }
}
