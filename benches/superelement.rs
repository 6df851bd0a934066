//! Benchmark of superelements (docs/theory.md §18):
//!
//! 1. the Craig–Bampton reduction of a sandwich panel of n × n shells
//!    (100 × 100: 10,201 nodes, 61,206 dofs) to the middles of its four
//!    sides with four fixed-interface modes (the solar array's panels),
//!    the free-free check off;
//! 2. the solar array's deployment (examples/solar_array.toml and
//!    solar_array_rigid.toml): model build (reductions included) and the
//!    47 s of dynamics, without result files;
//! 3. the cost of a dynamic step of a cantilever reduced to a
//!    superelement (its two ends, 4 modes) against the same 40 beams.
//!
//! Run with `cargo bench --bench superelement` (add `-- 50 100` to choose
//! the panel sizes); times are medians of repetitions.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use unfold::analysis::{AnalysisSettings, DynamicAnalysis, DynamicSettings, NoObserver};
use unfold::io::model_file::{parse_model, read_model};
use unfold::model::Model;
use unfold::reduction::{reduce, FlexibleBody, ModeSelection, ReductionSettings};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A 1.2 m × 0.8 m sandwich panel of `n × n` shells with its side
/// midpoints named 900001–900004.
fn panel(n: usize) -> Model {
    let text = format!(
        r#"title = "panel"
[analysis]
type = "modal"
[[ply_materials]]
name = "cfrp"
E1 = 181e9
E2 = 10.3e9
nu12 = 0.28
G12 = 7.17e9
G13 = 7.17e9
G23 = 3.78e9
density = 1600.0
[[laminates]]
name = "face"
unit = "deg"
plies = [{{ material = "cfrp", thickness = 0.125e-3, angle = 0.0 }}, {{ material = "cfrp", thickness = 0.125e-3, angle = 90.0 }}]
[[laminates]]
name = "panel"
faces = "face"
core = {{ thickness = 20e-3, G13 = 190e6, G23 = 90e6, density = 32.0 }}
[[panels]]
name = "panel"
size = [1.2, 0.8]
elements = [{n}, {n}]
laminate = "panel"
first_node = 1
first_element = 1
node_ids = {{ west = 900001, east = 900002, south = 900003, north = 900004 }}
"#
    );
    let input = parse_model(&text, Path::new("panel.toml")).unwrap();
    Model::from_input(&input).unwrap_or_else(|e| panic!("{e}"))
}

fn reduction(n: usize) {
    let mut build = Vec::new();
    let mut times = Vec::new();
    let mut dofs = 0;
    for _ in 0..3 {
        let t0 = Instant::now();
        let body = FlexibleBody::from_model(panel(n));
        let t1 = Instant::now();
        dofs = body.n_dofs();
        let boundary = [900001, 900002, 900003, 900004]
            .map(|id| body.node_index(id).unwrap())
            .to_vec();
        let mut settings = ReductionSettings::new(boundary, ModeSelection::Count(4));
        settings.compare_free_free = false;
        let r = reduce(body, &settings).unwrap();
        let t2 = Instant::now();
        assert_eq!(r.n_modes(), 4);
        build.push((t1 - t0).as_secs_f64());
        times.push((t2 - t1).as_secs_f64());
    }
    println!(
        "panel {n} × {n}: {dofs} dofs; model and K, M {:.3} s; reduction to 4 nodes + 4 modes {:.3} s",
        median(build),
        median(times)
    );
}

fn dynamic_settings(path: &Path) -> (Arc<Model>, DynamicSettings) {
    let file = read_model(path).unwrap();
    let settings = match file.analyses.into_iter().next() {
        Some(AnalysisSettings::Dynamic(s)) => s,
        _ => panic!("a dynamic analysis"),
    };
    (file.model, settings)
}

fn array(name: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    let (mut build, mut run) = (Vec::new(), Vec::new());
    let mut steps = (0, 0);
    for _ in 0..3 {
        let t0 = Instant::now();
        let (model, settings) = dynamic_settings(&path);
        let t1 = Instant::now();
        let mut analysis = DynamicAnalysis::new(model.clone(), settings);
        let out = analysis.run(model.initial_state(), &mut NoObserver);
        let t2 = Instant::now();
        steps = (out.steps, out.iterations);
        build.push((t1 - t0).as_secs_f64());
        run.push((t2 - t1).as_secs_f64());
    }
    println!(
        "{name}: build {:.3} s, 47 s of deployment {:.3} s ({} steps, {} iterations)",
        median(build),
        median(run),
        steps.0,
        steps.1
    );
}

/// The cantilever of tests/superelements.rs in beams or as a superelement
/// on its ends: time per step of 200 fixed steps of 1 ms.
fn per_step(superelement: bool) -> f64 {
    let se = if superelement {
        "[[superelements]]\nid = 100\nelements = [LIST]\nboundary = [1, 2]\nmodes = 4\ncheck_frequencies = false\n"
            .replace("LIST", &(1..=40).map(|i| i.to_string()).collect::<Vec<_>>().join(", "))
    } else {
        String::new()
    };
    let text = format!(
        r#"title = "cantilever"
[analysis]
type = "dynamic"
end_time = 0.2
time_step = 1e-3
adaptive = false
[[sections]]
name = "s"
EA = 1.0e7
GA2 = 4.0e6
GA3 = 4.0e6
GJ = 1.5e3
EI2 = 2.0e3
EI3 = 2.0e3
mass_per_length = 1.0
inertia_per_length = [2e-4, 1e-4, 1e-4]
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
[[nodes]]
id = 2
x = [2.0, 0.0, 0.0]
[[beam_lines]]
nodes = [1, 2]
elements = 40
section = "s"
first_element = 1
first_node = 3
[[supports]]
node = 1
fixed = ["all"]
[[loads]]
node = 2
force = [0.0, 0.0, -10.0]
{se}"#
    );
    let input = parse_model(&text, Path::new("cantilever.toml")).unwrap();
    let model = Arc::new(Model::from_input(&input).unwrap());
    let settings = match input.analyses().unwrap().into_iter().next() {
        Some(AnalysisSettings::Dynamic(s)) => s,
        _ => unreachable!(),
    };
    let mut times = Vec::new();
    for _ in 0..3 {
        let t0 = Instant::now();
        let out = DynamicAnalysis::new(model.clone(), settings.clone())
            .run(model.initial_state(), &mut NoObserver);
        times.push(t0.elapsed().as_secs_f64() / out.steps as f64);
    }
    median(times)
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if args.is_empty() {
        vec![26, 50, 100]
    } else {
        args
    };
    for n in sizes {
        reduction(n);
    }
    array("solar_array.toml");
    array("solar_array_rigid.toml");
    let (beams, reduced) = (per_step(false), per_step(true));
    println!(
        "cantilever, 40 beams: {:.1} µs a step; as a superelement (2 nodes, 4 modes): {:.1} µs a step",
        1e6 * beams,
        1e6 * reduced
    );
}
