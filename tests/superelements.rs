//! Superelements in the mechanism (src/elements/superelement.rs,
//! docs/theory.md §18): statics, dynamics and energies against the same
//! bodies in beam elements.

mod common;

use std::sync::Arc;

use unfold::model::input::{ModelInput, SectionInput, SuperelementInput};
use unfold::model::Model;

/// The section of the flexible beams: EI = 2000 N·m², 1 kg/m.
fn tube() -> SectionInput {
    SectionInput {
        mass_per_length: Some(1.0),
        inertia_per_length: Some([2e-4, 1e-4, 1e-4]),
        ..SectionInput::diagonal("tube", [1e7, 4e6, 4e6, 1.5e3, 2e3, 2e3])
    }
}

/// A cantilever of 20 elements (ids 1–20), 2 m along x from node 1
/// (clamped) to node 2, with a tip load `p` along z; as beams, or as a
/// superelement of them on nodes 1 and 2 with 4 modes.
fn cantilever(p: f64, reduced: bool) -> ModelInput {
    let mut m = ModelInput::new("cantilever");
    m.add_node(1, [0.0, 0.0, 0.0]);
    m.add_node(2, [2.0, 0.0, 0.0]);
    m.sections.push(tube());
    m.add_beam_line([1, 2], 20, "tube", Some([0.0, 0.0, 1.0]));
    m.beam_lines[0].first_element = Some(1);
    m.fix(1, &["all"]);
    m.add_load(2, [0.0, 0.0, p], [0.0; 3]);
    m.analysis.initial_increment = Some(1.0);
    if reduced {
        m.superelements.push(SuperelementInput {
            id: 100,
            boundary: vec![1, 2],
            elements: Some((1..=20).collect()),
            modes: Some(4),
            ..Default::default()
        });
    }
    m
}

/// Statics: a tip load on a cantilever reduced on its root and tip (the
/// constraint modes hold the exact static response to boundary loads)
/// deflects it as the beams do. Source: the beam model; tolerance 1e-6
/// relative: the beams are geometrically nonlinear, the superelement
/// linear in its frame, and the deflection is 4e-4 of the length, so the
/// nonlinear part is ~1e-7 of it.
#[test]
fn reduced_cantilever_deflects_as_the_beams() {
    let p = 1.0;
    let (beams, outcome, _) = common::run(&cantilever(p, false));
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    let w_beams = outcome.state.x[beams.node_index(2).unwrap()].z;
    let (model, outcome, _) = common::run(&cantilever(p, true));
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    assert_eq!(model.n_nodes(), 2, "the interior nodes left the model");
    let w = outcome.state.x[model.node_index(2).unwrap()].z;
    println!("tip: beams {w_beams:.9e}, superelement {w:.9e}");
    assert!((w - w_beams).abs() < 1e-6 * w_beams.abs());
    let _ = Arc::new(model);
}

use unfold::analysis::{DynamicAnalysis, Energies, Observer, Step};
use unfold::so3::{self, Vec3};
use unfold::state::State;

struct NoOutput;
impl Observer for NoOutput {}

/// Runs the first (dynamic) analysis of the model text `text`: every
/// accepted state and its energies.
fn run_dynamic(text: &str) -> (Arc<Model>, Vec<State>, Vec<Energies>) {
    let input: ModelInput = toml::from_str(text).expect("valid model file");
    let model = Arc::new(Model::from_input(&input).expect("valid model"));
    let settings = input.analyses().unwrap()[0].as_dynamic().unwrap().clone();
    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let (mut states, mut energies) = (Vec::new(), Vec::new());
    let mut step = analysis.start(model.initial_state(), &mut NoOutput);
    while let Step::Increment(_) = step {
        states.push(analysis.state().unwrap().clone());
        energies.push(*analysis.energies().unwrap());
        step = analysis.advance(&mut NoOutput);
    }
    let out = analysis.finish();
    assert!(out.error.is_none(), "{:?}", out.error);
    (model, states, energies)
}

/// A flexible pendulum: a 1 m beam of 20 elements (ids 1–20; the tube
/// section: EI = 2000 N·m², 1 kg/m; its first bending mode pinned-free
/// at 110 Hz) hinged at node 1 about z to the ground, released horizontal
/// under gravity along −y; `analysis` its analysis table, `beta` the
/// Rayleigh damping of the section, `body` what models the beam (empty
/// for the beams).
fn flexible_pendulum(analysis: &str, beta: f64, body: &str) -> String {
    format!(
        r#"title = "flexible pendulum"
{analysis}

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]

[[sections]]
name = "tube"
EA = 1e7
GA2 = 4e6
GA3 = 4e6
GJ = 1.5e3
EI2 = 2e3
EI3 = 2e3
mass_per_length = 1.0
inertia_per_length = [2e-4, 1e-4, 1e-4]
rayleigh_beta = {beta:?}

[[beam_lines]]
nodes = [1, 2]
elements = 20
section = "tube"
orientation = [0.0, 0.0, 1.0]
first_element = 1
first_node = 3

[[joints]]
id = 50
type = "revolute"
nodes = [1]
axis = [0.0, 0.0, 1.0]

[gravity]
acceleration = [0.0, -9.81, 0.0]
{body}"#
    )
}

/// The pendulum's beam as a superelement on `boundary` with `modes`
/// modes.
fn pendulum_superelement(boundary: &[u64], modes: usize, extra: &str) -> String {
    format!(
        r#"
[[superelements]]
id = 100
elements = [{}]
boundary = {boundary:?}
modes = {modes}
{extra}"#,
        (1..=20)
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The bending of the pendulum's tip in the frame of its root: the
/// transverse component of `R₁ᵀ(x_tip − x₁)`.
fn bending(r1: &unfold::so3::Rotation, x1: &Vec3, tip: &Vec3) -> f64 {
    (so3::matrix(r1).transpose() * (tip - x1)).y
}

/// The superelement of a model.
fn superelement(model: &Model) -> &unfold::elements::superelement::Superelement {
    model
        .elements
        .iter()
        .find_map(|e| e.as_superelement())
        .expect("a superelement")
}

/// Acceptance: the flexible pendulum as a superelement on its root node
/// alone (the tip recovered from 6 modes) swings as the beams do over
/// its first half swing (0.8 s): the bending of the tip in the frame of
/// the root within 1 % of the beams' (measured 0.32 %: 3.5e-7 m of a
/// 1.1e-4 m peak), the tip history within a tenth of that bending
/// (measured 4.2e-6 m, 3e-6 of the tip's 1.4 m travel; a rigid pendulum
/// would miss it by the whole bending). Source: the same beam in nonlinear beam
/// elements, the same steps (fixed, 0.2 ms: 45 per period of the first
/// bending mode) and ρ∞. Both are damped alike, so that the release's
/// free vibration dies and the bending follows the swing: the beams by
/// stiffness-proportional Rayleigh damping (β = 1.45e-4 s: 5 % on the
/// first bending mode), the superelement by the same β on its modes
/// (`ζ_k = β ω_k / 2`, which is `β K̄` on the elastic coordinates). The
/// bending is small (1.4e-3 of the length); the linear superelement lacks
/// the stiffening of the tension the swing and the weight put in the beam
/// (25 N against EI/L² = 2000 N: some 0.3 % of the bending).
#[test]
fn flexible_pendulum_swings_as_the_beams() {
    let analysis = r#"[analysis]
type = "dynamic"
end_time = 0.8
time_step = 0.0002
adaptive = false
rho_infinity = 0.9"#;
    let beta = 1.45e-4;
    let (beams, reference, _) = run_dynamic(&flexible_pendulum(analysis, beta, ""));
    // the modal damping ratios that make β K̄
    let probe = flexible_pendulum(analysis, beta, &pendulum_superelement(&[1], 6, ""));
    let input: ModelInput = toml::from_str(&probe).unwrap();
    let omega2 = superelement(&Model::from_input(&input).unwrap())
        .body()
        .omega_squared
        .clone();
    let ratios: Vec<f64> = omega2.iter().map(|w2| beta * w2.sqrt() / 2.0).collect();
    let extra = format!("damping_ratio = {ratios:?}");
    let (model, states, _) = run_dynamic(&flexible_pendulum(
        analysis,
        0.0,
        &pendulum_superelement(&[1], 6, &extra),
    ));
    assert_eq!(states.len(), reference.len());
    let se = superelement(&model);
    let mesh_tip = se.body().body.node_index(2).unwrap();
    let (root, root_b, tip_b) = (
        model.node_index(1).unwrap(),
        beams.node_index(1).unwrap(),
        beams.node_index(2).unwrap(),
    );
    let (mut worst_tip, mut worst_bend, mut largest_bend) = (0.0f64, 0.0f64, 0.0f64);
    for (r, s) in reference.iter().zip(&states) {
        assert!((r.time - s.time).abs() < 1e-12);
        let tip = se.recovered_mesh(s).position[mesh_tip];
        worst_tip = worst_tip.max((r.x[tip_b] - tip).norm());
        let br = bending(&r.q[root_b], &r.x[root_b], &r.x[tip_b]);
        let bs = bending(&s.q[root], &s.x[root], &tip);
        if ((s.time * 5000.0).round() as usize).is_multiple_of(200) {
            println!(
                "t {:.2}: bending beams {br:.4e}, superelement {bs:.4e}",
                s.time
            );
        }
        worst_bend = worst_bend.max((br - bs).abs());
        largest_bend = largest_bend.max(br.abs());
    }
    println!(
        "largest tip difference {worst_tip:.3e} m; bending: largest {largest_bend:.3e} m, largest difference {worst_bend:.3e} m"
    );
    // the tip's travel is 1.4 m; a rigid pendulum would miss its history
    // by the whole bending
    assert!(
        worst_tip < 0.1 * largest_bend,
        "tip history: {worst_tip:e} m"
    );
    assert!(
        worst_bend < 0.01 * largest_bend,
        "bending: {worst_bend:e} m of {largest_bend:e} m"
    );
}

/// Acceptance: with ρ∞ = 1 (the trapezoidal rule, which conserves the
/// energy of a conservative system to the accuracy of its quadrature) and
/// no damping, the energy balance of energies.csv holds for the flexible
/// pendulum as a superelement on its root and tip (6 modes: the boundary
/// pair and the modes both moving) over its first half swing, as for the
/// beams: its error is the quadrature's, O(h²). Source: docs/theory.md
/// §15.6. Measured: 5.56e-5 J at h = 1 ms, 1.38e-5 J at 0.5 ms (the
/// beams: 5.41e-5, 1.35e-5 J), 2.8e-6 of the weight's work m g L/2 =
/// 4.9 J. Asserted: below 1e-5 of it at 0.5 ms, and a quarter (within
/// 20 %) of the error at 1 ms: a residual inconsistent with the energies
/// would leave an error that does not fall as h².
#[test]
fn energy_is_conserved_with_rho_one() {
    let scale = 1.0 * 9.81 * 0.5;
    let mut errors = Vec::new();
    for h in [0.001, 0.0005] {
        let analysis = format!(
            "[analysis]\ntype = \"dynamic\"\nend_time = 0.8\ntime_step = {h}\nadaptive = false\nrho_infinity = 1.0"
        );
        let (_, states, energies) = run_dynamic(&flexible_pendulum(
            &analysis,
            0.0,
            &pendulum_superelement(&[1, 2], 6, ""),
        ));
        let worst = energies
            .iter()
            .fold(0.0f64, |a, e| a.max(e.balance_error.abs()));
        let last = energies.last().unwrap();
        println!(
            "h = {h}: {} steps; at {:.2} s kinetic {:.4} J, strain {:.3e} J, weight {:.4} J; largest balance error {worst:.3e} J",
            states.len(),
            last.time,
            last.kinetic,
            last.strain,
            last.gravity
        );
        assert!(last.kinetic > 0.1 * scale, "the pendulum swings");
        assert!(last.strain > 0.0, "and bends");
        errors.push(worst);
    }
    assert!(errors[1] < 1e-5 * scale, "balance error {:e} J", errors[1]);
    let ratio = errors[0] / errors[1];
    assert!(
        (ratio - 4.0).abs() < 0.8,
        "the error falls by {ratio} when h is halved"
    );
}

/// A blade spinning about z: the pendulum's beam (EI = 2000 N·m², its
/// first cantilever mode ω₀ = 157 rad/s) on its revolute hinge, every
/// node turning rigidly at `spin` rad/s at the start, under a load along
/// the spin axis (gravity 9.81 m/s² along −z: flap), its flap vibration
/// damped by Rayleigh β (5 % at ω₀) or the same β on the superelement's
/// modes; 0.6 s in steps of 1 ms.
fn spinning_blade(spin: f64, reduced: bool, ratios: &[f64]) -> String {
    let analysis = r#"[analysis]
type = "dynamic"
end_time = 0.6
time_step = 0.001
adaptive = false
rho_infinity = 0.9"#;
    let beta = if reduced { 0.0 } else { 6.4e-4 };
    let nodes: Vec<u64> = if reduced { vec![1] } else { (1..=21).collect() };
    let body = if reduced {
        pendulum_superelement(&[1], 6, &format!("damping_ratio = {ratios:?}"))
    } else {
        String::new()
    };
    flexible_pendulum(analysis, beta, &body).replace(
        "acceleration = [0.0, -9.81, 0.0]",
        &format!(
            "acceleration = [0.0, 0.0, -9.81]\n\n[[initial_motion]]\nnodes = {nodes:?}\nangular_velocity = [0.0, 0.0, {spin:?}]"
        ),
    )
}

/// The flap of the blade's tip (node 2, or recovered from the
/// superelement), averaged over the last 0.1 s (the vibration from the
/// load's sudden start damped out by then).
fn settled_flap(text: &str) -> f64 {
    let (model, states, _) = run_dynamic(text);
    let tip = |s: &State| match model.node_index(2) {
        Some(tip) => s.x[tip].z,
        None => {
            let se = superelement(&model);
            se.recovered_mesh(s).position[se.body().body.node_index(2).unwrap()].z
        }
    };
    let late: Vec<f64> = states.iter().filter(|s| s.time > 0.5).map(tip).collect();
    late.iter().sum::<f64>() / late.len() as f64
}

/// Acceptance (spin): the blade as a superelement (on its root, the tip
/// recovered from 6 modes, which carry its damping) flaps under its load as the beams do at a slow spin,
/// 2 rad/s (Ω/ω₀ = 1.3 %: a centrifugal stiffening of 2e-4), within 1 %
/// of the flap. At 50 rad/s (Ω/ω₀ = 0.32) the beams stiffen, and the
/// linear superelement does not: it keeps its flap at rest within 1 %
/// (a load along the spin axis meets no centrifugal force in the frame),
/// and the beams' flap falls below it by the centrifugal stiffening of a
/// uniform cantilever, `1 + 1.19 (Ω/ω₀)²` in the first mode (Southwell's
/// coefficient; Bauchau & Craig, Structural Analysis, §16.4; Hodges &
/// Pierce), within 2 % of that ratio (the load excites higher modes too,
/// whose coefficients differ). Documented in docs/theory.md §18.8.
/// Measured: flap at rest 6.1490e-4 m; at 2 rad/s beams 6.1468e-4,
/// superelement 6.1490e-4 (0.04 %); at 50 rad/s beams 5.4828e-4 (a
/// stiffening of 1.1215 against Southwell's 1.1202), superelement
/// 6.1490e-4.
#[test]
fn spinning_blade_flaps_as_the_beams_and_the_difference_is_centrifugal_stiffening() {
    // the modal damping ratios that make the beams' β K̄
    let probe: ModelInput = toml::from_str(&spinning_blade(0.0, true, &[0.0])).unwrap();
    let omega2 = superelement(&Model::from_input(&probe).unwrap())
        .body()
        .omega_squared
        .clone();
    let ratios: Vec<f64> = omega2.iter().map(|w2| 6.4e-4 * w2.sqrt() / 2.0).collect();
    let at_rest = settled_flap(&spinning_blade(0.0, true, &ratios));
    let (slow_beams, slow) = (
        settled_flap(&spinning_blade(2.0, false, &ratios)),
        settled_flap(&spinning_blade(2.0, true, &ratios)),
    );
    let (fast_beams, fast) = (
        settled_flap(&spinning_blade(50.0, false, &ratios)),
        settled_flap(&spinning_blade(50.0, true, &ratios)),
    );
    let southwell = 1.0 + 1.19 * (50.0f64 / 157.3).powi(2);
    println!(
        "flap at rest {at_rest:.5e} m; at 2 rad/s beams {slow_beams:.5e}, superelement {slow:.5e}; at 50 rad/s beams {fast_beams:.5e}, superelement {fast:.5e}; stiffening: beams {:.4}, Southwell {southwell:.4}",
        fast / fast_beams
    );
    assert!((slow - slow_beams).abs() < 0.01 * slow_beams.abs());
    assert!((fast - at_rest).abs() < 0.01 * at_rest.abs());
    assert!(((fast / fast_beams) / southwell - 1.0).abs() < 0.02);
}
