//! Nodes, sections, beams, masses and springs.

use super::{Body, CurveHandle, Entity, ModelBuilder};
use crate::elements::spring::SpringKind;
use crate::model::handles::{
    BeamHandle, BeamLineHandle, NodeHandle, PointMassHandle, RigidBodyHandle, SpringHandle,
};
use crate::model::input::{
    AngleUnit, BeamInput, BeamLineInput, InertiaInput, NodeInput, PointMassInput, RigidBodyInput,
    SectionInput, ShapeInput, SpringInput, StiffnessInput,
};
use crate::model::{Id, MAX_LINE_ELEMENTS};

/// A node: position and orientation in the reference configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    input: NodeInput,
    id: Option<Id>,
}

impl Node {
    /// A node at `x` with the identity orientation.
    pub fn at(x: impl Into<[f64; 3]>) -> Self {
        Self {
            input: NodeInput {
                id: 0,
                x: x.into(),
                rotation: None,
                unit: None,
                velocity: None,
                angular_velocity: None,
            },
            id: None,
        }
    }

    /// Its orientation, as a rotation vector (global frame) in radians.
    pub fn rotation(mut self, psi: impl Into<[f64; 3]>) -> Self {
        self.input.rotation = Some(psi.into());
        self
    }

    /// The unit of the rotation vector.
    pub fn unit(mut self, unit: AngleUnit) -> Self {
        self.input.unit = Some(unit);
        self
    }

    /// Its initial velocity (global frame), for dynamic analyses.
    pub fn velocity(mut self, v: impl Into<[f64; 3]>) -> Self {
        self.input.velocity = Some(v.into());
        self
    }

    /// Its initial angular velocity (global frame, rad/s), for dynamic
    /// analyses.
    pub fn angular_velocity(mut self, w: impl Into<[f64; 3]>) -> Self {
        self.input.angular_velocity = Some(w.into());
        self
    }

    /// Its id (default: the next free one).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Node {
    type Handle = NodeHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> NodeHandle {
        self.input.id = m.node_id(self.id, 1);
        let handle = NodeHandle(self.input.id);
        m.input.nodes.push(self.input);
        handle
    }
}

/// A beam cross-section, by its sectional stiffness and its mass.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    input: SectionInput,
}

/// A section of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SectionHandle(usize);

impl Section {
    /// A section of diagonal stiffness: axial `EA`, shear `GA2`, `GA3`
    /// (κ·G·A along local axes 2 and 3), torsion `GJ`, bending `EI2`,
    /// `EI3` about local axes 2 and 3.
    pub fn diagonal(ea: f64, ga2: f64, ga3: f64, gj: f64, ei2: f64, ei3: f64) -> Self {
        Self {
            input: SectionInput::diagonal("", [ea, ga2, ga3, gj, ei2, ei3]),
        }
    }

    /// A section of full symmetric 6×6 stiffness (rows), in the order
    /// axial strain, shear strains 2 and 3, torsion, curvatures 2 and 3.
    pub fn full(stiffness: [[f64; 6]; 6]) -> Self {
        Self {
            input: SectionInput {
                stiffness: Some(stiffness),
                ..SectionInput::default()
            },
        }
    }

    /// Its mass per unit length.
    pub fn mass_per_length(mut self, mass: f64) -> Self {
        self.input.mass_per_length = Some(mass);
        self
    }

    /// Its rotational inertia per unit length about the local axes 1, 2, 3
    /// (ρJ, ρI₂, ρI₃).
    pub fn inertia_per_length(mut self, inertia: [f64; 3]) -> Self {
        self.input.inertia_per_length = Some(inertia);
        self
    }

    /// Its Rayleigh damping `C_R = α M + β K_mat` (docs/theory.md §11.5):
    /// `alpha` in 1/s, `beta` in s.
    pub fn rayleigh_damping(mut self, alpha: f64, beta: f64) -> Self {
        self.input.rayleigh_alpha = Some(alpha);
        self.input.rayleigh_beta = Some(beta);
        self
    }

    /// Its name in the model file (default `section_N`, N its position).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.input.name = name.into();
        self
    }

    /// The section as the model file writes it, named `name`.
    pub fn into_input(mut self, name: impl Into<String>) -> SectionInput {
        self.input.name = name.into();
        self.input
    }
}

impl Entity for Section {
    type Handle = SectionHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> SectionHandle {
        let k = m.input.sections.len();
        if self.input.name.is_empty() {
            self.input.name = format!("section_{}", k + 1);
        }
        m.input.sections.push(self.input);
        SectionHandle(k)
    }
}

impl ModelBuilder {
    /// The name of a section in the model file.
    pub(super) fn section_name(&self, s: SectionHandle) -> String {
        self.input.sections[s.0].name.clone()
    }
}

/// What beams and beam lines share: section, orientation, initial strain.
#[derive(Clone, Debug, PartialEq)]
struct BeamProperties {
    section: SectionHandle,
    orientation: Option<[f64; 3]>,
    initial_strain: Option<[f64; 6]>,
    initial_strain_curve: Option<CurveHandle>,
}

impl BeamProperties {
    fn new(section: SectionHandle) -> Self {
        Self {
            section,
            orientation: None,
            initial_strain: None,
            initial_strain_curve: None,
        }
    }
}

macro_rules! beam_properties {
    () => {
        /// Reference vector of the section: local axis 2 is its part
        /// normal to the beam axis (default: global z, or global x for
        /// beams along z).
        pub fn orientation(mut self, v: impl Into<[f64; 3]>) -> Self {
            self.properties.orientation = Some(v.into());
            self
        }

        /// Sectional strains at which the section is stress-free (axial,
        /// shear 2, shear 3, torsion, curvature 2, curvature 3).
        pub fn initial_strain(mut self, strain: [f64; 6]) -> Self {
            self.properties.initial_strain = Some(strain);
            self
        }

        /// An axial initial strain alone: negative shortens the beam
        /// (pretension).
        pub fn axial_strain(self, strain: f64) -> Self {
            self.initial_strain([strain, 0.0, 0.0, 0.0, 0.0, 0.0])
        }

        /// The curve applying the initial strain gradually (default: all
        /// of it from `t = 0`).
        pub fn initial_strain_curve(mut self, curve: CurveHandle) -> Self {
            self.properties.initial_strain_curve = Some(curve);
            self
        }
    };
}

/// A two-node beam element.
#[derive(Clone, Debug, PartialEq)]
pub struct Beam {
    nodes: [NodeHandle; 2],
    properties: BeamProperties,
    id: Option<Id>,
}

impl Beam {
    /// A beam from `a` to `b` of `section`.
    pub fn between(a: NodeHandle, b: NodeHandle, section: SectionHandle) -> Self {
        Self {
            nodes: [a, b],
            properties: BeamProperties::new(section),
            id: None,
        }
    }

    beam_properties!();

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Beam {
    type Handle = BeamHandle;
    fn add_to(self, m: &mut ModelBuilder) -> BeamHandle {
        let id = m.element_id(self.id, 1);
        let p = self.properties;
        let input = BeamInput {
            id,
            nodes: self.nodes.map(|n| n.0),
            section: m.section_name(p.section),
            orientation: p.orientation,
            initial_strain: p.initial_strain,
            initial_strain_curve: p.initial_strain_curve.map(|c| m.curve_name(c)),
        };
        m.input.beams.push(input);
        BeamHandle(id)
    }
}

/// A straight line or a circular arc between two nodes, meshed into beam
/// elements of equal length; its interior nodes and its elements take the
/// next free ids.
#[derive(Clone, Debug, PartialEq)]
pub struct BeamLine {
    nodes: [NodeHandle; 2],
    elements: usize,
    arc_center: Option<[f64; 3]>,
    properties: BeamProperties,
}

impl BeamLine {
    /// `elements` beams of `section` from `a` to `b`.
    pub fn between(a: NodeHandle, b: NodeHandle, elements: usize, section: SectionHandle) -> Self {
        Self {
            nodes: [a, b],
            elements,
            arc_center: None,
            properties: BeamProperties::new(section),
        }
    }

    /// A circular arc about `center` (equidistant from both end nodes)
    /// instead of a straight line.
    pub fn arc(mut self, center: impl Into<[f64; 3]>) -> Self {
        self.arc_center = Some(center.into());
        self
    }

    beam_properties!();
}

impl Entity for BeamLine {
    type Handle = BeamLineHandle;
    fn add_to(self, m: &mut ModelBuilder) -> BeamLineHandle {
        // a line beyond the limit is reported by the validation, and
        // generates nothing
        let n = self.elements;
        let generated = if n <= MAX_LINE_ELEMENTS { n } else { 0 };
        let interior = generated.saturating_sub(1);
        let first_node = (interior > 0).then(|| m.node_id(None, interior));
        let first_element = m.element_id(None, generated);
        let p = self.properties;
        let input = BeamLineInput {
            nodes: self.nodes.map(|n| n.0),
            elements: n,
            section: m.section_name(p.section),
            orientation: p.orientation,
            first_node,
            first_element: Some(first_element),
            arc_center: self.arc_center,
            initial_strain: p.initial_strain,
            initial_strain_curve: p.initial_strain_curve.map(|c| m.curve_name(c)),
        };
        m.input.beam_lines.push(input);
        let mut nodes = vec![self.nodes[0]];
        if let Some(first) = first_node {
            nodes.extend((0..interior as Id).map(|i| NodeHandle(first + i)));
        }
        nodes.push(self.nodes[1]);
        BeamLineHandle {
            nodes,
            elements: (0..generated as Id)
                .map(|i| BeamHandle(first_element + i))
                .collect(),
        }
    }
}

/// A rigid body carried by a node.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidBody {
    input: RigidBodyInput,
    id: Option<Id>,
}

impl RigidBody {
    /// A body of `mass` carried by `node`, its centre of mass at the node
    /// and no rotational inertia.
    pub fn at(node: NodeHandle, mass: f64) -> Self {
        Self {
            input: RigidBodyInput {
                id: 0,
                node: node.0,
                mass,
                inertia: None,
                center_of_mass: None,
                shape: None,
            },
            id: None,
        }
    }

    /// Its principal inertia `[I11, I22, I33]` about the centre of mass,
    /// along the node's material axes.
    pub fn inertia(mut self, principal: [f64; 3]) -> Self {
        self.input.inertia = Some(InertiaInput::Diagonal(principal));
        self
    }

    /// Its full inertia tensor about the centre of mass (rows), in the
    /// node's material frame.
    pub fn inertia_tensor(mut self, rows: [[f64; 3]; 3]) -> Self {
        self.input.inertia = Some(InertiaInput::Full(rows));
        self
    }

    /// Position of its centre of mass relative to the node, in the node's
    /// material frame.
    pub fn center_of_mass(mut self, offset: impl Into<[f64; 3]>) -> Self {
        self.input.center_of_mass = Some(offset.into());
        self
    }

    /// The shape it is drawn with (default: the box of its mass and
    /// inertia): `Shape::box_of`, `Shape::plate`, `Shape::cylinder` or
    /// `Shape::point`.
    pub fn shape(mut self, shape: ShapeInput) -> Self {
        self.input.shape = Some(shape);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for RigidBody {
    type Handle = RigidBodyHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> RigidBodyHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = RigidBodyHandle(self.input.id);
        m.input.rigid_bodies.push(self.input);
        handle
    }
}

/// A point mass carried by a node.
#[derive(Clone, Debug, PartialEq)]
pub struct PointMass {
    input: PointMassInput,
    id: Option<Id>,
}

impl PointMass {
    /// A point of `mass` at `node`.
    pub fn at(node: NodeHandle, mass: f64) -> Self {
        Self {
            input: PointMassInput {
                id: 0,
                node: node.0,
                mass,
            },
            id: None,
        }
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for PointMass {
    type Handle = PointMassHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> PointMassHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = PointMassHandle(self.input.id);
        m.input.point_masses.push(self.input);
        handle
    }
}

/// A linear spring between two nodes, or between a node and the ground
/// (at the node's reference position and orientation).
#[derive(Clone, Debug, PartialEq)]
pub struct Spring {
    input: SpringInput,
    id: Option<Id>,
}

impl Spring {
    fn new(kind: SpringKind, a: NodeHandle, b: Body, stiffness: StiffnessInput) -> Self {
        Self {
            input: SpringInput {
                id: 0,
                kind,
                nodes: b.with_first(a),
                stiffness,
                damping: None,
                damping_ratio: None,
            },
            id: None,
        }
    }

    /// Resists the relative displacement along the global axes: one
    /// stiffness, or one per axis.
    pub fn translational(
        a: NodeHandle,
        b: impl Into<Body>,
        stiffness: impl Into<StiffnessInput>,
    ) -> Self {
        Self::new(SpringKind::Translational, a, b.into(), stiffness.into())
    }

    /// Resists the relative rotation, in `a`'s material frame (the global
    /// frame to the ground): one stiffness, or one per axis.
    pub fn rotational(
        a: NodeHandle,
        b: impl Into<Body>,
        stiffness: impl Into<StiffnessInput>,
    ) -> Self {
        Self::new(SpringKind::Rotational, a, b.into(), stiffness.into())
    }

    /// Resists the change of the distance between two nodes.
    pub fn axial(a: NodeHandle, b: NodeHandle, stiffness: f64) -> Self {
        Self::new(
            SpringKind::Axial,
            a,
            Body::Node(b),
            StiffnessInput::Isotropic(stiffness),
        )
    }

    /// A linear damper in parallel (dynamics only): one coefficient, or
    /// one per axis (N·s/m, N·m·s/rad).
    pub fn damping(mut self, c: impl Into<StiffnessInput>) -> Self {
        self.input.damping = Some(c.into());
        self
    }

    /// A damper in parallel given by its damping ratio `ζ`: `c = 2ζ√(k m)`
    /// on each axis, `m` the mass (or inertia) of the bodies the spring
    /// connects (docs/model-format.md, `[[springs]]`).
    pub fn damping_ratio(mut self, zeta: f64) -> Self {
        self.input.damping_ratio = Some(zeta);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Spring {
    type Handle = SpringHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> SpringHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = SpringHandle(self.input.id);
        m.input.springs.push(self.input);
        handle
    }
}
