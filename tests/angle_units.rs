//! Angles in degrees (`unit = "deg"`): a model written in degrees gives
//! the same model, and the same results, as the one written in radians,
//! wherever angles are given (node orientations, prescribed rotations,
//! drivers, joint springs).

mod common;

use std::f64::consts::PI;

use unfold::elements::ElementKind;
use unfold::joints::JointType;
use unfold::model::input::{
    AngleUnit, DriverInput, JointInput, JointSpringInput, ModelInput, PrescribedInput,
};
use unfold::so3::{self, Vec3};

/// Node 1 turned by 30° about z in its reference orientation, hinged to
/// the ground about z, with a linear torsion spring (k per unit angle,
/// unloaded at 10°) and a table spring (−1 N·m at −90°, +1 N·m at +90°),
/// driven to 45°; node 2, held in translation, turned 20° about x by a
/// prescribed rotation. Angles are written in `unit` (`None`: radians by
/// default).
fn model(unit: Option<AngleUnit>) -> ModelInput {
    let a = |deg: f64| match unit {
        Some(AngleUnit::Deg) => deg,
        _ => deg.to_radians(),
    };
    // 0.05 N·m per degree
    let k = match unit {
        Some(AngleUnit::Deg) => 0.05,
        _ => 0.05 * 180.0 / PI,
    };
    let mut m = ModelInput::new("angles");
    m.add_node(1, [0.0, 0.0, 0.0]);
    m.nodes[0].rotation = Some([0.0, 0.0, a(30.0)]);
    m.nodes[0].unit = unit;
    m.add_node(2, [1.0, 0.0, 0.0]);
    m.fix(2, &["translations"]);
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
        free_value: Some(a(10.0)),
        unit,
        ..Default::default()
    });
    m.joint_springs.push(JointSpringInput {
        id: 3,
        joint: 1,
        table: vec![[a(-90.0), -1.0], [a(90.0), 1.0]],
        unit,
        ..Default::default()
    });
    m.drivers.push(DriverInput {
        id: 4,
        joint: Some(1),
        value: a(45.0),
        unit,
        ..Default::default()
    });
    m.prescribed.push(PrescribedInput {
        node: 2,
        dof: None,
        value: None,
        rotation: Some([a(20.0), 0.0, 0.0]),
        unit,
        curve: None,
    });
    m
}

/// The driver's load at the end: the two springs at 45°,
/// `k (45° − 10°) + 1·(45°/90°)` = 0.05·35 + 0.5 = 2.25 N·m; node 2 turned
/// by 20° about x; node 1's reference orientation 30° about z. The same
/// in degrees and in radians (to 1e-12: the conversion is one rounding);
/// the load to 1e-8 (residual tolerance 1e-8 of the default settings).
#[test]
fn degrees_and_radians_give_the_same_model() {
    let mut loads = Vec::new();
    for unit in [None, Some(AngleUnit::Rad), Some(AngleUnit::Deg)] {
        let (model, outcome, _) = common::run(&model(unit));
        assert!(outcome.error.is_none(), "{unit:?}: {:?}", outcome.error);
        assert!(model.warnings.is_empty(), "{:?}", model.warnings);
        let n1 = common::node(&model, 1);
        let n2 = common::node(&model, 2);
        let z30 = so3::exp(&Vec3::new(0.0, 0.0, PI / 6.0));
        assert!(model.reference_q[n1].angle_to(&z30) < 1e-12);
        let x20 = so3::exp(&Vec3::new(PI / 9.0, 0.0, 0.0));
        assert!(outcome.state.q[n2].angle_to(&x20) < 1e-12, "{unit:?}");
        let ctx = model.context(outcome.time, unfold::elements::Need::RESIDUAL);
        let driver = model
            .elements
            .iter()
            .find(|e| e.kind() == ElementKind::Driver)
            .unwrap();
        let mut r = [0.0; 3];
        driver.results(&ctx, &outcome.state, &mut r);
        assert!((r[0] - PI / 4.0).abs() < 1e-9, "{unit:?}: angle {}", r[0]);
        loads.push(r[2]);
    }
    for l in &loads {
        assert!((l - 2.25).abs() < 1e-8, "{loads:?}");
    }
}

/// A unit on a coordinate that is not an angle is an error.
#[test]
fn a_unit_on_a_length_is_an_error() {
    let mut m = model(Some(AngleUnit::Deg));
    m.joints[0].kind = JointType::Prismatic;
    let errors = unfold::model::Model::from_input(&m)
        .unwrap_err()
        .to_string();
    for entity in ["joint spring 2", "joint spring 3", "driver 4"] {
        assert!(
            errors.contains(&format!(
                "{entity}: unit = \"deg\" applies to angles, but coordinate slide is a length"
            )),
            "{errors}"
        );
    }
}
