//! Validation of the curves, and resolution of the references to them.
//!
//! Every curve is checked to give finite values over the analysis, and
//! every quantity that follows a curve to stay finite when multiplied by
//! it: `|value|·max|f|` must be a finite number (docs/model-format.md,
//! "Curves"). A reference to a curve whose definition is itself invalid is
//! not reported again as undefined.

use std::collections::{HashMap, HashSet};

use super::Checker;
use crate::curves::{Curve, CurveIndex, Function};
use crate::model::input::CurveInput;
use crate::model::{CurveUse, ModelErrorKind};

/// Index of the built-in ramp `f = t`.
pub(super) const RAMP: CurveIndex = 0;
/// Index of the built-in constant `f = 1`.
pub(super) const CONSTANT: CurveIndex = 1;

/// The curves of a model, by name, and what follows each.
pub(super) struct CurveTable {
    /// Built-in curves first ([`RAMP`], [`CONSTANT`]), then the valid
    /// user curves.
    pub curves: Vec<Curve>,
    index: HashMap<String, CurveIndex>,
    /// Names of curves defined with errors (already reported).
    invalid: HashSet<String>,
    /// Every reference resolved, in order.
    pub uses: Vec<CurveUse>,
    /// End of the analysis: curves are checked over `[0, end_time]`.
    pub end_time: f64,
}

impl CurveTable {
    /// Validates the user curves; `end_time` is the end of the analysis
    /// (1 if it is itself invalid).
    pub fn build(ck: &mut Checker, input: &[CurveInput], end_time: f64) -> Self {
        let end_time = if end_time.is_finite() && end_time > 0.0 {
            end_time
        } else {
            1.0
        };
        let mut table = Self {
            curves: vec![Curve::ramp(), Curve::constant()],
            index: HashMap::from([
                (Curve::RAMP.to_string(), RAMP),
                (Curve::CONSTANT.to_string(), CONSTANT),
            ]),
            invalid: HashSet::new(),
            uses: Vec::new(),
            end_time,
        };
        let mut defined: HashSet<&str> = HashSet::new();
        for c in input {
            let entity = format!("curve \"{}\"", c.name);
            if !defined.insert(&c.name) {
                ck.push(ModelErrorKind::DuplicateId, &entity, "duplicate curve name");
                continue;
            }
            let curve = if c.function.is_some() || c.points.is_empty() {
                function_curve(ck, &entity, c, end_time)
            } else {
                table_curve(ck, &entity, c)
            };
            let Some(curve) = curve else {
                if !table.index.contains_key(&c.name) {
                    table.invalid.insert(c.name.clone());
                }
                continue;
            };
            if c.name == Curve::RAMP {
                ck.push(
                    ModelErrorKind::DuplicateId,
                    &entity,
                    "the name \"ramp\" is reserved for the built-in curve f(t) = t",
                );
                continue;
            }
            if c.name == Curve::CONSTANT {
                // models written before the built-in constant defined their
                // own: accepted when it is the same function
                if !(curve.is_constant_on(f64::MAX) && curve.value(0.0) == 1.0) {
                    ck.push(
                        ModelErrorKind::DuplicateId,
                        &entity,
                        "the name \"constant\" is reserved for the built-in curve f(t) = 1",
                    );
                }
                continue;
            }
            table.index.insert(c.name.clone(), table.curves.len());
            table.curves.push(curve);
        }
        table
    }

    /// The curve named `name` (or `default` when there is none), recorded
    /// as followed by `entity`; `None` (and an error, unless the curve's
    /// own definition was invalid) when it is not defined.
    pub fn resolve(
        &mut self,
        ck: &mut Checker,
        entity: &str,
        name: &Option<String>,
        default: CurveIndex,
    ) -> Option<CurveIndex> {
        let (curve, by_default) = match name {
            None => (default, true),
            Some(n) => match self.index.get(n) {
                Some(&i) => (i, false),
                None => {
                    if !self.invalid.contains(n) {
                        ck.push(
                            ModelErrorKind::UnknownCurve,
                            entity,
                            format!("curve \"{n}\" is not defined"),
                        );
                    }
                    return None;
                }
            },
        };
        self.uses.push(CurveUse {
            entity: entity.to_string(),
            curve,
            by_default,
        });
        Some(curve)
    }

    /// Checks that `what`, of size `magnitude`, stays finite when
    /// multiplied by the curve over the analysis.
    pub fn check_range(
        &self,
        ck: &mut Checker,
        entity: &str,
        what: &str,
        magnitude: f64,
        curve: CurveIndex,
    ) -> bool {
        let c = &self.curves[curve];
        let m = c.magnitude(self.end_time);
        if (magnitude * m).is_finite() {
            true
        } else {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "{what} ({magnitude:e}) times curve \"{}\" (up to {m:e}) exceeds the range of floating-point numbers",
                    c.name()
                ),
            );
            false
        }
    }
}

/// A piecewise-linear curve: finite points, strictly increasing
/// abscissae, finite differences between points (so that interpolation
/// cannot overflow).
fn table_curve(ck: &mut Checker, entity: &str, c: &CurveInput) -> Option<Curve> {
    let flat: Vec<f64> = c.points.iter().flatten().copied().collect();
    if !ck.finite(entity, "points", &flat) {
        return None;
    }
    if let Some(w) = c.points.windows(2).find(|w| w[1][0] <= w[0][0]) {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "abscissae must increase strictly, but t = {} is followed by t = {}",
                w[0][0], w[1][0]
            ),
        );
        return None;
    }
    if let Some(w) = c
        .points
        .windows(2)
        .find(|w| !((w[1][0] - w[0][0]).is_finite() && (w[1][1] - w[0][1]).is_finite()))
    {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "the points {:?} and {:?} are too far apart to interpolate between (their difference overflows)",
                w[0], w[1]
            ),
        );
        return None;
    }
    Some(Curve::piecewise_linear(
        &c.name,
        c.points.iter().map(|p| (p[0], p[1])).collect(),
    ))
}

/// A curve given by `function` and its parameters, finite over
/// `[0, end_time]`.
fn function_curve(ck: &mut Checker, entity: &str, c: &CurveInput, end_time: f64) -> Option<Curve> {
    let Some(name) = c.function.as_deref() else {
        ck.push(
            ModelErrorKind::Missing,
            entity,
            "needs at least one point [t, f], or a function",
        );
        return None;
    };
    if !c.points.is_empty() {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "give either points or a function, not both",
        );
        return None;
    }
    let given: [(&str, Option<f64>); 9] = [
        ("offset", c.offset),
        ("slope", c.slope),
        ("amplitude", c.amplitude),
        ("frequency", c.frequency),
        ("phase", c.phase),
        ("start", c.start),
        ("end", c.end),
        ("from", c.from),
        ("to", c.to),
    ];
    let allowed: &[&str] = match name {
        "linear" => &["offset", "slope"],
        "sine" => &["offset", "amplitude", "frequency", "phase"],
        "smooth_step" => &["start", "end", "from", "to"],
        _ => {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("unknown function \"{name}\" (available: linear, sine, smooth_step)"),
            );
            return None;
        }
    };
    let mut ok = true;
    for (key, v) in given {
        if let Some(v) = v {
            if !allowed.contains(&key) {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("`{key}` does not apply to a {name} curve"),
                );
                ok = false;
            } else {
                ok &= ck.finite(entity, key, &[v]);
            }
        }
    }
    let required = |ck: &mut Checker, key: &str, v: Option<f64>| {
        if v.is_none() {
            ck.push(
                ModelErrorKind::Missing,
                entity,
                format!("a {name} curve needs `{key}`"),
            );
        }
        v
    };
    let f = match name {
        "linear" => Function::Linear {
            offset: c.offset.unwrap_or(0.0),
            slope: c.slope.unwrap_or(1.0),
        },
        "sine" => Function::Sine {
            offset: c.offset.unwrap_or(0.0),
            amplitude: c.amplitude.unwrap_or(1.0),
            frequency: required(ck, "frequency", c.frequency)?,
            phase: c.phase.unwrap_or(0.0),
        },
        _ => {
            let (start, end) = (required(ck, "start", c.start), required(ck, "end", c.end));
            let (start, end) = (start?, end?);
            if start >= end {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("start must be before end, got {start} and {end}"),
                );
                return None;
            }
            Function::SmoothStep {
                start,
                end,
                from: c.from.unwrap_or(0.0),
                to: c.to.unwrap_or(1.0),
            }
        }
    };
    if !ok {
        return None;
    }
    // every intermediate of the evaluation finite over [0, end_time]
    let overflow = match f {
        Function::Linear { offset, slope } => {
            !(slope * end_time).is_finite() || !(offset + slope * end_time).is_finite()
        }
        Function::Sine {
            offset,
            amplitude,
            frequency,
            phase,
        } => {
            let argument = std::f64::consts::TAU * frequency * end_time;
            !(argument.is_finite()
                && (argument.abs() + phase.abs()).is_finite()
                && (offset.abs() + amplitude.abs()).is_finite())
        }
        Function::SmoothStep {
            start,
            end,
            from,
            to,
        } => !((end - start).is_finite() && (to - from).is_finite()),
    };
    if overflow {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "its values over the analysis (t from 0 to {end_time}) exceed the range of floating-point numbers"
            ),
        );
        return None;
    }
    Some(Curve::function(&c.name, f))
}
