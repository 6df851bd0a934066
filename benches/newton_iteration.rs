//! Benchmark: set-up, assembly and one Newton iteration (factorisation +
//! solve) on a straight cantilever of 1,000, 10,000 and 100,000 beam
//! elements.
//!
//! Run with `cargo bench --bench newton_iteration` (add `-- 1000 10000` to
//! choose sizes). For each size it reports
//! - the one-off set-up, phase by phase (median of repetitions): dof
//!   numbering (reverse Cuthill–McKee), sparsity pattern, scatter maps
//!   (element entries to matrix positions) and the symbolic analysis of the
//!   LU (ordering, elimination tree, supernodes);
//! - the median over repetitions of: residual + tangent assembly, numeric
//!   LU factorisation + solve, and the whole iteration; then how the time
//!   grows with size.

mod common;

use std::time::Instant;

use unfold::analysis::newton::NewtonSolver;
use unfold::assembly::{Assembler, TangentPattern};
use unfold::dofs::DofMap;
use unfold::linalg::SparseLu;
use unfold::so3::Vec3;

use common::{cantilever, median, sizes};

fn main() {
    let sizes = sizes(&[1_000, 10_000, 100_000]);
    println!(
        "threads: {}; times in ms (median of repetitions)",
        rayon::current_num_threads()
    );

    // set-up, phase by phase
    println!(
        "{:>9} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "elements", "unknowns", "nnz", "numbering", "pattern", "scatter", "symbolic", "setup"
    );
    for &n in &sizes {
        let model = cantilever(n);
        let reps = if n >= 100_000 { 3 } else { 7 };
        let mut phases = [vec![], vec![], vec![], vec![], vec![]];
        let (mut neq, mut nnz) = (0, 0);
        for _ in 0..reps {
            let t0 = Instant::now();
            let dofs = DofMap::new(&model);
            let t1 = Instant::now();
            let pattern = TangentPattern::new(&model, &dofs);
            let t2 = Instant::now();
            let assembler = Assembler::with_pattern(&model, &dofs, pattern);
            let t3 = Instant::now();
            let lu = SparseLu::analyze(&assembler.matrix).expect("symbolic analysis");
            let t4 = Instant::now();
            let times = [t1 - t0, t2 - t1, t3 - t2, t4 - t3, t4 - t0];
            for (p, t) in phases.iter_mut().zip(times) {
                p.push(t.as_secs_f64());
            }
            (neq, nnz) = (dofs.n_equations(), assembler.matrix.nnz());
            // dropped outside the timed region
            drop((lu, assembler));
        }
        let [a, b, c, d, e] = phases.map(median);
        println!(
            "{:>9} {:>9} {:>10} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>10.1}",
            n,
            neq,
            nnz,
            1e3 * a,
            1e3 * b,
            1e3 * c,
            1e3 * d,
            1e3 * e
        );
    }

    // Newton iteration
    println!(
        "{:>9} {:>9} {:>10} {:>10} {:>10}",
        "elements", "unknowns", "assembly", "factor+slv", "iteration"
    );
    let mut rows = Vec::new();
    for &n in &sizes {
        let model = cantilever(n);
        let mut solver = NewtonSolver::new(&model);

        // a deformed state, so that every geometric term is exercised
        let mut state = model.initial_state();
        for i in 0..model.n_nodes() {
            let s = i as f64 / n as f64;
            let dx = Vec3::new(-0.01 * s, 0.05 * s * s, -0.03 * s);
            state.displace_node(i, &dx, &Vec3::new(0.1 * s, 0.2 * s, 0.05 * s));
        }
        solver.assemble(&model, &state, 1.0, true);
        solver.analyze().expect("symbolic analysis");

        let reps = if n >= 100_000 { 5 } else { 11 };
        let (mut assembly, mut solve, mut total) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..reps {
            let ta = Instant::now();
            solver.assemble(&model, &state, 1.0, true);
            let a = ta.elapsed().as_secs_f64();
            let ts = Instant::now();
            solver.solve_linear_system().expect("solve");
            let s = ts.elapsed().as_secs_f64();
            assembly.push(a);
            solve.push(s);
            total.push(a + s);
        }
        let row = (n, median(assembly), median(solve), median(total));
        println!(
            "{:>9} {:>9} {:>10.1} {:>10.1} {:>10.1}",
            n,
            solver.dofs.n_equations(),
            1e3 * row.1,
            1e3 * row.2,
            1e3 * row.3
        );
        rows.push(row);
    }
    // growth: time ratio per size ratio (1.0 means linear)
    for w in rows.windows(2) {
        let (a, b) = (w[0], w[1]);
        let size = b.0 as f64 / a.0 as f64;
        println!(
            "{} → {} elements: iteration time × {:.2} for size × {:.0} (exponent {:.2})",
            a.0,
            b.0,
            b.3 / a.3,
            size,
            (b.3 / a.3).ln() / size.ln()
        );
    }
}
