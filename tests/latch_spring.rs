//! Spring latches (src/joints/latch.rs, src/analysis/impact.rs,
//! docs/joints.md §6.2, docs/theory.md §16.5): a rigid panel on a hinge to
//! the ground, latched through a stiff spring, against the closed forms of
//! its linear motion: the oscillation about the locking value after the
//! lock, the rattle across a dead band, the release under a load ramp; and
//! the input errors of the spring keys through the command line.
//!
//! The panel: a rigid body of mass `m = 1` and inertia `J_c = 1/12` about
//! its centre at (0.5, 0, 0), hinged about z at the origin to a fixed
//! node, so that its inertia about the hinge is `J = J_c + m/4 = 1/3` and
//! its equation of motion, with the hinge angle `θ`, is linear:
//! `J θ̈ = M(θ, t)` (tests/common/spring_latch.rs).

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::events::run;
use common::spring_latch::{
    panel, ramp_release, spinning_into_latch, BACKLASH, K_HOLD, K_RATTLE, OMEGA_0, RAMP, THETA_R,
    UNLATCH,
};
use unfold::analysis::LatchEventKind;
use unfold::elements::{ElementKind, Need};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// The panel's inertia about the hinge.
const J: f64 = 1.0 / 12.0 + 0.25;

/// The hinge angle: the panel's rotation about z (node 1 is fixed).
fn angle(state: &State) -> f64 {
    state.q[1].scaled_axis().z
}

/// The latch's results `[coordinate, locked, gap, load, contact]`.
fn latch_results(model: &Model, state: &State) -> [f64; 5] {
    let latch = model
        .elements
        .iter()
        .find(|e| e.kind() == ElementKind::Latch)
        .unwrap();
    let mut r = [0.0; 5];
    latch.results(&model.context(state.time, Need::RESIDUAL), state, &mut r);
    r
}

/// The times at which `f` crosses zero upwards along the steps, by linear
/// interpolation between accepted states.
fn upward_crossings(steps: &[(f64, f64)]) -> Vec<f64> {
    steps
        .windows(2)
        .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * (-w[0].1) / (w[1].1 - w[0].1))
        .collect()
}

/// Least-squares fit of `m + a cos ωt + b sin ωt` to `(t, y)`: `(m, a, b)`.
fn fit_harmonic(points: &[(f64, f64)], omega: f64) -> [f64; 3] {
    let mut n = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for &(t, y) in points {
        let phi = [1.0, (omega * t).cos(), (omega * t).sin()];
        for ((row, ri), pi) in n.iter_mut().zip(r.iter_mut()).zip(phi) {
            for (v, pj) in row.iter_mut().zip(phi) {
                *v += pi * pj;
            }
            *ri += pi * y;
        }
    }
    // Cramer's rule on the 3×3 normal equations (well conditioned: many
    // periods)
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&n);
    std::array::from_fn(|c| {
        let mut m = n;
        for (row, v) in m.iter_mut().zip(r) {
            row[c] = v;
        }
        det(&m) / d
    })
}

// ---------- (1) no backlash: oscillation about the locking value ----------

const K_LATCH: f64 = 1000.0;
const K_DRIVE: f64 = 1.0;
const THETA_L: f64 = std::f64::consts::FRAC_PI_2;
const THETA_F: f64 = THETA_L + 0.5;

/// Driven by a torsion spring `k_s (θ_f − θ)` from rest at θ = 0, the
/// panel reaches the latch at θ_L = 90° (no impact: the spring latch's
/// force is zero there) and then oscillates about the equilibrium of the
/// two springs, `θ_e = θ_L + k_s (θ_f − θ_L)/(k_L + k_s)`, at
/// `ω = √((k_L + k_s)/J)`: the linear equation `J θ̈ = −k_L (θ − θ_L) +
/// k_s (θ_f − θ)` after the lock. `√(k_L/J)` (the latch alone) differs
/// from it by `k_s/(2 k_L) = 5e-4`, and the static deflection `M/k_L`,
/// `M = k_s (θ_f − θ_L)` the drive moment at the lock, from `θ_e − θ_L` by
/// `k_s/k_L = 1e-3` of itself.
#[test]
fn a_spring_latch_without_backlash_oscillates_at_the_latch_frequency() {
    let text = panel(
        "end_time = 2.0\ntime_step = 0.001\nerror_tolerance = 1e-5\nrho_infinity = 1.0",
        &format!(
            r#"
[[joint_springs]]
id = 11
joint = 10
stiffness = {K_DRIVE}
free_value = {THETA_F}

[[latches]]
id = 20
joint = 10
value = {THETA_L}
mode = "spring"
stiffness = {K_LATCH}
"#
        ),
    );
    let (model, out, rec) = run(&text);
    assert_eq!(rec.locks.len(), 1, "{:?}", rec.locks);
    let lock = &rec.locks[0];
    assert_eq!(lock.kind, LatchEventKind::Lock);
    // the step lands on θ_L within the event tolerance, 1e-8 rad
    assert!((lock.coordinate - THETA_L).abs() <= 1e-8, "{lock:?}");
    // no impact: no impulse, no energy lost, the rate unchanged
    assert_eq!((lock.impulse, lock.energy_lost), (0.0, 0.0));
    assert_eq!(lock.rate_before, lock.rate_after);
    // the lock instant: θ(t) = θ_f (1 − cos ω_s t) before it, ω_s = √(k_s/J),
    // reaches θ_L at t_L = acos(1 − θ_L/θ_f)/ω_s; within 1e-5 s (the
    // integration error of the angle, 1e-5 rad measured below, over the
    // rate ~3.5 rad/s, with margin)
    let omega_s = (K_DRIVE / J).sqrt();
    let t_l = (1.0 - THETA_L / THETA_F).acos() / omega_s;
    let rate_l = THETA_F * omega_s * (omega_s * t_l).sin();
    eprintln!(
        "lock at t = {} (closed form {t_l}), rate {} (closed form {rate_l}); {} steps, {} rejected, {} event retries",
        lock.time, lock.rate_before, out.steps, out.rejected_steps, out.event_retries
    );
    assert!((lock.time - t_l).abs() <= 1e-5, "{} vs {t_l}", lock.time);
    assert!((lock.rate_before - rate_l).abs() <= 1e-4 * rate_l);

    // after the lock: the angle about its equilibrium
    let theta_e = THETA_L + K_DRIVE * (THETA_F - THETA_L) / (K_LATCH + K_DRIVE);
    let after: Vec<(f64, f64)> = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > lock.time)
        .map(|(i, s)| (i.time, angle(s)))
        .collect();
    let centred: Vec<(f64, f64)> = after.iter().map(|&(t, a)| (t, a - theta_e)).collect();
    let up = upward_crossings(&centred);
    assert!(up.len() >= 10, "{} crossings", up.len());
    let period = (up[up.len() - 1] - up[0]) / (up.len() - 1) as f64;
    let omega = 2.0 * std::f64::consts::PI / period;
    let exact = ((K_LATCH + K_DRIVE) / J).sqrt();
    let latch_alone = (K_LATCH / J).sqrt();
    eprintln!(
        "ω {omega} (closed form {exact}, error {:.3e}; √(k_L/J) = {latch_alone}, {:.3e}) over {} periods",
        omega / exact - 1.0,
        omega / latch_alone - 1.0,
        up.len() - 1
    );
    // frequency within 1e-3 of the closed form √((k_L + k_s)/J) (and of
    // √(k_L/J), 5e-4 away from it)
    assert!((omega / exact - 1.0).abs() <= 1e-3);
    assert!((omega / latch_alone - 1.0).abs() <= 1e-3);

    // the mean position and the amplitude from a least-squares fit of
    // m + a cos ωt + b sin ωt over the whole periods after the lock
    let window: Vec<(f64, f64)> = after
        .iter()
        .copied()
        .filter(|&(t, _)| t >= up[0] && t <= up[up.len() - 1])
        .collect();
    let [m, a, b] = fit_harmonic(&window, omega);
    let deflection = K_DRIVE * (THETA_F - THETA_L) / K_LATCH;
    let amplitude = ((THETA_L - theta_e).powi(2) + (lock.rate_before / exact).powi(2)).sqrt();
    eprintln!(
        "mean θ − θ_L {:.6e} (θ_e − θ_L {:.6e}, M/k_L {deflection:.6e}); amplitude {} (closed form {amplitude})",
        m - THETA_L,
        theta_e - THETA_L,
        a.hypot(b)
    );
    // the mean within 1 % of the static deflection M/k_L (5e-6 rad; θ_e
    // itself is 0.1 % from it)
    assert!((m - THETA_L - deflection).abs() <= 1e-2 * deflection);
    assert!((m - theta_e).abs() <= 1e-2 * deflection);
    // the amplitude of the free oscillation from the state at the lock,
    // √((θ_L − θ_e)² + (θ̇_L/ω)²), within 1e-3 (ρ∞ = 1: no numerical
    // dissipation)
    assert!((a.hypot(b) / amplitude - 1.0).abs() <= 1e-3);

    // the latch's load is its spring's, −k_L (θ − θ_L), at every step
    // after the lock (round-off), and it stays latched
    for (_, s) in rec.steps.iter().filter(|(i, _)| i.time >= lock.time) {
        let r = latch_results(&model, s);
        assert_eq!(r[1], 1.0);
        let spring = -K_LATCH * (angle(s) - THETA_L);
        assert!(
            (r[3] - spring).abs() <= 1e-9 * K_LATCH,
            "{} vs {spring}",
            r[3]
        );
    }
    // the energy balance with ρ∞ = 1: T + V conserved, the latch's spring
    // energy in V; within 1e-4 of the energy, ½ k_s θ_f²
    let e0 = 0.5 * K_DRIVE * THETA_F * THETA_F;
    for (i, s) in rec.steps.iter().step_by(500) {
        let e = unfold::analysis::energy::energies(&model, s);
        eprintln!("t = {} T + V − E₀ = {:.3e}", i.time, e.total() - e0);
    }
    eprintln!("energies at the end {:?}", out.energies);
    assert!(out.energies.balance_error.abs() <= 1e-4 * e0);
    assert!(out.energies.spring > 0.0);
}

// ---------- (2) backlash: the rattle across the dead band ----------

/// Spinning freely at ω₀ = 2 rad/s (no spring, no load), the panel latches
/// at θ_L = 0.5 rad with a dead band b = 0.1 rad: it flies across half the
/// band, is turned back by the latch's spring in half a cycle of
/// `Ω = √(k_L/J)` (30 rad/s), flies back across the whole band at −ω₀,
/// and so on: a rattle of period `T = 2b/ω₀ + 2π/Ω`, reaching `b/2 + ω₀/Ω`
/// beyond θ_L on either side (a linear spring returns the rate it
/// received). ρ∞ = 1: T + V is conserved. Fixed steps of 5e-4 s (the
/// steps that land on the events are shortened, the next ones are not):
/// with adaptive steps the step after each landing starts short and
/// doubles over some twenty steps, and at ρ∞ = 1 the integration of this
/// hinged body then loses energy whatever the latch (6e-4 of it over 0.3 s
/// for the same panel without latch started with a step of 1e-8 s).
#[test]
fn a_spring_latch_with_backlash_rattles_across_its_dead_band() {
    let text = spinning_into_latch(
        "end_time = 1.8\ntime_step = 0.0005\nadaptive = false\nrho_infinity = 1.0",
        &format!("backlash = {BACKLASH}"),
        "",
    );
    let (model, out, rec) = run(&text);
    assert_eq!(rec.locks.len(), 1, "{:?}", rec.locks);
    let lock = &rec.locks[0];
    // the lock at θ_L/ω₀: the step landed on θ_L within 1e-8 rad; the
    // time within 1e-5 s, the integration error of the rotation about the
    // hinge (2.8e-6 rad measured) over ω₀
    assert!((lock.coordinate - THETA_R).abs() <= 1e-8, "{lock:?}");
    assert!((lock.time - THETA_R / OMEGA_0).abs() <= 1e-5, "{lock:?}");
    let h = 0.5 * BACKLASH;
    let big_omega = (K_RATTLE / J).sqrt();
    let period = 2.0 * BACKLASH / OMEGA_0 + 2.0 * std::f64::consts::PI / big_omega;
    let reach = h + OMEGA_0 / big_omega;

    // entries into contact beyond the upper edge: the steps land on the
    // edge (within the event tolerance, 1e-8 rad)
    let x: Vec<(f64, f64)> = rec
        .steps
        .iter()
        .map(|(i, s)| (i.time, angle(s) - THETA_R))
        .collect();
    let entries: Vec<f64> = x
        .windows(2)
        .filter(|w| (w[0].1 - h).abs() <= 1e-8 && w[1].1 > h + 1e-8)
        .map(|w| w[0].0)
        .collect();
    let exits_below: Vec<f64> = x
        .windows(2)
        .filter(|w| (w[0].1 + h).abs() <= 1e-8 && w[1].1 < -h - 1e-8)
        .map(|w| w[0].0)
        .collect();
    eprintln!(
        "upper entries {entries:?}, lower entries {exits_below:?}; period closed form {period}; {} steps, {} rejected, {} event retries",
        out.steps, out.rejected_steps, out.event_retries
    );
    assert!(entries.len() >= 4, "{entries:?}");
    assert!(exits_below.len() >= 4, "{exits_below:?}");
    // the first entry after the flight across half the band, b/(2ω₀) after
    // the lock: 1e-6 s (the event tolerances, 1e-8 rad over 2 rad/s, and
    // the integration error of the rotation about the hinge over the
    // flight, 2.6e-7 rad measured, over ω₀)
    assert!((entries[0] - (lock.time + h / OMEGA_0)).abs() <= 1e-6);
    // the period, entry to entry at the upper edge and at the lower one:
    // within 1e-4 of the closed form (the integration error of the spring
    // half-cycles at error_tolerance 1e-5)
    for times in [&entries, &exits_below] {
        for w in times.windows(2) {
            let t = w[1] - w[0];
            assert!((t / period - 1.0).abs() <= 1e-4, "period {t} vs {period}");
        }
    }
    // lower entries half a period after the upper ones
    assert!((exits_below[0] - entries[0] - 0.5 * period).abs() <= 1e-4 * period);
    // the reach beyond θ_L on either side: the sampled extremes are within
    // 1e-3 of b/2 + ω₀/Ω (the sampling of a peak by steps of ~1e-3 s)
    let top = x.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let bottom = x
        .iter()
        .filter(|p| p.0 > lock.time)
        .map(|p| p.1)
        .fold(f64::MAX, f64::min);
    eprintln!("reach {top} and {bottom}, closed form ±{reach}");
    assert!(top <= reach * (1.0 + 1e-6) && top >= reach * (1.0 - 1e-3));
    assert!(-bottom <= reach * (1.0 + 1e-6) && -bottom >= reach * (1.0 - 1e-3));

    // no force inside the band (exactly zero), the spring's outside it
    let mut inside = 0;
    let mut rate_error = 0.0f64;
    for (_, s) in rec.steps.iter().filter(|(i, _)| i.time >= lock.time) {
        let r = latch_results(&model, s);
        let xs = angle(s) - THETA_R;
        if xs.abs() < h {
            inside += 1;
            assert_eq!((r[3], r[4]), (0.0, 0.0), "load inside the band at x = {xs}");
        } else {
            let spring = -K_RATTLE * (xs - h * xs.signum());
            assert!((r[3] - spring).abs() <= 1e-9 * K_RATTLE);
            assert_eq!(r[4], xs.signum());
        }
        if xs.abs() < h {
            rate_error = rate_error.max((s.velocity[1][5].abs() / OMEGA_0 - 1.0).abs());
        }
    }
    assert!(inside > 10);
    // the rate across the band is ±ω₀: within 5e-5 (half the energy's
    // tolerance below: the kinetic energy is all the energy there)
    eprintln!("largest relative error of the rate in the band {rate_error:.3e}");
    assert!(rate_error <= 5e-5);
    // energy with ρ∞ = 1: T + V against ½ J ω₀² within 1e-4 at every step
    // after the lock and in the balance at the end
    let e0 = 0.5 * J * OMEGA_0 * OMEGA_0;
    let mut worst = 0.0f64;
    for (k, (i, s)) in rec.steps.iter().enumerate() {
        let e = unfold::analysis::energy::energies(&model, s);
        worst = worst.max((e.total() - e0).abs());
        if k % 200 == 0 {
            eprintln!("t = {} T + V − E₀ = {:.3e}", i.time, e.total() - e0);
        }
    }
    eprintln!(
        "largest |T + V − E₀| {worst:.3e} of {e0}; at the end {:?}",
        out.energies
    );
    assert!(worst <= 1e-4 * e0);
    assert!(out.energies.balance_error.abs() <= 1e-4 * e0);
}

// ---------- (2b) one-sided spring latches ----------

/// Spinning freely at ω₀ = 2 rad/s, the panel reaches the latch at
/// θ_L = 0.5 rad (t = 0.25 s) whose spring (k = 300 N·m/rad, no dead band)
/// acts only beyond θ_L (`side = "beyond"`: a compliant end stop). It
/// enters the spring at ω₀, is turned back in half a cycle of
/// `Ω = √(k/J)` = 30 rad/s (`π/Ω` = 0.10472 s of contact, reaching
/// `ω₀/Ω` = 0.0667 rad beyond θ_L), and leaves at −ω₀ (a linear spring
/// without damping returns the rate it received); behind θ_L the latch is
/// free: the panel turns back at −ω₀ with no load on the latch. ρ∞ = 1
/// and fixed steps of 5e-4 s, as for the rattle above.
#[test]
fn a_one_sided_spring_latch_turns_the_panel_back_and_lets_it_go() {
    let text = spinning_into_latch(
        "end_time = 0.6\ntime_step = 0.0005\nadaptive = false\nrho_infinity = 1.0",
        "side = \"beyond\"",
        "",
    );
    let (model, _, rec) = run(&text);
    let big_omega = (K_RATTLE / J).sqrt();
    let x: Vec<(f64, f64, f64)> = rec
        .steps
        .iter()
        .map(|(i, s)| (i.time, angle(s) - THETA_R, s.velocity[1][5]))
        .collect();
    // the entry (the lock) and the exit are landed on: the states at
    // θ_L within 1e-8 rad (the event tolerance) moving beyond / back
    let entry = x
        .windows(2)
        .find(|w| w[0].1.abs() <= 1e-8 && w[1].1 > 1e-8)
        .expect("an entry")[0];
    let exit = x
        .windows(2)
        .find(|w| w[0].0 > entry.0 && w[0].1.abs() <= 1e-8 && w[1].1 < -1e-8)
        .expect("an exit")[0];
    eprintln!(
        "entry {entry:?}, exit {exit:?}; contact {} vs π/Ω = {}",
        exit.0 - entry.0,
        std::f64::consts::PI / big_omega
    );
    // out of the spring the latch goes straight to its free side (no dead
    // band: docs/joints.md §6.2), no step chasing an event of a band of no
    // width (down to 5e-13 s before; now none below 1e-4 s after the entry)
    let shortest = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > entry.0)
        .map(|(i, _)| i.step)
        .fold(f64::INFINITY, f64::min);
    assert!(shortest >= 1e-6, "a step of {shortest:e} s after the entry");
    // the spring engages at the entry and disengages at the exit, once each
    let crossings: Vec<(LatchEventKind, f64)> =
        rec.crossings.iter().map(|c| (c.kind, c.time)).collect();
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    assert_eq!(crossings[0].0, LatchEventKind::Engage, "{crossings:?}");
    assert_eq!(crossings[1].0, LatchEventKind::Disengage, "{crossings:?}");
    assert!(
        (crossings[1].1 - exit.0).abs() <= 1e-12,
        "{crossings:?} {exit:?}"
    );
    // the entry at θ_L/ω₀ (1e-5 s, as for the rattle) and at ω₀
    assert!((entry.0 - THETA_R / OMEGA_0).abs() <= 1e-5, "{entry:?}");
    assert!((entry.2 / OMEGA_0 - 1.0).abs() <= 1e-4, "{entry:?}");
    // contact for half a cycle: π/Ω within 1e-4 of it
    let contact = exit.0 - entry.0;
    let half = std::f64::consts::PI / big_omega;
    assert!((contact / half - 1.0).abs() <= 1e-4, "{contact} vs {half}");
    // the exit rate −ω₀ within 1e-4 (no damping: the rate returned)
    assert!((exit.2 / OMEGA_0 + 1.0).abs() <= 1e-4, "{exit:?}");
    // the reach beyond θ_L: ω₀/Ω, within 1e-3 (the sampling of the peak)
    let reach = OMEGA_0 / big_omega;
    let top = x.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    assert!(
        top <= reach * (1.0 + 1e-6) && top >= reach * (1.0 - 1e-3),
        "{top} vs {reach}"
    );
    // behind θ_L, free: no load (exactly zero), no contact, the rate −ω₀
    // (within 1e-4) and θ = θ_L − ω₀ (t − t_exit) (within 1e-6 rad)
    let mut free = 0;
    for (k, (i, s)) in rec.steps.iter().enumerate() {
        if i.time <= exit.0 {
            continue;
        }
        free += 1;
        let r = latch_results(&model, s);
        assert_eq!(r[1], 1.0, "still latched");
        assert_eq!(
            (r[3], r[4]),
            (0.0, 0.0),
            "load behind θ_L at t = {}",
            i.time
        );
        assert!((x[k].2 / OMEGA_0 + 1.0).abs() <= 1e-4, "{:?}", x[k]);
        let free_angle = -OMEGA_0 * (i.time - exit.0);
        assert!(
            (x[k].1 - free_angle).abs() <= 1e-6,
            "{:?} vs {free_angle}",
            x[k]
        );
    }
    assert!(free > 100, "{free}");
}

/// The same panel with the spring acting only behind θ_L (`side =
/// "behind"`: a pawl that holds the panel against coming back): it locks
/// at θ_L and goes on past it freely at ω₀, with no load on the latch.
#[test]
fn a_one_sided_spring_latch_lets_the_panel_go_on_past_it() {
    let text = spinning_into_latch(
        "end_time = 0.5\ntime_step = 0.0005\nadaptive = false\nrho_infinity = 1.0",
        "side = \"behind\"",
        "",
    );
    let (model, _, rec) = run(&text);
    assert_eq!(rec.locks.len(), 1, "{:?}", rec.locks);
    let lock = &rec.locks[0];
    assert!((lock.coordinate - THETA_R).abs() <= 1e-8, "{lock:?}");
    let (i, s) = rec.steps.last().unwrap();
    // on at ω₀: θ = ω₀ t within 1e-6 rad, the rate within 1e-6
    assert!((angle(s) - OMEGA_0 * i.time).abs() <= 1e-6, "{}", angle(s));
    assert!((s.velocity[1][5] / OMEGA_0 - 1.0).abs() <= 1e-6);
    // nothing acts on the panel: the rate within 1e-9 (8.6e-12 measured;
    // 1.6e-6 when the accelerations of steps of 5e-13 s took the
    // round-off of the velocity projection over γh, docs/theory.md §15.7)
    assert!((s.velocity[1][5] / OMEGA_0 - 1.0).abs() <= 1e-9);
    // the step that lands on θ_L is the only short one: the state there
    // passes θ_L by round-off, and the branch after the lock goes with
    // the rate (a branch from the sign of that round-off made the steps
    // after the lock chase a crossing down to 5e-13 s)
    let shortest = rec
        .steps
        .iter()
        .filter(|(i, _)| i.time > lock.time)
        .map(|(i, _)| i.step)
        .fold(f64::MAX, f64::min);
    assert!(shortest >= 1e-4, "a step of {shortest:e} s after the lock");
    for (i, s) in rec.steps.iter().filter(|(i, _)| i.time > lock.time) {
        let r = latch_results(&model, s);
        assert_eq!((r[1], r[3], r[4]), (1.0, 0.0, 0.0), "t = {}", i.time);
    }
}

// ---------- (3) the release under a load ramp ----------

/// `θ(t)` of the latched panel under the moment `R t` from rest:
/// `J θ̈ = R t − k θ`, `θ = (R/k)(t − sin ωt/ω)`, `ω = √(k/J)`; and its
/// rate.
fn held(t: f64) -> (f64, f64) {
    let w = (K_HOLD / J).sqrt();
    (
        RAMP / K_HOLD * (t - (w * t).sin() / w),
        RAMP / K_HOLD * (1.0 - (w * t).cos()),
    )
}

/// The panel latched at θ = 0 from the start (a latch at its value when
/// the analysis starts is latched there), loaded by a moment ramp
/// `M = R t` about the hinge: the latch's load `k θ` follows the closed
/// form `R (t − sin ωt/ω)` until it reaches the unlatch load `F_u`, at
/// `t_u`; the latch releases (an event), and the panel turns freely under
/// `J θ̈ = R t` from `θ(t_u)`, `θ̇(t_u)`.
#[test]
fn a_load_ramp_releases_a_spring_latch_at_its_unlatch_load() {
    let text = ramp_release(
        "end_time = 1.2\ntime_step = 0.001\nerror_tolerance = 1e-6",
        "",
    );
    let (model, out, rec) = run(&text);
    // t_u: R (t − sin ωt/ω) = F_u, by bisection on [0.4, 0.7] where it is
    // increasing
    let load = |t: f64| K_HOLD * held(t).0;
    let (mut lo, mut hi) = (0.4, 0.7);
    assert!(load(lo) < UNLATCH && load(hi) > UNLATCH);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if load(mid) < UNLATCH {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t_u = 0.5 * (lo + hi);
    let load_rate = K_HOLD * held(t_u).1;
    assert_eq!(rec.locks.len(), 1, "{:?}", rec.locks);
    let release = &rec.locks[0];
    assert_eq!(release.kind, LatchEventKind::Unlatch);
    // the angle while latched against the closed form: its error, δθ,
    // bounds the error of the load, k δθ
    let mut err = 0.0f64;
    for (i, s) in rec.steps.iter().filter(|(i, _)| i.time < release.time) {
        err = err.max((angle(s) - held(i.time).0).abs());
    }
    eprintln!(
        "release at t = {} (closed form {t_u}, difference {:.3e}), θ error before {err:.3e} rad, load rate {load_rate}; energy released {} (½F_u²/k = {}); {} steps, {} rejected, {} event retries",
        release.time,
        release.time - t_u,
        release.energy_lost,
        0.5 * UNLATCH * UNLATCH / K_HOLD,
        out.steps,
        out.rejected_steps,
        out.event_retries
    );
    // the angle error of the integration at error_tolerance 1e-6: 1e-6 rad
    assert!(err <= 1e-6, "{err:.3e}");
    // the release time: the load lands on F_u within its event tolerance
    // (1e-6 F_u, src/joints/latch.rs UNLATCH_TOLERANCE) and is k δθ off the
    // exact load: t within (1e-6 F_u + k δθ)/Ḟ of t_u
    let dt = (1e-6 * UNLATCH + K_HOLD * err) / load_rate;
    assert!(
        (release.time - t_u).abs() <= dt,
        "{} vs {t_u} (±{dt:.2e})",
        release.time
    );
    // the energy its spring held, ½ F_u²/k, leaves with it (1e-5: the
    // load within its tolerance)
    let held_energy = 0.5 * UNLATCH * UNLATCH / K_HOLD;
    assert!((release.energy_lost / held_energy - 1.0).abs() <= 1e-5);

    // then free: J θ̈ = R t from θ_u, θ̇_u (those of the simulation at the
    // release), θ(t) = θ_u + θ̇_u τ + R (t³ − t_u³ − 3 t_u² τ)/(6J),
    // τ = t − t_u; within 1e-3 of the travel over the 0.7 s after the
    // release (measured 1.1e-4: the integration error at error_tolerance
    // 1e-6 of a motion whose acceleration grows linearly, 1e-7 rad over
    // its first 0.3 s)
    let at = rec
        .steps
        .iter()
        .position(|(i, _)| i.increment == release.increment)
        .unwrap();
    let (t0, s0) = (rec.steps[at].0.time, &rec.steps[at].1);
    let (a0, w0) = (angle(s0), s0.velocity[1][5]);
    let mut free = 0.0f64;
    for (i, s) in &rec.steps[at + 1..] {
        let (t, tau) = (i.time, i.time - t0);
        let exact =
            a0 + w0 * tau + RAMP * (t.powi(3) - t0.powi(3) - 3.0 * t0 * t0 * tau) / (6.0 * J);
        free = free.max((angle(s) - exact).abs());
        let r = latch_results(&model, s);
        assert_eq!((r[1], r[3]), (0.0, 0.0), "released: no load");
    }
    let travel = angle(&out.state) - a0;
    eprintln!("free motion after the release: error {free:.3e} rad over {travel} rad");
    assert!(travel > 0.5, "the joint turns freely: {travel}");
    assert!(free <= 1e-3 * travel, "{free:.3e}");
    // the energy balance counts the released energy as dissipated: its
    // error stays that of the integration, 1e-5 of the work done
    eprintln!("energies at the end {:?}", out.energies);
    assert!((out.energies.dissipated - release.energy_lost).abs() <= 1e-12);
    assert!(out.energies.balance_error.abs() <= 1e-5 * out.energies.external_work);
}

// ---------- the dashpot ----------

/// Spinning at ω₀ = 2 rad/s into a spring latch at θ_L = 0.5 rad without
/// backlash, with a dashpot `d` of damping ratio `ζ = d/(2√(kJ)) = 0.02`:
/// after the lock `J ẍ + d ẋ + k x = 0` from `x = 0`, `ẋ = ω₀`, so
/// `x = (ω₀/ω_d) e^{−ζωτ} sin ω_d τ`, `ω_d = ω√(1 − ζ²)`, `τ = t − t_L`.
/// ρ∞ = 1 and fixed steps of 5e-4 s (ωh = 0.015: a phase error of
/// (ωh)²/12 = 2e-5 per radian, 6e-4 over the 30 rad of the run).
#[test]
fn a_spring_latch_with_a_dashpot_rings_down_as_a_damped_oscillator() {
    let zeta = 0.02;
    let omega = (K_RATTLE / J).sqrt();
    let d = 2.0 * zeta * (K_RATTLE * J).sqrt();
    let text = spinning_into_latch(
        "end_time = 1.25\ntime_step = 0.0005\nadaptive = false\nrho_infinity = 1.0",
        &format!("damping = {d}"),
        "",
    );
    let (model, out, rec) = run(&text);
    assert_eq!(rec.locks.len(), 1, "{:?}", rec.locks);
    let lock = &rec.locks[0];
    let (t_l, v) = (lock.time, lock.rate_before);
    let omega_d = omega * (1.0 - zeta * zeta).sqrt();
    let amplitude = v / omega_d;
    let mut worst = 0.0f64;
    for (i, s) in rec.steps.iter().filter(|(i, _)| i.time >= t_l) {
        let tau = i.time - t_l;
        let exact = amplitude * (-zeta * omega * tau).exp() * (omega_d * tau).sin();
        worst = worst.max((angle(s) - THETA_R - exact).abs());
        // the load is the spring's and the dashpot's, −(k x + d ẋ)
        let r = latch_results(&model, s);
        let f = K_RATTLE * (angle(s) - THETA_R) + d * s.velocity[1][5];
        assert!((r[3] + f).abs() <= 1e-9 * K_RATTLE);
    }
    eprintln!(
        "largest error against the damped oscillation {worst:.3e} rad (amplitude {amplitude}); energies at the end {:?}",
        out.energies
    );
    // within 2e-3 of the amplitude (the phase error above, with margin)
    assert!(worst <= 2e-3 * amplitude, "{worst:.3e}");
    // the dashpot's work counted as dissipated: the energy lost by the
    // closed-form motion by the end, ½ J ω₀² − (½ J ẋ² + ½ k x²), within
    // 1e-3 of it (the dissipation integrated by the trapezoidal rule over
    // the steps); the balance within 1e-4 of the energy
    let e0 = 0.5 * J * OMEGA_0 * OMEGA_0;
    let tau = out.time - t_l;
    let decay = (-zeta * omega * tau).exp();
    let x = amplitude * decay * (omega_d * tau).sin();
    let xdot = amplitude
        * decay
        * (omega_d * (omega_d * tau).cos() - zeta * omega * (omega_d * tau).sin());
    let lost = e0 - 0.5 * J * xdot * xdot - 0.5 * K_RATTLE * x * x;
    eprintln!(
        "dissipated {} (closed form {lost})",
        out.energies.dissipated
    );
    assert!((out.energies.dissipated / lost - 1.0).abs() <= 1e-3);
    assert!(out.energies.balance_error.abs() <= 1e-4 * e0);
}

/// A spring latch on an angle given in degrees (`unit = "deg"`: the
/// locking value and the backlash in degrees, the stiffness per degree,
/// the dashpot per degree per second) is the same latch as the one in
/// radians (1e-12 relative).
#[test]
fn spring_latch_keys_in_degrees_are_converted_to_radians() {
    let deg = std::f64::consts::PI / 180.0;
    let latch = |keys: &str| {
        let text = panel(
            "end_time = 0.1",
            &format!("[[latches]]\nid = 20\njoint = 10\nmode = \"spring\"\n{keys}\n"),
        );
        let input: ModelInput = toml::from_str(&text).unwrap();
        let model = Model::from_input(&input).unwrap();
        let l = model
            .elements
            .iter()
            .find_map(|e| e.as_latch())
            .unwrap()
            .clone();
        (l.value(), *l.spring().unwrap())
    };
    let (v_deg, s_deg) = latch(
        "value = 90.0\nunit = \"deg\"\nstiffness = 10.0\nbacklash = 2.0\ndamping = 0.5\nunlatch_load = 3.0",
    );
    let (v_rad, s_rad) = latch(&format!(
        "value = {}\nstiffness = {}\nbacklash = {}\ndamping = {}\nunlatch_load = 3.0",
        90.0 * deg,
        10.0 / deg,
        2.0 * deg,
        0.5 / deg
    ));
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(close(v_deg, v_rad));
    assert!(close(s_deg.stiffness, s_rad.stiffness));
    assert!(close(s_deg.backlash, s_rad.backlash));
    assert!(close(s_deg.damping, s_rad.damping));
    assert_eq!(s_deg.unlatch_load, Some(3.0));
}

/// A spring latch's stiffness and damping given with `unit = "deg"` are
/// noted in radians as a joint spring's are (10 N·m/deg = 10·180/π =
/// 572.9578 N·m/rad); a backlash of half a turn or more (200° here: ±100°
/// about the latch value) is warned of as a likely unit slip, one of 2°
/// is not.
#[test]
fn spring_latch_coefficients_per_degree_are_noted_and_a_huge_backlash_warned() {
    let model = |backlash: f64| {
        let text = panel(
            "end_time = 0.1",
            &format!(
                "[[latches]]\nid = 20\njoint = 10\nmode = \"spring\"\nvalue = 90.0\nunit = \"deg\"\nstiffness = 10.0\nbacklash = {backlash:?}\ndamping = 0.5\n"
            ),
        );
        let input: ModelInput = toml::from_str(&text).unwrap();
        Model::from_input(&input).unwrap()
    };
    let small = model(2.0);
    let notes: Vec<&str> = small.notes.iter().map(|n| n.message.as_str()).collect();
    assert!(
        notes.iter().any(|n| n
            .starts_with("stiffness = 10 with unit = \"deg\" is 10 N·m/deg = 5.729578e2 N·m/rad")),
        "{notes:?}"
    );
    assert!(
        notes.iter().any(|n| n.starts_with(
            "damping = 0.5 with unit = \"deg\" is 0.5 N·m·s/deg = 2.864789e1 N·m·s/rad"
        )),
        "{notes:?}"
    );
    assert!(
        !small
            .warnings
            .iter()
            .any(|w| w.message.contains("backlash")),
        "{:?}",
        small.warnings
    );
    let huge = model(200.0);
    assert!(
        huge.warnings
            .iter()
            .any(|w| w.entity == "latch 20" && w.message.contains("dead band of 200.0°")),
        "{:?}",
        huge.warnings
    );
}

/// The release through the command line: `events.csv` has one `unlatch`
/// row (the latch, its joint, the coordinate at `F_u/k` within the event
/// tolerance of the load, the energy released ½F_u²/k), `log.txt` a line
/// for it, and `latches.csv` the latch locked (1) up to the release and
/// open (0) after it, with its `contact` column.
#[test]
fn the_release_is_an_event_in_the_result_files() {
    let dir = scratch("release");
    let text = ramp_release(
        "end_time = 0.6\ntime_step = 0.001\nerror_tolerance = 1e-6",
        "",
    );
    let (out, _) = common::cli::run_text(&dir, &text);
    let table = |name: &str| -> (Vec<String>, Vec<Vec<String>>) {
        let text = std::fs::read_to_string(out.join(name)).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        (header, rows)
    };
    let (header, rows) = table("events.csv");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 1, "{rows:?}");
    let row = &rows[0];
    assert_eq!(row[col("kind")], "unlatch");
    assert_eq!(
        (row[col("element")].as_str(), row[col("joint")].as_str()),
        ("20", "10")
    );
    let c: f64 = row[col("coordinate")].parse().unwrap();
    let lost: f64 = row[col("energy_lost")].parse().unwrap();
    // θ at the release: F_u/k within the load's event tolerance (1e-6)
    assert!((c * K_HOLD / UNLATCH - 1.0).abs() <= 1e-5, "{c}");
    assert!((lost / (0.5 * UNLATCH * UNLATCH / K_HOLD) - 1.0).abs() <= 1e-5);
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains("latch 20: releases joint 10 at c = "), "{log}");
    let (header, rows) = table("latches.csv");
    assert_eq!(
        header,
        [
            "step",
            "time",
            "latch",
            "coordinate",
            "locked",
            "gap",
            "load",
            "contact"
        ]
    );
    let locked: Vec<f64> = rows.iter().map(|r| r[4].parse().unwrap()).collect();
    let first_open = locked.iter().position(|&l| l == 0.0).unwrap();
    assert!(first_open > 10, "{locked:?}");
    assert!(locked[..first_open].iter().all(|&l| l == 1.0));
    assert!(locked[first_open..].iter().all(|&l| l == 0.0));
}

// ---------- (4) input errors through the command line ----------

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-latch-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The spring keys are checked: a negative stiffness, a negative
/// backlash, a negative unlatch load, a spring latch without stiffness,
/// and spring keys in a rigid latch are input errors naming the file and
/// the latch, with exit code 2 (`unfold run` and `unfold check`).
#[test]
fn bad_spring_latch_keys_are_input_errors() {
    let dir = scratch("errors");
    let cases = [
        (
            "mode = \"spring\"\nstiffness = -5.0",
            "latch 20: stiffness must be positive and finite, got -5",
        ),
        (
            "mode = \"spring\"\nstiffness = 100.0\nbacklash = -0.1",
            "latch 20: backlash must be zero or positive and finite, got -0.1",
        ),
        (
            "mode = \"spring\"\nstiffness = 100.0\nunlatch_load = -1.0",
            "latch 20: unlatch_load must be positive and finite, got -1",
        ),
        (
            "mode = \"spring\"\nbacklash = 0.1",
            "latch 20: a spring latch needs `stiffness`",
        ),
        (
            "stiffness = 100.0\nbacklash = 0.1",
            "latch 20: `stiffness`, `backlash` apply to spring latches: add mode = \"spring\"",
        ),
        (
            "mode = \"rigid\"\ndamping = 2.0",
            "latch 20: `damping` applies to spring latches",
        ),
        (
            "mode = \"springy\"\nstiffness = 1.0",
            "unknown variant `springy`, expected `rigid` or `spring`",
        ),
    ];
    for (k, (keys, expected)) in cases.iter().enumerate() {
        let text = panel(
            "end_time = 0.1",
            &format!("[[latches]]\nid = 20\njoint = 10\nvalue = 0.5\n{keys}\n"),
        );
        let path = dir.join(format!("model{k}.toml"));
        std::fs::write(&path, text).unwrap();
        for command in ["check", "run"] {
            let out = Command::new(env!("CARGO_BIN_EXE_unfold"))
                .args([command, path.to_str().unwrap()])
                .current_dir(&dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{command} {keys}: {err}");
            assert!(err.contains(expected), "{command} {keys}: {err}");
            assert!(err.contains(&format!("model{k}.toml")), "{err}");
        }
    }
}

/// The release with fixed steps of 0.01 s, ten times the step whose
/// length would hide it: the latch's load `F_u` vanishes at the release,
/// so the accelerations are made consistent again there (docs/joints.md
/// §6.2). Kept, the step after the release would carry half of `F_u`:
/// a rate error of `½ F_u h/J` = 0.015 rad/s, 1e-2 rad over the free
/// motion.
#[test]
fn the_step_after_a_release_with_fixed_steps_carries_no_latch_load() {
    let text = ramp_release("end_time = 1.2\ntime_step = 0.01\nadaptive = false", "");
    let (_, out, rec) = run(&text);
    assert_eq!(rec.locks.len(), 1, "{:?}", rec.locks);
    let release = &rec.locks[0];
    assert_eq!(release.kind, LatchEventKind::Unlatch);
    let at = rec
        .steps
        .iter()
        .position(|(i, _)| i.increment == release.increment)
        .unwrap();
    let (t0, s0) = (rec.steps[at].0.time, &rec.steps[at].1);
    let (a0, w0) = (angle(s0), s0.velocity[1][5]);
    // the acceleration at the release: the ramp's alone, R t/J
    let accel = s0.acceleration[1][5];
    eprintln!(
        "release at {t0}: acceleration {accel} (free {})",
        RAMP * t0 / J
    );
    assert!(
        (accel - RAMP * t0 / J).abs() <= 1e-9 * RAMP * t0 / J,
        "{accel}"
    );
    // the free motion J θ̈ = R t from the state at the release: the
    // integration error of steps of 0.01 s on a cubic, measured 7.8e-5 rad
    // (bound 1e-4 of the travel; with the latch load kept over the step
    // after the release, 1.0e-2 rad)
    let mut free = 0.0f64;
    for (i, s) in &rec.steps[at + 1..] {
        let (t, tau) = (i.time, i.time - t0);
        let exact =
            a0 + w0 * tau + RAMP * (t.powi(3) - t0.powi(3) - 3.0 * t0 * t0 * tau) / (6.0 * J);
        free = free.max((angle(s) - exact).abs());
    }
    let travel = angle(&out.state) - a0;
    eprintln!(
        "free motion error {free:.3e} rad over {travel} rad; balance error {:.3e} of work {}",
        out.energies.balance_error, out.energies.external_work
    );
    assert!(travel > 0.5, "{travel}");
    assert!(free <= 1e-4 * travel, "{free:.3e}");
}
