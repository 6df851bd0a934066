//! Benchmark: time steps of the implicit dynamics (Lie-group
//! generalised-α, src/analysis/dynamics.rs) on a flexible beam pendulum of
//! 1,000 and 10,000 elements (100,000 on request: `-- 100000`), and the
//! kernels of its Newton iterations against those of a static one.
//!
//! Run with `cargo bench --bench dynamics` (add `-- 1000 10000 100000` to
//! choose sizes, `-- clamped` for a clamped end instead of the joint). The model: a 10 m steel-like beam (the section of
//! benches/newton_iteration.rs, with mass), pinned at one end by a revolute
//! joint to the ground, released from the horizontal under gravity, fixed
//! steps of 1 ms. For each size it reports
//! - per accepted step (median over the steps run): wall time, Newton
//!   iterations (corrections), heap allocations per step and per iteration
//!   (a counting global allocator; per iteration: between two iteration
//!   reports of the same step, i.e. solve, update, assembly, norms);
//! - the kernels on the state reached (median of repetitions): the dynamic
//!   assembly (residual with inertia forces, `S = β′M + γ′C + K T`), the
//!   static assembly (residual and stiffness) on the same state, the
//!   numeric LU factorisation, the triangular solves, and the static Newton
//!   iteration as benches/newton_iteration.rs times it
//!   (`NewtonSolver::assemble` + `solve_linear_system`);
//! - from the times of the iteration reports: the time of a step up to its
//!   first residual (predictor, first assembly), per correction (solve,
//!   update, assembly, convergence measures) and after its last residual
//!   (convergence test, acceptance);
//! - the split of a step: `(k + 1)` dynamic assemblies and `k`
//!   factorisations and solves for `k` corrections, the energy balance of
//!   the accepted step, and the rest (norms, predictor, updates, step
//!   control).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

use unfold::analysis::energy;
use unfold::analysis::newton::NewtonSolver;
use unfold::analysis::{
    CutbackInfo, DynamicAnalysis, DynamicSettings, GeneralizedAlpha, IncrementInfo, IterationInfo,
    Observer, Step,
};
use unfold::assembly::Assembler;
use unfold::dofs::DofMap;
use unfold::elements::{EvalContext, Need};
use unfold::linalg::SparseLu;
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::so3::{self, Vec3};
use unfold::state::State;

/// The system allocator, counting allocations and reallocations.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.load(Ordering::Relaxed)
}

/// Time step (s).
const H: f64 = 1e-3;

/// Newton's relative residual tolerance. The default 1e-8 is below the
/// round-off floor of these meshes: from rest, the first step stalls at a
/// relative residual of 3.2e-6 with 1,000 elements (the axial force of a
/// short stiff element, `EA (|x₂ − x₁|/l − 1)`, carries a round-off of
/// `ε EA |x|/l`, far above `ε` times the forces); the corrections'
/// criterion (1e-6 of the step's motion) then decides convergence.
const RESIDUAL_TOLERANCE: f64 = 1e-3;

/// The beam pendulum of `n` elements: 10 m along x, section of
/// benches/newton_iteration.rs (EA = 2.1e8 N, EI = 2.1e5 N·m²: a steel
/// tube of A = 1e-3 m², I = 1e-6 m⁴) with ρA = 7.85 kg/m, ρI = 7.85e-3
/// kg·m, ρJ = 2ρI; a revolute joint about y to the ground at x = 0
/// (`clamped`: a clamped end instead, no constraint equation); constant
/// gravity −9.81 z.
fn beam_pendulum(n: usize, steps: usize, clamped: bool) -> (Model, DynamicSettings) {
    let support = if clamped {
        "[[supports]]\nnode = 1\nfixed = [\"all\"]\n"
    } else {
        "[[joints]]\nid = 1\ntype = \"revolute\"\nnodes = [1]\naxis = [0.0, 1.0, 0.0]\n"
    };
    let text = format!(
        r#"
title = "beam pendulum of {n} elements"

[analysis]
type = "dynamic"
end_time = {end:?}
time_step = {H:?}
adaptive = false
rho_infinity = 0.9
residual_tolerance = {RESIDUAL_TOLERANCE:?}
output_every = 1000000

[[sections]]
name = "s"
EA = 2.1e8
GA2 = 8.1e7
GA3 = 8.1e7
GJ = 1.6e5
EI2 = 2.1e5
EI3 = 2.1e5
mass_per_length = 7.85
inertia_per_length = [1.57e-2, 7.85e-3, 7.85e-3]

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [10.0, 0.0, 0.0]

[[beam_lines]]
nodes = [1, 2]
elements = {n}
section = "s"
orientation = [0.0, 0.0, 1.0]
first_node = 3
first_element = 2

{support}
[[curves]]
name = "constant"
function = "linear"
offset = 1.0
slope = 0.0

[gravity]
acceleration = [0.0, 0.0, -9.81]
curve = "constant"
"#,
        end = steps as f64 * H,
    );
    let input: ModelInput = toml::from_str(&text).expect("valid benchmark model file");
    let model = Model::from_input(&input).expect("valid benchmark model");
    let settings = input.analyses().expect("valid analysis")[0]
        .as_dynamic()
        .expect("a dynamic analysis")
        .clone();
    (model, settings)
}

/// Allocation counts at each iteration report, and the iterations of each
/// accepted step.
#[derive(Default)]
struct Probe {
    /// (step, iteration, allocations so far, time)
    reports: Vec<(usize, usize, usize, Instant)>,
    iterations: Vec<usize>,
    /// The first cut-back: the benchmark motion must run at its step.
    cutback: Option<String>,
}

impl Observer for Probe {
    fn cutback(&mut self, info: &CutbackInfo) {
        self.cutback.get_or_insert_with(|| {
            format!("step from t = {} cut back: {}", info.time, info.reason)
        });
    }
    fn iteration(&mut self, info: &IterationInfo) {
        // reserved beforehand: recording does not allocate
        if self.reports.len() < self.reports.capacity() {
            self.reports.push((
                info.increment,
                info.iteration,
                allocations(),
                Instant::now(),
            ));
        }
    }
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        _: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        if info.increment > 0 && self.iterations.len() < self.iterations.capacity() {
            self.iterations.push(info.iterations);
        }
        Ok(())
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn sizes(default: &[usize]) -> Vec<usize> {
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

/// What was measured at one size.
struct Row {
    n: usize,
    unknowns: usize,
    step: f64,
    iterations: f64,
    dyn_assembly: f64,
    static_assembly: f64,
    factor: f64,
    solve: f64,
    static_iteration: f64,
    /// The energy balance of an accepted step.
    energy: f64,
}

fn main() {
    let sizes = sizes(&[1_000, 10_000]);
    let clamped = std::env::args().any(|a| a == "clamped");
    println!(
        "threads: {}; step h = {H} s, ρ∞ = 0.9, fixed steps; {}; times in ms",
        rayon::current_num_threads(),
        if clamped {
            "clamped beam"
        } else {
            "beam pinned by a revolute joint"
        }
    );
    let mut rows = Vec::new();
    for &n in &sizes {
        rows.push(measure(n, clamped));
    }

    println!();
    println!("split of a step: (k+1) dynamic assemblies + k (factorisation + solve) + energy balance + rest, k corrections per step");
    println!(
        "{:>9} {:>9} {:>8} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>8}",
        "elements",
        "unknowns",
        "step",
        "k",
        "assembly",
        "factor",
        "solve",
        "energy",
        "rest",
        "rest %"
    );
    for r in &rows {
        let k = r.iterations;
        let a = (k + 1.0) * r.dyn_assembly;
        let f = k * r.factor;
        let s = k * r.solve;
        let rest = r.step - a - f - s - r.energy;
        println!(
            "{:>9} {:>9} {:>8.2} {:>6.2} {:>10.2} {:>10.2} {:>10.2} {:>10.2} {:>10.2} {:>7.0}%",
            r.n,
            r.unknowns,
            1e3 * r.step,
            k,
            1e3 * a,
            1e3 * f,
            1e3 * s,
            1e3 * r.energy,
            1e3 * rest,
            100.0 * rest / r.step
        );
    }
    println!();
    println!("cost per Newton iteration, dynamic against static (same model and state)");
    println!(
        "{:>9} {:>12} {:>12} {:>12} {:>12} {:>8}",
        "elements", "dyn iter", "dyn kernels", "static iter", "assembly d/s", "ratio"
    );
    for r in &rows {
        // one iteration of a step: its share of the step time
        let per_iteration = r.step / r.iterations;
        let kernels = r.dyn_assembly + r.factor + r.solve;
        println!(
            "{:>9} {:>12.2} {:>12.2} {:>12.2} {:>12.2} {:>8.2}",
            r.n,
            1e3 * per_iteration,
            1e3 * kernels,
            1e3 * r.static_iteration,
            r.dyn_assembly / r.static_assembly,
            kernels / r.static_iteration
        );
    }
    for w in rows.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let size = b.n as f64 / a.n as f64;
        println!(
            "{} → {} elements: step time × {:.2} for size × {:.0} (exponent {:.2})",
            a.n,
            b.n,
            b.step / a.step,
            size,
            (b.step / a.step).ln() / size.ln()
        );
    }
}

fn measure(n: usize, clamped: bool) -> Row {
    let steps = if n >= 100_000 { 8 } else { 30 };
    let (model, settings) = beam_pendulum(n, steps, clamped);
    let model = Arc::new(model);

    // the analysis, step by step
    let t0 = Instant::now();
    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let t1 = Instant::now();
    let mut probe = Probe {
        reports: Vec::with_capacity(100 * steps + 100),
        iterations: Vec::with_capacity(steps + 10),
        cutback: None,
    };
    let mut step = analysis.start(model.initial_state(), &mut probe);
    let t2 = Instant::now();
    let mut times = Vec::with_capacity(steps);
    let mut step_allocations = Vec::with_capacity(steps);
    // (increment, start, end) of every accepted step
    let mut spans = Vec::with_capacity(steps);
    while let Step::Increment(_) = step {
        let a0 = allocations();
        let ts = Instant::now();
        step = analysis.advance(&mut probe);
        let te = Instant::now();
        let dt = (te - ts).as_secs_f64();
        if let Step::Increment(info) = &step {
            spans.push((info.increment, ts, te));
        }
        if let Some(why) = &probe.cutback {
            panic!("{n} elements: {why}");
        }
        if let Step::Increment(_) = step {
            times.push(dt);
            step_allocations.push(allocations() - a0);
        }
    }
    let state = analysis.state().expect("started").clone();
    // the iteration matrix of the analysis itself, with and without the
    // scaling of its constraint rows and multiplier columns (D8)
    let factor_time = |a: &unfold::linalg::SparseMatrix| {
        let mut lu = SparseLu::analyze(a).expect("symbolic analysis");
        let mut t = vec![];
        for _ in 0..5 {
            let ts = Instant::now();
            lu.factor(a).expect("factorisation");
            t.push(ts.elapsed().as_secs_f64());
        }
        median(t)
    };
    let scaled = analysis.iteration_matrix(H, true).expect("started");
    let unscaled = analysis.iteration_matrix(H, false).expect("started");
    let (f_scaled, f_unscaled) = (factor_time(&scaled), factor_time(&unscaled));
    drop((scaled, unscaled));
    let outcome = analysis.finish();
    assert!(
        outcome.error.is_none() && outcome.cutbacks == 0,
        "the benchmark motion runs at the fixed step: {:?}",
        outcome.error
    );
    // allocations between iteration reports of the same step
    let within: Vec<usize> = probe
        .reports
        .windows(2)
        .filter(|w| w[0].0 == w[1].0 && w[0].0 > 0)
        .map(|w| w[1].2 - w[0].2)
        .collect();
    // where a step's time goes, from the iteration reports: up to the
    // first residual (predictor, first assembly), per correction (solve,
    // update, assembly, convergence measures), after the last residual
    // (convergence test, acceptance: state copies, energy balance, output)
    let (mut lead, mut per_correction, mut tail) = (vec![], vec![], vec![]);
    for &(i, ts, te) in &spans {
        let mine: Vec<Instant> = probe
            .reports
            .iter()
            .filter(|r| r.0 == i)
            .map(|r| r.3)
            .collect();
        if let (Some(&first), Some(&last)) = (mine.first(), mine.last()) {
            lead.push((first - ts).as_secs_f64());
            tail.push((te - last).as_secs_f64());
            if mine.len() > 1 {
                per_correction.push((last - first).as_secs_f64() / (mine.len() - 1) as f64);
            }
        }
    }
    let iterations = probe.iterations.iter().sum::<usize>() as f64 / probe.iterations.len() as f64;
    let step_time = median(times);
    let unknowns = analysis.n_equations();
    println!();
    println!(
        "{n} elements: {unknowns} unknowns, {} stored entries; set-up {:.1} ms, start (initial accelerations) {:.1} ms",
        analysis.nnz(),
        1e3 * (t1 - t0).as_secs_f64(),
        1e3 * (t2 - t1).as_secs_f64()
    );
    println!(
        "  {} steps: {:.2} ms per step (median), {:.2} corrections per step (most {}), allocations per step {}–{}, per iteration {}–{}",
        probe.iterations.len(),
        1e3 * step_time,
        iterations,
        probe.iterations.iter().max().unwrap_or(&0),
        step_allocations.iter().min().unwrap_or(&0),
        step_allocations.iter().max().unwrap_or(&0),
        within.iter().min().unwrap_or(&0),
        within.iter().max().unwrap_or(&0),
    );
    println!(
        "  LU factorisation of the analysis's iteration matrix: {:.2} ms scaled (as solved), {:.2} ms unscaled",
        1e3 * f_scaled,
        1e3 * f_unscaled
    );
    println!(
        "  in a step (medians): up to the first residual {:.2} ms, per correction {:.2} ms, after the last residual {:.2} ms",
        1e3 * median(lead),
        1e3 * median(per_correction),
        1e3 * median(tail)
    );

    // kernels on the state reached
    let dofs = DofMap::new(&model);
    let mut assembler = Assembler::new(&model, &dofs);
    let scheme = GeneralizedAlpha::new(0.9);
    let t = state.time;
    let factors: Vec<_> = state
        .velocity
        .iter()
        .map(|v| so3::tangent(&(Vec3::new(v[3], v[4], v[5]) * H)))
        .collect();
    let dynamic = EvalContext {
        dynamics: true,
        ..model.context(
            t,
            Need::with_inertia(scheme.gamma_prime(H), scheme.beta_prime(H)),
        )
    };
    let statics = model.context(t, Need::STIFFNESS);
    assembler.assemble_factored(&model, &dynamic, &state, &factors);
    let mut lu = SparseLu::analyze(&assembler.matrix).expect("symbolic analysis");
    let mut rhs = vec![0.0; dofs.n_equations()];
    let reps = if n >= 100_000 { 5 } else { 15 };
    let (mut da, mut sa, mut fa, mut so) = (vec![], vec![], vec![], vec![]);
    for _ in 0..reps {
        let ts = Instant::now();
        assembler.assemble(&model, &statics, &state);
        sa.push(ts.elapsed().as_secs_f64());
        let ts = Instant::now();
        assembler.assemble_factored(&model, &dynamic, &state, &factors);
        da.push(ts.elapsed().as_secs_f64());
        for (eq, r) in rhs.iter_mut().enumerate() {
            *r = -assembler.residual[dofs.dof(eq)];
        }
        let ts = Instant::now();
        lu.factor(&assembler.matrix).expect("factorisation");
        fa.push(ts.elapsed().as_secs_f64());
        let ts = Instant::now();
        lu.solve_in_place(&mut rhs).expect("solve");
        so.push(ts.elapsed().as_secs_f64());
    }
    // the energies and powers recorded at every accepted step
    let mut en = vec![];
    for _ in 0..reps {
        let ts = Instant::now();
        let e = energy::energies(&model, &state);
        let p = energy::powers(&model, &state, Some(&assembler.residual));
        en.push(ts.elapsed().as_secs_f64());
        std::hint::black_box((e, p));
    }
    // the static Newton iteration of benches/newton_iteration.rs
    let mut solver = NewtonSolver::new(&model);
    solver.assemble(&model, &state, t, true);
    solver.analyze().expect("symbolic analysis");
    let mut st = vec![];
    for _ in 0..reps {
        let ts = Instant::now();
        solver.assemble(&model, &state, t, true);
        solver.solve_linear_system().expect("solve");
        st.push(ts.elapsed().as_secs_f64());
    }
    let row = Row {
        n,
        unknowns,
        step: step_time,
        iterations,
        dyn_assembly: median(da),
        static_assembly: median(sa),
        factor: median(fa),
        solve: median(so),
        static_iteration: median(st),
        energy: median(en),
    };
    println!(
        "  kernels: dynamic assembly {:.2} ms, static assembly {:.2} ms, LU factorisation {:.2} ms ({}), solve {:.2} ms, energy balance {:.2} ms; static Newton iteration {:.2} ms",
        1e3 * row.dyn_assembly,
        1e3 * row.static_assembly,
        1e3 * row.factor,
        format!("{:?}", lu.kernel()).to_lowercase(),
        1e3 * row.solve,
        1e3 * row.energy,
        1e3 * row.static_iteration
    );
    row
}
