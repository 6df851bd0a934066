//! Newton–Raphson on the nodes' configuration manifold: the solver shared
//! by every analysis.
//!
//! One iteration (docs/theory.md §7):
//! 1. assemble `r(q)` and `K = ∂r/∂q` at the current state;
//! 2. stop if the residual and the last correction are small (below);
//! 3. solve `K Δq = −r` with the sparse LU, whose symbolic analysis is
//!    computed once and reused;
//! 4. update translations additively and rotations multiplicatively,
//!    `x ← x + Δx`, `R ← R exp(ΔΘ~)`.
//!
//! Convergence requires both
//! - **residual**: for forces and for moments separately,
//!   `‖r‖₂ ≤ ε_r · ‖flux‖₂`, where the flux `Σₑ|rₑ|` measures the forces
//!   flowing through each dof (reactions included), or `‖r‖₂ ≤ 10⁻¹²·k·L`,
//!   the round-off floor of a structure of stiffness `k = max Kᵢᵢ` and size
//!   `L`;
//! - **constraints**: the equations of extra unknowns (the constraints of
//!   joints) hold to `ε_u · L`;
//! - **correction**: `max|Δx| ≤ ε_u · L` and `max|ΔΘ| ≤ ε_θ` for the next
//!   correction, estimated from the last one times the residual ratio,
//!   `|Δq_{k+1}| ≈ |Δq_k| ‖r_k‖/‖r_{k−1}‖` (exact in the quadratic regime;
//!   this saves the extra iteration that would only confirm convergence).
//!
//! The very first solve of a model always makes one correction, even from
//! equilibrium, so that a singular tangent (a mechanism, a missing support)
//! is found before the analysis starts.

use super::constraints::{self, ConstraintRank};
use super::{IterationInfo, Observer};
use crate::assembly::Assembler;
use crate::dofs::{DofKind, DofMap, NO_EQUATION};
use crate::elements::ExtraKind;
use crate::linalg::{smallest_relative_pivot, SolveError, SparseLu};
use crate::model::{Model, StaticSettings, COMPONENT_NAMES};
use crate::so3::{self, Vec3};
use crate::state::State;

/// A relative pivot below this marks the tangent as singular (round-off of
/// an exactly singular matrix is ~1e-16; a stiff but sound structure is far
/// above).
const SINGULAR_PIVOT: f64 = 1e-11;

/// Corrections larger than this (times the model size, or in radians)
/// mean the tangent is singular or nearly so.
const RUNAWAY_CORRECTION: f64 = 1e6;

/// The round-off floor of the residual, relative to `k·L`.
const RESIDUAL_FLOOR: f64 = 1e-12;

/// A residual grown by this factor over the force flux of the first
/// iteration is divergence. (The first corrections of a stiff beam may
/// legitimately raise the residual by 1e3–1e4: stretching from a linear
/// prediction of large rotations.)
const DIVERGED_GROWTH: f64 = 1e8;

/// Norms of one Newton iteration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ConvergenceNorms {
    /// `‖r‖₂` over free translation equations.
    pub residual_force: f64,
    /// `‖r‖₂` over free rotation equations.
    pub residual_moment: f64,
    /// `‖flux‖₂` over all translation dofs.
    pub flux_force: f64,
    /// `‖flux‖₂` over all rotation dofs.
    pub flux_moment: f64,
    /// `max(‖r_F‖/ref_F, ‖r_M‖/ref_M)` with `ref = max(‖flux‖, floor/ε_r)`:
    /// the residual criterion holds when this is at most `ε_r`.
    pub relative_residual: f64,
    /// Largest constraint violation relative to its tolerance (`ε_u·L`
    /// for distances, `ε_θ` for angles); the constraints hold when it is at
    /// most 1. Zero without constraints.
    pub residual_constraint: f64,
    /// `max|Δx|` of the last correction (0 before the first).
    pub displacement_correction: f64,
    /// `max|ΔΘ|` of the last correction (0 before the first).
    pub rotation_correction: f64,
}

/// Why Newton iterations stopped without converging.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NewtonFailure {
    /// The iteration limit was reached.
    #[error(
        "no convergence in {iterations} iterations (relative residual {relative_residual:.3e})"
    )]
    MaxIterations {
        /// Iterations done.
        iterations: usize,
        /// Last relative residual.
        relative_residual: f64,
    },
    /// The residual grew beyond any hope.
    #[error("diverging at iteration {iteration}: the residual grew by more than 1e8 (relative residual {relative_residual:.3e})")]
    Diverging {
        /// Iteration at which divergence was detected.
        iteration: usize,
        /// Relative residual then.
        relative_residual: f64,
    },
    /// NaN or infinite values appeared.
    #[error("non-finite values at iteration {iteration}")]
    NonFinite {
        /// Iteration at which they appeared.
        iteration: usize,
    },
    /// Arc-length control: the constraint on the arc length has no real
    /// root (the arc is too long for the curvature of the path).
    #[error("arc-length constraint without a real root at iteration {iteration}")]
    NoArcRoot {
        /// Iteration.
        iteration: usize,
    },
    /// The tangent is singular.
    #[error("singular tangent: no stiffness for {dof} (relative pivot {pivot:.1e}); the structure is a mechanism or is not restrained there")]
    Singular {
        /// The unknown without stiffness, e.g. `node 5 rz`.
        dof: String,
        /// Relative pivot size.
        pivot: f64,
    },
}

impl NewtonFailure {
    /// Iterations spent before the failure.
    pub fn iterations_spent(&self) -> usize {
        match self {
            Self::MaxIterations { iterations, .. } => *iterations,
            Self::Diverging { iteration, .. }
            | Self::NonFinite { iteration }
            | Self::NoArcRoot { iteration } => *iteration,
            Self::Singular { .. } => 0,
        }
    }
}

/// A converged Newton solve.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonResult {
    /// Corrections applied.
    pub iterations: usize,
    /// Relative residual at each evaluation.
    pub residuals: Vec<f64>,
}

/// Newton–Raphson solver: dof numbering, assembly storage, sparse LU and
/// work vectors, all allocated once.
pub struct NewtonSolver {
    /// Numbering of the free unknowns.
    pub dofs: DofMap,
    assembler: Assembler,
    lu: Option<SparseLu>,
    rhs: Vec<f64>,
    /// `max Kᵢᵢ` over translation and rotation equations, from the first
    /// tangent (sets the residual floor).
    stiffness_scale: Option<(f64, f64)>,
    /// Whether a tangent has been factored and solved once: until then a
    /// solve always makes one correction, even from equilibrium, so that a
    /// singular model (a mechanism) is caught at the start.
    tangent_checked: bool,
    /// What each extra unknown is (multiplier or coordinate).
    extra_kinds: Vec<ExtraKind>,
    /// Multipliers of redundant constraints, left out of the system.
    redundant: Vec<usize>,
}

impl NewtonSolver {
    /// Prepares numbering, pattern and buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let dofs = DofMap::new(model);
        let assembler = Assembler::new(model, &dofs);
        let n = dofs.n_equations();
        let ctx = model.context(0.0, false);
        let extra_kinds = model
            .elements
            .iter()
            .flat_map(|e| (0..e.n_extra()).map(move |k| (e, k)))
            .map(|(e, k)| e.extra_kind(&ctx, k))
            .collect();
        Self {
            dofs,
            assembler,
            lu: None,
            rhs: vec![0.0; n],
            stiffness_scale: None,
            tangent_checked: false,
            extra_kinds,
            redundant: Vec::new(),
        }
    }

    /// Whether each equation is a multiplier's.
    fn multiplier_equations(&self) -> Vec<bool> {
        let first_extra = self.dofs.n_dofs() - self.extra_kinds.len();
        (0..self.dofs.n_equations())
            .map(|eq| {
                let d = self.dofs.dof(eq);
                d >= first_extra
                    && matches!(
                        self.extra_kinds[d - first_extra],
                        ExtraKind::Multiplier { .. }
                    )
            })
            .collect()
    }

    /// Rank analysis of the constraints at `state` (docs/joints.md §5):
    /// redundant constraints are removed from the numbering (their
    /// multipliers stay zero) and the free motions are counted.
    pub fn constraint_rank(&mut self, model: &Model, state: &State) -> ConstraintRank {
        self.assemble(model, state, state.time, true);
        let rank = constraints::analyse(
            &self.dofs,
            &self.assembler.matrix,
            &self.multiplier_equations(),
        );
        self.redundant.clone_from(&rank.redundant);
        if !rank.redundant.is_empty() {
            self.dofs = DofMap::with_suppressed(model, &rank.redundant);
            self.assembler = Assembler::new(model, &self.dofs);
            self.lu = None;
            self.rhs = vec![0.0; self.dofs.n_equations()];
            self.stiffness_scale = None;
        }
        rank
    }

    /// Residual at every dof after the last evaluation: at fixed dofs, the
    /// reactions of the supports (`r = f_int − f_ext` there).
    pub fn residual(&self) -> &[f64] {
        &self.assembler.residual
    }

    /// Number of stored entries of the system matrix.
    pub fn nnz(&self) -> usize {
        self.assembler.matrix.nnz()
    }

    /// Describes a dof for messages: `node 5 rz`, `spring 3 unknown 1`.
    pub fn dof_label(&self, model: &Model, dof: usize) -> String {
        match self.dofs.node_component(dof) {
            Some((node, c)) => format!("node {} {}", model.node_ids[node], COMPONENT_NAMES[c]),
            None => {
                // find the element owning the extra unknown
                let mut k = dof - 6 * model.n_nodes();
                for e in &model.elements {
                    if k < e.n_extra() {
                        return format!("{} {} unknown {}", e.kind().name(), e.id(), k + 1);
                    }
                    k -= e.n_extra();
                }
                format!("dof {dof}")
            }
        }
    }

    /// Assembles residual (and tangent if asked) at `state` and `time`.
    pub fn assemble(&mut self, model: &Model, state: &State, time: f64, need_tangent: bool) {
        let ctx = model.context(time, need_tangent);
        self.assembler.assemble(model, &ctx, state);
    }

    /// The constraint left out as redundant that is violated the most at
    /// `state`, with its violation relative to the tolerance, if above 1:
    /// the constraints then contradict each other (two drivers imposing
    /// incompatible motions) instead of repeating each other.
    pub fn violated_redundant(
        &self,
        model: &Model,
        state: &State,
        settings: &StaticSettings,
    ) -> Option<(String, f64)> {
        if self.redundant.is_empty() {
            return None;
        }
        let ctx = model.context(state.time, false);
        let mut worst: Option<(String, f64)> = None;
        let mut offset = 0;
        for e in &model.elements {
            let ne = e.n_extra();
            let mine: Vec<usize> = self
                .redundant
                .iter()
                .filter(|&&k| k >= offset && k < offset + ne)
                .map(|&k| k - offset)
                .collect();
            if !mine.is_empty() {
                let n = e.n_local();
                let mut r = vec![0.0; n];
                let mut t = Vec::new();
                e.evaluate(
                    &ctx,
                    state,
                    &mut crate::elements::ElementOutput {
                        residual: &mut r,
                        tangent: &mut t,
                    },
                );
                for k in mine {
                    if let ExtraKind::Multiplier { scale, angular } = e.extra_kind(&ctx, k) {
                        let tol = if angular {
                            settings.rotation_tolerance
                        } else {
                            settings.displacement_tolerance * model.length_scale
                        };
                        let v = r[6 * e.nodes().len() + k].abs() / scale / tol;
                        if v > 1.0 && worst.as_ref().is_none_or(|w| v > w.1) {
                            worst = Some((
                                format!("{} {} equation {}", e.kind().name(), e.id(), k + 1),
                                v,
                            ));
                        }
                    }
                }
            }
            offset += ne;
        }
        worst
    }

    /// Residual and flux norms of the last assembly. The relative residual
    /// is measured against `max(flux, floor/ε_r)`, so that it is below
    /// `ε_r` exactly when the residual criterion holds.
    fn norms(&self, floor: (f64, f64), tol: f64, constraint_tol: (f64, f64)) -> ConvergenceNorms {
        let (mut rf, mut rm, mut ff, mut fm, mut rc) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
        let res = &self.assembler.residual;
        let flux = &self.assembler.flux;
        let first_extra = self.dofs.n_dofs() - self.extra_kinds.len();
        for dof in 0..res.len() {
            let free = self.dofs.equation(dof) != NO_EQUATION;
            let r2 = if free { res[dof] * res[dof] } else { 0.0 };
            match self.dofs.kind(dof) {
                DofKind::Translation => {
                    rf += r2;
                    ff += flux[dof] * flux[dof];
                }
                DofKind::Rotation => {
                    rm += r2;
                    fm += flux[dof] * flux[dof];
                }
                DofKind::Extra => match self.extra_kinds[dof - first_extra] {
                    ExtraKind::Multiplier { scale, angular } => {
                        if free {
                            let t = if angular {
                                constraint_tol.1
                            } else {
                                constraint_tol.0
                            };
                            rc = rc.max(res[dof].abs() / scale / t);
                        }
                    }
                    ExtraKind::Coordinate => {
                        rf += r2;
                        ff += flux[dof] * flux[dof];
                    }
                },
            }
        }
        let (rf, rm, ff, fm) = (rf.sqrt(), rm.sqrt(), ff.sqrt(), fm.sqrt());
        let rel = |r: f64, f: f64, floor: f64| {
            if r == 0.0 {
                0.0
            } else {
                r / f.max(floor / tol).max(f64::MIN_POSITIVE)
            }
        };
        ConvergenceNorms {
            residual_force: rf,
            residual_moment: rm,
            flux_force: ff,
            flux_moment: fm,
            relative_residual: rel(rf, ff, floor.0).max(rel(rm, fm, floor.1)),
            residual_constraint: rc,
            displacement_correction: 0.0,
            rotation_correction: 0.0,
        }
    }

    /// Largest diagonal entries of the tangent for translation and rotation
    /// equations.
    fn diagonal_scale(&self) -> (f64, f64) {
        let (mut kf, mut km) = (0.0f64, 0.0f64);
        let m = &self.assembler.matrix;
        for eq in 0..self.dofs.n_equations() {
            let d = m.position(eq, eq).map_or(0.0, |p| m.values()[p].abs());
            match self.dofs.kind(self.dofs.dof(eq)) {
                DofKind::Translation => kf = kf.max(d),
                DofKind::Rotation => km = km.max(d),
                DofKind::Extra => {}
            }
        }
        (kf, km)
    }

    /// One Newton evaluation shared by load and arc-length control:
    /// assembles residual and tangent at `state` and `time`, reports the
    /// iteration and decides whether the iterations have converged
    /// (`Ok(true)`, only if `may_converge`), must go on (`Ok(false)`) or
    /// have failed.
    #[allow(clippy::too_many_arguments)]
    fn assess(
        &mut self,
        model: &Model,
        settings: &StaticSettings,
        state: &State,
        time: f64,
        increment: usize,
        iteration: usize,
        progress: &mut Progress,
        may_converge: bool,
        observer: &mut dyn Observer,
    ) -> Result<bool, NewtonFailure> {
        let length = model.length_scale;
        self.assemble(model, state, time, true);
        if self.stiffness_scale.is_none() {
            self.stiffness_scale = Some(self.diagonal_scale());
        }
        let scale = self.stiffness_scale.expect("set above");
        let tol = settings.residual_tolerance;
        let floor = (RESIDUAL_FLOOR * scale.0 * length, RESIDUAL_FLOOR * scale.1);
        let constraint_tol = (
            settings.displacement_tolerance * length,
            settings.rotation_tolerance,
        );
        let mut norms = self.norms(floor, tol, constraint_tol);
        if let Some((dx, dth)) = progress.last_correction {
            norms.displacement_correction = dx;
            norms.rotation_correction = dth;
        }
        let residuals = &mut progress.residuals;
        residuals.push(norms.relative_residual);
        observer.iteration(&IterationInfo {
            increment,
            iteration,
            time,
            norms,
        });
        if !(norms.residual_force.is_finite() && norms.residual_moment.is_finite()) {
            return Err(NewtonFailure::NonFinite { iteration });
        }

        // convergence: residual, and the next correction estimated as the
        // last one scaled by the residual ratio, |Δq_k+1| ≈ |Δq_k| r_k/r_k-1
        let residual_ok = norms.relative_residual <= tol && norms.residual_constraint <= 1.0;
        let ratio = match residuals.len() {
            n if n >= 2 && residuals[n - 2] > 0.0 => (residuals[n - 1] / residuals[n - 2]).min(1.0),
            _ => 1.0,
        };
        let correction_ok = progress.last_correction.is_none_or(|(dx, dth)| {
            dx * ratio <= settings.displacement_tolerance * length
                && dth * ratio <= settings.rotation_tolerance
        });
        if may_converge && residual_ok && correction_ok {
            return Ok(true);
        }
        if iteration == settings.max_iterations {
            return Err(NewtonFailure::MaxIterations {
                iterations: iteration,
                relative_residual: norms.relative_residual,
            });
        }
        // divergence: forces and moments (over the model size) far beyond
        // those of the first iteration
        let magnitude = norms.residual_force + norms.residual_moment / length;
        let reference = *progress
            .first_flux
            .get_or_insert(norms.flux_force + norms.flux_moment / length);
        let reference = reference.max(floor.0 + floor.1 / length);
        if iteration > 0 && magnitude > DIVERGED_GROWTH * reference {
            return Err(NewtonFailure::Diverging {
                iteration,
                relative_residual: norms.relative_residual,
            });
        }
        Ok(false)
    }

    /// Iterates to equilibrium at load parameter `time`, starting from
    /// `state` (which holds the prescribed values for `time`).
    pub fn solve(
        &mut self,
        model: &Model,
        settings: &StaticSettings,
        state: &mut State,
        time: f64,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Result<NewtonResult, NewtonFailure> {
        let length = model.length_scale;
        let mut progress = Progress::default();
        for iteration in 0..=settings.max_iterations {
            let may_converge = self.tangent_checked;
            if self.assess(
                model,
                settings,
                state,
                time,
                increment,
                iteration,
                &mut progress,
                may_converge,
                observer,
            )? {
                return Ok(NewtonResult {
                    iterations: iteration,
                    residuals: progress.residuals,
                });
            }

            // solve K Δq = −r
            let solved = self.solve_linear_system();
            let (dx, dth) = match solved {
                Ok(()) => correction_size(&self.dofs, &self.rhs),
                Err(_) => (f64::INFINITY, f64::INFINITY),
            };
            if !(dx <= RUNAWAY_CORRECTION * length && dth <= RUNAWAY_CORRECTION) {
                return Err(self.diagnose(model, iteration));
            }

            self.tangent_checked = true;

            // update: x ← x + Δx, R ← R exp(ΔΘ~), extras additively
            self.update(model, state);
            progress.last_correction = Some((dx, dth));
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Weights of the arc-length norm, by equation: `1/L` for
    /// translations, 1 for rotations, 0 for extra unknowns.
    fn arc_weights(&self, length: f64) -> Vec<f64> {
        (0..self.dofs.n_equations())
            .map(|eq| match self.dofs.kind(self.dofs.dof(eq)) {
                DofKind::Translation => 1.0 / length,
                DofKind::Rotation => 1.0,
                DofKind::Extra => 0.0,
            })
            .collect()
    }

    /// `∂r/∂t` by a forward difference of the residual (loads, gravity and
    /// drivers move with `t`), by equation; the residual of the last
    /// assembly at `t` is kept.
    /// `r0` is work space (the residual at `t`, by dof).
    fn load_derivative(
        &mut self,
        model: &Model,
        state: &State,
        t: f64,
        r0: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        let h = 1e-7 * t.abs().max(1.0);
        r0.clone_from(&self.assembler.residual);
        let ctx = model.context(t + h, false);
        self.assembler.assemble(model, &ctx, state);
        for (eq, o) in out.iter_mut().enumerate() {
            let d = self.dofs.dof(eq);
            *o = (self.assembler.residual[d] - r0[d]) / h;
        }
        self.assembler.residual.copy_from_slice(r0);
    }

    /// Weighted length of the tangent predictor `Δt·q_t` at `state`, `t`:
    /// the arc of a first load increment `Δt` (1 if it cannot be
    /// computed; the first increment then cuts back as needed).
    pub fn tangent_arc(&mut self, model: &Model, state: &State, t: f64, dt: f64) -> f64 {
        self.assemble(model, state, t, true);
        let n = self.dofs.n_equations();
        let mut qt = vec![0.0; n];
        self.load_derivative(model, state, t, &mut Vec::new(), &mut qt);
        let w = self.arc_weights(model.length_scale);
        self.rhs.iter_mut().zip(&qt).for_each(|(r, q)| *r = -q);
        let ok = self.analyze().is_ok()
            && self.lu.as_mut().is_some_and(|lu| {
                lu.factor(&self.assembler.matrix).is_ok()
                    && lu.solve_in_place(&mut self.rhs).is_ok()
            });
        let norm: f64 = self
            .rhs
            .iter()
            .zip(&w)
            .map(|(v, w)| (v * w).powi(2))
            .sum::<f64>()
            .sqrt();
        if ok && norm.is_finite() && norm > 0.0 {
            norm * dt
        } else {
            1.0
        }
    }

    /// Arc-length (Crisfield's cylindrical) iterations of one increment
    /// (docs/theory.md §9): the load parameter `t` is an unknown and the
    /// increment `Δq` from the last converged state keeps the weighted
    /// length `‖Δq‖ = arc`. `direction` is the previous increment (by
    /// equation, weighted), used to choose the predictor's sign and the
    /// root of the constraint; it is replaced by this increment.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_arc(
        &mut self,
        model: &Model,
        settings: &StaticSettings,
        state: &mut State,
        t: &mut f64,
        arc: f64,
        direction: &mut Vec<f64>,
        increment: usize,
        observer: &mut dyn Observer,
    ) -> Result<NewtonResult, NewtonFailure> {
        let length = model.length_scale;
        let n = self.dofs.n_equations();
        let w = self.arc_weights(length);
        let wdot = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(&w)
                .map(|((x, y), w)| x * y * w * w)
                .sum()
        };
        let mut dq = vec![0.0; n];
        let mut qt = vec![0.0; n];
        let mut qt_sol = vec![0.0; n];
        let mut r0 = Vec::new();
        let mut progress = Progress::default();
        if direction.len() != n {
            direction.clear();
            direction.resize(n, 0.0);
        }
        for iteration in 0..=settings.max_iterations {
            // the predictor (iteration 0) is never a converged state
            let may_converge = iteration > 0;
            if self.assess(
                model,
                settings,
                state,
                *t,
                increment,
                iteration,
                &mut progress,
                may_converge,
                observer,
            )? {
                direction.copy_from_slice(&dq);
                return Ok(NewtonResult {
                    iterations: iteration,
                    residuals: progress.residuals,
                });
            }

            // q_t: K q_t = −∂r/∂t, and q_r: K q_r = −r, one factorisation
            self.load_derivative(model, state, *t, &mut r0, &mut qt);
            if self.solve_linear_system().is_err() {
                return Err(self.diagnose(model, iteration));
            }
            qt_sol.iter_mut().zip(&qt).for_each(|(x, q)| *x = -q);
            let solved = self
                .lu
                .as_mut()
                .expect("factored above")
                .solve_in_place(&mut qt_sol);
            if solved.is_err() {
                return Err(self.diagnose(model, iteration));
            }
            self.tangent_checked = true;
            let dt = if iteration == 0 {
                // predictor along the tangent, in the direction of the last
                // increment (forward at the first)
                let norm = wdot(&qt_sol, &qt_sol).sqrt();
                if !(norm > 0.0 && norm.is_finite()) {
                    return Err(self.diagnose(model, iteration));
                }
                let sign = if wdot(&qt_sol, direction) < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                self.rhs.iter_mut().for_each(|v| *v = 0.0);
                sign * arc / norm
            } else {
                // ‖a + δt q_t‖ = arc with a = Δq + q_r
                let (dd, dr, rr) = (
                    wdot(&dq, &dq),
                    wdot(&dq, &self.rhs),
                    wdot(&self.rhs, &self.rhs),
                );
                let (dt_, rt, bb) = (
                    wdot(&dq, &qt_sol),
                    wdot(&self.rhs, &qt_sol),
                    wdot(&qt_sol, &qt_sol),
                );
                let (aa, ab) = (dd + 2.0 * dr + rr, dt_ + rt);
                let disc = ab * ab - bb * (aa - arc * arc);
                if disc < 0.0 || bb == 0.0 {
                    return Err(NewtonFailure::NoArcRoot { iteration });
                }
                let roots = [(-ab + disc.sqrt()) / bb, (-ab - disc.sqrt()) / bb];
                // the root whose increment stays closest to the current one:
                // largest (a + δt q_t)·Δq
                let score = |r: f64| dd + dr + r * dt_;
                if score(roots[0]) >= score(roots[1]) {
                    roots[0]
                } else {
                    roots[1]
                }
            };
            for (r, q) in self.rhs.iter_mut().zip(&qt_sol) {
                *r += dt * q;
            }
            *t += dt;
            let (dx, dth) = correction_size(&self.dofs, &self.rhs);
            if !(dx <= RUNAWAY_CORRECTION * length && dth <= RUNAWAY_CORRECTION) {
                return Err(self.diagnose(model, iteration));
            }
            for (d, r) in dq.iter_mut().zip(&self.rhs) {
                *d += r;
            }
            state.time = *t;
            self.update(model, state);
            progress.last_correction = Some((dx, dth));
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Symbolic analysis of the tangent's pattern (done once; later calls
    /// do nothing).
    pub fn analyze(&mut self) -> Result<(), SolveError> {
        if self.lu.is_none() {
            self.lu = Some(SparseLu::analyze(&self.assembler.matrix)?);
        }
        Ok(())
    }

    /// Factors the last assembled tangent and solves `K Δq = −r`; the
    /// correction is then in [`NewtonSolver::correction`].
    pub fn solve_linear_system(&mut self) -> Result<(), SolveError> {
        for (eq, r) in self.rhs.iter_mut().enumerate() {
            *r = -self.assembler.residual[self.dofs.dof(eq)];
        }
        self.analyze()?;
        let lu = self.lu.as_mut().expect("analysed above");
        lu.factor(&self.assembler.matrix)?;
        lu.solve_in_place(&mut self.rhs)
    }

    /// The tangent of the last assembly (equation numbering).
    pub fn tangent(&self) -> &crate::linalg::SparseMatrix {
        &self.assembler.matrix
    }

    /// The correction `Δq` (by equation) of the last linear solve.
    pub fn correction(&self) -> &[f64] {
        &self.rhs
    }

    /// Explains a failed or runaway solve: singular (with the dof) or
    /// non-finite.
    fn diagnose(&self, model: &Model, iteration: usize) -> NewtonFailure {
        match smallest_relative_pivot(&self.assembler.matrix) {
            Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => NewtonFailure::Singular {
                dof: self.dof_label(model, self.dofs.dof(eq)),
                pivot,
            },
            _ => NewtonFailure::NonFinite { iteration },
        }
    }

    /// Applies the correction in `self.rhs` to `state`.
    fn update(&self, model: &Model, state: &mut State) {
        let n_nodes = model.n_nodes();
        for node in 0..n_nodes {
            let mut dx = Vec3::zeros();
            let mut dth = Vec3::zeros();
            let mut any_rotation = false;
            for c in 0..6 {
                let eq = self.dofs.equation(6 * node + c);
                if eq == NO_EQUATION {
                    continue;
                }
                if c < 3 {
                    dx[c] = self.rhs[eq];
                } else {
                    dth[c - 3] = self.rhs[eq];
                    any_rotation = true;
                }
            }
            state.x[node] += dx;
            if any_rotation {
                state.q[node] *= so3::exp(&dth);
                state.q[node].renormalize_fast();
            }
        }
        for (k, v) in state.extra.iter_mut().enumerate() {
            let eq = self.dofs.equation(6 * n_nodes + k);
            if eq != NO_EQUATION {
                *v += self.rhs[eq];
            }
        }
    }
}

/// What the iterations of one solve have seen so far.
#[derive(Default)]
struct Progress {
    /// Relative residual at each evaluation.
    residuals: Vec<f64>,
    /// `(max|Δx|, max|ΔΘ|)` of the last correction.
    last_correction: Option<(f64, f64)>,
    /// Force flux of the first evaluation (divergence reference).
    first_flux: Option<f64>,
}

/// `(max|Δx|, max|ΔΘ|)` of a correction.
fn correction_size(dofs: &DofMap, delta: &[f64]) -> (f64, f64) {
    let (mut dx, mut dth) = (0.0f64, 0.0f64);
    for (eq, &d) in delta.iter().enumerate() {
        let a = if d.is_finite() {
            d.abs()
        } else {
            f64::INFINITY
        };
        match dofs.kind(dofs.dof(eq)) {
            DofKind::Translation => dx = dx.max(a),
            DofKind::Rotation => dth = dth.max(a),
            DofKind::Extra => {}
        }
    }
    (dx, dth)
}
