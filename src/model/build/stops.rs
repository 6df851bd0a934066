//! `[[stops]]`: unilateral limits of joint coordinates.

use super::joints::{angle_unit, joint_coordinate, Context, Joints};
use super::AngleLimit;
use crate::joints::Stop;
use crate::model::input::StopInput;
use crate::model::ModelErrorKind;

pub(super) fn stop(cx: &mut Context, entity: &str, l: &StopInput, joints: &Joints) -> Option<Stop> {
    let mut ok = true;
    for (name, v) in [("lower", l.lower), ("upper", l.upper)] {
        if let Some(v) = v {
            if !v.is_finite() {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("{name} must be finite, got {v}"),
                );
                ok = false;
            }
        }
    }
    if l.lower.is_none() && l.upper.is_none() {
        cx.ck.push(
            ModelErrorKind::Missing,
            entity,
            "a stop needs `lower`, `upper` or both (the limits of the coordinate)",
        );
        ok = false;
    }
    if let (Some(lo), Some(up)) = (l.lower, l.upper) {
        if lo >= up {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("lower ({lo}) must be below upper ({up})"),
            );
            ok = false;
        }
    }
    let e = l.restitution.unwrap_or(0.0);
    if !(0.0..=1.0).contains(&e) {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("restitution must be in [0, 1], got {e}"),
        );
        ok = false;
    }
    let source = joint_coordinate(cx, entity, l.joint, &l.coordinate, joints)?;
    let unit = angle_unit(cx, entity, l.unit, &source)?;
    if !ok {
        return None;
    }
    let lower = l.lower.map_or(f64::NEG_INFINITY, |v| v * unit);
    let upper = l.upper.map_or(f64::INFINITY, |v| v * unit);
    if source.is_angle() && l.unit.is_none() {
        for v in [l.lower, l.upper].into_iter().flatten() {
            cx.ck
                .unitless_angle(entity, "limits at", v, AngleLimit::FullTurn);
        }
    }
    Some(Stop::new(l.id, l.joint, source, lower, upper, e))
}
