//! Elements with extra unknowns (Lagrange multipliers): numbering,
//! assembly, the indefinite saddle-point system and the update all work
//! end to end. The constraint here is a minimal one written for the test:
//! it ties the z displacements of two nodes, `Φ = (z_b − Z_b) − (z_a − Z_a)
//! = 0`, with the Lagrangian term `λ Φ`.

mod common;

use unfold::analysis::NoObserver;
use unfold::elements::{Element, ElementKind, ElementOutput, EvalContext, Offsets};
use unfold::model::input::{Id, ModelInput};
use unfold::model::Model;
use unfold::state::State;

/// `λ Φ` with `Φ` the difference of the z displacements of two nodes.
struct TieZ {
    nodes: [usize; 2],
    z0: [f64; 2],
    /// Offset of λ in `state.multipliers`.
    extra: usize,
}

impl Element for TieZ {
    fn kind(&self) -> ElementKind {
        ElementKind::Constraint
    }
    fn id(&self) -> Id {
        1000
    }
    fn nodes(&self) -> &[usize] {
        &self.nodes
    }
    fn n_multipliers(&self) -> usize {
        1
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.extra = offsets.multipliers;
    }
    fn evaluate(&self, _ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        let n = self.n_local(); // 13: two nodes and λ
        let lambda = state.multipliers[self.extra];
        let [a, b] = self.nodes;
        let phi = (state.x[b].z - self.z0[1]) - (state.x[a].z - self.z0[0]);
        // r = ∂(λΦ)/∂q and the constraint equation Φ
        out.residual[2] -= lambda;
        out.residual[8] += lambda;
        out.residual[12] += phi;
        if let Some(t) = out.stiffness.as_deref_mut() {
            t[12 * n + 2] -= 1.0;
            t[12 * n + 8] += 1.0;
            t[2 * n + 12] -= 1.0;
            t[8 * n + 12] += 1.0;
        }
    }
}

/// Two parallel cantilevers, tips tied in z, one of them loaded: both
/// tips deflect by `P/(2k)` (k = 3EI/L³ + shear) and the multiplier is the
/// force carried across the tie, `P/2`.
///
/// Source: linear beam theory. Tolerance 0.5 %, as for the linear
/// cantilever (one-point integration with 10 elements: 0.25 %).
#[test]
fn tied_cantilevers_share_the_load_through_a_multiplier() {
    let (ei, ga) = (1.0e3, 4.0e6);
    let mut m = ModelInput::new("tied cantilevers");
    m.add_section("s", [1.0e7, ga, ga, 1.0e3, ei, ei]);
    m.add_node(1, [0.0, 0.0, 0.0]).add_node(2, [1.0, 0.0, 0.0]);
    m.add_node(3, [0.0, 1.0, 0.0]).add_node(4, [1.0, 1.0, 0.0]);
    m.add_beam_line([1, 2], 10, "s", Some([0.0, 1.0, 0.0]));
    m.add_beam_line([3, 4], 10, "s", Some([0.0, 1.0, 0.0]));
    m.fix(1, &["all"]).fix(3, &["all"]);
    let p = 1.0;
    m.add_load(2, [0.0, 0.0, -p], [0.0; 3]);
    m.analysis.initial_increment = Some(1.0);
    let mut model = Model::from_input(&m).unwrap();
    let (a, b) = (model.node_index(2).unwrap(), model.node_index(4).unwrap());
    model.push_element(Box::new(TieZ {
        nodes: [a, b],
        z0: [0.0, 0.0],
        extra: 0,
    }));

    let model = std::sync::Arc::new(model);
    let mut analysis = common::analysis(&model, &m);
    // 2 × 10 elements: 22 nodes, 2 clamped → 120 node unknowns, plus λ
    assert_eq!(analysis.n_equations(), 121);
    let outcome = analysis.run(model.initial_state(), &mut NoObserver);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);

    let s = &outcome.state;
    let expected = p / 2.0 * (1.0 / (3.0 * ei) + 1.0 / ga);
    let (wa, wb) = (-s.x[a].z, -s.x[b].z);
    println!(
        "tips {wa:.6e} {wb:.6e}, expected {expected:.6e}, λ = {:.6}",
        s.multipliers[0]
    );
    assert!((wa - wb).abs() < 1e-9 * expected, "the tie is violated");
    assert!((wa - expected).abs() < 5e-3 * expected);
    // the multiplier is the force passed from the loaded beam to the other
    assert!((s.multipliers[0].abs() - p / 2.0).abs() < 1e-6 * p);
}
