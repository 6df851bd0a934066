//! The model of a set of cells in one configuration, with the
//! `unfold::model::builder` API: longerons, horizontals and diagonals as
//! beams (or, for the checks of the mechanism, as rigid links), corner
//! bodies and mid-hinge fittings as rigid bodies, and the hinges.
//!
//! Per face (`examples/era.md`): the top and the bottom horizontal, each
//! of two halves hinged to the corner bodies and to each other at the
//! mid-hinge, and two diagonals from the bottom corner bodies up to the
//! top mid-hinge, hinged at both ends: ten revolute joints. The hinges of
//! the top horizontal and of the diagonals are vertical (the top halves
//! fold in plan, each with its diagonal, about the vertical through its
//! corner hinge); those of the bottom horizontal are normal to the face
//! (its halves fold in the face plane, the mid-hinge rising). The first
//! half of a horizontal carries the mid-hinge fitting; the second half
//! and both diagonals are hinged to it.
//!
//! Each longeron with its two corner bodies is one part: the corner
//! bodies are rigid bodies on the longeron's end nodes (shared nodes: a
//! rigid connection).

use unfold::model::builder::*;
use unfold::model::input::{AnalysisInput, ModelInput};
use unfold::so3::Vec3;

use super::design::Design;
use super::geometry::{Configuration, Geometry};
use super::hinge::{self, HingeParts, Hinges};

/// How the members are modelled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Members {
    /// Geometrically exact beams, meshed as [`Design::mesh`] says, with
    /// the fittings' masses: the model of the deployment.
    Flexible,
    /// One node per member, a rigid link between its joints (no element):
    /// the model of a kinematic analysis and of the rank of the
    /// constraints.
    Rigid,
}

/// A member: the chain of its nodes, from its first end to its second,
/// and its beam elements (none for a rigid link, whose chain is its one
/// node).
#[derive(Clone, Debug, PartialEq)]
pub struct Member {
    /// Nodes from the first end to the second.
    pub nodes: Vec<NodeHandle>,
    /// Beam elements, in the same order.
    pub beams: Vec<BeamHandle>,
}

impl Member {
    /// The node at its first end.
    pub fn start(&self) -> NodeHandle {
        self.nodes[0]
    }

    /// The node at its second end.
    pub fn end(&self) -> NodeHandle {
        *self.nodes.last().expect("a member has a node")
    }
}

/// A longeron with its corner bodies.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// The longeron, from the bottom corner body up.
    pub longeron: Member,
    /// The node of the bottom corner body.
    pub bottom: NodeHandle,
    /// The node of the top corner body.
    pub top: NodeHandle,
}

/// A horizontal: two halves from the corner hinges to the mid-hinge.
#[derive(Clone, Debug, PartialEq)]
pub struct Horizontal {
    /// Halves at longeron `a` and at longeron `b`, each from its corner
    /// hinge to the mid-hinge.
    pub halves: [Member; 2],
    /// The mid-hinge.
    pub hinge: HingeParts,
}

/// The members of a face.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceParts {
    /// The longerons at its ends, `a` and `b` (indices into
    /// [`Parts::columns`]).
    pub columns: [usize; 2],
    /// Top horizontal.
    pub top: Horizontal,
    /// Bottom horizontal.
    pub bottom: Horizontal,
    /// Diagonals from the bottom corner bodies of `a` and `b` (first end)
    /// to the top mid-hinge (second end).
    pub diagonals: [Member; 2],
}

/// The parts of the model that checks and results refer to.
#[derive(Clone, Debug, PartialEq)]
pub struct Parts {
    /// Longerons, in layout order.
    pub columns: Vec<Column>,
    /// Faces, in layout order.
    pub faces: Vec<FaceParts>,
    /// The node clamped (bottom corner body of the first longeron in the
    /// list: the central one of a hexagon), if any.
    pub support: Option<NodeHandle>,
}

impl Parts {
    /// Every mid-hinge: top then bottom of each face.
    pub fn hinges(&self) -> impl Iterator<Item = &HingeParts> {
        self.faces
            .iter()
            .flat_map(|f| [&f.top.hinge, &f.bottom.hinge])
    }
}

/// What to build.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Scale of the configuration the model is built in (its reference).
    pub scale: f64,
    /// Beams or rigid links.
    pub members: Members,
    /// What holds or drives the mid-hinges.
    pub hinges: Hinges,
    /// Whether a bottom corner body is clamped (the structure is otherwise
    /// free in space).
    pub support: bool,
    /// Gravity (m/s²), if any.
    pub gravity: Option<[f64; 3]>,
    /// The analysis.
    pub analysis: AnalysisInput,
}

/// A model and its parts.
#[derive(Clone, Debug)]
pub struct Built {
    /// The model definition (what the model file holds).
    pub input: ModelInput,
    /// Its parts.
    pub parts: Parts,
    /// The configuration it was built in.
    pub configuration: Configuration,
}

/// Sections of the three kinds of member.
struct Sections {
    longeron: SectionHandle,
    horizontal: SectionHandle,
    diagonal: SectionHandle,
}

const VERTICAL: Vec3 = Vec3::new(0.0, 0.0, 1.0);

/// A member from `a` to `b`.
fn member(
    m: &mut ModelBuilder,
    kind: Members,
    a: Vec3,
    b: Vec3,
    elements: usize,
    section: SectionHandle,
) -> Member {
    match kind {
        Members::Flexible => {
            let (na, nb) = (m.node(a), m.node(b));
            let line = m.add(BeamLine::between(na, nb, elements, section));
            Member {
                nodes: line.nodes,
                beams: line.elements,
            }
        }
        Members::Rigid => Member {
            nodes: vec![m.node(0.5 * (a + b))],
            beams: Vec::new(),
        },
    }
}

/// A hinge between `a` and `b` at `point` about `axis`.
fn hinge(
    m: &mut ModelBuilder,
    a: NodeHandle,
    b: NodeHandle,
    point: Vec3,
    axis: Vec3,
) -> JointHandle {
    m.add(
        Joint::revolute(a, b)
            .at(point)
            .axis([axis.x, axis.y, axis.z]),
    )
}

/// A rigid body of `fitting` on `node` (flexible members only: the rigid
/// links of a kinematic model carry no mass).
fn fitting(m: &mut ModelBuilder, kind: Members, node: NodeHandle, f: super::design::Fitting) {
    if kind == Members::Flexible {
        m.add(RigidBody::at(node, f.mass).inertia(f.inertia()));
    }
}

/// Builds the model of `geometry` in the configuration of `options`.
pub fn build(geometry: &Geometry, options: &Options, title: &str) -> Built {
    let d: &Design = &geometry.design;
    let c = geometry.at(options.scale);
    let kind = options.members;
    let mut m = ModelBuilder::new(title);
    let section = |tube: &super::design::Tube, name: &str| {
        let s = tube.section().named(name);
        match d.rayleigh_beta {
            b if b > 0.0 => s.rayleigh_damping(0.0, b),
            _ => s,
        }
    };
    let sections = Sections {
        longeron: m.section(section(&d.longeron, "longeron")),
        horizontal: m.section(section(&d.horizontal, "horizontal")),
        diagonal: m.section(section(&d.diagonal, "diagonal")),
    };
    if let Some(g) = options.gravity {
        m.gravity(g);
    }

    // longerons and corner bodies
    let layout = &geometry.layout;
    let columns: Vec<Column> = c
        .columns
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let (a, b) = (Vec3::new(p[0], p[1], 0.0), Vec3::new(p[0], p[1], d.height));
            let longeron = member(&mut m, kind, a, b, d.mesh.longeron, sections.longeron);
            let (bottom, top) = (longeron.start(), longeron.end());
            // faces at k: a top clevis each at the top, a bottom and a
            // diagonal clevis each at the bottom
            let faces = layout.faces_at(k);
            fitting(&mut m, kind, top, d.corner_body(faces));
            fitting(&mut m, kind, bottom, d.corner_body(2 * faces));
            Column {
                longeron,
                bottom,
                top,
            }
        })
        .collect();

    // faces
    let mut faces = Vec::with_capacity(layout.faces.len());
    for (f, face) in layout.faces.iter().enumerate() {
        let p = &c.faces[f];
        let [a, b] = face.columns.map(|k| &columns[k]);
        let horizontal = |m: &mut ModelBuilder, top: bool| {
            let (ends, mid, bodies) = if top {
                (p.top, p.top_mid, [a.top, b.top])
            } else {
                (p.bottom, p.bottom_mid, [a.bottom, b.bottom])
            };
            let n = d.mesh.half_horizontal;
            let halves = [0, 1].map(|k| member(m, kind, ends[k], mid, n, sections.horizontal));
            let axis = geometry.hinge_axis(f, top);
            for k in 0..2 {
                hinge(m, halves[k].start(), bodies[k], ends[k], axis);
            }
            fitting(m, kind, halves[0].end(), d.mid_hinge_fitting(top));
            // the mid-hinge, about the axis oriented so that opening is
            // positive
            let sense = geometry.opening_sense(f, top);
            let joint = hinge(m, halves[0].end(), halves[1].end(), mid, sense * axis);
            let hinge = hinge::add(m, &d.hinge, joint, c.opening, options.hinges);
            Horizontal { halves, hinge }
        };
        let top = horizontal(&mut m, true);
        let bottom = horizontal(&mut m, false);
        let diagonals = [0, 1].map(|k| {
            let n = d.mesh.diagonal;
            member(&mut m, kind, p.diagonal[k], p.top_mid, n, sections.diagonal)
        });
        let bodies = [a.bottom, b.bottom];
        for k in 0..2 {
            hinge(
                &mut m,
                diagonals[k].start(),
                bodies[k],
                p.diagonal[k],
                VERTICAL,
            );
            hinge(
                &mut m,
                diagonals[k].end(),
                top.halves[0].end(),
                p.top_mid,
                VERTICAL,
            );
        }
        faces.push(FaceParts {
            columns: face.columns,
            top,
            bottom,
            diagonals,
        });
    }

    let support = options.support.then(|| {
        let node = columns[0].bottom;
        m.fix(node, Dofs::ALL);
        node
    });
    let mut input = m.into_input();
    input.analysis = options.analysis.clone().into();
    Built {
        input,
        parts: Parts {
            columns,
            faces,
            support,
        },
        configuration: c,
    }
}
