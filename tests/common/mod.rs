//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod ball;
pub mod cli;
pub mod elliptic;
pub mod events;
pub mod flexible_hinge;
pub mod hinged_body;
pub mod hinged_panel;
pub mod pendulum;
pub mod quadrature;
pub mod rigid_body;
pub mod rolling_disc;
pub mod spring_latch;
pub mod stop_arm;

use std::sync::Arc;

use unfold::analysis::observers::History;
use unfold::analysis::{IncrementInfo, StaticAnalysis, StaticOutcome, StaticSettings};
use unfold::model::builder::{
    Analysis, BeamLine, BeamLineHandle, Driver, Ground, Joint, Load, ModelBuilder, Section,
    SectionHandle,
};
use unfold::model::input::ModelInput;
use unfold::model::Model;

/// Builds and runs a model (its first analysis, from the initial state),
/// returning it with the outcome and the converged increments.
pub fn run(input: &ModelInput) -> (Arc<Model>, StaticOutcome, Vec<IncrementInfo>) {
    let model = Arc::new(Model::from_input(input).expect("valid model"));
    let mut rec = History::new();
    let outcome = analysis(&model, input).run(model.initial_state(), &mut rec);
    (model, outcome, rec.increments)
}

/// The settings of the first analysis of `input`.
pub fn settings(input: &ModelInput) -> StaticSettings {
    let all = input.analyses().expect("valid analyses");
    all[0].as_static().expect("a static analysis").clone()
}

/// The first analysis of `input` on `model`.
pub fn analysis(model: &Arc<Model>, input: &ModelInput) -> StaticAnalysis {
    StaticAnalysis::new(model.clone(), settings(input))
}

/// A straight line of `n` beam elements of `section` between two new
/// nodes at `a` and `b` (added in this order, before the interior nodes).
pub fn line(
    m: &mut ModelBuilder,
    a: [f64; 3],
    b: [f64; 3],
    n: usize,
    section: SectionHandle,
    orientation: [f64; 3],
) -> BeamLineHandle {
    let (a, b) = (m.node(a), m.node(b));
    m.add(BeamLine::between(a, b, n, section).orientation(orientation))
}

/// Index of node `id` in the model.
pub fn node(model: &Model, id: u64) -> usize {
    model.node_index(id).expect("node exists")
}

/// Reads a model file of `examples/`.
pub fn example(name: &str) -> ModelInput {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    unfold::io::model_file::parse_model(&text, &path).unwrap()
}

/// The square section of the driven 45° bend.
pub fn bend_section() -> Section {
    Section::diagonal(
        1.0e7, 4.166667e6, 4.166667e6, 8.333333e5, 8.333333e5, 8.333333e5,
    )
}

/// The driven 45° bend: an arc of radius 100 over 45° in 8 elements of
/// `section`, hinged at its root about x and driven to 0.15 rad, a tip
/// force `p` along z, with static analyses ending at `sequence`
/// (increments of 0.125 throughout, tolerances 1e-11, tight enough to
/// compare end states at 1e-9).
pub fn driven_bend(section: Section, sequence: &[f64], p: f64) -> ModelBuilder {
    let mut m = ModelBuilder::new("driven 45° bend");
    let r = 100.0;
    let square = m.section(section);
    let root = m.node([0.0, 0.0, 0.0]);
    let tip = m.node([
        r * (0.25 * std::f64::consts::PI).sin(),
        r * (1.0 - (0.25 * std::f64::consts::PI).cos()),
        0.0,
    ]);
    m.add(
        BeamLine::between(root, tip, 8, square)
            .arc([0.0, r, 0.0])
            .orientation([0.0, 0.0, 1.0]),
    );
    let hinge = m.add(Joint::revolute(root, Ground).axis([1.0, 0.0, 0.0]));
    m.add(Driver::on(hinge).value(0.15));
    m.add(Load::force(tip, [0.0, 0.0, p]));
    for (k, &end) in sequence.iter().enumerate() {
        let a = Analysis::statics()
            .end_time(end)
            .initial_increment(0.125)
            .max_increment(0.125)
            .residual_tolerance(1e-11)
            .displacement_tolerance(1e-11)
            .rotation_tolerance(1e-11);
        if k == 0 {
            m.analysis(a);
        } else {
            m.then(a);
        }
    }
    m
}

/// The text of the model file `name` of tests/data.
pub fn model_text(name: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}
