//! Energies of a motion and their balance (docs/theory.md §15.6).
//!
//! At a state: the kinetic energy `T` (inertia of beams, rigid bodies and
//! point masses, eqs. I1, I7), the strain energy of beams, the potential of
//! the weight `−Σ m g·x_c`, the energy of springs and joint springs. Along a
//! motion, [`EnergyBalance`] adds the work `W` done on the model by nodal
//! loads, drivers and prescribed motions, the work `W_h = −∫ M dc` of hinge
//! laws, the energy `D` taken out by dampers and impacts, and the balance
//! error
//!
//! ```text
//! E = (T + V) − (T₀ + V₀) − W − W_h + D,    V = V_strain + V_weight + V_spring,
//! ```
//!
//! zero for the exact motion; the numerical dissipation of `ρ∞ < 1` and
//! the error of the quadratures show there. Loads, drivers, dampers and
//! hinge laws work over a step as the integrator's equations use them:
//! their forces at `t_{n+1−α_f}` on the step's increments (D12a); the
//! reactions at prescribed unknowns by the trapezoidal rule on their power
//! `−Σ r_d v_d`. With a gravity that
//! follows a curve, `V_weight` uses the gravity of the current time (a
//! constant gravity is the conservative case).

use crate::elements::inertia::Momenta;
use crate::elements::{ElementKind, ElementOutput, Need};
use crate::model::Model;
use crate::so3;
use crate::state::State;

/// Energies at one state of a motion.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Energies {
    /// Time.
    pub time: f64,
    /// Kinetic energy `T`.
    pub kinetic: f64,
    /// Strain energy of beams (and of every element that stores elastic
    /// energy and is not a spring).
    pub strain: f64,
    /// Potential of the weight, `−Σ m g·x_c`.
    pub gravity: f64,
    /// Energy stored in springs, joint springs and spring latches.
    pub spring: f64,
    /// Work done on the model by loads, drivers and prescribed motions
    /// since the start of the motion.
    pub external_work: f64,
    /// Energy dissipated by dampers and impacts (latches locking) since the
    /// start of the motion.
    pub dissipated: f64,
    /// `(T + V) − (T₀ + V₀) − W − W_h + D`.
    pub balance_error: f64,
    /// Work `W_h = −∫ M dc` done on the model by hinge laws since the start
    /// of the motion (they have no potential; a hysteresis loop cycled
    /// adds minus its area).
    #[serde(default)]
    pub hinge_law_work: f64,
}

impl Energies {
    /// `T + V`.
    pub fn total(&self) -> f64 {
        self.kinetic + self.strain + self.gravity + self.spring
    }
}

/// Kinetic and potential energies of `state` (the work, dissipation and
/// balance are left at zero).
pub fn energies(model: &Model, state: &State) -> Energies {
    let ctx = model.context(state.time, Need::RESIDUAL);
    let mut e = Energies {
        time: state.time,
        ..Energies::default()
    };
    for el in &model.elements {
        e.kinetic += el.kinetic_energy(state);
        e.gravity += el.weight_potential(&ctx, state);
        let stored = el.strain_energy(&ctx, state);
        match el.kind() {
            ElementKind::Spring | ElementKind::JointSpring | ElementKind::Latch => {
                e.spring += stored
            }
            _ => e.strain += stored,
        }
    }
    e
}

/// Linear and angular momentum (about the global origin) of the whole
/// model at `state`, global frame.
pub fn momenta(model: &Model, state: &State) -> Momenta {
    let mut total = Momenta::default();
    for el in &model.elements {
        let m = el.momenta(state);
        total.linear += m.linear;
        total.angular += m.angular;
    }
    total
}

/// The power of the loads, drivers and prescribed motions on the model, and
/// that of its dampers, at `state` (the balance integrates the work of
/// loads, drivers and dampers by D12a, not from these powers).
/// `residual` is the assembled residual at every dof (reactions at fixed
/// dofs), if known.
pub fn powers(model: &Model, state: &State, residual: Option<&[f64]>) -> (f64, f64) {
    let ctx = model.context(state.time, Need::RESIDUAL);
    let ctx = crate::elements::EvalContext {
        dynamics: true,
        ..ctx
    };
    let (mut external, mut dissipated) = (0.0, 0.0);
    let mut r = Vec::new();
    for (i, el) in model.elements.iter().enumerate() {
        dissipated += el.dissipated_power(&ctx, state);
        if !matches!(el.kind(), ElementKind::NodalLoad | ElementKind::Driver) {
            continue;
        }
        r.clear();
        r.resize(el.n_local(), 0.0);
        el.evaluate(&ctx, state, &mut ElementOutput::residual(&mut r));
        // the force on the model is −r; its power on the local velocities
        let nodes = el.nodes();
        for (k, &node) in nodes.iter().enumerate() {
            for c in 0..6 {
                external -= r[6 * k + c] * state.velocity[node][c];
            }
        }
        let o = model.offsets(i);
        for c in 0..el.n_coordinates() {
            external -= r[6 * nodes.len() + c] * state.coordinate_rates[o.coordinates + c];
        }
    }
    if let Some(residual) = residual {
        external += prescribed_power(model, state, residual);
    }
    (external, dissipated)
}

/// The power of the reactions at prescribed unknowns, `−Σ r_d v_d`.
fn prescribed_power(model: &Model, state: &State, residual: &[f64]) -> f64 {
    let mut external = 0.0;
    for p in &model.prescribed {
        let (node, comps) = match *p {
            crate::model::Prescribed::Translation { node, axis, .. } => (node, axis..axis + 1),
            crate::model::Prescribed::Rotation { node, .. } => (node, 3..6),
        };
        for c in comps {
            external -= residual[6 * node + c] * state.velocity[node][c];
        }
    }
    external
}

/// The energies along a motion, with the work and the dissipation
/// integrated over its steps (see the module documentation). Give it every
/// accepted state in order.
#[derive(Clone, Debug)]
pub struct EnergyBalance {
    /// `α_f` of the generalised-α method (D1): the forces without
    /// potential work at `t_{n+1−α_f}` (D12a).
    alpha_f: f64,
    /// `T₀ + V₀`.
    initial: Option<f64>,
    /// Time and external power at the last state.
    last: Option<(f64, f64)>,
    work: f64,
    dissipated: f64,
    hinge_law_work: f64,
    /// The last state, for the increments of the next step (D12a).
    previous: Option<State>,
    /// The forces without potential of every element at the last state
    /// ([`Element::nonconservative_forces`](crate::elements::Element::nonconservative_forces)),
    /// `n_local` each, in the order of the model's elements; and those of
    /// the state being recorded.
    forces: Vec<f64>,
    current: Vec<f64>,
}

impl Default for EnergyBalance {
    fn default() -> Self {
        Self {
            alpha_f: 0.5,
            initial: None,
            last: None,
            work: 0.0,
            dissipated: 0.0,
            hinge_law_work: 0.0,
            previous: None,
            forces: Vec::new(),
            current: Vec::new(),
        }
    }
}

impl EnergyBalance {
    /// A balance that starts at the first state it is given, for steps of
    /// the trapezoidal rule (`α_f = ½`, `ρ∞ = 1`).
    pub fn new() -> Self {
        Self::default()
    }

    /// The same balance for steps of the generalised-α method with this
    /// `α_f` (D1, D12a).
    pub fn with_alpha_f(self, alpha_f: f64) -> Self {
        Self { alpha_f, ..self }
    }

    /// Adds an impact at the current instant (a latch locking,
    /// docs/theory.md §16): the energy it dissipates, and the work its
    /// impulses do through drivers and prescribed motions.
    pub fn impact(&mut self, dissipated: f64, work: f64) {
        self.dissipated += dissipated;
        self.work += work;
    }

    /// A balance that goes on from a state of a motion whose energies were
    /// `at` (the first state it is given): its work, dissipation and
    /// `T₀ + V₀ = T + V − W − W_h + D − E` carry on.
    pub fn continuing(at: &Energies) -> Self {
        Self {
            initial: Some(
                at.total() - at.external_work - at.hinge_law_work + at.dissipated
                    - at.balance_error,
            ),
            work: at.external_work,
            dissipated: at.dissipated,
            hinge_law_work: at.hinge_law_work,
            ..Self::default()
        }
    }

    /// Adds `state` (the next state of the motion) and returns its
    /// energies. `residual`: as in [`powers`].
    pub fn record(&mut self, model: &Model, state: &State, residual: Option<&[f64]>) -> Energies {
        let mut e = energies(model, state);
        let p_ext = residual.map_or(0.0, |r| prescribed_power(model, state, r));
        if let Some((t, q_ext)) = self.last {
            // trapezoidal rule over the step
            let h = state.time - t;
            self.work += 0.5 * h * (p_ext + q_ext);
        }
        self.last = Some((state.time, p_ext));
        self.nonconservative_work(model, state);
        let initial = *self.initial.get_or_insert(e.total());
        e.external_work = self.work;
        e.dissipated = self.dissipated;
        e.hinge_law_work = self.hinge_law_work;
        e.balance_error = e.total() - initial - self.work - self.hinge_law_work + self.dissipated;
        e
    }

    /// Closes the step that ended at `state` (the solution of the step,
    /// before an impact or a projection at the same instant changes its
    /// velocities): adds the work of the forces without potential over it
    /// with the forces at `state`. The next [`EnergyBalance::record`], at
    /// the same positions, then adds no work and keeps the forces at the
    /// velocities after the impact for the next step.
    pub fn close_step(&mut self, model: &Model, state: &State) {
        self.nonconservative_work(model, state);
    }

    /// Adds the work of the forces without potential over the step from
    /// the last state to `state` (D12a): `½ (f_n + f_{n+1})·δ` per element,
    /// `δ` the increments of its unknowns over the step (`Δx` global,
    /// `ΔΘ = log(R_nᵀ R_{n+1})` material, conjugate to the residual's
    /// rows, and the coordinates' changes). Dampers' forces go to `D`,
    /// hinge laws' to `W_h` (the work done on the model, `−∫M dc`).
    fn nonconservative_work(&mut self, model: &Model, state: &State) {
        let ctx = crate::elements::EvalContext {
            dynamics: true,
            ..model.context(state.time, Need::RESIDUAL)
        };
        let n: usize = model.elements.iter().map(|el| el.n_local()).sum();
        self.current.clear();
        self.current.resize(n, 0.0);
        let mut start = 0;
        for el in &model.elements {
            let m = el.n_local();
            let f = &mut self.current[start..start + m];
            if matches!(el.kind(), ElementKind::NodalLoad | ElementKind::Driver) {
                // the load's or the driver's residual: the force on the
                // model is −r
                el.evaluate(&ctx, state, &mut ElementOutput::residual(f));
            } else {
                el.nonconservative_forces(&ctx, state, f);
            }
            start += m;
        }
        if let Some(before) = &self.previous {
            if self.forces.len() == n {
                let (mut damped, mut hinge, mut external) = (0.0, 0.0, 0.0);
                let mut start = 0;
                for (i, el) in model.elements.iter().enumerate() {
                    let m = el.n_local();
                    let (f0, f1) = (
                        &self.forces[start..start + m],
                        &self.current[start..start + m],
                    );
                    start += m;
                    if f0.iter().chain(f1).all(|&f| f == 0.0) {
                        continue;
                    }
                    // D12a: the forces at t_{n+1−α_f}; loads and drivers,
                    // which the integrator does not damp, at mid-step (D12b)
                    let af = match el.kind() {
                        ElementKind::NodalLoad | ElementKind::Driver => 0.5,
                        _ => self.alpha_f,
                    };
                    let mean = |k: usize| af * f0[k] + (1.0 - af) * f1[k];
                    let mut w = 0.0;
                    let nodes = el.nodes();
                    for (k, &node) in nodes.iter().enumerate() {
                        let dx = state.x[node] - before.x[node];
                        let dtheta = so3::log(&(before.q[node].inverse() * state.q[node]));
                        for c in 0..3 {
                            w += mean(6 * k + c) * dx[c] + mean(6 * k + 3 + c) * dtheta[c];
                        }
                    }
                    let o = model.offsets(i).coordinates;
                    for c in 0..el.n_coordinates() {
                        let dc = state.coordinates[o + c] - before.coordinates[o + c];
                        w += mean(6 * nodes.len() + c) * dc;
                    }
                    match el.kind() {
                        ElementKind::HingeLaw => hinge -= w,
                        ElementKind::NodalLoad | ElementKind::Driver => external -= w,
                        _ => damped += w,
                    }
                }
                self.dissipated += damped;
                self.hinge_law_work += hinge;
                self.work += external;
            }
        }
        std::mem::swap(&mut self.forces, &mut self.current);
        match &mut self.previous {
            Some(p) => p.clone_from(state),
            None => self.previous = Some(state.clone()),
        }
    }
}
