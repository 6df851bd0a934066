//! Restart of latches (docs/results.md, "Restart files"): a run
//! restarted from a restart file written while a spring latch is latched
//! (its spring engaged on either side, or within its dead band), after
//! it released, or after a rigid latch locked goes on as the run that was
//! never stopped, to round-off.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::spring_latch;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-lrs-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `unfold run MODEL --out OUT --quiet` and extra arguments.
fn run(model: &Path, out: &Path, extra: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The analysis lines `analysis` of the panel of
/// tests/common/spring_latch.rs (a body of 1 kg, J = 1/3 kg·m² about its
/// hinge), in fixed steps of 5e-4 s.
fn fixed_steps(analysis: &str) -> String {
    format!("{analysis}\ntime_step = 0.0005\nadaptive = false")
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every number of a JSON value, in order.
fn flat(v: &serde_json::Value, out: &mut Vec<f64>) {
    match v {
        serde_json::Value::Number(n) => out.push(n.as_f64().unwrap()),
        serde_json::Value::Array(a) => a.iter().for_each(|x| flat(x, out)),
        serde_json::Value::Object(o) => o.values().for_each(|x| flat(x, out)),
        _ => {}
    }
}

/// The largest difference of the numbers of `a` and `b` (of one shape)
/// and the largest magnitude among those of `a`.
fn difference(a: &serde_json::Value, b: &serde_json::Value) -> (f64, f64) {
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

/// The rows of latches.csv after `t`, keyed by time (as written).
fn latch_rows(out: &Path, t: f64) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(out.join("latches.csv")).unwrap();
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let cols: Vec<&str> = l.split(',').collect();
            let time: f64 = cols[1].parse().unwrap();
            (time > t + 1e-12).then(|| {
                (
                    cols[1].to_string(),
                    cols[3..].iter().map(|c| c.parse().unwrap()).collect(),
                )
            })
        })
        .collect()
}

/// The events of events.csv after `t`, without their step numbers.
fn events_after(out: &Path, t: f64) -> Vec<String> {
    let text = std::fs::read_to_string(out.join("events.csv")).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap() > t + 1e-12)
        .map(|l| l.split(',').skip(2).collect::<Vec<_>>().join(","))
        .collect()
}

/// Runs `text` whole (with restart files at `times`), then restarted from
/// each of them; every restarted run must end in the state of the whole
/// run (positions, orientations, velocities, accelerations, multipliers
/// and internal variables to 1e-12 of the largest, the tolerance of
/// tests/cli_dynamics.rs for fixed steps), with the same rows of
/// latches.csv after the restart (to 1e-12) and the same events. Returns
/// the internal variables at each restart time.
fn whole_and_restarted(name: &str, text: &str, times: &[f64]) -> Vec<Vec<f64>> {
    let dir = scratch(name);
    let model = dir.join("model.toml");
    std::fs::write(&model, text).unwrap();
    let whole = dir.join("whole");
    run(&model, &whole, &[]);
    let end = json(&whole.join("restart.json"));
    let mut internals = Vec::new();
    for &t in times {
        let file = whole.join(format!("restart-{t}.json"));
        let at = json(&file);
        let mut internal = Vec::new();
        flat(&at["state"]["internal"], &mut internal);
        internals.push(internal);
        let part = dir.join(format!("from-{t}"));
        run(&model, &part, &["--restart", file.to_str().unwrap()]);
        let restarted = json(&part.join("restart.json"));
        for key in [
            "x",
            "q",
            "velocity",
            "acceleration",
            "pseudo_acceleration",
            "multipliers",
            "internal",
        ] {
            let (diff, scale) = difference(&end["state"][key], &restarted["state"][key]);
            assert!(
                diff <= 1e-12 * scale.max(1.0),
                "restarted at {t}: {key} differs by {diff:e} (of {scale:e})"
            );
        }
        let (a, b) = (latch_rows(&whole, t), latch_rows(&part, t));
        assert!(!a.is_empty());
        assert_eq!(a.len(), b.len(), "restarted at {t}");
        for (time, row) in &a {
            let other = b.get(time).unwrap_or_else(|| panic!("no row at {time}"));
            for (u, v) in row.iter().zip(other) {
                assert!(
                    (u - v).abs() <= 1e-12 * u.abs().max(1.0),
                    "t = {time}: {row:?} {other:?}"
                );
            }
        }
        assert_eq!(
            events_after(&whole, t),
            events_after(&part, t),
            "restarted at {t}"
        );
    }
    internals
}

/// The panel spinning at 2 rad/s latches at 0.5 rad through a spring of
/// 300 N·m/rad with a dead band of 0.1 rad (the rattle of
/// tests/latch_spring.rs: latched at t = 0.25, its spring engaged above
/// the band from 0.275 to 0.38, the band crossed back until 0.43, engaged
/// below it until 0.535). Restarted while engaged above (t = 0.3), within
/// the band (0.4) and engaged below (0.45): each goes on as the whole run.
#[test]
fn a_latched_spring_latch_goes_on_through_a_restart() {
    let text = spring_latch::spinning_into_latch(
        &fixed_steps("end_time = 0.7\nrho_infinity = 1.0"),
        &format!("backlash = {}", spring_latch::BACKLASH),
        "[output]\nrestart_times = [0.3, 0.4, 0.45]",
    );
    let internals = whole_and_restarted("latched", &text, &[0.3, 0.4, 0.45]);
    // internal variables: the hinge's unwrapped angle, then the latch's
    // unwrapped angle, lock flag, side of the band and parity of its
    // events; latched (1) at each time, on the side above (1), within (0)
    // and below (−1)
    for (internal, side) in internals.iter().zip([1.0, 0.0, -1.0]) {
        assert_eq!(internal.len(), 5, "{internal:?}");
        assert_eq!(internal[2], 1.0, "{internal:?}");
        assert_eq!(internal[3], side, "{internal:?}");
    }
}

/// The panel latched at 0 from the start under a moment ramp of 2 N·m/s
/// releases at its unlatch load of 1 N·m (tests/latch_spring.rs: at
/// about t = 0.5 s): restarted after the release (t = 0.6), and before it
/// (t = 0.3, so that the release happens in the restarted run), each goes
/// on as the whole run.
#[test]
fn a_released_spring_latch_goes_on_through_a_restart() {
    let text = spring_latch::ramp_release(
        &fixed_steps("end_time = 0.8"),
        "[output]\nrestart_times = [0.3, 0.6]",
    );
    let internals = whole_and_restarted("released", &text, &[0.3, 0.6]);
    // (the hinge's angle, then the latch's angle, lock flag and side)
    assert_eq!(internals[0][2], 1.0, "{:?}", internals[0]);
    // released beyond c_L: the lock flag 0, the side 1 (it must come back
    // to c_L before it can latch again)
    assert_eq!(internals[1][2], 0.0, "{:?}", internals[1]);
    assert_eq!(internals[1][3], 1.0, "{:?}", internals[1]);
}

/// The panel of tests/common/hinged_panel.rs opened by its spring into a
/// rigid latch at 90° (locked at t = 0.427641 s), in fixed steps of
/// 0.01 s. Restarted at t = 0.5 and 0.55, once its steps have grown back
/// to `time_step` after the lock, it goes on locked as the whole run.
/// (Restarts while they grow back:
/// [`a_run_restarted_while_its_steps_grow_back_repeats_the_whole_run`].)
#[test]
fn a_run_restarted_after_a_rigid_lock_goes_on_locked_as_the_whole_run() {
    let text = common::hinged_panel::latched_panel(
        "panel on a rigid latch",
        "[analysis]\ntype = \"dynamic\"\nend_time = 0.6\ntime_step = 0.01\nadaptive = false",
        90.0,
        "[output]\nrestart_times = [0.5, 0.55]",
    );
    let internals = whole_and_restarted("rigid", &text, &[0.5, 0.55]);
    // internal variables: the unwrapped angles of the hinge, its spring
    // and its latch, all at the lock's π/2 (to round-off), then the
    // latch's lock flag, 1
    for internal in &internals {
        assert_eq!(internal.len(), 4, "{internal:?}");
        for angle in &internal[..3] {
            assert!(
                (angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12,
                "{internal:?}"
            );
        }
        assert_eq!(internal[3], 1.0, "{internal:?}");
    }
}

/// The rows of `file` in `out` after `t`, from their `time` column on
/// (the step numbers before it count from the restart), as written.
fn rows_after(out: &Path, file: &str, t: f64) -> Vec<String> {
    let text = std::fs::read_to_string(out.join(file)).unwrap();
    let mut lines = text.lines();
    let time = lines
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == "time")
        .unwrap();
    lines
        .filter(|l| l.split(',').nth(time).unwrap().parse::<f64>().unwrap() > t + 1e-12)
        .map(|l| l.split(',').skip(time).collect::<Vec<_>>().join(","))
        .collect()
}

/// The panel opened by its spring into the rigid latch at 90°, with
/// adaptive steps (locked at t = 0.4275372 s; the steps then double from
/// the landing step of 5e-9 s for about twenty steps) and with fixed steps
/// of 0.01 s (locked at 0.4276417 s; the step after it 4 times the
/// landing step of 1e-8 s, then growing by 1.5 a step, to `time_step`
/// at about 0.467 s). Restarted before the lock and while the steps grow
/// back, each restarted run takes the steps of the whole run and writes
/// the same rows, to the last digit, in every result file: the steps'
/// times and sizes, the nodes' motion, the joints' and the latch's loads,
/// the energies; its final state is the whole run's to the last bit.
#[test]
fn a_run_restarted_while_its_steps_grow_back_repeats_the_whole_run() {
    for (name, analysis, times) in [
        ("adaptive", "", [0.4275, 0.42755, 0.4277, 0.43]),
        ("fixed", "adaptive = false", [0.4276, 0.42765, 0.428, 0.44]),
    ] {
        let list = times.map(|t| t.to_string()).join(", ");
        let text = common::hinged_panel::latched_panel(
            "panel on a rigid latch",
            &format!(
                "[analysis]\ntype = \"dynamic\"\nend_time = 0.6\ntime_step = 0.01\n{analysis}"
            ),
            90.0,
            &format!("[output]\nrestart_times = [{list}]"),
        );
        let dir = scratch(&format!("regrow-{name}"));
        let model = dir.join("model.toml");
        std::fs::write(&model, text).unwrap();
        let whole = dir.join("whole");
        run(&model, &whole, &[]);
        let end = json(&whole.join("restart.json"));
        for t in times {
            let file = whole.join(format!("restart-{t}.json"));
            let part = dir.join(format!("from-{t}"));
            run(&model, &part, &["--restart", file.to_str().unwrap()]);
            // the file's step controller was growing back: shorter than
            // time_step, but after 0.4275 (before the lock)
            let size = json(&file)["motion"]["control"]["size"].as_f64().unwrap();
            assert!(
                t == 0.4275 || t == 0.4276 || size < 0.01,
                "{name} {t}: {size}"
            );
            for csv in [
                "steps.csv",
                "nodes.csv",
                "nodes_velocities.csv",
                "joints.csv",
                "latches.csv",
                "energies.csv",
            ] {
                let (a, b) = (rows_after(&whole, csv, t), rows_after(&part, csv, t));
                assert!(a.len() > 5, "{name} {t} {csv}");
                assert_eq!(a, b, "{name}: restarted at {t}: {csv}");
            }
            assert_eq!(events_after(&whole, t), events_after(&part, t));
            let restarted = json(&part.join("restart.json"));
            assert_eq!(end["state"], restarted["state"], "{name}: restarted at {t}");
        }
    }
}
