//! `[analysis]`: the analysis settings, with their defaults and limits.

use super::{
    num, Checker, LARGEST_ELEMENT_VALUE, MAX_INCREMENTS, MAX_ITERATIONS, MIN_RELATIVE_INCREMENT,
};
use crate::model::input::AnalysisInput;
use crate::model::{ModelErrorKind, StaticSettings};

/// Analysis settings with defaults (docs/model-format.md).
pub(super) fn settings(ck: &mut Checker, a: &AnalysisInput) -> StaticSettings {
    if !matches!(a.kind.as_str(), "static" | "kinetostatic" | "kinematic") {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "unknown analysis type \"{}\" (available: static, kinetostatic, kinematic)",
                a.kind
            ),
        );
    }
    let end = a.end_time;
    ck.positive("analysis", "end_time", end);
    let initial = a.initial_increment.unwrap_or(end / 10.0);
    let s = StaticSettings {
        end_time: end,
        initial_increment: initial,
        min_increment: a.min_increment.unwrap_or(end * 1e-6),
        max_increment: a.max_increment.unwrap_or(initial),
        max_iterations: a.max_iterations.unwrap_or(25),
        // quadratic convergence makes 1e-8 cheap: one iteration more than 1e-4
        residual_tolerance: a.residual_tolerance.unwrap_or(1e-8),
        displacement_tolerance: a.displacement_tolerance.unwrap_or(1e-6),
        rotation_tolerance: a.rotation_tolerance.unwrap_or(1e-6),
        output_every: a.output_every.unwrap_or(1),
        kinematic: a.kind == "kinematic",
        arc_length: a.control.as_deref() == Some("arc_length"),
        max_increments: a.max_increments.unwrap_or(1000),
    };
    if !matches!(
        a.control.as_deref(),
        None | Some("load") | Some("arc_length")
    ) {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "unknown control \"{}\" (available: load, arc_length)",
                a.control.as_deref().unwrap_or("")
            ),
        );
    }
    if s.arc_length && s.kinematic {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
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
                "analysis",
                format!("{name} must be at most {LARGEST_ELEMENT_VALUE:e}"),
            );
        }
    }
    if let Some(k) = a.constraint_scale {
        ck.positive("analysis", "constraint_scale", k);
    }
    if let Some(p) = a.constraint_penalty {
        if !(p.is_finite() && p >= 0.0) {
            ck.push(
                ModelErrorKind::NonPositive,
                "analysis",
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
            "analysis",
            "max_increments must be at least 1",
        );
    }
    ck.positive("analysis", "initial_increment", s.initial_increment);
    ck.positive("analysis", "min_increment", s.min_increment);
    ck.positive("analysis", "max_increment", s.max_increment);
    ck.positive("analysis", "residual_tolerance", s.residual_tolerance);
    ck.positive(
        "analysis",
        "displacement_tolerance",
        s.displacement_tolerance,
    );
    ck.positive("analysis", "rotation_tolerance", s.rotation_tolerance);
    // relative tolerances of 1 or more accept any iterate
    for (name, v) in [
        ("residual_tolerance", s.residual_tolerance),
        ("displacement_tolerance", s.displacement_tolerance),
        ("rotation_tolerance", s.rotation_tolerance),
    ] {
        if v >= 1.0 {
            ck.push(
                ModelErrorKind::Invalid,
                "analysis",
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
            "analysis",
            format!(
                "max_iterations must be from 1 to {MAX_ITERATIONS}, got {}",
                s.max_iterations
            ),
        );
    }
    if s.max_increments as f64 > MAX_INCREMENTS {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "max_increments must be at most {MAX_INCREMENTS:e}, got {}",
                s.max_increments
            ),
        );
    }
    // a run of more than MAX_INCREMENTS increments is a hang, not an analysis
    let increments = s.end_time / s.max_increment;
    if increments > MAX_INCREMENTS {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "end_time / max_increment = {increments:.3e}: the analysis would need more than {MAX_INCREMENTS:e} increments"
            ),
        );
    }
    if s.min_increment < MIN_RELATIVE_INCREMENT * s.end_time {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
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
            "analysis",
            "output_every must be at least 1",
        );
    }
    if s.min_increment > s.initial_increment || s.initial_increment > s.max_increment {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "increments must satisfy min_increment ≤ initial_increment ≤ max_increment, got {} ≤ {} ≤ {}",
                num(s.min_increment),
                num(s.initial_increment),
                num(s.max_increment)
            ),
        );
    }
    s
}
