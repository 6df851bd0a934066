//! Benchmark: one evaluation of a geometrically exact beam element as a
//! dynamic step asks for it: the residual with inertia forces, the
//! tangent stiffness and the inertia matrix (mass and gyroscopic terms),
//! on a bent and twisted element moving with velocities and accelerations
//! at both nodes; and, for comparison, the residual alone.
//!
//! Run with `cargo bench --bench beam_kernel`; prints nanoseconds per
//! evaluation (median of repetitions of 10,000 evaluations; `-- quick`
//! for five repetitions only).

#[allow(dead_code)]
mod common;

use std::hint::black_box;
use std::time::{Duration, Instant};

use unfold::elements::beam::{Beam, BeamSection, InitialStrain, SectionStiffness};
use unfold::elements::{Element, ElementOutput, Need};
use unfold::so3::{self, Rotation, Vec3};
use unfold::state::State;

use common::median;

/// Evaluations per timed repetition.
const BATCH: usize = 10_000;

/// A steel tube of 1 m between two nodes, with its mass and rotational
/// inertia.
fn beam() -> Beam {
    let section = BeamSection {
        stiffness: SectionStiffness::from_diagonal(&nalgebra::SVector::<f64, 6>::new(
            2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5,
        )),
        mass_per_length: 7.8,
        inertia_per_length: Vec3::new(2.0e-3, 1.0e-3, 1.0e-3),
        damping: Default::default(),
    };
    let x = [Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0)];
    let r = [Rotation::identity(); 2];
    let initial = InitialStrain::default();
    Beam::new(1, [0, 1], x, r, Vec3::new(0.0, 0.0, 1.0), section, initial).expect("a valid beam")
}

/// The element bent, twisted and stretched, moving.
fn moving_state() -> State {
    let x = vec![Vec3::new(0.01, -0.02, 0.0), Vec3::new(0.97, 0.15, -0.1)];
    let q = vec![
        so3::exp(&Vec3::new(0.1, -0.2, 0.3)),
        so3::exp(&Vec3::new(0.4, 0.1, 0.5)),
    ];
    let mut state = State::at_rest(0.0, x, q);
    state.velocity = vec![
        [0.1, -0.3, 0.2, 1.5, -0.7, 2.0],
        [0.4, 0.2, -0.1, -0.5, 0.9, 1.1],
    ];
    state.acceleration = vec![
        [2.0, 1.0, -3.0, 10.0, -4.0, 6.0],
        [-1.0, 0.5, 2.0, 3.0, 7.0, -2.0],
    ];
    state
}

/// Median nanoseconds per evaluation of `beam` at `state` with `need`.
fn time_per_evaluation(beam: &Beam, state: &State, need: Need, dynamics: bool) -> f64 {
    let curves = [];
    let ctx = unfold::elements::EvalContext {
        time: 0.0,
        curves: &curves,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        need,
        dynamics,
        scaling: Default::default(),
    };
    let mut residual = [0.0; 12];
    let mut stiffness = [0.0; 144];
    let mut inertia = [0.0; 144];
    let mut times = Vec::new();
    let start = Instant::now();
    // `-- quick`: five repetitions (for an instruction count under callgrind)
    let quick = std::env::args().any(|a| a == "quick");
    while times.len() < 5
        || (!quick && start.elapsed() < Duration::from_secs(2) && times.len() < 200)
    {
        let t0 = Instant::now();
        for _ in 0..BATCH {
            residual.fill(0.0);
            stiffness.fill(0.0);
            inertia.fill(0.0);
            let mut out = ElementOutput {
                residual: &mut residual,
                stiffness: need.stiffness.then_some(&mut stiffness[..]),
                inertia: need.inertia.map(|_| &mut inertia[..]),
            };
            beam.evaluate(black_box(&ctx), black_box(state), &mut out);
            black_box(&residual);
        }
        times.push(t0.elapsed().as_secs_f64() / BATCH as f64 * 1e9);
    }
    median(times)
}

fn main() {
    let beam = beam();
    let state = moving_state();
    // generalised-α weights of a step of 1 ms (γ' and β' of order 1/h, 1/h²)
    let full = time_per_evaluation(&beam, &state, Need::with_inertia(1.5e3, 1.0e6), true);
    let residual = time_per_evaluation(&beam, &state, Need::stiffness(false), true);
    println!("beam evaluation, residual + tangent + inertia matrix: {full:8.1} ns");
    println!("beam evaluation, residual alone (with inertia forces): {residual:8.1} ns");
}
