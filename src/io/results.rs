//! Result files of a run (docs/results.md):
//! - `nodes.csv`: position, displacement and orientation of every node at
//!   every output step;
//! - `reactions.csv`: support reactions (forces and moments, global frame);
//! - one table per kind of element that reports results
//!   ([`ElementKind::results_file`]: `beams.csv`, `springs.csv`,
//!   `joints.csv`, `drivers.csv`, `joint_springs.csv`), whose columns are
//!   the elements' [`crate::elements::Element::result_names`]
//!   ([`ElementKind::result_columns`]: a joint's coordinates are named,
//!   `angle`, `slide`..., and its type is in a column `type`);
//! - `steps.csv`: one line per output step (increment, load parameter,
//!   iterations, final relative residual);
//! - in a run with a dynamic analysis: `nodes_velocities.csv` (velocity,
//!   angular velocity and their rates of every node at every output step),
//!   `energies.csv` (the energy balance at the output steps of dynamic
//!   analyses), the rates of the joint coordinates in `joints.csv`, and the
//!   velocities in the grids;
//! - `vtk/step_NNNNN.vtu` and `unfold.pvd`: the configurations for ParaView;
//! - `summary.json`: size of the model, counts, wall time and status.
//!
//! Rows of a step are in increasing node or element id.
//!
//! **One step is all or nothing.** A step is formatted in memory, then its
//! grid is written (to a temporary file renamed into place), then its rows
//! are appended to every CSV file, and last the collection `unfold.pvd`
//! that lists the grids is replaced. If any of these writes fails (a full
//! disk), the CSV files are cut back to their length before the step and
//! the grid is removed, so every file holds the same steps; the error
//! names the file.
//!
//! **The directory belongs to one run.** A lock file (`.unfold.lock`) is
//! held for the life of the writer: a second run on the same directory is
//! refused. Files that unfold writes ([`owned_files`], `vtk/step_*.vtu`)
//! and that this run will not rewrite are removed when it starts, so that
//! no result of an earlier model is left beside the new ones; other files
//! are left alone.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::number::{push_integer, Sci, Shortest};
use super::vtk;
use crate::analysis::{
    AnalysisSettings, ContactKind, DynamicOutcome, Energies, IncrementInfo, LatchEventKind,
    LinearSolverCounts, Observer, StaticAnalysis, StaticOutcome,
};
use crate::elements::{ElementKind, Need};
use crate::joints::Coordinate;
use crate::model::Model;
use crate::so3::{self, Vec3};
use crate::state::State;

/// Result files in the output directory that unfold writes besides the
/// tables of the element kinds ([`ElementKind::results_file`]) and the
/// grids `vtk/step_NNNNN.vtu`; `view.html` is the page `unfold view`
/// makes of them (docs/viewer.md).
const RUN_FILES: [&str; 10] = [
    "log.txt",
    "steps.csv",
    "nodes.csv",
    "nodes_velocities.csv",
    "energies.csv",
    "events.csv",
    "reactions.csv",
    "unfold.pvd",
    "summary.json",
    "view.html",
];

/// Result files in the output directory that unfold writes (besides the
/// grids `vtk/step_NNNNN.vtu`): those of a run and the table of each kind
/// of element. A run removes those of them it will not rewrite, and their
/// temporary files (`NAME.tmp`).
pub fn owned_files() -> impl Iterator<Item = &'static str> {
    RUN_FILES.into_iter().chain(
        ElementKind::ALL
            .into_iter()
            .filter_map(ElementKind::results_file),
    )
}

/// The lock file of an output directory.
pub const LOCK_FILE: &str = ".unfold.lock";

/// `e`, with the file's name in front of its message.
pub fn file_error(path: &Path, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

/// Per-increment record kept for `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct IncrementRecord {
    /// Increment number (0: initial equilibrium).
    pub increment: usize,
    /// Load parameter reached.
    pub time: f64,
    /// Increment size.
    pub step: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// Relative residual at each iteration.
    pub residuals: Vec<f64>,
}

/// What one analysis of a run did, for `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct AnalysisRecord {
    /// Analysis type (`static`, `kinematic`).
    #[serde(rename = "type")]
    pub kind: String,
    /// `t` it started from.
    pub start_time: f64,
    /// Its requested end.
    pub end_time: f64,
    /// `t` it reached.
    pub final_time: f64,
    /// Converged increments after its initial equilibrium.
    pub increments: usize,
    /// Newton iterations of its converged increments.
    pub iterations: usize,
    /// Its cut-backs.
    pub cutbacks: usize,
    /// Whether it stopped early (the analyses after it were not run).
    pub failed: bool,
    /// Its wall-clock time, seconds.
    pub wall_time_s: f64,
    /// What a dynamic analysis did besides (absent for the others).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dynamic: Option<DynamicRecord>,
}

/// The time steps and the energy balance of a dynamic analysis, for
/// `summary.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct DynamicRecord {
    /// Accepted time steps.
    pub steps: usize,
    /// Steps rejected: cut back after Newton failed, or rejected by the
    /// local error estimate.
    pub rejected_steps: usize,
    /// Of which rejected by the error estimate.
    pub error_rejections: usize,
    /// Newton iterations of the accepted steps.
    pub newton_iterations: usize,
    /// Newton iterations of the rejected steps.
    pub wasted_iterations: usize,
    /// Numeric factorisations of the iteration matrix (docs/results.md).
    pub factorisations: usize,
    /// Numeric factorisations of the constrained mass system of the
    /// velocity projection and the restarts.
    pub mass_factorisations: usize,
    /// Steps whose modified Newton iterations were retried with fresh
    /// factors.
    pub newton_retries: usize,
    /// Factorisations, solves and GMRES iterations of the sparse solvers
    /// (docs/results.md).
    pub linear_solver: LinearSolverCounts,
    /// Wall-clock time, seconds.
    pub wall_time_s: f64,
    /// Energy balance error `(T + V) − (T₀ + V₀) − W + D` at the last
    /// converged step (docs/results.md, `energies.csv`).
    pub energy_balance_error: f64,
    /// Largest absolute balance error over the steps.
    pub largest_energy_balance_error: f64,
    /// Largest kinetic energy over the steps: the scale of the errors.
    pub largest_kinetic_energy: f64,
    /// Events written to `events.csv`: latches locked, spring latches
    /// released (unlatched), impacts of stops with rebound, contacts
    /// closed (plastic impacts), contacts released.
    pub locks: usize,
    /// See [`Self::locks`].
    pub unlatches: usize,
    /// See [`Self::locks`].
    pub impacts: usize,
    /// See [`Self::locks`].
    pub contacts_closed: usize,
    /// See [`Self::locks`].
    pub contacts_released: usize,
    /// Spring latches' band crossings written to `events.csv`: the
    /// coordinate leaving the dead band across an edge (`engage`), coming
    /// back into it (`disengage`), and a latch released beyond `c_L`
    /// coming back to it (`rearm`).
    pub engages: usize,
    /// See [`Self::engages`].
    pub disengages: usize,
    /// See [`Self::engages`].
    pub rearms: usize,
    /// Energy dissipated by the impacts of these events, and dropped by
    /// the spring latches that released (the sum of `energy_lost` of
    /// `events.csv`, each impact counted once: latches that lock in one
    /// step, and stops struck in one step, share one impact and report its
    /// whole loss on each row).
    pub impact_energy_lost: f64,
}

impl DynamicRecord {
    /// The record of `outcome`, with the largest balance error and kinetic
    /// energy seen over its steps.
    pub fn of(outcome: &DynamicOutcome, largest_error: f64, largest_kinetic: f64) -> Self {
        let count = |k| outcome.contacts.iter().filter(|c| c.kind == k).count();
        let latch_events = |k| outcome.locks.iter().filter(|l| l.kind == k).count();
        Self {
            steps: outcome.steps,
            rejected_steps: outcome.rejected_steps,
            error_rejections: outcome.error_rejections,
            newton_iterations: outcome.iterations,
            wasted_iterations: outcome.wasted_iterations,
            factorisations: outcome.factorisations,
            mass_factorisations: outcome.mass_factorisations,
            newton_retries: outcome.newton_retries,
            linear_solver: outcome.linear_solver,
            wall_time_s: outcome.wall_time,
            energy_balance_error: outcome.energies.balance_error,
            largest_energy_balance_error: largest_error.max(outcome.energies.balance_error.abs()),
            largest_kinetic_energy: largest_kinetic.max(outcome.energies.kinetic),
            locks: latch_events(LatchEventKind::Lock),
            unlatches: latch_events(LatchEventKind::Unlatch),
            impacts: count(ContactKind::Impact),
            contacts_closed: count(ContactKind::Close),
            contacts_released: count(ContactKind::Release),
            // reported to the observer (Observer::band_crossing), not kept
            // in the outcome: counted by the recorder that writes them
            engages: latch_events(LatchEventKind::Engage),
            disengages: latch_events(LatchEventKind::Disengage),
            rearms: latch_events(LatchEventKind::Rearm),
            impact_energy_lost: impact_energy_lost(outcome),
        }
    }
}

/// The energy the impacts of `outcome` dissipated: per step, one loss for
/// its locks and one for its stop events (each shared by the rows of the
/// step, docs/joints.md §6.2 and §6.3).
fn impact_energy_lost(outcome: &DynamicOutcome) -> f64 {
    let once = |rows: &mut dyn Iterator<Item = (usize, f64)>| {
        let mut total = 0.0;
        let mut last = None;
        for (step, lost) in rows {
            if last != Some(step) {
                total += lost;
                last = Some(step);
            }
        }
        total
    };
    once(&mut outcome.locks.iter().map(|l| (l.increment, l.energy_lost)))
        + once(
            &mut outcome
                .contacts
                .iter()
                .map(|c| (c.increment, c.energy_lost)),
        )
}

/// What one analysis of a run did, whatever its type: the counts that the
/// summary adds up.
#[derive(Clone, Debug, Default)]
pub struct AnalysisEnd {
    /// `t` reached.
    pub time: f64,
    /// Converged increments or time steps (after the start).
    pub increments: usize,
    /// Newton iterations of the converged ones.
    pub iterations: usize,
    /// Newton iterations of those cut back or rejected.
    pub wasted_iterations: usize,
    /// Cut-backs after Newton failed.
    pub cutbacks: usize,
    /// Constraint equations removed as redundant.
    pub redundant_constraints: usize,
    /// Wall-clock time, seconds.
    pub wall_time: f64,
    /// Why it stopped early, if it did.
    pub error: Option<String>,
    /// Whether it stopped on request (a signal).
    pub interrupted: Option<super::run::Interrupted>,
    /// The dynamic analysis's record.
    pub dynamic: Option<DynamicRecord>,
}

impl From<&StaticOutcome> for AnalysisEnd {
    fn from(o: &StaticOutcome) -> Self {
        Self {
            time: o.time,
            increments: o.increments,
            iterations: o.iterations,
            wasted_iterations: o.wasted_iterations,
            cutbacks: o.cutbacks,
            redundant_constraints: o.redundant_constraints,
            wall_time: o.wall_time,
            error: o.error.as_ref().map(|e| e.to_string()),
            interrupted: o.error.as_ref().and_then(super::run::Interrupted::of),
            dynamic: None,
        }
    }
}

impl From<&DynamicOutcome> for AnalysisEnd {
    fn from(o: &DynamicOutcome) -> Self {
        Self {
            time: o.time,
            increments: o.steps,
            iterations: o.iterations,
            wasted_iterations: o.wasted_iterations,
            cutbacks: o.cutbacks,
            redundant_constraints: o.redundant_constraints,
            wall_time: o.wall_time,
            error: o.error.as_ref().map(|e| e.to_string()),
            interrupted: o
                .error
                .as_ref()
                .and_then(super::run::Interrupted::of_dynamic),
            dynamic: Some(DynamicRecord::of(o, 0.0, 0.0)),
        }
    }
}

/// Where a run stands, as written in `summary.json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RunStatus {
    /// Written when the run starts. Left in place, it means that the
    /// process ended without writing its final summary (killed, or its
    /// summary could not be written).
    Running,
    /// The analysis reached `end_time`.
    Completed,
    /// The analysis stopped early: no convergence, inconsistent
    /// constraints, or a result file could not be written.
    Failed,
    /// Stopped on request (a signal) after a converged increment.
    Interrupted,
}

impl RunStatus {
    /// The name written in `summary.json`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Running => "running",
            Self::Completed => "completed",
            Self::Failed => "failed",
            Self::Interrupted => "interrupted",
        }
    }
}

/// Final report of a run, written as `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Model file.
    pub model: String,
    /// Model title.
    pub title: String,
    /// Where the run stands.
    pub status: RunStatus,
    /// Error message when failed, the reason when interrupted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub message: Option<String>,
    /// Number of nodes.
    pub nodes: usize,
    /// Number of elements (loads excluded).
    pub elements: usize,
    /// Number of beam elements.
    pub beams: usize,
    /// Number of joints.
    pub joints: usize,
    /// Number of drivers.
    pub drivers: usize,
    /// Constraint equations removed as redundant.
    pub redundant_constraints: usize,
    /// Equations solved: free unknowns, after the redundant constraint
    /// equations were removed (before the run starts: all of them).
    pub dofs: usize,
    /// Non-zeros of the system matrix as first assembled (redundant
    /// constraint equations included).
    pub nonzeros: usize,
    /// Converged increments after the initial equilibrium.
    pub increments: usize,
    /// Newton iterations of converged increments.
    pub iterations: usize,
    /// Iterations per increment (initial equilibrium excluded).
    pub average_iterations: f64,
    /// Iterations spent in increments that were cut back.
    pub wasted_iterations: usize,
    /// Cut-backs.
    pub cutbacks: usize,
    /// Load parameter reached.
    pub final_time: f64,
    /// Requested end of the analysis.
    pub end_time: f64,
    /// Wall-clock time of the analysis, seconds.
    pub wall_time_s: f64,
    /// Output steps written.
    pub output_steps: usize,
    /// Each analysis of the run, in order (one unless the model file asks
    /// for a sequence).
    pub analyses: Vec<AnalysisRecord>,
    /// Warnings of the analyses about converged increments (a limit point
    /// passed under load control), as logged.
    pub warnings: Vec<String>,
    /// The model's own warnings, as `unfold check` and `unfold run` print
    /// them (a latch value that reads as degrees, a unit that looks
    /// wrong): `entity: message`.
    pub model_warnings: Vec<String>,
    /// Every converged increment.
    pub increment_log: Vec<IncrementRecord>,
    /// What each modal analysis of the run found (docs/results.md,
    /// "Modes").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub modes: Vec<super::modes::ModalRecord>,
    /// The largest load of each latch over the run, and when it locked
    /// (docs/results.md, "Peak loads").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub latches: Vec<super::peaks::LatchPeak>,
    /// The same for each stop, and when it first closed.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stops: Vec<super::peaks::StopPeak>,
    /// The same for each contact between bodies.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<super::peaks::StopPeak>,
    /// Each superelement: its reduction and the peak results of its
    /// original elements (docs/results.md, "Superelements").
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub superelements: Vec<super::peaks::SuperelementRecord>,
    /// Iterations of the initial equilibria, left out of the average.
    #[serde(skip)]
    initial_iterations: usize,
    /// Free unknowns before redundant constraint equations are removed.
    #[serde(skip)]
    unknowns: usize,
}

impl Summary {
    /// The summary of a run of the analyses `plan` on `model` (read from
    /// `model_file`), the first of which is `first`, that has not started:
    /// status `running`, counts of the model, no increment.
    pub fn start(
        model_file: &str,
        model: &Model,
        first: &StaticAnalysis,
        plan: &[AnalysisSettings],
    ) -> Self {
        let end_time = plan
            .last()
            .map_or(first.settings().end_time, |a| a.end_time());
        Self::start_with(
            model_file,
            model,
            first.n_equations(),
            first.solver().nnz(),
            end_time,
        )
    }

    /// The summary of a run on `model` (read from `model_file`) whose first
    /// analysis has `dofs` unknowns and `nonzeros` non-zeros in its matrix,
    /// ending at `end_time`, that has not started.
    pub fn start_with(
        model_file: &str,
        model: &Model,
        dofs: usize,
        nonzeros: usize,
        end_time: f64,
    ) -> Self {
        let count = |k: ElementKind| model.elements.iter().filter(|e| e.kind() == k).count();
        Self {
            model: model_file.to_string(),
            title: model.title.clone(),
            status: RunStatus::Running,
            message: None,
            nodes: model.n_nodes(),
            elements: model.elements.len() - count(ElementKind::NodalLoad),
            beams: count(ElementKind::Beam),
            joints: count(ElementKind::Joint),
            drivers: count(ElementKind::Driver),
            redundant_constraints: 0,
            dofs,
            nonzeros,
            increments: 0,
            iterations: 0,
            average_iterations: 0.0,
            wasted_iterations: 0,
            cutbacks: 0,
            final_time: 0.0,
            end_time,
            wall_time_s: 0.0,
            output_steps: 0,
            analyses: Vec::new(),
            warnings: Vec::new(),
            model_warnings: model.warnings.iter().map(|w| w.to_string()).collect(),
            increment_log: Vec::new(),
            modes: Vec::new(),
            latches: Vec::new(),
            stops: Vec::new(),
            contacts: Vec::new(),
            superelements: Vec::new(),
            initial_iterations: 0,
            unknowns: dofs,
        }
    }

    /// Adds what analysis `kind` (from `start_time` to `end_time`) did,
    /// `outcome`, to the counts; `initial_iterations` are those of its
    /// initial equilibrium (left out of the average).
    pub fn add(
        &mut self,
        kind: &str,
        start_time: f64,
        end_time: f64,
        outcome: &StaticOutcome,
        initial_iterations: usize,
    ) {
        self.add_end(
            kind,
            start_time,
            end_time,
            &outcome.into(),
            initial_iterations,
        );
    }

    /// As [`Summary::add`], for an analysis of any type that ended as
    /// `outcome` says.
    pub fn add_end(
        &mut self,
        kind: &str,
        start_time: f64,
        end_time: f64,
        outcome: &AnalysisEnd,
        initial_iterations: usize,
    ) {
        self.analyses.push(AnalysisRecord {
            kind: kind.to_string(),
            start_time,
            end_time,
            final_time: outcome.time,
            increments: outcome.increments,
            iterations: outcome.iterations,
            cutbacks: outcome.cutbacks,
            failed: outcome.error.is_some(),
            wall_time_s: outcome.wall_time,
            dynamic: outcome.dynamic.clone(),
        });
        self.redundant_constraints = self
            .redundant_constraints
            .max(outcome.redundant_constraints);
        // the equations solved: without the redundant ones
        self.dofs = self.unknowns.saturating_sub(self.redundant_constraints);
        self.increments += outcome.increments;
        self.iterations += outcome.iterations;
        self.wasted_iterations += outcome.wasted_iterations;
        self.cutbacks += outcome.cutbacks;
        self.final_time = outcome.time;
        self.wall_time_s += outcome.wall_time;
        // the initial equilibria are not increments
        self.initial_iterations += initial_iterations;
        self.average_iterations = if self.increments > 0 {
            self.iterations.saturating_sub(self.initial_iterations) as f64 / self.increments as f64
        } else {
            0.0
        };
    }

    /// Newton iterations of the initial equilibria of the analyses added
    /// (counted in `iterations`, not in `average_iterations`).
    pub fn initial_iterations(&self) -> usize {
        self.initial_iterations
    }

    /// The final status, the increments recorded by `writer`.
    pub fn finish(&mut self, writer: &ResultWriter, status: RunStatus, message: Option<String>) {
        self.status = status;
        self.message = message;
        self.output_steps = writer.output_steps();
        self.increment_log = writer.log.clone();
    }
}

/// A lock held on an output directory for the life of a run: an advisory
/// lock on `.unfold.lock`, released by the system when the process ends,
/// however it ends, so that the file left by a killed process does not
/// block the next run (which says so: [`DirectoryLock::stale_owner`]). The
/// file itself is removed when the lock is dropped (while still locked: a
/// run that opened it meanwhile finds, once it holds the lock, that the
/// file is no longer the one at the path, and starts again).
///
/// The lock file also holds [`SUMMARY_RESERVE`] bytes taken on the disk
/// when the run starts, given back by [`DirectoryLock::release_reserve`]
/// so that a run that filled the disk can still write the `summary.json`
/// saying that it failed.
#[derive(Debug)]
pub struct DirectoryLock {
    file: File,
    path: PathBuf,
    /// The process named in a lock file found unlocked (a run that did
    /// not end: killed, or its machine stopped).
    stale_owner: Option<String>,
    /// Length of the lock file without its reserve (the owner's id).
    owner_length: u64,
}

/// Attempts at locking a directory whose lock file is being replaced.
const LOCK_ATTEMPTS: usize = 10;

/// Bytes of disk taken by the lock file for the summary of a run that
/// fills the disk: more than a summary without its increment log (about
/// 2 kB, plus some 300 bytes per latch, stop and warning).
pub const SUMMARY_RESERVE: usize = 64 * 1024;

impl DirectoryLock {
    /// Locks `dir`, or fails with [`io::ErrorKind::ResourceBusy`] if
    /// another run holds it. A disk too full for the reserve of
    /// [`SUMMARY_RESERVE`] bytes fails too, before anything is written.
    pub fn acquire(dir: &Path) -> io::Result<Self> {
        let path = dir.join(LOCK_FILE);
        for _ in 0..LOCK_ATTEMPTS {
            let mut file = Self::try_acquire(dir, &path)?;
            // the file locked must still be the one at the path (not one
            // removed by the run that held it)
            if same_file(&file, &path) {
                // a process id left in a file nobody held: its run did not
                // end (a run that ends removes the file)
                let mut left = String::new();
                let _ = io::Read::read_to_string(&mut file, &mut left);
                let left = left.trim();
                let stale_owner = (!left.is_empty()).then(|| left.to_string());
                let owner = std::process::id().to_string();
                let reserve = vec![b' '; SUMMARY_RESERVE];
                file.set_len(0)
                    .and_then(|()| file.seek(SeekFrom::Start(0)))
                    .and_then(|_| file.write_all(owner.as_bytes()))
                    .and_then(|()| file.write_all(b"\n"))
                    .and_then(|()| file.write_all(&reserve))
                    .and_then(|()| file.flush())
                    .map_err(|e| {
                        // nothing of this run is left
                        let _ = std::fs::remove_file(&path);
                        file_error(&path, e)
                    })?;
                return Ok(Self {
                    file,
                    path,
                    stale_owner,
                    owner_length: owner.len() as u64 + 1,
                });
            }
        }
        Err(io::Error::new(
            io::ErrorKind::ResourceBusy,
            format!(
                "{}: its lock file {LOCK_FILE} keeps being replaced by other runs; choose another output directory",
                dir.display()
            ),
        ))
    }

    /// The process (its id) of a run whose lock file was found in the
    /// directory but held by nobody: that run did not end (it was killed,
    /// or its machine stopped) and its results there are replaced.
    pub fn stale_owner(&self) -> Option<&str> {
        self.stale_owner.as_deref()
    }

    /// Gives back the disk space reserved for the summary (see the type's
    /// documentation); the lock is kept.
    pub fn release_reserve(&mut self) -> io::Result<()> {
        self.file
            .set_len(self.owner_length)
            .map_err(|e| file_error(&self.path, e))
    }

    /// Opens and locks the lock file `path` of `dir`.
    fn try_acquire(dir: &Path, path: &Path) -> io::Result<File> {
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| file_error(path, e))?;
        match file.try_lock() {
            Ok(()) => Ok(file),
            Err(std::fs::TryLockError::WouldBlock) => {
                let owner = std::fs::read_to_string(path).unwrap_or_default();
                let owner = owner.trim();
                let by = if owner.is_empty() {
                    String::new()
                } else {
                    format!(" (process {owner})")
                };
                Err(io::Error::new(
                    io::ErrorKind::ResourceBusy,
                    format!(
                        "{}: another run is writing its results there{by}; wait for it to end or choose another output directory",
                        dir.display()
                    ),
                ))
            }
            Err(std::fs::TryLockError::Error(e)) => Err(file_error(path, e)),
        }
    }
}

impl Drop for DirectoryLock {
    fn drop(&mut self) {
        // removed while locked (see the type's documentation); the lock
        // goes with the file handle
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Whether `path` names the open `file` (the same inode).
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Without inode numbers a lock file in use cannot be removed (Windows),
/// so the file at the path is the one opened.
#[cfg(not(unix))]
fn same_file(_file: &File, _path: &Path) -> bool {
    true
}

/// A CSV file written one step at a time: the rows of a step are gathered
/// in `pending`, appended by [`Self::append`], and kept by
/// [`Self::settle`] or cut off by [`Self::rollback`].
struct CsvFile {
    path: PathBuf,
    file: File,
    /// Length of the file after the last settled step.
    settled: u64,
    /// Rows of the step being written (text, kept as bytes: the numbers
    /// are written into it as bytes).
    pending: Vec<u8>,
}

impl CsvFile {
    fn create(path: PathBuf, header: &str) -> io::Result<Self> {
        let mut file = File::create(&path).map_err(|e| file_error(&path, e))?;
        let line = format!("{header}\n");
        file.write_all(line.as_bytes())
            .map_err(|e| file_error(&path, e))?;
        Ok(Self {
            path,
            file,
            settled: line.len() as u64,
            pending: Vec::new(),
        })
    }

    fn append(&mut self) -> io::Result<()> {
        self.file
            .write_all(&self.pending)
            .map_err(|e| file_error(&self.path, e))
    }

    fn settle(&mut self) {
        self.settled += self.pending.len() as u64;
        self.pending.clear();
    }

    /// Cuts the file back to its last settled step (best effort: it only
    /// shortens the file, which needs no space).
    fn rollback(&mut self) {
        self.pending.clear();
        let _ = self.file.set_len(self.settled);
        let _ = self.file.seek(SeekFrom::Start(self.settled));
    }
}

/// The CSV file of the results of one kind of element.
struct ElementTable {
    kind: ElementKind,
    file: CsvFile,
    /// The result columns ([`ElementKind::result_columns`]), after the id
    /// column (and a joint's `type`).
    columns: Vec<&'static str>,
    /// Elements (indices in `model.elements`) in increasing id, each with
    /// the column of each of its results.
    elements: Vec<(usize, Vec<usize>)>,
    /// Number of columns whose rates follow the results (the joint
    /// coordinates, the first columns of joints.csv, in a run with
    /// dynamics), 0 otherwise.
    rates: usize,
}

/// Result columns written as integers: the states and sides of latches
/// (`locked`, `contact`), stops (`contact`), contacts (`closed`) and hinge
/// laws (`branch`).
const INTEGER_RESULTS: [&str; 4] = ["locked", "contact", "closed", "branch"];

/// The number of results of `e` whose rates are written in a run with
/// dynamics: a joint's coordinates, its first results.
fn rated_results(e: &dyn crate::elements::Element) -> usize {
    e.as_joint()
        .map_or(0, |j| j.joint_type().coordinates().len())
}

/// The files of a run with a dynamic analysis.
struct MotionFiles {
    /// `nodes_velocities.csv`.
    velocities: CsvFile,
    /// `energies.csv`.
    energies: CsvFile,
    /// `events.csv`: written row by row as events happen, after the step
    /// they happened on.
    events: CsvFile,
}

/// The header of `events.csv` (docs/results.md).
pub const EVENTS_HEADER: &str =
    "step,increment,time,element,kind,joint,coordinate,rate_before,rate_after,impulse,energy_lost";

/// One row of `events.csv`: a latch locking, a stop struck, closed or
/// released.
#[derive(Clone, Debug, PartialEq)]
pub struct EventRow<'a> {
    /// The increment (time step) it happened on, numbered across the run.
    pub increment: usize,
    /// Its time.
    pub time: f64,
    /// The latch or stop.
    pub element: crate::model::Id,
    /// `lock`, `impact`, `contact` or `release`.
    pub kind: &'a str,
    /// The joint whose coordinate it watches (none for a contact with a
    /// plane: the column is left empty).
    pub joint: Option<crate::model::Id>,
    /// The coordinate at the event.
    pub coordinate: f64,
    /// The coordinate's rate before and after.
    pub rate_before: f64,
    /// See [`Self::rate_before`].
    pub rate_after: f64,
    /// The impulse along the coordinate.
    pub impulse: f64,
    /// The energy the impact dissipated.
    pub energy_lost: f64,
}

/// Relative motion over the step of the differences that give the rates of
/// the joint coordinates: 1e-4 of the model size or 1e-4 rad. With
/// Richardson extrapolation of central differences the truncation error is
/// of order (1e-4)⁴ and the round-off about 1e-12 of the rate.
const RATE_MOTION: f64 = 1e-4;

/// Writes result files as the analysis converges.
pub struct ResultWriter {
    dir: PathBuf,
    lock: DirectoryLock,
    encoding: vtk::Encoding,
    /// A grid at every this many output steps; 0: none.
    vtk_every: usize,
    nodes: CsvFile,
    /// Node indices in increasing id.
    node_order: Vec<usize>,
    steps: CsvFile,
    reactions: Option<CsvFile>,
    /// Supported nodes (indices) in increasing id, for reactions.
    supported: Vec<usize>,
    tables: Vec<ElementTable>,
    /// Result values of one element: as long as the longest list of
    /// result names of the model.
    values: Vec<f64>,
    /// A row of a table: its result columns, then its rates.
    row: Vec<f64>,
    pvd_file: vtk::PvdFile,
    /// Output steps written (a grid at some of them: `vtk_every`).
    output_steps: usize,
    /// The time of the last output step written.
    last_output: Option<f64>,
    /// Every converged increment, for the summary.
    pub log: Vec<IncrementRecord>,
    /// The files of a run with dynamics.
    motion: Option<MotionFiles>,
    /// The analysis running is dynamic: its steps have velocities and
    /// energies.
    moving: bool,
    /// The energies of the step about to be written, if dynamic.
    energies: Option<Energies>,
}

/// Removes `path` if it exists.
fn remove_if_present(path: &Path) -> io::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(file_error(path, e)),
        _ => Ok(()),
    }
}

/// Whether `name` is a grid of a step, or the temporary file of one.
fn is_step_grid(name: &str) -> bool {
    name.starts_with("step_") && (name.ends_with(".vtu") || name.ends_with(".tmp"))
}

/// Removes from `dir` the files of an earlier run that this one will not
/// rewrite (those `writes` does not name), every temporary file and every
/// grid `vtk/step_NNNNN.vtu`.
fn remove_leftovers(dir: &Path, writes: impl Fn(&str) -> bool) -> io::Result<()> {
    for name in owned_files() {
        if !writes(name) {
            remove_if_present(&dir.join(name))?;
        }
        remove_if_present(&dir.join(format!("{name}.tmp")))?;
    }
    // the temporary collection of earlier versions
    remove_if_present(&dir.join("unfold.tmp"))?;
    let vtk_dir = dir.join("vtk");
    let entries = match std::fs::read_dir(&vtk_dir) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        entries => entries.map_err(|e| file_error(&vtk_dir, e))?,
    };
    for entry in entries {
        let path = entry.map_err(|e| file_error(&vtk_dir, e))?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if is_step_grid(name) {
            remove_if_present(&path)?;
        }
    }
    Ok(())
}

/// Records in `dir` a run rejected before its first analysis started, by
/// the checks of [`crate::analysis::preflight`]: `summary.json` alone
/// (`summary`, the run's summary as it started, for example
/// [`Summary::start`]), status `failed` with `message`. The directory is
/// locked as for a run, and the files of an earlier run are removed (none
/// would belong to this model), its restart files too but `keep` (the
/// restart file given to this run, if any); no other file is written.
pub fn write_rejected(
    dir: &Path,
    mut summary: Summary,
    message: &str,
    keep: Option<&Path>,
) -> io::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| file_error(dir, e))?;
    let mut lock = DirectoryLock::acquire(dir)?;
    remove_leftovers(dir, |_| false)?;
    super::restart::remove_earlier(dir, keep)?;
    // an empty grid folder of an earlier run goes too
    let _ = std::fs::remove_dir(dir.join("vtk"));
    summary.status = RunStatus::Failed;
    summary.message = Some(message.to_string());
    write_summary_file(dir, &summary, &mut lock)
}

/// Writes `summary` to `dir/summary.json` (through a temporary file, so
/// that it is never seen half written). If that fails (a full disk), the
/// lock's reserve is given back and the summary written again, and then
/// without its increment log (saying so in its message) if it is still
/// too long.
fn write_summary_file(dir: &Path, summary: &Summary, lock: &mut DirectoryLock) -> io::Result<()> {
    let path = dir.join("summary.json");
    let write = |summary: &Summary| {
        let text = serde_json::to_string_pretty(summary).map_err(io::Error::other)?;
        vtk::write_atomically(&path, (text + "\n").as_bytes())
    };
    let Err(first) = write(summary) else {
        return Ok(());
    };
    if lock.release_reserve().is_ok() {
        if write(summary).is_ok() {
            return Ok(());
        }
        let note = "the increment log is left out: the disk was too full for it";
        let compact = Summary {
            increment_log: Vec::new(),
            message: Some(match &summary.message {
                Some(m) => format!("{m} ({note})"),
                None => note.to_string(),
            }),
            ..summary.clone()
        };
        if write(&compact).is_ok() {
            return Ok(());
        }
    }
    Err(first)
}

impl ResultWriter {
    /// Locks `dir` (creating it and `dir/vtk`), removes the result files
    /// of an earlier run that this one will not rewrite (see the module
    /// documentation), and creates the CSV files with their headers.
    pub fn create(dir: &Path, model: &Model) -> io::Result<Self> {
        Self::create_for(dir, model, false)
    }

    /// As [`ResultWriter::create`], for a run with a dynamic analysis if
    /// `dynamics`: it also writes `nodes_velocities.csv`, `energies.csv`,
    /// the rates of the joint coordinates and the velocities in the grids.
    pub fn create_for(dir: &Path, model: &Model, dynamics: bool) -> io::Result<Self> {
        let vtk_dir = dir.join("vtk");
        std::fs::create_dir_all(&vtk_dir).map_err(|e| file_error(&vtk_dir, e))?;
        let lock = DirectoryLock::acquire(dir)?;

        // what this run writes
        let has = |k: ElementKind| model.elements.iter().any(|e| e.kind() == k);
        let supported = {
            let mut s: Vec<usize> = (0..model.n_nodes())
                .filter(|&i| model.fixed[i].iter().any(|&f| f))
                .collect();
            s.sort_by_key(|&i| model.node_ids[i]);
            s
        };
        let writes = |name: &str| match name {
            "reactions.csv" => !supported.is_empty(),
            "nodes_velocities.csv" | "energies.csv" | "events.csv" => dynamics,
            // written again by whoever writes the summary
            "summary.json" => false,
            // the page of earlier results: `unfold view` makes it again
            "view.html" => false,
            _ => ElementKind::ALL
                .into_iter()
                .find(|k| k.results_file() == Some(name))
                .is_none_or(has),
        };

        remove_leftovers(dir, writes)?;
        super::modes::remove_leftovers(dir)?;

        let mut node_order: Vec<usize> = (0..model.n_nodes()).collect();
        node_order.sort_by_key(|&i| model.node_ids[i]);
        // one table per kind that has results, a column for each quantity
        // its elements report (a joint only its own coordinates)
        let mut tables = Vec::new();
        for kind in ElementKind::ALL {
            let Some(name) = kind.results_file() else {
                continue;
            };
            let mut elements: Vec<usize> = (0..model.elements.len())
                .filter(|&k| model.elements[k].kind() == kind)
                .collect();
            if elements.is_empty() {
                continue;
            }
            elements.sort_by_key(|&k| model.elements[k].id());
            let columns =
                kind.result_columns(elements.iter().map(|&k| model.elements[k].result_names()));
            let elements: Vec<(usize, Vec<usize>)> = elements
                .into_iter()
                .map(|k| {
                    let names = model.elements[k].result_names();
                    let at = |n: &&str| columns.iter().position(|c| c == n);
                    (k, names.iter().filter_map(at).collect())
                })
                .collect();
            // the rates of the columns of the coordinates, the first ones
            let rates = if dynamics {
                let mut rated: Vec<usize> = elements
                    .iter()
                    .flat_map(|(k, at)| &at[..rated_results(&*model.elements[*k])])
                    .copied()
                    .collect();
                rated.sort_unstable();
                rated.dedup();
                debug_assert!(rated.iter().enumerate().all(|(i, &c)| i == c));
                rated.len()
            } else {
                0
            };
            let mut header = format!("step,time,{}", kind.id_column());
            if kind == ElementKind::Joint {
                header += ",type";
            }
            for c in &columns {
                header += &format!(",{c}");
            }
            for c in &columns[..rates] {
                header += &format!(",{c}_rate");
            }
            tables.push(ElementTable {
                kind,
                file: CsvFile::create(dir.join(name), &header)?,
                columns,
                elements,
                rates,
            });
        }
        let longest = model
            .elements
            .iter()
            .map(|e| e.result_names().len())
            .max()
            .unwrap_or(0);
        Ok(Self {
            dir: dir.to_path_buf(),
            lock,
            encoding: vtk::Encoding::default(),
            vtk_every: 1,
            nodes: CsvFile::create(
                dir.join("nodes.csv"),
                "step,time,node,x,y,z,ux,uy,uz,qw,qx,qy,qz",
            )?,
            node_order,
            steps: CsvFile::create(
                dir.join("steps.csv"),
                "step,increment,time,step_size,iterations,relative_residual",
            )?,
            reactions: (!supported.is_empty())
                .then(|| {
                    CsvFile::create(
                        dir.join("reactions.csv"),
                        "step,time,node,Fx,Fy,Fz,Mx,My,Mz",
                    )
                })
                .transpose()?,
            supported,
            tables,
            values: vec![0.0; longest],
            row: Vec::new(),
            output_steps: 0,
            last_output: None,
            pvd_file: vtk::PvdFile::new(dir.join("unfold.pvd")),
            log: Vec::new(),
            motion: dynamics
                .then(|| -> io::Result<MotionFiles> {
                    Ok(MotionFiles {
                        velocities: CsvFile::create(
                            dir.join("nodes_velocities.csv"),
                            "step,time,node,vx,vy,vz,wx,wy,wz,ax,ay,az,dwx,dwy,dwz",
                        )?,
                        energies: CsvFile::create(
                            dir.join("energies.csv"),
                            "step,time,kinetic,strain,gravity,spring,external_work,dissipated,balance_error,hinge_law_work",
                        )?,
                        events: CsvFile::create(dir.join("events.csv"), EVENTS_HEADER)?,
                    })
                })
                .transpose()?,
            moving: false,
            energies: None,
        })
    }

    /// Whether the analysis now running is dynamic (its steps have
    /// velocities and energies; those of the others are at rest).
    pub fn set_dynamic(&mut self, dynamic: bool) {
        self.moving = dynamic;
        self.energies = None;
    }

    /// Writes a VTK grid at every `every`-th output step (the first
    /// included), none if `every` is 0 (`[output] vtk`, `vtk_every`).
    pub fn with_vtk_every(mut self, every: usize) -> Self {
        self.vtk_every = every;
        if every == 0 {
            // no grid will be written: no empty directory either
            let _ = std::fs::remove_dir(self.dir.join("vtk"));
        }
        self
    }

    /// Writes the grids in `encoding` (binary by default).
    pub fn with_vtk_encoding(mut self, encoding: vtk::Encoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Number of output steps written.
    pub fn output_steps(&self) -> usize {
        self.output_steps
    }

    /// The load parameter of the last output step written, if any.
    pub fn last_output_time(&self) -> Option<f64> {
        self.last_output
    }

    /// Writes `summary.json` (through a temporary file, so that it is
    /// never seen half written; on a full disk, into the space the lock
    /// reserved for it).
    pub fn write_summary(&mut self, summary: &Summary) -> io::Result<()> {
        write_summary_file(&self.dir, summary, &mut self.lock)
    }

    /// The process of an earlier run whose lock file was left in the
    /// directory (see [`DirectoryLock::stale_owner`]).
    pub fn stale_lock(&self) -> Option<&str> {
        self.lock.stale_owner()
    }

    /// Appends `row` to `events.csv` (a run with dynamics; its step, the
    /// last output step, was written before).
    pub fn write_event(&mut self, row: &EventRow) -> io::Result<()> {
        let step = self.output_steps.saturating_sub(1);
        let Some(m) = self.motion.as_mut() else {
            return Ok(());
        };
        m.events.pending = format!(
            "{step},{},{:e},{},{},{},{:e},{:e},{:e},{:e},{:e}\n",
            row.increment,
            row.time,
            row.element,
            row.kind,
            row.joint.map_or(String::new(), |j| j.to_string()),
            row.coordinate,
            row.rate_before,
            row.rate_after,
            row.impulse,
            row.energy_lost
        )
        .into_bytes();
        match m.events.append() {
            Ok(()) => {
                m.events.settle();
                Ok(())
            }
            Err(e) => {
                m.events.rollback();
                Err(e)
            }
        }
    }

    /// Every CSV file.
    fn csv_files(&mut self) -> impl Iterator<Item = &mut CsvFile> {
        let motion = self
            .motion
            .as_mut()
            .map(|m| [&mut m.velocities, &mut m.energies]);
        [&mut self.nodes, &mut self.steps]
            .into_iter()
            .chain(self.reactions.as_mut())
            .chain(self.tables.iter_mut().map(|t| &mut t.file))
            .chain(motion.into_iter().flatten())
    }

    /// Formats the rows of output step `step` into the files' pending
    /// text.
    fn format_step(
        &mut self,
        step: usize,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) {
        let t = info.time;
        // `step,time,` of every row
        let mut lead = Vec::new();
        push_integer(&mut lead, step as u64, 0);
        lead.push(b',');
        Sci::<12>(t).push_bytes(&mut lead);
        lead.push(b',');
        for &i in &self.node_order {
            let x = state.x[i];
            let u = x - model.reference_x[i];
            let q = state.q[i].quaternion();
            let w = &mut self.nodes.pending;
            w.extend_from_slice(&lead);
            push_integer(w, model.node_ids[i], 0);
            push_values::<12>(w, &[x.x, x.y, x.z, u.x, u.y, u.z]);
            // the quaternion to the last digit: it reads back to the same
            // unit quaternion
            for c in [q.w, q.i, q.j, q.k] {
                w.push(b',');
                Shortest(c).push_bytes(w);
            }
            w.push(b'\n');
        }
        let ctx = model.context(t, Need::RESIDUAL);
        // the state moved along its velocities, for the rates
        let moved = if self.moving && self.tables.iter().any(|t| t.rates > 0) {
            motion_probes(model, state)
        } else {
            None
        };
        let mut rates = [0.0; Coordinate::ALL.len()];
        for table in &mut self.tables {
            self.row.clear();
            self.row.resize(table.columns.len() + table.rates, f64::NAN);
            let (row, row_rates) = self.row.split_at_mut(table.columns.len());
            for (k, at) in &table.elements {
                let e = &model.elements[*k];
                debug_assert_eq!(e.kind(), table.kind);
                let n = e.result_names().len();
                let values = &mut self.values[..n];
                values.fill(0.0);
                e.results(&ctx, state, values);
                // absent quantities (a coordinate the joint does not have)
                // are empty
                row.fill(f64::NAN);
                for (&c, &v) in at.iter().zip(values.iter()) {
                    row[c] = v;
                }
                let w = &mut table.file.pending;
                w.extend_from_slice(&lead);
                push_integer(w, e.id(), 0);
                if table.kind == ElementKind::Joint {
                    let t = e.as_joint().map_or("", |j| j.joint_type().name());
                    w.push(b',');
                    w.extend_from_slice(t.as_bytes());
                }
                for (v, name) in row.iter().zip(&table.columns) {
                    w.push(b',');
                    if INTEGER_RESULTS.contains(name) && v.is_finite() {
                        // a state or a side: 0, 1, −1
                        let _ = write!(w, "{}", v.round() as i64);
                    } else if !v.is_nan() {
                        // + 0.0: a load −f of f = 0 is written 0, not −0
                        Sci::<9>(*v + 0.0).push_bytes(w);
                    }
                }
                if table.rates > 0 {
                    row_rates.fill(f64::NAN);
                    let r = &mut rates[..rated_results(e.as_ref()).min(n)];
                    match &moved {
                        Some(probes) => result_rates(e.as_ref(), &ctx, probes, r),
                        None => r.fill(0.0),
                    }
                    for ((&c, v), value) in at.iter().zip(r.iter()).zip(values.iter()) {
                        if !value.is_nan() {
                            row_rates[c] = *v;
                        }
                    }
                    for v in row_rates.iter() {
                        w.push(b',');
                        if !v.is_nan() {
                            Sci::<9>(*v + 0.0).push_bytes(w);
                        }
                    }
                }
                w.push(b'\n');
            }
        }
        if let Some(m) = self.motion.as_mut() {
            for &i in &self.node_order {
                // at rest outside dynamic analyses; Ω and Ω̇ material, to
                // global: ω = RΩ, ω̇ = RΩ̇
                let (v, a) = if self.moving {
                    (state.velocity[i], state.acceleration[i])
                } else {
                    ([0.0; 6], [0.0; 6])
                };
                let r = so3::matrix(&state.q[i]);
                let w = r * Vec3::new(v[3], v[4], v[5]);
                let dw = r * Vec3::new(a[3], a[4], a[5]);
                let out = &mut m.velocities.pending;
                out.extend_from_slice(&lead);
                push_integer(out, model.node_ids[i], 0);
                push_values::<12>(out, &[v[0], v[1], v[2], w.x, w.y, w.z]);
                push_values::<9>(out, &[a[0], a[1], a[2], dw.x, dw.y, dw.z]);
                out.push(b'\n');
            }
            match (self.moving, &self.energies) {
                (true, Some(e)) => {
                    let _ = writeln!(
                        m.energies.pending,
                        "{step},{t:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.6e},{:.12e}",
                        e.kinetic,
                        e.strain,
                        e.gravity,
                        e.spring,
                        e.external_work,
                        e.dissipated,
                        e.balance_error,
                        e.hinge_law_work
                    );
                }
                _ => {
                    // at rest (a static step): the stored energies; work,
                    // dissipation and balance belong to motions
                    let e = crate::analysis::energy::energies(model, state);
                    let _ = writeln!(
                        m.energies.pending,
                        "{step},{t:.12e},{:.12e},{:.12e},{:.12e},{:.12e},,,,",
                        0.0, e.strain, e.gravity, e.spring
                    );
                }
            }
        }
        if let Some(file) = self.reactions.as_mut() {
            for &i in &self.supported {
                let f = Vec3::new(residual[6 * i], residual[6 * i + 1], residual[6 * i + 2]);
                // the rotational residual is conjugate to material rotations
                let m_mat = Vec3::new(
                    residual[6 * i + 3],
                    residual[6 * i + 4],
                    residual[6 * i + 5],
                );
                let m = so3::matrix(&state.q[i]) * m_mat;
                let out = &mut file.pending;
                out.extend_from_slice(&lead);
                push_integer(out, model.node_ids[i], 0);
                push_values::<9>(out, &[f.x, f.y, f.z, m.x, m.y, m.z]);
                out.push(b'\n');
            }
        }
        let _ = writeln!(
            self.steps.pending,
            "{step},{},{t:.12e},{:.6e},{},{:.3e}",
            info.increment,
            info.step,
            info.iterations,
            info.residuals.last().copied().unwrap_or(0.0)
        );
    }

    /// Writes one output step to every file, or to none (see the module
    /// documentation).
    fn write_step(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> io::Result<()> {
        let step = self.output_steps;
        self.format_step(step, info, model, state, residual);
        // the grid of this output step, if one is written
        let grid = (self.vtk_every > 0 && step.is_multiple_of(self.vtk_every)).then(|| {
            let name = format!("step_{step:05}.vtu");
            (self.dir.join("vtk").join(&name), format!("vtk/{name}"))
        });
        if let Some((path, _)) = &grid {
            let ctx = model.context(info.time, Need::RESIDUAL);
            let velocities = self.motion.is_some().then_some(self.moving);
            if let Err(e) = vtk::write_step_vtu(path, model, &ctx, state, self.encoding, velocities)
            {
                self.csv_files().for_each(CsvFile::rollback);
                return Err(e);
            }
        }
        let mut result = self.csv_files().try_for_each(|f| f.append());
        if let (true, Some((_, file))) = (result.is_ok(), &grid) {
            result = self.pvd_file.append(info.time, file);
        }
        if result.is_ok() {
            self.output_steps += 1;
            self.last_output = Some(info.time);
        }
        match result {
            Ok(()) => {
                self.csv_files().for_each(CsvFile::settle);
                Ok(())
            }
            Err(e) => {
                self.csv_files().for_each(CsvFile::rollback);
                if let Some((path, _)) = &grid {
                    let _ = std::fs::remove_file(path);
                }
                Err(e)
            }
        }
    }
}

/// Appends `,v` for every value, with `P` digits after the point
/// (`{:.Pe}`).
fn push_values<const P: usize>(out: &mut Vec<u8>, values: &[f64]) {
    for &v in values {
        out.push(b',');
        Sci::<P>(v).push_bytes(out);
    }
}

/// The state moved along its velocities by `±e` and `±e/2` (nodes on the
/// group, `x + e ẋ`, `R exp(e Ω~)`; coordinates `c + e ċ`), and `e`; `None`
/// at rest.
fn motion_probes(model: &Model, state: &State) -> Option<(f64, [State; 4])> {
    let (mut v, mut w) = (0.0f64, 0.0f64);
    for r in &state.velocity {
        v = v.max(Vec3::new(r[0], r[1], r[2]).norm());
        w = w.max(Vec3::new(r[3], r[4], r[5]).norm());
    }
    let rate = state
        .coordinate_rates
        .iter()
        .fold(0.0f64, |m, r| m.max(r.abs()));
    // the inverse of the time over which a node moves by the model's size
    // or turns by a radian (a coordinate, length or angle, likewise)
    let l = model.length_scale;
    let pace = (v / l).max(w).max(rate / l.min(1.0));
    if pace == 0.0 || !pace.is_finite() {
        return None;
    }
    let e = RATE_MOTION / pace;
    let moved = |h: f64| {
        let mut s = state.clone();
        for node in 0..s.n_nodes() {
            let r = state.velocity[node];
            s.displace_node(
                node,
                &(Vec3::new(r[0], r[1], r[2]) * h),
                &(Vec3::new(r[3], r[4], r[5]) * h),
            );
        }
        for (c, r) in s.coordinates.iter_mut().zip(&state.coordinate_rates) {
            *c += h * r;
        }
        s
    };
    Some((e, [moved(e), moved(-e), moved(0.5 * e), moved(-0.5 * e)]))
}

/// The rates of the first `out.len()` results of `element` along the
/// motion: central differences over `±e` and `±e/2`, Richardson
/// extrapolated, `ċ = (4 D(e/2) − D(e))/3`.
fn result_rates(
    element: &dyn crate::elements::Element,
    ctx: &crate::elements::EvalContext,
    (e, probes): &(f64, [State; 4]),
    out: &mut [f64],
) {
    let n = element.result_names().len();
    let mut values = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for (v, s) in values.iter_mut().zip(probes) {
        element.results(ctx, s, v);
    }
    for (k, r) in out.iter_mut().enumerate() {
        let d1 = (values[0][k] - values[1][k]) / (2.0 * e);
        let d2 = (values[2][k] - values[3][k]) / e;
        *r = (4.0 * d2 - d1) / 3.0;
    }
}

impl Observer for ResultWriter {
    fn energies(&mut self, energies: &Energies) {
        self.energies = Some(*energies);
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        reactions: &[f64],
    ) -> io::Result<()> {
        self.log.push(IncrementRecord {
            increment: info.increment,
            time: info.time,
            step: info.step,
            iterations: info.iterations,
            residuals: info.residuals.clone(),
        });
        if info.output {
            self.write_step(info, model, state, reactions)?;
        }
        Ok(())
    }
}
