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
use unfold::io::run::{
    signal_name, stop_on_signals, Interrupted, Recorder, SignalEvent, Silent, StopRequest,
};
use unfold::elements::ElementKind;
use unfold::model::input::{BeamLineInput, Id, LoadInput, ModelInput, SectionInput};
use unfold::model::Model;

/// Circular tube section of outer diameter `d`, wall `t` (solid for
/// `t ≥ d/2`), from `E` and `G`; shear factor 0.5 for thin tubes, 0.9 for
/// solid rods.
fn tube(name: &str, e: f64, g: f64, d: f64, t: f64) -> SectionInput {
    let ro = d / 2.0;
    let ri = (ro - t).max(0.0);
    let a = PI * (ro * ro - ri * ri);
    let i = PI / 4.0 * (ro.powi(4) - ri.powi(4));
    let kappa = if ri > 0.0 { 0.5 } else { 0.9 };
    SectionInput {
        name: name.into(),
        ea: Some(e * a),
        ga2: Some(kappa * g * a),
        ga3: Some(kappa * g * a),
        gj: Some(g * 2.0 * i),
        ei2: Some(e * i),
        ei3: Some(e * i),
        ..SectionInput::default()
    }
}

/// Node id of corner `k` (0, 1, 2) at level `j`.
fn corner(j: usize, k: usize) -> Id {
    (100 * j + k + 1) as Id
}

/// Builds the mast with `bays` bays.
pub fn build(bays: usize) -> ModelInput {
    let (radius, bay) = (0.15, 0.25);
    let mut m = ModelInput::new(format!("Triangular lattice mast, {bays} bays"));
    m.analysis.initial_increment = Some(0.25);
    m.sections.push(tube("cfrp_tube", 120e9, 5e9, 0.012, 0.001));
    m.sections.push(tube("cable", 200e9, 77e9, 0.002, 0.001));

    // corners of every level
    for j in 0..=bays {
        for k in 0..3 {
            let a = 2.0 * PI * k as f64 / 3.0;
            m.add_node(
                corner(j, k),
                [radius * a.cos(), radius * a.sin(), bay * j as f64],
            );
        }
    }
    // interior nodes and elements are numbered from 10000 up
    let mut next_node: Id = 10_000;
    let mut next_element: Id = 1;
    let mut member = |m: &mut ModelInput, a: Id, b: Id, section: &str, strain: Option<[f64; 6]>| {
        m.beam_lines.push(BeamLineInput {
            nodes: [a, b],
            elements: 2,
            section: section.into(),
            // local axis 2 towards the mast axis direction z, or x for
            // members along z
            orientation: None,
            first_node: Some(next_node),
            first_element: Some(next_element),
            arc_center: None,
            initial_strain: strain,
            initial_strain_curve: None,
        });
        next_node += 1;
        next_element += 2;
    };
    let pretension = Some([-1e-3, 0.0, 0.0, 0.0, 0.0, 0.0]);
    for j in 0..bays {
        for k in 0..3 {
            let k1 = (k + 1) % 3;
            // longeron, batten of the upper triangle, crossed diagonals of
            // the face
            member(&mut m, corner(j, k), corner(j + 1, k), "cfrp_tube", None);
            member(
                &mut m,
                corner(j + 1, k),
                corner(j + 1, k1),
                "cfrp_tube",
                None,
            );
            member(&mut m, corner(j, k), corner(j + 1, k1), "cable", pretension);
            member(&mut m, corner(j, k1), corner(j + 1, k), "cable", pretension);
        }
    }
    // base battens
    for k in 0..3 {
        member(
            &mut m,
            corner(0, k),
            corner(0, (k + 1) % 3),
            "cfrp_tube",
            None,
        );
        m.fix(corner(0, k), &["all"]);
    }
    // tip: lateral force along x shared by the three corners, and a torque
    // about z as three tangential forces
    let (force, torque) = (40.0, 6.0);
    for k in 0..3 {
        let a = 2.0 * PI * k as f64 / 3.0;
        let f_t = torque / (3.0 * radius);
        m.loads.push(LoadInput {
            node: corner(bays, k),
            force: Some([force / 3.0 - f_t * a.sin(), f_t * a.cos(), 0.0]),
            moment: None,
            follower: false,
            curve: None,
        });
    }
    m
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let bays: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(8);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "results/lattice_mast".into()));

    let input = build(bays);
    std::fs::create_dir_all(&out)?;
    let file = out.join("lattice_mast.toml");
    std::fs::write(&file, input.to_toml()?)?;
    println!("model written to {}", file.display());

    let model = Model::from_input(&input)?;
    let mut analysis = StaticAnalysis::new(&model);
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
    let mut recorder = Recorder::create(&out, &label, &model, &analysis, Silent)?.with_stop(&stop);
    let outcome = analysis.run(&mut recorder);
    let report = recorder.finish(&outcome);
    println!("{}", report.last_line);
    if let Some(e) = report.output_errors.into_iter().next() {
        return Err(e.into());
    }
    if let Some(e) = outcome.error {
        if let Some(i) = Interrupted::of(&e) {
            eprintln!("{i} at t = {}; results up to it are kept", outcome.time);
            std::process::exit(i.exit_code().into());
        }
        return Err(e.into());
    }
    let tip: Vec<usize> = (0..3)
        .map(|k| model.node_index(corner(bays, k)).unwrap())
        .collect();
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
