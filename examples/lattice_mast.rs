//! A deployed triangular lattice mast built by a Rust program.
//!
//! The program builds the model with the `unfold` API, writes it as a model
//! file (so that it can be inspected, edited and rerun with `unfold run`),
//! then runs the static analysis, writing the same result files as
//! `unfold run` (docs/results.md), and prints the tip motion.
//!
//! ```text
//! cargo run --release --example lattice_mast -- [bays] [output directory]
//! ```
//!
//! The mast (a 2 m class deployable boom in its deployed, locked state):
//! - a triangular cross-section inscribed in a circle of radius 0.15 m
//!   (side 0.26 m), bays 0.25 m high, 8 bays by default;
//! - three longerons, a triangle of battens at every level, and two
//!   crossed diagonals per face and bay, all joined rigidly at the nodes;
//! - longerons and battens: CFRP tubes Ø 12 × 1 mm (E = 120 GPa,
//!   G = 5 GPa); diagonals: steel cables modelled as Ø 2 mm rods
//!   (E = 200 GPa, G = 77 GPa), pretensioned by a 0.1 % shortening;
//! - base triangle clamped; at the top, a lateral force of 40 N and a
//!   torque of 6 N·m about the mast axis, in zero gravity.
//!
//! Every member is meshed with 2 elements so that its bending between
//! joints is represented.

use std::f64::consts::PI;
use std::path::PathBuf;

use unfold::analysis::StaticAnalysis;
use unfold::elements::ElementKind;
use unfold::io::run::{
    format_time, signal_name, stop_on_signals, Interrupted, Recorder, SignalEvent, Silent,
    StopRequest,
};
use unfold::model::builder::*;
use unfold::model::input::ModelInput;

/// Circular tube section of outer diameter `d`, wall `t` (solid for
/// `t ≥ d/2`), from `E` and `G`; shear factor 0.5 for thin tubes, 0.9 for
/// solid rods.
fn tube(e: f64, g: f64, d: f64, t: f64) -> Section {
    let ro = d / 2.0;
    let ri = (ro - t).max(0.0);
    let a = PI * (ro * ro - ri * ri);
    let i = PI / 4.0 * (ro.powi(4) - ri.powi(4));
    let kappa = if ri > 0.0 { 0.5 } else { 0.9 };
    Section::diagonal(
        e * a,
        kappa * g * a,
        kappa * g * a,
        g * 2.0 * i,
        e * i,
        e * i,
    )
}

/// The mast with `bays` bays, and the corners of its tip.
pub fn mast(bays: usize) -> (ModelBuilder, [NodeHandle; 3]) {
    let (radius, bay) = (0.15, 0.25);
    let mut m = ModelBuilder::new(format!("Triangular lattice mast, {bays} bays"));
    m.analysis(Analysis::statics().initial_increment(0.25));
    let cfrp_tube = m.section(tube(120e9, 5e9, 0.012, 0.001).named("cfrp_tube"));
    let cable = m.section(tube(200e9, 77e9, 0.002, 0.001).named("cable"));

    // corners of every level: node 100 j + k + 1 is corner k of level j
    let corner: Vec<[NodeHandle; 3]> = (0..=bays)
        .map(|j| {
            std::array::from_fn(|k| {
                let a = 2.0 * PI * k as f64 / 3.0;
                let x = [radius * a.cos(), radius * a.sin(), bay * j as f64];
                m.node_with_id((100 * j + k + 1) as Id, x)
            })
        })
        .collect();
    // members of 2 elements (local axis 2 by default: towards z, or x for
    // members along z); the cables pretensioned by a shortening
    for j in 0..bays {
        for k in 0..3 {
            let k1 = (k + 1) % 3;
            // longeron, batten of the upper triangle, crossed diagonals of
            // the face
            let (lower, upper) = (corner[j], corner[j + 1]);
            m.beam_line(lower[k], upper[k], 2, cfrp_tube);
            m.beam_line(upper[k], upper[k1], 2, cfrp_tube);
            for (a, b) in [(lower[k], upper[k1]), (lower[k1], upper[k])] {
                m.add(BeamLine::between(a, b, 2, cable).axial_strain(-1e-3));
            }
        }
    }
    // base battens; the base is clamped
    for k in 0..3 {
        m.beam_line(corner[0][k], corner[0][(k + 1) % 3], 2, cfrp_tube);
        m.fix(corner[0][k], Dofs::ALL);
    }
    // tip: lateral force along x shared by the three corners, and a torque
    // about z as three tangential forces
    let (force, torque) = (40.0, 6.0);
    let tip = corner[bays];
    for (k, node) in tip.into_iter().enumerate() {
        let a = 2.0 * PI * k as f64 / 3.0;
        let f_t = torque / (3.0 * radius);
        m.add(Load::force(
            node,
            [force / 3.0 - f_t * a.sin(), f_t * a.cos(), 0.0],
        ));
    }
    (m, tip)
}

/// The model file of the mast with `bays` bays.
pub fn build(bays: usize) -> ModelInput {
    mast(bays).0.into_input()
}

/// Most bays: about 39 nodes and elements each, so that the mast stays
/// well within the 500 000 of a model (docs/model-format.md, "Limits").
const MAX_BAYS: usize = 10_000;

const USAGE: &str = "usage: cargo run --release --example lattice_mast -- [BAYS] [OUTPUT_DIRECTORY]\n  BAYS: number of bays, 1 to 10000 (default 8)\n  OUTPUT_DIRECTORY: default results/lattice_mast";

/// The number of bays and the output directory from the command-line
/// arguments `args` (the program's name left out).
pub fn arguments(mut args: impl Iterator<Item = String>) -> Result<(usize, PathBuf), String> {
    let bays = match args.next() {
        None => 8,
        Some(a) => match a.parse::<usize>() {
            Ok(n) if (1..=MAX_BAYS).contains(&n) => n,
            _ => {
                return Err(format!(
                    "BAYS must be a whole number from 1 to {MAX_BAYS}, got \"{a}\""
                ))
            }
        },
    };
    let out = PathBuf::from(args.next().unwrap_or_else(|| "results/lattice_mast".into()));
    if let Some(extra) = args.next() {
        return Err(format!("unexpected argument \"{extra}\""));
    }
    Ok((bays, out))
}

fn main() -> std::process::ExitCode {
    let (bays, out) = match arguments(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(message) => {
            eprintln!("error: {message}\n{USAGE}");
            return std::process::ExitCode::from(2);
        }
    };
    match run(bays, &out) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::from(1)
        }
    }
}

/// Builds the mast, writes its model file, runs it into `out` and prints
/// the tip motion.
fn run(bays: usize, out: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let (mast, tip) = mast(bays);
    std::fs::create_dir_all(out)?;
    let file = out.join("lattice_mast.toml");
    std::fs::write(&file, mast.to_toml()?)?;
    println!("model written to {}", file.display());

    let model = std::sync::Arc::new(mast.build()?);
    let settings = mast.analyses()?.remove(0);
    let settings = settings.as_static().ok_or("a static analysis")?.clone();
    let mut analysis = StaticAnalysis::new(model.clone(), settings);
    // loads are elements of the model too: count them apart
    let loads = model
        .elements
        .iter()
        .filter(|e| e.kind() == ElementKind::NodalLoad)
        .count();
    println!(
        "{} nodes, {} beam elements, {} nodal loads, {} unknowns",
        model.n_nodes(),
        model.elements.len() - loads,
        loads,
        analysis.n_equations()
    );
    // the result files, log.txt and summary.json of `unfold run`; SIGINT
    // or SIGTERM stop after the current increment
    let stop = StopRequest::new();
    stop_on_signals(&stop, |event| match event {
        SignalEvent::Stopping(s) => eprintln!(
            "{}: stopping after the current increment (again to stop at once)",
            signal_name(s)
        ),
        SignalEvent::Ending(s) => eprintln!("{}: stopping at once", signal_name(s)),
    })?;
    let label = file.display().to_string();
    let mut recorder = Recorder::create(out, &label, &analysis, Silent)?.with_stop(&stop);
    let outcome = analysis.run(model.initial_state(), &mut recorder);
    let report = recorder.finish(&outcome);
    println!("{}", report.last_line);
    if let Some(e) = report.output_errors.into_iter().next() {
        return Err(e.into());
    }
    if let Some(e) = outcome.error {
        if let Some(i) = Interrupted::of(&e) {
            eprintln!(
                "{i} at t = {}; results up to it are kept",
                format_time(outcome.time)
            );
            std::process::exit(i.exit_code().into());
        }
        return Err(e.into());
    }
    let tip = tip.map(|n| model.node(n));
    let mean = |v: &[unfold::so3::Vec3]| tip.iter().map(|&i| v[i]).sum::<unfold::so3::Vec3>() / 3.0;
    let u = mean(&outcome.state.x) - mean(&model.reference_x);
    // twist: rotation of the top triangle about its centre, from corner 0
    let (c0, c) = (mean(&model.reference_x), mean(&outcome.state.x));
    let (r0, r) = (model.reference_x[tip[0]] - c0, outcome.state.x[tip[0]] - c);
    let twist = r0.x * r.y - r0.y * r.x;
    let twist = twist.atan2(r0.x * r.x + r0.y * r.y);
    println!(
        "{} increments, {} iterations; tip displacement ({:.3e}, {:.3e}, {:.3e}) m, twist {:.3e} rad; results in {}",
        outcome.increments,
        outcome.iterations,
        u.x,
        u.y,
        u.z,
        twist,
        out.display()
    );
    Ok(())
}
