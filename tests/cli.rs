//! The command-line tool: bad input gets a clear message naming the file,
//! the entity and the problem, with exit code 2; an analysis that fails
//! stops cleanly with exit code 1 and keeps the results written so far.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `unfold` with `args`, returning (exit code, stdout, stderr).
fn unfold(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A valid two-element cantilever; `edit` changes its text.
const CANTILEVER: &str = r#"
title = "two-element cantilever"

[[sections]]
name = "s"
EA = 1.0e7
GA2 = 4.0e6
GA3 = 4.0e6
GJ = 1.0e3
EI2 = 1.0e3
EI3 = 1.0e3

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [0.5, 0.0, 0.0]

[[nodes]]
id = 3
x = [1.0, 0.0, 0.0]

[[beams]]
id = 1
nodes = [1, 2]
section = "s"

[[beams]]
id = 2
nodes = [2, 3]
section = "s"

[[supports]]
node = 1
fixed = ["all"]

[[loads]]
node = 3
force = [0.0, 0.0, -1.0]
"#;

/// Writes `text` as `name` in `dir` and runs `unfold run` on it.
fn run_model(dir: &Path, name: &str, text: &str) -> (i32, String, String) {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    unfold(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

/// Asserts a bad-input rejection: exit code 2, and a message on stderr
/// that names the file and contains every fragment.
fn assert_rejected(name: &str, text: &str, fragments: &[&str]) {
    let dir = scratch(name);
    let file = format!("{name}.toml");
    let (code, _, err) = run_model(&dir, &file, text);
    assert_eq!(code, 2, "{name}: exit code {code}, stderr: {err}");
    assert!(
        err.contains(&file),
        "{name}: the message does not name the file: {err}"
    );
    for f in fragments {
        assert!(err.contains(f), "{name}: message lacks «{f}»: {err}");
    }
    assert!(!err.contains("panicked"), "{name}: panic: {err}");
}

#[test]
fn valid_model_runs_and_checks() {
    let dir = scratch("valid");
    let (code, out, err) = run_model(&dir, "ok.toml", CANTILEVER);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("completed"), "{out}");
    let (code, out, _) = unfold(&["check", dir.join("ok.toml").to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(
        out.contains("valid model") && out.contains("12 unknowns"),
        "{out}"
    );
}

#[test]
fn unknown_node() {
    let text = CANTILEVER.replace("nodes = [2, 3]", "nodes = [2, 99]");
    assert_rejected("unknown_node", &text, &["beam 2", "node 99 does not exist"]);
}

#[test]
fn duplicate_id() {
    let text = CANTILEVER.replace("id = 3\nx = [1.0, 0.0, 0.0]", "id = 2\nx = [1.0, 0.0, 0.0]");
    assert_rejected("duplicate_node", &text, &["node 2", "duplicate node id"]);
    let text = CANTILEVER.replace("id = 2\nnodes = [2, 3]", "id = 1\nnodes = [2, 3]");
    assert_rejected(
        "duplicate_element",
        &text,
        // the element that holds the id already is named
        &["beam 1", "duplicate element id: beam 1 has id 1 already"],
    );
}

#[test]
fn zero_length_beam() {
    let text = CANTILEVER.replace("x = [1.0, 0.0, 0.0]", "x = [0.5, 0.0, 0.0]");
    assert_rejected(
        "zero_length",
        &text,
        &["beam 2", "zero length", "nodes 2 and 3 coincide"],
    );
}

#[test]
fn non_positive_stiffness_and_mass() {
    let text = CANTILEVER.replace("EA = 1.0e7", "EA = -1.0e7");
    assert_rejected(
        "negative_stiffness",
        &text,
        &["section \"s\"", "EA must be positive"],
    );
    let text = format!("{CANTILEVER}\n[[point_masses]]\nid = 10\nnode = 3\nmass = 0.0\n");
    assert_rejected(
        "zero_mass",
        &text,
        &["point mass 10", "mass must be positive"],
    );
    let text = format!(
        "{CANTILEVER}\n[[springs]]\nid = 11\nkind = \"axial\"\nnodes = [1, 3]\nstiffness = -5.0\n"
    );
    assert_rejected(
        "negative_spring",
        &text,
        &["spring 11", "stiffness must be positive"],
    );
}

#[test]
fn missing_section() {
    let text = CANTILEVER.replace(
        "section = \"s\"\n\n[[beams]]\nid = 2",
        "section = \"tube\"\n\n[[beams]]\nid = 2",
    );
    assert_rejected(
        "missing_section",
        &text,
        &["beam 1", "section \"tube\" is not defined"],
    );
    let text = CANTILEVER.replace("EI3 = 1.0e3\n", "");
    assert_rejected(
        "incomplete_section",
        &text,
        &["section \"s\"", "missing EI3"],
    );
}

#[test]
fn unknown_field() {
    let text = CANTILEVER.replace("EA = 1.0e7", "EAA = 1.0e7");
    // the parser names the field and the line
    assert_rejected("unknown_field", &text, &["unknown field `EAA`", "line 6"]);
}

/// Schema errors in the words of a model file, not of the reader's
/// language: a number written in quotes, a missing required key.
#[test]
fn schema_errors_speak_of_the_model_file() {
    let text = CANTILEVER.replace("EA = 1.0e7", "EA = \"1.0e7\"");
    assert_rejected(
        "quoted_number",
        &text,
        &[
            "line 6",
            "expected a number",
            "\"1.0e7\" is a string: write numbers without quotes",
        ],
    );
    let (_, _, err) = check_model("quoted_number_check", &text);
    assert!(
        !err.contains("f64") && !err.contains("TOML parse error"),
        "{err}"
    );
    let text = CANTILEVER.replace("id = 2\nx = [0.5", "x = [0.5");
    assert_rejected(
        "missing_id",
        &text,
        &["the required key `id` is missing from this table"],
    );
}

#[test]
fn malformed_file_and_missing_file() {
    assert_rejected(
        "malformed",
        "[[nodes]\nid = 1",
        &["TOML syntax error at line 1"],
    );
    let (code, _, err) = unfold(&["run", "/nonexistent/model.toml"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("/nonexistent/model.toml") && err.contains("cannot read"),
        "{err}"
    );
}

#[test]
fn unrestrained_structure_is_detected_before_running() {
    let text = CANTILEVER.replace("[[supports]]\nnode = 1\nfixed = [\"all\"]\n", "");
    assert_rejected(
        "free_body",
        &text,
        &[
            "nodes 1, 2, 3",
            "free body",
            "unrestrained rigid-body motion",
        ],
    );
}

#[test]
fn mechanism_is_reported_as_singular_with_its_dof() {
    // pinned instead of clamped: the beam can turn about node 1; the
    // tangent is factored once before the analysis starts, so this is
    // caught at t = 0 as invalid input
    let dir = scratch("mechanism");
    let text = CANTILEVER.replace("fixed = [\"all\"]", "fixed = [\"translations\"]");
    let (code, _, err) = run_model(&dir, "pinned.toml", &text);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("pinned.toml"), "{err}");
    assert!(
        err.contains("singular tangent") && err.contains("mechanism"),
        "{err}"
    );
    assert!(err.contains("node "), "the message names no node: {err}");
    let summary = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
    assert!(summary.contains("\"status\": \"failed\""), "{summary}");
}

#[test]
fn bad_values_in_analysis_and_supports() {
    let text = format!("{CANTILEVER}\n[analysis]\ntype = \"transient\"\nend_time = -1.0\n");
    assert_rejected(
        "bad_analysis",
        &text,
        &[
            "analysis",
            "unknown analysis type \"transient\"",
            "end_time must be positive",
        ],
    );
    let text = CANTILEVER.replace("fixed = [\"all\"]", "fixed = [\"everything\"]");
    assert_rejected(
        "bad_support",
        &text,
        &["supports[1] (node 1)", "unknown component \"everything\""],
    );
    let text = CANTILEVER.replace(
        "[[loads]]\nnode = 3",
        "[[loads]]\nnode = 3\ncurve = \"missing\"",
    );
    assert_rejected(
        "bad_curve",
        &text,
        &["loads[1] (node 3)", "curve \"missing\" is not defined"],
    );
}

#[test]
fn divergence_stops_cleanly_and_keeps_results() {
    // a tip force bending the beam further than three Newton iterations
    // per increment can follow, with a coarse minimum increment: the first
    // increments converge, then the run must stop, say where, and keep them
    let dir = scratch("diverge");
    let text = CANTILEVER.replace("force = [0.0, 0.0, -1.0]", "force = [0.0, 0.0, -5.0e3]")
        + "\n[analysis]\ninitial_increment = 0.05\nmax_iterations = 3\nmin_increment = 0.01\n";
    let (code, out, err) = run_model(&dir, "diverge.toml", &text);
    assert_eq!(code, 1, "stdout {out}\nstderr {err}");
    assert!(
        err.contains("diverge.toml") && err.contains("no convergence at increment"),
        "{err}"
    );
    assert!(
        err.contains("from t = ") && err.contains("no convergence in 3 iterations"),
        "{err}"
    );
    assert!(err.contains("results up to t ="), "{err}");
    let summary: String = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
    assert!(summary.contains("\"status\": \"failed\""));
    // the converged steps are in the CSV and the PVD
    let steps = std::fs::read_to_string(dir.join("out/steps.csv")).unwrap();
    assert!(steps.lines().count() >= 4, "{steps}");
    let pvd = std::fs::read_to_string(dir.join("out/unfold.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), steps.lines().count() - 1);
}

#[test]
fn other_inconsistencies_are_named() {
    let text = CANTILEVER.replace(
        "section = \"s\"\n\n[[beams]]\nid = 2",
        "section = \"s\"\norientation = [2.0, 0.0, 0.0]\n\n[[beams]]\nid = 2",
    );
    assert_rejected(
        "parallel_orientation",
        &text,
        &["beam 1", "parallel to the beam axis"],
    );
    let text = format!("{CANTILEVER}\n[[rigid_bodies]]\nid = 10\nnode = 3\nmass = 1.0\ninertia = [1.0, -2.0, 1.0]\n");
    assert_rejected(
        "bad_inertia",
        &text,
        &["rigid body 10", "positive semi-definite"],
    );
    let text = format!(
        "{CANTILEVER}\n[[springs]]\nid = 11\nkind = \"axial\"\nnodes = [3]\nstiffness = 5.0\n"
    );
    assert_rejected("axial_to_ground", &text, &["spring 11", "needs two nodes"]);
    let text = format!("{CANTILEVER}\n[[nodes]]\nid = 7\nx = [3.0, 0.0, 0.0]\n");
    assert_rejected("lonely_node", &text, &["node 7", "not connected"]);
    let text = format!(
        "{CANTILEVER}\n[[curves]]\nname = \"c\"\npoints = [[0.0, 0.0], [1.0, 1.0], [0.5, 2.0]]\n"
    );
    assert_rejected(
        "bad_curve_points",
        &text,
        &["curve \"c\"", "increase strictly"],
    );
    let text = format!("{CANTILEVER}\n[[prescribed]]\nnode = 3\ndof = \"x\"\nvalue = 0.1\nrotation = [0.0, 0.0, 1.0]\n");
    assert_rejected(
        "bad_prescribed",
        &text,
        &["prescribed[1] (node 3)", "either `dof` and `value`"],
    );
    let text = format!("{CANTILEVER}\n[[beam_lines]]\nnodes = [1, 3]\nelements = 2\nsection = \"s\"\narc_center = [0.5, 5.0, 0.0]\nfirst_node = 50\nfirst_element = 50\n");
    let text = text.replace("x = [1.0, 0.0, 0.0]", "x = [1.0, 0.1, 0.0]");
    assert_rejected("bad_arc", &text, &["beam_lines[1]", "not equidistant"]);
    let text = CANTILEVER.replace(
        "[[beams]]\nid = 2\nnodes = [2, 3]",
        "[[beams]]\nid = 2\nnodes = [2, 2]",
    );
    assert_rejected("self_beam", &text, &["beam 2", "both ends are node 2"]);
}

/// A hinged link: the cantilever's tip joined to a rigid link (node 4) by a
/// revolute joint about y.
fn hinged(extra: &str) -> String {
    format!(
        "{CANTILEVER}\n[[nodes]]\nid = 4\nx = [1.0, 0.0, 0.0]\n\n[[rigid_bodies]]\nid = 20\nnode = 4\nmass = 1.0\ninertia = [0.01, 0.01, 0.01]\n\n{extra}"
    )
}

#[test]
fn bad_joint_definitions() {
    let joint = |body: &str| hinged(&format!("[[joints]]\nid = 30\n{body}\n"));
    assert_rejected(
        "joint_unknown_node",
        &joint("type = \"revolute\"\nnodes = [3, 44]\naxis = [0, 1, 0]"),
        &["joint 30", "node 44 does not exist"],
    );
    assert_rejected(
        "joint_self",
        &joint("type = \"revolute\"\nnodes = [3, 3]\naxis = [0, 1, 0]"),
        &["joint 30", "joins node 3 to itself"],
    );
    assert_rejected(
        "joint_axes_not_coincident",
        &joint("type = \"revolute\"\nnodes = [3, 4]\naxis = [0, 1, 0]\naxis_b = [0, 0.8, 0.6]"),
        &["joint 30", "axes of the revolute joint must coincide"],
    );
    assert_rejected(
        "joint_missing_axis",
        &joint("type = \"revolute\"\nnodes = [3, 4]"),
        &["joint 30", "needs `axis`"],
    );
    assert_rejected(
        "joint_zero_axis",
        &joint("type = \"prismatic\"\nnodes = [3, 4]\naxis = [0, 0, 0]"),
        &["joint 30", "axis must be a non-zero finite vector"],
    );
    assert_rejected(
        "helical_without_pitch",
        &joint("type = \"helical\"\nnodes = [3, 4]\naxis = [1, 0, 0]"),
        &["joint 30", "needs `pitch`"],
    );
    assert_rejected(
        "universal_arms",
        &joint("type = \"universal\"\nnodes = [3, 4]\naxis = [0, 1, 0]\naxis_b = [0, 1, 0.1]"),
        &["joint 30", "must be perpendicular"],
    );
    assert_rejected(
        "unknown_joint_type",
        &joint("type = \"hinge\"\nnodes = [3, 4]\naxis = [0, 1, 0]"),
        &["unknown variant `hinge`"],
    );
    let ok = "type = \"revolute\"\nnodes = [3, 4]\naxis = [0, 1, 0]";
    assert_rejected(
        "spring_on_missing_joint",
        &joint(&format!(
            "{ok}\n\n[[joint_springs]]\nid = 31\njoint = 99\nstiffness = 1.0"
        )),
        &["joint spring 31", "joint 99 does not exist"],
    );
    assert_rejected(
        "spring_negative",
        &joint(&format!(
            "{ok}\n\n[[joint_springs]]\nid = 31\njoint = 30\nstiffness = -1.0"
        )),
        &["joint spring 31", "stiffness must be zero or positive"],
    );
    assert_rejected(
        "spring_bad_coordinate",
        &joint(&format!("{ok}\n\n[[joint_springs]]\nid = 31\njoint = 30\ncoordinate = \"slide\"\nstiffness = 1.0")),
        &["joint spring 31", "has no coordinate \"slide\"", "angle"],
    );
    assert_rejected(
        "spring_table_not_increasing",
        &joint(&format!(
            "{ok}\n\n[[joint_springs]]\nid = 31\njoint = 30\ntable = [[0.0, 0.0], [0.0, 1.0]]"
        )),
        &["joint spring 31", "strictly increasing"],
    );
    assert_rejected(
        "driver_both_targets",
        &joint(&format!(
            "{ok}\n\n[[drivers]]\nid = 32\njoint = 30\nnode = 4\nvalue = 1.0"
        )),
        &["driver 32", "give either `joint`"],
    );
    assert_rejected(
        "driver_node_without_direction",
        &joint(&format!(
            "{ok}\n\n[[drivers]]\nid = 32\nnode = 4\nvalue = 1.0"
        )),
        &["driver 32", "needs `direction`"],
    );
}

/// The hinged link is a mechanism without a spring or a driver: a static
/// analysis reports the singular tangent at the start (exit code 2); a
/// kinematic analysis with no driver reports the free motion; with a
/// driver on the hinge it runs.
#[test]
fn mechanism_without_driver_is_reported() {
    let ok = "[[joints]]\nid = 30\ntype = \"revolute\"\nnodes = [3, 4]\naxis = [0, 1, 0]\n";
    let (_, _, err) = {
        let dir = scratch("free_hinge");
        run_model(&dir, "free_hinge.toml", &hinged(ok))
    };
    assert!(err.contains("singular tangent"), "{err}");
    // the free motion is the hinge's: the message names its joint, not
    // only the unknown of the smallest pivot
    assert!(
        err.contains("in a free motion that moves joint 30"),
        "{err}"
    );

    // a kinematic analysis of the rigid link alone, hinged to the ground
    let link = "[analysis]\ntype = \"kinematic\"\n\n[[nodes]]\nid = 1\nx = [0.0, 0.0, 0.0]\n\n[[joints]]\nid = 1\ntype = \"revolute\"\nnodes = [1]\naxis = [0, 0, 1]\n";
    assert_rejected(
        "kinematic_free",
        link,
        &[
            "do not make the mechanism determinate",
            "1 motion(s) are left free",
            "node 1 rz",
        ],
    );
    let dir = scratch("kinematic_driven");
    let driven = format!("{link}\n[[drivers]]\nid = 2\njoint = 1\nvalue = 1.0\n");
    let (code, out, err) = run_model(&dir, "driven.toml", &driven);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("completed"), "{out}");
    let drivers = std::fs::read_to_string(dir.join("out").join("drivers.csv")).unwrap();
    let last = drivers.lines().last().unwrap();
    // the link turned by the driven 1 rad
    assert!(last.contains(",2,1.000000000e0,1.000000000e0,"), "{last}");
}

#[test]
fn bad_function_curves() {
    let curve = |body: &str| format!("{CANTILEVER}\n[[curves]]\nname = \"c\"\n{body}\n");
    assert_rejected(
        "curve_unknown_function",
        &curve("function = \"cosine\""),
        &["curve \"c\"", "unknown function \"cosine\""],
    );
    assert_rejected(
        "sine_without_frequency",
        &curve("function = \"sine\"\namplitude = 2.0"),
        &["curve \"c\"", "needs `frequency`"],
    );
    assert_rejected(
        "step_backwards",
        &curve("function = \"smooth_step\"\nstart = 2.0\nend = 1.0"),
        &["curve \"c\"", "start must be before end"],
    );
    assert_rejected(
        "function_and_points",
        &curve("function = \"linear\"\npoints = [[0.0, 0.0], [1.0, 1.0]]"),
        &["curve \"c\"", "either points or a function"],
    );
    assert_rejected(
        "misplaced_parameter",
        &curve("function = \"linear\"\nfrequency = 3.0"),
        &[
            "curve \"c\"",
            "`frequency` does not apply to a linear curve",
        ],
    );
}

/// A point mass m = 2 kg at L = 1 m from a hinge about z, in gravity
/// g = 9.81 m/s² along −y, turned by a driver through `value` (in `unit`
/// when given): `extra` is appended (analysis settings).
fn pendulum(value: &str, unit: Option<&str>, extra: &str) -> String {
    let unit = unit.map_or(String::new(), |u| format!("unit = \"{u}\"\n"));
    format!(
        "[[nodes]]\nid = 2\nx = [1.0, 0.0, 0.0]\n\n[[joints]]\nid = 1\ntype = \"revolute\"\nnodes = [2]\naxis = [0.0, 0.0, 1.0]\nposition = [0.0, 0.0, 0.0]\n\n[[point_masses]]\nid = 2\nnode = 2\nmass = 2.0\n\n[gravity]\nacceleration = [0.0, -9.81, 0.0]\n\n[[drivers]]\nid = 3\njoint = 1\nvalue = {value}\n{unit}\n{extra}"
    )
}

/// Rows of drivers.csv as (time, coordinate, load).
fn driver_rows(dir: &Path) -> Vec<(f64, f64, f64)> {
    std::fs::read_to_string(dir.join("out/drivers.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<f64> = l
                .split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect();
            (c[1], c[3], c[5])
        })
        .collect()
}

/// In a kinematic analysis the gravity (and every load) acts in full by
/// default: the driver torque of the pendulum at 45° is the static moment
/// m g L sin 45° = 13.873 N·m (it was half of it, 6.94 N·m, when gravity
/// followed the default ramp). Tolerance 1e-6 relative: the constraint
/// and residual tolerances are 1e-6 and 1e-8. `check` and `run` say which
/// curve each load follows; a kinematic analysis that ramps gravity, and a
/// static one whose gravity follows the default ramp while drivers move
/// the model, are warned about.
#[test]
fn load_history_is_explicit_and_visible() {
    let dir = scratch("pendulum");
    let text = pendulum(
        "1.5707963267948966",
        None,
        "[analysis]\ntype = \"kinematic\"\n",
    );
    let (code, out, err) = run_model(&dir, "pendulum.toml", &text);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    assert!(
        out.contains("load history: curve \"constant\" (f = 1) is followed by gravity (default)"),
        "{out}"
    );
    assert!(
        out.contains("load history: curve \"ramp\" (f = t) is followed by driver 3 (default)"),
        "{out}"
    );
    let rows = driver_rows(&dir);
    let (_, angle, load) = rows[5];
    assert!(
        (angle - std::f64::consts::FRAC_PI_4).abs() < 1e-9,
        "{rows:?}"
    );
    let expected = 2.0 * 9.81 * 1.0 * std::f64::consts::FRAC_PI_4.sin();
    assert!(
        (load - expected).abs() < 1e-6 * expected,
        "{load} vs {expected}"
    );
    let (code, out, _) = unfold(&["check", dir.join("pendulum.toml").to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(out.contains("is followed by gravity (default)"), "{out}");

    // an explicit ramp on gravity in a kinematic analysis: kept, warned
    let ramped = text.replace(
        "acceleration = [0.0, -9.81, 0.0]\n",
        "acceleration = [0.0, -9.81, 0.0]\ncurve = \"ramp\"\n",
    );
    let (code, _, err) = run_model(&dir, "ramped.toml", &ramped);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: ")
            && err.contains("ramped.toml: gravity: follows curve \"ramp\" in a kinematic analysis"),
        "{err}"
    );
    let (_, _, load) = driver_rows(&dir)[5];
    assert!((load - expected / 2.0).abs() < 1e-6 * expected, "{load}");

    // statics: gravity follows the ramp by default, with a warning when
    // drivers move the model; `curve = "constant"` is the built-in f = 1
    let statics = pendulum("1.5707963267948966", None, "");
    let (code, out, err) = run_model(&dir, "static.toml", &statics);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("static.toml: gravity: follows the default ramp"),
        "{err}"
    );
    assert!(
        out.contains("is followed by driver 3 (default), gravity (default)"),
        "{out}"
    );
    let constant = statics.replace(
        "acceleration = [0.0, -9.81, 0.0]\n",
        "acceleration = [0.0, -9.81, 0.0]\ncurve = \"constant\"\n",
    );
    let (code, _, err) = run_model(&dir, "constant.toml", &constant);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let (_, _, load) = driver_rows(&dir)[5];
    assert!((load - expected).abs() < 1e-6 * expected, "{load}");
}

/// A driver value meant in degrees: read in radians, 90 rad over ten
/// increments asks for 9 rad per increment (more than half a turn): a
/// warning names the driver and suggests `unit = "deg"`, and load control
/// limits the increments to a quarter turn each; with the unit, the hinge
/// turns by π/2 in ten increments without a cut-back.
#[test]
fn angles_in_degrees() {
    let dir = scratch("degrees");
    let kinematic = "[analysis]\ntype = \"kinematic\"\n";
    let (code, out, err) = run_model(&dir, "rad.toml", &pendulum("90", None, kinematic));
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("rad.toml: driver 3: asks for 9.0000 rad (515.7°) in one increment")
            && err.contains("unit = \"deg\""),
        "{err}"
    );
    // load control limits its increments to a quarter turn each
    // (π/2 / 90 = 1.745e-2) rather than cutting them back
    assert!(
        out.contains("note: load increments limited to 1.7453e-2") && out.contains(" 0 cut-backs"),
        "{out}"
    );
    let (code, out, err) = run_model(&dir, "deg.toml", &pendulum("90", Some("deg"), kinematic));
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    assert!(
        out.contains("10 increments") && out.contains(" 0 cut-backs"),
        "{out}"
    );
    let (_, angle, _) = *driver_rows(&dir).last().unwrap();
    assert!(
        (angle - std::f64::consts::FRAC_PI_2).abs() < 1e-9,
        "{angle}"
    );

    // a unit on a length, and an unknown unit
    let slide = pendulum("0.1", Some("deg"), kinematic).replace("\"revolute\"", "\"prismatic\"");
    assert_rejected(
        "unit_on_slide",
        &slide,
        &[
            "driver 3",
            "unit = \"deg\" applies to angles, but coordinate slide is a length",
        ],
    );
    assert_rejected(
        "unknown_unit",
        &pendulum("90", Some("grad"), kinematic),
        &["unknown variant `grad`", "expected `rad` or `deg`"],
    );
}

/// `check` runs every check that needs no analysis, with the message and
/// the exit code (2) of `run`: an undriven four-bar in a kinematic
/// analysis is not determinate; a mechanism in statics has a singular
/// tangent, named by node and component.
#[test]
fn check_finds_what_run_rejects() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/four_bar.toml"),
    )
    .unwrap();
    let free = &text[..text.find("[[drivers]]").unwrap()];
    let pinned = CANTILEVER.replace("fixed = [\"all\"]", "fixed = [\"translations\"]");
    for (name, model, message) in [
        (
            "free_four_bar",
            free.to_string(),
            "do not make the mechanism determinate: 1 motion(s) are left free",
        ),
        ("pinned", pinned, "singular tangent: no stiffness for node "),
    ] {
        let dir = scratch(name);
        let file = format!("{name}.toml");
        let (run_code, _, run_err) = run_model(&dir, &file, &model);
        let (code, out, err) = unfold(&["check", dir.join(&file).to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {out}{err}");
        assert_eq!(run_code, 2, "{name}: {run_err}");
        assert!(!out.contains("valid model"), "{name}: {out}");
        assert!(err.contains(message), "{name}: {err}");
        // the same message as the run
        let first = err.lines().next().unwrap();
        assert!(
            run_err.contains(first),
            "{name}: check «{first}», run «{run_err}»"
        );
    }
    // with its driver, the four-bar checks, with its redundant equations
    let dir = scratch("four_bar_checks");
    std::fs::write(dir.join("four_bar.toml"), &text).unwrap();
    let (code, out, err) = unfold(&["check", dir.join("four_bar.toml").to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("valid model") && out.contains("3 redundant"),
        "{out}"
    );
}

/// Sizes are checked before anything is allocated: a beam line of
/// i64::MAX elements (a capacity-overflow panic before), 2³² + 1 (an
/// abort allocating 103 GB) or 10⁹ elements (15 GB in `check`) is an
/// error within a second, reported with the other problems of the file
/// (here a NaN coordinate, never reached before); node ids near i64::MAX
/// that would generate ids beyond it are errors too.
#[test]
fn sizes_and_ids_are_limited_before_allocating() {
    let line = |n: &str| {
        CANTILEVER.replace(
            "[[beams]]\nid = 1\nnodes = [1, 2]\nsection = \"s\"\n",
            &format!("[[beam_lines]]\nnodes = [1, 2]\nelements = {n}\nsection = \"s\"\n"),
        ) + "\n[[nodes]]\nid = 7\nx = [nan, 0.0, 0.0]\n"
    };
    for n in ["9223372036854775807", "4294967297", "1000000000"] {
        let start = std::time::Instant::now();
        assert_rejected(
            &format!("elements_{n}"),
            &line(n),
            &[
                &format!("beam_lines[1] (nodes 1 to 2): {n} elements: more than the limit of 100000 per line"),
                "node 7: x must be finite",
            ],
        );
        // a bound far above the milliseconds it takes, far below the
        // minutes and gigabytes of the allocation it replaces
        assert!(start.elapsed().as_secs() < 20);
    }
    let ids = CANTILEVER
        .replace("id = 3\nx", "id = 9223372036854775806\nx")
        .replace("nodes = [2, 3]", "nodes = [2, 9223372036854775806]")
        .replace(
            "[[beams]]\nid = 1\nnodes = [1, 2]\nsection = \"s\"\n",
            "[[beam_lines]]\nnodes = [1, 2]\nelements = 3\nsection = \"s\"\n",
        )
        .replace("node = 3", "node = 9223372036854775806");
    assert_rejected(
        "huge_ids",
        &ids,
        &[
            "beam_lines[1] (nodes 1 to 2)",
            "interior nodes would get ids above 9223372036854775807",
        ],
    );
}

/// Writing to a full or closed stream never panics: messages that cannot
/// be written are dropped and the exit code stays that of the outcome.
#[test]
fn unwritable_output_streams_do_not_panic() {
    let dir = scratch("dev_full");
    std::fs::write(dir.join("ok.toml"), CANTILEVER).unwrap();
    std::fs::write(
        dir.join("bad.toml"),
        CANTILEVER.replace("EA = 1.0e7", "EA = -1.0"),
    )
    .unwrap();
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    for (file, expected) in [("ok.toml", 0), ("bad.toml", 2)] {
        for args in [vec!["check", file], vec!["run", file, "--out", "out"]] {
            let out = Command::new(env!("CARGO_BIN_EXE_unfold"))
                .args(&args)
                .current_dir(&dir)
                .stdout(full())
                .stderr(full())
                .output()
                .unwrap();
            assert_eq!(out.status.code(), Some(expected), "{args:?}");
        }
    }
}

/// Curves and loads that can only give non-finite values are rejected at
/// input, naming the entity; a reference to an invalid curve is not
/// reported again as undefined.
#[test]
fn non_finite_curves_and_products_are_rejected() {
    let with_curve = |curve: &str, load: &str| {
        CANTILEVER.replace(
            "force = [0.0, 0.0, -1.0]",
            &format!("force = {load}\ncurve = \"c\""),
        ) + &format!("\n[[curves]]\nname = \"c\"\n{curve}\n")
    };
    let dir = scratch("sine");
    let text = with_curve("function = \"sine\"\nfrequency = 1e308", "[0.0, 0.0, -1.0]");
    let (code, _, err) = run_model(&dir, "sine.toml", &text);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("curve \"c\": its values over the analysis (t from 0 to 1) exceed the range of floating-point numbers"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "one problem, one message: {err}");
    assert_rejected(
        "amplitude_product",
        &with_curve(
            "function = \"sine\"\nfrequency = 1.0\namplitude = 1e300",
            "[0.0, 0.0, -1e300]",
        ),
        &["loads[1] (node 3): force (1e300) times curve \"c\" (up to 1e300) exceeds the range"],
    );
    assert_rejected(
        "table_overflow",
        &with_curve(
            "points = [[0.0, -1.7e308], [1.0, 1.7e308]]",
            "[0.0, 0.0, -1.0]",
        ),
        &["curve \"c\"", "too far apart to interpolate"],
    );
    assert_rejected(
        "reserved_constant",
        &(CANTILEVER.to_string() + "\n[[curves]]\nname = \"constant\"\npoints = [[0.0, 2.0]]\n"),
        &[
            "curve \"constant\"",
            "reserved for the built-in curve f(t) = 1",
        ],
    );
}

/// One message per problem: a bad orientation on a ten-element beam line
/// is reported once, at the line (not once per generated beam, with
/// doubled brackets); an invalid joint or node is not reported again by
/// what refers to it.
#[test]
fn one_message_per_problem() {
    let text = CANTILEVER.replace(
        "[[beams]]\nid = 1\nnodes = [1, 2]\nsection = \"s\"\n",
        "[[beam_lines]]\nnodes = [1, 2]\nelements = 10\nsection = \"s\"\norientation = [1.0, 0.0, 0.0]\nfirst_node = 100\n",
    );
    let dir = scratch("one_message");
    let (code, _, err) = run_model(&dir, "line.toml", &text);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("beam_lines[1] (nodes 1 to 2): orientation vector [1.0, 0.0, 0.0] is zero or parallel to the line"),
        "{err}"
    );
    assert!(!err.contains("))"), "{err}");

    let text = hinged(
        "[[joints]]\nid = 30\ntype = \"revolute\"\nnodes = [3, 4]\n\n[[joint_springs]]\nid = 31\njoint = 30\nstiffness = 1.0\n\n[[drivers]]\nid = 32\njoint = 30\nvalue = 1.0\n",
    )
    .replace("x = [1.0, 0.0, 0.0]\n\n[[rigid", "x = [1.0, nan, 0.0]\n\n[[rigid");
    let (code, _, err) = run_model(&dir, "joint.toml", &text);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("joint 30: a revolute joint needs `axis`"),
        "{err}"
    );
    assert!(err.contains("node 4: x must be finite"), "{err}");
    assert_eq!(err.lines().count(), 2, "{err}");
}

/// Analysis settings that could only hang or accept anything: more than
/// 10⁶ increments, steps lost in the round-off of t, 10⁶ iterations,
/// tolerances of 1 or more, constraint scaling beyond 1e150.
#[test]
fn analysis_settings_are_limited() {
    let analysis = |body: &str| format!("{CANTILEVER}\n[analysis]\n{body}\n");
    assert_rejected(
        "too_many_increments",
        &analysis("end_time = 1.0e9\ninitial_increment = 0.1\nmax_increment = 0.1\nmin_increment = 0.01"),
        &["analysis: end_time / max_increment = 1.000e10: the analysis would need more than 1e6 increments"],
    );
    assert_rejected(
        "tiny_min_increment",
        &analysis("min_increment = 1e-300"),
        &[
            "analysis: min_increment must be at least end_time·1e-12",
            "got 1e-300",
        ],
    );
    assert_rejected(
        "many_iterations",
        &analysis("max_iterations = 1000000"),
        &["analysis: max_iterations must be from 1 to 1000, got 1000000"],
    );
    assert_rejected(
        "loose_tolerance",
        &analysis("residual_tolerance = 2.0\nconstraint_scale = 1e200"),
        &[
            "analysis: residual_tolerance must be below 1",
            "analysis: constraint_scale must be at most 1e150",
        ],
    );
}

/// Values each in range whose products are not: the element is named, and
/// the elements of a beam line sharing the problem are counted in one
/// message.
#[test]
fn out_of_range_element_forces_are_named() {
    assert_rejected(
        "heavy_mass",
        &format!(
            "{CANTILEVER}\n[[point_masses]]\nid = 10\nnode = 3\nmass = 1e308\n\n[gravity]\nacceleration = [0.0, 0.0, -9.81]\n"
        ),
        &["point mass 10: its forces or stiffness in the reference configuration at t = 0.5 are not finite or exceed 1e150"],
    );
    let text = CANTILEVER
        .replace("EA = 1.0e7", "EA = 1.0e160")
        .replace(
            "[[beams]]\nid = 1\nnodes = [1, 2]\nsection = \"s\"\n\n[[beams]]\nid = 2\nnodes = [2, 3]\nsection = \"s\"\n",
            "[[beam_lines]]\nnodes = [1, 3]\nelements = 4\nsection = \"s\"\nfirst_node = 10\n",
        )
        .replace("[[nodes]]\nid = 2\nx = [0.5, 0.0, 0.0]\n", "");
    let dir = scratch("stiff_line");
    let (code, _, err) = run_model(&dir, "stiff.toml", &text);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("beam 1 (and 3 other beam elements): its forces or stiffness in the reference configuration at t = 0 are not finite or exceed 1e150"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// Runs `unfold check` on `text` written as `name` in a scratch directory:
/// (exit code, stdout, stderr).
fn check_model(name: &str, text: &str) -> (i32, String, String) {
    let dir = scratch(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    unfold(&["check", path.to_str().unwrap()])
}

/// Asserts that `check` accepts `text` (exit 0) with a warning containing
/// every fragment, or with no warning at all if `fragments` is empty.
fn assert_warned(name: &str, text: &str, fragments: &[&str]) {
    let (code, out, err) = check_model(name, text);
    assert_eq!(code, 0, "{name}: {out}{err}");
    if fragments.is_empty() {
        assert!(!err.contains("warning"), "{name}: {err}");
    }
    for f in fragments {
        assert!(
            err.contains("warning: ") && err.contains(f),
            "{name}: warning lacks «{f}»: {err}"
        );
    }
}

/// Angles without a unit that look like degrees are warned about, naming
/// the entity and suggesting `unit = "deg"`: a driven angle beyond a full
/// turn (30 rad for a pendulum meant to swing 30°), a node's or a
/// prescribed rotation vector longer than half a turn, a joint spring's
/// free angle or table angles beyond a full turn. `unit = "rad"` says the
/// radians are meant and silences them; `unit = "deg"` converts.
#[test]
fn angles_that_look_like_degrees_are_warned_about() {
    let kinematic = "[analysis]\ntype = \"kinematic\"\n";
    let hint = "If it is in degrees, write unit = \"deg\" (unit = \"rad\" confirms radians)";
    assert_warned(
        "driver_30",
        &pendulum("30", None, kinematic),
        &[
            "driver 3: drives its angle up to 30.0000 rad (1718.9°), more than a full turn",
            hint,
        ],
    );
    assert_warned(
        "driver_30_rad",
        &pendulum("30", Some("rad"), kinematic),
        &[],
    );
    assert_warned(
        "driver_30_deg",
        &pendulum("30", Some("deg"), kinematic),
        &[],
    );
    // a full turn written to a few digits is a full turn
    assert_warned("driver_2pi", &pendulum("6.2832", None, kinematic), &[]);

    let node = CANTILEVER.replace(
        "id = 3\nx = [1.0, 0.0, 0.0]",
        "id = 3\nx = [1.0, 0.0, 0.0]\nrotation = [0.0, 0.0, 90.0]",
    );
    assert_warned(
        "node_rotation",
        &node,
        &[
            "node 3: rotation has the length 90.0000 rad (5156.6°), more than half a turn",
            hint,
        ],
    );
    assert_warned(
        "node_rotation_rad",
        &node.replace(
            "rotation = [0.0, 0.0, 90.0]",
            "rotation = [0.0, 0.0, 90.0]\nunit = \"rad\"",
        ),
        &[],
    );

    // 4 rad in ten increments: not too fast per increment, but more than
    // half a turn in all
    let prescribed =
        format!("{CANTILEVER}\n[[prescribed]]\nnode = 3\nrotation = [4.0, 0.0, 0.0]\n");
    assert_warned(
        "prescribed_rotation",
        &prescribed,
        &[
            "prescribed[1] (node 3): rotation reaches 4.0000 rad (229.2°), more than half a turn",
            hint,
        ],
    );
    assert_warned(
        "prescribed_rotation_rad",
        &prescribed.replace("[4.0, 0.0, 0.0]\n", "[4.0, 0.0, 0.0]\nunit = \"rad\"\n"),
        &[],
    );

    let spring = |body: &str| {
        hinged(&format!(
            "[[joints]]\nid = 30\ntype = \"revolute\"\nnodes = [3, 4]\naxis = [0, 1, 0]\n\n[[joint_springs]]\nid = 31\njoint = 30\n{body}\n"
        ))
    };
    assert_warned(
        "free_value",
        &spring("stiffness = 1.0\nfree_value = 90.0"),
        &[
            "joint spring 31: free_value is 90.0000 rad (5156.6°), more than a full turn",
            hint,
        ],
    );
    assert_warned(
        "free_value_rad",
        &spring("stiffness = 1.0\nfree_value = 90.0\nunit = \"rad\""),
        &[],
    );
    assert_warned(
        "spring_table",
        &spring("table = [[-90.0, -1.0], [90.0, 1.0]]"),
        &[
            "joint spring 31: the angles of its table reach 90.0000 rad",
            hint,
        ],
    );
    // a slide is a length: no warning
    assert_warned(
        "slide_spring",
        &spring("stiffness = 1.0\nfree_value = 90.0").replace("\"revolute\"", "\"prismatic\""),
        &[],
    );
}

/// A prescribed rotation changing by more than half a turn over the
/// largest increment is warned about, as a driver is (within an increment
/// the analysis cannot tell it from the same rotation less a turn: 4π in
/// two increments gave no torque at all), with the increment load control
/// takes instead: a quarter turn, (π/2)/4π of t.
#[test]
fn a_prescribed_rotation_too_fast_for_an_increment_is_warned_about() {
    let text = format!(
        "{CANTILEVER}\n[[prescribed]]\nnode = 3\nrotation = [12.566370614359172, 0.0, 0.0]\nunit = \"rad\"\n\n[analysis]\ninitial_increment = 0.5\n"
    );
    assert_warned(
        "prescribed_fast",
        &text,
        &[
            "prescribed[1] (node 3): turns the node by up to 6.2832 rad (360.0°) in one increment of t = 0.5 (max_increment): more than half a turn",
            "load increments are limited to 1.250e-1 (a quarter turn each).",
        ],
    );
    let (_, _, err) = check_model("prescribed_fast_again", &text);
    assert!(
        !err.contains("unit = \"deg\""),
        "unit given: no hint: {err}"
    );
    assert_warned(
        "prescribed_slow",
        &text.replace("initial_increment = 0.5", "initial_increment = 0.25"),
        &[],
    );
}

/// A beam's natural length `L(1 + ε f(t))` must stay positive: an initial
/// axial strain of −1 or below (with its curve) is an error naming the
/// beam or the line; an initial curvature that turns one element's ends
/// by half a turn or more is one too (the relative rotation of an
/// element's ends is at most π).
#[test]
fn initial_strains_that_no_beam_can_take_are_rejected() {
    let strained = |strain: &str, extra: &str| {
        CANTILEVER.replace(
            "[[beams]]\nid = 2\nnodes = [2, 3]\nsection = \"s\"\n",
            &format!("[[beams]]\nid = 2\nnodes = [2, 3]\nsection = \"s\"\ninitial_strain = {strain}\n{extra}"),
        )
    };
    assert_rejected(
        "strain_minus_one",
        &strained("[-1.0, 0.0, 0.0, 0.0, 0.0, 0.0]", ""),
        &[
            "beam 2: initial axial strain -1 must stay above -1",
            "natural length",
        ],
    );
    assert_rejected(
        "strain_minus_two",
        &strained("[-2.0, 0.0, 0.0, 0.0, 0.0, 0.0]", ""),
        &["beam 2: initial axial strain -2 must stay above -1"],
    );
    // −0.5 times a curve reaching 3: −1.5 at the end
    let curved = strained(
        "[-0.5, 0.0, 0.0, 0.0, 0.0, 0.0]",
        "initial_strain_curve = \"c\"\n\n[[curves]]\nname = \"c\"\npoints = [[0.0, 0.0], [1.0, 3.0]]\n",
    );
    assert_rejected(
        "strain_curve",
        &curved,
        &["beam 2: initial axial strain -0.5 (times curve \"c\": down to -1.5) must stay above -1"],
    );
    // the same curve going negative leaves a positive strain: valid
    let (code, _, err) = check_model(
        "strain_lengthens",
        &curved.replace("[1.0, 3.0]", "[1.0, -3.0]"),
    );
    assert_eq!(code, 0, "{err}");
    let line = CANTILEVER.replace(
        "[[beams]]\nid = 1\nnodes = [1, 2]\nsection = \"s\"\n\n[[beams]]\nid = 2\nnodes = [2, 3]\nsection = \"s\"\n",
        "[[beam_lines]]\nnodes = [1, 3]\nelements = 4\nsection = \"s\"\nfirst_node = 10\ninitial_strain = [-1.5, 0.0, 0.0, 0.0, 0.0, 0.0]\n",
    )
    .replace("[[nodes]]\nid = 2\nx = [0.5, 0.0, 0.0]\n", "");
    assert_rejected(
        "strain_line",
        &line,
        &["beam_lines[1] (nodes 1 to 3): initial axial strain -1.5 must stay above -1"],
    );
    // 7 rad/m over 0.5 m: 3.5 rad, more than π, on one element; the same
    // over four elements of 0.25 m and 1.75 rad each is fine
    assert_rejected(
        "curvature",
        &strained("[0.0, 0.0, 0.0, 0.0, 0.0, 7.0]", ""),
        &["beam 2: its initial twist and curvature [0.0, 0.0, 7.0] turn its end sections by 3.5000 rad over its length 0.5", "divide it into more elements"],
    );
    let (code, _, err) = check_model(
        "curvature_meshed",
        &line.replace(
            "[-1.5, 0.0, 0.0, 0.0, 0.0, 0.0]",
            "[0.0, 0.0, 0.0, 0.0, 0.0, 7.0]",
        ),
    );
    assert_eq!(code, 0, "{err}");
}

/// Conflicting input is not resolved silently: a component both fixed by
/// a support and prescribed is an error (the clamp moved); a component
/// fixed twice, and gravity in a model without mass, are warnings.
#[test]
fn conflicting_supports_and_loads_are_named() {
    let moved = format!("{CANTILEVER}\n[[prescribed]]\nnode = 1\ndof = \"x\"\nvalue = 0.1\n");
    assert_rejected(
        "prescribed_on_fixed",
        &moved,
        &["prescribed[1] (node 1): component x of node 1 is also fixed by a support"],
    );
    let turned = format!("{CANTILEVER}\n[[prescribed]]\nnode = 1\nrotation = [0.1, 0.0, 0.0]\n");
    assert_rejected(
        "prescribed_rotation_on_fixed",
        &turned,
        &["prescribed[1] (node 1): the rotation of node 1 is prescribed, but rx, ry, rz are also fixed by a support"],
    );
    // a free component of a supported node may be prescribed
    let free = CANTILEVER.replace("fixed = [\"all\"]", "fixed = [\"y\", \"z\", \"rotations\"]")
        + "\n[[prescribed]]\nnode = 1\ndof = \"x\"\nvalue = 0.1\n";
    assert_warned("prescribed_free_component", &free, &[]);

    let twice = format!("{CANTILEVER}\n[[supports]]\nnode = 1\nfixed = [\"x\", \"rz\"]\n");
    assert_warned(
        "support_twice",
        &twice,
        &["supports[2] (node 1): fixes x, rz again, already fixed by supports[1]"],
    );
    assert_warned(
        "support_twice_in_one",
        &CANTILEVER.replace("fixed = [\"all\"]", "fixed = [\"all\", \"x\"]"),
        &["supports[1] (node 1): fixes x again, already fixed by this entry"],
    );
    assert_warned(
        "gravity_without_mass",
        &format!("{CANTILEVER}\n[gravity]\nacceleration = [0.0, 0.0, -9.81]\n"),
        &["gravity: acts on no mass"],
    );
    assert_warned(
        "gravity_with_mass",
        &format!("{CANTILEVER}\n[[point_masses]]\nid = 10\nnode = 3\nmass = 1.0\n\n[gravity]\nacceleration = [0.0, 0.0, -9.81]\n"),
        &[],
    );
}

/// Every misspelt key of a file is reported in one go, each with its line
/// (the file is read again without it); a top-level key written after a
/// table header, which TOML puts into that table, gets a hint naming the
/// table. A misspelt required key is reported once, not again as missing.
#[test]
fn every_misspelt_key_is_reported_with_its_line() {
    let text = CANTILEVER
        .replace("EA = 1.0e7", "EAA = 1.0e7")
        .replace("[[supports]]", "[[support]]")
        .replace("id = 2\nx = [0.5", "idd = 2\nx = [0.5")
        + "\n[analysis]\ntype = \"static\"\ntitle = \"late\"\n";
    let dir = scratch("typos");
    let (code, out, err) = run_model(&dir, "typos.toml", &text);
    assert_eq!(code, 2, "{out}{err}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("typos.toml: line "))
        .collect();
    assert_eq!(lines.len(), 4, "{err}");
    for (fragment, line) in [
        ("unknown field `EAA`", "line 6"),
        ("unknown field `idd`", "line 18"),
        ("unknown field `support`", "line 35"),
        ("unknown field `title`", "line 45"),
    ] {
        assert!(err.contains(fragment), "lacks {fragment}: {err}");
        assert!(
            lines.iter().any(|l| l.contains(line)),
            "lacks {line}: {err}"
        );
    }
    // in the order of the file, the missing `id` not reported
    let at = |f: &str| err.find(f).unwrap();
    assert!(
        at("`EAA`") < at("`idd`")
            && at("`idd`") < at("`support`")
            && at("`support`") < at("`title`")
    );
    assert!(!err.contains("missing field"), "{err}");
    assert!(
        err.contains(
            "hint: `title` is a top-level key, but here it is read as a key of [analysis]"
        ) && err.contains("write top-level keys before the first header"),
        "{err}"
    );
    // the hint names an entry of an array of tables too
    let (_, _, err) = check_model(
        "late_key",
        &CANTILEVER.replace(
            "id = 3\nx = [1.0, 0.0, 0.0]",
            "id = 3\nx = [1.0, 0.0, 0.0]\ntitle = \"t\"",
        ),
    );
    assert!(err.contains("read as a key of [[nodes]] entry 3"), "{err}");
    // a wrong type ends the report (tables are read in the order of their
    // names: beams, sections, supports): what follows could be its
    // consequence
    let (code, _, err) = check_model(
        "wrong_type",
        &CANTILEVER
            .replace(
                "nodes = [1, 2]\nsection",
                "nodes = [1, 2]\norientaton = [0.0, 1.0, 0.0]\nsection",
            )
            .replace("EA = 1.0e7", "EA = \"big\"")
            .replace("[[supports]]", "[[support]]"),
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("`orientaton`") && err.contains("invalid type"),
        "{err}"
    );
    assert!(!err.contains("`support`"), "{err}");
}

/// Reads the stderr and the file list of a run into `dir/out`.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.join("out"))
        .map(|entries| {
            entries
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// A model rejected by the start-of-run checks (a mechanism in statics,
/// an undriven kinematic mechanism) exits with 2 before any result is
/// written: no empty CSV file, no grid folder, no "failed … results in"
/// line; `summary.json` alone says why. The results of an earlier run in
/// the directory are removed, since they are not this model's.
#[test]
fn a_model_rejected_at_the_start_leaves_only_its_summary() {
    let dir = scratch("rejected");
    let (code, _, err) = run_model(&dir, "ok.toml", CANTILEVER);
    assert_eq!(code, 0, "{err}");
    assert!(listing(&dir).contains(&"nodes.csv".to_string()));
    let pinned = CANTILEVER.replace("fixed = [\"all\"]", "fixed = [\"translations\"]");
    let (code, out, err) = run_model(&dir, "pinned.toml", &pinned);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("singular tangent"), "{err}");
    assert!(
        !out.contains("failed") && !err.contains("results in"),
        "{out}{err}"
    );
    assert_eq!(listing(&dir), vec!["summary.json".to_string()]);
    let summary = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
    assert!(
        summary.contains("\"status\": \"failed\"") && summary.contains("singular tangent"),
        "{summary}"
    );

    let dir = scratch("rejected_kinematic");
    let link = "[analysis]\ntype = \"kinematic\"\n\n[[nodes]]\nid = 1\nx = [0.0, 0.0, 0.0]\n\n[[joints]]\nid = 1\ntype = \"revolute\"\nnodes = [1]\naxis = [0, 0, 1]\n";
    let (code, out, err) = run_model(&dir, "link.toml", link);
    assert_eq!(code, 2, "{err}");
    assert!(!out.contains("failed"), "{out}");
    assert_eq!(listing(&dir), vec!["summary.json".to_string()]);
}

/// The lock file of the output directory is removed when a run ends,
/// whether it completed or failed; one left by a killed process (its pid
/// dead, its lock released by the system) does not block the next run.
#[test]
fn the_lock_file_goes_when_the_run_ends() {
    let dir = scratch("lock");
    let (code, _, err) = run_model(&dir, "ok.toml", CANTILEVER);
    assert_eq!(code, 0, "{err}");
    assert!(!dir.join("out/.unfold.lock").exists());
    let diverging = CANTILEVER.replace("force = [0.0, 0.0, -1.0]", "force = [0.0, 0.0, -5.0e3]")
        + "\n[analysis]\ninitial_increment = 0.05\nmax_iterations = 3\nmin_increment = 0.01\n";
    let (code, _, err) = run_model(&dir, "diverge.toml", &diverging);
    assert_eq!(code, 1, "{err}");
    assert!(!dir.join("out/.unfold.lock").exists());
    // a stale lock file naming a process that no longer runs
    std::fs::write(dir.join("out/.unfold.lock"), "4194304").unwrap();
    let (code, _, err) = run_model(&dir, "ok.toml", CANTILEVER);
    assert_eq!(code, 0, "{err}");
    assert!(!dir.join("out/.unfold.lock").exists());
}

/// Command-line values that cannot be meant: `--threads 0` is an error,
/// more threads than cores a warning; `--out` naming a file is an error
/// saying so (it was "out/vtk: Not a directory").
#[test]
fn command_line_values_are_checked() {
    let dir = scratch("threads");
    let model = dir.join("ok.toml");
    std::fs::write(&model, CANTILEVER).unwrap();
    let out = dir.join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        unfold(&args)
    };
    let (code, _, err) = run(&["--threads", "0"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--threads 0: give at least 1"), "{err}");
    let (code, _, err) = run(&["--threads", "4096"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: --threads 4096: more threads than the") && err.contains("cores"),
        "{err}"
    );
    let file = dir.join("afile");
    std::fs::write(&file, "").unwrap();
    let (code, _, err) = unfold(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        file.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!("--out {}: is a file", file.display()))
            && !err.contains("Not a directory"),
        "{err}"
    );
}

/// An over-driven mechanism (the four-bar with a second driver on the
/// rocker): `check` warns that the driver's equation is redundant with the
/// joints and the other drivers, names it, and says the run stops if they
/// contradict; the run warns the same and stops at its first increment.
/// The four-bar with its one driver gets no such warning.
#[test]
fn an_over_driven_mechanism_is_warned_about() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/four_bar.toml"),
    )
    .unwrap();
    let (code, out, err) = check_model("four_bar_one_driver", &text);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!err.contains("redundant"), "{err}");
    let over = format!("{text}\n[[drivers]]\nid = 11\njoint = 4\nvalue = 1.0\n");
    let (code, out, err) = check_model("four_bar_two_drivers", &over);
    assert_eq!(code, 0, "{out}{err}");
    let warning = "driver 11: equation 1 is redundant with the joints and the other drivers at t = 0: the driver repeats or contradicts what they impose";
    assert!(
        err.contains(warning)
            && err.contains("the run stops at the first increment where they disagree"),
        "{err}"
    );
    let dir = scratch("over_driven");
    let (code, _, err) = run_model(&dir, "over.toml", &over);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(warning), "{err}");
    assert!(
        err.contains("inconsistent constraints at t = ") && err.contains("driver 11 equation 1"),
        "{err}"
    );
}

/// A sequence of analyses (`[[analysis]]`): the cantilever loaded to
/// t = 1, then (from that state) to t = 2, runs both in order into one set
/// of result files: steps numbered 0, 1, 2, ... across both analyses
/// (the second analysis's equilibrium at its start, the state already
/// written as the first one's last step, is not written again), increments
/// numbered on, time going on from 1 to 2, and `summary.json` listing each
/// analysis. Its end state is that of one analysis from 0 to 2 in the same
/// increments: the same nodes.csv row of the tip at the last step, to
/// 1e-12 of the tip's displacement (the same equilibrium to round-off; the
/// written zeros differ at 1e-20).
#[test]
fn a_sequence_of_analyses_runs_into_one_set_of_results() {
    let dir = scratch("sequence");
    let text = format!(
        "{CANTILEVER}\n[[analysis]]\nend_time = 1.0\ninitial_increment = 0.25\n\n[[analysis]]\nend_time = 2.0\ninitial_increment = 0.25\n"
    );
    let (code, out, err) = run_model(&dir, "sequence.toml", &text);
    assert_eq!(code, 0, "stdout {out}\nstderr {err}");
    assert!(
        out.contains("analysis 2 of 2: static from t = 1 to t = 2"),
        "{out}"
    );
    let steps = std::fs::read_to_string(dir.join("out/steps.csv")).unwrap();
    let rows: Vec<Vec<String>> = steps
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    // steps 0..=8, increments 0..=8, t from 0 to 2 by 0.25
    assert_eq!(rows.len(), 9, "{steps}");
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[0], k.to_string(), "{steps}");
        assert_eq!(row[1], k.to_string(), "{steps}");
        let t: f64 = row[2].parse().unwrap();
        assert!((t - 0.25 * k as f64).abs() < 1e-12, "{steps}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["increments"], 8);
    assert_eq!(summary["final_time"], 2.0);
    assert_eq!(summary["end_time"], 2.0);
    assert_eq!(summary["output_steps"], 9);
    let analyses = summary["analyses"].as_array().unwrap();
    assert_eq!(analyses.len(), 2);
    assert_eq!(analyses[1]["start_time"], 1.0);
    assert_eq!(analyses[1]["end_time"], 2.0);
    assert_eq!(analyses[1]["increments"], 4);
    let last_rows = |nodes: &str| -> Vec<f64> {
        let row = nodes
            .lines()
            .find(|l| l.starts_with("8,") && l.split(',').nth(2) == Some("3"))
            .expect("the tip at step 8");
        row.split(',').skip(3).map(|v| v.parse().unwrap()).collect()
    };
    let sequence_tip = last_rows(&std::fs::read_to_string(dir.join("out/nodes.csv")).unwrap());

    // one analysis from 0 to 2
    let one = scratch("sequence-one");
    let text = format!("{CANTILEVER}\n[analysis]\nend_time = 2.0\ninitial_increment = 0.25\n");
    let (code, _, err) = run_model(&one, "one.toml", &text);
    assert_eq!(code, 0, "{err}");
    let one_tip = last_rows(&std::fs::read_to_string(one.join("out/nodes.csv")).unwrap());
    let u = (sequence_tip[3].powi(2) + sequence_tip[5].powi(2)).sqrt();
    let worst = sequence_tip
        .iter()
        .zip(&one_tip)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst <= 1e-12 * u, "{sequence_tip:?} vs {one_tip:?}");
}

/// A sequence whose analyses do not go forward in time, or that gives the
/// model's constraint scaling again, is rejected naming the analysis.
#[test]
fn a_sequence_must_go_forward() {
    let text = format!(
        "{CANTILEVER}\n[[analysis]]\nend_time = 1.0\n\n[[analysis]]\nend_time = 0.5\nconstraint_scale = 3.0\n"
    );
    assert_rejected(
        "backwards",
        &text,
        &[
            "analysis[2]: end_time must be after the end of the analysis before it (t = 1), got 0.5",
            "analysis[2]: constraint_scale belongs to the model",
        ],
    );
    let text = CANTILEVER.replace(
        "title = \"two-element cantilever\"",
        "title = \"two-element cantilever\"\nanalysis = []",
    );
    assert_rejected("no_analysis", &text, &["at least one [[analysis]] table"]);
}

/// The twisted cantilever of the new-user trial (L = 2, GJ = 5920, ten
/// elements, end rotation 4π about the axis), with increments of
/// `increment` asked for.
fn twisted_cantilever(increment: f64) -> String {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/twisted_cantilever.toml"
    );
    std::fs::read_to_string(path)
        .expect("the twisted cantilever")
        .replace(
            "initial_increment = 0.5\n",
            &format!("initial_increment = {increment}\n"),
        )
}

/// The torque of a prescribed end rotation of two full turns is
/// `GJ·4π/L` = 37 196.46 (uniform torsion) whether increments of 0.5 or of
/// 0.1 are asked for: increments of 0.5 (a full turn each) gave no torque
/// at all, as a full turn cannot be told from none within an increment;
/// load control now takes increments of a quarter turn at most, notes it,
/// and the builder's warning says so. Reaction moment at the clamp, last
/// step of reactions.csv, to 1e-6 of the torque.
#[test]
fn a_prescribed_rotation_of_two_turns_gives_its_torque_whatever_the_increment() {
    let torque = 5.92e3 * 4.0 * std::f64::consts::PI / 2.0;
    for (increment, tag) in [(0.5, "two"), (0.1, "ten")] {
        let dir = scratch(&format!("twist_{tag}"));
        let (code, out, err) = run_model(&dir, "twist.toml", &twisted_cantilever(increment));
        assert_eq!(code, 0, "{out}{err}");
        if increment == 0.5 {
            assert!(
                err.contains("load increments are limited to 1.250e-1 (a quarter turn each)"),
                "{err}"
            );
            assert!(
                out.contains("note: load increments limited to 1.2500e-1"),
                "{out}"
            );
        }
        let reactions = std::fs::read_to_string(dir.join("out/reactions.csv")).unwrap();
        let last = reactions.lines().rev().find(|l| l.contains(",1,")).unwrap();
        // step,time,node,Fx,Fy,Fz,Mx,My,Mz
        let mx: f64 = last.split(',').nth(6).unwrap().parse().unwrap();
        println!("{increment}: reaction moment {mx} against {torque}");
        assert!((mx.abs() - torque).abs() <= 1e-6 * torque, "{last}");
    }
}

/// A rotational spring whose relative rotation passes half a turn stops
/// the run (exit 1) naming the spring and the increment (its law m = Kψ
/// holds below half a turn: beyond, ψ = log(…) measures the rotation the
/// other way round and the moment turns the wrong way); the results up to
/// the last increment before are kept.
#[test]
fn a_rotational_spring_past_half_a_turn_stops_the_run() {
    let rollup = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever_rollup.toml"),
    )
    .unwrap();
    let spring = format!(
        "{rollup}\n[[springs]]\nid = 100\nkind = \"rotational\"\nnodes = [11]\nstiffness = 1.0\n"
    );
    let dir = scratch("spring_half_turn");
    let (code, out, err) = run_model(&dir, "rs.toml", &spring);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains(
            "spring 100, between t = 0.5 and t = 0.6: its relative rotation passed half a turn"
        ) && err.contains("a rotational spring's law m = K ψ holds below half a turn only"),
        "{err}"
    );
    assert!(err.contains("results up to t = 0.5 are kept"), "{err}");
    let summary = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
    assert!(summary.contains("\"status\": \"failed\""), "{summary}");
}

/// Kinematic increments show the largest constraint violation relative to
/// its tolerance at each iteration (converged: at most 1), not the
/// relative residual, which without loads stays near 1 (the four-bar
/// printed 9.7e-1 5.0e-1 6.8e-1 0.0e0); static increments keep the
/// relative residuals.
#[test]
fn kinematic_increments_show_the_constraint_violation() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/four_bar.toml");
    let dir = scratch("kinematic_lines");
    // every increment's line, also when the output is not a terminal
    let (code, out, err) = unfold(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
        "--verbose",
    ]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out
        .lines()
        .filter(|l| l.starts_with("increment "))
        .collect();
    assert_eq!(lines.len(), 73, "{out}");
    for line in &lines {
        let (_, values) = line
            .split_once("constraint violations (× tolerance): ")
            .unwrap_or_else(|| panic!("{line}"));
        let values: Vec<f64> = values.split(' ').map(|v| v.parse().unwrap()).collect();
        assert!(*values.last().unwrap() <= 1.0, "{line}");
        assert_eq!(values.len(), line_iterations(line) + 1, "{line}");
    }
    // the first increment starts far from the constraints (the crank
    // turned by its driver, the rest not yet)
    assert!(
        lines[1].contains("e8") || lines[1].contains("e9"),
        "{}",
        lines[1]
    );
    let dir = scratch("static_lines");
    let (code, out, _) = run_model(&dir, "c.toml", CANTILEVER);
    assert_eq!(code, 0);
    let log = std::fs::read_to_string(dir.join("out/log.txt")).unwrap();
    assert!(log.contains("relative residuals: "), "{log}");
    assert!(!log.contains("constraint violations"), "{log}");
    // a redirected run leaves the increments' lines to log.txt unless
    // --verbose (docs/results.md, "What a run prints")
    assert!(!out.contains("relative residuals: "), "{out}");
    assert!(out.contains("completed: "), "{out}");
    let path = dir.join("c.toml");
    let (code, out, _) = unfold(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        dir.join("verbose").to_str().unwrap(),
        "--verbose",
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("relative residuals: "), "{out}");
}

/// The number of iterations an increment line gives.
fn line_iterations(line: &str) -> usize {
    line.split("iterations")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .unwrap()
}

/// The shallow clamped arch of the new-user trial under load control in
/// increments of 0.05 warns on stderr, in log.txt and in summary.json
/// about the increments across which the tangent's determinant changed
/// sign, among them increment 2 (t = 0.05 to 0.1), across the limit load
/// t ≈ 0.0845; the run goes on (exit 0).
#[test]
fn the_run_warns_about_limit_points_passed() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/shallow_arch.toml");
    let text = &std::fs::read_to_string(path).expect("the arch model");
    let dir = scratch("arch_limit");
    let (code, out, err) = run_model(&dir, "arch.toml", text);
    assert_eq!(code, 0, "{out}{err}");
    let warning = "warning: increment 2 (t = 0.05 to 0.1): the determinant of the tangent stiffness changed sign within this increment";
    assert!(
        err.contains(warning) && err.contains("control = \"arc_length\""),
        "{err}"
    );
    let log = std::fs::read_to_string(dir.join("out/log.txt")).unwrap();
    assert!(log.contains(warning), "{log}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    let warnings = summary["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .starts_with("increment 2 (t = 0.05 to 0.1)")),
        "{warnings:?}"
    );
}

/// A kinetostatic analysis is named so, not `static`, in what a run
/// writes: the console, `log.txt` and the analyses of `summary.json`.
/// It is solved as a static one, so its restart files continue it (and
/// those written as `static` before it had its own name still do).
#[test]
fn kinetostatic_runs_are_named_kinetostatic() {
    let dir = scratch("kinetostatic");
    let text = pendulum(
        "1.0",
        None,
        "[analysis]\ntype = \"kinetostatic\"\nend_time = 1.0\n",
    );
    let (code, out, err) = run_model(&dir, "pendulum.toml", &text);
    assert_eq!(code, 0, "{err}");
    let log = std::fs::read_to_string(dir.join("out/log.txt")).unwrap();
    let first = log.lines().next().unwrap();
    assert!(first.contains("kinetostatic analysis to t = 1"), "{first}");
    assert!(out.contains("kinetostatic analysis to t = 1"), "{out}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["analyses"][0]["type"], "kinetostatic", "{summary}");
    // its restart file, as written and as an older one naming it static
    let restart = dir.join("out/restart.json");
    let written = std::fs::read_to_string(&restart).unwrap();
    assert!(written.contains("\"analysis_type\":\"kinetostatic\""));
    let older = dir.join("older.json");
    std::fs::write(
        &older,
        written.replace(
            "\"analysis_type\":\"kinetostatic\"",
            "\"analysis_type\":\"static\"",
        ),
    )
    .unwrap();
    let model = dir.join("pendulum.toml");
    std::fs::write(&model, text.replace("end_time = 1.0", "end_time = 2.0")).unwrap();
    for (name, file) in [("again", &restart), ("older", &older)] {
        let o = dir.join(name);
        let (code, _, err) = unfold(&[
            "run",
            model.to_str().unwrap(),
            "--restart",
            file.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{name}: {err}");
    }
}
