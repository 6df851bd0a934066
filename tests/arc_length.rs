//! Arc-length path control through the limit point of a snapping
//! structure.

mod common;

use unfold::analysis::{IncrementInfo, Observer, StaticAnalysis};
use unfold::joints::JointType;
use unfold::model::input::{JointInput, ModelInput};
use unfold::model::Model;
use unfold::state::State;

/// Keeps (t, apex deflection) at every converged increment.
#[derive(Default)]
struct Path {
    points: Vec<(f64, f64)>,
    apex: usize,
    height: f64,
}

impl Observer for Path {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        s: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.points
            .push((info.time, self.height - s.x[self.apex].y));
        Ok(())
    }
}

/// The von Mises truss: two pin-jointed bars from supports at (±b, 0) to
/// an apex at (0, h), loaded downwards at the apex. Each bar is one beam
/// element, hinged at both ends (revolute joints about z), so it carries
/// only its axial force `N = EA (l/l₀ − 1)` (the beam's axial strain is
/// the engineering strain of the chord). Equilibrium of the apex at
/// deflection `w`:
///
/// `P(w) = −2N (h − w)/l = 2 EA (1 − l/l₀) (h − w)/l`,  `l = √(b² + (h − w)²)`,
///
/// which rises to a limit load, falls through zero at `w = h` and becomes
/// negative (snap-through), then rises again past `w = 2h`. Load control
/// cannot pass the limit point; arc-length control follows the whole
/// path. Tolerance: 1e-6 of the limit load (the residual tolerance is
/// 1e-10 of the force flux).
#[test]
fn von_mises_truss_is_followed_through_its_limit_point() {
    let (b, h, ea): (f64, f64, f64) = (1.0, 0.1, 1.0e6);
    let p_ref = 2.0 * 2.0 * ea * h.powi(3) / (3.0 * 3f64.sqrt() * b.powi(3)); // ~2 × limit load
    let mut m = ModelInput::new("von Mises truss");
    m.add_section("bar", [ea, 4e5, 4e5, 1e3, 1e3, 1e3]);
    m.add_node(1, [-b, 0.0, 0.0]).add_node(2, [b, 0.0, 0.0]);
    m.add_node(3, [0.0, h, 0.0]).add_node(4, [0.0, h, 0.0]);
    m.add_beam(1, [1, 3], "bar", Some([0.0, 0.0, 1.0]));
    m.add_beam(2, [2, 4], "bar", Some([0.0, 0.0, 1.0]));
    let hinge = |id, nodes: Vec<u64>| JointInput {
        id,
        kind: JointType::Revolute,
        nodes,
        axis: Some([0.0, 0.0, 1.0]),
        ..Default::default()
    };
    m.joints.push(hinge(10, vec![1]));
    m.joints.push(hinge(11, vec![2]));
    m.joints.push(hinge(12, vec![3, 4]));
    m.add_load(3, [0.0, -p_ref, 0.0], [0.0; 3]);
    m.analysis.control = Some("arc_length".into());
    m.analysis.initial_increment = Some(0.05);
    m.analysis.max_increment = Some(0.2);
    m.analysis.residual_tolerance = Some(1e-10);
    m.analysis.displacement_tolerance = Some(1e-10);
    m.analysis.rotation_tolerance = Some(1e-10);

    let model = Model::from_input(&m).expect("valid model");
    let mut path = Path {
        apex: model.node_index(3).unwrap(),
        height: h,
        ..Default::default()
    };
    let outcome = StaticAnalysis::new(&model).run(&mut path);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    assert_eq!(outcome.time, 1.0);

    let l0 = (b * b + h * h).sqrt();
    let p_of = |w: f64| {
        let l = (b * b + (h - w).powi(2)).sqrt();
        2.0 * ea * (1.0 - l / l0) * (h - w) / l
    };
    let p_limit = path
        .points
        .iter()
        .map(|&(_, w)| p_of(w))
        .fold(0.0f64, f64::max);
    let mut worst = 0.0f64;
    for &(t, w) in &path.points {
        worst = worst.max((t * p_ref - p_of(w)).abs() / p_limit);
    }
    let t_min = path
        .points
        .iter()
        .map(|p| p.0)
        .fold(f64::INFINITY, f64::min);
    let w_end = path.points.last().unwrap().1;
    println!(
        "{} increments, {} iterations; worst |P − P(w)| = {worst:.2e} P_limit; t_min = {t_min:.3}, final w = {w_end:.4} (2h = {})",
        outcome.increments,
        outcome.iterations,
        2.0 * h
    );
    assert!(
        worst < 1e-6,
        "path off the equilibrium curve by {worst:.2e}"
    );
    // the path went through the unstable branch (negative load) and ended
    // inverted (w > 2h)
    assert!(t_min < -0.1, "the load never reversed: t_min = {t_min}");
    assert!(w_end > 2.0 * h, "not snapped through: w = {w_end}");
}
