//! Curves, loads, gravity, supports, prescribed motions and the analysis.

use std::ops::BitOr;

use super::{Entity, ModelBuilder};
use crate::curves::Curve;
use crate::model::handles::{LoadHandle, NodeHandle};
use crate::model::input::{
    AnalysisInput, AngleUnit, CurveInput, GravityInput, LoadInput, PrescribedInput,
};
use crate::model::{Id, COMPONENT_NAMES};

/// A curve `f(t)` of the load parameter, which loads, gravity, prescribed
/// motions, drivers and initial strains follow.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadCurve {
    input: CurveInput,
}

/// A curve of the model: one added, or a built-in one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CurveHandle(CurveRef);

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum CurveRef {
    Ramp,
    Constant,
    Added(usize),
}

impl CurveHandle {
    /// The built-in ramp `f(t) = t`.
    pub const RAMP: Self = Self(CurveRef::Ramp);
    /// The built-in constant `f(t) = 1`.
    pub const CONSTANT: Self = Self(CurveRef::Constant);
}

impl LoadCurve {
    fn function(name: &str) -> Self {
        Self {
            input: CurveInput {
                function: Some(name.into()),
                ..CurveInput::default()
            },
        }
    }

    /// Piecewise linear through the points `[t, f]` (strictly increasing
    /// `t`), constant beyond the first and the last.
    pub fn points(points: impl Into<Vec<[f64; 2]>>) -> Self {
        Self {
            input: CurveInput {
                points: points.into(),
                ..CurveInput::default()
            },
        }
    }

    /// `offset + slope·t`.
    pub fn linear(offset: f64, slope: f64) -> Self {
        let mut c = Self::function("linear");
        c.input.offset = Some(offset);
        c.input.slope = Some(slope);
        c
    }

    /// `offset + amplitude·sin(2π·frequency·t + phase)`.
    pub fn sine(offset: f64, amplitude: f64, frequency: f64, phase: f64) -> Self {
        let mut c = Self::function("sine");
        c.input.offset = Some(offset);
        c.input.amplitude = Some(amplitude);
        c.input.frequency = Some(frequency);
        c.input.phase = Some(phase);
        c
    }

    /// From 0 at `t = start` to 1 at `t = end`, with zero rate and
    /// acceleration at both ends (see [`LoadCurve::between`] for other
    /// values).
    pub fn smooth_step(start: f64, end: f64) -> Self {
        let mut c = Self::function("smooth_step");
        c.input.start = Some(start);
        c.input.end = Some(end);
        c
    }

    /// A smooth step going from `from` to `to` instead of 0 to 1.
    pub fn between(mut self, from: f64, to: f64) -> Self {
        self.input.from = Some(from);
        self.input.to = Some(to);
        self
    }

    /// Its name in the model file (default `curve_N`, N its position).
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.input.name = name.into();
        self
    }
}

impl Entity for LoadCurve {
    type Handle = CurveHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> CurveHandle {
        let k = m.input.curves.len();
        if self.input.name.is_empty() {
            self.input.name = format!("curve_{}", k + 1);
        }
        m.input.curves.push(self.input);
        CurveHandle(CurveRef::Added(k))
    }
}

impl ModelBuilder {
    /// The name of a curve in the model file.
    pub(super) fn curve_name(&self, c: CurveHandle) -> String {
        match c.0 {
            CurveRef::Ramp => Curve::RAMP.into(),
            CurveRef::Constant => Curve::CONSTANT.into(),
            CurveRef::Added(k) => self.input.curves[k].name.clone(),
        }
    }
}

/// One component of a node's motion: a translation along a global axis
/// or an incremental rotation about a material axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Component {
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

impl Component {
    /// Position among a node's six unknowns.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Name in model files (`x`, …, `rz`).
    pub fn name(self) -> &'static str {
        COMPONENT_NAMES[self.index()]
    }
}

/// A set of components of a node.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Dofs(u8);

impl Dofs {
    /// No component.
    pub const NONE: Self = Self(0);
    /// The three translations.
    pub const TRANSLATIONS: Self = Self(0b000111);
    /// The three rotations.
    pub const ROTATIONS: Self = Self(0b111000);
    /// All six components.
    pub const ALL: Self = Self(0b111111);

    /// Whether `c` is in the set.
    pub fn contains(self, c: Component) -> bool {
        self.0 & (1 << c.index()) != 0
    }

    /// The names of the model file: the groups `all`, `translations`,
    /// `rotations` where they apply, the single components otherwise.
    pub(super) fn names(self) -> Vec<String> {
        if self == Self::ALL {
            return vec!["all".into()];
        }
        let mut names = Vec::new();
        for (group, name, range) in [
            (Self::TRANSLATIONS, "translations", 0..3),
            (Self::ROTATIONS, "rotations", 3..6),
        ] {
            if self.0 & group.0 == group.0 {
                names.push(name.to_string());
            } else {
                names.extend(
                    range
                        .filter(|&i| self.0 & (1 << i) != 0)
                        .map(|i| COMPONENT_NAMES[i].to_string()),
                );
            }
        }
        names
    }
}

impl From<Component> for Dofs {
    fn from(c: Component) -> Self {
        Self(1 << c.index())
    }
}

impl<const N: usize> From<[Component; N]> for Dofs {
    fn from(cs: [Component; N]) -> Self {
        cs.into_iter().fold(Self::NONE, |d, c| d | c)
    }
}

impl From<&[Component]> for Dofs {
    fn from(cs: &[Component]) -> Self {
        cs.iter().fold(Self::NONE, |d, &c| d | c)
    }
}

impl<T: Into<Dofs>> BitOr<T> for Dofs {
    type Output = Dofs;
    fn bitor(self, other: T) -> Dofs {
        Dofs(self.0 | other.into().0)
    }
}

impl BitOr for Component {
    type Output = Dofs;
    fn bitor(self, other: Component) -> Dofs {
        Dofs::from(self) | other
    }
}

/// A nodal force and moment following a curve: dead (fixed global
/// direction) unless [`Load::follower`].
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    input: LoadInput,
    curve: Option<CurveHandle>,
}

impl Load {
    fn new(node: NodeHandle, force: Option<[f64; 3]>, moment: Option<[f64; 3]>) -> Self {
        Self {
            input: LoadInput {
                node: node.0,
                force,
                moment,
                follower: false,
                curve: None,
            },
            curve: None,
        }
    }

    /// A force on `node`, reached when the curve equals 1.
    pub fn force(node: NodeHandle, force: impl Into<[f64; 3]>) -> Self {
        Self::new(node, Some(force.into()), None)
    }

    /// A moment on `node`, reached when the curve equals 1.
    pub fn moment(node: NodeHandle, moment: impl Into<[f64; 3]>) -> Self {
        Self::new(node, None, Some(moment.into()))
    }

    /// A force and a moment on `node`.
    pub fn force_and_moment(
        node: NodeHandle,
        force: impl Into<[f64; 3]>,
        moment: impl Into<[f64; 3]>,
    ) -> Self {
        Self::new(node, Some(force.into()), Some(moment.into()))
    }

    /// Components in the node's material frame, turning with it.
    pub fn follower(mut self) -> Self {
        self.input.follower = true;
        self
    }

    /// The curve it follows (default: the ramp in statics, the constant in
    /// a kinematic analysis).
    pub fn curve(mut self, curve: CurveHandle) -> Self {
        self.curve = Some(curve);
        self
    }
}

impl Entity for Load {
    type Handle = LoadHandle;
    fn add_to(mut self, m: &mut ModelBuilder) -> LoadHandle {
        self.input.curve = self.curve.map(|c| m.curve_name(c));
        m.input.loads.push(self.input);
        LoadHandle(m.input.loads.len() as Id)
    }
}

/// A uniform gravity field acting on every mass.
#[derive(Clone, Debug, PartialEq)]
pub struct Gravity {
    acceleration: [f64; 3],
    curve: Option<CurveHandle>,
}

impl Gravity {
    /// The acceleration of gravity `g`, reached when the curve equals 1.
    pub fn of(g: impl Into<[f64; 3]>) -> Self {
        Self {
            acceleration: g.into(),
            curve: None,
        }
    }

    /// The curve it follows (default: the ramp in statics, the constant in
    /// a kinematic analysis).
    pub fn curve(mut self, curve: CurveHandle) -> Self {
        self.curve = Some(curve);
        self
    }
}

impl Entity for Gravity {
    type Handle = ();
    fn add_to(self, m: &mut ModelBuilder) {
        m.input.gravity = Some(GravityInput {
            acceleration: self.acceleration,
            curve: self.curve.map(|c| m.curve_name(c)),
        });
    }
}

/// A prescribed motion of a node, relative to its reference
/// configuration: one translation, or the whole rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct PrescribedMotion {
    input: PrescribedInput,
    curve: Option<CurveHandle>,
}

impl PrescribedMotion {
    /// The translation `component` (`X`, `Y` or `Z`) of `node`, reaching
    /// `value` when the curve equals 1.
    pub fn translation(node: NodeHandle, component: Component, value: f64) -> Self {
        Self {
            input: PrescribedInput {
                node: node.0,
                dof: Some(component.name().into()),
                value: Some(value),
                rotation: None,
                unit: None,
                curve: None,
            },
            curve: None,
        }
    }

    /// The rotation of `node`, `R(t) = exp(f(t) ψ~) R₀` with `ψ` in the
    /// global frame (radians unless [`PrescribedMotion::unit`]).
    pub fn rotation(node: NodeHandle, psi: impl Into<[f64; 3]>) -> Self {
        Self {
            input: PrescribedInput {
                node: node.0,
                dof: None,
                value: None,
                rotation: Some(psi.into()),
                unit: None,
                curve: None,
            },
            curve: None,
        }
    }

    /// The unit of the rotation.
    pub fn unit(mut self, unit: AngleUnit) -> Self {
        self.input.unit = Some(unit);
        self
    }

    /// The curve it follows (default: the ramp).
    pub fn curve(mut self, curve: CurveHandle) -> Self {
        self.curve = Some(curve);
        self
    }
}

impl Entity for PrescribedMotion {
    type Handle = ();
    fn add_to(mut self, m: &mut ModelBuilder) {
        self.input.curve = self.curve.map(|c| m.curve_name(c));
        m.input.prescribed.push(self.input);
    }
}

/// The analysis and its parameters (docs/model-format.md, `[analysis]`);
/// each left unset takes its default.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis(AnalysisInput);

impl Analysis {
    fn of_type(kind: &str) -> Self {
        Self(AnalysisInput {
            kind: kind.into(),
            ..AnalysisInput::default()
        })
    }

    /// Nonlinear statics: loads and drivers follow the load parameter `t`
    /// from 0 to `end_time`.
    pub fn statics() -> Self {
        Self::of_type("static")
    }

    /// Nonlinear statics of a mechanism moved by its drivers (the same
    /// analysis as [`Analysis::statics`], named for what it does).
    pub fn kinetostatic() -> Self {
        Self::of_type("kinetostatic")
    }

    /// Kinematic analysis: the joints and drivers determine every unknown.
    pub fn kinematic() -> Self {
        Self::of_type("kinematic")
    }

    /// Implicit dynamics (Lie-group generalised-α, docs/theory.md §15)
    /// from the state reached to `end_time`; a model whose analyses are
    /// all dynamic or modal may have parts free to move as rigid bodies.
    pub fn dynamic() -> Self {
        Self::of_type("dynamic")
    }

    /// Dynamics: the first time step (default a hundredth of the span).
    pub fn time_step(mut self, h: f64) -> Self {
        self.0.time_step = Some(h);
        self
    }

    /// Dynamics: the spectral radius at infinite frequency `ρ∞ ∈ [0, 1]`
    /// (default 0.9).
    pub fn rho_infinity(mut self, rho: f64) -> Self {
        self.0.rho_infinity = Some(rho);
        self
    }

    /// Dynamics: fixed steps of `time_step` instead of steps sized by the
    /// error estimate.
    pub fn fixed_step(mut self) -> Self {
        self.0.adaptive = Some(false);
        self
    }

    /// Dynamics: the smallest time step (default `time_step · 1e-6`).
    pub fn min_step(mut self, h: f64) -> Self {
        self.0.min_step = Some(h);
        self
    }

    /// Dynamics: the largest time step (default a tenth of the span, or
    /// `time_step` with fixed steps).
    pub fn max_step(mut self, h: f64) -> Self {
        self.0.max_step = Some(h);
        self
    }

    /// Dynamics: the relative tolerance of the local error estimate
    /// (default 1e-4).
    pub fn error_tolerance(mut self, tolerance: f64) -> Self {
        self.0.error_tolerance = Some(tolerance);
        self
    }

    /// Dynamics: the Newton method, `full` (default: the iteration matrix
    /// factored at every iteration) or `modified` (its factors kept while
    /// they serve).
    pub fn newton(mut self, method: &str) -> Self {
        self.0.newton = Some(method.into());
        self
    }

    /// Dynamics: the frame of the angular velocities in the time scheme,
    /// `material` (default) or `spatial` (docs/theory.md §15.9).
    pub fn angular_velocities(mut self, frame: &str) -> Self {
        self.0.angular_velocities = Some(frame.into());
        self
    }

    /// Modal analysis: the `modes` lowest natural modes about the state
    /// reached (docs/theory.md §14.7).
    pub fn modal(modes: usize) -> Self {
        let mut a = Self::of_type("modal");
        a.0.modes = Some(modes);
        a
    }

    /// Modal analysis: the modes nearest to this frequency (Hz).
    pub fn shift(mut self, frequency: f64) -> Self {
        self.0.shift = Some(frequency);
        self
    }

    /// Modal analysis: only the modes with frequencies in `[low, high]`
    /// (Hz).
    pub fn frequency_range(mut self, low: f64, high: f64) -> Self {
        self.0.frequency_range = Some([low, high]);
        self
    }

    /// Modal analysis: the eigen-solver, `auto`, `dense` or `lanczos`.
    pub fn solver(mut self, solver: &str) -> Self {
        self.0.solver = Some(solver.into());
        self
    }

    /// Final value of the load parameter (default 1).
    pub fn end_time(mut self, t: f64) -> Self {
        self.0.end_time = t;
        self
    }

    /// First increment of `t` (default `end_time / 10`).
    pub fn initial_increment(mut self, h: f64) -> Self {
        self.0.initial_increment = Some(h);
        self
    }

    /// Smallest increment before the analysis gives up (default
    /// `end_time · 1e-6`).
    pub fn min_increment(mut self, h: f64) -> Self {
        self.0.min_increment = Some(h);
        self
    }

    /// Largest increment (default the initial one).
    pub fn max_increment(mut self, h: f64) -> Self {
        self.0.max_increment = Some(h);
        self
    }

    /// Newton iterations per increment before a cut-back (default 25).
    pub fn max_iterations(mut self, n: usize) -> Self {
        self.0.max_iterations = Some(n);
        self
    }

    /// Residual tolerance relative to the force flux (default 1e-8).
    pub fn residual_tolerance(mut self, tolerance: f64) -> Self {
        self.0.residual_tolerance = Some(tolerance);
        self
    }

    /// Displacement correction tolerance relative to the model size
    /// (default 1e-6).
    pub fn displacement_tolerance(mut self, tolerance: f64) -> Self {
        self.0.displacement_tolerance = Some(tolerance);
        self
    }

    /// Rotation correction tolerance in radians (default 1e-6).
    pub fn rotation_tolerance(mut self, tolerance: f64) -> Self {
        self.0.rotation_tolerance = Some(tolerance);
        self
    }

    /// Results written every `n` increments (default 1).
    pub fn output_every(mut self, n: usize) -> Self {
        self.0.output_every = Some(n);
        self
    }

    /// Values of `t` the analysis lands on exactly and writes results at.
    pub fn output_times(mut self, times: impl Into<Vec<f64>>) -> Self {
        self.0.output_times = Some(times.into());
        self
    }

    /// Dynamics: results written every `interval` of time from the start
    /// of the analysis, the steps landing on those times.
    pub fn output_interval(mut self, interval: f64) -> Self {
        self.0.output_interval = Some(interval);
        self
    }

    /// Scaling factor `k` of the constraint equations (default from the
    /// model's stiffness).
    pub fn constraint_scale(mut self, k: f64) -> Self {
        self.0.constraint_scale = Some(k);
        self
    }

    /// Penalty `p` of the constraint equations (default as `k`).
    pub fn constraint_penalty(mut self, p: f64) -> Self {
        self.0.constraint_penalty = Some(p);
        self
    }

    /// Arc-length path control through limit points, with at most
    /// `max_increments` increments.
    pub fn arc_length(mut self, max_increments: usize) -> Self {
        self.0.control = Some("arc_length".into());
        self.0.max_increments = Some(max_increments);
        self
    }

    /// The `[analysis]` table of the model file.
    pub fn into_input(self) -> AnalysisInput {
        self.0
    }

    /// The settings of this analysis alone (from `t = 0`), validated as in
    /// a model file.
    pub fn settings(self) -> Result<crate::analysis::StaticSettings, crate::model::ModelErrors> {
        match self.analysis_settings()? {
            crate::analysis::AnalysisSettings::Static(s) => Ok(s),
            other => Err(crate::model::ModelErrors(vec![crate::model::ModelError {
                kind: crate::model::ModelErrorKind::Invalid,
                entity: "analysis".into(),
                message: format!(
                    "a {} analysis has no static settings: use analysis_settings",
                    other.name()
                ),
            }])),
        }
    }

    /// The settings of this analysis alone (from `t = 0`), of whatever
    /// type, validated as in a model file.
    pub fn analysis_settings(
        self,
    ) -> Result<crate::analysis::AnalysisSettings, crate::model::ModelErrors> {
        let input = crate::model::input::ModelInput {
            analysis: self.0.into(),
            ..crate::model::input::ModelInput::default()
        };
        let mut all = input.analyses()?;
        Ok(all.remove(0))
    }
}
