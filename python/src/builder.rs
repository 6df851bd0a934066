//! The builders of `unfold::model::builder` as Python classes, with the
//! same names, the same methods and the same defaults: each Python object
//! holds the Rust builder, and each method returns a new object with the
//! method applied (`Joint.revolute(a, b).axis([0, 0, 1])`), so that a
//! builder can be kept and reused as a template. `ModelBuilder.add`
//! adds an entity and returns its handle, as in Rust.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use unfold::model::builder as b;
use unfold::model::builder::{Body, CurveHandle};
use unfold::model::input::{LatchSide, ModelInput};

use crate::errors;
use crate::model::PyModel;

/// Defines a Python class holding a Rust builder: `Clone`, with a
/// `__repr__` from its `Debug`.
macro_rules! wrapper {
    ($(#[$doc:meta])* $py:ident, $name:literal, $rust:ty) => {
        $(#[$doc])*
        #[pyclass(name = $name, module = "unfold", frozen, from_py_object)]
        #[derive(Clone, Debug)]
        pub struct $py(pub $rust);

        impl $py {
            /// A new object with `f` applied to a copy of the builder.
            #[allow(dead_code)]
            fn with(&self, f: impl FnOnce($rust) -> $rust) -> Self {
                Self(f(self.0.clone()))
            }
        }
    };
}

/// Defines a Python class holding a Rust handle of an element: its id,
/// equality, hashing and a `repr` (`JointHandle(5)`).
macro_rules! element_handle {
    ($(#[$doc:meta])* $py:ident, $name:literal, $rust:ty) => {
        $(#[$doc])*
        #[pyclass(name = $name, module = "unfold", frozen, eq, hash, from_py_object)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub struct $py(pub $rust);

        #[pymethods]
        impl $py {
            /// The element's id in the model file.
            #[getter]
            fn id(&self) -> u64 {
                self.0.id() as u64
            }

            /// The kind of element, as the result files name it
            /// (`beam`, `joint`, `latch`...).
            #[getter]
            fn kind(&self) -> String {
                kind_name(unfold::model::builder::ElementRef::kind(self.0))
            }

            fn __repr__(&self) -> String {
                format!("{}({})", $name, self.0.id())
            }
        }

        impl ElementLike for $py {
            fn key(&self) -> (unfold::elements::ElementKind, unfold::model::Id) {
                use unfold::model::builder::ElementRef;
                (self.0.kind(), ElementRef::id(self.0))
            }
        }
    };
}

/// The Python name of a kind of element: the library's name with
/// underscores (`hinge_law`, `rigid_body`), as its result file is named.
pub fn kind_name(kind: unfold::elements::ElementKind) -> String {
    kind.name().replace(' ', "_")
}

/// The kind of element of a Python name (`hinge_law`, or `hinge law`).
pub fn kind_of(name: &str) -> PyResult<unfold::elements::ElementKind> {
    unfold::elements::ElementKind::ALL
        .into_iter()
        .find(|k| k.name() == name || kind_name(*k) == name)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "no kind of element is named {name:?} (kinds: {})",
                unfold::elements::ElementKind::ALL.map(kind_name).join(", ")
            ))
        })
}

/// What a handle of an element tells: its kind and id.
pub trait ElementLike {
    /// The kind and the id.
    fn key(&self) -> (unfold::elements::ElementKind, unfold::model::Id);
}

// ---------------------------------------------------------------- enums

/// A unit of angles.
#[pyclass(
    name = "AngleUnit",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyAngleUnit {
    /// Radians.
    Rad,
    /// Degrees.
    Deg,
}

impl From<PyAngleUnit> for b::AngleUnit {
    fn from(u: PyAngleUnit) -> Self {
        match u {
            PyAngleUnit::Rad => Self::Rad,
            PyAngleUnit::Deg => Self::Deg,
        }
    }
}

/// How a latch's coordinate reaches its locking value.
#[pyclass(
    name = "Approach",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyApproach {
    /// The coordinate increases to the value.
    Increasing,
    /// The coordinate decreases to the value.
    Decreasing,
}

impl From<PyApproach> for b::Approach {
    fn from(a: PyApproach) -> Self {
        match a {
            PyApproach::Increasing => Self::Increasing,
            PyApproach::Decreasing => Self::Decreasing,
        }
    }
}

/// The bound a hinge law starts on.
#[pyclass(
    name = "StartBranch",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyStartBranch {
    /// The loading bound.
    Load,
    /// The unloading bound.
    Unload,
}

impl From<PyStartBranch> for b::StartBranch {
    fn from(s: PyStartBranch) -> Self {
        match s {
            PyStartBranch::Load => Self::Load,
            PyStartBranch::Unload => Self::Unload,
        }
    }
}

/// The side of the locking value a spring latch's spring acts on.
#[pyclass(
    name = "LatchSide",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyLatchSide {
    /// Both sides.
    Both,
    /// Beyond the value, in the direction of approach.
    Beyond,
    /// Behind it.
    Behind,
}

impl From<PyLatchSide> for LatchSide {
    fn from(s: PyLatchSide) -> Self {
        match s {
            PyLatchSide::Both => Self::Both,
            PyLatchSide::Beyond => Self::Beyond,
            PyLatchSide::Behind => Self::Behind,
        }
    }
}

/// The type of a joint.
#[pyclass(
    name = "JointType",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyJointType {
    /// Hinge.
    Revolute,
    /// Sliding along the axis.
    Prismatic,
    /// Rotation about and sliding along the axis.
    Cylindrical,
    /// Ball joint.
    Spherical,
    /// Motion in a plane.
    Planar,
    /// Cardan joint.
    Universal,
    /// Screw.
    Helical,
    /// A node on a curve through nodes.
    Slider,
    /// Rigid connection at the joint point.
    Rigid,
    /// Node B held in A's material frame.
    Glue,
}

impl From<PyJointType> for b::JointType {
    fn from(t: PyJointType) -> Self {
        use PyJointType as P;
        match t {
            P::Revolute => Self::Revolute,
            P::Prismatic => Self::Prismatic,
            P::Cylindrical => Self::Cylindrical,
            P::Spherical => Self::Spherical,
            P::Planar => Self::Planar,
            P::Universal => Self::Universal,
            P::Helical => Self::Helical,
            P::Slider => Self::Slider,
            P::Rigid => Self::Rigid,
            P::Glue => Self::Glue,
        }
    }
}

/// A relative coordinate of a joint (docs/joints.md).
#[pyclass(
    name = "Coordinate",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyCoordinate {
    /// The angle about the joint axis.
    Angle,
    /// The slide along local axis 1.
    Slide1,
    /// The slide along local axis 2.
    Slide2,
    /// The slide along local axis 3 (the joint axis).
    Slide3,
    /// The first Cardan angle.
    Cardan1,
    /// The second Cardan angle.
    Cardan2,
    /// The parameter along a slider's curve.
    CurveParameter,
}

impl From<PyCoordinate> for b::Coordinate {
    fn from(c: PyCoordinate) -> Self {
        use PyCoordinate as P;
        match c {
            P::Angle => Self::Angle,
            P::Slide1 => Self::Slide1,
            P::Slide2 => Self::Slide2,
            P::Slide3 => Self::Slide3,
            P::Cardan1 => Self::Cardan1,
            P::Cardan2 => Self::Cardan2,
            P::CurveParameter => Self::CurveParameter,
        }
    }
}

/// One component of a node's motion: a translation along a global axis
/// or an incremental rotation about a material axis.
#[pyclass(
    name = "Component",
    module = "unfold",
    eq,
    eq_int,
    frozen,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PyComponent {
    /// Translation along global x.
    X,
    /// Translation along global y.
    Y,
    /// Translation along global z.
    Z,
    /// Rotation about the node's material axis 1.
    Rx,
    /// Rotation about the node's material axis 2.
    Ry,
    /// Rotation about the node's material axis 3.
    Rz,
}

impl From<PyComponent> for b::Component {
    fn from(c: PyComponent) -> Self {
        use PyComponent as P;
        match c {
            P::X => Self::X,
            P::Y => Self::Y,
            P::Z => Self::Z,
            P::Rx => Self::Rx,
            P::Ry => Self::Ry,
            P::Rz => Self::Rz,
        }
    }
}

#[pymethods]
impl PyComponent {
    fn __or__(&self, other: &Bound<'_, PyAny>) -> PyResult<PyDofs> {
        Ok(PyDofs(
            b::Dofs::from(b::Component::from(*self)) | dofs(other)?,
        ))
    }

    /// Name in model files (`x`, …, `rz`).
    fn name_in_file(&self) -> &'static str {
        b::Component::from(*self).name()
    }
}

/// A set of components of a node: `Dofs.ALL`, `Dofs.TRANSLATIONS`,
/// `Dofs.ROTATIONS`, `Component.X | Component.Rz`.
#[pyclass(name = "Dofs", module = "unfold", frozen, eq, hash, from_py_object)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PyDofs(pub b::Dofs);

#[pymethods]
impl PyDofs {
    /// No component.
    #[classattr]
    const NONE: PyDofs = PyDofs(b::Dofs::NONE);
    /// The three translations.
    #[classattr]
    const TRANSLATIONS: PyDofs = PyDofs(b::Dofs::TRANSLATIONS);
    /// The three rotations.
    #[classattr]
    const ROTATIONS: PyDofs = PyDofs(b::Dofs::ROTATIONS);
    /// All six components.
    #[classattr]
    const ALL: PyDofs = PyDofs(b::Dofs::ALL);

    /// Whether `c` is in the set.
    fn contains(&self, c: PyComponent) -> bool {
        self.0.contains(c.into())
    }

    fn __contains__(&self, c: PyComponent) -> bool {
        self.contains(c)
    }

    fn __or__(&self, other: &Bound<'_, PyAny>) -> PyResult<PyDofs> {
        Ok(PyDofs(self.0 | dofs(other)?))
    }

    fn __repr__(&self) -> String {
        let names: Vec<&str> = [
            b::Component::X,
            b::Component::Y,
            b::Component::Z,
            b::Component::Rx,
            b::Component::Ry,
            b::Component::Rz,
        ]
        .into_iter()
        .filter(|c| self.0.contains(*c))
        .map(|c| c.name())
        .collect();
        format!("Dofs({})", names.join(" | "))
    }
}

/// A `Dofs`, a `Component` or a sequence of components.
fn dofs(obj: &Bound<'_, PyAny>) -> PyResult<b::Dofs> {
    if let Ok(d) = obj.extract::<PyDofs>() {
        return Ok(d.0);
    }
    if let Ok(c) = obj.extract::<PyComponent>() {
        return Ok(b::Component::from(c).into());
    }
    if let Ok(cs) = obj.extract::<Vec<PyComponent>>() {
        let cs: Vec<b::Component> = cs.into_iter().map(Into::into).collect();
        return Ok(b::Dofs::from(cs.as_slice()));
    }
    Err(PyTypeError::new_err(
        "components: a Dofs, a Component or a list of Components",
    ))
}

// -------------------------------------------------------------- handles

/// A node of the model.
#[pyclass(
    name = "NodeHandle",
    module = "unfold",
    frozen,
    eq,
    hash,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PyNodeHandle(pub b::NodeHandle);

#[pymethods]
impl PyNodeHandle {
    /// The node's id in the model file.
    #[getter]
    fn id(&self) -> u64 {
        self.0.id()
    }

    fn __repr__(&self) -> String {
        format!("NodeHandle({})", self.0.id())
    }
}

element_handle!(
    /// A beam element.
    PyBeamHandle,
    "BeamHandle",
    b::BeamHandle
);
element_handle!(
    /// A rigid body.
    PyRigidBodyHandle,
    "RigidBodyHandle",
    b::RigidBodyHandle
);
element_handle!(
    /// A point mass.
    PyPointMassHandle,
    "PointMassHandle",
    b::PointMassHandle
);
element_handle!(
    /// A spring.
    PySpringHandle,
    "SpringHandle",
    b::SpringHandle
);
element_handle!(
    /// A nodal load (its id is its position in `loads`, from 1).
    PyLoadHandle,
    "LoadHandle",
    b::LoadHandle
);
element_handle!(
    /// A joint.
    PyJointHandle,
    "JointHandle",
    b::JointHandle
);
element_handle!(
    /// A spring or damper on a joint coordinate.
    PyJointSpringHandle,
    "JointSpringHandle",
    b::JointSpringHandle
);
element_handle!(
    /// A hinge law with memory.
    PyHingeLawHandle,
    "HingeLawHandle",
    b::HingeLawHandle
);
element_handle!(
    /// A driver.
    PyDriverHandle,
    "DriverHandle",
    b::DriverHandle
);
element_handle!(
    /// A latch.
    PyLatchHandle,
    "LatchHandle",
    b::LatchHandle
);
element_handle!(
    /// A unilateral stop.
    PyStopHandle,
    "StopHandle",
    b::StopHandle
);
element_handle!(
    /// A unilateral contact.
    PyContactHandle,
    "ContactHandle",
    b::ContactHandle
);
element_handle!(
    /// A rolling disc.
    PyRollingDiscHandle,
    "RollingDiscHandle",
    b::RollingDiscHandle
);

/// The nodes and elements of a beam line.
#[pyclass(name = "BeamLineHandle", module = "unfold", frozen, from_py_object)]
#[derive(Clone, Debug)]
pub struct PyBeamLineHandle(pub b::BeamLineHandle);

#[pymethods]
impl PyBeamLineHandle {
    /// Every node along the line, from its first end node to its last.
    #[getter]
    fn nodes(&self) -> Vec<PyNodeHandle> {
        self.0.nodes.iter().map(|&n| PyNodeHandle(n)).collect()
    }

    /// The elements, in order along the line.
    #[getter]
    fn elements(&self) -> Vec<PyBeamHandle> {
        self.0.elements.iter().map(|&e| PyBeamHandle(e)).collect()
    }

    /// The nodes strictly inside the line.
    fn interior(&self) -> Vec<PyNodeHandle> {
        self.0.interior().iter().map(|&n| PyNodeHandle(n)).collect()
    }

    /// The first end node.
    fn start(&self) -> PyNodeHandle {
        PyNodeHandle(self.0.start())
    }

    /// The last end node.
    fn end(&self) -> PyNodeHandle {
        PyNodeHandle(self.0.end())
    }

    fn __repr__(&self) -> String {
        format!(
            "BeamLineHandle(nodes {}..{}, {} elements)",
            self.0.start().id(),
            self.0.end().id(),
            self.0.elements.len()
        )
    }
}

/// A section of the model.
#[pyclass(
    name = "SectionHandle",
    module = "unfold",
    frozen,
    eq,
    hash,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PySectionHandle(pub b::SectionHandle);

#[pymethods]
impl PySectionHandle {
    fn __repr__(&self) -> String {
        format!("{:?}", self.0)
    }
}

/// A curve of the model: one added, or a built-in one
/// (`CurveHandle.RAMP`, `CurveHandle.CONSTANT`).
#[pyclass(
    name = "CurveHandle",
    module = "unfold",
    frozen,
    eq,
    hash,
    from_py_object
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PyCurveHandle(pub CurveHandle);

#[pymethods]
impl PyCurveHandle {
    /// The built-in ramp `f(t) = t`.
    #[classattr]
    const RAMP: PyCurveHandle = PyCurveHandle(CurveHandle::RAMP);
    /// The built-in constant `f(t) = 1`.
    #[classattr]
    const CONSTANT: PyCurveHandle = PyCurveHandle(CurveHandle::CONSTANT);

    fn __repr__(&self) -> String {
        format!("{:?}", self.0)
    }
}

/// The ground, as the second body of a joint or a spring: `unfold.Ground`.
#[pyclass(name = "GroundType", module = "unfold", frozen, from_py_object)]
#[derive(Clone, Copy, Debug)]
pub struct PyGround;

#[pymethods]
impl PyGround {
    fn __repr__(&self) -> &'static str {
        "Ground"
    }
}

/// A node handle or the ground.
fn body(obj: &Bound<'_, PyAny>) -> PyResult<Body> {
    if let Ok(n) = obj.extract::<PyNodeHandle>() {
        return Ok(Body::Node(n.0));
    }
    if obj.extract::<PyGround>().is_ok() {
        return Ok(Body::Ground);
    }
    Err(PyTypeError::new_err(
        "the second body: a NodeHandle or unfold.Ground",
    ))
}

/// A stiffness or damping coefficient: one value, or one per axis.
#[derive(FromPyObject)]
pub enum Stiffness {
    /// One value.
    Isotropic(f64),
    /// One per axis.
    PerAxis([f64; 3]),
}

impl From<Stiffness> for unfold::model::input::StiffnessInput {
    fn from(s: Stiffness) -> Self {
        match s {
            Stiffness::Isotropic(k) => Self::Isotropic(k),
            Stiffness::PerAxis(k) => Self::PerAxis(k),
        }
    }
}

// ---------------------------------------------------------- structure

wrapper!(
    /// A node: position and orientation in the reference configuration.
    PyNode,
    "Node",
    b::Node
);

#[pymethods]
impl PyNode {
    /// A node at `x` with the identity orientation.
    #[staticmethod]
    fn at(x: [f64; 3]) -> Self {
        Self(b::Node::at(x))
    }

    /// Its orientation, as a rotation vector (global frame) in radians.
    fn rotation(&self, psi: [f64; 3]) -> Self {
        self.with(|n| n.rotation(psi))
    }

    /// The unit of the rotation vector.
    fn unit(&self, unit: PyAngleUnit) -> Self {
        self.with(|n| n.unit(unit.into()))
    }

    /// Its initial velocity (global frame), for dynamic analyses.
    fn velocity(&self, v: [f64; 3]) -> Self {
        self.with(|n| n.velocity(v))
    }

    /// Its initial angular velocity (global frame, rad/s).
    fn angular_velocity(&self, w: [f64; 3]) -> Self {
        self.with(|n| n.angular_velocity(w))
    }

    /// Its id (default: the next free one).
    fn id(&self, id: u32) -> Self {
        self.with(|n| n.id(id as _))
    }
}

wrapper!(
    /// A beam cross-section, by its sectional stiffness and its mass.
    PySection,
    "Section",
    b::Section
);

#[pymethods]
impl PySection {
    /// A section of diagonal stiffness: axial `EA`, shear `GA2`, `GA3`,
    /// torsion `GJ`, bending `EI2`, `EI3` about local axes 2 and 3.
    #[staticmethod]
    fn diagonal(ea: f64, ga2: f64, ga3: f64, gj: f64, ei2: f64, ei3: f64) -> Self {
        Self(b::Section::diagonal(ea, ga2, ga3, gj, ei2, ei3))
    }

    /// A section of full symmetric 6×6 stiffness (rows), in the order
    /// axial strain, shear strains 2 and 3, torsion, curvatures 2 and 3.
    #[staticmethod]
    fn full(stiffness: [[f64; 6]; 6]) -> Self {
        Self(b::Section::full(stiffness))
    }

    /// Its mass per unit length.
    fn mass_per_length(&self, mass: f64) -> Self {
        self.with(|s| s.mass_per_length(mass))
    }

    /// Its rotational inertia per unit length about the local axes 1, 2, 3.
    fn inertia_per_length(&self, inertia: [f64; 3]) -> Self {
        self.with(|s| s.inertia_per_length(inertia))
    }

    /// Its Rayleigh damping `C_R = α M + β K_mat`: `alpha` in 1/s, `beta` in s.
    fn rayleigh_damping(&self, alpha: f64, beta: f64) -> Self {
        self.with(|s| s.rayleigh_damping(alpha, beta))
    }

    /// Its name in the model file (default `section_N`).
    fn named(&self, name: String) -> Self {
        self.with(|s| s.named(name))
    }
}

wrapper!(
    /// A two-node beam element.
    PyBeam,
    "Beam",
    b::Beam
);

#[pymethods]
impl PyBeam {
    /// A beam from `a` to `b` of `section`.
    #[staticmethod]
    fn between(a: PyNodeHandle, b: PyNodeHandle, section: PySectionHandle) -> Self {
        Self(b::Beam::between(a.0, b.0, section.0))
    }

    /// Reference vector of the section: local axis 2 is its part normal
    /// to the beam axis.
    fn orientation(&self, v: [f64; 3]) -> Self {
        self.with(|x| x.orientation(v))
    }

    /// Sectional strains at which the section is stress-free.
    fn initial_strain(&self, strain: [f64; 6]) -> Self {
        self.with(|x| x.initial_strain(strain))
    }

    /// An axial initial strain alone: negative shortens the beam.
    fn axial_strain(&self, strain: f64) -> Self {
        self.with(|x| x.axial_strain(strain))
    }

    /// The curve applying the initial strain gradually.
    fn initial_strain_curve(&self, curve: PyCurveHandle) -> Self {
        self.with(|x| x.initial_strain_curve(curve.0))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A straight line or a circular arc between two nodes, meshed into
    /// beam elements of equal length.
    PyBeamLine,
    "BeamLine",
    b::BeamLine
);

#[pymethods]
impl PyBeamLine {
    /// `elements` beams of `section` from `a` to `b`.
    #[staticmethod]
    fn between(
        a: PyNodeHandle,
        b: PyNodeHandle,
        elements: usize,
        section: PySectionHandle,
    ) -> Self {
        Self(b::BeamLine::between(a.0, b.0, elements, section.0))
    }

    /// A circular arc about `center` instead of a straight line.
    fn arc(&self, center: [f64; 3]) -> Self {
        self.with(|x| x.arc(center))
    }

    /// Reference vector of the section.
    fn orientation(&self, v: [f64; 3]) -> Self {
        self.with(|x| x.orientation(v))
    }

    /// Sectional strains at which the section is stress-free.
    fn initial_strain(&self, strain: [f64; 6]) -> Self {
        self.with(|x| x.initial_strain(strain))
    }

    /// An axial initial strain alone: negative shortens the beam.
    fn axial_strain(&self, strain: f64) -> Self {
        self.with(|x| x.axial_strain(strain))
    }

    /// The curve applying the initial strain gradually.
    fn initial_strain_curve(&self, curve: PyCurveHandle) -> Self {
        self.with(|x| x.initial_strain_curve(curve.0))
    }
}

wrapper!(
    /// A rigid body carried by a node.
    PyRigidBody,
    "RigidBody",
    b::RigidBody
);

#[pymethods]
impl PyRigidBody {
    /// A body of `mass` carried by `node`, its centre of mass at the node
    /// and no rotational inertia.
    #[staticmethod]
    fn at(node: PyNodeHandle, mass: f64) -> Self {
        Self(b::RigidBody::at(node.0, mass))
    }

    /// Its principal inertia `[I11, I22, I33]` about the centre of mass.
    fn inertia(&self, principal: [f64; 3]) -> Self {
        self.with(|x| x.inertia(principal))
    }

    /// Its full inertia tensor about the centre of mass (rows).
    fn inertia_tensor(&self, rows: [[f64; 3]; 3]) -> Self {
        self.with(|x| x.inertia_tensor(rows))
    }

    /// Position of its centre of mass relative to the node (material frame).
    fn center_of_mass(&self, offset: [f64; 3]) -> Self {
        self.with(|x| x.center_of_mass(offset))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A point mass carried by a node.
    PyPointMass,
    "PointMass",
    b::PointMass
);

#[pymethods]
impl PyPointMass {
    /// A point of `mass` at `node`.
    #[staticmethod]
    fn at(node: PyNodeHandle, mass: f64) -> Self {
        Self(b::PointMass::at(node.0, mass))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A linear spring between two nodes, or between a node and the ground.
    PySpring,
    "Spring",
    b::Spring
);

#[pymethods]
impl PySpring {
    /// Resists the relative displacement along the global axes: one
    /// stiffness, or one per axis.
    #[staticmethod]
    fn translational(
        a: PyNodeHandle,
        b: &Bound<'_, PyAny>,
        stiffness: Stiffness,
    ) -> PyResult<Self> {
        Ok(Self(b::Spring::translational(a.0, body(b)?, stiffness)))
    }

    /// Resists the relative rotation, in `a`'s material frame.
    #[staticmethod]
    fn rotational(a: PyNodeHandle, b: &Bound<'_, PyAny>, stiffness: Stiffness) -> PyResult<Self> {
        Ok(Self(b::Spring::rotational(a.0, body(b)?, stiffness)))
    }

    /// Resists the change of the distance between two nodes.
    #[staticmethod]
    fn axial(a: PyNodeHandle, b: PyNodeHandle, stiffness: f64) -> Self {
        Self(b::Spring::axial(a.0, b.0, stiffness))
    }

    /// A linear damper in parallel: one coefficient, or one per axis.
    fn damping(&self, c: Stiffness) -> Self {
        self.with(|x| x.damping(c))
    }

    /// A damper in parallel given by its damping ratio `ζ`.
    fn damping_ratio(&self, zeta: f64) -> Self {
        self.with(|x| x.damping_ratio(zeta))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

// ---------------------------------------------------------- mechanism

wrapper!(
    /// A kinematic pair between node A and node B, or between node A and
    /// the ground.
    PyJoint,
    "Joint",
    b::Joint
);

#[pymethods]
impl PyJoint {
    /// A joint of type `kind` between `a` and `b` (a node or `Ground`).
    #[staticmethod]
    fn new(kind: PyJointType, a: PyNodeHandle, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self(b::Joint::new(kind.into(), a.0, body(b)?)))
    }

    /// A hinge: rotation about `axis` only.
    #[staticmethod]
    fn revolute(a: PyNodeHandle, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self(b::Joint::revolute(a.0, body(b)?)))
    }

    /// Sliding along `axis` only.
    #[staticmethod]
    fn prismatic(a: PyNodeHandle, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self(b::Joint::prismatic(a.0, body(b)?)))
    }

    /// Rotation about and sliding along `axis`.
    #[staticmethod]
    fn cylindrical(a: PyNodeHandle, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self(b::Joint::cylindrical(a.0, body(b)?)))
    }

    /// A ball joint.
    #[staticmethod]
    fn spherical(a: PyNodeHandle, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self(b::Joint::spherical(a.0, body(b)?)))
    }

    /// Motion in the plane normal to `axis`.
    #[staticmethod]
    fn planar(a: PyNodeHandle, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self(b::Joint::planar(a.0, body(b)?)))
    }

    /// A Cardan joint of cross arms `arm_a` and `arm_b`.
    #[staticmethod]
    fn universal(
        a: PyNodeHandle,
        b: &Bound<'_, PyAny>,
        arm_a: [f64; 3],
        arm_b: [f64; 3],
    ) -> PyResult<Self> {
        Ok(Self(b::Joint::universal(a.0, body(b)?, arm_a, arm_b)))
    }

    /// A screw about `axis` advancing `pitch` per turn.
    #[staticmethod]
    fn helical(a: PyNodeHandle, b: &Bound<'_, PyAny>, pitch: f64) -> PyResult<Self> {
        Ok(Self(b::Joint::helical(a.0, body(b)?, pitch)))
    }

    /// A rigid connection of two nodes at the joint point.
    #[staticmethod]
    fn rigid(a: PyNodeHandle, b: PyNodeHandle) -> Self {
        Self(b::Joint::rigid(a.0, b.0))
    }

    /// Node B held where it is in A's material frame.
    #[staticmethod]
    fn glue(a: PyNodeHandle, b: PyNodeHandle) -> Self {
        Self(b::Joint::glue(a.0, b.0))
    }

    /// `node` sliding on the C¹ spline through the nodes of `curve`.
    #[staticmethod]
    fn slider(node: PyNodeHandle, curve: Vec<PyNodeHandle>) -> Self {
        let curve: Vec<b::NodeHandle> = curve.into_iter().map(|n| n.0).collect();
        Self(b::Joint::slider(node.0, &curve))
    }

    /// The joint axis `e₃`, reference configuration.
    fn axis(&self, axis: [f64; 3]) -> Self {
        self.with(|x| x.axis(axis))
    }

    /// The same axis as carried by body B.
    fn axis_b(&self, axis: [f64; 3]) -> Self {
        self.with(|x| x.axis_b(axis))
    }

    /// The direction from which its angles are measured (`e₁`).
    fn reference_direction(&self, direction: [f64; 3]) -> Self {
        self.with(|x| x.reference_direction(direction))
    }

    /// The joint point (default: node A's position).
    fn at(&self, point: [f64; 3]) -> Self {
        self.with(|x| x.at(point))
    }

    /// Glue: where B is held, in A's material frame.
    fn offset(&self, offset: [f64; 3]) -> Self {
        self.with(|x| x.offset(offset))
    }

    /// Glue: whether B's rotations are locked to A's too (default true).
    fn lock_rotations(&self, lock: bool) -> Self {
        self.with(|x| x.lock_rotations(lock))
    }

    /// Slider: a polyline through the curve nodes instead of a spline.
    fn polyline(&self) -> Self {
        self.with(|x| x.polyline())
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A spring and/or a damper on a joint coordinate.
    PyJointSpring,
    "JointSpring",
    b::JointSpring
);

#[pymethods]
impl PyJointSpring {
    /// On the first coordinate of `joint`.
    #[staticmethod]
    fn on(joint: PyJointHandle) -> Self {
        Self(b::JointSpring::on(joint.0))
    }

    /// The joint coordinate it acts on.
    fn coordinate(&self, coordinate: PyCoordinate) -> Self {
        self.with(|x| x.coordinate(coordinate.into()))
    }

    /// The unit of the angles.
    fn unit(&self, unit: PyAngleUnit) -> Self {
        self.with(|x| x.unit(unit.into()))
    }

    /// A linear spring of stiffness `k`.
    fn stiffness(&self, k: f64) -> Self {
        self.with(|x| x.stiffness(k))
    }

    /// The coordinate at which the linear spring is unloaded (default 0).
    fn free_value(&self, value: f64) -> Self {
        self.with(|x| x.free_value(value))
    }

    /// A nonlinear spring: points `[coordinate, force]`.
    fn table(&self, points: Vec<[f64; 2]>) -> Self {
        self.with(|x| x.table(points))
    }

    /// A linear damper of coefficient `c`.
    fn damping(&self, c: f64) -> Self {
        self.with(|x| x.damping(c))
    }

    /// A nonlinear damper: points `[rate, force]`.
    fn damping_table(&self, points: Vec<[f64; 2]>) -> Self {
        self.with(|x| x.damping_table(points))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// The analytic tape-spring shape of a hinge law's bounds
    /// (docs/joints.md §4.1).
    PyTapeSpring,
    "TapeSpring",
    b::TapeSpring
);

#[pymethods]
impl PyTapeSpring {
    /// The shape: deployment moment `M_d`, locking angle `c_L`, locking
    /// peak `M_L`, locked stiffness `K`, snap width `w`, and the optional
    /// rounding of its corners.
    #[new]
    #[pyo3(signature = (deployment_moment, locking_angle, locking_peak, locked_stiffness, snap_width, rounding=None))]
    fn new(
        deployment_moment: f64,
        locking_angle: f64,
        locking_peak: f64,
        locked_stiffness: f64,
        snap_width: f64,
        rounding: Option<f64>,
    ) -> Self {
        Self(b::TapeSpring {
            deployment_moment,
            locking_angle,
            locking_peak,
            locked_stiffness,
            snap_width,
            rounding,
        })
    }
}

wrapper!(
    /// A hysteretic moment law on a joint coordinate (a hinge law with
    /// memory, docs/joints.md §4.1).
    PyHingeLaw,
    "HingeLaw",
    b::HingeLaw
);

#[pymethods]
impl PyHingeLaw {
    /// On the first coordinate of `joint`, with elastic slope `k_e`.
    #[staticmethod]
    fn on(joint: PyJointHandle, elastic_slope: f64) -> Self {
        Self(b::HingeLaw::on(joint.0, elastic_slope))
    }

    /// The joint coordinate it acts on.
    fn coordinate(&self, coordinate: PyCoordinate) -> Self {
        self.with(|x| x.coordinate(coordinate.into()))
    }

    /// The unit of the angles.
    fn unit(&self, unit: PyAngleUnit) -> Self {
        self.with(|x| x.unit(unit.into()))
    }

    /// Bounds from tables of points `[coordinate, moment]`.
    fn tables(&self, load: Vec<[f64; 2]>, unload: Vec<[f64; 2]>) -> Self {
        self.with(|x| x.tables(load, unload))
    }

    /// Bounds from the tape-spring shape.
    fn tape_spring(&self, shape: PyTapeSpring) -> Self {
        self.with(|x| x.tape_spring(shape.0))
    }

    /// The bound it starts on (default the loading bound).
    fn start(&self, start: PyStartBranch) -> Self {
        self.with(|x| x.start(start.into()))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A prescribed history `value · f(t)` of a joint coordinate, or of a
    /// node's translation or rotation.
    PyDriver,
    "Driver",
    b::Driver
);

#[pymethods]
impl PyDriver {
    /// Drives the first coordinate of `joint`.
    #[staticmethod]
    fn on(joint: PyJointHandle) -> Self {
        Self(b::Driver::on(joint.0))
    }

    /// Drives the translation of `node` along `direction` (global).
    #[staticmethod]
    fn translation(node: PyNodeHandle, direction: [f64; 3]) -> Self {
        Self(b::Driver::translation(node.0, direction))
    }

    /// Drives the rotation of `node` about `axis` (global).
    #[staticmethod]
    fn rotation(node: PyNodeHandle, axis: [f64; 3]) -> Self {
        Self(b::Driver::rotation(node.0, axis))
    }

    /// The joint coordinate driven.
    fn coordinate(&self, coordinate: PyCoordinate) -> Self {
        self.with(|x| x.coordinate(coordinate.into()))
    }

    /// The coordinate's value when the curve equals 1 (m, or rad).
    fn value(&self, value: f64) -> Self {
        self.with(|x| x.value(value))
    }

    /// An angle's value when the curve equals 1, in `unit`.
    fn angle(&self, value: f64, unit: PyAngleUnit) -> Self {
        self.with(|x| x.angle(value, unit.into()))
    }

    /// The curve `f(t)` (default the ramp).
    fn curve(&self, curve: PyCurveHandle) -> Self {
        self.with(|x| x.curve(curve.0))
    }

    /// Acts only while `start ≤ t ≤ end`.
    fn active(&self, start: f64, end: f64) -> Self {
        self.with(|x| x.active(start, end))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A latch on a joint coordinate (docs/joints.md §6.2).
    PyLatch,
    "Latch",
    b::Latch
);

#[pymethods]
impl PyLatch {
    /// Locks the first coordinate of `joint` at `value` (m, or rad).
    #[staticmethod]
    fn on(joint: PyJointHandle, value: f64) -> Self {
        Self(b::Latch::on(joint.0, value))
    }

    /// The joint coordinate it locks.
    fn coordinate(&self, coordinate: PyCoordinate) -> Self {
        self.with(|x| x.coordinate(coordinate.into()))
    }

    /// The locking angle, in `unit`.
    fn angle(&self, value: f64, unit: PyAngleUnit) -> Self {
        self.with(|x| x.angle(value, unit.into()))
    }

    /// How the coordinate reaches the locking value.
    fn approach(&self, approach: PyApproach) -> Self {
        self.with(|x| x.approach(approach.into()))
    }

    /// The side of the locking value a spring latch's spring acts on.
    fn side(&self, side: PyLatchSide) -> Self {
        self.with(|x| x.side(side.into()))
    }

    /// A spring latch of stiffness `stiffness` about the locking value.
    fn spring(&self, stiffness: f64) -> Self {
        self.with(|x| x.spring(stiffness))
    }

    /// A spring latch's dead band: its total width about the locking value.
    fn backlash(&self, backlash: f64) -> Self {
        self.with(|x| x.backlash(backlash))
    }

    /// A spring latch's dashpot.
    fn damping(&self, damping: f64) -> Self {
        self.with(|x| x.damping(damping))
    }

    /// The load at which a spring latch releases.
    fn unlatch_load(&self, load: f64) -> Self {
        self.with(|x| x.unlatch_load(load))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A unilateral stop on a joint coordinate (docs/joints.md §6.3).
    PyStop,
    "Stop",
    b::Stop
);

#[pymethods]
impl PyStop {
    /// A stop on the first coordinate of `joint`, without limits yet.
    #[staticmethod]
    fn on(joint: PyJointHandle) -> Self {
        Self(b::Stop::on(joint.0))
    }

    /// The joint coordinate it limits.
    fn coordinate(&self, coordinate: PyCoordinate) -> Self {
        self.with(|x| x.coordinate(coordinate.into()))
    }

    /// The lower limit.
    fn lower(&self, value: f64) -> Self {
        self.with(|x| x.lower(value))
    }

    /// The upper limit.
    fn upper(&self, value: f64) -> Self {
        self.with(|x| x.upper(value))
    }

    /// The unit of the limits of an angle.
    fn unit(&self, unit: PyAngleUnit) -> Self {
        self.with(|x| x.unit(unit.into()))
    }

    /// The coefficient of restitution `e ∈ [0, 1]` (default 0).
    fn restitution(&self, e: f64) -> Self {
        self.with(|x| x.restitution(e))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A unilateral contact (docs/joints.md §6.4).
    PyContact,
    "Contact",
    b::Contact
);

#[pymethods]
impl PyContact {
    /// A point on `node` against the fixed plane through `point` with
    /// normal `normal`.
    #[staticmethod]
    fn plane(node: PyNodeHandle, point: [f64; 3], normal: [f64; 3]) -> Self {
        Self(b::Contact::plane(node.0, point, normal))
    }

    /// Spheres centred on nodes `a` and `b`.
    #[staticmethod]
    fn spheres(a: PyNodeHandle, b: PyNodeHandle) -> Self {
        Self(b::Contact::spheres(a.0, b.0))
    }

    /// The radius of the sphere of a contact with a plane.
    fn radius(&self, r: f64) -> Self {
        self.with(|x| x.radius(r))
    }

    /// The radii of the spheres of a contact of spheres.
    fn radii(&self, ra: f64, rb: f64) -> Self {
        self.with(|x| x.radii(ra, rb))
    }

    /// The coefficient of restitution (default 0).
    fn restitution(&self, e: f64) -> Self {
        self.with(|x| x.restitution(e))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

wrapper!(
    /// A rigid disc rolling without slipping on a fixed plane
    /// (docs/joints.md §3.8).
    PyRollingDisc,
    "RollingDisc",
    b::RollingDisc
);

#[pymethods]
impl PyRollingDisc {
    /// A disc of `radius` centred on `node`, with axis `axis` (material
    /// frame), on the plane through the origin with normal `normal`.
    #[new]
    fn new(node: PyNodeHandle, radius: f64, axis: [f64; 3], normal: [f64; 3]) -> Self {
        Self(b::RollingDisc::new(node.0, radius, axis, normal))
    }

    /// A point of the plane (default the origin).
    fn point(&self, point: [f64; 3]) -> Self {
        self.with(|x| x.point(point))
    }

    /// Its id (default: the next free element id).
    fn id(&self, id: u32) -> Self {
        self.with(|x| x.id(id as _))
    }
}

// ------------------------------------------------------------ loading

wrapper!(
    /// A curve `f(t)` of the load parameter.
    PyLoadCurve,
    "LoadCurve",
    b::LoadCurve
);

#[pymethods]
impl PyLoadCurve {
    /// Piecewise linear through the points `[t, f]`.
    #[staticmethod]
    fn points(points: Vec<[f64; 2]>) -> Self {
        Self(b::LoadCurve::points(points))
    }

    /// `offset + slope·t`.
    #[staticmethod]
    fn linear(offset: f64, slope: f64) -> Self {
        Self(b::LoadCurve::linear(offset, slope))
    }

    /// `offset + amplitude·sin(2π·frequency·t + phase)`.
    #[staticmethod]
    fn sine(offset: f64, amplitude: f64, frequency: f64, phase: f64) -> Self {
        Self(b::LoadCurve::sine(offset, amplitude, frequency, phase))
    }

    /// From 0 at `t = start` to 1 at `t = end`, with zero rate and
    /// acceleration at both ends.
    #[staticmethod]
    fn smooth_step(start: f64, end: f64) -> Self {
        Self(b::LoadCurve::smooth_step(start, end))
    }

    /// A smooth step going from `from_` to `to` instead of 0 to 1.
    fn between(&self, from_: f64, to: f64) -> Self {
        self.with(|x| x.between(from_, to))
    }

    /// Its name in the model file (default `curve_N`).
    fn named(&self, name: String) -> Self {
        self.with(|x| x.named(name))
    }
}

wrapper!(
    /// A nodal force and moment following a curve.
    PyLoad,
    "Load",
    b::Load
);

#[pymethods]
impl PyLoad {
    /// A force on `node`, reached when the curve equals 1.
    #[staticmethod]
    fn force(node: PyNodeHandle, force: [f64; 3]) -> Self {
        Self(b::Load::force(node.0, force))
    }

    /// A moment on `node`.
    #[staticmethod]
    fn moment(node: PyNodeHandle, moment: [f64; 3]) -> Self {
        Self(b::Load::moment(node.0, moment))
    }

    /// A force and a moment on `node`.
    #[staticmethod]
    fn force_and_moment(node: PyNodeHandle, force: [f64; 3], moment: [f64; 3]) -> Self {
        Self(b::Load::force_and_moment(node.0, force, moment))
    }

    /// Components in the node's material frame, turning with it.
    fn follower(&self) -> Self {
        self.with(|x| x.follower())
    }

    /// The curve it follows.
    fn curve(&self, curve: PyCurveHandle) -> Self {
        self.with(|x| x.curve(curve.0))
    }
}

wrapper!(
    /// A uniform gravity field acting on every mass.
    PyGravity,
    "Gravity",
    b::Gravity
);

#[pymethods]
impl PyGravity {
    /// The acceleration of gravity `g`.
    #[staticmethod]
    fn of(g: [f64; 3]) -> Self {
        Self(b::Gravity::of(g))
    }

    /// The curve it follows.
    fn curve(&self, curve: PyCurveHandle) -> Self {
        self.with(|x| x.curve(curve.0))
    }
}

wrapper!(
    /// A prescribed motion of a node, relative to its reference
    /// configuration.
    PyPrescribedMotion,
    "PrescribedMotion",
    b::PrescribedMotion
);

#[pymethods]
impl PyPrescribedMotion {
    /// The translation `component` (`X`, `Y` or `Z`) of `node`.
    #[staticmethod]
    fn translation(node: PyNodeHandle, component: PyComponent, value: f64) -> Self {
        Self(b::PrescribedMotion::translation(
            node.0,
            component.into(),
            value,
        ))
    }

    /// The rotation of `node`, `R(t) = exp(f(t) ψ~) R₀`.
    #[staticmethod]
    fn rotation(node: PyNodeHandle, psi: [f64; 3]) -> Self {
        Self(b::PrescribedMotion::rotation(node.0, psi))
    }

    /// The unit of the rotation.
    fn unit(&self, unit: PyAngleUnit) -> Self {
        self.with(|x| x.unit(unit.into()))
    }

    /// The curve it follows (default: the ramp).
    fn curve(&self, curve: PyCurveHandle) -> Self {
        self.with(|x| x.curve(curve.0))
    }
}

wrapper!(
    /// The analysis and its parameters (docs/model-format.md, `[analysis]`).
    PyAnalysis,
    "Analysis",
    b::Analysis
);

#[pymethods]
impl PyAnalysis {
    /// Nonlinear statics.
    #[staticmethod]
    fn statics() -> Self {
        Self(b::Analysis::statics())
    }

    /// Nonlinear statics of a mechanism moved by its drivers.
    #[staticmethod]
    fn kinetostatic() -> Self {
        Self(b::Analysis::kinetostatic())
    }

    /// Kinematic analysis.
    #[staticmethod]
    fn kinematic() -> Self {
        Self(b::Analysis::kinematic())
    }

    /// Implicit dynamics (Lie-group generalised-α).
    #[staticmethod]
    fn dynamic() -> Self {
        Self(b::Analysis::dynamic())
    }

    /// Modal analysis: the `modes` lowest natural modes.
    #[staticmethod]
    fn modal(modes: usize) -> Self {
        Self(b::Analysis::modal(modes))
    }

    /// Dynamics: the first time step.
    fn time_step(&self, h: f64) -> Self {
        self.with(|x| x.time_step(h))
    }

    /// Dynamics: the spectral radius at infinite frequency (default 0.9).
    fn rho_infinity(&self, rho: f64) -> Self {
        self.with(|x| x.rho_infinity(rho))
    }

    /// Dynamics: fixed steps of `time_step`.
    fn fixed_step(&self) -> Self {
        self.with(|x| x.fixed_step())
    }

    /// Dynamics: the smallest time step.
    fn min_step(&self, h: f64) -> Self {
        self.with(|x| x.min_step(h))
    }

    /// Dynamics: the largest time step.
    fn max_step(&self, h: f64) -> Self {
        self.with(|x| x.max_step(h))
    }

    /// Dynamics: the relative tolerance of the local error estimate.
    fn error_tolerance(&self, tolerance: f64) -> Self {
        self.with(|x| x.error_tolerance(tolerance))
    }

    /// Dynamics: the Newton method, `full` or `modified`.
    fn newton(&self, method: &str) -> Self {
        self.with(|x| x.newton(method))
    }

    /// Dynamics: the frame of the angular velocities in the time scheme,
    /// `material` or `spatial`.
    fn angular_velocities(&self, frame: &str) -> Self {
        self.with(|x| x.angular_velocities(frame))
    }

    /// Modal analysis: the modes nearest to this frequency (Hz).
    fn shift(&self, frequency: f64) -> Self {
        self.with(|x| x.shift(frequency))
    }

    /// Modal analysis: only the modes with frequencies in `[low, high]`.
    fn frequency_range(&self, low: f64, high: f64) -> Self {
        self.with(|x| x.frequency_range(low, high))
    }

    /// Modal analysis: the eigen-solver, `auto`, `dense` or `lanczos`.
    fn solver(&self, solver: &str) -> Self {
        self.with(|x| x.solver(solver))
    }

    /// Final value of the load parameter (default 1).
    fn end_time(&self, t: f64) -> Self {
        self.with(|x| x.end_time(t))
    }

    /// First increment of `t` (default `end_time / 10`).
    fn initial_increment(&self, h: f64) -> Self {
        self.with(|x| x.initial_increment(h))
    }

    /// Smallest increment before the analysis gives up.
    fn min_increment(&self, h: f64) -> Self {
        self.with(|x| x.min_increment(h))
    }

    /// Largest increment (default the initial one).
    fn max_increment(&self, h: f64) -> Self {
        self.with(|x| x.max_increment(h))
    }

    /// Newton iterations per increment before a cut-back (default 25).
    fn max_iterations(&self, n: usize) -> Self {
        self.with(|x| x.max_iterations(n))
    }

    /// Residual tolerance relative to the force flux (default 1e-8).
    fn residual_tolerance(&self, tolerance: f64) -> Self {
        self.with(|x| x.residual_tolerance(tolerance))
    }

    /// Displacement correction tolerance (default 1e-6).
    fn displacement_tolerance(&self, tolerance: f64) -> Self {
        self.with(|x| x.displacement_tolerance(tolerance))
    }

    /// Rotation correction tolerance in radians (default 1e-6).
    fn rotation_tolerance(&self, tolerance: f64) -> Self {
        self.with(|x| x.rotation_tolerance(tolerance))
    }

    /// Results written every `n` increments (default 1).
    fn output_every(&self, n: usize) -> Self {
        self.with(|x| x.output_every(n))
    }

    /// Values of `t` the analysis lands on exactly and writes results at.
    fn output_times(&self, times: Vec<f64>) -> Self {
        self.with(|x| x.output_times(times))
    }

    /// Dynamics: results written every `interval` of time.
    fn output_interval(&self, interval: f64) -> Self {
        self.with(|x| x.output_interval(interval))
    }

    /// Scaling factor `k` of the constraint equations.
    fn constraint_scale(&self, k: f64) -> Self {
        self.with(|x| x.constraint_scale(k))
    }

    /// Penalty `p` of the constraint equations.
    fn constraint_penalty(&self, p: f64) -> Self {
        self.with(|x| x.constraint_penalty(p))
    }

    /// Arc-length path control, with at most `max_increments` increments.
    fn arc_length(&self, max_increments: usize) -> Self {
        self.with(|x| x.arc_length(max_increments))
    }
}

// -------------------------------------------------------------- model

/// A model being built (`unfold::model::builder::ModelBuilder`): each
/// call adds one entity and returns its handle; nothing is checked until
/// [`PyModelBuilder::build`], which reports every problem together.
#[pyclass(name = "ModelBuilder", module = "unfold")]
#[derive(Clone, Debug)]
pub struct PyModelBuilder {
    /// The Rust builder.
    pub inner: b::ModelBuilder,
}

#[pymethods]
impl PyModelBuilder {
    /// An empty model with a title, to be run as a static analysis unless
    /// `analysis` says otherwise.
    #[new]
    fn new(title: String) -> Self {
        Self {
            inner: b::ModelBuilder::new(title),
        }
    }

    /// Adds `entity` (a `Node`, `Section`, `Beam`, `BeamLine`, `RigidBody`,
    /// `PointMass`, `Spring`, `Joint`, `JointSpring`, `HingeLaw`, `Driver`,
    /// `Latch`, `Stop`, `Contact`, `RollingDisc`, `Load`, `Gravity`,
    /// `PrescribedMotion` or `LoadCurve`) and returns its handle (`None`
    /// for gravity and prescribed motions).
    fn add<'py>(&mut self, py: Python<'py>, entity: &Bound<'py, PyAny>) -> PyResult<Py<PyAny>> {
        let m = &mut self.inner;
        macro_rules! try_add {
            ($($py:ty => $handle:expr),* $(,)?) => {
                $(
                    if let Ok(e) = entity.extract::<$py>() {
                        #[allow(clippy::redundant_closure_call)]
                        return Ok(($handle)(m.add(e.0)).into_pyobject(py)?.into_any().unbind());
                    }
                )*
            };
        }
        try_add!(
            PyNode => PyNodeHandle,
            PySection => PySectionHandle,
            PyLoadCurve => PyCurveHandle,
            PyBeam => PyBeamHandle,
            PyBeamLine => PyBeamLineHandle,
            PyRigidBody => PyRigidBodyHandle,
            PyPointMass => PyPointMassHandle,
            PySpring => PySpringHandle,
            PyJoint => PyJointHandle,
            PyJointSpring => PyJointSpringHandle,
            PyHingeLaw => PyHingeLawHandle,
            PyDriver => PyDriverHandle,
            PyLatch => PyLatchHandle,
            PyStop => PyStopHandle,
            PyContact => PyContactHandle,
            PyRollingDisc => PyRollingDiscHandle,
            PyLoad => PyLoadHandle,
        );
        if let Ok(g) = entity.extract::<PyGravity>() {
            m.add(g.0);
            return Ok(py.None());
        }
        if let Ok(p) = entity.extract::<PyPrescribedMotion>() {
            m.add(p.0);
            return Ok(py.None());
        }
        Err(PyTypeError::new_err(format!(
            "cannot add a {} to a model",
            entity.get_type().name()?
        )))
    }

    /// Adds a node at `x` (identity orientation), with the next free id
    /// unless `id` is given.
    #[pyo3(signature = (x, id=None))]
    fn node(&mut self, x: [f64; 3], id: Option<u32>) -> PyNodeHandle {
        PyNodeHandle(match id {
            Some(id) => self.inner.node_with_id(id as _, x),
            None => self.inner.node(x),
        })
    }

    /// Adds a node at `x` with the id `id`.
    fn node_with_id(&mut self, id: u32, x: [f64; 3]) -> PyNodeHandle {
        PyNodeHandle(self.inner.node_with_id(id as _, x))
    }

    /// Gives `node` the initial velocity `v` and angular velocity `w`.
    fn initial_velocity(&mut self, node: PyNodeHandle, v: [f64; 3], w: [f64; 3]) {
        self.inner.initial_velocity(node.0, v, w);
    }

    /// Gives `nodes` the rigid motion `v(x) = velocity + angular_velocity × (x − about)`.
    fn initial_motion(
        &mut self,
        nodes: Vec<PyNodeHandle>,
        velocity: [f64; 3],
        angular_velocity: [f64; 3],
        about: [f64; 3],
    ) {
        self.inner.initial_motion(
            nodes.into_iter().map(|n| n.0),
            velocity,
            angular_velocity,
            about,
        );
    }

    /// Adds a beam cross-section.
    fn section(&mut self, section: PySection) -> PySectionHandle {
        PySectionHandle(self.inner.section(section.0))
    }

    /// Adds a curve `f(t)`.
    fn curve(&mut self, curve: PyLoadCurve) -> PyCurveHandle {
        PyCurveHandle(self.inner.curve(curve.0))
    }

    /// Adds a beam element between two nodes.
    fn beam(&mut self, a: PyNodeHandle, b: PyNodeHandle, section: PySectionHandle) -> PyBeamHandle {
        PyBeamHandle(self.inner.beam(a.0, b.0, section.0))
    }

    /// Meshes the straight line between two nodes into `elements` beams.
    fn beam_line(
        &mut self,
        a: PyNodeHandle,
        b: PyNodeHandle,
        elements: usize,
        section: PySectionHandle,
    ) -> PyBeamLineHandle {
        PyBeamLineHandle(self.inner.beam_line(a.0, b.0, elements, section.0))
    }

    /// Fixes the components `dofs` of `node`: `Dofs.ALL`, `Component.Z`,
    /// `[Component.X, Component.Rz]`.
    fn fix(&mut self, node: PyNodeHandle, dofs: &Bound<'_, PyAny>) -> PyResult<()> {
        self.inner.fix(node.0, self::dofs(dofs)?);
        Ok(())
    }

    /// A uniform gravity field `g` following the default curve.
    fn gravity(&mut self, g: [f64; 3]) {
        self.inner.gravity(g);
    }

    /// Sets the analysis (the only one, replacing any sequence).
    fn analysis(&mut self, analysis: PyAnalysis) {
        self.inner.analysis(analysis.0);
    }

    /// Adds an analysis after the last one (a sequence).
    fn then(&mut self, analysis: PyAnalysis) {
        self.inner.then(analysis.0);
    }

    /// Validates the model and builds it: a `Model`, or a `ModelError`
    /// with every problem found, as for a model file.
    fn build(&self, py: Python<'_>) -> PyResult<PyModel> {
        PyModel::from_input(py, self.inner.input().clone(), None)
    }

    /// The model file (TOML) that `unfold run` reads.
    fn to_toml(&self) -> PyResult<String> {
        self.inner
            .to_toml()
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The model definition as a dictionary of the file schema
    /// (docs/model-format.md).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_dict(py, self.inner.input())
    }

    fn __repr__(&self) -> String {
        let i = self.inner.input();
        format!(
            "ModelBuilder({:?}: {} nodes, {} beams, {} beam lines, {} joints)",
            i.title.clone().unwrap_or_default(),
            i.nodes.len(),
            i.beams.len(),
            i.beam_lines.len(),
            i.joints.len()
        )
    }
}

/// `input` as a dictionary of the file schema.
pub fn to_dict<'py>(py: Python<'py>, input: &ModelInput) -> PyResult<Bound<'py, PyAny>> {
    pythonize::pythonize(py, input).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// A dictionary of the file schema as a model definition.
pub fn from_dict(py: Python<'_>, dict: &Bound<'_, PyDict>) -> PyResult<ModelInput> {
    pythonize::depythonize::<ModelInput>(dict.as_any()).map_err(|e| {
        errors::model_error(
            py,
            format!("the model dictionary does not follow the schema: {e}"),
            vec![("model".into(), e.to_string())],
        )
    })
}

/// Adds the classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAngleUnit>()?;
    m.add_class::<PyApproach>()?;
    m.add_class::<PyStartBranch>()?;
    m.add_class::<PyLatchSide>()?;
    m.add_class::<PyJointType>()?;
    m.add_class::<PyCoordinate>()?;
    m.add_class::<PyComponent>()?;
    m.add_class::<PyDofs>()?;
    m.add_class::<PyNodeHandle>()?;
    m.add_class::<PyBeamHandle>()?;
    m.add_class::<PyRigidBodyHandle>()?;
    m.add_class::<PyPointMassHandle>()?;
    m.add_class::<PySpringHandle>()?;
    m.add_class::<PyLoadHandle>()?;
    m.add_class::<PyJointHandle>()?;
    m.add_class::<PyJointSpringHandle>()?;
    m.add_class::<PyHingeLawHandle>()?;
    m.add_class::<PyDriverHandle>()?;
    m.add_class::<PyLatchHandle>()?;
    m.add_class::<PyStopHandle>()?;
    m.add_class::<PyContactHandle>()?;
    m.add_class::<PyRollingDiscHandle>()?;
    m.add_class::<PyBeamLineHandle>()?;
    m.add_class::<PySectionHandle>()?;
    m.add_class::<PyCurveHandle>()?;
    m.add_class::<PyGround>()?;
    m.add("Ground", PyGround)?;
    m.add_class::<PyNode>()?;
    m.add_class::<PySection>()?;
    m.add_class::<PyBeam>()?;
    m.add_class::<PyBeamLine>()?;
    m.add_class::<PyRigidBody>()?;
    m.add_class::<PyPointMass>()?;
    m.add_class::<PySpring>()?;
    m.add_class::<PyJoint>()?;
    m.add_class::<PyJointSpring>()?;
    m.add_class::<PyTapeSpring>()?;
    m.add_class::<PyHingeLaw>()?;
    m.add_class::<PyDriver>()?;
    m.add_class::<PyLatch>()?;
    m.add_class::<PyStop>()?;
    m.add_class::<PyContact>()?;
    m.add_class::<PyRollingDisc>()?;
    m.add_class::<PyLoadCurve>()?;
    m.add_class::<PyLoad>()?;
    m.add_class::<PyGravity>()?;
    m.add_class::<PyPrescribedMotion>()?;
    m.add_class::<PyAnalysis>()?;
    m.add_class::<PyModelBuilder>()?;
    Ok(())
}
