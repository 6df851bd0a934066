//! Joints, joint springs and dampers, drivers, latches, stops and contacts
//! (docs/joints.md).

use super::{Body, CurveHandle, Entity, ModelBuilder};
use crate::joints::{Coordinate, JointType};
use crate::model::handles::{
    ContactHandle, DriverHandle, HingeLawHandle, JointHandle, JointSpringHandle, LatchHandle,
    NodeHandle, RollingDiscHandle, StopHandle,
};
use crate::model::input::{
    AngleUnit, Approach, ContactInput, ContactType, DriverInput, HingeLawInput, JointInput,
    JointSpringInput, LatchInput, LatchMode, LatchSide, RollingDiscInput, StartBranch, StopInput,
    TapeSpringInput,
};
use crate::model::Id;

/// A kinematic pair between node A and node B, or between node A and the
/// [`super::Ground`].
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    input: JointInput,
    id: Option<Id>,
}

impl Joint {
    /// A joint of type `kind` between `a` and `b` (a node or the ground).
    pub fn new(kind: JointType, a: NodeHandle, b: impl Into<Body>) -> Self {
        Self {
            input: JointInput {
                kind,
                nodes: b.into().with_first(a),
                ..JointInput::default()
            },
            id: None,
        }
    }

    /// A hinge: rotation about [`Joint::axis`] only.
    pub fn revolute(a: NodeHandle, b: impl Into<Body>) -> Self {
        Self::new(JointType::Revolute, a, b)
    }

    /// Sliding along [`Joint::axis`] only.
    pub fn prismatic(a: NodeHandle, b: impl Into<Body>) -> Self {
        Self::new(JointType::Prismatic, a, b)
    }

    /// Rotation about and sliding along [`Joint::axis`].
    pub fn cylindrical(a: NodeHandle, b: impl Into<Body>) -> Self {
        Self::new(JointType::Cylindrical, a, b)
    }

    /// A ball joint: the joint point is common, rotations are free.
    pub fn spherical(a: NodeHandle, b: impl Into<Body>) -> Self {
        Self::new(JointType::Spherical, a, b)
    }

    /// Motion in the plane normal to [`Joint::axis`].
    pub fn planar(a: NodeHandle, b: impl Into<Body>) -> Self {
        Self::new(JointType::Planar, a, b)
    }

    /// A Cardan joint of cross arms `arm_a` (carried by A) and `arm_b`
    /// (carried by B), perpendicular.
    pub fn universal(
        a: NodeHandle,
        b: impl Into<Body>,
        arm_a: impl Into<[f64; 3]>,
        arm_b: impl Into<[f64; 3]>,
    ) -> Self {
        Self::new(JointType::Universal, a, b)
            .axis(arm_a)
            .axis_b(arm_b)
    }

    /// A screw about [`Joint::axis`] advancing `pitch` per turn (signed).
    pub fn helical(a: NodeHandle, b: impl Into<Body>, pitch: f64) -> Self {
        let mut j = Self::new(JointType::Helical, a, b);
        j.input.pitch = Some(pitch);
        j
    }

    /// A rigid connection of two nodes at the joint point.
    pub fn rigid(a: NodeHandle, b: NodeHandle) -> Self {
        Self::new(JointType::Rigid, a, b)
    }

    /// Node B held where it is in A's material frame (see
    /// [`Joint::offset`], [`Joint::lock_rotations`]).
    pub fn glue(a: NodeHandle, b: NodeHandle) -> Self {
        Self::new(JointType::Glue, a, b)
    }

    /// `node` sliding on the C¹ spline through the nodes of `curve` (see
    /// [`Joint::polyline`]).
    pub fn slider(node: NodeHandle, curve: &[NodeHandle]) -> Self {
        let mut j = Self::new(JointType::Slider, node, super::Ground);
        j.input.curve = curve.iter().map(|n| n.0).collect();
        j
    }

    /// The joint axis `e₃` (hinge, sliding or screw axis; normal of a
    /// planar joint), reference configuration.
    pub fn axis(mut self, axis: impl Into<[f64; 3]>) -> Self {
        self.input.axis = Some(axis.into());
        self
    }

    /// The same axis as carried by body B, which must coincide with
    /// [`Joint::axis`] (a universal joint: B's cross arm).
    pub fn axis_b(mut self, axis: impl Into<[f64; 3]>) -> Self {
        self.input.axis_b = Some(axis.into());
        self
    }

    /// The direction from which its angles are measured (`e₁`).
    pub fn reference_direction(mut self, direction: impl Into<[f64; 3]>) -> Self {
        self.input.reference_direction = Some(direction.into());
        self
    }

    /// The joint point (default: node A's position).
    pub fn at(mut self, point: impl Into<[f64; 3]>) -> Self {
        self.input.position = Some(point.into());
        self
    }

    /// Glue: where B is held, in A's material frame (default: where B is).
    pub fn offset(mut self, offset: impl Into<[f64; 3]>) -> Self {
        self.input.offset = Some(offset.into());
        self
    }

    /// Glue: whether B's rotations are locked to A's too (default true).
    pub fn lock_rotations(mut self, lock: bool) -> Self {
        self.input.lock_rotations = Some(lock);
        self
    }

    /// Slider: a polyline through the curve nodes instead of a spline.
    pub fn polyline(mut self) -> Self {
        self.input.spline = Some(false);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Joint {
    type Handle = JointHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> JointHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = JointHandle(self.input.id);
        m.input.joints.push(self.input);
        handle
    }
}

/// A spring and/or a damper on a joint coordinate: linear (a stiffness,
/// a damping coefficient) or tabulated.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpring {
    input: JointSpringInput,
    id: Option<Id>,
}

impl JointSpring {
    /// On the first coordinate of `joint` (see [`JointSpring::coordinate`]).
    pub fn on(joint: JointHandle) -> Self {
        Self {
            input: JointSpringInput {
                joint: joint.0,
                ..JointSpringInput::default()
            },
            id: None,
        }
    }

    /// The joint coordinate it acts on.
    pub fn coordinate(mut self, coordinate: Coordinate) -> Self {
        self.input.coordinate = Some(coordinate.name().into());
        self
    }

    /// The unit of the angles (free value, table abscissae, stiffness and
    /// damping per unit) when the coordinate is an angle.
    pub fn unit(mut self, unit: AngleUnit) -> Self {
        self.input.unit = Some(unit);
        self
    }

    /// A linear spring of stiffness `k` (N/m, or N·m per angle unit).
    pub fn stiffness(mut self, k: f64) -> Self {
        self.input.stiffness = Some(k);
        self
    }

    /// The coordinate at which the linear spring is unloaded (default 0).
    pub fn free_value(mut self, value: f64) -> Self {
        self.input.free_value = Some(value);
        self
    }

    /// A nonlinear spring: points `[coordinate, force]`.
    pub fn table(mut self, points: impl Into<Vec<[f64; 2]>>) -> Self {
        self.input.table = points.into();
        self
    }

    /// A linear damper of coefficient `c`.
    pub fn damping(mut self, c: f64) -> Self {
        self.input.damping = Some(c);
        self
    }

    /// A nonlinear damper: points `[rate, force]`.
    pub fn damping_table(mut self, points: impl Into<Vec<[f64; 2]>>) -> Self {
        self.input.damping_table = points.into();
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for JointSpring {
    type Handle = JointSpringHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> JointSpringHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = JointSpringHandle(self.input.id);
        m.input.joint_springs.push(self.input);
        handle
    }
}

/// A hysteretic moment law on a joint coordinate (a hinge law with
/// memory, docs/joints.md §4.1): bounds from tables or the tape-spring
/// shape, and the elastic slope between them.
#[derive(Clone, Debug, PartialEq)]
pub struct HingeLaw {
    input: HingeLawInput,
    id: Option<Id>,
}

impl HingeLaw {
    /// On the first coordinate of `joint`, with elastic slope `k_e`
    /// (N·m or N per coordinate unit) between the bounds.
    pub fn on(joint: JointHandle, elastic_slope: f64) -> Self {
        Self {
            input: HingeLawInput {
                joint: joint.0,
                elastic_slope: Some(elastic_slope),
                ..HingeLawInput::default()
            },
            id: None,
        }
    }

    /// The joint coordinate it acts on.
    pub fn coordinate(mut self, coordinate: Coordinate) -> Self {
        self.input.coordinate = Some(coordinate.name().into());
        self
    }

    /// The unit of the angles (table abscissae, tape-spring angles, slopes
    /// per unit) when the coordinate is an angle.
    pub fn unit(mut self, unit: AngleUnit) -> Self {
        self.input.unit = Some(unit);
        self
    }

    /// Bounds from tables of points `[coordinate, moment]`: the loading
    /// bound `f_load` and the unloading bound `f_unload ≤ f_load`.
    pub fn tables(
        mut self,
        load: impl Into<Vec<[f64; 2]>>,
        unload: impl Into<Vec<[f64; 2]>>,
    ) -> Self {
        self.input.load_table = load.into();
        self.input.unload_table = unload.into();
        self
    }

    /// Bounds from the tape-spring shape.
    pub fn tape_spring(mut self, shape: TapeSpringInput) -> Self {
        self.input.tape_spring = Some(shape);
        self
    }

    /// The bound it starts on in the reference configuration (default
    /// the loading bound).
    pub fn start(mut self, start: StartBranch) -> Self {
        self.input.start = Some(start);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for HingeLaw {
    type Handle = HingeLawHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> HingeLawHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = HingeLawHandle(self.input.id);
        m.input.hinge_laws.push(self.input);
        handle
    }
}

/// A prescribed history `value · f(t)` of a joint coordinate, or of a
/// node's translation along or rotation about a direction, relative to
/// the reference configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Driver {
    input: DriverInput,
    curve: Option<CurveHandle>,
    id: Option<Id>,
}

impl Driver {
    fn new(input: DriverInput) -> Self {
        Self {
            input,
            curve: None,
            id: None,
        }
    }

    /// Drives the first coordinate of `joint` (see [`Driver::coordinate`]).
    pub fn on(joint: JointHandle) -> Self {
        Self::new(DriverInput {
            joint: Some(joint.0),
            ..DriverInput::default()
        })
    }

    /// Drives the translation of `node` along `direction` (global).
    pub fn translation(node: NodeHandle, direction: impl Into<[f64; 3]>) -> Self {
        Self::new(DriverInput {
            node: Some(node.0),
            direction: Some(direction.into()),
            ..DriverInput::default()
        })
    }

    /// Drives the rotation of `node` about `axis` (global).
    pub fn rotation(node: NodeHandle, axis: impl Into<[f64; 3]>) -> Self {
        Self::new(DriverInput {
            node: Some(node.0),
            direction: Some(axis.into()),
            motion: Some("rotation".into()),
            ..DriverInput::default()
        })
    }

    /// The joint coordinate driven.
    pub fn coordinate(mut self, coordinate: Coordinate) -> Self {
        self.input.coordinate = Some(coordinate.name().into());
        self
    }

    /// The coordinate's value when the curve equals 1 (m, or rad).
    pub fn value(mut self, value: f64) -> Self {
        self.input.value = value;
        self
    }

    /// An angle's value when the curve equals 1, in `unit`.
    pub fn angle(mut self, value: f64, unit: AngleUnit) -> Self {
        self.input.value = value;
        self.input.unit = Some(unit);
        self
    }

    /// The curve `f(t)` (default the ramp).
    pub fn curve(mut self, curve: CurveHandle) -> Self {
        self.curve = Some(curve);
        self
    }

    /// Acts only while `start ≤ t ≤ end` (`end` may be infinite), released
    /// outside.
    pub fn active(mut self, start: f64, end: f64) -> Self {
        self.input.active = Some([start, end]);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Driver {
    type Handle = DriverHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> DriverHandle {
        self.input.id = m.element_id(self.id, 1);
        self.input.curve = self.curve.map(|c| m.curve_name(c));
        let handle = DriverHandle(self.input.id);
        m.input.drivers.push(self.input);
        handle
    }
}

/// A latch on a joint coordinate (docs/joints.md §6.2): the coordinate locks
/// when it reaches its locking value moving in the direction of approach,
/// rigidly and for good (in dynamic analyses, with the impact of the lock)
/// or, with [`Latch::spring`], through a stiff spring.
#[derive(Clone, Debug, PartialEq)]
pub struct Latch {
    input: LatchInput,
    id: Option<Id>,
}

impl Latch {
    /// Locks the first coordinate of `joint` at `value` (m, or rad; see
    /// [`Latch::angle`]).
    pub fn on(joint: JointHandle, value: f64) -> Self {
        Self {
            input: LatchInput {
                joint: joint.0,
                value,
                ..LatchInput::default()
            },
            id: None,
        }
    }

    /// The joint coordinate it locks.
    pub fn coordinate(mut self, coordinate: Coordinate) -> Self {
        self.input.coordinate = Some(coordinate.name().into());
        self
    }

    /// The locking angle, in `unit`.
    pub fn angle(mut self, value: f64, unit: AngleUnit) -> Self {
        self.input.value = value;
        self.input.unit = Some(unit);
        self
    }

    /// How the coordinate reaches the locking value (default: away from
    /// the reference configuration, where it is 0).
    pub fn approach(mut self, approach: Approach) -> Self {
        self.input.approach = Some(approach);
        self
    }

    /// The side of the locking value a spring latch's spring acts on
    /// (default both; docs/model-format.md, `side`).
    pub fn side(mut self, side: LatchSide) -> Self {
        self.input.side = Some(side);
        self
    }

    /// A spring latch (docs/joints.md §6.2): once latched, a spring of
    /// stiffness `stiffness` about the locking value (N·m/rad or N/m; per
    /// degree with [`Latch::angle`] in degrees) instead of a constraint.
    pub fn spring(mut self, stiffness: f64) -> Self {
        self.input.mode = Some(LatchMode::Spring);
        self.input.stiffness = Some(stiffness);
        self
    }

    /// A spring latch's dead band: its total width about the locking
    /// value, in the unit of the locking value.
    pub fn backlash(mut self, backlash: f64) -> Self {
        self.input.backlash = Some(backlash);
        self
    }

    /// A spring latch's dashpot, acting while latched.
    pub fn damping(mut self, damping: f64) -> Self {
        self.input.damping = Some(damping);
        self
    }

    /// The load at which a spring latch releases.
    pub fn unlatch_load(mut self, load: f64) -> Self {
        self.input.unlatch_load = Some(load);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Latch {
    type Handle = LatchHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> LatchHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = LatchHandle(self.input.id);
        m.input.latches.push(self.input);
        handle
    }
}

/// A unilateral stop on a joint coordinate (docs/joints.md §6.3): the
/// coordinate stays within its limits, with impacts of restitution `e`
/// and persistent contact (in dynamic analyses).
#[derive(Clone, Debug, PartialEq)]
pub struct Stop {
    input: StopInput,
    id: Option<Id>,
}

impl Stop {
    /// A stop on the first coordinate of `joint`, without limits yet (see
    /// [`Stop::lower`], [`Stop::upper`]); values in m, or rad unless
    /// [`Stop::unit`] says otherwise.
    pub fn on(joint: JointHandle) -> Self {
        Self {
            input: StopInput {
                joint: joint.0,
                ..StopInput::default()
            },
            id: None,
        }
    }

    /// The joint coordinate it limits.
    pub fn coordinate(mut self, coordinate: Coordinate) -> Self {
        self.input.coordinate = Some(coordinate.name().into());
        self
    }

    /// The lower limit `c_min`.
    pub fn lower(mut self, value: f64) -> Self {
        self.input.lower = Some(value);
        self
    }

    /// The upper limit `c_max`.
    pub fn upper(mut self, value: f64) -> Self {
        self.input.upper = Some(value);
        self
    }

    /// The unit of the limits of an angle.
    pub fn unit(mut self, unit: AngleUnit) -> Self {
        self.input.unit = Some(unit);
        self
    }

    /// The coefficient of restitution `e ∈ [0, 1]` (default 0).
    pub fn restitution(mut self, e: f64) -> Self {
        self.input.restitution = Some(e);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Stop {
    type Handle = StopHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> StopHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = StopHandle(self.input.id);
        m.input.stops.push(self.input);
        handle
    }
}

/// A unilateral contact (docs/joints.md §6.4): a sphere centred on a node
/// against a fixed plane, or two spheres centred on two nodes; impacts of
/// restitution `e` and persistent contact (in dynamic analyses).
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    input: ContactInput,
    id: Option<Id>,
}

impl Contact {
    /// A point on `node` (a sphere of radius 0 until [`Contact::radius`])
    /// against the fixed plane through `point` with normal `normal`
    /// (global, pointing to the node's side; any length but zero).
    pub fn plane(node: NodeHandle, point: [f64; 3], normal: [f64; 3]) -> Self {
        Self {
            input: ContactInput {
                kind: ContactType::Plane,
                node: Some(node.0),
                point: Some(point),
                normal: Some(normal),
                ..ContactInput::default()
            },
            id: None,
        }
    }

    /// Spheres centred on nodes `a` and `b`, whose radii
    /// [`Contact::radii`] gives (required, not both zero).
    pub fn spheres(a: NodeHandle, b: NodeHandle) -> Self {
        Self {
            input: ContactInput {
                kind: ContactType::Spheres,
                nodes: Some(vec![a.0, b.0]),
                ..ContactInput::default()
            },
            id: None,
        }
    }

    /// The radius of the sphere of a contact with a plane (m).
    pub fn radius(mut self, r: f64) -> Self {
        self.input.radius = Some(r);
        self
    }

    /// The radii of the spheres of a contact of spheres (m).
    pub fn radii(mut self, ra: f64, rb: f64) -> Self {
        self.input.radii = Some(vec![ra, rb]);
        self
    }

    /// The coefficient of restitution `e ∈ [0, 1]` (default 0).
    pub fn restitution(mut self, e: f64) -> Self {
        self.input.restitution = Some(e);
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for Contact {
    type Handle = ContactHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> ContactHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = ContactHandle(self.input.id);
        m.input.contacts.push(self.input);
        handle
    }
}

/// A rigid disc rolling without slipping on a fixed plane
/// (docs/joints.md §3.8): its node at the centre, its axis a material
/// direction of the node. The disc must touch the plane in the reference
/// configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct RollingDisc {
    input: RollingDiscInput,
    id: Option<Id>,
}

impl RollingDisc {
    /// A disc of radius `radius` centred on `node`, with axis `axis`
    /// (material frame of the node), on the plane through the origin with
    /// normal `normal` (pointing to the disc's side).
    pub fn new(
        node: NodeHandle,
        radius: f64,
        axis: impl Into<[f64; 3]>,
        normal: impl Into<[f64; 3]>,
    ) -> Self {
        Self {
            input: RollingDiscInput {
                node: node.0,
                radius,
                axis: axis.into(),
                normal: normal.into(),
                ..RollingDiscInput::default()
            },
            id: None,
        }
    }

    /// A point of the plane (default the origin).
    pub fn point(mut self, point: impl Into<[f64; 3]>) -> Self {
        self.input.point = Some(point.into());
        self
    }

    /// Its id (default: the next free element id).
    pub fn id(mut self, id: Id) -> Self {
        self.id = Some(id);
        self
    }
}

impl Entity for RollingDisc {
    type Handle = RollingDiscHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> RollingDiscHandle {
        self.input.id = m.element_id(self.id, 1);
        let handle = RollingDiscHandle(self.input.id);
        m.input.rolling_discs.push(self.input);
        handle
    }
}
