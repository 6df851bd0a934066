//! `[[latches]]`: locks of joint coordinates at the end of their travel.

use super::joints::{angle_unit, joint_coordinate, Context, Joints};
use super::AngleLimit;
use crate::joints::Latch;
use crate::model::input::{Approach, LatchInput};
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
    let value = l.value * angle_unit(cx, entity, l.unit, &source)?;
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
    Some(Latch::new(l.id, l.joint, source, value, approach))
}
