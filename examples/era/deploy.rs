//! The deployment driven through the mid-hinges: every mid-hinge opened
//! at the same rate from the folded to the deployed angle, by drivers on
//! the joint angles (displacement control), and what is measured on the
//! way.
//!
//! Along this path every face is in the same state, so the configuration
//! is known in closed form ([`Geometry::scale_at`]): the longerons move
//! on straight lines towards (away from) the clamped one, keep their
//! orientation and stay vertical, and the members are not strained.

use std::error::Error;
use std::f64::consts::PI;
use std::path::Path;

use unfold::analysis::{
    CutbackInfo, IncrementInfo, IterationInfo, Observer, StaticAnalysis, StaticOutcome,
};
use unfold::io::run::{Recorder, Silent};
use unfold::model::builder::Analysis;
use unfold::model::Model;
use unfold::so3::{self, Vec3};
use unfold::state::State;

use super::geometry::Geometry;
use super::hinge::Hinges;
use super::model::{build, Built, Members, Options};

/// The model of the deployment: built folded, a longeron clamped, every
/// mid-hinge driven to `π` along a smooth step, in `increments` equal
/// increments of `t` of a
/// kinetostatic analysis (flexible members) or of a kinematic one (rigid
/// links).
pub fn model(geometry: &Geometry, members: Members, increments: usize) -> Built {
    let h = 1.0 / increments.max(1) as f64;
    let analysis = match members {
        Members::Flexible => Analysis::kinetostatic(),
        Members::Rigid => Analysis::kinematic(),
    };
    let options = Options {
        scale: geometry.design.folded_scale,
        members,
        hinges: Hinges::Driven { opening: PI },
        support: true,
        analysis: analysis
            .end_time(1.0)
            .initial_increment(h)
            .max_increment(h)
            .min_increment(1e-4 * h),
    };
    let title = format!(
        "Deployment of the ERA {}: every mid-hinge driven open",
        geometry.name
    );
    build(geometry, &options, &title)
}

/// The flexible model at `scale`, a longeron clamped, the mid-hinges as
/// `hinges`, for a static analysis: the model of the checks.
pub fn structure(geometry: &Geometry, scale: f64, hinges: Hinges) -> Built {
    let options = Options {
        scale,
        members: Members::Flexible,
        hinges,
        support: true,
        analysis: Analysis::statics().initial_increment(1.0),
    };
    let title = format!("The ERA {} at scale {scale}, mid-hinges {hinges:?}", geometry.name);
    build(geometry, &options, &title)
}

/// The deployed structure, every mid-hinge locked, a longeron clamped.
pub fn deployed(geometry: &Geometry) -> Built {
    let mut built = structure(geometry, 1.0, Hinges::Locked);
    built.input.title = Some(format!("The deployed ERA {}, mid-hinges locked", geometry.name));
    built
}

/// What is measured at a converged increment.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Increment (0: the equilibrium at `t = 0`).
    pub increment: usize,
    /// Load parameter.
    pub time: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// The prescribed opening angle of the mid-hinges (rad).
    pub opening: f64,
    /// The scale of the layout it corresponds to.
    pub scale: f64,
    /// Largest distance of a longeron node from where the closed form puts
    /// it (m).
    pub longeron_error: f64,
    /// Largest rotation of a corner body from its reference orientation
    /// (rad): a longeron tilting or spinning.
    pub corner_rotation: f64,
    /// Largest axial force in a member (N).
    pub axial: f64,
    /// Largest bending moment `√(M₂² + M₃²)` in a member (N·m).
    pub bending: f64,
    /// Largest torsion in a member (N·m).
    pub torsion: f64,
    /// The load of the first mid-hinge's driver (N·m).
    pub driver_load: f64,
    /// Largest `|driver load − spring force|` over the mid-hinges (N·m):
    /// zero when the drivers only hold the springs (the members carry no
    /// moment about the hinge axes).
    pub hinge_imbalance: f64,
}

/// Where the closed form puts the longeron axes at scale `s`, the
/// clamped longeron (the first) staying where it is in the folded
/// configuration.
pub fn longeron_axes(geometry: &Geometry, s: f64) -> Vec<[f64; 2]> {
    let s0 = geometry.design.folded_scale;
    let c0 = geometry.layout.columns[0];
    geometry
        .layout
        .columns
        .iter()
        .map(|c| {
            [
                s * c[0] - (s - s0) * c0[0],
                s * c[1] - (s - s0) * c0[1],
            ]
        })
        .collect()
}

/// Measures `state` (the model of [`model`]) against the closed form.
pub fn measure(
    geometry: &Geometry,
    built: &Built,
    model: &Model,
    state: &State,
    info: &IncrementInfo,
) -> Record {
    // the opening the drivers prescribe
    let parts = &built.parts;
    let first = parts.hinges().next().expect("a mid-hinge");
    let target = first
        .driver
        .and_then(|d| model.results(d, state).get("target"))
        .unwrap_or(0.0);
    let opening = first.reference_opening + target;
    let scale = geometry.scale_at(opening);
    let axes = longeron_axes(geometry, scale);
    let mut record = Record {
        increment: info.increment,
        time: info.time,
        iterations: info.iterations,
        opening,
        scale,
        longeron_error: 0.0,
        corner_rotation: 0.0,
        axial: 0.0,
        bending: 0.0,
        torsion: 0.0,
        driver_load: 0.0,
        hinge_imbalance: 0.0,
    };
    for (column, axis) in parts.columns.iter().zip(&axes) {
        for &node in &column.longeron.nodes {
            let i = model.node(node);
            let z = model.reference_x[i].z;
            let expected = Vec3::new(axis[0], axis[1], z);
            record.longeron_error = record.longeron_error.max((state.x[i] - expected).norm());
        }
        for node in [column.bottom, column.top] {
            let i = model.node(node);
            let turn = model.reference_q[i].inverse() * state.q[i];
            record.corner_rotation = record.corner_rotation.max(so3::log(&turn).norm());
        }
    }
    let beams = parts.faces.iter().flat_map(|f| {
        f.top
            .halves
            .iter()
            .chain(&f.bottom.halves)
            .chain(&f.diagonals)
            .flat_map(|m| m.beams.iter())
    });
    let longerons = parts.columns.iter().flat_map(|c| c.longeron.beams.iter());
    for &beam in beams.chain(longerons) {
        let s = model.section_forces(beam, state);
        record.axial = record.axial.max(s.force.x.abs());
        record.torsion = record.torsion.max(s.moment.x.abs());
        record.bending = record.bending.max(s.moment.y.hypot(s.moment.z));
    }
    for (k, hinge) in parts.hinges().enumerate() {
        let (Some(driver), Some(spring)) = (hinge.driver, hinge.spring) else {
            continue;
        };
        let load = model.results(driver, state).get("load").unwrap_or(f64::NAN);
        let force = model.results(spring, state).get("spring").unwrap_or(f64::NAN);
        if k == 0 {
            record.driver_load = load;
        }
        record.hinge_imbalance = record.hinge_imbalance.max((load - force).abs());
    }
    record
}

/// Summary of a deployment run.
#[derive(Clone, Debug)]
pub struct Figures {
    /// Unknowns of the analysis (redundant constraints included).
    pub unknowns: usize,
    /// Constraint equations found redundant.
    pub redundant_constraints: usize,
    /// Converged increments (the initial equilibrium excluded).
    pub increments: usize,
    /// Newton iterations per increment (the initial equilibrium excluded).
    pub iterations_per_increment: f64,
    /// Largest number of iterations of an increment.
    pub max_iterations: usize,
    /// Cut-backs.
    pub cutbacks: usize,
    /// Wall time of the analysis (s).
    pub wall_time: f64,
}

/// A deployment run.
pub struct Run {
    /// Every converged increment.
    pub records: Vec<Record>,
    /// The states at the times asked for, with their records.
    pub snapshots: Vec<(Record, State)>,
    /// Counts and timings.
    pub figures: Figures,
    /// The analysis outcome (final state; error if it stopped early).
    pub outcome: StaticOutcome,
}

/// Records every increment, keeps the states at the snapshot times and
/// passes everything on to the result files' recorder.
struct DeployObserver<'a> {
    geometry: &'a Geometry,
    built: &'a Built,
    recorder: Option<Recorder>,
    snapshot_times: Vec<f64>,
    snapshots: Vec<(Record, State)>,
    records: Vec<Record>,
    log: bool,
}

impl Observer for DeployObserver<'_> {
    fn iteration(&mut self, info: &IterationInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.iteration(info);
        }
    }

    fn cutback(&mut self, info: &CutbackInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.cutback(info);
        }
    }

    fn note(&mut self, text: &str) {
        if let Some(r) = self.recorder.as_mut() {
            r.note(text);
        }
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> std::io::Result<()> {
        let record = measure(self.geometry, self.built, model, state, info);
        if self.log {
            println!(
                "increment {:3}  t = {:.4}  iterations {}  opening {:6.1}°  scale {:.4}  longerons off by {:.1e} m, turned {:.1e} rad  members: N {:.1e} N, M {:.1e} N·m, T {:.1e} N·m  driver {:+.4} N·m",
                record.increment,
                record.time,
                record.iterations,
                record.opening.to_degrees(),
                record.scale,
                record.longeron_error,
                record.corner_rotation,
                record.axial,
                record.bending,
                record.torsion,
                record.driver_load,
            );
        }
        while let Some(&t) = self.snapshot_times.first() {
            if info.time < t - 1e-12 {
                break;
            }
            self.snapshots.push((record.clone(), state.clone()));
            self.snapshot_times.remove(0);
        }
        self.records.push(record);
        match self.recorder.as_mut() {
            Some(r) => r.increment(info, model, state, residual),
            None => Ok(()),
        }
    }
}

/// Runs the deployment `built` (from [`model`]); with `out`, writes the
/// result files there (the model file name `file` recorded in them).
/// Keeps the states at the first increments reaching `snapshot_times`
/// (increasing).
pub fn run(
    geometry: &Geometry,
    built: &Built,
    out: Option<(&Path, &str)>,
    snapshot_times: &[f64],
    log: bool,
) -> Result<Run, Box<dyn Error>> {
    let model = Model::from_input(&built.input)?;
    let mut analysis = StaticAnalysis::new(&model);
    let recorder = match out {
        Some((dir, file)) => Some(Recorder::create(dir, file, &model, &analysis, Silent)?),
        None => None,
    };
    let mut observer = DeployObserver {
        geometry,
        built,
        recorder,
        snapshot_times: snapshot_times.to_vec(),
        snapshots: Vec::new(),
        records: Vec::new(),
        log,
    };
    let outcome = analysis.run(&mut observer);
    if let Some(recorder) = observer.recorder.take() {
        let report = recorder.finish(&outcome);
        if let Some(e) = report.output_errors.into_iter().next() {
            return Err(e.into());
        }
    }
    let records = observer.records;
    let steps: Vec<&Record> = records.iter().skip(1).collect();
    let figures = Figures {
        unknowns: analysis.n_equations(),
        redundant_constraints: outcome.redundant_constraints,
        increments: outcome.increments,
        iterations_per_increment: steps.iter().map(|r| r.iterations).sum::<usize>() as f64
            / steps.len().max(1) as f64,
        max_iterations: steps.iter().map(|r| r.iterations).max().unwrap_or(0),
        cutbacks: outcome.cutbacks,
        wall_time: outcome.wall_time,
    };
    Ok(Run {
        records,
        snapshots: observer.snapshots,
        figures,
        outcome,
    })
}
