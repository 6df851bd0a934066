//! Checks of the independent references of tests/common (elliptic
//! functions, torque-free and heavy-top rigid bodies, periods by
//! quadrature) against known values, before they are used to validate the
//! dynamic analysis.

mod common;

use std::f64::consts::{FRAC_PI_2, PI};

use common::elliptic::{complete_k, jacobi};
use common::quadrature::{oscillation_period, pendulum_period, pendulum_period_by_quadrature};
use common::rigid_body::{
    arnold_bruls_top, energy_and_momentum, torque_free_period, BodyState, HeavyTop,
};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Γ(1/4) (Abramowitz & Stegun table 6.1: 3.6256099082219083119).
const GAMMA_QUARTER: f64 = 3.625_609_908_221_908;

#[test]
fn complete_elliptic_integral_known_values() {
    // K(0) = π/2 exactly
    assert!((complete_k(0.0) - FRAC_PI_2).abs() < 1e-15);
    // K(1/2) = Γ(1/4)²/(4√π) = 1.8540746773013719 (the lemniscatic case,
    // A&S 17.3.31 with Legendre's relation); limit 4e-16 (round-off)
    let lemniscatic = GAMMA_QUARTER * GAMMA_QUARTER / (4.0 * PI.sqrt());
    assert!((complete_k(0.5) - lemniscatic).abs() < 4e-16);
    // K(0.9) = 2.5780921133481733 and K(1 − 1e-6) = 8.2940514636010622
    // (mpmath.ellipk at 30 digits); relative limit 1e-14
    assert!((complete_k(0.9) / 2.578_092_113_348_173_3 - 1.0).abs() < 1e-14);
    assert!((complete_k(0.999_999) / 8.294_051_463_601_062 - 1.0).abs() < 1e-14);
}

#[test]
fn jacobi_elliptic_functions_known_values() {
    // (m, u, sn, cn, dn) from mpmath.ellipfun at 30 digits; limit 1e-14
    let table = [
        (
            0.3,
            0.5,
            0.474_215_622_711_820_6,
            0.880_408_736_426_462_4,
            0.965_678_964_745_951_2,
        ),
        (
            0.3,
            1.7,
            0.999_932_478_587_555_9,
            0.011_620_596_617_518_459,
            0.836_684_236_423_589,
        ),
        (
            0.7,
            0.5,
            0.467_292_005_359_033_6,
            0.884_103_037_958_547_5,
            0.920_405_740_534_723_7,
        ),
        (
            0.7,
            1.7,
            0.978_246_780_750_654_9,
            0.207_444_537_047_809_83,
            0.574_563_543_192_296_7,
        ),
        (
            0.99,
            0.5,
            0.462_289_399_299_146_9,
            0.886_729_108_181_091_5,
            0.887_933_345_574_248_4,
        ),
        (
            0.99,
            1.7,
            0.937_203_883_447_315_2,
            0.348_781_996_168_482_3,
            0.361_154_249_653_466_66,
        ),
    ];
    for (m, u, sn, cn, dn) in table {
        let (s, c, d) = jacobi(u, m);
        assert!((s - sn).abs() < 1e-14, "sn({u} | {m}) = {s}, not {sn}");
        assert!((c - cn).abs() < 1e-14, "cn({u} | {m}) = {c}, not {cn}");
        assert!((d - dn).abs() < 1e-14, "dn({u} | {m}) = {d}, not {dn}");
    }
    // limits m = 0 (sin, cos, 1) and m = 1 (tanh, sech, sech), A&S 16.6
    let (s, c, d) = jacobi(0.8, 0.0);
    assert!((s - 0.8f64.sin()).abs() < 1e-16 && (c - 0.8f64.cos()).abs() < 1e-16 && d == 1.0);
    let (s, c, d) = jacobi(0.8, 1.0);
    assert!((s - 0.8f64.tanh()).abs() < 1e-16 && (c - 1.0 / 0.8f64.cosh()).abs() < 1e-16);
    assert!((d - c).abs() < 1e-16);
    // the quarter period: sn(K) = 1, cn(K) = 0, dn(K) = √(1 − m) (A&S
    // 16.5), and sn(K/2) = 1/√(1 + √(1 − m)) (A&S 16.5.2); limit 1e-13
    for m in [0.1, 0.5, 0.9, 0.999] {
        let k = complete_k(m);
        let (s, c, d) = jacobi(k, m);
        assert!((s - 1.0).abs() < 1e-13, "sn(K | {m}) = {s}");
        assert!(c.abs() < 1e-13, "cn(K | {m}) = {c}");
        assert!((d - (1.0 - m).sqrt()).abs() < 1e-13, "dn(K | {m}) = {d}");
        let (s, _, _) = jacobi(0.5 * k, m);
        assert!((s - 1.0 / (1.0 + (1.0 - m).sqrt()).sqrt()).abs() < 1e-13);
    }
    // sn² + cn² = 1, dn² + m sn² = 1 (A&S 16.9.1) to round-off (1e-14), and
    // d sn/du = cn dn (A&S 16.16.1) by central differences at step 1e-5
    // (truncation ~1e-11, round-off ~1e-11); limit 1e-9
    for m in [0.05, 0.5, 0.95] {
        for i in 0..20 {
            let u = -3.0 + 0.37 * i as f64;
            let (s, c, d) = jacobi(u, m);
            assert!((s * s + c * c - 1.0).abs() < 1e-14);
            assert!((d * d + m * s * s - 1.0).abs() < 1e-14);
            let e = 1e-5;
            let slope = (jacobi(u + e, m).0 - jacobi(u - e, m).0) / (2.0 * e);
            assert!((slope - c * d).abs() < 1e-9, "d sn/du at u = {u}, m = {m}");
        }
    }
}

#[test]
fn pendulum_period_by_quadrature_and_in_closed_form_agree() {
    // small amplitude: 2π √(L/g) (1 + θ₀²/16) (L&L §11 problem 1,
    // next term 11θ₀⁴/3072 = 4e-11 at θ₀ = 0.01); limit 1e-9 relative
    let (l, g): (f64, f64) = (1.3, 9.81);
    let small = 2.0 * PI * (l / g).sqrt() * (1.0 + 0.01f64.powi(2) / 16.0);
    let t = pendulum_period_by_quadrature(l * l, 1.0, l, g, 0.01);
    assert!((t / small - 1.0).abs() < 1e-9, "{t} against {small}");
    // large amplitudes, physical pendulum (I_O = m L²/3, d = L/2): the
    // quadrature of the energy equation against 4√(L_eq/g) K(sin²(θ₀/2)),
    // two independent computations; limit 1e-11 relative (the quadrature's
    // tolerance 1e-12 and its round-off near the turning points)
    for theta0 in [0.3, FRAC_PI_2, 2.5, 3.1] {
        let (m, i_o, d) = (2.0, 2.0 * l * l / 3.0, 0.5 * l);
        let q = pendulum_period_by_quadrature(i_o, m, d, g, theta0);
        let k = pendulum_period(i_o, m, d, g, theta0);
        assert!(
            (q / k - 1.0).abs() < 1e-11,
            "θ₀ = {theta0}: {q} against {k}"
        );
    }
    // a harmonic oscillator V = ½ k x², m: T = 2π √(m/k) at any amplitude;
    // limit 1e-11
    let t = oscillation_period(|x| 0.5 * 7.0 * (0.4 - x) * (0.4 + x), 3.0, -0.4, 0.4, 1e-12);
    assert!((t / (2.0 * PI * (3.0f64 / 7.0).sqrt()) - 1.0).abs() < 1e-11);
}

/// Times at which `f` changes sign between successive samples, by linear
/// interpolation.
fn sign_changes(times: &[f64], values: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..values.len() {
        let (a, b) = (values[i - 1], values[i]);
        if a * b < 0.0 {
            out.push(times[i - 1] + (times[i] - times[i - 1]) * a / (a - b));
        }
    }
    out
}

#[test]
fn torque_free_flip_period_matches_an_integration_of_euler_equations() {
    // a torque-free asymmetric body (I = 1, 2, 3) spun about its
    // intermediate axis with small perturbations, on either side of the
    // separatrix M² = 2EI₂; Euler's equations by RK4 (HeavyTop without
    // gravity, fixed point at the centre of mass)
    let inertia = [1.0, 2.0, 3.0];
    for omega0 in [[0.05, 6.0, 0.05], [0.2, 6.0, 0.0], [0.0, 5.0, 0.1]] {
        let (e, m2) = energy_and_momentum(inertia, omega0);
        let period = torque_free_period(inertia, e, m2);
        let body = HeavyTop {
            mass: 1.0,
            inertia_com: Matrix3::from_diagonal(&Vector3::from(inertia)),
            center_of_mass: Vector3::zeros(),
            gravity: Vector3::zeros(),
        };
        let start = BodyState {
            time: 0.0,
            orientation: UnitQuaternion::identity(),
            omega: Vector3::from(omega0),
        };
        let dt = 1e-3;
        let times: Vec<f64> = (1..=(2.6 * period / dt) as usize)
            .map(|i| i as f64 * dt)
            .collect();
        let states = body.states_at(start, &times, 2e-4);
        let omega2: Vec<f64> = states.iter().map(|s| s.omega.y).collect();
        let flips = sign_changes(&times, &omega2);
        // Ω₂ ∝ sn(ω_p (t − t₀)) changes sign every T/2 (L&L §37): four
        // flips in 2.6 periods, spaced T/2; limit 1e-6 relative (the linear
        // interpolation of the crossing at samples 1e-3 apart where Ω₂ is
        // nearly linear, and RK4 at 2e-4 s: far below)
        assert!(flips.len() >= 4, "{omega0:?}: flips at {flips:?}");
        for w in flips.windows(2) {
            let half = w[1] - w[0];
            assert!(
                (half / (0.5 * period) - 1.0).abs() < 1e-6,
                "{omega0:?}: flips {half} s apart, closed form T/2 = {}",
                0.5 * period
            );
        }
        // energy and |M| kept by the integration: limit 1e-12 relative
        let last = states.last().unwrap();
        let (e1, m21) = energy_and_momentum(inertia, last.omega.into());
        assert!((e1 / e - 1.0).abs() < 1e-12 && (m21 / m2 - 1.0).abs() < 1e-12);
    }
}

#[test]
fn heavy_top_reference_is_converged_and_matches_an_independent_integration() {
    let (top, start) = arnold_bruls_top();
    // Richardson: with RK4 the error of the run at N steps is about
    // 16/15 |x_N − x_2N|, and that of the run at 2N steps 1/15 of it;
    // limit 1e-10 m on the centre of mass at t = 2 s
    let coarse = top.integrate(start, 2.0, 200_000);
    let fine = top.integrate(start, 2.0, 400_000);
    let (a, b) = (top.com(&coarse), top.com(&fine));
    let error_fine = (a - b).norm() / 15.0;
    assert!(error_fine < 1e-10, "estimated error {error_fine:e} m");
    // the orientation as well: limit 1e-10 rad
    let angle = (coarse.orientation.inverse() * fine.orientation).angle() / 15.0;
    assert!(angle < 1e-10, "estimated error {angle:e} rad");
    // against the DOP853 integration of bench/peer/reference.py (SciPy,
    // rtol = atol = 1e-13, quoted to 10 digits in bench/peer/README.md);
    // limit 2e-10 m (its last digit)
    let dop853 = Vector3::new(-0.150_416_822_7, -0.724_165_591_6, -0.673_022_269_6);
    assert!((b - dop853).norm() < 2e-10, "{b:?} against {dop853:?}");
    // the motion keeps its energy and the vertical angular momentum (gravity
    // has no moment about the vertical through the fixed point): limit 1e-10
    // relative
    let (e0, e1) = (top.energy(&start), top.energy(&fine));
    assert!((e1 / e0 - 1.0).abs() < 1e-10, "energy {e0} → {e1}");
    let (m0, m1) = (top.momentum(&start).z, top.momentum(&fine).z);
    assert!(
        (m1 / m0 - 1.0).abs() < 1e-10,
        "vertical momentum {m0} → {m1}"
    );
}
