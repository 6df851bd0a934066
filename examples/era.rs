//! The ERA deployable platform flown on MIR (Cardona, §6.2): one cell, or
//! the hexagon of 24 cells, built with the `unfold` model builders,
//! checked as a mechanism and as a structure, and deployed through its
//! mid-hinges.
//!
//! ```text
//! cargo run --release --example era -- [cell|platform] [output directory] [increments]
//! ```
//!
//! The program
//! 1. builds the structure deployed (mid-hinges locked) and folded (the
//!    deployment: every mid-hinge driven open), and writes both model
//!    files (`era_<structure>_deployed.toml`, `era_<structure>_deployment.toml`);
//! 2. checks the design: the rank of the constraints of the rigid-link
//!    model (no motion left when the mid-hinges are locked, three per
//!    longeron less three when they are free), the zero modes of the
//!    stiffness of the flexible model free in space, the regular tangent
//!    of the clamped structure; and counts the unknowns and the mean
//!    bandwidth;
//! 3. runs the deployment (kinetostatic, flexible members), writes the
//!    result files (VTK for ParaView, CSV, `summary.json`) into
//!    `deployment/`, and a drawing of the folded, half-open and deployed
//!    configurations (`era_<structure>.png`, `.svg`).
//!
//! `examples/era.md` describes the design, every parameter and the
//! figures. Dynamics, the nonlinear hinge law with its hysteresis and the
//! latches are not modelled yet: the mid-hinge springs are linear
//! stand-ins (`era/hinge.rs`).

#[path = "era/checks.rs"]
pub mod checks;
#[path = "era/deploy.rs"]
pub mod deploy;
#[path = "era/design.rs"]
pub mod design;
#[path = "era/geometry.rs"]
pub mod geometry;
#[path = "era/hinge.rs"]
pub mod hinge;
#[path = "era/model.rs"]
pub mod model;
#[path = "era/picture.rs"]
pub mod picture;

use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::Instant;

use unfold::analysis::preflight;
use unfold::model::Model;

use design::Design;
use geometry::{Geometry, Structure};
use hinge::Hinges;
use model::Members;

/// Times (load parameter) of the configurations drawn.
pub const DRAWN: [f64; 3] = [0.0, 0.5, 1.0];

/// What a run of the program found.
#[derive(Clone, Debug)]
pub struct Report {
    /// Counts of the deployed structure.
    pub counts: checks::Counts,
    /// Rank of the rigid-link model, deployed, mid-hinges locked.
    pub locked: checks::Rank,
    /// Rank of the rigid-link model, folded, mid-hinges free.
    pub free: checks::Rank,
    /// Zero modes of the stiffness of the deployed structure, locked and
    /// clamped.
    pub zero_modes_locked: usize,
    /// Lowest non-zero stiffness eigenvalue of the locked structure
    /// ([`checks::zero_modes`], N/m).
    pub softest: f64,
    /// The deployment.
    pub deployment: deploy::Figures,
    /// Its last increment.
    pub last: deploy::Record,
    /// Largest force and moments in a member along the deployment (N, N·m).
    pub peak: (f64, f64, f64),
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Wall time of each phase (s): set-up and checks, deployment,
    /// drawings.
    pub timings: [f64; 3],
}

/// Runs the program for `structure` with `increments` increments,
/// writing into `out`; with `log`, prints as it goes.
pub fn run(
    structure: Structure,
    out: &Path,
    increments: usize,
    log: bool,
) -> Result<Report, Box<dyn Error>> {
    let say = |s: String| {
        if log {
            println!("{s}");
        }
    };
    let start = Instant::now();
    let design = Design::default();
    let geometry = Geometry::new(&design, structure);
    let name = &geometry.name;
    say(describe(&geometry));
    std::fs::create_dir_all(out)?;
    let mut files = Vec::new();

    // the two models
    let deployment = deploy::model(&geometry, Members::Flexible, increments);
    let deployed = deploy::deployed(&geometry);
    for (built, what) in [(&deployed, "deployed"), (&deployment, "deployment")] {
        let file = out.join(format!("era_{name}_{what}.toml"));
        std::fs::write(&file, built.input.to_toml()?)?;
        say(format!("model written to {}", file.display()));
        files.push(file);
    }

    // counts
    let model = Model::from_input(&deployed.input)?;
    let counts = checks::counts(&model);
    say(format!(
        "{} nodes, {} unknowns ({} node components, {} multipliers), mean bandwidth {:.1} numbered by reverse Cuthill–McKee, {:.1} as built",
        counts.nodes,
        counts.unknowns,
        counts.unknowns - counts.multipliers,
        counts.multipliers,
        counts.mean_bandwidth,
        counts.mean_bandwidth_as_built
    ));

    // the mechanism and the structure
    let locked = checks::rank(&geometry, 1.0, Hinges::Locked)?;
    let free = checks::rank(&geometry, design.folded_scale, Hinges::Free)?;
    say(format!(
        "rigid links: mid-hinges locked, deployed: {} free motions ({} redundant equations of {} unknowns); mid-hinges free, folded: {} free motions",
        locked.free_motions,
        locked.redundant.unwrap_or(0),
        locked.unknowns,
        free.free_motions
    ));
    let clamped = preflight::check(&model)?;
    say(format!(
        "flexible, deployed, locked, clamped: regular tangent, {} free motions of the joints alone (beam nodes)",
        clamped.free_motions
    ));
    let modes = checks::zero_modes(&model, 6)?;
    let softest = modes
        .modes
        .iter()
        .find(|m| !m.is_zero())
        .map_or(f64::NAN, |m| m.omega_squared);
    say(format!(
        "flexible, deployed, locked, clamped: {} zero modes of the stiffness; softest deformation {:.3e} N/m",
        modes.zero_modes, softest
    ));
    let setup = start.elapsed().as_secs_f64();

    // the deployment
    let start = Instant::now();
    let dir = out.join("deployment");
    let file = format!("era_{name}_deployment.toml");
    let run = deploy::run(&geometry, &deployment, Some((&dir, &file)), &DRAWN, log)?;
    if let Some(e) = &run.outcome.error {
        return Err(format!("the deployment stopped at t = {}: {e}", run.outcome.time).into());
    }
    let f = &run.figures;
    let last = run.records.last().expect("increment 0").clone();
    let peak = run.records.iter().fold((0.0f64, 0.0f64, 0.0f64), |p, r| {
        (p.0.max(r.axial), p.1.max(r.bending), p.2.max(r.torsion))
    });
    say(format!(
        "deployment: {} unknowns, {} increments, {:.2} iterations per increment (at most {}), {} cut-backs, {:.3} s; results in {}",
        f.unknowns,
        f.increments,
        f.iterations_per_increment,
        f.max_iterations,
        f.cutbacks,
        f.wall_time,
        dir.display()
    ));
    say(format!(
        "deployed: longerons within {:.2e} m of the design, corner bodies turned by {:.2e} rad; largest in a member along the way: N {:.2e} N, M {:.2e} N·m, T {:.2e} N·m",
        last.longeron_error, last.corner_rotation, peak.0, peak.1, peak.2
    ));
    let deploying = start.elapsed().as_secs_f64();

    // drawings
    let start = Instant::now();
    let model = Model::from_input(&deployment.input)?;
    let panels = run
        .snapshots
        .iter()
        .map(|(r, state)| {
            let label = format!(
                "t = {:.2}: mid-hinges open {:.0}°, scale {:.2}",
                r.time,
                r.opening.to_degrees(),
                r.scale
            );
            picture::panel(&deployment, &model, state, &label)
        })
        .collect();
    let title = format!("ERA {name}: folded, half-way and deployed (isometric view)");
    let drawing = picture::drawing(&title, panels);
    for ext in ["png", "svg"] {
        let file = out.join(format!("era_{name}.{ext}"));
        match ext {
            "png" => drawing.write_png(&file)?,
            _ => drawing.write_svg(&file)?,
        }
        say(format!("drawing written to {}", file.display()));
        files.push(file);
    }
    let drawing_time = start.elapsed().as_secs_f64();
    say(format!(
        "set-up and checks {setup:.2} s, deployment {deploying:.2} s, drawings {drawing_time:.2} s"
    ));
    Ok(Report {
        counts,
        locked,
        free,
        zero_modes_locked: modes.zero_modes,
        softest,
        deployment: run.figures,
        last,
        peak,
        files,
        timings: [setup, deploying, drawing_time],
    })
}

/// A few lines on the dimensions and masses.
pub fn describe(g: &Geometry) -> String {
    let d = &g.design;
    let l = &g.layout;
    format!(
        "ERA {}: {} cells, {} longerons, {} faces, {} mid-hinges; cell side {} m, height {} m; horizontals {:.4} m between hinges (halves {:.4} m), diagonals {:.4} m; folded at scale {} (mid-hinges open {:.1}°)",
        g.name,
        l.cells.len(),
        l.columns.len(),
        l.faces.len(),
        2 * l.faces.len(),
        d.side,
        d.height,
        2.0 * g.half_length,
        g.half_length,
        g.diagonal_length(),
        d.folded_scale,
        g.folded().opening.to_degrees(),
    )
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let structure = match args.first().map(String::as_str) {
        None | Some("cell") => Structure::Cell,
        Some("platform") => Structure::PLATFORM,
        Some(other) => {
            eprintln!("unknown structure {other:?}: cell or platform");
            std::process::exit(2);
        }
    };
    let default_out = format!("results/era_{}", structure.name());
    let out = PathBuf::from(args.get(1).map_or(default_out.as_str(), String::as_str));
    let increments: usize = match args.get(2).map(|s| s.parse()) {
        None => 24,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("increments: a positive integer");
            std::process::exit(2);
        }
    };
    run(structure, &out, increments, true)?;
    Ok(())
}
