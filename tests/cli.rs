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
        &["beam 1", "duplicate element id"],
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

#[test]
fn malformed_file_and_missing_file() {
    assert_rejected(
        "malformed",
        "[[nodes]\nid = 1",
        &["TOML parse error at line 1"],
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
    let text = format!("{CANTILEVER}\n[analysis]\ntype = \"dynamic\"\nend_time = -1.0\n");
    assert_rejected(
        "bad_analysis",
        &text,
        &[
            "analysis",
            "unknown analysis type \"dynamic\"",
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
        "{CANTILEVER}\n[[nodes]]\nid = 4\nx = [1.0, 0.0, 0.0]\n\n[[rigid_bodies]]\nid = 20\nnode = 4\nmass = 1.0\n\n{extra}"
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
