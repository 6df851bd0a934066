//! The checks of a model that need no analysis: what `unfold check` runs
//! after the input is validated, and what the static analysis itself
//! checks before its first increment, with the same errors.
//!
//! 1. The rank of the constraints at the reference configuration
//!    (docs/joints.md §5): redundant constraint equations are counted, and
//!    a kinematic analysis whose joints and drivers leave motions free is
//!    rejected ([`StaticError::Indeterminate`]). A redundant equation of a
//!    driver is warned about: the driver either repeats what the joints
//!    and the other drivers impose (two drivers turning one axle through
//!    two hinges by the same angle) or contradicts it (an over-driven
//!    mechanism), which only the first increment tells: the analysis then
//!    stops ([`StaticError::Inconsistent`]).
//! 2. The initial stiffness: the tangent at `t = 0` is factored and solved
//!    for a probe load that acts on every unknown (the analysis's first
//!    correction acts only along the loads of `t = 0`, so a run with no
//!    load at the start finds a mechanism only later); a singular tangent
//!    (a mechanism in statics, a missing support) is named by node and
//!    component, as a run names it ([`StaticError::Initial`] with
//!    [`NewtonFailure::Singular`]), and so are non-finite values in the
//!    reference configuration.
//!
//! Equilibrium itself is not sought: that is the analysis.
//!
//! A run whose first analysis other than a modal one is dynamic is checked
//! by the start of that analysis instead ([`check_motion`]): the initial
//! velocities against the joints, latches, stops and rolling contacts
//! (docs/theory.md D10) and the consistent initial accelerations (D9),
//! which are its step 0 and need no time step.

use std::sync::Arc;

use super::dynamics::{DynamicAnalysis, DynamicError};
use super::newton::{NewtonFailure, NewtonSolver};
use super::observers::History;
use super::settings::{DynamicSettings, StaticSettings};
use super::statics::StaticError;
use crate::dofs::DofKind;
use crate::elements::{Element, ElementKind};
use crate::linalg::{smallest_relative_pivot, SparseLu};
use crate::model::{Model, ModelWarning};
use crate::state::State;

// the Newton solver's thresholds: a check reports what a run would
use super::newton::{non_finite_origin, RUNAWAY_CORRECTION, SINGULAR_PIVOT};

/// What the checks found in a sound model.
#[derive(Clone, Debug, PartialEq)]
pub struct Preflight {
    /// Free unknowns, redundant constraints included (as in the log of a
    /// run).
    pub unknowns: usize,
    /// Constraint equations that repeat others (removed by the analysis).
    pub redundant_constraints: usize,
    /// Motions the constraints leave free (to springs and beams in
    /// statics; none in a kinematic analysis).
    pub free_motions: usize,
    /// Input that is valid but probably not meant: a driver equation among
    /// the redundant ones.
    pub warnings: Vec<ModelWarning>,
}

/// Runs the checks of the module documentation on `model`, for the first
/// analysis of a run, with `settings`.
pub fn check(model: &Model, settings: &StaticSettings) -> Result<Preflight, StaticError> {
    let mut solver = NewtonSolver::new(model);
    let unknowns = solver.dofs.n_equations();
    let mut state = model.initial_state();
    model.apply_prescribed(&mut state, 0.0);

    // rank of the constraints, as StaticAnalysis::start
    let rank = solver.constraint_rank(model, &state, 0.0);
    let free = rank.degrees_of_freedom();
    if settings.kinematic && free > 0 {
        return Err(solver.indeterminate(model, &rank));
    }

    // residual and tangent at t = 0, then the tangent's response to a
    // probe load
    solver.assemble(model, &state, 0.0, true);
    if solver.residual().iter().any(|r| !r.is_finite()) {
        return Err(StaticError::Initial {
            time: 0.0,
            failure: NewtonFailure::NonFinite {
                iteration: 0,
                origin: non_finite_origin(model, &state, 0.0),
            },
        });
    }
    if let Some(failure) = singular_direction(model, &solver, &state) {
        return Err(StaticError::Initial { time: 0.0, failure });
    }
    Ok(Preflight {
        unknowns,
        redundant_constraints: rank.redundant.len(),
        free_motions: free,
        warnings: redundant_drivers(model, &rank.redundant),
    })
}

/// Runs the start of a dynamic analysis of `model` with `settings` from
/// the model's initial state, as a run whose first analysis (modal ones
/// aside) it is: latches and stops at their values locked or closed, the
/// initial velocities checked against every constraint, the initial
/// accelerations and multipliers solved for. Returns the number of free
/// unknowns, or the error with which the run would stop at `t = 0`.
pub fn check_motion(model: &Arc<Model>, settings: &DynamicSettings) -> Result<usize, DynamicError> {
    let mut analysis = DynamicAnalysis::new(model.clone(), settings.clone());
    let unknowns = analysis.n_equations();
    analysis.start(model.initial_state(), &mut History::new());
    match analysis.finish().error {
        Some(e) => Err(e),
        None => Ok(unknowns),
    }
}

/// A warning for each redundant equation (`redundant`: indices among the
/// multipliers) that belongs to a driver.
fn redundant_drivers(model: &Model, redundant: &[usize]) -> Vec<ModelWarning> {
    let mut warnings = Vec::new();
    for (k, e) in model.elements.iter().enumerate() {
        let (offset, n) = (model.offsets(k).multipliers, e.n_multipliers());
        if e.kind() == ElementKind::Driver {
            for &k in redundant.iter().filter(|&&k| k >= offset && k < offset + n) {
                warnings.push(ModelWarning {
                    entity: format!("driver {}", e.id()),
                    message: format!(
                        "equation {} is redundant with the joints and the other drivers at t = 0: the driver repeats or contradicts what they impose (an over-driven mechanism); if it contradicts them the run stops at the first increment where they disagree (\"inconsistent constraints\"): remove the driver or free the motion it drives",
                        k - offset + 1
                    ),
                });
            }
        }
    }
    warnings
}

/// Solves `K Δq = b` for a probe load `b` with every component of the size
/// of the tangent's diagonal (times the model size `L` for forces, zero on
/// constraint equations) and a pseudo-random sign and magnitude, so that
/// it has a component along any direction without stiffness. As in the
/// Newton solver, a correction beyond [`RUNAWAY_CORRECTION`] (`·L` for
/// translations) marks a singular tangent, confirmed and located by the
/// smallest relative pivot (below [`SINGULAR_PIVOT`]).
fn singular_direction(
    model: &Model,
    solver: &NewtonSolver,
    state: &State,
) -> Option<NewtonFailure> {
    let k = solver.tangent();
    let n = k.dim();
    if n == 0 {
        return None;
    }
    let length = model.length_scale;
    let kinds: Vec<DofKind> = (0..n).map(|eq| solver.dofs.equation_kind(eq)).collect();
    let mut probe: Vec<f64> = (0..n)
        .map(|eq| {
            let size = match kinds[eq] {
                DofKind::Translation => length,
                DofKind::Rotation => 1.0,
                DofKind::Coordinate { .. } | DofKind::Multiplier(_) => return 0.0,
            };
            let d = k.position(eq, eq).map_or(0.0, |p| k.values()[p].abs());
            let d = if d > 0.0 {
                d
            } else {
                k.column_max_abs(eq).max(1.0)
            };
            // a fixed sequence of factors in ±[0.5, 1.5] (Weyl sequence of
            // the golden ratio)
            let u = (eq as f64 * 0.618_033_988_749_895).fract();
            let factor = if eq % 3 == 1 { -0.5 - u } else { 0.5 + u };
            factor * d * size
        })
        .collect();
    let load = probe.clone();
    let solved = SparseLu::analyze(k).and_then(|mut lu| {
        lu.factor(k)?;
        lu.solve_in_place(&mut probe)
    });
    // (a non-finite correction runs away too)
    let within = |dq: f64, limit: f64| dq.is_finite() && dq.abs() <= limit;
    let runaway = solved.is_err()
        || probe.iter().zip(&kinds).any(|(&dq, kind)| match kind {
            DofKind::Translation => !within(dq, RUNAWAY_CORRECTION * length),
            DofKind::Rotation => !within(dq, RUNAWAY_CORRECTION),
            DofKind::Coordinate { .. } | DofKind::Multiplier(_) => false,
        });
    if !runaway {
        return None;
    }
    match smallest_relative_pivot(k) {
        Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => {
            let mut dof = solver.dof_label(model, solver.dofs.dof(eq));
            // the runaway correction is the free motion: the joints it
            // moves are those to look at (a hinge without spring), not
            // the unknown of the smallest pivot, often inside a member
            let finite = solved.is_ok() && probe.iter().all(|v| v.is_finite());
            let motion = if finite {
                Some(probe)
            } else {
                shifted_solve(k, load)
            };
            let joints = motion
                .map(|m| moving_joints(model, solver, state, &m))
                .unwrap_or_default();
            if !joints.is_empty() {
                dof = format!("{dof}, in a free motion that moves {}", joints.join(", "));
            }
            Some(NewtonFailure::Singular { dof, pivot })
        }
        _ => None,
    }
}

/// The joints whose coordinates ([`crate::joints::Joint::coordinates`])
/// the motion `direction` (by equation) moves, largest first, at most
/// [`FREE_JOINTS_NAMED`]: `direction` scaled to a turn of 1e-6 rad (or a
/// translation of 1e-6 of the model size) at its largest, a joint whose
/// coordinate changes by more than 1e-2 of that (in radians or model
/// sizes) is moved by it; a joint that holds its coordinate is not.
fn moving_joints(
    model: &Model,
    solver: &NewtonSolver,
    state: &State,
    direction: &[f64],
) -> Vec<String> {
    let length = model.length_scale;
    let dofs = &solver.dofs;
    let largest = direction
        .iter()
        .enumerate()
        .map(|(eq, d)| match dofs.equation_kind(eq) {
            DofKind::Translation => d.abs() / length,
            DofKind::Rotation => d.abs(),
            DofKind::Coordinate { length: l } => d.abs() * l / length,
            DofKind::Multiplier(_) => 0.0,
        })
        .fold(0.0f64, f64::max);
    if !(largest.is_finite() && largest > 0.0) {
        return Vec::new();
    }
    let e = 1e-6 / largest;
    let step: Vec<f64> = direction
        .iter()
        .enumerate()
        .map(|(eq, d)| match dofs.equation_kind(eq) {
            DofKind::Multiplier(_) => 0.0,
            _ => e * d,
        })
        .collect();
    let mut moved = state.clone();
    moved.update(dofs, &step);
    let mut found: Vec<(f64, String)> = Vec::new();
    let (mut before, mut after) = ([0.0; 3], [0.0; 3]);
    for j in model.elements.iter().filter_map(|el| el.as_joint()) {
        let n = j.joint_type().coordinates().len();
        j.coordinates(state, &mut before[..n]);
        j.coordinates(&moved, &mut after[..n]);
        let change = before[..n]
            .iter()
            .zip(&after[..n])
            .filter(|(b, a)| b.is_finite() && a.is_finite())
            .map(|(b, a)| (a - b).abs())
            .fold(0.0f64, f64::max);
        if change > 1e-2 * 1e-6 {
            found.push((change, format!("joint {}", j.id())));
        }
    }
    found.sort_by(|a, b| b.0.total_cmp(&a.0));
    found
        .into_iter()
        .take(FREE_JOINTS_NAMED)
        .map(|(_, name)| name)
        .collect()
}

/// `(K + σ D) Δq = b` with `D` the magnitude of each column's diagonal
/// (its largest entry where the diagonal is zero, the largest diagonal of
/// `K` where the column is zero) and `σ` = 1e-9: where `K` is singular to
/// working precision, the solution is dominated by its directions
/// without stiffness, which the shift makes finite.
fn shifted_solve(k: &crate::linalg::SparseMatrix, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let diagonal = |eq: usize| k.position(eq, eq).map_or(0.0, |p| k.values()[p].abs());
    let scale = (0..k.dim()).map(diagonal).fold(0.0f64, f64::max);
    let mut shifted = k.clone();
    for eq in 0..k.dim() {
        if let Some(p) = k.position(eq, eq) {
            let d = match diagonal(eq) {
                d if d > 0.0 => d,
                _ => match k.column_max_abs(eq) {
                    c if c > 0.0 => c,
                    _ => scale,
                },
            };
            shifted.values_mut()[p] += 1e-9 * d;
        }
    }
    let mut lu = SparseLu::analyze(&shifted).ok()?;
    lu.factor(&shifted).ok()?;
    lu.solve_in_place(&mut b).ok()?;
    b.iter().all(|v| v.is_finite()).then_some(b)
}

/// Joints named at most in the message of a singular tangent.
const FREE_JOINTS_NAMED: usize = 4;
