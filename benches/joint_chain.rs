//! Benchmark: assembly and one Newton iteration of a hinged chain: `n`
//! beam links, each joined to the next by a revolute joint (5 multipliers
//! each), the first hinged to the ground, in a deformed configuration with
//! non-zero multipliers. Measures the cost of joint elements (exact
//! second derivatives by hyper-dual numbers) against that of the beams
//! and of the saddle-point LU.
//!
//! Run with `cargo bench --bench joint_chain` (add sizes, e.g. `-- 100 1000`).

use std::time::Instant;

use unfold::analysis::newton::NewtonSolver;
use unfold::joints::JointType;
use unfold::model::input::{JointInput, ModelInput};
use unfold::model::Model;
use unfold::so3::{self, Vec3};

fn chain(n: usize) -> Model {
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
        m.joint_springs
            .push(unfold::model::input::JointSpringInput {
                id: 200_000 + i as u64,
                joint: 100_000 + i as u64,
                stiffness: Some(10.0),
                ..Default::default()
            });
    }
    m.add_load(2 * n as u64, [0.0, 1.0, 0.0], [0.0; 3]);
    Model::from_input(&m).expect("valid benchmark model")
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![100, 1_000, 10_000]
    } else {
        sizes
    };
    println!(
        "threads: {}; times in ms (median of repetitions)",
        rayon::current_num_threads()
    );
    println!(
        "{:>7} {:>9} {:>10} {:>10} {:>10} {:>12} {:>10}",
        "joints", "unknowns", "nnz", "assembly", "factor+slv", "joint eval µs", "iteration"
    );
    for &n in &sizes {
        let model = chain(n);
        let mut solver = NewtonSolver::new(&model);
        let mut state = model.initial_state();
        for (i, (x, q)) in state.x.iter_mut().zip(state.q.iter_mut()).enumerate() {
            let s = i as f64 / (2 * n) as f64;
            *x += Vec3::new(-0.01 * s, 0.05 * s * s, 0.001 * s);
            *q *= so3::exp(&Vec3::new(0.01 * s, 0.02 * s, 0.3 * s));
        }
        for (k, v) in state.extra.iter_mut().enumerate() {
            *v = 1e-3 * (k % 7) as f64;
        }
        solver.assemble(&model, &state, 1.0, true);
        solver.analyze().expect("symbolic analysis");
        let reps = if n >= 10_000 { 5 } else { 11 };
        let (mut assembly, mut solve) = (Vec::new(), Vec::new());
        for _ in 0..reps {
            let ta = Instant::now();
            solver.assemble(&model, &state, 1.0, true);
            assembly.push(ta.elapsed().as_secs_f64());
            let ts = Instant::now();
            solver.solve_linear_system().expect("solve");
            solve.push(ts.elapsed().as_secs_f64());
        }
        // one joint element alone, sequentially
        let joint = model
            .elements
            .iter()
            .find(|e| e.kind() == unfold::elements::ElementKind::Joint && e.nodes().len() == 2)
            .expect("a joint");
        let k = joint.n_local();
        let (mut r, mut t) = (vec![0.0; k], vec![0.0; k * k]);
        let ctx = model.context(1.0, true);
        let tj = Instant::now();
        let evals = 2000;
        for _ in 0..evals {
            r.fill(0.0);
            t.fill(0.0);
            joint.evaluate(
                &ctx,
                &state,
                &mut unfold::elements::ElementOutput {
                    residual: &mut r,
                    tangent: &mut t,
                },
            );
        }
        let per_joint = tj.elapsed().as_secs_f64() / evals as f64;
        let (a, s) = (median(assembly), median(solve));
        println!(
            "{:>7} {:>9} {:>10} {:>10.2} {:>10.2} {:>12.1} {:>10.2}",
            n,
            solver.dofs.n_equations(),
            solver.nnz(),
            1e3 * a,
            1e3 * s,
            1e6 * per_joint,
            1e3 * (a + s)
        );
    }
}
