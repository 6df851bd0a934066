//! Benchmark: the deployment of the ERA structures of examples/era.rs
//! (paper §6.2) in dynamics without gravity, from folded to every
//! mid-hinge locked: one cell, the triangle of 4 cells, the platform of
//! 24 cells. No result files are written.
//!
//! Run with `cargo bench --bench era_platform` (add `-- cell triangle
//! platform` to choose; all three by default). For each structure it
//! reports the unknowns, the mean bandwidth, the steps (accepted,
//! rejected, retried to land on a lock), the Newton iterations, the lock
//! instants, the wall time and the processor time of the process over the
//! deployment (and the wall time to the last lock: deployed and locked),
//! and the growth of these from the cell.

#[allow(dead_code)]
#[path = "../examples/era.rs"]
mod era;

use std::time::Instant;

use unfold::model::Model;

use era::checks;
use era::deploy;
use era::design::Design;
use era::geometry::{Geometry, Structure};

/// Processor time (user and system) of this process so far (s), from
/// `/proc/self/stat` (Linux; `NaN` elsewhere).
fn cpu_time() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // the fields after the command name, which is in parentheses
    let fields: Vec<&str> = stat
        .rsplit_once(')')
        .map_or("", |(_, rest)| rest)
        .split_whitespace()
        .collect();
    let ticks = |k: usize| fields.get(k).and_then(|s| s.parse::<f64>().ok());
    // utime and stime are fields 14 and 15 of stat(5), 12 and 13 here;
    // clock ticks of 1/100 s
    match (ticks(11), ticks(12)) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}

struct Measured {
    name: String,
    cells: usize,
    unknowns: usize,
    bandwidth: f64,
    steps: usize,
    iterations: usize,
    wall: f64,
    cpu: f64,
}

fn measure(structure: Structure) -> Measured {
    let geometry = Geometry::new(&Design::default(), structure);
    let case = era::case(structure, 0.0);
    let built = deploy::model(&geometry, &case);
    let counts = checks::counts(&Model::from_input(&built.input).expect("the model"));
    let nominal = deploy::nominal(&geometry).expect("the nominal geometry");
    let (start, cpu) = (Instant::now(), cpu_time());
    let run = deploy::run(&built, &nominal, None, 0.1, false).expect("the deployment");
    let (wall, cpu) = (start.elapsed().as_secs_f64(), cpu_time() - cpu);
    let f = &run.figures;
    let locked = f.locks.iter().flatten().count();
    let (first, last) = f
        .locks
        .iter()
        .flatten()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    println!(
        "{}: {} cells, {} unknowns ({} multipliers), mean bandwidth {:.1}; to t = {:.3} s{}: {} steps ({} rejected, {} retried to land on a lock), {} iterations ({:.2} per step, {} more in rejected steps); {} of {} mid-hinges locked, from {:.4} to {:.4} s; locked geometry within {:.2e} m of the nominal; wall {:.2} s, processor {:.2} s ({:.2} ms per iteration)",
        geometry.name,
        geometry.layout.cells.len(),
        counts.unknowns,
        counts.multipliers,
        counts.mean_bandwidth,
        run.outcome.time,
        run.outcome
            .error
            .as_ref()
            .map_or(String::new(), |e| format!(" (stopped: {e})")),
        f.steps,
        f.rejected,
        f.event_retries,
        f.iterations,
        f.iterations as f64 / f.steps.max(1) as f64,
        f.wasted_iterations,
        locked,
        f.locks.len(),
        first,
        last,
        f.locked_geometry_error,
        wall,
        cpu,
        1e3 * wall / (f.iterations + f.wasted_iterations).max(1) as f64,
    );
    if let Some(w) = f.wall_time_to_last_lock {
        println!(
            "  deployed and locked: the last mid-hinge locked at t = {last:.4} s, {w:.2} s of wall time into the analysis (the rest of the wall time follows the locked structure to t = {:.3} s)",
            run.outcome.time
        );
    }
    let s = &run.outcome.linear_solver;
    println!(
        "  iteration matrix: {} LDLᵀ + {} LU factorisations, {} solves, {} GMRES iterations, {} fall-backs to the LU, {} matrices preconditioned by earlier LU factors; mass system: {} LDLᵀ + {} LU, {} solves, {} GMRES iterations",
        s.iteration_matrix.symmetric_factorisations,
        s.iteration_matrix.lu_factorisations,
        s.iteration_matrix.solves,
        s.iteration_matrix.iterations,
        s.iteration_matrix.fallbacks,
        s.iteration_matrix.reuses,
        s.mass_system.symmetric_factorisations,
        s.mass_system.lu_factorisations,
        s.mass_system.solves,
        s.mass_system.iterations,
    );
    Measured {
        name: geometry.name,
        cells: geometry.layout.cells.len(),
        unknowns: counts.unknowns,
        bandwidth: counts.mean_bandwidth,
        steps: f.steps,
        iterations: f.iterations + f.wasted_iterations,
        wall,
        cpu,
    }
}

fn main() {
    let chosen: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let all = ["cell", "triangle", "platform"];
    let names: Vec<&str> = if chosen.is_empty() {
        all.to_vec()
    } else {
        all.iter()
            .copied()
            .filter(|n| chosen.iter().any(|c| c == n))
            .collect()
    };
    let measured: Vec<Measured> = names
        .iter()
        .map(|n| {
            measure(match *n {
                "cell" => Structure::Cell,
                "triangle" => Structure::REDUCED,
                _ => Structure::PLATFORM,
            })
        })
        .collect();
    if let Some(cell) = measured.iter().find(|m| m.cells == 1) {
        for m in measured.iter().filter(|m| m.cells > 1) {
            println!(
                "{} against the cell: {}× the cells, {:.1}× the unknowns, {:.1}× the mean bandwidth, {:.2}× the steps, {:.2}× the iterations, {:.1}× the wall time, {:.1}× the processor time ({:.1}× per iteration)",
                m.name,
                m.cells,
                m.unknowns as f64 / cell.unknowns as f64,
                m.bandwidth / cell.bandwidth,
                m.steps as f64 / cell.steps as f64,
                m.iterations as f64 / cell.iterations as f64,
                m.wall / cell.wall,
                m.cpu / cell.cpu,
                (m.cpu / m.iterations as f64) / (cell.cpu / cell.iterations as f64),
            );
        }
    }
}
