//! The checks of the start of a dynamic run through the command-line
//! tool: `unfold check` runs those of `unfold run` (initial velocities
//! against joints, latches and rolling contacts) with the same message and
//! exit code 2, a run rejected there leaves `summary.json` alone (status
//! `failed`), a latch at its value at `t = 0` gets its own advice, and the
//! messages about initial velocities name each node once
//! (README.md, docs/results.md, docs/model-format.md).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::pendulum;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-start-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `unfold` with `args`: (exit code, stdout, stderr).
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

/// `unfold check MODEL` and `unfold run MODEL --out OUT --quiet`.
fn check_and_run(model: &Path, out: &Path) -> ((i32, String), (i32, String, String)) {
    let (code, _, err) = unfold(&["check", model.to_str().unwrap()]);
    let run = unfold(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    ((code, err), run)
}

/// The files in `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// The hanging pendulum of tests/common/pendulum.rs, hinged to the ground
/// about z at the origin, its body at (0, −0.5, 0), in a dynamic analysis;
/// `extra` tables added.
fn pendulum(extra: &str) -> String {
    pendulum::hanging(
        r#"title = "compound pendulum"
[analysis]
type = "dynamic"
end_time = 1.0
time_step = 0.001
max_step = 0.01"#,
        "",
        extra,
    )
}

/// The upright disc of tests/common/rolling_disc.rs, of radius 0.5
/// rolling along +y at 2 m/s (docs/model-format.md, `[[rolling_discs]]`),
/// its spin `spin` about the global x axis: −4 rad/s rolls, other values
/// slip.
fn disc(spin: f64) -> String {
    common::rolling_disc::upright_disc(
        r#"title = "rolling disc"
[analysis]
type = "dynamic"
end_time = 0.1
time_step = 0.01
adaptive = false"#,
        spin,
    )
}

/// Initial velocities that the constraints forbid: `unfold check` finds
/// them as `unfold run` does, with the same message and exit code 2; the
/// run leaves `summary.json` alone, `failed` with that message, and no
/// result file that could pass for results (no `nodes.csv`, no grid, no
/// restart file); a result set of an earlier run in the directory is
/// removed. Velocities that the constraints allow pass both.
#[test]
fn check_finds_the_initial_velocities_a_run_refuses() {
    let dir = scratch("velocities");
    let cases = [
        (
            // a velocity along the arm pulls the body off the hinge
            "joint",
            pendulum("[[initial_motion]]\nnodes = [2]\nvelocity = [0.0, 0.05, 0.0]\n"),
            "the initial velocities violate joint 3 equation",
        ),
        (
            // spinning at −3 rad/s while moving at 2 m/s: the rim slips
            "slip",
            disc(-3.0),
            "the initial velocities violate rolling disc 2 equation",
        ),
    ];
    for (name, text, wanted) in cases {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, text).unwrap();
        let out = dir.join(name);
        // results of an earlier, valid run of a model in the directory
        std::fs::write(
            dir.join("ok.toml"),
            if name == "slip" {
                disc(-4.0)
            } else {
                pendulum("")
            },
        )
        .unwrap();
        let ((code, err), _) = check_and_run(&dir.join("ok.toml"), &out);
        assert_eq!(code, 0, "{name}: {err}");
        assert!(out.join("nodes.csv").exists());

        let ((code, check_err), (run_code, _, run_err)) = check_and_run(&model, &out);
        assert_eq!(code, 2, "{name}: {check_err}");
        assert_eq!(run_code, 2, "{name}: {run_err}");
        let line = format!(
            "error: {}: dynamic analysis at t = 0: {wanted}",
            model.display()
        );
        assert!(
            check_err.contains(&line),
            "{name}: {line:?} not in {check_err}"
        );
        // the same message, and nothing else, from check and run
        assert_eq!(check_err, run_err, "{name}");
        assert_eq!(files(&out), ["summary.json"], "{name}");
        let s = summary(&out);
        assert_eq!(s["status"], "failed", "{name}");
        let message = s["message"].as_str().unwrap();
        assert!(message.contains(wanted), "{name}: {message}");
        assert_eq!(s["output_steps"], 0, "{name}");
    }
}

/// The same velocity check when a modal analysis comes first (it leaves
/// the state as it is): `check` and `run` refuse the model before the
/// modal analysis, which writes nothing.
#[test]
fn a_modal_analysis_first_does_not_hide_the_velocity_check() {
    let dir = scratch("modal-first");
    let text = pendulum("[[initial_motion]]\nnodes = [2]\nvelocity = [0.0, 0.05, 0.0]\n").replace(
        "[analysis]\ntype = \"dynamic\"",
        "[[analysis]]\ntype = \"modal\"\nmodes = 1\n\n[[analysis]]\ntype = \"dynamic\"",
    );
    let model = dir.join("m.toml");
    std::fs::write(&model, text).unwrap();
    let out = dir.join("out");
    let ((code, err), (run_code, _, run_err)) = check_and_run(&model, &out);
    assert_eq!((code, run_code), (2, 2), "{err}\n{run_err}");
    assert!(err.contains("violate joint 3 equation"), "{err}");
    assert_eq!(files(&out), ["summary.json"]);
}

/// A latch at its value at `t = 0` (within the event tolerance) starts
/// locked: initial velocities that turn its joint are refused with advice
/// that names the latch and says it is locked from the start, by `check`
/// and `run` alike (exit 2).
#[test]
fn a_latch_locked_at_the_start_gets_its_own_advice() {
    let dir = scratch("latch");
    let model = dir.join("latch.toml");
    // ω = 0.1 rad/s about the hinge: v = ω × r = (0.05, 0, 0) at the body
    std::fs::write(
        &model,
        pendulum(
            "[[initial_motion]]\nnodes = [2]\nangular_velocity = [0.0, 0.0, 0.1]\n\n[[latches]]\nid = 9\njoint = 3\nvalue = 1e-10\n",
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let ((code, err), (run_code, _, run_err)) = check_and_run(&model, &out);
    assert_eq!((code, run_code), (2, 2), "{err}\n{run_err}");
    for wanted in [
        "dynamic analysis at t = 0: latch 9 is at its locking value at t = 0",
        "so it is locked from the start, but the initial velocities move the joint",
        "start the joint away from the latch's value",
    ] {
        assert!(err.contains(wanted), "{wanted:?} not in {err}");
    }
    assert!(!err.contains("one rigid motion"), "{err}");
    // the joint's own rate: the body turns at +0.1 rad/s about the hinge's
    // axis z, the joint angle increases (joints.csv of the same motion)
    assert!(err.contains("its rate is 1.000e-1 "), "{err}");
    assert_eq!(err, run_err);
    assert_eq!(files(&out), ["summary.json"]);
}

/// A disc that slips at the start gets rolling advice, not the generic
/// advice of a joint: the centre speed v = 2 m/s along n × a = +y needs
/// the spin −v/r = −4 rad/s about the axle a = +x; −3 rad/s slips.
#[test]
fn a_slipping_disc_gets_rolling_advice() {
    let dir = scratch("slip-advice");
    let model = dir.join("slip.toml");
    std::fs::write(&model, disc(-3.0)).unwrap();
    let out = dir.join("out");
    let ((code, err), (run_code, _, run_err)) = check_and_run(&model, &out);
    assert_eq!((code, run_code), (2, 2), "{err}\n{run_err}");
    for wanted in [
        "the initial velocities violate rolling disc 2 equation",
        "no slip along the plane's tangent",
        "the disc must roll",
        "−v/r about the axle",
    ] {
        assert!(err.contains(wanted), "{wanted:?} not in {err}");
    }
    assert!(!err.contains("one rigid motion"), "{err}");
    assert_eq!(err, run_err);
}

/// A node given an initial velocity twice, and a velocity on a supported
/// component: the messages say where the first velocity came from and name
/// the node once.
#[test]
fn initial_velocity_messages_name_the_node_once() {
    let dir = scratch("messages");
    let cases = [
        (
            "twice",
            pendulum("[[initial_motion]]\nnodes = [2]\nvelocity = [0.1, 0.0, 0.0]\n").replace(
                "x = [0.0, -0.5, 0.0]",
                "x = [0.0, -0.5, 0.0]\nangular_velocity = [0.0, 0.0, 0.1]",
            ),
            "initial_motion[1]: node 2 already has an initial velocity from its [[nodes]] entry",
        ),
        (
            "twice-motion",
            pendulum(
                "[[initial_motion]]\nnodes = [2]\nvelocity = [0.1, 0.0, 0.0]\n\n[[initial_motion]]\nnodes = [2]\nvelocity = [0.1, 0.0, 0.0]\n",
            ),
            "initial_motion[2]: node 2 already has an initial velocity from initial_motion[1]",
        ),
        (
            "supported",
            pendulum("").replace(
                "x = [0.0, 0.0, 0.0]",
                "x = [0.0, 0.0, 0.0]\nvelocity = [0.1, 0.0, 0.0]",
            ),
            "node 1: the node is supported in x but is given a velocity there",
        ),
    ];
    for (name, text, wanted) in cases {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, text).unwrap();
        let ((code, err), (run_code, _, run_err)) = check_and_run(&model, &dir.join(name));
        assert_eq!((code, run_code), (2, 2), "{name}: {err}");
        assert!(
            err.contains(&format!("{}: {wanted}", model.display())),
            "{name}: {wanted:?} not in {err}"
        );
        assert_eq!(err, run_err, "{name}");
        assert!(!err.contains("from node"), "{name}: {err}");
    }
}

/// A slide on a vertical prismatic joint to the ground, starting at
/// `c = 0`, with the stop `limit` (`upper = -1.0`, …) on its coordinate.
fn slide_on_stop(limit: &str) -> String {
    format!(
        r#"title = "mass on a stop"
[analysis]
type = "dynamic"
end_time = 0.5
time_step = 0.002
max_step = 0.01

[[nodes]]
id = 1
x = [0.0, 0.0, 1.0]

[[rigid_bodies]]
id = 1
node = 1
mass = 1.0
inertia = [0.004, 0.004, 0.004]

[gravity]
acceleration = [0.0, 0.0, -9.81]

[[joints]]
id = 2
type = "prismatic"
nodes = [1]
axis = [0.0, 0.0, 1.0]

[[stops]]
id = 3
joint = 2
{limit}
restitution = 0.5
"#
    )
}

/// A stop whose limit the coordinate already passes at the start (an
/// `upper` written for a `lower`, a `lower` above the start) is refused
/// by `unfold check` and `unfold run` alike, exit code 2, naming the stop,
/// its joint, the coordinate, the limit and the overshoot; no impact law
/// resolves such a start (before this check, a run found a zero impulse
/// "impact" at every step of 1e-11 s, or closed the stop at the start
/// value, reporting a negative gap). A stop just reached at the start
/// (within the event tolerance) closes there, and one clear of it runs.
#[test]
fn a_stop_that_starts_beyond_its_limit_is_an_input_error() {
    let dir = scratch("stop-beyond");
    let cases = [
        (
            "upper",
            "upper = -1.0",
            "upper limit -1.000000e0 by 1.000e0",
        ),
        (
            "lower",
            "lower = 0.5",
            "lower limit 5.000000e-1 by 5.000e-1",
        ),
    ];
    for (name, limit, wanted) in cases {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, slide_on_stop(limit)).unwrap();
        let out = dir.join(name);
        let ((code, check_err), (run_code, _, run_err)) = check_and_run(&model, &out);
        assert_eq!(code, 2, "{name}: {check_err}");
        assert_eq!(run_code, 2, "{name}: {run_err}");
        let line = format!(
            "error: {}: dynamic analysis at t = 0: stop 3 starts beyond its limit at t = 0: the coordinate of joint 2 is 0.000000e0, beyond the {wanted}",
            model.display()
        );
        assert!(
            check_err.contains(&line),
            "{name}: {line:?} not in {check_err}"
        );
        assert_eq!(check_err, run_err, "{name}");
        assert_eq!(files(&out), ["summary.json"], "{name}");
    }
    // clear of its limit, and exactly on it: both run
    for (name, limit) in [("clear", "lower = -0.1"), ("touching", "lower = 0.0")] {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, slide_on_stop(limit)).unwrap();
        let ((code, err), (run_code, _, run_err)) = check_and_run(&model, &dir.join(name));
        assert_eq!(code, 0, "{name}: {err}");
        assert_eq!(run_code, 0, "{name}: {run_err}");
    }
}
