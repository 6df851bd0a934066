//! Benchmark: assembly and one Newton iteration (factorisation + solve) on
//! a straight cantilever of 1,000, 10,000 and 100,000 beam elements.
//!
//! Run with `cargo bench --bench newton_iteration` (add `-- 1000 10000` to
//! choose sizes). For each size it reports the one-off set-up (numbering,
//! sparse pattern, symbolic analysis) and the median over repetitions of:
//! residual + tangent assembly, numeric LU factorisation + solve, and the
//! whole iteration; then how the time grows with size.

use std::time::Instant;

use unfold::analysis::newton::NewtonSolver;
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::so3::{self, Vec3};

fn cantilever(n: usize) -> Model {
    let mut m = ModelInput::new(format!("cantilever of {n} elements"));
    let l = 10.0;
    m.add_node(1, [0.0; 3]);
    m.add_node(2, [l, 0.0, 0.0]);
    m.add_section("s", [2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5]);
    m.beam_lines.push(unfold::model::input::BeamLineInput {
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
        vec![1_000, 10_000, 100_000]
    } else {
        sizes
    };
    println!(
        "threads: {}; times in ms (median of repetitions)",
        rayon::current_num_threads()
    );
    println!(
        "{:>9} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "elements", "unknowns", "nnz", "setup", "symbolic", "assembly", "factor+slv", "iteration"
    );
    let mut rows = Vec::new();
    for &n in &sizes {
        let model = cantilever(n);
        let t0 = Instant::now();
        let mut solver = NewtonSolver::new(&model);
        let setup = t0.elapsed().as_secs_f64();

        // a deformed state, so that every geometric term is exercised
        let mut state = model.initial_state();
        for (i, (x, q)) in state.x.iter_mut().zip(state.q.iter_mut()).enumerate() {
            let s = i as f64 / n as f64;
            *x += Vec3::new(-0.01 * s, 0.05 * s * s, -0.03 * s);
            *q *= so3::exp(&Vec3::new(0.1 * s, 0.2 * s, 0.05 * s));
        }
        solver.assemble(&model, &state, 1.0, true);
        let t1 = Instant::now();
        solver.analyze().expect("symbolic analysis");
        let symbolic = t1.elapsed().as_secs_f64();

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
            "{:>9} {:>9} {:>10} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>10.1}",
            n,
            solver.dofs.n_equations(),
            solver.nnz(),
            1e3 * setup,
            1e3 * symbolic,
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
