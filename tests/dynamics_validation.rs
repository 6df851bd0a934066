//! Validation of the dynamic analysis (src/analysis/dynamics.rs, the
//! Lie-group generalised-α method) against closed-form solutions,
//! independent integrations written in tests/common without any of the
//! library's code, and the modal analysis:
//!
//! - the flips of a free asymmetric body spun near its intermediate axis
//!   (Dzhanibekov): energy and spatial angular momentum kept, flip period
//!   against Landau & Lifshitz §37;
//! - the heavy top on a spherical joint (Arnold & Brüls 2007) against RK4
//!   on Euler's equations with a quaternion, and the order of convergence;
//! - a very stiff beam swinging as a pendulum from the horizontal, against
//!   the elliptic-integral period;
//! - a four-bar linkage falling under gravity: constraints kept to
//!   round-off, energy conserved to the method's O(h²) error;
//! - the flexible beam pendulum of bench/peer: energy balance with and
//!   without numerical dissipation;
//! - the free vibration of a cantilever against its modal analysis and
//!   Euler–Bernoulli;
//! - the step controller under a sudden load, against fixed small steps;
//! - the condition number of the iteration matrix as `h → 0`, scaled and
//!   unscaled.
//!
//! Each test states the figures it measured next to its limits; every
//! test runs in a few seconds in release.
//!
//! Every model is built with the Rust API; the quantities compared are
//! computed here from the state (positions, orientations, velocities),
//! except the strain energy of beams, taken from the library.

mod common;

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use unfold::analysis::{
    AngularVelocities, DynamicAnalysis, DynamicSettings, IncrementInfo, ModalAnalysis,
    ModalSettings, NoObserver, Observer,
};
use unfold::model::builder::*;
use unfold::model::Model;
use unfold::so3;
use unfold::state::State;

use common::quadrature::pendulum_period;
use common::rigid_body::{
    arnold_bruls_top, energy_and_momentum, torque_free_period, BodyState, HeavyTop,
};

/// Keeps the state of every converged step.
#[derive(Default)]
struct History {
    states: Vec<State>,
}

impl Observer for History {
    fn increment(
        &mut self,
        _: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.states.push(state.clone());
        Ok(())
    }
}

/// Fixed steps `h` from `start.time` to `end_time` with spectral radius
/// `rho`, tight Newton tolerances; returns every converged state.
fn run_fixed(model: &Arc<Model>, start: State, end_time: f64, h: f64, rho: f64) -> Vec<State> {
    run_fixed_in(model, start, end_time, h, rho, AngularVelocities::Material)
}

/// [`run_fixed`] with the scheme's angular velocities in `frame`.
fn run_fixed_in(
    model: &Arc<Model>,
    start: State,
    end_time: f64,
    h: f64,
    rho: f64,
    frame: AngularVelocities,
) -> Vec<State> {
    let mut settings = DynamicSettings::new(end_time, h).fixed_step();
    settings.rho_infinity = rho;
    settings.angular_velocities = frame;
    settings.residual_tolerance = 1e-10;
    settings.displacement_tolerance = 1e-10;
    settings.rotation_tolerance = 1e-10;
    let mut history = History::default();
    let outcome = DynamicAnalysis::new(model.clone(), settings).run(start, &mut history);
    assert!(
        outcome.error.is_none(),
        "the dynamic analysis stopped: {:?}",
        outcome.error
    );
    assert!((outcome.time - end_time).abs() < 1e-9 * end_time);
    history.states
}

/// Times at which `value` crosses zero, by cubic Hermite interpolation
/// between successive samples `(t, value, rate)`.
fn zero_crossings(samples: &[(f64, f64, f64)]) -> Vec<f64> {
    let mut out = Vec::new();
    for w in samples.windows(2) {
        let ((t0, y0, d0), (t1, y1, d1)) = (w[0], w[1]);
        if y0 == 0.0 || y0 * y1 >= 0.0 {
            continue;
        }
        let h = t1 - t0;
        let p = |s: f64| {
            let (s2, s3) = (s * s, s * s * s);
            (2.0 * s3 - 3.0 * s2 + 1.0) * y0
                + (s3 - 2.0 * s2 + s) * h * d0
                + (-2.0 * s3 + 3.0 * s2) * y1
                + (s3 - s2) * h * d1
        };
        // bisection on the interpolant (monotone enough between samples)
        let (mut a, mut b) = (0.0, 1.0);
        for _ in 0..60 {
            let m = 0.5 * (a + b);
            if p(m) * y0 > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        out.push(t0 + 0.5 * (a + b) * h);
    }
    out
}

/// Rotation matrix of a node's orientation.
fn matrix(q: &so3::Rotation) -> Matrix3<f64> {
    so3::matrix(q)
}

// ---------------------------------------------------------------------------
// Dzhanibekov flip
// ---------------------------------------------------------------------------

#[test]
fn dzhanibekov_flip_keeps_energy_and_momentum_and_flips_with_the_closed_form_period() {
    // a free asymmetric body, principal inertia (1, 2, 3) kg·m² about its
    // centre of mass (the node, free in all six components: a model whose
    // analyses are all dynamic may have free parts), spun at 6 rad/s about
    // the intermediate axis with a small perturbation
    let inertia = [1.0, 2.0, 3.0];
    let omega0 = [0.05, 6.0, 0.05];
    // the errors in energy and momentum are 3.0 h² and 3.6 h² relative,
    // bounded over the run (measured at h = 2e-3, 1e-3, 5e-4: 1.2e-5,
    // 3.0e-6, 7.5e-7 in energy): h = 4e-4 meets 1e-6 with a margin of 2
    let (end, h) = (10.0, 4e-4);
    let mut m = ModelBuilder::new("Dzhanibekov flip");
    let body = m.node([0.0, 0.0, 0.0]);
    m.add(RigidBody::at(body, 1.0).inertia(inertia));
    m.analysis(
        Analysis::dynamic()
            .end_time(end)
            .time_step(h)
            .rho_infinity(1.0)
            .fixed_step(),
    );
    let model = Arc::new(m.build().expect("a valid model"));
    let mut start = model.initial_state();
    let n = model.node(body);
    start.velocity[n] = [0.0, 0.0, 0.0, omega0[0], omega0[1], omega0[2]];

    let states = run_fixed(&model, start, end, h, 1.0);

    // energy ½ Ω·JΩ and spatial angular momentum R J Ω at every step
    let j = Matrix3::from_diagonal(&Vector3::from(inertia));
    let (e0, m20) = energy_and_momentum(inertia, omega0);
    let l0 = j * Vector3::from(omega0);
    let (mut de, mut dl) = (0.0f64, 0.0f64);
    for s in &states {
        let w = Vector3::new(s.velocity[n][3], s.velocity[n][4], s.velocity[n][5]);
        let e = 0.5 * w.dot(&(j * w));
        let l = matrix(&s.q[n]) * (j * w);
        de = de.max((e / e0 - 1.0).abs());
        dl = dl.max((l - l0).norm() / l0.norm());
    }
    // ρ∞ = 1 keeps energy and momentum: limit 1e-6 relative over 10 s
    // (task target; measured 4.8e-7 and 5.7e-7)
    assert!(de < 1e-6, "energy kept to {de:e}");
    assert!(dl < 1e-6, "spatial angular momentum kept to {dl:e}");

    // Ω₂ (body frame) reverses at each flip, every T/2 with
    // T = 4K(k)/ω_p (Landau & Lifshitz §37, tests/common/rigid_body.rs)
    let period = torque_free_period(inertia, e0, m20);
    let samples: Vec<(f64, f64, f64)> = states
        .iter()
        .map(|s| (s.time, s.velocity[n][4], s.acceleration[n][4]))
        .collect();
    let flips = zero_crossings(&samples);
    assert!(flips.len() >= 3, "flips at {flips:?}, period {period}");
    let measured = 2.0 * (flips[flips.len() - 1] - flips[0]) / (flips.len() - 1) as f64;
    // limit 1 % (task target; measured 3.6e-8)
    assert!(
        (measured / period - 1.0).abs() < 0.01,
        "flip period {measured} s against the closed form {period} s"
    );
}

// ---------------------------------------------------------------------------
// heavy top
// ---------------------------------------------------------------------------

/// The heavy top of tests/common (Arnold & Brüls 2007, the problem of
/// bench/peer) as a model: a node at the centre of mass carrying the rigid
/// body, a spherical joint to the ground at the origin, constant gravity.
fn heavy_top_model() -> (Arc<Model>, State, usize) {
    let (top, start) = arnold_bruls_top();
    let mut m = ModelBuilder::new("heavy top");
    let x = top.center_of_mass;
    let node = m.node([x.x, x.y, x.z]);
    let j = top.inertia_com;
    m.add(RigidBody::at(node, top.mass).inertia([j[(0, 0)], j[(1, 1)], j[(2, 2)]]));
    m.add(Joint::spherical(node, Ground).at([0.0, 0.0, 0.0]));
    m.add(Gravity::of([top.gravity.x, top.gravity.y, top.gravity.z]).curve(CurveHandle::CONSTANT));
    let model = Arc::new(m.build().expect("a valid model"));
    let n = model.node(node);
    let mut s = model.initial_state();
    // velocity of the centre of mass Ω × X (global), angular velocity
    // material (= global at t = 0)
    let w = start.omega;
    let v = w.cross(&x);
    s.velocity[n] = [v.x, v.y, v.z, w.x, w.y, w.z];
    (model, s, n)
}

/// The span of the heavy-top runs (s).
const TOP_END: f64 = 1.0;

/// The errors of the top at `t = TOP_END`, run at fixed step `h` with ρ∞ =
/// `rho`: centre of mass (m) and orientation (rad) against RK4.
fn heavy_top_errors(h: f64, rho: f64, reference: &BodyState, top: &HeavyTop) -> (f64, f64) {
    heavy_top_errors_at(TOP_END, h, rho, reference, top)
}

/// The errors of the top at `end` (see [`heavy_top_errors`]).
fn heavy_top_errors_at(
    end: f64,
    h: f64,
    rho: f64,
    reference: &BodyState,
    top: &HeavyTop,
) -> (f64, f64) {
    heavy_top_errors_in(end, h, rho, reference, top, AngularVelocities::Material)
}

/// [`heavy_top_errors_at`] with the scheme's angular velocities in `frame`.
fn heavy_top_errors_in(
    end: f64,
    h: f64,
    rho: f64,
    reference: &BodyState,
    top: &HeavyTop,
    frame: AngularVelocities,
) -> (f64, f64) {
    let (model, start, n) = heavy_top_model();
    let states = run_fixed_in(&model, start, end, h, rho, frame);
    let last = states.last().unwrap();
    let com = last.x[n];
    let com_ref = top.com(reference);
    let q: UnitQuaternion<f64> = last.q[n];
    let angle = (reference.orientation.inverse() * q).angle();
    ((Vector3::new(com.x, com.y, com.z) - com_ref).norm(), angle)
}

#[test]
fn heavy_top_follows_an_independent_integration_with_second_order_convergence() {
    let (top, start) = arnold_bruls_top();
    // RK4 at 5 µs over 1 s (|Ω| h ≈ 7.5e-4): checked against RK4 at twice
    // the step, the reference is converged far below the errors measured
    let reference = top.integrate(start, TOP_END, 200_000);
    let coarse = top.integrate(start, TOP_END, 100_000);
    let reference_error = (reference.orientation.inverse() * coarse.orientation).angle();
    assert!(
        reference_error < 1e-10,
        "RK4 reference moves by {reference_error:e} rad"
    );

    // ρ∞ = 0.9: with ρ∞ = 1 the index-3 multiplier of the spherical joint
    // is not damped (the trapezoidal rule is unstable on index-3
    // constraints, Cardona & Géradin 1989): without the velocity
    // projection (docs/theory.md D13) the Newton iterations per step grow
    // from 2 to 6 by t = 0.75 s at h = 5e-5, the steps are cut from
    // t ≈ 0.77 s and the run fails at t ≈ 0.95 s (measured); ρ∞ = 1 with
    // the projection is the next test
    let rho = 0.9;
    // the error of the method at 1 s is ≈ 10.5 h² rad (measured: 1.7e-3,
    // 4.2e-4, 1.05e-4, 2.6e-5, 6.6e-6 rad at h = 4e-4 … 2.5e-5), so
    // h = 2.5e-5 meets 1e-5 rad (task target) with a margin of 1.5; Newton's
    // tolerances 1e-10 are 1e5 times below the error they are compared with
    let h_fine = 2.5e-5;
    let (e_com, e_rot) = heavy_top_errors(h_fine, rho, &reference, &top);
    assert!(
        e_com < 1e-5 && e_rot < 1e-5,
        "at h = {h_fine}: {e_com:e} m, {e_rot:e} rad"
    );

    // convergence: the error of the orientation at 1 s against h at four
    // fixed steps, slope of the least-squares line in log–log 2 ± 0.1
    // (second order of the Lie-group generalised-α, Brüls, Cardona &
    // Arnold 2012, §4)
    let steps = [2e-4, 1e-4, 5e-5, h_fine];
    let errors: Vec<f64> = steps
        .iter()
        .map(|&h| {
            if h == h_fine {
                e_rot
            } else {
                heavy_top_errors(h, rho, &reference, &top).1
            }
        })
        .collect();
    let slope = log_log_slope(&steps, &errors);
    assert!(
        (slope - 2.0).abs() < 0.1,
        "errors {errors:?} at {steps:?}: slope {slope}"
    );
}

#[test]
fn heavy_top_at_rho_one_with_velocity_projection_keeps_second_order() {
    // ρ∞ = 1 (no numerical dissipation): the velocities are projected on
    // the velocity constraints after each step (docs/theory.md D13), which
    // stops the growth of the parasitic multiplier mode that failed the
    // run at t ≈ 0.95 s without it
    let end = 2.0;
    let (top, start) = arnold_bruls_top();
    // RK4 at 5 µs over 2 s, against RK4 at twice the step
    let reference = top.integrate(start, end, 400_000);
    let coarse = top.integrate(start, end, 200_000);
    let reference_error = (reference.orientation.inverse() * coarse.orientation).angle();
    assert!(
        reference_error < 1e-10,
        "RK4 reference moves by {reference_error:e} rad"
    );
    let rho = 1.0;
    // the error of the method at 2 s is ≈ 3.6e4 h² rad (measured: 3.57e-4,
    // 8.9e-5 rad at h = 1e-4, 5e-5), so h = 1.6e-5 meets 1e-5 rad (task
    // target) with a margin of 1.1
    let h_fine = 1.6e-5;
    let (e_com, e_rot) = heavy_top_errors_at(end, h_fine, rho, &reference, &top);
    eprintln!("ρ∞ = 1 at h = {h_fine}: {e_com:e} m, {e_rot:e} rad after {end} s");
    assert!(
        e_com < 1e-5 && e_rot < 1e-5,
        "at h = {h_fine}: {e_com:e} m, {e_rot:e} rad"
    );
    // convergence: slope of the least-squares line in log–log 2 ± 0.1
    // (second order of the Lie-group generalised-α, Brüls, Cardona &
    // Arnold 2012, §4, kept by the projection)
    let steps = [4e-4, 2e-4, 1e-4, h_fine];
    let errors: Vec<f64> = steps
        .iter()
        .map(|&h| {
            if h == h_fine {
                e_rot
            } else {
                heavy_top_errors_at(end, h, rho, &reference, &top).1
            }
        })
        .collect();
    let slope = log_log_slope(&steps, &errors);
    eprintln!("ρ∞ = 1: errors {errors:?} at {steps:?}: slope {slope}");
    assert!(
        (slope - 2.0).abs() < 0.1,
        "errors {errors:?} at {steps:?}: slope {slope}"
    );
}

#[test]
fn heavy_top_error_is_that_of_the_lie_group_method_itself() {
    // The peer benchmark's step (bench/peer: h = 3.125e-4 s, ρ∞ = 0.9,
    // 2 s). The centre of mass of the method at this step, written
    // independently (bench/peer/study/top_lie_alpha.py, `lieproj`: the
    // same Lie-group generalised-α on R³ × SO(3) with material angular
    // velocities, node at the centre of mass, the projection D13–D13a,
    // Newton to 1e-11 on finite-difference Jacobians, NumPy), is 1.4818e-3 m
    // from DOP853 at t = 2 s; unfold's error must be that one (measured
    // 1.4818e-3 m) within 0.5 %: a change of the predictor, the initial
    // accelerations or the projection that alters the method's result
    // moves it. The error is the formulation's (docs/theory.md §15.9):
    // Exudyn's index-3 generalised-α on Euler parameters has 4.63e-4 m at
    // this step, the same method with spatial angular velocities 3.48e-4 m.
    let end = 2.0;
    let (top, start) = arnold_bruls_top();
    // RK4 at 5 µs over 2 s, against RK4 at twice the step
    let reference = top.integrate(start, end, 400_000);
    let coarse = top.integrate(start, end, 200_000);
    let reference_error = (top.com(&reference) - top.com(&coarse)).norm();
    assert!(
        reference_error < 1e-9,
        "RK4 reference moves by {reference_error:e} m"
    );
    let (e_com, _) = heavy_top_errors_at(end, 3.125e-4, 0.9, &reference, &top);
    let independent = 1.4818e-3;
    assert!(
        (e_com - independent).abs() < 5e-3 * independent,
        "centre of mass {e_com:e} m from the reference, the method's own error {independent:e} m"
    );
}

#[test]
fn heavy_top_in_the_spatial_scheme_has_the_independent_integrators_error() {
    // The same step and span as the test above, the scheme's angular
    // velocities spatial (`angular_velocities = "spatial"`,
    // docs/theory.md §15.9). The independent integrator with spatial
    // angular velocities and the projection D13–D13a
    // (bench/peer/study/top_lie_alpha.py, `spatialproj`) is 2.851e-3 m and
    // 7.095e-4 m from DOP853 at h = 6.25e-4 and 3.125e-4 s (largest
    // distance over the output times, here at t = 2 s); unfold's must be
    // those within 0.5 % (measured 2.8508e-3 and 7.0951e-4 m), half the
    // material scheme's 5.319e-3 and 1.4818e-3 m: the step for 1e-3 m is
    // Exudyn's (3.125e-4 s, 4.63e-4 m), not half of it.
    let end = 2.0;
    let (top, start) = arnold_bruls_top();
    let reference = top.integrate(start, end, 400_000);
    for (h, independent) in [(6.25e-4, 2.851e-3), (3.125e-4, 7.095e-4)] {
        let (e_com, _) =
            heavy_top_errors_in(end, h, 0.9, &reference, &top, AngularVelocities::Spatial);
        eprintln!("spatial scheme, h = {h}: {e_com:e} m (independent {independent:e} m)");
        assert!(
            (e_com - independent).abs() < 5e-3 * independent,
            "h = {h}: centre of mass {e_com:e} m from the reference, the method's own error {independent:e} m"
        );
    }
}

/// `angular_velocities` takes `material` (the default) or `spatial`; any
/// other value is an input error naming the analysis and the values.
#[test]
fn the_frame_of_the_angular_velocities_is_read_from_the_model_file() {
    let model = |line: &str| {
        format!(
            "[analysis]\ntype = \"dynamic\"\nend_time = 0.1\n{line}\n\n[[nodes]]\nid = 1\nx = [0.0, 1.0, 0.0]\n\n[[rigid_bodies]]\nid = 1\nnode = 1\nmass = 15.0\ninertia = [0.234375, 0.46875, 0.234375]\n"
        )
    };
    let frame = |line: &str| {
        let input: unfold::model::input::ModelInput =
            toml::from_str(&model(line)).expect("valid toml");
        input.analyses().map(|a| match &a[0] {
            unfold::analysis::AnalysisSettings::Dynamic(d) => d.angular_velocities,
            _ => panic!("a dynamic analysis"),
        })
    };
    assert_eq!(frame("").unwrap(), AngularVelocities::Material);
    assert_eq!(
        frame("angular_velocities = \"spatial\"").unwrap(),
        AngularVelocities::Spatial
    );
    let error = frame("angular_velocities = \"body\"")
        .expect_err("refused")
        .to_string();
    assert!(
        error.contains("analysis")
            && error.contains("unknown angular_velocities \"body\" (available: material, spatial)"),
        "{error}"
    );
}

/// Slope of the least-squares line through `(log h, log e)`.
fn log_log_slope(h: &[f64], e: &[f64]) -> f64 {
    let n = h.len() as f64;
    let (x, y): (Vec<f64>, Vec<f64>) = h.iter().zip(e).map(|(h, e)| (h.ln(), e.ln())).unzip();
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

// ---------------------------------------------------------------------------
// stiff beam pendulum
// ---------------------------------------------------------------------------

#[test]
fn stiff_beam_pendulum_from_the_horizontal_has_the_elliptic_integral_period() {
    // a 1 m beam, stiff (EI = 1e6 N·m², EA = 1e9 N: its sag and stretch
    // under weight and centrifugal load change the period by < 1e-6),
    // hinged about y at one end, released from the horizontal
    let (l, rho_a, rho_i, g) = (1.0, 1.0, 1e-6, 9.81);
    let mut m = ModelBuilder::new("stiff pendulum");
    let pin = m.node([0.0, 0.0, 0.0]);
    let tip = m.node([l, 0.0, 0.0]);
    let s = m.section(
        Section::diagonal(1e9, 4e8, 4e8, 1e6, 1e6, 1e6)
            .mass_per_length(rho_a)
            .inertia_per_length([2.0 * rho_i, rho_i, rho_i]),
    );
    m.add(BeamLine::between(pin, tip, 4, s).orientation([0.0, 0.0, 1.0]));
    m.add(Joint::revolute(pin, Ground).axis([0.0, 1.0, 0.0]));
    m.add(Gravity::of([0.0, 0.0, -g]).curve(CurveHandle::CONSTANT));
    let model = Arc::new(m.build().expect("a valid model"));
    let t = model.node(tip);

    // the rigid rod: I_O = ρA L³/3 + ρI L (consistent translational mass and
    // lumped section inertia are exact in a rigid motion, theory.md §11.3),
    // m = ρA L, d = L/2, θ₀ = 90°
    let mass = rho_a * l;
    let i_o = rho_a * l.powi(3) / 3.0 + rho_i * l;
    let period = pendulum_period(i_o, mass, 0.5 * l, g, 0.5 * PI);

    let states = run_fixed(&model, model.initial_state(), 1.3 * period, 1e-3, 0.9);
    // the tip passes x = 0 at T/4, 3T/4 and 5T/4
    let samples: Vec<(f64, f64, f64)> = states
        .iter()
        .map(|s| (s.time, s.x[t].x, s.velocity[t][0]))
        .collect();
    let crossings = zero_crossings(&samples);
    assert_eq!(crossings.len(), 3, "{crossings:?}");
    let measured = crossings[2] - crossings[0];
    eprintln!(
        "period {measured} s, elliptic integral {period} s: {:e}",
        measured / period - 1.0
    );
    // limit 1e-4 relative (task target; measured 4.3e-6). Newton
    // converges quadratically to a residual of ~1e-8 of the flux, the
    // round-off of forces ε E A |x|/L with EA = 1e9, and accepts it as its
    // round-off plateau (corrections of 1e-16 m); with a plateau judged by
    // ε of the flux alone the step was cut to 1e-6 s without end
    assert!(
        (measured / period - 1.0).abs() < 1e-4,
        "period {measured} s against 4√(L_eq/g) K(1/2) = {period} s"
    );
}

// ---------------------------------------------------------------------------
// four-bar linkage under gravity
// ---------------------------------------------------------------------------

/// A rigid link of the four-bar: node (index) at its centre of mass, mass
/// and inertia tensor about it (global frame = material frame at the
/// start).
struct Link {
    node: usize,
    mass: f64,
    inertia: Matrix3<f64>,
}

/// The four-bar linkage run for `end` s at fixed step `h` with ρ∞ = `rho`:
/// the largest joint gap, the spread of T + V relative to the largest
/// kinetic energy (the level of the total energy is arbitrary), that
/// kinetic energy, and the largest difference of the velocities of a pin
/// from its two sides.
fn four_bar(end: f64, h: f64, rho: f64) -> (f64, f64, f64, f64) {
    // crank-rocker (Grashof: 1 + 4 ≤ 4 + 2): ground pivots A = (0, 0, 0)
    // and D = (4, 0, 0), crank AB = 1, coupler BC = 4, rocker DC = 2, in
    // the x–y plane, hinges about z; slender links of 1 kg/m released from
    // rest with the crank vertical, gravity −y
    let (a, d) = (
        Vector3::<f64>::new(0.0, 0.0, 0.0),
        Vector3::<f64>::new(4.0, 0.0, 0.0),
    );
    let b = Vector3::<f64>::new(0.0, 1.0, 0.0);
    // C on |C − B| = 4, |C − D| = 2 (circle intersection, upper branch)
    let (r1, r2): (f64, f64) = (4.0, 2.0);
    let bd = d - b;
    let dist = bd.norm();
    let along = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist);
    let height = (r1 * r1 - along * along).sqrt();
    let normal = Vector3::new(-bd.y, bd.x, 0.0) / dist;
    let c = b + bd * (along / dist) + normal * height;
    let g = 9.81;

    let mut m = ModelBuilder::new("four-bar under gravity");
    let mut links = Vec::new();
    let mut handles = Vec::new();
    for (p, q) in [(a, b), (b, c), (d, c)] {
        let mid = 0.5 * (p + q);
        let len = (q - p).norm();
        let node = m.node([mid.x, mid.y, mid.z]);
        let mass = len;
        // slender rod about its centre, m L²/12 about its normals and a
        // thousandth of it about its axis e
        let i = mass * len * len / 12.0;
        let e = (q - p) / len;
        let inertia = Matrix3::identity() * i - (i - 1e-3 * i) * e * e.transpose();
        m.add(RigidBody::at(node, mass).inertia_tensor(inertia.into()));
        links.push(Link {
            node: 0,
            mass,
            inertia,
        });
        handles.push(node);
    }
    let (crank, coupler, rocker) = (handles[0], handles[1], handles[2]);
    let z = [0.0, 0.0, 1.0];
    m.add(Joint::revolute(crank, Ground).axis(z).at([a.x, a.y, a.z]));
    m.add(Joint::revolute(crank, coupler).axis(z).at([b.x, b.y, b.z]));
    m.add(Joint::revolute(coupler, rocker).axis(z).at([c.x, c.y, c.z]));
    m.add(Joint::revolute(rocker, Ground).axis(z).at([d.x, d.y, d.z]));
    m.add(Gravity::of([0.0, -g, 0.0]).curve(CurveHandle::CONSTANT));
    let model = Arc::new(m.build().expect("a valid model"));
    for (link, h) in links.iter_mut().zip(&handles) {
        link.node = model.node(*h);
    }

    // the pins of each pair of links, from both sides (material offsets of
    // the reference configuration carried by each node's rotation)
    let reference: Vec<Vector3<f64>> = links
        .iter()
        .map(|link| {
            let x = model.reference_x[link.node];
            Vector3::new(x.x, x.y, x.z)
        })
        .collect();
    let pin = |s: &State, k: usize, p: &Vector3<f64>| {
        let nd = links[k].node;
        let x = s.x[nd];
        Vector3::new(x.x, x.y, x.z) + matrix(&s.q[nd]) * (p - reference[k])
    };
    // velocity of a pin: ẋ + R (Ω × (p − X)), Ω material
    let pin_velocity = |s: &State, k: usize, p: &Vector3<f64>| {
        let nd = links[k].node;
        let v = &s.velocity[nd];
        let w = Vector3::new(v[3], v[4], v[5]);
        Vector3::new(v[0], v[1], v[2]) + matrix(&s.q[nd]) * w.cross(&(p - reference[k]))
    };
    let states = run_fixed(&model, model.initial_state(), end, h, rho);
    let (mut violation, mut e_min, mut e_max, mut t_max) = (0.0f64, f64::MAX, f64::MIN, 0.0f64);
    let mut rate = 0.0f64;
    for s in &states {
        let gaps = [
            pin(s, 0, &a) - a,
            pin(s, 0, &b) - pin(s, 1, &b),
            pin(s, 1, &c) - pin(s, 2, &c),
            pin(s, 2, &d) - d,
        ];
        for gap in gaps {
            violation = violation.max(gap.norm());
        }
        let rates = [
            pin_velocity(s, 0, &a),
            pin_velocity(s, 0, &b) - pin_velocity(s, 1, &b),
            pin_velocity(s, 1, &c) - pin_velocity(s, 2, &c),
            pin_velocity(s, 2, &d),
        ];
        for r in rates {
            rate = rate.max(r.norm());
        }
        // T + V from the state: ½ m|v|² + ½ Ω·J Ω − m g·x
        let mut kinetic = 0.0;
        let mut potential = 0.0;
        for link in &links {
            let v = &s.velocity[link.node];
            let w = Vector3::new(v[3], v[4], v[5]);
            kinetic += 0.5 * link.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                + 0.5 * w.dot(&(link.inertia * w));
            potential += link.mass * g * s.x[link.node].y;
        }
        let e = kinetic + potential;
        e_min = e_min.min(e);
        e_max = e_max.max(e);
        t_max = t_max.max(kinetic);
    }
    (violation, (e_max - e_min) / t_max, t_max, rate)
}

#[test]
fn four_bar_under_gravity_keeps_its_constraints_and_its_energy() {
    // ρ∞ = 0.95. With ρ∞ = 1 and without the velocity projection
    // (docs/theory.md D13) the spread grows as the step shrinks
    // (measured: 2.7e-3 at h = 4e-3, 7.4e-3 at 2e-3, and Newton fails at
    // t = 9.8 s at 1e-3): the undamped parasitic mode of the index-3
    // multipliers, for which the trapezoidal rule (ρ∞ = 1) is unstable
    // (Cardona & Géradin 1989), not an error of the motion (ρ∞ = 1 with
    // the projection is the next test). With ρ∞ = 0.95
    // the spread is the method's O(h²) error: 7.6e-4, 1.9e-4, 4.8e-5 at
    // h = 4e-3, 2e-3, 1e-3 (measured)
    let rho = 0.95;
    let (violation, drift, t_max, _) = four_bar(10.0, 1e-3, rho);
    let (_, drift_coarse, _, _) = four_bar(10.0, 2e-3, rho);
    // constraints at round-off, without drift over 10 s: limit 1e-10 of the
    // link length (index-3 constraints solved at each step to the Newton
    // tolerance 1e-10; measured 8e-14)
    assert!(violation < 1e-10, "largest joint gap {violation:e} m");
    // energy: limit 1e-4 of the largest kinetic energy at h = 1e-3 (task
    // target)
    assert!(t_max > 1.0, "the linkage moves: T_max = {t_max}");
    assert!(drift < 1e-4, "energy spread {drift:e} of T_max = {t_max} J");
    // and it is the O(h²) error: halving h divides it by 4 (3 to 5)
    let ratio = drift_coarse / drift;
    assert!(
        (3.0..5.0).contains(&ratio),
        "energy spread {drift_coarse:e} at h = 2e-3, {drift:e} at 1e-3"
    );
}

#[test]
fn four_bar_at_rho_one_keeps_its_constraints_and_its_energy() {
    // ρ∞ = 1, no numerical dissipation: the velocities are projected on
    // the velocity constraints after each step (docs/theory.md D13).
    // Without it the multipliers grew from 40 to 4e5 by t = 9 s and Newton
    // failed at t = 9.805 s (measured)
    let rho = 1.0;
    let (violation, drift, t_max, rate) = four_bar(10.0, 1e-3, rho);
    let (_, drift_coarse, _, _) = four_bar(10.0, 4e-3, rho);
    eprintln!("ρ∞ = 1: joint gap {violation:e} m, pin velocity gap {rate:e} m/s, energy spread {drift:e} (h = 1e-3), {drift_coarse:e} (4e-3)");
    // constraints at round-off over 10 s: limit 1e-10 of the link length
    // (Newton tolerance 1e-10; measured 7.9e-14)
    assert!(violation < 1e-10, "largest joint gap {violation:e} m");
    // the velocity constraints after the projection: limit 1e-9 of the
    // speed scale √(2 T_max) (the central difference of D13 gives Φ̇ to
    // ~2e-11 of the velocities; measured 6.1e-10 m/s against 11 m/s;
    // without the projection, at ρ∞ = 0.95, 3.3e-5 m/s)
    let speed = (2.0 * t_max).sqrt();
    assert!(
        rate < 1e-9 * speed,
        "pin velocities differ by {rate:e} m/s (speed scale {speed} m/s)"
    );
    // energy: limit 1e-4 of the largest kinetic energy at h = 1e-3 (task
    // target; measured 4.8e-5)
    assert!(t_max > 1.0, "the linkage moves: T_max = {t_max}");
    assert!(drift < 1e-4, "energy spread {drift:e} of T_max = {t_max} J");
    // the O(h²) error of the method, not a drift: h × 4 multiplies it by
    // 16 (12 to 20)
    let ratio = drift_coarse / drift;
    assert!(
        (12.0..20.0).contains(&ratio),
        "energy spread {drift_coarse:e} at h = 4e-3, {drift:e} at 1e-3"
    );
}

// ---------------------------------------------------------------------------
// flexible beam pendulum
// ---------------------------------------------------------------------------

/// The flexible pendulum of bench/peer (1 m, EA 4e5 N, GA 1.5e5 N, GJ 0.8,
/// EI 1 N·m², ρA 1 kg/m, hinged about y at x = 0, from the horizontal).
fn flexible_pendulum(elements: usize) -> Arc<Model> {
    let mut m = ModelBuilder::new("flexible pendulum");
    let pin = m.node([0.0, 0.0, 0.0]);
    let tip = m.node([1.0, 0.0, 0.0]);
    let rho_i = 1.0 / 4.0e5;
    let s = m.section(
        Section::diagonal(4.0e5, 1.5e5, 1.5e5, 0.8, 1.0, 1.0)
            .mass_per_length(1.0)
            .inertia_per_length([2.0 * rho_i, rho_i, rho_i]),
    );
    m.add(BeamLine::between(pin, tip, elements, s).orientation([0.0, 0.0, 1.0]));
    m.add(Joint::revolute(pin, Ground).axis([0.0, 1.0, 0.0]));
    m.add(Gravity::of([0.0, 0.0, -9.81]).curve(CurveHandle::CONSTANT));
    Arc::new(m.build().expect("a valid model"))
}

/// Runs step by step at fixed steps `h` with ρ∞ = `rho`: at every
/// accepted state, `T + V` computed from the state by
/// [`unfold::analysis::energy::energies`] and the balance error the
/// analysis reports (`(T + V) − (T₀ + V₀) − W + D`, here with `W = D = 0`).
fn energy_history(model: &Arc<Model>, end_time: f64, h: f64, rho: f64) -> Vec<(f64, f64)> {
    let mut settings = DynamicSettings::new(end_time, h).fixed_step();
    settings.rho_infinity = rho;
    settings.residual_tolerance = 1e-10;
    settings.displacement_tolerance = 1e-10;
    settings.rotation_tolerance = 1e-10;
    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let mut history = History::default();
    let mut out = Vec::new();
    let mut step = analysis.start(model.initial_state(), &mut history);
    while let unfold::analysis::Step::Increment(_) = step {
        let state = analysis.state().expect("started");
        let total = unfold::analysis::energy::energies(model, state).total();
        out.push((total, analysis.energies().expect("started").balance_error));
        step = analysis.advance(&mut history);
    }
    let outcome = analysis.finish();
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    assert!((outcome.time - end_time).abs() < 1e-9 * end_time);
    out
}

#[test]
fn flexible_pendulum_energy_balance() {
    // 20 elements; h = 1 ms resolves the first bending mode (≈ 15 rad/s
    // when hanging, stiffened by the swing: ωh ≈ 0.02-0.05); 2 s is past
    // the first passage through the bottom, where the beam whips
    let model = flexible_pendulum(20);
    let (end, h) = (2.0, 1e-3);
    // the scale: the weight's work down to the hanging position,
    // m g L/2 = 4.905 J (the total energy is 0 at the start, the level of
    // V being the pin's)
    let scale = 1.0 * 9.81 * 0.5;

    // ρ∞ = 1: no numerical dissipation, the balance error is the method's
    // O(h²) error and stays bounded
    let conservative = energy_history(&model, end, h, 1.0);
    let e0 = conservative[0].0;
    let drift = conservative
        .iter()
        .map(|(e, _)| (e - e0).abs() / scale)
        .fold(0.0, f64::max);
    // limit 1e-4 of m g L/2 over 2 s, 7 times the 1.3e-5 measured (task
    // target: bounded, not growing with the swings)
    assert!(drift < 1e-4, "ρ∞ = 1: energy drift {drift:e} of m g L/2");

    // ρ∞ < 1: the energy the method takes out is what the balance reports
    // (no loads, no dampers: W = D = 0, and the pin's reaction does no
    // work), it is only taken out (the balance error never rises above
    // round-off), and more of it the lower ρ∞
    let lost = |rho: f64| {
        let history = energy_history(&model, end, h, rho);
        let e0 = history[0].0;
        let mut worst_account = 0.0f64;
        let mut highest = f64::MIN;
        for &(e, balance) in &history {
            worst_account = worst_account.max((balance - (e - e0)).abs() / scale);
            highest = highest.max(balance / scale);
        }
        assert!(
            worst_account < 1e-12,
            "ρ∞ = {rho}: balance against ΔT + ΔV {worst_account:e}"
        );
        assert!(
            highest < 1e-12,
            "ρ∞ = {rho}: the balance rises to {highest:e} of m g L/2"
        );
        -history.last().unwrap().1 / scale
    };
    let (lost_09, lost_05) = (lost(0.9), lost(0.5));
    eprintln!("dissipated: {lost_09:e} (ρ∞ = 0.9), {lost_05:e} (ρ∞ = 0.5) of m g L/2");
    assert!(
        0.0 < lost_09 && lost_09 < lost_05,
        "dissipated {lost_09:e} (ρ∞ = 0.9), {lost_05:e} (ρ∞ = 0.5)"
    );
    // ρ∞ = 0.9: the dissipation stays below 1 % over 2 s (task target)
    assert!(
        lost_09 < 0.01,
        "ρ∞ = 0.9: dissipated {lost_09:e} of m g L/2"
    );
}

// ---------------------------------------------------------------------------
// cantilever free vibration
// ---------------------------------------------------------------------------

#[test]
fn cantilever_free_vibration_has_the_modal_and_euler_bernoulli_frequency() {
    // 1 m cantilever, EI = 1 N·m², ρA = 1 kg/m, shear and axial stiffness
    // 1e6 (Euler–Bernoulli limit), negligible section inertia; 12 elements
    // put the first frequency of the model within 0.1 % of Euler–Bernoulli
    // (measured below), so the test compares the response with both
    let (l, ei, rho_a) = (1.0f64, 1.0f64, 1.0f64);
    let n_el = 12;
    let mut m = ModelBuilder::new("cantilever free vibration");
    let root = m.node([0.0, 0.0, 0.0]);
    let tip = m.node([l, 0.0, 0.0]);
    let s = m.section(
        Section::diagonal(1e6, 1e6, 1e6, 1.0, ei, ei)
            .mass_per_length(rho_a)
            .inertia_per_length([2e-9, 1e-9, 1e-9]),
    );
    let line = m.add(BeamLine::between(root, tip, n_el, s).orientation([0.0, 0.0, 1.0]));
    m.fix(root, Dofs::ALL);
    let model = Arc::new(m.build().expect("a valid model"));

    // the modal analysis of the same model about its reference state: the
    // two lowest modes bend about y and z with the same frequency
    let modal = ModalAnalysis::new(model.clone(), ModalSettings::lowest(2))
        .run(model.initial_state(), &mut NoObserver);
    assert!(modal.error.is_none(), "{:?}", modal.error);

    // start at rest in the first mode bending in x–z, tip deflection
    // 1e-3 L (linear range). The mode shape of the model, not the
    // Euler–Bernoulli one: the latter's slopes disagree with the element
    // chords by O(h_e²), which the shear stiffness (GA = 1e6) against the
    // small section inertia turns into rotational accelerations of ~1e13
    // rad/s², a transient no step of this size can follow
    let t = model.node(tip);
    let (omega_modal, shape) = modal
        .modes
        .iter()
        .find(|m| m.shape[t][2].abs() > 10.0 * m.shape[t][1].abs())
        .map(|m| (m.angular_frequency, &m.shape))
        .expect("a mode bending in x–z among the two lowest");
    let scale = 1e-3 * l / shape[t][2];
    let mut start = model.initial_state();
    for &node in &line.nodes {
        let i = model.node(node);
        let u = shape[i];
        start.x[i] += so3::Vec3::new(u[0], u[1], u[2]) * scale;
        start.q[i] = so3::exp(&(so3::Vec3::new(u[3], u[4], u[5]) * scale)) * start.q[i];
    }

    // Euler–Bernoulli: ω₁ = (β₁L)² √(EI/(ρA L⁴)), β₁L = 1.875104
    // (Blevins, Formulas for natural frequency and mode shape, table 8-1)
    let beta_l = 1.875_104_068_711_961f64;
    let omega = beta_l * beta_l * (ei / (rho_a * l.powi(4))).sqrt();
    let period = 2.0 * PI / omega;
    // 100 steps a period: the period elongation of generalised-α at
    // ωh = 0.063 is ~3e-4 (Chung & Hulbert 1993), far below 1 %
    let states = run_fixed(&model, start, 2.3 * period, period / 100.0, 0.9);
    let samples: Vec<(f64, f64, f64)> = states
        .iter()
        .map(|s| (s.time, s.x[t].z, s.velocity[t][2]))
        .collect();
    let crossings = zero_crossings(&samples);
    assert!(crossings.len() >= 4, "{crossings:?}");
    let measured =
        2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    let against_modal = measured * omega_modal / (2.0 * PI) - 1.0;
    let against_beam = measured / period - 1.0;
    let modal_against_beam = omega_modal / omega - 1.0;
    eprintln!(
        "period {measured} s: {against_modal:e} against the modal analysis, {against_beam:e} against Euler–Bernoulli (modal {modal_against_beam:e})"
    );
    // limits 1 % (task target)
    assert!(
        against_modal.abs() < 0.01,
        "period {measured} s against the modal analysis {} s",
        2.0 * PI / omega_modal
    );
    assert!(
        against_beam.abs() < 0.01,
        "period {measured} s against Euler–Bernoulli {period} s"
    );
}

// ---------------------------------------------------------------------------
// step control under a sudden load
// ---------------------------------------------------------------------------

/// Accepted step sizes with their end times, and the tip deflection.
struct Steps {
    tip: usize,
    steps: Vec<(f64, f64, f64)>,
    cutbacks: usize,
}

impl Observer for Steps {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.steps.push((info.time, info.step, state.x[self.tip].z));
        Ok(())
    }
    fn cutback(&mut self, _: &unfold::analysis::CutbackInfo) {
        self.cutbacks += 1;
    }
}

#[test]
fn step_controller_cuts_at_a_sudden_load_and_grows_back() {
    // the cantilever of the free-vibration test in 6 elements (T₁ ≈ 1.79
    // s), section inertia ρA r² with r² = EI/EA, at rest; a tip force of
    // 0.03 N along z (static deflection F L³/3EI = 1 cm) switched on over
    // 1 ms at t = 1 s
    let (l, ei) = (1.0f64, 1.0f64);
    let mut m = ModelBuilder::new("cantilever under a sudden load");
    let root = m.node([0.0, 0.0, 0.0]);
    let tip = m.node([l, 0.0, 0.0]);
    let s = m.section(
        Section::diagonal(1e6, 1e6, 1e6, 1.0, ei, ei)
            .mass_per_length(1.0)
            .inertia_per_length([2e-6, 1e-6, 1e-6]),
    );
    m.add(BeamLine::between(root, tip, 6, s).orientation([0.0, 0.0, 1.0]));
    m.fix(root, Dofs::ALL);
    let (t_load, rise) = (1.0, 1e-3);
    let curve = m.curve(LoadCurve::points([
        [0.0, 0.0],
        [t_load, 0.0],
        [t_load + rise, 1.0],
    ]));
    m.add(Load::force(tip, [0.0, 0.0, 0.03]).curve(curve));
    let model = Arc::new(m.build().expect("a valid model"));
    let t = model.node(tip);
    let end = 3.0;
    let checks = vec![1.5, 2.0, 2.5, 3.0];

    // adaptive: first step 0.05 s, error tolerance 1e-4 (the default);
    // ρ∞ = 0.6 damps the axial and shear modes the load excites through
    // the geometric coupling, which no step of interest resolves
    let rho = 0.6;
    let mut settings = DynamicSettings::new(end, 0.05).rho_infinity(rho);
    settings.output_times = checks.clone();
    let mut adaptive = Steps {
        tip: t,
        steps: Vec::new(),
        cutbacks: 0,
    };
    let outcome =
        DynamicAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut adaptive);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);

    // the step before the load, the smallest around it, the largest after
    let before = adaptive
        .steps
        .iter()
        .filter(|s| s.0 < t_load && s.0 > 0.5)
        .map(|s| s.1)
        .fold(0.0, f64::max);
    let smallest = adaptive
        .steps
        .iter()
        .filter(|s| s.0 >= t_load && s.0 < t_load + 0.2)
        .map(|s| s.1)
        .fold(f64::MAX, f64::min);
    let after = adaptive
        .steps
        .iter()
        .filter(|s| s.0 > t_load + 0.5)
        .map(|s| s.1)
        .fold(0.0, f64::max);
    eprintln!(
        "steps {} rejected {} (error {}) cutbacks {}: h before {before:e}, smallest {smallest:e}, after {after:e}",
        outcome.steps, outcome.rejected_steps, outcome.error_rejections, adaptive.cutbacks
    );
    // the load cuts the step (from 0.4 s at rest) to the time of its rise
    // (at most 2 ms; measured 0.91 ms, 0.28 ms before the filter and the
    // metric of the mass of docs/theory.md §15.5) and the controller grows
    // it back, without failing, to what the motion after the load needs:
    // at least 3 times its smallest (measured 4.3 ms, 4.7 times; 1.1 ms
    // before). Not to the step before: the load excites the beam's higher
    // bending modes, which nothing damps and the error estimate follows
    // where the step resolves them
    assert!(
        outcome.error_rejections + outcome.cutbacks > 0,
        "the load was not felt"
    );
    // the estimate fluctuates by up to 2 from step to step on this ringing
    // beam; the PI controller follows its trend (docs/theory.md §15.5):
    // measured 720 steps, 101 rejected by the estimate (12 % of the
    // attempts; 3053 and 464 before the filter and the metric of the mass,
    // 3135 and 1078, 34 %, with the elementary controller), none cut back
    // by Newton. At most 20 % of the attempts
    let attempts = outcome.steps + outcome.rejected_steps;
    assert!(
        5 * outcome.rejected_steps <= attempts,
        "{} of {attempts} attempts rejected",
        outcome.rejected_steps
    );
    assert!(smallest <= 2.0 * rise, "smallest step {smallest:e} s");
    assert!(
        after >= 3.0 * smallest,
        "step {after:e} s after the load, {smallest:e} at it"
    );

    // the response against fixed steps of 0.5 ms at the output times
    let mut settings = DynamicSettings::new(end, 5e-4)
        .fixed_step()
        .rho_infinity(rho);
    settings.output_times = checks.clone();
    let mut fixed = Steps {
        tip: t,
        steps: Vec::new(),
        cutbacks: 0,
    };
    let outcome =
        DynamicAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut fixed);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    let at = |run: &Steps, time: f64| {
        run.steps
            .iter()
            .find(|s| (s.0 - time).abs() < 1e-9)
            .map(|s| s.2)
            .expect("an output time")
    };
    let static_deflection = 0.03 * l.powi(3) / (3.0 * ei);
    let worst = checks
        .iter()
        .map(|&c| (at(&adaptive, c) - at(&fixed, c)).abs() / static_deflection)
        .fold(0.0, f64::max);
    eprintln!("adaptive against fixed: {worst:e} of the static deflection");
    // limit 1e-3 of the static deflection (measured 7.5e-4; 1.3e-4 with
    // the 3053 steps of the estimate before the filter and the metric of
    // the mass, which measured the section rotations as angles): the
    // local error tolerance 1e-4 of the step's motion, accumulated over
    // the steps
    assert!(
        worst < 1e-3,
        "adaptive against fixed steps: {worst:e} of F L³/3EI"
    );
}

// ---------------------------------------------------------------------------
// conditioning of the iteration matrix
// ---------------------------------------------------------------------------

/// 2-norm condition number `σ_max/σ_min` of a sparse matrix, by the
/// dense SVD (nalgebra).
fn condition_number(matrix: &unfold::linalg::SparseMatrix) -> f64 {
    let n = matrix.dim();
    let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
    for (row, col, v) in matrix.entries() {
        dense[(row, col)] += v;
    }
    let sigma = dense.singular_values();
    sigma.max() / sigma.min()
}

#[test]
fn scaled_iteration_matrix_stays_conditioned_as_the_step_shrinks() {
    // the flexible pendulum in 4 elements (30 unknowns and the 5
    // multipliers of the hinge) at its start
    let model = flexible_pendulum(4);
    let settings = DynamicSettings::new(1.0, 1e-3);
    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let mut history = History::default();
    analysis.start(model.initial_state(), &mut history);
    let steps = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6];
    let (mut scaled, mut unscaled) = (Vec::new(), Vec::new());
    for &h in &steps {
        scaled.push(condition_number(
            &analysis.iteration_matrix(h, true).unwrap(),
        ));
        unscaled.push(condition_number(
            &analysis.iteration_matrix(h, false).unwrap(),
        ));
    }
    eprintln!("h {steps:?}\nscaled {scaled:.3?}\nunscaled {unscaled:.3?}");
    // scaled (D8): bounded as h → 0. At h = 1e-2 the stiffness dominates
    // and the condition number is its own (measured 1.4e7); below, β′M
    // and the scaled constraint blocks both grow as 1/h², and over
    // h = 1e-4 … 1e-6 it stays within a factor 2 (measured 4.6e5 to 7.7e5)
    let small = &scaled[2..];
    let (lo, hi) = small
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), &c| (lo.min(c), hi.max(c)));
    assert!(hi / lo < 2.0, "scaled: {scaled:.3?} at {steps:?}");
    assert!(hi <= scaled[0], "scaled: {scaled:.3?} at {steps:?}");
    // unscaled: the multiplier blocks keep the model's k while β′M grows
    // as 1/h², so σ_max ∝ 1/h² and σ_min ∝ k²h²: the condition number
    // grows as 1/h⁴ (log–log slope over the last decade 4 ± 0.2; measured
    // 4.0), 1e11 at h = 1e-6
    let slope = -log_log_slope(&steps[3..], &unscaled[3..]);
    assert!(
        (slope - 4.0).abs() < 0.2,
        "unscaled: {unscaled:.3?}, slope {slope}"
    );
    assert!(
        unscaled[4] > 1e5 * scaled[4],
        "unscaled {unscaled:.3?}, scaled {scaled:.3?}"
    );
}
