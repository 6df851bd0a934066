//! Rayleigh damping of beams in dynamics (docs/theory.md §11.5, I10–I13):
//! the logarithmic decrement of a cantilever's free vibration in its first
//! mode against the modal damping ratio `ζ = α/(2ω) + βω/2`, the energy
//! balance of the damped motion, and the input checks of the damping keys.

use std::sync::Arc;

use unfold::analysis::{
    AnalysisSettings, DynamicAnalysis, Energies, ModalAnalysis, ModalSettings, Observer, Step,
};
use unfold::elements::beam::RayleighDamping;
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// Length (m), bending stiffness (N·m²) and mass per length (kg/m) of the
/// cantilever; Euler–Bernoulli `ω₁ = 1.87510² √(EI/(m L⁴)) = 35.16 rad/s`.
const LENGTH: f64 = 1.0;
const EI: f64 = 100.0;
const MASS: f64 = 1.0;
/// Elements along the cantilever.
const ELEMENTS: usize = 20;

/// A cantilever along x, clamped at x = 0, bending in the x–z plane, with
/// Rayleigh damping `(alpha, beta)`, and a dynamic analysis of `periods`
/// periods of the first mode in fixed steps of `1/steps_per_period` of it
/// with `ρ∞ = 1` (no numerical dissipation), at the default tolerances:
/// the round-off of the shear forces, `GA ε |x|/ℓ ≈ 4e-9 N`, above 1e-8
/// of the force flux at the instants of zero deflection (flux ~0.2 N
/// there), is the stiffness part of the round-off floor of the dynamic
/// iterations (docs/theory.md §15.1).
fn cantilever(alpha: f64, beta: f64, periods: f64, steps_per_period: f64) -> String {
    let period = 2.0 * std::f64::consts::PI / euler_bernoulli_omega();
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = {end:?}
time_step = {h:?}
adaptive = false
rho_infinity = 1.0

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [{LENGTH:?}, 0.0, 0.0]

[[supports]]
node = 1
fixed = ["all"]

[[sections]]
name = "rod"
EA = 1.0e6
GA2 = 1.0e6
GA3 = 1.0e6
GJ = 1.0e2
EI2 = {EI:?}
EI3 = {EI:?}
mass_per_length = {MASS:?}
inertia_per_length = [2.0e-5, 1.0e-5, 1.0e-5]
rayleigh_alpha = {alpha:?}
rayleigh_beta = {beta:?}

[[beam_lines]]
nodes = [1, 2]
elements = {ELEMENTS}
section = "rod"
orientation = [0.0, 1.0, 0.0]
"#,
        end = periods * period,
        h = period / steps_per_period,
    )
}

/// `ω₁` of the Euler–Bernoulli cantilever (rad/s).
fn euler_bernoulli_omega() -> f64 {
    1.875_104_068_711_961_f64.powi(2) * (EI / (MASS * LENGTH.powi(4))).sqrt()
}

fn parse(text: &str) -> (Arc<Model>, Vec<AnalysisSettings>) {
    let input: ModelInput = toml::from_str(text).expect("valid toml");
    let model = Model::from_input(&input).expect("valid model");
    (Arc::new(model), input.analyses().expect("valid analyses"))
}

/// The tip deflection `w(t)` and the energies of every step.
struct Motion {
    times: Vec<f64>,
    tip: Vec<f64>,
    energies: Vec<Energies>,
    omega: f64,
}

/// The free vibration of the damped cantilever started in its first
/// (undamped) mode, tip velocity 1e-2 ω₁ L (a deflection of about 1e-2 L:
/// the frequency changes by ~1e-4 with the amplitude), and `ω₁` of the
/// discrete model from a modal analysis.
fn free_vibration(alpha: f64, beta: f64, periods: f64, steps_per_period: f64) -> Motion {
    free_vibration_of(1e-2, alpha, beta, periods, steps_per_period).0
}

/// As [`free_vibration`] with a tip deflection of about `amplitude` L,
/// with the outcome's counts: steps, rejected steps, Newton iterations.
fn free_vibration_of(
    amplitude: f64,
    alpha: f64,
    beta: f64,
    periods: f64,
    steps_per_period: f64,
) -> (Motion, [usize; 3]) {
    let (model, analyses) = parse(&cantilever(alpha, beta, periods, steps_per_period));
    let settings = analyses[0].as_dynamic().unwrap().clone();
    let tip = model.node_index(2).unwrap();

    // the first bending mode in the x–z plane
    let mut modal = ModalAnalysis::new(model.clone(), ModalSettings::lowest(4));
    let modes = modal.run(model.initial_state(), &mut NoOutput);
    assert!(modes.error.is_none(), "{:?}", modes.error);
    let mode = modes
        .modes
        .iter()
        .find(|m| m.shape[tip][2].abs() > 1e-3 * m.shape[tip][1].abs())
        .expect("a bending mode in z");
    let omega = mode.angular_frequency;
    let scale = amplitude * omega * LENGTH / mode.shape[tip][2];
    let mut start = model.initial_state();
    for (v, s) in start.velocity.iter_mut().zip(&mode.shape) {
        for c in 0..6 {
            v[c] = scale * s[c];
        }
    }

    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let mut motion = Motion {
        times: Vec::new(),
        tip: Vec::new(),
        energies: Vec::new(),
        omega,
    };
    let record = |a: &DynamicAnalysis, m: &mut Motion| {
        let s: &State = a.state().unwrap();
        m.times.push(s.time);
        m.tip.push(s.x[tip].z);
        m.energies.push(*a.energies().unwrap());
    };
    let mut step = analysis.start(start, &mut NoOutput);
    while let Step::Increment(_) = step {
        record(&analysis, &mut motion);
        step = analysis.advance(&mut NoOutput);
    }
    let out = analysis.finish();
    assert!(out.error.is_none(), "{:?}", out.error);
    eprintln!(
        "{} steps, {} iterations, {} rejected, {:.2} s",
        out.steps, out.iterations, out.rejected_steps, out.wall_time
    );
    (motion, [out.steps, out.rejected_steps, out.iterations])
}

struct NoOutput;
impl Observer for NoOutput {}

/// Maxima of `w(t)`, located by the parabola through the largest sample
/// and its neighbours: `(t, w)`.
fn peaks(t: &[f64], w: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for i in 1..w.len() - 1 {
        if w[i] > w[i - 1] && w[i] >= w[i + 1] && w[i] > 0.0 {
            let (a, b, c) = (w[i - 1], w[i], w[i + 1]);
            let h = t[i + 1] - t[i];
            let d = 0.5 * (a - c) / (a - 2.0 * b + c);
            out.push((t[i] + d * h, b - 0.25 * (a - c) * d));
        }
    }
    out
}

/// The damping ratio from the logarithmic decrement over the peaks
/// (`δ = ln(w₀/w_n)/n`, `ζ = δ/√(4π² + δ²)`, exact for a viscously damped
/// oscillator).
fn measured_ratio(motion: &Motion) -> (f64, usize) {
    let p = peaks(&motion.times, &motion.tip);
    assert!(p.len() >= 6, "{} peaks", p.len());
    let n = p.len() - 1;
    let delta = (p[0].1 / p[n].1).ln() / n as f64;
    (
        delta / (4.0 * std::f64::consts::PI.powi(2) + delta * delta).sqrt(),
        n,
    )
}

/// Acceptance: the free vibration of a cantilever with mass-proportional
/// damping alone, stiffness-proportional damping alone, and both, decays
/// with the logarithmic decrement of the modal damping ratio
/// `ζ = α/(2ω) + βω/2` (I13; Rayleigh damping leaves the undamped modes
/// uncoupled, so the first mode decays alone), `ω` the first angular
/// frequency of the same discrete model (modal analysis), which is
/// within 1e-3 of Euler–Bernoulli's. Ten periods in 100 fixed steps per
/// period with `ρ∞ = 1`, the trapezoidal rule: its decay rate is that of
/// `λ̃ = (2/h) artanh(hλ/2) = λ (1 + (hλ)²/12 + …)`, whose damping ratio is
/// `ζ (1 − (ωh)²/6)`, 6.6e-4 low at `ωh = 2π/100`. Tolerances: 2e-3 of
/// `ζ` against the exact ratio (three times that bias), and 1e-4 against
/// the ratio with the bias (what is left: the amplitude, 1e-2 L, and the
/// peak interpolation).
#[test]
fn logarithmic_decrement_matches_the_modal_damping_ratio() {
    let omega_eb = euler_bernoulli_omega();
    // ζ = 0.02 from each part at ω = ω_EB
    let alpha = 0.04 * omega_eb;
    let beta = 0.04 / omega_eb;
    for (a, b) in [(alpha, 0.0), (0.0, beta), (alpha, beta)] {
        let motion = free_vibration(a, b, 10.0, 100.0);
        let omega = motion.omega;
        // the discrete model's first frequency: 20 linear elements, within
        // 1e-3 of the Euler–Bernoulli value (docs/theory.md §14.7)
        assert!(
            ((omega - omega_eb) / omega_eb).abs() < 1e-3,
            "{omega} {omega_eb}"
        );
        let expected = RayleighDamping { alpha: a, beta: b }.damping_ratio(omega);
        let (zeta, n) = measured_ratio(&motion);
        let error = (zeta - expected).abs() / expected;
        let wh = omega * motion.times[1];
        let discrete = expected * (1.0 - wh * wh / 6.0);
        let residual = (zeta - discrete).abs() / expected;
        eprintln!(
            "α = {a:.4}, β = {b:.3e}: ζ measured {zeta:.6} over {n} periods, expected {expected:.6}, relative error {error:.2e}, {residual:.2e} with the trapezoidal bias"
        );
        assert!(error < 2e-3, "ζ = {zeta}, expected {expected}");
        assert!(
            residual < 1e-4,
            "ζ = {zeta}, expected {discrete} with the bias"
        );
    }
}

/// Acceptance: the energy dissipated by the Rayleigh damping, `∫ v·C_R v dt`
/// (I11), is the energy the cantilever loses. With `ρ∞ = 1` the integrator
/// dissipates nothing else on a linear problem; the balance error
/// `E = (T + V) − (T₀ + V₀) + D` (D12) with `D` the work of the
/// integrator's damping force at the mid-step velocity (D12a at
/// `α_f = ½`) is round-off and the geometric nonlinearity: measured
/// 2.1e-7 of the energy lost (the trapezoidal rule on the power,
/// `½ (P_n + P_{n+1})`, used before, differed by `(ωh)²/4 = 9.9e-4`).
/// Tolerance 2e-3 of the energy lost, which is more than 90 % of the
/// initial energy after ten periods at ζ = 0.04.
#[test]
fn energy_dissipated_is_the_energy_lost() {
    let omega = euler_bernoulli_omega();
    let motion = free_vibration(0.04 * omega, 0.04 / omega, 10.0, 100.0);
    let first = motion.energies.first().unwrap();
    let last = motion.energies.last().unwrap();
    let lost = first.total() - last.total();
    eprintln!(
        "initial energy {:.6e}, lost {:.6e}, dissipated {:.6e}, balance error {:.3e}",
        first.total(),
        lost,
        last.dissipated,
        last.balance_error
    );
    assert!(lost > 0.9 * first.total());
    assert!(last.external_work == 0.0);
    assert!(
        last.balance_error.abs() < 2e-3 * lost,
        "balance error {} of {lost}",
        last.balance_error
    );
    // at every step, the dissipation grows and the balance holds
    for w in motion.energies.windows(2) {
        assert!(w[1].dissipated >= w[0].dissipated);
        assert!(w[1].balance_error.abs() < 2e-3 * lost);
    }
}

/// Bad damping coefficients are input errors naming the section and the
/// key: negative, infinite or NaN values.
#[test]
fn bad_damping_coefficients_are_refused() {
    for (key, value) in [
        ("rayleigh_alpha", "-1.0"),
        ("rayleigh_beta", "-1e-3"),
        ("rayleigh_beta", "inf"),
        ("rayleigh_alpha", "nan"),
    ] {
        let text = cantilever(0.0, 0.0, 1.0, 10.0).replace(
            "rayleigh_alpha = 0.0\nrayleigh_beta = 0.0",
            &format!("{key} = {value}"),
        );
        assert!(text.contains(&format!("{key} = {value}")));
        let input: ModelInput = toml::from_str(&text).expect("valid toml");
        let err = Model::from_input(&input).unwrap_err().to_string();
        assert!(
            err.contains("section \"rod\"") && err.contains(key) && err.contains("≥ 0"),
            "{err}"
        );
    }
}

/// The builder's `Section::rayleigh_damping` gives the keys of the model
/// file, and the beam damps a shearing velocity (dissipated power
/// `v·C_R v`, I11) as its stiffness says, but not a rigid rotation (a
/// velocity field set on the element alone, its support aside).
#[test]
fn builder_sections_carry_rayleigh_damping() {
    use unfold::analysis::energy::powers;
    use unfold::model::builder::{Dofs, ModelBuilder, Section};
    let section = Section::diagonal(1e6, 1e6, 1e6, 1e2, 1e2, 1e2)
        .mass_per_length(1.0)
        .rayleigh_damping(0.0, 1e-3);
    let input = section.clone().into_input("rod");
    assert_eq!(
        (input.rayleigh_alpha, input.rayleigh_beta),
        (Some(0.0), Some(1e-3))
    );
    let mut m = ModelBuilder::new("damped beam");
    let (a, b) = (m.node([0.0, 0.0, 0.0]), m.node([1.0, 0.0, 0.0]));
    let s = m.section(section);
    m.beam(a, b, s);
    m.fix(a, Dofs::ALL);
    let model = m.build().expect("valid model");
    let (ia, ib) = (model.node(a), model.node(b));
    // the second node moves along z alone: a shear strain rate ẇ/L, no
    // curvature rate, so v·C_R v = β (GA/L) ẇ² = 1e-3 · 1e6 · 0.01 = 10
    let mut state = model.initial_state();
    state.velocity[ib][2] = 0.1;
    let (_, shear) = powers(&model, &state, None);
    let expected = 1e-3 * 1e6 * 0.1 * 0.1;
    assert!(
        (shear - expected).abs() <= 1e-12 * expected,
        "{shear} {expected}"
    );
    // a rigid rotation about z through the first node: no power
    let mut state = model.initial_state();
    state.velocity[ib][1] = 0.1;
    state.velocity[ia][5] = 0.1;
    state.velocity[ib][5] = 0.1;
    let (_, rigid) = powers(&model, &state, None);
    assert!(rigid.abs() <= 1e-12 * expected, "{rigid}");
}

/// At a tip deflection of 1e-3 L the forces of the motion are so small
/// that the round-off of the shear forces (`GA ε |x|/ℓ ≈ 4e-9 N`) is
/// above `residual_tolerance` (1e-8) times their flux at the instants of
/// zero deflection: Newton's residual stalls there, and is accepted at its
/// round-off plateau (corrections within 1024 ε of the unknowns,
/// docs/theory.md §15.1) instead of the step being cut back. Before that
/// rule one period took 1995 steps and 1112 cut-backs. One period at
/// 100 fixed steps, default tolerances: measured 100 steps, none rejected,
/// 2.0 iterations per step; at most 3 per step on average bounds it.
#[test]
fn small_vibration_runs_at_the_default_tolerances_without_cut_backs() {
    let (motion, [steps, rejected, iterations]) = free_vibration_of(1e-3, 0.0, 0.0, 1.0, 100.0);
    eprintln!("1e-3 L: {steps} steps, {rejected} rejected, {iterations} iterations");
    assert_eq!(rejected, 0, "{steps} steps, {iterations} iterations");
    assert_eq!(steps, 100);
    assert!(iterations <= 3 * steps, "{iterations} iterations");
    // the motion is the vibration asked for: the tip's largest deflection
    // about 1e-3 L (the mode scaled to a velocity 1e-3 ω₁ L; 20 %)
    let largest = motion.tip.iter().fold(0.0f64, |m, w| m.max(w.abs()));
    assert!(
        (largest - 1e-3 * LENGTH).abs() < 0.2e-3 * LENGTH,
        "largest tip deflection {largest}"
    );
}
