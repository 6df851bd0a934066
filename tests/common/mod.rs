//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod elliptic;
pub mod quadrature;
pub mod rigid_body;

use std::sync::Arc;

use unfold::analysis::observers::History;
use unfold::analysis::{IncrementInfo, StaticAnalysis, StaticOutcome, StaticSettings};
use unfold::model::builder::{BeamLine, BeamLineHandle, ModelBuilder, SectionHandle};
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
