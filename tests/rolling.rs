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

use std::f64::consts::PI;
use std::sync::Arc;

use unfold::analysis::{DynamicAnalysis, DynamicSettings, IncrementInfo, Observer};
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
    let mut b = ModelBuilder::new("rolling disc");
    let straight = big_r.is_infinite();
    // e_r = x̂, e_t = ŷ; a = (cos θ, 0, sin θ), centre above-inside the
    // contact point
    let a = Vec3::new(theta.cos(), 0.0, theta.sin());
    let (centre, velocity, omega) = if straight {
        let c = Vec3::new(0.0, 0.0, r);
        (c, Vec3::new(0.0, v, 0.0), a * (-v / r))
    } else {
        let w = steady_rate(r, theta, big_r);
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

#[test]
fn steady_circular_rolling_keeps_the_closed_form_tilt_radius_and_rate() {
    let (m, r, theta0, big_r) = (1.0, 0.5, 0.3, 2.0);
    let d = disc(m, r, theta0, big_r, 0.0);
    let w = steady_rate(r, theta0, big_r);
    let period = 2.0 * PI / w;
    let end = 3.0 * period;
    for (rho, h) in [(0.98, 5e-3)] {
        let out = run(&d, end, h, rho);
        let (mut e_theta, mut e_r, mut e_phase, mut slip, mut height) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut phi_prev = 0.0;
        let mut turns = 0.0;
        for s in &out.history.states {
            let (theta, p, sl) = measure(&d, s, r);
            e_theta = e_theta.max((theta - theta0).abs() / theta0);
            e_r = e_r.max((p.x.hypot(p.y) - big_r).abs() / big_r);
            let mut phi = p.y.atan2(p.x);
            if phi < phi_prev - PI {
                turns += 1.0;
            }
            phi_prev = phi;
            phi += 2.0 * PI * turns;
            e_phase = e_phase.max((phi - w * s.time).abs() / (2.0 * PI));
            slip = slip.max(sl / (w * big_r));
            height = height.max(p.z.abs() / r);
        }
        let its = &out.history.iterations[1..];
        let mean = its.iter().sum::<usize>() as f64 / its.len() as f64;
        println!(
            "ρ∞ = {rho}, h = {h}: tilt {e_theta:.2e}, radius {e_r:.2e}, phase {e_phase:.2e} turn, slip {slip:.2e}, height {height:.2e}, energy {:.2e}, iterations {mean:.2} (max {}), {:.2} s",
            out.energy_drift,
            its.iter().max().unwrap(),
            out.wall
        );
    }
}
