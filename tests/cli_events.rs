//! What the command-line tool says about latches, stops and joint
//! coefficients: each lock or impact in the log with its element, time
//! and energy lost, their count and loss in the line closing the analysis,
//! the run's last line and `summary.json`; a note for a latch that a
//! dynamic analysis never locked (a warning) and for one a static or kinematic
//! analysis passes (docs/joints.md §6.2); a note giving a joint spring's
//! or hinge law's coefficient per degree in N·m/rad (docs/model-format.md).

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::cli::{csv_rows as rows, summary};
use common::hinged_panel::latched_panel;
use common::pendulum;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-events-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `unfold run MODEL --out OUT` and extra arguments.
fn run(model: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(extra)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The rows of a CSV file as maps from column name to value (NaN for
/// text), and the column `kind` of each.
fn table(path: &Path) -> Vec<HashMap<String, f64>> {
    rows(path)
        .into_iter()
        .map(|r| {
            r.into_iter()
                .map(|(k, v)| (k, v.parse().unwrap_or(f64::NAN)))
                .collect()
        })
        .collect()
}

/// The `kind` of each row of `events.csv` in `out`.
fn kinds(out: &Path) -> Vec<String> {
    rows(&out.join("events.csv"))
        .into_iter()
        .map(|mut r| r.remove("kind").unwrap())
        .collect()
}

/// The latched panel of tests/common/hinged_panel.rs (J_O = 1/3 kg·m²,
/// a torsion spring of 2 N·m/rad unloaded at 180°, id 4) with its latch
/// (id 5) at `latch` degrees; `analysis` its analysis tables, `extra`
/// more tables.
fn panel(analysis: &str, latch: f64, extra: &str) -> String {
    latched_panel("panel latched to the ground", analysis, latch, extra)
}

const DYNAMIC: &str = "[analysis]
type = \"dynamic\"
end_time = 1.0
time_step = 0.001
max_step = 0.01
output_every = 10
";

/// The lock of the panel at 90°, through the command line: the log line
/// of the event names the latch, its joint, the time and the energy lost,
/// which is Carnot's loss `½ J_O θ̇⁻² = ½ k (π² − π²/4) = 0.75 π² =
/// 7.4022 J` (the spring's energy released from 0 to 90°, all kinetic at
/// the lock); the line closing the analysis and the run's last line count
/// the lock and give the loss; `summary.json` holds it too. The log of a
/// dynamic analysis speaks of steps, not increments.
#[test]
fn a_lock_is_reported_in_the_log_and_the_last_line() {
    let dir = scratch("lock");
    let model = dir.join("panel.toml");
    std::fs::write(&model, panel(DYNAMIC, 90.0, "")).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &[]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let events = table(&out.join("events.csv"));
    assert_eq!(events.len(), 1);
    let e = &events[0];
    // 0.75 π², to the energy balance error of the run (1.2e-3 J with the
    // default error tolerance 1e-4: 1.5e-4 relative), within 1e-3
    // relative
    let carnot = 0.75 * std::f64::consts::PI.powi(2);
    assert!(
        (e["energy_lost"] - carnot).abs() <= 1e-3 * carnot,
        "{} against {carnot}",
        e["energy_lost"]
    );
    // θ(t) = π (1 − cos ωt), ω = √(k/J_O) = √6: θ = π/2 at t = π/(3√6) =
    // 0.427517 s, within the error tolerance (5e-5 s)
    let t_lock = std::f64::consts::PI / (3.0 * 6f64.sqrt());
    assert!((e["time"] - t_lock).abs() < 5e-5, "{}", e["time"]);

    let lock_line = stdout
        .lines()
        .find(|l| l.contains("latch 5: locks joint 3"))
        .unwrap_or_else(|| panic!("no lock line in {stdout}"));
    assert!(
        lock_line.starts_with(&format!("step {:4}", e["increment"])),
        "{lock_line}"
    );
    assert!(
        lock_line.contains(&format!("t = {:.6}", e["time"])),
        "{lock_line}"
    );
    assert!(lock_line.contains("at c = 1.570796"), "{lock_line}");
    assert!(
        lock_line.contains(&format!("energy lost {:.6e}", e["energy_lost"])),
        "{lock_line}"
    );
    let counted = format!("1 lock, energy lost in impacts {:.3e}", e["energy_lost"]);
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let closing = log
        .lines()
        .find(|l| l.starts_with("dynamic analysis to t = 1:"))
        .unwrap();
    assert!(closing.ends_with(&counted), "{closing}");
    let last = stdout.lines().last().unwrap();
    assert!(
        last.starts_with("completed:") && last.contains(&format!("; {counted}; results in")),
        "{last}"
    );
    assert_eq!(log.lines().last(), Some(last));
    // every line about a step of the dynamic analysis says "step"
    assert!(!log.lines().any(|l| l.starts_with("increment")), "{log}");
    assert!(log.contains("landed on event \"latch 5\""), "{log}");
    let d = &summary(&out)["analyses"][0]["dynamic"];
    assert_eq!(d["locks"], 1);
    assert_eq!(d["impact_energy_lost"].as_f64(), Some(e["energy_lost"]));
    // nothing to note: the latch locked
    assert!(!stdout.contains("never locked"), "{stdout}");
}

/// A pendulum (2 kg at 0.5 m, J_c = 0.1 kg·m²) falls from the horizontal
/// onto a stop at −60° with restitution 0.5: its impacts and the final
/// contact are counted in the last line, with the energy lost summed over
/// the rows of `events.csv` (one impact per step), as in `summary.json`.
#[test]
fn the_impacts_of_a_stop_are_counted_with_their_loss() {
    let dir = scratch("stop");
    let model = dir.join("pendulum.toml");
    std::fs::write(
        &model,
        pendulum::onto_a_stop(
            r#"title = "pendulum onto a stop"
[analysis]
type = "dynamic"
end_time = 3.0
time_step = 0.01"#,
            0.5,
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let events = table(&out.join("events.csv"));
    let kinds = kinds(&out);
    let impacts = kinds.iter().filter(|k| *k == "impact").count();
    assert!(impacts >= 1, "{kinds:?}");
    assert_eq!(
        kinds.last().map(String::as_str),
        Some("contact"),
        "{kinds:?}"
    );
    assert_eq!(kinds.len(), impacts + 1, "{kinds:?}");
    // one event per step here: the loss is the sum of the rows
    let lost: f64 = events.iter().map(|e| e["energy_lost"]).sum();
    let d = &summary(&out)["analyses"][0]["dynamic"];
    assert_eq!(d["impacts"], impacts);
    let recorded = d["impact_energy_lost"].as_f64().unwrap();
    // the rows are written to 16 digits
    assert!((recorded - lost).abs() <= 1e-12 * lost, "{recorded} {lost}");
    let stdout = text(&o.stdout);
    let last = stdout.lines().last().unwrap();
    let counted = format!(
        "{impacts} impact{}, 1 contact closed, energy lost in impacts {recorded:.3e}; results in",
        if impacts > 1 { "s" } else { "" }
    );
    assert!(last.contains(&counted), "{counted:?} not in {last}");
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(
        log.contains("stop 8: impact of joint 7 at c = -1.047198"),
        "{log}"
    );
    assert!(log.contains("stop 8: contact closed on joint 7"), "{log}");
}

/// A latch at −90°, reached decreasing, on a panel that the spring opens
/// towards +180°: it never locks. The run completes (exit 0) with a note,
/// shown even with `--quiet` and kept in `log.txt`, naming the latch and
/// the range its joint covered (0 to 318.56°: the panel swings through the
/// spring's free angle and back).
#[test]
fn a_latch_that_never_locks_is_a_warning() {
    let dir = scratch("never");
    let model = dir.join("panel.toml");
    std::fs::write(&model, panel(DYNAMIC, -90.0, "")).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // a latch is there to lock: one that never does is a warning, on
    // the console even with --quiet, in the log and in summary.json
    let stderr = text(&o.stderr);
    let note = stderr
        .lines()
        .find(|l| l.starts_with("warning: latch 5 never locked in the dynamic analysis to t = 1"))
        .unwrap_or_else(|| panic!("no warning in {stderr}"));
    assert!(
        note.contains("joint 3 stayed within [0 rad (0.00°), 5.5"),
        "{note}"
    );
    assert!(
        note.contains(
            "the latch locks when the coordinate reaches -1.570796 rad (-90.00°) decreasing"
        ),
        "{note}"
    );
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains(note), "{log}");
    let s = summary(&out);
    assert_eq!(s["analyses"][0]["dynamic"]["locks"], 0);
    let warned = s["warnings"].as_array().unwrap();
    assert!(
        warned
            .iter()
            .any(|w| w.as_str().unwrap() == &note["warning: ".len()..]),
        "{warned:?}"
    );
    // its peak is no design load
    let latch = &s["latches"][0];
    assert_eq!(latch["latch"], 5);
    assert!(latch["locked_at"].is_null(), "{latch}");
    assert_eq!(latch["design_load"], false, "{latch}");
    assert!(
        latch["note"].as_str().unwrap().contains("never locked"),
        "{latch}"
    );
}

/// Latches lock only in dynamics: a static analysis of the panel finds its
/// equilibrium at 180°, past the latch at 90°, and a kinematic one whose
/// driver turns the hinge to 120° passes it too; each run completes with a
/// note naming the latch, its joint and the analysis. A driver that stops
/// at 60° passes nothing: no note.
#[test]
fn a_latch_passed_in_statics_is_noted() {
    let dir = scratch("static");
    let cases = [
        (
            "static",
            "[analysis]\ntype = \"static\"\nend_time = 1.0\n",
            "",
            true,
        ),
        (
            "kinematic",
            "[analysis]\ntype = \"kinematic\"\nend_time = 1.0\ninitial_increment = 0.1\n",
            "[[drivers]]\nid = 6\njoint = 3\nvalue = 120.0\nunit = \"deg\"\n",
            true,
        ),
        (
            "short",
            "[analysis]\ntype = \"kinematic\"\nend_time = 1.0\ninitial_increment = 0.1\n",
            "[[drivers]]\nid = 6\njoint = 3\nvalue = 60.0\nunit = \"deg\"\n",
            false,
        ),
    ];
    for (name, analysis, extra, passes) in cases {
        let model = dir.join(format!("{name}.toml"));
        std::fs::write(&model, panel(analysis, 90.0, extra)).unwrap();
        let out = dir.join(name);
        let o = run(&model, &out, &["--quiet"]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let stdout = text(&o.stdout);
        let kind = if name == "static" {
            "static"
        } else {
            "kinematic"
        };
        let wanted = format!(
            "note: latch 5: the {kind} analysis carried joint 3 past the latch's value 1.570796 rad (90.00°)"
        );
        assert_eq!(stdout.contains(&wanted), passes, "{name}: {stdout}");
        if passes {
            assert!(
                stdout.contains("latches lock only in a dynamic analysis"),
                "{name}: {stdout}"
            );
            let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
            assert_eq!(log.matches(&wanted).count(), 1, "{name}: {log}");
        }
    }
}

/// A joint spring's stiffness and damping and a hinge law's slope given
/// with `unit = "deg"` are per degree: a note gives each in N·m/rad
/// (2 N·m/deg = 2·180/π = 114.5916 N·m/rad), from `check` and from `run`
/// (on stderr, and once in `log.txt`). In radians there is nothing to note.
#[test]
fn coefficients_per_degree_are_noted_in_radians() {
    let dir = scratch("degrees");
    let hinge = "[[hinge_laws]]\nid = 7\njoint = 3\nunit = \"deg\"\nelastic_slope = 10.0\nload_table = [[0.0, 1.0], [180.0, 1.0]]\nunload_table = [[0.0, -1.0], [180.0, -1.0]]\n";
    let text_deg = panel(DYNAMIC, 90.0, hinge).replace(
        "stiffness = 2.0\nfree_value = 3.141592653589793",
        "stiffness = 2.0\ndamping = 0.5\nfree_value = 180.0\nunit = \"deg\"",
    );
    let model = dir.join("deg.toml");
    std::fs::write(&model, &text_deg).unwrap();
    let check = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(["check", model.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(check.status.success(), "{}", text(&check.stderr));
    let out = dir.join("out");
    let o = run(&model, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let notes = [
        "joint spring 4: stiffness = 2 with unit = \"deg\" is 2 N·m/deg = 1.145916e2 N·m/rad",
        "joint spring 4: damping = 0.5 with unit = \"deg\" is 0.5 N·m·s/deg = 2.864789e1 N·m·s/rad",
        "hinge law 7: elastic_slope = 10 with unit = \"deg\" is 10 N·m/deg = 5.729578e2 N·m/rad",
    ];
    for n in notes {
        for (what, stderr) in [("check", text(&check.stderr)), ("run", text(&o.stderr))] {
            assert!(
                stderr.contains(&format!("note: {}: {n}", model.display())),
                "{what}: {n:?} not in {stderr}"
            );
        }
        assert_eq!(log.matches(n).count(), 1, "{n:?} in {log}");
    }

    // the same coefficients in radians: no note
    let model = dir.join("rad.toml");
    std::fs::write(
        &model,
        panel(DYNAMIC, 90.0, &hinge.replace("unit = \"deg\"\n", "")).replace(
            "free_value = 3.141592653589793",
            "damping = 0.5\nfree_value = 3.141592653589793",
        ),
    )
    .unwrap();
    let check = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(["check", model.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(check.status.success(), "{}", text(&check.stderr));
    assert!(
        !text(&check.stderr).contains("note:"),
        "{}",
        text(&check.stderr)
    );
}

/// A stop on the wrong side of the motion: the panel swings from 0
/// towards +360° but its only limit is 10° below the start. The run
/// completes with a note, as for a latch that never locks, naming the
/// stop, its joint, the range the joint covered and the stop's limits.
#[test]
fn a_stop_never_struck_is_noted() {
    let dir = scratch("never-struck");
    let model = dir.join("panel.toml");
    let stop = "\n[[stops]]\nid = 6\njoint = 3\nlower = -10.0\nunit = \"deg\"\nrestitution = 0.3\n";
    std::fs::write(&model, panel(DYNAMIC, -90.0, stop)).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    let note = stdout
        .lines()
        .find(|l| l.starts_with("note: stop 6 was never struck in the dynamic analysis to t = 1"))
        .unwrap_or_else(|| panic!("no note in {stdout}"));
    assert!(
        note.contains("joint 3 stayed within [0 rad (0.00°), 5.5"),
        "{note}"
    );
    assert!(
        note.contains("the stop's limits are [-0.174533 rad (-10.00°), ∞]"),
        "{note}"
    );
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains(note), "{log}");
    // a stop that is struck gets no note: the same stop at 10° above the
    // start, which the panel reaches at once
    let struck = stop.replace("lower = -10.0", "upper = 10.0");
    std::fs::write(&model, panel(DYNAMIC, -90.0, &struck)).unwrap();
    let o = run(&model, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        !text(&o.stdout).contains("never struck"),
        "{}",
        text(&o.stdout)
    );
}

/// A spring latch (2 N·m/° = 114.59 N·m/rad, dead band 1°, unlatch load
/// 5 N·m) that the panel reaches at 0.43 s and pulls open: `events.csv`
/// has the lock, the spring engaging and the unlatch; the run's last
/// line and `summary.json` count one lock and one unlatch, not two locks,
/// and the energy the spring held at the release, `½ F_u²/k = 0.10908 J`
/// (docs/joints.md §6.2), as lost in impacts and unlatches.
#[test]
fn an_unlatch_is_counted_as_an_unlatch() {
    let dir = scratch("unlatch");
    let model = dir.join("panel.toml");
    let spring = "mode = \"spring\"\nstiffness = 2.0\nbacklash = 1.0\nunlatch_load = 5.0\n";
    std::fs::write(&model, panel(DYNAMIC, 90.0, spring)).unwrap();
    let out = dir.join("out");
    let o = run(&model, &out, &["--quiet"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    // the spring engages at the edge of the band between the two
    assert_eq!(kinds(&out), ["lock", "engage", "unlatch"]);
    let d = &summary(&out)["analyses"][0]["dynamic"];
    assert_eq!(
        (d["locks"].as_u64(), d["unlatches"].as_u64()),
        (Some(1), Some(1)),
        "{d}"
    );
    let k = 2.0 * 180.0 / std::f64::consts::PI;
    let held = 0.5 * 5.0 * 5.0 / k;
    let lost = d["impact_energy_lost"].as_f64().unwrap();
    // the release lands within the event tolerance of the unlatch load
    assert!((lost - held).abs() < 1e-4 * held, "{lost} vs {held}");
    let last = text(&o.stderr) + &text(&o.stdout);
    assert!(
        last.contains(&format!(
            "1 lock, 1 unlatch, energy lost in impacts and unlatches {lost:.3e}"
        )),
        "{last}"
    );
}
