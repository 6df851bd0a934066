//! Benchmark: numeric LU factorisation + solve with the simplicial and the
//! supernodal kernel of the sparse LU, on the tangents of
//! - a straight cantilever (1,000 / 10,000 / 100,000 beam elements),
//! - a chain of hinged links (100 / 1,000 / 10,000 revolute joints),
//! - the folding mast cell of `examples/mast_cell.rs` (folded state),
//! - the lattice mast of `examples/lattice_mast.rs` (8 / 30 / 99 bays),
//! - a square grid of beams (20², 40², 60² nodes),
//!
//! with the kernel the rule in `src/linalg.rs` picks; and, with `-- small`
//! alone, small systems (cantilevers of 1 to 320 beams, chains of 1 to 20
//! links) with the dense kernel besides. These are the measurements behind
//! that rule.
//!
//! Run with `cargo bench --bench lu_kernel` (`-- small` for the small
//! systems).

#[allow(dead_code)]
mod common;
#[allow(dead_code)]
#[path = "../examples/lattice_mast.rs"]
mod lattice_mast;
#[allow(dead_code)]
#[path = "../examples/mast_cell.rs"]
mod mast_cell;

use std::time::{Duration, Instant};

use unfold::analysis::newton::NewtonSolver;
use unfold::linalg::{LuKernel, SparseLu, SparseMatrix};
use unfold::model::Model;
use unfold::so3::Vec3;
use unfold::state::State;

use common::{cantilever, chain, grid, median};

/// A deformed state of `model` with non-zero multipliers, so that every
/// geometric term is in the tangent.
fn deformed(model: &Model) -> State {
    let mut state = model.initial_state();
    let n = state.x.len() as f64;
    for i in 0..state.x.len() {
        let s = i as f64 / n;
        let dx = Vec3::new(-0.01 * s, 0.05 * s * s, 0.001 * s);
        state.displace_node(i, &dx, &Vec3::new(0.01 * s, 0.02 * s, 0.3 * s));
    }
    for (k, v) in state.multipliers.iter_mut().enumerate() {
        *v = 1e-3 * (k % 7) as f64;
    }
    state
}

/// Median times of factor + solve of `a` with each of `kernels`,
/// alternated repetition by repetition (so that a change of load on the
/// machine weighs on all alike) for about a second (at least 5
/// repetitions each, at most `most`).
fn factor_solve_with<const K: usize>(
    a: &SparseMatrix,
    kernels: [LuKernel; K],
    most: usize,
) -> [f64; K] {
    let mut lu = kernels.map(|k| SparseLu::analyze_with(a, k).expect("symbolic analysis"));
    let b: Vec<f64> = (0..a.dim()).map(|i| 1.0 + (i % 5) as f64).collect();
    let mut x = b.clone();
    let mut times = [(); K].map(|_| Vec::new());
    let start = Instant::now();
    while times[0].len() < 5 || (start.elapsed() < Duration::from_secs(1) && times[0].len() < most)
    {
        for (lu, t) in lu.iter_mut().zip(times.iter_mut()) {
            x.copy_from_slice(&b);
            let t0 = Instant::now();
            lu.factor(a).expect("factorisation");
            lu.solve_in_place(&mut x).expect("solve");
            t.push(t0.elapsed().as_secs_f64());
        }
    }
    times.map(median)
}

/// Median times of factor + solve of `a` with the simplicial and the
/// supernodal kernel (see [`factor_solve_with`]).
fn factor_solve(a: &SparseMatrix) -> (f64, f64) {
    let [s, p] = factor_solve_with(a, [LuKernel::Simplicial, LuKernel::Supernodal], 201);
    (s, p)
}

/// The small systems: factor + solve with the three kernels, in µs.
fn small_systems() {
    println!("factor + solve in µs (median of repetitions)");
    println!(
        "{:<22} {:>8} {:>10} {:>11} {:>11} {:>11} {:>11}",
        "model", "unknowns", "nnz", "simplicial", "supernodal", "dense", "rule"
    );
    let models = [1, 2, 4, 10, 20, 80, 320]
        .map(|n| (format!("cantilever {n}"), cantilever(n)))
        .into_iter()
        .chain([1, 2, 5, 20].map(|n| (format!("joint chain {n}"), chain(n))));
    for (name, model) in models {
        let mut solver = NewtonSolver::new(&model);
        solver.assemble(&model, &deformed(&model), 1.0, true);
        let a = solver.tangent();
        let kernels = [LuKernel::Simplicial, LuKernel::Supernodal, LuKernel::Dense];
        let [s, p, d] = factor_solve_with(a, kernels, 20_001);
        let chosen = SparseLu::analyze(a).expect("symbolic analysis");
        println!(
            "{:<22} {:>8} {:>10} {:>11.2} {:>11.2} {:>11.2} {:>11}",
            name,
            a.dim(),
            a.nnz(),
            1e6 * s,
            1e6 * p,
            1e6 * d,
            format!("{:?}", chosen.kernel()),
        );
    }
}

fn report(name: &str, solver: &NewtonSolver) {
    let a = solver.tangent();
    let (simplicial, supernodal) = factor_solve(a);
    let chosen = SparseLu::analyze(a).expect("symbolic analysis");
    println!(
        "{:<22} {:>8} {:>10} {:>9.2} {:>11.3} {:>11.3} {:>7.2} {:>11}",
        name,
        a.dim(),
        a.nnz(),
        chosen.flops_per_entry(),
        1e3 * simplicial,
        1e3 * supernodal,
        supernodal / simplicial,
        format!("{:?}", chosen.kernel()),
    );
}

fn main() {
    if std::env::args().any(|a| a == "small") {
        small_systems();
        return;
    }
    println!(
        "threads: {}; factor + solve in ms (median of repetitions)",
        rayon::current_num_threads()
    );
    println!(
        "{:<22} {:>8} {:>10} {:>9} {:>11} {:>11} {:>7} {:>11}",
        "model", "unknowns", "nnz", "flops/nnz", "simplicial", "supernodal", "ratio", "rule"
    );
    for n in [1_000, 10_000, 100_000] {
        let model = cantilever(n);
        let mut solver = NewtonSolver::new(&model);
        solver.assemble(&model, &deformed(&model), 1.0, true);
        report(&format!("cantilever {n}"), &solver);
    }
    for n in [100, 1_000, 10_000] {
        let model = chain(n);
        let mut solver = NewtonSolver::new(&model);
        solver.assemble(&model, &deformed(&model), 1.0, true);
        report(&format!("joint chain {n}"), &solver);
    }
    {
        // the tangent of the folded cell, with the redundant constraints
        // left out as the analysis does
        let design = mast_cell::Design::default();
        let cell = mast_cell::build_design(&design, 24).expect("mast cell");
        let model = Model::from_input(&cell.input).expect("mast cell model");
        let run = mast_cell::run(&design, &cell, None, false).expect("mast cell run");
        let state = run.outcome.state;
        let mut solver = NewtonSolver::new(&model);
        solver.constraint_rank(&model, &state, state.time);
        solver.assemble(&model, &state, state.time, true);
        report("mast cell (folded)", &solver);
    }
    for bays in [8, 30, 99] {
        let model = Model::from_input(&lattice_mast::build(bays)).expect("lattice mast");
        let mut solver = NewtonSolver::new(&model);
        solver.assemble(&model, &deformed(&model), 1.0, true);
        report(&format!("lattice mast {bays}"), &solver);
    }
    for k in [20, 40, 60] {
        let model = grid(k);
        let mut solver = NewtonSolver::new(&model);
        solver.assemble(&model, &deformed(&model), 1.0, true);
        report(&format!("grid {k}x{k}"), &solver);
    }
}
