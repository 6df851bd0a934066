//! Energies of a motion and their balance (docs/theory.md §15.6).
//!
//! At a state: the kinetic energy `T` (inertia of beams, rigid bodies and
//! point masses, eqs. I1, I7), the strain energy of beams, the potential of
//! the weight `−Σ m g·x_c`, the energy of springs and joint springs. Along a
//! motion, [`EnergyBalance`] adds, by the trapezoidal rule over the steps,
//! the work `W = ∫ P_ext dt` done on the model by nodal loads, drivers and
//! prescribed motions (`P_ext = −Σ rₑ·vₑ` over those elements, and
//! `−Σ r_d v_d` over prescribed dofs: the reactions' power) and the energy
//! `D = ∫ P_d dt` taken out by dampers, and the balance error
//!
//! ```text
//! E = (T + V) − (T₀ + V₀) − W + D,    V = V_strain + V_weight + V_spring,
//! ```
//!
//! zero for the exact motion; the numerical dissipation of `ρ∞ < 1` and
//! the error of the trapezoidal rule show there. With a gravity that
//! follows a curve, `V_weight` uses the gravity of the current time (a
//! constant gravity is the conservative case).

use crate::elements::inertia::Momenta;
use crate::elements::{ElementKind, ElementOutput, Need};
use crate::model::Model;
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
    /// `(T + V) − (T₀ + V₀) − W + D`.
    pub balance_error: f64,
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
/// that of its dampers, at `state` (see the module documentation).
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
        for p in &model.prescribed {
            let (node, comps) = match *p {
                crate::model::Prescribed::Translation { node, axis, .. } => (node, axis..axis + 1),
                crate::model::Prescribed::Rotation { node, .. } => (node, 3..6),
            };
            for c in comps {
                external -= residual[6 * node + c] * state.velocity[node][c];
            }
        }
    }
    (external, dissipated)
}

/// The energies along a motion, with the work and the dissipation
/// integrated over its steps (see the module documentation). Give it every
/// accepted state in order.
#[derive(Clone, Debug, Default)]
pub struct EnergyBalance {
    /// `T₀ + V₀`.
    initial: Option<f64>,
    /// Time and powers at the last state.
    last: Option<(f64, f64, f64)>,
    work: f64,
    dissipated: f64,
}

impl EnergyBalance {
    /// A balance that starts at the first state it is given.
    pub fn new() -> Self {
        Self::default()
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
    /// `T₀ + V₀ = T + V − W + D − E` carry on.
    pub fn continuing(at: &Energies) -> Self {
        Self {
            initial: Some(at.total() - at.external_work + at.dissipated - at.balance_error),
            last: None,
            work: at.external_work,
            dissipated: at.dissipated,
        }
    }

    /// Adds `state` (the next state of the motion) and returns its
    /// energies. `residual`: as in [`powers`].
    pub fn record(&mut self, model: &Model, state: &State, residual: Option<&[f64]>) -> Energies {
        let mut e = energies(model, state);
        let (p_ext, p_d) = powers(model, state, residual);
        if let Some((t, q_ext, q_d)) = self.last {
            // trapezoidal rule over the step
            let h = state.time - t;
            self.work += 0.5 * h * (p_ext + q_ext);
            self.dissipated += 0.5 * h * (p_d + q_d);
        }
        self.last = Some((state.time, p_ext, p_d));
        let initial = *self.initial.get_or_insert(e.total());
        e.external_work = self.work;
        e.dissipated = self.dissipated;
        e.balance_error = e.total() - initial - self.work + self.dissipated;
        e
    }
}
