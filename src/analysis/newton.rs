//! Newton–Raphson on the nodes' configuration manifold: the solver shared
//! by every analysis.
//!
//! One iteration (docs/theory.md §7):
//! 1. assemble `r(q)` and `K = ∂r/∂q` at the current state;
//! 2. stop if the residual, the constraints and the next correction are
//!    small (below);
//! 3. solve `K Δq = −r` with the sparse LU, whose symbolic analysis is
//!    computed once and reused;
//! 4. update translations additively and rotations multiplicatively,
//!    `x ← x + Δx`, `R ← R exp(ΔΘ~)`; if the update turned nodes and the
//!    translation residual jumped (elements stretched by the linear update
//!    of their turning ends), a translation correction `K_xx Δx = −r_x` at
//!    the new rotations puts the positions back in line (§7.2).
//!
//! A load increment starts from a predictor: each node continues the
//! motion of the last increment on the group (§7.3).
//!
//! Convergence (§7.1) requires at least one correction in the increment
//! and all of
//! - **residual**: for forces, for moments and for the generalised forces
//!   of coordinates separately, `‖(|r| − c ρ)⁺‖₂ ≤ ε_r ‖flux‖₂`: the part of
//!   each equation's residual above its round-off floor,
//!   `ρᵢ = ε Σⱼ |Kᵢⱼ| sⱼ` (`sⱼ` the size of unknown `j`: `|x| + ℓ` of its
//!   node, `ℓ` the length of its elements, 1 rad, or the value of a
//!   coordinate or multiplier), against the flux `Σₑ|rₑ|` of the forces
//!   flowing through the dofs (reactions included); a coordinate's
//!   generalised force counts divided by the length a unit of it spans
//!   ([`DofKind::Coordinate`]), against the force flux;
//! - **constraints**: the equations of multipliers (the constraints of
//!   joints) hold, above their round-off floor, to `ε_u D` for distances and
//!   `ε_θ` for angles, where `D = max|Δx|` is the largest translation of the
//!   increment so far;
//! - **correction**: the next correction, estimated as the last one times
//!   the residual ratio, `|Δq_{k+1}| ≈ |Δq_k| ρ_k/ρ_{k−1}` (exact in the
//!   quadratic regime; this saves the iteration that would only confirm
//!   convergence), is below `ε_u D` for translations and coordinates
//!   (times their length), `ε_θ` for rotations, and `ε_r` times the flux of
//!   its group for the force `k Δλ` of a multiplier, each above its own
//!   round-off (`c ε (|x| + ℓ)`, `c ε`, `c ε |c|`, `c ε |kλ|`);
//!
//! or else the residual has stopped decreasing within `PLATEAU_FACTOR`
//! of its round-off floor (it is at its round-off plateau).
//!
//! None of these depends on the extent of the model, on unloaded parts of
//! it or on the units: the flux, the floors and `D` are all local or
//! carried by the loaded part.
//!
//! The very first solve of a model always makes one correction, even from
//! equilibrium, so that a singular tangent (a mechanism, a missing support)
//! is found before the analysis starts.

use super::constraints::{self, ConstraintRank};
use super::settings::StaticSettings;
use super::statics::StaticError;
use super::{IterationInfo, Observer};
use crate::assembly::Assembler;
use crate::dofs::{DofKind, DofMap, NO_EQUATION};
use crate::elements::{ConstraintKind, ElementOutput, Need};
use crate::linalg::{
    smallest_relative_pivot, DeterminantSign, LuKernel, SolveError, SparseLu, SymmetricFirst,
};
use crate::model::{Model, COMPONENT_NAMES};
use crate::so3::{self, Vec3};
use crate::state::State;

/// A relative pivot below this marks the tangent as singular (round-off of
/// an exactly singular matrix is ~1e-16; a stiff but sound structure is far
/// above).
pub(crate) const SINGULAR_PIVOT: f64 = 1e-11;

/// Corrections larger than this times the size of the free part of the
/// model (the bounding box of the nodes that can translate), or than this
/// in radians, mean the tangent is singular or nearly so. A guard only:
/// no converged result depends on it.
pub(crate) const RUNAWAY_CORRECTION: f64 = 1e6;

/// An update that turns nodes and raises the residual of the translation
/// equations more than this many times (and above round-off) is followed
/// by a translation correction (docs/theory.md §7.2): the linear update
/// `x ← x + Δx` of a node whose element turned by `θ` stretches the element
/// by `θ²/2`, which in a slender beam is a force far larger than any load,
/// where Newton's step should have reduced the residual. Near the solution
/// the residual falls and no correction is made, so Newton's quadratic
/// convergence is kept.
const STRETCH_GROWTH: f64 = 10.0;

/// ... and only when that residual is more than this share of the force
/// flux: spurious forces that dominate the forces in the structure. (On
/// the 45° bend, residuals grown tenfold but below 1e-3 of the flux occur
/// in the quadratic end of Newton's iterations; correcting them costs a
/// solve and gains nothing.)
const STRETCH_SHARE: f64 = 0.1;

/// A predictor is followed by a translation correction (on the same
/// conditions) only if it turned a node by more than this (rad). The
/// predictors of the mast cell turn its nodes by 1e-3 to 0.06 rad and the
/// correction then saves no iteration (it did in 95 of 96 increments, for
/// the same 260 iterations); those of the roll-up in 8 to 40 increments
/// turn them by 0.16 to 0.8 rad, and the correction saves 4 to 10
/// iterations per increment.
const PREDICTOR_TURN: f64 = 0.1;

/// `c`: the round-off floor of a residual is `c ρᵢ`, `ρᵢ = ε Σⱼ |Kᵢⱼ| sⱼ`
/// being the residual that a relative error `ε` on every unknown would
/// produce in equation `i` (docs/theory.md §7.1). Measured on the
/// validation models (every test of `tests/`, with the tolerances set to
/// zero so that iterations go on to the round-off plateau), the residual
/// of Newton's iterates once they stop decreasing lies between 0 and 7.6
/// times `ρᵢ`, median 0.2, 99 % below 4. Above `c` a residual is never
/// taken for round-off; the rare plateaus above it are caught by
/// [`PLATEAU_FACTOR`].
const FLOOR_FACTOR: f64 = 4.0;

/// A residual that has stopped decreasing (by less than half in an
/// iteration) while within this many `ρᵢ` of zero is at its
/// round-off plateau: accepted whatever the correction (which is then only
/// round-off, amplified by the conditioning of the tangent). A safety net
/// for plateaus above [`FLOOR_FACTOR`]; a residual this small moves the
/// nodes by less than ~1e-12 of their positions and element lengths.
const PLATEAU_FACTOR: f64 = 1024.0;

/// Arc-length iterations of one increment whose constraint may have no
/// real root (each then takes the increment of closest approach) before the
/// increment is cut back. On the deep arch and Lee's frame the increments
/// that converge need at most 2; those that need more go on doing so until
/// the iteration limit.
const MAX_CLOSEST_APPROACHES: usize = 3;

/// The work `|r·Δq|` of an iteration grown by this factor over that of the
/// first iteration is divergence: a residual grown 1e8 times, with a
/// correction grown as much. (The first corrections of a stiff beam may
/// legitimately raise the residual by 1e3–1e4: stretching from a linear
/// prediction of large rotations.)
const DIVERGED_GROWTH: f64 = 1e16;

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
    /// `‖r/ℓ‖₂` over free coordinate equations (generalised forces divided
    /// by the length a unit of the coordinate spans: forces).
    pub residual_coordinate: f64,
    /// `max(‖e_F‖/‖flux_F‖, ‖e_M‖/‖flux_M‖, ‖e_C/ℓ‖/‖flux_F‖)`, where
    /// `eᵢ = (|rᵢ| − c ρᵢ)⁺` is the part of each residual above its
    /// round-off floor: the residual criterion holds when this is at most
    /// `ε_r`; 0 when every residual is at round-off.
    pub relative_residual: f64,
    /// Largest constraint violation above round-off, relative to its
    /// tolerance (`ε_u·D` for distances, `D` the largest translation of the
    /// increment, the previous increment's before the first correction;
    /// `ε_θ` for angles); the constraints hold when it is at most 1. Zero
    /// without constraints.
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
    #[error("diverging at iteration {iteration}: the work of the residual on its correction grew by more than 1e16 (relative residual {relative_residual:.3e})")]
    Diverging {
        /// Iteration at which divergence was detected.
        iteration: usize,
        /// Relative residual then.
        relative_residual: f64,
    },
    /// Dynamics: the iterations moved away from the solution (the
    /// residual grew from the predictor's) until the iteration matrix
    /// could not be solved or the correction ran away: the step is too
    /// long for the motion, not a sign of a mechanism.
    #[error("Newton diverged: the residual grew from {from:.1e} to {to:.1e} in {iteration} iterations ({what}); the step is too long for the motion there")]
    Diverged {
        /// Iteration at which it stopped.
        iteration: usize,
        /// The larger of the force and moment residuals (N, N·m) at the
        /// predictor.
        from: f64,
        /// The same at the last iterate.
        to: f64,
        /// What stopped it: a singular iteration matrix at the diverged
        /// iterate (naming the unknown), a runaway correction.
        what: String,
    },
    /// NaN or infinite values appeared.
    #[error("non-finite values at iteration {iteration} {origin}")]
    NonFinite {
        /// Iteration at which they appeared.
        iteration: usize,
        /// Where they came from: `in the residual of beam 12`, `in curve
        /// "c" (NaN at t = 0.5)`, `in the solution of the linear system`.
        origin: String,
    },
    /// Arc-length control: the increment turned back along the path it
    /// came from (it would retrace it).
    #[error("arc-length increment turning back along the path at iteration {iteration}")]
    PathReversed {
        /// Iteration.
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
    /// Dynamics: Newton converged to a motion that no step of this size
    /// can follow, a spurious root of the step's equations (a node turned
    /// by more than the step may follow, or carried far from the
    /// predictor; docs/theory.md §15.5): the step is cut back.
    #[error("spurious solution after {iterations} iterations: {what}")]
    Spurious {
        /// Iterations it took.
        iterations: usize,
        /// What is wrong with it, naming the node.
        what: String,
    },
    /// The step converged, but its estimated local error is above the
    /// tolerance (the step controller shrinks it).
    #[error("local error estimate {error:.3e} times its tolerance{}", if at.is_empty() { String::new() } else { format!(", largest at {at}: the steps follow a motion there far faster than the rest (a stiff and light part vibrating, an impact, a load switched on at once); damp it (rayleigh_beta of its section, rho_infinity below 1), or raise error_tolerance") })]
    ErrorEstimate {
        /// Error relative to the tolerance.
        error: f64,
        /// Where the estimate was largest (`node 12`; empty if unknown).
        at: String,
    },
}

impl NewtonFailure {
    /// Iterations spent before the failure.
    pub fn iterations_spent(&self) -> usize {
        match self {
            Self::MaxIterations { iterations, .. } | Self::Spurious { iterations, .. } => {
                *iterations
            }
            Self::Diverging { iteration, .. }
            | Self::Diverged { iteration, .. }
            | Self::NonFinite { iteration, .. }
            | Self::NoArcRoot { iteration }
            | Self::PathReversed { iteration } => *iteration,
            Self::Singular { .. } | Self::ErrorEstimate { .. } => 0,
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
    /// Factors of the nearly symmetric systems that the dynamic analysis
    /// forms on the same pattern (the impacts of locks, docs/theory.md §16).
    symmetric: Option<SymmetricFirst>,
    rhs: Vec<f64>,
    /// Round-off unit `ε Σⱼ |Kᵢⱼ| sⱼ` of each equation's residual at the
    /// last assessment (the floor is [`FLOOR_FACTOR`] times it).
    floor: Vec<f64>,
    /// Size `sⱼ` of each unknown's value (work space of the floor).
    size: Vec<f64>,
    /// Sum of the corrections of the current increment, by equation.
    step: Vec<f64>,
    /// `D`: largest translation of the last converged increment.
    last_motion: f64,
    /// Translation residual of the last converged state.
    converged_translation_residual: f64,
    /// Diagonal of the bounding box of the nodes that can translate (the
    /// scale of the runaway guard).
    free_size: f64,
    /// `ℓₙ`: largest reference distance from each node to the other nodes
    /// of its elements (its elements' length), part of the size of its
    /// position in the round-off floor.
    node_lengths: Vec<f64>,
    /// Positions in the matrix values of the entries in the rows and
    /// columns of held equations (rotations, angular multipliers), and of
    /// their diagonal entries, for the translation iterations.
    held_entries: Option<(Vec<usize>, Vec<usize>)>,
    /// Whether the last assembly is at the current state and time (and may
    /// be used by the next assessment instead of assembling again).
    fresh: bool,
    /// Weight of translations in the arc-length norm (rotations: 1).
    translation_weight: f64,
    /// Whether `step` holds a predictor's motion for the next solve.
    predicted: bool,
    /// Work space of the size of `rhs`.
    work: Vec<f64>,
    /// Whether translation corrections are made (until one finds the
    /// translation block singular).
    translation_corrections: bool,
    /// Translation corrections made so far.
    translation_count: usize,
    /// Arc-length iterations without a real root so far.
    closest_approach_count: usize,
    /// Whether a tangent has been factored and solved once: until then a
    /// solve always makes one correction, even from equilibrium, so that a
    /// singular model (a mechanism) is caught at the start.
    tangent_checked: bool,
    /// Multipliers of redundant constraints, left out of the system.
    redundant: Vec<usize>,
    /// Whether the constraints of each element were active at the last
    /// rank analysis.
    active: Vec<bool>,
    /// Scaling of the constraint equations (their multipliers' `k`).
    scaling: crate::elements::ConstraintScaling,
    /// Sign of the tangent's determinant (docs/theory.md §9): the
    /// workspace, and the sign of the last Newton system factored by the
    /// simplicial kernel.
    determinant: DeterminantSign,
    newton_sign: Option<f64>,
    /// Numberings made so far: a factorisation kept outside the solver
    /// holds while this is the one it was made in.
    numbering: usize,
}

impl NewtonSolver {
    /// Prepares numbering, pattern and buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let dofs = DofMap::new(model);
        let assembler = Assembler::new(model, &dofs);
        let n = dofs.n_equations();
        let free_size = free_size(model, &dofs);
        let node_lengths = node_lengths(model);
        Self {
            dofs,
            assembler,
            lu: None,
            symmetric: None,
            rhs: vec![0.0; n],
            floor: vec![0.0; n],
            size: vec![0.0; n],
            step: vec![0.0; n],
            last_motion: 0.0,
            converged_translation_residual: 0.0,
            free_size,
            node_lengths,
            held_entries: None,
            predicted: false,
            fresh: false,
            translation_weight: 1.0,
            work: vec![0.0; n],
            translation_corrections: true,
            translation_count: 0,
            closest_approach_count: 0,
            tangent_checked: false,
            redundant: Vec::new(),
            active: Vec::new(),
            scaling: model.scaling,
            determinant: DeterminantSign::default(),
            newton_sign: None,
            numbering: 0,
        }
    }

    /// Resizes the work vectors after a change of numbering.
    fn resize(&mut self) {
        let n = self.dofs.n_equations();
        for v in [
            &mut self.rhs,
            &mut self.floor,
            &mut self.size,
            &mut self.step,
            &mut self.work,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
    }

    /// Whether each equation is a multiplier's.
    fn multiplier_equations(&self) -> Vec<bool> {
        (0..self.dofs.n_equations())
            .map(|eq| matches!(self.dofs.equation_kind(eq), DofKind::Multiplier(_)))
            .collect()
    }

    /// Rank analysis of the constraints at `state` and `time`
    /// (docs/joints.md §5): redundant constraints are removed from the
    /// numbering (their multipliers stay zero) and the free motions are
    /// counted. Run at the start of an analysis, and again whenever the
    /// set of active constraints changes ([`Self::active_set_changed`]):
    /// the numbering is then rebuilt from the model's, with the redundant
    /// constraints of now.
    pub fn constraint_rank(&mut self, model: &Model, state: &State, time: f64) -> ConstraintRank {
        self.active.clear();
        self.active.extend(
            model
                .elements
                .iter()
                .map(|e| e.n_multipliers() > 0 && e.constraints_active(time, state)),
        );
        if !self.redundant.is_empty() {
            // back to the full numbering
            self.redundant.clear();
            self.renumber(model);
        }
        self.assemble(model, state, time, true);
        let rank = constraints::analyse(
            &self.dofs,
            &self.assembler.matrix,
            &self.multiplier_equations(),
        );
        self.redundant.clone_from(&rank.redundant);
        if !rank.redundant.is_empty() {
            self.renumber(model);
        }
        rank
    }

    /// Numbers the unknowns again, without the redundant multipliers.
    fn renumber(&mut self, model: &Model) {
        self.dofs = DofMap::with_suppressed(model, &self.redundant);
        self.assembler = Assembler::new(model, &self.dofs);
        self.lu = None;
        self.symmetric = None;
        self.numbering += 1;
        self.newton_sign = None;
        self.held_entries = None;
        self.resize();
    }

    /// Whether the constraints acting at `time` in `state` are not those of
    /// the last rank analysis (a driver's window opened or closed). No
    /// allocation.
    pub fn active_set_changed(&self, model: &Model, state: &State, time: f64) -> bool {
        model
            .elements
            .iter()
            .zip(&self.active)
            .any(|(e, &was)| e.n_multipliers() > 0 && e.constraints_active(time, state) != was)
    }

    /// Multipliers removed as redundant by the last rank analysis.
    pub fn redundant_count(&self) -> usize {
        self.redundant.len()
    }

    /// The error of a kinematic analysis whose constraints leave the
    /// motions `rank.freedom` free, naming the least constrained unknowns.
    pub fn indeterminate(&self, model: &Model, rank: &ConstraintRank) -> StaticError {
        let free = rank.degrees_of_freedom();
        let dofs: Vec<String> = rank
            .freedom
            .iter()
            .take(free.min(6))
            .map(|&(d, _)| self.dof_label(model, d))
            .collect();
        StaticError::Indeterminate {
            free,
            dofs: dofs.join(", "),
        }
    }

    /// Residual at every dof after the last evaluation: at fixed dofs, the
    /// reactions of the supports (`r = f_int − f_ext` there).
    pub fn residual(&self) -> &[f64] {
        &self.assembler.residual
    }

    /// Translation corrections made so far (docs/theory.md §7.2), each one
    /// more assembly and factorisation.
    pub fn translation_corrections(&self) -> usize {
        self.translation_count
    }

    /// Arc-length iterations so far whose constraint had no real root
    /// (docs/theory.md §9).
    pub fn closest_approaches(&self) -> usize {
        self.closest_approach_count
    }

    /// The numbering, the assembler and a solver of nearly symmetric
    /// systems of the current numbering, for an analysis that forms its
    /// own matrices on the same pattern (dynamics). The solver's symbolic
    /// analysis is kept between calls and dropped when the numbering
    /// changes.
    pub(crate) fn system(&mut self) -> (&DofMap, &mut Assembler, &mut Option<SymmetricFirst>) {
        self.fresh = false;
        (&self.dofs, &mut self.assembler, &mut self.symmetric)
    }

    /// Which numbering of the unknowns is current: it changes whenever the
    /// pattern is built again (a rank analysis that renumbers), so that an
    /// analysis keeping its own factors knows they no longer apply.
    pub(crate) fn numbering(&self) -> usize {
        self.numbering
    }

    /// The assembler (its last residual, flux and matrix).
    pub(crate) fn assembler(&self) -> &Assembler {
        &self.assembler
    }

    /// Number of stored entries of the system matrix.
    pub fn nnz(&self) -> usize {
        self.assembler.matrix.nnz()
    }

    /// Describes a dof for messages: `node 5 rz`, `joint 3 unknown 1`
    /// (the element's coordinates, then its multipliers, from 1).
    pub fn dof_label(&self, model: &Model, dof: usize) -> String {
        if let Some((node, c)) = self.dofs.node_component(dof) {
            return format!("node {} {}", model.node_ids[node], COMPONENT_NAMES[c]);
        }
        // the element owning the coordinate or multiplier
        for (i, e) in model.elements.iter().enumerate() {
            if let Some(k) = self
                .dofs
                .element_extra_dofs(model, i)
                .position(|d| d == dof)
            {
                return format!("{} {} unknown {}", e.kind().name(), e.id(), k + 1);
            }
        }
        format!("dof {dof}")
    }

    /// Assembles residual (and tangent if asked) at `state` and `time`.
    pub fn assemble(&mut self, model: &Model, state: &State, time: f64, need_tangent: bool) {
        self.fresh = false;
        let ctx = model.context(time, Need::stiffness(need_tangent));
        self.assembler.assemble(model, &ctx, state);
    }

    /// The constraint left out as redundant that is violated the most at
    /// `state`, with its violation above round-off relative to the
    /// tolerance (`ε_u D` with `D` the translation of the last increment,
    /// or `ε_θ`), if above 1: the constraints then contradict each other
    /// (two drivers imposing incompatible motions) instead of repeating
    /// each other.
    pub fn violated_redundant(
        &self,
        model: &Model,
        state: &State,
        settings: &StaticSettings,
    ) -> Option<(String, f64)> {
        let distance = settings.displacement_tolerance * self.last_motion;
        self.violated_redundant_within(model, state, distance, settings.rotation_tolerance)
    }

    /// [`Self::violated_redundant`] with the tolerances of distance and
    /// angle equations given (a dynamic step's: `ε_u` times the step's
    /// largest translation, `ε_θ`).
    pub fn violated_redundant_within(
        &self,
        model: &Model,
        state: &State,
        distance_tolerance: f64,
        angle_tolerance: f64,
    ) -> Option<(String, f64)> {
        if self.redundant.is_empty() {
            return None;
        }
        let ctx = model.context(state.time, Need::STIFFNESS);
        let mut worst: Option<(String, f64)> = None;
        for (i, e) in model.elements.iter().enumerate() {
            let (nm, o) = (e.n_multipliers(), model.offsets(i));
            let mine: Vec<usize> = self
                .redundant
                .iter()
                .filter(|&&k| k >= o.multipliers && k < o.multipliers + nm)
                .map(|&k| k - o.multipliers)
                .collect();
            if mine.is_empty() {
                continue;
            }
            let n = e.n_local();
            let mut r = vec![0.0; n];
            let mut t = vec![0.0; n * n];
            e.evaluate(
                &ctx,
                state,
                &mut ElementOutput::with_stiffness(&mut r, &mut t),
            );
            // sizes of the element's unknowns, for the round-off floor
            let nodes = e.nodes();
            let (nq, nc) = (6 * nodes.len(), e.n_coordinates());
            let size: Vec<f64> = (0..n)
                .map(|j| match j {
                    j if j < nq && j % 6 < 3 => {
                        let node = nodes[j / 6];
                        state.x[node].norm() + self.node_lengths[node]
                    }
                    j if j < nq => 1.0,
                    j if j < nq + nc => state.coordinates[o.coordinates + j - nq].abs(),
                    j => state.multipliers[o.multipliers + j - nq - nc].abs(),
                })
                .collect();
            for k in mine {
                let kind = e.multiplier_kind(k);
                let scale = ctx.scaling.of(kind).0;
                let tol = match kind {
                    ConstraintKind::Angle => angle_tolerance,
                    ConstraintKind::Distance => distance_tolerance,
                };
                let row = nq + nc + k;
                // tangent in column-major order: K_ij at j·n + i
                let floor: f64 = FLOOR_FACTOR
                    * f64::EPSILON
                    * (0..n).map(|j| t[j * n + row].abs() * size[j]).sum::<f64>();
                let excess = (r[row].abs() - floor).max(0.0) / scale;
                let v = if excess == 0.0 { 0.0 } else { excess / tol };
                if v > 1.0 && worst.as_ref().is_none_or(|w| v > w.1) {
                    worst = Some((
                        format!("{} {} equation {}", e.kind().name(), e.id(), k + 1),
                        v,
                    ));
                }
            }
        }
        worst
    }

    /// Round-off unit of every equation's residual at `state`, from the
    /// last assembled tangent (docs/theory.md §7.1):
    /// `ε Σⱼ |Kᵢⱼ| sⱼ`, the residual that relative errors `ε` on
    /// every unknown would produce, with `sⱼ = |x| + ℓ` of the node for
    /// translations (its position is known to `ε|x|`, and its elements
    /// compute strains of order 1 from lengths `ℓ`), 1 (rad) for rotations
    /// and the magnitude of the value for coordinates and multipliers.
    /// Local to each equation: neither the extent of the model nor a stiff
    /// part elsewhere changes it.
    fn round_off_floor(&mut self, state: &State) {
        for (eq, s) in self.size.iter_mut().enumerate() {
            *s = unknown_size(&self.dofs, &self.node_lengths, state, self.dofs.dof(eq));
        }
        self.floor.fill(0.0);
        for (row, col, v) in self.assembler.matrix.entries() {
            self.floor[row] += v.abs() * self.size[col];
        }
        self.floor.iter_mut().for_each(|f| *f *= f64::EPSILON);
    }

    /// `D`: the largest translation of the current increment so far.
    fn motion(&self) -> f64 {
        self.step
            .iter()
            .enumerate()
            .filter(|&(eq, _)| self.dofs.equation_kind(eq) == DofKind::Translation)
            .fold(0.0f64, |m, (_, v)| m.max(v.abs()))
    }

    /// Residual, flux and constraint norms of the last assembly
    /// (docs/theory.md §7.1), with `distance_tol` the tolerance of distance
    /// constraints. Each kind of unknown has its group: forces
    /// (translations), moments (rotations), the generalised forces of
    /// coordinates divided by their lengths (forces, against the force
    /// flux: the one element owning a coordinate makes its own flux equal
    /// to its residual), and the constraints.
    fn norms(&self, settings: &StaticSettings, distance_tol: f64, factor: f64) -> ConvergenceNorms {
        let (mut rf, mut rm, mut rq, mut ef, mut em, mut eq_c, mut ff, mut fm, mut rc) =
            (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0f64);
        let res = &self.assembler.residual;
        let flux = &self.assembler.flux;
        // flux over every node dof, fixed ones included (reactions)
        for (dof, f) in flux.iter().enumerate() {
            match self.dofs.kind(dof) {
                DofKind::Translation => ff += f * f,
                DofKind::Rotation => fm += f * f,
                DofKind::Coordinate { .. } | DofKind::Multiplier(_) => {}
            }
        }
        // residual and its part above round-off over free equations
        for (eq, &unit) in self.floor.iter().enumerate() {
            let dof = self.dofs.dof(eq);
            let r = res[dof];
            let e = (r.abs() - factor * unit).max(0.0);
            match self.dofs.kind(dof) {
                DofKind::Translation => {
                    rf += r * r;
                    ef += e * e;
                }
                DofKind::Rotation => {
                    rm += r * r;
                    em += e * e;
                }
                DofKind::Coordinate { length } => {
                    rq += (r / length).powi(2);
                    eq_c += (e / length).powi(2);
                }
                DofKind::Multiplier(kind) => {
                    if e > 0.0 {
                        let t = match kind {
                            ConstraintKind::Angle => settings.rotation_tolerance,
                            ConstraintKind::Distance => distance_tol,
                        };
                        rc = rc.max(e / self.scaling.of(kind).0 / t);
                    }
                }
            }
        }
        // e > 0 implies a non-zero flux (flux ≥ |r| at every dof)
        let rel = |e: f64, f: f64| if e == 0.0 { 0.0 } else { e / f };
        ConvergenceNorms {
            residual_force: rf.sqrt(),
            residual_moment: rm.sqrt(),
            flux_force: ff.sqrt(),
            flux_moment: fm.sqrt(),
            residual_coordinate: rq.sqrt(),
            relative_residual: rel(ef.sqrt(), ff.sqrt())
                .max(rel(em.sqrt(), fm.sqrt()))
                .max(rel(eq_c.sqrt(), ff.sqrt())),
            residual_constraint: rc,
            displacement_correction: 0.0,
            rotation_correction: 0.0,
        }
    }

    /// Whether the next correction, estimated as the last one (in
    /// `self.rhs`) times `ratio`, is below `ε_u D` for translations and
    /// coordinates (times their length), `ε_θ` for rotations, and
    /// `ε_r ‖flux‖` of its group for the force `k Δλ` of a multiplier, each
    /// above the round-off of the unknown.
    fn correction_converged(
        &self,
        state: &State,
        settings: &StaticSettings,
        ratio: f64,
        motion: f64,
        norms: &ConvergenceNorms,
    ) -> bool {
        let (tol_x, tol_theta) = (
            settings.displacement_tolerance * motion,
            settings.rotation_tolerance + FLOOR_FACTOR * f64::EPSILON,
        );
        let round_off = FLOOR_FACTOR * f64::EPSILON;
        self.rhs.iter().enumerate().all(|(eq, &delta)| {
            let d = self.dofs.dof(eq);
            let next = delta.abs() * ratio;
            let size = || unknown_size(&self.dofs, &self.node_lengths, state, d);
            match self.dofs.kind(d) {
                DofKind::Translation => next - round_off * size() <= tol_x,
                DofKind::Rotation => next <= tol_theta,
                DofKind::Coordinate { length } => (next - round_off * size()) * length <= tol_x,
                DofKind::Multiplier(kind) => {
                    let flux = match kind {
                        ConstraintKind::Distance => norms.flux_force,
                        ConstraintKind::Angle => norms.flux_moment,
                    };
                    let k = self.scaling.of(kind).0;
                    (next - round_off * size()) * k <= settings.residual_tolerance * flux
                }
            }
        })
    }

    /// One Newton evaluation shared by load and arc-length control:
    /// assembles residual and tangent at `state` and `time` (unless the
    /// last assembly is already there), reports the iteration and decides
    /// whether the iterations have converged (`Ok(true)`, only if
    /// `may_converge`), must go on (`Ok(false)`) or have failed.
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
        if !std::mem::take(&mut self.fresh) {
            self.assemble(model, state, time, true);
        }
        self.round_off_floor(state);
        let motion = self.motion();
        // before the first correction D = 0: constraints are reported
        // against the previous increment's translation
        let reference_motion = if iteration == 0 {
            self.last_motion
        } else {
            motion
        };
        let distance_tol = settings.displacement_tolerance * reference_motion;
        let mut norms = self.norms(settings, distance_tol, FLOOR_FACTOR);
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
        let finite = norms.residual_force.is_finite()
            && norms.residual_moment.is_finite()
            && self.floor.iter().all(|f| f.is_finite())
            && self.assembler.residual.iter().all(|r| r.is_finite());
        if !finite {
            return Err(self.non_finite(model, state, time, iteration));
        }

        let tol = settings.residual_tolerance;
        let converged = match progress.last_correction {
            // every increment makes at least one correction
            None => false,
            Some(_) => {
                // the next correction estimated as the last one scaled by
                // the residual ratio, |Δq_k+1| ≈ |Δq_k| ρ_k/ρ_k-1
                let ratio = match residuals[..] {
                    [.., previous, last] if previous > 0.0 => (last / previous).min(1.0),
                    _ => 1.0,
                };
                let converged = norms.relative_residual <= tol
                    && norms.residual_constraint <= 1.0
                    && self.correction_converged(state, settings, ratio, motion, &norms);
                // or at the round-off plateau: stopped decreasing, within
                // PLATEAU_FACTOR of round-off
                let plateau = || {
                    let loose = self.norms(settings, distance_tol, PLATEAU_FACTOR);
                    ratio > 0.5
                        && loose.relative_residual <= tol
                        && loose.residual_constraint <= 1.0
                };
                converged || plateau()
            }
        };
        if may_converge && converged {
            self.last_motion = motion;
            self.converged_translation_residual = self.translation_residual();
            return Ok(true);
        }
        if iteration == settings.max_iterations {
            return Err(NewtonFailure::MaxIterations {
                iterations: iteration,
                relative_residual: norms.relative_residual,
            });
        }
        Ok(false)
    }

    /// Divergence test after the correction in `self.rhs` has been solved
    /// for: the work `|r·Δq|` of the iteration against that of the first
    /// (or, if larger, the work of the round-off floors), both free of the
    /// units and of the extent of the model.
    fn check_divergence(
        &self,
        progress: &mut Progress,
        iteration: usize,
    ) -> Result<(), NewtonFailure> {
        let (mut work, mut floor) = (0.0f64, 0.0f64);
        for (eq, &delta) in self.rhs.iter().enumerate() {
            work += self.assembler.residual[self.dofs.dof(eq)] * delta;
            floor += self.floor[eq] * delta.abs();
        }
        let work = work.abs();
        let reference = progress.first_work.get_or_insert(work).max(floor);
        if iteration > 0 && work > DIVERGED_GROWTH * reference {
            return Err(NewtonFailure::Diverging {
                iteration,
                relative_residual: progress.residuals.last().copied().unwrap_or(0.0),
            });
        }
        Ok(())
    }

    /// Names the origin of non-finite values met at `state` and `time`:
    /// a curve, the gravity, a node, or the first element whose residual or
    /// tangent is not finite (each element is evaluated again on its own;
    /// this runs only after a failure).
    fn non_finite(
        &self,
        model: &Model,
        state: &State,
        time: f64,
        iteration: usize,
    ) -> NewtonFailure {
        NewtonFailure::NonFinite {
            iteration,
            origin: non_finite_origin(model, state, time),
        }
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
        let mut progress = Progress::default();
        // the sum of the corrections starts with the predictor's motion
        // (whose last assembly, if any, is at this state and time)
        if !std::mem::take(&mut self.predicted) {
            self.step.fill(0.0);
            self.fresh = false;
        }
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
            if !(dx <= RUNAWAY_CORRECTION * self.free_size && dth <= RUNAWAY_CORRECTION) {
                return Err(self.diagnose(model, state, time, iteration));
            }
            self.check_divergence(&mut progress, iteration)?;

            self.tangent_checked = true;

            // update: x ← x + Δx, R ← R exp(ΔΘ~), extras additively, then
            // the positions brought in line with the rotations (§7.2)
            let before = self.translation_residual();
            self.update(state);
            if dth > 0.0 {
                self.translation_correction(model, state, time, before, true);
            }
            progress.last_correction = Some((dx, dth));
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Predictor of a load increment (docs/theory.md §7.3): moves the free
    /// unknowns of `state` (the converged state `g_n`, prescribed values
    /// already set for the new `t`) along the motion of the last increment,
    /// from `previous` (`g_{n−1}`), scaled by `scale = Δt_{n+1}/Δt_n`.
    /// Each node continues its last relative motion on the group, in its
    /// material frame: `g_pred = g_n (g_{n−1}⁻¹ g_n)^s`, i.e.
    /// `R_pred = R_n exp(s ψ)`, `x_pred = x_n + R_n Tᵀ(sψ) s T⁻ᵀ(ψ) b` with
    /// `ψ = log(R_{n−1}ᵀ R_n)`, `b = R_{n−1}ᵀ (x_n − x_{n−1})`;
    /// coordinates and multipliers are extrapolated linearly. A rigid motion of an element is
    /// continued exactly, so its length does not change (a linear
    /// extrapolation of positions would stretch every turning element by
    /// the square of its rotation).
    pub fn predict(
        &mut self,
        model: &Model,
        state: &mut State,
        previous: &State,
        scale: f64,
        time: f64,
    ) {
        let before = self.converged_translation_residual;
        // the predictor's motion starts the increment's sum of corrections
        self.step.fill(0.0);
        self.predicted = true;
        let mut turn = 0.0f64;
        for node in 0..model.n_nodes() {
            let eqs = [0, 1, 2, 3, 4, 5].map(|c| self.dofs.equation(6 * node + c));
            let free_x = [0, 1, 2].map(|c| eqs[c] != NO_EQUATION);
            let free_r = [3, 4, 5].map(|c| eqs[c] != NO_EQUATION);
            if !free_x.iter().chain(&free_r).any(|&f| f) {
                continue;
            }
            let (r0, r1) = (previous.q[node], state.q[node]);
            let psi = so3::log(&(r0.inverse() * r1));
            let b = r0.inverse() * (state.x[node] - previous.x[node]);
            let v = so3::SkewSeries::new(so3::Operator::TangentInv, &psi).apply_transpose(&b);
            let mut psi_s = psi * scale;
            let p =
                so3::SkewSeries::new(so3::Operator::Tangent, &psi_s).apply_transpose(&(v * scale));
            let dx = r1 * p;
            for c in 0..3 {
                if free_x[c] {
                    state.x[node][c] += dx[c];
                    self.step[eqs[c]] = dx[c];
                }
                if free_r[c] {
                    self.step[eqs[c + 3]] = psi_s[c];
                } else {
                    psi_s[c] = 0.0;
                }
            }
            if free_r.iter().any(|&f| f) {
                state.q[node] = r1 * so3::exp(&psi_s);
                turn = turn.max(psi_s.norm());
            }
        }
        let (first_c, first_m) = (self.dofs.first_coordinate(), self.dofs.first_multiplier());
        let extras = [
            (first_c, &mut state.coordinates, &previous.coordinates),
            (first_m, &mut state.multipliers, &previous.multipliers),
        ];
        for (first, values, before) in extras {
            for (k, v) in values.iter_mut().enumerate() {
                let eq = self.dofs.equation(first + k);
                if eq != NO_EQUATION {
                    let delta = scale * (*v - before[k]);
                    *v += delta;
                    self.step[eq] = delta;
                }
            }
        }
        if turn > PREDICTOR_TURN {
            self.translation_correction(model, state, time, before, false);
        }
    }

    /// Translation correction (docs/theory.md §7.2) after an update that
    /// turned nodes: assembles at the new state and, if the translation
    /// residual grew more than [`STRETCH_GROWTH`] times over `before` (its
    /// value before the update) and above round-off, and exceeds
    /// [`STRETCH_SHARE`] of the force flux, solves `K_xx Δx = −r_x` with the
    /// rotations (and the multipliers of angular constraints) held, and
    /// moves the nodes by `Δx`. For beams the translation residual is linear
    /// in the positions at fixed rotations, so one solve puts every element
    /// chord where its section frames say. `self.rhs` then holds the whole
    /// correction of the iteration if `add` (else the translation
    /// correction). Without a correction the assembly is kept for the next
    /// assessment. A model whose translations are over-determined at fixed
    /// rotations (closed loops of rigid bodies) has a singular translation
    /// block: the correction is then skipped, and not tried again.
    fn translation_correction(
        &mut self,
        model: &Model,
        state: &mut State,
        time: f64,
        before: f64,
        add: bool,
    ) {
        if !self.translation_corrections {
            return;
        }
        self.assemble(model, state, time, true);
        self.fresh = true;
        self.round_off_floor(state);
        let floor = FLOOR_FACTOR * self.translation_norm(&self.floor);
        let flux = self.translation_norm_dofs(&self.assembler.flux);
        let r = self.translation_residual();
        // (non-finite values are left to the next assessment to report)
        if !(r > STRETCH_GROWTH * before.max(floor) && r > STRETCH_SHARE * flux) {
            return;
        }
        self.fresh = false;
        self.work.copy_from_slice(&self.rhs);
        let dx = match self.solve_translations() {
            Ok(()) => correction_size(&self.dofs, &self.rhs).0,
            Err(_) => f64::INFINITY,
        };
        if dx <= RUNAWAY_CORRECTION * self.free_size {
            self.update(state);
            self.translation_count += 1;
            if add {
                for (r, w) in self.rhs.iter_mut().zip(&self.work) {
                    *r += w;
                }
            }
        } else {
            self.translation_corrections = false;
            self.rhs.copy_from_slice(&self.work);
        }
    }

    /// Weights of the arc-length norm, by equation (docs/theory.md §9):
    /// `w_x` for translations (times their length for coordinates), 1 for
    /// rotations, 0 for multipliers, with
    /// `w_x = ‖q_t,θ‖/‖q_t,x‖` from the first tangent predictor (set by
    /// [`NewtonSolver::tangent_arc`]; 1 before it or if either part is
    /// zero), so that translations and rotations weigh alike in the first
    /// increment, whatever the units, the extent of the model or the
    /// stiffness of its parts.
    fn arc_weights(&self) -> Vec<f64> {
        (0..self.dofs.n_equations())
            .map(|eq| match self.dofs.equation_kind(eq) {
                DofKind::Translation => self.translation_weight,
                DofKind::Rotation => 1.0,
                DofKind::Coordinate { length } => self.translation_weight * length,
                DofKind::Multiplier(_) => 0.0,
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
        let ctx = model.context(t + h, Need::RESIDUAL);
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
        self.rhs.iter_mut().zip(&qt).for_each(|(r, q)| *r = -q);
        let ok = self.analyze().is_ok()
            && self.lu.as_mut().is_some_and(|lu| {
                lu.factor(&self.assembler.matrix).is_ok()
                    && lu.solve_in_place(&mut self.rhs).is_ok()
            });
        // translations weighted to balance rotations in this predictor
        let (mut nx, mut nth) = (0.0f64, 0.0f64);
        for (eq, v) in self.rhs.iter().enumerate() {
            match self.dofs.equation_kind(eq) {
                DofKind::Translation => nx += v * v,
                DofKind::Rotation => nth += v * v,
                DofKind::Coordinate { .. } | DofKind::Multiplier(_) => {}
            }
        }
        self.translation_weight = if ok && nx > 0.0 && nth > 0.0 && (nth / nx).is_finite() {
            (nth / nx).sqrt()
        } else {
            1.0
        };
        let w = self.arc_weights();
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
    /// equation), which sets the predictor's sign and the root of the
    /// constraint; it is replaced by this increment.
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
        let n = self.dofs.n_equations();
        let w = self.arc_weights();
        let wdot = |a: &[f64], b: &[f64]| -> f64 {
            a.iter()
                .zip(b)
                .zip(&w)
                .map(|((x, y), w)| x * y * w * w)
                .sum()
        };
        self.step.fill(0.0);
        self.fresh = false;
        let mut qt = vec![0.0; n];
        let mut qt_sol = vec![0.0; n];
        let mut r0 = Vec::new();
        let mut progress = Progress::default();
        if direction.len() != n {
            direction.clear();
            direction.resize(n, 0.0);
        }
        // the previous increment, if any, tells forward from backward
        let has_direction = wdot(direction, direction) > 0.0;
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
                // an increment that turned back retraces the path
                if has_direction && wdot(&self.step, direction) < 0.0 {
                    return Err(NewtonFailure::PathReversed { iteration });
                }
                direction.copy_from_slice(&self.step);
                return Ok(NewtonResult {
                    iterations: iteration,
                    residuals: progress.residuals,
                });
            }

            // q_t: K q_t = −∂r/∂t, and q_r: K q_r = −r, one factorisation
            self.load_derivative(model, state, *t, &mut r0, &mut qt);
            if self.solve_linear_system().is_err() {
                return Err(self.diagnose(model, state, *t, iteration));
            }
            self.check_divergence(&mut progress, iteration)?;
            qt_sol.iter_mut().zip(&qt).for_each(|(x, q)| *x = -q);
            let solved = self
                .lu
                .as_mut()
                .expect("factored above")
                .solve_in_place(&mut qt_sol);
            if solved.is_err() {
                return Err(self.diagnose(model, state, *t, iteration));
            }
            self.tangent_checked = true;
            let dt = if iteration == 0 {
                // predictor along the tangent, in the direction of the last
                // increment (forward at the first)
                let norm = wdot(&qt_sol, &qt_sol).sqrt();
                if !(norm > 0.0 && norm.is_finite()) {
                    return Err(self.diagnose(model, state, *t, iteration));
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
                    wdot(&self.step, &self.step),
                    wdot(&self.step, &self.rhs),
                    wdot(&self.rhs, &self.rhs),
                );
                let (dq_t, qr_t, bb) = (
                    wdot(&self.step, &qt_sol),
                    wdot(&self.rhs, &qt_sol),
                    wdot(&qt_sol, &qt_sol),
                );
                if !(bb > 0.0 && bb.is_finite()) {
                    return Err(NewtonFailure::NoArcRoot { iteration });
                }
                let (aa, ab) = (dd + 2.0 * dr + rr, dq_t + qr_t);
                let disc = ab * ab - bb * (aa - arc * arc);
                if disc < 0.0 {
                    // no real root (the correction of the residual reaches
                    // out of the cylinder, typically the stretching of
                    // stiff members after a turn): the increment of closest
                    // approach, minimising ‖a + δt q_t‖; later iterations
                    // come back to the arc
                    progress.closest_approaches += 1;
                    self.closest_approach_count += 1;
                    if progress.closest_approaches > MAX_CLOSEST_APPROACHES {
                        return Err(NewtonFailure::NoArcRoot { iteration });
                    }
                    -ab / bb
                } else {
                    let roots = [(-ab + disc.sqrt()) / bb, (-ab - disc.sqrt()) / bb];
                    // the root whose increment goes on along the path:
                    // largest (a + δt q_t)·d, with d the previous increment
                    // (the current one in the first increment)
                    let (along, along_t) = if has_direction {
                        (
                            wdot(&self.step, direction) + wdot(&self.rhs, direction),
                            wdot(&qt_sol, direction),
                        )
                    } else {
                        (dd + dr, dq_t)
                    };
                    if along + roots[0] * along_t >= along + roots[1] * along_t {
                        roots[0]
                    } else {
                        roots[1]
                    }
                }
            };
            for (r, q) in self.rhs.iter_mut().zip(&qt_sol) {
                *r += dt * q;
            }
            *t += dt;
            let (dx, dth) = correction_size(&self.dofs, &self.rhs);
            if !(dx <= RUNAWAY_CORRECTION * self.free_size && dth <= RUNAWAY_CORRECTION) {
                return Err(self.diagnose(model, state, *t, iteration));
            }
            state.time = *t;
            self.update(state);
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
        self.newton_sign = None;
        lu.factor(&self.assembler.matrix)?;
        if lu.kernel() != LuKernel::Supernodal {
            // read off the factors: a pass over them, no more
            self.newton_sign = self.determinant.of(lu, &self.assembler.matrix);
        }
        lu.solve_in_place(&mut self.rhs)
    }

    /// Sign of the determinant of the tangent after a converged solve
    /// (docs/theory.md §9): that of the last Newton system factored (at
    /// the last iterate but one, within the tolerances of the converged
    /// state) with the simplicial kernel; with the supernodal kernel, that
    /// of the tangent assembled at the converged state, factored once more
    /// by the simplicial kernel, below 5,000 unknowns only (`None` above:
    /// [`DeterminantSign`]).
    pub fn tangent_sign(&mut self) -> Option<f64> {
        let lu = self.lu.as_ref()?;
        match lu.kernel() {
            LuKernel::Simplicial | LuKernel::Dense => self.newton_sign,
            LuKernel::Supernodal => self.determinant.of(lu, &self.assembler.matrix),
        }
    }

    /// `‖r‖₂` over the free translation equations of the last assembly.
    fn translation_residual(&self) -> f64 {
        (0..self.dofs.n_equations())
            .map(|eq| self.dofs.dof(eq))
            .filter(|&d| self.dofs.kind(d) == DofKind::Translation)
            .map(|d| self.assembler.residual[d].powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// `‖v‖₂` over the translation dofs of `v` (by dof, fixed ones
    /// included).
    fn translation_norm_dofs(&self, v: &[f64]) -> f64 {
        v.iter()
            .enumerate()
            .filter(|&(d, _)| self.dofs.kind(d) == DofKind::Translation)
            .map(|(_, x)| x * x)
            .sum::<f64>()
            .sqrt()
    }

    /// `‖v‖₂` over the translation equations of `v` (by equation).
    fn translation_norm(&self, v: &[f64]) -> f64 {
        v.iter()
            .enumerate()
            .filter(|&(eq, _)| self.dofs.kind(self.dofs.dof(eq)) == DofKind::Translation)
            .map(|(_, x)| x * x)
            .sum::<f64>()
            .sqrt()
    }

    /// Whether an equation is held in a translation iteration: rotations,
    /// and multipliers of constraints on angles (whose gradients lie in the
    /// rotations).
    fn held(&self, eq: usize) -> bool {
        matches!(
            self.dofs.equation_kind(eq),
            DofKind::Rotation | DofKind::Multiplier(ConstraintKind::Angle)
        )
    }

    /// Translation iteration (docs/theory.md §7.2): solves the last
    /// assembled system with the rotations (and the multipliers of angular
    /// constraints) held, `K_xx Δx = −r_x`, into `self.rhs`. The tangent is
    /// overwritten (rows and columns of held equations replaced by the
    /// identity); the next assembly restores it.
    fn solve_translations(&mut self) -> Result<(), SolveError> {
        if self.held_entries.is_none() {
            let (mut off, mut diagonal) = (Vec::new(), Vec::new());
            for (k, (row, col, _)) in self.assembler.matrix.entries().enumerate() {
                if self.held(row) || self.held(col) {
                    if row == col {
                        diagonal.push(k);
                    } else {
                        off.push(k);
                    }
                }
            }
            self.held_entries = Some((off, diagonal));
        }
        let (off, diagonal) = self.held_entries.as_ref().expect("set above");
        let values = self.assembler.matrix.values_mut();
        for &k in off {
            values[k] = 0.0;
        }
        for &k in diagonal {
            values[k] = 1.0;
        }
        for eq in 0..self.rhs.len() {
            self.rhs[eq] = if self.held(eq) {
                0.0
            } else {
                -self.assembler.residual[self.dofs.dof(eq)]
            };
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

    /// Explains a failed or runaway solve of the system assembled at
    /// `state` and `time`: non-finite input (naming its origin), singular
    /// (with the dof), or a non-finite solution.
    fn diagnose(&self, model: &Model, state: &State, time: f64, iteration: usize) -> NewtonFailure {
        let matrix = &self.assembler.matrix;
        if !(matrix.values().iter().all(|v| v.is_finite())
            && self.assembler.residual.iter().all(|v| v.is_finite()))
        {
            return self.non_finite(model, state, time, iteration);
        }
        match smallest_relative_pivot(matrix) {
            Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => NewtonFailure::Singular {
                dof: self.dof_label(model, self.dofs.dof(eq)),
                pivot,
            },
            _ => NewtonFailure::NonFinite {
                iteration,
                origin: "in the solution of the linear system (a nearly singular tangent)".into(),
            },
        }
    }

    /// Applies the correction in `self.rhs` to `state` (the update rule
    /// of [`State::update`]) and adds it to the increment's sum
    /// `self.step`.
    fn update(&mut self, state: &mut State) {
        for (s, d) in self.step.iter_mut().zip(&self.rhs) {
            *s += d;
        }
        state.update(&self.dofs, &self.rhs);
    }
}

/// What the iterations of one solve have seen so far.
#[derive(Default)]
struct Progress {
    /// Relative residual at each evaluation.
    residuals: Vec<f64>,
    /// `(max|Δx|, max|ΔΘ|)` of the last correction.
    last_correction: Option<(f64, f64)>,
    /// Arc-length iterations whose constraint had no real root.
    closest_approaches: usize,
    /// Work `|r·Δq|` of the first iteration (divergence reference).
    first_work: Option<f64>,
}

/// `(max|Δx|, max|ΔΘ|)` of a correction, coordinates counted as the
/// displacements they make (times their length); multipliers (forces) are
/// not motions.
fn correction_size(dofs: &DofMap, delta: &[f64]) -> (f64, f64) {
    let (mut dx, mut dth) = (0.0f64, 0.0f64);
    for (eq, &d) in delta.iter().enumerate() {
        let a = if d.is_finite() {
            d.abs()
        } else {
            f64::INFINITY
        };
        match dofs.equation_kind(eq) {
            DofKind::Translation => dx = dx.max(a),
            DofKind::Rotation => dth = dth.max(a),
            DofKind::Coordinate { length } => dx = dx.max(a * length),
            DofKind::Multiplier(_) => {}
        }
    }
    (dx, dth)
}

/// `sⱼ`, the size of the value of unknown `dof` (docs/theory.md §7.1):
/// `|x| + ℓ` for a translation, 1 rad for a rotation, the magnitude of a
/// coordinate or multiplier.
fn unknown_size(dofs: &DofMap, node_lengths: &[f64], state: &State, dof: usize) -> f64 {
    match dofs.kind(dof) {
        DofKind::Translation => state.x[dof / 6].norm() + node_lengths[dof / 6],
        DofKind::Rotation => 1.0,
        DofKind::Coordinate { .. } => state.coordinates[dof - dofs.first_coordinate()].abs(),
        DofKind::Multiplier(_) => state.multipliers[dof - dofs.first_multiplier()].abs(),
    }
}

/// `ℓₙ` of every node: the largest reference distance to another node of
/// one of its elements (0 for a node whose elements all have one node).
fn node_lengths(model: &Model) -> Vec<f64> {
    let mut lengths = vec![0.0f64; model.n_nodes()];
    for e in &model.elements {
        let nodes = e.nodes();
        for &a in nodes {
            for &b in nodes {
                let d = (model.reference_x[a] - model.reference_x[b]).norm();
                lengths[a] = lengths[a].max(d);
            }
        }
    }
    lengths
}

/// Diagonal of the bounding box of the nodes that have a free translation
/// (the model's length scale if there are none).
fn free_size(model: &Model, dofs: &DofMap) -> f64 {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for (node, x) in model.reference_x.iter().enumerate() {
        if (0..3).any(|c| dofs.equation(6 * node + c) != NO_EQUATION) {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
    }
    let d = (hi - lo).norm();
    if d > 0.0 && d.is_finite() {
        d
    } else {
        model.length_scale
    }
}

/// Where non-finite values come from at `state` and `time`: a curve, the
/// gravity, a node's position or orientation, a coordinate or multiplier,
/// or the
/// first element whose residual or tangent is not finite, each element
/// evaluated again on its own.
pub(crate) fn non_finite_origin(model: &Model, state: &State, time: f64) -> String {
    for c in &model.curves {
        let v = c.value(time);
        if !v.is_finite() {
            return format!("in curve \"{}\" ({v} at t = {time})", c.name());
        }
    }
    if !model.gravity_at(time).iter().all(|g| g.is_finite()) {
        return format!("in the gravity at t = {time}");
    }
    for (node, (x, q)) in state.x.iter().zip(&state.q).enumerate() {
        if !(x.iter().all(|v| v.is_finite()) && q.coords.iter().all(|v| v.is_finite())) {
            return format!("in the position of node {}", model.node_ids[node]);
        }
    }
    let ctx = model.context(time, Need::STIFFNESS);
    let (mut residual, mut tangent) = (Vec::new(), Vec::new());
    for e in &model.elements {
        let n = e.n_local();
        residual.clear();
        residual.resize(n, 0.0);
        tangent.clear();
        tangent.resize(n * n, 0.0);
        e.evaluate(
            &ctx,
            state,
            &mut ElementOutput::with_stiffness(&mut residual, &mut tangent),
        );
        let what = if !residual.iter().all(|v| v.is_finite()) {
            "residual"
        } else if !tangent.iter().all(|v| v.is_finite()) {
            "tangent"
        } else {
            continue;
        };
        return format!("in the {what} of {} {}", e.kind().name(), e.id());
    }
    for (i, e) in model.elements.iter().enumerate() {
        let o = model.offsets(i);
        let (nc, nm) = (e.n_coordinates(), e.n_multipliers());
        let mut values = state.coordinates[o.coordinates..o.coordinates + nc]
            .iter()
            .chain(&state.multipliers[o.multipliers..o.multipliers + nm]);
        if let Some(k) = values.position(|v| !v.is_finite()) {
            return format!("in unknown {} of {} {}", k + 1, e.kind().name(), e.id());
        }
    }
    "in the assembled system".into()
}
