//! `unfold view`: one self-contained HTML page that animates a run in 3-D
//! in a web browser (docs/viewer.md).
//!
//! The page is made from the files of a results directory:
//! - the grids of `unfold.pvd` (`vtk/step_NNNNN.vtu`, [`grid`]): the
//!   points of every output step, the cells (beams and links drawn as
//!   tubes, joint markers as spheres, the rigid bodies' shapes, panels
//!   and other quadrilaterals, polygons and hexahedra as surfaces), and
//!   the scalar fields to colour them by: every floating-point cell or
//!   point array (vectors by their length, `rotation` as the angle turned)
//!   that is not zero throughout, and the joint force and moment of
//!   `joints.csv` on the joints' markers and links;
//! - the histories of the CSV files ([`DEFAULT_HISTORIES`]), one series per
//!   entity and column, for the time-history plot;
//! - `events.csv` (locks, impacts, releases) for the marks on the time line,
//!   and `summary.json` for the title and status.
//!
//! Frames and series are quantised and compressed ([`pack`]); the
//! JavaScript libraries the page needs (three.js, uPlot, in
//! `assets/viewer/vendor` with their licences) are embedded, compressed,
//! with the page's own script and style (`assets/viewer`), so that it
//! works offline.

pub mod grid;
pub mod pack;

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde_json::{json, Value};

use super::histories::{HistoryError, Table};
use super::vtk::KIND_LINK;
use crate::elements::ElementKind;
use grid::{Grid, Section};
use pack::{code, range, Blob};

/// The CSV histories a page holds by default (those the run wrote): the
/// files of one row per step and per joint-like entity. `nodes.csv`,
/// `nodes_velocities.csv` and `beams.csv` are left out: their values are
/// the grids' points and colours already, and they are the largest files.
pub const DEFAULT_HISTORIES: [&str; 12] = [
    "energies.csv",
    "steps.csv",
    "joints.csv",
    "drivers.csv",
    "joint_springs.csv",
    "hinge_laws.csv",
    "latches.csv",
    "stops.csv",
    "contacts.csv",
    "springs.csv",
    "rolling.csv",
    "reactions.csv",
];

/// Frames of a page by default, at most: a longer run is shown at evenly
/// spaced output steps (and at every step of an event).
pub const MAX_FRAMES: usize = 2000;

/// The id columns of the history files, after `time`.
const ID_COLUMNS: [&str; 7] = [
    "node", "element", "joint", "driver", "latch", "stop", "contact",
];

/// The page template and what it embeds.
const TEMPLATE: &str = include_str!("../../../assets/viewer/viewer.html");
const SCRIPT: &str = include_str!("../../../assets/viewer/viewer.js");
const STYLE: &str = include_str!("../../../assets/viewer/viewer.css");
const THREE: &str = include_str!("../../../assets/viewer/vendor/three.min.js");
const THREE_LICENSE: &str = include_str!("../../../assets/viewer/vendor/three.LICENSE");
const UPLOT: &str = include_str!("../../../assets/viewer/vendor/uPlot.iife.min.js");
const UPLOT_STYLE: &str = include_str!("../../../assets/viewer/vendor/uPlot.min.css");
const UPLOT_LICENSE: &str = include_str!("../../../assets/viewer/vendor/uPlot.LICENSE");

/// What `unfold view` is asked for.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// The history files to embed (`joints.csv`, or `joints`), every CSV
    /// file of the directory for `all`; empty for [`DEFAULT_HISTORIES`].
    pub histories: Vec<String>,
    /// At most this many frames ([`MAX_FRAMES`] by default).
    pub max_frames: usize,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self {
            histories: Vec::new(),
            max_frames: MAX_FRAMES,
        }
    }
}

/// What a page holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewReport {
    /// Output steps of the run.
    pub steps: usize,
    /// Frames of the page.
    pub frames: usize,
    /// Points and cells of each frame.
    pub points: usize,
    /// Cells of each frame.
    pub cells: usize,
    /// Colour fields.
    pub fields: Vec<String>,
    /// History series.
    pub series: usize,
    /// Events on the time line.
    pub events: usize,
    /// Size of the page, bytes.
    pub bytes: usize,
    /// Size of its data before compression, bytes.
    pub raw_data_bytes: usize,
    /// What the user should know (cells not drawn, frames left out).
    pub notes: Vec<String>,
}

/// Why a page could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// The directory does not exist.
    #[error("{0}: no such directory; give the results directory of a run (`unfold run MODEL --out DIR`, then `unfold view DIR`)")]
    NoDirectory(PathBuf),
    /// A file was given.
    #[error("{path}: is a file, not a results directory{hint}")]
    NotADirectory {
        /// The file.
        path: PathBuf,
        /// What to do instead.
        hint: String,
    },
    /// The directory holds no grids of a run.
    #[error("{path}: not a results directory of `unfold run`: {reason}")]
    NotResults {
        /// The directory.
        path: PathBuf,
        /// What is missing.
        reason: String,
    },
    /// A history asked for is not there.
    #[error("{path}: no such history file (the histories of this run: {known})")]
    NoHistory {
        /// The file looked for.
        path: PathBuf,
        /// The CSV files there.
        known: String,
    },
    /// A file is not as `unfold run` writes it.
    #[error("{path}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A CSV file could not be read.
    #[error(transparent)]
    History(#[from] HistoryError),
    /// The page could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The page.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
}

impl ViewError {
    /// Whether the error is in what was given (exit code 2), not in
    /// writing the page (exit code 1).
    pub fn is_input(&self) -> bool {
        !matches!(self, Self::Write { .. })
    }
}

/// Makes the page of the results in `dir` and writes it to `out`.
pub fn write_view(dir: &Path, out: &Path, options: &ViewOptions) -> Result<ViewReport, ViewError> {
    let (html, mut report) = page(dir, options)?;
    super::vtk::write_atomically(out, html.as_bytes()).map_err(|source| ViewError::Write {
        path: out.to_path_buf(),
        source,
    })?;
    report.bytes = html.len();
    Ok(report)
}

/// The page of the results in `dir`, and what it holds.
pub fn page(dir: &Path, options: &ViewOptions) -> Result<(String, ViewReport), ViewError> {
    let collection = results_collection(dir)?;
    let steps = read_collection(&collection)?;
    let summary = read_summary(dir)?;
    let events = read_events(dir)?;
    let mut report = ViewReport {
        steps: steps.len(),
        ..ViewReport::default()
    };

    // the frames: evenly spaced steps, and the step of every event
    let mut chosen: Vec<usize> = if steps.len() <= options.max_frames.max(2) {
        (0..steps.len()).collect()
    } else {
        let n = options.max_frames.max(2);
        (0..n)
            .map(|k| k * (steps.len() - 1) / (n - 1))
            .chain(events.iter().filter_map(|e| e.step))
            .filter(|&s| s < steps.len())
            .collect()
    };
    chosen.sort_unstable();
    chosen.dedup();
    if chosen.len() < steps.len() {
        report.notes.push(format!(
            "{} of the {} output steps are frames of the page (--max-frames {}, and the steps of the events)",
            chosen.len(),
            steps.len(),
            options.max_frames
        ));
    }

    // the grids, read in parallel
    let grids: Vec<Grid> = chosen
        .par_iter()
        .map(|&s| read_grid(&steps[s].1))
        .collect::<Result<_, _>>()?;
    let frames = Frames::new(&grids, &chosen, &steps)?;
    drop(grids);
    report.frames = frames.steps.len();
    report.points = frames.points;
    report.cells = frames.types.len();

    let mut blob = Blob::default();
    let mut fields = frames.fields;
    if let Some(joints) = Table::read(&dir.join("joints.csv"))? {
        fields.extend(joint_load_fields(
            &joints,
            &chosen,
            &frames.kind,
            &frames.element_id,
        )?);
    }
    let field_values: Vec<Value> = fields
        .iter()
        .map(|f| {
            report.fields.push(f.name.clone());
            f.pack(&mut blob)
        })
        .collect();
    let histories = histories(dir, &options.histories, steps.len(), &mut blob)?;
    report.series = histories.1;
    report.events = events.len();
    for (t, n) in &frames.skipped {
        report.notes.push(format!(
            "{n} cells of VTK type {t} are not drawn (the page draws vertices, lines, triangles, quadrilaterals, polygons and hexahedra)"
        ));
    }

    let kinds: BTreeMap<String, &str> = ElementKind::ALL
        .into_iter()
        .map(|k| (k.code().to_string(), k.name()))
        .chain(std::iter::once((KIND_LINK.to_string(), "rigid link")))
        .collect();
    let dynamic = summary
        .get("analyses")
        .and_then(Value::as_array)
        .is_some_and(|a| a.iter().any(|x| x["type"] == "dynamic"));
    let manifest = json!({
        "format": "unfold view",
        "version": 1,
        "generator": concat!("unfold ", env!("CARGO_PKG_VERSION")),
        "title": summary.get("title").cloned().unwrap_or(Value::Null),
        "model": summary.get("model").cloned().unwrap_or(Value::Null),
        "status": summary.get("status").cloned().unwrap_or(Value::Null),
        "message": summary.get("message").cloned().unwrap_or(Value::Null),
        "directory": dir.display().to_string(),
        "time_name": if dynamic { "time" } else { "load parameter" },
        "steps": steps.iter().map(|s| s.0).collect::<Vec<_>>(),
        "frames": {
            "steps": chosen,
            "times": chosen.iter().map(|&s| steps[s].0).collect::<Vec<_>>(),
        },
        "points": {
            "count": frames.points,
            "lo": frames.lo,
            "hi": frames.hi,
            "positions": blob.frames(&frames.positions, 3 * frames.points.max(1)),
        },
        "cells": {
            "count": frames.types.len(),
            "types": blob.bytes(&frames.types),
            "offsets": blob.i32s(&frames.offsets),
            "connectivity": blob.i32s(&frames.connectivity),
            "kind": blob.i32s(&frames.kind),
            "element_id": blob.f64s(&frames.element_id),
        },
        "kinds": kinds,
        "fields": field_values,
        "histories": histories.0,
        "events": events.iter().map(Event::to_json).collect::<Vec<_>>(),
    });
    report.raw_data_bytes = blob.len();
    let data = blob.finish();

    let title = summary
        .get("title")
        .and_then(Value::as_str)
        .map_or_else(|| dir.display().to_string(), str::to_string);
    let html = fill(
        TEMPLATE,
        &[
            ("TITLE", &escape_html(&title)),
            ("STYLE", &format!("{UPLOT_STYLE}\n{STYLE}")),
            ("LICENCES", &licences()),
            ("LIBRARIES", &libraries()),
            ("MANIFEST", &script_json(&manifest)),
            ("DATA", &data),
            ("SCRIPT", SCRIPT),
        ],
    );
    Ok((html, report))
}

/// `unfold.pvd` of `dir`, with an error that says what `dir` is if it is
/// not a results directory.
fn results_collection(dir: &Path) -> Result<PathBuf, ViewError> {
    if dir.is_file() {
        let is_model = dir.extension().is_some_and(|e| e == "toml");
        let hint = if is_model {
            let stem = dir
                .file_stem()
                .map_or("model".into(), |s| s.to_string_lossy().into_owned());
            format!(
                ": run the model first (`unfold run {}`) and view its results (`unfold view results/{stem}`)",
                dir.display()
            )
        } else {
            ": give the directory `unfold run MODEL --out DIR` wrote".to_string()
        };
        return Err(ViewError::NotADirectory {
            path: dir.to_path_buf(),
            hint,
        });
    }
    if !dir.is_dir() {
        return Err(ViewError::NoDirectory(dir.to_path_buf()));
    }
    let pvd = dir.join("unfold.pvd");
    if pvd.is_file() {
        return Ok(pvd);
    }
    let not = |reason: String| ViewError::NotResults {
        path: dir.to_path_buf(),
        reason,
    };
    let summary = dir.join("summary.json");
    if let Ok(text) = std::fs::read_to_string(&summary) {
        let s: Value = serde_json::from_str(&text).unwrap_or(Value::Null);
        let status = s["status"].as_str().unwrap_or("unknown");
        let message = s["message"]
            .as_str()
            .map_or(String::new(), |m| format!(": {m}"));
        let modes = if dir.join("modes.pvd").is_file() {
            " (its modes.pvd holds the modes of a modal analysis, for ParaView)"
        } else {
            ""
        };
        return Err(not(format!(
            "the run wrote no output step (no unfold.pvd{modes}); summary.json says status \"{status}\"{message}"
        )));
    }
    Err(not(
        "it has neither unfold.pvd nor summary.json; give the directory `unfold run MODEL --out DIR` wrote"
            .into(),
    ))
}

/// The `(time, grid file)` of each output step of a collection file.
fn read_collection(pvd: &Path) -> Result<Vec<(f64, PathBuf)>, ViewError> {
    let text = std::fs::read_to_string(pvd).map_err(|e| ViewError::Malformed {
        path: pvd.to_path_buf(),
        message: e.to_string(),
    })?;
    let malformed = |message: String| ViewError::Malformed {
        path: pvd.to_path_buf(),
        message,
    };
    let base = pvd.parent().unwrap_or(Path::new("."));
    let mut steps = Vec::new();
    for (at, _) in text.match_indices("<DataSet") {
        let tag = &text[at..at + text[at..].find('>').unwrap_or(text.len() - at)];
        let time = grid::attribute(tag, "timestep")
            .and_then(|t| t.parse::<f64>().ok())
            .ok_or_else(|| malformed(format!("a DataSet without a timestep: {tag}")))?;
        let file = grid::attribute(tag, "file")
            .ok_or_else(|| malformed(format!("a DataSet without a file: {tag}")))?;
        steps.push((time, base.join(file)));
    }
    if steps.is_empty() {
        return Err(malformed("the collection lists no grid".into()));
    }
    Ok(steps)
}

/// Reads a grid, with an error naming it.
fn read_grid(path: &Path) -> Result<Grid, ViewError> {
    let malformed = |message: String| ViewError::Malformed {
        path: path.to_path_buf(),
        message,
    };
    let bytes = std::fs::read(path).map_err(|e| malformed(e.to_string()))?;
    Grid::parse(&bytes).map_err(malformed)
}

/// `summary.json`, or an empty object when there is none.
fn read_summary(dir: &Path) -> Result<serde_json::Map<String, Value>, ViewError> {
    let path = dir.join("summary.json");
    match std::fs::read_to_string(&path) {
        Ok(text) => match serde_json::from_str(&text) {
            Ok(Value::Object(m)) => Ok(m),
            Ok(_) => Err(ViewError::Malformed {
                path,
                message: "not a JSON object".into(),
            }),
            Err(e) => Err(ViewError::Malformed {
                path,
                message: e.to_string(),
            }),
        },
        Err(_) => Ok(serde_json::Map::new()),
    }
}

/// A row of `events.csv`.
#[derive(Clone, Debug, PartialEq)]
struct Event {
    time: f64,
    step: Option<usize>,
    kind: String,
    element: Option<u64>,
    joint: Option<u64>,
    /// What the element is (`latch`, `stop`, `contact`), if its file says.
    owner: Option<&'static str>,
}

impl Event {
    /// Its description: `latch 98: lock of joint 96`.
    fn label(&self) -> String {
        let mut label = match (self.owner, self.element) {
            (Some(o), Some(e)) => format!("{o} {e}: {}", self.kind),
            (None, Some(e)) => format!("element {e}: {}", self.kind),
            _ => self.kind.clone(),
        };
        if let Some(j) = self.joint {
            let _ = write!(label, " of joint {j}");
        }
        label
    }

    fn to_json(&self) -> Value {
        let label = self.label();
        json!({
            "time": self.time,
            "step": self.step,
            "kind": self.kind,
            "element": self.element,
            "joint": self.joint,
            "label": label,
        })
    }
}

/// The rows of `events.csv` (none without the file), each with what its
/// element is (from the ids of `latches.csv`, `stops.csv` and
/// `contacts.csv`).
fn read_events(dir: &Path) -> Result<Vec<Event>, ViewError> {
    let Some(table) = Table::read(&dir.join("events.csv"))? else {
        return Ok(Vec::new());
    };
    let mut owners: HashMap<u64, &'static str> = HashMap::new();
    for (file, column) in [
        ("latches.csv", "latch"),
        ("stops.csv", "stop"),
        ("contacts.csv", "contact"),
    ] {
        if let Some(t) = Table::read(&dir.join(file))? {
            if let Some(c) = t.find(column) {
                for r in 0..t.rows.len() {
                    owners.insert(t.id(r, c)?, column);
                }
            }
        }
    }
    let time = table.column("time")?;
    let kind = table.column("kind")?;
    let (step, element, joint) = (
        table.find("step"),
        table.find("element"),
        table.find("joint"),
    );
    let id = |r: usize, c: Option<usize>| -> Result<Option<u64>, ViewError> {
        match c {
            Some(c) if !table.rows[r].1[c].is_empty() => Ok(Some(table.id(r, c)?)),
            _ => Ok(None),
        }
    };
    (0..table.rows.len())
        .map(|r| {
            Ok(Event {
                time: table.number(r, time)?,
                step: id(r, step)?.map(|s| s as usize),
                kind: table.rows[r].1[kind].clone(),
                element: id(r, element)?,
                joint: id(r, joint)?,
                owner: id(r, element)?.and_then(|e| owners.get(&e).copied()),
            })
        })
        .collect()
}

/// A colour field: one value per point or cell at each frame.
struct Field {
    name: String,
    /// On the cells (else the points).
    cells: bool,
    /// Values, frame after frame (NaN where the field has no value).
    values: Vec<f64>,
    /// Width of a frame.
    width: usize,
    /// Cells (or points) that carry the field; all if `None`.
    mask: Option<Vec<u8>>,
    /// Where it comes from, for the page.
    source: String,
}

impl Field {
    /// The field's range, codes and mask in `blob`; its description.
    fn pack(&self, blob: &mut Blob) -> Value {
        let (lo, hi) = range(self.values.iter().copied()).unwrap_or((0.0, 0.0));
        let codes: Vec<u16> = self.values.iter().map(|&v| code(v, lo, hi)).collect();
        json!({
            "name": self.name,
            "on": if self.cells { "cells" } else { "points" },
            "min": lo,
            "max": hi,
            "source": self.source,
            "values": blob.frames(&codes, self.width.max(1)),
            "mask": self.mask.as_ref().map(|m| blob.bytes(m)),
        })
    }
}

/// The frames of a page: topology (the same at every step), positions
/// quantised, and the colour fields of the grids.
struct Frames {
    steps: Vec<usize>,
    points: usize,
    lo: [f64; 3],
    hi: [f64; 3],
    positions: Vec<u16>,
    types: Vec<u8>,
    offsets: Vec<i32>,
    connectivity: Vec<i32>,
    kind: Vec<i32>,
    element_id: Vec<f64>,
    fields: Vec<Field>,
    /// VTK types of cells not drawn, and their number.
    skipped: Vec<(u8, usize)>,
}

/// VTK cell types the page draws: vertex, line, triangle, polygon, quad,
/// hexahedron.
const DRAWN: [u8; 6] = [1, 3, 5, 7, 9, 12];

impl Frames {
    fn new(grids: &[Grid], chosen: &[usize], steps: &[(f64, PathBuf)]) -> Result<Self, ViewError> {
        let first = &grids[0];
        let path = |k: usize| steps[chosen[k]].1.clone();
        let malformed = |k: usize, message: String| ViewError::Malformed {
            path: path(k),
            message,
        };
        let topology = |g: &Grid, name: &str| -> Result<Vec<f64>, String> {
            let a = g
                .array(Section::Topology, name)
                .or_else(|| g.array(Section::Cells, name))
                .ok_or_else(|| format!("no {name} array"))?;
            Ok(a.values.clone())
        };
        let (points, cells) = (first.points, first.cells);
        let topo = ["connectivity", "offsets", "types", "kind", "element_id"]
            .map(|n| topology(first, n).map_err(|m| malformed(0, m)));
        let [connectivity, offsets, types, kind, element_id] = topo;
        let (connectivity, offsets, types, kind, element_id) =
            (connectivity?, offsets?, types?, kind?, element_id?);
        if offsets.len() != cells || types.len() != cells {
            return Err(malformed(
                0,
                "the cell arrays do not have a value per cell".into(),
            ));
        }
        if connectivity.iter().any(|&p| p < 0.0 || p >= points as f64) {
            return Err(malformed(
                0,
                "a cell refers to a point the grid does not have".into(),
            ));
        }
        let mut skipped: BTreeMap<u8, usize> = BTreeMap::new();
        for &t in &types {
            if !DRAWN.contains(&(t as u8)) {
                *skipped.entry(t as u8).or_default() += 1;
            }
        }

        // the scalars of the first grid's floating-point arrays: a
        // vector's length, `rotation` as the angle turned; not the axes
        let mut names: Vec<(Section, String, usize)> = Vec::new();
        for a in &first.arrays {
            if !a.float || !matches!(a.section, Section::Points | Section::Cells) {
                continue;
            }
            if a.name.starts_with("axis_") || a.name.starts_with("mode_") {
                continue;
            }
            names.push((a.section, a.name.clone(), a.components));
        }
        let width = |s: Section| if s == Section::Cells { cells } else { points };

        // every frame: positions and scalars, the same topology
        let mut positions = Vec::with_capacity(grids.len() * 3 * points);
        let mut scalars: Vec<Vec<f64>> = names
            .iter()
            .map(|(s, _, _)| Vec::with_capacity(grids.len() * width(*s)))
            .collect();
        for (k, g) in grids.iter().enumerate() {
            if (g.points, g.cells) != (points, cells)
                || k > 0
                    && (topology(g, "connectivity").ok() != Some(connectivity.clone())
                        || topology(g, "types").ok() != Some(types.clone()))
            {
                return Err(malformed(
                    k,
                    format!(
                        "its cells are not those of {} (the page draws one mesh)",
                        path(0).display()
                    ),
                ));
            }
            let p = g
                .require(Section::Geometry, "position")
                .or_else(|_| {
                    g.arrays
                        .iter()
                        .find(|a| a.section == Section::Geometry)
                        .ok_or("no points".to_string())
                })
                .map_err(|m| malformed(k, m))?;
            positions.extend_from_slice(&p.values);
            for ((section, name, components), out) in names.iter().zip(&mut scalars) {
                let a = g
                    .require(*section, name)
                    .map_err(|m| malformed(k, format!("{m}, which the first grid has")))?;
                if a.components != *components {
                    return Err(malformed(
                        k,
                        format!("{name:?}: {} components", a.components),
                    ));
                }
                out.extend(a.values.chunks_exact(*components).map(|c| match c {
                    [v] => *v,
                    _ => c.iter().map(|v| v * v).sum::<f64>().sqrt(),
                }));
            }
        }

        // positions quantised in the box of every frame
        let mut lo = [0.0; 3];
        let mut hi = [0.0; 3];
        for c in 0..3 {
            let (l, h) = range(positions.iter().skip(c).step_by(3).copied()).unwrap_or((0.0, 0.0));
            lo[c] = l;
            hi[c] = h;
        }
        let positions = positions
            .iter()
            .enumerate()
            .map(|(i, &v)| code(v, lo[i % 3], hi[i % 3]))
            .collect();

        // fields: those not zero throughout; a cell field on the cells of
        // the kinds that have a value somewhere (a beam with no moment is
        // coloured by its zero, a joint marker is not)
        let mut fields = Vec::new();
        for ((section, name, components), values) in names.into_iter().zip(scalars) {
            if values.iter().all(|&v| v == 0.0 || !v.is_finite()) {
                continue;
            }
            let cells_field = section == Section::Cells;
            let mask = cells_field.then(|| {
                let mut carried: Vec<i64> = Vec::new();
                for (i, &v) in values.iter().enumerate() {
                    let c = i % cells;
                    if v != 0.0 && !carried.contains(&(kind[c] as i64)) {
                        carried.push(kind[c] as i64);
                    }
                }
                kind.iter()
                    .map(|&k| u8::from(carried.contains(&(k as i64))))
                    .collect::<Vec<u8>>()
            });
            let (label, how) = match (components, name.as_str()) {
                (1, _) => (name.clone(), "value"),
                (3, "rotation") => (
                    "rotation angle".to_string(),
                    "length of the rotation vector",
                ),
                (_, _) => (format!("|{name}|"), "length of the vector"),
            };
            let kind_of = if cells_field { "cell" } else { "point" };
            fields.push(Field {
                name: label,
                cells: cells_field,
                width: width(section),
                values,
                mask,
                source: format!("{kind_of} data {name} of the grids ({how})"),
            });
        }
        Ok(Self {
            steps: chosen.to_vec(),
            points,
            lo,
            hi,
            positions,
            types: types.iter().map(|&t| t as u8).collect(),
            offsets: offsets.iter().map(|&o| o as i32).collect(),
            connectivity: connectivity.iter().map(|&p| p as i32).collect(),
            kind: kind.iter().map(|&k| k as i32).collect(),
            element_id,
            fields,
            skipped: skipped.into_iter().collect(),
        })
    }
}

/// The force and moment each joint carries (`joints.csv`, the lengths of
/// `Fx, Fy, Fz` and `Mx, My, Mz`), on its marker and links.
fn joint_load_fields(
    joints: &Table,
    chosen: &[usize],
    kind: &[i32],
    element_id: &[f64],
) -> Result<Vec<Field>, ViewError> {
    let (Some(step), Some(id)) = (joints.find("step"), joints.find("joint")) else {
        return Ok(Vec::new());
    };
    let columns = |names: [&str; 3]| names.map(|n| joints.find(n));
    let groups = [
        ("joint force |F|", columns(["Fx", "Fy", "Fz"])),
        ("joint moment |M|", columns(["Mx", "My", "Mz"])),
    ];
    let frame_of: HashMap<usize, usize> = chosen.iter().enumerate().map(|(f, &s)| (s, f)).collect();
    // the cells of each joint: its marker and links
    let joint_code = ElementKind::Joint.code();
    let mut cells_of: HashMap<u64, Vec<usize>> = HashMap::new();
    for (c, (&k, &e)) in kind.iter().zip(element_id).enumerate() {
        if k == joint_code || k == KIND_LINK {
            cells_of.entry(e as u64).or_default().push(c);
        }
    }
    let n = kind.len();
    let mut fields = Vec::new();
    for (name, cols) in groups {
        let [Some(x), Some(y), Some(z)] = cols else {
            continue;
        };
        let mut values = vec![f64::NAN; chosen.len() * n];
        let mut mask = vec![0u8; n];
        for r in 0..joints.rows.len() {
            let s = joints.id(r, step)? as usize;
            let Some(&f) = frame_of.get(&s) else {
                continue;
            };
            let Some(cells) = cells_of.get(&joints.id(r, id)?) else {
                continue;
            };
            let v = [x, y, z]
                .iter()
                .map(|&c| joints.number(r, c).map(|v| v * v))
                .sum::<Result<f64, _>>()?
                .sqrt();
            for &c in cells {
                values[f * n + c] = v;
                mask[c] = 1;
            }
        }
        if values.iter().all(|v| !v.is_finite() || *v == 0.0) {
            continue;
        }
        fields.push(Field {
            name: name.to_string(),
            cells: true,
            values,
            width: n,
            mask: Some(mask),
            source: format!(
                "joints.csv, length of ({}) in the global axes, on each joint's marker and links",
                if name.contains('F') {
                    "Fx, Fy, Fz"
                } else {
                    "Mx, My, Mz"
                }
            ),
        });
    }
    Ok(fields)
}

/// The history series of the CSV files `asked` (or the defaults) in
/// `dir`, packed in `blob`: their description and number.
fn histories(
    dir: &Path,
    asked: &[String],
    n_steps: usize,
    blob: &mut Blob,
) -> Result<(Value, usize), ViewError> {
    let csv_files = || -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| e.file_name().into_string().ok())
            .filter(|n| n.ends_with(".csv") && n != "events.csv")
            .collect();
        names.sort();
        names
    };
    let files: Vec<(String, bool)> = if asked.is_empty() {
        DEFAULT_HISTORIES
            .iter()
            .map(|f| (f.to_string(), false))
            .collect()
    } else if asked.iter().any(|a| a == "all") {
        csv_files().into_iter().map(|f| (f, false)).collect()
    } else {
        asked
            .iter()
            .map(|a| {
                let f = if a.ends_with(".csv") {
                    a.clone()
                } else {
                    format!("{a}.csv")
                };
                (f, true)
            })
            .collect()
    };
    let mut out = Vec::new();
    let mut count = 0;
    for (file, required) in files {
        let path = dir.join(&file);
        let Some(table) = Table::read(&path)? else {
            if required {
                return Err(ViewError::NoHistory {
                    path,
                    known: csv_files().join(", "),
                });
            }
            continue;
        };
        let (Some(step), Some(time)) = (table.find("step"), table.find("time")) else {
            continue;
        };
        let entity = table
            .header
            .get(time + 1)
            .filter(|h| ID_COLUMNS.contains(&h.as_str()))
            .map(|_| time + 1);
        // a column of text, a joint's `type`, says what the entity is
        let label = entity.and_then(|_| table.find("type"));
        let skip = |c: usize| {
            c == step
                || c == time
                || Some(c) == entity
                || Some(c) == label
                || table.header[c] == "increment"
        };
        let columns: Vec<usize> = (0..table.header.len()).filter(|&c| !skip(c)).collect();
        // values[entity][column][step], and the entity's type
        let mut series: BTreeMap<u64, (Option<&str>, Vec<Vec<f64>>)> = BTreeMap::new();
        for r in 0..table.rows.len() {
            let s = table.id(r, step)? as usize;
            if s >= n_steps {
                continue;
            }
            let e = match entity {
                Some(c) => table.id(r, c)?,
                None => 0,
            };
            let entry = series.entry(e).or_insert_with(|| {
                let kind = label.map(|c| table.rows[r].1[c].as_str());
                (kind, vec![vec![f64::NAN; n_steps]; columns.len()])
            });
            for (k, &c) in columns.iter().enumerate() {
                entry.1[k][s] = table.number(r, c)?;
            }
        }
        let mut entities = Vec::new();
        for (e, (kind, values)) in series {
            let mut list = Vec::new();
            for (k, v) in values.iter().enumerate() {
                let Some((lo, hi)) = range(v.iter().copied()) else {
                    continue;
                };
                // a positive series over many decades (step sizes,
                // residuals) is kept as its logarithm
                let log = lo > 0.0 && hi > 1e3 * lo;
                let (codes, lo, hi): (Vec<u16>, f64, f64) = if log {
                    let (l, h) = (lo.log10(), hi.log10());
                    (v.iter().map(|&x| code(x.log10(), l, h)).collect(), l, h)
                } else {
                    (v.iter().map(|&x| code(x, lo, hi)).collect(), lo, hi)
                };
                list.push(json!({
                    "column": table.header[columns[k]],
                    "min": lo,
                    "max": hi,
                    "log": log,
                    "values": blob.frames(&codes, n_steps),
                }));
                count += 1;
            }
            if !list.is_empty() {
                entities.push(json!({ "id": entity.map(|_| e), "type": kind, "series": list }));
            }
        }
        if !entities.is_empty() {
            out.push(json!({
                "file": file,
                "entity": entity.map(|c| table.header[c].clone()),
                "entities": entities,
            }));
        }
    }
    Ok((Value::Array(out), count))
}

/// `template` with each `{{KEY}}` replaced by its value; what is put in is
/// not searched again.
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out =
        String::with_capacity(template.len() + values.iter().map(|v| v.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some(at) = rest.find("{{") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        match after.find("}}").and_then(|end| {
            let key = &after[..end];
            values
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, v)| (end, *v))
        }) {
            Some((end, value)) => {
                out.push_str(value);
                rest = &after[end + 2..];
            }
            None => {
                out.push_str("{{");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// `text` for an HTML element's content.
fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// JSON for a `<script type="application/json">` element: `<` escaped, so
/// that no string in it closes the element.
fn script_json(value: &Value) -> String {
    value.to_string().replace('<', "\\u003c")
}

/// The notices of the embedded libraries, as their licences ask.
fn licences() -> String {
    let clean = |t: &str| t.replace("--", "- -");
    format!(
        "<!--\nThis page embeds, compressed:\n\nthree.js r187 (https://threejs.org), bundled from the npm package three 0.187.0:\n\n{}\n\nuPlot 1.6.32 (https://github.com/leeoniya/uPlot):\n\n{}\n-->",
        clean(THREE_LICENSE),
        clean(UPLOT_LICENSE)
    )
}

/// The libraries as compressed base64 scripts, which the page's script
/// inflates and runs in order.
fn libraries() -> String {
    [("three", THREE), ("uPlot", UPLOT)]
        .iter()
        .map(|(name, code)| {
            format!(
                "<script type=\"application/octet-stream\" data-library=\"{name}\">{}</script>",
                pack::deflate_base64(code.as_bytes())
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_replaces_known_keys_once() {
        let t = "a {{X}} b {{Y}} {{unknown}} {{X";
        assert_eq!(
            fill(t, &[("X", "{{Y}}"), ("Y", "2")]),
            "a {{Y}} b 2 {{unknown}} {{X"
        );
        assert_eq!(
            script_json(&json!({"a": "</script>"})),
            "{\"a\":\"\\u003c/script>\"}"
        );
    }
}
