//! Result files of modal analyses (docs/results.md, "Modes"):
//! - `modes.csv`: one line per mode of every modal analysis of the run
//!   (frequency in Hz, `ω` in rad/s, `ω²`, generalised mass, effective
//!   masses, whether it is a zero mode, residual);
//! - `mode_shapes.csv`: per mode and node, the six components of the
//!   mass-normalised shape (global frame);
//! - per modal analysis, a grid per mode, `vtk/mode_NNNN.vtu` (the first
//!   modal analysis of the run) or `vtk/mode_K_NNNN.vtu` (the K-th), at
//!   the state it linearised about, with the shape as the point vectors
//!   `mode_displacement` and `mode_rotation`, scaled to a largest nodal
//!   translation of 1 (model length units); and the collection
//!   `modes.pvd` (`modes_K.pvd`), whose "time" is the mode number, for
//!   ParaView.
//!
//! The CSV files are rewritten whole (atomically) after each modal
//! analysis, so they always hold the modes of every modal analysis run so
//! far.

use std::fmt::Write as _;
use std::io;
use std::path::Path;

use serde::Serialize;

use super::results::file_error;
use super::vtk::{self, Encoding, ModeField};
use crate::analysis::{ModalOutcome, NaturalMode};
use crate::eigen::Method;
use crate::elements::Need;
use crate::model::Model;
use crate::so3::Vec3;

/// Header of `modes.csv`.
pub const MODES_HEADER: &str = "analysis,mode,frequency_hz,omega_rad_s,omega_squared,generalized_mass,effective_mass_x,effective_mass_y,effective_mass_z,zero_mode,residual";

/// Header of `mode_shapes.csv`.
pub const SHAPES_HEADER: &str = "analysis,mode,node,ux,uy,uz,rx,ry,rz";

/// What a modal analysis found, for `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ModalRecord {
    /// Its place in the run's sequence of analyses (from 1).
    pub analysis: usize,
    /// `t` of the state it linearised about.
    pub time: f64,
    /// Eigen-solver used (`dense`, `lanczos`).
    pub solver: &'static str,
    /// Free unknowns, multipliers included.
    pub unknowns: usize,
    /// Independent constraint equations.
    pub constraints: usize,
    /// Rigid-body and mechanism modes among the modes.
    pub zero_modes: usize,
    /// Frequencies of the modes, Hz.
    pub frequencies_hz: Vec<f64>,
    /// Wall-clock time, seconds.
    pub wall_time_s: f64,
    /// Why it failed, if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

impl ModalRecord {
    /// The record of `outcome`, the `analysis`-th analysis of the run.
    pub fn of(analysis: usize, outcome: &ModalOutcome) -> Self {
        Self {
            analysis,
            time: outcome.time,
            solver: solver_name(outcome.method),
            unknowns: outcome.unknowns,
            constraints: outcome.constraints,
            zero_modes: outcome.zero_modes,
            frequencies_hz: outcome.modes.iter().map(|m| m.frequency).collect(),
            wall_time_s: outcome.wall_time,
            error: outcome.error.as_ref().map(|e| e.to_string()),
        }
    }
}

/// The name of a solver in the model file and the results.
pub fn solver_name(method: Method) -> &'static str {
    match method {
        Method::Auto => "auto",
        Method::Dense => "dense",
        Method::Lanczos => "lanczos",
    }
}

/// Whether `name` (in `dir`) is a file of modal results that a new run
/// replaces: `modes.csv`, `mode_shapes.csv`, `modes*.pvd` and their
/// temporary files.
pub fn is_modal_file(name: &str) -> bool {
    let name = name.strip_suffix(".tmp").unwrap_or(name);
    matches!(name, "modes.csv" | "mode_shapes.csv")
        || (name.starts_with("modes") && name.ends_with(".pvd"))
}

/// Whether `name` (in `dir/vtk`) is the grid of a mode, or its temporary
/// file.
pub fn is_mode_grid(name: &str) -> bool {
    name.starts_with("mode_") && (name.ends_with(".vtu") || name.ends_with(".tmp"))
}

/// Removes the modal results of an earlier run from `dir` (the directory
/// is locked by the caller).
pub fn remove_leftovers(dir: &Path) -> io::Result<()> {
    for (folder, matches) in [
        (dir.to_path_buf(), is_modal_file as fn(&str) -> bool),
        (dir.join("vtk"), is_mode_grid),
    ] {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        for entry in entries {
            let path = entry.map_err(|e| file_error(&folder, e))?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if matches(name) {
                match std::fs::remove_file(&path) {
                    Err(e) if e.kind() != io::ErrorKind::NotFound => {
                        return Err(file_error(&path, e))
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(())
}

/// The modal result files of a run, kept in memory and rewritten after
/// each modal analysis.
#[derive(Debug, Default)]
pub struct ModalFiles {
    modes: String,
    shapes: String,
    /// Modal analyses written so far.
    runs: usize,
}

impl ModalFiles {
    /// Writes the files of `outcome`, the `analysis`-th analysis of the
    /// run, into `dir`. Every error names its file.
    pub fn write(
        &mut self,
        dir: &Path,
        model: &Model,
        analysis: usize,
        outcome: &ModalOutcome,
        encoding: Encoding,
    ) -> io::Result<()> {
        self.runs += 1;
        if self.modes.is_empty() {
            self.modes = format!("{MODES_HEADER}\n");
            self.shapes = format!("{SHAPES_HEADER}\n");
        }
        let mut order: Vec<usize> = (0..model.n_nodes()).collect();
        order.sort_by_key(|&i| model.node_ids[i]);
        for (k, mode) in outcome.modes.iter().enumerate() {
            let [ex, ey, ez] = mode.effective_mass;
            let _ = writeln!(
                self.modes,
                "{analysis},{},{:e},{:e},{:e},{:e},{ex:e},{ey:e},{ez:e},{},{:e}",
                k + 1,
                mode.frequency,
                mode.angular_frequency,
                mode.omega_squared,
                mode.generalized_mass,
                u8::from(mode.is_zero()),
                mode.residual
            );
            for &i in &order {
                let s = &mode.shape[i];
                let _ = writeln!(
                    self.shapes,
                    "{analysis},{},{},{:e},{:e},{:e},{:e},{:e},{:e}",
                    k + 1,
                    model.node_ids[i],
                    s[0],
                    s[1],
                    s[2],
                    s[3],
                    s[4],
                    s[5]
                );
            }
        }
        vtk::write_atomically(&dir.join("modes.csv"), self.modes.as_bytes())?;
        vtk::write_atomically(&dir.join("mode_shapes.csv"), self.shapes.as_bytes())?;

        // a grid per mode and their collection
        let (prefix, collection) = if self.runs == 1 {
            ("mode_".to_string(), "modes.pvd".to_string())
        } else {
            (
                format!("mode_{}_", self.runs),
                format!("modes_{}.pvd", self.runs),
            )
        };
        let ctx = model.context(outcome.time, Need::RESIDUAL);
        let mut entries = Vec::with_capacity(outcome.modes.len());
        for (k, mode) in outcome.modes.iter().enumerate() {
            let name = format!("{prefix}{:04}.vtu", k + 1);
            let (translation, rotation) = unit_shape(mode);
            let scale = mode.generalized_mass.sqrt();
            let coordinates: Vec<f64> = mode.coordinates.iter().map(|c| c * scale).collect();
            let field = ModeField {
                translation: &translation,
                rotation: &rotation,
                coordinates: &coordinates,
            };
            vtk::write_mode_vtu(
                &dir.join("vtk").join(&name),
                model,
                &ctx,
                &outcome.state,
                encoding,
                field,
            )?;
            entries.push(((k + 1) as f64, format!("vtk/{name}")));
        }
        vtk::write_pvd(&dir.join(collection), &entries)
    }
}

/// The shape of `mode` scaled to a largest nodal translation of 1 (a
/// largest rotation of 1 without translation): the mass-normalised shape
/// times `√generalized_mass`.
fn unit_shape(mode: &NaturalMode) -> (Vec<Vec3>, Vec<Vec3>) {
    let scale = mode.generalized_mass.sqrt();
    mode.shape
        .iter()
        .map(|s| {
            (
                Vec3::new(s[0], s[1], s[2]) * scale,
                Vec3::new(s[3], s[4], s[5]) * scale,
            )
        })
        .unzip()
}
