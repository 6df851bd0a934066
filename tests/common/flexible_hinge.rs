//! The flexible hinged panel (tests/latches.rs, tests/energy_balance.rs;
//! docs/theory.md §15.5, `flex_latch`): a boom from node 1, clamped, to
//! node 11 at (1, 0, 0) and a panel from node 12 at the boom's tip to
//! node 22 at (2, 0, 0), each a line of beams of the section `rod` of a
//! 1 m steel-like rod, the panel on a revolute joint (id 1) about z to the
//! boom's tip, opened from the boom's line by a torsion spring (id 2;
//! 2 N·m/rad, free at 180°) and latched at 90° (id 3); no gravity.

/// The `[[sections]]` table of the rod, `rod`, with the keys `extra`
/// (damping) after its mass per length.
pub fn rod_section(extra: &str) -> String {
    format!(
        r#"[[sections]]
name = "rod"
EA = 2.2e7
GA2 = 7.35e6
GA3 = 7.35e6
GJ = 408.0
EI2 = 550.0
EI3 = 550.0
mass_per_length = 0.848
{extra}inertia_per_length = [4.24e-5, 2.12e-5, 2.12e-5]"#
    )
}

/// The model text: the analysis tables `analysis`, then the boom and the
/// panel of `elements` beams each, of the rod's section with the keys
/// `section_extra`.
pub fn flexible_hinge(analysis: &str, elements: usize, section_extra: &str) -> String {
    let section = rod_section(section_extra);
    format!(
        r#"
{analysis}

{section}

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
[[nodes]]
id = 11
x = [1.0, 0.0, 0.0]
[[nodes]]
id = 12
x = [1.0, 0.0, 0.0]
[[nodes]]
id = 22
x = [2.0, 0.0, 0.0]

[[beam_lines]]
nodes = [1, 11]
elements = {elements}
section = "rod"
orientation = [0.0, 1.0, 0.0]
first_node = 2
first_element = 101
[[beam_lines]]
nodes = [12, 22]
elements = {elements}
section = "rod"
orientation = [0.0, 1.0, 0.0]
first_node = 13
first_element = 201

[[supports]]
node = 1
fixed = ["all"]

[[joints]]
id = 1
type = "revolute"
nodes = [11, 12]
axis = [0.0, 0.0, 1.0]

[[joint_springs]]
id = 2
joint = 1
stiffness = 2.0
free_value = 3.141592653589793

[[latches]]
id = 3
joint = 1
value = 1.5707963267948966
"#
    )
}
