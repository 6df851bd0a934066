//! The models of docs/tutorial.md run as a new user runs them, and what
//! the tutorial says of their results holds: the two-panel wing deploys,
//! locks flat and dissipates the work of its springs; the flexible wing
//! deploys as the rigid one until its first lock; a rigid latch on
//! flexible panels is reported as not giving a design load; a lean output
//! for studies; the warnings about a likely wrong model (docs/model-format.md,
//! "Checks, warnings and limits"), bodies that end inside one another, and
//! a collapse of the steps.

mod common;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use common::cli::{self, csv_rows as rows, number, summary};

fn scratch(name: &str) -> PathBuf {
    cli::scratch("tutorial", name)
}

fn example(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    std::fs::read_to_string(path).unwrap()
}

/// The work the three preloaded springs of the wing do from folded to
/// flat: `∫ k (θ_f − θ) dθ` over each hinge's travel `Θ`, `k (θ_f Θ − Θ²/2)`
/// (root: 0.0111 N·m/deg, free at 135°, 90° of travel; hinges 2 and 3:
/// 0.00556 N·m/deg, free at ∓270°, 180° of travel).
fn spring_work() -> f64 {
    let per_rad = 180.0 / PI;
    let work = |k_deg: f64, free_deg: f64, travel_deg: f64| {
        let (k, f, t) = (
            k_deg * per_rad,
            free_deg.to_radians(),
            travel_deg.to_radians(),
        );
        k * (f * t - 0.5 * t * t)
    };
    work(0.0111, 135.0, 90.0) + 2.0 * work(0.00556, 270.0, 180.0)
}

/// The lock rows of `events.csv`: (latch, time, energy lost).
fn locks(out: &Path) -> Vec<(u64, f64, f64)> {
    rows(&out.join("events.csv"))
        .iter()
        .filter(|r| r["kind"] == "lock")
        .map(|r| {
            (
                r["element"].parse().unwrap(),
                number(r, "time"),
                number(r, "energy_lost"),
            )
        })
        .collect()
}

/// The position of `node` at the last output step.
fn final_position(out: &Path, node: u64) -> [f64; 3] {
    let rows = rows(&out.join("nodes.csv"));
    let r = rows
        .iter()
        .rev()
        .find(|r| r["node"] == node.to_string())
        .unwrap();
    [number(r, "x"), number(r, "y"), number(r, "z")]
}

#[test]
fn the_rigid_wing_deploys_locks_flat_and_dissipates_its_springs_work() {
    let dir = scratch("rigid");
    let model = dir.join("wing_rigid.toml");
    std::fs::write(&model, example("wing_rigid.toml")).unwrap();
    // check counts the latches
    let o = cli::unfold(&["check", model.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(
        text.contains("4 rigid bodies") && text.contains("3 latches"),
        "{text}"
    );
    // a well-made model: no warning (notes only: the springs' stiffness per
    // degree read in N·m/rad)
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("warning"), "{err}");
    let out = dir.join("out");
    cli::run_model(&model, &out);
    let s = summary(&out);
    assert_eq!(s["status"], "completed");
    // nor at the end: every latch locked, no body inside another or
    // inside the spacecraft
    assert_eq!(
        s["warnings"].as_array().unwrap().len(),
        0,
        "{}",
        s["warnings"]
    );
    // the root locks first, then hinge 3, then hinge 2 (docs/tutorial.md)
    let locks = locks(&out);
    let order: Vec<u64> = locks.iter().map(|l| l.0).collect();
    assert_eq!(order, [102, 302, 202], "{locks:?}");
    // Energy: the springs' work all goes into the plastic impacts of the
    // locks (the wing is at rest, locked flat, at the end; no damping):
    // within 1e-3 of the work, the energy balance's order with the
    // default error tolerance (measured: see the tutorial)
    let lost: f64 = locks.iter().map(|l| l.2).sum();
    let work = spring_work();
    assert!(
        (lost - work).abs() <= 1e-3 * work,
        "lost {lost} J against the springs' work {work} J"
    );
    // Deployed flat along +x: yoke 0.3 m, panels' centres at 0.8 and 1.8 m
    // (the geometry of the model; 1e-9 m, the latches' lock tolerance
    // 1e-8 rad times the 2 m reach)
    for (node, x) in [(10, 0.15), (20, 0.8), (30, 1.8)] {
        let p = final_position(&out, node);
        let d = ((p[0] - x).powi(2) + p[1].powi(2) + p[2].powi(2)).sqrt();
        assert!(d <= 1e-7, "node {node} at {p:?}, expected ({x}, 0, 0)");
    }
    // rigid panels: the peaks are loads
    for l in s["latches"].as_array().unwrap() {
        assert_eq!(l["design_load"], true, "{l}");
        assert!(l.get("note").is_none(), "{l}");
        assert!(l["lock_impulse"].as_f64().unwrap() != 0.0, "{l}");
    }
    // states written as integers
    for r in rows(&out.join("latches.csv")) {
        assert!(r["locked"] == "0" || r["locked"] == "1", "{r:?}");
    }
}

#[test]
fn the_flexible_wing_deploys_as_the_rigid_one_until_its_first_lock() {
    let dir = scratch("flexible");
    let (rigid, _) = cli::run_text(&dir, &example("wing_rigid.toml"));
    let rigid_locks = locks(&rigid);
    let dir = scratch("flexible_panels");
    let (out, _) = cli::run_text(&dir, &example("wing_flexible.toml"));
    let s = summary(&out);
    assert_eq!(s["status"], "completed");
    let flexible_locks = locks(&out);
    assert_eq!(flexible_locks.len(), 3, "{flexible_locks:?}");
    // Before any lock the panels, whose first mode (18 Hz) is far above
    // the deployment's pace, bend by M L/EI ≈ 1.5 · 1/2100 rad under the
    // springs: the root locks when the rigid wing's does, within 1e-3
    // (measured: see the tutorial)
    let (t_rigid, t_flexible) = (rigid_locks[0].1, flexible_locks[0].1);
    assert_eq!(flexible_locks[0].0, 102);
    assert!(
        (t_flexible - t_rigid).abs() <= 1e-3 * t_rigid,
        "root lock at {t_flexible} s against {t_rigid} s"
    );
    // Spring latches: their peaks are loads, bounded by the energy the
    // springs released (k θ²/2 ≤ W: |M| ≤ √(2 k W)) plus the springs'
    // own moments (at most 1.5 N·m)
    let k = 34.9 * 180.0 / PI;
    let bound = (2.0 * k * spring_work()).sqrt() + 1.5;
    for l in s["latches"].as_array().unwrap() {
        assert_eq!(l["mode"], "spring");
        assert_eq!(l["design_load"], true, "{l}");
        let peak = l["peak_load"].as_f64().unwrap().abs();
        assert!(peak > 1.0 && peak <= bound, "{l}: bound {bound}");
    }
}

/// The flexible wing with rigid latches: the peak of the root latch is
/// the lock's, reported as not a design load, with the lock's impulse and
/// energy lost.
#[test]
fn a_rigid_latch_on_flexible_panels_is_not_a_design_load() {
    let text = example("wing_flexible.toml")
        .replace(
            "mode = \"spring\"\nstiffness = 34.9\ndamping = 0.0349\n",
            "",
        )
        .replace("end_time = 5.0", "end_time = 0.5");
    assert!(!text.contains("mode = \"spring\""));
    let dir = scratch("rigid_latch_on_beams");
    let (out, o) = cli::run_text(&dir, &text);
    let s = summary(&out);
    let root = &s["latches"][0];
    assert_eq!(root["latch"], 102);
    assert_eq!(root["design_load"], false, "{root}");
    let note = root["note"].as_str().unwrap();
    assert!(note.contains("not a design load"), "{note}");
    assert!(root["lock_impulse"].as_f64().unwrap() != 0.0, "{root}");
    assert!(root["lock_energy_lost"].as_f64().unwrap() > 0.0, "{root}");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("latch 102: peak load") && stderr.contains("not a design load"),
        "{stderr}"
    );
    assert!(s["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("latch 102: peak load")));
    // the latches that did not lock by t = 0.5 held nothing: no design
    // load either, and their note says why
    let open = &s["latches"][1];
    assert_eq!(open["design_load"], false);
    assert!(
        open["note"].as_str().unwrap().contains("never locked"),
        "{open}"
    );
}

/// `[output] vtk = false` writes no grid and the same CSV files;
/// `vtk_every = 10` a grid at every tenth output step.
#[test]
fn the_output_section_chooses_the_files() {
    let full = example("wing_rigid.toml");
    let dir = scratch("lean_full");
    let (all, _) = cli::run_text(&dir, &full);
    let lean_text = full.replace(
        "[output]\nplots = [\"joints\", \"energies\"]",
        "[output]\nvtk = false",
    );
    assert!(lean_text.contains("vtk = false"));
    let dir = scratch("lean");
    let (lean, _) = cli::run_text(&dir, &lean_text);
    assert!(!lean.join("unfold.pvd").exists());
    let grids = |out: &Path| {
        std::fs::read_dir(out.join("vtk"))
            .map(|d| d.count())
            .unwrap_or(0)
    };
    assert_eq!(grids(&lean), 0);
    // the histories are those of the full run, to the last digit
    for file in [
        "steps.csv",
        "joints.csv",
        "latches.csv",
        "events.csv",
        "energies.csv",
    ] {
        assert_eq!(
            std::fs::read_to_string(all.join(file)).unwrap(),
            std::fs::read_to_string(lean.join(file)).unwrap(),
            "{file}"
        );
    }
    let steps = rows(&all.join("steps.csv")).len();
    assert_eq!(grids(&all), steps);
    let every = full.replace(
        "[output]\nplots = [\"joints\", \"energies\"]",
        "[output]\nvtk_every = 10",
    );
    let dir = scratch("every");
    let (tenth, _) = cli::run_text(&dir, &every);
    assert_eq!(grids(&tenth), steps.div_ceil(10));
    let pvd = std::fs::read_to_string(tenth.join("unfold.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), steps.div_ceil(10));
    // vtk_every = 0 is refused
    let dir = scratch("every_zero");
    let model = dir.join("m.toml");
    std::fs::write(
        &model,
        full.replace("plots = [\"joints\", \"energies\"]", "vtk_every = 0"),
    )
    .unwrap();
    let o = cli::unfold(&["check", model.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("vtk_every must be 1 or more"));
}

/// The slips of docs/tutorial.md §8: a hinge placed 4.5 m from the
/// panels it joins, a panel's mass in grams.
#[test]
fn likely_wrong_models_are_warned_of() {
    let rigid = example("wing_rigid.toml");
    let check = |name: &str, text: &str| {
        let dir = scratch(name);
        let model = dir.join("m.toml");
        std::fs::write(&model, text).unwrap();
        let o = cli::unfold(&["check", model.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let far = rigid.replace("position = [0.0, 0.0, -0.7]", "position = [0.0, 0.0, -5.2]");
    assert_ne!(far, rigid);
    let err = check("far_hinge", &far);
    // panel 1's box reaches √(0.5² + 0.25²) = 0.559 m from its centre;
    // the hinge is 5.0 m from it
    assert!(
        err.contains("warning:") && err.contains("joint 300: its point lies 5 from node 20"),
        "{err}"
    );
    let grams = rigid.replacen("mass = 2.0", "mass = 2000.0", 1);
    let err = check("grams", &grams);
    assert!(
        err.contains("the masses of its bodies span a factor of 4000"),
        "{err}"
    );
    // hinge 3's latch put on hinge 2, which has its own: hinge 3 is left
    // without one, and with panel 2's value (+180°) the latch never locks
    let wrong = "id = 302\njoint = 300\n";
    assert!(rigid.contains(wrong));
    let err = check(
        "latch_elsewhere",
        &rigid.replace(wrong, "id = 302\njoint = 200\n"),
    );
    assert!(
        err.contains("joint 300: is driven by joint spring 301 and has neither latch nor stop, where 2 other driven joints have one"),
        "{err}"
    );
    // the same latch twice on one joint
    let twin = rigid.replace(
        "id = 202\njoint = 200\nvalue = -180.0",
        "id = 202\njoint = 100\nvalue = 90.0",
    );
    assert_ne!(twin, rigid);
    let err = check("twin_latch", &twin);
    assert!(
        err.contains("latch 202: locks joint 100 at the value at which latch 102 locks it already"),
        "{err}"
    );
    assert!(
        err.contains("joint 200: is driven by joint spring 201"),
        "{err}"
    );
    // a panel without its inertia
    let no_inertia = rigid.replacen("inertia = [0.2083, 0.1667, 0.0417]\n", "", 1);
    assert_ne!(no_inertia, rigid);
    let err = check("no_inertia", &no_inertia);
    assert!(
        err.contains("rigid body 21: has a mass and no `inertia`"),
        "{err}"
    );
}

/// A hinge axis along the panel instead of the hinge line: with hinge 2's
/// axis along z the panels fold back into the spacecraft (the box behind
/// its wall, x < -0.02), and with hinge 3's panel 2 turns in the plane of
/// panel 1 and ends on it. Both runs complete, locks and all; the
/// warnings name the bodies (docs/model-format.md, "Checks, warnings and
/// limits"). The right model has none (above).
#[test]
fn bodies_that_end_inside_one_another_are_warned_of() {
    let rigid = example("wing_rigid.toml");
    let wrong_axis = |joint: u64| {
        let line = format!("id = {joint}\ntype = \"revolute\"\n");
        let at = rigid.find(&line).unwrap();
        let axis = at + rigid[at..].find("axis = [0.0, 1.0, 0.0]").unwrap();
        let mut text = rigid.clone();
        text.replace_range(axis..axis + 22, "axis = [0.0, 0.0, 1.0]");
        text
    };
    let run = |name: &str, text: &str| {
        let dir = scratch(name);
        let model = dir.join("m.toml");
        std::fs::write(&model, text).unwrap();
        let out = dir.join("out");
        let o = cli::unfold(&[
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert_eq!(o.status.code(), Some(0));
        let s = summary(&out);
        assert_eq!(s["status"], "completed");
        let warnings: Vec<String> = s["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string())
            .collect();
        let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
        for w in &warnings {
            assert!(stderr.contains(&format!("warning: {w}")), "{stderr}");
        }
        warnings
    };
    // panel 1's centre ends at x = -0.2, panel 2's at -1.2 (measured)
    let w = run("hinge_2_along_z", &wrong_axis(200));
    for panel in [21, 31] {
        assert!(
            w.iter().any(|w| w.contains(&format!("of rigid body {panel} lies inside rigid body 2 (fixed) at the end of the run (t = 5), and not at its start"))),
            "{w:?}"
        );
    }
    // panel 2 on panel 1, as stowed but turned half a turn about z
    let w = run("hinge_3_along_z", &wrong_axis(300));
    assert!(
        w.iter().any(|w| w.starts_with("100% of rigid body 31 lies inside rigid body 21 at the end of the run (t = 5), as at its start, though they moved relative to each other")),
        "{w:?}"
    );
    assert!(!w.iter().any(|w| w.contains("rigid body 2 ")), "{w:?}");
}

/// The flexible wing without damping, its panels of 10 elements, and a
/// rigid root latch: after the lock the error estimate asks for steps of
/// about 1e-5 s (the panels ring at the frequencies of their mesh). The
/// rejected steps are logged with the node where the estimate is largest,
/// the collapse is warned of, and with a `min_step` above those steps the
/// analysis stops saying where and why.
#[test]
fn a_collapse_of_the_steps_is_said_and_located() {
    let undamped = example("wing_flexible.toml")
        .replace(
            "mode = \"spring\"\nstiffness = 34.9\ndamping = 0.0349\n",
            "",
        )
        .replace("rayleigh_beta = 1.75e-4\n", "")
        .replace("elements = 4", "elements = 10")
        .replace("max_step = 0.001", "")
        .replace("end_time = 5.0", "end_time = 0.47");
    // a first step far too long, 0.5 s: the steps fall below 1e-4 of it
    let text = undamped.replace("time_step = 0.001", "time_step = 0.5\nmax_step = 0.5");
    let dir = scratch("collapse");
    let (out, _) = cli::run_text(&dir, &text);
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let rejected: Vec<&str> = log
        .lines()
        .filter(|l| l.contains(" rejected: local error estimate "))
        .collect();
    let s = summary(&out);
    let counted = s["analyses"][0]["dynamic"]["error_rejections"]
        .as_u64()
        .unwrap();
    assert!(!rejected.is_empty(), "{log}");
    assert!(
        rejected
            .iter()
            .all(|l| l.contains("times its tolerance, largest at node ")),
        "{rejected:?}"
    );
    // one line per step the estimate rejected
    assert_eq!(rejected.len() as u64, counted);
    let warning = s["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .find(|w| w.contains("the steps collapsed"))
        .unwrap_or_else(|| panic!("{}", s["warnings"]));
    assert!(
        warning.contains("largest at node ") && warning.contains("rayleigh_beta"),
        "{warning}"
    );
    // below min_step: the run stops, naming the node and the remedy
    let text = undamped.replace("time_step = 0.001", "time_step = 0.01\nmin_step = 2e-5");
    let dir = scratch("collapse_floor");
    let model = dir.join("m.toml");
    std::fs::write(&model, text).unwrap();
    let o = cli::unfold(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        dir.join("out").to_str().unwrap(),
    ]);
    assert_ne!(o.status.code(), Some(0));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("below min_step: local error estimate")
            && err.contains("largest at node ")
            && err.contains("damp it"),
        "{err}"
    );
    assert_eq!(summary(&dir.join("out"))["status"], "failed");
}
