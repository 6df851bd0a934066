//! `output_interval` of a dynamic analysis (docs/model-format.md,
//! docs/results.md): results at `t0 + kΔt` and the end, landed on exactly
//! like `output_times`, without changing the motion beyond the
//! integrator's error; its checks and how it combines with `output_times`
//! and `output_every`.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::pendulum;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-oi-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn unfold(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(args)
        .output()
        .unwrap()
}

/// Writes `text` as `DIR/NAME.toml` and runs it into `DIR/NAME`.
fn run(dir: &Path, name: &str, text: &str) -> (Output, PathBuf) {
    let model = dir.join(format!("{name}.toml"));
    std::fs::write(&model, text).unwrap();
    let out = dir.join(name);
    let o = unfold(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    (o, out)
}

/// The rows of a CSV file as maps from column name to value.
fn table(path: &Path) -> Vec<HashMap<String, f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .filter_map(|(k, v)| v.parse().ok().map(|v| (k.to_string(), v)))
                .collect()
        })
        .collect()
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// The hanging pendulum of tests/common/pendulum.rs: a body of m = 2 kg,
/// J_c = 0.01 kg·m² at d = 0.5 m below the hinge, launched from the bottom
/// at θ̇0 = 4 rad/s (a swing of 0.95 rad: far from linear), over 2 s.
fn pendulum(extra: &str) -> String {
    pendulum::hanging(
        &format!(
            r#"title = "compound pendulum"
[analysis]
type = "dynamic"
end_time = 2.0
time_step = 0.001
max_step = 0.01
{extra}"#
        ),
        "angular_velocity = [0.0, 0.0, 4.0]\nvelocity = [2.0, 0.0, 0.0]",
        "",
    )
}

/// `(θ, θ̇)` of the pendulum at `t`: `J_O θ̈ = −m g d sin θ`,
/// `J_O = J_c + m d² = 0.51 kg·m²`, integrated by classical Runge–Kutta
/// with 20 000 steps per second (error far below 1e-10 rad).
fn exact(t: f64) -> (f64, f64) {
    let (j_o, mgd) = (0.01 + 2.0 * 0.25, 2.0 * 9.81 * 0.5);
    let f = |s: [f64; 2]| [s[1], -mgd / j_o * s[0].sin()];
    let n = (t * 20_000.0).round().max(1.0) as usize;
    let h = t / n as f64;
    let mut s = [0.0, 4.0];
    for _ in 0..n {
        let k1 = f(s);
        let k2 = f([s[0] + 0.5 * h * k1[0], s[1] + 0.5 * h * k1[1]]);
        let k3 = f([s[0] + 0.5 * h * k2[0], s[1] + 0.5 * h * k2[1]]);
        let k4 = f([s[0] + h * k3[0], s[1] + h * k3[1]]);
        for i in 0..2 {
            s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    (s[0], s[1])
}

#[test]
fn rows_fall_on_the_grid_and_the_motion_is_that_of_the_run_without_it() {
    let dir = scratch("grid");
    let (o, with) = run(&dir, "interval", &pendulum("output_interval = 0.1"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = table(&with.join("joints.csv"));
    // t = 0, 0.1, …, 2.0: 21 rows, each at k·0.1 to 1e-12 (the steps land
    // on the grid times as on output_times)
    assert_eq!(rows.len(), 21);
    for (k, r) in rows.iter().enumerate() {
        let t = r["time"];
        assert!((t - 0.1 * k as f64).abs() < 1e-12, "row {k} at t = {t}");
    }
    // summary.json counts the rows written: the 21 grid times
    let s = summary(&with);
    assert_eq!(s["output_steps"], 21);
    assert_eq!(table(&with.join("steps.csv")).len(), 21);
    assert!(s["increments"].as_u64().unwrap() > 100, "{s}");

    // the run that writes every step and lands on nothing but the end
    let (o, plain) = run(&dir, "plain", &pendulum(""));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let plain_rows = table(&plain.join("joints.csv"));
    let (a, b) = (rows.last().unwrap(), plain_rows.last().unwrap());
    assert_eq!(a["time"], 2.0);
    assert_eq!(b["time"], 2.0);
    let (theta, rate) = exact(2.0);
    // landing on the 20 grid times costs few steps: a step cut short by
    // one does not size the next (docs/theory.md §13, "Landing"):
    // measured 468 steps against 457 without the grid (528 when the steps
    // grew back from each cut step); within 5 %
    let steps = |out: &Path| summary(out)["increments"].as_u64().unwrap() as f64;
    let (n_grid, n_plain) = (steps(&with), steps(&plain));
    assert!(n_grid <= 1.05 * n_plain, "{n_grid} vs {n_plain} steps");
    // both against the exact motion at t = 2: measured 2.17e-4 rad and
    // 1.68e-3 rad/s with the grid, 2.24e-4 rad and 1.71e-3 rad/s without
    // (the global error of error_tolerance = 1e-4 over 2 s); within
    // 5e-4 rad and 5e-3 rad/s
    for r in [a, b] {
        assert!(
            (r["angle"] - theta).abs() < 5e-4,
            "{} vs {theta}",
            r["angle"]
        );
        assert!(
            (r["angle_rate"] - rate).abs() < 5e-3,
            "{} vs {rate}",
            r["angle_rate"]
        );
    }
    // the two runs differ by less than their error (measured 7.4e-6 rad)
    assert!(
        (a["angle"] - b["angle"]).abs() < 1e-4,
        "{} vs {}",
        a["angle"],
        b["angle"]
    );
    // and at every grid time (measured at most 3.6e-4 rad): within 1e-3
    for r in &rows {
        let (theta, _) = exact(r["time"]);
        assert!(
            (r["angle"] - theta).abs() < 1e-3,
            "t = {}: {} vs {theta}",
            r["time"],
            r["angle"]
        );
    }

    // the grid is landed on as output_times are: the same run to the last
    // digit written
    let times: Vec<String> = (1..20).map(|k| format!("{:?}", k as f64 * 0.1)).collect();
    let listed = format!(
        "output_times = [{}]\noutput_every = 1000000",
        times.join(", ")
    );
    let (o, given) = run(&dir, "listed", &pendulum(&listed));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let given_rows = table(&given.join("joints.csv"));
    assert_eq!(given_rows.len(), rows.len());
    for (p, q) in rows.iter().zip(&given_rows) {
        for key in ["time", "angle", "angle_rate", "M3"] {
            assert_eq!(p.get(key), q.get(key), "{key} at t = {}", p["time"]);
        }
    }
}

#[test]
fn output_times_join_the_grid() {
    let dir = scratch("union");
    // 0.25 and 0.75 are off the grid of 0.5, 1.5 is on it
    let (o, out) = run(
        &dir,
        "union",
        &pendulum("output_interval = 0.5\noutput_times = [0.25, 0.75, 1.5]"),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let times: Vec<f64> = table(&out.join("steps.csv"))
        .iter()
        .map(|r| r["time"])
        .collect();
    let expected = [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0];
    assert_eq!(times.len(), expected.len(), "{times:?}");
    for (t, e) in times.iter().zip(expected) {
        assert!((t - e).abs() < 1e-12, "{times:?}");
    }
    assert_eq!(summary(&out)["output_steps"], 7);
}

#[test]
fn check_prints_it_and_bad_values_are_input_errors() {
    let dir = scratch("check");
    let model = dir.join("ok.toml");
    std::fs::write(&model, pendulum("output_interval = 0.1")).unwrap();
    let o = unfold(&["check", model.to_str().unwrap()]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("output every 0.1 (20 times, with output_times and the end)"),
        "{text}"
    );
    for (extra, message) in [
        (
            "output_interval = 0.1\noutput_every = 5",
            "analysis: output_interval and output_every cannot both be given",
        ),
        (
            "output_interval = -0.1",
            "analysis: output_interval must be positive and finite, got -0.1",
        ),
        (
            "output_interval = 0.0",
            "analysis: output_interval must be positive and finite, got 0",
        ),
        (
            "output_interval = 3.0",
            "analysis: output_interval (3) must not exceed the span of the analysis (2",
        ),
        (
            "output_interval = 1e-12",
            "analysis: output_interval (1e-12) is shorter than a step can be",
        ),
    ] {
        let model = dir.join("bad.toml");
        std::fs::write(&model, pendulum(extra)).unwrap();
        let out = dir.join("bad");
        let check = ["check", model.to_str().unwrap()];
        let run = [
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        for args in [&check[..], &run[..]] {
            let o = unfold(args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{extra}: {err}");
            assert!(err.contains(message), "{extra}: {err}");
        }
    }
    // a static analysis does not take it
    let model = dir.join("static.toml");
    std::fs::write(
        &model,
        pendulum("output_interval = 0.1").replace("type = \"dynamic\"", "type = \"static\""),
    )
    .unwrap();
    let o = unfold(&["check", model.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("output_interval belongs to dynamic analyses"),
        "{err}"
    );
}
