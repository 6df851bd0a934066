//! Craig–Bampton reduction of beam models (src/reduction): the reduced
//! body's frequencies, clamped at its boundary and free-free, against the
//! full model's (docs/theory.md §17.3).

use unfold::model::input::{ModelInput, SectionInput};
use unfold::model::Model;
use unfold::reduction::{reduce, FlexibleBody, ModeSelection, ReductionSettings};

/// A free straight beam of `n` elements, 2 m along x: EI = 2000 N·m²,
/// 1 kg/m (a slender aluminium tube), with the rotational inertia of a
/// thin tube.
fn beam(n: usize) -> ModelInput {
    let mut m = ModelInput::new("free beam");
    m.analysis.kind = "modal".into();
    m.add_node(1, [0.0, 0.0, 0.0]);
    m.add_node(2, [2.0, 0.0, 0.0]);
    m.sections.push(SectionInput {
        mass_per_length: Some(1.0),
        inertia_per_length: Some([2e-4, 1e-4, 1e-4]),
        ..SectionInput::diagonal("tube", [1e7, 4e6, 4e6, 1.5e3, 2e3, 2e3])
    });
    m.add_beam_line([1, 2], n, "tube", Some([0.0, 0.0, 1.0]));
    m
}

#[test]
fn beam_reduced_on_its_ends_keeps_its_frequencies() {
    let body = FlexibleBody::from_model(Model::from_input(&beam(40)).unwrap());
    let ends = vec![body.node_index(1).unwrap(), body.node_index(2).unwrap()];
    let r = reduce(
        body,
        &ReductionSettings::new(ends, ModeSelection::Count(10)),
    )
    .unwrap();
    let rep = &r.report;
    println!("{rep:#?}");
}
