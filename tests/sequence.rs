//! Analyses take a state and return a state: a static analysis from
//! `t = 0` to 1 followed by one from 1 to 2, started from the first one's
//! final state, ends where one analysis from 0 to 2 ends; the step-by-step
//! interface gives the same increments as a run at once.
//!
//! The model: the 45° bend of Bathe & Bolourchi (examples/bend_45.toml,
//! radius 100, tip load P = 600 out of plane at t = 1, following the ramp
//! to 2P at t = 2), whose root is not clamped but hinged to the ground
//! about its tangent (x) and turned about it by a driver, 0.15 rad per
//! unit of t: large rotations, a multiplier-enforced hinge and a driven
//! coordinate whose internal variables (the unwrapped angle) carry from
//! one analysis to the next.

mod common;

use std::sync::Arc;

use unfold::analysis::{NoObserver, StaticAnalysis, StaticOutcome, StaticSettings, Step};
use unfold::model::builder::*;
use unfold::model::Model;
use unfold::so3;

/// The driven bend, with the analyses of `sequence` (end times).
fn driven_bend(sequence: &[f64]) -> ModelBuilder {
    common::driven_bend(common::bend_section(), sequence, 600.0)
}

/// The model and the settings of its analyses.
fn build(m: &ModelBuilder) -> (Arc<Model>, Vec<StaticSettings>) {
    let model = Arc::new(m.build().expect("valid model"));
    let settings = m
        .analyses()
        .expect("valid analyses")
        .iter()
        .map(|a| a.as_static().expect("static").clone())
        .collect();
    (model, settings)
}

/// Largest distance between the nodes of two states, and largest angle
/// between their orientations.
fn difference(a: &unfold::state::State, b: &unfold::state::State) -> (f64, f64) {
    let dx =
        a.x.iter()
            .zip(&b.x)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).norm()));
    let dth = a.q.iter().zip(&b.q).fold(0.0f64, |m, (p, q)| {
        m.max(so3::log(&(p.inverse() * q)).norm())
    });
    (dx, dth)
}

fn run(model: &Arc<Model>, settings: StaticSettings, start: unfold::state::State) -> StaticOutcome {
    let outcome = StaticAnalysis::new(model.clone(), settings).run(start, &mut NoObserver);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    outcome
}

/// Static 0 → 1 then static 1 → 2 from the first one's final state equals
/// static 0 → 2. The two paths take the same increments, but the second
/// analysis starts its first increment without the predictor's last
/// motion, so its iterates differ; both converge to the same equilibrium,
/// to the Newton tolerance: the next correction below 1e-11 of the
/// increment's motion (~5) and the residual below 1e-11 of the flux, so
/// positions must agree to 1e-10 of the largest displacement (~75 here),
/// orientations to 1e-10 rad and the multipliers (the hinge's and the
/// driver's loads) to 1e-8 of the largest. Measured: 1e-14, 5e-16 rad
/// and 2e-16 of the largest, round-off (both end on the round-off plateau
/// of the last increment), in as many iterations (74).
#[test]
fn two_analyses_in_sequence_end_where_one_does() {
    let (model, settings) = build(&driven_bend(&[2.0]));
    let whole = run(&model, settings[0].clone(), model.initial_state());

    let (model2, settings) = build(&driven_bend(&[1.0, 2.0]));
    assert_eq!(settings.len(), 2);
    assert_eq!(settings[1].initial_increment, 0.125);
    let first = run(&model2, settings[0].clone(), model2.initial_state());
    assert_eq!(first.time, 1.0);
    let second = run(&model2, settings[1].clone(), first.state.clone());
    assert_eq!(second.time, 2.0);
    assert_eq!(first.increments + second.increments, whole.increments);

    let tip = model.n_nodes() - 1;
    let motion = (whole.state.x[1] - model.reference_x[1])
        .norm()
        .max((whole.state.x[tip] - model.reference_x[tip]).norm());
    let (dx, dth) = difference(&whole.state, &second.state);
    let lambda = whole
        .state
        .multipliers
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let dl = whole
        .state
        .multipliers
        .iter()
        .zip(&second.state.multipliers)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "largest motion {motion:.3}: positions differ by {dx:.2e}, orientations by {dth:.2e} rad, multipliers by {dl:.2e} of {lambda:.3e}; iterations {} and {} + {}",
        whole.iterations, first.iterations, second.iterations
    );
    assert!(motion > 10.0, "a large motion: {motion}");
    assert!(dx <= 1e-10 * motion, "{dx:e}");
    assert!(dth <= 1e-10, "{dth:e}");
    assert!(dl <= 1e-8 * lambda, "{dl:e}");
    // the internal variables (the driver's unwrapped angle) carried over
    assert_eq!(whole.state.internal.len(), second.state.internal.len());
    for (a, b) in whole.state.internal.iter().zip(&second.state.internal) {
        assert!((a - b).abs() <= 1e-10, "{a} vs {b}");
    }
}

/// The step-by-step interface (start, advance, state, finish) reports
/// every increment a run reports and ends at the same state, bit for bit.
#[test]
fn step_by_step_is_a_run() {
    let (model, settings) = build(&driven_bend(&[1.0]));
    let mut all = unfold::analysis::observers::History::new();
    let at_once = StaticAnalysis::new(model.clone(), settings[0].clone())
        .run(model.initial_state(), &mut all);

    let mut analysis = StaticAnalysis::new(model.clone(), settings[0].clone());
    let mut steps = Vec::new();
    let mut step = analysis.start(model.initial_state(), &mut NoObserver);
    while let Step::Increment(info) = step {
        // the state of every increment is there to look at
        assert_eq!(analysis.state().expect("started").time, info.time);
        steps.push(info);
        step = analysis.advance(&mut NoObserver);
    }
    assert_eq!(step, Step::Finished);
    assert!(analysis.error().is_none());
    let outcome = analysis.finish();
    assert_eq!(steps, all.increments);
    assert_eq!(outcome.state, at_once.state);
    assert_eq!(
        (outcome.increments, outcome.iterations),
        (at_once.increments, at_once.iterations)
    );
    // after the end, nothing more happens
    assert_eq!(analysis.advance(&mut NoObserver), Step::Stopped);
}
