//! Convergence of Newton's iterations (docs/theory.md §7): the measures
//! that decide convergence depend neither on the extent of the model, nor
//! on its unloaded parts, nor on the units; an increment whose load changed
//! is never accepted without a correction; non-finite values name their
//! origin; and the slender roll-up converges in a few iterations.

mod common;

use std::f64::consts::PI;

use common::node;
use std::sync::Arc;

use unfold::analysis::observers::History;
use unfold::analysis::{NewtonFailure, StaticOutcome};
use unfold::elements::{Element, ElementKind, ElementOutput, EvalContext};
use unfold::model::input::{BeamLineInput, ModelInput};
use unfold::model::Model;
use unfold::so3;
use unfold::state::State;

/// A straight line of `n` beam elements from node 1 at `a` to node 2 at
/// `b`; interior nodes get ids 3, 4, ... in order from `a`.
fn line(
    m: &mut ModelInput,
    a: [f64; 3],
    b: [f64; 3],
    n: usize,
    section: &str,
    orientation: [f64; 3],
) {
    m.add_node(1, a);
    m.add_node(2, b);
    m.beam_lines.push(BeamLineInput {
        nodes: [1, 2],
        elements: n,
        section: section.into(),
        orientation: Some(orientation),
        first_node: Some(3),
        first_element: Some(1),
        arc_center: None,
        initial_strain: None,
        initial_strain_curve: None,
    });
}

/// Runs `model`, returning the outcome and the iterations of every
/// increment after the initial equilibrium.
fn run_model(model: Model, input: &ModelInput) -> (Arc<Model>, StaticOutcome, Vec<usize>) {
    let model = Arc::new(model);
    let mut history = History::new();
    let outcome = common::analysis(&model, input).run(model.initial_state(), &mut history);
    let iterations = history.increments[1..].iter().map(|i| i.iterations);
    (model, outcome, iterations.collect())
}

/// The cantilever of the README and the crate example: 2 m, 10 elements,
/// EA = 1e8 N, GA = 4e7 N, EI = GJ = 1e5 N·m², clamped at node 1 (x = 0),
/// tip force `p` along −z at node 2 (x = 2 m), in 10 load increments.
/// `scale` is the length unit in metres (1e-3: millimetres), forces stay
/// in newtons.
fn cantilever(p: f64, scale: f64) -> ModelInput {
    let l = 2.0 / scale;
    let mut m = ModelInput::new("cantilever");
    let (ea, ga, ei) = (1e8, 4e7, 1e5 / (scale * scale));
    m.add_section("s", [ea, ga, ga, ei, ei, ei]);
    line(&mut m, [0.0; 3], [l, 0.0, 0.0], 10, "s", [0.0, 1.0, 0.0]);
    m.fix(1, &["all"]);
    m.add_load(2, [0.0, 0.0, -p], [0.0; 3]);
    m.analysis.initial_increment = Some(0.1);
    m
}

/// Tip deflection (along z) and the iterations of every increment.
fn tip_deflection(input: &ModelInput) -> (f64, Vec<usize>) {
    let model = Model::from_input(input).expect("valid model");
    let (model, outcome, iterations) = run_model(model, input);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    let tip = node(&model, 2);
    (
        outcome.state.x[tip].z - model.reference_x[tip].z,
        iterations,
    )
}

/// A node far away, fixed in every component, changes nothing: the tip
/// deflection is the same to round-off, in as many iterations, and equals
/// Timoshenko's `P L³/3EI + P L/GA` within 0.5 % (the one-point integrated
/// element is too flexible in bending by `1/(4 n²)` of the bending term,
/// 0.25 % with 10 elements, see tests/beam_validation.rs).
///
/// Before the convergence measures were made local, the node at 1e6 made
/// the model size 1e6 times larger, with the residual floor and the
/// correction tolerance: every increment was accepted after one or no
/// correction and the tip did not move at all.
#[test]
fn a_far_fixed_node_changes_nothing() {
    let p = 10.0;
    let (reference, iterations) = tip_deflection(&cantilever(p, 1.0));
    let timoshenko = -(p * 8.0 / (3.0 * 1e5) + p * 2.0 / 4e7);
    println!(
        "without the far node: w = {reference:.9e} (Timoshenko {timoshenko:.9e}), iterations {iterations:?}"
    );
    assert!((reference - timoshenko).abs() < 5e-3 * timoshenko.abs());
    for far in [1.0e3, 1.0e6] {
        let mut m = cantilever(p, 1.0);
        m.add_node(99, [far, 0.0, 0.0]);
        m.fix(99, &["all"]);
        let (w, its) = tip_deflection(&m);
        println!("far node at {far:.0e}: w = {w:.9e}, iterations {its:?}");
        // round-off: a different numbering of the same equations
        assert!((w - reference).abs() < 1e-12 * reference.abs(), "w = {w}");
        assert_eq!(its, iterations);
    }
}

/// An unloaded part standing far away, free to move (a cantilever of its
/// own at x = 1e6 m), and an unloaded part much stiffer than the loaded
/// one (a clamped bar 1e6 times stiffer, beside it) change nothing: same
/// tip deflection to round-off, same iterations. The stiff part raises
/// the largest stiffness of the model, to which the residual floor and the
/// constraint scaling used to be proportional.
#[test]
fn unloaded_parts_far_away_or_stiff_change_nothing() {
    let p = 10.0;
    let (reference, iterations) = tip_deflection(&cantilever(p, 1.0));
    let extra_part = |m: &mut ModelInput, at: [f64; 3], section: &str| {
        m.add_node(101, at);
        m.add_node(102, [at[0] + 5.0, at[1], at[2]]);
        m.beam_lines.push(BeamLineInput {
            nodes: [101, 102],
            elements: 8,
            section: section.into(),
            orientation: Some([0.0, 1.0, 0.0]),
            first_node: Some(103),
            first_element: Some(101),
            arc_center: None,
            initial_strain: None,
            initial_strain_curve: None,
        });
        m.fix(101, &["all"]);
    };
    let mut far = cantilever(p, 1.0);
    extra_part(&mut far, [1.0e6, 0.0, 0.0], "s");
    let mut stiff = cantilever(p, 1.0);
    stiff.add_section("stiff", [1e14, 4e13, 4e13, 1e11, 1e11, 1e11]);
    extra_part(&mut stiff, [0.0, 1.0, 0.0], "stiff");
    for (name, m) in [("far free part", far), ("stiff part", stiff)] {
        let (w, its) = tip_deflection(&m);
        println!("{name}: w = {w:.9e} (alone {reference:.9e}), iterations {its:?}");
        assert!(
            (w - reference).abs() < 1e-12 * reference.abs(),
            "{name}: w = {w}"
        );
        assert_eq!(its, iterations, "{name}");
    }
}

/// The same cantilever in metres and in millimetres (EI in N·mm²), under a
/// tip force bending it by a third of its length: the tip deflections
/// agree to round-off and every increment takes the same iterations.
///
/// Tolerance: 1e-10 of the deflection, the relative tolerance of Newton's
/// iterations (1e-8 of the flux) being the same in both units, and both
/// converging quadratically far below it.
#[test]
fn results_do_not_depend_on_the_units() {
    let p = 2.5e4; // P L²/EI = 1: tip deflection ~0.3 L
    let (metres, its_m) = tip_deflection(&cantilever(p, 1.0));
    let (millimetres, its_mm) = tip_deflection(&cantilever(p, 1e-3));
    println!("w = {metres:.12e} m, {millimetres:.12e} mm; iterations {its_m:?} and {its_mm:?}");
    assert!(metres < -0.5, "not a large deflection: {metres}");
    assert!((millimetres * 1e-3 - metres).abs() < 1e-10 * metres.abs());
    assert_eq!(its_m, its_mm);
}

/// No increment whose load changed is accepted on its first evaluation:
/// every one makes at least one correction, whatever the model (the far
/// node cantilever, where an increment used to be accepted after none, the
/// 45° bend, the roll-up, a mechanism).
#[test]
fn a_changed_load_is_never_accepted_without_a_correction() {
    let mut far = cantilever(10.0, 1.0);
    far.add_node(99, [1.0e6, 0.0, 0.0]);
    far.fix(99, &["all"]);
    let models = [
        ("far node", far),
        ("45° bend", common::example("bend_45.toml")),
        ("roll-up", common::example("cantilever_rollup.toml")),
        ("slider-crank", common::example("slider_crank.toml")),
    ];
    for (name, input) in models {
        let model = Model::from_input(&input).expect("valid model");
        let (_, outcome, iterations) = run_model(model, &input);
        assert!(outcome.error.is_none(), "{name}: {:?}", outcome.error);
        println!("{name}: iterations {iterations:?}");
        assert!(
            iterations.iter().all(|&k| k >= 1),
            "{name}: an increment converged without a correction: {iterations:?}"
        );
    }
}

/// A ground spring on the tip whose residual (or tangent) becomes NaN
/// once `t > 0.45`: the stand-in for an element that breaks down in some
/// configuration.
struct BreakingSpring {
    id: u64,
    node: [usize; 1],
    /// NaN in the tangent instead of the residual.
    in_tangent: bool,
}

impl Element for BreakingSpring {
    fn kind(&self) -> ElementKind {
        ElementKind::Spring
    }
    fn id(&self) -> u64 {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.node
    }
    fn evaluate(&self, ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let k = 1e3;
        let broken = if ctx.time > 0.45 { f64::NAN } else { 1.0 };
        let (r_factor, k_factor) = if self.in_tangent {
            (1.0, broken)
        } else {
            (broken, 1.0)
        };
        let x = state.x[self.node[0]];
        for c in 0..3 {
            // reference position of the tip: (2, 0, 0)
            let u = x[c] - if c == 0 { 2.0 } else { 0.0 };
            out.residual[c] += k * u * r_factor;
            if let Some(t) = out.stiffness.as_deref_mut() {
                t[c * 6 + c] += k * k_factor;
            }
        }
    }
}

/// Non-finite values name where they come from: the analysis stops (after
/// cutting back down to the smallest increment) with a message naming the
/// element kind and id, and whether its residual or its tangent broke.
#[test]
fn non_finite_values_name_the_element() {
    for (in_tangent, what) in [(false, "residual"), (true, "tangent")] {
        let input = cantilever(10.0, 1.0);
        let mut model = Model::from_input(&input).expect("valid model");
        let tip = node(&model, 2);
        model.push_element(Box::new(BreakingSpring {
            id: 77,
            node: [tip],
            in_tangent,
        }));
        let (_, outcome, _) = run_model(model, &input);
        let error = outcome.error.expect("the run must stop").to_string();
        println!("{error}");
        assert!(
            error.contains("non-finite values at iteration")
                && error.contains(&format!("in the {what} of spring 77")),
            "{error}"
        );
        // it went as close to t = 0.45 as the smallest increment allows
        assert!(
            outcome.time > 0.449 && outcome.time <= 0.45,
            "t = {}",
            outcome.time
        );
    }
    // the failure value itself
    let failure = NewtonFailure::NonFinite {
        iteration: 2,
        origin: "in the residual of beam 3".into(),
    };
    assert_eq!(
        failure.to_string(),
        "non-finite values at iteration 2 in the residual of beam 3"
    );
}

/// The roll-up of a slender strip (L = 1, EA = 4e5, GA = 1.5e5, GJ = 0.8,
/// EI = 1, 40 elements) into a full circle by the end moment `2π EI/L` in
/// 8 increments: every increment converges in at most 5 iterations (it
/// took 11 each with linear updates from the last state: each element
/// turning by up to π/4 per increment was stretched by the linear update
/// of its ends, a force 1e5 times the load), and the strip closes into the
/// circle: with the helicoidal interpolation the 40 chords turning by
/// 2π/40 close exactly, so the tip returns to the clamp within the Newton
/// tolerance (1e-6 L allowed) and its section has turned by 2π.
#[test]
fn slender_rollup_converges_in_few_iterations() {
    let mut m = ModelInput::new("slender roll-up");
    m.add_section("strip", [4e5, 1.5e5, 1.5e5, 0.8, 1.0, 1.0]);
    line(
        &mut m,
        [0.0; 3],
        [1.0, 0.0, 0.0],
        40,
        "strip",
        [0.0, 1.0, 0.0],
    );
    m.fix(1, &["all"]);
    m.add_load(2, [0.0; 3], [0.0, 0.0, 2.0 * PI]);
    m.analysis.initial_increment = Some(0.125);
    m.analysis.max_increment = Some(0.125);
    let model = Model::from_input(&m).expect("valid model");
    let (model, outcome, iterations) = run_model(model, &m);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    println!(
        "iterations per increment {iterations:?}, translation corrections {}",
        outcome.translation_corrections
    );
    assert_eq!(iterations.len(), 8);
    assert!(iterations.iter().all(|&k| k <= 5), "{iterations:?}");
    let tip = node(&model, 2);
    let gap = outcome.state.x[tip].norm();
    let turn = so3::log(&outcome.state.q[tip]).norm();
    println!("tip at {gap:.2e} L from the clamp, section turned by 2π + {turn:.1e}");
    assert!(gap < 1e-6, "tip at {:?}", outcome.state.x[tip]);
    assert!(turn < 1e-6, "tip rotation {turn}");
}
