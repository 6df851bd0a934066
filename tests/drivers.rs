//! Drivers with an acting window: released after it, taking over the
//! coordinate where they find it when they start late.

use std::sync::Arc;

use unfold::analysis::observers::OnIncrement;
use unfold::analysis::{IncrementInfo, StaticAnalysis};
use unfold::elements::{ElementKind, Need};
use unfold::joints::JointType;
use unfold::model::input::{DriverInput, JointInput, JointSpringInput, ModelInput};
use unfold::model::Model;
use unfold::state::State;

/// (t, hinge angle, load of driver 1, load of driver 2) at a converged
/// state.
fn row(t: f64, model: &Model, s: &State) -> (f64, f64, f64, f64) {
    let ctx = model.context(t, Need::RESIDUAL);
    let mut row = (t, 0.0, 0.0, 0.0);
    let mut v = [0.0; 9];
    for e in &model.elements {
        match (e.kind(), e.id()) {
            (ElementKind::Joint, _) => {
                e.results(&ctx, s, &mut v);
                row.1 = v[0];
            }
            (ElementKind::Driver, 10) => {
                e.results(&ctx, s, &mut v[..3]);
                row.2 = v[2];
            }
            (ElementKind::Driver, 11) => {
                e.results(&ctx, s, &mut v[..3]);
                row.3 = v[2];
            }
            _ => {}
        }
    }
    row
}

/// A rigid link hinged to the ground with a torsion spring k. Driver 10
/// turns the hinge to 0.5 rad over t ∈ [0, 1] and is released after; the
/// spring then brings the link back to 0 (t = 2, no load). Driver 11
/// starts at t = 2 and turns the link by 0.3 rad more over t ∈ [2, 3]
/// from where it finds it. Expected (statics): angle = 0.5 t, load k·θ
/// for t ≤ 1; angle 0 and both loads 0 for 1 < t < 2; angle 0.3 (t − 2),
/// load k·θ for t ≥ 2. Tolerance 1e-9 rad and 1e-9 k (Newton tolerances
/// set to 1e-12).
#[test]
fn driver_acts_in_its_window_only() {
    let k = 20.0;
    let mut m = ModelInput::new("windowed drivers");
    m.add_node(1, [0.0, 0.0, 0.0]);
    m.joints.push(JointInput {
        id: 1,
        kind: JointType::Revolute,
        nodes: vec![1],
        axis: Some([0.0, 0.0, 1.0]),
        ..Default::default()
    });
    m.joint_springs.push(JointSpringInput {
        id: 2,
        joint: 1,
        stiffness: Some(k),
        ..Default::default()
    });
    m.drivers.push(DriverInput {
        id: 10,
        joint: Some(1),
        value: 0.5,
        active: Some([0.0, 1.0]),
        ..Default::default()
    });
    m.drivers.push(DriverInput {
        id: 11,
        joint: Some(1),
        value: 0.3,
        active: Some([2.0, f64::INFINITY]),
        ..Default::default()
    });
    m.analysis.end_time = 3.0;
    m.analysis.initial_increment = Some(0.25);
    m.analysis.max_increment = Some(0.25);
    m.analysis.displacement_tolerance = Some(1e-12);
    m.analysis.rotation_tolerance = Some(1e-12);
    m.analysis.residual_tolerance = Some(1e-12);
    // the link's node has no stiffness of its own besides the joints:
    // ground it in translation so that only the hinge turns
    m.fix(1, &["x", "y", "z"]);
    let model = Arc::new(Model::from_input(&m).expect("valid model"));
    let mut rows = Vec::new();
    let settings = m.analyses().unwrap()[0].as_static().unwrap().clone();
    let outcome = StaticAnalysis::new(model.clone(), settings).run(
        model.initial_state(),
        &mut OnIncrement(|i: &IncrementInfo, m: &Model, s: &State| rows.push(row(i.time, m, s))),
    );
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    assert_eq!(rows.len(), 13, "12 increments and the initial state");
    for &(t, angle, load1, load2) in &rows {
        let (expected, l1, l2) = if t <= 1.0 {
            (0.5 * t, k * 0.5 * t, 0.0)
        } else if t < 2.0 {
            (0.0, 0.0, 0.0)
        } else {
            (0.3 * (t - 2.0), 0.0, k * 0.3 * (t - 2.0))
        };
        println!("t {t:.2}: angle {angle:.12} (expected {expected}), loads {load1:.9} {load2:.9}");
        assert!(
            (angle - expected).abs() < 1e-9,
            "t = {t}: angle {angle}, expected {expected}"
        );
        assert!(
            (load1 - l1).abs() < 1e-9 * k,
            "t = {t}: driver 10 load {load1}, expected {l1}"
        );
        assert!(
            (load2 - l2).abs() < 1e-9 * k,
            "t = {t}: driver 11 load {load2}, expected {l2}"
        );
    }
}

/// A hinge driven along a smooth step (a quintic, zero rate and
/// acceleration at both ends) in a kinematic analysis: the angle follows
/// `value·s(τ)` exactly (tolerance 1e-10 rad, the constraint tolerance).
#[test]
fn smooth_step_curve_drives_a_hinge() {
    let text = r#"
[analysis]
type = "kinematic"
end_time = 2.0
initial_increment = 0.1
displacement_tolerance = 1e-12
rotation_tolerance = 1e-12

[[curves]]
name = "stroke"
function = "smooth_step"
start = 0.5
end = 1.5

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[joints]]
id = 1
type = "revolute"
nodes = [1]
axis = [0.0, 0.0, 1.0]

[[drivers]]
id = 2
joint = 1
value = 1.2
curve = "stroke"
"#;
    let input = unfold::io::model_file::parse_model(text, std::path::Path::new("smooth.toml"))
        .expect("valid model file");
    let model = Arc::new(Model::from_input(&input).expect("valid model"));
    let mut angles = Vec::new();
    let settings = input.analyses().unwrap()[0].as_static().unwrap().clone();
    let outcome = StaticAnalysis::new(model.clone(), settings).run(
        model.initial_state(),
        &mut OnIncrement(|i: &IncrementInfo, m: &Model, s: &State| {
            let mut v = [0.0; 9];
            m.elements[0].results(&m.context(i.time, Need::RESIDUAL), s, &mut v);
            angles.push((i.time, v[0]));
        }),
    );
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    for (t, angle) in angles {
        let tau = ((t - 0.5) / 1.0f64).clamp(0.0, 1.0);
        let expected = 1.2 * tau.powi(3) * (10.0 - 15.0 * tau + 6.0 * tau * tau);
        assert!(
            (angle - expected).abs() < 1e-10,
            "t = {t}: {angle} vs {expected}"
        );
    }
}
