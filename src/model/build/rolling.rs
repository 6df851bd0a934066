//! `[[rolling_discs]]`: discs rolling without slipping on fixed planes.

use super::Builder;
use crate::joints::RollingDisc;
use crate::model::ModelErrorKind;
use crate::so3::{self, Vec3};

/// A disc whose lowest point is farther than this fraction of its radius
/// from the plane in the reference configuration does not touch it.
const CONTACT_TOLERANCE: f64 = 1e-9;

/// A disc axis within this angle (rad) of the plane's normal lies flat:
/// its lowest point is not defined.
const FLAT: f64 = 1e-6;

impl Builder<'_> {
    pub(super) fn rolling_discs(&mut self) {
        let input = self.input;
        for d in &input.rolling_discs {
            let entity = format!("rolling disc {}", d.id);
            let id_ok = self.claim_id(&entity, d.id);
            let node = self.node(&entity, d.node);
            if !(d.radius.is_finite() && d.radius > 0.0) {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("radius must be positive, got {}", d.radius),
                );
                continue;
            }
            let axis = self.unit(&entity, "axis", d.axis);
            let normal = self.unit(&entity, "normal", d.normal);
            let point = Vec3::from(d.point.unwrap_or([0.0; 3]));
            if !point.iter().all(|c| c.is_finite()) {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("point must be finite, got {:?}", point.as_slice()),
                );
                continue;
            }
            let (Some(node), Some(axis), Some(normal), true) = (node, axis, normal, id_ok) else {
                continue;
            };
            let (x, r) = (self.nodes[node].x, so3::matrix(&self.nodes[node].q));
            let a = r * axis;
            let sin = a.cross(&normal).norm();
            if sin < FLAT {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    "the disc's axis is along the plane's normal: a disc lying flat has no lowest point",
                );
                continue;
            }
            // height of the lowest point of the rim, Φ of docs/joints.md (R1)
            let height = normal.dot(&(x - point)) - d.radius * sin;
            if height.abs() > CONTACT_TOLERANCE * d.radius {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!(
                        "the disc does not touch the plane in the reference configuration: its lowest point is at {height:.6e} from it"
                    ),
                );
                continue;
            }
            self.elements.push(Box::new(RollingDisc::new(
                d.id,
                node,
                d.radius,
                axis,
                point,
                normal,
                (x, r),
            )));
        }
    }
}
