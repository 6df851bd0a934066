//! Restart files (src/io/restart.rs): a run stopped half-way and continued
//! from its restart file ends in the state of a run that was never
//! stopped; a restart against another model, or with nothing left to run,
//! or from a damaged file, is refused with exit code 2 and a message naming
//! the file.
//!
//! The model: the driven 45° bend of tests/sequence.rs (Bathe & Bolourchi's
//! curved cantilever, radius 100, tip load 600 following the ramp, hinged
//! at its root about its tangent and turned there by a driver): large
//! rotations, a multiplier-enforced hinge and a driver whose internal
//! variables (the unwrapped angle) must come through the restart.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use unfold::io::restart::{fingerprint, Restart, RestartError};
use unfold::model::builder::*;
use unfold::model::input::{ModelInput, OutputInput};
use unfold::model::Model;
use unfold::state::State;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-restart-{}-{name}", std::process::id()));
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

/// The driven bend with the analyses ending at `sequence` (increments of
/// 0.125 throughout) and a tip load `p`.
fn driven_bend(sequence: &[f64], p: f64) -> ModelInput {
    bend_with_analyses(common::bend_section(), sequence, p, None)
}

/// The driven bend of section `section` with the static analyses ending at
/// `sequence`, a tip load `p` and, if `modes` is given, a modal analysis
/// of that many modes after them.
fn bend_with_analyses(
    section: Section,
    sequence: &[f64],
    p: f64,
    modes: Option<usize>,
) -> ModelInput {
    let mut m = common::driven_bend(section, sequence, p);
    if let Some(n) = modes {
        m.then(Analysis::modal(n));
    }
    m.into_input()
}

/// Writes `input` as `name` in `dir`, runs it into `dir/out_<name>` with
/// `extra` arguments; returns (exit code, stderr, output directory).
fn run(dir: &Path, name: &str, input: &ModelInput, extra: &[&str]) -> (i32, String, PathBuf) {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, input.to_toml().unwrap()).unwrap();
    let out = dir.join(format!("out_{name}"));
    let mut args = vec![
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let (code, _, err) = unfold(&args);
    (code, err, out)
}

/// The state of a restart file.
fn state(path: &Path) -> State {
    Restart::read(path).unwrap().state
}

/// Largest difference of positions (relative to `scale`) and of
/// orientations (rad), and of multipliers (relative to the largest).
fn difference(a: &State, b: &State, scale: f64) -> (f64, f64, f64) {
    let dx =
        a.x.iter()
            .zip(&b.x)
            .map(|(p, q)| (p - q).norm())
            .fold(0.0, f64::max)
            / scale;
    let dq =
        a.q.iter()
            .zip(&b.q)
            .map(|(p, q)| p.angle_to(q))
            .fold(0.0, f64::max);
    let big = a.multipliers.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
    let dl = a
        .multipliers
        .iter()
        .zip(&b.multipliers)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / big;
    (dx, dq, dl)
}

#[test]
fn a_run_stopped_half_way_and_restarted_ends_as_one_never_stopped() {
    let dir = scratch("half");
    // uninterrupted 0 → 2, with a restart file requested at t = 1
    let mut whole = driven_bend(&[2.0], 600.0);
    whole.output = Some(OutputInput {
        restart_times: vec![1.0],
        ..OutputInput::default()
    });
    let (code, err, out_whole) = run(&dir, "whole", &whole, &[]);
    assert_eq!(code, 0, "{err}");
    // the same model run 0 → 1, then continued to 2 from its restart.json
    let (code, err, out_first) = run(&dir, "first", &driven_bend(&[1.0], 600.0), &[]);
    assert_eq!(code, 0, "{err}");
    let restart = out_first.join("restart.json");
    let first = state(&restart);
    assert_eq!(first.time, 1.0);
    let (code, err, out_second) = run(
        &dir,
        "second",
        &driven_bend(&[2.0], 600.0),
        &["--restart", restart.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{err}");
    let log = std::fs::read_to_string(out_second.join("log.txt")).unwrap();
    assert!(
        log.contains("restarted from") && log.contains("at t = 1 in analysis 1 of 1"),
        "{log}"
    );

    // the same final state: positions to 1e-12 of the radius, rotations to
    // 1e-12 rad, multipliers to 1e-10 of the largest (the restarted run's
    // first increment starts without the previous increment's predictor, so
    // its Newton iterates differ and meet at the converged state to
    // round-off; residual tolerance 1e-11)
    let a = state(&out_whole.join("restart.json"));
    let b = state(&out_second.join("restart.json"));
    assert_eq!((a.time, b.time), (2.0, 2.0));
    let (dx, dq, dl) = difference(&a, &b, 100.0);
    assert!(
        dx < 1e-12 && dq < 1e-12 && dl < 1e-10,
        "{dx:e} {dq:e} {dl:e}"
    );
    assert_eq!(a.internal.len(), b.internal.len());
    for (u, v) in a.internal.iter().zip(&b.internal) {
        assert!((u - v).abs() < 1e-12, "internal variables {u} and {v}");
    }

    // the restart file written at t = 1 by the uninterrupted run holds the
    // state the first run ended with (same increments): to 1e-12
    let at_one = state(&out_whole.join("restart-1.json"));
    assert_eq!(at_one.time, 1.0);
    let (dx, dq, _) = difference(&at_one, &first, 100.0);
    assert!(dx < 1e-12 && dq < 1e-12, "{dx:e} {dq:e}");
    // and a run restarted from it ends as the others: to 1e-12
    let from_mid = out_whole.join("restart-1.json");
    let (code, err, out_third) = run(
        &dir,
        "third",
        &driven_bend(&[2.0], 600.0),
        &["--restart", from_mid.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{err}");
    let c = state(&out_third.join("restart.json"));
    let (dx, dq, _) = difference(&a, &c, 100.0);
    assert!(dx < 1e-12 && dq < 1e-12, "{dx:e} {dq:e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_restart_at_the_end_of_an_analysis_continues_with_the_next() {
    let dir = scratch("sequence");
    // analyses 0 → 1 and 1 → 2 in one run; then a run of the first one
    // alone, restarted with both: it goes on with the second
    let both = driven_bend(&[1.0, 2.0], 600.0);
    let (code, err, out_both) = run(&dir, "both", &both, &[]);
    assert_eq!(code, 0, "{err}");
    let (code, err, out_first) = run(&dir, "first", &driven_bend(&[1.0], 600.0), &[]);
    assert_eq!(code, 0, "{err}");
    let restart = out_first.join("restart.json");
    let (code, err, out_rest) = run(
        &dir,
        "rest",
        &both,
        &["--restart", restart.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{err}");
    let log = std::fs::read_to_string(out_rest.join("log.txt")).unwrap();
    assert!(log.contains("in analysis 2 of 2"), "{log}");
    let r = Restart::read(&out_rest.join("restart.json")).unwrap();
    assert_eq!(
        r.analysis, 1,
        "the restart file names the analysis of the model's sequence"
    );
    // the same end state: limits as above (1e-12)
    let (dx, dq, _) = difference(&state(&out_both.join("restart.json")), &r.state, 100.0);
    assert!(dx < 1e-12 && dq < 1e-12, "{dx:e} {dq:e}");

    // nothing left to run: refused (exit 2), naming the file
    let done = out_both.join("restart.json");
    let (code, err, _) = run(&dir, "done", &both, &["--restart", done.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("restart.json") && err.contains("nothing is left to run"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_restart_against_another_model_or_a_damaged_file_is_refused() {
    let dir = scratch("refused");
    let (code, err, out) = run(&dir, "first", &driven_bend(&[1.0], 600.0), &[]);
    assert_eq!(code, 0, "{err}");
    let restart = out.join("restart.json");
    let arg = restart.to_str().unwrap();

    // another load: another model
    let (code, err, _) = run(
        &dir,
        "other",
        &driven_bend(&[2.0], 700.0),
        &["--restart", arg],
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("restart.json") && err.contains("written for another model"),
        "{err}"
    );
    // the analyses may change (a later end, other increments): accepted
    let mut later = driven_bend(&[3.0], 600.0);
    later.analysis.initial_increment = Some(0.25);
    later.analysis.max_increment = Some(0.25);
    let (code, err, _) = run(&dir, "later", &later, &["--restart", arg]);
    assert_eq!(code, 0, "{err}");

    // damaged files: cut short, another JSON file, a non-unit quaternion
    let text = std::fs::read_to_string(&restart).unwrap();
    let cut = dir.join("cut.json");
    std::fs::write(&cut, &text[..text.len() / 2]).unwrap();
    let other = dir.join("other.json");
    std::fs::write(&other, "{\"format\": \"something else\"}").unwrap();
    let bad_q = dir.join("bad_q.json");
    let r = Restart::read(&restart).unwrap();
    let q0 = r.state.q[0];
    let written = serde_json::to_string(&[q0.w, q0.i, q0.j, q0.k]).unwrap();
    assert!(
        text.contains(&written),
        "orientations written as [w, x, y, z]"
    );
    std::fs::write(&bad_q, text.replacen(&written, "[2.0,0.0,0.0,0.0]", 1)).unwrap();
    let missing = dir.join("missing.json");
    for (file, fragment) in [
        (&cut, "not a valid unfold restart file"),
        (&other, "is not \"unfold restart\""),
        (&bad_q, "is not a unit quaternion"),
        (&missing, "cannot read the restart file"),
    ] {
        let (code, err, _) = run(
            &dir,
            "damaged",
            &driven_bend(&[2.0], 600.0),
            &["--restart", file.to_str().unwrap()],
        );
        assert_eq!(code, 2, "{err}");
        let name = file.file_name().unwrap().to_str().unwrap();
        assert!(err.contains(name) && err.contains(fragment), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn restart_files_keep_every_number_to_the_last_bit() {
    // a state with every vector filled with awkward values
    let input = driven_bend(&[1.0], 600.0);
    let model = Model::from_input(&input).unwrap();
    let mut s = model.initial_state();
    let mut v = 0.1f64;
    let mut next = || {
        v = (v * 7.3 + 0.123_456_789).fract() - 0.5;
        v * 1e3f64.powf(3.0 * v)
    };
    s.time = 0.3;
    for i in 0..s.x.len() {
        s.x[i] = [next(), next(), next()].into();
        let psi = unfold::so3::Vec3::new(next(), next(), next()).normalize() * 2.9;
        s.q[i] = unfold::so3::exp(&psi);
        s.velocity[i] = [next(), next(), next(), next(), next(), next()];
        s.acceleration[i] = [next(), next(), next(), next(), next(), next()];
        s.pseudo_acceleration[i] = [next(), next(), next(), next(), next(), next()];
    }
    s.multipliers.iter_mut().for_each(|m| *m = next());
    s.internal.iter_mut().for_each(|m| *m = next());
    let restart = Restart {
        model_title: "driven 45° bend".into(),
        model_fingerprint: fingerprint(&input),
        analysis: 0,
        analysis_type: "static".into(),
        state: s.clone(),
        motion: None,
    };
    let dir = scratch("bits");
    let path = dir.join("restart.json");
    restart.write(&path).unwrap();
    let back = Restart::read(&path).unwrap();
    // bit for bit (PartialEq on f64 with the same values)
    assert_eq!(back, restart);
    assert_eq!(back.state, s);
    // the model fingerprint: unchanged by the analyses, changed by the
    // model; resuming checks it and the sizes
    let plan = input.analyses().unwrap();
    assert!(back
        .resume(&path, &fingerprint(&input), &model, &plan)
        .is_ok());
    let mut other_analysis = input.clone();
    other_analysis.analysis.end_time = 5.0;
    assert_eq!(fingerprint(&other_analysis), fingerprint(&input));
    let mut moved = input.clone();
    moved.nodes[0].x[2] += 1e-9;
    assert_ne!(fingerprint(&moved), fingerprint(&input));
    let refused = back.resume(&path, &fingerprint(&moved), &model, &plan);
    assert!(matches!(refused, Err(RestartError::Model { .. })));
    let mut short = back.clone();
    short.state.multipliers.pop();
    let refused = short.resume(&path, &fingerprint(&input), &model, &plan);
    assert!(matches!(
        refused,
        Err(RestartError::Size {
            what: "multipliers",
            ..
        })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A static analysis 0 → 1 then a modal analysis of the loaded bend; run
/// whole, and again restarted from the end of the static analysis of a run
/// of it alone: the modal analysis after the restart point runs, about the
/// same state, and gives the same frequencies. The restart file written at
/// the end of the whole run (its last analysis modal) holds the state the
/// modal analysis was given, unchanged.
#[test]
fn a_restart_before_a_modal_analysis_gives_its_frequencies() {
    let dir = scratch("modal");
    // the square section of side 1 with density 1: mass 1 per length,
    // inertia [1/6, 1/12, 1/12] per length
    let massive = || {
        Section::diagonal(
            1.0e7, 4.166667e6, 4.166667e6, 8.333333e5, 8.333333e5, 8.333333e5,
        )
        .mass_per_length(1.0)
        .inertia_per_length([1.0 / 6.0, 1.0 / 12.0, 1.0 / 12.0])
    };
    let whole = bend_with_analyses(massive(), &[1.0], 600.0, Some(6));
    let (code, err, out_whole) = run(&dir, "whole", &whole, &[]);
    assert_eq!(code, 0, "{err}");
    let (code, err, out_first) = run(
        &dir,
        "first",
        &bend_with_analyses(massive(), &[1.0], 600.0, None),
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let restart = out_first.join("restart.json");
    let (code, err, out_rest) = run(
        &dir,
        "rest",
        &whole,
        &["--restart", restart.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{err}");
    let log = std::fs::read_to_string(out_rest.join("log.txt")).unwrap();
    assert!(
        log.contains("at t = 1 in analysis 2 of 2") && log.contains("modal at t = 1"),
        "{log}"
    );

    let frequencies = |out: &Path| -> Vec<f64> {
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["status"], "completed", "{summary}");
        summary["modes"][0]["frequencies_hz"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_f64().unwrap())
            .collect()
    };
    let (f_whole, f_rest) = (frequencies(&out_whole), frequencies(&out_rest));
    assert_eq!(f_whole.len(), 6);
    assert_eq!(f_rest.len(), 6);
    // the restart carries the state to the last bit and the static runs
    // took the same increments, so the linearisation is the same: the
    // frequencies agree to 1e-10 relative (round-off of the assembly and
    // of the eigen-solver)
    for (a, b) in f_whole.iter().zip(&f_rest) {
        assert!(*a > 0.0, "{f_whole:?}");
        assert!((a - b).abs() <= 1e-10 * a, "{f_whole:?} {f_rest:?}");
    }

    // the whole run's restart.json names its modal analysis (index 1 from
    // 0) and holds the state it was given: that of the static analysis,
    // as the first run ended (same increments; to 1e-12)
    let r = Restart::read(&out_whole.join("restart.json")).unwrap();
    assert_eq!((r.analysis, r.analysis_type.as_str()), (1, "modal"));
    assert_eq!(r.state.time, 1.0);
    let (dx, dq, dl) = difference(&r.state, &state(&restart), 100.0);
    assert!(
        dx < 1e-12 && dq < 1e-12 && dl < 1e-10,
        "{dx:e} {dq:e} {dl:e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A restart time at the start of the run (t = 0, where the model itself
/// is the state) or beyond the last analysis is refused at input (exit 2),
/// naming `[output]`, instead of being silently ignored.
#[test]
fn restart_times_outside_the_run_are_refused() {
    let dir = scratch("times_outside");
    for (name, t) in [("at_zero", 0.0), ("beyond", 3.0)] {
        let mut input = driven_bend(&[2.0], 600.0);
        input.output = Some(OutputInput {
            restart_times: vec![t],
            ..OutputInput::default()
        });
        let (code, err, _) = run(&dir, name, &input, &[]);
        assert_eq!(code, 2, "t = {t}: {err}");
        assert!(
            err.contains("output") && err.contains("restart_times must lie after the start"),
            "t = {t}: {err}"
        );
    }
}

/// Restart files of version 1 (before the step controller's memory was
/// kept in `motion`) are still read: the panel of
/// tests/common/hinged_panel.rs opened by its spring into a rigid latch,
/// with adaptive steps, restarted from its file at t = 0.4277 s (while its
/// steps double back after the lock at 0.42754 s) written as version 1
/// (`motion` with its energies and `last_step` only) ends at the whole
/// run's positions and orientations (to 1e-12 of the panel's 0.5 m and
/// 1e-12 rad; the locked panel does not move; its steps start again from
/// `time_step`, so its accelerations, of the size of the round-off,
/// differ: by 2.4e-3 rad/s² measured); the file
/// as written (version 2) ends in the whole run's state to the last bit.
/// A file of a later version is refused with exit code 2 and a message
/// naming it and the versions read.
#[test]
fn restart_files_of_version_1_are_read_and_later_versions_refused() {
    let dir = scratch("versions");
    let model = dir.join("panel.toml");
    let text = common::hinged_panel::latched_panel(
        "panel on a rigid latch",
        "[analysis]\ntype = \"dynamic\"\nend_time = 0.6\ntime_step = 0.01",
        90.0,
        "[output]\nrestart_times = [0.4277]",
    );
    std::fs::write(&model, text).unwrap();
    let run = |out: &str, extra: &[&str]| {
        let out = dir.join(out);
        let mut args = vec![
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let (code, _, err) = unfold(&args);
        (code, err, out)
    };
    let (code, err, whole) = run("whole", &[]);
    assert_eq!(code, 0, "{err}");
    let file = whole.join("restart-0.4277.json");
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert_eq!(written["version"], 2);
    let mut v1 = written.clone();
    v1["version"] = 1.into();
    v1["motion"] = serde_json::json!({
        "energies": written["motion"]["energies"],
        "last_step": written["motion"]["last_step"],
    });
    let later = {
        let mut v = written.clone();
        v["version"] = 3.into();
        v
    };
    let (v1_file, later_file) = (dir.join("v1.json"), dir.join("v3.json"));
    std::fs::write(&v1_file, v1.to_string()).unwrap();
    std::fs::write(&later_file, later.to_string()).unwrap();

    let end = state(&whole.join("restart.json"));
    let (code, err, out) = run("from-v2", &["--restart", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(state(&out.join("restart.json")), end);
    let (code, err, out) = run("from-v1", &["--restart", v1_file.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let (dx, dq, _) = difference(&end, &state(&out.join("restart.json")), 0.5);
    assert!(dx < 1e-12 && dq < 1e-12, "{dx:e} {dq:e}");
    let (code, err, _) = run("from-v3", &["--restart", later_file.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("v3.json") && err.contains("version 3; this unfold reads versions 1 and 2"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Tens of thousands of restart times (a restart file each, every one
/// holding the whole state) are refused at input with the limit and what
/// to do; a list of times outside the run is reported once, with how
/// many more, not once per time.
#[test]
fn too_many_restart_times_are_refused() {
    let dir = scratch("too_many_times");
    let mut input = driven_bend(&[2.0], 600.0);
    input.output = Some(OutputInput {
        restart_times: (1..=20_000).map(|k| k as f64 * 1e-4).collect(),
        ..OutputInput::default()
    });
    let (code, err, _) = run(&dir, "many", &input, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("restart_times has 20000 times: a run writes at most 1000 restart files"),
        "{err}"
    );
    input.output = Some(OutputInput {
        restart_times: (1..=500).map(|k| 2.0 + k as f64).collect(),
        ..OutputInput::default()
    });
    let (code, err, _) = run(&dir, "outside", &input, &[]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.matches("restart_times must lie").count(), 1, "{err}");
    assert!(err.contains("got 3 (and 499 more)"), "{err}");
}

/// A restart file edited or damaged so that it holds what no run writes
/// is refused (exit 2, naming the file and the value), not integrated
/// from or silently replaced: a time before the start of the analysis, a
/// step of the controller's memory that is negative or longer than the
/// analysis, a last step of zero, an error estimate below zero, an event
/// side that is not ±1. The file as written is accepted.
#[test]
fn a_restart_file_with_values_no_run_writes_is_refused() {
    let dir = scratch("edited");
    let model = dir.join("panel.toml");
    let text = common::hinged_panel::latched_panel(
        "panel on a rigid latch",
        "[analysis]\ntype = \"dynamic\"\nend_time = 0.6\ntime_step = 0.01",
        90.0,
        "[output]\nrestart_times = [0.3]",
    );
    std::fs::write(&model, text).unwrap();
    let run = |out: &str, extra: &[&str]| {
        let out = dir.join(out);
        let mut args = vec![
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let (code, _, err) = unfold(&args);
        (code, err)
    };
    let (code, err) = run("whole", &[]);
    assert_eq!(code, 0, "{err}");
    let file = dir.join("whole/restart-0.3.json");
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert!(
        written["motion"]["control"]["size"].is_number(),
        "{}",
        written["motion"]
    );
    let edits: [(&str, &[&str], serde_json::Value, &str); 7] = [
        (
            "before",
            &["state", "time"],
            (-1.0).into(),
            "its time t = -1 is before the start of analysis 1",
        ),
        (
            "negative",
            &["motion", "control", "size"],
            (-1.0).into(),
            "motion.control.size = -1 is not a step of the analysis",
        ),
        (
            "huge",
            &["motion", "control", "size"],
            1e300.into(),
            "motion.control.size = 1e300 is not a step of the analysis",
        ),
        (
            "zero",
            &["motion", "last_step"],
            0.0.into(),
            "motion.last_step = 0 is not a step of the analysis",
        ),
        (
            "error",
            &["motion", "control", "last_error"],
            (-1.0).into(),
            "last_error = -1 must be zero or positive",
        ),
        (
            "sides",
            &["motion", "control", "event_sides"],
            serde_json::json!([2.0]),
            "event_sides holds 2, not 1 or -1",
        ),
        (
            "mass",
            &["motion", "mass_scale"],
            serde_json::json!([0.0, 1.0]),
            "motion.mass_scale = [0, 1] must be positive",
        ),
    ];
    for (name, path, value, fragment) in edits {
        let mut v = written.clone();
        let mut at = &mut v;
        for key in path {
            at = &mut at[*key];
        }
        *at = value.clone();
        if path == ["state", "time"] {
            // the file's time is the state's
            v["time"] = value;
        }
        let edited = dir.join(format!("{name}.json"));
        std::fs::write(&edited, v.to_string()).unwrap();
        let (code, err) = run(name, &["--restart", edited.to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.json")) && err.contains(fragment),
            "{name}: {err}"
        );
    }
    let (code, err) = run("as-written", &["--restart", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
