//! What a run records of its latches and stops, through the command line
//! (docs/results.md): the crossings of a spring latch's dead band in
//! `events.csv` (`engage`, `disengage`, `rearm`, with `lock` and
//! `unlatch`), at the times of a prescribed motion; and the largest load
//! of each latch and stop in `summary.json`, against the closed forms of
//! panels held against a hinge moment and against the histories of the
//! same run.
//!
//! The panels: rigid bodies of mass `m = 1` and inertia `J_c = 1/12` about
//! their centres, 0.5 m from a hinge about z to a fixed node, so that the
//! inertia about the hinge is `J = J_c + m/4 = 1/3` and each panel's
//! equation of motion, with its hinge angle `θ`, is `J θ̈ = M(θ, t)`.

mod common;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use common::cli::{self, csv_rows as rows, number, summary};

/// The inertia of a panel about its hinge.
const J: f64 = 1.0 / 12.0 + 0.25;

fn scratch(name: &str) -> PathBuf {
    cli::scratch("latch-records", name)
}

/// Writes `text` as a model in `dir` and runs it into `dir/out`.
fn run(dir: &Path, text: &str) -> PathBuf {
    cli::run_text(dir, text).0
}

/// A panel `n` (node `n`, its hinge node `10 + n` at `(0, y, 0)`, joint
/// `20 + n`) and `extra` tables.
fn panel(n: usize, y: f64, extra: &str) -> String {
    format!(
        r#"
[[nodes]]
id = {hinge}
x = [0.0, {y}, 0.0]

[[nodes]]
id = {n}
x = [0.5, {y}, 0.0]

[[supports]]
node = {hinge}
fixed = ["all"]

[[rigid_bodies]]
id = {n}
node = {n}
mass = 1.0
inertia = [0.08333333333333333, 0.08333333333333333, 0.08333333333333333]

[[joints]]
id = {joint}
type = "revolute"
nodes = [{hinge}, {n}]
axis = [0.0, 0.0, 1.0]
position = [0.0, {y}, 0.0]
{extra}"#,
        hinge = 10 + n,
        joint = 20 + n,
    )
}

// ---------- the crossings of a spring latch's dead band ----------

/// A row of `events.csv` expected: kind, time, coordinate.
type Row = (&'static str, f64, f64);

/// The amplitude of the drive `θ(t) = A sin πt`.
const A: f64 = 0.6;
/// The latches' value, dead band and stiffness.
const LATCH: f64 = 0.4;
const BACKLASH: f64 = 0.1;
const K: f64 = 10.0;

/// The first `t ≥ 0` within the quarter period `[k, k + 1/2]` (`rising`)
/// or `[k + 1/2, k + 1]` at which `A sin πt = c` (0 < c < A).
fn at(k: f64, rising: bool, c: f64) -> f64 {
    let s = (c / A).asin() / PI;
    if rising {
        k + s
    } else {
        k + 1.0 - s
    }
}

/// Two hinges driven through `θ(t) = A sin πt` (A = 0.6 rad, `θ̇(0) = Aπ`
/// given as the initial motion) across spring latches at θ_L = 0.4 rad
/// with a dead band of 0.1 rad (edges at 0.35 and 0.45 rad) and a spring
/// of 10 N·m/rad, whose load `k (|x| − b/2)` reaches the unlatch load `F_u`
/// at `|x| = b/2 + F_u/k`. Latch 1, `F_u` = 2 N·m: locks rising through
/// 0.4, engages at 0.45, carries at most 1.5 N·m up to A, disengages
/// coming back through 0.45, engages at 0.35 below the band and releases
/// at 0.4 − 0.05 − 0.2 = 0.15 rad; it locks again on the next rise
/// (t = 2 + …) and engages. Latch 2, `F_u` = 1 N·m: locks, engages,
/// releases rising at 0.55 rad, beyond its value, rearms coming back
/// through 0.4, and locks, engages and releases again on the next rise.
/// The drive fixes the motion, so each crossing is at the instant the
/// sine reaches its edge: `t = k + asin(c/A)/π` rising, `k + 1 − …`
/// falling.
#[test]
fn a_driven_spring_latch_crosses_its_dead_band_at_the_drive_s_times() {
    let latches = |n: usize, unlatch: f64| {
        format!(
            r#"
[[drivers]]
id = {driver}
joint = {joint}
value = {A}
curve = "swing"

[[latches]]
id = {latch}
joint = {joint}
value = {LATCH}
mode = "spring"
stiffness = {K}
backlash = {BACKLASH}
unlatch_load = {unlatch}

[[initial_motion]]
nodes = [{n}]
angular_velocity = [0.0, 0.0, {omega:?}]
about = [0.0, {y}, 0.0]
"#,
            driver = 40 + n,
            joint = 20 + n,
            latch = 30 + n,
            omega = A * PI,
            y = n as f64,
        )
    };
    let text = format!(
        r#"title = "hinges driven across spring latches"
[analysis]
type = "dynamic"
end_time = 2.4
time_step = 0.002
max_step = 0.01

[[curves]]
name = "swing"
function = "sine"
frequency = 0.5
{}{}"#,
        panel(1, 1.0, &latches(1, 2.0)),
        panel(2, 2.0, &latches(2, 1.0)),
    );
    let dir = scratch("driven");
    let out = run(&dir, &text);
    let h = 0.5 * BACKLASH;
    // each latch, its unlatch load and its rows
    let expected: [(usize, f64, Vec<Row>); 2] = [
        (
            31,
            2.0,
            vec![
                ("lock", at(0.0, true, LATCH), LATCH),
                ("engage", at(0.0, true, LATCH + h), LATCH + h),
                ("disengage", at(0.0, false, LATCH + h), LATCH + h),
                ("engage", at(0.0, false, LATCH - h), LATCH - h),
                (
                    "unlatch",
                    at(0.0, false, LATCH - h - 2.0 / K),
                    LATCH - h - 2.0 / K,
                ),
                ("lock", at(2.0, true, LATCH), LATCH),
                ("engage", at(2.0, true, LATCH + h), LATCH + h),
            ],
        ),
        (
            32,
            1.0,
            vec![
                ("lock", at(0.0, true, LATCH), LATCH),
                ("engage", at(0.0, true, LATCH + h), LATCH + h),
                (
                    "unlatch",
                    at(0.0, true, LATCH + h + 1.0 / K),
                    LATCH + h + 1.0 / K,
                ),
                ("rearm", at(0.0, false, LATCH), LATCH),
                ("lock", at(2.0, true, LATCH), LATCH),
                ("engage", at(2.0, true, LATCH + h), LATCH + h),
                (
                    "unlatch",
                    at(2.0, true, LATCH + h + 1.0 / K),
                    LATCH + h + 1.0 / K,
                ),
            ],
        ),
    ];
    let events = rows(&out.join("events.csv"));
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    for (latch, unlatch, expected) in &expected {
        let found: Vec<_> = events
            .iter()
            .filter(|r| r["element"] == latch.to_string())
            .collect();
        let kinds: Vec<&str> = found.iter().map(|r| r["kind"].as_str()).collect();
        let want: Vec<&str> = expected.iter().map(|e| e.0).collect();
        assert_eq!(kinds, want, "latch {latch}");
        for (r, &(kind, t, c)) in found.iter().zip(expected) {
            let (time, coordinate) = (number(r, "time"), number(r, "coordinate"));
            let rate = (number(r, "rate_before"), number(r, "rate_after"));
            let drive_rate = A * PI * (PI * t).cos();
            eprintln!(
                "latch {latch} {kind}: t {time} ({:+.2e}), c {coordinate} ({:+.2e}), rate {} ({:+.2e})",
                time - t,
                coordinate - c,
                rate.0,
                rate.0 / drive_rate - 1.0
            );
            assert_eq!(r["joint"], (latch - 10).to_string());
            // the coordinate at an edge or at c_L within the event
            // tolerance, 1e-8 rad; at an unlatch, the load within its
            // tolerance, 1e-6 F_u, i.e. 1e-6 F_u/k in x
            let tol_c = if kind == "unlatch" {
                1e-6 * unlatch / K
            } else {
                1e-8
            };
            assert!(
                (coordinate - c).abs() <= tol_c,
                "{kind}: {coordinate} vs {c}"
            );
            // the time: the driven angle follows the sine within the
            // constraint tolerance (1e-6 rad), so the crossing is within
            // (1e-6 + tol_c)/|θ̇| of the sine's (measured: 6.4e-9 s)
            let tol_t = (1e-6 + tol_c) / drive_rate.abs();
            assert!((time - t).abs() <= tol_t, "{kind}: t = {time} vs {t}");
            // the rate: no jump at a spring latch's events, and the drive's
            // Aπ cos πt within 1e-5 of it (the integration error of the
            // velocities of the driven hinge, measured 1.2e-8 of the rate)
            assert_eq!(rate.0, rate.1, "{kind}");
            assert!(
                (rate.0 / drive_rate - 1.0).abs() <= 1e-5,
                "{kind}: {rate:?}"
            );
            // no impulse; energy lost only at an unlatch: what the spring
            // held, ½ k (|x| − b/2)² = ½ F_u²/k
            assert_eq!(number(r, "impulse"), 0.0);
            if kind != "unlatch" {
                assert_eq!(number(r, "energy_lost"), 0.0, "{kind}");
            }
        }
    }
    // each row is a log line
    for phrase in [
        "latch 31: spring engages on joint 21 at c = 0.450000",
        "latch 31: spring disengages on joint 21 at c = 0.450000",
        "latch 31: spring engages on joint 21 at c = 0.350000",
        "latch 32: rearms on joint 22 at c = 0.400000",
    ] {
        assert!(log.contains(phrase), "{phrase}\n{log}");
    }
    // the largest load of latch 31: its unlatch load, carried at the
    // release (2 N·m pulling the hinge back up: positive), within the
    // unlatch tolerance 1e-6 F_u; that of latch 32 is −1 N·m
    let s = summary(&out);
    let peaks = s["latches"].as_array().unwrap();
    let peak = |i: usize| peaks[i]["peak_load"].as_f64().unwrap();
    assert_eq!(peaks[0]["latch"], 31);
    assert!((peak(0) - 2.0).abs() <= 1e-6 * 2.0, "{}", peaks[0]);
    let release = expected[0].2[4].1;
    assert!((peaks[0]["peak_time"].as_f64().unwrap() - release).abs() <= 1e-6);
    assert!((peak(1) + 1.0).abs() <= 1e-6, "{}", peaks[1]);
    assert_eq!(peaks[0]["mode"], "spring");
    assert_eq!(peaks[0]["quantity"], "moment");
}

/// A panel spinning freely at ω₀ = 2 rad/s into a one-sided spring latch
/// at θ_L = 0.5 rad (300 N·m/rad acting only beyond θ_L, no dead band:
/// the edge is θ_L): the lock and the spring's engagement are rows of the
/// same step, at θ_L/ω₀ = 0.25 s; the spring turns the panel back in half
/// a cycle of Ω = √(k/J) = 30 rad/s and disengages π/Ω later at θ_L,
/// moving back at −ω₀ (a linear spring returns the rate it received). Its
/// largest load is `k ω₀/Ω = ω₀ √(kJ)` = 20 N·m, pushing θ down. ρ∞ = 1
/// and fixed steps of 0.5 ms, as in tests/latch_spring.rs.
#[test]
fn a_one_sided_spring_latch_engages_at_its_lock_and_disengages_half_a_cycle_later() {
    let omega_0 = 2.0;
    let k = 300.0;
    let text = format!(
        r#"title = "a panel turned back by a one-sided spring latch"
[analysis]
type = "dynamic"
end_time = 0.6
time_step = 0.0005
adaptive = false
rho_infinity = 1.0
{}"#,
        panel(
            1,
            0.0,
            &format!(
                r#"
[[initial_motion]]
nodes = [1]
angular_velocity = [0.0, 0.0, {omega_0}]

[[latches]]
id = 31
joint = 21
value = {THETA_L}
mode = "spring"
stiffness = {k}
side = "beyond"
"#
            )
        )
    );
    let dir = scratch("one-sided");
    let out = run(&dir, &text);
    let events = rows(&out.join("events.csv"));
    let kinds: Vec<&str> = events.iter().map(|r| r["kind"].as_str()).collect();
    assert_eq!(kinds, ["lock", "engage", "disengage"]);
    let big_omega = (k / J).sqrt();
    let t_lock = THETA_L / omega_0;
    let t_exit = t_lock + PI / big_omega;
    // the lock and the engagement: one step, at θ_L within the event
    // tolerance (1e-8 rad), at θ_L/ω₀ within 1e-5 s (the integration error
    // of the free rotation, 2.8e-6 rad in tests/latch_spring.rs, over ω₀)
    assert_eq!(events[0]["time"], events[1]["time"]);
    for r in &events {
        assert!((number(r, "coordinate") - THETA_L).abs() <= 1e-8, "{r:?}");
    }
    assert!((number(&events[1], "time") - t_lock).abs() <= 1e-5);
    assert!((number(&events[1], "rate_before") / omega_0 - 1.0).abs() <= 1e-4);
    // the exit: π/Ω after the lock within 1e-4 of π/Ω (the integration
    // error of the half cycle, as in tests/latch_spring.rs), at −ω₀
    // within 1e-4
    let exit = &events[2];
    eprintln!(
        "disengage at {} (closed form {t_exit}), rate {}",
        number(exit, "time"),
        number(exit, "rate_before")
    );
    assert!((number(exit, "time") - t_exit).abs() <= 1e-4 * PI / big_omega);
    assert!((number(exit, "rate_before") / omega_0 + 1.0).abs() <= 1e-4);
    // the peak load −ω₀√(kJ), sampled every 0.5 ms: within ½ (Ω h/2)² =
    // 2.8e-5 of it and the integration error, 1e-4 in all (8.6e-6
    // measured), at the middle of the contact, within a step
    let s = summary(&out);
    let latch = &s["latches"][0];
    let peak = latch["peak_load"].as_f64().unwrap();
    let exact = -omega_0 * (k * J).sqrt();
    eprintln!("peak {peak} vs {exact}: {latch}");
    assert!((peak / exact - 1.0).abs() <= 1e-4, "{latch}");
    let middle = 0.5 * (t_lock + t_exit);
    assert!(
        (latch["peak_time"].as_f64().unwrap() - middle).abs() <= 5e-4,
        "{latch}"
    );
}

// ---------- peak loads ----------

/// The hinge moment on each panel, N·m.
const M: f64 = 2.0;
/// The locking value, rad.
const THETA_L: f64 = 0.5;
/// The spring latch: stiffness and damping ratio `ζ = d / (2√(kJ))`.
const K_HOLD: f64 = 200.0;
const ZETA: f64 = 0.2;

/// The load of the spring latch `τ` after its lock: from `x = 0`,
/// `ẋ = ω_L` the panel obeys `J ẍ + d ẋ + k x = M`, so that
/// `x = M/k + e^{−ζωτ} (a cos ω_d τ + b sin ω_d τ)`, `a = −M/k`,
/// `b = (ω_L + ζω a)/ω_d`, `ω = √(k/J)`, `ω_d = ω√(1 − ζ²)`; the latch's
/// load is `−(k x + d ẋ)`.
fn spring_latch_load(tau: f64) -> f64 {
    let omega = (K_HOLD / J).sqrt();
    let omega_d = omega * (1.0 - ZETA * ZETA).sqrt();
    let d = 2.0 * ZETA * (K_HOLD * J).sqrt();
    let omega_l = (2.0 * M * THETA_L / J).sqrt();
    let a = -M / K_HOLD;
    let b = (omega_l + ZETA * omega * a) / omega_d;
    let (c, s) = ((omega_d * tau).cos(), (omega_d * tau).sin());
    let e = (-ZETA * omega * tau).exp();
    let x = M / K_HOLD + e * (a * c + b * s);
    let rate = e * (-ZETA * omega * (a * c + b * s) + omega_d * (b * c - a * s));
    -(K_HOLD * x + d * rate)
}

/// Three panels from rest under a constant hinge moment M = 2 N·m, each
/// reaching θ_L = 0.5 rad at `t_L = √(2Jθ_L/M)` with `ω_L = √(2Mθ_L/J)`:
/// a rigid latch, a plastic stop and a spring latch (200 N·m/rad, damping
/// ratio 0.2) hold them. Held still, the rigid latch and the stop carry
/// `M` from the lock on (no transient: the body is fixed); the spring
/// latch's load follows the damped oscillator `J ẍ + d ẋ + k x = M`
/// ([`spring_latch_load`]), peaks at 17.84 N·m and tends to `M`. The
/// summary's peaks are these, at the right times, and the largest of
/// the same run's `latches.csv` and `stops.csv` (every step an output
/// step).
#[test]
fn the_peak_loads_of_latches_and_stops_are_those_of_their_histories() {
    let d = 2.0 * ZETA * (K_HOLD * J).sqrt();
    let moment = format!("\n[[loads]]\nnode = {{}}\nmoment = [0.0, 0.0, {M}]\n");
    let loaded = |n: usize, extra: &str| moment.replace("{}", &n.to_string()) + extra;
    let text = format!(
        r#"title = "three panels held against a hinge moment"
[analysis]
type = "dynamic"
end_time = 3.5
time_step = 0.001
max_step = 0.001
rho_infinity = 0.8
{}{}{}"#,
        panel(
            1,
            0.0,
            &loaded(1, &format!("\n[[latches]]\nid = 31\njoint = 21\nvalue = {THETA_L}\n"))
        ),
        panel(
            2,
            1.0,
            &loaded(2, &format!("\n[[stops]]\nid = 32\njoint = 22\nupper = {THETA_L}\n"))
        ),
        panel(
            3,
            2.0,
            &loaded(
                3,
                &format!(
                    "\n[[latches]]\nid = 33\njoint = 23\nvalue = {THETA_L}\nmode = \"spring\"\nstiffness = {K_HOLD}\ndamping = {d:?}\n"
                )
            )
        ),
    );
    let dir = scratch("held");
    let out = run(&dir, &text);
    let s = summary(&out);
    let t_lock = (2.0 * J * THETA_L / M).sqrt();
    let field = |v: &serde_json::Value, name: &str| v[name].as_f64().unwrap();

    // the largest |load| of each element in its file, with its time
    let largest = |file: &str, id_column: &str, id: u64| -> (f64, f64, f64) {
        let (mut best, mut time, mut last) = (0.0f64, f64::NAN, f64::NAN);
        for r in rows(&out.join(file)) {
            if r[id_column] != id.to_string() {
                continue;
            }
            let load = number(&r, "load");
            if load.abs() > best.abs() {
                (best, time) = (load, number(&r, "time"));
            }
            last = load;
        }
        (best, time, last)
    };
    // the summary's peaks are the largest loads of the files: the same
    // numbers written with 10 significant digits (5e-10 of them), at the
    // same times (written with 13, 5e-13)
    let same_as_file = |entry: &serde_json::Value, file: &str, column: &str, id: u64| {
        let (load, time, last) = largest(file, column, id);
        let peak = field(entry, "peak_load");
        eprintln!(
            "{column} {id}: peak {peak} at {}, file {load} at {time}, last {last}",
            field(entry, "peak_time")
        );
        assert!(
            (peak - load).abs() <= 5e-10 * load.abs(),
            "{entry} vs {load}"
        );
        // the time: a row of the file at it (13 digits) whose load is the
        // largest to the file's 10 digits (a held load is the same to them
        // at many steps, its largest where round-off puts it)
        let at = field(entry, "peak_time");
        let there = rows(&out.join(file))
            .into_iter()
            .filter(|r| r[column] == id.to_string())
            .find(|r| (number(r, "time") - at).abs() <= 5e-13 * at)
            .map(|r| number(&r, "load"));
        assert!(
            there.is_some_and(|l| (l - load).abs() <= 5e-10 * load.abs()),
            "{entry}: load {there:?} at {at}, largest {load} at {time}"
        );
        (peak, last)
    };

    let latches = s["latches"].as_array().unwrap();
    assert_eq!(latches.len(), 2);
    let (rigid, spring) = (&latches[0], &latches[1]);
    assert_eq!(
        (rigid["latch"].as_u64(), rigid["joint"].as_u64()),
        (Some(31), Some(21))
    );
    assert_eq!(
        (rigid["mode"].as_str(), rigid["quantity"].as_str()),
        (Some("rigid"), Some("moment"))
    );
    assert_eq!(spring["mode"], "spring");
    // locked at t_L, as its row of events.csv says: the steps land on the
    // lock within 1e-8 rad, and the free rotation under the constant
    // moment is integrated to 1.6e-7 s of t_L (measured) at steps of 1 ms:
    // 1e-6 s
    let events = rows(&out.join("events.csv"));
    for (entry, element) in [(rigid, "31"), (spring, "33")] {
        let lock = events.iter().find(|r| r["element"] == element).unwrap();
        assert_eq!(field(entry, "locked_at"), number(lock, "time"), "{entry}");
        assert!(
            (field(entry, "locked_at") - t_lock).abs() <= 1e-6,
            "{entry}"
        );
    }

    // the rigid latch holds −M (pushing θ down) from the lock on: within
    // 1e-6 M (the residual tolerance, 1e-8 of the moment flux of the model,
    // whose largest moments are the spring latch's 18 N·m; 1.3e-9 M
    // measured), at its peak and at the end
    let (peak, last) = same_as_file(rigid, "latches.csv", "latch", 31);
    assert!((peak + M).abs() <= 1e-6 * M, "{rigid}");
    assert!((last + M).abs() <= 1e-6 * M, "{last}");
    assert!(field(rigid, "peak_time") >= field(rigid, "locked_at"));

    // the stop: closed at t_L, holding +M (pushing θ back into its range)
    let stops = s["stops"].as_array().unwrap();
    assert_eq!(stops.len(), 1);
    let stop = &stops[0];
    assert_eq!(
        (stop["stop"].as_u64(), stop["joint"].as_u64()),
        (Some(32), Some(22))
    );
    assert!((field(stop, "closed_at") - t_lock).abs() <= 1e-6, "{stop}");
    let (peak, last) = same_as_file(stop, "stops.csv", "stop", 32);
    assert!((peak - M).abs() <= 1e-6 * M, "{stop}");
    assert!((last - M).abs() <= 1e-6 * M, "{last}");

    // the spring latch: the peak of the closed form, sampled every 1 ms
    // (a smooth peak of a load oscillating at ω = 24.5 rad/s is missed by at
    // most ½ (ω h/2)² = 7.5e-5 of it; the integration adds 1e-6, measured:
    // 2.7e-6 in all): within 1e-4, 44 ms after the lock within a step
    let (tau, exact) = (0..200_000)
        .map(|i| {
            let tau = i as f64 * 1e-6;
            (tau, spring_latch_load(tau))
        })
        .fold(
            (0.0, 0.0),
            |a, b| if b.1.abs() > f64::abs(a.1) { b } else { a },
        );
    let (peak, last) = same_as_file(spring, "latches.csv", "latch", 33);
    eprintln!("spring latch: peak {peak} vs {exact} at τ = {tau}, last {last}");
    assert!((peak / exact - 1.0).abs() <= 1e-4, "{spring} vs {exact}");
    assert!(peak.abs() >= M);
    let peak_tau = field(spring, "peak_time") - t_lock;
    assert!((peak_tau - tau).abs() <= 1e-3, "{peak_tau} vs {tau}");
    // at the end (3.09 s after the lock) the transient is down to
    // e^{−ζωτ} = 3e-7 of its size: the load is the closed form's within
    // 1e-6 M (7.7e-8 measured) and M's within 1e-5 M
    let end = spring_latch_load(3.5 - t_lock);
    assert!((last - end).abs() <= 1e-6 * M, "{last} vs {end}");
    assert!((last + M).abs() <= 1e-5 * M, "{last}");
}

/// A panel opened by a torsion spring (1 N·m/rad, free at 2 rad; `m = 2`,
/// `J = 2/3` about the hinge) into a stiff spring latch with a dead band
/// (`k_L` = 1e5 N·m/rad: a contact lasts half a period,
/// `π√(J/k_L)` = 8.1 ms), run with `analysis` steps.
fn stiff_rattle(analysis: &str) -> String {
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = 1.6
rho_infinity = 1.0
{analysis}

[[nodes]]
id = 1
x = [0.5, 0.0, 0.0]

[[rigid_bodies]]
id = 1
node = 1
mass = 2.0
inertia = [0.01, 0.1666667, 0.1666667]

[[joints]]
id = 10
type = "revolute"
nodes = [1]
axis = [0.0, 0.0, 1.0]
position = [0.0, 0.0, 0.0]

[[joint_springs]]
id = 11
joint = 10
stiffness = 1.0
free_value = 2.0

[[latches]]
id = 20
joint = 10
value = 1.5707963267948966
mode = "spring"
stiffness = 100000.0
backlash = 0.02
"#
    )
}

/// Fixed steps of 0.02 s, longer than a contact of the latch's spring
/// (8.1 ms), give a peak load half the true one, `ċ√(J k_L)` = 618 N·m
/// at the lock's 2.39 rad/s (measured: 300 N·m) while the energy stays
/// balanced; the run warns that the steps do not resolve the latch's
/// spring (a contact of 21 ms crossed by one step of 0.02 s and three
/// slivers landing on the edge of the band is one step, not four).
/// Adaptive steps land on the edges of the dead band and resolve each
/// contact with many steps: no warning, and the peak within 1 % of the
/// closed form.
#[test]
fn a_latch_spring_the_steps_do_not_resolve_is_warned_of() {
    let coarse = run(
        &scratch("coarse-rattle"),
        &stiff_rattle("time_step = 0.02\nadaptive = false"),
    );
    let warnings = summary(&coarse)["warnings"].to_string();
    eprintln!("{warnings}");
    assert!(
        warnings.contains("latch 20: a contact of its spring lasted")
            && warnings.contains("do not resolve the latch's spring"),
        "{warnings}"
    );
    let fine = run(
        &scratch("fine-rattle"),
        &stiff_rattle("time_step = 0.002\nmax_step = 0.005"),
    );
    let s = summary(&fine);
    let warnings = s["warnings"].to_string();
    assert!(!warnings.contains("do not resolve"), "{warnings}");
    // a load −f of f = 0 (in the band) is written 0, not −0
    let latches = std::fs::read_to_string(fine.join("latches.csv")).unwrap();
    assert!(latches.contains(",0.000000000e0") && !latches.contains("-0.000000000e0"));
    let peak = s["latches"][0]["peak_load"].as_f64().unwrap();
    // the first contact from the rate at the first engage: a half-sine of
    // amplitude ċ√(J k_L) (the torsion spring's 1 N·m/rad beside
    // k_L = 1e5 changes it by 5e-6); 1 %: the peak sampled at the steps
    let events = rows(&fine.join("events.csv"));
    let engage = events.iter().find(|r| r["kind"] == "engage").unwrap();
    let rate = number(engage, "rate_before");
    let exact = rate.abs() * (2.0 / 3.0 * 1e5f64).sqrt();
    eprintln!("peak {peak} N·m, closed form {exact} N·m (engaging at {rate} rad/s)");
    assert!(
        (peak.abs() / exact - 1.0).abs() <= 1e-2,
        "{peak} vs {exact}"
    );
}

/// A spring latch locked by a dynamic analysis (its dashpot rings the
/// lock down), then a static analysis ramping a moment of 100 N·m on the
/// panel over 4–5 s, beyond the latch's unlatch load of 70 N·m: statics
/// holds latches whatever the load (docs/joints.md §6.2), and says so
/// once, when the load passes 70 N·m: at t = 4.7 s within the static
/// increments of 0.1 s (the torsion spring's 0.43 N·m beside it).
#[test]
fn a_static_analysis_loading_a_latch_beyond_its_unlatch_load_says_so() {
    let text = format!(
        r#"
[[analysis]]
type = "dynamic"
end_time = 4.0
time_step = 0.002
max_step = 0.005

[[analysis]]
type = "static"
end_time = 5.0

[[curves]]
name = "late"
points = [[0.0, 0.0], [4.0, 0.0], [5.0, 1.0]]

[[loads]]
node = 1
moment = [0.0, 0.0, 100.0]
curve = "late"
{}"#,
        stiff_rattle("")
            .split_once("[[nodes]]")
            .map(|(_, rest)| format!("[[nodes]]{rest}"))
            .unwrap()
            .replace(
                "stiffness = 100000.0\nbacklash = 0.02",
                "stiffness = 1000.0\ndamping = 20.0\nunlatch_load = 70.0"
            )
    );
    let dir = scratch("static-overload");
    let out = run(&dir, &text);
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let notes: Vec<&str> = log
        .lines()
        .filter(|l| l.contains("beyond its unlatch_load"))
        .collect();
    eprintln!("{notes:?}");
    assert_eq!(notes.len(), 1, "{log}");
    assert!(
        notes[0].starts_with("note: latch 20: the static analysis loads it with 70.")
            && notes[0].contains("at t = 4.7,"),
        "{}",
        notes[0]
    );
}
