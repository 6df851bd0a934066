//! `[[joint_springs]]`: springs and dampers on joint coordinates, linear
//! or tabulated.

use super::joints::{angle_unit, joint_coordinate, Context, Joints};
use super::AngleLimit;
use crate::joints::{JointSpring, Law};
use crate::model::input::JointSpringInput;
use crate::model::ModelErrorKind;

/// A law from a linear coefficient or a table, the coordinate (table
/// abscissae) scaled by `unit` and the coefficient divided by it.
#[allow(clippy::too_many_arguments)]
fn law(
    cx: &mut Context,
    entity: &str,
    what: &str,
    linear: Option<f64>,
    x0: f64,
    table: &[[f64; 2]],
    unit: f64,
) -> Result<Option<Law>, ()> {
    match (linear, table.is_empty()) {
        (Some(_), false) => {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("give either a linear {what} coefficient or a {what} table, not both"),
            );
            Err(())
        }
        (Some(k), true) => {
            if !(k.is_finite() && k >= 0.0 && (k / unit).is_finite()) {
                cx.ck.push(
                    ModelErrorKind::NonPositive,
                    entity,
                    format!("{what} must be zero or positive and finite, got {k}"),
                );
                return Err(());
            }
            Ok(Some(Law::Linear { k: k / unit, x0 }))
        }
        (None, false) => {
            let points: Vec<(f64, f64)> = table.iter().map(|p| (p[0] * unit, p[1])).collect();
            if points.len() < 2
                || points.iter().any(|p| !(p.0.is_finite() && p.1.is_finite()))
                || points.windows(2).any(|w| {
                    w[1].0 <= w[0].0
                        || !(w[1].0 - w[0].0).is_finite()
                        || !(w[1].1 - w[0].1).is_finite()
                })
            {
                cx.ck.push(ModelErrorKind::Invalid, entity, format!("the {what} table needs at least two finite points with strictly increasing abscissae (and differences between them that do not overflow)"));
                return Err(());
            }
            let l = Law::Table(points);
            if what == "damping" && l.eval(0.0).0 != 0.0 {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "the damping table must give zero force at zero rate",
                );
                return Err(());
            }
            Ok(Some(l))
        }
        (None, true) => Ok(None),
    }
}

pub(super) fn joint_spring(
    cx: &mut Context,
    entity: &str,
    s: &JointSpringInput,
    joints: &Joints,
) -> Option<JointSpring> {
    let source = joint_coordinate(cx, entity, s.joint, &s.coordinate, joints);
    let unit = match &source {
        Some(src) => angle_unit(cx, entity, s.unit, src)?,
        None => 1.0,
    };
    let x0 = s.free_value.unwrap_or(0.0) * unit;
    if !x0.is_finite() {
        cx.ck
            .push(ModelErrorKind::Invalid, entity, "free_value must be finite");
        return None;
    }
    // angles that look like degrees
    if s.unit.is_none() && source.as_ref().is_some_and(|src| src.is_angle()) {
        cx.ck
            .unitless_angle(entity, "free_value is", x0, AngleLimit::FullTurn);
        let widest = s
            .table
            .iter()
            .map(|p| p[0].abs())
            .filter(|a| a.is_finite())
            .fold(0.0, f64::max);
        cx.ck.unitless_angle(
            entity,
            "the angles of its table reach",
            widest,
            AngleLimit::FullTurn,
        );
    }
    let spring = law(cx, entity, "stiffness", s.stiffness, x0, &s.table, unit);
    let damper = law(
        cx,
        entity,
        "damping",
        s.damping,
        0.0,
        &s.damping_table,
        unit,
    );
    let (spring, damper) = (spring.ok()?, damper.ok()?);
    // coefficients per degree, as read
    if let (Some(k), Some(_)) = (s.stiffness, &spring) {
        cx.ck.per_degree(entity, "stiffness", k, "N·m", unit);
    }
    if let (Some(c), Some(_)) = (s.damping, &damper) {
        cx.ck.per_degree(entity, "damping", c, "N·m·s", unit);
    }
    if spring.is_none() && damper.is_none() {
        cx.ck.push(
            ModelErrorKind::Missing,
            entity,
            "needs a stiffness, a table, a damping or a damping_table",
        );
        return None;
    }
    Some(JointSpring::new(s.id, source?, spring, damper))
}
