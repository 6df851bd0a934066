//! The Rust model builders (`unfold::model::builder`): the ids they choose,
//! the model file they write, the validation they share with model files,
//! and the handles that find nodes and elements in the built model.

use unfold::analysis::{NoObserver, StaticAnalysis};
use unfold::elements::ElementKind;
use unfold::io::model_file::parse_model;
use unfold::model::builder::*;
use unfold::model::input::ModelInput;

/// A hinged two-link arm with a little of everything.
fn arm() -> (ModelBuilder, [NodeHandle; 3], JointHandle, DriverHandle) {
    let mut m = ModelBuilder::new("arm");
    let base = m.node([0.0, 0.0, 0.0]);
    let elbow = m.node_with_id(10, [1.0, 0.0, 0.0]);
    let hand = m.node([1.0, 1.0, 0.0]);
    let s = m.section(Section::diagonal(1e6, 4e5, 4e5, 80.0, 100.0, 100.0).mass_per_length(1.0));
    m.beam_line(base, elbow, 4, s);
    let forearm = m.node([1.0, 0.0, 0.0]);
    m.add(BeamLine::between(forearm, hand, 3, s).orientation([0.0, 0.0, 1.0]));
    let hinge = m.add(Joint::revolute(elbow, forearm).axis([0.0, 0.0, 1.0]));
    let ramp = m.curve(LoadCurve::points([[0.0, 0.0], [1.0, 1.0]]).named("ramp2"));
    let drive = m.add(Driver::on(hinge).angle(30.0, AngleUnit::Deg).curve(ramp));
    m.add(PointMass::at(hand, 0.5));
    m.fix(base, Dofs::ALL);
    m.add(Load::force(hand, [0.0, 0.0, -1.0]));
    m.analysis(Analysis::kinetostatic().initial_increment(0.25));
    (m, [base, elbow, hand], hinge, drive)
}

#[test]
fn ids_are_chosen_after_the_largest_used() {
    let (m, [base, elbow, hand], hinge, drive) = arm();
    let input = m.input();
    // nodes: 1, then 10 given, then 11 onwards; the first line's interior
    // nodes follow the hand (11) and the forearm node
    assert_eq!((base.id(), elbow.id(), hand.id()), (1, 10, 11));
    let ids: Vec<u64> = input.nodes.iter().map(|n| n.id).collect();
    assert_eq!(ids, vec![1, 10, 11, 15]);
    assert_eq!(input.beam_lines[0].first_node, Some(12));
    assert_eq!(input.beam_lines[1].first_node, Some(16));
    // element ids are shared by every kind but loads
    assert_eq!(input.beam_lines[0].first_element, Some(1));
    assert_eq!(input.beam_lines[1].first_element, Some(5));
    assert_eq!((hinge.id(), drive.id()), (8, 9));
    assert_eq!(input.point_masses[0].id, 10);
    assert_eq!(input.sections[0].name, "section_1");
    assert_eq!(input.drivers[0].curve.as_deref(), Some("ramp2"));
    assert_eq!(input.supports[0].fixed, vec!["all"]);
}

#[test]
fn components_are_written_by_the_names_of_the_file() {
    let mut m = ModelBuilder::new("supports");
    let n = m.node([0.0; 3]);
    m.fix(n, Dofs::ALL);
    m.fix(n, Dofs::TRANSLATIONS | Component::Rz);
    m.fix(n, [Component::X, Component::Z]);
    m.fix(n, Component::Rx | Component::Ry | Component::Rz);
    let fixed: Vec<Vec<String>> = m.input().supports.iter().map(|s| s.fixed.clone()).collect();
    assert_eq!(
        fixed,
        vec![
            vec!["all"],
            vec!["translations", "rz"],
            vec!["x", "z"],
            vec!["rotations"]
        ]
    );
}

/// The model written by the builder reads back to the same definition,
/// and the built model and the one read from the file run to the same
/// state, bit for bit.
#[test]
fn the_written_model_file_reads_back_and_runs_the_same() {
    let (m, [_, _, hand], _, _) = arm();
    let text = m.to_toml().unwrap();
    let back = parse_model(&text, std::path::Path::new("arm.toml")).unwrap();
    assert_eq!(&back, m.input());
    let built = std::sync::Arc::new(m.build().unwrap());
    let read = std::sync::Arc::new(unfold::model::Model::from_input(&back).unwrap());
    let settings = m.analyses().unwrap()[0].as_static().unwrap().clone();
    let a = StaticAnalysis::new(built.clone(), settings.clone())
        .run(built.initial_state(), &mut NoObserver);
    let b = StaticAnalysis::new(read.clone(), settings).run(read.initial_state(), &mut NoObserver);
    assert!(a.error.is_none(), "{:?}", a.error);
    assert_eq!(a.state, b.state);
    assert_eq!(built.node(hand), read.node(hand));
}

/// A builder model is checked by the validation of model files: the
/// same problems, named the same way.
#[test]
fn a_wrong_model_is_reported_as_its_file_would_be() {
    let mut m = ModelBuilder::new("wrong");
    let a = m.node([0.0; 3]);
    let b = m.node([1.0, 0.0, 0.0]);
    let s = m.section(Section::diagonal(1e6, 4e5, 4e5, 80.0, 100.0, -1.0).named("bad"));
    m.beam(a, a, s);
    m.add(Joint::revolute(a, b));
    m.fix(a, Dofs::NONE);
    let from_builder = m.build().unwrap_err().to_string();
    let text = m.to_toml().unwrap();
    let from_file = parse_model(&text, std::path::Path::new("wrong.toml"))
        .map(|input| {
            unfold::model::Model::from_input(&input)
                .unwrap_err()
                .to_string()
        })
        .unwrap();
    assert_eq!(from_builder, from_file);
    for expected in [
        "section \"bad\": EI3 must be positive, got -1",
        "beam 1: both ends are node 1",
        "joint 2: a revolute joint needs `axis`",
        "supports[1] (node 1): lists no component to fix",
    ] {
        assert!(from_builder.contains(expected), "{from_builder}");
    }
}

#[test]
fn handles_find_their_nodes_and_elements() {
    let (m, [base, _, hand], hinge, drive) = arm();
    let model = m.build().unwrap();
    assert_eq!(model.node(base), 0);
    assert_eq!(model.reference_position(hand).y, 1.0);
    let joint = model.element(hinge);
    assert_eq!((joint.kind(), joint.id()), (ElementKind::Joint, hinge.id()));
    let k = model.element_index(drive);
    assert_eq!(model.elements[k].kind(), ElementKind::Driver);
    // the results named as in drivers.csv, at the reference state: the
    // coordinate at zero, the target that of t = 0
    let state = model.initial_state();
    let r = model.results(drive, &state);
    assert_eq!(r.names[..3], ["coordinate", "target", "load"]);
    assert_eq!(r.get("coordinate"), Some(0.0));
    assert_eq!(r.get("no such quantity"), None);
    // a joint's coordinates by name, as in joints.csv: a revolute joint
    // has an angle, and no slide
    let r = model.results(hinge, &state);
    assert_eq!(r.names[..4], ["angle", "F1", "F2", "F3"]);
    assert_eq!(r.get("angle"), Some(0.0));
    assert_eq!(r.get("slide"), None);
}

#[test]
#[should_panic(expected = "node 99 is not in model \"arm\"")]
fn a_handle_of_another_model_is_refused() {
    let mut other = ModelBuilder::new("other");
    let far = other.node_with_id(99, [0.0; 3]);
    let (m, ..) = arm();
    m.build().unwrap().node(far);
}

/// `ModelInput::add_section` and the builder's section write the same
/// diagonal section.
#[test]
fn one_diagonal_section() {
    let mut input = ModelInput::new("s");
    input.add_section("s", [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let section = Section::diagonal(1.0, 2.0, 3.0, 4.0, 5.0, 6.0).into_input("s");
    assert_eq!(input.sections[0], section);
    assert_eq!(section.ei3, Some(6.0));
}

/// A sequence of analyses written by the builder is an array of
/// `[[analysis]]` tables, read back to the same definition and the same
/// settings, each starting where the one before ends (default increments
/// a tenth of each span); a single analysis is still written as one
/// `[analysis]` table.
#[test]
fn a_sequence_of_analyses_round_trips() {
    let (mut m, ..) = arm();
    m.analysis(Analysis::kinetostatic().end_time(1.0));
    let one = m.to_toml().unwrap();
    assert!(
        one.contains("\n[analysis]\n") && !one.contains("[[analysis]]"),
        "{one}"
    );
    m.then(Analysis::kinematic().end_time(3.0).output_times([1.5, 2.0]));
    let text = m.to_toml().unwrap();
    assert_eq!(text.matches("[[analysis]]").count(), 2, "{text}");
    let back = parse_model(&text, std::path::Path::new("arm.toml")).unwrap();
    assert_eq!(&back, m.input());
    let settings = back.analyses().unwrap();
    assert_eq!(settings.len(), 2);
    let second = settings[1].as_static().unwrap();
    assert!(second.kinematic);
    assert_eq!(second.end_time, 3.0);
    assert_eq!(second.initial_increment, 0.2);
    assert_eq!(second.output_times, vec![1.5, 2.0]);
    assert_eq!(settings, m.analyses().unwrap());
}

/// The dynamic step controls of the builder (`min_step`, `max_step`,
/// `error_tolerance`, `newton`) reach the settings as the fields of
/// `[analysis]` do, and are written to the model file.
#[test]
fn dynamic_step_controls_reach_the_settings() {
    let a = Analysis::dynamic()
        .end_time(2.0)
        .time_step(0.01)
        .min_step(1e-6)
        .max_step(0.02)
        .error_tolerance(1e-5)
        .newton("modified");
    let settings = a.clone().analysis_settings().unwrap();
    let d = settings.as_dynamic().unwrap();
    assert_eq!(
        (d.min_step, d.max_step, d.error_tolerance),
        (1e-6, 0.02, 1e-5)
    );
    assert_eq!(d.newton, unfold::analysis::NewtonMethod::Modified);
    let input = a.into_input();
    assert_eq!(input.max_step, Some(0.02));
    assert_eq!(input.newton.as_deref(), Some("modified"));
}
