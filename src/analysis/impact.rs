//! Latches locking during a dynamic analysis (docs/theory.md §16,
//! docs/joints.md §6.2): the events that land a time step on a lock, and the
//! impact of the lock.
//!
//! A latch is watched through its event function `g = s (c − c_L)`
//! ([`LatchEvent`]); the step controller lands a step on `g = 0`. When an
//! accepted step has brought an open latch from `g < 0` to `g ≥ −tol`, the
//! latch locks, and the velocities jump as in a perfectly plastic impact
//! (the reference paper's treatment of a lock, §6.2: momentum conserved,
//! the velocity jump computed explicitly; Pfeiffer & Glocker 1996, ch. 5):
//!
//! ```text
//! [ M   −kBᵀ ] [ Δv ]   [ 0     ]
//! [ −kB   0  ] [ π  ] = [ k Φ̇⁻ ],      v⁺ = v⁻ + Δv,
//! ```
//!
//! `M` the assembled mass matrix, `B` the gradients of the constraints,
//! `kπ` the impulses, so that `Φ̇⁺ = 0`. For a latch's lock
//! ([`lock_latches`]) `Φ̇⁻ = ċ⁻` on the latch's row, the constraints
//! already active keeping their rates, which the projection of every
//! accepted step's velocities (D13) leaves at round-off; a stop's impact
//! ([`stop_events_at`]) is solved in two stages, the velocities made
//! consistent with the constraints active first. The energy lost is `½ Δvᵀ M Δv`
//! (Carnot's loss, docs/theory.md §16, LK3), momentum is conserved (the
//! impulses are internal), and the integrator restarts from the
//! post-impact state with consistent accelerations (D9).

use super::control::EventFunction;
use super::dynamics::{constraint_rates, DynamicError};
use super::energy;
use super::newton::{NewtonSolver, SINGULAR_PIVOT};
use crate::dofs::{DofKind, NO_EQUATION};
use crate::elements::{ConstraintKind, Element, EvalContext, Need};
use crate::joints::latch::{SpringEvent, EVENT_TOLERANCE};
use crate::joints::stop::Contact;
use crate::joints::{Latch, Stop};
use crate::linalg::{smallest_relative_pivot, SymmetricFirst};
use crate::model::{Id, Model};
use crate::state::State;

/// Unknowns whose diagonal mass is below this fraction of the largest of
/// their kind have no mass (as for the initial accelerations, D9).
const MASSLESS: f64 = 1e-12;

/// Entries of a latch's gradient below this (relative to its largest)
/// do not load an unknown.
const NEGLIGIBLE_GRADIENT: f64 = 1e-12;

/// What happened at a latch ([`LockInfo::kind`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LatchEventKind {
    /// The latch locked: a rigid latch's plastic impact, or a spring
    /// latch latching (no impact).
    #[default]
    Lock,
    /// A spring latch's load reached its unlatch load: it released.
    Unlatch,
    /// A latched spring latch's coordinate left its dead band across an
    /// edge beyond which its spring acts ([`super::Observer::band_crossing`]).
    Engage,
    /// It came back into the dead band: the spring no longer acts.
    Disengage,
    /// A spring latch released beyond `c_L` came back to `c_L`: it may
    /// lock again the next time it reaches it in the direction of
    /// approach.
    Rearm,
}

impl LatchEventKind {
    /// The name written in `events.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Lock => "lock",
            Self::Unlatch => "unlatch",
            Self::Engage => "engage",
            Self::Disengage => "disengage",
            Self::Rearm => "rearm",
        }
    }
}

/// A latch that locked (or a spring latch that released) during a dynamic
/// analysis ([`super::Observer::lock`]); or a spring latch's coordinate
/// crossing an edge of its dead band, or coming back to `c_L` after a
/// release beyond it ([`super::Observer::band_crossing`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LockInfo {
    /// What happened.
    pub kind: LatchEventKind,
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
    /// `ċ⁻`: the coordinate's rate just before the lock (with the
    /// velocities consistent with the other constraints).
    pub rate_before: f64,
    /// `ċ⁺`: its rate just after (0 after a rigid lock; unchanged by a
    /// spring latch's events).
    pub rate_after: f64,
    /// `kπ`: the impulse of the lock along the coordinate (N·m·s for an
    /// angle, N·s for a length), opposed to the approach (0 for a spring
    /// latch).
    pub impulse: f64,
    /// `½ Δvᵀ M Δv`: the energy the impact dissipates. Latches that lock
    /// in the same step share one impact and report its whole loss. For a
    /// spring latch that releases, the energy its spring held (it leaves
    /// the model with the latch); 0 when a spring latch latches.
    pub energy_lost: f64,
    /// `T⁻ − T⁺`, the drop of the kinetic energy: the energy lost (when
    /// no constraint depends on time), up to round-off.
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

/// The event function of a latch: for a rigid latch `g = s (c − c_L)`
/// while it is open, 1 once locked (no more events); for a spring latch
/// `(−1)ⁿ w` ([`Latch::watch`], [`Latch::watch_sign`]), with the tolerance 1.
pub struct LatchEvent {
    element: usize,
    name: String,
    tolerance: f64,
    rigid: bool,
}

impl EventFunction for LatchEvent {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn value(&self, model: &Model, state: &State) -> f64 {
        match model.elements[self.element].as_latch() {
            Some(l) if l.spring().is_some() => {
                l.watch_sign(state) * l.watch(state, event_tolerance(model, l))
            }
            Some(l) if !l.is_locked(state) => l.gap(state),
            _ => 1.0,
        }
    }
    fn tolerance(&self) -> f64 {
        self.tolerance
    }
    /// A rigid latch's `g = s (c − c_L)` follows the motion; a spring
    /// latch's watch jumps between ±1.
    fn anticipated(&self) -> bool {
        self.rigid
    }
    /// `ġ = s ċ` of an open rigid latch.
    fn rate(&self, model: &Model, state: &State) -> Option<f64> {
        match model.elements[self.element].as_latch() {
            Some(l) if self.rigid && !l.is_locked(state) => Some(l.gap_rate(state)),
            _ => None,
        }
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
                rigid: l.spring().is_none(),
                tolerance: if l.spring().is_some() {
                    1.0
                } else {
                    event_tolerance(model, l)
                },
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

/// Closes, without impact, the open stops of `state` that are at a limit
/// (within the event tolerance): the start of a dynamic analysis. A
/// contact whose consistent load then pulls opens at the end of the first
/// step (a release event).
pub fn close_at_start(model: &Model, state: &mut State) {
    for e in &model.elements {
        if let Some(s) = e.as_stop() {
            let (g, side) = s.gap(state);
            if s.contact(state) == Contact::Open && g.abs() <= gap_tolerance(model, s) {
                s.set_contact(state, side);
            }
        }
    }
}

/// The first stop or contact of `model` whose coordinate starts beyond its
/// limit by more than the event tolerance, as the error that stops the
/// analysis: a stop placed on the wrong side of the start (`upper` written
/// for `lower`), or bodies that a previous analysis left interpenetrating.
/// No impact law resolves such a start: a step would close the stop where
/// the coordinate is, not at its limit, or find an impact at every step.
pub fn beyond_limit_at_start(model: &Model, state: &State) -> Option<DynamicError> {
    model.elements.iter().find_map(|e| {
        let s = e.as_stop()?;
        let (g, side) = s.gap(state);
        if g >= -gap_tolerance(model, s) {
            return None;
        }
        let c = s.coordinate(state);
        let unit = if s.is_angle() { " rad" } else { "" };
        let detail = match s.joint() {
            Some(joint) => {
                let (name, limit) = match side {
                    Contact::Upper => ("upper", s.limit(Contact::Upper)),
                    _ => ("lower", s.limit(Contact::Lower)),
                };
                format!(
                    "the coordinate of joint {joint} is {c:.6e}{unit}, beyond the {name} limit {limit:.6e}{unit} by {:.3e}{unit}; a stop acts on a coordinate that starts within [lower, upper]: check which limit is meant (lower or upper) and the joint's reference",
                    -g
                )
            }
            None => format!(
                "its gap is {g:.3e} (the bodies interpenetrate); start the sphere(s) clear of the surface"
            ),
        };
        Some(DynamicError::StartsBeyondLimit {
            what: format!("{} {}", s.noun(), e.id()),
            time: state.time,
            detail,
        })
    })
}

/// What [`lock_latches`] did.
pub struct Impact {
    /// The latches locked.
    pub locks: Vec<LockInfo>,
    /// Constraint equations found redundant by the rank analysis that
    /// followed the change of the active set.
    pub redundant: usize,
    /// Work of the impulses through drivers and prescribed motions (zero
    /// when no constraint depends on time).
    pub work: f64,
}

/// The velocity jump of one impact system (see the module documentation).
struct Jump {
    /// The solution by equation: `Δv`, then `π` (unscaled) at the
    /// multiplier equations.
    solution: Vec<f64>,
    /// `½ Δvᵀ M Δv`.
    energy: f64,
}

/// Why an impact system has no answer.
enum Singular {
    /// An unknown without mass that nothing holds is struck: node,
    /// component.
    Massless(usize, usize),
    /// The system is singular (at this unknown, if found).
    System(String),
}

/// Solves the impact system at `state` with the solver's numbering:
/// `rhs(eq)` on the multiplier equations (`k Φ̇⁻` to cancel), `struck` the
/// multiplier equations of the latches locking (which hold nothing else)
/// with their gradients; applies `Δv` to the velocities of `state`.
fn jump(
    model: &Model,
    solver: &mut NewtonSolver,
    state: &mut State,
    rhs_of: &dyn Fn(usize, usize) -> f64,
    struck: &[(usize, &[usize], &[f64])],
) -> Result<Jump, Singular> {
    let time = state.time;
    let (dofs, assembler, factors) = solver.system();
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
    let is_multiplier: Vec<bool> = (0..n)
        .map(|eq| matches!(dofs.equation_kind(eq), DofKind::Multiplier(_)))
        .collect();
    let struck_rows: Vec<usize> = struck.iter().map(|s| s.0).collect();
    // unknowns without mass held by a constraint other than the new locks
    // (a hinge node glued to its body): the constraints carry the impulse
    let mut held = vec![false; n];
    for (row, col, v) in stiffness.entries() {
        if v != 0.0 && light[row] && is_multiplier[col] && !struck_rows.contains(&col) {
            held[row] = true;
        }
    }
    // an impulse on an unknown without mass that nothing else holds has no
    // finite answer
    for &(_, nodes, grad) in struck {
        let largest = grad.iter().fold(0.0f64, |a, g| a.max(g.abs()));
        for (k, &node) in nodes.iter().enumerate() {
            for c in 0..6 {
                let eq = dofs.equation(6 * node + c);
                if eq != NO_EQUATION
                    && light[eq]
                    && !held[eq]
                    && grad[6 * k + c].abs() > NEGLIGIBLE_GRADIENT * largest
                {
                    return Err(Singular::Massless(node, c));
                }
            }
        }
    }

    // multiplier rows and columns scaled to the mass (as D9); massless
    // rows that no constraint holds take their stiffness row (as D9: they
    // follow quasi-statically)
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
    let mut rhs: Vec<f64> = (0..n)
        .map(|eq| {
            if is_multiplier[eq] {
                rhs_of(eq, dofs.dof(eq)) * s_eq[eq]
            } else {
                0.0
            }
        })
        .collect();
    // symmetric (a mass matrix bordered by the constraint rows): its LDLᵀ,
    // checked to the backward error of a pivoted LU (linalg::symmetric),
    // costs a tenth of the LU's factorisation on the ERA platform
    let solved = (|| {
        if factors.is_none() {
            *factors = Some(SymmetricFirst::analyze(&assembler.matrix)?);
        }
        let factors = factors.as_mut().expect("analysed above");
        factors.factor(&assembler.matrix)?;
        factors.solve_in_place(&mut rhs)
    })();
    if solved.is_err() || !rhs.iter().all(|v| v.is_finite()) {
        let at = match smallest_relative_pivot(&assembler.matrix) {
            Ok((eq, pivot)) if pivot < SINGULAR_PIVOT => {
                format!(" (at {})", solver.dof_label(model, solver.dofs.dof(eq)))
            }
            _ => String::new(),
        };
        return Err(Singular::System(at));
    }

    // v⁺ = v⁻ + Δv; ½ ΔvᵀMΔv; π unscaled
    let dofs = &solver.dofs;
    let mut energy = 0.0;
    for (row, col, m) in mass.entries() {
        if !is_multiplier[row] && !is_multiplier[col] {
            energy += 0.5 * rhs[row] * m * rhs[col];
        }
    }
    for (eq, dv) in rhs.iter_mut().enumerate() {
        let d = dofs.dof(eq);
        if let Some((node, c)) = dofs.node_component(d) {
            state.velocity[node][c] += *dv;
        } else if d < dofs.first_multiplier() {
            state.coordinate_rates[d - dofs.first_coordinate()] += *dv;
        } else {
            *dv *= s_eq[eq];
        }
    }
    Ok(Jump {
        solution: rhs,
        energy,
    })
}

/// Locks the open latches that the step from `before` to `state` brought
/// to their value from the side of approach (`g` from below `−tol` to at
/// least `−tol`), runs the rank analysis of the constraints again, and
/// applies the impact to the velocities of `state` (see the module
/// documentation): `B_L Δv = −ċ` on the locks, the other constraints
/// keeping their rates, whose `½ ΔvᵀMΔv` is the energy lost (Carnot's).
/// The velocities of `state` are those of an accepted step, projected on
/// the constraints active at it (D13), which the open latches are not
/// part of: their rates are round-off.
///
/// `None` if no latch locked. The accelerations are left to the caller
/// (D9 at the post-impact state).
pub fn lock_latches(
    model: &Model,
    solver: &mut NewtonSolver,
    before: &State,
    state: &mut State,
    increment: usize,
) -> Result<Option<Impact>, DynamicError> {
    let reached: Vec<&Latch> = model
        .elements
        .iter()
        .filter_map(|e| e.as_latch())
        .filter(|l| {
            let tol = event_tolerance(model, l);
            l.spring().is_none()
                && !l.is_locked(state)
                && l.gap(before) < -tol
                && l.gap(state) >= -tol
        })
        .collect();
    if reached.is_empty() {
        return Ok(None);
    }
    let time = state.time;
    let failed = |why: Singular| {
        let latches = reached
            .iter()
            .map(|l| format!("latch {}", l.id()))
            .collect::<Vec<_>>()
            .join(", ");
        let reason = match why {
            Singular::Massless(node, c) => format!(
                "the impulse of the lock acts on node {} ({}) which has no mass in that direction and no other constraint holds, so the velocity jump is not defined; give the bodies the latch joins their mass (rigid bodies, point masses or beams at the joint's nodes, or nodes glued to them){}",
                model.node_ids[node],
                crate::model::COMPONENT_NAMES[c],
                rotation_hint(c >= 3)
            ),
            Singular::System(at) => format!(
                "the impact equations are singular{at}: the mass matrix is singular on the motion the impulse excites (an unknown without mass that no constraint holds); give the bodies mass{}",
                rotation_hint(names_rotation(&at))
            ),
        };
        DynamicError::Impact {
            latches,
            time,
            reason,
        }
    };
    let kinetic_before = energy::energies(model, state).kinetic;

    // the locks: the active set changes, rank analysis again
    let struck: Vec<(f64, Vec<f64>)> = reached.iter().map(|l| l.rate(state)).collect();
    for l in &reached {
        l.lock(state);
    }
    let rank = solver.constraint_rank(model, state, time);
    for &k in &rank.redundant {
        state.multipliers[k] = 0.0;
    }
    let first = solver.dofs.first_multiplier();
    let rows: Vec<usize> = reached
        .iter()
        .map(|l| solver.dofs.equation(first + l.multiplier()))
        .collect();
    let ctx = model.context(time, Need::RESIDUAL);
    // −k B_L Δv = k ċ on the latch rows, zero elsewhere
    let rhs_of = |eq: usize, _: usize| {
        rows.iter()
            .zip(&reached)
            .zip(&struck)
            .find(|((&r, _), _)| r == eq)
            .map_or(0.0, |((_, l), (rate, _))| l.scaling(&ctx).0 * rate)
    };
    let hit: Vec<(usize, &[usize], &[f64])> = rows
        .iter()
        .zip(&reached)
        .zip(&struck)
        .map(|((&r, &l), (_, g))| (r, l.pair_nodes(), g.as_slice()))
        .collect();
    let j = jump(model, solver, state, &rhs_of, &hit).map_err(failed)?;
    let kinetic_after = energy::energies(model, state).kinetic;
    let locks = reached
        .iter()
        .zip(&rows)
        .zip(&struck)
        .map(|((l, &eq), (rate, _))| LockInfo {
            kind: LatchEventKind::Lock,
            increment,
            time,
            latch: l.id(),
            joint: l.joint(),
            coordinate: l.coordinate(state),
            rate_before: *rate,
            rate_after: 0.0,
            impulse: if eq == NO_EQUATION {
                0.0
            } else {
                l.scaling(&ctx).0 * j.solution[eq]
            },
            energy_lost: j.energy,
            kinetic_energy_drop: kinetic_before - kinetic_after,
        })
        .collect();
    Ok(Some(Impact {
        locks,
        redundant: rank.redundant.len(),
        // T⁺ − T⁻ = W − ½ΔvᵀMΔv
        work: kinetic_after - kinetic_before + j.energy,
    }))
}

// ---------- spring latches (docs/theory.md §16.5) ----------

/// What [`spring_latch_events_at`] did.
#[derive(Default)]
pub struct SpringLatching {
    /// The locks and releases, in the order of the latches.
    pub events: Vec<LockInfo>,
    /// The crossings of the edges of the dead bands where a spring
    /// engages or disengages, and the returns to `c_L` of latches released
    /// beyond it, in the order of the latches (at the same state: the
    /// steps land on them as on the locks).
    pub crossings: Vec<LockInfo>,
    /// The energy the springs of the latches that released held.
    pub released: f64,
    /// Whether a load jumped (a release, or a lock with a dashpot moving):
    /// the accelerations must be made consistent again.
    pub restart: bool,
}

/// The events of the spring latches over the accepted step from `before`
/// to `state`: each whose watched quantity ([`Latch::watch`]) came from
/// above 1 to at most 1 changes its state ([`Latch::spring_transition`]):
/// it latches at `c_L` (no impact: its law is a spring about `c_L`),
/// releases when its load reaches its unlatch load, or follows its
/// coordinate across an edge of its dead band. A latch that locks with a
/// load already at its unlatch load (a dashpot moving fast) releases at
/// once.
pub fn spring_latch_events_at(
    model: &Model,
    before: &State,
    state: &mut State,
    increment: usize,
) -> SpringLatching {
    let mut out = SpringLatching::default();
    for l in model.elements.iter().filter_map(|e| e.as_latch()) {
        let Some(spring) = l.spring() else {
            continue;
        };
        let tol = event_tolerance(model, l);
        if !(l.watch(before, tol) > 1.0 && l.watch(state, tol) <= 1.0) {
            continue;
        }
        for _ in 0..3 {
            let energy = if l.is_locked(state) {
                spring.energy(l.spring_state(state).0)
            } else {
                0.0
            };
            let Some(event) = l.spring_transition(state) else {
                break;
            };
            let kind = match event {
                SpringEvent::Lock => {
                    // the dashpot's load d ċ appears at once
                    out.restart |= spring.damping * l.rate(state).0 != 0.0;
                    LatchEventKind::Lock
                }
                SpringEvent::Unlatch => {
                    // the latch's load, its unlatch load, vanishes at once
                    out.restart = true;
                    out.released += energy;
                    LatchEventKind::Unlatch
                }
                SpringEvent::Engage | SpringEvent::Disengage | SpringEvent::Rearm => {
                    let kind = match event {
                        SpringEvent::Engage => LatchEventKind::Engage,
                        SpringEvent::Disengage => LatchEventKind::Disengage,
                        _ => LatchEventKind::Rearm,
                    };
                    out.crossings.push(spring_event(l, state, kind, increment));
                    break;
                }
                SpringEvent::Band => break,
            };
            out.events.push(LockInfo {
                energy_lost: if kind == LatchEventKind::Unlatch {
                    energy
                } else {
                    0.0
                },
                ..spring_event(l, state, kind, increment)
            });
            if kind == LatchEventKind::Unlatch || l.watch(state, tol) > 1.0 {
                break;
            }
        }
        // one flip of the event function's sign for the step, whatever the
        // number of changes (the step controller crossed one event)
        l.flip_watch_sign(state);
    }
    out
}

/// The record of a spring latch's event `kind` at `state`: its coordinate
/// and rate there (the velocities do not jump), no impulse, no energy
/// lost.
fn spring_event(l: &Latch, state: &State, kind: LatchEventKind, increment: usize) -> LockInfo {
    let rate = l.rate(state).0;
    LockInfo {
        kind,
        increment,
        time: state.time,
        latch: l.id(),
        joint: l.joint(),
        coordinate: l.coordinate(state),
        rate_before: rate,
        rate_after: rate,
        impulse: 0.0,
        energy_lost: 0.0,
        kinetic_energy_drop: 0.0,
    }
}

// ---------- unilateral stops (docs/theory.md §16.4) ----------

/// A closed stop opens when its contact load falls to this fraction of the
/// largest load it has carried since it closed (the release event's
/// tolerance).
pub const RELEASE_TOLERANCE: f64 = 1e-6;

/// Contact loads below this fraction of the constraint scaling `k` count
/// as zero in the release tolerance (a stop that closed without load).
const NEGLIGIBLE_LOAD: f64 = 1e-12;

/// What happened at a stop ([`ContactInfo::kind`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactKind {
    /// An impact with restitution: the coordinate rebounds, the stop stays
    /// open.
    Impact,
    /// A plastic impact (or a rebound too slow to leave the contact) that
    /// closes the stop.
    Close,
    /// The contact load fell to zero: the stop opens, no impact.
    Release,
}

impl ContactKind {
    /// The name written in `events.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Impact => "impact",
            Self::Close => "contact",
            Self::Release => "release",
        }
    }
}

/// An event of a stop during a dynamic analysis
/// ([`super::Observer::contact`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactInfo {
    /// The step that landed on it.
    pub increment: usize,
    /// Its time.
    pub time: f64,
    /// The stop.
    pub stop: Id,
    /// The joint whose coordinate it limits (`None` for a contact with a
    /// plane).
    pub joint: Option<Id>,
    /// What happened.
    pub kind: ContactKind,
    /// The coordinate at the event.
    pub coordinate: f64,
    /// `ċ⁻`, `ċ⁺`: the coordinate's rate before and after the event (with
    /// the velocities consistent with the other constraints).
    pub rate_before: f64,
    /// See [`Self::rate_before`].
    pub rate_after: f64,
    /// The impulse of the stop along the coordinate, positive pushing it
    /// back into its range (N·s, or N·m·s for an angle); 0 for a release.
    pub impulse: f64,
    /// The energy the impact dissipates, `(1 − e)/(1 + e) ½ ΔvᵀMΔv`
    /// (docs/theory.md §16, LK3 with restitution); stops struck in the same
    /// step share one impact and report its whole loss.
    pub energy_lost: f64,
    /// `T₁ − T⁺`, the drop of the kinetic energy over the impact (from the
    /// velocities consistent with the other constraints).
    pub kinetic_energy_drop: f64,
}

/// `|g|` at or below which a step has landed on a stop's limit: as a
/// latch's ([`EVENT_TOLERANCE`], of the model's size for a length).
pub fn gap_tolerance(model: &Model, stop: &Stop) -> f64 {
    if stop.is_angle() {
        EVENT_TOLERANCE
    } else {
        EVENT_TOLERANCE * model.length_scale
    }
}

/// `|N|` at or below which a closed stop's load counts as zero:
/// `N_tol = 1e-6 max(N_max, |N|, 1e-12 k)` (docs/theory.md §16.4,
/// "Releases located on the load"), `N_max` the largest load carried
/// since it closed. `|N|` is in it so that the event function
/// `w = N/N_tol` keeps one scale over the step that first carries a load:
/// `N_max` is 0 at the state that closed the stop and becomes `|N|` when
/// the step after it is accepted, and with `N_tol` from `N_max` alone `w`
/// went from 4.5e15 (`N` = 47 N·m against `N_tol` = 1.0e-14 N·m) to
/// −1.8e6 over the next step of the arm of tests/stop_rest.rs: the regula
/// falsi never located the fall of `N` to zero, and the release was taken
/// after 30 retries where the stop pulled by 86 N·m.
fn load_tolerance(model: &Model, stop: &Stop, state: &State) -> f64 {
    let ctx = model.context(state.time, Need::RESIDUAL);
    let k = stop.scaling(&ctx).0;
    let load = if stop.contact(state) == Contact::Open {
        0.0
    } else {
        stop.load(&ctx, state).abs()
    };
    RELEASE_TOLERANCE * stop.load_scale(state).max(load).max(NEGLIGIBLE_LOAD * k)
}

/// The stop's watched quantity relative to its tolerance, `w`: the gap
/// `g/g_tol` while open, the load `N/N_tol` while closed; an event when
/// it reaches 0 (lands within ±1).
pub fn stop_watch(model: &Model, stop: &Stop, state: &State) -> f64 {
    if stop.contact(state) == Contact::Open {
        stop.gap(state).0 / gap_tolerance(model, stop)
    } else {
        let ctx = model.context(state.time, Need::RESIDUAL);
        stop.load(&ctx, state) / load_tolerance(model, stop, state)
    }
}

/// The event function of a stop: `(−1)ⁿ w` ([`stop_watch`],
/// [`Stop::watch_sign`]), with the tolerance 1.
pub struct StopEvent {
    element: usize,
    name: String,
}

impl EventFunction for StopEvent {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn value(&self, model: &Model, state: &State) -> f64 {
        match model.elements[self.element].as_stop() {
            Some(s) => s.watch_sign(state) * stop_watch(model, s, state),
            None => 1.0,
        }
    }
    fn tolerance(&self) -> f64 {
        1.0
    }
}

/// The event functions of the model's stops.
pub fn stop_events(model: &Model) -> Vec<Box<dyn EventFunction>> {
    let mut events: Vec<Box<dyn EventFunction>> = Vec::new();
    for (element, e) in model.elements.iter().enumerate() {
        if let Some(s) = e.as_stop() {
            events.push(Box::new(StopEvent {
                element,
                name: format!("{} {}", s.noun(), e.id()),
            }));
        }
    }
    events
}

/// What [`stop_events_at`] did.
pub struct ContactImpact {
    /// The events, in the order of the stops.
    pub events: Vec<ContactInfo>,
    /// Constraint equations found redundant by the last rank analysis.
    pub redundant: usize,
    /// The energy lost by the impact (0 if there was none).
    pub energy_lost: f64,
    /// Work of the impulses through drivers and prescribed motions.
    pub work: f64,
    /// The time to the top of the shortest rebound (`e|ċ⁻|/|c̈|`), the
    /// size of the next step, so that the step lands where the coordinate
    /// is out of the event band (none without a rebound under an
    /// acceleration).
    pub rebound_step: Option<f64>,
}

/// Whether the location `at` of a singular impact (` at node 101 rx`)
/// names a rotation.
fn names_rotation(at: &str) -> bool {
    [" rx", " ry", " rz"].iter().any(|r| at.contains(r))
}

/// What to add to the message of a singular impact on a rotation: beams
/// carry rotational inertia only from their section's
/// `inertia_per_length` (0 when not given), so that a beam with mass
/// leaves its nodes' rotations without any.
fn rotation_hint(rotation: bool) -> &'static str {
    if rotation {
        "; a rotation has no inertia there: beams have rotational inertia only from the inertia_per_length of their section (0 when not given), whatever their mass_per_length"
    } else {
        ""
    }
}

/// The error of an impact at stops.
fn stop_failure(model: &Model, stops: &[&Stop], time: f64, why: Singular) -> DynamicError {
    let latches = stops
        .iter()
        .map(|s| format!("{} {}", s.noun(), s.id()))
        .collect::<Vec<_>>()
        .join(", ");
    let reason = match why {
        Singular::Massless(node, c) => format!(
            "the impulse of the {} acts on node {} ({}) which has no mass in that direction and no other constraint holds, so the velocity jump is not defined; give the bodies it acts on their mass (rigid bodies, point masses or beams at its nodes){}",
            stops[0].noun(),
            model.node_ids[node],
            crate::model::COMPONENT_NAMES[c],
            rotation_hint(c >= 3)
        ),
        Singular::System(at) => format!(
            "the impact equations are singular{at}: the mass matrix is singular on the motion the impulse excites; give the bodies mass{}",
            rotation_hint(names_rotation(&at))
        ),
    };
    DynamicError::Impact {
        latches,
        time,
        reason,
    }
}

/// The events of the stops over the accepted step from `before` to
/// `state` (docs/theory.md §16.4):
/// - a closed stop whose load has fallen to zero (`N ≤ N_tol`) opens;
/// - an open stop that has reached a limit (`g` from above `g_tol` to at
///   most `g_tol`) is struck: after the velocities are made consistent
///   with the other constraints, the rebound rate `e |ċ⁻|` is compared with
///   `v_min = √(2 g_tol |c̈|)` (`c̈` the coordinate's mean acceleration
///   over the step), the rate that brings the coordinate back within the
///   event band from `g_tol` away: above it the impact has restitution
///   `e`, `B Δv = −(1 + e) ċ⁻`, and the stop stays open; at or below it the
///   impact is plastic, `B Δv = −ċ⁻`, and the stop closes (persistent
///   contact: no chattering of ever shorter rebounds);
/// - an open stop found beyond the band (`g < −g_tol`) without having
///   been above it at the step before is struck where it is found if it
///   is deeper than at the step before.
///
/// Each event is counted in the stop's state ([`Stop::watch_sign`]). The
/// accelerations are left to the caller (D9 at the post-event state),
/// then [`release_pulling`].
pub fn stop_events_at(
    model: &Model,
    solver: &mut NewtonSolver,
    before: &State,
    state: &mut State,
    increment: usize,
    end_time: f64,
) -> Result<Option<ContactImpact>, DynamicError> {
    let stops: Vec<&Stop> = model.elements.iter().filter_map(|e| e.as_stop()).collect();
    let time = state.time;
    let mut events = Vec::new();
    // releases
    for s in &stops {
        let ctx = model.context(time, Need::RESIDUAL);
        if s.contact(state) != Contact::Open
            && s.contact(before) != Contact::Open
            && s.load(&ctx, state) <= load_tolerance(model, s, before)
        {
            let (rate, _) = s.rate(state);
            events.push(ContactInfo {
                increment,
                time,
                stop: s.id(),
                joint: s.joint(),
                kind: ContactKind::Release,
                coordinate: s.coordinate(state),
                rate_before: rate,
                rate_after: rate,
                impulse: 0.0,
                energy_lost: 0.0,
                kinetic_energy_drop: 0.0,
            });
            s.set_contact(state, Contact::Open);
        }
    }
    // impacts
    let reached: Vec<&Stop> = stops
        .iter()
        .copied()
        .filter(|s| {
            let (w0, w1) = (stop_watch(model, s, before), stop_watch(model, s, state));
            // reached from above the event band; or found beyond it
            // having never left it since a rebound (a flight out of the
            // band and back within one step: struck where it is found),
            // deeper than at the step before: a stop released beyond its
            // band (closed there, `|g| > tol`) is leaving, not struck
            // (§16.4, "Struck beyond the band")
            s.contact(state) == Contact::Open
                && s.contact(before) == Contact::Open
                && ((w0 > 1.0 && w1 <= 1.0) || (w0 <= 1.0 && w1 < -1.0 && w1 < w0))
        })
        .collect();
    if reached.is_empty() {
        if events.is_empty() {
            return Ok(None);
        }
        let rank = solver.constraint_rank(model, state, time);
        for &k in &rank.redundant {
            state.multipliers[k] = 0.0;
        }
        return Ok(Some(ContactImpact {
            events,
            redundant: rank.redundant.len(),
            energy_lost: 0.0,
            work: 0.0,
            rebound_step: None,
        }));
    }
    let failed = |why| stop_failure(model, &reached, time, why);
    // mean acceleration of each coordinate over the step
    let h = time - before.time;
    let accelerations: Vec<f64> = reached
        .iter()
        .map(|s| {
            if h > 0.0 {
                ((s.rate(state).0 - s.rate(before).0) / h).abs()
            } else {
                0.0
            }
        })
        .collect();

    // 1. velocities consistent with the constraints already active
    if solver.dofs.first_multiplier() < solver.dofs.n_dofs() {
        let (rates, _) = constraint_rates(model, solver, state, end_time);
        jump(model, solver, state, &|_, d| -rates[d], &[]).map_err(failed)?;
    }
    let kinetic_consistent = energy::energies(model, state).kinetic;

    // 2. the impact: each stop struck is a constraint for it
    struct Struck<'a> {
        stop: &'a Stop,
        side: Contact,
        rate: f64,
        grad: Vec<f64>,
        /// The restitution applied: `e`, or 0 when the stop closes.
        e: f64,
        approaching: bool,
        /// The time to the top of the rebound, `e|ċ⁻|/|c̈|`.
        rise_time: f64,
    }
    let struck: Vec<Struck> = reached
        .iter()
        .zip(&accelerations)
        .map(|(&s, &a)| {
            let side = s.gap(state).1;
            let (rate, grad) = s.rate(state);
            // the rate towards the limit
            let approach = -side.side() * rate;
            let tol = gap_tolerance(model, s);
            let v_min = (2.0 * tol * a).sqrt();
            // the top of the rebound's flight under the acceleration `a`,
            // from the gap where the step landed (within ±tol): it must
            // leave the event band
            let rebound = s.restitution() * approach;
            let top = s.gap(state).0 + rebound * rebound / (2.0 * a);
            let e = if rebound > v_min && top > tol {
                s.restitution()
            } else {
                0.0
            };
            Struck {
                stop: s,
                side,
                rate,
                grad,
                e,
                approaching: approach > 0.0,
                rise_time: e * approach / a,
            }
        })
        .collect();
    for k in &struck {
        // counts the event; closed for the impact
        k.stop.set_contact(state, k.side);
    }
    let rank = solver.constraint_rank(model, state, time);
    for &k in &rank.redundant {
        state.multipliers[k] = 0.0;
    }
    let first = solver.dofs.first_multiplier();
    let rows: Vec<usize> = struck
        .iter()
        .map(|k| solver.dofs.equation(first + k.stop.multiplier()))
        .collect();
    let ctx = model.context(time, Need::RESIDUAL);
    // −k B Δv = k (1 + e) ċ⁻ on the rows of the stops approaching; a stop
    // reached moving away (grazing) keeps its rate
    let rhs_of = |eq: usize, _: usize| {
        rows.iter()
            .zip(&struck)
            .find(|(&r, _)| r == eq)
            .map_or(0.0, |(_, k)| {
                if k.approaching {
                    k.stop.scaling(&ctx).0 * (1.0 + k.e) * k.rate
                } else {
                    0.0
                }
            })
    };
    let hit: Vec<(usize, &[usize], &[f64])> = rows
        .iter()
        .zip(&struck)
        .map(|(&r, k)| (r, k.stop.pair_nodes(), k.grad.as_slice()))
        .collect();
    let j = jump(model, solver, state, &rhs_of, &hit).map_err(failed)?;
    let kinetic_after = energy::energies(model, state).kinetic;
    // ½ΔvᵀMΔv = (1 + e)² × Carnot's loss; with restitution the loss is
    // (1 − e²) of it: (1 − e)/(1 + e) ½ΔvᵀMΔv (one e for the impact; stops
    // with different e struck together report the drop of T)
    let e0 = struck[0].e;
    let energy_lost = if struck.iter().all(|k| k.e == e0) {
        (1.0 - e0) / (1.0 + e0) * j.energy
    } else {
        kinetic_consistent - kinetic_after
    };
    // the stops that rebound open again (no event counted: the impact was
    // the event)
    let mut reopened = false;
    for k in &struck {
        if k.e > 0.0 || !k.approaching {
            k.stop.reopen(state);
            reopened = true;
        }
    }
    let redundant = if reopened {
        let rank = solver.constraint_rank(model, state, time);
        for &k in &rank.redundant {
            state.multipliers[k] = 0.0;
        }
        rank.redundant.len()
    } else {
        rank.redundant.len()
    };
    for (k, &eq) in struck.iter().zip(&rows) {
        let closes = k.stop.contact(state) != Contact::Open;
        events.push(ContactInfo {
            increment,
            time,
            stop: k.stop.id(),
            joint: k.stop.joint(),
            kind: if closes {
                ContactKind::Close
            } else {
                ContactKind::Impact
            },
            coordinate: k.stop.coordinate(state),
            rate_before: k.rate,
            rate_after: k.stop.rate(state).0,
            impulse: if eq == NO_EQUATION {
                0.0
            } else {
                k.side.side() * k.stop.scaling(&ctx).0 * j.solution[eq]
            },
            energy_lost,
            kinetic_energy_drop: kinetic_consistent - kinetic_after,
        });
    }
    let rebound_step = struck
        .iter()
        .filter(|k| k.e > 0.0 && k.approaching && k.rise_time.is_finite())
        .map(|k| k.rise_time)
        .reduce(f64::min);
    Ok(Some(ContactImpact {
        events,
        redundant,
        energy_lost,
        work: kinetic_after - kinetic_consistent + energy_lost,
        rebound_step,
    }))
}

/// Opens, without counting an event, the stops of `state` that closed at
/// this state's impact but whose consistent load pulls (`N < 0`, found
/// with the accelerations of D9): the contact closed while the motion was
/// leaving it. Returns whether any opened (the caller then analyses the
/// rank of the constraints and computes the accelerations again).
pub fn release_pulling(model: &Model, state: &mut State, closed_now: &[Id]) -> bool {
    let ctx = model.context(state.time, Need::RESIDUAL);
    let mut opened = false;
    for e in &model.elements {
        if let Some(s) = e.as_stop() {
            if closed_now.contains(&s.id())
                && s.contact(state) != Contact::Open
                && s.load(&ctx, state) < 0.0
            {
                s.reopen(state);
                opened = true;
            }
        }
    }
    opened
}
