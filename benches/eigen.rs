//! Benchmark: the eigen-solvers of modal analysis (`src/eigen.rs`) on the
//! pencils of `tests/pencils` — the first 20 modes of
//! - a fixed–fixed spring–mass chain and a planar beam-like pencil with
//!   constraints, singular mass (and, free, three rigid-body modes), of
//!   about 10,000 unknowns, by shift-invert Lanczos;
//! - the same pencils with about 2,000 unknowns, by the dense solver (and
//!   by Lanczos, for comparison).
//!
//! Run with `cargo bench --bench eigen`. Times are medians of repetitions
//! (wall clock, including the symmetrisation, the symbolic analysis and
//! the factorisation).

#[allow(dead_code)]
#[path = "../tests/pencils/mod.rs"]
mod pencils;

use std::time::Instant;

use unfold::eigen::{solve, EigenSettings, Method, ModalSolution, Pencil};
use unfold::linalg::SparseMatrix;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn run(
    name: &str,
    (k, m, multiplier): &(SparseMatrix, SparseMatrix, Vec<bool>),
    method: Method,
    reps: usize,
) -> ModalSolution {
    let pencil = Pencil {
        stiffness: k,
        mass: m,
        multiplier,
    };
    let settings = EigenSettings {
        method,
        ..EigenSettings::lowest(20)
    };
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..reps {
        let start = Instant::now();
        let sol = solve(&pencil, &settings).expect("modes");
        times.push(start.elapsed().as_secs_f64());
        last = Some(sol);
    }
    let sol = last.unwrap();
    let unknowns = multiplier.iter().filter(|&&q| !q).count();
    let residual = sol.modes.iter().map(|m| m.residual).fold(0.0, f64::max);
    let first = sol
        .modes
        .iter()
        .find(|m| !m.is_zero())
        .map_or(0.0, |m| m.omega_squared);
    println!(
        "{name:<34} {unknowns:>6} unknowns {:>3} constraints  {method:>8?}  {:>9.1} ms  \
         zero {}  ω²₁ {first:.6e}  ω²₂₀ {:.6e}  max residual {residual:.1e}  restarts {}  solves {}",
        multiplier.len() - unknowns,
        1e3 * median(times),
        sol.zero_modes,
        sol.modes[19].omega_squared,
        sol.restarts,
        sol.operator_applications,
    );
    sol
}

fn main() {
    println!("first 20 modes (median of the repetitions)");
    let big_chain = pencils::chain(10_000, 3.0e4, 2.5, true);
    let sol = run("chain, fixed–fixed", &big_chain, Method::Lanczos, 5);
    let exact = |j: usize| {
        let s = (j as f64 * std::f64::consts::PI / (2.0 * 10_001.0)).sin();
        4.0 * 3.0e4 / 2.5 * s * s
    };
    let err = sol
        .modes
        .iter()
        .enumerate()
        .map(|(j, m)| (m.omega_squared - exact(j + 1)).abs() / exact(j + 1))
        .fold(0.0, f64::max);
    println!("{:>34} largest error against the closed form {err:.1e}", "");
    run(
        "beam, pinned–supported",
        &pencils::beam(3_333, true, true, 7),
        Method::Lanczos,
        5,
    );
    run(
        "beam, free (3 rigid-body modes)",
        &pencils::beam(3_333, false, false, 7),
        Method::Lanczos,
        5,
    );

    for method in [Method::Dense, Method::Lanczos] {
        run(
            "beam, pinned–supported",
            &pencils::beam(333, true, true, 7),
            method,
            5,
        );
    }
    let chain = pencils::chain(2_000, 3.0e4, 2.5, true);
    let beam = pencils::beam(666, true, true, 7);
    let free = pencils::beam(666, false, false, 7);
    for method in [Method::Dense, Method::Lanczos] {
        let reps = if method == Method::Dense { 3 } else { 5 };
        run("chain, fixed–fixed", &chain, method, reps);
        run("beam, pinned–supported", &beam, method, reps);
        run("beam, free (3 rigid-body modes)", &free, method, reps);
    }
}
