//! `[[joints]]`: the kinematic pairs; and the table of the joints built,
//! through which joint springs and drivers refer to a joint's coordinate.

use std::collections::{HashMap, HashSet};

use super::Builder;
use super::{drivers, hinge_laws, joint_springs, latches, stops};
use crate::elements::Element;
use crate::joints::types::{Coordinate, JointParameters};
use crate::joints::{Joint, JointType, Pair, PairCoordinate};
use crate::model::input::{AngleUnit, Id, JointInput};
use crate::model::ModelErrorKind;
use crate::so3::{self, Mat3, Vec3};

/// Angle below which two axes count as parallel (rad).
const PARALLEL: f64 = 1e-6;

impl Builder<'_> {
    /// `v` normalised; an error naming `what` if it is zero or not finite.
    pub(super) fn unit(&mut self, entity: &str, what: &str, v: [f64; 3]) -> Option<Vec3> {
        let v = Vec3::from(v);
        let n = v.norm();
        if v.iter().all(|c| c.is_finite()) && n > 0.0 && n.is_finite() {
            Some(v / n)
        } else {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "{what} must be a non-zero finite vector, got {:?}",
                    v.as_slice()
                ),
            );
            None
        }
    }
}

/// The builder, as the joint functions know it.
pub(super) type Context<'b, 'i> = Builder<'i>;

/// A joint as built, for joint springs and drivers to refer to.
struct Built {
    joint_type: JointType,
    nodes: Vec<usize>,
    pair: Pair,
}

/// Joints as built, for joint springs and drivers to refer to.
#[derive(Default)]
pub(super) struct Joints {
    built: HashMap<Id, Built>,
    /// Ids of joints defined with errors (already reported).
    invalid: HashSet<Id>,
}

/// Builds every joint, joint spring and driver of the input.
pub(super) fn build(cx: &mut Builder) {
    let input = cx.input;
    let mut joints = Joints::default();
    for j in &input.joints {
        let entity = format!("joint {}", j.id);
        let id_ok = cx.claim_id(&entity, j.id);
        match (joint(cx, &entity, j), id_ok) {
            (Some(joint), true) => {
                joints.built.insert(
                    j.id,
                    Built {
                        joint_type: joint.joint_type(),
                        nodes: joint.nodes().to_vec(),
                        pair: joint.pair().clone(),
                    },
                );
                cx.elements.push(Box::new(joint));
            }
            _ => {
                if !joints.built.contains_key(&j.id) {
                    joints.invalid.insert(j.id);
                }
            }
        }
    }
    for s in &input.joint_springs {
        let entity = format!("joint spring {}", s.id);
        let id_ok = cx.claim_id(&entity, s.id);
        if let (Some(e), true) = (joint_springs::joint_spring(cx, &entity, s, &joints), id_ok) {
            cx.elements.push(Box::new(e));
        }
    }
    for h in &input.hinge_laws {
        let entity = format!("hinge law {}", h.id);
        let id_ok = cx.claim_id(&entity, h.id);
        if let (Some(e), true) = (hinge_laws::hinge_law(cx, &entity, h, &joints), id_ok) {
            cx.elements.push(Box::new(e));
        }
    }
    for d in &input.drivers {
        let entity = format!("driver {}", d.id);
        let id_ok = cx.claim_id(&entity, d.id);
        if let (Some(e), true) = (drivers::driver(cx, &entity, d, &joints), id_ok) {
            cx.elements.push(Box::new(e));
        }
    }
    for l in &input.latches {
        let entity = format!("latch {}", l.id);
        let id_ok = cx.claim_id(&entity, l.id);
        if let (Some(e), true) = (latches::latch(cx, &entity, l, &joints), id_ok) {
            cx.elements.push(Box::new(e));
        }
    }
    for l in &input.stops {
        let entity = format!("stop {}", l.id);
        let id_ok = cx.claim_id(&entity, l.id);
        if let (Some(e), true) = (stops::stop(cx, &entity, l, &joints), id_ok) {
            cx.elements.push(Box::new(e));
        }
    }
}

/// A triad with `e₃ = axis` and `e₁` along the projection of `reference`
/// (or any normal direction).
pub(super) fn triad(axis: &Vec3, reference: Option<&Vec3>) -> Option<Mat3> {
    let guess = |a: &Vec3| {
        if a.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        }
    };
    let r = reference.copied().unwrap_or_else(|| guess(axis));
    let e1 = r - axis * axis.dot(&r);
    if e1.norm() < 1e-9 {
        return None;
    }
    let e1 = e1.normalize();
    let e2 = axis.cross(&e1);
    Some(Mat3::from_columns(&[e1, e2, *axis]))
}

fn joint(cx: &mut Context, entity: &str, j: &JointInput) -> Option<Joint> {
    let t = j.kind;
    let ok_count = if t == JointType::Glue || t == JointType::Rigid {
        j.nodes.len() == 2
    } else {
        matches!(j.nodes.len(), 1 | 2)
    };
    if !ok_count {
        let want = if t == JointType::Glue || t == JointType::Rigid {
            "two nodes"
        } else {
            "one node (joint to the ground) or two nodes"
        };
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("a {} joint needs {want}, got {}", t.name(), j.nodes.len()),
        );
        return None;
    }
    if j.nodes.len() == 2 && j.nodes[0] == j.nodes[1] {
        cx.ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("joins node {} to itself", j.nodes[0]),
        );
        return None;
    }
    let idx: Vec<Option<usize>> = j.nodes.iter().map(|&n| cx.node(entity, n)).collect();

    // fields that only some types take
    let needs_axis = matches!(
        t,
        JointType::Revolute
            | JointType::Prismatic
            | JointType::Cylindrical
            | JointType::Planar
            | JointType::Universal
            | JointType::Helical
    );
    let unexpected = |field: &str, present: bool, cx: &mut Context| {
        if present {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("`{field}` does not apply to a {} joint", t.name()),
            );
        }
    };
    unexpected("pitch", j.pitch.is_some() && t != JointType::Helical, cx);
    unexpected("offset", j.offset.is_some() && t != JointType::Glue, cx);
    unexpected(
        "lock_rotations",
        j.lock_rotations.is_some() && t != JointType::Glue,
        cx,
    );
    unexpected("curve", !j.curve.is_empty() && t != JointType::Slider, cx);
    unexpected("spline", j.spline.is_some() && t != JointType::Slider, cx);
    unexpected("axis", j.axis.is_some() && !needs_axis, cx);
    unexpected("axis_b", j.axis_b.is_some() && !needs_axis, cx);
    unexpected(
        "reference_direction",
        j.reference_direction.is_some() && (!needs_axis || t == JointType::Universal),
        cx,
    );
    unexpected("position", j.position.is_some() && t == JointType::Glue, cx);

    // joint axes
    let e = if needs_axis {
        let Some(axis) = j.axis else {
            cx.ck.push(
                ModelErrorKind::Missing,
                entity,
                format!("a {} joint needs `axis`", t.name()),
            );
            return None;
        };
        let axis = cx.unit(entity, "axis", axis)?;
        let axis_b = match j.axis_b {
            Some(v) => Some(cx.unit(entity, "axis_b", v)?),
            None => None,
        };
        if t == JointType::Universal {
            // e₁ = arm on A, e₂ = arm on B
            let arm_b = match axis_b {
                Some(v) => v,
                None => {
                    cx.ck.push(ModelErrorKind::Missing, entity, "a universal joint needs `axis` (the cross arm on A) and `axis_b` (the arm on B)");
                    return None;
                }
            };
            if axis.dot(&arm_b).abs() > PARALLEL {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "the cross arms `axis` and `axis_b` must be perpendicular (angle {:.3}°)",
                        axis.dot(&arm_b).acos().to_degrees()
                    ),
                );
                return None;
            }
            Mat3::from_columns(&[axis, arm_b, axis.cross(&arm_b)])
        } else {
            if let Some(ab) = axis_b {
                let angle = axis.cross(&ab).norm().asin();
                if angle > PARALLEL || axis.dot(&ab) < 0.0 {
                    cx.ck.push(ModelErrorKind::Invalid, entity, format!("the axes of the {} joint must coincide: `axis` and `axis_b` differ by {:.4}°", t.name(), axis.dot(&ab).clamp(-1.0, 1.0).acos().to_degrees()));
                    return None;
                }
            }
            let r = match j.reference_direction {
                Some(v) => Some(cx.unit(entity, "reference_direction", v)?),
                None => None,
            };
            match triad(&axis, r.as_ref()) {
                Some(m) => m,
                None => {
                    cx.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        "`reference_direction` is parallel to `axis`",
                    );
                    return None;
                }
            }
        }
    } else {
        Mat3::identity()
    };

    let mut parameters = JointParameters {
        lead: 0.0,
        lock_rotations: j.lock_rotations.unwrap_or(true),
        curve: None,
    };
    if t == JointType::Helical {
        match j.pitch {
            Some(p) if p.is_finite() => parameters.lead = p / std::f64::consts::TAU,
            Some(p) => {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("pitch must be finite, got {p}"),
                );
                return None;
            }
            None => {
                cx.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "a helical joint needs `pitch` (advance per turn)",
                );
                return None;
            }
        }
    }

    // the nodes (the checks above need none of them)
    let idx: Vec<usize> = idx.into_iter().collect::<Option<_>>()?;
    let a = idx[0];
    let b = idx.get(1).copied();
    let (xa, ra) = (cx.nodes[a].x, so3::matrix(&cx.nodes[a].q));

    if t == JointType::Slider {
        if j.curve.len() < 2 {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                "a slider needs `curve` with at least two nodes",
            );
            return None;
        }
        if b.is_some() {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                "a slider takes one node in `nodes` (the sliding node) and its path in `curve`",
            );
            return None;
        }
        let curve: Vec<usize> = j
            .curve
            .iter()
            .map(|&n| cx.node(entity, n))
            .collect::<Option<_>>()?;
        if curve.contains(&a) {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("the sliding node {} is also on its curve", j.nodes[0]),
            );
            return None;
        }
        for w in curve.windows(2) {
            if (cx.nodes[w[1]].x - cx.nodes[w[0]].x).norm() == 0.0 {
                cx.ck.push(
                    ModelErrorKind::ZeroLength,
                    entity,
                    "two consecutive curve nodes coincide",
                );
                return None;
            }
        }
        let p = j.position.map_or(xa, Vec3::from);
        let pts: Vec<Vec3> = curve.iter().map(|&c| cx.nodes[c].x).collect();
        let spline = j.spline.unwrap_or(true);
        let s0 = project_on_curve(&pts, &p, spline);
        return Some(Joint::slider(
            j.id,
            a,
            ra.transpose() * (p - xa),
            &curve,
            spline,
            s0,
        ));
    }

    let bb = b.map(|b| (cx.nodes[b].x, so3::matrix(&cx.nodes[b].q)));
    let pair = if t == JointType::Glue {
        let b = b.expect("checked: two nodes");
        let (xb, rb) = bb.expect("two nodes");
        let a_off = match j.offset {
            Some(o) if o.iter().all(|v| v.is_finite()) => Vec3::from(o),
            Some(o) => {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("offset must be finite, got {o:?}"),
                );
                return None;
            }
            None => ra.transpose() * (xb - xa),
        };
        let _ = b;
        Pair {
            a: a_off,
            ea: ra.transpose(),
            b: Vec3::zeros(),
            eb: rb.transpose(),
            ground: None,
        }
    } else {
        let p = match j.position {
            Some(p) if p.iter().all(|v| v.is_finite()) => Vec3::from(p),
            Some(p) => {
                cx.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("position must be finite, got {p:?}"),
                );
                return None;
            }
            None => xa,
        };
        Pair::from_reference(&p, &e, (&xa, &ra), bb.as_ref().map(|(x, r)| (x, r)))
    };
    Some(Joint::new(j.id, t, a, b, pair, parameters))
}

/// Parameter of the point of the slider curve through `pts` nearest to
/// `p`: the nearest point of the polygon, refined on the spline by Newton
/// iterations on `(C(s) − p)·C'(s) = 0`.
fn project_on_curve(pts: &[Vec3], p: &Vec3, spline: bool) -> f64 {
    use crate::joints::hyperdual::{HyperDual, V3};
    use crate::joints::types::SliderCurve;
    let mut s = project_on_polyline(pts, p);
    if !spline {
        return s;
    }
    let curve = SliderCurve { spline: true };
    let c: Vec<V3<HyperDual>> = pts.iter().map(V3::cst).collect();
    for _ in 0..20 {
        // f(s) = ½|C(s) − p|², f' and f'' from one hyper-dual evaluation
        let x = HyperDual::new(s, 1.0, 1.0);
        let d = curve.point(&c, x).sub(&V3::cst(p));
        let f = d.dot(&d) * 0.5;
        if f.e12.abs() < 1e-300 {
            break;
        }
        let step = f.e1 / f.e12;
        s -= step;
        if step.abs() < 1e-14 * (1.0 + s.abs()) {
            break;
        }
    }
    s
}

/// Parameter (distance along the polygon) of the point of the polyline
/// `pts` nearest to `p`.
fn project_on_polyline(pts: &[Vec3], p: &Vec3) -> f64 {
    let (mut best, mut best_s, mut start) = (f64::INFINITY, 0.0, 0.0);
    for w in pts.windows(2) {
        let d = w[1] - w[0];
        let l = d.norm();
        let t = ((p - w[0]).dot(&d) / (l * l)).clamp(0.0, 1.0);
        let dist = (w[0] + d * t - p).norm();
        if dist < best {
            best = dist;
            best_s = start + t * l;
        }
        start += l;
    }
    best_s
}

/// Resolves `coordinate` of joint `joint` into a pair coordinate.
pub(super) fn joint_coordinate(
    cx: &mut Context,
    entity: &str,
    joint: Id,
    coordinate: &Option<String>,
    joints: &Joints,
) -> Option<PairCoordinate> {
    let Some(b) = joints.built.get(&joint) else {
        if !joints.invalid.contains(&joint) {
            cx.ck.push(
                ModelErrorKind::UnknownNode,
                entity,
                format!("joint {joint} does not exist"),
            );
        }
        return None;
    };
    let coords = b.joint_type.coordinates();
    let usable: Vec<Coordinate> = coords
        .iter()
        .copied()
        .filter(|c| *c != Coordinate::CurveParameter)
        .collect();
    let names: Vec<&str> = usable.iter().map(|c| c.name()).collect();
    let c = match coordinate {
        None => usable.first().copied(),
        Some(n) => usable.iter().copied().find(|c| c.name() == n),
    };
    match c {
        Some(c) => Some(PairCoordinate {
            nodes: b.nodes.clone(),
            pair: b.pair.clone(),
            coordinate: c,
        }),
        None => {
            let msg = if names.is_empty() {
                format!(
                    "joint {joint} ({}) has no coordinate that springs, drivers, hinge laws, latches or stops can act on",
                    b.joint_type.name()
                )
            } else {
                format!(
                    "joint {joint} ({}) has no coordinate {:?}; it has {}",
                    b.joint_type.name(),
                    coordinate.as_deref().unwrap_or(""),
                    names.join(", ")
                )
            };
            cx.ck.push(ModelErrorKind::Invalid, entity, msg);
            None
        }
    }
}

/// Radians per unit of the angles of an entry acting on `source`; an error
/// if a unit is given for a coordinate that is not an angle.
pub(super) fn angle_unit(
    cx: &mut Context,
    entity: &str,
    unit: Option<AngleUnit>,
    source: &PairCoordinate,
) -> Option<f64> {
    match unit {
        Some(u) if !source.is_angle() => {
            cx.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "unit = \"{}\" applies to angles, but coordinate {} is a length",
                    u.name(),
                    source.coordinate.name()
                ),
            );
            None
        }
        u => Some(u.unwrap_or_default().radians()),
    }
}
