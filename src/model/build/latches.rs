//! `[[latches]]`: locks of joint coordinates at the end of their travel.

use super::joints::{angle_unit, joint_coordinate, Context, Joints};
use super::AngleLimit;
use crate::joints::latch::SpringLatch;
use crate::joints::Latch;
use crate::model::input::{Approach, LatchInput, LatchMode, LatchSide};
use crate::model::ModelErrorKind;

pub(super) fn latch(
    cx: &mut Context,
    entity: &str,
    l: &LatchInput,
    joints: &Joints,
) -> Option<Latch> {
    if !l.value.is_finite() {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("value must be finite, got {}", l.value),
        );
        return None;
    }
    let source = joint_coordinate(cx, entity, l.joint, &l.coordinate, joints)?;
    let unit = angle_unit(cx, entity, l.unit, &source)?;
    let value = l.value * unit;
    let approach = match l.approach {
        Some(Approach::Increasing) => 1.0,
        Some(Approach::Decreasing) => -1.0,
        None if value > 0.0 => 1.0,
        None if value < 0.0 => -1.0,
        None => {
            cx.ck.push(
                ModelErrorKind::Missing,
                entity,
                "a latch at the reference value 0 needs `approach` (\"increasing\" or \"decreasing\")",
            );
            return None;
        }
    };
    if source.is_angle() && l.unit.is_none() {
        cx.ck
            .unitless_angle(entity, "locks at", value, AngleLimit::FullTurn);
    }
    let latch = Latch::new(l.id, l.joint, source, value, approach);
    match l.mode.unwrap_or_default() {
        LatchMode::Rigid => {
            let given: Vec<&str> = [
                ("stiffness", l.stiffness),
                ("backlash", l.backlash),
                ("damping", l.damping),
                ("unlatch_load", l.unlatch_load),
                ("side", l.side.map(|_| 0.0)),
            ]
            .iter()
            .filter(|(_, v)| v.is_some())
            .map(|(k, _)| *k)
            .collect();
            if !given.is_empty() {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "`{}` {} to spring latches: add mode = \"spring\" (a rigid latch holds its coordinate as a constraint)",
                        given.join("`, `"),
                        if given.len() == 1 { "applies" } else { "apply" }
                    ),
                );
                return None;
            }
            Some(latch)
        }
        LatchMode::Spring => {
            let mut spring = spring(cx, entity, l, unit, latch.is_angle())?;
            // the sign of c − c_L the spring acts on
            spring.side = match l.side.unwrap_or_default() {
                LatchSide::Both => None,
                LatchSide::Beyond => Some(approach),
                LatchSide::Behind => Some(-approach),
            };
            Some(latch.with_spring(spring))
        }
    }
}

/// The compliant lock of a spring latch, its angles in `unit` (rad per
/// unit of the entry) converted to radians.
fn spring(
    cx: &mut Context,
    entity: &str,
    l: &LatchInput,
    unit: f64,
    angle: bool,
) -> Option<SpringLatch> {
    let mut ok = true;
    let mut bad = |cx: &mut Context, kind, message: String| {
        cx.ck.push(kind, entity, message);
        ok = false;
    };
    let stiffness = match l.stiffness {
        None => {
            bad(
                cx,
                ModelErrorKind::Missing,
                "a spring latch needs `stiffness` (N·m/rad or N/m, positive)".into(),
            );
            0.0
        }
        Some(k) if !(k.is_finite() && k > 0.0 && (k / unit).is_finite()) => {
            bad(
                cx,
                ModelErrorKind::NonPositive,
                format!("stiffness must be positive and finite, got {k}"),
            );
            0.0
        }
        Some(k) => k / unit,
    };
    let backlash = l.backlash.unwrap_or(0.0);
    if !(backlash.is_finite() && backlash >= 0.0) {
        bad(
            cx,
            ModelErrorKind::Invalid,
            format!("backlash must be zero or positive and finite, got {backlash}"),
        );
    }
    let damping = l.damping.unwrap_or(0.0);
    if !(damping.is_finite() && damping >= 0.0 && (damping / unit).is_finite()) {
        bad(
            cx,
            ModelErrorKind::Invalid,
            format!("damping must be zero or positive and finite, got {damping}"),
        );
    }
    if let Some(f) = l.unlatch_load {
        if !(f.is_finite() && f > 0.0) {
            bad(
                cx,
                ModelErrorKind::NonPositive,
                format!("unlatch_load must be positive and finite, got {f}"),
            );
        }
    }
    if angle && l.unit.is_none() {
        cx.ck
            .unitless_angle(entity, "backlash is", backlash, AngleLimit::FullTurn);
    }
    if angle && ok {
        cx.ck
            .per_degree(entity, "stiffness", l.stiffness.unwrap_or(0.0), "N·m", unit);
        cx.ck.per_degree(entity, "damping", damping, "N·m·s", unit);
        // a dead band of half a turn or more (±90° about the latch value)
        // is no latch's backlash: most likely radians written as degrees
        let band = backlash * unit;
        if band >= std::f64::consts::PI {
            cx.ck.warn(
                entity,
                format!(
                    "backlash {backlash} is a dead band of {:.1}° (±{:.1}° about the latch value), half a turn or more: a latch's backlash is usually a few degrees; check the unit",
                    band.to_degrees(),
                    0.5 * band.to_degrees()
                ),
            );
        }
    }
    ok.then(|| SpringLatch {
        stiffness,
        backlash: backlash * unit,
        damping: damping / unit,
        unlatch_load: l.unlatch_load,
        side: None,
    })
}
