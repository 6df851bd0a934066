//! Building a model in Rust: typed builders that return handles.
//!
//! ```
//! use unfold::model::builder::*;
//!
//! // a 2 m cantilever of 8 elements (EI = 1e5 N·m²) with a 1 N tip load
//! let mut m = ModelBuilder::new("cantilever");
//! let root = m.node([0.0, 0.0, 0.0]);
//! let tip = m.node([2.0, 0.0, 0.0]);
//! let steel = m.section(Section::diagonal(1e8, 4e7, 4e7, 1e5, 1e5, 1e5));
//! let line = m.add(BeamLine::between(root, tip, 8, steel).orientation([0.0, 0.0, 1.0]));
//! m.fix(root, Dofs::ALL);
//! m.add(Load::force(tip, [0.0, 0.0, -1.0]));
//! let model = m.build().unwrap();
//! assert_eq!(model.n_nodes(), 9);
//! assert_eq!(line.interior().len(), 7);
//! assert_eq!(model.reference_position(line.nodes[4]).x, 1.0);
//! ```
//!
//! [`ModelBuilder`] is the typed front of the file schema
//! ([`crate::model::input`]): each call adds one entry to a
//! [`ModelInput`], with ids chosen automatically (one more than the
//! largest used so far, as the file format does for `beam_lines`) unless
//! given, components and kinds as enums, sections and curves by handle
//! instead of by name. [`ModelBuilder::build`] then validates that input
//! with [`Model::from_input`], exactly as a model file is validated. So a
//! model built in Rust and the same model read from a file are checked by
//! the same code, report the same messages (naming the entities as the
//! written file does: `beam 12`, `beam_lines[3] (nodes 1 to 2)`), and the
//! builder can write the model file ([`ModelBuilder::to_toml`]) that, run
//! with `unfold run`, gives the same results. Nothing is checked while the
//! model is being built: a builder call cannot fail, and every problem is
//! reported together by `build`.
//!
//! The handles returned ([`NodeHandle`], [`BeamHandle`], [`JointHandle`],
//! …) find their node or element in the built model
//! ([`Model::node`], [`Model::element`], [`Model::results`]).

mod loading;
mod mechanism;
mod shells;
mod structure;

pub use loading::{
    Analysis, Component, CurveHandle, Dofs, Gravity, Load, LoadCurve, PrescribedMotion,
};
pub use mechanism::{Contact, Driver, HingeLaw, Joint, JointSpring, Latch, RollingDisc, Stop};
pub use shells::{Core, Laminate, LaminateHandle, Panel, PlyMaterial, PlyMaterialHandle, Shell};
pub use structure::{Beam, BeamLine, Node, PointMass, RigidBody, Section, SectionHandle, Spring};

pub use super::handles::{
    BeamHandle, BeamLineHandle, ContactHandle, DriverHandle, ElementRef, ElementResults,
    HingeLawHandle, JointHandle, JointSpringHandle, LatchHandle, LoadHandle, NodeHandle,
    PanelHandle, PointMassHandle, RigidBodyHandle, RollingDiscHandle, ShellHandle, SpringHandle,
    StopHandle,
};
pub use super::input::{
    AngleUnit, Approach, PanelPoint, PanelSide, ShapeInput as Shape, StartBranch,
    TapeSpringInput as TapeSpring,
};
pub use super::{Id, Model, ModelErrors};
pub use crate::joints::{Coordinate, JointType};

use super::input::{ModelInput, SupportInput};

/// The ground, as the second body of a joint or a spring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ground;

/// The second body of a joint or of a spring: a node, or the [`Ground`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Body {
    /// A node.
    Node(NodeHandle),
    /// The ground.
    Ground,
}

impl From<NodeHandle> for Body {
    fn from(n: NodeHandle) -> Self {
        Self::Node(n)
    }
}

impl From<Ground> for Body {
    fn from(_: Ground) -> Self {
        Self::Ground
    }
}

impl Body {
    /// The node ids of `[a, self]`.
    fn with_first(self, a: NodeHandle) -> Vec<Id> {
        match self {
            Self::Node(b) => vec![a.0, b.0],
            Self::Ground => vec![a.0],
        }
    }
}

/// Something a model is made of: a node, a section, an element, a load,
/// a curve. [`ModelBuilder::add`] adds it and returns its handle.
pub trait Entity {
    /// What refers to the entity once added.
    type Handle;
    /// Adds the entity to `model`.
    fn add_to(self, model: &mut ModelBuilder) -> Self::Handle;
}

/// A model being built (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelBuilder {
    input: ModelInput,
    /// One more than the largest node id used.
    next_node: Id,
    /// One more than the largest element id used.
    next_element: Id,
}

impl ModelBuilder {
    /// An empty model with a title, to be run as a static analysis unless
    /// [`ModelBuilder::analysis`] says otherwise.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            input: ModelInput::new(title),
            next_node: 1,
            next_element: 1,
        }
    }

    /// Adds `entity` and returns its handle.
    pub fn add<E: Entity>(&mut self, entity: E) -> E::Handle {
        entity.add_to(self)
    }

    /// Adds a node at `x` (identity orientation), with the next free id.
    pub fn node(&mut self, x: impl Into<[f64; 3]>) -> NodeHandle {
        self.add(Node::at(x))
    }

    /// Adds a node at `x` with the id `id`.
    pub fn node_with_id(&mut self, id: Id, x: impl Into<[f64; 3]>) -> NodeHandle {
        self.add(Node::at(x).id(id))
    }

    /// Gives node `node` the initial velocity `v` and angular velocity
    /// `w` (global frame), for dynamic analyses.
    pub fn initial_velocity(
        &mut self,
        node: NodeHandle,
        v: impl Into<[f64; 3]>,
        w: impl Into<[f64; 3]>,
    ) {
        if let Some(n) = self.input.nodes.iter_mut().find(|n| n.id == node.0) {
            n.velocity = Some(v.into());
            n.angular_velocity = Some(w.into());
        }
    }

    /// Gives `nodes` the rigid motion in which the point `about` moves
    /// with `velocity` and everything turns with `angular_velocity`
    /// (global frame): `v(x) = velocity + angular_velocity × (x − about)`.
    pub fn initial_motion(
        &mut self,
        nodes: impl IntoIterator<Item = NodeHandle>,
        velocity: impl Into<[f64; 3]>,
        angular_velocity: impl Into<[f64; 3]>,
        about: impl Into<[f64; 3]>,
    ) {
        self.input
            .initial_motion
            .push(crate::model::input::InitialMotionInput {
                nodes: nodes.into_iter().map(|n| n.0).collect(),
                velocity: Some(velocity.into()),
                angular_velocity: Some(angular_velocity.into()),
                about: Some(about.into()),
            });
    }

    /// Adds a beam cross-section.
    pub fn section(&mut self, section: Section) -> SectionHandle {
        self.add(section)
    }

    /// Adds a curve `f(t)`.
    pub fn curve(&mut self, curve: LoadCurve) -> CurveHandle {
        self.add(curve)
    }

    /// Adds a beam element between two nodes, with the default
    /// orientation of its section (see [`Beam`] for the others).
    pub fn beam(&mut self, a: NodeHandle, b: NodeHandle, section: SectionHandle) -> BeamHandle {
        self.add(Beam::between(a, b, section))
    }

    /// Meshes the straight line between two nodes into `elements` beam
    /// elements (see [`BeamLine`] for arcs, orientation and initial
    /// strain).
    pub fn beam_line(
        &mut self,
        a: NodeHandle,
        b: NodeHandle,
        elements: usize,
        section: SectionHandle,
    ) -> BeamLineHandle {
        self.add(BeamLine::between(a, b, elements, section))
    }

    /// Fixes the components `dofs` of `node`: `Dofs::ALL`,
    /// `Dofs::TRANSLATIONS`, `Component::Z`, `[Component::X, Component::Rz]`.
    pub fn fix(&mut self, node: NodeHandle, dofs: impl Into<Dofs>) {
        self.input.supports.push(SupportInput {
            node: node.0,
            fixed: dofs.into().names(),
        });
    }

    /// A uniform gravity field `g` following the default curve (the ramp
    /// in statics, the constant in a kinematic analysis); see [`Gravity`]
    /// for another curve.
    pub fn gravity(&mut self, g: impl Into<[f64; 3]>) {
        self.add(Gravity::of(g));
    }

    /// Sets the analysis and its parameters (the only one, replacing any
    /// sequence).
    pub fn analysis(&mut self, analysis: Analysis) {
        self.input.analysis = analysis.into_input().into();
    }

    /// Adds an analysis after the last one: a sequence of analyses, each
    /// starting from the final state of the one before (`[[analysis]]`).
    pub fn then(&mut self, analysis: Analysis) {
        self.input.analysis.push(analysis.into_input());
    }

    /// Validates the model and builds it: every problem found, as for a
    /// model file.
    pub fn build(&self) -> Result<Model, ModelErrors> {
        Model::from_input(&self.input)
    }

    /// The settings of the analyses, validated, in order.
    pub fn analyses(&self) -> Result<Vec<crate::analysis::AnalysisSettings>, ModelErrors> {
        self.input.analyses()
    }

    /// The model definition as the file schema holds it.
    pub fn input(&self) -> &ModelInput {
        &self.input
    }

    /// The model definition as the file schema holds it.
    pub fn into_input(self) -> ModelInput {
        self.input
    }

    /// The model file (TOML).
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        self.input.to_toml()
    }

    /// `id`, or the next free node id; the ids after it become the free
    /// ones.
    fn node_id(&mut self, id: Option<Id>, count: usize) -> Id {
        let first = id.unwrap_or(self.next_node);
        self.next_node = self.next_node.max(first.saturating_add(count as Id));
        first
    }

    /// `id`, or the next free element id (shared by beams, masses,
    /// springs, joints, joint springs and drivers).
    fn element_id(&mut self, id: Option<Id>, count: usize) -> Id {
        let first = id.unwrap_or(self.next_element);
        self.next_element = self.next_element.max(first.saturating_add(count as Id));
        first
    }
}
