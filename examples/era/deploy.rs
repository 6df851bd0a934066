//! The deployment in dynamics: the structure built folded, a bottom
//! corner body of the first longeron clamped (the attachment to the
//! station), released at rest; the tape springs of the mid-hinges open
//! it and the latches lock each mid-hinge when its halves come in line,
//! with the plastic impact of the lock (paper §6.2). An implicit dynamic
//! analysis (Lie-group generalised-α, docs/theory.md §15) with steps
//! sized by the error estimate and landing on every lock.
//!
//! What is measured on the way: the opening angle and the moments of
//! every mid-hinge, the energies, the lock instants; at the end, how far
//! the structure is from its nominal deployed geometry.

use std::error::Error;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

use unfold::analysis::{
    AnalysisSettings, ContactInfo, CutbackInfo, DynamicAnalysis, DynamicOutcome, Energies,
    EventInfo, IncrementInfo, IterationInfo, LockInfo, Observer, WarningInfo,
};
use unfold::io::results::AnalysisEnd;
use unfold::io::run::{Recorder, Silent};
use unfold::model::input::AnalysisInput;
use unfold::model::Model;
use unfold::state::State;

use super::geometry::Geometry;
use super::hinge::Hinges;
use super::model::{build, Built, Members, Options};

/// Standard gravity (m/s²).
pub const G0: f64 = 9.806_65;

/// The parameters of a deployment run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    /// Gravity along the longerons, downwards, in units of `G0` (the
    /// paper's second analysis: 0.01).
    pub gravity: f64,
    /// End of the analysis (s).
    pub end_time: f64,
    /// First time step (s).
    pub time_step: f64,
    /// Largest time step (s).
    pub max_step: f64,
    /// Spectral radius at infinite frequency of the generalised-α method.
    pub rho_infinity: f64,
    /// Local error tolerance of a step (docs/model-format.md).
    pub error_tolerance: f64,
    /// Steps sized by the error estimate (otherwise fixed steps of
    /// `time_step`, shortened only to land on a lock or when Newton
    /// fails).
    pub adaptive: bool,
}

/// The model of the deployment of `case`: built folded, the first
/// longeron's bottom corner body clamped, every mid-hinge with its tape
/// spring and latch.
pub fn model(geometry: &Geometry, case: &Case) -> Built {
    let analysis = AnalysisInput {
        kind: "dynamic".into(),
        end_time: case.end_time,
        time_step: Some(case.time_step),
        max_step: Some(case.max_step),
        rho_infinity: Some(case.rho_infinity),
        error_tolerance: Some(case.error_tolerance),
        adaptive: Some(case.adaptive),
        ..AnalysisInput::default()
    };
    let options = Options {
        scale: geometry.design.folded_scale,
        members: Members::Flexible,
        hinges: Hinges::Free,
        support: true,
        gravity: (case.gravity != 0.0).then_some([0.0, 0.0, -case.gravity * G0]),
        analysis,
    };
    let title = format!(
        "Deployment of the ERA {} by its mid-hinge tape springs, gravity {} g",
        geometry.name, case.gravity
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
        gravity: None,
        analysis: unfold::model::builder::Analysis::statics()
            .initial_increment(1.0)
            .into_input(),
    };
    let title = format!(
        "The ERA {} at scale {scale}, mid-hinges {hinges:?}",
        geometry.name
    );
    build(geometry, &options, &title)
}

/// The deployed structure, every mid-hinge locked, a longeron clamped.
pub fn deployed(geometry: &Geometry) -> Built {
    let mut built = structure(geometry, 1.0, Hinges::Locked);
    built.input.title = Some(format!(
        "The deployed ERA {}, mid-hinges locked",
        geometry.name
    ));
    built
}

/// Where every node of the deployment model stands when the structure is
/// deployed as designed: the nodes of [`deployed`] (built by the same
/// code in the same order) moved so that the clamped longeron stays where
/// it is folded.
pub fn nominal(geometry: &Geometry) -> Result<Vec<unfold::so3::Vec3>, Box<dyn Error>> {
    let model = Model::from_input(&deployed(geometry).input)?;
    let s0 = geometry.design.folded_scale;
    let c0 = geometry.layout.columns[0];
    let shift = unfold::so3::Vec3::new((s0 - 1.0) * c0[0], (s0 - 1.0) * c0[1], 0.0);
    Ok(model.reference_x.iter().map(|x| x + shift).collect())
}

/// One mid-hinge at a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HingeState {
    /// Opening angle `γ` (rad, `π` locked).
    pub opening: f64,
    /// Moment of the tape spring opening the hinge, `−M` of
    /// docs/joints.md §4.1 (N·m).
    pub spring: f64,
    /// Moment of the latch, positive opening (N·m).
    pub latch: f64,
    /// Whether it is locked.
    pub locked: bool,
}

/// What is measured at a converged step.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Step (0: the start).
    pub step: usize,
    /// Time (s).
    pub time: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Every mid-hinge, top then bottom of each face.
    pub hinges: Vec<HingeState>,
    /// Energies at the step.
    pub energies: Energies,
    /// Work done on the structure by the tape springs since the start (J):
    /// `−∫ M dc`, the hinge-law work `W_h` of the energy balance
    /// (docs/theory.md D12a).
    pub spring_work: f64,
}

/// Summary of a deployment run.
#[derive(Clone, Debug)]
pub struct Figures {
    /// Unknowns of the analysis.
    pub unknowns: usize,
    /// Accepted time steps.
    pub steps: usize,
    /// Rejected steps (Newton failed, or error estimate).
    pub rejected: usize,
    /// Steps retried shorter to land on a lock.
    pub event_retries: usize,
    /// Newton iterations of the accepted steps.
    pub iterations: usize,
    /// Of rejected steps.
    pub wasted_iterations: usize,
    /// Lock times of the mid-hinges, in the order of the hinges (`None`:
    /// not locked).
    pub locks: Vec<Option<f64>>,
    /// Largest distance of a node from its nominal deployed position at
    /// the end of the motion (m): the locked structure still vibrates.
    pub geometry_error: f64,
    /// The same for the equilibrium of the locked structure reached from
    /// the end of the motion (a static analysis, at rest) (m): its locked
    /// configuration (NaN when the motion stopped early).
    pub locked_geometry_error: f64,
    /// Newton iterations of that equilibrium.
    pub equilibrium_iterations: usize,
    /// Energy the impacts of the locks dissipated (J).
    pub impact_loss: f64,
    /// Energy balance error at the end (J): that of `energies.csv`, which
    /// counts the tape springs' work as work done on the structure.
    pub balance_error: f64,
    /// Work done on the structure by the tape springs over the run (J).
    pub hinge_law_work: f64,
    /// Largest moment a latch applied (N·m).
    pub peak_latch_moment: f64,
    /// Wall time of the analysis (s).
    pub wall_time: f64,
    /// Wall time from the start of the analysis to the last lock (s;
    /// `None` without locks).
    pub wall_time_to_last_lock: Option<f64>,
}

/// A deployment run.
pub struct Run {
    /// Every converged step.
    pub records: Vec<Record>,
    /// States kept along the way (at least every `snapshot_interval`).
    pub snapshots: Vec<State>,
    /// Counts and timings.
    pub figures: Figures,
    /// The analysis outcome (final state; error if it stopped early).
    pub outcome: DynamicOutcome,
}

/// Records every step, keeps states and passes everything on to the
/// result files' recorder.
struct DeployObserver<'a> {
    built: &'a Built,
    recorder: Option<Recorder>,
    interval: f64,
    snapshots: Vec<State>,
    records: Vec<Record>,
    energies: Option<Energies>,
    log: bool,
    /// When the analysis started, and the wall time (s) from then to the
    /// last lock so far.
    started: std::time::Instant,
    last_lock_wall: Option<f64>,
}

impl DeployObserver<'_> {
    fn measure(&self, info: &IncrementInfo, model: &Model, state: &State) -> Record {
        let hinges = self
            .built
            .parts
            .hinges()
            .map(|h| {
                let law = h.law.map(|l| model.results(l, state));
                let latch = h.latch.map(|l| model.results(l, state));
                let c = law
                    .as_ref()
                    .and_then(|r| r.get("coordinate"))
                    .unwrap_or(f64::NAN);
                HingeState {
                    opening: h.reference_opening + c,
                    spring: -law.and_then(|r| r.get("moment")).unwrap_or(0.0),
                    latch: latch.as_ref().and_then(|r| r.get("load")).unwrap_or(0.0),
                    locked: latch.and_then(|r| r.get("locked")) == Some(1.0),
                }
            })
            .collect::<Vec<_>>();
        let energies = self.energies.unwrap_or_default();
        Record {
            spring_work: energies.hinge_law_work,
            step: info.increment,
            time: info.time,
            iterations: info.iterations,
            hinges,
            energies,
        }
    }
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

    fn event(&mut self, info: &EventInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.event(info);
        }
    }

    fn band_crossing(&mut self, info: &LockInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.band_crossing(info);
        }
    }

    fn contact(&mut self, info: &ContactInfo) {
        if let Some(r) = self.recorder.as_mut() {
            r.contact(info);
        }
    }

    fn warning(&mut self, info: &WarningInfo) {
        if self.log {
            println!("  warning: {}", info.message);
        }
        if let Some(r) = self.recorder.as_mut() {
            r.warning(info);
        }
    }

    fn energies(&mut self, energies: &Energies) {
        self.energies = Some(*energies);
        if let Some(r) = self.recorder.as_mut() {
            r.energies(energies);
        }
    }

    fn lock(&mut self, info: &LockInfo) {
        self.last_lock_wall = Some(self.started.elapsed().as_secs_f64());
        if self.log {
            println!(
                "  t = {:.4} s: latch {} locks (rate {:+.3} rad/s, impulse {:.3e} N·m·s, {:.3e} J lost)",
                info.time, info.latch, info.rate_before, info.impulse, info.energy_lost
            );
        }
        if let Some(r) = self.recorder.as_mut() {
            r.lock(info);
        }
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> std::io::Result<()> {
        let record = self.measure(info, model, state);
        if self.log && info.increment.is_multiple_of(10) {
            let open: Vec<String> = record
                .hinges
                .iter()
                .map(|h| format!("{:5.1}", h.opening.to_degrees()))
                .collect();
            println!(
                "  step {:4}  t = {:.4} s  {} iterations  mid-hinges open [{}]°  kinetic energy {:.3e} J",
                info.increment,
                info.time,
                info.iterations,
                open.join(" "),
                record.energies.kinetic
            );
        }
        let keep = match self.snapshots.last() {
            None => true,
            Some(s) => (info.time / self.interval).floor() > (s.time / self.interval).floor() + 0.5,
        };
        if keep {
            self.snapshots.push(state.clone());
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
/// Keeps a state at least every `snapshot_interval` (s); `nominal` are
/// the nodes' nominal deployed positions ([`nominal`]).
pub fn run(
    built: &Built,
    nominal: &[unfold::so3::Vec3],
    out: Option<(&Path, &str)>,
    snapshot_interval: f64,
    log: bool,
) -> Result<Run, Box<dyn Error>> {
    let model = Arc::new(Model::from_input(&built.input)?);
    let plan = built.input.analyses()?;
    let settings = match &plan[0] {
        AnalysisSettings::Dynamic(d) => d.clone(),
        other => return Err(format!("a dynamic analysis, not {}", other.name()).into()),
    };
    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let recorder = match out {
        Some((dir, file)) => Some(Recorder::create_dynamic_first(
            dir, file, &analysis, &plan, Silent,
        )?),
        None => None,
    };
    let mut observer = DeployObserver {
        built,
        recorder,
        interval: snapshot_interval,
        snapshots: Vec::new(),
        records: Vec::new(),
        energies: None,
        log,
        started: std::time::Instant::now(),
        last_lock_wall: None,
    };
    let outcome = analysis.run(model.initial_state(), &mut observer);
    if let Some(mut recorder) = observer.recorder.take() {
        let end = AnalysisEnd::from(&outcome);
        recorder.end_analysis(&end);
        let report = recorder.finish_after(Some(&end), &outcome.state);
        if let Some(e) = report.output_errors.into_iter().next() {
            return Err(e.into());
        }
    }
    let observer_last_lock_wall = observer.last_lock_wall;
    let records = observer.records;
    let hinges: Vec<_> = built.parts.hinges().collect();
    let locks = hinges
        .iter()
        .map(|h| {
            let latch = h.latch?;
            outcome
                .locks
                .iter()
                .find(|l| l.latch == latch.id())
                .map(|l| l.time)
        })
        .collect();
    let last = records.last().expect("step 0");
    let error = |state: &State| {
        state
            .x
            .iter()
            .zip(nominal)
            .map(|(x, x0)| (x - x0).norm())
            .fold(0.0, f64::max)
    };
    let geometry_error = error(&outcome.state);
    // the locked configuration: the equilibrium at the end time, from the
    // end of the motion brought to rest, the latches as they are
    let mut rest = outcome.state.clone();
    for v in rest
        .velocity
        .iter_mut()
        .chain(rest.acceleration.iter_mut())
        .chain(rest.pseudo_acceleration.iter_mut())
    {
        *v = [0.0; 6];
    }
    for v in rest
        .coordinate_rates
        .iter_mut()
        .chain(rest.coordinate_accelerations.iter_mut())
        .chain(rest.coordinate_pseudo_accelerations.iter_mut())
    {
        *v = 0.0;
    }
    // (only when the motion reached its end: a structure stopped halfway
    // is still a mechanism)
    let (locked_geometry_error, equilibrium_iterations) = if outcome.error.is_none() {
        let statics = unfold::model::builder::Analysis::statics()
            .end_time(rest.time + 1.0)
            .initial_increment(1.0)
            .settings()?;
        let equilibrium = unfold::analysis::StaticAnalysis::new(model.clone(), statics)
            .run(rest, &mut unfold::analysis::NoObserver);
        if let Some(e) = &equilibrium.error {
            return Err(format!("the equilibrium of the locked structure: {e}").into());
        }
        (error(&equilibrium.state), equilibrium.iterations)
    } else {
        (f64::NAN, 0)
    };
    let peak_latch_moment = records
        .iter()
        .flat_map(|r| r.hinges.iter().map(|h| h.latch.abs()))
        .fold(0.0, f64::max);
    let figures = Figures {
        unknowns: analysis.n_equations(),
        steps: outcome.steps,
        rejected: outcome.rejected_steps,
        event_retries: outcome.event_retries,
        iterations: outcome.iterations,
        wasted_iterations: outcome.wasted_iterations,
        locks,
        geometry_error,
        locked_geometry_error,
        equilibrium_iterations,
        impact_loss: outcome.locks.iter().map(|l| l.energy_lost).sum(),
        balance_error: outcome.energies.balance_error,
        hinge_law_work: last.spring_work,
        peak_latch_moment,
        wall_time: outcome.wall_time,
        wall_time_to_last_lock: observer_last_lock_wall,
    };
    Ok(Run {
        records,
        snapshots: observer.snapshots,
        figures,
        outcome,
    })
}

/// The opening angle the mid-hinges lock at (rad).
pub const LOCKED_OPENING: f64 = PI;
