//! The ERA deployable platform flown on MIR (Cardona, §6.2): one cell, the
//! triangle of 4 cells (the platform reduced) or the hexagon of 24 cells,
//! built with the `unfold` model builders,
//! checked as a mechanism and as a structure, and deployed in dynamics by
//! the tape springs of its mid-hinges until every latch has locked.
//!
//! ```text
//! cargo run --release --example era -- [cell|triangle|platform] [output directory] [gravities, g: 0,0.01]
//! ```
//!
//! The program
//! 1. builds the structure deployed (mid-hinges locked) and folded (every
//!    mid-hinge with its tape spring and latch), and writes the model
//!    files (`era_<structure>_deployed.toml`,
//!    `era_<structure>_deployment_<g>g.toml`);
//! 2. checks the design: the rank of the constraints of the rigid-link
//!    model (no motion left when the mid-hinges are locked, one, the
//!    deployment, when they are free), the zero modes of the
//!    stiffness of the deployed structure, clamped; and counts the
//!    unknowns and the mean bandwidth;
//! 3. runs the deployment in dynamics twice, without gravity and with
//!    0.01 g along the longerons (the paper's two analyses), writes the
//!    result files (VTK for ParaView, CSV with `energies.csv`,
//!    `hinge_laws.csv`, `latches.csv`, `summary.json`) into
//!    `deployment_<g>g/`, a drawing of six successive configurations up
//!    to the last lock (`era_<structure>_<g>g_configurations.png`, `.svg`:
//!    the paper's figure 6), the opening angle of one mid-hinge against
//!    time with its lock (`…_hinge_angle`: figure 7), the moments on the
//!    mid-hinges (`…_hinge_moments`) and the energies (`…_energies`).
//!
//! `examples/era.md` describes the design, every parameter and the
//! figures.

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

use unfold::io::plot::{Axis, Chart, Series};
use unfold::model::Model;

use deploy::{Case, Record};
use design::Design;
use geometry::{Geometry, Structure};
use hinge::Hinges;

/// Configurations drawn: six, from the start to the last lock.
pub const DRAWN: usize = 6;

/// The two deployments of the paper: without gravity and with 0.01 g
/// along the longerons.
pub const GRAVITIES: [f64; 2] = [0.0, 0.01];

/// The time span and steps of the deployment of `structure`: fixed steps
/// of 0.01 s (the paper took 74 steps over 1.2 s), shortened to land on
/// each lock, with `ρ∞ = 0.5` to damp the vibrations of the members that
/// the steps do not resolve (examples/era.md compares the lock instants
/// with a run whose steps follow the error estimate).
pub fn case(structure: Structure, gravity: f64) -> Case {
    match structure {
        Structure::Cell => Case {
            gravity,
            end_time: 2.0,
            time_step: 0.01,
            max_step: 0.01,
            rho_infinity: 0.5,
            error_tolerance: 1e-4,
            adaptive: false,
        },
        _ => Case {
            gravity,
            end_time: 2.5,
            time_step: 0.01,
            max_step: 0.01,
            rho_infinity: 0.5,
            error_tolerance: 1e-4,
            adaptive: false,
        },
    }
}

/// What a deployment found.
#[derive(Clone, Debug)]
pub struct Deployment {
    /// Gravity (g).
    pub gravity: f64,
    /// Counts and timings.
    pub figures: deploy::Figures,
    /// Whether the analysis reached its end.
    pub completed: bool,
}

/// What a run of the program found.
#[derive(Clone, Debug)]
pub struct Report {
    /// Counts of the deployment model.
    pub counts: checks::Counts,
    /// Rank of the rigid-link model, deployed, mid-hinges locked.
    pub locked: checks::Rank,
    /// Rank of the rigid-link model, folded, mid-hinges free.
    pub free: checks::Rank,
    /// The deployments, without and with gravity.
    pub deployments: Vec<Deployment>,
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Wall time of the set-up and checks, of each deployment and of the
    /// drawings (s).
    pub timings: Vec<f64>,
}

/// Runs the program for `structure` with the deployments at `gravities`,
/// writing into `out`; with `log`, prints as it goes.
pub fn run(
    structure: Structure,
    gravities: &[f64],
    out: &Path,
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
    let name = geometry.name.clone();
    say(describe(&geometry));
    std::fs::create_dir_all(out)?;
    let mut files = Vec::new();

    // the deployed structure, and the counts of the deployment model
    let deployed = deploy::deployed(&geometry);
    let file = out.join(format!("era_{name}_deployed.toml"));
    std::fs::write(&file, deployed.input.to_toml()?)?;
    files.push(file);
    let first = deploy::model(&geometry, &case(structure, 0.0));
    let counts = checks::counts(&Model::from_input(&first.input)?);
    say(format!(
        "deployment model: {} nodes, {} unknowns ({} node components and coordinates, {} multipliers), mean bandwidth {:.1} numbered by reverse Cuthill–McKee, {:.1} as built",
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
    if structure == Structure::Cell {
        let model = Model::from_input(&deployed.input)?;
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
    }
    let mut timings = vec![start.elapsed().as_secs_f64()];

    let nominal = deploy::nominal(&geometry)?;
    let mut deployments = Vec::new();
    let mut drawing_time = 0.0;
    for &gravity in gravities {
        let start = Instant::now();
        let tag = format!("{}g", gravity);
        let built = deploy::model(&geometry, &case(structure, gravity));
        let file = format!("era_{name}_deployment_{tag}.toml");
        std::fs::write(out.join(&file), built.input.to_toml()?)?;
        files.push(out.join(&file));
        let dir = out.join(format!("deployment_{tag}"));
        say(format!(
            "deployment with gravity {gravity} g: results in {}",
            dir.display()
        ));
        let run = deploy::run(&built, &nominal, Some((&dir, &file)), 0.01, log)?;
        let f = &run.figures;
        let locks: Vec<String> = f
            .locks
            .iter()
            .map(|t| t.map_or("open".into(), |t| format!("{t:.4}")))
            .collect();
        say(format!(
            "deployment, {gravity} g: {} unknowns, {} steps ({} rejected, {} retried to land on a lock), {} iterations ({:.2} per step, {} more in rejected steps), {:.2} s; locks at t = [{}] s; at t = {:.3} s the nodes are within {:.2e} m of the nominal deployed geometry (vibrating), the equilibrium of the locked structure within {:.2e} m ({} iterations); impacts dissipated {:.3e} J; largest latch moment {:.2} N·m; work of the tape springs {:.4} J; energy balance error {:.2e} J",
            f.unknowns,
            f.steps,
            f.rejected,
            f.event_retries,
            f.iterations,
            f.iterations as f64 / f.steps.max(1) as f64,
            f.wasted_iterations,
            f.wall_time,
            locks.join(", "),
            run.outcome.time,
            f.geometry_error,
            f.locked_geometry_error,
            f.equilibrium_iterations,
            f.impact_loss,
            f.peak_latch_moment,
            f.hinge_law_work,
            f.balance_error,
        ));
        let completed = run.outcome.error.is_none();
        if let Some(e) = &run.outcome.error {
            say(format!(
                "the deployment stopped at t = {}: {e}",
                run.outcome.time
            ));
        }
        timings.push(start.elapsed().as_secs_f64());

        // drawings
        let start = Instant::now();
        let model = Model::from_input(&built.input)?;
        let last_lock = f.locks.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
        let end = if last_lock > 0.0 {
            last_lock
        } else {
            run.outcome.time
        };
        let panels = (0..DRAWN)
            .filter_map(|k| {
                let t = end * k as f64 / (DRAWN - 1) as f64;
                let state = run
                    .snapshots
                    .iter()
                    .min_by(|a, b| (a.time - t).abs().total_cmp(&(b.time - t).abs()))?;
                let label = format!("t = {:.2} s", state.time);
                Some(picture::panel(&built, &model, state, &label))
            })
            .collect();
        let title = format!(
            "ERA {name} deploying, gravity {gravity} g: six configurations to the last lock (isometric view)"
        );
        let drawing = picture::drawing(&title, panels);
        let base = |what: &str| out.join(format!("era_{name}_{tag}_{what}"));
        drawing.write_png(&base("configurations.png"))?;
        drawing.write_svg(&base("configurations.svg"))?;
        files.push(base("configurations.png"));
        for (what, chart) in charts(&name, gravity, &run.records, &f.locks) {
            chart.write_png(&base(&format!("{what}.png")))?;
            chart.write_svg(&base(&format!("{what}.svg")))?;
            files.push(base(&format!("{what}.png")));
        }
        drawing_time += start.elapsed().as_secs_f64();
        deployments.push(Deployment {
            gravity,
            figures: run.figures,
            completed,
        });
    }
    timings.push(drawing_time);
    say(format!(
        "set-up and checks {:.2} s, deployments {} s, drawings {:.2} s; files in {}",
        timings[0],
        timings[1..timings.len() - 1]
            .iter()
            .map(|t| format!("{t:.2}"))
            .collect::<Vec<_>>()
            .join(" and "),
        drawing_time,
        out.display()
    ));
    Ok(Report {
        counts,
        locked,
        free,
        deployments,
        files,
        timings,
    })
}

/// The charts of a deployment: the opening angle of the first mid-hinge
/// against time with its lock (the paper's figure 7), the moments on
/// every mid-hinge, the energies.
pub fn charts(
    name: &str,
    gravity: f64,
    records: &[Record],
    locks: &[Option<f64>],
) -> Vec<(&'static str, Chart)> {
    let time = Axis::new("time", "s");
    let mut angle = Chart::new(
        format!("ERA {name}, gravity {gravity} g: opening angle of the top mid-hinge of face 1"),
        time.clone(),
        Axis::new("opening angle", "°"),
    )
    .series(Series::new(
        "mid-hinge 1 (top, face 1)",
        records
            .iter()
            .map(|r| (r.time, r.hinges[0].opening.to_degrees())),
    ));
    if let Some(t) = locks[0] {
        angle = angle.event(t, format!("lock, t = {t:.3} s"));
    }
    let hinges = records.first().map_or(0, |r| r.hinges.len()).min(6);
    let mut moments = Chart::new(
        format!("ERA {name}, gravity {gravity} g: moment opening the mid-hinges (spring + latch)"),
        time.clone(),
        Axis::new("moment", "N·m"),
    );
    for k in 0..hinges {
        moments = moments.series(Series::new(
            format!("mid-hinge {}", k + 1),
            records
                .iter()
                .map(|r| (r.time, r.hinges[k].spring + r.hinges[k].latch)),
        ));
    }
    let energy = |label: &str, f: &dyn Fn(&Record) -> f64| {
        Series::new(label, records.iter().map(|r| (r.time, f(r))))
    };
    let energies = Chart::new(
        format!("ERA {name}, gravity {gravity} g: energies"),
        time,
        Axis::new("energy", "J"),
    )
    .series(energy("work of the tape springs", &|r| r.spring_work))
    .series(energy("kinetic", &|r| r.energies.kinetic))
    .series(energy("strain (members)", &|r| r.energies.strain))
    .series(energy("dissipated (impacts, damping)", &|r| {
        r.energies.dissipated
    }))
    .series(energy("gravity potential", &|r| r.energies.gravity));
    vec![
        ("hinge_angle", angle),
        ("hinge_moments", moments),
        ("energies", energies),
    ]
}

/// A few lines on the dimensions and masses.
pub fn describe(g: &Geometry) -> String {
    let d = &g.design;
    let l = &g.layout;
    format!(
        "ERA {}: {} cells, {} longerons, {} faces, {} mid-hinges; cell side {} m, height {} m; horizontals {:.4} m between hinges (halves {:.4} m), diagonals {:.4} m; folded at scale {} (mid-hinges open {:.1}°); tape springs {} N·m, locking peak {} N·m",
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
        d.hinge.deployment_moment,
        d.hinge.locking_peak,
    )
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let structure = match args.first().map(String::as_str) {
        None | Some("cell") => Structure::Cell,
        Some("platform") => Structure::PLATFORM,
        Some("triangle") => Structure::REDUCED,
        Some(other) => {
            eprintln!("unknown structure {other:?}: cell, triangle or platform");
            std::process::exit(2);
        }
    };
    let default_out = format!("results/era_{}", structure.name());
    let out = PathBuf::from(args.get(1).map_or(default_out.as_str(), String::as_str));
    // the gravities (g) to deploy under: both of the paper's by default
    let gravities = match args.get(2) {
        None => GRAVITIES.to_vec(),
        Some(list) => match list
            .split(',')
            .map(str::parse::<f64>)
            .collect::<Result<Vec<_>, _>>()
        {
            Ok(g) => g,
            Err(e) => {
                eprintln!("gravities {list:?}: {e} (a list such as 0,0.01)");
                std::process::exit(2);
            }
        },
    };
    let report = unfold::assembly::on_worker_thread(|| {
        run(structure, &gravities, &out, true).map_err(|e| e.to_string())
    })?;
    if report.deployments.iter().any(|d| !d.completed) {
        std::process::exit(1);
    }
    Ok(())
}
