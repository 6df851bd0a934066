//! `[[nodes]]`: the reference positions and orientations.

use super::{AngleLimit, Builder, NodeData};
use crate::model::input::MAX_ID;
use crate::model::ModelErrorKind;
use crate::so3::{self, Vec3};

impl Builder<'_> {
    /// `[[nodes]]`: unique ids, finite positions and rotations, a finite
    /// extent.
    pub(super) fn nodes(&mut self) {
        for n in &self.input.nodes {
            let entity = format!("node {}", n.id);
            if self.node_index.contains_key(&n.id) || self.invalid_nodes.contains(&n.id) {
                self.ck
                    .push(ModelErrorKind::DuplicateId, &entity, "duplicate node id");
                continue;
            }
            let rot = n.rotation.unwrap_or([0.0; 3]);
            let unit = n.unit.unwrap_or_default();
            let mut ok = true;
            if n.id > MAX_ID {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("id larger than {MAX_ID}, the largest a model file can hold"),
                );
                ok = false;
            }
            ok &= self.ck.finite(&entity, "x", &n.x) & self.ck.finite(&entity, "rotation", &rot);
            // the exponential map squares the angle
            let psi = Vec3::from(rot) * unit.radians();
            if ok && !psi.norm_squared().is_finite() {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!(
                        "rotation {rot:?} is too large: its squared angle exceeds the range of floating-point numbers"
                    ),
                );
                ok = false;
            }
            if !ok {
                self.invalid_nodes.insert(n.id);
                continue;
            }
            if n.unit.is_none() {
                self.ck.unitless_angle(
                    &entity,
                    "rotation has the length",
                    psi.norm(),
                    AngleLimit::HalfTurn,
                );
            }
            self.node_index.insert(n.id, self.nodes.len());
            self.node_ids.push(n.id);
            self.nodes.push(NodeData {
                x: Vec3::from(n.x),
                q: so3::exp(&psi),
            });
        }
        // every difference of positions (beam axes, offsets) finite
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for n in &self.nodes {
            lo = lo.inf(&n.x);
            hi = hi.sup(&n.x);
        }
        if !self.nodes.is_empty() && !(hi - lo).norm().is_finite() {
            self.ck.push(
                ModelErrorKind::Invalid,
                "nodes",
                format!(
                    "span from {:?} to {:?}: distances between them exceed the range of floating-point numbers",
                    lo.as_slice(),
                    hi.as_slice()
                ),
            );
            // nothing built on these positions could be checked: every
            // node counts as invalid (and reported)
            self.invalid_nodes.extend(self.node_ids.drain(..));
            self.node_index.clear();
            self.nodes.clear();
        }
    }
}
