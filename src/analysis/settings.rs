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
    /// Natural frequencies and modes about the state reached
    /// ([`super::ModalAnalysis`]).
    Modal(ModalSettings),
}

impl AnalysisSettings {
    /// The end of the analysis (final value of `t`).
    pub fn end_time(&self) -> f64 {
        match self {
            Self::Static(s) => s.end_time,
            Self::Modal(s) => s.time,
        }
    }

    /// The analysis type as the model file names it (`static`,
    /// `kinematic`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Static(s) if s.kinematic => "kinematic",
            Self::Static(_) => "static",
            Self::Modal(_) => "modal",
        }
    }

    /// The settings of a static analysis, if it is one.
    pub fn as_static(&self) -> Option<&StaticSettings> {
        match self {
            Self::Static(s) => Some(s),
            Self::Modal(_) => None,
        }
    }

    /// The settings of a modal analysis, if it is one.
    pub fn as_modal(&self) -> Option<&ModalSettings> {
        match self {
            Self::Modal(s) => Some(s),
            _ => None,
        }
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
