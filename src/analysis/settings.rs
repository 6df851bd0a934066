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
    /// `kinetostatic`, `kinematic`, `dynamic`, `modal`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Static(s) if s.kinematic => "kinematic",
            Self::Static(s) if s.kinetostatic => "kinetostatic",
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
    /// Named a kinetostatic analysis in the model file (the same solution
    /// as a static one: quasi-static, displacement controlled); only its
    /// name in the log and the result files differs.
    pub kinetostatic: bool,
    /// Arc-length path control instead of load increments.
    pub arc_length: bool,
    /// Arc-length control: largest number of increments.
    pub max_increments: usize,
}

/// Parameters of the implicit dynamic analysis (docs/model-format.md,
/// `[analysis] type = "dynamic"`; docs/theory.md §15).
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicSettings {
    /// Start of the analysis (0 for the first of a model; the end of the
    /// one before in a sequence): a run restarted within the analysis
    /// takes the span of the analysis from it, as the run never stopped
    /// did.
    pub start_time: f64,
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
    /// Whether Newton factors the iteration matrix at every iteration or
    /// keeps its factors while they serve (docs/theory.md §15.1).
    pub newton: NewtonMethod,
    /// The frame of the angular velocities in the scheme's recurrences.
    pub angular_velocities: AngularVelocities,
    /// Results are written every this many steps.
    pub output_every: usize,
    /// Times the analysis lands on and writes results at, increasing.
    pub output_times: Vec<f64>,
    /// The interval of the grid of output times set by
    /// [`DynamicSettings::with_output_interval`] (its times are among
    /// `output_times`), for reports.
    pub output_interval: Option<f64>,
}

impl DynamicSettings {
    /// Settings from 0 to `end_time` with steps of `time_step`, adaptive,
    /// and every other value at its default, as a model file gives them
    /// (docs/model-format.md): `min_step = time_step·1e-6`,
    /// `max_step` = a tenth of the span (here `end_time`, the span from
    /// 0), or `time_step` if larger ([`default_max_step`]), `ρ∞ = 0.9`,
    /// error tolerance 1e-4, 25 iterations, tolerances 1e-8 / 1e-6 /
    /// 1e-6, output every step. An analysis that starts later than 0 sets
    /// `max_step` from its own span.
    pub fn new(end_time: f64, time_step: f64) -> Self {
        Self {
            start_time: 0.0,
            end_time,
            time_step,
            min_step: time_step * 1e-6,
            max_step: default_max_step(end_time, time_step),
            rho_infinity: DEFAULT_RHO_INFINITY,
            adaptive: true,
            error_tolerance: DEFAULT_ERROR_TOLERANCE,
            max_iterations: 25,
            residual_tolerance: 1e-8,
            displacement_tolerance: 1e-6,
            rotation_tolerance: 1e-6,
            newton: NewtonMethod::default(),
            angular_velocities: AngularVelocities::default(),
            output_every: 1,
            output_times: Vec::new(),
            output_interval: None,
        }
    }

    /// Results at `start + k·interval` (`k = 1, 2, …` up to `end_time`),
    /// the steps landing on them, besides the `output_times` already given
    /// (a grid time nearer than `apart` to one of them or to `end_time`
    /// is left out: the steps could not land on both), and at the events
    /// and `end_time`; no longer every `output_every` steps. `start` is the
    /// start of the analysis (the grid is the same when a run restarts
    /// within it).
    pub fn with_output_interval(mut self, start: f64, interval: f64, apart: f64) -> Self {
        let mut times = self.output_times.clone();
        let mut k = 1.0;
        loop {
            let t = start + k * interval;
            if t > self.end_time - apart {
                break;
            }
            if self.output_times.iter().all(|&o| (o - t).abs() >= apart) {
                times.push(t);
            }
            k += 1.0;
        }
        times.sort_by(f64::total_cmp);
        self.output_times = times;
        self.output_interval = Some(interval);
        self.output_every = usize::MAX;
        self
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

/// How the dynamic analysis's Newton iterations use the iteration matrix
/// `S` (docs/theory.md §15.1, model files' `[analysis] newton`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NewtonMethod {
    /// `S` assembled and factored at every iteration: quadratic
    /// convergence, one factorisation per iteration.
    #[default]
    Full,
    /// The factors of `S` kept across iterations and steps while the step
    /// size, the scaling and the numbering are those they were made for and
    /// each iteration reduces the residual enough; the residual is still
    /// the true one, checked with the same tolerances.
    Modified,
}

/// In which frame the generalised-α recurrences of the dynamic analysis
/// carry the nodes' angular velocities and accelerations (docs/theory.md
/// §15.9, model files' `[analysis] angular_velocities`). The elements see
/// material angular velocities either way; the two schemes differ only in
/// how a step combines the rates of its two ends.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AngularVelocities {
    /// Material (body-frame) `Ω`, `R_{n+1} = R_n exp(hΔΘ~)`: the scheme
    /// of the reference paper.
    #[default]
    Material,
    /// Spatial `ω = RΩ` (right-trivialised): the rates of step `n` are
    /// combined in the frame of `R_n` and turned into that of `R_{n+1}`.
    /// About four times smaller error constant on a fast-spinning rigid
    /// body (the heavy top); its iteration matrix has a gyroscopic term
    /// more.
    Spatial,
}

impl AngularVelocities {
    /// The name used in model files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Material => "material",
            Self::Spatial => "spatial",
        }
    }
}

impl NewtonMethod {
    /// The name used in model files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Modified => "modified",
        }
    }
}

/// Default largest step of an adaptive dynamic analysis over `span` whose
/// first step is `time_step`: a tenth of the span, so that the error
/// estimate sees the motion at least ten times, or `time_step` if that is
/// larger (a first step the user asked for is never above the largest).
pub fn default_max_step(span: f64, time_step: f64) -> f64 {
    (span / 10.0).max(time_step)
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
