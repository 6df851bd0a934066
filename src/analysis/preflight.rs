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
use crate::elements::ElementKind;
use crate::linalg::{smallest_relative_pivot, SparseLu};
use crate::model::{Model, ModelWarning};

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
    if let Some(failure) = singular_direction(model, &solver) {
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
                        "equation {} is redundant with the joints and the other drivers at t = 0: the driver repeats or contradicts what they impose (an over-driven mechanism); if it contradicts them the run stops at its first increment (\"inconsistent constraints\"): remove the driver or free the motion it drives",
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
fn singular_direction(model: &Model, solver: &NewtonSolver) -> Option<NewtonFailure> {
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
        Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => Some(NewtonFailure::Singular {
            dof: solver.dof_label(model, solver.dofs.dof(eq)),
            pivot,
        }),
        _ => None,
    }
}
