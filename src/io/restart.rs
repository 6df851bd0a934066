//! Restart files: the full state of a run at a converged step, from which a
//! later run continues (`unfold run MODEL --restart results/x/restart.json`)
//! to the same result as a run that was never stopped.
//!
//! A run writes `restart.json` into its output directory when it ends
//! (completed, failed or interrupted: the last converged step), and
//! `restart-<t>.json` at each of the times `[output] restart_times` of the
//! model file (at the first converged step at or after each; the analyses
//! land on them, as on output times). The file is JSON
//! (docs/results.md, "Restart files"):
//!
//! ```text
//! { "format": "unfold restart", "version": 2,
//!   "model": { "title": "…", "fingerprint": "fnv1a64:…" },
//!   "analysis": 1, "analysis_type": "static", "time": 0.5,
//!   "state": { "time": 0.5, "x": [[x, y, z], …], "q": [[w, x, y, z], …], … } }
//! ```
//!
//! `state` is the whole [`State`] (positions, orientations, coordinates,
//! multipliers, internal variables, velocities, accelerations and
//! pseudo-accelerations), every number written to its last bit, so a
//! continued run repeats the arithmetic of an uninterrupted one. A file
//! written in a dynamic analysis also has `motion`
//! ([`crate::analysis::Continuation`]: the energy balance at that step,
//! the size of the step that ended there, and, since version 2, the step
//! controller's next size and memory, the regrowth after a lock and the
//! pseudo-accelerations of the step before), written once the next step's
//! size is chosen ([`crate::analysis::Observer::continuation`]); a dynamic
//! analysis continued from a step inside it keeps the state's velocities
//! and accelerations and goes on with these
//! ([`crate::analysis::DynamicAnalysis::continued`]). Files of version 1
//! are still read: their `motion` has no controller's memory, and the
//! continued run starts its steps from `time_step`.
//! `analysis` (from 1) is the analysis of the model's sequence that was
//! running. A restart continues that analysis from `time` when `time` is
//! before its `end_time`, else the next one, and runs the rest of the
//! sequence; the analyses of the file may change between the runs (a later
//! `end_time`, another output), the model may not.
//!
//! The model's fingerprint ([`fingerprint`]) is a hash of the model input
//! without its analyses and outputs, plus what of the first analysis
//! shapes the model (its type, which sets the default load curve, and the
//! constraint scaling and penalty, by which the multipliers are scaled):
//! a restart against another model is refused with [`RestartError::Model`].

use std::hash::Hasher;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::analysis::{AnalysisSettings, Continuation};
use crate::model::input::ModelInput;
use crate::model::Model;
use crate::state::State;

/// The `format` field of a restart file.
pub const FORMAT: &str = "unfold restart";

/// The version of the format written. Version 1 (no step controller's
/// memory in `motion`) is read too; other versions are refused.
pub const VERSION: u32 = 2;

/// The versions read.
const READ_VERSIONS: [u32; 2] = [1, VERSION];

/// Name of the restart file written at the end of a run.
pub const LAST: &str = "restart.json";

/// A restart file: the state of a run at a converged step and where in the
/// model's analyses it was.
#[derive(Clone, Debug, PartialEq)]
pub struct Restart {
    /// Title of the model.
    pub model_title: String,
    /// [`fingerprint`] of the model input.
    pub model_fingerprint: String,
    /// Index (from 0) of the running analysis in the model's sequence.
    pub analysis: usize,
    /// Its type, as the model file names it.
    pub analysis_type: String,
    /// The state.
    pub state: State,
    /// What a dynamic analysis needs besides the state to go on.
    pub motion: Option<Continuation>,
}

/// The file as written.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RestartFile {
    format: String,
    version: u32,
    model: ModelId,
    /// From 1.
    analysis: usize,
    analysis_type: String,
    time: f64,
    state: State,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    motion: Option<Continuation>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelId {
    title: String,
    fingerprint: String,
}

/// Only the header, to recognise a file before reading the rest.
#[derive(Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u32>,
}

/// Why a restart file cannot be used; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum RestartError {
    /// The file cannot be read.
    #[error("{path}: cannot read the restart file: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// The file is not a restart file of this format, or is damaged.
    #[error("{path}: not a valid unfold restart file: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What is wrong, with the place in the file.
        message: String,
    },
    /// The file was written for another model.
    #[error("{path}: the restart was written for another model (\"{title}\", fingerprint {written}; this model's is {model}): a run can continue only the model it was written from, whose nodes, elements, loads and curves must be unchanged (its analyses may change)")]
    Model {
        /// The file.
        path: PathBuf,
        /// Title of the model it was written for.
        title: String,
        /// Its fingerprint.
        written: String,
        /// The fingerprint of the model given.
        model: String,
    },
    /// The state does not have the sizes of the model's state.
    #[error("{path}: the state has {found} {what}, the model {expected}")]
    Size {
        /// The file.
        path: PathBuf,
        /// Which vector.
        what: &'static str,
        /// The model's size.
        expected: usize,
        /// The file's.
        found: usize,
    },
    /// The analysis that was running is not in the model's sequence, or is
    /// of another type now.
    #[error("{path}: the restart is in analysis {index} ({written}, t = {time}), but {now}")]
    Analysis {
        /// The file.
        path: PathBuf,
        /// Index from 1.
        index: usize,
        /// Its type when written.
        written: String,
        /// Time of the restart.
        time: f64,
        /// What the model has instead.
        now: String,
    },
    /// Nothing is left to run after the restart time.
    #[error("{path}: the restart (t = {time}) is {where_} the end of the last analysis (end_time = {end}): nothing is left to run; raise its end_time above {time} or add an analysis")]
    Finished {
        /// The file.
        path: PathBuf,
        /// Time of the restart.
        time: f64,
        /// The last analysis's end time.
        end: f64,
        /// `at` or `past`.
        where_: &'static str,
    },
}

/// Where a restarted run starts: the analysis of the model's sequence
/// (index from 0) and its start state.
#[derive(Clone, Debug)]
pub struct Resume {
    /// The analysis to run first; those after it follow.
    pub analysis: usize,
    /// Its start state.
    pub state: State,
    /// The state is a converged step inside that analysis (not the end of
    /// the one before): a dynamic analysis continues with the state's
    /// velocities and accelerations
    /// ([`crate::analysis::DynamicAnalysis::continued`]).
    pub continues: bool,
    /// What a dynamic analysis needs besides the state to go on, if the
    /// restart is inside one.
    pub motion: Option<Continuation>,
}

/// The fingerprint of a model input: the 64-bit FNV-1a hash of its JSON
/// form without the analyses, the outputs and the bodies' drawn shapes,
/// with the type, constraint scale and penalty of the first analysis
/// (module documentation), as `fnv1a64:` and 16 hex digits. Two inputs that build the same model with
/// the same scaling have the same fingerprint.
pub fn fingerprint(input: &ModelInput) -> String {
    let first = &*input.analysis;
    let shaping = (
        first.kind.as_str(),
        first.constraint_scale,
        first.constraint_penalty,
    );
    let mut model = input.clone();
    model.analysis = Default::default();
    model.output = None;
    // a body's shape is drawn, not simulated: a new shape continues a run
    for body in &mut model.rigid_bodies {
        body.shape = None;
    }
    let text = serde_json::to_string(&(&model, shaping)).expect("a model input serialises");
    let mut hash = FnvHasher::default();
    hash.write(text.as_bytes());
    format!("fnv1a64:{:016x}", hash.finish())
}

/// FNV-1a, 64 bits (Fowler, Noll & Vo; the IETF draft
/// draft-eastlake-fnv): stable across platforms and versions, unlike
/// std's hasher.
struct FnvHasher(u64);

impl Default for FnvHasher {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Hasher for FnvHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

impl Restart {
    /// Writes the file at `path` (through a temporary file renamed over
    /// it, so that a run stopped while writing never leaves half a file).
    pub fn write(&self, path: &Path) -> io::Result<()> {
        let file = RestartFile {
            format: FORMAT.into(),
            version: VERSION,
            model: ModelId {
                title: self.model_title.clone(),
                fingerprint: self.model_fingerprint.clone(),
            },
            analysis: self.analysis + 1,
            analysis_type: self.analysis_type.clone(),
            time: self.state.time,
            state: self.state.clone(),
            motion: self.motion.clone(),
        };
        let err = |e: io::Error| io::Error::new(e.kind(), format!("{}: {e}", path.display()));
        let text = serde_json::to_vec(&file).map_err(|e| err(e.into()))?;
        let tmp = path.with_extension("json.tmp");
        let written = std::fs::File::create(&tmp)
            .and_then(|mut f| {
                f.write_all(&text)?;
                f.write_all(b"\n")?;
                f.sync_all()
            })
            .and_then(|()| std::fs::rename(&tmp, path));
        written.map_err(|e| {
            // a full disk leaves no half-written file behind
            let _ = std::fs::remove_file(&tmp);
            err(e)
        })
    }

    /// Reads a restart file.
    pub fn read(path: &Path) -> Result<Self, RestartError> {
        let text = std::fs::read_to_string(path).map_err(|source| RestartError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let parse = |message: String| RestartError::Parse {
            path: path.to_path_buf(),
            message,
        };
        let header: Header = serde_json::from_str(&text).map_err(|e| parse(e.to_string()))?;
        if header.format.as_deref() != Some(FORMAT) {
            return Err(parse(format!("its \"format\" is not \"{FORMAT}\"")));
        }
        if !header.version.is_some_and(|v| READ_VERSIONS.contains(&v)) {
            let found = match header.version {
                Some(v) => format!("version {v}"),
                None => "no \"version\"".to_string(),
            };
            return Err(parse(format!(
                "{found}; this unfold reads versions 1 and {VERSION}"
            )));
        }
        let file: RestartFile = serde_json::from_str(&text).map_err(|e| parse(e.to_string()))?;
        if file.analysis == 0 {
            return Err(parse("\"analysis\" counts from 1".into()));
        }
        if file.time.to_bits() != file.state.time.to_bits() {
            return Err(parse(format!(
                "\"time\" ({}) is not the state's ({})",
                file.time, file.state.time
            )));
        }
        Ok(Self {
            model_title: file.model.title,
            model_fingerprint: file.model.fingerprint,
            analysis: file.analysis - 1,
            analysis_type: file.analysis_type,
            state: file.state,
            motion: file.motion,
        })
    }

    /// Where a run of `model` (of fingerprint `fingerprint`) with the
    /// analyses `plan` continues from this restart, read from `path`
    /// (named in errors): the running analysis when the restart time is
    /// before its end, else the next.
    pub fn resume(
        &self,
        path: &Path,
        fingerprint: &str,
        model: &Model,
        plan: &[AnalysisSettings],
    ) -> Result<Resume, RestartError> {
        let path = path.to_path_buf();
        if self.model_fingerprint != fingerprint {
            return Err(RestartError::Model {
                path,
                title: self.model_title.clone(),
                written: self.model_fingerprint.clone(),
                model: fingerprint.to_string(),
            });
        }
        let s = &self.state;
        let sizes = model.state_sizes();
        let n = model.n_nodes();
        let nc = sizes.coordinates;
        for (what, expected, found) in [
            ("node positions", n, s.x.len()),
            ("node orientations", n, s.q.len()),
            ("node velocities", n, s.velocity.len()),
            ("node accelerations", n, s.acceleration.len()),
            ("node pseudo-accelerations", n, s.pseudo_acceleration.len()),
            ("coordinates", nc, s.coordinates.len()),
            ("coordinate rates", nc, s.coordinate_rates.len()),
            (
                "coordinate accelerations",
                nc,
                s.coordinate_accelerations.len(),
            ),
            (
                "coordinate pseudo-accelerations",
                nc,
                s.coordinate_pseudo_accelerations.len(),
            ),
            ("multipliers", sizes.multipliers, s.multipliers.len()),
            ("internal variables", sizes.internal, s.internal.len()),
        ] {
            if expected != found {
                return Err(RestartError::Size {
                    path,
                    what,
                    expected,
                    found,
                });
            }
        }
        // a_{n−1} of `motion`: none (after a restart of the accelerations)
        // or one per node and per coordinate
        if let Some(m) = &self.motion {
            for (what, expected, found) in [
                (
                    "node pseudo-accelerations of the step before",
                    n,
                    m.previous_pseudo_acceleration.len(),
                ),
                (
                    "coordinate pseudo-accelerations of the step before",
                    nc,
                    m.previous_coordinate_pseudo_accelerations.len(),
                ),
            ] {
                if found != 0 && found != expected {
                    return Err(RestartError::Size {
                        path,
                        what,
                        expected,
                        found,
                    });
                }
            }
        }
        let analysis_error = |now: String| RestartError::Analysis {
            path: path.clone(),
            index: self.analysis + 1,
            written: self.analysis_type.clone(),
            time: s.time,
            now,
        };
        let Some(running) = plan.get(self.analysis) else {
            return Err(analysis_error(format!(
                "the model has {} analysis(es)",
                plan.len()
            )));
        };
        // a kinetostatic analysis is a static one under another name (and
        // was written as "static" before it had its own)
        fn base(t: &str) -> &str {
            if t == "kinetostatic" {
                "static"
            } else {
                t
            }
        }
        let same_type = |a: &str, b: &str| base(a) == base(b);
        if !same_type(running.name(), &self.analysis_type) {
            return Err(analysis_error(format!(
                "that analysis of the model is {}",
                running.name()
            )));
        }
        let end = running.end_time();
        // the analysis runs from the end of the one before (0 for the
        // first): a state before that, or one whose time is not a number,
        // is not one of its states
        let start = match self.analysis {
            0 => 0.0,
            k => plan[k - 1].end_time(),
        };
        if !s.time.is_finite() || s.time < start - END_TOLERANCE * start.abs().max(1.0) {
            return Err(RestartError::Parse {
                path,
                message: format!(
                    "its time t = {} is before the start of analysis {} ({}, from t = {start})",
                    s.time,
                    self.analysis + 1,
                    running.name()
                ),
            });
        }
        if let Some(message) = self.motion.as_ref().and_then(|m| m.invalid(start, end)) {
            return Err(RestartError::Parse { path, message });
        }
        let analysis = if s.time < end - END_TOLERANCE * end.abs().max(1.0) {
            self.analysis
        } else {
            self.analysis + 1
        };
        if analysis >= plan.len() {
            let end = plan.last().map_or(end, |a| a.end_time());
            let where_ = if s.time > end + END_TOLERANCE * end.abs().max(1.0) {
                "past"
            } else {
                "at"
            };
            return Err(RestartError::Finished {
                path,
                time: s.time,
                end,
                where_,
            });
        }
        Ok(Resume {
            analysis,
            state: self.state.clone(),
            continues: analysis == self.analysis,
            motion: self.motion.clone().filter(|_| analysis == self.analysis),
        })
    }
}

/// A restart time at which the running analysis is taken as ended,
/// relative: the step controller lands on `end_time` to round-off.
const END_TOLERANCE: f64 = 1e-12;

/// Writes the restart files of a run: at the requested times and at its
/// end. Analyses are numbered in the model's sequence (a restarted run
/// that starts in its second analysis numbers it 1 from 0).
#[derive(Clone, Debug)]
pub struct RestartWriter {
    dir: PathBuf,
    model_title: String,
    model_fingerprint: String,
    times: Vec<f64>,
    /// The first of `times` not yet written.
    next: usize,
}

impl RestartWriter {
    /// Restart files of a run of the model `input` into `dir`, at the
    /// times `[output] restart_times` of the input.
    pub fn new(dir: &Path, input: &ModelInput) -> Self {
        let mut times = input
            .output
            .as_ref()
            .map(|o| o.restart_times.clone())
            .unwrap_or_default();
        times.sort_by(f64::total_cmp);
        Self {
            dir: dir.to_path_buf(),
            model_title: input.title.clone().unwrap_or_default(),
            model_fingerprint: fingerprint(input),
            times,
            next: 0,
        }
    }

    /// Starts the requested times after `time` (a restarted run does not
    /// write those before its start again).
    pub fn starting_at(mut self, time: f64) -> Self {
        self.next = self.times.partition_point(|&t| t <= time);
        self
    }

    /// The path of the file written at the end of the run.
    pub fn last_path(&self) -> PathBuf {
        self.dir.join(LAST)
    }

    fn restart(
        &self,
        analysis: usize,
        analysis_type: &str,
        state: &State,
        motion: Option<Continuation>,
    ) -> Restart {
        Restart {
            model_title: self.model_title.clone(),
            model_fingerprint: self.model_fingerprint.clone(),
            analysis,
            analysis_type: analysis_type.to_string(),
            state: state.clone(),
            motion,
        }
    }

    /// After a converged step of analysis `analysis` (index in the model's
    /// sequence) at `state.time`: writes `restart-<t>.json` for the
    /// requested time `t` reached (to round-off), or passed, since the last
    /// step, with what a dynamic analysis needs besides to go on
    /// (`motion`).
    pub fn increment(
        &mut self,
        analysis: usize,
        analysis_type: &str,
        state: &State,
        motion: Option<Continuation>,
    ) -> io::Result<()> {
        match self.due(state.time) {
            Some(t) => self.write_at(t, analysis, analysis_type, state, motion),
            None => Ok(()),
        }
    }

    /// The requested time reached (to round-off), or passed, by a
    /// converged step at `time` since the last step, if any: its file is
    /// then due ([`Self::write_at`]; a dynamic analysis writes it once the
    /// size of its next step is chosen).
    pub fn due(&mut self, time: f64) -> Option<f64> {
        let mut due = None;
        while let Some(&t) = self.times.get(self.next) {
            if time < t - END_TOLERANCE * t.abs().max(1.0) {
                break;
            }
            due = Some(t);
            self.next += 1;
        }
        due
    }

    /// Writes `restart-<t>.json`, for the requested time `t`, with
    /// `state`, a converged step of analysis `analysis`, and `motion`.
    pub fn write_at(
        &self,
        t: f64,
        analysis: usize,
        analysis_type: &str,
        state: &State,
        motion: Option<Continuation>,
    ) -> io::Result<()> {
        self.restart(analysis, analysis_type, state, motion)
            .write(&self.dir.join(format!("restart-{t}.json")))
    }

    /// At the end of the run: writes `restart.json` with `state`, the last
    /// converged state of analysis `analysis` (with `motion` in a dynamic
    /// analysis).
    pub fn finish(
        &self,
        analysis: usize,
        analysis_type: &str,
        state: &State,
        motion: Option<Continuation>,
    ) -> io::Result<()> {
        self.restart(analysis, analysis_type, state, motion)
            .write(&self.last_path())
    }
}

/// Removes the restart files of an earlier run from `dir` (`restart.json`,
/// `restart-<t>.json` and their temporary files), but `keep`; a run
/// rejected at its start leaves none of another model behind.
pub fn remove_earlier(dir: &Path, keep: Option<&Path>) -> io::Result<()> {
    let named = |e: io::Error| io::Error::new(e.kind(), format!("{}: {e}", dir.display()));
    let keep = keep.and_then(|k| k.canonicalize().ok());
    let entries = match std::fs::read_dir(dir) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        entries => entries.map_err(named)?,
    };
    for entry in entries {
        let path = entry.map_err(named)?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let stem = name.strip_suffix(".tmp").unwrap_or(name);
        let restart = stem == LAST || (stem.starts_with("restart-") && stem.ends_with(".json"));
        let kept = keep.is_some() && path.canonicalize().ok() == keep;
        if !restart || kept {
            continue;
        }
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => {
                return Err(io::Error::new(e.kind(), format!("{}: {e}", path.display())))
            }
            _ => {}
        }
    }
    Ok(())
}
