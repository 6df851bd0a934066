//! Models and helpers shared by the benchmarks.

use unfold::joints::JointType;
use unfold::model::input::{BeamLineInput, JointInput, JointSpringInput, ModelInput};
use unfold::model::Model;

/// A straight cantilever of `n` beam elements, 10 m long, clamped at one
/// end, with a force and a moment at the other.
#[allow(dead_code)]
pub fn cantilever(n: usize) -> Model {
    let mut m = ModelInput::new(format!("cantilever of {n} elements"));
    let l = 10.0;
    m.add_node(1, [0.0; 3]);
    m.add_node(2, [l, 0.0, 0.0]);
    m.add_section("s", [2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5]);
    m.beam_lines.push(BeamLineInput {
        nodes: [1, 2],
        elements: n,
        section: "s".into(),
        orientation: Some([0.0, 0.0, 1.0]),
        first_node: Some(3),
        first_element: Some(1),
        arc_center: None,
        initial_strain: None,
        initial_strain_curve: None,
    });
    m.fix(1, &["all"]);
    m.add_load(2, [0.0, 1.0, -1.0], [0.5, 0.0, 0.0]);
    Model::from_input(&m).expect("valid benchmark model")
}

/// A chain of `n` beam links, each joined to the next by a revolute joint
/// (5 multipliers each) with a hinge spring, the first hinged to the
/// ground, with a force at the free end.
#[allow(dead_code)]
pub fn chain(n: usize) -> Model {
    let mut m = ModelInput::new(format!("chain of {n} hinged links"));
    m.add_section("s", [2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5]);
    let l = 0.1;
    for i in 0..n {
        // link i: nodes 2i+1 (start) and 2i+2 (end)
        let x0 = l * i as f64;
        m.add_node(2 * i as u64 + 1, [x0, 0.0, 0.0]);
        m.add_node(2 * i as u64 + 2, [x0 + l, 0.0, 0.0]);
        m.add_beam(
            i as u64 + 1,
            [2 * i as u64 + 1, 2 * i as u64 + 2],
            "s",
            Some([0.0, 0.0, 1.0]),
        );
        let nodes = if i == 0 {
            vec![1]
        } else {
            vec![2 * i as u64, 2 * i as u64 + 1]
        };
        m.joints.push(JointInput {
            id: 100_000 + i as u64,
            kind: JointType::Revolute,
            nodes,
            axis: Some([0.0, 0.0, 1.0]),
            ..Default::default()
        });
    }
    // hinge springs keep the chain determinate
    for i in 0..n {
        m.joint_springs.push(JointSpringInput {
            id: 200_000 + i as u64,
            joint: 100_000 + i as u64,
            stiffness: Some(10.0),
            ..Default::default()
        });
    }
    m.add_load(2 * n as u64, [0.0, 1.0, 0.0], [0.0; 3]);
    Model::from_input(&m).expect("valid benchmark model")
}

/// Median of `v` (upper median for an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// Sizes given on the command line (`cargo bench --bench NAME -- 100
/// 1000`), or `default`.
pub fn sizes(default: &[usize]) -> Vec<usize> {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    if sizes.is_empty() {
        default.to_vec()
    } else {
        sizes
    }
}

/// A square grid of `k × k` nodes, 0.1 m apart, joined by beams along both
/// directions, clamped along one edge and loaded at the opposite corner: a
/// plate-like frame whose factors have wide fronts.
#[allow(dead_code)]
pub fn grid(k: usize) -> Model {
    let mut m = ModelInput::new(format!("grid of {k} x {k} nodes"));
    m.add_section("s", [2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5]);
    let id = |i: usize, j: usize| (i * k + j + 1) as u64;
    for i in 0..k {
        for j in 0..k {
            m.add_node(id(i, j), [0.1 * i as f64, 0.1 * j as f64, 0.0]);
        }
    }
    let mut e = 0;
    for i in 0..k {
        for j in 0..k {
            if i + 1 < k {
                e += 1;
                m.add_beam(e, [id(i, j), id(i + 1, j)], "s", Some([0.0, 0.0, 1.0]));
            }
            if j + 1 < k {
                e += 1;
                m.add_beam(e, [id(i, j), id(i, j + 1)], "s", Some([0.0, 0.0, 1.0]));
            }
        }
        m.fix(id(i, 0), &["all"]);
    }
    m.add_load(id(k - 1, k - 1), [0.0, 0.0, -1.0], [0.0; 3]);
    Model::from_input(&m).expect("valid benchmark model")
}
