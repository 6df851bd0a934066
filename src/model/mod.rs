//! The validated, immutable model: nodes, elements, supports, prescribed
//! motions and curves, with ids resolved to indices.
//!
//! A [`Model`] is built from a [`input::ModelInput`] (read from a model file
//! or written in Rust) by [`Model::from_input`], which checks everything and
//! reports every problem it finds, each naming the entity concerned, and
//! keeps the warnings (input that is valid but probably not what was
//! meant) in [`Model::warnings`] for the caller to show. The analyses the
//! input asks for are not part of the model: [`input::ModelInput::analyses`]
//! gives their settings ([`crate::analysis::AnalysisSettings`]), and an
//! analysis takes the model (shared, `Arc<Model>`) and a start state.

mod build;
pub mod builder;
mod handles;
pub mod input;
pub mod overlaps;

use std::fmt;

use crate::curves::{Curve, CurveIndex};
use crate::elements::{ConstraintScaling, Element, ElementKind, EvalContext, Need, Offsets};
use crate::so3::{Rotation, Vec3};
use crate::state::State;

/// Identifier of a node or an element, as written in the model file and in
/// the result files.
pub type Id = u64;

pub use build::{
    LARGEST_ELEMENT_VALUE, MAX_INCREMENTS, MAX_ITERATIONS, MAX_LINE_ELEMENTS, MAX_MODEL_SIZE,
    MIN_RELATIVE_INCREMENT,
};
pub use builder::ModelBuilder;
pub use handles::{
    BeamHandle, BeamLineHandle, ContactHandle, DriverHandle, ElementRef, ElementResults,
    HingeLawHandle, JointHandle, JointSpringHandle, LatchHandle, LoadHandle, NodeHandle,
    PanelHandle, PointMassHandle, RigidBodyHandle, RollingDiscHandle, ShellHandle, SpringHandle,
    StopHandle,
};

/// Names of the six components of a node, in local unknown order.
pub const COMPONENT_NAMES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// A prescribed motion of one node.
#[derive(Clone, Debug, PartialEq)]
pub enum Prescribed {
    /// `x_axis(t) = X_axis + f(t) value`.
    Translation {
        /// Node index.
        node: usize,
        /// Global axis 0, 1 or 2.
        axis: usize,
        /// Displacement when the curve equals 1.
        value: f64,
        /// Curve index.
        curve: CurveIndex,
    },
    /// `R(t) = exp(f(t) ψ~) R₀`, `ψ` in the global frame.
    Rotation {
        /// Node index.
        node: usize,
        /// Rotation vector when the curve equals 1.
        psi: Vec3,
        /// Curve index.
        curve: CurveIndex,
    },
}

/// The most a prescribed rotation or a driven angle may turn in one load
/// increment: a quarter turn, half of the half turn beyond which the
/// increment would be ambiguous, leaving the other half to the Newton
/// iterations of the free rotations that follow it
/// ([`Model::rotation_step_limit`]).
pub const MAX_TURN_PER_INCREMENT: f64 = std::f64::consts::FRAC_PI_2;

/// A validated model.
pub struct Model {
    /// Title from the model file.
    pub title: String,
    /// Node ids, by node index.
    pub node_ids: Vec<Id>,
    /// Node index of each id.
    node_lookup: std::collections::HashMap<Id, usize>,
    /// Reference positions, by node index.
    pub reference_x: Vec<Vec3>,
    /// Reference orientations, by node index.
    pub reference_q: Vec<Rotation>,
    /// All elements (loads included).
    pub elements: Vec<Box<dyn Element>>,
    /// Index of each element by kind and id.
    element_lookup: std::collections::HashMap<(ElementKind, Id), usize>,
    /// Fixed components of each node (supports and prescribed motions).
    pub fixed: Vec<[bool; 6]>,
    /// Prescribed motions.
    pub prescribed: Vec<Prescribed>,
    /// Load curves; index 0 is the built-in ramp, 1 the built-in constant.
    pub curves: Vec<Curve>,
    /// Which curve each load, the gravity, each prescribed motion, each
    /// driver and each gradual initial strain follows.
    pub curve_uses: Vec<CurveUse>,
    /// Input that is valid but probably not what was meant.
    pub warnings: Vec<ModelWarning>,
    /// Remarks on valid input worth stating once: how a value given in
    /// other units was read (a stiffness per degree in N·m/rad).
    pub notes: Vec<ModelWarning>,
    /// Gravity acceleration and its curve.
    pub gravity: Option<(Vec3, CurveIndex)>,
    /// Diagonal of the bounding box of the nodes (1 if zero): the length
    /// against which displacement tolerances are measured.
    pub length_scale: f64,
    /// Scaling and penalty of the constraint equations.
    pub scaling: ConstraintScaling,
    /// Initial velocity of each node: `(ẋ, ω)`, both global (zero unless
    /// the model gives them, for dynamic analyses).
    pub initial_velocity: Vec<[f64; 6]>,
    /// Where each element's coordinates, multipliers and internal
    /// variables start in the state.
    offsets: Vec<Offsets>,
    /// Sizes of the state's coordinates, multipliers and internal
    /// variables.
    sizes: Offsets,
}

/// A quantity that follows a curve.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveUse {
    /// The entity, as in messages (`gravity`, `loads[2] (node 5)`, `driver 3`).
    pub entity: String,
    /// The curve.
    pub curve: CurveIndex,
    /// Whether the curve is the default one (no `curve` given).
    pub by_default: bool,
}

/// Input that is valid but probably not what was meant, naming the entity.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{entity}: {message}")]
pub struct ModelWarning {
    /// The entity, as the user wrote it.
    pub entity: String,
    /// What looks wrong, and what to write instead.
    pub message: String,
}

impl fmt::Debug for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Model")
            .field("title", &self.title)
            .field("nodes", &self.node_ids.len())
            .field("elements", &self.elements.len())
            .finish()
    }
}

impl Model {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.node_ids.len()
    }

    /// The reference (initial) state, at rest at `t = 0`: what a first
    /// analysis starts from.
    pub fn initial_state(&self) -> State {
        let mut coordinates = vec![0.0; self.sizes.coordinates];
        for (e, o) in self.elements.iter().zip(&self.offsets) {
            e.initial_coordinates(
                &mut coordinates[o.coordinates..o.coordinates + e.n_coordinates()],
            );
        }
        let mut state = State::at_rest(0.0, self.reference_x.clone(), self.reference_q.clone())
            .with_unknowns(coordinates, self.sizes.multipliers, self.sizes.internal);
        // velocities: ẋ global, Ω = Rᵀω material
        for (i, v) in self.initial_velocity.iter().enumerate() {
            let w = self.reference_q[i].inverse() * Vec3::new(v[3], v[4], v[5]);
            state.velocity[i] = [v[0], v[1], v[2], w.x, w.y, w.z];
        }
        state
    }

    /// Sets the initial velocity of node `node` (index): `v` and the
    /// angular velocity `w`, both global.
    pub fn set_initial_velocity(&mut self, node: usize, v: Vec3, w: Vec3) {
        if self.initial_velocity.len() != self.n_nodes() {
            self.initial_velocity = vec![[0.0; 6]; self.n_nodes()];
        }
        self.initial_velocity[node] = [v.x, v.y, v.z, w.x, w.y, w.z];
    }

    /// Where the coordinates, multipliers and internal variables of
    /// element `e` start in the state.
    pub fn offsets(&self, e: usize) -> Offsets {
        self.offsets[e]
    }

    /// Numbers of coordinates, multipliers and internal variables of the
    /// state.
    pub fn state_sizes(&self) -> Offsets {
        self.sizes
    }

    /// Tells every element where its unknowns and internal variables are
    /// in the state (after the element list changed).
    fn place_elements(&mut self) {
        self.offsets.clear();
        let mut o = Offsets::default();
        for e in &mut self.elements {
            e.set_offsets(o);
            self.offsets.push(o);
            o.coordinates += e.n_coordinates();
            o.multipliers += e.n_multipliers();
            o.internal += e.n_internal();
        }
        self.sizes = o;
    }

    /// Adds an element, telling it where its coordinates, multipliers and
    /// internal variables are stored in the state.
    pub fn push_element(&mut self, e: Box<dyn Element>) {
        self.element_lookup
            .insert((e.kind(), e.id()), self.elements.len());
        self.elements.push(e);
        self.place_elements();
    }

    /// The evaluation context at load parameter `time` (statics: no
    /// inertia forces) asking for `need`.
    pub fn context(&self, time: f64, need: Need) -> EvalContext<'_> {
        EvalContext {
            time,
            curves: &self.curves,
            gravity: self.gravity_at(time),
            need,
            dynamics: false,
            scaling: self.scaling,
        }
    }

    /// Updates the internal variables of every element after `state` has
    /// converged (unwrapped joint angles).
    pub fn update_internal(&self, state: &mut State) {
        let ctx = self.context(state.time, Need::RESIDUAL);
        let mut buf = Vec::new();
        for (e, o) in self.elements.iter().zip(&self.offsets) {
            let (n, offset) = (e.n_internal(), o.internal);
            if n > 0 {
                buf.clear();
                buf.extend_from_slice(&state.internal[offset..offset + n]);
                e.update_internal(&ctx, state, &mut buf);
                state.internal[offset..offset + n].copy_from_slice(&buf);
            }
        }
    }

    /// Sets [`Model::scaling`] from [`Model::default_scaling`].
    pub fn with_default_scaling(mut self, scale: Option<f64>, penalty: Option<f64>) -> Self {
        self.scaling = self.default_scaling(scale, penalty);
        self
    }

    /// Default scaling of constraint equations (docs/joints.md §1): `k` and
    /// `p` equal to the largest diagonal stiffness of the elements' tangents
    /// in the reference state, for translations and rotations separately;
    /// a kind without stiffness takes the other's times or over `L²`
    /// ([`Model::length_scale`]), so that the scaling follows the units of
    /// the model, and a model without stiffness (rigid bodies and joints
    /// only) takes 1 for both; `scale` and `penalty`, when given, replace
    /// `k` and `p` of both kinds.
    pub fn default_scaling(&self, scale: Option<f64>, penalty: Option<f64>) -> ConstraintScaling {
        let state = self.initial_state();
        let ctx = EvalContext {
            scaling: ConstraintScaling {
                force: (0.0, 0.0),
                moment: (0.0, 0.0),
                rate_time: 1.0,
            },
            ..self.context(0.0, Need::STIFFNESS)
        };
        let (mut kf, mut km) = (0.0f64, 0.0f64);
        for e in &self.elements {
            // constraints are what is scaled; a superelement's modal
            // coordinates are not, its boundary nodes' stiffness counts
            if e.n_multipliers() > 0 {
                continue;
            }
            let n = e.n_local();
            let mut r = vec![0.0; n];
            let mut t = vec![0.0; n * n];
            e.evaluate(
                &ctx,
                &state,
                &mut crate::elements::ElementOutput::with_stiffness(&mut r, &mut t),
            );
            for i in 0..6 * e.nodes().len() {
                let d = t[i * n + i].abs();
                if i % 6 < 3 {
                    kf = kf.max(d);
                } else {
                    km = km.max(d);
                }
            }
        }
        // a kind without stiffness takes the other's through the model's
        // length `L` (k_moment = k_force L²), so that k has the units of
        // its kind whichever units the model is in; a model without any
        // stiffness takes 1 for both (k_moment = L² there made the rank
        // analysis of the ERA cell's rigid links, a mechanism of one free
        // motion, find none: tests/era.rs)
        let found = |v: f64| v > 0.0 && v.is_finite();
        let l2 = self.length_scale * self.length_scale;
        let (kf, km) = match (found(kf), found(km)) {
            (true, true) => (kf, km),
            (true, false) => (kf, kf * l2),
            (false, true) => (km / l2, km),
            (false, false) => (1.0, 1.0),
        };
        let pick = |v: f64, user: Option<f64>| user.unwrap_or(v);
        ConstraintScaling {
            force: (pick(kf, scale), pick(kf, penalty)),
            moment: (pick(km, scale), pick(km, penalty)),
            rate_time: 1.0,
        }
    }

    /// The load history in words, one line per curve: which loads, gravity,
    /// prescribed motions, drivers and initial strains follow it, those
    /// that follow it by default marked so (at most [`LISTED`] entities
    /// named per line).
    pub fn load_history(&self) -> Vec<String> {
        let mut lines = Vec::new();
        for (c, curve) in self.curves.iter().enumerate() {
            let uses: Vec<&CurveUse> = self.curve_uses.iter().filter(|u| u.curve == c).collect();
            if uses.is_empty() {
                continue;
            }
            let mut named: Vec<String> = uses
                .iter()
                .take(LISTED)
                .map(|u| {
                    if u.by_default {
                        format!("{} (default)", u.entity)
                    } else {
                        u.entity.clone()
                    }
                })
                .collect();
            if uses.len() > LISTED {
                let defaults = uses[LISTED..].iter().filter(|u| u.by_default).count();
                named.push(format!(
                    "and {} more ({defaults} by default)",
                    uses.len() - LISTED
                ));
            }
            lines.push(format!(
                "curve \"{}\" ({}) is followed by {}",
                curve.name(),
                curve.describe(),
                named.join(", ")
            ));
        }
        lines
    }

    /// Index of the node with id `id`.
    pub fn node_index(&self, id: Id) -> Option<usize> {
        self.node_lookup.get(&id).copied()
    }

    /// Gravity acceleration at load parameter `t`.
    pub fn gravity_at(&self, t: f64) -> Vec3 {
        match self.gravity {
            Some((g, c)) => g * self.curves[c].value(t),
            None => Vec3::zeros(),
        }
    }

    /// The largest load increment over which no prescribed rotation and no
    /// driven angle changes by more than [`MAX_TURN_PER_INCREMENT`]
    /// anywhere in `[0, end_time]`, if any of them moves: beyond half a
    /// turn an increment cannot tell a rotation from the same rotation less
    /// a full turn (docs/joints.md §3.3), so a larger increment would miss
    /// whole turns or converge to the wrong branch. Load control keeps its
    /// increments below it.
    pub fn rotation_step_limit(&self, end_time: f64) -> Option<f64> {
        let prescribed = self.prescribed.iter().filter_map(|p| match p {
            Prescribed::Rotation { psi, curve, .. } => Some((psi.norm(), *curve)),
            Prescribed::Translation { .. } => None,
        });
        let driven = self.elements.iter().filter_map(|e| e.imposed_angle());
        prescribed
            .chain(driven)
            .filter(|&(amplitude, curve)| {
                amplitude != 0.0 && !self.curves[curve].is_constant_on(end_time)
            })
            .map(|(amplitude, curve)| {
                self.curves[curve].largest_step(amplitude, MAX_TURN_PER_INCREMENT, end_time)
            })
            .reduce(f64::min)
    }

    /// Sets the prescribed components of `state` to their values at `t`.
    pub fn apply_prescribed(&self, state: &mut State, t: f64) {
        for p in &self.prescribed {
            match *p {
                Prescribed::Translation {
                    node,
                    axis,
                    value,
                    curve,
                } => {
                    state.x[node][axis] =
                        self.reference_x[node][axis] + value * self.curves[curve].value(t);
                }
                Prescribed::Rotation { node, psi, curve } => {
                    state.q[node] = crate::so3::exp(&(psi * self.curves[curve].value(t)))
                        * self.reference_q[node];
                }
            }
        }
    }
}

/// Entities named per line of [`Model::load_history`].
pub const LISTED: usize = 8;

/// What is wrong with a model definition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelErrorKind {
    /// A reference to a node id that does not exist.
    UnknownNode,
    /// Two entities with the same id or name.
    DuplicateId,
    /// A beam or spring whose nodes coincide.
    ZeroLength,
    /// A stiffness, mass or inertia that must be positive is not.
    NonPositive,
    /// A reference to a section that does not exist.
    UnknownSection,
    /// A reference to a curve that does not exist.
    UnknownCurve,
    /// A reference to a laminate or a ply material that does not exist.
    UnknownLaminate,
    /// A required value is missing.
    Missing,
    /// A value is not acceptable (wrong name, not finite, inconsistent).
    Invalid,
    /// Part of the structure can move as a rigid body.
    Unrestrained,
}

/// One problem in a model definition, naming the entity concerned.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{entity}: {message}")]
pub struct ModelError {
    /// Kind of problem.
    pub kind: ModelErrorKind,
    /// The entity, as the user wrote it (`beam 3`, `section "tube"`).
    pub entity: String,
    /// What is wrong.
    pub message: String,
}

/// Every problem found in a model definition.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelErrors(pub Vec<ModelError>);

impl fmt::Display for ModelErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ModelErrors {}
