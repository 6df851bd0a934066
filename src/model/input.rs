//! The model definition as written by a user: the schema of the TOML model
//! file (docs/model-format.md), also usable directly from Rust.
//!
//! Every table rejects unknown fields, so a misspelt key is an error and not
//! a silently ignored value. A [`ModelInput`] is turned into a validated
//! [`crate::model::Model`] by [`crate::model::Model::from_input`].

use serde::{Deserialize, Serialize};

pub use super::Id;
pub use crate::elements::spring::SpringKind;

/// Largest id: TOML integers are 64-bit signed, so a model with a larger id
/// (or generating one, see `beam_lines`) could not be written back.
pub const MAX_ID: Id = i64::MAX as Id;

/// The unit of the angles of an entry (`unit = "deg"`); radians by default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AngleUnit {
    /// Radians.
    #[default]
    Rad,
    /// Degrees.
    Deg,
}

impl AngleUnit {
    /// Radians per unit.
    pub fn radians(self) -> f64 {
        match self {
            Self::Rad => 1.0,
            Self::Deg => std::f64::consts::PI / 180.0,
        }
    }

    /// Name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Rad => "rad",
            Self::Deg => "deg",
        }
    }
}

/// The keys of the top level of a model file ([`ModelInput`]'s fields).
pub const TOP_LEVEL_KEYS: [&str; 29] = [
    "title",
    "analysis",
    "nodes",
    "sections",
    "beams",
    "beam_lines",
    "ply_materials",
    "laminates",
    "shells",
    "panels",
    "rigid_bodies",
    "point_masses",
    "springs",
    "supports",
    "prescribed",
    "loads",
    "gravity",
    "curves",
    "joints",
    "joint_springs",
    "hinge_laws",
    "drivers",
    "latches",
    "stops",
    "contacts",
    "rolling_discs",
    "superelements",
    "initial_motion",
    "output",
];

/// A complete model definition.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModelInput {
    /// Free text describing the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
    /// The analysis to run and its parameters: one `[analysis]` table, or
    /// a sequence of `[[analysis]]` tables run one after the other.
    #[serde(default)]
    pub analysis: Analyses,
    /// Nodes: positions and orientations of the reference configuration.
    #[serde(default)]
    pub nodes: Vec<NodeInput>,
    /// Beam cross-section properties, referenced by name.
    #[serde(default)]
    pub sections: Vec<SectionInput>,
    /// Two-node geometrically exact beam elements.
    #[serde(default)]
    pub beams: Vec<BeamInput>,
    /// Straight or circular lines meshed into beam elements.
    #[serde(default)]
    pub beam_lines: Vec<BeamLineInput>,
    /// Orthotropic (or isotropic) ply materials, referenced by name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ply_materials: Vec<PlyMaterialInput>,
    /// Shell sections: ply stacks and sandwiches, referenced by name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub laminates: Vec<LaminateInput>,
    /// Four-node shell elements.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shells: Vec<ShellInput>,
    /// Rectangular panels meshed into shell elements, with property zones
    /// and edge stiffeners.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub panels: Vec<PanelInput>,
    /// Rigid bodies attached to a node.
    #[serde(default)]
    pub rigid_bodies: Vec<RigidBodyInput>,
    /// Point masses attached to a node.
    #[serde(default)]
    pub point_masses: Vec<PointMassInput>,
    /// Linear springs between two nodes or from a node to the ground.
    #[serde(default)]
    pub springs: Vec<SpringInput>,
    /// Fixed degrees of freedom.
    #[serde(default)]
    pub supports: Vec<SupportInput>,
    /// Prescribed displacements and rotations.
    #[serde(default)]
    pub prescribed: Vec<PrescribedInput>,
    /// Nodal forces and moments.
    #[serde(default)]
    pub loads: Vec<LoadInput>,
    /// Uniform gravity field acting on every mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<GravityInput>,
    /// Piecewise-linear load curves, referenced by name.
    #[serde(default)]
    pub curves: Vec<CurveInput>,
    /// Kinematic pairs (docs/joints.md).
    #[serde(default)]
    pub joints: Vec<JointInput>,
    /// Springs and dampers on joint coordinates.
    #[serde(default)]
    pub joint_springs: Vec<JointSpringInput>,
    /// Hysteretic moment laws on joint coordinates (hinge laws with
    /// memory).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hinge_laws: Vec<HingeLawInput>,
    /// Prescribed histories of joint coordinates or node components.
    #[serde(default)]
    pub drivers: Vec<DriverInput>,
    /// Locks of joint coordinates at the end of their travel.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub latches: Vec<LatchInput>,
    /// Unilateral stops of joint coordinates (joint limits).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stops: Vec<StopInput>,
    /// Unilateral contacts of spheres on nodes with fixed planes or with
    /// each other.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactInput>,
    /// Discs rolling without slipping on fixed planes (docs/joints.md
    /// §3.8).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rolling_discs: Vec<RollingDiscInput>,
    /// Flexible bodies reduced by Craig–Bampton (docs/model-format.md,
    /// "Superelements").
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub superelements: Vec<SuperelementInput>,
    /// Rigid motions of sets of nodes at the start (dynamic analyses).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub initial_motion: Vec<InitialMotionInput>,
    /// What a run writes besides the result files (`[output]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<OutputInput>,
    /// The directory of the model file, against which the files a
    /// superelement names are found (set by
    /// [`crate::io::model_file::read_model`]; none: the working
    /// directory). Not part of the file.
    #[serde(skip)]
    pub base_dir: Option<std::path::PathBuf>,
}

/// A flexible body reduced by Craig–Bampton and moved as a superelement
/// on a floating frame (docs/model-format.md, "Superelements";
/// docs/theory.md §18). Its body comes from one source: `elements` of
/// this model, a `model` file of the body, Matrix Market `stiffness`,
/// `mass` and `dofs` files, or a Nastran `dmig` punch file.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SuperelementInput {
    /// Element id.
    pub id: Id,
    /// The boundary nodes: ids of nodes of the body that keep their six
    /// dofs and are nodes of the model (joints and beams attach to them).
    pub boundary: Vec<Id>,
    /// The model's nodes the boundary nodes are, in the same order, for a
    /// body from a file (default: the same ids). Each must be where its
    /// boundary node is placed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodes: Option<Vec<Id>>,
    /// The boundary node whose frame is the floating frame (default the
    /// first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_node: Option<Id>,
    /// Source: ids of beams (of `[[beams]]` or `[[beam_lines]]`), rigid
    /// bodies and point masses of this model, reduced together; their
    /// nodes that are not boundary nodes leave the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<Vec<Id>>,
    /// Source: a model file of the body (its beams, rigid bodies and point
    /// masses; supports, loads and analyses ignored), relative to this
    /// file's directory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// Source: the stiffness, a Matrix Market file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<String>,
    /// Source: the mass, a Matrix Market file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<String>,
    /// Source: the dof map of the Matrix Market files (`node component`
    /// per row).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dofs: Option<String>,
    /// Source: a Nastran punch file of DMIG entries.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dmig: Option<String>,
    /// Name of the stiffness in the DMIG file (default `KAAX`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dmig_stiffness: Option<String>,
    /// Name of the mass in the DMIG file (default `MAAX`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dmig_mass: Option<String>,
    /// Imported matrices: the node coordinates (`id x y z` per line);
    /// default the model's nodes of the same ids.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinates: Option<String>,
    /// Imported matrices: the cells to draw (`id n1 n2 [n3 [n4]]` per
    /// line).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cells: Option<String>,
    /// A body from a file: where its origin is placed in the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f64; 3]>,
    /// A body from a file: the rotation vector that turns its axes into
    /// the model's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f64; 3]>,
    /// Unit of `rotation`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// Number of fixed-interface modes kept...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    /// ...or every mode up to this frequency (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_frequency: Option<f64>,
    /// Modal damping ratio: one for every mode, or one per mode (default
    /// 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<DampingRatioInput>,
    /// `consistent` (default: the body's mass matrix) or `lumped` (point
    /// masses at the nodes, the reference paper's eq. 27–29).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<crate::reduction::InertiaModel>,
    /// Whether the free-free frequencies of the full body are computed to
    /// check the reduction (default true; a Lanczos solve of the whole
    /// body).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub check_frequencies: Option<bool>,
}

/// Modal damping ratios: one value or one per mode.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum DampingRatioInput {
    /// The same ratio for every mode.
    All(f64),
    /// One ratio per mode, in increasing frequency.
    PerMode(Vec<f64>),
}

/// `[output]`: files a run writes besides the results.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputInput {
    /// Times at which a restart file `restart-<t>.json` is written
    /// (besides `restart.json` at the end of every run), in increasing
    /// order, within the analyses; the analyses land on them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub restart_times: Vec<f64>,
    /// Charts written with the results when the run ends (`joints`,
    /// `moments`, `energies`; docs/plots.md), into `plots/` of the
    /// output directory.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plots: Vec<String>,
    /// Whether the VTK grids (`vtk/step_NNNNN.vtu`, `unfold.pvd`) are
    /// written (default true); the CSV histories are written either way.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtk: Option<bool>,
    /// A VTK grid at every `vtk_every`-th output step (the first, then
    /// every N-th; default 1, every output step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtk_every: Option<u64>,
}

impl OutputInput {
    /// Every how many output steps a VTK grid is written; 0: none.
    pub fn vtk_interval(output: Option<&Self>) -> usize {
        match output {
            Some(o) if o.vtk == Some(false) => 0,
            Some(o) => o.vtk_every.map_or(1, |n| n.max(1) as usize),
            None => 1,
        }
    }
}

/// A kinematic pair between node A and node B (or the ground).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointInput {
    /// Element id (unique among all elements).
    pub id: Id,
    /// `revolute`, `prismatic`, `cylindrical`, `spherical`, `planar`,
    /// `universal`, `helical`, `slider`, `rigid` or `glue`.
    #[serde(rename = "type")]
    pub kind: crate::joints::JointType,
    /// `[A, B]`, or `[A]` for a joint to the ground.
    pub nodes: Vec<Id>,
    /// Joint axis `e₃` (hinge, sliding or screw axis; normal of a planar
    /// joint), reference configuration. Universal joints: the cross arm
    /// carried by A.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    /// The same axis as carried by body B, when the model gives each body's
    /// axis (paper eq. 19); must coincide with `axis`. Universal joints:
    /// the cross arm carried by B, perpendicular to `axis`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_b: Option<[f64; 3]>,
    /// Direction from which angles are measured (`e₁`), default: a
    /// direction normal to the axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_direction: Option<[f64; 3]>,
    /// Joint point, default the first node's position (not for `glue`,
    /// whose point is set by `offset`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f64; 3]>,
    /// Helical joints: axial advance per turn (signed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch: Option<f64>,
    /// Glue: where node B is held, in A's material frame (default: where B
    /// is in the reference configuration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<[f64; 3]>,
    /// Glue: whether B's rotations are locked to A's too (default true).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lock_rotations: Option<bool>,
    /// Slider: the nodes the curve passes through, in order (at least 2).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub curve: Vec<Id>,
    /// Slider: a C¹ spline (default) or a polyline (`false`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spline: Option<bool>,
}

/// A spring and/or a damper on a joint coordinate.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointSpringInput {
    /// Element id.
    pub id: Id,
    /// The joint.
    pub joint: Id,
    /// Which coordinate (`angle`, `slide`, `angle1`...), default the joint's
    /// first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// Unit of the angles when the coordinate is an angle: `free_value`,
    /// the abscissae of `table`, and the angle in `stiffness` (N·m per
    /// unit), `damping` and `damping_table` (per unit per unit of `t`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// Linear spring: stiffness (N/m or N·m/rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Linear spring: coordinate value at which it is unloaded (default 0,
    /// the reference configuration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_value: Option<f64>,
    /// Nonlinear spring: points `[coordinate, force]` (force or moment),
    /// interpolated linearly and extrapolated with the end slopes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub table: Vec<[f64; 2]>,
    /// Linear damper: coefficient (N·s/m or N·m·s/rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Nonlinear damper: points `[rate, force]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub damping_table: Vec<[f64; 2]>,
}

/// A hysteretic moment law on a joint coordinate (docs/joints.md §4.1):
/// two bounding branches, given as tables or as the tape-spring shape,
/// and the elastic slope between them.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HingeLawInput {
    /// Element id.
    pub id: Id,
    /// The joint.
    pub joint: Id,
    /// Which coordinate (`angle`, `slide`, `angle1`...), default the joint's
    /// first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// Unit of the angles when the coordinate is an angle: table abscissae,
    /// the angles of the tape-spring shape, and the angle in the slopes
    /// (N·m per unit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// `k_e > 0`: slope of the moment between the bounds (N·m/rad or N/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic_slope: Option<f64>,
    /// The loading bound `f_load`: points `[coordinate, moment]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub load_table: Vec<[f64; 2]>,
    /// The unloading bound `f_unload`: points `[coordinate, moment]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unload_table: Vec<[f64; 2]>,
    /// Both bounds from the analytic tape-spring shape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tape_spring: Option<TapeSpringInput>,
    /// The bound the hinge starts on in the reference configuration:
    /// `load` (default) or `unload`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<StartBranch>,
}

/// The bound a hinge law starts on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StartBranch {
    /// The loading bound `f_load(0)`.
    #[default]
    Load,
    /// The unloading bound `f_unload(0)`.
    Unload,
}

/// Parameters of the tape-spring shape (docs/joints.md §4.1), angles in
/// the unit of the entry.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TapeSpringInput {
    /// `M_d ≥ 0`: moment deploying the hinge over its travel (N·m).
    pub deployment_moment: f64,
    /// `c_L`: angle at which the hinge locks.
    pub locking_angle: f64,
    /// `M_L > M_d`: moment that unlocks (folds) the locked hinge (N·m).
    pub locking_peak: f64,
    /// `K > 0`: slope of the locked branch (N·m per angle unit).
    pub locked_stiffness: f64,
    /// `w > 0`: width over which the moment falls from `M_L` to `M_d` when
    /// the hinge unlocks.
    pub snap_width: f64,
    /// `h ≥ 0`: half-width of the rounding of the corners (default: a
    /// quarter of the smaller of `w` and `M_d/K`; 0 for sharp corners).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rounding: Option<f64>,
}

/// A prescribed history `value · f(t)` of a joint coordinate, or of a
/// node's translation along or rotation about a direction, relative to the
/// reference configuration.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DriverInput {
    /// Element id.
    pub id: Id,
    /// The joint whose coordinate is driven...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<Id>,
    /// ...and which coordinate (default the joint's first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// Or the node that is driven...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<Id>,
    /// ...along (translation) or about (rotation) this global direction...
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
    /// ...`translation` (default) or `rotation`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
    /// Value of the coordinate when the curve equals 1 (m, or rad unless
    /// `unit` says otherwise).
    pub value: f64,
    /// Unit of `value` for an angle coordinate or a node rotation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// Curve `f(t)`, default the ramp `f(t) = t`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
    /// `[start, end]`: the driver acts only while `start ≤ t ≤ end` and is
    /// released outside (`end` may be `inf`); one starting at `start > 0`
    /// takes over the coordinate where it is then. Default: always.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub active: Option<[f64; 2]>,
}

/// A latch on a joint coordinate (docs/joints.md §6.2): the coordinate locks
/// when it reaches `value` moving in the direction of approach, rigidly
/// (and stays locked) or through a stiff spring (which may release).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LatchInput {
    /// Element id.
    pub id: Id,
    /// The joint.
    pub joint: Id,
    /// Which coordinate (`angle`, `slide`, `angle1`...), default the joint's
    /// first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// Locking value `c_L` (m, or rad unless `unit` says otherwise).
    pub value: f64,
    /// Unit of `value` for an angle coordinate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// `increasing` or `decreasing`: how the coordinate reaches `value`
    /// (default: away from the reference configuration, where it is 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approach: Option<Approach>,
    /// `rigid` (default): once locked, `c = c_L` is a constraint;
    /// `spring`: a stiff spring about `c_L`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<LatchMode>,
    /// Spring mode: its stiffness `k > 0` (N·m/rad or N/m; per `unit` on
    /// an angle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Spring mode: the total width `b ≥ 0` of the dead band about `c_L`
    /// (m, or rad unless `unit` says otherwise), default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backlash: Option<f64>,
    /// Spring mode: the coefficient `d ≥ 0` of its dashpot (N·m·s/rad or
    /// N·s/m; per `unit` on an angle), default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Spring mode: the load (N·m or N) at which it releases; none: never.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unlatch_load: Option<f64>,
    /// Spring mode: the side of `c_L` its spring acts on (default both).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<LatchSide>,
}

/// A unilateral stop on a joint coordinate (docs/joints.md §6.3): the
/// coordinate stays within `[lower, upper]`, impacts at a limit with
/// restitution `restitution`, and rests against it in persistent contact.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StopInput {
    /// Element id.
    pub id: Id,
    /// The joint.
    pub joint: Id,
    /// Which coordinate (`angle`, `slide`, `angle1`...), default the joint's
    /// first.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// `c_min` (m, or rad unless `unit` says otherwise); none: no lower
    /// limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    /// `c_max`; none: no upper limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    /// Unit of the limits for an angle coordinate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// Coefficient of restitution `e ∈ [0, 1]`, default 0 (plastic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
}

/// What a contact is between.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactType {
    /// A sphere on a node and a fixed plane.
    #[default]
    Plane,
    /// Spheres on two nodes.
    Spheres,
}

impl ContactType {
    /// Name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Plane => "plane",
            Self::Spheres => "spheres",
        }
    }
}

/// A unilateral contact (docs/joints.md §6.4): a sphere centred on a node
/// against a fixed plane (`type = "plane"`: `node`, `point`, `normal`,
/// `radius`), or two spheres centred on two nodes (`type = "spheres"`:
/// `nodes`, `radii`). The gap stays non-negative, with impacts of
/// restitution `restitution` and persistent contact.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactInput {
    /// Element id.
    pub id: Id,
    /// `plane` or `spheres`.
    #[serde(rename = "type")]
    pub kind: ContactType,
    /// The node at the sphere's centre (`plane`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<Id>,
    /// A point of the plane (global), default the origin (`plane`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    /// The plane's normal (global), pointing to the sphere's side
    /// (`plane`); any length but zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// The sphere's radius (m), default 0 (`plane`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// The two nodes at the spheres' centres (`spheres`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodes: Option<Vec<Id>>,
    /// The spheres' radii (m), not both zero (`spheres`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radii: Option<Vec<f64>>,
    /// Coefficient of restitution `e ∈ [0, 1]`, default 0 (plastic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
}

/// A rigid disc rolling without slipping on a fixed plane
/// (docs/joints.md §3.8): its node is at the centre, its axis a material
/// direction of the node.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RollingDiscInput {
    /// Element id.
    pub id: Id,
    /// The node at the disc's centre.
    pub node: Id,
    /// Radius of the disc (m), positive.
    pub radius: f64,
    /// The disc's axis in the node's material frame.
    pub axis: [f64; 3],
    /// A point of the plane (global), default the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 3]>,
    /// The plane's normal (global), pointing to the disc's side.
    pub normal: [f64; 3],
}

/// How a latch's coordinate reaches its locking value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Approach {
    /// With the coordinate increasing.
    Increasing,
    /// With the coordinate decreasing.
    Decreasing,
}

/// The side of the locking value on which a spring latch's spring acts,
/// relative to the direction of approach.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LatchSide {
    /// Both: it holds the coordinate about `c_L` either way.
    #[default]
    Both,
    /// Only against the coordinate going on past `c_L` in the direction
    /// of approach: a compliant end stop, free coming back.
    Beyond,
    /// Only against the coordinate coming back from `c_L`: a pawl that
    /// holds it, free going on.
    Behind,
}

/// What a latch does once locked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LatchMode {
    /// `c − c_L = 0` is a constraint with a multiplier.
    #[default]
    Rigid,
    /// A stiff spring about `c_L`, with backlash, a dashpot and an unlatch
    /// load.
    Spring,
}

/// The analyses of a model: one (`[analysis]`, the default static analysis
/// when the table is absent) or a sequence run in order (`[[analysis]]`),
/// each starting from the final state of the one before. Never empty.
///
/// It dereferences to the first analysis, so that a model with one
/// analysis reads and sets it as `input.analysis.end_time`.
#[derive(Clone, Debug, PartialEq)]
pub struct Analyses(Vec<AnalysisInput>);

impl Analyses {
    /// A sequence of analyses; `None` if it is empty.
    pub fn sequence(analyses: Vec<AnalysisInput>) -> Option<Self> {
        (!analyses.is_empty()).then_some(Self(analyses))
    }

    /// The analyses, in order.
    pub fn all(&self) -> &[AnalysisInput] {
        &self.0
    }

    /// Appends an analysis to the sequence.
    pub fn push(&mut self, analysis: AnalysisInput) {
        self.0.push(analysis);
    }
}

impl Default for Analyses {
    fn default() -> Self {
        Self(vec![AnalysisInput::default()])
    }
}

impl From<AnalysisInput> for Analyses {
    fn from(a: AnalysisInput) -> Self {
        Self(vec![a])
    }
}

impl std::ops::Deref for Analyses {
    type Target = AnalysisInput;
    fn deref(&self) -> &AnalysisInput {
        &self.0[0]
    }
}

impl std::ops::DerefMut for Analyses {
    fn deref_mut(&mut self) -> &mut AnalysisInput {
        &mut self.0[0]
    }
}

impl Serialize for Analyses {
    /// One analysis as a table (`[analysis]`), a sequence as an array of
    /// tables (`[[analysis]]`).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match &self.0[..] {
            [one] => one.serialize(s),
            all => all.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Analyses {
    /// A table or a non-empty array of tables; the messages of a table's
    /// fields are those of [`AnalysisInput`], with their place in the file.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = Analyses;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an [analysis] table or a sequence of [[analysis]] tables")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Analyses, A::Error> {
                let one =
                    AnalysisInput::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                Ok(Analyses(vec![one]))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Analyses, A::Error> {
                let all = Vec::<AnalysisInput>::deserialize(
                    serde::de::value::SeqAccessDeserializer::new(seq),
                )?;
                Analyses::sequence(all).ok_or_else(|| {
                    serde::de::Error::invalid_length(0, &"at least one [[analysis]] table")
                })
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// Kind and parameters of an analysis.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AnalysisInput {
    /// Analysis type: `"static"` (default) or its alias `"kinetostatic"`
    /// (nonlinear statics, loads and drivers), `"kinematic"` (the
    /// joints and drivers must determine every unknown), or `"modal"`
    /// (natural frequencies and modes about the state reached).
    #[serde(rename = "type", default = "default_analysis_type")]
    pub kind: String,
    /// Final value of the load parameter `t` (pseudo-time), default 1 (each
    /// analysis of a sequence ends later than the one before).
    #[serde(default = "default_end_time")]
    pub end_time: f64,
    /// First increment of `t`, default a tenth of the analysis's span
    /// (`end_time / 10` for the first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_increment: Option<f64>,
    /// Smallest increment before the analysis gives up, default 1e-6 of the
    /// span (`end_time · 1e-6` for the first).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_increment: Option<f64>,
    /// Largest increment, default the initial increment.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_increment: Option<f64>,
    /// Newton iterations allowed per increment before it is cut back, default 25.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_iterations: Option<usize>,
    /// Residual tolerance relative to the force flux, default 1e-8.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_tolerance: Option<f64>,
    /// Displacement correction tolerance relative to the model size, default 1e-6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement_tolerance: Option<f64>,
    /// Rotation correction tolerance in radians, default 1e-6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation_tolerance: Option<f64>,
    /// Write results every this many converged increments (default 1); the
    /// last increment is always written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_every: Option<usize>,
    /// Values of `t` the analysis lands on exactly and writes results at
    /// (increasing, within the analysis's span).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_times: Option<Vec<f64>>,
    /// Dynamics: results written at the start of the analysis plus every
    /// multiple of this interval (and at `output_times`, the events and
    /// the end), the steps landing on them; excludes `output_every`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_interval: Option<f64>,
    /// Scaling factor `k` of constraint equations (eq. 17), default the
    /// largest diagonal stiffness of the model (docs/joints.md §1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraint_scale: Option<f64>,
    /// Penalty `p` of constraint equations (eq. 17), default as `k`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraint_penalty: Option<f64>,
    /// Path control: `load` (default; increments of `t`) or `arc_length`
    /// (increments of the arc length of the path in the space of
    /// displacements, `t` becomes an unknown: passes limit points of the
    /// load, docs/theory.md §9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<String>,
    /// Arc-length control: largest number of increments, default 1000.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_increments: Option<usize>,
    /// Dynamics: first time step, default a hundredth of the span.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_step: Option<f64>,
    /// Dynamics: smallest time step, default `time_step · 1e-6`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_step: Option<f64>,
    /// Dynamics: largest time step, default a tenth of the span (adaptive)
    /// or `time_step` (fixed steps).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step: Option<f64>,
    /// Dynamics: spectral radius at infinite frequency `ρ∞ ∈ [0, 1]`,
    /// default 0.9.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_infinity: Option<f64>,
    /// Dynamics: relative tolerance of the local error estimate, default
    /// 1e-4.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_tolerance: Option<f64>,
    /// Dynamics: whether the step follows the error estimate (default
    /// true); `false` for fixed steps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<bool>,
    /// Dynamics: `full` (default; the iteration matrix factored at every
    /// iteration) or `modified` (its factors kept while they serve).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub newton: Option<String>,
    /// Dynamics: the frame of the angular velocities in the time scheme,
    /// `material` (default) or `spatial`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_velocities: Option<String>,
    /// Modal analysis: number of modes, default 10.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    /// Modal analysis: frequency (Hz) near which the modes are sought.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift: Option<f64>,
    /// Modal analysis: only the modes in `[low, high]` (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency_range: Option<[f64; 2]>,
    /// Modal analysis: eigen-solver, `auto` (default), `dense` or
    /// `lanczos`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solver: Option<String>,
}

fn default_analysis_type() -> String {
    "static".to_string()
}
fn default_end_time() -> f64 {
    1.0
}

impl Default for AnalysisInput {
    fn default() -> Self {
        Self {
            kind: default_analysis_type(),
            end_time: default_end_time(),
            initial_increment: None,
            min_increment: None,
            max_increment: None,
            max_iterations: None,
            residual_tolerance: None,
            displacement_tolerance: None,
            rotation_tolerance: None,
            output_every: None,
            output_times: None,
            output_interval: None,
            constraint_scale: None,
            constraint_penalty: None,
            control: None,
            max_increments: None,
            time_step: None,
            min_step: None,
            max_step: None,
            rho_infinity: None,
            error_tolerance: None,
            adaptive: None,
            newton: None,
            angular_velocities: None,
            modes: None,
            shift: None,
            frequency_range: None,
            solver: None,
        }
    }
}

/// A node of the reference configuration.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NodeInput {
    /// Unique node id.
    pub id: Id,
    /// Position in the global frame.
    pub x: [f64; 3],
    /// Orientation as a rotation vector (global frame), default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f64; 3]>,
    /// Unit of `rotation` (its length is the angle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// Initial velocity (global frame), default zero; dynamic analyses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[f64; 3]>,
    /// Initial angular velocity (global frame, rad/s), default zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_velocity: Option<[f64; 3]>,
}

/// `[[initial_motion]]`: a rigid motion given to a set of nodes at the
/// start, `v(x) = v + ω × (x − about)`, `ω` to every node (global frame).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InitialMotionInput {
    /// The nodes that move together.
    pub nodes: Vec<Id>,
    /// Velocity of the point `about`, default zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[f64; 3]>,
    /// Angular velocity (rad/s), default zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_velocity: Option<[f64; 3]>,
    /// The point whose velocity is `velocity`, default the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<[f64; 3]>,
}

/// Cross-section properties of a beam.
///
/// Give either the six diagonal stiffnesses (`EA`, `GA2`, `GA3`, `GJ`,
/// `EI2`, `EI3`) or the full symmetric 6×6 `stiffness` matrix in the order
/// (axial strain, shear strains 2 and 3, torsion, curvatures 2 and 3).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SectionInput {
    /// Name by which beams refer to the section.
    pub name: String,
    /// Axial stiffness E·A.
    #[serde(rename = "EA", default, skip_serializing_if = "Option::is_none")]
    pub ea: Option<f64>,
    /// Shear stiffness along local axis 2, κ₂·G·A.
    #[serde(rename = "GA2", default, skip_serializing_if = "Option::is_none")]
    pub ga2: Option<f64>,
    /// Shear stiffness along local axis 3, κ₃·G·A.
    #[serde(rename = "GA3", default, skip_serializing_if = "Option::is_none")]
    pub ga3: Option<f64>,
    /// Torsional stiffness G·J.
    #[serde(rename = "GJ", default, skip_serializing_if = "Option::is_none")]
    pub gj: Option<f64>,
    /// Bending stiffness about local axis 2, E·I₂.
    #[serde(rename = "EI2", default, skip_serializing_if = "Option::is_none")]
    pub ei2: Option<f64>,
    /// Bending stiffness about local axis 3, E·I₃.
    #[serde(rename = "EI3", default, skip_serializing_if = "Option::is_none")]
    pub ei3: Option<f64>,
    /// Full 6×6 sectional stiffness (rows), instead of the diagonal values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<[[f64; 6]; 6]>,
    /// Mass per unit length, default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_per_length: Option<f64>,
    /// Rotational inertia per unit length about the local axes 1, 2, 3
    /// (ρJ, ρI₂, ρI₃), default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_per_length: Option<[f64; 3]>,
    /// Rayleigh damping, mass-proportional coefficient `α` (1/s), default
    /// 0 (docs/theory.md §11.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rayleigh_alpha: Option<f64>,
    /// Rayleigh damping, stiffness-proportional coefficient `β` (s),
    /// default 0 (docs/theory.md §11.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rayleigh_beta: Option<f64>,
}

impl SectionInput {
    /// A section of diagonal stiffnesses `[EA, GA2, GA3, GJ, EI2, EI3]`,
    /// without mass.
    pub fn diagonal(name: impl Into<String>, diagonal: [f64; 6]) -> Self {
        let [ea, ga2, ga3, gj, ei2, ei3] = diagonal.map(Some);
        Self {
            name: name.into(),
            ea,
            ga2,
            ga3,
            gj,
            ei2,
            ei3,
            ..Self::default()
        }
    }
}

/// A two-node beam element.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BeamInput {
    /// Unique element id.
    pub id: Id,
    /// End nodes.
    pub nodes: [Id; 2],
    /// Name of the section.
    pub section: String,
    /// Reference vector: local axis 2 is its part normal to the beam axis.
    /// Default: global z, or global x for beams along z.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<[f64; 3]>,
    /// Sectional strains at which the section is stress-free, measured from
    /// the reference geometry (axial, shear 2, shear 3, torsion, curvature 2,
    /// curvature 3). A negative axial value shortens the beam: pretension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_strain: Option<[f64; 6]>,
    /// Curve `f(t)` applying the initial strain gradually (`f(t) ε_init`);
    /// default: all of it from `t = 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_strain_curve: Option<String>,
}

/// A line between two existing nodes, meshed into beam elements.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BeamLineInput {
    /// End nodes (must exist).
    pub nodes: [Id; 2],
    /// Number of elements.
    pub elements: usize,
    /// Name of the section.
    pub section: String,
    /// Reference vector for local axis 2 (as for beams).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<[f64; 3]>,
    /// Id of the first interior node; the others follow. Default: one more
    /// than the largest node id of the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_node: Option<Id>,
    /// Id of the first element; the others follow. Default: one more than
    /// the largest element id of the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_element: Option<Id>,
    /// Centre of a circular arc through both end nodes; absent for a
    /// straight line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arc_center: Option<[f64; 3]>,
    /// Initial strain of every element (as for beams).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_strain: Option<[f64; 6]>,
    /// Curve applying the initial strain gradually (as for beams).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_strain_curve: Option<String>,
}

/// `[[ply_materials]]`: an orthotropic ply material (`E1`, `E2`, `nu12`,
/// `G12`, `G13`, `G23`) or an isotropic one (`E`, `nu`), and its density.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PlyMaterialInput {
    /// Name by which laminates refer to it.
    pub name: String,
    /// Young's modulus along the fibres.
    #[serde(rename = "E1", default, skip_serializing_if = "Option::is_none")]
    pub e1: Option<f64>,
    /// Young's modulus across the fibres, in the plane.
    #[serde(rename = "E2", default, skip_serializing_if = "Option::is_none")]
    pub e2: Option<f64>,
    /// Major Poisson's ratio `ν₁₂`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nu12: Option<f64>,
    /// In-plane shear modulus.
    #[serde(rename = "G12", default, skip_serializing_if = "Option::is_none")]
    pub g12: Option<f64>,
    /// Transverse shear modulus in the fibre–normal plane.
    #[serde(rename = "G13", default, skip_serializing_if = "Option::is_none")]
    pub g13: Option<f64>,
    /// Transverse shear modulus in the transverse–normal plane.
    #[serde(rename = "G23", default, skip_serializing_if = "Option::is_none")]
    pub g23: Option<f64>,
    /// Isotropic material: Young's modulus (instead of `E1` … `G23`).
    #[serde(rename = "E", default, skip_serializing_if = "Option::is_none")]
    pub e: Option<f64>,
    /// Isotropic material: Poisson's ratio.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nu: Option<f64>,
    /// Density (mass per volume), default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
}

/// A ply of a laminate: its material, thickness and fibre angle.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PlyInput {
    /// Name of its `[[ply_materials]]` entry.
    pub material: String,
    /// Thickness.
    pub thickness: f64,
    /// Angle from the shell's material axis to the fibres, about the
    /// normal, in the laminate's `unit` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
}

/// The core of a sandwich laminate.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CoreInput {
    /// Thickness.
    pub thickness: f64,
    /// Transverse shear modulus in the plane of the core's direction 1
    /// (a honeycomb's ribbon direction `L`).
    #[serde(rename = "G13")]
    pub g13: f64,
    /// Transverse shear modulus in the plane of the core's direction 2
    /// (`W`).
    #[serde(rename = "G23")]
    pub g23: f64,
    /// Density, default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// In-plane Young's modulus (isotropic), default 0 (a honeycomb).
    #[serde(rename = "E", default, skip_serializing_if = "Option::is_none")]
    pub e: Option<f64>,
    /// In-plane Poisson's ratio, default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nu: Option<f64>,
    /// Angle of direction 1 from the shell's material axis, in the
    /// laminate's `unit` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f64>,
}

/// `[[laminates]]`: a stack of plies (`plies`), or a sandwich (`core` with
/// `faces`, or with `bottom_face` and `top_face`).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LaminateInput {
    /// Name by which shells and panels refer to it.
    pub name: String,
    /// A stack: its plies from the bottom (`z = −h/2`) up.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plies: Vec<PlyInput>,
    /// A sandwich: its core.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub core: Option<CoreInput>,
    /// A sandwich: the laminate (a stack) of both face sheets, its plies
    /// listed from the core outward.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<String>,
    /// A sandwich: the laminate of the bottom face sheet (from the core
    /// outward, i.e. downward), instead of `faces`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bottom_face: Option<String>,
    /// A sandwich: the laminate of the top face sheet (from the core
    /// outward, i.e. upward), instead of `faces`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top_face: Option<String>,
    /// Unit of the ply and core angles (radians by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
}

/// `[[shells]]`: a four-node shell element.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShellInput {
    /// Unique element id.
    pub id: Id,
    /// The four nodes, in order around the element (its normal follows
    /// them by the right-hand rule).
    pub nodes: [Id; 4],
    /// Name of its laminate.
    pub laminate: String,
    /// Direction whose projection on the element is its material axis
    /// `x` (ply angles are measured from it); default global x, or
    /// global y for an element whose normal is along x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material_axis: Option<[f64; 3]>,
    /// Load per unit area along the element's normal (a pressure on its
    /// bottom face), reached when its curve equals 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<f64>,
    /// Curve of the pressure, default as for loads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_curve: Option<String>,
}

/// A side of a panel: `south` (from its origin along `a`), `east`,
/// `north`, `west` (from its origin along `b`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PanelSide {
    /// `η = 0`, along `a`.
    South,
    /// `ξ = a`, along `b`.
    East,
    /// `η = b`, along `a`.
    North,
    /// `ξ = 0`, along `b`.
    West,
}

impl PanelSide {
    /// Every side, counterclockwise from `south`.
    pub const ALL: [PanelSide; 4] = [Self::South, Self::East, Self::North, Self::West];

    /// Name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::South => "south",
            Self::East => "east",
            Self::North => "north",
            Self::West => "west",
        }
    }
}

/// A named node of a panel: a corner or the middle of a side.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PanelPoint {
    /// The corner at the origin, `(0, 0)`.
    SouthWest,
    /// The middle of the south side, `(a/2, 0)`.
    South,
    /// The corner `(a, 0)`.
    SouthEast,
    /// The middle of the east side, `(a, b/2)`.
    East,
    /// The corner `(a, b)`.
    NorthEast,
    /// The middle of the north side, `(a/2, b)`.
    North,
    /// The corner `(0, b)`.
    NorthWest,
    /// The middle of the west side, `(0, b/2)`.
    West,
}

impl PanelPoint {
    /// Every named point, counterclockwise from the origin.
    pub const ALL: [PanelPoint; 8] = [
        Self::SouthWest,
        Self::South,
        Self::SouthEast,
        Self::East,
        Self::NorthEast,
        Self::North,
        Self::NorthWest,
        Self::West,
    ];

    /// Name used in files (`node_ids`) and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::SouthWest => "south_west",
            Self::South => "south",
            Self::SouthEast => "south_east",
            Self::East => "east",
            Self::NorthEast => "north_east",
            Self::North => "north",
            Self::NorthWest => "north_west",
            Self::West => "west",
        }
    }

    /// Its place in halves of the sides, `(0|1|2, 0|1|2)`.
    fn halves(self) -> (usize, usize) {
        match self {
            Self::SouthWest => (0, 0),
            Self::South => (1, 0),
            Self::SouthEast => (2, 0),
            Self::East => (2, 1),
            Self::NorthEast => (2, 2),
            Self::North => (1, 2),
            Self::NorthWest => (0, 2),
            Self::West => (0, 1),
        }
    }

    /// Its grid position `(i, j)` on a panel of `nx × ny` elements (both
    /// even).
    pub fn grid(self, nx: usize, ny: usize) -> (usize, usize) {
        let (a, b) = self.halves();
        (a * nx / 2, b * ny / 2)
    }

    /// The named point at grid position `(i, j)` of an `nx × ny` panel,
    /// if any.
    pub fn at(nx: usize, ny: usize, i: usize, j: usize) -> Option<PanelPoint> {
        Self::ALL.into_iter().find(|p| p.grid(nx, ny) == (i, j))
    }
}

impl PanelNodeIds {
    /// The id given to `point`, if any.
    pub fn get(&self, point: PanelPoint) -> Option<Id> {
        match point {
            PanelPoint::SouthWest => self.south_west,
            PanelPoint::South => self.south,
            PanelPoint::SouthEast => self.south_east,
            PanelPoint::East => self.east,
            PanelPoint::NorthEast => self.north_east,
            PanelPoint::North => self.north,
            PanelPoint::NorthWest => self.north_west,
            PanelPoint::West => self.west,
        }
    }

    /// Gives `point` the id `id`.
    pub fn set(&mut self, point: PanelPoint, id: Id) {
        let slot = match point {
            PanelPoint::SouthWest => &mut self.south_west,
            PanelPoint::South => &mut self.south,
            PanelPoint::SouthEast => &mut self.south_east,
            PanelPoint::East => &mut self.east,
            PanelPoint::NorthEast => &mut self.north_east,
            PanelPoint::North => &mut self.north,
            PanelPoint::NorthWest => &mut self.north_west,
            PanelPoint::West => &mut self.west,
        };
        *slot = Some(id);
    }
}

/// A rectangular zone of a panel with its own laminate: the elements
/// whose centres lie in `[from, to]` (panel coordinates along `a` and
/// `b`, from the origin).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PanelZoneInput {
    /// Lower corner `(ξ, η)`.
    pub from: [f64; 2],
    /// Upper corner `(ξ, η)`.
    pub to: [f64; 2],
    /// Name of its laminate.
    pub laminate: String,
}

/// A stiffener along a side of a panel: beam elements on the side's
/// nodes, their axis offset along the panel's normal.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StiffenerInput {
    /// The side.
    pub side: PanelSide,
    /// Name of its `[[sections]]` entry (stiffness about its own
    /// centroid; local axis 2 along the panel's normal).
    pub section: String,
    /// Distance from the panel's mid-surface to the stiffener's axis,
    /// along the normal (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
}

/// Ids given to the named nodes of a panel (its corners and the middles
/// of its sides) instead of their grid ids.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PanelNodeIds {
    /// Corner at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub south_west: Option<Id>,
    /// Middle of the south side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub south: Option<Id>,
    /// Corner at `(a, 0)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub south_east: Option<Id>,
    /// Middle of the east side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub east: Option<Id>,
    /// Corner at `(a, b)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub north_east: Option<Id>,
    /// Middle of the north side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub north: Option<Id>,
    /// Corner at `(0, b)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub north_west: Option<Id>,
    /// Middle of the west side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub west: Option<Id>,
}

/// `[[panels]]`: a flat rectangular panel of `size = [a, b]` meshed into
/// `elements = [nx, ny]` shell elements (both even, so that the middle of
/// each side is a node).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PanelInput {
    /// Name in messages.
    pub name: String,
    /// Side lengths `[a, b]` along the panel's axes.
    pub size: [f64; 2],
    /// Elements along each side `[nx, ny]`, both even.
    pub elements: [usize; 2],
    /// Name of the laminate of the panel (outside its zones).
    pub laminate: String,
    /// The corner `south_west`, default the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<[f64; 3]>,
    /// Direction of side `a` (and the panel's material axis), default
    /// global x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_a: Option<[f64; 3]>,
    /// A direction in the panel's plane, not along `axis_a`: side `b` is
    /// its part normal to `axis_a`; default global y.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_b: Option<[f64; 3]>,
    /// Zones with their own laminate; a later zone overrides an earlier
    /// one where they overlap.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub zones: Vec<PanelZoneInput>,
    /// Stiffeners along sides.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stiffeners: Vec<StiffenerInput>,
    /// Load per unit area along the panel's normal `a × b`, reached when
    /// its curve equals 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<f64>,
    /// Curve of the pressure, default as for loads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_curve: Option<String>,
    /// Id of the node at grid position `(0, 0)`: node `(i, j)` has id
    /// `first_node + j (nx + 1) + i`. Default: one more than the largest
    /// node id so far.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_node: Option<Id>,
    /// Id of the first shell element: element `(i, j)` has id
    /// `first_element + j nx + i`, the stiffeners' beams follow. Default:
    /// one more than the largest element id so far.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_element: Option<Id>,
    /// Ids of the corners and side middles instead of their grid ids.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node_ids: Option<PanelNodeIds>,
}

/// A rigid body carried by a node.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RigidBodyInput {
    /// Unique element id.
    pub id: Id,
    /// The node that carries the body.
    pub node: Id,
    /// Mass.
    pub mass: f64,
    /// Inertia tensor about the centre of mass, in the node's material
    /// frame: either the diagonal `[I11, I22, I33]` or the full 3×3 rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<InertiaInput>,
    /// Position of the centre of mass relative to the node, in the node's
    /// material frame. Default: at the node.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center_of_mass: Option<[f64; 3]>,
    /// The shape drawn in the VTK files and the viewer (no part of the
    /// mechanics). Default: the box of uniform density with the body's
    /// mass and inertia ([`crate::elements::shape::BodyShape::from_inertia`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeInput>,
}

/// The kind of a rigid body's drawn shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// A box: `size` = three edges along the shape's axes 1, 2, 3.
    Box,
    /// A rectangular plate: `size` = two edges along axes 1 and 2,
    /// `thickness` along axis 3 (default zero: a quadrilateral).
    Plate,
    /// A circular cylinder about axis 3: `radius` and `length`.
    Cylinder,
    /// A point: the body is drawn as a vertex at its node.
    Point,
}

impl ShapeKind {
    /// Name used in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Box => "box",
            Self::Plate => "plate",
            Self::Cylinder => "cylinder",
            Self::Point => "point",
        }
    }
}

/// The drawn shape of a rigid body (`shape = { type = "box", … }`):
/// which fields a kind takes is in [`ShapeKind`]; the shape's axes are the
/// node's material axes turned by `rotation`, its centre at `center`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShapeInput {
    /// Box, plate, cylinder or point.
    #[serde(rename = "type")]
    pub kind: ShapeKind,
    /// Edge lengths: three for a box, two for a plate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<Vec<f64>>,
    /// Thickness of a plate (default zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Radius of a cylinder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Length of a cylinder along its axis (zero: a disc).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// Centre of the shape relative to the node, in the node's material
    /// frame. Default: the centre of mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<[f64; 3]>,
    /// Rotation vector from the node's material axes to the shape's axes
    /// (in the node's material frame). Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f64; 3]>,
    /// Unit of `rotation` (radians by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
}

impl ShapeInput {
    /// A shape of `kind` with no dimensions given yet.
    fn of(kind: ShapeKind) -> Self {
        Self {
            kind,
            size: None,
            thickness: None,
            radius: None,
            length: None,
            center: None,
            rotation: None,
            unit: None,
        }
    }

    /// A box of edges `size` along the shape's axes.
    pub fn box_of(size: [f64; 3]) -> Self {
        Self {
            size: Some(size.to_vec()),
            ..Self::of(ShapeKind::Box)
        }
    }

    /// A plate of edges `size` along the shape's axes 1 and 2, of zero
    /// thickness ([`ShapeInput::thickness`] gives it one).
    pub fn plate(size: [f64; 2]) -> Self {
        Self {
            size: Some(size.to_vec()),
            ..Self::of(ShapeKind::Plate)
        }
    }

    /// A cylinder of `radius` and `length` about the shape's axis 3.
    pub fn cylinder(radius: f64, length: f64) -> Self {
        Self {
            radius: Some(radius),
            length: Some(length),
            ..Self::of(ShapeKind::Cylinder)
        }
    }

    /// A point: the body drawn as a vertex at its node.
    pub fn point() -> Self {
        Self::of(ShapeKind::Point)
    }

    /// The thickness of a plate.
    pub fn thickness(mut self, t: f64) -> Self {
        self.thickness = Some(t);
        self
    }

    /// The centre of the shape relative to the node (node material frame).
    pub fn center(mut self, c: impl Into<[f64; 3]>) -> Self {
        self.center = Some(c.into());
        self
    }

    /// The rotation vector (radians) from the node's material axes to the
    /// shape's.
    pub fn rotation(mut self, psi: impl Into<[f64; 3]>) -> Self {
        self.rotation = Some(psi.into());
        self
    }
}

/// An inertia tensor: principal values or the full symmetric matrix.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum InertiaInput {
    /// `[I11, I22, I33]`.
    Diagonal([f64; 3]),
    /// The full 3×3 tensor, by rows.
    Full([[f64; 3]; 3]),
}

/// A point mass carried by a node.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PointMassInput {
    /// Unique element id.
    pub id: Id,
    /// The node that carries the mass.
    pub node: Id,
    /// Mass.
    pub mass: f64,
}

/// A linear spring between two nodes, or between a node and the ground.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SpringInput {
    /// Unique element id.
    pub id: Id,
    /// What the spring resists.
    pub kind: SpringKind,
    /// One node (spring to ground, at the node's reference position and
    /// orientation) or two nodes.
    pub nodes: Vec<Id>,
    /// Stiffness: one value (isotropic) or three values along the axes.
    /// Axial springs take one value.
    pub stiffness: StiffnessInput,
    /// Coefficient of a linear damper in parallel (dynamics only): one
    /// value or three along the axes (N·s/m, N·m·s/rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<StiffnessInput>,
    /// Damping ratio `ζ` of the damper in parallel, on each axis
    /// `c = 2ζ√(k m)` with `m` the mass (or inertia) of the bodies the
    /// spring connects (docs/model-format.md). Not with `damping`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_ratio: Option<f64>,
}

/// A scalar or a 3-vector of spring stiffnesses.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum StiffnessInput {
    /// The same value on all three axes.
    Isotropic(f64),
    /// One value per axis.
    PerAxis([f64; 3]),
}

impl From<f64> for StiffnessInput {
    fn from(k: f64) -> Self {
        Self::Isotropic(k)
    }
}

impl From<[f64; 3]> for StiffnessInput {
    fn from(k: [f64; 3]) -> Self {
        Self::PerAxis(k)
    }
}

/// Fixed degrees of freedom of a node.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SupportInput {
    /// The node.
    pub node: Id,
    /// Components to fix: `x`, `y`, `z` (global translations), `rx`, `ry`,
    /// `rz` (incremental rotations about the node's material axes), or the
    /// groups `translations`, `rotations`, `all`.
    pub fixed: Vec<String>,
}

/// A prescribed motion of a node: one translation component, or the whole
/// rotation.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PrescribedInput {
    /// The node.
    pub node: Id,
    /// Translation component `x`, `y` or `z` to prescribe, with `value`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof: Option<String>,
    /// Displacement reached when the curve equals 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// Rotation vector (global frame) reached when the curve equals 1:
    /// `R(t) = exp(f(t) ψ~) R₀`. Fixes all three rotations of the node.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f64; 3]>,
    /// Unit of `rotation`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<AngleUnit>,
    /// Name of the curve `f(t)`; default `ramp` (`f(t) = t`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
}

/// A nodal force and moment.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadInput {
    /// The loaded node.
    pub node: Id,
    /// Force reached when the curve equals 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force: Option<[f64; 3]>,
    /// Moment reached when the curve equals 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moment: Option<[f64; 3]>,
    /// `false` (default): fixed global direction (dead load). `true`:
    /// components in the node's material frame, turning with the node.
    #[serde(default)]
    pub follower: bool,
    /// Name of the load curve; default `ramp` (`f(t) = t`), or `constant`
    /// in a kinematic analysis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
}

/// A uniform gravity field.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GravityInput {
    /// Acceleration of gravity reached when the curve equals 1.
    pub acceleration: [f64; 3],
    /// Name of the load curve; default `ramp`, or `constant` in a
    /// kinematic analysis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
}

/// A curve `f(t)`: a piecewise-linear table (`points`) or a simple
/// function (`function` and its parameters).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CurveInput {
    /// Name by which loads refer to the curve.
    pub name: String,
    /// Points `[t, f]` with strictly increasing `t`. Constant beyond the
    /// first and last points.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<[f64; 2]>,
    /// Instead of points: `linear` (`offset + slope·t`), `sine`
    /// (`offset + amplitude·sin(2π·frequency·t + phase)`) or `smooth_step`
    /// (from `from` at `start` to `to` at `end`, zero rate and acceleration
    /// at both ends).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub function: Option<String>,
    /// `linear`, `sine`: value at `t = 0` / mean value (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// `linear`: slope (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slope: Option<f64>,
    /// `sine`: amplitude (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<f64>,
    /// `sine`: frequency, cycles per unit of `t` (required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// `sine`: phase in radians (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<f64>,
    /// `smooth_step`: start and end of the transition (required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<f64>,
    /// `smooth_step`: end of the transition (required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<f64>,
    /// `smooth_step`: value before `start` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<f64>,
    /// `smooth_step`: value after `end` (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<f64>,
}

// ---------- helpers for models written in Rust (see also crate::model::builder) ----------

impl ModelInput {
    /// An empty model with a title.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: Some(title.into()),
            ..Self::default()
        }
    }

    /// Adds a node at `x` with the identity orientation.
    pub fn add_node(&mut self, id: Id, x: [f64; 3]) -> &mut Self {
        self.nodes.push(NodeInput {
            id,
            x,
            rotation: None,
            unit: None,
            velocity: None,
            angular_velocity: None,
        });
        self
    }

    /// Adds a section with the diagonal stiffnesses
    /// `[EA, GA2, GA3, GJ, EI2, EI3]`.
    pub fn add_section(&mut self, name: impl Into<String>, diagonal: [f64; 6]) -> &mut Self {
        self.sections.push(SectionInput::diagonal(name, diagonal));
        self
    }

    /// Adds a beam between two nodes.
    pub fn add_beam(
        &mut self,
        id: Id,
        nodes: [Id; 2],
        section: impl Into<String>,
        orientation: Option<[f64; 3]>,
    ) -> &mut Self {
        self.beams.push(BeamInput {
            id,
            nodes,
            section: section.into(),
            orientation,
            initial_strain: None,
            initial_strain_curve: None,
        });
        self
    }

    /// Adds a straight line of `elements` beams between two existing nodes;
    /// interior nodes and elements get the next free ids.
    pub fn add_beam_line(
        &mut self,
        nodes: [Id; 2],
        elements: usize,
        section: impl Into<String>,
        orientation: Option<[f64; 3]>,
    ) -> &mut Self {
        self.beam_lines.push(BeamLineInput {
            nodes,
            elements,
            section: section.into(),
            orientation,
            first_node: None,
            first_element: None,
            arc_center: None,
            initial_strain: None,
            initial_strain_curve: None,
        });
        self
    }

    /// Fixes the listed components (`"all"`, `"x"`, `"rz"`, ...) of a node.
    pub fn fix(&mut self, node: Id, components: &[&str]) -> &mut Self {
        self.supports.push(SupportInput {
            node,
            fixed: components.iter().map(|s| s.to_string()).collect(),
        });
        self
    }

    /// Adds a dead nodal force and moment following the default curve (the
    /// ramp in statics, the constant in a kinematic analysis).
    pub fn add_load(&mut self, node: Id, force: [f64; 3], moment: [f64; 3]) -> &mut Self {
        self.loads.push(LoadInput {
            node,
            force: Some(force),
            moment: Some(moment),
            follower: false,
            curve: None,
        });
        self
    }

    /// Serialises the model to TOML text.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string_pretty(self)
    }
}
