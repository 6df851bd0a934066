//! Helpers shared by the integration tests.
#![allow(dead_code)]

use unfold::analysis::{IncrementInfo, Observer, StaticAnalysis, StaticOutcome};
use unfold::model::input::{BeamLineInput, ModelInput};
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

/// A straight line of `n` beam elements from node 1 at `a` to node 2 at
/// `b`; interior nodes get ids 3, 4, ... in order from `a`.
pub fn line(
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
