//! `[[hinge_laws]]`: hysteretic moment laws on joint coordinates, their
//! bounds given as tables or as the tape-spring shape.

use super::joints::{angle_unit, joint_coordinate, Context, Joints};
use crate::joints::{Branch, HingeLaw, Hysteresis, TapeSpring};
use crate::model::input::{HingeLawInput, StartBranch, TapeSpringInput};
use crate::model::ModelErrorKind;

/// A bound from a table, its abscissae scaled by `unit`.
fn table(cx: &mut Context, entity: &str, what: &str, t: &[[f64; 2]], unit: f64) -> Option<Branch> {
    let points: Vec<(f64, f64)> = t.iter().map(|p| (p[0] * unit, p[1])).collect();
    if points.len() < 2 {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("{what} needs at least two points, got {}", points.len()),
        );
        return None;
    }
    if let Some(p) = t.iter().find(|p| !(p[0].is_finite() && p[1].is_finite())) {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("{what}: point {p:?} is not finite"),
        );
        return None;
    }
    if let Some(i) = (1..points.len()).find(|&i| {
        points[i].0 <= points[i - 1].0
            || !(points[i].0 - points[i - 1].0).is_finite()
            || !(points[i].1 - points[i - 1].1).is_finite()
    }) {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "{what}: the abscissae must be strictly increasing (with differences that do not overflow), but point {} ({:?}) follows {:?}",
                i + 1,
                t[i],
                t[i - 1]
            ),
        );
        return None;
    }
    Some(Branch::new(points, 0.0))
}

/// The tape-spring shape, angles scaled by `unit` and the stiffness divided
/// by it.
fn tape_spring(
    cx: &mut Context,
    entity: &str,
    t: &TapeSpringInput,
    unit: f64,
) -> Option<(Branch, Branch)> {
    let mut ok = true;
    let mut bad = |ok: &mut bool, cond: bool, msg: String| {
        if !cond {
            cx.ck.push(ModelErrorKind::Invalid, entity, msg);
            *ok = false;
        }
    };
    let md = t.deployment_moment;
    bad(
        &mut ok,
        md.is_finite() && md >= 0.0,
        format!("tape_spring: deployment_moment must be zero or positive and finite, got {md}"),
    );
    bad(
        &mut ok,
        t.locking_peak.is_finite() && t.locking_peak > md,
        format!(
            "tape_spring: locking_peak must be finite and larger than deployment_moment ({md}), got {}",
            t.locking_peak
        ),
    );
    let k = t.locked_stiffness / unit;
    bad(
        &mut ok,
        k.is_finite() && k > 0.0,
        format!(
            "tape_spring: locked_stiffness must be positive and finite, got {}",
            t.locked_stiffness
        ),
    );
    let (cl, w) = (t.locking_angle * unit, t.snap_width * unit);
    bad(
        &mut ok,
        cl.is_finite(),
        format!(
            "tape_spring: locking_angle must be finite, got {}",
            t.locking_angle
        ),
    );
    bad(
        &mut ok,
        w.is_finite() && w > 0.0,
        format!(
            "tape_spring: snap_width must be positive and finite, got {}",
            t.snap_width
        ),
    );
    let rounding = match t.rounding {
        Some(h) => {
            bad(
                &mut ok,
                h.is_finite() && h >= 0.0,
                format!("tape_spring: rounding must be zero or positive and finite, got {h}"),
            );
            h * unit
        }
        None => 0.25 * w.min(md / k),
    };
    if !ok {
        return None;
    }
    Some(
        TapeSpring {
            deployment_moment: md,
            locking_angle: cl,
            locking_peak: t.locking_peak,
            locked_stiffness: k,
            snap_width: w,
            rounding,
        }
        .branches(),
    )
}

pub(super) fn hinge_law(
    cx: &mut Context,
    entity: &str,
    s: &HingeLawInput,
    joints: &Joints,
) -> Option<HingeLaw> {
    let source = joint_coordinate(cx, entity, s.joint, &s.coordinate, joints);
    let unit = match &source {
        Some(src) => angle_unit(cx, entity, s.unit, src)?,
        None => 1.0,
    };
    let elastic = match s.elastic_slope {
        None => {
            cx.ck.push(
                ModelErrorKind::Missing,
                entity,
                "needs elastic_slope, the slope of the moment between the bounds",
            );
            None
        }
        Some(k) if !(k.is_finite() && k > 0.0 && (k / unit).is_finite()) => {
            cx.ck.push(
                ModelErrorKind::NonPositive,
                entity,
                format!("elastic_slope must be positive and finite, got {k}"),
            );
            None
        }
        Some(k) => Some(k / unit),
    };
    let tables = !(s.load_table.is_empty() && s.unload_table.is_empty());
    let branches = match (&s.tape_spring, tables) {
        (Some(_), true) => {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                "give either load_table and unload_table or tape_spring, not both",
            );
            None
        }
        (Some(t), false) => tape_spring(cx, entity, t, unit),
        (None, true) => {
            let load = table(cx, entity, "load_table", &s.load_table, unit);
            let unload = table(cx, entity, "unload_table", &s.unload_table, unit);
            load.zip(unload)
        }
        (None, false) => {
            cx.ck.push(
                ModelErrorKind::Missing,
                entity,
                "needs its bounds: load_table and unload_table, or tape_spring",
            );
            None
        }
    };
    let ((load, unload), elastic) = (branches?, elastic?);
    // slopes per degree, as read
    if let Some(k) = s.elastic_slope {
        cx.ck.per_degree(entity, "elastic_slope", k, "N·m", unit);
    }
    if let Some(t) = &s.tape_spring {
        cx.ck.per_degree(
            entity,
            "tape_spring locked_stiffness",
            t.locked_stiffness,
            "N·m",
            unit,
        );
    }
    let law = Hysteresis {
        load,
        unload,
        elastic,
    };
    if let Some(c) = law.crossing() {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!(
                "the loading bound must not be below the unloading bound, but at {} = {:.6} f_load = {:.6} < f_unload = {:.6}",
                source.as_ref().map_or("c", |s| s.coordinate.name()),
                c / unit,
                law.load.eval(c).0,
                law.unload.eval(c).0
            ),
        );
        return None;
    }
    let start = match s.start.unwrap_or_default() {
        StartBranch::Load => law.load.eval(0.0).0,
        StartBranch::Unload => law.unload.eval(0.0).0,
    };
    Some(HingeLaw::new(s.id, source?, law, start))
}
