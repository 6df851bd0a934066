//! A run's record: the result files ([`super::results`]), `log.txt` and
//! `summary.json`, written by one [`Recorder`] for the command-line tool
//! and for programs that build their model with the library.
//!
//! ```no_run
//! # use std::sync::Arc;
//! # use unfold::analysis::{StaticAnalysis, StaticSettings};
//! # use unfold::io::run::{Recorder, Silent};
//! # fn run(model: Arc<unfold::model::Model>, settings: StaticSettings) -> std::io::Result<()> {
//! let mut analysis = StaticAnalysis::new(model.clone(), settings);
//! let mut recorder = Recorder::create("results/x".as_ref(), "x.toml", &analysis, Silent)?;
//! let outcome = analysis.run(model.initial_state(), &mut recorder);
//! let report = recorder.finish(&outcome);
//! # Ok(()) }
//! ```
//!
//! A sequence of analyses ([`Recorder::create_sequence`]) is recorded in
//! one set of files: each analysis starts from the final state of the one
//! before ([`Recorder::next_analysis`]), the output steps and increments
//! are numbered on across them, and `summary.json` lists each analysis.
//!
//! A dynamic analysis ([`Recorder::create_dynamic_first`],
//! [`Recorder::open_dynamic`], [`Recorder::end_analysis`]) adds its time
//! steps, the velocities of its output steps and their energies
//! (`nodes_velocities.csv`, `energies.csv`) and its energy balance in
//! `summary.json`.
//!
//! Stopping: a [`StopRequest`] shared with the recorder (set by
//! [`stop_on_signals`] on SIGINT, SIGTERM or SIGHUP) makes it write the
//! increment that has just converged as an output step, then stop the
//! analysis with an [`Interrupted`] error; the summary then says
//! `interrupted`. A step is never split between files: the request is
//! looked at between increments, and a second signal, which ends the
//! process at once, waits for the step being written.
//!
//! Restart files ([`super::restart`]): with [`Recorder::with_restart`]
//! the recorder writes them at the requested times and, when the run ends,
//! `restart.json` with its last converged state.
//!
//! The library never prints: what a person should see goes to a
//! [`Console`], which the caller provides.

use std::borrow::Cow;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicI32, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use super::modes::ModalFiles;
use super::peaks::PeakLoads;
use super::restart::RestartWriter;
use super::results::{
    file_error, AnalysisEnd, DynamicRecord, EventRow, ResultWriter, RunStatus, Summary,
};
use super::vtk::Encoding;
use crate::analysis::impact::{self, LatchEventKind};
use crate::analysis::statics::StaticError;
use crate::analysis::{
    AnalysisSettings, ContactInfo, Continuation, CutbackInfo, DynamicAnalysis, DynamicError,
    Energies, EventInfo, IncrementInfo, IterationInfo, LockInfo, Observer, RejectionInfo,
    StaticAnalysis, StaticOutcome, WarningInfo,
};
use crate::elements::ElementKind;
use crate::joints::latch::Latch;
use crate::joints::stop::Contact;
use crate::model::{Id, Model};
use crate::state::State;

mod modal;

use super::line::Line;
use super::residual::{Reported, Shown};

/// What a person watching the run sees. Every method has an empty
/// default.
pub trait Console {
    /// A line of the log worth showing: an increment, a cut-back, a note.
    fn line(&mut self, _text: &str) {}
    /// After each converged increment.
    fn progress(&mut self, _info: &IncrementInfo) {}
    /// The last line of the run (status, counts, where the results are).
    fn finish(&mut self, _text: &str) {}
    /// A warning of the analysis (shown even when lines are not).
    fn warning(&mut self, _text: &str) {}
    /// A note on the outcome of the run (a latch that never locked), to be
    /// shown even when lines are not; `text` starts with `note:`.
    fn note(&mut self, text: &str) {
        self.line(text);
    }
}

/// A console that shows nothing.
pub struct Silent;

impl Console for Silent {}

/// A request to stop a run between increments, shared between the thread
/// that asks (a signal handler) and the [`Recorder`]. It also guards the
/// writing of a step: [`StopRequest::output`] is held while a step is
/// written.
#[derive(Clone, Debug, Default)]
pub struct StopRequest {
    inner: Arc<StopInner>,
}

#[derive(Debug, Default)]
struct StopInner {
    /// 0: none; −1: asked without a signal; otherwise the signal number.
    signal: AtomicI32,
    output: Mutex<()>,
}

impl StopRequest {
    /// No stop requested.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the run to stop, because of `signal` (its number) if any.
    /// Only the first request counts.
    pub fn request(&self, signal: Option<i32>) {
        let _ = self.inner.signal.compare_exchange(
            0,
            signal.unwrap_or(-1),
            Ordering::SeqCst,
            Ordering::SeqCst,
        );
    }

    /// Whether a stop was requested, and by which signal.
    pub fn requested(&self) -> Option<Interrupted> {
        match self.inner.signal.load(Ordering::SeqCst) {
            0 => None,
            -1 => Some(Interrupted { signal: None }),
            s => Some(Interrupted { signal: Some(s) }),
        }
    }

    /// Held while a step is being written.
    pub fn output(&self) -> MutexGuard<'_, ()> {
        self.inner
            .output
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// The error with which a recorder stops an analysis on request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interrupted {
    /// The signal that asked for it.
    pub signal: Option<i32>,
}

impl Interrupted {
    /// The exit status of a process stopped this way: `128 + signal`
    /// (130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP), as shells
    /// report a process killed by the signal; 1 without a signal.
    pub fn exit_code(&self) -> u8 {
        self.signal
            .and_then(|s| u8::try_from(128 + s).ok())
            .unwrap_or(1)
    }

    /// The interruption behind a stopped analysis, if that is why it
    /// stopped.
    pub fn of(error: &StaticError) -> Option<Self> {
        match error {
            StaticError::Output(e) => e.get_ref()?.downcast_ref::<Self>().copied(),
            _ => None,
        }
    }

    /// As [`Interrupted::of`], for a dynamic analysis.
    pub fn of_dynamic(error: &DynamicError) -> Option<Self> {
        match error {
            DynamicError::Output(e) => e.get_ref()?.downcast_ref::<Self>().copied(),
            _ => None,
        }
    }
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.signal {
            Some(s) => write!(f, "interrupted by {}", signal_name(s)),
            None => write!(f, "interrupted"),
        }
    }
}

impl std::error::Error for Interrupted {}

/// The usual name of a signal number.
pub fn signal_name(signal: i32) -> String {
    match signal {
        1 => "SIGHUP".into(),
        2 => "SIGINT".into(),
        15 => "SIGTERM".into(),
        s => format!("signal {s}"),
    }
}

/// What a signal handler installed by [`stop_on_signals`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SignalEvent {
    /// A first signal: the run will stop after the current increment.
    Stopping(i32),
    /// A second signal: the process ends now, with status `128 + signal`,
    /// once the step being written (if any) is complete.
    Ending(i32),
}

/// A signal within this time of the first is the same request, not a
/// second one: GNU `timeout` sends its signal to the run and then to its
/// whole process group, so that the run receives it twice within
/// microseconds; a person's second Ctrl-C comes after reading the first
/// message.
pub const SAME_REQUEST: std::time::Duration = std::time::Duration::from_millis(250);

/// Handles SIGINT, SIGTERM and SIGHUP from now on (Unix): the first sets
/// `stop`, a second one (more than [`SAME_REQUEST`] after the first) ends
/// the process at once (status `128 + signal`) after the step being
/// written. `report` is called on each, from the handling thread. It also
/// makes a write past the file-size limit (`ulimit -f`) fail with an
/// error instead of killing the process (SIGXFSZ).
#[cfg(unix)]
pub fn stop_on_signals(
    stop: &StopRequest,
    report: impl Fn(SignalEvent) + Send + 'static,
) -> io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM, SIGXFSZ};
    signal_hook::flag::register(SIGXFSZ, Arc::new(std::sync::atomic::AtomicBool::new(false)))?;
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    let stop = stop.clone();
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let mut first: Option<std::time::Instant> = None;
            for signal in signals.forever() {
                match first {
                    None => {
                        first = Some(std::time::Instant::now());
                        stop.request(Some(signal));
                        report(SignalEvent::Stopping(signal));
                        continue;
                    }
                    Some(at) if at.elapsed() < SAME_REQUEST => continue,
                    Some(_) => {}
                }
                report(SignalEvent::Ending(signal));
                let _writing = stop.output();
                std::process::exit(128 + signal);
            }
        })?;
    Ok(())
}

/// Without Unix signals, nothing is installed.
#[cfg(not(unix))]
pub fn stop_on_signals(
    _stop: &StopRequest,
    _report: impl Fn(SignalEvent) + Send + 'static,
) -> io::Result<()> {
    Ok(())
}

/// A load parameter for messages: six decimals, trailing zeros dropped
/// (`1`, `0.071849`), or six in exponent form outside `[1e-3, 1e6)`.
pub fn format_time(t: f64) -> String {
    if t == 0.0 || !t.is_finite() {
        return format!("{t}");
    }
    if (1e-3..1e6).contains(&t.abs()) {
        let fixed = format!("{t:.6}");
        fixed
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{t:.6e}")
    }
}

/// The message of a dynamic analysis that stopped with `error` at `state`,
/// for a person: the error itself, except for initial velocities that move
/// a latch locked at the start (at its value in the start state `state`,
/// within the event tolerance), where the generic advice (one rigid
/// motion) does not fit.
pub fn dynamic_error_message(model: &Model, state: &State, error: &DynamicError) -> String {
    let DynamicError::InconsistentVelocity {
        constraint,
        rate,
        tolerance,
    } = error
    else {
        return error.to_string();
    };
    // a rolling disc (docs/joints.md §3.8): equation 1 keeps the rim on
    // the plane, equations 2 and 3 are the no-slip conditions along the
    // plane's tangents t₁, t₂
    if let Some(rest) = constraint.strip_prefix("rolling disc ") {
        let equation = rest.rsplit(' ').next().unwrap_or("");
        let id = rest.split(' ').next().unwrap_or("");
        return match equation {
            "2" | "3" => format!(
                "the initial velocities violate rolling disc {id} equation {equation} (no slip along the plane's tangent t{}): its contact point slides at {rate:.3e} (tolerance {tolerance:.1e}); the disc must roll: give its centre the velocity ω × (centre − contact point), so that a centre speed v goes with a spin v/r about the axle (−v/r about the axle a for a disc rolling along n × a, n the plane's normal; docs/joints.md §3.8)",
                if equation == "2" { 1 } else { 2 }
            ),
            _ => format!(
                "the initial velocities violate rolling disc {id} equation {equation} (contact with the plane): its rim's lowest point moves along the plane's normal at {rate:.3e} (tolerance {tolerance:.1e}); give the centre a velocity in the plane, and the disc no tilting rate that raises or lowers its rim (docs/joints.md §3.8)"
            ),
        };
    }
    // a driver whose curve starts moving while the bodies are at rest
    if let Some(rest) = constraint.strip_prefix("driver ") {
        let id = rest.split(' ').next().unwrap_or("");
        return format!(
            "the initial velocities violate driver {id}: its curve moves the joint at the start (the constraint's rate is {rate:.3e}, tolerance {tolerance:.1e}) while the initial velocities do not; start the driver's curve with zero rate (function = \"smooth_step\", or a table whose first segment is flat), or give the driven bodies the initial velocities of that motion"
        );
    }
    let latch = model.elements.iter().find_map(|e| {
        let l = e.as_latch()?;
        (*constraint == format!("{} {} equation 1", e.kind().name(), e.id())).then_some((e.id(), l))
    });
    let Some((id, latch)) = latch else {
        return error.to_string();
    };
    let c = latch.coordinate(state);
    let unit = if latch.is_angle() { " rad" } else { "" };
    // the joint's own rate `ċ` (the constraint's rate `Φ̇` has the sign of
    // its equation, not of the coordinate)
    let joint_rate = latch.rate(state).0;
    format!(
        "latch {id} is at its locking value at t = {} (joint {} at {}{unit}, the latch's value {}{unit}), so it is locked from the start, but the initial velocities move the joint: its rate is {joint_rate:.3e} (tolerance {tolerance:.1e}); give the joint's nodes velocities that keep the coordinate still, or start the joint away from the latch's value",
        format_time(state.time),
        latch.joint(),
        format_time(c),
        format_time(latch.value())
    )
}

/// The events of dynamic analyses in a few words (`1 lock, 3 impacts,
/// 1 contact closed, energy lost in impacts 7.401e0`, then `; spring
/// latches' band crossings: 6 engages, 5 disengages` if any), or `None`
/// if they had none: the counts of `events.csv`'s rows of each kind and
/// the energy their impacts dissipated.
fn events_summary(records: &[&DynamicRecord]) -> Option<String> {
    let sum = |f: fn(&DynamicRecord) -> usize| records.iter().map(|d| f(d)).sum::<usize>();
    let plural = |n: usize, one: &str, many: &str| match n {
        0 => None,
        1 => Some(format!("1 {one}")),
        n => Some(format!("{n} {many}")),
    };
    let parts: Vec<String> = [
        plural(sum(|d| d.locks), "lock", "locks"),
        plural(sum(|d| d.unlatches), "unlatch", "unlatches"),
        plural(sum(|d| d.impacts), "impact", "impacts"),
        plural(
            sum(|d| d.contacts_closed),
            "contact closed",
            "contacts closed",
        ),
        plural(
            sum(|d| d.contacts_released),
            "contact released",
            "contacts released",
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    let crossings: Vec<String> = [
        plural(sum(|d| d.engages), "engage", "engages"),
        plural(sum(|d| d.disengages), "disengage", "disengages"),
        plural(sum(|d| d.rearms), "rearm", "rearms"),
    ]
    .into_iter()
    .flatten()
    .collect();
    let crossings = (!crossings.is_empty())
        .then(|| format!("spring latches' band crossings: {}", crossings.join(", ")));
    if parts.is_empty() {
        return crossings;
    }
    let lost: f64 = records.iter().map(|d| d.impact_energy_lost).sum();
    // a spring latch that releases drops the energy its spring held
    let how = if sum(|d| d.unlatches) > 0 {
        "in impacts and unlatches"
    } else {
        "in impacts"
    };
    let events = format!("{}, energy lost {how} {lost:.3e}", parts.join(", "));
    Some(match crossings {
        Some(c) => format!("{events}; {c}"),
        None => events,
    })
}

/// The size of a model in one line: nodes and elements of each kind.
pub fn describe(model: &Model) -> String {
    let count = |k: ElementKind| model.elements.iter().filter(|e| e.kind() == k).count();
    // the kinds a model may lack, named only when present
    let extra: String = [
        (ElementKind::HingeLaw, "hinge laws"),
        (ElementKind::Latch, "latches"),
        (ElementKind::Stop, "stops"),
        (ElementKind::Contact, "contacts"),
        (ElementKind::RollingDisc, "rolling discs"),
        (ElementKind::Shell, "shells"),
        (ElementKind::Superelement, "superelements"),
    ]
    .into_iter()
    .filter_map(|(kind, name)| match count(kind) {
        0 => None,
        n => Some(format!(", {n} {name}")),
    })
    .collect();
    format!(
        "{} nodes, {} beams, {} rigid bodies, {} point masses, {} springs, {} joints, {} joint springs, {} drivers, {} loads",
        model.n_nodes(),
        count(ElementKind::Beam),
        count(ElementKind::RigidBody),
        count(ElementKind::PointMass),
        count(ElementKind::Spring),
        count(ElementKind::Joint),
        count(ElementKind::JointSpring),
        count(ElementKind::Driver),
        count(ElementKind::NodalLoad),
    ) + &extra
}

/// `log.txt`: a line per increment, iteration, cut-back and note. A write
/// error is kept and reported at the next increment; nothing more is
/// written to the file after it.
struct LogFile {
    path: PathBuf,
    file: BufWriter<File>,
    error: Option<io::Error>,
    /// The error was reported to the analysis already.
    reported: bool,
    /// When the file was last flushed.
    flushed: Instant,
}

/// How often `log.txt` is flushed between output steps: a person following
/// the file sees it at most this late, and a run of short steps does not
/// pay a write to the file at every step.
const LOG_FLUSH_INTERVAL: Duration = Duration::from_millis(200);

impl LogFile {
    fn create(path: PathBuf) -> io::Result<Self> {
        let file = File::create(&path).map_err(|e| file_error(&path, e))?;
        Ok(Self {
            path,
            file: BufWriter::new(file),
            error: None,
            reported: false,
            flushed: Instant::now(),
        })
    }

    fn line(&mut self, text: &str) {
        self.write(text.as_bytes());
    }

    /// A line built as bytes ([`Line`]).
    fn write_bytes(&mut self, line: &Line) {
        self.write(line.bytes());
    }

    /// `line` and its end, copied into the file's buffer.
    fn write(&mut self, line: &[u8]) {
        if self.error.is_none() {
            let written = self
                .file
                .write_all(line)
                .and_then(|()| self.file.write_all(b"\n"));
            if let Err(e) = written {
                self.error = Some(file_error(&self.path, e));
            }
        }
    }

    /// Flushes; the first error, once.
    fn flush(&mut self) -> io::Result<()> {
        self.flushed = Instant::now();
        if self.error.is_none() {
            if let Err(e) = self.file.flush() {
                self.error = Some(file_error(&self.path, e));
            }
        }
        self.report()
    }

    /// At the end of an increment: flushes when `output` (a step written)
    /// or after [`LOG_FLUSH_INTERVAL`]; the first error, once.
    fn flush_at_increment(&mut self, output: bool) -> io::Result<()> {
        if output || self.flushed.elapsed() >= LOG_FLUSH_INTERVAL {
            return self.flush();
        }
        self.report()
    }

    /// The first error, once.
    fn report(&mut self) -> io::Result<()> {
        match &self.error {
            Some(e) if !self.reported => {
                self.reported = true;
                Err(io::Error::new(e.kind(), e.to_string()))
            }
            _ => Ok(()),
        }
    }
}

/// How a run ended, for the caller to report.
#[derive(Debug)]
pub struct RunReport {
    /// The final status, as written in `summary.json`.
    pub status: RunStatus,
    /// The summary as written (or as it would have been).
    pub summary: Summary,
    /// The interruption, if the run was stopped on request.
    pub interrupted: Option<Interrupted>,
    /// Result files that could not be written at the end (`summary.json`,
    /// `log.txt`); each error names its file.
    pub output_errors: Vec<io::Error>,
    /// The last line of the run, as written to `log.txt`.
    pub last_line: String,
    /// The load parameter of the last output step written (the results
    /// kept), if any.
    pub last_output_time: Option<f64>,
}

/// Records a run: result files, `log.txt`, `summary.json`; stops it on
/// request. See the module documentation.
pub struct Recorder {
    writer: ResultWriter,
    log: LogFile,
    console: Box<dyn Console>,
    stop: StopRequest,
    summary: Summary,
    /// End of the last analysis of the run.
    end_time: f64,
    /// Number of analyses of the run.
    analyses: usize,
    /// The analysis running: its index, type, start and end.
    current: Running,
    /// Increments of the analyses before the running one.
    increment_offset: usize,
    /// Whether `current` is a static analysis not yet closed.
    open: bool,
    /// Why a modal analysis of the run failed, if one did.
    failure: Option<String>,
    /// The result files of the modal analyses.
    modal: ModalFiles,
    /// Encoding of the grids.
    encoding: Encoding,
    /// Largest constraint violation (relative to its tolerance) at each
    /// iteration of the increment being solved.
    violations: Vec<f64>,
    /// The solver's relative residual at each iteration of the increment
    /// being solved, and the log's report of it.
    reported: Vec<(f64, Reported)>,
    /// The model's length scale, which turns moments into forces when the
    /// log tells residuals at round-off ([`Reported::of`]).
    length_scale: f64,
    /// Restart files, and the index in the model's sequence of the first
    /// analysis recorded.
    restart: Option<(RestartWriter, usize)>,
    /// Largest absolute energy balance error and kinetic energy over the
    /// steps of the running dynamic analysis.
    energy_extremes: (f64, f64),
    /// The energies of its last converged step.
    energies: Option<Energies>,
    /// What it needs besides its last converged state to go on (for
    /// restart files), as it reported once its next step was sized.
    motion: Option<Continuation>,
    /// The requested restart time reached by its last converged step,
    /// whose file is written with that continuation.
    restart_due: Option<f64>,
    /// The latches of the model over the running analysis.
    latches: Vec<LatchWatch>,
    /// The stops and contacts over the running analysis.
    stops: Vec<StopWatch>,
    /// The largest loads of the latches, stops and contacts over the run.
    peaks: PeakLoads,
    /// The line of an iteration or increment, its buffer kept from line
    /// to line.
    text: Line,
    /// The band crossings of spring latches written to `events.csv` by
    /// the running analysis: engages, disengages, rearms.
    crossings: [usize; 3],
}

/// What the recorder follows of a stop or contact over a dynamic
/// analysis: whether it was struck, and the range of its coordinate (of
/// its gap, for a contact), for the note on one never struck.
struct StopWatch {
    /// The stop's index among the model's elements.
    element: usize,
    id: Id,
    /// The joint of a stop (`None` for a contact).
    joint: Option<Id>,
    /// Whether `c` is an angle.
    angle: bool,
    /// `(c_min, c_max)`.
    limits: (f64, f64),
    /// Closed when the analysis started, or by an event since.
    struck: bool,
    /// The range of `c` over the converged steps.
    low: f64,
    high: f64,
}

impl StopWatch {
    /// The stops and contacts of `model` at `state`.
    fn of(model: &Model, state: &State) -> Vec<Self> {
        model
            .elements
            .iter()
            .enumerate()
            .filter_map(|(element, e)| {
                let stop = e.as_stop()?;
                let c = stop.coordinate(state);
                Some(Self {
                    element,
                    id: e.id(),
                    joint: stop.joint(),
                    angle: stop.is_angle(),
                    limits: stop.limits(),
                    struck: stop.contact(state) != Contact::Open,
                    low: c,
                    high: c,
                })
            })
            .collect()
    }
}

/// What the recorder follows of a latch over an analysis, for the notes
/// of docs/joints.md §6.2 ("Where latches lock"): a latch passed by a
/// static or kinematic analysis, which does not lock it, and a latch that
/// a whole dynamic analysis never locked.
struct LatchWatch {
    /// The latch's index among the model's elements.
    element: usize,
    /// Its id and its joint's.
    id: Id,
    joint: Id,
    /// `c_L`, `s` and whether `c` is an angle.
    value: f64,
    approach: f64,
    angle: bool,
    /// Locked when the analysis started.
    locked_at_start: bool,
    /// Locked by now.
    locked: bool,
    /// The range of `c` over the converged increments.
    low: f64,
    high: f64,
    /// `g = s (c − c_L)` was below `−tol` at a converged increment.
    before: bool,
    /// Said already that the analysis carried it past its value.
    passed: bool,
    /// A spring latch's contact so far.
    contact: SpringContact,
    /// The largest force of its spring in the analysis.
    largest: f64,
    /// Its whole contacts: the longest step within, start and end times,
    /// largest force, and the increment that ended it.
    contacts: Vec<(f64, f64, f64, f64, usize)>,
    /// Said already that a static analysis loaded it beyond its unlatch
    /// load.
    overloaded: bool,
    /// `(t, c, ċ)` at the last converged steps of a dynamic analysis while
    /// it was open, the lock's step last (at most [`RATE_WINDOW_STEPS`] +
    /// 1).
    recent: std::collections::VecDeque<(f64, f64, f64)>,
}

impl LatchWatch {
    /// The latches of `model` at `state`.
    fn of(model: &Model, state: &State) -> Vec<Self> {
        model
            .elements
            .iter()
            .enumerate()
            .filter_map(|(element, e)| {
                let l = e.as_latch()?;
                let c = l.coordinate(state);
                let locked = l.is_locked(state);
                Some(Self {
                    element,
                    id: e.id(),
                    joint: l.joint(),
                    value: l.value(),
                    approach: l.approach(),
                    angle: l.is_angle(),
                    locked_at_start: locked,
                    locked,
                    low: c,
                    high: c,
                    before: l.gap(state) < -impact::event_tolerance(model, l),
                    passed: false,
                    contact: SpringContact {
                        sign: spring_force(l, state).signum(),
                        longest: 0.0,
                        from: state.time,
                        whole: false,
                        peak: 0.0,
                    },
                    largest: 0.0,
                    contacts: Vec::new(),
                    overloaded: false,
                    recent: Default::default(),
                })
            })
            .collect()
    }

    /// The start of an analysis at `state` (its first converged
    /// increment): `watch` as the analysis before left it (whether each
    /// latch was short of its value), the rest from `state`.
    fn start(watch: &mut Vec<Self>, model: &Model, state: &State) {
        let mut now = Self::of(model, state);
        for (w, before) in now.iter_mut().zip(watch.iter()) {
            w.before |= before.before;
        }
        *watch = now;
    }

    /// Follows the contact of its spring to the converged step at `time`
    /// where its force is `f`: a contact is the steps between two changes
    /// of the force's sign, half a period of the latch's oscillation about
    /// an edge of its dead band (docs/joints.md §6.2); `step` is the size
    /// of the step that ended at `time`.
    fn follow_contact(&mut self, f: f64, time: f64, step: f64, increment: usize) {
        let sign = if f == 0.0 { 0.0 } else { f.signum() };
        self.largest = self.largest.max(f.abs());
        let c = &mut self.contact;
        if sign == c.sign {
            c.longest = c.longest.max(step);
            c.peak = c.peak.max(f.abs());
            return;
        }
        if c.sign != 0.0 && c.whole {
            // the step that ended the contact crossed part of it too
            let longest = c.longest.max(step);
            self.contacts
                .push((longest, c.from, time, c.peak, increment));
        }
        *c = SpringContact {
            sign,
            longest: step,
            from: time,
            whole: true,
            peak: f.abs(),
        };
    }

    /// `c` with its unit, and in degrees for an angle.
    fn show(&self, c: f64) -> String {
        if self.angle {
            format!("{} rad ({:.2}°)", format_time(c), c.to_degrees())
        } else {
            format_time(c)
        }
    }

    /// The direction of approach in words.
    fn direction(&self) -> &'static str {
        if self.approach > 0.0 {
            "increasing"
        } else {
            "decreasing"
        }
    }
}

/// The force of latch `l`'s spring at `state` (without its dashpot): 0
/// when it is open, not a spring latch, or within its dead band.
fn spring_force(l: &Latch, state: &State) -> f64 {
    match l.spring() {
        Some(s) if l.is_locked(state) => s.spring_force(l.coordinate(state) - l.value()).0,
        _ => 0.0,
    }
}

/// A spring latch's contact being followed ([`LatchWatch::follow_contact`]).
#[derive(Clone, Copy, Debug)]
struct SpringContact {
    /// The sign of the spring's force (0: none).
    sign: f64,
    /// The longest converged step of that sign so far, from `from`.
    longest: f64,
    from: f64,
    /// Begun within the analysis (not already under way at its start).
    whole: bool,
    /// The largest `|f|` of the contact.
    peak: f64,
}

/// Contacts whose force stays below this fraction of the spring's largest
/// force are not counted among the contacts resolved or not.
const CONTACT_FORCE: f64 = 1e-3;

/// The steps before a lock over which the rate of the latch's coordinate
/// is followed ([`Recorder::vibrating_lock`]).
const RATE_WINDOW_STEPS: usize = 20;

/// A lock is reported when the rate of its coordinate swung, over the
/// last [`RATE_WINDOW_STEPS`] steps, about its least-squares line in time
/// by more than this fraction of its mean rate over them,
/// `(c_L − c_{n−k})/(t_L − t_{n−k})`. A joint driven smoothly to its
/// latch follows the line (its acceleration); one that vibrates swings
/// about it by twice the vibration's amplitude. Measured: an undamped
/// two-beam boom opened by a spring onto a latch, whose lock rate ranged
/// from −4.4 to −8.2 rad/s with the steps (−6.0 for the rigid boom),
/// swung by 36 to 49 % of its mean rate with three of four step settings
/// (below 30 % at ρ∞ = 0.5); with Rayleigh damping (β = 3e-5) by 28 % at
/// most; the locks of the ERA cell and triangle (fixed steps of 0.01 s)
/// not enough to be reported.
const LOCK_RATE_RANGE: f64 = 0.3;

/// A contact of a spring latch resolved by fewer steps than this is
/// reported: its half-period sampled at n steps, a peak between two of
/// them is missed by up to `1 − cos(π/2n)` (8 % at n = 4), and below it
/// the integration itself no longer follows the spring.
const RESOLVED_CONTACT_STEPS: usize = 4;

/// The analysis being recorded.
struct Running {
    index: usize,
    kind: &'static str,
    start_time: f64,
    end_time: f64,
    initial_iterations: usize,
    /// `ε_r`: a converged increment whose last relative residual is above
    /// it was accepted at the round-off plateau of its residual.
    residual_tolerance: f64,
}

impl Running {
    fn of_dynamic(index: usize, analysis: &DynamicAnalysis) -> Self {
        Self {
            index,
            kind: "dynamic",
            start_time: 0.0,
            end_time: analysis.settings().end_time,
            initial_iterations: 0,
            residual_tolerance: analysis.settings().residual_tolerance,
        }
    }

    fn of(index: usize, analysis: &StaticAnalysis) -> Self {
        let s = analysis.settings();
        Self {
            index,
            kind: if s.kinematic {
                "kinematic"
            } else if s.kinetostatic {
                "kinetostatic"
            } else {
                "static"
            },
            start_time: 0.0,
            end_time: s.end_time,
            initial_iterations: 0,
            residual_tolerance: s.residual_tolerance,
        }
    }
}

impl Recorder {
    /// Locks and prepares `dir` for a run of `analysis` (of a model read
    /// from `model_file`, as named in the summary): result files with their
    /// headers, `log.txt` with a first line describing the model, and a
    /// `summary.json` saying `running`; the run is shown on `console`.
    /// Every error names its file.
    pub fn create(
        dir: &Path,
        model_file: &str,
        analysis: &StaticAnalysis,
        console: impl Console + 'static,
    ) -> io::Result<Self> {
        let plan = [AnalysisSettings::Static(analysis.settings().clone())];
        Self::create_sequence(dir, model_file, analysis, &plan, console)
    }

    /// As [`Recorder::create`], for a run of the analyses `plan` in order,
    /// the first of which is `first`.
    pub fn create_sequence(
        dir: &Path,
        model_file: &str,
        first: &StaticAnalysis,
        plan: &[AnalysisSettings],
        console: impl Console + 'static,
    ) -> io::Result<Self> {
        let model = &**first.model();
        let summary = Summary::start(model_file, model, first, plan);
        let running = Running::of(0, first);
        let unknowns = first.n_equations();
        Self::create_with(
            dir, model_file, model, summary, running, unknowns, plan, console,
        )
    }

    /// As [`Recorder::create_sequence`], for a run whose first analysis
    /// is the dynamic analysis `first`.
    pub fn create_dynamic_first(
        dir: &Path,
        model_file: &str,
        first: &DynamicAnalysis,
        plan: &[AnalysisSettings],
        console: impl Console + 'static,
    ) -> io::Result<Self> {
        let model = &**first.model();
        let end_time = plan
            .last()
            .map_or(first.settings().end_time, |a| a.end_time());
        let unknowns = first.n_equations();
        let summary = Summary::start_with(model_file, model, unknowns, first.nnz(), end_time);
        let running = Running::of_dynamic(0, first);
        let mut recorder = Self::create_with(
            dir, model_file, model, summary, running, unknowns, plan, console,
        )?;
        recorder.writer.set_dynamic(true);
        Ok(recorder)
    }

    /// Opens the record of the dynamic analysis `next`, which starts from
    /// the final state of the analysis before it, at `t = from` (that
    /// analysis closed with [`Recorder::end_analysis`]).
    pub fn open_dynamic(&mut self, next: &DynamicAnalysis, from: f64) {
        self.current = Running::of_dynamic(self.current.index + 1, next);
        self.open_next(from);
    }

    /// Opens the record of the static analysis `next` after another
    /// analysis (closed with [`Recorder::end_analysis`]), from `t = from`.
    pub fn open_static(&mut self, next: &StaticAnalysis, from: f64) {
        self.current = Running::of(self.current.index + 1, next);
        self.open_next(from);
    }

    fn open_next(&mut self, from: f64) {
        self.open = true;
        self.crossings = [0; 3];
        self.energy_extremes = (0.0, 0.0);
        self.energies = None;
        self.motion = None;
        self.restart_due = None;
        self.writer.set_dynamic(self.current.kind == "dynamic");
        self.line(&format!(
            "analysis {} of {}: {} from t = {} to t = {}",
            self.current.index + 1,
            self.analyses,
            self.current.kind,
            format_time(from),
            format_time(self.current.end_time)
        ));
    }

    /// Closes the record of the running analysis, which ended as `end`
    /// says (nothing if it is closed already).
    pub fn end_analysis(&mut self, end: &AnalysisEnd) {
        self.close_end(end);
    }

    /// The recorder of a run of `plan` whose first analysis is `running`,
    /// a static one if `running.kind` is not `modal`.
    #[allow(clippy::too_many_arguments)]
    fn create_with(
        dir: &Path,
        model_file: &str,
        model: &Model,
        summary: Summary,
        running: Running,
        unknowns: usize,
        plan: &[AnalysisSettings],
        console: impl Console + 'static,
    ) -> io::Result<Self> {
        let dynamics = plan.iter().any(|a| a.as_dynamic().is_some());
        let writer = ResultWriter::create_for(dir, model, dynamics)?;
        let log = LogFile::create(dir.join("log.txt"))?;
        let mut recorder = Self {
            writer,
            log,
            console: Box::new(console),
            stop: StopRequest::new(),
            end_time: summary.end_time,
            summary,
            analyses: plan.len().max(1),
            open: running.kind != "modal",
            current: running,
            increment_offset: 0,
            failure: None,
            modal: ModalFiles::default(),
            encoding: Encoding::default(),
            violations: Vec::new(),
            reported: Vec::new(),
            length_scale: model.length_scale,
            restart: None,
            energy_extremes: (0.0, 0.0),
            energies: None,
            motion: None,
            restart_due: None,
            latches: Vec::new(),
            stops: Vec::new(),
            peaks: PeakLoads::of(model),
            text: Line::default(),
            crossings: [0; 3],
        };
        let analyses = if plan.len() > 1 {
            let each: Vec<String> = plan
                .iter()
                .map(|a| match a.as_modal() {
                    Some(m) => format!("modal at t = {}", format_time(m.time)),
                    None => format!("{} to t = {}", a.name(), format_time(a.end_time())),
                })
                .collect();
            format!("{} analyses: {}", plan.len(), each.join(", "))
        } else {
            match recorder.current.kind {
                "modal" => format!(
                    "modal analysis at t = {}",
                    format_time(recorder.current.end_time)
                ),
                kind => format!(
                    "{kind} analysis to t = {}",
                    format_time(recorder.current.end_time)
                ),
            }
        };
        recorder.line(&format!(
            "{model_file}: {}; {unknowns} unknowns; {analyses}",
            describe(model),
        ));
        if let Some(owner) = recorder.writer.stale_lock().map(str::to_owned) {
            recorder.note_line(&format!(
                "{}: an earlier run (process {owner}) did not end there: it was killed or its machine stopped, leaving its lock file {}; no process holds the directory now, so this run takes it over and replaces that run's results",
                dir.display(),
                super::results::LOCK_FILE
            ));
        }
        // warnings are shown by the caller; the log keeps them with the run
        for w in &model.warnings {
            recorder.log.line(&format!("warning: {w}"));
        }
        for n in &model.notes {
            recorder.log.line(&format!("note: {n}"));
        }
        for line in model.load_history() {
            recorder.line(&format!("load history: {line}"));
        }
        recorder.log.flush()?;
        recorder.writer.write_summary(&recorder.summary)?;
        Ok(recorder)
    }

    /// Closes the record of the analysis that returned `outcome` and opens
    /// that of `next`, which starts from `outcome`'s final state.
    pub fn next_analysis(&mut self, outcome: &StaticOutcome, next: &StaticAnalysis) {
        self.close(outcome);
        self.current = Running::of(self.current.index + 1, next);
        self.open = true;
        self.line(&format!(
            "analysis {} of {}: {} from t = {} to t = {}",
            self.current.index + 1,
            self.analyses,
            self.current.kind,
            format_time(outcome.time),
            format_time(self.current.end_time)
        ));
    }

    /// Adds the running analysis's `outcome` to the summary.
    fn close(&mut self, outcome: &StaticOutcome) {
        self.close_end(&outcome.into());
    }

    /// Adds the running analysis, which ended as `end` says, to the
    /// summary.
    fn close_end(&mut self, end: &AnalysisEnd) {
        if !std::mem::replace(&mut self.open, false) {
            return;
        }
        let mut end = end.clone();
        if let Some(d) = end.dynamic.as_mut() {
            // the outcome keeps locks and unlatches; the band crossings
            // are the rows this recorder wrote
            let [engages, disengages, rearms] = std::mem::take(&mut self.crossings);
            d.engages = d.engages.max(engages);
            d.disengages = d.disengages.max(disengages);
            d.rearms = d.rearms.max(rearms);
            let (error, kinetic) = self.energy_extremes;
            d.largest_energy_balance_error = d.largest_energy_balance_error.max(error);
            d.largest_kinetic_energy = d.largest_kinetic_energy.max(kinetic);
            self.line(&format!(
                "dynamic analysis to t = {}: {} steps, {} rejected ({} by the error estimate), {} iterations, {:.3} s; energy balance error {:.3e} (largest {:.3e}; largest kinetic energy {:.3e}){}",
                format_time(end.time),
                d.steps,
                d.rejected_steps,
                d.error_rejections,
                d.newton_iterations,
                d.wall_time_s,
                d.energy_balance_error,
                d.largest_energy_balance_error,
                d.largest_kinetic_energy,
                events_summary(&[d]).map_or(String::new(), |e| format!("; {e}"))
            ));
        }
        self.never_locked(&end);
        let c = &self.current;
        self.summary
            .add_end(c.kind, c.start_time, c.end_time, &end, c.initial_iterations);
        self.increment_offset += end.increments;
    }

    /// `info` numbered on across the analyses of the run (a copy only
    /// after the first analysis).
    fn renumbered<'a>(&self, info: &'a IncrementInfo) -> Cow<'a, IncrementInfo> {
        if self.increment_offset == 0 {
            return Cow::Borrowed(info);
        }
        Cow::Owned(IncrementInfo {
            increment: info.increment + self.increment_offset,
            ..info.clone()
        })
    }

    /// Stops the run when `stop` is requested.
    pub fn with_stop(mut self, stop: &StopRequest) -> Self {
        self.stop = stop.clone();
        self
    }

    /// Writes restart files with `writer` (io::restart); the first analysis
    /// recorded is analysis `first_analysis` (from 0) of the model's
    /// sequence, as in a restarted run.
    pub fn with_restart(mut self, writer: RestartWriter, first_analysis: usize) -> Self {
        self.restart = Some((writer, first_analysis));
        self
    }

    /// A VTK grid at every `every`-th output step, none if 0
    /// ([`ResultWriter::with_vtk_every`]).
    pub fn with_vtk_every(mut self, every: usize) -> Self {
        self.writer = self.writer.with_vtk_every(every);
        self
    }

    /// Writes the grids in `encoding` (binary by default).
    pub fn with_vtk_encoding(mut self, encoding: Encoding) -> Self {
        self.writer = self.writer.with_vtk_encoding(encoding);
        self.encoding = encoding;
        self
    }

    /// The result files.
    pub fn writer(&self) -> &ResultWriter {
        &self.writer
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        self.writer.dir()
    }

    /// Follows the latches to the converged increment `info` at `state`:
    /// a note when a static or kinematic analysis carries one past its
    /// value in its direction of approach (only dynamic analyses lock
    /// latches).
    fn watch_latches(&mut self, info: &IncrementInfo, model: &Model, state: &State) {
        let statics = self.current.kind != "dynamic";
        let mut notes = Vec::new();
        for w in &mut self.latches {
            let Some(l) = model.elements.get(w.element).and_then(|e| e.as_latch()) else {
                continue;
            };
            if !statics {
                w.follow_contact(spring_force(l, state), info.time, info.step, info.increment);
            }
            if let Some(limit) = l.spring().and_then(|s| s.unlatch_load) {
                let load = l.spring_state(state).2;
                if statics && w.locked && !w.overloaded && load.abs() > limit {
                    w.overloaded = true;
                    notes.push(format!(
                        "latch {}: the {} analysis loads it with {} at t = {}, beyond its unlatch_load {}; latches release only in a dynamic analysis: a static or kinematic one holds them whatever the load (docs/joints.md §6.2)",
                        w.id,
                        self.current.kind,
                        format_time(load.abs()),
                        format_time(info.time),
                        format_time(limit)
                    ));
                }
            }
            if w.locked {
                continue;
            }
            w.locked = l.is_locked(state);
            let c = l.coordinate(state);
            if !statics {
                if w.recent.len() > RATE_WINDOW_STEPS {
                    w.recent.pop_front();
                }
                w.recent.push_back((info.time, c, l.rate(state).0));
            }
            w.low = w.low.min(c);
            w.high = w.high.max(c);
            let (g, tolerance) = (l.gap(state), impact::event_tolerance(model, l));
            if g < -tolerance {
                w.before = true;
            } else if statics && w.before && g > tolerance && !w.passed {
                w.passed = true;
                notes.push(format!(
                    "latch {}: the {} analysis carried joint {} past the latch's value {} at t = {} (to {}); latches lock only in a dynamic analysis: a static or kinematic one leaves them open (docs/joints.md §6.2)",
                    w.id,
                    self.current.kind,
                    w.joint,
                    w.show(w.value),
                    format_time(info.time),
                    w.show(c)
                ));
            }
        }
        for n in notes {
            self.note_line(&n);
        }
    }

    /// At the end of a dynamic analysis that reached its end: a warning
    /// for each latch open at its start that it never locked, with the
    /// range its coordinate covered (a latch is there to lock: one that
    /// does not is most often a value or an approach of the wrong sign, or
    /// a deployment too short or too weak).
    fn never_locked(&mut self, end: &AnalysisEnd) {
        if self.current.kind != "dynamic" || end.error.is_some() {
            return;
        }
        let span = self.span(end);
        let warnings: Vec<String> = self
            .latches
            .iter()
            .filter(|w| !w.locked_at_start && !w.locked)
            .map(|w| {
                // a coordinate that crossed the value against the approach
                let crossed = w.low <= w.value && w.value <= w.high;
                format!(
                    "latch {} never locked in the dynamic analysis {span}: joint {} stayed within [{}, {}]{}, and the latch locks when the coordinate reaches {} {}",
                    w.id,
                    w.joint,
                    w.show(w.low),
                    w.show(w.high),
                    if crossed {
                        " and passed the latch's value only against its approach"
                    } else {
                        ""
                    },
                    w.show(w.value),
                    w.direction()
                )
            })
            .collect();
        for w in warnings {
            self.outcome_warning(&w);
        }
        self.never_struck(end);
        self.unresolved_contacts();
    }

    /// A warning when latch `info.latch` locks a joint whose rate swung,
    /// over the last [`RATE_WINDOW_STEPS`] steps, about its least-squares
    /// line in time by more than [`LOCK_RATE_RANGE`] of its mean rate (one
    /// allocation per open latch and step, for `ċ`'s gradient, in the
    /// observer, not in Newton's loop): the joint vibrates (the ends of
    /// an undamped flexible member rung by a spring), so that the lock's
    /// rate `ċ⁻`, and with it its impulse and energy lost, is the
    /// vibration's phase at the lock; in a model without damping it also
    /// depends on how much of the vibration the steps damp (ρ∞ < 1, longer
    /// steps).
    fn vibrating_lock(&mut self, info: &LockInfo) {
        let Some(w) = self.latches.iter().find(|w| w.id == info.latch) else {
            return;
        };
        let Some(&(t0, c0, _)) = w.recent.front() else {
            return;
        };
        if w.recent.len() <= RATE_WINDOW_STEPS || info.time <= t0 {
            return;
        }
        let mean = (info.coordinate - c0) / (info.time - t0);
        // the rates of the window, the lock's ċ⁻ last, about their
        // least-squares line in t: a smooth approach follows the line
        // (its acceleration), a vibration swings about it
        let points: Vec<(f64, f64)> = w
            .recent
            .iter()
            .take(RATE_WINDOW_STEPS)
            .map(|r| (r.0, r.2))
            .chain(std::iter::once((info.time, info.rate_before)))
            .collect();
        let n = points.len() as f64;
        let (tm, vm) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
        let (stv, stt) = points.iter().fold((0.0, 0.0), |(a, b), p| {
            (a + (p.0 - tm) * (p.1 - vm), b + (p.0 - tm) * (p.0 - tm))
        });
        let slope = if stt > 0.0 { stv / stt } else { 0.0 };
        let (low, high) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                let off = p.1 - (vm + slope * (p.0 - tm));
                (lo.min(off), hi.max(off))
            });
        if high - low <= LOCK_RATE_RANGE * mean.abs() {
            return;
        }
        let unit = if w.angle { "rad/s" } else { "per s" };
        let warning = WarningInfo {
            increment: info.increment,
            from: t0,
            time: info.time,
            message: format!(
                "latch {}: joint {} vibrates as it locks: over the {RATE_WINDOW_STEPS} steps before the lock its rate swung by {:.3e} {unit} about its trend, against a mean rate of {mean:.3e}, and it locked at {:.3e}; the lock's rate, impulse and energy lost are those of the vibration's phase at the lock, and without damping they change with the steps (which damp part of the vibration); damp the members (rayleigh_beta of their sections) for a rate that does not depend on the steps",
                w.id, w.joint, high - low, info.rate_before
            ),
        };
        Observer::warning(self, &warning);
    }

    /// At the end of a dynamic analysis: a warning for each spring latch
    /// with a contact shorter than [`RESOLVED_CONTACT_STEPS`] of the
    /// longest step taken within it: the steps do not resolve its spring,
    /// and its peak load and its rattles are unreliable (with fixed steps
    /// longer than a contact, a peak load half the true one and half the
    /// rattles have been seen, with the energy balanced). Steps cut short
    /// to land on the edges of the dead band do not count as resolving it.
    fn unresolved_contacts(&mut self) {
        let warnings: Vec<WarningInfo> = self
            .latches
            .iter()
            .filter_map(|w| {
                // contacts whose force stays below CONTACT_FORCE of the
                // largest (the round-off of a step landed on an edge) are
                // not counted
                let (longest, from, to, _, increment) = w
                    .contacts
                    .iter()
                    .filter(|c| c.3 >= CONTACT_FORCE * w.largest)
                    .min_by(|a, b| ((a.2 - a.1) / a.0).total_cmp(&((b.2 - b.1) / b.0)))
                    .copied()?;
                let steps = (to - from) / longest;
                (steps < RESOLVED_CONTACT_STEPS as f64).then(|| WarningInfo {
                    increment,
                    from,
                    time: to,
                    message: format!(
                        "latch {}: a contact of its spring lasted {} s, {steps:.1} of the steps taken within it ({} s): the steps do not resolve the latch's spring, so its peak load and the number of its rattles are unreliable; use adaptive steps, or steps at least {} times shorter than a contact",
                        w.id,
                        format_time(to - from),
                        format_time(longest),
                        4 * RESOLVED_CONTACT_STEPS
                    ),
                })
            })
            .collect();
        for w in &warnings {
            Observer::warning(self, w);
        }
    }

    /// At the end of a dynamic analysis that reached its end: a note for
    /// each stop or contact it never closed, with the range its coordinate
    /// (or gap) covered: a limit on the wrong side or of the wrong sign
    /// shows there.
    fn never_struck(&mut self, end: &AnalysisEnd) {
        if self.current.kind != "dynamic" || end.error.is_some() {
            return;
        }
        let span = self.span(end);
        let mut notes = Vec::new();
        for w in self.stops.iter().filter(|w| !w.struck) {
            let show = |c: f64| {
                if w.angle {
                    format!("{} rad ({:.2}°)", format_time(c), c.to_degrees())
                } else {
                    format_time(c)
                }
            };
            notes.push(match w.joint {
                Some(joint) => {
                    let (lower, upper) = w.limits;
                    let limit = |c: f64| {
                        if c.is_finite() {
                            show(c)
                        } else if c > 0.0 {
                            "∞".to_string()
                        } else {
                            "−∞".to_string()
                        }
                    };
                    format!(
                        "stop {} was never struck in the dynamic analysis {span}: joint {joint} stayed within [{}, {}], and the stop's limits are [{}, {}]",
                        w.id,
                        show(w.low),
                        show(w.high),
                        limit(lower),
                        limit(upper)
                    )
                }
                None => format!(
                    "contact {} never closed in the dynamic analysis {span}: its gap stayed within [{}, {}]",
                    w.id,
                    format_time(w.low),
                    format_time(w.high)
                ),
            });
        }
        for n in notes {
            self.note_line(&n);
        }
    }

    /// The time span of the analysis ending at `end`, in words: `to t =
    /// 5`, or `from t = 2 to t = 5` when it did not start at 0 (after
    /// another analysis, or from a restart: what it says covers that span
    /// alone).
    fn span(&self, end: &AnalysisEnd) -> String {
        let start = self.current.start_time;
        if start > 0.0 {
            format!(
                "from t = {} to t = {}",
                format_time(start),
                format_time(end.time)
            )
        } else {
            format!("to t = {}", format_time(end.time))
        }
    }

    /// A warning on the outcome of the run (its own, or one the caller
    /// found, such as [`crate::model::overlaps::overlap_warnings`]): in
    /// `log.txt`, on the console and in `summary.json`.
    pub fn outcome_warning(&mut self, text: &str) {
        self.log.line(&format!("warning: {text}"));
        self.console.warning(text);
        self.summary.warnings.push(text.to_string());
    }

    /// A note of the run's outcome: in `log.txt`, and shown even when the
    /// increments are not.
    fn note_line(&mut self, text: &str) {
        let text = format!("note: {text}");
        self.log.line(&text);
        self.console.note(&text);
    }

    /// Appends `row` to `events.csv`; a write error fails the run at its
    /// end (the analysis goes on: its other results are being written).
    fn write_event(&mut self, row: &EventRow) {
        // a contact between bodies watches no joint
        let (element, on_joint, bare) = match row.kind {
            "lock" => ("latch", "locks joint", "locks"),
            "unlatch" => ("latch", "releases joint", "releases"),
            "engage" => ("latch", "spring engages on joint", "spring engages"),
            "disengage" => ("latch", "spring disengages on joint", "spring disengages"),
            "rearm" => ("latch", "rearms on joint", "rearms"),
            "impact" => ("stop", "impact of joint", "impact"),
            "contact" => ("stop", "contact closed on joint", "contact closed"),
            _ => ("stop", "contact released on joint", "contact released"),
        };
        let (element, what) = match row.joint {
            Some(j) => (element, format!("{on_joint} {j}")),
            None => ("contact", bare.to_string()),
        };
        self.line(&format!(
            "step {:4}  t = {:.6}: {element} {}: {what} at c = {:.6}: rate {:.6e} -> {:.6e}, impulse {:.6e}, energy lost {:.6e}",
            row.increment,
            row.time,
            row.element,
            row.coordinate,
            row.rate_before,
            row.rate_after,
            row.impulse,
            row.energy_lost
        ));
        let _writing = self.stop.output();
        if let Err(e) = self.writer.write_event(row) {
            if self.failure.is_none() {
                self.failure = Some(e.to_string());
            }
        }
    }

    /// Writes a line to `log.txt` and shows it.
    pub fn line(&mut self, text: &str) {
        self.log.line(text);
        self.console.line(text);
    }

    /// Ends the record of a run whose (last) analysis returned `outcome`:
    /// the status (completed, failed or interrupted), the last line of
    /// `log.txt`, and `summary.json`. Write errors are returned in the
    /// report, not lost.
    pub fn finish(self, outcome: &StaticOutcome) -> RunReport {
        self.finish_with(Some(outcome), &outcome.state)
    }

    /// As [`Recorder::finish`], for a run whose last static analysis (if
    /// any) returned `outcome` and whose last converged state is `state`
    /// (that of `outcome`, or the state a modal analysis after it was
    /// given and left unchanged), written to `restart.json`; a failed
    /// modal analysis fails the run.
    pub fn finish_with(self, outcome: Option<&StaticOutcome>, state: &State) -> RunReport {
        let end = outcome.map(AnalysisEnd::from);
        self.finish_after(end.as_ref(), state)
    }

    /// As [`Recorder::finish_with`], for a run whose last static or
    /// dynamic analysis ended as `last` says.
    pub fn finish_after(mut self, last: Option<&AnalysisEnd>, state: &State) -> RunReport {
        let error = last.and_then(|o| o.error.as_ref());
        if let Some(o) = last {
            self.close_end(o);
        }
        let interrupted = last.and_then(|o| o.interrupted);
        let (status, message) = match (error, interrupted, self.failure.take()) {
            (None, _, None) => (RunStatus::Completed, None),
            (None, _, Some(failure)) => (RunStatus::Failed, Some(failure)),
            (Some(_), Some(i), _) => (
                RunStatus::Interrupted,
                Some(format!(
                    "{i} at t = {}",
                    format_time(self.summary.final_time)
                )),
            ),
            (Some(e), None, _) => (RunStatus::Failed, Some(e.clone())),
        };
        // rigid locks onto beams or shells whose peak is the impact's
        for w in self.peaks.mark_impact_peaks() {
            self.log.line(&format!("warning: {w}"));
            self.console.warning(&w);
            self.summary.warnings.push(w);
        }
        let mut output_errors = Vec::new();
        if let Some((restart, first)) = &self.restart {
            let _writing = self.stop.output();
            let index = first + self.current.index;
            // the dynamic analysis that ended at `state`
            let motion = self
                .motion
                .clone()
                .filter(|m| m.energies.time == state.time);
            if let Err(e) = restart.finish(index, self.current.kind, state, motion) {
                output_errors.push(e);
            }
        }
        if let Err(e) = self.log.flush() {
            output_errors.push(e);
        }
        // a result file that could not be written fails the run, and its
        // summary says which (a full disk: docs/results.md)
        let (status, message) = match output_errors.first() {
            None => (status, message),
            Some(e) => {
                let what = format!("cannot write results: {e}");
                match (status, message) {
                    (RunStatus::Completed, _) => (RunStatus::Failed, Some(what)),
                    (status, Some(m)) => (status, Some(format!("{m}; {what}"))),
                    (status, None) => (status, Some(what)),
                }
            }
        };
        self.summary.latches = self.peaks.latches();
        self.summary.stops = self.peaks.stops();
        self.summary.contacts = self.peaks.contacts();
        self.summary.superelements = self.peaks.superelements();
        self.summary.finish(&self.writer, status, message);
        let s = &self.summary;
        // the initial equilibria's iterations are counted in the total,
        // not in the average
        let initial = if self.analyses > 1 {
            "the initial equilibria"
        } else {
            "the initial equilibrium"
        };
        let dynamic: Vec<_> = s
            .analyses
            .iter()
            .filter_map(|a| a.dynamic.as_ref())
            .collect();
        // the locks and impacts of the run, when it had some
        let events = events_summary(&dynamic).map_or(String::new(), |e| format!("{e}; "));
        let last_line = if !dynamic.is_empty()
            && dynamic.len() == s.analyses.iter().filter(|a| a.kind != "modal").count()
        {
            // dynamic analyses only (and modal ones): time steps
            let steps: usize = dynamic.iter().map(|d| d.steps).sum();
            let rejected: usize = dynamic.iter().map(|d| d.rejected_steps).sum();
            let balance = dynamic.last().map_or(0.0, |d| d.energy_balance_error);
            format!(
                "{}: {steps} steps, {rejected} rejected, {} iterations ({:.2} per step), t = {}, {:.3} s, energy balance error {balance:.3e}; {events}results in {}",
                s.status.name(),
                s.iterations,
                if steps > 0 { s.iterations as f64 / steps as f64 } else { 0.0 },
                format_time(s.final_time),
                s.wall_time_s,
                self.writer.dir().display()
            )
        } else {
            let steps = if dynamic.is_empty() {
                String::new()
            } else {
                let steps: usize = dynamic.iter().map(|d| d.steps).sum();
                let rejected: usize = dynamic.iter().map(|d| d.rejected_steps).sum();
                format!(" (of which {steps} time steps, {rejected} rejected)")
            };
            format!(
                "{}: {} increments{steps}, {} iterations ({} for {initial}; {:.2} per increment), {} cut-backs, t = {}, {:.3} s; {events}results in {}",
                s.status.name(),
                s.increments,
                s.iterations,
                s.initial_iterations(),
                s.average_iterations,
                s.cutbacks,
                format_time(s.final_time),
                s.wall_time_s,
                self.writer.dir().display()
            )
        };
        self.log.line(&last_line);
        self.console.finish(&last_line);
        if let Err(e) = self.log.flush() {
            output_errors.push(e);
        }
        {
            let _writing = self.stop.output();
            if let Err(e) = self.writer.write_summary(&self.summary) {
                output_errors.push(e);
            }
        }
        RunReport {
            status,
            summary: self.summary,
            interrupted,
            output_errors,
            last_line,
            last_output_time: self.writer.last_output_time(),
        }
    }
}

impl Observer for Recorder {
    fn continuation(&mut self, state: &State, continuation: &Continuation) -> io::Result<()> {
        self.motion = Some(continuation.clone());
        let Some(t) = self.restart_due.take() else {
            return Ok(());
        };
        let Some((restart, first)) = &self.restart else {
            return Ok(());
        };
        let _writing = self.stop.output();
        restart.write_at(
            t,
            first + self.current.index,
            self.current.kind,
            state,
            Some(continuation.clone()),
        )
    }

    fn energies(&mut self, energies: &Energies) {
        let (error, kinetic) = &mut self.energy_extremes;
        *error = error.max(energies.balance_error.abs());
        *kinetic = kinetic.max(energies.kinetic);
        self.energies = Some(*energies);
        self.writer.energies(energies);
    }

    fn iteration(&mut self, info: &IterationInfo) {
        if info.iteration == 0 {
            self.violations.clear();
            self.reported.clear();
        }
        self.violations.push(info.norms.residual_constraint);
        let n = &info.norms;
        let reported = Reported::of(n, self.length_scale);
        self.reported.push((n.relative_residual, reported));
        // `    step 3 iteration 1: |r_F| 1.323e-10 (flux 9.007e2)  …`
        let word = if self.current.kind == "dynamic" {
            "step"
        } else {
            "increment"
        };
        let line = self.text.clear();
        line.text("    ")
            .text(word)
            .text(" ")
            .int(info.increment + self.increment_offset)
            .text(" iteration ")
            .int(info.iteration)
            .text(": |r_F| ")
            .sci::<3>(n.residual_force)
            .text(" (flux ")
            .sci::<3>(n.flux_force)
            .text(")  |r_M| ")
            .sci::<3>(n.residual_moment)
            .text(" (flux ")
            .sci::<3>(n.flux_moment)
            .text(")  |r_C| ")
            .sci::<3>(n.residual_coordinate)
            .text("  relative ");
        Shown::<3>(reported).push_to(line);
        line.text("  max|c| ")
            .sci::<3>(n.residual_constraint)
            .text("  max|dx| ")
            .sci::<3>(n.displacement_correction)
            .text("  max|dθ| ")
            .sci::<3>(n.rotation_correction);
        self.log.write_bytes(&self.text);
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> io::Result<()> {
        if info.increment == 0 {
            self.current.start_time = info.time;
            self.current.initial_iterations = info.iterations;
            if self.latches.is_empty() && info.time == 0.0 {
                // the run's start: from the model's initial state, which
                // the initial equilibrium may have moved past a latch
                self.latches = LatchWatch::of(model, &model.initial_state());
            }
            LatchWatch::start(&mut self.latches, model, state);
            self.stops = StopWatch::of(model, state);
        }
        self.watch_latches(info, model, state);
        for w in &mut self.stops {
            if let Some(stop) = model.elements.get(w.element).and_then(|e| e.as_stop()) {
                let c = stop.coordinate(state);
                w.low = w.low.min(c);
                w.high = w.high.max(c);
            }
        }
        // a later analysis starts at the final state of the one before,
        // written already: its equilibrium there is logged, not written
        let restart =
            info.increment == 0 && self.current.index > 0 && self.writer.output_steps() > 0;
        let info = &*self.renumbered(info);
        self.peaks.sample(model, state, info.increment);
        if info.output {
            self.peaks.sample_recovered(model, state, info.increment);
        }
        // a kinematic analysis has no loads: its residual is all constraint
        // violation, measured against the tolerance of each constraint
        let (what, values) = if self.current.kind == "kinematic" {
            ("constraint violations (× tolerance)", &self.violations)
        } else {
            ("relative residuals", &info.residuals)
        };
        let (word, size) = if self.current.kind == "dynamic" {
            ("step", "h")
        } else {
            ("increment", "dt")
        };
        let kinematic = self.current.kind == "kinematic";
        // converged above the tolerance: accepted at the round-off
        // plateau of the residual (docs/theory.md §7.1)
        let last = values
            .len()
            .checked_sub(1)
            .and_then(|k| self.reported.get(k));
        let stopped = match (kinematic, last, values.last()) {
            (false, Some(&(value, Reported::Ratio(r))), Some(v)) => {
                value.to_bits() == v.to_bits()
                    && info.iterations > 0
                    && r > self.current.residual_tolerance
            }
            _ => false,
        };
        // `step    1  t = 0.000313  h = 3.125e-4  iterations  1  …`, in
        // the buffer kept from line to line
        let line = self.text.clear();
        line.text(word)
            .text(" ")
            .padded(info.increment, 4)
            .text("  t = ")
            .fixed::<6>(info.time)
            .text("  ")
            .text(size)
            .text(" = ")
            .sci::<3>(info.step)
            .text("  iterations ")
            .padded(info.iterations, 2)
            .text("  ");
        if values.is_empty() {
            // the start of a dynamic analysis: its state, no equations
            // solved for a step
            line.text("(the initial state)");
        } else {
            line.text(what);
            if stopped {
                line.text(" (stopped at round-off)");
            }
            line.text(": ");
        }
        for (k, r) in values.iter().enumerate() {
            if k > 0 {
                line.text(" ");
            }
            // the report of the iteration that gave this residual (the
            // same value), residuals at round-off told so
            match self.reported.get(k) {
                Some(&(value, reported)) if !kinematic && value.to_bits() == r.to_bits() => {
                    Shown::<1>(reported).push_to(line);
                }
                _ => {
                    line.sci::<1>(*r);
                }
            }
        }
        self.log.write_bytes(&self.text);
        self.console.line(self.text.as_text());
        self.console.progress(info);
        if restart {
            return self.log.flush();
        }

        // a stop request before the end: this increment is the last
        // output step
        let stop = self.stop.requested().filter(|_| info.time < self.end_time);
        {
            let _writing = self.stop.output();
            if stop.is_some() && !info.output {
                let last = IncrementInfo {
                    output: true,
                    ..info.clone()
                };
                self.writer.increment(&last, model, state, residual)?;
            } else {
                self.writer.increment(info, model, state, residual)?;
            }
            if let Some((restart, first)) = &mut self.restart {
                if self.current.kind == "dynamic" {
                    // written with the step's continuation, once the next
                    // step is sized (Observer::continuation)
                    self.restart_due = restart.due(state.time);
                } else {
                    restart.increment(
                        *first + self.current.index,
                        self.current.kind,
                        state,
                        None,
                    )?;
                }
            }
        }
        self.log.flush_at_increment(info.output || stop.is_some())?;
        match stop {
            Some(i) => Err(io::Error::new(io::ErrorKind::Interrupted, i)),
            None => Ok(()),
        }
    }

    fn note(&mut self, text: &str) {
        self.line(&format!("note: {text}"));
    }

    fn warning(&mut self, info: &WarningInfo) {
        let word = if self.current.kind == "dynamic" {
            "step"
        } else {
            "increment"
        };
        let text = format!(
            "{word} {} (t = {} to {}): {}",
            info.increment + self.increment_offset,
            format_time(info.from),
            format_time(info.time),
            info.message
        );
        self.log.line(&format!("warning: {text}"));
        self.console.warning(&text);
        self.summary.warnings.push(text);
    }

    fn rejected(&mut self, info: &RejectionInfo) {
        let at = if info.at.is_empty() {
            String::new()
        } else {
            format!(", largest at {}", info.at)
        };
        self.log.line(&format!(
            "step {:4}  from t = {:.6}: step {:.3e} rejected: local error estimate {:.3e} times its tolerance{at}; retrying with {:.3e}",
            info.increment + self.increment_offset,
            info.time,
            info.step,
            info.error,
            info.next_step
        ));
    }

    fn cutback(&mut self, info: &CutbackInfo) {
        let word = if self.current.kind == "dynamic" {
            "step"
        } else {
            "increment"
        };
        self.line(&format!(
            "{word} {:4}  from t = {:.6}: step {:.3e} failed ({}); retrying with {:.3e}",
            info.increment + self.increment_offset,
            info.time,
            info.failed_step,
            info.reason,
            info.next_step
        ));
    }

    fn lock(&mut self, info: &LockInfo) {
        if info.kind == LatchEventKind::Lock {
            self.vibrating_lock(info);
        }
        self.peaks
            .event(info, info.increment + self.increment_offset);
        self.write_event(&EventRow {
            increment: info.increment + self.increment_offset,
            time: info.time,
            element: info.latch,
            kind: info.kind.name(),
            joint: Some(info.joint),
            coordinate: info.coordinate,
            rate_before: info.rate_before,
            rate_after: info.rate_after,
            impulse: info.impulse,
            energy_lost: info.energy_lost,
        });
    }

    fn band_crossing(&mut self, info: &LockInfo) {
        match info.kind {
            LatchEventKind::Engage => self.crossings[0] += 1,
            LatchEventKind::Disengage => self.crossings[1] += 1,
            LatchEventKind::Rearm => self.crossings[2] += 1,
            LatchEventKind::Lock | LatchEventKind::Unlatch => {}
        }
        self.lock(info);
    }

    fn contact(&mut self, info: &ContactInfo) {
        for w in self.stops.iter_mut().filter(|w| w.id == info.stop) {
            w.struck = true;
        }
        self.write_event(&EventRow {
            increment: info.increment + self.increment_offset,
            time: info.time,
            element: info.stop,
            kind: info.kind.name(),
            joint: info.joint,
            coordinate: info.coordinate,
            rate_before: info.rate_before,
            rate_after: info.rate_after,
            impulse: info.impulse,
            energy_lost: info.energy_lost,
        });
    }

    fn event(&mut self, info: &EventInfo) {
        let word = if self.current.kind == "dynamic" {
            "step"
        } else {
            "increment"
        };
        self.line(&format!(
            "{word} {:4}  t = {:.6}: landed on event \"{}\" (value {:.3e})",
            info.increment + self.increment_offset,
            info.time,
            info.name,
            info.value
        ));
    }
}
