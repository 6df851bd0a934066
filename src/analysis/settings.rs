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
}

impl AnalysisSettings {
    /// The end of the analysis (final value of `t`).
    pub fn end_time(&self) -> f64 {
        match self {
            Self::Static(s) => s.end_time,
        }
    }

    /// The analysis type as the model file names it (`static`,
    /// `kinematic`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Static(s) if s.kinematic => "kinematic",
            Self::Static(_) => "static",
        }
    }

    /// The settings of a static analysis, if it is one.
    pub fn as_static(&self) -> Option<&StaticSettings> {
        match self {
            Self::Static(s) => Some(s),
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
