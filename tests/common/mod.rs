//! Helpers shared by the integration tests.
#![allow(dead_code)]

use unfold::analysis::{IncrementInfo, Observer, StaticAnalysis, StaticOutcome};
use unfold::model::builder::{BeamLine, BeamLineHandle, ModelBuilder, SectionHandle};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// Keeps every converged increment.
#[derive(Default)]
pub struct Recorder {
    pub increments: Vec<IncrementInfo>,
}

impl Observer for Recorder {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        _: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.increments.push(info.clone());
        Ok(())
    }
}

/// Builds and runs a model, returning it with the outcome and the
/// converged increments.
pub fn run(input: &ModelInput) -> (Model, StaticOutcome, Vec<IncrementInfo>) {
    let model = Model::from_input(input).expect("valid model");
    let mut rec = Recorder::default();
    let outcome = StaticAnalysis::new(&model).run(&mut rec);
    (model, outcome, rec.increments)
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
