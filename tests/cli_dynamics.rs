//! Dynamic analyses through the command-line tool: a run alone and in a
//! sequence, the velocities and energies it writes (checked against the
//! closed forms of a rigid pendulum), a run that stops early, a restart
//! that repeats the uninterrupted run, an interrupted run, and bad input
//! (docs/results.md, docs/model-format.md).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::cli::{csv_rows as table, number as num, summary};
use common::hinged_panel::latched_panel;
use common::pendulum;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-dyn-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `unfold run MODEL --out OUT --quiet` and extra arguments.
fn run(model: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .arg("--quiet")
        .args(extra)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The steps (first column) of every CSV file in `out`, which must agree.
fn same_steps(out: &Path) -> Vec<usize> {
    let steps = |p: &Path| -> Vec<usize> {
        let mut s: Vec<usize> = std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect();
        s.dedup();
        s
    };
    let reference = steps(&out.join("steps.csv"));
    for entry in std::fs::read_dir(out).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy();
        // the modal analyses' tables are by mode
        // (events.csv lists events, by the step they happened on)
        if name.ends_with(".csv") && !name.starts_with("mode") && name != "events.csv" {
            assert_eq!(steps(&path), reference, "{}", path.display());
        }
    }
    reference
}

/// Mass (kg), distance of the centre of mass from the hinge (m), inertia
/// about the centre (kg·m²) and gravity (m/s²) of the pendulum below.
const M: f64 = pendulum::MASS;
const D: f64 = pendulum::DISTANCE;
const J: f64 = pendulum::INERTIA;
const G: f64 = pendulum::G;

/// The pendulum of tests/common/pendulum.rs (hinge id 7, gravity on its
/// default curve); `analysis` and `extra` tables added.
fn pendulum(analysis: &str, extra: &str) -> String {
    pendulum::pendulum(&format!("title = \"pendulum\"\n{analysis}"), 7, None, extra)
}

/// Fixed steps of 5 ms over a quarter swing and more.
const FIXED: &str = "[analysis]
type = \"dynamic\"
end_time = 0.6
time_step = 0.005
adaptive = false
output_times = [0.1234]
";

#[test]
fn pendulum_run_writes_velocities_and_a_small_energy_balance() {
    let dir = scratch("pendulum");
    let model = dir.join("pendulum.toml");
    std::fs::write(&model, pendulum(FIXED, "")).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &["--vtk-ascii"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let steps = same_steps(&out);

    // the output time between two steps is landed on: 24 steps of 5 ms,
    // one of 3.4 ms to 0.1234, then 96 of 5 ms from there, the last
    // shortened to land on 0.6
    let s = summary(&out);
    assert_eq!(s["status"], "completed");
    let d = &s["analyses"][0]["dynamic"];
    assert_eq!(d["steps"], 121, "{d}");
    assert_eq!(steps.len(), 122);
    let energies = table(&out.join("energies.csv"));
    assert!(energies
        .iter()
        .any(|r| (num(r, "time") - 0.1234).abs() < 1e-12));

    // energies against the closed forms of the state written: kinetic
    // ½ m |v|² + ½ J |ω|² of the body from nodes_velocities.csv, potential
    // m g y of its centre of mass from nodes.csv, both to the 10
    // significant digits of the files
    let joints = table(&out.join("joints.csv"));
    let nodes: Vec<_> = table(&out.join("nodes.csv"))
        .into_iter()
        .filter(|r| r["node"] == "2")
        .collect();
    let velocities: Vec<_> = table(&out.join("nodes_velocities.csv"))
        .into_iter()
        .filter(|r| r["node"] == "2")
        .collect();
    let mgd = M * G * D;
    let square = |r: &std::collections::HashMap<String, String>, k: [&str; 3]| -> f64 {
        k.iter().map(|c| num(r, c).powi(2)).sum()
    };
    let mut largest_error = 0.0f64;
    let mut largest_drift = 0.0f64;
    for ((e, j), (n, v)) in energies
        .iter()
        .zip(&joints)
        .zip(nodes.iter().zip(&velocities))
    {
        let kinetic =
            0.5 * M * square(v, ["vx", "vy", "vz"]) + 0.5 * J * square(v, ["wx", "wy", "wz"]);
        assert!(
            (num(e, "kinetic") - kinetic).abs() <= 1e-9 * mgd,
            "t = {}: kinetic {} vs ½ m v² + ½ J ω² = {kinetic}",
            e["time"],
            e["kinetic"]
        );
        let potential = M * G * num(n, "y");
        assert!((num(e, "gravity") - potential).abs() <= 1e-9 * mgd);
        // the rate of the hinge angle (differences along the motion) is the
        // body's angular velocity about z, to the digits of the files
        let rate = num(j, "angle_rate");
        assert!((num(v, "wz") - rate).abs() <= 1e-8 * (1.0 + rate.abs()));
        // the centre of mass turns about the hinge, |v| = d|θ̇|: the
        // index-3 equations hold the joint on positions, the projection
        // on velocities
        let speed = square(v, ["vx", "vy", "vz"]).sqrt();
        largest_drift = largest_drift.max((speed - D * rate.abs()).abs());
        largest_error = largest_error.max(num(e, "balance_error").abs());
    }
    // measured 1.9e-4 m/s at speeds up to 2.2 m/s (ωh ≈ 0.02) with the
    // velocities of the index-3 scheme; projected on the velocity
    // constraints after every step (docs/theory.md §15.7), 3.0e-10 m/s,
    // the digits of the files (13 significant, speeds of 2.2 m/s, and
    // the central difference of the projection, ~1e-10): 1e-8 bounds it
    println!("largest | |v| − d|θ̇| | = {largest_drift:.3e} m/s");
    assert!(largest_drift < 1e-8, "{largest_drift}");
    // the balance error of a second-order method with ωh ≈ 0.02: measured
    // 2.6e-4 of m g d (1.0e-3 with steps of 10 ms, 4× larger: second
    // order); 1e-3 bounds it
    assert!(largest_error < 1e-3 * mgd, "{largest_error}");
    let recorded = d["largest_energy_balance_error"].as_f64().unwrap();
    assert!((recorded - largest_error).abs() <= 1e-6 * largest_error.max(1e-12));
    // by 0.6 s the pendulum has passed the bottom: the kinetic energy
    // reached m g d there (energy conservation), within the balance error
    let kinetic = d["largest_kinetic_energy"].as_f64().unwrap();
    assert!((kinetic - mgd).abs() < 2e-3 * mgd, "{kinetic}");

    // the grids carry the velocities
    let grid = std::fs::read_to_string(out.join("vtk/step_00010.vtu")).unwrap();
    assert!(grid.contains("Name=\"velocity\""), "{grid}");
    assert!(grid.contains("Name=\"angular_velocity\""));
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(
        log.contains("step   10  t = 0.050000  h = 5.000e-3"),
        "{log}"
    );
    assert!(log
        .lines()
        .last()
        .unwrap()
        .starts_with("completed: 121 steps, 0 rejected"));
}

/// The same sequence with its load given no curve: the default ramp
/// f = t of a sequence that starts static goes on growing through the
/// dynamic analysis (docs/model-format.md, "Loads in time"), which `check`
/// and `run` warn about, naming the load and the analysis; with the curve
/// written, no such warning.
#[test]
fn a_load_ramped_through_the_motion_after_a_preload_is_warned_about() {
    let dir = scratch("ramped");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/boom_release.toml"),
    )
    .unwrap();
    assert!(text.contains("curve = \"preload_release\""));
    for (name, text, warned) in [
        (
            "ramped",
            text.replace("curve = \"preload_release\"", ""),
            true,
        ),
        (
            "confirmed",
            text.replace("curve = \"preload_release\"", "curve = \"ramp\""),
            false,
        ),
        ("held", text.clone(), false),
    ] {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, text).unwrap();
        let checked = check(&model);
        let err = stderr(&checked);
        assert!(checked.status.success(), "{name}: {err}");
        let warning = "loads[1] (node 11): follows the default ramp f = t, which goes on growing through the dynamic analysis[2] (t = 1 to 2.5)";
        assert_eq!(err.contains(warning), warned, "{name}: {err}");
    }
}

/// Static preload, release (dynamic), modes about the final state
/// (examples/boom_release.toml): one set of files, steps numbered on, the
/// free vibration at the frequency the modal analysis finds.
#[test]
fn static_dynamic_modal_sequence_in_one_record() {
    let dir = scratch("sequence");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/boom_release.toml");
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&out);
    let kinds: Vec<&str> = s["analyses"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["type"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["static", "dynamic", "modal"]);
    assert!(s["analyses"][0].get("dynamic").is_none());
    assert_eq!(s["analyses"][1]["dynamic"]["steps"], 600);
    let steps = same_steps(&out);
    assert_eq!(steps, (0..steps.len()).collect::<Vec<_>>());

    // static steps: at rest, no work nor balance; dynamic steps: all
    let energies = table(&out.join("energies.csv"));
    let first_dynamic = energies
        .iter()
        .position(|r| !r["balance_error"].is_empty())
        .unwrap();
    assert_eq!(
        first_dynamic, 5,
        "4 increments and the start, then dynamics"
    );
    assert!(energies[..first_dynamic]
        .iter()
        .all(|r| num(r, "kinetic") == 0.0));
    // the strain energy of the preload, P²L³/(6 EI) = 0.970 J (a tip load
    // on a cantilever), to the shear and the 5 % deflection
    let preload = num(&energies[first_dynamic - 1], "strain");
    assert!((preload - 0.9701).abs() < 0.01, "{preload}");
    // released: its energy swings between strain and kinetic; the release
    // excites the higher bending modes, whose energy (3.3e-3 of it, measured)
    // the numerical dissipation of ρ∞ = 0.9 takes out in the first steps
    for r in &energies[first_dynamic..] {
        let total = num(r, "kinetic") + num(r, "strain");
        assert!((total - preload).abs() < 5e-3 * preload, "{r:?}");
        assert!(num(r, "balance_error").abs() < 5e-3 * preload);
    }

    // the tip's free vibration: its period, from the first to the last
    // zero crossing upwards and downwards (five periods), against 1/f₁ of
    // the modal analysis about the final state (measured 0.12 %); a single
    // period is off by up to 0.9 %, its crossings shifted by the higher
    // bending modes the release excites: over five, 0.5 % bounds it
    let tip: Vec<(f64, f64)> = table(&out.join("nodes.csv"))
        .iter()
        .filter(|r| r["node"] == "11" && num(r, "time") > 1.0)
        .map(|r| (num(r, "time"), num(r, "uz")))
        .collect();
    let crossings = |up: bool| -> Vec<f64> {
        tip.windows(2)
            .filter(|w| {
                if up {
                    w[0].1 < 0.0 && w[1].1 >= 0.0
                } else {
                    w[0].1 > 0.0 && w[1].1 <= 0.0
                }
            })
            .map(|w| w[0].0 + (w[1].0 - w[0].0) * (-w[0].1) / (w[1].1 - w[0].1))
            .collect()
    };
    let mean_period = |c: Vec<f64>| (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64;
    let (up, down) = (crossings(true), crossings(false));
    assert!(up.len() >= 5 && down.len() >= 5, "{up:?} {down:?}");
    let period = 0.5 * (mean_period(up) + mean_period(down));
    let modes = table(&out.join("modes.csv"));
    let f1: f64 = num(&modes[0], "frequency_hz");
    assert!(
        (period * f1 - 1.0).abs() < 5e-3,
        "period {period} s, 1/f1 = {}",
        1.0 / f1
    );
    // and Euler–Bernoulli's 3.5616 Hz for the clamped rod, within the
    // 10 elements and the shear of the model (0.3 %)
    assert!((f1 / 3.5616 - 1.0).abs() < 3e-3, "{f1}");
}

/// Dynamic, static, dynamic: the equilibrium after the swing is at rest,
/// and the motion after it starts from rest (the pendulum hangs still).
#[test]
fn an_equilibrium_after_a_motion_is_at_rest() {
    let dir = scratch("rest");
    let model = dir.join("rest.toml");
    let analyses = "[[analysis]]
type = \"dynamic\"
end_time = 0.3
time_step = 0.01
adaptive = false

[[analysis]]
type = \"static\"
end_time = 0.4

[[analysis]]
type = \"dynamic\"
end_time = 0.6
time_step = 0.01
adaptive = false
";
    std::fs::write(&model, pendulum(analyses, "")).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = summary(&out);
    assert_eq!(s["analyses"][2]["dynamic"]["steps"], 20);
    // hanging at rest in the last analysis: no kinetic energy beyond
    // round-off (m g d = 9.81 J)
    let energies = table(&out.join("energies.csv"));
    let last: Vec<_> = energies
        .iter()
        .filter(|r| num(r, "time") > 0.4 + 1e-9)
        .collect();
    assert_eq!(last.len(), 20);
    for r in last {
        assert!(num(r, "kinetic") < 1e-12 * M * G * D, "{r:?}");
    }
}

/// A moment of 1e5 N·m applied at once at t = 0.3 that Newton cannot
/// follow in 4 iterations, with no smaller step allowed: the run stops at
/// the last converged step, keeps every file with the same steps, says
/// why and exits 1.
#[test]
fn a_dynamic_run_that_cannot_go_on_stops_with_its_files() {
    let dir = scratch("failing");
    let model = dir.join("kick.toml");
    let analysis = FIXED
        .replace(
            "time_step = 0.005",
            "time_step = 0.01\nmin_step = 0.01\nmax_iterations = 4",
        )
        .replace("output_times = [0.1234]\n", "");
    let kick = r#"
[[curves]]
name = "kick"
points = [[0.0, 0.0], [0.3, 0.0], [0.3001, 1.0]]

[[loads]]
node = 2
moment = [0.0, 0.0, 1e5]
curve = "kick"
"#;
    std::fs::write(&model, pendulum(&analysis, kick)).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("dynamic analysis at t = 0.3: no convergence at step 31"),
        "{err}"
    );
    assert!(err.contains("largest residual at node 2"), "{err}");
    assert!(err.contains("results up to t = 0.3 are kept"), "{err}");
    let steps = same_steps(&out);
    assert_eq!(steps.len(), 31);
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    assert!(s["message"].as_str().unwrap().contains("below min_step"));
    assert_eq!(s["analyses"][0]["dynamic"]["steps"], 30);
    // the restart file holds the last converged step
    let restart: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("restart.json")).unwrap()).unwrap();
    assert!((restart["time"].as_f64().unwrap() - 0.3).abs() < 1e-12);
}

/// The largest relative difference between two arrays of numbers (nested
/// JSON arrays), relative to the largest magnitude of the first.
fn difference(a: &serde_json::Value, b: &serde_json::Value) -> (f64, f64) {
    fn flat(v: &serde_json::Value, out: &mut Vec<f64>) {
        match v {
            serde_json::Value::Array(a) => a.iter().for_each(|x| flat(x, out)),
            serde_json::Value::Number(n) => out.push(n.as_f64().unwrap()),
            _ => {}
        }
    }
    let (mut x, mut y) = (Vec::new(), Vec::new());
    flat(a, &mut x);
    flat(b, &mut y);
    assert_eq!(x.len(), y.len());
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = x
        .iter()
        .zip(&y)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    (diff, scale)
}

/// A run restarted from `restart-0.3.json` ends in the state of the run
/// that was never stopped: positions, orientations, velocities,
/// accelerations and multipliers to 1e-12 (fixed steps), and its energy
/// balance goes on.
#[test]
fn a_restarted_dynamic_run_repeats_the_uninterrupted_one() {
    let dir = scratch("restart");
    let model = dir.join("pendulum.toml");
    std::fs::write(&model, pendulum(FIXED, "[output]\nrestart_times = [0.3]\n")).unwrap();
    let whole = dir.join("whole");
    let o = run(&model, &whole, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let part = dir.join("part");
    let o = run(
        &model,
        &part,
        &[
            "--restart",
            whole.join("restart-0.3.json").to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |out: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(out.join("restart.json")).unwrap()).unwrap()
    };
    let (a, b) = (read(&whole), read(&part));
    for key in [
        "x",
        "q",
        "velocity",
        "acceleration",
        "pseudo_acceleration",
        "multipliers",
    ] {
        let (diff, scale) = difference(&a["state"][key], &b["state"][key]);
        assert!(diff <= 1e-12 * scale, "{key}: {diff:e} of {scale:e}");
    }
    let (diff, scale) = difference(
        &serde_json::json!([
            a["motion"]["energies"]["balance_error"],
            a["motion"]["energies"]["kinetic"]
        ]),
        &serde_json::json!([
            b["motion"]["energies"]["balance_error"],
            b["motion"]["energies"]["kinetic"]
        ]),
    );
    assert!(diff <= 1e-12 * scale.max(1.0), "{diff:e}");
    // the restarted run started at 0.3 and took the 60 steps left
    assert_eq!(summary(&part)["analyses"][0]["dynamic"]["steps"], 60);
}

/// A restart into the directory that holds its restart file would replace
/// the histories of the run it continues: refused with exit 2, the
/// histories left as they were, the way out named.
#[test]
fn a_restart_into_its_own_results_directory_is_refused() {
    let dir = scratch("restart-same-dir");
    let model = dir.join("pendulum.toml");
    std::fs::write(&model, pendulum(FIXED, "[output]\nrestart_times = [0.3]\n")).unwrap();
    let first = dir.join("first");
    let o = run(&model, &first, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let steps = std::fs::read_to_string(first.join("steps.csv")).unwrap();
    for file in ["restart-0.3.json", "restart.json"] {
        // the same directory, named another way (a trailing `.`)
        let o = run(
            &model,
            &first.join("."),
            &["--restart", first.join(file).to_str().unwrap()],
        );
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains(file)
                && err.contains("is in the output directory")
                && err.contains("first-continued"),
            "{err}"
        );
        assert_eq!(
            std::fs::read_to_string(first.join("steps.csv")).unwrap(),
            steps,
            "the first run's histories are kept"
        );
    }
    // into another directory: accepted
    let o = run(
        &model,
        &dir.join("second"),
        &[
            "--restart",
            first.join("restart-0.3.json").to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Constraints that contradict each other in a dynamic analysis: a
/// driver turning a hinge to 120° through a rigid latch at 90°, and two
/// drivers of one hinge to different angles. The later equation is found
/// redundant (docs/joints.md §5) and left out; once a step violates it
/// the analysis stops (exit 1) with `inconsistent constraints`, naming
/// it, the steps before kept, instead of running on with the joint
/// through its latch.
#[test]
fn contradicting_constraints_stop_a_dynamic_analysis() {
    let dir = scratch("inconsistent");
    let body = "[analysis]
type = \"dynamic\"
end_time = 1.0
time_step = 0.01

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[rigid_bodies]]
id = 10
node = 1
mass = 1.0
inertia = [0.01, 0.1, 0.1]
center_of_mass = [0.5, 0.0, 0.0]

[[joints]]
id = 1
type = \"revolute\"
nodes = [1]
axis = [0.0, 0.0, 1.0]

[[curves]]
name = \"s\"
function = \"smooth_step\"
start = 0.0
end = 1.0

[[drivers]]
id = 4
joint = 1
value = 120.0
unit = \"deg\"
curve = \"s\"
";
    let through_latch = format!(
        "{body}
[[latches]]
id = 3
joint = 1
value = 90.0
unit = \"deg\"
"
    );
    let two_drivers = format!(
        "{body}
[[drivers]]
id = 5
joint = 1
value = 60.0
unit = \"deg\"
curve = \"s\"
"
    );
    for (name, text, culprit) in [
        ("latch", through_latch, "latch 3 equation 1"),
        ("drivers", two_drivers, "driver 5 equation 1"),
    ] {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, text).unwrap();
        let out = dir.join(name);
        let o = run(&model, &out, &[]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert!(
            err.contains("inconsistent constraints")
                && err.contains(&format!(
                    "{culprit} was found redundant but is now violated"
                )),
            "{name}: {err}"
        );
        let s = summary(&out);
        assert_eq!(s["status"], "failed", "{name}");
        // the joint never passed the latch: every angle written is at
        // most 90° within the rotation tolerance 1e-6 rad (the steps after
        // the lock grow from a tiny landing step, and the violation passes
        // the tolerance within a few: measured 5.6e-7 rad at the last
        // step kept); with two drivers the first step stops it
        let angles: Vec<f64> = table(&out.join("joints.csv"))
            .iter()
            .map(|r| num(r, "angle"))
            .collect();
        assert!(!angles.is_empty(), "{name}");
        let limit = std::f64::consts::FRAC_PI_2 + 1e-6;
        assert!(angles.iter().all(|&a| a <= limit), "{name}: {angles:?}");
    }
}

/// A dynamic analysis of a model without mass (a cantilever whose section
/// has no `mass_per_length`) has no motion to follow: refused by `check`
/// and by `run` with exit 2, as a modal analysis of it is, instead of a
/// run of Newton iterations on a state that does not move.
#[test]
fn a_dynamic_analysis_of_a_model_without_mass_is_refused() {
    let dir = scratch("massless");
    let model = dir.join("massless.toml");
    std::fs::write(
        &model,
        "[analysis]
type = \"dynamic\"
end_time = 1.0
time_step = 0.02

[[sections]]
name = \"s\"
EA = 1.0e6
GA2 = 4.0e5
GA3 = 4.0e5
GJ = 50.0
EI2 = 50.0
EI3 = 50.0

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]

[[beam_lines]]
nodes = [1, 2]
elements = 4
section = \"s\"

[[supports]]
node = 1
fixed = [\"all\"]

[[loads]]
node = 2
force = [0.0, 0.0, -1.0]
",
    )
    .unwrap();
    let checked = check(&model);
    assert_eq!(checked.status.code(), Some(2), "{}", stderr(&checked));
    let o = run(&model, &dir.join("out"), &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("massless.toml") && err.contains("the model has no mass"),
        "{err}"
    );
}

/// Bad input is refused before any step, exit 2, naming the analysis or
/// the entity and what is wrong.
#[test]
fn bad_dynamic_input_is_refused_with_exit_2() {
    let dir = scratch("bad");
    let cases: [(&str, String, &[&str]); 7] = [
        (
            "rho",
            pendulum(
                &FIXED.replace("adaptive", "rho_infinity = 1.5\nadaptive"),
                "",
            ),
            &["analysis", "rho_infinity must lie in [0, 1]", "1.5"],
        ),
        (
            "step",
            pendulum(
                &FIXED.replace("time_step = 0.005", "time_step = -0.005"),
                "",
            ),
            &["analysis", "time_step"],
        ),
        (
            "bounds",
            pendulum(
                &FIXED.replace("adaptive = false", "min_step = 0.01\nmax_step = 0.001"),
                "",
            ),
            &[
                "analysis",
                "min_step (0.01) must not exceed max_step (0.001)",
            ],
        ),
        (
            "unknown",
            pendulum(
                FIXED,
                "[[initial_motion]]\nnodes = [2, 99]\nangular_velocity = [0.0, 0.0, 1.0]\n",
            ),
            &["initial_motion[1]", "node 99 does not exist"],
        ),
        (
            "support",
            // the hinge node is clamped: it cannot turn with the body
            pendulum(
                FIXED,
                "[[initial_motion]]\nnodes = [1, 2]\nangular_velocity = [0.0, 0.0, 1.0]\n",
            ),
            &[
                "initial_motion[1]",
                "node 1 is supported in rz but is given an angular velocity",
            ],
        ),
        (
            "joint",
            // a velocity along the arm pulls the body off the hinge
            pendulum(
                FIXED,
                "[[initial_motion]]\nnodes = [2]\nvelocity = [1.0, 0.0, 0.0]\n",
            ),
            &["initial velocities violate joint 7", "equation"],
        ),
        (
            "driver",
            // the default ramp moves the hinge from t = 0, the body at rest
            pendulum(FIXED, "[[drivers]]\nid = 20\njoint = 7\nvalue = 1.0\n"),
            &[
                "the initial velocities violate driver 20",
                "function = \"smooth_step\"",
            ],
        ),
    ];
    for (name, text, wanted) in cases {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, text).unwrap();
        let o = run(&model, &dir.join(name), &[]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        for w in wanted {
            assert!(err.contains(w), "{name}: {w:?} not in {err}");
        }
        assert!(err.contains(&format!("{name}.toml")), "{name}: {err}");
        if name == "step" {
            // min_step and max_step were not given: their defaults, derived
            // from time_step, are not reported as errors of their own
            assert!(
                !err.contains("min_step") && !err.contains("max_step"),
                "{err}"
            );
        }
    }
}

/// SIGINT stops a dynamic run after its current step, as a static one:
/// exit 130, every file with the same steps, the summary and the restart
/// file at the last step.
#[cfg(unix)]
#[test]
fn sigint_stops_a_dynamic_run_after_a_step() {
    use std::time::{Duration, Instant};
    let dir = scratch("sigint");
    let model = dir.join("long.toml");
    // 100,000 steps: minutes if not interrupted
    let long = FIXED
        .replace("end_time = 0.6", "end_time = 500.0")
        .replace("output_times = [0.1234]\n", "");
    std::fs::write(&model, pendulum(&long, "")).unwrap();
    let out = dir.join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        let n = std::fs::read_to_string(out.join("steps.csv"))
            .map(|t| t.lines().count())
            .unwrap_or(0);
        if n > 5 {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no step written");
        std::thread::sleep(Duration::from_millis(10));
    }
    // SAFETY: kill(2) on our own child's pid
    assert_eq!(
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) },
        0
    );
    let status = child.wait().unwrap();
    let mut err = String::new();
    use std::io::Read;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    let steps = same_steps(&out);
    let s = summary(&out);
    assert_eq!(s["status"], "interrupted");
    assert_eq!(s["output_steps"].as_u64().unwrap() as usize, steps.len());
    let restart: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("restart.json")).unwrap()).unwrap();
    assert_eq!(restart["time"], s["final_time"]);
    assert!(restart["motion"]["energies"].is_object());
}

/// A latch's results through the command line: `latches.csv` holds the
/// same steps as `steps.csv`; the latch is open (0) until the step that
/// lands on the lock and locked (1) from then on; on that step the
/// coordinate is the locking value, 90°, within the event tolerance of
/// 1e-8 rad (docs/joints.md §6.2) and stays there.
#[test]
fn latch_results_are_written_with_every_step() {
    let dir = scratch("latch");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/latched_panels.toml");
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let latches = table(&out.join("latches.csv"));
    let steps = table(&out.join("steps.csv"));
    assert_eq!(latches.len(), steps.len());
    let value =
        |r: &std::collections::HashMap<String, String>, k: &str| -> f64 { r[k].parse().unwrap() };
    let first = latches
        .iter()
        .position(|r| value(r, "locked") == 1.0)
        .expect("the latch locks within 0.1 s");
    assert!(first > 0);
    for r in &latches[..first] {
        assert_eq!(value(r, "locked"), 0.0);
        assert!(value(r, "gap") < 0.0);
    }
    for r in &latches[first..] {
        assert_eq!(value(r, "locked"), 1.0);
        assert!((value(r, "coordinate") - std::f64::consts::FRAC_PI_2).abs() < 1e-8);
        assert!(value(r, "gap").abs() < 1e-8);
    }
}

/// A modal analysis of a model with nothing left to vibrate (a panel
/// hinged to the ground whose latch has locked) has no mode: a note, not
/// an error, and the run completes (exit 0). Before the lock the same
/// model has one mode, `ω = √(k/J_O) = √(2/(1/3)) = 2.4495 rad/s`.
#[test]
fn a_modal_analysis_with_no_mode_left_is_a_note() {
    let dir = scratch("nomode");
    let model = dir.join("panel.toml");
    std::fs::write(
        &model,
        latched_panel(
            "panel latched to the ground, then its modes",
            r#"[[analysis]]
type = "modal"
modes = 3
[[analysis]]
type = "dynamic"
end_time = 0.6
time_step = 0.001
max_step = 0.01
output_every = 10
[[analysis]]
type = "modal"
modes = 3"#,
            90.0,
            "",
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains("the model has no mode"), "{log}");
    let modes = table(&out.join("modes.csv"));
    assert_eq!(modes.len(), 1, "one mode before the lock, none after");
    // √(k/J_O), J_O = 1/12 + 0.5² = 1/3 kg·m²: to round-off of the solver
    assert!((num(&modes[0], "omega_rad_s") - 6f64.sqrt()).abs() < 1e-9);
    assert_eq!(summary(&out)["status"], "completed");
}

/// The header of `events.csv` (docs/results.md).
const EVENTS_HEADER: &str =
    "step,increment,time,element,kind,joint,coordinate,rate_before,rate_after,impulse,energy_lost";

/// The lock of the latched panels is one row of `events.csv`, on the step
/// where `latches.csv` first shows the latch locked, and is counted in
/// `summary.json`.
#[test]
fn events_csv_lists_the_lock_of_a_latch() {
    let dir = scratch("events-latch");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/latched_panels.toml");
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("events.csv")).unwrap();
    assert_eq!(text.lines().next(), Some(EVENTS_HEADER));
    let events = table(&out.join("events.csv"));
    assert_eq!(events.len(), 1, "{text}");
    let e = &events[0];
    assert_eq!(e["kind"], "lock");
    assert_eq!(e["element"], "20");
    assert_eq!(e["joint"], "10");
    let latches = table(&out.join("latches.csv"));
    let first = latches
        .iter()
        .find(|r| num(r, "locked") == 1.0)
        .expect("the latch locks");
    assert_eq!(e["step"], first["step"]);
    // the same time (to the digits of each file, 1e-10 relative)
    assert!((num(e, "time") - num(first, "time")).abs() <= 1e-10 * num(e, "time"));
    // at the locking angle (90°, within the event tolerance 1e-8 rad)
    assert!((num(e, "coordinate") - std::f64::consts::FRAC_PI_2).abs() <= 1e-8);
    assert!(num(e, "rate_before") > 0.0 && num(e, "rate_after") == 0.0);
    assert!(num(e, "impulse") < 0.0 && num(e, "energy_lost") > 0.0);
    let s = summary(&out);
    let d = &s["analyses"][0]["dynamic"];
    assert_eq!(d["locks"], 1, "{d}");
    assert_eq!(d["impacts"], 0, "{d}");
    assert_eq!(d["contacts_closed"], 0, "{d}");
    assert_eq!(d["contacts_released"], 0, "{d}");
}

/// The pendulum falls from the horizontal onto a stop at −60° with
/// restitution 0.5: rebounds (`impact` rows, the rate reversed and halved)
/// until the rebound is too slow, then rests (`contact`); the counts in
/// `summary.json` match the rows. Without the stop (and without any
/// event), `events.csv` holds its header alone.
#[test]
fn events_csv_lists_the_impacts_of_a_stop() {
    let dir = scratch("events-stop");
    let model = dir.join("pendulum.toml");
    let analysis = "[analysis]\ntype = \"dynamic\"\nend_time = 3.0\ntime_step = 0.01\n";
    let stop =
        "curve = \"constant\"\n\n[[stops]]\nid = 8\njoint = 7\nlower = -60.0\nunit = \"deg\"\nrestitution = 0.5\n";
    std::fs::write(&model, pendulum(analysis, stop)).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let events = table(&out.join("events.csv"));
    assert!(events.len() >= 2, "{events:?}");
    let (last, impacts) = events.split_last().unwrap();
    for e in impacts {
        assert_eq!(e["kind"], "impact");
        assert_eq!(e["element"], "8");
        assert_eq!(e["joint"], "7");
        assert!((num(e, "coordinate") + 60f64.to_radians()).abs() <= 1e-8);
        // ω⁺ = −e ω⁻ (1e-6, the digits of the file)
        let (before, after) = (num(e, "rate_before"), num(e, "rate_after"));
        assert!((after + 0.5 * before).abs() <= 1e-6 * before.abs(), "{e:?}");
        assert!(num(e, "impulse") > 0.0 && num(e, "energy_lost") > 0.0);
    }
    assert_eq!(last["kind"], "contact");
    // the closed stop holds the coordinate: its rate at round-off
    // (1e-12 of the approach)
    let closing = num(last, "rate_before").abs();
    assert!(num(last, "rate_after").abs() <= 1e-12 * closing, "{last:?}");
    let s = summary(&out);
    let d = &s["analyses"][0]["dynamic"];
    assert_eq!(d["impacts"], impacts.len(), "{d}");
    assert_eq!(d["contacts_closed"], 1, "{d}");
    assert_eq!(d["locks"], 0, "{d}");
    // the stop's results: in contact at the end, holding the pendulum
    let stops = table(&out.join("stops.csv"));
    let end = stops.last().unwrap();
    assert_eq!(num(end, "contact"), -1.0);
    assert!(num(end, "load") > 0.0);

    // no stop: the header alone
    std::fs::write(
        &model,
        pendulum(
            &analysis.replace("3.0", "0.05").replace("0.01", "0.001"),
            "",
        ),
    )
    .unwrap();
    let o = run(&model, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("events.csv")).unwrap();
    assert_eq!(text, format!("{EVENTS_HEADER}\n"));
    assert!(!out.join("stops.csv").exists());
    let s = summary(&out);
    assert_eq!(s["analyses"][0]["dynamic"]["impacts"], 0);
}

/// `unfold check MODEL`.
fn check(model: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(["check", model.to_str().unwrap()])
        .output()
        .unwrap()
}

/// With `adaptive = false` the steps are `time_step` (docs/model-format.md)
/// even when `max_step` is given larger, which is warned about as having
/// no effect: over 0.6 s in steps of 5 ms with an output time at 0.1234,
/// every step is 5 ms but the one landing on 0.1234 (3.4 ms) and the last
/// one, landing on 0.6 (1.6 ms). (Before, easy steps grew by 1.5 up to
/// `max_step`: 1004 steps instead of 10 000 in the case reported.)
#[test]
fn fixed_steps_stay_at_time_step_when_max_step_is_given() {
    let dir = scratch("fixed-max-step");
    let model = dir.join("pendulum.toml");
    std::fs::write(
        &model,
        pendulum(&FIXED.replace("adaptive", "max_step = 0.05\nadaptive"), ""),
    )
    .unwrap();
    let c = check(&model);
    let text = String::from_utf8_lossy(&c.stdout).into_owned() + &stderr(&c);
    assert_eq!(c.status.code(), Some(0), "{text}");
    assert!(
        text.contains("max_step (0.05) has no effect with adaptive = false"),
        "{text}"
    );
    assert!(text.contains("time step 0.005 (fixed)"), "{text}");
    assert!(text.contains("max_step 0.005"), "{text}");
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rows = table(&out.join("steps.csv"));
    let sizes: Vec<f64> = rows[1..].iter().map(|r| num(r, "step_size")).collect();
    // steps.csv writes 7 significant digits
    let h = 0.005;
    assert!(sizes.iter().all(|&s| s <= h * (1.0 + 1e-6)), "{sizes:?}");
    let short: Vec<f64> = sizes
        .iter()
        .copied()
        .filter(|&s| s < h * (1.0 - 1e-6))
        .collect();
    assert_eq!(short.len(), 2, "{short:?}");
    assert!((short[0] - 0.0034).abs() < 1e-9, "{short:?}");
    assert!((short[1] - 0.0016).abs() < 1e-9, "{short:?}");
    assert_eq!(sizes.len(), 121);
}

/// The step settings are checked with messages that name what the user
/// wrote (docs/model-format.md, dynamic analyses):
/// - `max_step` alone, smaller than the default first step span/100: the
///   first step is `max_step` (no error about derived values);
/// - a `time_step` lost in the round-off of `t` is named as such, not
///   through the `min_step` derived from it;
/// - fixed steps of 1 µs over 10 s: too many steps, not a `min_step`
///   message;
/// - two output times nearer than a step can be: an error naming both
///   (before, the second was dropped silently).
#[test]
fn step_settings_are_refused_naming_what_was_written() {
    let dir = scratch("step-settings");
    let dynamic = |keys: &str| format!("[analysis]\ntype = \"dynamic\"\nend_time = 10.0\n{keys}\n");
    let cases: [(&str, String, Option<&str>, &[&str]); 4] = [
        (
            "max-step-only",
            dynamic("max_step = 0.01"),
            None,
            &["time step 0.01 (adaptive"],
        ),
        (
            "tiny-step",
            dynamic("time_step = 1e-12\nmax_step = 0.01"),
            Some("min_step"),
            &[
                "analysis: time_step must be at least end_time·1e-12 = 1e-11",
                "got 1e-12",
            ],
        ),
        (
            "many-steps",
            dynamic("time_step = 1e-6\nadaptive = false"),
            Some("min_step"),
            &["would need more than 1e6 steps"],
        ),
        (
            "close-output-times",
            dynamic(
                "time_step = 0.001\nmax_step = 0.01\noutput_times = [0.0005, 0.00050000001, 3.0]",
            ),
            None,
            &[
                "output_times 0.0005 and 0.00050000001",
                "cannot land on both",
            ],
        ),
    ];
    for (name, analysis, absent, wanted) in cases {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, pendulum(&analysis, "")).unwrap();
        let c = check(&model);
        let text = String::from_utf8_lossy(&c.stdout).into_owned() + &stderr(&c);
        let code = if name == "max-step-only" { 0 } else { 2 };
        assert_eq!(c.status.code(), Some(code), "{name}: {text}");
        for w in wanted {
            assert!(text.contains(w), "{name}: {w:?} not in {text}");
        }
        if let Some(a) = absent {
            assert!(!text.contains(a), "{name}: {a:?} in {text}");
        }
    }
}

/// A fixed step far too long for the motion is noted once, with the
/// local error estimate it has: the pendulum (small-swing period 1.55 s)
/// in steps of 0.5 s (an estimate of order 1 of the step's motion); the
/// same pendulum in steps of 5 ms has none.
#[test]
fn a_fixed_step_too_long_for_the_motion_is_noted() {
    let dir = scratch("long-fixed-step");
    for (name, analysis, noted) in [
        (
            "long",
            "[analysis]\ntype = \"dynamic\"\nend_time = 3.0\ntime_step = 0.5\nadaptive = false\n"
                .to_string(),
            true,
        ),
        ("short", FIXED.to_string(), false),
    ] {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, pendulum(&analysis, "")).unwrap();
        let out = dir.join(name);
        let o = run(&model, &out, &[]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
        let notes = log
            .lines()
            .filter(|l| l.contains("note:") && l.contains("local error estimate of the fixed step"))
            .count();
        assert_eq!(notes, usize::from(noted), "{name}: {log}");
    }
}

/// A step accepted at the round-off plateau of its residual, whose log
/// line ends with a relative residual above `residual_tolerance`, is
/// explained by a note, once per analysis (docs/results.md, log.txt): a
/// free 2 m beam in 10 elements falling and spinning at 1 rad/s has such
/// steps (relative residual ~4e-7 against 1e-8, last correction ~1e-15 of
/// the unknowns).
#[test]
fn a_step_accepted_at_round_off_is_noted_once() {
    let dir = scratch("round-off");
    let model = dir.join("falling_beam.toml");
    std::fs::write(
        &model,
        format!(
            r#"title = "falling spinning beam"
[analysis]
type = "dynamic"
end_time = 2.0
time_step = 0.001
max_step = 0.01
output_times = [0.5, 1.0, 1.5]
output_every = 1000

{rod}

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 11
x = [2.0, 0.0, 0.0]

[[beam_lines]]
nodes = [1, 11]
elements = 10
section = "rod"
orientation = [0.0, 1.0, 0.0]
first_node = 2
first_element = 1

[[initial_motion]]
nodes = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]
angular_velocity = [0.0, 0.0, 1.0]
about = [1.0, 0.0, 0.0]

[gravity]
acceleration = [0.0, 0.0, -9.81]
"#,
            rod = common::flexible_hinge::rod_section("")
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let above = log
        .lines()
        .filter(|l| l.starts_with("step"))
        .filter(|l| {
            l.split_whitespace()
                .last()
                .and_then(|r| r.parse::<f64>().ok())
                .is_some_and(|r| r > 1e-8)
        })
        .count();
    assert!(above >= 1, "{log}");
    // each of them says so before its numbers, and only they (to the
    // rounding of the two digits shown; docs/results.md, log.txt)
    for line in log.lines().filter(|l| l.starts_with("step")) {
        let Some(last) = line
            .split_whitespace()
            .last()
            .and_then(|r| r.parse::<f64>().ok())
        else {
            continue;
        };
        if line.contains("relative residuals (stopped at round-off): ") {
            assert!(last >= 0.95e-8, "{line}");
        } else {
            assert!(last <= 1.05e-8, "{line}");
        }
    }
    let notes: Vec<&str> = log
        .lines()
        .filter(|l| {
            l.starts_with("note:") && l.contains("converged at the round-off of its residual")
        })
        .collect();
    assert_eq!(notes.len(), 1, "{log}");
    assert!(
        notes[0].contains("above residual_tolerance 1e-8"),
        "{}",
        notes[0]
    );
}
