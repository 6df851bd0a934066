//! Nonlinear static analysis: Newton–Raphson over increments of the load
//! parameter `t`, with automatic cut-back and regrowth.
//!
//! 1. Equilibrium at `t = 0` (pretension, loads whose curves start at a
//!    non-zero value): increment 0.
//! 2. Each increment moves `t` by `Δt`, sets prescribed motions to their
//!    values at the new `t`, moves the free unknowns by the predictor (each
//!    node continues the motion of the last increment, docs/theory.md
//!    §7.3) and iterates to equilibrium.
//! 3. A failed increment (no convergence, divergence, singular tangent) is
//!    restarted from the last converged state with `Δt/2`; the analysis
//!    stops when `Δt` would fall below `min_increment`.
//! 4. After an increment converged in at most [`EASY_ITERATIONS`]
//!    iterations, `Δt` grows by [`GROWTH`], up to `max_increment`.
//!
//! Everything converged before a failure has already been passed to the
//! observer, so result files written so far stay valid.

use std::time::Instant;

use super::newton::{NewtonFailure, NewtonSolver};
use super::{CutbackInfo, IncrementInfo, Observer};
use crate::model::Model;
use crate::state::State;

/// Increments converged in this many iterations or fewer let `Δt` grow.
pub const EASY_ITERATIONS: usize = 5;
/// Growth factor of `Δt` after an easy increment.
pub const GROWTH: f64 = 1.5;
/// Reduction factor of `Δt` after a failed increment.
pub const CUTBACK: f64 = 0.5;

/// Why a static analysis stopped before `end_time`.
#[derive(Debug, thiserror::Error)]
pub enum StaticError {
    /// An increment failed with the smallest allowed step.
    #[error("no convergence at increment {increment} from t = {time:.6}: the step {step:.3e} failed and half of it would be below min_increment: {reason}")]
    Diverged {
        /// Increment that failed.
        increment: usize,
        /// Last converged load parameter.
        time: f64,
        /// Last step tried.
        step: f64,
        /// Last failure.
        reason: NewtonFailure,
    },
    /// Equilibrium could not be found in the initial configuration.
    #[error("no equilibrium in the initial configuration (t = 0): {0}")]
    Initial(NewtonFailure),
    /// A kinematic analysis whose joints and drivers leave motions free.
    #[error("the joints and drivers do not make the mechanism determinate: {free} motion(s) are left free (least constrained: {dofs}); add drivers or supports, or run a kinetostatic analysis")]
    Indeterminate {
        /// Number of free motions.
        free: usize,
        /// The least constrained unknowns.
        dofs: String,
    },
    /// Constraints removed as redundant turned out violated: they
    /// contradict the others.
    #[error("inconsistent constraints at t = {time:.6}: {constraint} was found redundant at the start but is now violated ({violation:.1e} × its tolerance); two joints or drivers impose incompatible motions")]
    Inconsistent {
        /// Load parameter.
        time: f64,
        /// The violated constraint.
        constraint: String,
        /// Violation relative to the tolerance.
        violation: f64,
    },
    /// Arc-length control used its increments before reaching `end_time`.
    #[error("arc-length control: end_time not reached in {increments} increments (t = {time:.6}); raise max_increments or the increment sizes")]
    ArcLengthLimit {
        /// Increments allowed.
        increments: usize,
        /// Load parameter reached.
        time: f64,
    },
    /// A result file could not be written.
    #[error("writing results: {0}")]
    Output(#[from] std::io::Error),
}

/// What a static analysis did.
#[derive(Debug)]
pub struct StaticOutcome {
    /// Last converged state.
    pub state: State,
    /// Converged increments after the initial equilibrium.
    pub increments: usize,
    /// Newton iterations in all converged increments (increment 0 included).
    pub iterations: usize,
    /// Newton iterations spent in failed attempts.
    pub wasted_iterations: usize,
    /// Number of cut-backs.
    pub cutbacks: usize,
    /// Translation corrections (docs/theory.md §7.2): one more assembly and
    /// factorisation each, besides the iterations.
    pub translation_corrections: usize,
    /// Arc-length iterations whose constraint had no real root and took
    /// the increment of closest approach (docs/theory.md §9).
    pub closest_approaches: usize,
    /// Constraint equations removed as redundant (docs/joints.md §5).
    pub redundant_constraints: usize,
    /// Load parameter reached.
    pub time: f64,
    /// Wall-clock time in seconds.
    pub wall_time: f64,
    /// `None` if `end_time` was reached.
    pub error: Option<StaticError>,
}

/// A nonlinear static analysis of a model.
pub struct StaticAnalysis<'m> {
    model: &'m Model,
    solver: NewtonSolver,
}

impl<'m> StaticAnalysis<'m> {
    /// Prepares the analysis: dof numbering, sparse pattern, buffers.
    pub fn new(model: &'m Model) -> Self {
        Self {
            model,
            solver: NewtonSolver::new(model),
        }
    }

    /// Number of free unknowns.
    pub fn n_equations(&self) -> usize {
        self.solver.dofs.n_equations()
    }

    /// The Newton solver (for inspection: dof numbering, residual).
    pub fn solver(&self) -> &NewtonSolver {
        &self.solver
    }

    /// Runs from the reference configuration to `end_time`.
    pub fn run(&mut self, observer: &mut dyn Observer) -> StaticOutcome {
        let mut outcome = self.run_increments(observer);
        outcome.translation_corrections = self.solver.translation_corrections();
        outcome.closest_approaches = self.solver.closest_approaches();
        outcome
    }

    /// The analysis proper (see [`StaticAnalysis::run`]).
    fn run_increments(&mut self, observer: &mut dyn Observer) -> StaticOutcome {
        let start = Instant::now();
        let model = self.model;
        let s = &model.settings;
        let mut state = model.initial_state();
        // the state is filled in by `finish`
        let mut outcome = StaticOutcome {
            state: State::default(),
            increments: 0,
            iterations: 0,
            wasted_iterations: 0,
            cutbacks: 0,
            translation_corrections: 0,
            closest_approaches: 0,
            redundant_constraints: 0,
            time: 0.0,
            wall_time: 0.0,
            error: None,
        };
        let finish = |mut o: StaticOutcome, state: State, error: Option<StaticError>| {
            o.state = state;
            o.error = error;
            o.wall_time = start.elapsed().as_secs_f64();
            o
        };

        // rank of the constraints: redundant ones out, determinacy
        model.apply_prescribed(&mut state, 0.0);
        let rank = self.solver.constraint_rank(model, &state);
        outcome.redundant_constraints = rank.redundant.len();
        if !rank.redundant.is_empty() {
            observer.note(&format!(
                "{} redundant constraint equation(s) removed (over-constrained loops); their multipliers are zero and the others carry the loads",
                rank.redundant.len()
            ));
        }
        if s.kinematic && rank.degrees_of_freedom() > 0 {
            let dofs: Vec<String> = rank
                .freedom
                .iter()
                .take(rank.degrees_of_freedom().min(6))
                .map(|&(d, _)| self.solver.dof_label(model, d))
                .collect();
            let error = StaticError::Indeterminate {
                free: rank.degrees_of_freedom(),
                dofs: dofs.join(", "),
            };
            return finish(outcome, state, Some(error));
        }

        // initial equilibrium, increment 0
        match self.solver.solve(model, s, &mut state, 0.0, 0, observer) {
            Ok(r) => {
                model.update_internal(&mut state);
                outcome.iterations += r.iterations;
                let info = IncrementInfo {
                    increment: 0,
                    time: 0.0,
                    step: 0.0,
                    iterations: r.iterations,
                    residuals: r.residuals,
                    output: true,
                };
                if let Err(e) = observer.increment(&info, model, &state, self.solver.residual()) {
                    return finish(outcome, state, Some(e.into()));
                }
            }
            Err(f) => return finish(outcome, state, Some(StaticError::Initial(f))),
        }

        if s.arc_length {
            let error = self.arc_length(&mut state, &mut outcome, observer);
            return finish(outcome, state, error);
        }

        let mut t = 0.0;
        let mut dt = s.initial_increment;
        let mut backup = state.clone();
        // the converged state before the last one, and the step between
        // them, for the predictor
        let mut previous: Option<(State, f64)> = None;

        let mut increment = 1;
        while t < s.end_time {
            // step, snapped to end_time when within round-off of it
            let mut step = dt.min(s.end_time - t);
            if s.end_time - (t + step) <= 1e-9 * s.end_time {
                step = s.end_time - t;
            }
            let t_new = t + step;
            backup.clone_from(&state);
            state.time = t_new;
            model.apply_prescribed(&mut state, t_new);
            // predictor: each node continues its last increment
            if let Some((p, last_step)) = &previous {
                self.solver
                    .predict(model, &mut state, p, step / last_step, t_new);
            }
            match self
                .solver
                .solve(model, s, &mut state, t_new, increment, observer)
            {
                Ok(r) => {
                    model.update_internal(&mut state);
                    if let Some((constraint, violation)) =
                        self.solver.violated_redundant(model, &state, s)
                    {
                        let error = StaticError::Inconsistent {
                            time: t_new,
                            constraint,
                            violation,
                        };
                        return finish(outcome, backup, Some(error));
                    }
                    t = if t_new >= s.end_time {
                        s.end_time
                    } else {
                        t_new
                    };
                    outcome.increments += 1;
                    outcome.iterations += r.iterations;
                    outcome.time = t;
                    let output = increment % s.output_every == 0 || t >= s.end_time;
                    let info = IncrementInfo {
                        increment,
                        time: t,
                        step,
                        iterations: r.iterations,
                        residuals: r.residuals,
                        output,
                    };
                    if let Err(e) = observer.increment(&info, model, &state, self.solver.residual())
                    {
                        return finish(outcome, state, Some(e.into()));
                    }
                    if r.iterations <= EASY_ITERATIONS {
                        dt = (dt * GROWTH).min(s.max_increment);
                    }
                    match &mut previous {
                        Some((p, last_step)) => {
                            p.clone_from(&backup);
                            *last_step = step;
                        }
                        None => previous = Some((backup.clone(), step)),
                    }
                    increment += 1;
                }
                Err(reason) => {
                    outcome.wasted_iterations += reason.iterations_spent();
                    state.clone_from(&backup);
                    let next = step * CUTBACK;
                    if next < s.min_increment {
                        return finish(
                            outcome,
                            state,
                            Some(StaticError::Diverged {
                                increment,
                                time: t,
                                step,
                                reason,
                            }),
                        );
                    }
                    outcome.cutbacks += 1;
                    observer.cutback(&CutbackInfo {
                        increment,
                        time: t,
                        failed_step: step,
                        next_step: next,
                        reason,
                    });
                    dt = next;
                }
            }
        }
        finish(outcome, state, None)
    }

    /// Arc-length path control (docs/theory.md §9) from the converged
    /// initial state: increments of a fixed arc length in the space of the
    /// unknowns, `t` found with them, until `t` reaches `end_time` (the
    /// last increment is then redone in load control to land on it).
    fn arc_length(
        &mut self,
        state: &mut State,
        outcome: &mut StaticOutcome,
        observer: &mut dyn Observer,
    ) -> Option<StaticError> {
        let model = self.model;
        let s = &model.settings;
        // the first arc: the tangent predictor of a load increment
        // initial_increment; its bounds scale like the load increments
        let arc0 = self
            .solver
            .tangent_arc(model, state, 0.0, s.initial_increment);
        let (arc_min, arc_max) = (
            arc0 * s.min_increment / s.initial_increment,
            arc0 * s.max_increment / s.initial_increment,
        );
        let mut arc = arc0;
        let mut direction = Vec::new();
        let mut t = 0.0;
        let mut backup = state.clone();
        let mut increment = 1;
        while increment <= s.max_increments {
            backup.clone_from(state);
            let (t_start, dir_backup) = (t, direction.clone());
            let mut result = self.solver.solve_arc(
                model,
                s,
                state,
                &mut t,
                arc,
                &mut direction,
                increment,
                observer,
            );
            if result.is_ok() && t >= s.end_time {
                // land on end_time with a load-controlled increment, from the
                // start of the increment or else from the arc's end; if
                // neither converges the arc is cut back like a failure
                let arc_end = state.clone();
                for start in [&backup, &arc_end] {
                    let mut landed = start.clone();
                    landed.time = s.end_time;
                    let solved =
                        self.solver
                            .solve(model, s, &mut landed, s.end_time, increment, observer);
                    match solved {
                        Ok(r) => {
                            *state = landed;
                            t = s.end_time;
                            result = Ok(r);
                            break;
                        }
                        Err(f) => {
                            outcome.wasted_iterations += f.iterations_spent();
                            result = Err(f);
                        }
                    }
                }
            }
            match result {
                Ok(r) => {
                    let step = t - t_start;
                    model.update_internal(state);
                    outcome.increments += 1;
                    outcome.iterations += r.iterations;
                    outcome.time = t;
                    let done = t >= s.end_time;
                    let info = IncrementInfo {
                        increment,
                        time: t,
                        step,
                        iterations: r.iterations,
                        residuals: r.residuals,
                        output: increment % s.output_every == 0 || done,
                    };
                    if let Err(e) = observer.increment(&info, model, state, self.solver.residual())
                    {
                        return Some(e.into());
                    }
                    if done {
                        return None;
                    }
                    if r.iterations <= EASY_ITERATIONS {
                        arc = (arc * GROWTH).min(arc_max);
                    }
                    increment += 1;
                }
                Err(reason) => {
                    outcome.wasted_iterations += reason.iterations_spent();
                    state.clone_from(&backup);
                    t = t_start;
                    direction = dir_backup;
                    let next = arc * CUTBACK;
                    if next < arc_min {
                        return Some(StaticError::Diverged {
                            increment,
                            time: t,
                            step: arc,
                            reason,
                        });
                    }
                    outcome.cutbacks += 1;
                    observer.cutback(&CutbackInfo {
                        increment,
                        time: t,
                        failed_step: arc,
                        next_step: next,
                        reason,
                    });
                    arc = next;
                }
            }
        }
        Some(StaticError::ArcLengthLimit {
            increments: s.max_increments,
            time: t,
        })
    }
}
