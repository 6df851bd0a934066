//! Analysis settings: what the `[analysis]` table (or each `[[analysis]]`
//! table of a sequence) of a model file asks for, validated, kept beside the
//! model rather than in it (docs/model-format.md, `[analysis]`). They are
//! read from a model input by [`crate::model::input::ModelInput::analyses`].

/// The settings of one analysis.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum AnalysisSettings {
    /// Nonlinear statics, kinetostatics or kinematics
    /// ([`super::StaticAnalysis`]).
    Static(StaticSettings),
    /// Implicit dynamics, Lie-group generalised-α
    /// ([`super::DynamicAnalysis`]).
    Dynamic(DynamicSettings),
    /// Natural frequencies and modes about the state reached
    /// ([`super::ModalAnalysis`]).
    Modal(ModalSettings),
}

impl AnalysisSettings {
    /// The end of the analysis (final value of `t`).
    pub fn end_time(&self) -> f64 {
        match self {
            Self::Static(s) => s.end_time,
            Self::Dynamic(s) => s.end_time,
            Self::Modal(s) => s.time,
        }
    }

    /// The analysis type as the model file names it (`static`,
    /// `kinematic`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Static(s) if s.kinematic => "kinematic",
            Self::Static(_) => "static",
            Self::Dynamic(_) => "dynamic",
            Self::Modal(_) => "modal",
        }
    }

    /// The settings of a static analysis, if it is one.
    pub fn as_static(&self) -> Option<&StaticSettings> {
        match self {
            Self::Static(s) => Some(s),
            _ => None,
        }
    }

    /// The settings of a modal analysis, if it is one.
    pub fn as_modal(&self) -> Option<&ModalSettings> {
        match self {
            Self::Modal(s) => Some(s),
            _ => None,
        }
    }

    /// The settings of a dynamic analysis, if it is one.
    pub fn as_dynamic(&self) -> Option<&DynamicSettings> {
        match self {
            Self::Dynamic(s) => Some(s),
            _ => None,
        }
    }
}

impl From<DynamicSettings> for AnalysisSettings {
    fn from(s: DynamicSettings) -> Self {
        Self::Dynamic(s)
    }
}

impl From<StaticSettings> for AnalysisSettings {
    fn from(s: StaticSettings) -> Self {
        Self::Static(s)
    }
}

/// Parameters of the nonlinear static analysis (see docs/model-format.md,
/// `[analysis]`, for the meaning and default of each).
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSettings {
    /// Final value of the load parameter.
    pub end_time: f64,
    /// First increment.
    pub initial_increment: f64,
    /// Smallest increment allowed after cut-backs.
    pub min_increment: f64,
    /// Largest increment allowed when increments grow again.
    pub max_increment: f64,
    /// Newton iterations per increment before a cut-back.
    pub max_iterations: usize,
    /// Residual tolerance, relative to the force flux.
    pub residual_tolerance: f64,
    /// Displacement increment tolerance, relative to the largest
    /// translation of the increment.
    pub displacement_tolerance: f64,
    /// Rotation increment tolerance (radians).
    pub rotation_tolerance: f64,
    /// Results are written every this many increments.
    pub output_every: usize,
    /// Values of `t` the analysis lands on and writes results at, in
    /// increasing order.
    pub output_times: Vec<f64>,
    /// Kinematic analysis: the joints and drivers must determine every
    /// unknown (docs/joints.md §6).
    pub kinematic: bool,
    /// Arc-length path control instead of load increments.
    pub arc_length: bool,
    /// Arc-length control: largest number of increments.
    pub max_increments: usize,
}

/// Parameters of the implicit dynamic analysis (docs/model-format.md,
/// `[analysis] type = "dynamic"`; docs/theory.md §15).
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicSettings {
    /// Final time.
    pub end_time: f64,
    /// First time step.
    pub time_step: f64,
    /// Smallest step before the analysis gives up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Spectral radius at infinite frequency `ρ∞ ∈ [0, 1]`: 1 keeps every
    /// frequency (no numerical dissipation), 0 damps the highest ones out
    /// in one step.
    pub rho_infinity: f64,
    /// Whether the step follows the local error estimate; fixed steps
    /// (only cut back when Newton fails) otherwise.
    pub adaptive: bool,
    /// Tolerance on the local error estimate, relative to the motion of
    /// the step (docs/theory.md §15.5).
    pub error_tolerance: f64,
    /// Newton iterations per step before the step is cut back.
    pub max_iterations: usize,
    /// Residual tolerance, relative to the force flux.
    pub residual_tolerance: f64,
    /// Correction tolerance, relative to the largest translation of the
    /// step.
    pub displacement_tolerance: f64,
    /// Rotation correction tolerance (radians).
    pub rotation_tolerance: f64,
    /// Results are written every this many steps.
    pub output_every: usize,
    /// Times the analysis lands on and writes results at, increasing.
    pub output_times: Vec<f64>,
}

impl DynamicSettings {
    /// Settings from 0 (or the start state's time) to `end_time` with
    /// steps of `time_step`, adaptive, and every other value at its
    /// default (docs/model-format.md): `min_step = time_step·1e-6`,
    /// `max_step = time_step·100` (at most the span), `ρ∞ = 0.9`, error
    /// tolerance 1e-4, 25 iterations, tolerances 1e-8 / 1e-6 / 1e-6,
    /// output every step.
    pub fn new(end_time: f64, time_step: f64) -> Self {
        Self {
            end_time,
            time_step,
            min_step: time_step * 1e-6,
            max_step: time_step * 100.0,
            rho_infinity: DEFAULT_RHO_INFINITY,
            adaptive: true,
            error_tolerance: DEFAULT_ERROR_TOLERANCE,
            max_iterations: 25,
            residual_tolerance: 1e-8,
            displacement_tolerance: 1e-6,
            rotation_tolerance: 1e-6,
            output_every: 1,
            output_times: Vec::new(),
        }
    }

    /// Fixed steps of `time_step` (cut back only when Newton fails).
    pub fn fixed_step(mut self) -> Self {
        self.adaptive = false;
        self.max_step = self.time_step;
        self
    }

    /// With spectral radius `rho` at infinite frequency.
    pub fn rho_infinity(mut self, rho: f64) -> Self {
        self.rho_infinity = rho;
        self
    }

    /// With relative local error tolerance `tol`.
    pub fn error_tolerance(mut self, tol: f64) -> Self {
        self.error_tolerance = tol;
        self
    }
}

/// Default `ρ∞`: 0.9 damps the spurious high frequencies of stiff members
/// and of the index-3 constraints within tens of steps while the
/// frequencies resolved by the step lose less than 1e-3 of their amplitude
/// per period (Brüls, Cardona & Arnold 2012, §5).
pub const DEFAULT_RHO_INFINITY: f64 = 0.9;

/// Default relative local error tolerance: a step's error estimate at most
/// 1e-4 of its motion, i.e. about four significant digits over a
/// swing; tighten it for validation runs.
pub const DEFAULT_ERROR_TOLERANCE: f64 = 1e-4;

/// Parameters of a modal analysis (docs/model-format.md, `[analysis]` with
/// `type = "modal"`).
#[derive(Clone, Debug, PartialEq)]
pub struct ModalSettings {
    /// Number of modes wanted (zero modes included).
    pub modes: usize,
    /// Frequency (Hz) near which the modes are sought; `None` for the
    /// lowest modes.
    pub shift: Option<f64>,
    /// Only the modes with frequencies in `[low, high]` (Hz), at most
    /// `modes` of them, the lowest.
    pub frequency_range: Option<(f64, f64)>,
    /// Eigen-solver: dense, Lanczos, or chosen by size.
    pub solver: crate::eigen::Method,
    /// `t` at which it runs: the end of the analysis before it (0 for a
    /// first analysis). A modal analysis does not move `t`.
    pub time: f64,
}

impl ModalSettings {
    /// The `modes` lowest modes, solver chosen by size, at `t = 0`.
    pub fn lowest(modes: usize) -> Self {
        Self {
            modes,
            shift: None,
            frequency_range: None,
            solver: crate::eigen::Method::Auto,
            time: 0.0,
        }
    }
}
