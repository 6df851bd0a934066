//! The registry of element kinds: what the code outside an element needs
//! to know about its kind, in one place. A new kind of element is a module
//! of its own (implementing [`super::Element`]) plus one variant here,
//! whose entries say how it is named in messages, coded in VTK files, and
//! which result file and VTK cell arrays its results go to; the result and
//! VTK writers (`crate::io`) read them and need no change.

/// The closed set of element kinds (for outputs and messages).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ElementKind {
    /// Geometrically exact beam.
    Beam,
    /// Rigid body attached to a node.
    RigidBody,
    /// Point mass attached to a node.
    PointMass,
    /// Linear spring.
    Spring,
    /// Nodal force and moment.
    NodalLoad,
    /// Kinematic constraint enforced with Lagrange multipliers (its extra
    /// unknowns).
    Constraint,
    /// Kinematic pair of the joint library.
    Joint,
    /// Spring or damper on a joint coordinate.
    JointSpring,
    /// Hysteretic moment law on a joint coordinate (hinge law with memory).
    HingeLaw,
    /// Prescribed history of a joint coordinate or node component.
    Driver,
    /// Lock of a joint coordinate at the end of its travel.
    Latch,
    /// Unilateral stop of a joint coordinate (joint limits with impact).
    Stop,
    /// Unilateral contact of a sphere on a node with a fixed plane or with
    /// a sphere on another node.
    Contact,
    /// Disc rolling without slipping on a plane.
    RollingDisc,
    /// Flat four-node shell of a laminated section (linear).
    Shell,
    /// Flexible body reduced by Craig–Bampton on a floating frame.
    Superelement,
}

/// A cell data array of the VTK files filled from an element's results:
/// `components` values from index `first` of [`super::Element::results`].
/// Cells of other kinds hold zeros.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellField {
    /// Name of the array.
    pub name: &'static str,
    /// Values per cell (1 for a scalar, 3 for a vector).
    pub components: usize,
    /// Index of the first value in the element's results.
    pub first: usize,
}

impl CellField {
    const fn new(name: &'static str, components: usize, first: usize) -> Self {
        Self {
            name,
            components,
            first,
        }
    }
}

impl ElementKind {
    /// Every kind, in the order of their result files and VTK arrays.
    pub const ALL: [ElementKind; 16] = [
        Self::Beam,
        Self::RigidBody,
        Self::PointMass,
        Self::Spring,
        Self::NodalLoad,
        Self::Constraint,
        Self::Joint,
        Self::JointSpring,
        Self::HingeLaw,
        Self::Driver,
        Self::Latch,
        Self::Stop,
        Self::Contact,
        Self::RollingDisc,
        Self::Shell,
        Self::Superelement,
    ];

    /// Lower-case name used in messages and output file names.
    pub fn name(self) -> &'static str {
        match self {
            Self::Beam => "beam",
            Self::RigidBody => "rigid body",
            Self::PointMass => "point mass",
            Self::Spring => "spring",
            Self::NodalLoad => "load",
            Self::Constraint => "constraint",
            Self::Joint => "joint",
            Self::JointSpring => "joint spring",
            Self::HingeLaw => "hinge law",
            Self::Driver => "driver",
            Self::Latch => "latch",
            Self::Stop => "stop",
            Self::Contact => "contact",
            Self::RollingDisc => "rolling disc",
            Self::Shell => "shell",
            Self::Superelement => "superelement",
        }
    }

    /// Numeric code written to VTK files (cell data `kind`).
    pub fn code(self) -> i32 {
        match self {
            Self::Beam => 1,
            Self::RigidBody => 2,
            Self::PointMass => 3,
            Self::Spring => 4,
            Self::NodalLoad => 5,
            Self::Constraint => 6,
            Self::Joint => 7,
            Self::JointSpring => 8,
            Self::Driver => 9,
            Self::HingeLaw => 10,
            Self::Latch => 11,
            Self::Stop => 12,
            Self::Contact => 14,
            Self::RollingDisc => 13,
            Self::Shell => 15,
            Self::Superelement => 16,
        }
    }

    /// The CSV file of the results of this kind (docs/results.md), with
    /// the header `step,time,<id column>,<result names…>`; `None` for kinds
    /// without results.
    pub fn results_file(self) -> Option<&'static str> {
        match self {
            Self::Beam => Some("beams.csv"),
            Self::Spring => Some("springs.csv"),
            Self::Joint => Some("joints.csv"),
            Self::Driver => Some("drivers.csv"),
            Self::JointSpring => Some("joint_springs.csv"),
            Self::HingeLaw => Some("hinge_laws.csv"),
            Self::Latch => Some("latches.csv"),
            Self::Stop => Some("stops.csv"),
            Self::Contact => Some("contacts.csv"),
            Self::RollingDisc => Some("rolling.csv"),
            Self::Shell => Some("shells.csv"),
            Self::Superelement => Some("superelements.csv"),
            Self::RigidBody | Self::PointMass | Self::NodalLoad | Self::Constraint => None,
        }
    }

    /// Name of the id column of [`Self::results_file`].
    pub fn id_column(self) -> &'static str {
        match self {
            Self::Joint => "joint",
            Self::Driver => "driver",
            Self::Latch => "latch",
            Self::Stop => "stop",
            Self::Contact => "contact",
            Self::RollingDisc => "joint",
            Self::Superelement => "superelement",
            _ => "element",
        }
    }

    /// The result columns of the file of this kind (after its id column)
    /// for elements reporting `names` (their
    /// [`super::Element::result_names`]): every name any of them reports,
    /// once. A joint reports its own coordinates only: the columns of
    /// joints are those of its joints in the order of
    /// [`crate::joints::joint::JOINT_COLUMNS`] (docs/results.md). The
    /// elements of every other kind report the same names.
    pub fn result_columns<'a>(
        self,
        names: impl IntoIterator<Item = &'a [&'static str]>,
    ) -> Vec<&'static str> {
        let mut columns: Vec<&'static str> = Vec::new();
        for list in names {
            for name in list {
                if !columns.contains(name) {
                    columns.push(name);
                }
            }
        }
        if self == Self::Joint {
            use crate::joints::joint::JOINT_COLUMNS;
            let place = |n: &&str| JOINT_COLUMNS.iter().position(|c| c == n);
            columns.sort_by_key(|n| place(n).unwrap_or(JOINT_COLUMNS.len()));
        }
        columns
    }

    /// The VTK cell arrays filled from the results of this kind.
    pub fn cell_fields(self) -> &'static [CellField] {
        const BEAM: [CellField; 6] = [
            CellField::new("N", 1, 0),
            CellField::new("V2", 1, 1),
            CellField::new("V3", 1, 2),
            CellField::new("T", 1, 3),
            CellField::new("M2", 1, 4),
            CellField::new("M3", 1, 5),
        ];
        const SHELL: [CellField; 4] = [
            CellField::new("shell_N", 3, 0),
            CellField::new("shell_M", 3, 3),
            CellField::new("shell_Q", 2, 6),
            CellField::new("shell_von_mises", 1, 8),
        ];
        const SPRING: [CellField; 2] = [
            CellField::new("spring_F", 3, 0),
            CellField::new("spring_D", 3, 3),
        ];
        match self {
            Self::Beam => &BEAM,
            Self::Spring => &SPRING,
            Self::Shell => &SHELL,
            _ => &[],
        }
    }
}

/// Shape of an element in the VTK output: the cell drawn through its first
/// [`CellShape::nodes`] nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellShape {
    /// A line between the element's two nodes.
    Line,
    /// A vertex at the element's node.
    Vertex,
    /// A quadrilateral through the element's four nodes, in order around
    /// it (shells).
    Quad,
    /// Not drawn.
    None,
}

impl CellShape {
    /// Number of nodes of the cell.
    pub fn nodes(self) -> usize {
        match self {
            Self::Vertex => 1,
            Self::Line => 2,
            Self::Quad => 4,
            Self::None => 0,
        }
    }

    /// VTK cell type code (`VTK_VERTEX` 1, `VTK_LINE` 3, `VTK_QUAD` 9);
    /// `None` for an element that is not drawn.
    pub fn vtk_type(self) -> Option<u8> {
        match self {
            Self::Vertex => Some(1),
            Self::Line => Some(3),
            Self::Quad => Some(9),
            Self::None => None,
        }
    }

    /// The shape of a cell of `n` points (1, 2 or 4).
    pub fn with_nodes(n: usize) -> Self {
        match n {
            1 => Self::Vertex,
            2 => Self::Line,
            4 => Self::Quad,
            _ => Self::None,
        }
    }
}
