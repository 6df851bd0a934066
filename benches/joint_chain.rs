//! Benchmark: assembly and one Newton iteration of a hinged chain: `n`
//! beam links, each joined to the next by a revolute joint (5 multipliers
//! each), the first hinged to the ground, in a deformed configuration with
//! non-zero multipliers. Measures the cost of joint elements (exact
//! second derivatives by hyper-dual numbers) against that of the beams
//! and of the saddle-point LU.
//!
//! Run with `cargo bench --bench joint_chain` (add sizes, e.g. `-- 100 1000`).

mod common;

use std::time::Instant;

use unfold::analysis::newton::NewtonSolver;
use unfold::so3::Vec3;

use common::{chain, median, sizes};

fn main() {
    let sizes = sizes(&[100, 1_000, 10_000]);
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
        for i in 0..model.n_nodes() {
            let s = i as f64 / (2 * n) as f64;
            let dx = Vec3::new(-0.01 * s, 0.05 * s * s, 0.001 * s);
            state.displace_node(i, &dx, &Vec3::new(0.01 * s, 0.02 * s, 0.3 * s));
        }
        for (k, v) in state.multipliers.iter_mut().enumerate() {
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
        let ctx = model.context(1.0, unfold::elements::Need::STIFFNESS);
        let tj = Instant::now();
        let evals = 2000;
        for _ in 0..evals {
            r.fill(0.0);
            t.fill(0.0);
            joint.evaluate(
                &ctx,
                &state,
                &mut unfold::elements::ElementOutput::with_stiffness(&mut r, &mut t),
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
