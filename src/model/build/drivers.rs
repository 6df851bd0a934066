//! `[[drivers]]`: prescribed histories of joint coordinates and of node
//! translations and rotations.

use super::curves::RAMP;
use super::joints::{angle_unit, joint_coordinate, triad, Context, Joints};
use super::AngleLimit;
use crate::joints::types::Coordinate;
use crate::joints::{Driver, Pair, PairCoordinate};
use crate::model::input::DriverInput;
use crate::model::ModelErrorKind;
use crate::so3;
use std::f64::consts::FRAC_PI_2;

/// Change of a driven angle in one increment beyond which the increment is
/// ambiguous: the branch of an angle is followed only while an increment
/// turns it by less than half a turn (docs/joints.md §3.3).
const AMBIGUOUS_TURN: f64 = std::f64::consts::PI;

pub(super) fn driver(
    cx: &mut Context,
    entity: &str,
    d: &DriverInput,
    joints: &Joints,
) -> Option<Driver> {
    let curve = cx.curve(entity, &d.curve, RAMP);
    if !d.value.is_finite() {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("value must be finite, got {}", d.value),
        );
        return None;
    }
    let source = match (d.joint, d.node) {
        (Some(j), None) => {
            if d.direction.is_some() || d.motion.is_some() {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "`direction` and `motion` apply to node drivers, not joint drivers",
                );
                return None;
            }
            joint_coordinate(cx, entity, j, &d.coordinate, joints)?
        }
        (None, Some(n)) => {
            if d.coordinate.is_some() {
                cx.ck.push(ModelErrorKind::Invalid, entity, "`coordinate` applies to joint drivers; a node driver takes `direction` and `motion`");
                return None;
            }
            let node = cx.node(entity, n);
            let Some(dir) = d.direction else {
                cx.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "a node driver needs `direction`",
                );
                return None;
            };
            let dir = cx.unit(entity, "direction", dir)?;
            let coordinate = match d.motion.as_deref() {
                None | Some("translation") => Coordinate::Slide3,
                Some("rotation") => Coordinate::Angle,
                Some(m) => {
                    cx.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!("motion must be \"translation\" or \"rotation\", got \"{m}\""),
                    );
                    return None;
                }
            };
            let node = node?;
            let (x, r) = (cx.nodes[node].x, so3::matrix(&cx.nodes[node].q));
            let e = triad(&dir, None).expect("a unit vector has a normal");
            let pair = Pair::node_to_ground(&x, &r, &e);
            PairCoordinate {
                nodes: vec![node],
                pair,
                coordinate,
            }
        }
        _ => {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                "give either `joint` (and `coordinate`) or `node` (with `direction` and `motion`)",
            );
            return None;
        }
    };
    let value = d.value * angle_unit(cx, entity, d.unit, &source)?;
    let curve = curve?;
    if !cx
        .curves
        .check_range(&mut cx.ck, entity, "value", value.abs(), curve)
    {
        return None;
    }
    let window = match d.active {
        None => None,
        Some([start, end]) if !start.is_nan() && !end.is_nan() && start < end => Some((start, end)),
        Some(w) => {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("active must be [start, end] with start < end, got {w:?}"),
            );
            return None;
        }
    };
    // a value meant in degrees: the per-increment warning, when it
    // applies, already says so
    if source.is_angle() && !warn_fast_angle(cx, entity, d, value, curve) && d.unit.is_none() {
        let total = value.abs() * cx.curves.curves[curve].magnitude(cx.curves.end_time);
        cx.ck.unitless_angle(
            entity,
            "drives its angle up to",
            total,
            AngleLimit::FullTurn,
        );
    }
    let driver = Driver::new(d.id, source, value, curve);
    Some(match window {
        Some((start, end)) => driver.with_window(start, end),
        None => driver,
    })
}

/// Warns when a driven angle would turn by more than half a turn in one
/// of the largest increments: load control then limits its increments
/// (`Model::rotation_step_limit`); a value meant in degrees and read in
/// radians does this. Whether it warned.
fn warn_fast_angle(
    cx: &mut Context,
    entity: &str,
    d: &DriverInput,
    value: f64,
    curve: usize,
) -> bool {
    let Some(h) = cx.plan.max_increment else {
        return false;
    };
    if !(h.is_finite() && h > 0.0) {
        return false;
    }
    let end = cx.curves.end_time;
    let change = value.abs() * cx.curves.curves[curve].largest_change(h, end);
    if change > AMBIGUOUS_TURN {
        let hint = if d.unit.is_none() {
            " If the value is in degrees, write unit = \"deg\"."
        } else {
            ""
        };
        cx.ck.warn(
            entity,
            format!(
                "asks for {change:.4} rad ({:.1}°) in one increment of t = {h} (max_increment): more than half a turn, which an increment cannot follow (docs/joints.md §3.3); load increments are limited to {:.3e} (a quarter turn each).{hint}",
                change.to_degrees(),
                cx.curves.curves[curve].largest_step(value, FRAC_PI_2, end)
            ),
        );
        return true;
    }
    false
}
