//! Time histories of a run, drawn from its result files for a report
//! (docs/plots.md): the joint coordinates, the moments (or forces) the
//! joint springs, hinge laws, latches and drivers apply along them, and
//! the energies of a dynamic analysis with its balance error on a chart
//! of its own.
//!
//! The files are read as `unfold run` writes them (docs/results.md): the
//! type of each joint and its coordinates from `joints.csv` (its columns
//! `type`, `angle`, `slide`...); which joint and coordinate each spring,
//! law, latch and driver acts on from the model file named in
//! `summary.json` (or given). The instants at which latches lock (the
//! first step with `locked = 1` in `latches.csv`) and the events of
//! `events.csv`, when the run wrote one, are vertical lines on the charts
//! of their joint and on the energy charts.
//!
//! ```no_run
//! use unfold::io::histories::{Format, Histories, Request};
//!
//! let h = Histories::read("results/panels".as_ref(), None).unwrap();
//! let figures = h.figures(&Request::default()).unwrap();
//! for path in Histories::write(&figures, "results/panels/plots".as_ref(), Format::Both).unwrap() {
//!     println!("{}", path.display());
//! }
//! ```

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::plot::{Axis, Chart, PlotError, Series};
use crate::joints::{Coordinate, JointType};
use crate::model::Id;

/// A family of charts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Group {
    /// The coordinates of every joint against `t`, one chart per joint.
    Joints,
    /// Moments and forces along the joint coordinates: joint springs and
    /// dampers, hinge laws, latch loads and driver loads, one chart per
    /// joint.
    Moments,
    /// The moment of each hinge law against its coordinate (the
    /// hysteresis loop), one chart per law.
    HingeLaws,
    /// Energies of a dynamic analysis, and its balance error.
    Energies,
}

impl Group {
    /// Every group, in the order charts are written.
    pub const ALL: [Group; 4] = [
        Group::Joints,
        Group::Moments,
        Group::HingeLaws,
        Group::Energies,
    ];

    /// What a name of a chart may be, for messages.
    pub const NAMES: &'static str =
        "joints, moments or energies (against t), or hinge_laws (moment against angle)";

    /// Name on the command line and in `[output] plots`.
    pub fn name(self) -> &'static str {
        match self {
            Group::Joints => "joints",
            Group::Moments => "moments",
            Group::HingeLaws => "hinge_laws",
            Group::Energies => "energies",
        }
    }

    /// The group named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|g| g.name() == name)
    }
}

/// How the axes name the units of the values, which are those of the
/// model (docs/model-format.md: consistent units of the user's choice).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UnitLabels {
    /// SI: s, m, N, N·m, J (the recommended system).
    #[default]
    Si,
    /// The model's own units, named by their dimension ("force·length").
    Model,
}

impl UnitLabels {
    fn time(self) -> &'static str {
        match self {
            Self::Si => "s",
            Self::Model => "time unit",
        }
    }
    fn length(self) -> &'static str {
        match self {
            Self::Si => "m",
            Self::Model => "length unit",
        }
    }
    fn force(self) -> &'static str {
        match self {
            Self::Si => "N",
            Self::Model => "force unit",
        }
    }
    fn moment(self) -> &'static str {
        match self {
            Self::Si => "N·m",
            Self::Model => "force·length",
        }
    }
    fn energy(self) -> &'static str {
        match self {
            Self::Si => "J",
            Self::Model => "force·length",
        }
    }
}

/// What to draw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Request {
    /// The groups; empty for every group the results allow.
    pub groups: Vec<Group>,
    /// The joints of the joint and moment charts; empty for all.
    pub joints: Vec<Id>,
    /// Angles in degrees (the files give radians).
    pub degrees: bool,
    /// Unit names on the axes.
    pub units: UnitLabels,
}

/// File formats of the charts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Format {
    /// PNG pictures.
    Png,
    /// SVG drawings.
    Svg,
    /// Both.
    #[default]
    Both,
}

/// A chart and the stem of its file names.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// File name without extension (`joint_10`).
    pub name: String,
    /// The chart.
    pub chart: Chart,
}

/// Why the histories could not be read or drawn.
#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    /// The results directory does not exist.
    #[error("{0}: no such directory")]
    NoDirectory(PathBuf),
    /// The directory holds no results of a run.
    #[error("{0}: no results here (no steps.csv); write them with `unfold run MODEL --out DIR`")]
    NoResults(PathBuf),
    /// A file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// A result file is not as `unfold run` writes it.
    #[error("{path}, line {line}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// Line number, from 1.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A joint asked for is not in the results.
    #[error("joint {id}: not in {path} (its joints: {known})")]
    UnknownJoint {
        /// The joint asked for.
        id: Id,
        /// `joints.csv`.
        path: PathBuf,
        /// The joints it holds.
        known: String,
    },
    /// A group asked for that the results cannot give.
    #[error("{group}: nothing to plot: {reason}")]
    Unavailable {
        /// The group's name.
        group: &'static str,
        /// Why.
        reason: String,
    },
    /// The output directory could not be created.
    #[error("{path}: {source}")]
    Write {
        /// The directory.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// A chart could not be drawn or written.
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// A CSV result file: header and rows as text, numbers parsed on demand
/// so that an error names the line.
#[derive(Clone, Debug)]
pub(crate) struct Table {
    pub(crate) path: PathBuf,
    pub(crate) header: Vec<String>,
    /// Line number (from 1) and fields of each row.
    pub(crate) rows: Vec<(usize, Vec<String>)>,
}

impl Table {
    /// Reads `path`; `None` if the file does not exist.
    pub(crate) fn read(path: &Path) -> Result<Option<Self>, HistoryError> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => {
                return Err(HistoryError::Read {
                    path: path.to_path_buf(),
                    source,
                })
            }
        };
        let malformed = |line, message: String| HistoryError::Malformed {
            path: path.to_path_buf(),
            line,
            message,
        };
        let mut lines = text.lines().enumerate();
        let header: Vec<String> = match lines.next() {
            Some((_, h)) if !h.trim().is_empty() => {
                h.split(',').map(|c| c.trim().to_string()).collect()
            }
            _ => return Err(malformed(1, "empty file: no header row".into())),
        };
        let mut rows = Vec::new();
        for (k, line) in lines {
            if line.trim().is_empty() {
                continue;
            }
            let fields: Vec<String> = line.split(',').map(|f| f.trim().to_string()).collect();
            if fields.len() != header.len() {
                return Err(malformed(
                    k + 1,
                    format!(
                        "{} fields, but the header names {} columns",
                        fields.len(),
                        header.len()
                    ),
                ));
            }
            rows.push((k + 1, fields));
        }
        Ok(Some(Self {
            path: path.to_path_buf(),
            header,
            rows,
        }))
    }

    /// Index of column `name`, if the file has it.
    pub(crate) fn find(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// Index of column `name`, which the file must have.
    pub(crate) fn column(&self, name: &str) -> Result<usize, HistoryError> {
        self.find(name).ok_or_else(|| HistoryError::Malformed {
            path: self.path.clone(),
            line: 1,
            message: format!("no column `{name}` in the header"),
        })
    }

    /// The number in row `r`, column `c`: NaN where the field is empty.
    pub(crate) fn number(&self, r: usize, c: usize) -> Result<f64, HistoryError> {
        let (line, fields) = &self.rows[r];
        let field = &fields[c];
        if field.is_empty() {
            return Ok(f64::NAN);
        }
        field.parse().map_err(|_| HistoryError::Malformed {
            path: self.path.clone(),
            line: *line,
            message: format!("column `{}`: {field:?} is not a number", self.header[c]),
        })
    }

    /// The id in row `r`, column `c`.
    pub(crate) fn id(&self, r: usize, c: usize) -> Result<Id, HistoryError> {
        let (line, fields) = &self.rows[r];
        fields[c].parse().map_err(|_| HistoryError::Malformed {
            path: self.path.clone(),
            line: *line,
            message: format!("column `{}`: {:?} is not an id", self.header[c], fields[c]),
        })
    }

    /// For each id of column `id_column` (in increasing order), its
    /// points `(time, value)` of each of `columns`.
    #[allow(clippy::type_complexity)]
    fn histories(
        &self,
        id_column: &str,
        columns: &[&str],
    ) -> Result<BTreeMap<Id, Vec<Vec<(f64, f64)>>>, HistoryError> {
        let time = self.column("time")?;
        let id = self.column(id_column)?;
        let cols: Vec<usize> = columns
            .iter()
            .map(|c| self.column(c))
            .collect::<Result<_, _>>()?;
        let mut out: BTreeMap<Id, Vec<Vec<(f64, f64)>>> = BTreeMap::new();
        for r in 0..self.rows.len() {
            let t = self.number(r, time)?;
            let entry = out
                .entry(self.id(r, id)?)
                .or_insert_with(|| vec![Vec::new(); cols.len()]);
            for (k, &c) in cols.iter().enumerate() {
                entry[k].push((t, self.number(r, c)?));
            }
        }
        Ok(out)
    }
}

/// How many of each noun, in order of first appearance: `["1 lock",
/// "3 engages"]` (plural with `es` after `ch` and `s`).
fn counted<'a>(nouns: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for noun in nouns {
        match counts.iter_mut().find(|c| c.0 == noun) {
            Some(c) => c.1 += 1,
            None => counts.push((noun, 1)),
        }
    }
    counts
        .iter()
        .map(|&(noun, n)| match n {
            1 => format!("1 {noun}"),
            _ if noun.ends_with("ch") || noun.ends_with('s') => format!("{n} {noun}es"),
            _ => format!("{n} {noun}s"),
        })
        .collect()
}

/// `x` to four significant digits, in exponent form outside [1e-3, 1e5).
fn significant(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 {
        return "0".into();
    }
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        let text = format!("{x:.decimals$}");
        // trailing zeros say nothing here
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        format!("{x:.3e}")
    }
}

/// Events closer in time to the one before than this fraction of a
/// chart's time range are labelled as one group.
const EVENT_GROUP: f64 = 0.03;

/// Whether a series has a finite value.
fn has_values(points: &[(f64, f64)]) -> bool {
    points.iter().any(|p| p.0.is_finite() && p.1.is_finite())
}

/// What the model file says about the coordinates in the results.
#[derive(Clone, Debug, Default)]
struct Coordinates {
    /// Type of each joint.
    joints: BTreeMap<Id, JointType>,
    /// Joint and coordinate of each joint spring, hinge law, latch and
    /// joint driver, by file and id.
    acting: BTreeMap<(&'static str, Id), (Id, Coordinate)>,
    /// Locking value of each latch (m or rad).
    latch_values: BTreeMap<Id, f64>,
}

impl Coordinates {
    /// From the model file at `path` (parsed, not built).
    fn of_model(path: &Path) -> Option<Self> {
        let text = std::fs::read_to_string(path).ok()?;
        let input = super::model_file::parse_model(&text, path).ok()?;
        let joints: BTreeMap<Id, JointType> = input.joints.iter().map(|j| (j.id, j.kind)).collect();
        // the coordinate named, or the joint's first (as the model builder
        // resolves it, src/model/build/joints.rs)
        let resolve = |joint: Id, name: &Option<String>| -> Option<(Id, Coordinate)> {
            let coords = joints.get(&joint)?.coordinates();
            let c = match name {
                None => coords.first().copied(),
                Some(n) => coords.iter().copied().find(|c| c.name() == n),
            }?;
            Some((joint, c))
        };
        let mut acting = BTreeMap::new();
        let mut latch_values = BTreeMap::new();
        for s in &input.joint_springs {
            if let Some(c) = resolve(s.joint, &s.coordinate) {
                acting.insert(("joint_springs", s.id), c);
            }
        }
        for h in &input.hinge_laws {
            if let Some(c) = resolve(h.joint, &h.coordinate) {
                acting.insert(("hinge_laws", h.id), c);
            }
        }
        for l in &input.latches {
            if let Some(c) = resolve(l.joint, &l.coordinate) {
                acting.insert(("latches", l.id), c);
                let unit = if c.1.is_angle() {
                    l.unit.unwrap_or_default().radians()
                } else {
                    1.0
                };
                latch_values.insert(l.id, l.value * unit);
            }
        }
        for d in &input.drivers {
            if let Some(c) = d.joint.and_then(|j| resolve(j, &d.coordinate)) {
                acting.insert(("drivers", d.id), c);
            }
        }
        Some(Self {
            joints,
            acting,
            latch_values,
        })
    }
}

/// A vertical line: at `t`, on the charts of `joint` (all joint charts if
/// `None`) and on the energy charts.
#[derive(Clone, Debug, PartialEq)]
struct Event {
    time: f64,
    joint: Option<Id>,
    label: String,
    /// Kind of event of `events.csv` (`impact`, `lock`; `lock` too for a
    /// lock read from `latches.csv`), to count the events of a group.
    kind: Option<String>,
    /// Energy lost at the event (`events.csv`), in the model's units.
    lost: Option<f64>,
    /// The element (latch, stop, contact) of an `events.csv` row, if the
    /// file names it.
    element: Option<Id>,
}

/// Kinds of `events.csv` rows drawn as ticks rather than labelled lines:
/// a spring latch's band crossings, which come by the dozen when it
/// rattles across its dead band.
const MINOR_EVENTS: [&str; 3] = ["engage", "disengage", "rearm"];

impl Event {
    /// Whether it is drawn as a tick ([`MINOR_EVENTS`]).
    fn is_minor(&self) -> bool {
        self.kind
            .as_deref()
            .is_some_and(|k| MINOR_EVENTS.contains(&k))
    }
}

/// The result files of one run, read.
#[derive(Debug)]
pub struct Histories {
    dir: PathBuf,
    /// Types of the analyses of the run (`summary.json`), if known.
    analysis_types: Vec<String>,
    /// Coordinates of the model, if its file could be read.
    coordinates: Option<Coordinates>,
    /// The model file looked for.
    model_file: Option<PathBuf>,
    joints: Option<Table>,
    joint_springs: Option<Table>,
    hinge_laws: Option<Table>,
    latches: Option<Table>,
    drivers: Option<Table>,
    energies: Option<Table>,
    events: Vec<Event>,
}

impl Histories {
    /// Reads the result files in `dir`; `model` is the model file that
    /// says which joint coordinate each spring, law, latch and driver acts
    /// on (default: the one named in `summary.json`, relative to the
    /// current directory if relative).
    pub fn read(dir: &Path, model: Option<&Path>) -> Result<Self, HistoryError> {
        if !dir.is_dir() {
            return Err(HistoryError::NoDirectory(dir.to_path_buf()));
        }
        if !dir.join("steps.csv").is_file() {
            return Err(HistoryError::NoResults(dir.to_path_buf()));
        }
        let summary_path = dir.join("summary.json");
        let summary: Option<serde_json::Value> = match std::fs::read_to_string(&summary_path) {
            Ok(text) => Some(
                serde_json::from_str(&text).map_err(|e| HistoryError::Malformed {
                    path: summary_path.clone(),
                    line: e.line(),
                    message: e.to_string(),
                })?,
            ),
            Err(_) => None,
        };
        let analysis_types = summary
            .as_ref()
            .and_then(|s| s["analyses"].as_array())
            .map(|a| {
                a.iter()
                    .filter_map(|x| x["type"].as_str().map(str::to_string))
                    .collect()
            })
            .unwrap_or_default();
        let model_file = model.map(Path::to_path_buf).or_else(|| {
            summary
                .as_ref()
                .and_then(|s| s["model"].as_str())
                .map(PathBuf::from)
        });
        let coordinates = model_file.as_deref().and_then(Coordinates::of_model);
        let table = |name: &str| Table::read(&dir.join(name));
        let mut h = Self {
            dir: dir.to_path_buf(),
            analysis_types,
            coordinates,
            model_file,
            joints: table("joints.csv")?,
            joint_springs: table("joint_springs.csv")?,
            hinge_laws: table("hinge_laws.csv")?,
            latches: table("latches.csv")?,
            drivers: table("drivers.csv")?,
            energies: table("energies.csv")?,
            events: Vec::new(),
        };
        h.events = h.read_events()?;
        Ok(h)
    }

    /// What the charts cannot know, to tell the user: the model file was
    /// not found, so angles and lengths are not told apart.
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        // joints.csv names its coordinates and the type of each joint
        let has_coordinates = self
            .joints
            .as_ref()
            .is_some_and(|t| t.find("type").is_none())
            || self.joint_springs.is_some()
            || self.hinge_laws.is_some()
            || self.latches.is_some();
        if self.coordinates.is_none() && has_coordinates {
            let which = self
                .model_file
                .as_ref()
                .map_or("summary.json names none".into(), |p| {
                    format!("{} cannot be read", p.display())
                });
            notes.push(format!(
                "model file unknown ({which}; give it with --model): the loads of joint springs, hinge laws, latches and drivers are drawn on one chart as the files give them, moments and forces (along angles in rad and slides in length units) without telling them apart"
            ));
        }
        notes
    }

    /// Lock instants (`latches.csv`) and the events of `events.csv`.
    fn read_events(&self) -> Result<Vec<Event>, HistoryError> {
        let mut events = Vec::new();
        if let Some(t) = &self.latches {
            let (time, latch, locked) =
                (t.column("time")?, t.column("latch")?, t.column("locked")?);
            let mut seen = BTreeSet::new();
            for r in 0..t.rows.len() {
                let id = t.id(r, latch)?;
                if t.number(r, locked)? == 1.0 && seen.insert(id) {
                    let joint = self
                        .coordinates
                        .as_ref()
                        .and_then(|c| c.acting.get(&("latches", id)))
                        .map(|a| a.0);
                    events.push(Event {
                        time: t.number(r, time)?,
                        joint,
                        label: format!("latch {id} locks"),
                        kind: Some("lock".into()),
                        lost: None,
                        element: Some(id),
                    });
                }
            }
        }
        // events.csv, when the run wrote one: `time`, `joint`, `energy_lost`
        // and possibly a kind of event
        if let Some(t) = Table::read(&self.dir.join("events.csv"))? {
            let time = t.column("time")?;
            let joint = t.find("joint");
            let lost = t.find("energy_lost");
            let element = t.find("element");
            let kind = ["event", "kind", "type"].iter().find_map(|c| t.find(c));
            for r in 0..t.rows.len() {
                let element = match element {
                    Some(c) if !t.rows[r].1[c].is_empty() => Some(t.id(r, c)?),
                    _ => None,
                };
                let at = t.number(r, time)?;
                let joint = match joint {
                    Some(c) if !t.rows[r].1[c].is_empty() => Some(t.id(r, c)?),
                    _ => None,
                };
                let kind = match kind {
                    Some(c) if !t.rows[r].1[c].is_empty() => t.rows[r].1[c].clone(),
                    _ => "event".to_string(),
                };
                let mut label = kind.clone();
                if let Some(j) = joint {
                    label += &format!(" at joint {j}");
                }
                let lost = match lost {
                    Some(c) => Some(t.number(r, c)?).filter(|e| e.is_finite()),
                    None => None,
                };
                // a lock already marked from latches.csv at the same instant
                // (and joint, where both are known) takes the energy lost
                // instead of a second line
                let tol = 1e-9 * at.abs().max(1.0);
                let minor = kind.as_str();
                if MINOR_EVENTS.contains(&minor) {
                    events.push(Event {
                        time: at,
                        joint,
                        label,
                        kind: Some(kind),
                        lost,
                        element,
                    });
                    continue;
                }
                if let Some(e) = events.iter_mut().find(|e: &&mut Event| {
                    (e.time - at).abs() <= tol
                        && (e.joint == joint || joint.is_none() || e.joint.is_none())
                }) {
                    e.lost = e.lost.or(lost);
                    continue;
                }
                events.push(Event {
                    time: at,
                    joint,
                    label,
                    kind: Some(kind),
                    lost,
                    element,
                });
            }
        }
        Ok(events)
    }

    /// The horizontal axis: the load parameter of static and kinematic
    /// analyses, time in dynamic ones.
    fn time_axis(&self, units: UnitLabels) -> Axis {
        let dynamic = self.analysis_types.iter().any(|t| t == "dynamic") || self.energies.is_some();
        let quasi_static = self
            .analysis_types
            .iter()
            .any(|t| t == "static" || t == "kinetostatic" || t == "kinematic");
        match (dynamic, quasi_static) {
            (true, false) => Axis::new("time t", units.time()),
            (true, true) => Axis::new("t: load parameter (static), time (dynamic)", units.time()),
            _ => Axis::dimensionless("load parameter t"),
        }
    }

    /// The joints in `joints.csv`, in increasing id.
    pub fn joint_ids(&self) -> Result<Vec<Id>, HistoryError> {
        let Some(t) = &self.joints else {
            return Ok(Vec::new());
        };
        let c = t.column("joint")?;
        let ids: BTreeSet<Id> = (0..t.rows.len())
            .map(|r| t.id(r, c))
            .collect::<Result<_, _>>()?;
        Ok(ids.into_iter().collect())
    }

    /// The groups these results can give.
    pub fn available(&self) -> Vec<Group> {
        let mut groups = Vec::new();
        if self.joints.is_some() {
            groups.push(Group::Joints);
        }
        if self.joint_springs.is_some()
            || self.hinge_laws.is_some()
            || self.latches.is_some()
            || self.drivers.is_some()
        {
            groups.push(Group::Moments);
        }
        if self.hinge_laws.is_some() {
            groups.push(Group::HingeLaws);
        }
        if self.energies.is_some() {
            groups.push(Group::Energies);
        }
        groups
    }

    /// The charts of `request`: an error if a group asked for has nothing
    /// to draw, or a joint asked for is not in the results.
    pub fn figures(&self, request: &Request) -> Result<Vec<Figure>, HistoryError> {
        let available = self.available();
        let groups: Vec<Group> = if request.groups.is_empty() {
            available.clone()
        } else {
            let mut g = request.groups.clone();
            g.sort();
            g.dedup();
            g
        };
        if groups.is_empty() {
            return Err(HistoryError::Unavailable {
                group: "results",
                reason: format!(
                    "{} has no joint, moment or energy histories",
                    self.dir.display()
                ),
            });
        }
        let known = self.joint_ids()?;
        for &id in &request.joints {
            if !known.contains(&id) {
                return Err(HistoryError::UnknownJoint {
                    id,
                    path: self.dir.join("joints.csv"),
                    known: if known.is_empty() {
                        "none".into()
                    } else {
                        known
                            .iter()
                            .map(Id::to_string)
                            .collect::<Vec<_>>()
                            .join(", ")
                    },
                });
            }
        }
        let chosen = |j: Id| request.joints.is_empty() || request.joints.contains(&j);
        let mut figures = Vec::new();
        for group in groups {
            if !available.contains(&group) {
                let missing = format!("joints.csv is missing from {}", self.dir.display());
                let reason = match group {
                    Group::Joints => match &self.coordinates {
                        Some(c) if c.joints.is_empty() => {
                            "the model has no joints (no joints.csv)".to_string()
                        }
                        Some(_) => format!("{missing}, although the model has joints"),
                        None => missing,
                    },
                    Group::Moments => {
                        "the model has no joint springs, hinge laws, latches or drivers".into()
                    }
                    Group::HingeLaws => "no hinge_laws.csv: the model has no hinge laws".into(),
                    Group::Energies => {
                        "no energies.csv: energies are written by dynamic analyses".into()
                    }
                };
                return Err(HistoryError::Unavailable {
                    group: group.name(),
                    reason,
                });
            }
            match group {
                Group::Joints => figures.extend(self.joint_figures(request, &chosen)?),
                Group::Moments => figures.extend(self.moment_figures(request, &chosen)?),
                Group::HingeLaws => figures.extend(self.hinge_law_figures(request, &chosen)?),
                Group::Energies => figures.extend(self.energy_figures(request)?),
            }
        }
        // a run that stopped before its first step has rows without values
        figures.retain(|f| f.chart.series.iter().any(|s| has_values(&s.points)));
        if figures.is_empty() {
            return Err(HistoryError::Unavailable {
                group: "results",
                reason: format!("{} has no step with values", self.dir.display()),
            });
        }
        Ok(figures)
    }

    /// The events on the charts of joint `joint` (`None`: charts of no
    /// single joint, which show every event).
    fn events_of(&self, joint: Option<Id>) -> impl Iterator<Item = &Event> {
        self.events
            .iter()
            .filter(move |e| joint.is_none() || e.joint.is_none() || e.joint == joint)
    }

    /// Draws the events of `joint` on `chart`: each a vertical line;
    /// events closer to the one before than [`EVENT_GROUP`] of the chart's
    /// time range are labelled once as a group ("10 impacts at joint 2,
    /// 1.242–1.354 s, 0.6131 J lost"), so that a run of rebounds does not
    /// pile up its labels; a spring latch's band crossings are ticks, one
    /// label per rattle ("latch 20: 10 engages, 10 disengages, 0.275–1.772
    /// s").
    fn with_events(&self, mut chart: Chart, joint: Option<Id>, units: UnitLabels) -> Chart {
        let (mut minor, mut events): (Vec<&Event>, Vec<&Event>) =
            self.events_of(joint).partition(|e| e.is_minor());
        events.sort_by(|a, b| a.time.total_cmp(&b.time));
        minor.sort_by(|a, b| a.time.total_cmp(&b.time));
        let (lo, hi) = chart
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .map(|p| p.0)
            .filter(|x| x.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let close = if hi > lo {
            EVENT_GROUP * (hi - lo)
        } else {
            0.0
        };
        // events closer than `close` to the one before join its group
        fn groups(events: Vec<&Event>, close: f64) -> Vec<Vec<&Event>> {
            let mut groups: Vec<Vec<&Event>> = Vec::new();
            for e in events {
                match groups.last_mut() {
                    Some(g) if e.time - g[g.len() - 1].time <= close => g.push(e),
                    _ => groups.push(vec![e]),
                }
            }
            groups
        }
        let time_unit = match chart.x.unit.as_str() {
            "–" => String::new(),
            u => format!(" {u}"),
        };
        for group in groups(events, close) {
            let label = Self::group_label(&group, units, &time_unit);
            chart = chart.event(group[0].time, label);
            for e in &group[1..] {
                chart = chart.event(e.time, "");
            }
        }
        // band crossings: a tick each, one label per latch between its
        // locks and unlatches (a rattle)
        for cluster in Self::rattles(minor, &self.events) {
            let label = Self::cluster_label(&cluster, &time_unit);
            chart = chart.tick(cluster[0].time, label);
            for e in &cluster[1..] {
                chart = chart.tick(e.time, "");
            }
        }
        chart
    }

    /// The band crossings `minor` (in order of time) in clusters: those of
    /// one latch (or joint, for files that name no latch) between two of
    /// its other events (locks, unlatches) among `all`.
    fn rattles<'a>(minor: Vec<&'a Event>, all: &[Event]) -> Vec<Vec<&'a Event>> {
        let key = |e: &Event| (e.element, e.joint);
        let mut clusters: Vec<Vec<&Event>> = Vec::new();
        for e in minor {
            let open = clusters.iter_mut().rev().find(|c| key(c[0]) == key(e));
            match open {
                // the same rattle unless a lock or unlatch of the latch
                // came between
                Some(c)
                    if !all.iter().any(|m| {
                        !m.is_minor()
                            && m.time > c[c.len() - 1].time
                            && m.time < e.time
                            && match (m.element, e.element) {
                                (Some(a), Some(b)) => a == b,
                                _ => m.joint == e.joint,
                            }
                    }) =>
                {
                    c.push(e)
                }
                _ => clusters.push(vec![e]),
            }
        }
        clusters.sort_by(|a, b| a[0].time.total_cmp(&b[0].time));
        clusters
    }

    /// The label of a cluster of band crossings: the latch (or the joint)
    /// if they share one, how many of each kind and their interval of
    /// time (`latch 5: 6 engages, 5 disengages, 0.4277–0.532 s`).
    fn cluster_label(cluster: &[&Event], time_unit: &str) -> String {
        let shared = |f: fn(&Event) -> Option<Id>| {
            f(cluster[0]).filter(|id| cluster.iter().all(|e| f(e) == Some(*id)))
        };
        let whose = match (shared(|e| e.element), shared(|e| e.joint)) {
            (Some(latch), _) => format!("latch {latch}: "),
            (None, Some(joint)) => format!("joint {joint}: "),
            (None, None) => String::new(),
        };
        let what = counted(cluster.iter().map(|e| e.kind.as_deref().unwrap_or("event")));
        let (first, last) = (cluster[0].time, cluster[cluster.len() - 1].time);
        let when = if cluster.len() == 1 {
            format!("at {}{time_unit}", significant(first))
        } else {
            format!("{}–{}{time_unit}", significant(first), significant(last))
        };
        format!("{whose}{}, {when}", what.join(", "))
    }

    /// The label of a group of events: the event's own for one event;
    /// otherwise how many of each kind, the joint if they share one, the
    /// interval of time and the energy lost in all.
    fn group_label(group: &[&Event], units: UnitLabels, time_unit: &str) -> String {
        let lost = group.iter().filter_map(|e| e.lost).sum::<f64>();
        let any_lost = group.iter().any(|e| e.lost.is_some());
        let with_lost = |text: String| {
            if any_lost {
                format!("{text}, {} {} lost", significant(lost), units.energy())
            } else {
                text
            }
        };
        if let [e] = group {
            return with_lost(e.label.clone());
        }
        let what = counted(
            group
                .iter()
                .map(|e| e.kind.as_deref().unwrap_or(e.label.as_str())),
        );
        let joint = group[0].joint.filter(|j| {
            group.iter().all(|e| e.joint == Some(*j)) && group.iter().all(|e| e.kind.is_some())
        });
        let at = joint.map_or(String::new(), |j| format!(" at joint {j}"));
        let (first, last) = (group[0].time, group[group.len() - 1].time);
        with_lost(format!(
            "{}{at}, {}–{}{time_unit}",
            what.join(", "),
            significant(first),
            significant(last),
        ))
    }

    /// The unit of coordinate `c` (and the factor from the file's values).
    fn coordinate_unit(c: Coordinate, request: &Request) -> (&'static str, f64) {
        if c.is_angle() {
            if request.degrees {
                ("°", 180.0 / std::f64::consts::PI)
            } else {
                ("rad", 1.0)
            }
        } else {
            (request.units.length(), 1.0)
        }
    }

    /// The type of each joint of `joints.csv`: its column `type`, or the
    /// model file's for a file without one.
    fn joint_types(&self, t: &Table) -> Result<BTreeMap<Id, JointType>, HistoryError> {
        let Some(c) = t.find("type") else {
            return Ok(self
                .coordinates
                .as_ref()
                .map(|c| c.joints.clone())
                .unwrap_or_default());
        };
        let id = t.column("joint")?;
        let mut types = BTreeMap::new();
        for r in 0..t.rows.len() {
            let (line, fields) = &t.rows[r];
            let name = &fields[c];
            let kind = JointType::from_name(name).ok_or_else(|| HistoryError::Malformed {
                path: t.path.clone(),
                line: *line,
                message: format!("column `type`: {name:?} is not a joint type"),
            })?;
            types.insert(t.id(r, id)?, kind);
        }
        Ok(types)
    }

    /// One chart per joint and kind of coordinate (angles, lengths): the
    /// columns of `joints.csv` named after its coordinates (`angle`,
    /// `slide`...; [`Coordinate::name`]).
    fn joint_figures(
        &self,
        request: &Request,
        chosen: &dyn Fn(Id) -> bool,
    ) -> Result<Vec<Figure>, HistoryError> {
        let Some(t) = &self.joints else {
            return Ok(Vec::new());
        };
        if t.find("c1").is_some() {
            return Err(HistoryError::Malformed {
                path: t.path.clone(),
                line: 1,
                message: "columns `c1`, `c2`, `c3`: written by an earlier version of unfold, before the coordinate columns were named (`angle`, `slide`...); run the model again".into(),
            });
        }
        // the coordinates that have a column, in the file's order
        let present: Vec<Coordinate> = Coordinate::ALL
            .into_iter()
            .filter(|c| t.find(c.name()).is_some())
            .collect();
        let names: Vec<&str> = present.iter().map(|c| c.name()).collect();
        let histories = t.histories("joint", &names)?;
        let types = self.joint_types(t)?;
        let x = self.time_axis(request.units);
        let mut figures = Vec::new();
        for (id, columns) in histories {
            if !chosen(id) {
                continue;
            }
            let kind = types.get(&id).copied();
            // the joint's coordinates (by place among `present`): those of
            // its type, or those it has values of
            let coords: Vec<usize> = match kind {
                Some(kind) => kind
                    .coordinates()
                    .iter()
                    .map(|c| match present.iter().position(|p| p == c) {
                        Some(k) => Ok(k),
                        None => t.column(c.name()),
                    })
                    .collect::<Result<_, _>>()?,
                None => (0..present.len())
                    .filter(|&k| has_values(&columns[k]))
                    .collect(),
            };
            let (angles, lengths): (Vec<usize>, Vec<usize>) =
                coords.into_iter().partition(|&k| present[k].is_angle());
            let split = !angles.is_empty() && !lengths.is_empty();
            for (part, members) in [("angles", angles), ("lengths", lengths)] {
                if members.is_empty() {
                    continue;
                }
                let first = present[members[0]];
                let (unit, factor) = Self::coordinate_unit(first, request);
                let quantity = if first.is_angle() {
                    "angle"
                } else {
                    "displacement"
                };
                let what: Vec<&str> = members.iter().map(|&k| names[k]).collect();
                let title = match kind {
                    Some(kind) => format!("Joint {id} ({}): {}", kind.name(), what.join(", ")),
                    None => format!("Joint {id}: {}", what.join(", ")),
                };
                let mut chart = Chart::new(title, x.clone(), Axis::new(quantity, unit));
                for &k in &members {
                    let points = columns[k].iter().map(|&(t, v)| (t, v * factor));
                    chart = chart.series(Series::new(names[k], points));
                }
                let name = if split {
                    format!("joint_{id}_{part}")
                } else {
                    format!("joint_{id}")
                };
                figures.push(Figure {
                    name,
                    chart: self.with_events(chart, Some(id), request.units),
                });
            }
        }
        Ok(figures)
    }

    /// One chart per joint of the moments (or forces) along its
    /// coordinates; all of them on one chart when the joints are unknown.
    fn moment_figures(
        &self,
        request: &Request,
        chosen: &dyn Fn(Id) -> bool,
    ) -> Result<Vec<Figure>, HistoryError> {
        // the files of loads along joint coordinates: (table, its name in
        // `Coordinates::acting`, id column, [(column, legend)], and the
        // sign that turns the file's value into the load on the joint's
        // second body, positive in the sense of increasing coordinate:
        // springs, dampers and hinge laws are written positive resisting
        // an increase (they apply −f on the second body), latch and driver
        // loads positive pushing the coordinate up (docs/results.md))
        type Source<'t> = (&'t Option<Table>, &'static str, &'static str, Legends, f64);
        type Legends = &'static [(&'static str, &'static str)];
        let sources: [Source; 4] = [
            (
                &self.joint_springs,
                "joint_springs",
                "element",
                &[("spring", "spring"), ("damper", "damper")],
                -1.0,
            ),
            (
                &self.hinge_laws,
                "hinge_laws",
                "element",
                &[("moment", "hinge law")],
                -1.0,
            ),
            (&self.latches, "latches", "latch", &[("load", "latch")], 1.0),
            (
                &self.drivers,
                "drivers",
                "driver",
                &[("load", "driver")],
                1.0,
            ),
        ];
        // series by joint and by kind of coordinate (angle or not): None
        // when unknown
        let mut charts: BTreeMap<(Option<Id>, bool), Vec<Series>> = BTreeMap::new();
        for (table, file, id_column, columns, sign) in sources {
            let Some(t) = table else { continue };
            let cols: Vec<&str> = columns.iter().map(|c| c.0).collect();
            for (id, histories) in t.histories(id_column, &cols)? {
                let acting = self
                    .coordinates
                    .as_ref()
                    .and_then(|c| c.acting.get(&(file, id)))
                    .copied();
                if let Some((joint, _)) = acting {
                    if !chosen(joint) {
                        continue;
                    }
                } else if file == "drivers" && self.coordinates.is_some() {
                    // a driver of a node, not of a joint coordinate
                    continue;
                }
                let key = (acting.map(|a| a.0), acting.is_none_or(|a| a.1.is_angle()));
                for ((_, legend), points) in columns.iter().zip(histories) {
                    // a damper that never acts is left out
                    if !has_values(&points)
                        || (*legend == "damper" && points.iter().all(|p| p.1 == 0.0))
                    {
                        continue;
                    }
                    let coordinate = acting.map_or(String::new(), |a| format!(", {}", a.1.name()));
                    charts.entry(key).or_default().push(Series::new(
                        format!("{legend} {id}{coordinate}"),
                        points.into_iter().map(|(t, v)| (t, sign * v)),
                    ));
                }
            }
        }
        let x = self.time_axis(request.units);
        let split = |joint: Option<Id>| {
            charts.contains_key(&(joint, true)) && charts.contains_key(&(joint, false))
        };
        let mut figures = Vec::new();
        for (&(joint, angle), series) in &charts {
            let known = self.coordinates.is_some();
            let (quantity, unit) = match (known, angle) {
                (false, _) => (
                    "moment or force",
                    format!("{} or {}", request.units.moment(), request.units.force()),
                ),
                (true, true) => ("moment", request.units.moment().to_string()),
                (true, false) => ("force", request.units.force().to_string()),
            };
            let (title, mut name) = match joint {
                Some(j) => (
                    format!("Joint {j}: {quantity}s on its second body, + increasing c"),
                    format!("moments_joint_{j}"),
                ),
                None => (
                    "Loads on the joints' second bodies, + increasing c".into(),
                    "moments".into(),
                ),
            };
            if split(joint) {
                name += if angle { "_moments" } else { "_forces" };
            }
            let mut chart = Chart::new(title, x.clone(), Axis::new(quantity, unit));
            for s in series {
                chart = chart.series(s.clone());
            }
            figures.push(Figure {
                name,
                chart: self.with_events(chart, joint, request.units),
            });
        }
        Ok(figures)
    }

    /// One chart per hinge law: its moment `M` (positive resisting an
    /// increase of the coordinate, as in `hinge_laws.csv`) against its
    /// coordinate, the hysteresis loop, with the work `∫ M dc` over the
    /// run (trapezoidal rule on the output steps: the energy the law
    /// dissipated, over closed cycles) in the legend and the locking value
    /// of each latch on the same coordinate as a vertical line.
    fn hinge_law_figures(
        &self,
        request: &Request,
        chosen: &dyn Fn(Id) -> bool,
    ) -> Result<Vec<Figure>, HistoryError> {
        let Some(t) = &self.hinge_laws else {
            return Ok(Vec::new());
        };
        let mut figures = Vec::new();
        for (id, mut columns) in t.histories("element", &["coordinate", "moment"])? {
            let moment = columns.pop().unwrap_or_default();
            let coordinate = columns.pop().unwrap_or_default();
            let acting = self
                .coordinates
                .as_ref()
                .and_then(|c| c.acting.get(&("hinge_laws", id)))
                .copied();
            if acting.is_some_and(|a| !chosen(a.0)) {
                continue;
            }
            // (c, M) at each output step
            let loop_points: Vec<(f64, f64)> = coordinate
                .iter()
                .zip(&moment)
                .map(|(c, m)| (c.1, m.1))
                .collect();
            if !has_values(&loop_points) {
                continue;
            }
            let work: f64 = loop_points
                .windows(2)
                .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
                .filter(|w| w.is_finite())
                .sum();
            let angle = acting.is_none_or(|a| a.1.is_angle());
            let (x_axis, factor, y_axis, energy) = match acting {
                Some((_, c)) => {
                    let (unit, factor) = Self::coordinate_unit(c, request);
                    let (quantity, y) = if c.is_angle() {
                        ("angle", Axis::new("moment M", request.units.moment()))
                    } else {
                        ("displacement", Axis::new("force F", request.units.force()))
                    };
                    (
                        Axis::new(
                            if c.name() == quantity {
                                quantity.to_string()
                            } else {
                                format!("{quantity} {}", c.name())
                            },
                            unit,
                        ),
                        factor,
                        y,
                        request.units.energy(),
                    )
                }
                None => (
                    Axis::new("coordinate", format!("rad or {}", request.units.length())),
                    1.0,
                    Axis::new(
                        "moment or force",
                        format!("{} or {}", request.units.moment(), request.units.force()),
                    ),
                    request.units.energy(),
                ),
            };
            let title = match acting {
                Some((joint, c)) => format!(
                    "Hinge law {id} on joint {joint}: {} against {}, + resisting an increase",
                    if angle { "moment" } else { "force" },
                    c.name()
                ),
                None => format!("Hinge law {id}: moment against coordinate"),
            };
            let mut chart = Chart::new(title, x_axis, y_axis).series(Series::new(
                format!("hinge law {id}, ∫ M dc = {} {energy}", significant(work)),
                loop_points.iter().map(|&(c, m)| (c * factor, m)),
            ));
            // the locking values of the latches on this coordinate
            if let (Some((joint, c)), Some(coords)) = (acting, &self.coordinates) {
                for (&latch, &value) in &coords.latch_values {
                    if coords.acting.get(&("latches", latch)) == Some(&(joint, c)) {
                        let shown = value * factor;
                        let unit = chart.x.unit.clone();
                        chart = chart.event(
                            shown,
                            format!("latch {latch} locks at {} {unit}", significant(shown)),
                        );
                    }
                }
            }
            figures.push(Figure {
                name: format!("hinge_law_{id}"),
                chart,
            });
        }
        Ok(figures)
    }

    /// The energies, and the balance error on a chart of its own.
    fn energy_figures(&self, request: &Request) -> Result<Vec<Figure>, HistoryError> {
        let Some(t) = &self.energies else {
            return Ok(Vec::new());
        };
        let columns = [
            ("kinetic", "kinetic T"),
            ("strain", "strain"),
            ("gravity", "gravity"),
            ("spring", "springs"),
            ("external_work", "external work W"),
            ("dissipated", "dissipated D"),
            ("hinge_law_work", "hinge-law work W_h"),
        ];
        // the hinge-law work is absent from the files of earlier versions
        let columns: Vec<_> = columns
            .into_iter()
            .filter(|c| c.0 != "hinge_law_work" || t.find(c.0).is_some())
            .collect();
        let names: Vec<&str> = columns.iter().map(|c| c.0).collect();
        let time = t.column("time")?;
        let cols: Vec<usize> = names
            .iter()
            .map(|c| t.column(c))
            .collect::<Result<_, _>>()?;
        let balance = t.column("balance_error")?;
        let mut histories = vec![Vec::with_capacity(t.rows.len()); cols.len()];
        let mut error = Vec::with_capacity(t.rows.len());
        for r in 0..t.rows.len() {
            let at = t.number(r, time)?;
            for (k, &c) in cols.iter().enumerate() {
                histories[k].push((at, t.number(r, c)?));
            }
            error.push((at, t.number(r, balance)?));
        }
        let x = self.time_axis(request.units);
        let energy = request.units.energy();
        let mut chart = Chart::new("Energies", x.clone(), Axis::new("energy", energy));
        // a form of energy the model does not have (zero throughout, or
        // round-off: below 1e-9 of the largest energy) is left out; the
        // kinetic energy is always shown
        let largest = histories
            .iter()
            .flatten()
            .map(|p| p.1.abs())
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        for ((_, legend), points) in columns.iter().zip(histories) {
            let negligible = |v: f64| !v.is_finite() || v.abs() <= 1e-9 * largest;
            if *legend != "kinetic T" && points.iter().all(|p| negligible(p.1)) {
                continue;
            }
            chart = chart.series(Series::new(*legend, points));
        }
        let mut figures = vec![Figure {
            name: "energies".into(),
            chart: self.with_events(chart, None, request.units),
        }];
        if has_values(&error) {
            let chart = Chart::new(
                "Energy balance error E = (T + V) − (T₀ + V₀) − W − W_h + D",
                x,
                Axis::new("E", energy),
            )
            .series(Series::new("balance error E", error));
            figures.push(Figure {
                name: "energy_balance_error".into(),
                chart: self.with_events(chart, None, request.units),
            });
        }
        Ok(figures)
    }

    /// Writes `figures` into `out` (created if missing) as
    /// `<name>.png` and/or `<name>.svg`; returns the files written.
    pub fn write(
        figures: &[Figure],
        out: &Path,
        format: Format,
    ) -> Result<Vec<PathBuf>, HistoryError> {
        std::fs::create_dir_all(out).map_err(|source| HistoryError::Write {
            path: out.to_path_buf(),
            source,
        })?;
        let mut written = Vec::new();
        for f in figures {
            if matches!(format, Format::Png | Format::Both) {
                let path = out.join(format!("{}.png", f.name));
                f.chart.write_png(&path)?;
                written.push(path);
            }
            if matches!(format, Format::Svg | Format::Both) {
                let path = out.join(format!("{}.svg", f.name));
                f.chart.write_svg(&path)?;
                written.push(path);
            }
        }
        Ok(written)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energies_are_labelled_to_four_digits() {
        assert_eq!(significant(2.25), "2.25");
        assert_eq!(significant(235.6161), "235.6");
        assert_eq!(significant(-0.0123456), "-0.01235");
        assert_eq!(significant(12000.0), "12000");
        assert_eq!(significant(0.0), "0");
        assert_eq!(significant(1.5e-6), "1.500e-6");
    }

    #[test]
    fn malformed_rows_are_named_by_line() {
        let dir = std::env::temp_dir().join(format!("unfold-histories-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        std::fs::write(&path, "step,time,joint,angle\n0,0,1,0.5\n\n1,0.1,1,abc\n").unwrap();
        let t = Table::read(&path).unwrap().unwrap();
        let e = t.histories("joint", &["angle"]).unwrap_err().to_string();
        assert!(
            e.ends_with("t.csv, line 4: column `angle`: \"abc\" is not a number"),
            "{e}"
        );
        std::fs::write(&path, "step,time\n0,0,3\n").unwrap();
        let e = Table::read(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("t.csv, line 2: 3 fields, but the header names 2 columns"),
            "{e}"
        );
        std::fs::write(&path, "").unwrap();
        let e = Table::read(&path).unwrap_err().to_string();
        assert!(e.contains("line 1: empty file"), "{e}");
        assert!(Table::read(&dir.join("absent.csv")).unwrap().is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
