//! Result files of a run (docs/results.md):
//! - `nodes.csv`: position, displacement and orientation of every node at
//!   every output step;
//! - `beams.csv`: section forces and moments of every beam;
//! - `springs.csv`: force and deformation of every spring;
//! - `reactions.csv`: support reactions (forces and moments, global frame);
//! - `joints.csv`: relative coordinates of every joint and the load it
//!   applies to its first body, in the joint axes;
//! - `drivers.csv`: driven coordinate, its target and the actuator load;
//! - `joint_springs.csv`: coordinate, rate and force of joint springs and
//!   dampers;
//! - `steps.csv`: one line per output step (increment, load parameter,
//!   iterations, final relative residual);
//! - `vtk/step_NNNNN.vtu` and `unfold.pvd`: the configurations for ParaView;
//! - `summary.json`: size of the model, counts, wall time and status,
//!   written at the end (also after a failure).
//!
//! Each step is appended and flushed as soon as it converges, so a run that
//! stops early keeps everything written before.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::vtk;
use crate::analysis::{IncrementInfo, Observer};
use crate::elements::ElementKind;
use crate::model::Model;
use crate::so3::{self, Vec3};
use crate::state::State;

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

/// Final report of a run, written as `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Model file.
    pub model: String,
    /// Model title.
    pub title: String,
    /// `"completed"` or `"failed"`.
    pub status: String,
    /// Error message when failed.
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
    /// Free unknowns (equations).
    pub dofs: usize,
    /// Non-zeros of the system matrix.
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
    /// Every converged increment.
    pub increment_log: Vec<IncrementRecord>,
}

/// Writes result files as the analysis converges.
pub struct ResultWriter {
    dir: PathBuf,
    nodes: BufWriter<File>,
    beams: Option<BufWriter<File>>,
    springs: Option<BufWriter<File>>,
    joints: Option<BufWriter<File>>,
    drivers: Option<BufWriter<File>>,
    joint_springs: Option<BufWriter<File>>,
    reactions: Option<BufWriter<File>>,
    steps: BufWriter<File>,
    pvd: Vec<(f64, String)>,
    /// Supported nodes (index), for reactions.
    supported: Vec<usize>,
    /// Every converged increment, for the summary.
    pub log: Vec<IncrementRecord>,
}

fn csv(path: &Path, header: &str) -> std::io::Result<BufWriter<File>> {
    let mut w = BufWriter::new(File::create(path)?);
    writeln!(w, "{header}")?;
    Ok(w)
}

impl ResultWriter {
    /// Creates `dir` (and `dir/vtk`) and the CSV files with their headers.
    /// Grids left in `dir/vtk` by an earlier run are removed, so that the
    /// directory holds one run only.
    pub fn create(dir: &Path, model: &Model) -> std::io::Result<Self> {
        let vtk_dir = dir.join("vtk");
        std::fs::create_dir_all(&vtk_dir)?;
        for entry in std::fs::read_dir(&vtk_dir)? {
            let path = entry?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if name.starts_with("step_") && name.ends_with(".vtu") {
                std::fs::remove_file(&path)?;
            }
        }
        let _ = std::fs::remove_file(dir.join("summary.json"));
        let has = |k: ElementKind| model.elements.iter().any(|e| e.kind() == k);
        let supported: Vec<usize> = (0..model.n_nodes())
            .filter(|&i| model.fixed[i].iter().any(|&f| f))
            .collect();
        Ok(Self {
            dir: dir.to_path_buf(),
            nodes: csv(
                &dir.join("nodes.csv"),
                "step,time,node,x,y,z,ux,uy,uz,qw,qx,qy,qz",
            )?,
            beams: has(ElementKind::Beam)
                .then(|| csv(&dir.join("beams.csv"), "step,time,element,N,V2,V3,T,M2,M3"))
                .transpose()?,
            springs: has(ElementKind::Spring)
                .then(|| {
                    csv(
                        &dir.join("springs.csv"),
                        "step,time,element,F1,F2,F3,D1,D2,D3",
                    )
                })
                .transpose()?,
            joints: has(ElementKind::Joint)
                .then(|| {
                    csv(
                        &dir.join("joints.csv"),
                        "step,time,joint,c1,c2,c3,F1,F2,F3,M1,M2,M3",
                    )
                })
                .transpose()?,
            drivers: has(ElementKind::Driver)
                .then(|| {
                    csv(
                        &dir.join("drivers.csv"),
                        "step,time,driver,coordinate,target,load",
                    )
                })
                .transpose()?,
            joint_springs: has(ElementKind::JointSpring)
                .then(|| {
                    csv(
                        &dir.join("joint_springs.csv"),
                        "step,time,element,coordinate,rate,spring,damper",
                    )
                })
                .transpose()?,
            reactions: (!supported.is_empty())
                .then(|| {
                    csv(
                        &dir.join("reactions.csv"),
                        "step,time,node,Fx,Fy,Fz,Mx,My,Mz",
                    )
                })
                .transpose()?,
            steps: csv(
                &dir.join("steps.csv"),
                "step,increment,time,step_size,iterations,relative_residual",
            )?,
            pvd: Vec::new(),
            supported,
            log: Vec::new(),
        })
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Number of output steps written.
    pub fn output_steps(&self) -> usize {
        self.pvd.len()
    }

    /// Writes `summary.json`.
    pub fn write_summary(&self, summary: &Summary) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(summary).map_err(std::io::Error::other)?;
        std::fs::write(self.dir.join("summary.json"), text + "\n")
    }

    fn write_step(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        residual: &[f64],
    ) -> std::io::Result<()> {
        let step = self.pvd.len();
        let t = info.time;
        for i in 0..model.n_nodes() {
            let x = state.x[i];
            let u = x - model.reference_x[i];
            let q = state.q[i].quaternion();
            writeln!(
                self.nodes,
                "{step},{t:.12e},{},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.15e},{:.15e},{:.15e},{:.15e}",
                model.node_ids[i], x.x, x.y, x.z, u.x, u.y, u.z, q.w, q.i, q.j, q.k
            )?;
        }
        let ctx = model.context(t, false);
        let mut values = [0.0; 9];
        for e in &model.elements {
            let file = match e.kind() {
                ElementKind::Beam => self.beams.as_mut(),
                ElementKind::Spring => self.springs.as_mut(),
                ElementKind::Joint => self.joints.as_mut(),
                ElementKind::Driver => self.drivers.as_mut(),
                ElementKind::JointSpring => self.joint_springs.as_mut(),
                _ => None,
            };
            if let Some(w) = file {
                let n = e.result_names().len();
                e.results(&ctx, state, &mut values[..n]);
                write!(w, "{step},{t:.12e},{}", e.id())?;
                for v in &values[..n] {
                    // absent quantities (a joint with fewer coordinates) are empty
                    if v.is_nan() {
                        write!(w, ",")?;
                    } else {
                        write!(w, ",{v:.9e}")?;
                    }
                }
                writeln!(w)?;
            }
        }
        if let Some(w) = self.reactions.as_mut() {
            for &i in &self.supported {
                let f = Vec3::new(residual[6 * i], residual[6 * i + 1], residual[6 * i + 2]);
                // the rotational residual is conjugate to material rotations
                let m_mat = Vec3::new(
                    residual[6 * i + 3],
                    residual[6 * i + 4],
                    residual[6 * i + 5],
                );
                let m = so3::matrix(&state.q[i]) * m_mat;
                writeln!(
                    w,
                    "{step},{t:.12e},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e}",
                    model.node_ids[i], f.x, f.y, f.z, m.x, m.y, m.z
                )?;
            }
        }
        writeln!(
            self.steps,
            "{step},{},{t:.12e},{:.6e},{},{:.3e}",
            info.increment,
            info.step,
            info.iterations,
            info.residuals.last().copied().unwrap_or(0.0)
        )?;
        for w in [
            Some(&mut self.nodes),
            Some(&mut self.steps),
            self.beams.as_mut(),
            self.springs.as_mut(),
            self.joints.as_mut(),
            self.drivers.as_mut(),
            self.joint_springs.as_mut(),
            self.reactions.as_mut(),
        ]
        .into_iter()
        .flatten()
        {
            w.flush()?;
        }
        let name = format!("step_{step:05}.vtu");
        vtk::write_vtu(&self.dir.join("vtk").join(&name), model, &ctx, state)?;
        self.pvd.push((t, format!("vtk/{name}")));
        vtk::write_pvd(&self.dir.join("unfold.pvd"), &self.pvd)
    }
}

impl Observer for ResultWriter {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        reactions: &[f64],
    ) -> std::io::Result<()> {
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
