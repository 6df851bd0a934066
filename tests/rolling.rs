//! A thin disc rolling without slipping on a horizontal plane (the rolling
//! disc joint, docs/joints.md §3.8; reference paper eq. 15).
//!
//! Steady circular rolling of a thin uniform disc (mass m, radius r,
//! `I_axial = ½mr²`, `I_diam = ¼mr²`), tilted by θ from the vertical
//! towards the centre O of the circle of radius R that its contact point
//! describes, the whole turning about the vertical through O at the rate
//! Ω. Rolling gives the spin relative to the turning frame `s = −ΩR/r`,
//! so `ω = Ω ẑ − (ΩR/r) a` (a the disc's axis); the centre moves on the
//! circle of radius `R − r sin θ`. The moment about the centre of the
//! contact force (`N = mg`, radial `−mΩ²(R − r sin θ)`) balances the rate
//! of the angular momentum `Ω ẑ × H_G`, which gives
//!
//! ```text
//! Ω² cos θ (3R/2 − (5/4) r sin θ) = g sin θ,
//! ```
//!
//! derived here by the Newton–Euler equations about the centre of mass
//! as in Greenwood, *Principles of Dynamics* (2nd ed., 1988), §8.6 (the
//! rolling disc); for `R ≫ r` it is the classical `tan θ = (3/2) v²/(gR)`,
//! `v = ΩR` (Greenwood; Goldstein, *Classical Mechanics*).

mod common;

use std::f64::consts::PI;
use std::sync::Arc;

use unfold::analysis::{DynamicAnalysis, DynamicSettings, IncrementInfo, Observer};
use unfold::io::model_file::parse_model;
use unfold::model::builder::*;
use unfold::model::Model;
use unfold::so3::{self, Vec3};
use unfold::state::State;

const G: f64 = 9.81;

/// Keeps every converged state and the Newton iterations.
#[derive(Default)]
struct History {
    states: Vec<State>,
    iterations: Vec<usize>,
}

impl Observer for History {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.states.push(state.clone());
        self.iterations.push(info.iterations);
        Ok(())
    }
}

/// The disc's steady precession rate for tilt θ and contact-path radius
/// R (see the module documentation).
fn steady_rate(r: f64, theta: f64, big_r: f64) -> f64 {
    (G * theta.sin() / (theta.cos() * (1.5 * big_r - 1.25 * r * theta.sin()))).sqrt()
}

struct Disc {
    model: Arc<Model>,
    node: usize,
    start: State,
}

/// A disc of mass `m`, radius `r`, its axis the node's material e₃, at
/// tilt θ with its contact point at (R, 0, 0) on the plane z = 0, moving
/// in steady rolling about the vertical through the origin at the rate
/// Ω (straight along +y at speed `v` if `big_r` is infinite).
fn disc(m: f64, r: f64, theta: f64, big_r: f64, v: f64) -> Disc {
    disc_at_rate(m, r, theta, big_r, v, 1.0)
}

/// [`disc`] with the steady rate (and the velocities that roll with it)
/// multiplied by `factor`.
fn disc_at_rate(m: f64, r: f64, theta: f64, big_r: f64, v: f64, factor: f64) -> Disc {
    let mut b = ModelBuilder::new("rolling disc");
    let straight = big_r.is_infinite();
    // e_r = x̂, e_t = ŷ; a = (cos θ, 0, sin θ), centre above-inside the
    // contact point
    let a = Vec3::new(theta.cos(), 0.0, theta.sin());
    let (centre, velocity, omega) = if straight {
        let c = Vec3::new(0.0, 0.0, r);
        (c, Vec3::new(0.0, v, 0.0), a * (-v / r))
    } else {
        let w = factor * steady_rate(r, theta, big_r);
        let c = Vec3::new(big_r - r * theta.sin(), 0.0, r * theta.cos());
        let omega = Vec3::z() * w - a * (w * big_r / r);
        (c, Vec3::new(0.0, w * c.x, 0.0), omega)
    };
    let node = b.add(
        Node::at([centre.x, centre.y, centre.z])
            .rotation([0.0, PI / 2.0 - theta, 0.0])
            .velocity([velocity.x, velocity.y, velocity.z])
            .angular_velocity([omega.x, omega.y, omega.z]),
    );
    b.add(RigidBody::at(node, m).inertia([0.25 * m * r * r, 0.25 * m * r * r, 0.5 * m * r * r]));
    b.add(RollingDisc::new(node, r, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]));
    b.add(Gravity::of([0.0, 0.0, -G]).curve(CurveHandle::CONSTANT));
    let model = Arc::new(b.build().expect("a valid model"));
    let n = model.node(node);
    let start = model.initial_state();
    Disc {
        model,
        node: n,
        start,
    }
}

struct Run {
    history: History,
    energy_drift: f64,
    wall: f64,
}

fn run(d: &Disc, end: f64, h: f64, rho: f64) -> Run {
    let mut settings = DynamicSettings::new(end, h).fixed_step();
    settings.rho_infinity = rho;
    settings.residual_tolerance = 1e-10;
    settings.displacement_tolerance = 1e-10;
    settings.rotation_tolerance = 1e-10;
    let mut history = History::default();
    let outcome =
        DynamicAnalysis::new(d.model.clone(), settings).run(d.start.clone(), &mut history);
    assert!(
        outcome.error.is_none(),
        "the dynamic analysis stopped: {:?}",
        outcome.error
    );
    let total = outcome.energies.kinetic + outcome.energies.gravity;
    Run {
        energy_drift: outcome.energies.balance_error / total.abs().max(1e-300),
        history,
        wall: outcome.wall_time,
    }
}

/// Tilt, contact point and contact-point slip velocity of the disc.
fn measure(d: &Disc, s: &State, r: f64) -> (f64, Vec3, f64) {
    let n = d.node;
    let rm = so3::matrix(&s.q[n]);
    let a = rm * Vec3::z();
    let theta = a.z.asin();
    let w = a.cross(&Vec3::z()).cross(&a);
    let u = -w.normalize();
    let p = s.x[n] + u * r;
    let v = &s.velocity[n];
    let omega = rm * Vec3::new(v[3], v[4], v[5]);
    let slip = Vec3::new(v[0], v[1], v[2]) + omega.cross(&(u * r));
    (theta, p, slip.norm())
}

/// Largest deviations over a run of steady circular rolling: tilt and
/// contact-path radius (relative), phase of the contact point about the
/// vertical axis against `Ω t` (turns), slip velocity (relative to the
/// speed `ΩR`) and height of the contact point (relative to r).
#[derive(Debug, Default)]
struct Deviations {
    tilt: f64,
    radius: f64,
    phase: f64,
    slip: f64,
    height: f64,
}

fn deviations(d: &Disc, states: &[State], r: f64, theta0: f64, big_r: f64) -> Deviations {
    let w = steady_rate(r, theta0, big_r);
    let mut e = Deviations::default();
    let (mut phi_prev, mut turns) = (0.0, 0.0);
    for s in states {
        let (theta, p, slip) = measure(d, s, r);
        e.tilt = e.tilt.max((theta - theta0).abs() / theta0);
        e.radius = e.radius.max((p.x.hypot(p.y) - big_r).abs() / big_r);
        let phi = p.y.atan2(p.x);
        if phi < phi_prev - PI {
            turns += 1.0;
        }
        phi_prev = phi;
        e.phase = e
            .phase
            .max((phi + 2.0 * PI * turns - w * s.time).abs() / (2.0 * PI));
        e.slip = e.slip.max(slip / (w * big_r));
        e.height = e.height.max(p.z.abs() / r);
    }
    e
}

fn mean_iterations(h: &History) -> (f64, usize) {
    let its = &h.iterations[1..];
    let mean = its.iter().sum::<usize>() as f64 / its.len() as f64;
    (mean, *its.iter().max().unwrap_or(&0))
}

#[test]
fn steady_circular_rolling_keeps_the_closed_form_tilt_radius_and_rate() {
    // m = 1 kg, r = 0.5 m, θ = 0.3 rad, R = 2 m: Ω = 1.038 rad/s (a
    // turn in 6.05 s), speed ΩR = 2.08 m/s, spin 4.15 rad/s
    let (m, r, theta0, big_r) = (1.0, 0.5, 0.3, 2.0);
    let w = steady_rate(r, theta0, big_r);
    let end = 3.0 * 2.0 * PI / w;
    let d = disc(m, r, theta0, big_r, 0.0);

    // ρ∞ = 0.98 at h = 5e-3 and 2.5e-3 over three turns (3641 steps at
    // the finer); ρ∞ = 1 in the test below
    let (rho, h) = (0.98, 5e-3);
    let coarse = run(&d, end, h, rho);
    let fine = run(&d, end, 0.5 * h, rho);
    let e = deviations(&d, &coarse.history.states, r, theta0, big_r);
    let e_fine = deviations(&d, &fine.history.states, r, theta0, big_r);
    let (its, max_its) = mean_iterations(&coarse.history);
    println!(
        "h = {h}: {e:?}, energy {:.2e}, iterations {its:.2} (max {max_its}), {:.2} s",
        coarse.energy_drift, coarse.wall
    );
    println!(
        "h = {}: {e_fine:?}, energy {:.2e}, {:.2} s",
        0.5 * h,
        fine.energy_drift,
        fine.wall
    );

    // the closed-form relation holds to 1e-4 over three turns: tilt,
    // radius and phase at h = 5e-3 (measured 4.9e-5, 1.5e-5, 2.1e-5 turn)
    assert!(e.tilt < 1e-4 && e.radius < 1e-4 && e.phase < 1e-4, "{e:?}");
    // ... with the second-order error of the method (Brüls, Cardona &
    // Arnold 2012): halving h divides the tilt error by 4 ± 0.4
    // (measured 3.99)
    let ratio = e.tilt / e_fine.tilt;
    assert!(
        (ratio - 4.0).abs() < 0.4,
        "tilt errors {e:?} and {e_fine:?}"
    );
    // no slip: the contact velocity is set by Newton's tolerance (1e-10 of
    // the step's motion on the rows τAv), not by the step: measured
    // 1.2e-9 of the speed at h = 5e-3
    assert!(e.slip < 1e-8, "{e:?}");
    // the holonomic contact to round-off (measured 1.4e-13 of r)
    assert!(e.height < 1e-11, "{e:?}");
    // the constraint forces do no work: T + V kept to 1e-8 (measured
    // −9.5e-10 at ρ∞ = 0.98; −2.5e-8 at ρ∞ = 0.9, its numerical
    // dissipation)
    assert!(coarse.energy_drift.abs() < 1e-8, "{}", coarse.energy_drift);
    // Newton converges quadratically: two iterations per step (measured)
    assert!(max_its <= 3, "{its} iterations per step, at most {max_its}");

    // the test tells a wrong rate: started 1e-3 faster than the closed
    // form, the disc nutates by more than the tolerance (measured below)
    let off = disc_at_rate(m, r, theta0, big_r, 0.0, 1.001);
    let out = run(&off, end, h, rho);
    let e_off = deviations(&off, &out.history.states, r, theta0, big_r);
    println!("rate × 1.001: {e_off:?}");
    assert!(e_off.tilt > 1e-4, "{e_off:?}");
}

/// ρ∞ = 1 keeps every frequency: the velocities are projected on the
/// contact and no-slip constraints after each step (docs/theory.md §15.7,
/// D13; without it the undamped index-3 multipliers of the contact made
/// the run stop at t = 16.66 s with a singular iteration matrix).
#[test]
fn steady_circular_rolling_conserves_energy_at_rho_one() {
    let (m, r, theta0, big_r) = (1.0, 0.5, 0.3, 2.0);
    let w = steady_rate(r, theta0, big_r);
    let end = 3.0 * 2.0 * PI / w;
    let d = disc(m, r, theta0, big_r, 0.0);
    let h = 5e-3;
    let out = run(&d, end, h, 1.0);
    let e = deviations(&d, &out.history.states, r, theta0, big_r);
    println!(
        "ρ∞ = 1, h = {h}: {e:?}, energy {:.2e}, {:.2} s",
        out.energy_drift, out.wall
    );
    // the closed form of steady rolling (as at ρ∞ = 0.98 above): tilt,
    // radius and phase within 1e-4 over three turns
    assert!(e.tilt < 1e-4 && e.radius < 1e-4 && e.phase < 1e-4, "{e:?}");
    // rolling without slip, the contact held (limits as above)
    assert!(e.slip < 1e-8 && e.height < 1e-11, "{e:?}");
    // T + V kept to 1e-8 as at ρ∞ = 0.98 (measured −6.7e-11: the
    // projection removes ½δvᵀMδv = O(h⁴) per step)
    assert!(out.energy_drift.abs() < 1e-8, "{}", out.energy_drift);
}

#[test]
fn upright_disc_rolls_straight_without_drift() {
    // r = 0.5 m at 2 m/s (above the speed √(gr/3) = 1.28 m/s that keeps
    // a thin disc upright; e.g. Greenwood §8.6), over 2 s (8 radians per
    // metre... 16 rad of spin)
    let (m, r, v, end) = (1.0, 0.5, 2.0, 2.0);
    let d = disc(m, r, 0.0, f64::INFINITY, v);
    let out = run(&d, end, 5e-3, 0.98);
    let mut drift = 0.0f64;
    let mut tilt = 0.0f64;
    let mut slip = 0.0f64;
    let mut along = 0.0f64;
    for s in &out.history.states {
        let (theta, p, sl) = measure(&d, s, r);
        drift = drift.max(p.x.abs() / r);
        tilt = tilt.max(theta.abs());
        slip = slip.max(sl / v);
        along = along.max((s.x[d.node].y - v * s.time).abs() / r);
    }
    let (its, max_its) = mean_iterations(&out.history);
    println!(
        "upright: drift {drift:.2e}, tilt {tilt:.2e}, slip {slip:.2e}, distance error {along:.2e}, energy {:.2e}, iterations {its:.2} (max {max_its})",
        out.energy_drift
    );
    // no sideways drift, no tilt: the symmetric motion is kept to
    // round-off (measured below 1e-14)
    assert!(
        drift < 1e-12 && tilt < 1e-12,
        "drift {drift:e}, tilt {tilt:e}"
    );
    // the distance rolled is v t (uniform motion: exact for the method)
    assert!(along < 1e-9, "{along:e}");
    assert!(slip < 1e-8, "{slip:e}");
    assert!(out.energy_drift.abs() < 1e-10, "{}", out.energy_drift);
}

/// In statics and kinematic analyses the rolling condition holds on the
/// increments (docs/joints.md §3.8): the contact point does not slide,
/// the disc may roll and pivot about it. A standing disc alone is
/// therefore a mechanism (rolling and pivoting cost nothing): its static
/// analysis stops with an error naming a free rotation. Held by
/// rotational springs to the ground (k = 100 N·m/rad) and pushed along
/// its axis at the centre (P = 1 N), it leans without sliding: the plane
/// carries `N = mg` and the friction `−P`, and the contact point stays at
/// the origin.
#[test]
fn statics_holds_the_contact_point() {
    let (m, r, k, push) = (2.0, 0.5, 100.0, 1.0);
    let build = |springs: bool| {
        let mut b = ModelBuilder::new("standing disc");
        // axis (material e3) along x, rolling along y
        let n = b.add(Node::at([0.0, 0.0, r]).rotation([0.0, PI / 2.0, 0.0]));
        b.add(RigidBody::at(n, m).inertia([0.25 * m * r * r, 0.25 * m * r * r, 0.5 * m * r * r]));
        let disc = b.add(RollingDisc::new(n, r, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]));
        b.add(Gravity::of([0.0, 0.0, -G]));
        if springs {
            b.add(Spring::rotational(n, Ground, k));
            b.add(Load::force(n, [push, 0.0, 0.0]));
        }
        b.analysis(
            Analysis::statics()
                .residual_tolerance(1e-12)
                .displacement_tolerance(1e-12)
                .rotation_tolerance(1e-12),
        );
        let settings = b.analyses().unwrap()[0].as_static().unwrap().clone();
        (Arc::new(b.build().expect("a valid model")), settings, disc)
    };
    let (model, settings, _) = build(false);
    let out = unfold::analysis::StaticAnalysis::new(model.clone(), settings)
        .run(model.initial_state(), &mut unfold::analysis::NoObserver);
    let e = format!("{:?}", out.error);
    println!("free: {e}");
    assert!(e.contains("Singular") && e.contains("node 1 r"), "{e}");

    let (model, settings, disc) = build(true);
    let out = unfold::analysis::StaticAnalysis::new(model.clone(), settings)
        .run(model.initial_state(), &mut unfold::analysis::NoObserver);
    assert!(out.error.is_none(), "{:?}", out.error);
    let res = model.results(disc, &out.state);
    let get = |name: &str| res.get(name).unwrap();
    let c = Vec3::new(get("cx"), get("cy"), get("cz"));
    // the lean: moment P r about the contact line against k − m g r
    let lean = push * r / (k - m * G * r);
    let x = out.state.x[model.node_index(1).expect("node 1")];
    println!(
        "held: N = {}, F = ({}, {}), contact {c:?}, centre x = {} (lean {lean})",
        get("N"),
        get("F1"),
        get("F2"),
        x.x
    );
    // N = mg and friction −P to the residual tolerance; the centre
    // displaced by r δ, δ from the moment balance about the contact line
    // P r cos δ + m g r sin δ = k δ in its small-angle form, to 1e-3 (the
    // form's error is ~δ², 3e-5)
    assert!((get("N") - m * G).abs() < 1e-9 * m * G, "N = {}", get("N"));
    assert!((get("F1") + push).abs() < 1e-9 && get("F2").abs() < 1e-9);
    // the contact point stays: the rule A(q)(q ⊖ q_n) = 0 is the backward
    // Euler rule on each increment, exact to first order; for a lean δ in
    // one increment it lets the contact slide by r(δ cos δ − sin δ) ≈
    // rδ³/3 (2.8e-8 m here), less when the lean is spread over increments
    // (measured 2.3e-9 m)
    assert!(
        c.norm() < r * lean.powi(3) / 3.0,
        "the contact point slid to {c:?}"
    );
    assert!(
        (x.x - r * lean).abs() < 1e-3 * r * lean,
        "{} against {}",
        x.x,
        r * lean
    );
}

/// Bad input is reported with the entity and what is wrong.
#[test]
fn bad_rolling_discs_are_reported() {
    let case = |radius: f64, axis: [f64; 3], normal: [f64; 3], z: f64| {
        let mut b = ModelBuilder::new("bad disc");
        let n = b.add(Node::at([0.0, 0.0, z]).rotation([0.0, PI / 2.0, 0.0]));
        b.add(RigidBody::at(n, 1.0).inertia([1.0, 1.0, 1.0]));
        b.add(RollingDisc::new(n, radius, axis, normal).id(40));
        match b.build() {
            Ok(_) => String::from("accepted"),
            Err(e) => e.to_string(),
        }
    };
    let zero_radius = case(0.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], 0.5);
    assert!(
        zero_radius.contains("rolling disc 40") && zero_radius.contains("radius must be positive"),
        "{zero_radius}"
    );
    let negative = case(-1.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], 0.5);
    assert!(negative.contains("radius must be positive"), "{negative}");
    let normal = case(0.5, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0], 0.5);
    assert!(
        normal.contains("rolling disc 40") && normal.contains("normal must be a non-zero"),
        "{normal}"
    );
    let axis = case(0.5, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.5);
    assert!(axis.contains("axis must be a non-zero"), "{axis}");
    let apart = case(0.5, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], 0.6);
    assert!(apart.contains("does not touch the plane"), "{apart}");
    let flat = case(0.5, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.5);
    assert!(flat.contains("lying flat"), "{flat}");

    // an unknown node, in a model file
    let text = r#"
[analysis]
type = "dynamic"
end_time = 1.0

[[nodes]]
id = 1
x = [0.0, 0.0, 0.5]

[[rigid_bodies]]
id = 1
node = 1
mass = 1.0

[[rolling_discs]]
id = 2
node = 7
radius = 0.5
axis = [1.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"#;
    let input = parse_model(text, std::path::Path::new("disc.toml")).expect("parses");
    let e = Model::from_input(&input)
        .expect_err("node 7 does not exist")
        .to_string();
    assert!(
        e.contains("rolling disc 2") && e.contains("node 7 does not exist"),
        "{e}"
    );
    println!("{zero_radius}\n{normal}\n{apart}\n{flat}\n{e}");
}

/// The example of docs/model-format.md (`[[rolling_discs]]`, the disc of
/// tests/common/rolling_disc.rs): an upright disc rolling along +y at
/// 2 m/s covers 2 m in 1 s (uniform motion, exact for the method up to
/// Newton's tolerance: 1e-9).
#[test]
fn model_file_example_rolls() {
    let text = &common::rolling_disc::upright_disc(
        r#"
[analysis]
type = "dynamic"
end_time = 1.0
time_step = 0.01
adaptive = false"#,
        -4.0,
    );
    let input = parse_model(text, std::path::Path::new("disc.toml")).expect("parses");
    let model = Arc::new(Model::from_input(&input).expect("builds"));
    let settings = input.analyses().unwrap()[0].as_dynamic().unwrap().clone();
    let out = DynamicAnalysis::new(model.clone(), settings)
        .run(model.initial_state(), &mut History::default());
    assert!(out.error.is_none(), "{:?}", out.error);
    let x = out.state.x[0];
    assert!((x - Vec3::new(0.0, 2.0, 0.5)).norm() < 1e-9, "{x:?}");
}
