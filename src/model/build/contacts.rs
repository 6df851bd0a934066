//! `[[contacts]]`: unilateral contacts of spheres on nodes with fixed
//! planes or with each other.

use super::{num, Builder};
use crate::joints::latch::EVENT_TOLERANCE;
use crate::joints::stop::{Plane, Spheres};
use crate::joints::Stop;
use crate::model::input::{ContactInput, ContactType};
use crate::model::ModelErrorKind;
use crate::so3::Vec3;

/// The keys of each type of contact, for the error on a key of the other.
const PLANE_KEYS: [&str; 4] = ["node", "point", "normal", "radius"];
const SPHERES_KEYS: [&str; 2] = ["nodes", "radii"];

impl Builder<'_> {
    pub(super) fn contacts(&mut self) {
        let input = self.input;
        // a gap below −tol in the reference configuration is a penetration
        // (tol: the event tolerance of the analysis, of the model's size)
        let tolerance =
            EVENT_TOLERANCE * super::length_scale(input, self.nodes.iter().map(|n| &n.x));
        for c in &input.contacts {
            let entity = format!("contact {}", c.id);
            let id_ok = self.claim_id(&entity, c.id);
            let e = c.restitution.unwrap_or(0.0);
            let mut ok = id_ok;
            if !(0.0..=1.0).contains(&e) {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("restitution must be in [0, 1], got {}", num(e)),
                );
                ok = false;
            }
            let misplaced: Vec<&str> = match c.kind {
                ContactType::Plane => [("nodes", c.nodes.is_some()), ("radii", c.radii.is_some())]
                    .into_iter()
                    .filter_map(|(k, given)| given.then_some(k))
                    .collect(),
                ContactType::Spheres => [
                    ("node", c.node.is_some()),
                    ("point", c.point.is_some()),
                    ("normal", c.normal.is_some()),
                    ("radius", c.radius.is_some()),
                ]
                .into_iter()
                .filter_map(|(k, given)| given.then_some(k))
                .collect(),
            };
            if !misplaced.is_empty() {
                let (keys, other) = match c.kind {
                    ContactType::Plane => (&SPHERES_KEYS[..], "spheres"),
                    ContactType::Spheres => (&PLANE_KEYS[..], "plane"),
                };
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!(
                        "`{}` belong to type = \"{other}\" ({}), not to type = \"{}\"",
                        misplaced.join("`, `"),
                        keys.join(", "),
                        c.kind.name()
                    ),
                );
                ok = false;
            }
            let stop = match c.kind {
                ContactType::Plane => self.plane_contact(&entity, c, e, tolerance),
                ContactType::Spheres => self.spheres_contact(&entity, c, e, tolerance),
            };
            if let (Some(stop), true) = (stop, ok) {
                self.elements.push(Box::new(stop));
            }
        }
    }

    /// A radius: finite and zero or positive.
    fn radius(&mut self, entity: &str, what: &str, r: f64) -> Option<f64> {
        if r.is_finite() && r >= 0.0 {
            Some(r)
        } else {
            self.ck.push(
                ModelErrorKind::NonPositive,
                entity,
                format!("{what} must be zero or positive and finite, got {}", num(r)),
            );
            None
        }
    }

    fn plane_contact(
        &mut self,
        entity: &str,
        c: &ContactInput,
        e: f64,
        tolerance: f64,
    ) -> Option<Stop> {
        let node = match c.node {
            Some(id) => self.node(entity, id),
            None => {
                self.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "a contact with a plane needs `node` (the node at the sphere's centre)",
                );
                None
            }
        };
        let normal = match c.normal {
            Some(n) => self.unit(entity, "normal", n),
            None => {
                self.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "a contact with a plane needs `normal` (the plane's normal, pointing to the sphere's side)",
                );
                None
            }
        };
        let point = Vec3::from(c.point.unwrap_or([0.0; 3]));
        let point_ok = self.ck.finite(entity, "point", point.as_slice());
        let radius = self.radius(entity, "radius", c.radius.unwrap_or(0.0));
        let (Some(node), Some(normal), Some(radius), true) = (node, normal, radius, point_ok)
        else {
            return None;
        };
        let plane = Plane {
            node,
            normal,
            point,
            radius,
        };
        let g = plane.gap(&self.nodes[node].x);
        if g < -tolerance {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "the sphere on node {} penetrates the plane in the reference configuration: its gap n·(x − p) − r is {g:.3e} m (the centre must be at least the radius {} from the plane, on the side of the normal)",
                    self.node_ids[node],
                    num(radius)
                ),
            );
            return None;
        }
        Some(Stop::on_plane(c.id, plane, e))
    }

    fn spheres_contact(
        &mut self,
        entity: &str,
        c: &ContactInput,
        e: f64,
        tolerance: f64,
    ) -> Option<Stop> {
        let Some(ids) = &c.nodes else {
            self.ck.push(
                ModelErrorKind::Missing,
                entity,
                "a contact of spheres needs `nodes` (the two nodes at the spheres' centres)",
            );
            return None;
        };
        if ids.len() != 2 {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("nodes must be two node ids, got {} of them", ids.len()),
            );
            return None;
        }
        let Some(radii) = &c.radii else {
            self.ck.push(
                ModelErrorKind::Missing,
                entity,
                "a contact of spheres needs `radii` (the spheres' radii, [r_a, r_b])",
            );
            return None;
        };
        if radii.len() != 2 {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("radii must be two numbers, got {} of them", radii.len()),
            );
            return None;
        }
        let a = self.node(entity, ids[0]);
        let b = self.node(entity, ids[1]);
        let ra = self.radius(entity, "radii[1]", radii[0]);
        let rb = self.radius(entity, "radii[2]", radii[1]);
        let (Some(a), Some(b), Some(ra), Some(rb)) = (a, b, ra, rb) else {
            return None;
        };
        if ra + rb == 0.0 {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                "radii are both zero: two points touch only where they coincide, where the contact has no normal; give the spheres their radii",
            );
            return None;
        }
        if a == b {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("the two spheres are on the same node {}", ids[0]),
            );
            return None;
        }
        let spheres = Spheres {
            nodes: [a, b],
            radii: [ra, rb],
        };
        let g = spheres.gap(&self.nodes[a].x, &self.nodes[b].x);
        if g < -tolerance {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "the spheres on nodes {} and {} penetrate each other in the reference configuration: their gap |x_b − x_a| − r_a − r_b is {g:.3e} m",
                    ids[0],
                    ids[1]
                ),
            );
            return None;
        }
        Some(Stop::between_spheres(c.id, spheres, e))
    }
}
