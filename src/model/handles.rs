//! Handles: what [`super::builder::ModelBuilder`] returns for each node and
//! element it adds, and how a built [`Model`] finds them again, so that a
//! program never translates ids into indices by hand.
//!
//! A handle holds the id written in the model file (and, for an element,
//! its kind): it stays valid for the model built from the builder, and for
//! the model read back from the file the builder wrote.

use std::fmt;

use super::input::{PanelPoint, PanelSide};
use super::{Id, Model};
use crate::elements::beam::SectionForces;
use crate::elements::{Element, ElementKind};
use crate::so3::Vec3;
use crate::state::State;

/// A node of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeHandle(pub(super) Id);

impl NodeHandle {
    /// The node's id in the model file.
    pub fn id(self) -> Id {
        self.0
    }
}

impl fmt::Display for NodeHandle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "node {}", self.0)
    }
}

/// Any handle of an element: its kind and its id.
pub trait ElementRef: Copy {
    /// The element's kind.
    fn kind(self) -> ElementKind;
    /// The element's id in the model file (for a load, its position in
    /// `loads`, from 1).
    fn id(self) -> Id;
}

macro_rules! element_handle {
    ($(#[$doc:meta])* $name:ident, $kind:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(pub(super) Id);

        impl $name {
            /// The element's id in the model file.
            pub fn id(self) -> Id {
                self.0
            }
        }

        impl ElementRef for $name {
            fn kind(self) -> ElementKind {
                $kind
            }
            fn id(self) -> Id {
                self.0
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "{} {}", $kind.name(), self.0)
            }
        }
    };
}

element_handle!(
    /// A beam element.
    BeamHandle,
    ElementKind::Beam
);
element_handle!(
    /// A shell element.
    ShellHandle,
    ElementKind::Shell
);
element_handle!(
    /// A rigid body.
    RigidBodyHandle,
    ElementKind::RigidBody
);
element_handle!(
    /// A point mass.
    PointMassHandle,
    ElementKind::PointMass
);
element_handle!(
    /// A spring between nodes or to the ground.
    SpringHandle,
    ElementKind::Spring
);
element_handle!(
    /// A nodal load (its id is its position in `loads`, from 1).
    LoadHandle,
    ElementKind::NodalLoad
);
element_handle!(
    /// A joint.
    JointHandle,
    ElementKind::Joint
);
element_handle!(
    /// A spring or damper on a joint coordinate.
    JointSpringHandle,
    ElementKind::JointSpring
);
element_handle!(
    /// A hysteretic moment law on a joint coordinate.
    HingeLawHandle,
    ElementKind::HingeLaw
);
element_handle!(
    /// A driver.
    DriverHandle,
    ElementKind::Driver
);
element_handle!(
    /// A latch.
    LatchHandle,
    ElementKind::Latch
);
element_handle!(
    /// A unilateral stop.
    StopHandle,
    ElementKind::Stop
);
element_handle!(
    /// A unilateral contact.
    ContactHandle,
    ElementKind::Contact
);
element_handle!(
    /// A rolling disc.
    RollingDiscHandle,
    ElementKind::RollingDisc
);

/// The nodes and elements of a beam line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BeamLineHandle {
    /// Every node along the line, from its first end node to its last
    /// (the interior nodes between them).
    pub nodes: Vec<NodeHandle>,
    /// The elements, in order along the line.
    pub elements: Vec<BeamHandle>,
}

impl BeamLineHandle {
    /// The nodes strictly inside the line.
    pub fn interior(&self) -> &[NodeHandle] {
        &self.nodes[1..self.nodes.len() - 1]
    }

    /// The first end node.
    pub fn start(&self) -> NodeHandle {
        self.nodes[0]
    }

    /// The last end node.
    pub fn end(&self) -> NodeHandle {
        self.nodes[self.nodes.len() - 1]
    }
}

/// The nodes and elements of a panel (docs/model-format.md,
/// `[[panels]]`): a grid of `(nx + 1) × (ny + 1)` nodes, `(i, j)` at
/// `i a/nx` along side `a` and `j b/ny` along side `b`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PanelHandle {
    /// Elements along each side, `[nx, ny]`.
    pub elements: [usize; 2],
    /// Id of the grid node `(0, 0)` (unless named otherwise).
    pub(super) first_node: Id,
    /// Ids given to the named points, in the order of [`PanelPoint::ALL`].
    pub(super) named: [Option<Id>; 8],
    /// The shells, `(i, j)` at `j nx + i`.
    pub shells: Vec<ShellHandle>,
    /// The beams of each stiffener (in the order given), from the start
    /// of its side.
    pub stiffeners: Vec<Vec<BeamHandle>>,
}

impl PanelHandle {
    /// The node at grid position `(i, j)`.
    ///
    /// # Panics
    /// Outside the grid.
    #[track_caller]
    pub fn node(&self, i: usize, j: usize) -> NodeHandle {
        let [nx, ny] = self.elements;
        assert!(
            i <= nx && j <= ny,
            "({i}, {j}) is outside the {nx} × {ny} panel"
        );
        let named = PanelPoint::at(nx, ny, i, j).and_then(|p| {
            let k = PanelPoint::ALL.iter().position(|q| *q == p)?;
            self.named[k]
        });
        NodeHandle(named.unwrap_or(self.first_node + (j * (nx + 1) + i) as Id))
    }

    /// A named node: a corner or the middle of a side.
    pub fn point(&self, point: PanelPoint) -> NodeHandle {
        let (i, j) = point.grid(self.elements[0], self.elements[1]);
        self.node(i, j)
    }

    /// The nodes along `side`, from its start (`south` and `north` from
    /// west to east, `east` and `west` from south to north).
    pub fn side(&self, side: PanelSide) -> Vec<NodeHandle> {
        let [nx, ny] = self.elements;
        match side {
            PanelSide::South => (0..=nx).map(|i| self.node(i, 0)).collect(),
            PanelSide::North => (0..=nx).map(|i| self.node(i, ny)).collect(),
            PanelSide::West => (0..=ny).map(|j| self.node(0, j)).collect(),
            PanelSide::East => (0..=ny).map(|j| self.node(nx, j)).collect(),
        }
    }

    /// Every node, row by row from the south side.
    pub fn nodes(&self) -> Vec<NodeHandle> {
        let [nx, ny] = self.elements;
        (0..=ny)
            .flat_map(|j| (0..=nx).map(move |i| (i, j)))
            .map(|(i, j)| self.node(i, j))
            .collect()
    }

    /// The shell at `(i, j)` (its corner nearest the origin at node
    /// `(i, j)`).
    pub fn shell(&self, i: usize, j: usize) -> ShellHandle {
        self.shells[j * self.elements[0] + i]
    }
}

/// The results of one element at one state, named as in its result file
/// (docs/results.md).
#[derive(Clone, Debug, PartialEq)]
pub struct ElementResults {
    /// Names of the quantities ([`Element::result_names`]).
    pub names: &'static [&'static str],
    /// Their values, in the same order.
    pub values: Vec<f64>,
}

impl ElementResults {
    /// The quantity named `name` (as in the header of the result file:
    /// `angle`, `slide`... for a joint's coordinates); `None` if the
    /// element has no such quantity (a coordinate its joint type does not
    /// have), or it is absent (the target of a released driver).
    pub fn get(&self, name: &str) -> Option<f64> {
        let i = self.names.iter().position(|n| *n == name)?;
        Some(self.values[i]).filter(|v| !v.is_nan())
    }
}

impl Model {
    /// Index of the node of `node`.
    ///
    /// # Panics
    /// If the model has no such node (a handle of another model).
    #[track_caller]
    pub fn node(&self, node: NodeHandle) -> usize {
        match self.node_index(node.0) {
            Some(i) => i,
            None => panic!("{node} is not in model \"{}\"", self.title),
        }
    }

    /// Reference position of `node`.
    #[track_caller]
    pub fn reference_position(&self, node: NodeHandle) -> Vec3 {
        self.reference_x[self.node(node)]
    }

    /// Index in [`Model::elements`] of the element of `handle`.
    ///
    /// # Panics
    /// If the model has no such element (a handle of another model).
    #[track_caller]
    pub fn element_index(&self, handle: impl ElementRef) -> usize {
        let (kind, id) = (handle.kind(), handle.id());
        let is = |i: usize| {
            self.elements
                .get(i)
                .is_some_and(|e| e.kind() == kind && e.id() == id)
        };
        // the table built with the model, or a search if elements were
        // added since
        match self.element_lookup.get(&(kind, id)) {
            Some(&i) if is(i) => i,
            _ => match (0..self.elements.len()).find(|&i| is(i)) {
                Some(i) => i,
                None => panic!("{} {id} is not in model \"{}\"", kind.name(), self.title),
            },
        }
    }

    /// The element of `handle`.
    #[track_caller]
    pub fn element(&self, handle: impl ElementRef) -> &dyn Element {
        &*self.elements[self.element_index(handle)]
    }

    /// The results of the element of `handle` at `state` (at its load
    /// parameter `state.time`), as written in its result file.
    #[track_caller]
    pub fn results(&self, handle: impl ElementRef, state: &State) -> ElementResults {
        let e = self.element(handle);
        let names = e.result_names();
        let mut values = vec![0.0; names.len()];
        e.results(
            &self.context(state.time, crate::elements::Need::RESIDUAL),
            state,
            &mut values,
        );
        ElementResults { names, values }
    }

    /// The shell element of `handle`, for its stress recovery
    /// ([`crate::elements::shell::Shell::layer_stresses`]).
    #[track_caller]
    pub fn shell(&self, handle: ShellHandle) -> &crate::elements::shell::Shell {
        self.element(handle)
            .as_shell()
            .expect("a shell handle refers to a shell element")
    }

    /// The section forces of a beam at `state`: `(N, V₂, V₃)` and
    /// `(T, M₂, M₃)` at its midpoint, in the section frame.
    #[track_caller]
    pub fn section_forces(&self, beam: BeamHandle, state: &State) -> SectionForces {
        let r = self.results(beam, state).values;
        SectionForces {
            force: Vec3::new(r[0], r[1], r[2]),
            moment: Vec3::new(r[3], r[4], r[5]),
        }
    }
}
