//! Benchmark: a square sandwich panel of n × n shell elements (26, 50,
//! 100): building the model (the stiffness of every element is computed
//! once, when it is made), assembling the residual and the tangent at the
//! reference configuration and at a displaced one with rotations (where
//! every element takes `K·diag(I, T⁻¹(ψ))`), assembling the mass matrix
//! (modal analysis), and one factorisation and solve of the tangent.
//!
//! Run with `cargo bench --bench shell_assembly` (add `-- 100` to choose
//! sizes); times in ms, medians of repetitions.

mod common;

use std::sync::Arc;
use std::time::Instant;

use unfold::analysis::newton::NewtonSolver;
use unfold::assembly::Assembler;
use unfold::elements::Need;
use unfold::model::builder::*;
use unfold::model::Model;
use unfold::so3::Vec3;

use common::{median, sizes};

/// A 1 m square sandwich panel (carbon/epoxy [0/90] faces, 20 mm
/// honeycomb) of `n × n` elements, clamped along its west side.
fn panel(n: usize) -> ModelBuilder {
    let mut m = ModelBuilder::new(format!("panel of {n} × {n} shells"));
    let c = m
        .add(PlyMaterial::orthotropic(181e9, 10.3e9, 0.28, 7.17e9, 7.17e9, 3.78e9).density(1600.0));
    let face =
        m.add(Laminate::plies([(c, 0.125e-3, 0.0), (c, 0.125e-3, 90.0)]).unit(AngleUnit::Deg));
    let lam = m.add(Laminate::sandwich(
        face,
        Core::new(20e-3, 190e6, 90e6).density(32.0),
        face,
    ));
    let p = m.add(Panel::new([1.0, 1.0], [n, n], lam).pressure(10.0));
    for node in p.side(PanelSide::West) {
        m.fix(node, Dofs::ALL);
    }
    m
}

fn main() {
    let sizes = sizes(&[26, 50, 100]);
    println!(
        "threads: {}; times in ms (median of repetitions)",
        rayon::current_num_threads()
    );
    println!(
        "{:>9} {:>9} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "elements",
        "unknowns",
        "build",
        "K at ref",
        "K rotated",
        "mass",
        "factor+slv",
        "per elem µs"
    );
    for &n in &sizes {
        let builder = panel(n);
        let reps = if n >= 100 { 5 } else { 11 };
        let mut build = Vec::new();
        for _ in 0..reps.min(5) {
            let t = Instant::now();
            let model = builder.build().expect("valid panel");
            build.push(t.elapsed().as_secs_f64());
            drop(model);
        }
        let model: Arc<Model> = Arc::new(builder.build().unwrap());
        let mut solver = NewtonSolver::new(&model);
        let reference = model.initial_state();
        // a bent state: every node displaced and turned by up to 0.01 rad
        let mut bent = model.initial_state();
        for i in 0..model.n_nodes() {
            let x = model.reference_x[i];
            let w = 1e-3 * x.x * x.x;
            bent.displace_node(
                i,
                &Vec3::new(0.0, 0.0, w),
                &Vec3::new(1e-3 * x.y, -2e-3 * x.x, 1e-4),
            );
        }
        solver.assemble(&model, &reference, 1.0, true);
        solver.analyze().expect("symbolic analysis");
        let (mut at_ref, mut rotated, mut solve) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..reps {
            let t = Instant::now();
            solver.assemble(&model, &reference, 1.0, true);
            at_ref.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            solver.solve_linear_system().expect("solve");
            solve.push(t.elapsed().as_secs_f64());
            let t = Instant::now();
            solver.assemble(&model, &bent, 1.0, true);
            rotated.push(t.elapsed().as_secs_f64());
        }
        // the mass matrix, as a modal analysis assembles it
        let mut assembler = Assembler::new(&model, &solver.dofs);
        let mut matrix = assembler.matrix.clone();
        let ctx = model.context(0.0, Need::with_inertia(0.0, 1.0));
        let mut mass = Vec::new();
        for _ in 0..reps {
            let t = Instant::now();
            assembler.assemble_inertia(&model, &ctx, &reference, &mut matrix);
            mass.push(t.elapsed().as_secs_f64());
        }
        let elements = n * n;
        let k_ref = median(at_ref);
        println!(
            "{:>9} {:>9} {:>9.1} {:>10.1} {:>10.1} {:>10.1} {:>10.1} {:>10.2}",
            elements,
            solver.dofs.n_equations(),
            1e3 * median(build),
            1e3 * k_ref,
            1e3 * median(rotated),
            1e3 * median(mass),
            1e3 * median(solve),
            1e6 * k_ref / elements as f64
        );
    }
}
