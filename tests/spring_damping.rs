//! Dampers in parallel with springs between nodes (`[[springs]]` with
//! `damping` or `damping_ratio`; docs/model-format.md, docs/theory.md §5
//! S4): the free vibration of a mass on a damped spring against the exact
//! damped oscillator, the reduced mass of two bodies, the inertia about the
//! node of a rigid body with an offset centre of mass, the energy balance,
//! and the input errors.

use std::sync::Arc;

use unfold::analysis::{AnalysisSettings, DynamicAnalysis, Energies, Observer, Step};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::so3;

struct NoOutput;
impl Observer for NoOutput {}

fn parse(text: &str) -> Result<(Arc<Model>, Vec<AnalysisSettings>), String> {
    let input: ModelInput = toml::from_str(text).map_err(|e| e.to_string())?;
    let model = Model::from_input(&input).map_err(|e| e.to_string())?;
    Ok((
        Arc::new(model),
        input.analyses().map_err(|e| e.to_string())?,
    ))
}

/// Times, the coordinate `read` of every step, and the energies.
struct History {
    t: Vec<f64>,
    u: Vec<f64>,
    energies: Vec<Energies>,
}

fn run(text: &str, read: impl Fn(&unfold::state::State) -> f64) -> History {
    let (model, analyses) = parse(text).expect("valid model");
    let settings = analyses[0].as_dynamic().unwrap().clone();
    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let mut h = History {
        t: Vec::new(),
        u: Vec::new(),
        energies: Vec::new(),
    };
    let mut step = analysis.start(model.initial_state(), &mut NoOutput);
    while let Step::Increment(_) = step {
        let s = analysis.state().unwrap();
        h.t.push(s.time);
        h.u.push(read(s));
        h.energies.push(*analysis.energies().unwrap());
        step = analysis.advance(&mut NoOutput);
    }
    let out = analysis.finish();
    assert!(out.error.is_none(), "{:?}", out.error);
    h
}

/// `u(t) = (u̇₀/ω_d) e^{−ζωt} sin(ω_d t)`, `ω_d = ω√(1 − ζ²)`: the viscously
/// damped oscillator started at rest position with velocity `u̇₀`.
fn damped(t: f64, omega: f64, zeta: f64, v0: f64) -> f64 {
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    v0 / wd * (-zeta * omega * t).exp() * (wd * t).sin()
}

/// Largest error of the history against the damped oscillator, relative
/// to the initial amplitude `u̇₀/ω`.
fn error(h: &History, omega: f64, zeta: f64, v0: f64) -> f64 {
    h.t.iter()
        .zip(&h.u)
        .map(|(&t, &u)| (u - damped(t, omega, zeta, v0)).abs())
        .fold(0.0, f64::max)
        / (v0 / omega)
}

/// The analysis block: `periods` periods of `2π/ω` in 400 fixed steps per
/// period with `ρ∞ = 1` (the trapezoidal rule: no numerical damping; its
/// frequency is `(ωh)²/12 = 1.3e-5` relative low at `ωh = 2π/400`, a phase
/// error of 4e-4 rad after five periods).
fn analysis(omega: f64, periods: f64) -> String {
    let period = std::f64::consts::TAU / omega;
    format!(
        "[analysis]\ntype = \"dynamic\"\nend_time = {:?}\ntime_step = {:?}\nadaptive = false\nrho_infinity = 1.0\n",
        periods * period,
        period / 400.0
    )
}

/// Source: the viscously damped one-degree-of-freedom oscillator (e.g.
/// Géradin & Rixen, "Mechanical Vibrations", §2.2): a point mass
/// `m = 2 kg` on a translational spring to ground `k = 800 N/m` along x
/// (`ω = 20 rad/s`) with `damping_ratio = 0.05`, so `c = 2ζ√(km) = 4 N·s/m`,
/// started at its rest position at 1 m/s. Over five periods the motion
/// follows `u(t)` within 2e-3 of the amplitude (the integration's phase
/// error, 4e-4 rad, and its damping-ratio bias `(ωh)²/6 = 4e-5` relative,
/// are well inside; a ratio 2 % off gives 5e-3); the energy lost equals
/// the damper's work, the balance error below 1e-4 of the initial energy.
#[test]
fn mass_on_a_damped_spring_follows_the_damped_oscillator() {
    let (m, k, zeta, v0): (f64, f64, f64, f64) = (2.0, 800.0, 0.05, 1.0);
    let omega = (k / m).sqrt();
    let text = format!(
        r#"{}
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
velocity = [{v0:?}, 0.0, 0.0]

[[supports]]
node = 1
fixed = ["y", "z", "rotations"]

[[point_masses]]
id = 10
node = 1
mass = {m:?}

[[springs]]
id = 20
kind = "translational"
nodes = [1]
stiffness = {k:?}
damping_ratio = {zeta:?}
"#,
        analysis(omega, 5.0)
    );
    let h = run(&text, |s| s.x[0].x);
    let e = error(&h, omega, zeta, v0);
    println!("mass on a damped spring: error {e:.2e} of the amplitude");
    assert!(e < 2e-3, "error {e:.3e}");
    // the same ratio 2 % off is told apart
    let off = error(&h, omega, 1.02 * zeta, v0);
    assert!(off > 2.0 * e, "{off:.3e} vs {e:.3e}");

    // energy: kinetic + strain + dissipated = ½ m u̇₀²
    let e0 = 0.5 * m * v0 * v0;
    let last = h.energies.last().unwrap();
    println!(
        "dissipated {:.6} J of {e0} J, balance error {:.2e} J",
        last.dissipated, last.balance_error
    );
    assert!(last.dissipated > 0.8 * e0, "{last:?}");
    assert!(last.balance_error.abs() < 1e-4 * e0, "{last:?}");

    // the coefficient given directly is the same damper
    let coefficient = text.replace(
        &format!("damping_ratio = {zeta:?}"),
        &format!("damping = {:?}", 2.0 * zeta * (k * m).sqrt()),
    );
    let h2 = run(&coefficient, |s| s.x[0].x);
    let same =
        h.u.iter()
            .zip(&h2.u)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
    assert!(same < 1e-12, "{same:e}");
}

/// Two bodies, `m_a = 1 kg` and `m_b = 3 kg`, free along x, joined by an
/// axial spring `k = 300 N/m` with `damping_ratio = 0.1`: the ratio refers
/// to the reduced mass `m_a m_b/(m_a + m_b) = 0.75 kg`, so the elongation
/// is the damped oscillator of `ω = √(k/0.75) = 20 rad/s`, `ζ = 0.1`
/// (source and tolerance as above), and the centre of mass keeps its
/// velocity (the damper's forces are internal) to round-off.
#[test]
fn the_ratio_of_two_bodies_refers_to_their_reduced_mass() {
    let (ma, mb, k, zeta): (f64, f64, f64, f64) = (1.0, 3.0, 300.0, 0.1);
    let omega = (k * (ma + mb) / (ma * mb)).sqrt();
    // relative velocity 1 m/s, centre of mass at 0.25 m/s
    let (va, vb) = (-0.5, 0.5);
    let text = format!(
        r#"{}
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
velocity = [{va:?}, 0.0, 0.0]

[[nodes]]
id = 2
x = [0.5, 0.0, 0.0]
velocity = [{vb:?}, 0.0, 0.0]

[[supports]]
node = 1
fixed = ["y", "z", "rotations"]

[[supports]]
node = 2
fixed = ["y", "z", "rotations"]

[[point_masses]]
id = 10
node = 1
mass = {ma:?}

[[point_masses]]
id = 11
node = 2
mass = {mb:?}

[[springs]]
id = 20
kind = "axial"
nodes = [1, 2]
stiffness = {k:?}
damping_ratio = {zeta:?}
"#,
        analysis(omega, 5.0)
    );
    let h = run(&text, |s| s.x[1].x - s.x[0].x - 0.5);
    let e = error(&h, omega, zeta, vb - va);
    println!("two bodies: error {e:.2e} of the amplitude");
    assert!(e < 2e-3, "error {e:.3e}");
    let g = run(&text, |s| ma * s.velocity[0][0] + mb * s.velocity[1][0]);
    let p0 = ma * va + mb * vb;
    let drift = g.u.iter().map(|p| (p - p0).abs()).fold(0.0, f64::max);
    assert!(drift < 1e-12 * (ma + mb), "momentum drift {drift:e}");
}

/// A rigid body on a node that only turns about z, against a rotational
/// spring to ground `k = 50 N·m/rad` with `damping_ratio = 0.05`: mass
/// 4 kg, inertia about its centre `diag(0.1, 0.2, 0.3)` kg·m², centre of
/// mass at (0.2, 0.1, 0) from the node, so its inertia about the node's z
/// axis is `0.3 + 4 (0.2² + 0.1²) = 0.5 kg·m²` (parallel axes),
/// `ω = √(k/J) = 10 rad/s`; the turn about z is the damped oscillator
/// (source and tolerance as above).
#[test]
fn a_rotational_ratio_uses_the_inertia_about_the_node() {
    let (k, zeta, w0) = (50.0, 0.05, 0.5);
    let omega = (k / 0.5f64).sqrt();
    let text = format!(
        r#"{}
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
angular_velocity = [0.0, 0.0, {w0:?}]

[[supports]]
node = 1
fixed = ["translations", "rx", "ry"]

[[rigid_bodies]]
id = 10
node = 1
mass = 4.0
inertia = [0.1, 0.2, 0.3]
center_of_mass = [0.2, 0.1, 0.0]

[[springs]]
id = 20
kind = "rotational"
nodes = [1]
stiffness = {k:?}
damping_ratio = {zeta:?}
"#,
        analysis(omega, 5.0)
    );
    let h = run(&text, |s| so3::log(&s.q[0]).z);
    let e = error(&h, omega, zeta, w0);
    println!("rotational: error {e:.2e} of the amplitude");
    assert!(e < 2e-3, "error {e:.3e}");
}

/// Input errors name the spring and what is wrong.
#[test]
fn damper_input_errors_are_clear() {
    let base = r#"
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]

[[springs]]
id = 20
kind = "axial"
nodes = [1, 2]
stiffness = 10.0
"#;
    let cases = [
        (
            "damping = 1.0\ndamping_ratio = 0.1",
            "give `damping` (the coefficients) or `damping_ratio`, not both",
        ),
        ("damping = -1.0", "damping must be zero or positive"),
        ("damping = [1.0, 2.0, 3.0]", "a single coefficient"),
        (
            "damping_ratio = -0.1",
            "damping_ratio must be zero or positive",
        ),
        (
            "damping_ratio = 0.1",
            "damping_ratio needs a mass on node 1 and 2",
        ),
    ];
    for (keys, expected) in cases {
        let Err(err) = parse(&format!("{base}{keys}\n")) else {
            panic!("{keys}: accepted");
        };
        assert!(
            err.contains("spring 20") && err.contains(expected),
            "{keys}: {err}"
        );
    }
}
