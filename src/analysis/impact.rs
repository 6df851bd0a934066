//! Latches locking during a dynamic analysis (docs/theory.md §16,
//! docs/joints.md §6.2): the events that land a time step on a lock, and the
//! impact of the lock.
//!
//! A latch is watched through its event function `g = s (c − c_L)`
//! ([`LatchEvent`]); the step controller lands a step on `g = 0`. When an
//! accepted step has brought an open latch from `g < 0` to `g ≥ −tol`, the
//! latch locks, and the velocities jump as in a perfectly plastic impact
//! (the reference paper's treatment of a lock: momentum conserved, the
//! velocity jump computed explicitly; Pfeiffer & Glocker 1996, ch. 5):
//!
//! ```text
//! [ M   −kBᵀ ] [ Δv ]   [ 0      ]
//! [ −kB   0  ] [ π  ] = [ k Φ̇⁻  ],      Φ̇⁻ = B v⁻ + ∂Φ/∂t,
//! ```
//!
//! `M` the assembled mass matrix, `B` the gradients of the newly locked
//! coordinate (`Φ̇⁻ = ċ⁻`) and of the constraints already active, `kπ` the
//! impulses: after the impact every constraint holds at velocity level,
//! `Φ̇⁺ = 0`. Then `v⁺ = v⁻ + Δv`, the energy lost is `½ Δvᵀ M Δv`, equal
//! to `T⁻ − T⁺` when no constraint depends on time (I3 of docs/theory.md
//! §16), momentum is conserved (the impulses are internal), and the
//! integrator restarts from the post-impact state with consistent
//! accelerations (D9).

use super::control::EventFunction;
use super::dynamics::{constraint_rates, DynamicError};
use super::energy;
use super::newton::{NewtonSolver, SINGULAR_PIVOT};
use crate::dofs::{DofKind, NO_EQUATION};
use crate::elements::{ConstraintKind, Element, EvalContext, Need};
use crate::joints::latch::EVENT_TOLERANCE;
use crate::joints::Latch;
use crate::linalg::{smallest_relative_pivot, SparseLu};
use crate::model::{Id, Model};
use crate::state::State;

/// Unknowns whose diagonal mass is below this fraction of the largest of
/// their kind have no mass (as for the initial accelerations, D9).
const MASSLESS: f64 = 1e-12;

/// Entries of a latch's gradient below this (relative to its largest)
/// do not load an unknown.
const NEGLIGIBLE_GRADIENT: f64 = 1e-12;

/// A latch that locked during a dynamic analysis ([`super::Observer::lock`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LockInfo {
    /// The step that landed on the lock.
    pub increment: usize,
    /// Time of the lock.
    pub time: f64,
    /// The latch.
    pub latch: Id,
    /// The joint whose coordinate it locks.
    pub joint: Id,
    /// The coordinate at the lock (within the event tolerance of `c_L`).
    pub coordinate: f64,
    /// `ċ⁻`: the coordinate's rate just before the lock.
    pub rate_before: f64,
    /// `kπ`: the impulse of the lock along the coordinate (N·m·s for an
    /// angle, N·s for a length), opposed to the approach.
    pub impulse: f64,
    /// `½ Δvᵀ M Δv`: the energy the impact dissipates. Latches that lock
    /// in the same step share one impact and report its whole loss.
    pub energy_lost: f64,
    /// `T⁻ − T⁺`, the drop of the kinetic energy (equal to
    /// [`Self::energy_lost`] up to round-off).
    pub kinetic_energy_drop: f64,
}

/// `|g|` at or below which a step has landed on `latch`'s lock.
pub fn event_tolerance(model: &Model, latch: &Latch) -> f64 {
    if latch.is_angle() {
        EVENT_TOLERANCE
    } else {
        EVENT_TOLERANCE * model.length_scale
    }
}

/// The event function of a latch: `g = s (c − c_L)` while it is open, 1
/// once locked (no more events).
pub struct LatchEvent {
    element: usize,
    name: String,
    tolerance: f64,
}

impl EventFunction for LatchEvent {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn value(&self, model: &Model, state: &State) -> f64 {
        match model.elements[self.element].as_latch() {
            Some(l) if !l.is_locked(state) => l.gap(state),
            _ => 1.0,
        }
    }
    fn tolerance(&self) -> f64 {
        self.tolerance
    }
}

/// The event functions of the model's latches.
pub fn latch_events(model: &Model) -> Vec<Box<dyn EventFunction>> {
    let mut events: Vec<Box<dyn EventFunction>> = Vec::new();
    for (element, e) in model.elements.iter().enumerate() {
        if let Some(l) = e.as_latch() {
            events.push(Box::new(LatchEvent {
                element,
                name: format!("latch {}", e.id()),
                tolerance: event_tolerance(model, l),
            }));
        }
    }
    events
}

/// Locks, without impact, the open latches of `state` that are at their
/// value (within the event tolerance): the start of a dynamic analysis.
/// The initial velocities are then checked against them (D10).
pub fn lock_at_start(model: &Model, state: &mut State) {
    for e in &model.elements {
        if let Some(l) = e.as_latch() {
            if !l.is_locked(state) && l.gap(state).abs() <= event_tolerance(model, l) {
                l.lock(state);
            }
        }
    }
}

/// What [`lock_latches`] did.
pub struct Impact {
    /// The latches locked.
    pub locks: Vec<LockInfo>,
    /// Constraint equations found redundant by the rank analysis that
    /// followed the change of the active set.
    pub redundant: usize,
}

/// Locks the open latches that the step from `before` to `state` brought
/// to their value from the side of approach (`g` from below `−tol` to at
/// least `−tol`), runs the rank analysis of the constraints again, and
/// applies the impact (see the module documentation) to the velocities of
/// `state`. `None` if no latch locked. The accelerations are left to the
/// caller (D9 at the post-impact state).
pub fn lock_latches(
    model: &Model,
    solver: &mut NewtonSolver,
    before: &State,
    state: &mut State,
    increment: usize,
    end_time: f64,
) -> Result<Option<Impact>, DynamicError> {
    // the latches reached, with ċ⁻ and B_L
    let mut reached: Vec<(&Latch, f64, Vec<f64>)> = Vec::new();
    for e in &model.elements {
        let Some(l) = e.as_latch() else { continue };
        if l.is_locked(state) {
            continue;
        }
        let tol = event_tolerance(model, l);
        if l.gap(before) < -tol && l.gap(state) >= -tol {
            let (rate, grad) = l.rate(state);
            reached.push((l, rate, grad));
        }
    }
    if reached.is_empty() {
        return Ok(None);
    }
    let time = state.time;
    let names = || {
        reached
            .iter()
            .map(|(l, ..)| format!("latch {}", l.id()))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let kinetic_before = energy::energies(model, state).kinetic;
    for (l, ..) in &reached {
        l.lock(state);
    }

    // the active set changed: rank analysis again
    let rank = solver.constraint_rank(model, state, time);
    for &k in &rank.redundant {
        state.multipliers[k] = 0.0;
    }
    // −k Φ̇⁻ of every constraint (drivers' and prescribed motions' rates
    // included)
    let (rates, _) = constraint_rates(model, solver, state, end_time);

    // the mass matrix M and the constraint rows −kB at the lock
    let (dofs, assembler, lu) = solver.system();
    let mut stiffness = assembler.matrix.clone();
    let mut mass = assembler.matrix.clone();
    let ctx = EvalContext {
        dynamics: true,
        ..model.context(time, Need::with_inertia(0.0, 1.0))
    };
    assembler.assemble_split(model, &ctx, state, &mut stiffness, &mut mass);
    let n = dofs.n_equations();
    let mut diagonal = vec![0.0; n];
    for (row, col, v) in mass.entries() {
        if row == col {
            diagonal[row] = v;
        }
    }
    let mut scale = [0.0f64; 2];
    for (eq, &m) in diagonal.iter().enumerate() {
        match dofs.equation_kind(eq) {
            DofKind::Translation | DofKind::Coordinate { .. } => scale[0] = scale[0].max(m),
            DofKind::Rotation => scale[1] = scale[1].max(m),
            DofKind::Multiplier(_) => {}
        }
    }
    let light: Vec<bool> = (0..n)
        .map(|eq| match dofs.equation_kind(eq) {
            DofKind::Translation | DofKind::Coordinate { .. } => {
                diagonal[eq] <= MASSLESS * scale[0]
            }
            DofKind::Rotation => diagonal[eq] <= MASSLESS * scale[1],
            DofKind::Multiplier(_) => false,
        })
        .collect();

    // the latches' multiplier equations (NO_EQUATION if redundant)
    let latch_rows: Vec<usize> = reached
        .iter()
        .map(|(l, ..)| dofs.equation(dofs.first_multiplier() + l.multiplier()))
        .collect();
    let is_multiplier: Vec<bool> = (0..n)
        .map(|eq| matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)))
        .collect();
    // unknowns without mass held by a constraint other than the new locks
    // (a hinge node glued to its body): the constraints carry the impulse
    let mut held = vec![false; n];
    for (row, col, v) in stiffness.entries() {
        if v != 0.0 && light[row] && is_multiplier[col] && !latch_rows.contains(&col) {
            held[row] = true;
        }
    }

    // an impulse on an unknown without mass that nothing else holds has no
    // finite answer
    for (l, _, grad) in &reached {
        let largest = grad.iter().fold(0.0f64, |a, g| a.max(g.abs()));
        for (k, &node) in l.pair_nodes().iter().enumerate() {
            for c in 0..6 {
                let eq = dofs.equation(6 * node + c);
                if eq != NO_EQUATION
                    && light[eq]
                    && !held[eq]
                    && grad[6 * k + c].abs() > NEGLIGIBLE_GRADIENT * largest
                {
                    return Err(DynamicError::Impact {
                        latches: names(),
                        time,
                        reason: format!(
                            "the impulse of the lock acts on node {} ({}) which has no mass in that direction and no other constraint holds, so the velocity jump is not defined; give the bodies the latch joins their mass (rigid bodies, point masses or beams at the joint's nodes, or nodes glued to them)",
                            model.node_ids[node],
                            crate::model::COMPONENT_NAMES[c]
                        ),
                    });
                }
            }
        }
    }

    // the impact system, multiplier rows and columns scaled to the mass
    // (as D9); massless rows that no constraint holds take their stiffness
    // row (as D9: they follow quasi-statically)
    let k_of = |kind: ConstraintKind| model.scaling.of(kind).0;
    let s_eq: Vec<f64> = (0..n)
        .map(|eq| match dofs.equation_kind(eq) {
            DofKind::Multiplier(kind) => {
                let m = match kind {
                    ConstraintKind::Distance => scale[0],
                    ConstraintKind::Angle => scale[1],
                };
                if m > 0.0 {
                    m / k_of(kind)
                } else {
                    1.0
                }
            }
            _ => 1.0,
        })
        .collect();
    {
        let values = assembler.matrix.values_mut();
        let (k, m) = (stiffness.values(), mass.values());
        for (i, (row, col, _)) in stiffness.entries().enumerate() {
            let v = if is_multiplier[row] || is_multiplier[col] || (light[row] && !held[row]) {
                k[i] + m[i]
            } else {
                m[i]
            };
            values[i] = v * s_eq[row] * s_eq[col];
        }
    }
    // −k B Δv = k Φ̇⁻ on the constraint rows (the latches' ċ⁻ exact)
    let mut rhs: Vec<f64> = (0..n)
        .map(|eq| {
            if is_multiplier[eq] {
                -rates[dofs.dof(eq)] * s_eq[eq]
            } else {
                0.0
            }
        })
        .collect();
    for ((l, rate, _), &eq) in reached.iter().zip(&latch_rows) {
        if eq != NO_EQUATION {
            let k = l.scaling(&ctx).0;
            rhs[eq] = k * rate * s_eq[eq];
        }
    }
    let solved = (|| {
        if lu.is_none() {
            *lu = Some(SparseLu::analyze(&assembler.matrix)?);
        }
        let lu = lu.as_mut().expect("analysed above");
        lu.factor(&assembler.matrix)?;
        lu.solve_in_place(&mut rhs)
    })();
    if solved.is_err() || !rhs.iter().all(|v| v.is_finite()) {
        let what = match smallest_relative_pivot(&assembler.matrix) {
            Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => {
                format!(" (at {})", solver.dof_label(model, solver.dofs.dof(eq)))
            }
            _ => String::new(),
        };
        return Err(DynamicError::Impact {
            latches: names(),
            time,
            reason: format!(
                "the impact equations are singular{what}: the mass matrix is singular on the motion the lock's impulse excites (an unknown without mass that no constraint holds); give the bodies mass"
            ),
        });
    }

    // v⁺ = v⁻ + Δv; ½ ΔvᵀMΔv
    let dofs = &solver.dofs;
    let mut lost = 0.0;
    for (row, col, m) in mass.entries() {
        if !is_multiplier[row] && !is_multiplier[col] {
            lost += 0.5 * rhs[row] * m * rhs[col];
        }
    }
    for (eq, &dv) in rhs.iter().enumerate() {
        let d = dofs.dof(eq);
        if let Some((node, c)) = dofs.node_component(d) {
            state.velocity[node][c] += dv;
        } else if d < dofs.first_multiplier() {
            state.coordinate_rates[d - dofs.first_coordinate()] += dv;
        }
    }
    let kinetic_after = energy::energies(model, state).kinetic;
    let locks = reached
        .iter()
        .zip(&latch_rows)
        .map(|((l, rate, _), &eq)| LockInfo {
            increment,
            time,
            latch: l.id(),
            joint: l.joint(),
            coordinate: l.coordinate(state),
            rate_before: *rate,
            impulse: if eq == NO_EQUATION {
                0.0
            } else {
                l.scaling(&ctx).0 * rhs[eq] * s_eq[eq]
            },
            energy_lost: lost,
            kinetic_energy_drop: kinetic_before - kinetic_after,
        })
        .collect();
    Ok(Some(Impact {
        locks,
        redundant: rank.redundant.len(),
    }))
}
