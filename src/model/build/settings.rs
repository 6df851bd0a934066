//! `[analysis]` or `[[analysis]]`: the settings of the analysis, or of
//! each analysis of a sequence, with their defaults and limits.

use super::{
    num, Checker, LARGEST_ELEMENT_VALUE, MAX_INCREMENTS, MAX_ITERATIONS, MIN_RELATIVE_INCREMENT,
};
use crate::analysis::control::LANDING_SNAP;
use crate::analysis::settings::{default_max_step, DEFAULT_ERROR_TOLERANCE, DEFAULT_RHO_INFINITY};
use crate::analysis::{
    AnalysisSettings, AngularVelocities, DynamicSettings, ModalSettings, NewtonMethod,
    StaticSettings,
};
use crate::eigen::Method;
use crate::model::input::{Analyses, AnalysisInput, ModelInput};
use crate::model::{ModelErrorKind, ModelErrors};

impl ModelInput {
    /// The settings of the analyses the model asks for, in order, validated
    /// (the same checks and messages as [`crate::model::Model::from_input`],
    /// which reports them with the rest of the model).
    pub fn analyses(&self) -> Result<Vec<AnalysisSettings>, ModelErrors> {
        let mut ck = Checker::default();
        let mut all = analyses(&mut ck, &self.analysis);
        // the analyses land on the restart times: they join the output
        // times of the analysis they fall in
        if let Some(o) = &self.output {
            let mut start = 0.0;
            // (a modal analysis has no increments: it neither moves `t`
            // nor writes restart files)
            for (end, times) in all.iter_mut().filter_map(|a| match a {
                AnalysisSettings::Static(s) => Some((s.end_time, &mut s.output_times)),
                AnalysisSettings::Dynamic(s) => Some((s.end_time, &mut s.output_times)),
                _ => None,
            }) {
                let within = o.restart_times.iter().filter(|&&t| t > start && t <= end);
                times.extend(within);
                times.sort_by(f64::total_cmp);
                times.dedup();
                start = end;
            }
        }
        if ck.errors.is_empty() {
            Ok(all)
        } else {
            Err(ModelErrors(ck.errors))
        }
    }
}

/// What the model's own checks and defaults take from its analyses: the
/// type of the first (the default curve of loads), whether any uses arc
/// length, the end of the last and the largest load increment.
#[derive(Clone, Debug)]
pub(super) struct Plan {
    /// The first analysis is kinematic.
    pub kinematic: bool,
    /// Some analysis uses arc-length control.
    pub arc_length: bool,
    /// End of the last analysis.
    pub end_time: f64,
    /// Largest `max_increment` of the load-controlled analyses.
    pub max_increment: Option<f64>,
    /// No analysis seeks a static equilibrium (dynamic and modal analyses
    /// only): parts free to move as rigid bodies are allowed (their inertia
    /// holds them; a modal analysis reports their rigid-body modes).
    pub no_statics: bool,
    /// The first analysis is dynamic (loads and gravity act in full from
    /// the start by default).
    pub first_dynamic: bool,
    /// The first dynamic analysis after a static one (a preload, then the
    /// motion): its entity (`analysis[2]`), start and end. Loads and
    /// gravity without a curve follow the ramp through it.
    pub dynamic_after_static: Option<(String, f64, f64)>,
}

impl Plan {
    pub(super) fn of(settings: &[AnalysisSettings]) -> Self {
        let statics = || settings.iter().filter_map(AnalysisSettings::as_static);
        let load = statics().filter(|s| !s.arc_length);
        Self {
            kinematic: settings
                .first()
                .and_then(AnalysisSettings::as_static)
                .is_some_and(|s| s.kinematic),
            arc_length: statics().any(|s| s.arc_length),
            end_time: settings.last().map_or(1.0, |s| s.end_time()),
            max_increment: load.map(|s| s.max_increment).reduce(f64::max),
            no_statics: statics().next().is_none(),
            first_dynamic: settings.first().is_some_and(|s| s.as_dynamic().is_some()),
            dynamic_after_static: settings
                .iter()
                .enumerate()
                .skip(1)
                .find_map(|(k, s)| s.as_dynamic().map(|d| (k, d)))
                .filter(|_| settings.first().is_some_and(|s| s.as_static().is_some()))
                .map(|(k, d)| (format!("analysis[{}]", k + 1), d.start_time, d.end_time)),
        }
    }
}

/// Settings of every analysis of `analyses`, with defaults
/// (docs/model-format.md). Each analysis of a sequence starts where the one
/// before ends; the entities of messages are `analysis`, or
/// `analysis[k]` (from 1) in a sequence.
pub(super) fn analyses(ck: &mut Checker, analyses: &Analyses) -> Vec<AnalysisSettings> {
    let all = analyses.all();
    let mut start = 0.0;
    let mut out = Vec::with_capacity(all.len());
    for (k, a) in all.iter().enumerate() {
        let entity = if all.len() == 1 {
            "analysis".to_string()
        } else {
            format!("analysis[{}]", k + 1)
        };
        if k > 0 {
            if a.kind != "modal" && a.end_time.is_finite() && a.end_time <= start {
                ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!(
                        "end_time must be after the end of the analysis before it (t = {}), got {}",
                        num(start),
                        num(a.end_time)
                    ),
                );
            }
            for (name, v) in [
                ("constraint_scale", a.constraint_scale),
                ("constraint_penalty", a.constraint_penalty),
            ] {
                if v.is_some() {
                    ck.push(
                        ModelErrorKind::Invalid,
                        &entity,
                        format!("{name} belongs to the model and applies to every analysis: give it in the first one"),
                    );
                }
            }
        }
        if a.kind == "modal" {
            // a modal analysis does not move t
            out.push(AnalysisSettings::Modal(modal_settings(
                ck, &entity, a, start,
            )));
            continue;
        }
        for (name, given) in [
            ("modes", a.modes.is_some()),
            ("shift", a.shift.is_some()),
            ("frequency_range", a.frequency_range.is_some()),
            ("solver", a.solver.is_some()),
        ] {
            if given {
                ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("{name} applies to a modal analysis (type = \"modal\")"),
                );
            }
        }
        let s = if a.kind == "dynamic" {
            AnalysisSettings::Dynamic(dynamic_settings(ck, &entity, a, start))
        } else {
            // keys of dynamic analyses in a static one (an unknown type
            // is reported by `settings` alone: a typo such as "dynamics"
            // would otherwise first be told to take the static keys)
            let known = matches!(a.kind.as_str(), "static" | "kinetostatic" | "kinematic");
            for (key, given) in dynamic_keys(a) {
                if given && known {
                    ck.push(
                        ModelErrorKind::Invalid,
                        &entity,
                        format!("{key} belongs to dynamic analyses (type = \"dynamic\"); a {} analysis takes initial_increment, min_increment and max_increment", a.kind),
                    );
                }
            }
            AnalysisSettings::Static(settings(ck, &entity, a, start))
        };
        start = s.end_time();
        out.push(s);
    }
    out
}

/// The keys that only dynamic analyses take, and whether each is given.
fn dynamic_keys(a: &AnalysisInput) -> [(&'static str, bool); 9] {
    [
        ("output_interval", a.output_interval.is_some()),
        ("time_step", a.time_step.is_some()),
        ("min_step", a.min_step.is_some()),
        ("max_step", a.max_step.is_some()),
        ("rho_infinity", a.rho_infinity.is_some()),
        ("error_tolerance", a.error_tolerance.is_some()),
        ("adaptive", a.adaptive.is_some()),
        ("newton", a.newton.is_some()),
        ("angular_velocities", a.angular_velocities.is_some()),
    ]
}

/// Largest number of modes a modal analysis may ask for: beyond it the
/// dense solver's O(n³) and Lanczos's basis of 2·modes vectors of the
/// model's size make the request a mistake rather than an analysis.
const MAX_MODES: usize = 10_000;

/// Settings of a modal analysis at `t = start`, with defaults.
fn modal_settings(ck: &mut Checker, entity: &str, a: &AnalysisInput, start: f64) -> ModalSettings {
    // the keys of incremental analyses do not apply
    for (name, given) in [
        ("initial_increment", a.initial_increment.is_some()),
        ("min_increment", a.min_increment.is_some()),
        ("max_increment", a.max_increment.is_some()),
        ("max_iterations", a.max_iterations.is_some()),
        ("residual_tolerance", a.residual_tolerance.is_some()),
        ("displacement_tolerance", a.displacement_tolerance.is_some()),
        ("rotation_tolerance", a.rotation_tolerance.is_some()),
        ("output_every", a.output_every.is_some()),
        ("output_times", a.output_times.is_some()),
        ("control", a.control.is_some()),
        ("max_increments", a.max_increments.is_some()),
    ]
    .into_iter()
    .chain(dynamic_keys(a))
    {
        if given {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("{name} does not apply to a modal analysis (it linearises about the state reached and does not move t)"),
            );
        }
    }
    let modes = a.modes.unwrap_or(10);
    if modes == 0 || modes > MAX_MODES {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("modes must be from 1 to {MAX_MODES}, got {modes}"),
        );
    }
    if let Some(f) = a.shift {
        if !(f.is_finite() && f >= 0.0) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "shift must be a frequency in Hz, zero or positive, got {}",
                    num(f)
                ),
            );
        }
    }
    if let Some([lo, hi]) = a.frequency_range {
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "frequency_range must be [low, high] in Hz with 0 ≤ low < high, got [{}, {}]",
                    num(lo),
                    num(hi)
                ),
            );
        }
    }
    let solver = match a.solver.as_deref() {
        None | Some("auto") => Method::Auto,
        Some("dense") => Method::Dense,
        Some("lanczos") => Method::Lanczos,
        Some(other) => {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("unknown solver \"{other}\" (available: auto, dense, lanczos)"),
            );
            Method::Auto
        }
    };
    ModalSettings {
        modes,
        shift: a.shift,
        frequency_range: a.frequency_range.map(|[lo, hi]| (lo, hi)),
        solver,
        time: start,
    }
}

/// Settings of one analysis from `start` to its end, with defaults.
fn settings(ck: &mut Checker, entity: &str, a: &AnalysisInput, start: f64) -> StaticSettings {
    if !matches!(a.kind.as_str(), "static" | "kinetostatic" | "kinematic") {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "unknown analysis type \"{}\" (available: static, kinetostatic, kinematic, dynamic, modal)",
                a.kind
            ),
        );
    }
    let end = a.end_time;
    ck.positive(entity, "end_time", end);
    let span = end - start;
    let initial = a.initial_increment.unwrap_or(span / 10.0);
    let s = StaticSettings {
        end_time: end,
        initial_increment: initial,
        min_increment: a.min_increment.unwrap_or(span * 1e-6),
        max_increment: a.max_increment.unwrap_or(initial),
        max_iterations: a.max_iterations.unwrap_or(25),
        // quadratic convergence makes 1e-8 cheap: one iteration more than 1e-4
        residual_tolerance: a.residual_tolerance.unwrap_or(1e-8),
        displacement_tolerance: a.displacement_tolerance.unwrap_or(1e-6),
        rotation_tolerance: a.rotation_tolerance.unwrap_or(1e-6),
        output_every: a.output_every.unwrap_or(1),
        output_times: a.output_times.clone().unwrap_or_default(),
        kinematic: a.kind == "kinematic",
        kinetostatic: a.kind == "kinetostatic",
        arc_length: a.control.as_deref() == Some("arc_length"),
        max_increments: a.max_increments.unwrap_or(1000),
    };
    if !matches!(
        a.control.as_deref(),
        None | Some("load") | Some("arc_length")
    ) {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "unknown control \"{}\" (available: load, arc_length)",
                a.control.as_deref().unwrap_or("")
            ),
        );
    }
    if s.arc_length && s.kinematic {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "a kinematic analysis follows its drivers: arc-length control does not apply",
        );
    }
    // k and p multiply the constraint gradients in the tangent
    for (name, v) in [
        ("constraint_scale", a.constraint_scale),
        ("constraint_penalty", a.constraint_penalty),
    ] {
        if v.is_some_and(|v| v > LARGEST_ELEMENT_VALUE) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("{name} must be at most {LARGEST_ELEMENT_VALUE:e}"),
            );
        }
    }
    if let Some(k) = a.constraint_scale {
        ck.positive(entity, "constraint_scale", k);
    }
    if let Some(p) = a.constraint_penalty {
        if !(p.is_finite() && p >= 0.0) {
            ck.push(
                ModelErrorKind::NonPositive,
                entity,
                format!(
                    "constraint_penalty must be zero or positive, got {}",
                    num(p)
                ),
            );
        }
    }
    if s.max_increments == 0 {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "max_increments must be at least 1",
        );
    }
    ck.positive(entity, "initial_increment", s.initial_increment);
    ck.positive(entity, "min_increment", s.min_increment);
    ck.positive(entity, "max_increment", s.max_increment);
    ck.positive(entity, "residual_tolerance", s.residual_tolerance);
    ck.positive(entity, "displacement_tolerance", s.displacement_tolerance);
    ck.positive(entity, "rotation_tolerance", s.rotation_tolerance);
    // relative tolerances of 1 or more accept any iterate
    for (name, v) in [
        ("residual_tolerance", s.residual_tolerance),
        ("displacement_tolerance", s.displacement_tolerance),
        ("rotation_tolerance", s.rotation_tolerance),
    ] {
        if v >= 1.0 {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "{name} must be below 1 (a relative tolerance, or radians), got {}",
                    num(v)
                ),
            );
        }
    }
    if s.max_iterations == 0 || s.max_iterations > MAX_ITERATIONS {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "max_iterations must be from 1 to {MAX_ITERATIONS}, got {}",
                s.max_iterations
            ),
        );
    }
    if s.max_increments as f64 > MAX_INCREMENTS {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "max_increments must be at most {MAX_INCREMENTS:e}, got {}",
                s.max_increments
            ),
        );
    }
    // a run of more than MAX_INCREMENTS increments is a hang, not an analysis
    let increments = span / s.max_increment;
    if increments > MAX_INCREMENTS {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "{} / max_increment = {increments:.3e}: the analysis would need more than {MAX_INCREMENTS:e} increments",
                if start == 0.0 { "end_time" } else { "(end_time − start)" }
            ),
        );
    }
    if s.min_increment < MIN_RELATIVE_INCREMENT * s.end_time {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "min_increment must be at least end_time·{MIN_RELATIVE_INCREMENT:e} = {:e} (smaller steps are lost in the round-off of t), got {}",
                MIN_RELATIVE_INCREMENT * s.end_time,
                num(s.min_increment)
            ),
        );
    }
    if s.output_every == 0 {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "output_every must be at least 1",
        );
    }
    if s.min_increment > s.initial_increment || s.initial_increment > s.max_increment {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "increments must satisfy min_increment ≤ initial_increment ≤ max_increment, got {} ≤ {} ≤ {}",
                num(s.min_increment),
                num(s.initial_increment),
                num(s.max_increment)
            ),
        );
    }
    for &t in &s.output_times {
        if !(t.is_finite() && t > start && t <= end) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "output_times must lie after the start of the analysis (t = {}) and not after its end_time ({}), got {}",
                    num(start),
                    num(end),
                    num(t)
                ),
            );
        }
    }
    if s.output_times.windows(2).any(|w| w[1] <= w[0]) {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "output_times must be in increasing order",
        );
    }
    s
}

/// Settings of one dynamic analysis from `start` to its end, with
/// defaults (docs/model-format.md, dynamic analyses).
fn dynamic_settings(
    ck: &mut Checker,
    entity: &str,
    a: &AnalysisInput,
    start: f64,
) -> DynamicSettings {
    for (key, given) in [
        ("initial_increment", a.initial_increment.is_some()),
        ("min_increment", a.min_increment.is_some()),
        ("max_increment", a.max_increment.is_some()),
        ("control", a.control.is_some()),
        ("max_increments", a.max_increments.is_some()),
    ] {
        if given {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("{key} belongs to static analyses; a dynamic analysis takes time_step, min_step and max_step"),
            );
        }
    }
    let end = a.end_time;
    ck.positive(entity, "end_time", end);
    let span = end - start;
    // the default first step is a hundredth of the span, or max_step if
    // that is smaller
    let time_step = a.time_step.unwrap_or(match a.max_step {
        Some(m) if m > 0.0 && m < span / 100.0 => m,
        _ => span / 100.0,
    });
    // the default smallest step is time_step·1e-6, not below the round-off
    // of t (nor above time_step)
    let round_off = MIN_RELATIVE_INCREMENT * end.abs();
    let min_step = a
        .min_step
        .unwrap_or((time_step * 1e-6).max(round_off).min(time_step));
    let adaptive = a.adaptive.unwrap_or(true);
    let mut s = DynamicSettings {
        start_time: start,
        end_time: end,
        time_step,
        min_step,
        max_step: a.max_step.unwrap_or(if adaptive {
            default_max_step(span, time_step)
        } else {
            time_step
        }),
        rho_infinity: a.rho_infinity.unwrap_or(DEFAULT_RHO_INFINITY),
        adaptive,
        error_tolerance: a.error_tolerance.unwrap_or(DEFAULT_ERROR_TOLERANCE),
        max_iterations: a.max_iterations.unwrap_or(25),
        residual_tolerance: a.residual_tolerance.unwrap_or(1e-8),
        displacement_tolerance: a.displacement_tolerance.unwrap_or(1e-6),
        rotation_tolerance: a.rotation_tolerance.unwrap_or(1e-6),
        newton: match a.newton.as_deref() {
            Some("full") | None => NewtonMethod::Full,
            Some("modified") => NewtonMethod::Modified,
            Some(other) => {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("unknown newton \"{other}\" (available: modified, full)"),
                );
                NewtonMethod::default()
            }
        },
        angular_velocities: match a.angular_velocities.as_deref() {
            Some("material") | None => AngularVelocities::Material,
            Some("spatial") => AngularVelocities::Spatial,
            Some(other) => {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "unknown angular_velocities \"{other}\" (available: material, spatial)"
                    ),
                );
                AngularVelocities::default()
            }
        },
        output_every: a.output_every.unwrap_or(1),
        output_times: a.output_times.clone().unwrap_or_default(),
        output_interval: None,
    };
    if !(s.rho_infinity.is_finite() && (0.0..=1.0).contains(&s.rho_infinity)) {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "rho_infinity must lie in [0, 1] (1: no numerical dissipation), got {}",
                num(s.rho_infinity)
            ),
        );
    }
    // min_step and max_step not given are derived from time_step: only a
    // time_step of its own is then reported
    // (and time_step not given from the span: end_time is reported)
    let time_ok = if a.time_step.is_some() || span > 0.0 {
        ck.positive(entity, "time_step", s.time_step)
    } else {
        false
    };
    let derived_ok = |given: bool| given || time_ok;
    let mut steps_ok = time_ok
        & (!derived_ok(a.min_step.is_some()) || ck.positive(entity, "min_step", s.min_step))
        & (!derived_ok(a.max_step.is_some()) || ck.positive(entity, "max_step", s.max_step));
    if steps_ok && s.time_step < round_off {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "time_step must be at least end_time·{MIN_RELATIVE_INCREMENT:e} = {:e} (smaller steps are lost in the round-off of t), got {}",
                round_off,
                num(s.time_step)
            ),
        );
        steps_ok = false;
    }
    if steps_ok && s.min_step > s.max_step {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "min_step ({}) must not exceed max_step ({})",
                num(s.min_step),
                num(s.max_step)
            ),
        );
    } else if steps_ok && s.time_step > s.max_step {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "time_step ({}) must not exceed max_step ({})",
                num(s.time_step),
                num(s.max_step)
            ),
        );
    } else if steps_ok && s.time_step < s.min_step {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "time_step ({}) must not be below min_step ({})",
                num(s.time_step),
                num(s.min_step)
            ),
        );
    }
    // fixed steps: time_step throughout, cut back when Newton fails and
    // grown back to time_step, never beyond
    if !adaptive {
        if let Some(m) = a.max_step.filter(|&m| steps_ok && m > s.time_step) {
            ck.warn(
                entity,
                format!(
                    "max_step ({}) has no effect with adaptive = false: the steps are time_step ({})",
                    num(m),
                    num(s.time_step)
                ),
            );
        }
        s.max_step = s.max_step.min(s.time_step);
    }
    if steps_ok && s.min_step < round_off {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "min_step must be at least end_time·{MIN_RELATIVE_INCREMENT:e} = {:e} (smaller steps are lost in the round-off of t), got {}",
                MIN_RELATIVE_INCREMENT * s.end_time,
                num(s.min_step)
            ),
        );
    }
    if steps_ok && span / s.max_step > MAX_INCREMENTS {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "(end_time − start) / max_step = {:.3e}: the analysis would need more than {MAX_INCREMENTS:e} steps",
                span / s.max_step
            ),
        );
    }
    if !(s.error_tolerance.is_finite() && s.error_tolerance > 0.0 && s.error_tolerance < 1.0) {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "error_tolerance must lie between 0 and 1 (a relative tolerance), got {}",
                num(s.error_tolerance)
            ),
        );
    }
    for (name, v) in [
        ("residual_tolerance", s.residual_tolerance),
        ("displacement_tolerance", s.displacement_tolerance),
        ("rotation_tolerance", s.rotation_tolerance),
    ] {
        if !(v.is_finite() && v > 0.0 && v < 1.0) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("{name} must lie between 0 and 1, got {}", num(v)),
            );
        }
    }
    if s.max_iterations == 0 || s.max_iterations > MAX_ITERATIONS {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "max_iterations must be from 1 to {MAX_ITERATIONS}, got {}",
                s.max_iterations
            ),
        );
    }
    if s.output_every == 0 {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "output_every must be at least 1",
        );
    }
    for &t in &s.output_times {
        if !(t.is_finite() && t > start && t <= end) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "output_times must lie after the start of the analysis (t = {}) and not after its end_time ({}), got {}",
                    num(start),
                    num(end),
                    num(t)
                ),
            );
        }
    }
    if s.output_times.windows(2).any(|w| w[1] <= w[0]) {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "output_times must be in increasing order",
        );
    } else if steps_ok {
        // times nearer than a step can be to each other (or to the start)
        // would be landed on as one
        let apart = s.min_step.max(LANDING_SNAP * end.abs().max(start.abs()));
        let mut before = start;
        for &t in &s.output_times {
            if t - before < apart {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "output_times {} and {} are {:.3e} apart, nearer than a step can be ({}, the larger of min_step and end_time·{LANDING_SNAP:e}): the steps cannot land on both; keep one",
                        num(before),
                        num(t),
                        t - before,
                        num(apart)
                    ),
                );
            }
            before = t;
        }
    }
    match a.output_interval {
        Some(dt) => output_interval(ck, entity, a, s, start, dt, steps_ok),
        None => s,
    }
}

/// Checks `output_interval = dt` of a dynamic analysis from `start` and
/// adds its grid of output times to `s`.
fn output_interval(
    ck: &mut Checker,
    entity: &str,
    a: &AnalysisInput,
    s: DynamicSettings,
    start: f64,
    dt: f64,
    steps_ok: bool,
) -> DynamicSettings {
    let span = s.end_time - start;
    let apart = s
        .min_step
        .max(LANDING_SNAP * s.end_time.abs().max(start.abs()));
    let message = if a.output_every.is_some() {
        "output_interval and output_every cannot both be given: output_interval writes results at regular times, output_every at every n-th step; keep one".to_string()
    } else if !(dt.is_finite() && dt > 0.0) {
        format!(
            "output_interval must be positive and finite, got {}",
            num(dt)
        )
    } else if span.is_nan() || span <= 0.0 {
        // end_time before the start: reported with end_time
        return s;
    } else if dt > span {
        format!(
            "output_interval ({}) must not exceed the span of the analysis ({}, from t = {} to end_time {})",
            num(dt),
            num(span),
            num(start),
            num(s.end_time)
        )
    } else if steps_ok && dt < apart {
        format!(
            "output_interval ({}) is shorter than a step can be ({}, the larger of min_step and end_time·{LANDING_SNAP:e}): the steps cannot land on every output time",
            num(dt),
            num(apart)
        )
    } else if span / dt > MAX_INCREMENTS {
        format!(
            "output_interval ({}) asks for {:.3e} output times, more than {MAX_INCREMENTS:e}",
            num(dt),
            span / dt
        )
    } else {
        return s.with_output_interval(start, dt, apart);
    };
    ck.push(ModelErrorKind::Invalid, entity, message);
    s
}
