//! The step controller on static analyses (src/analysis/control.rs,
//! docs/theory.md §13): a step across an event is retried shortened until
//! it lands on the event, and a change of the active constraints (a driver
//! handing over to another) has the rank of the constraints analysed again.

use std::sync::Arc;

use unfold::analysis::observers::History;
use unfold::analysis::{EventFunction, StaticAnalysis};
use unfold::model::builder::*;
use unfold::model::Model;
use unfold::state::State;

/// "The `z` of node `node` reaches `value`": `g = z − value`.
struct Reaches {
    node: usize,
    value: f64,
    tolerance: f64,
}

impl EventFunction for Reaches {
    fn name(&self) -> String {
        format!("tip z = {}", self.value)
    }
    fn value(&self, _: &Model, state: &State) -> f64 {
        state.x[self.node].z - self.value
    }
    fn tolerance(&self) -> f64 {
        self.tolerance
    }
}

/// The 45° bend of examples/bend_45.toml (tip at z = 53.37 at t = 1,
/// Simo & Vu-Quoc 1986), with tight tolerances.
fn bend() -> (Arc<Model>, unfold::analysis::StaticSettings, usize) {
    let mut input = {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/bend_45.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        unfold::io::model_file::parse_model(&text, &path).unwrap()
    };
    input.analysis.residual_tolerance = Some(1e-11);
    input.analysis.displacement_tolerance = Some(1e-11);
    input.analysis.rotation_tolerance = Some(1e-11);
    let model = Arc::new(Model::from_input(&input).unwrap());
    let settings = input.analyses().unwrap()[0].as_static().unwrap().clone();
    let tip = model.node_index(9).unwrap();
    (model, settings, tip)
}

/// The tip of the bend rises through z = 40 between two increments of
/// the plain run. Watched as an event with a tolerance of 1e-9 of its
/// value, the step across it is retried shortened (regula falsi on the
/// fraction of the step) until the tip lands within 4e-8 of 40; the event
/// is reported once, at that increment, which is written (an output
/// step), and the run goes on to t = 1 to the same end state as the plain
/// run (to 1e-10 of the tip's displacement: both end at the Newton
/// tolerance 1e-11 of the last increment's motion).
#[test]
fn a_step_lands_on_an_event() {
    let (model, settings, tip) = bend();
    let mut plain = History::with_states();
    let reference =
        StaticAnalysis::new(model.clone(), settings.clone()).run(model.initial_state(), &mut plain);
    assert!(reference.error.is_none(), "{:?}", reference.error);
    // the increments of the plain run that bracket z = 40
    let z: Vec<(f64, f64)> = plain.steps().map(|(i, s)| (i.time, s.x[tip].z)).collect();
    let k = z
        .iter()
        .position(|&(_, zk)| zk > 40.0)
        .expect("the tip passes 40");
    let (t_before, t_after) = (z[k - 1].0, z[k].0);

    let event = Reaches {
        node: tip,
        value: 40.0,
        tolerance: 4e-8,
    };
    let mut log = History::with_states();
    let outcome = StaticAnalysis::new(model.clone(), settings)
        .with_event(Box::new(event))
        .run(model.initial_state(), &mut log);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    println!(
        "events {:?}; {} retries; {} increments against {}",
        log.events, outcome.event_retries, outcome.increments, reference.increments
    );
    assert_eq!(log.events.len(), 1);
    let e = &log.events[0];
    assert!(e.value.abs() <= 4e-8, "landed at z − 40 = {:e}", e.value);
    assert!(e.time > t_before && e.time < t_after, "t = {}", e.time);
    assert!(outcome.event_retries >= 1);
    let (info, state) = log
        .steps()
        .find(|(i, _)| i.increment == e.increment)
        .expect("the event's increment");
    assert!(info.output);
    assert_eq!(info.time, e.time);
    assert!((state.x[tip].z - 40.0).abs() <= 4e-8);
    // the same end
    assert_eq!(outcome.time, 1.0);
    let motion = (reference.state.x[tip] - model.reference_x[tip]).norm();
    let dx = (outcome.state.x[tip] - reference.state.x[tip]).norm();
    assert!(dx <= 1e-10 * motion, "{dx:e}");
}

/// A hinge (a link hinged to the ground about z, pulled sideways at its
/// end by a constant 1 N) driven by driver A until t = 0.5 (its angle
/// rises to 0.2 rad at t = 0.4 and stays there), then by driver B, which
/// takes over the angle where it finds it and turns it by 0.6 rad per
/// unit of t. At t = 0.5, where the analysis lands (an output time), both
/// act: B repeats A (the same constraint, consistent with it), a
/// redundant equation that makes the tangent singular unless the rank of
/// the constraints is analysed again there (without it the step to 0.5
/// fails, "singular tangent: no stiffness for driver 4 unknown 1", down to
/// the smallest step); after it, A is released and B carries the load.
/// Expected: the rank analysed again at 0.5 and at the next step (the
/// active set changed twice), B's equation left out at 0.5 with a zero
/// multiplier, the hinge at 0.2 + 0.6 (t − 0.5) rad within the constraint
/// tolerance (1e-10 rad here) and the driving moment equal to the moment
/// of the load about the hinge (global equilibrium, to 1e-9 of it: the
/// residuals are held to 1e-10 of their fluxes or to their round-off,
/// ~ε·EA·L ≈ 1e-10 N here; measured 3e-14).
#[test]
fn a_driver_handing_over_has_the_rank_analysed_again() {
    let mut m = ModelBuilder::new("hand-over");
    let (hub, end) = (m.node([0.0; 3]), m.node([1.0, 0.0, 0.0]));
    let s = m.section(Section::diagonal(1e5, 4e4, 4e4, 1e2, 1e2, 1e2));
    m.add(Beam::between(hub, end, s).orientation([0.0, 0.0, 1.0]));
    let hinge = m.add(Joint::revolute(hub, Ground).axis([0.0, 0.0, 1.0]));
    let rise = m.curve(LoadCurve::points([[0.0, 0.0], [0.4, 0.4], [0.5, 0.4]]));
    let a = m.add(Driver::on(hinge).value(0.5).curve(rise).active(0.0, 0.5));
    let b = m.add(Driver::on(hinge).value(0.6).active(0.5, f64::INFINITY));
    m.add(Load::force(end, [0.0, 1.0, 0.0]).curve(CurveHandle::CONSTANT));
    m.analysis(
        Analysis::kinetostatic()
            .initial_increment(0.1)
            .output_times([0.5])
            .rotation_tolerance(1e-10)
            .displacement_tolerance(1e-10)
            .residual_tolerance(1e-10),
    );
    let model = Arc::new(m.build().unwrap());
    let settings = m.analyses().unwrap()[0].as_static().unwrap().clone();
    let mut log = History::with_states();
    let outcome = StaticAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut log);
    for n in &log.notes {
        println!("note: {n}");
    }
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    assert_eq!(outcome.rank_analyses, 2);
    assert!(
        log.notes
            .iter()
            .any(|n| n.contains("t = 0.5") && n.contains("1 redundant")),
        "{:?}",
        log.notes
    );

    let hinge_angle = |s: &State| model.results(hinge, s).get("angle").unwrap();
    let driver = |d: DriverHandle, s: &State, what: &str| model.results(d, s).get(what).unwrap();
    let (hub, end) = (model.node(hub), model.node(end));
    let mut at_half = false;
    let mut worst = 0.0f64;
    for (info, state) in log.steps() {
        let t = info.time;
        let expected = if t <= 0.4 {
            0.5 * t
        } else if t <= 0.5 {
            0.2
        } else {
            0.2 + 0.6 * (t - 0.5)
        };
        assert!(
            (hinge_angle(state) - expected).abs() < 1e-10,
            "t = {t}: {} vs {expected}",
            hinge_angle(state)
        );
        // the moment of the 1 N load about the hinge, balanced by the
        // driver acting at t
        let arm = state.x[end] - state.x[hub];
        let moment = arm.x * 1.0;
        let acting = if t <= 0.5 { a } else { b };
        let load = driver(acting, state, "load");
        worst = worst.max((load + moment).abs() / moment.abs());
        assert!(
            (load + moment).abs() <= 1e-9 * moment.abs(),
            "t = {t}: driver load {load}, moment of the load {moment}"
        );
        if t == 0.5 {
            at_half = true;
            // B repeats A there: left out, its multiplier zero
            assert_eq!(driver(b, state, "load"), 0.0);
        }
    }
    println!("largest relative imbalance of the driving moment {worst:.1e}");
    assert!(at_half, "the analysis landed on t = 0.5");
    assert_eq!(outcome.time, 1.0);
}
