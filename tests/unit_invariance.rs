//! Results that do not depend on the units chosen: the same models in SI
//! (m, kg, s) and in mm, g, s (lengths × 1e3, masses × 1e3, so forces ×
//! 1e6, moments × 1e9), run through the command line.
//!
//! Each model is written once with its unit factors `L` (length) and `M`
//! (mass); a result in the second system must be the first times its
//! dimension, and counts (modes, steps, impacts) must be the same.

mod common;

use common::cli::{column, run_text, scratch, summary, unfold};

/// mm, g, s against m, kg, s.
const MM: (f64, f64) = (1e3, 1e3);
const SI: (f64, f64) = (1.0, 1.0);

/// A rigid rod of 1 m and 1 kg (inertia m L²/12 about its centre) hanging
/// from a hinge about z at the origin, its centre 0.5 m below, under
/// g = 9.81 m/s² along −y, with a torsion spring of 2 N·m/rad on the
/// hinge: a dynamic analysis (at rest, so it stays there), a static one,
/// then the modes.
fn hanging_pendulum((l, m): (f64, f64)) -> String {
    let inertia = m * l * l / 12.0;
    format!(
        r#"
title = "hanging pendulum"

[[analysis]]
type = "dynamic"
end_time = 0.5
time_step = 0.01

[[analysis]]
type = "static"
end_time = 1.0

[[analysis]]
type = "modal"
modes = 4

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [0.0, {y:?}, 0.0]

[[supports]]
node = 1
fixed = ["all"]

[[rigid_bodies]]
id = 1
node = 2
mass = {m:?}
inertia = [{inertia:?}, {small:?}, {inertia:?}]

[[joints]]
id = 3
type = "revolute"
nodes = [1, 2]
axis = [0.0, 0.0, 1.0]
position = [0.0, 0.0, 0.0]

[[joint_springs]]
id = 5
joint = 3
stiffness = {k:?}

[gravity]
acceleration = [0.0, {g:?}, 0.0]
"#,
        y = -0.5 * l,
        small = 1e-4 * m * l * l,
        k = 2.0 * m * l * l,
        g = -9.81 * l,
    )
}

/// Reported before: 3 modes in mm, g, s, two of them at ω² = 1/mass along
/// the directions the hinge constrains (its constraint rows were scaled
/// with k = 1 against a rotational stiffness of 1e9 and were taken as
/// dependent); 1 mode in SI.
#[test]
fn a_pendulum_has_the_same_modes_in_mm_g_s_as_in_si() {
    let mut frequencies = Vec::new();
    for (name, units) in [("si", SI), ("mm", MM)] {
        let dir = scratch("units", &format!("pendulum-{name}"));
        let (out, _) = run_text(&dir, &hanging_pendulum(units));
        let f = column(&out.join("modes.csv"), "frequency_hz");
        assert_eq!(f.len(), 1, "{name}: one mode (the swing), got {f:?}");
        let mass_x = column(&out.join("modes.csv"), "effective_mass_x")[0];
        let mass_y = column(&out.join("modes.csv"), "effective_mass_y")[0];
        // the swing about the bottom moves the rod's centre along x only:
        // no effective mass along the hinge's constrained y
        assert!(mass_y.abs() < 1e-9 * units.1, "{name}: {mass_y}");
        assert!(mass_x > 0.5 * units.1, "{name}: {mass_x}");
        frequencies.push(f[0]);
    }
    // ω² = (m g d + k)/J_hinge, J_hinge = m L²/12 + m d² = 1/3 kg·m²,
    // m g d = 4.905 N·m: ω² = 20.715 rad²/s² (small oscillations about
    // the bottom); the static state is exact to its tolerance 1e-8, so
    // 1e-8 relative
    let exact = (3.0f64 * (9.81 * 0.5 + 2.0)).sqrt() / (2.0 * std::f64::consts::PI);
    for f in &frequencies {
        assert!((f / exact - 1.0).abs() < 1e-8, "{f} against {exact}");
    }
    // the same to round-off in both systems (a frequency has no length or
    // mass in it)
    assert!(
        (frequencies[0] / frequencies[1] - 1.0).abs() < 1e-12,
        "{frequencies:?}"
    );
}

/// A point mass of 2 kg on a prismatic joint along −y to the ground,
/// falling under gravity onto a stop 0.2 m down (restitution 0.5): it
/// bounces to rest. A model of one node, whose size was taken as 1 in any
/// units, so that the stop's landing tolerance 1e-8 of the size was 1e-8 m
/// in SI and 1e-8 mm in mm: 59 steps against 102.
fn ball_on_stop((l, m): (f64, f64)) -> String {
    format!(
        r#"
title = "ball on a prismatic stop"

[analysis]
type = "dynamic"
end_time = 1.0
time_step = 0.01

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[point_masses]]
id = 1
node = 1
mass = {m:?}

[[joints]]
id = 2
type = "prismatic"
nodes = [1]
axis = [0.0, -1.0, 0.0]

[[stops]]
id = 3
joint = 2
upper = {upper:?}
restitution = 0.5

[gravity]
acceleration = [0.0, {g:?}, 0.0]
"#,
        m = 2.0 * m,
        upper = 0.2 * l,
        g = -9.81 * l,
    )
}

#[test]
fn a_ball_on_a_stop_takes_the_same_steps_in_mm_as_in_m() {
    let mut runs = Vec::new();
    for (name, units) in [("si", SI), ("mm", MM)] {
        let dir = scratch("units", &format!("ball-{name}"));
        let (out, _) = run_text(&dir, &ball_on_stop(units));
        let s = summary(&out);
        let d = &s["analyses"][0]["dynamic"];
        let stroke = column(&out.join("joints.csv"), "slide");
        runs.push((
            d["steps"].as_u64().unwrap(),
            d["impacts"].as_u64().unwrap(),
            *stroke.last().unwrap() / units.0,
        ));
    }
    // the same steps and impacts: the size of a one-node model is its own
    // length (here the stop's 0.2 m), in its own units
    assert_eq!(runs[0].0, runs[1].0, "{runs:?}");
    assert_eq!(runs[0].1, runs[1].1, "{runs:?}");
    // at rest on the stop at the end, 0.2 m down, within the landing
    // tolerance 1e-8 of the size
    for r in &runs {
        assert!((r.2 - 0.2).abs() < 1e-8, "{runs:?}");
    }
}

/// A tape-spring hinge law in kN·mm-like magnitudes (the N·m law of
/// docs/model-format.md scaled by 1e-3 in moment): accepted, as it is in
/// N·m. It was refused by round-off: "f_load = 0.005200 < f_unload =
/// 0.005200" beyond the lock, where both bounds follow one line.
#[test]
fn a_tape_spring_law_in_small_units_is_accepted() {
    let dir = scratch("units", "tape-spring");
    let model = dir.join("model.toml");
    let text = format!(
        r#"
[analysis]
type = "dynamic"
end_time = 0.01

{}

[[hinge_laws]]
id = 4
joint = 3
elastic_slope = 0.01
tape_spring = {{ deployment_moment = 3e-4, locking_angle = 1.5, locking_peak = 0.01, locked_stiffness = 0.005, snap_width = 0.1 }}
"#,
        body_on_hinge()
    );
    std::fs::write(&model, text).unwrap();
    let o = unfold(&["check", model.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(!err.contains("loading bound"), "{err}");
}

fn body_on_hinge() -> &'static str {
    r#"
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [0.5, 0.0, 0.0]

[[supports]]
node = 1
fixed = ["all"]

[[rigid_bodies]]
id = 1
node = 2
mass = 1.0
inertia = [1e-4, 0.08333333333333333, 0.08333333333333333]

[[joints]]
id = 3
type = "revolute"
nodes = [1, 2]
axis = [0.0, 0.0, 1.0]
position = [0.0, 0.0, 0.0]
"#
}
