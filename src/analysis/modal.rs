//! Modal analysis: undamped natural frequencies and mode shapes of the
//! model linearised about a state (docs/theory.md §14.7).
//!
//! The state is any state of the model: the reference configuration (a
//! first analysis), the static equilibrium reached by the analysis before
//! it in a sequence (a preloaded or deployed structure), or a state built
//! by a program. At that state and its time `t` one evaluation of every
//! element gives
//!
//! ```text
//! K = ∂r/∂q   (the static tangent: material and geometric stiffness,
//!              the constraint Hessians times the multipliers, follower loads)
//! M = ∂r/∂v̇   (the mass matrix of beams, rigid bodies and point masses)
//! ```
//!
//! on the numbering of the static analysis: supports and prescribed
//! motions have no equation, every joint and driver brings its multiplier
//! rows `B`, redundant constraints are left out after the rank analysis of
//! the constraints (docs/joints.md §5). The eigen-solvers of
//! [`crate::eigen`] then solve `K x + Bᵀ μ = ω² M x`, `B x = 0`.
//!
//! What is reported ([`NaturalMode`]):
//! - `ω²`, `ω` (rad/s) and `f = ω/2π` (Hz); rigid-body and mechanism modes
//!   have `ω² = 0` exactly (not an error), a configuration that is not
//!   stable gives negative `ω²` (`ω`, `f` then carry a minus sign);
//! - the shape at every node, six components `(u, θ)` in the global frame
//!   (a material rotation `ΔΘ` becomes `R ΔΘ`), **mass-normalised**:
//!   `xᵀ M x = 1`, the sign chosen so that its largest component is
//!   positive;
//! - the generalised mass `φᵀ M φ` of the shape `φ` scaled to a largest
//!   nodal translation of 1 (a largest rotation of 1 for a mode without
//!   translation), and the effective masses `(xᵀ M r_d)²` along the
//!   global axes `d`, with `r_d` the unit translation of every node along
//!   `d` at its free unknowns (for a free structure they add up to its
//!   mass over all modes).
//!
//! A model without mass is an error ([`ModalError::NoMass`]), as is a
//! pencil the solvers reject ([`ModalError::Eigen`]).

use std::sync::Arc;
use std::time::Instant;

use super::newton::NewtonSolver;
use super::settings::ModalSettings;
use super::Observer;
use crate::assembly::Assembler;
use crate::dofs::{DofKind, NO_EQUATION};
use crate::eigen::{self, EigenError, EigenSettings, Method, ModalSolution, Pencil};
use crate::elements::{EvalContext, Need};
use crate::model::Model;
use crate::so3::{self, Vec3};
use crate::state::State;

/// A state whose relative residual `‖r‖/‖flux‖` (over the unknowns'
/// equations) is above this is reported as not an equilibrium (an
/// [`Observer::note`]): its frequencies are those of the tangent there,
/// which differ from those of the motion about an equilibrium by the
/// unbalanced forces. A hundred times the default residual tolerance of
/// statics (1e-8), so a converged static state never triggers it.
pub const EQUILIBRIUM_TOLERANCE: f64 = 1e-6;

/// Why a modal analysis could not be made.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum ModalError {
    /// The mass matrix is zero.
    #[error("the model has no mass: give its beam sections a mass_per_length (and inertia_per_length), or add rigid bodies or point masses")]
    NoMass,
    /// The eigen-solver failed.
    #[error("eigen-solver: {0}")]
    Eigen(#[from] EigenError),
}

/// A natural mode of the linearised model.
#[derive(Clone, Debug, PartialEq)]
pub struct NaturalMode {
    /// `ω²` (rad²/s² in SI units); exactly 0 for a rigid-body or
    /// mechanism mode.
    pub omega_squared: f64,
    /// `ω` (rad/s), negative for a negative `ω²` (`−√|ω²|`).
    pub angular_frequency: f64,
    /// `f = ω/2π` (Hz), with the sign of `ω`.
    pub frequency: f64,
    /// `φᵀMφ` for the shape scaled to a largest nodal translation of 1
    /// (largest rotation of 1 when it has no translation).
    pub generalized_mass: f64,
    /// Effective masses along the global x, y, z axes, `(xᵀ M r_d)²` with
    /// the mass-normalised shape `x`.
    pub effective_mass: [f64; 3],
    /// Shape at every node, `[ux, uy, uz, θx, θy, θz]`, global frame,
    /// mass-normalised; zero at fixed components.
    pub shape: Vec<[f64; 6]>,
    /// Generalised coordinates of elements in the shape (sliders).
    pub coordinates: Vec<f64>,
    /// Relative residual `‖Kx + Bᵀμ − ω²Mx‖/‖Kx‖` of the eigen-solver.
    pub residual: f64,
}

impl NaturalMode {
    /// Whether this is a rigid-body or mechanism mode.
    pub fn is_zero(&self) -> bool {
        self.omega_squared == 0.0
    }
}

/// What a modal analysis did.
#[derive(Debug)]
pub struct ModalOutcome {
    /// The state it linearised about, unchanged (the start of the next
    /// analysis of a sequence).
    pub state: State,
    /// `t` of that state.
    pub time: f64,
    /// The modes, by increasing `ω²`.
    pub modes: Vec<NaturalMode>,
    /// How many of them are zero (rigid-body and mechanism modes).
    pub zero_modes: usize,
    /// Solver used.
    pub method: Method,
    /// Free unknowns (equations, multipliers included).
    pub unknowns: usize,
    /// Independent constraint equations.
    pub constraints: usize,
    /// Constraint equations left out as redundant.
    pub redundant_constraints: usize,
    /// Relative residual of the state (`‖r‖/‖flux‖` over the unknowns'
    /// equations): about zero at an equilibrium.
    pub equilibrium_residual: f64,
    /// Lanczos: solves with the factorised shifted matrix.
    pub operator_applications: usize,
    /// Wall-clock time in seconds.
    pub wall_time: f64,
    /// Why it failed, if it did (then `modes` is empty).
    pub error: Option<ModalError>,
}

/// A modal analysis of a model (see the module documentation).
pub struct ModalAnalysis {
    model: Arc<Model>,
    settings: ModalSettings,
    solver: NewtonSolver,
}

impl ModalAnalysis {
    /// Prepares the analysis of `model` with `settings`.
    pub fn new(model: impl Into<Arc<Model>>, settings: ModalSettings) -> Self {
        let model = model.into();
        let solver = NewtonSolver::new(&model);
        Self {
            model,
            settings,
            solver,
        }
    }

    /// The model.
    pub fn model(&self) -> &Arc<Model> {
        &self.model
    }

    /// The settings.
    pub fn settings(&self) -> &ModalSettings {
        &self.settings
    }

    /// Number of free unknowns (multipliers included).
    pub fn n_equations(&self) -> usize {
        self.solver.dofs.n_equations()
    }

    /// The numbering and the static solver it linearises with.
    pub fn solver(&self) -> &NewtonSolver {
        &self.solver
    }

    /// Whether `model` has mass on its free unknowns (in its reference
    /// configuration): without it a modal analysis fails with
    /// [`ModalError::NoMass`]. The check of `unfold check`.
    pub fn has_mass(model: &Model) -> bool {
        let dofs = crate::dofs::DofMap::new(model);
        let mut assembler = Assembler::new(model, &dofs);
        let (mut k, mut m) = (assembler.matrix.clone(), assembler.matrix.clone());
        let mut state = model.initial_state();
        model.apply_prescribed(&mut state, 0.0);
        let ctx = model.context(0.0, Need::with_inertia(0.0, 1.0));
        assembler.assemble_split(model, &ctx, &state, &mut k, &mut m);
        let multiplier: Vec<bool> = (0..dofs.n_equations())
            .map(|eq| matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)))
            .collect();
        has_mass(&m, &multiplier)
    }

    /// The modes of the model linearised about `start` (at its time).
    pub fn run(&mut self, start: State, observer: &mut dyn Observer) -> ModalOutcome {
        let started = Instant::now();
        let model = self.model.clone();
        let mut state = start;
        let t = state.time;
        model.apply_prescribed(&mut state, t);
        let mut outcome = ModalOutcome {
            state: State::default(),
            time: t,
            modes: Vec::new(),
            zero_modes: 0,
            method: self.settings.solver,
            unknowns: 0,
            constraints: 0,
            redundant_constraints: 0,
            equilibrium_residual: 0.0,
            operator_applications: 0,
            wall_time: 0.0,
            error: None,
        };

        // rank of the constraints: redundant ones out of the numbering
        let rank = self.solver.constraint_rank(&model, &state, t);
        for &k in &rank.redundant {
            state.multipliers[k] = 0.0;
        }
        if !rank.redundant.is_empty() {
            observer.note(&format!(
                "{} redundant constraint equation(s) left out of the modal analysis (over-constrained: joints, supports or drivers that repeat one another)",
                rank.redundant.len()
            ));
        }
        outcome.redundant_constraints = rank.redundant.len();
        let dofs = &self.solver.dofs;
        outcome.unknowns = dofs.n_equations();

        // stiffness and mass from one evaluation of every element
        let mut assembler = Assembler::new(&model, dofs);
        let (mut k, mut m) = (assembler.matrix.clone(), assembler.matrix.clone());
        let ctx: EvalContext = model.context(t, Need::with_inertia(0.0, 1.0));
        assembler.assemble_split(&model, &ctx, &state, &mut k, &mut m);
        let n = dofs.n_equations();
        let multiplier: Vec<bool> = (0..n)
            .map(|eq| matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)))
            .collect();

        // how far the state is from an equilibrium
        let (mut r2, mut f2) = (0.0, 0.0);
        for eq in (0..n).filter(|&eq| !multiplier[eq]) {
            let d = dofs.dof(eq);
            r2 += assembler.residual[d].powi(2);
            f2 += assembler.flux[d].powi(2);
        }
        outcome.equilibrium_residual = if f2 > 0.0 { (r2 / f2).sqrt() } else { 0.0 };
        if outcome.equilibrium_residual > EQUILIBRIUM_TOLERANCE {
            observer.note(&format!(
                "the state at t = {t} is not an equilibrium (relative residual {:.2e}): the frequencies are those of the tangent there",
                outcome.equilibrium_residual
            ));
        }

        // a model without mass has no modes
        let result = if has_mass(&m, &multiplier) {
            let pencil = Pencil {
                stiffness: &k,
                mass: &m,
                multiplier: &multiplier,
            };
            solve(&pencil, &self.settings, observer).map_err(ModalError::from)
        } else {
            Err(ModalError::NoMass)
        };
        match result {
            Ok(solution) => {
                outcome.method = solution.method;
                outcome.constraints = solution.constraint_rank;
                outcome.operator_applications = solution.operator_applications;
                outcome.modes = solution
                    .modes
                    .iter()
                    .map(|mode| natural_mode(&model, &self.solver, &state, &m, &multiplier, mode))
                    .collect();
                outcome.zero_modes = outcome.modes.iter().filter(|m| m.is_zero()).count();
            }
            Err(e) => outcome.error = Some(e),
        }
        outcome.state = state;
        outcome.wall_time = started.elapsed().as_secs_f64();
        outcome
    }
}

/// Whether the mass matrix has a non-zero diagonal entry on an unknown
/// (it is positive semi-definite: otherwise it is zero there).
fn has_mass(m: &crate::linalg::SparseMatrix, multiplier: &[bool]) -> bool {
    m.entries()
        .any(|(i, j, v)| i == j && !multiplier[i] && v != 0.0)
}

/// `ω² = (2π f)²` of a frequency in Hz.
fn omega_squared(frequency: f64) -> f64 {
    (2.0 * std::f64::consts::PI * frequency).powi(2)
}

/// The modes the settings ask for: the `modes` lowest, or nearest to the
/// shift, or the lowest `modes` in the frequency range.
fn solve(
    pencil: &Pencil,
    settings: &ModalSettings,
    observer: &mut dyn Observer,
) -> Result<ModalSolution, EigenError> {
    let range = settings.frequency_range;
    let shift = settings
        .shift
        .or(range.map(|r| r.0).filter(|&lo| lo > 0.0))
        .map(omega_squared);
    // the dense solver gives every mode: pick from all of them
    let n = pencil.multiplier.len();
    let dense = match settings.solver {
        Method::Dense => true,
        Method::Lanczos => false,
        Method::Auto => n <= eigen::DENSE_UNKNOWNS,
    };
    if dense && (range.is_some() || shift.is_some()) {
        let eigen = EigenSettings {
            method: Method::Dense,
            ..EigenSettings::lowest(n)
        };
        let mut all = match eigen::solve(pencil, &eigen) {
            Err(EigenError::TooManyModes { available, .. }) if available > 0 => eigen::solve(
                pencil,
                &EigenSettings {
                    modes: available,
                    ..eigen
                },
            )?,
            Err(EigenError::TooManyModes { .. }) => return Ok(no_modes(pencil, observer)),
            other => other?,
        };
        if range.is_none() {
            // the modes nearest to the shift, by increasing ω²
            let sigma = shift.unwrap_or(0.0);
            all.modes.sort_by(|a, b| {
                (a.omega_squared - sigma)
                    .abs()
                    .total_cmp(&(b.omega_squared - sigma).abs())
            });
            all.modes.truncate(settings.modes);
            all.modes
                .sort_by(|a, b| a.omega_squared.total_cmp(&b.omega_squared));
            all.zero_modes = all.modes.iter().filter(|m| m.is_zero()).count();
            return Ok(all);
        }
        return Ok(in_range(all, settings));
    }
    let mut wanted = settings.modes;
    loop {
        let eigen = EigenSettings {
            shift,
            method: settings.solver,
            ..EigenSettings::lowest(wanted)
        };
        let solution = match eigen::solve(pencil, &eigen) {
            Err(EigenError::TooManyModes { available, .. }) if available > 0 => {
                if range.is_none() {
                    observer.note(&format!(
                        "{} modes asked, the model has {available}: all of them are computed",
                        settings.modes
                    ));
                }
                let eigen = EigenSettings {
                    modes: available,
                    ..eigen
                };
                let all = eigen::solve(pencil, &eigen)?;
                if range.is_none() {
                    return Ok(all);
                }
                // every mode is there: keep those in the range
                return Ok(in_range(all, settings));
            }
            Err(EigenError::TooManyModes { .. }) => return Ok(no_modes(pencil, observer)),
            other => other?,
        };
        let Some((_, hi)) = range else {
            return Ok(solution);
        };
        let highest = solution.modes.last().map_or(0.0, |m| m.omega_squared);
        let kept = in_range(solution, settings);
        if kept.modes.len() >= settings.modes || highest > omega_squared(hi) {
            return Ok(kept);
        }
        // not far enough up yet: ask for twice as many
        wanted *= 2;
    }
}

/// The lowest `settings.modes` modes of `solution` in the frequency range.
fn in_range(mut solution: ModalSolution, settings: &ModalSettings) -> ModalSolution {
    if let Some((lo, hi)) = settings.frequency_range {
        let (lo, hi) = (omega_squared(lo), omega_squared(hi));
        solution
            .modes
            .retain(|m| m.omega_squared >= lo && m.omega_squared <= hi);
        solution.modes.truncate(settings.modes);
        solution.zero_modes = solution.modes.iter().filter(|m| m.is_zero()).count();
    }
    solution
}

/// A mode of the eigen-solver in node components, with its masses.
fn natural_mode(
    model: &Model,
    solver: &NewtonSolver,
    state: &State,
    m: &crate::linalg::SparseMatrix,
    multiplier: &[bool],
    mode: &eigen::Mode,
) -> NaturalMode {
    let dofs = &solver.dofs;
    let n = dofs.n_equations();
    let mut x: Vec<f64> = mode.shape.clone();
    for (v, &is) in x.iter_mut().zip(multiplier) {
        if is {
            *v = 0.0;
        }
    }

    // sign: the largest component of the shape positive
    let largest = x
        .iter()
        .copied()
        .fold(0.0f64, |a, v| if v.abs() > a.abs() { v } else { a });
    if largest < 0.0 {
        x.iter_mut().for_each(|v| *v = -*v);
    }

    // node components, rotations to the global frame
    let value = |dof: usize| match dofs.equation(dof) {
        NO_EQUATION => 0.0,
        eq => x[eq],
    };
    let shape: Vec<[f64; 6]> = (0..model.n_nodes())
        .map(|i| {
            let u = Vec3::new(value(6 * i), value(6 * i + 1), value(6 * i + 2));
            let theta = so3::matrix(&state.q[i])
                * Vec3::new(value(6 * i + 3), value(6 * i + 4), value(6 * i + 5));
            [u.x, u.y, u.z, theta.x, theta.y, theta.z]
        })
        .collect();
    let first = dofs.first_coordinate();
    let coordinates = (first..dofs.first_multiplier()).map(value).collect();

    // generalised mass of the shape scaled to a unit largest translation
    // (rotation): xᵀMx = 1, so it is 1/s² for the scale s
    let size = |r: std::ops::Range<usize>| {
        shape
            .iter()
            .map(|s| (s[r.clone()].iter().map(|v| v * v).sum::<f64>()).sqrt())
            .fold(0.0f64, f64::max)
    };
    let scale = match size(0..3) {
        s if s > 0.0 => s,
        _ => size(3..6),
    };
    let generalized_mass = if scale > 0.0 {
        1.0 / (scale * scale)
    } else {
        0.0
    };

    // effective masses: (xᵀ M r_d)², r_d the unit translation along d
    let mut mx = vec![0.0; n];
    m.mul_vec(&x, &mut mx);
    let mut effective_mass = [0.0; 3];
    for (d, e) in effective_mass.iter_mut().enumerate() {
        let gamma: f64 = (0..model.n_nodes())
            .map(|i| match dofs.equation(6 * i + d) {
                NO_EQUATION => 0.0,
                eq => mx[eq],
            })
            .sum();
        *e = gamma * gamma;
    }
    NaturalMode {
        omega_squared: mode.omega_squared,
        angular_frequency: mode.angular_frequency(),
        frequency: mode.frequency(),
        generalized_mass,
        effective_mass,
        shape,
        coordinates,
        residual: mode.residual,
    }
}

/// The answer for a model with no motion left to vibrate (every unknown
/// with mass held by supports, joints, latches or drivers): no mode, said
/// in a note, as a legitimate result rather than an error.
fn no_modes(pencil: &Pencil, observer: &mut dyn Observer) -> ModalSolution {
    observer.note(
        "the model has no mode: every direction that carries mass is held by supports, joints, latches or drivers",
    );
    ModalSolution {
        modes: Vec::new(),
        zero_modes: 0,
        infinite_modes: None,
        constraint_rank: pencil.multiplier.len(),
        shift: 0.0,
        method: Method::Auto,
        operator_applications: 0,
        restarts: 0,
    }
}
