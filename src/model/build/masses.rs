//! `[[rigid_bodies]]` and `[[point_masses]]`.

use super::{AngleLimit, Builder, Checker};
use crate::elements::mass::RigidBody;
use crate::elements::shape::{BodyShape, Solid};
use crate::model::input::{InertiaInput, ShapeInput, ShapeKind};
use crate::model::ModelErrorKind;
use crate::so3::{self, Mat3, Vec3};

impl Builder<'_> {
    /// `[[rigid_bodies]]` and `[[point_masses]]`.
    pub(super) fn masses(&mut self) {
        let input = self.input;
        for rb in &input.rigid_bodies {
            if self.absorbed_elements.contains(&rb.id) {
                continue;
            }
            let entity = format!("rigid body {}", rb.id);
            let id_ok = self.claim_id(&entity, rb.id);
            let node = self.node(&entity, rb.node);
            let mass_ok = self.ck.positive(&entity, "mass", rb.mass);
            let inertia = match &rb.inertia {
                None => Some(Mat3::zeros()),
                Some(i) => inertia_tensor(&mut self.ck, &entity, i),
            };
            let offset = rb.center_of_mass.unwrap_or([0.0; 3]);
            let offset_ok = self.ck.finite(&entity, "center_of_mass", &offset);
            let shape = match &rb.shape {
                None => Some(None),
                Some(s) => body_shape(&mut self.ck, &entity, s, Vec3::from(offset)).map(Some),
            };
            if let (true, Some(node), true, Some(inertia), true, Some(shape)) =
                (id_ok, node, mass_ok, inertia, offset_ok, shape)
            {
                let body = RigidBody::new(rb.id, node, rb.mass, inertia, Vec3::from(offset));
                self.elements.push(Box::new(match shape {
                    Some(s) => body.with_shape(s),
                    None => body,
                }));
            }
        }
        for pm in &input.point_masses {
            if self.absorbed_elements.contains(&pm.id) {
                continue;
            }
            let entity = format!("point mass {}", pm.id);
            let id_ok = self.claim_id(&entity, pm.id);
            let node = self.node(&entity, pm.node);
            let mass_ok = self.ck.positive(&entity, "mass", pm.mass);
            if let (true, Some(node), true) = (id_ok, node, mass_ok) {
                self.elements
                    .push(Box::new(RigidBody::point_mass(pm.id, node, pm.mass)));
            }
        }
    }
}

/// Validated inertia tensor: symmetric, positive semi-definite.
fn inertia_tensor(ck: &mut Checker, entity: &str, i: &InertiaInput) -> Option<Mat3> {
    let m = match i {
        InertiaInput::Diagonal(d) => Mat3::from_diagonal(&Vec3::from(*d)),
        InertiaInput::Full(rows) => Mat3::from_fn(|r, c| rows[r][c]),
    };
    let flat: Vec<f64> = m.iter().copied().collect();
    if !ck.finite(entity, "inertia", &flat) {
        return None;
    }
    if (m - m.transpose()).abs().max() > 1e-9 * m.abs().max() {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "the inertia tensor is not symmetric",
        );
        return None;
    }
    let eig = m.symmetric_eigenvalues();
    if eig.iter().any(|&e| e < -1e-12 * m.abs().max()) {
        ck.push(
            ModelErrorKind::NonPositive,
            entity,
            format!(
                "the inertia tensor must be positive semi-definite, eigenvalues {:?}",
                eig.as_slice()
            ),
        );
        return None;
    }
    Some(m)
}

/// The validated shape of a rigid body (`shape = { … }`); `offset` its
/// centre of mass, the shape's default centre. Each dimension the kind
/// needs must be given and positive (a plate's thickness and a cylinder's
/// length may be zero), and none it does not take may be given.
fn body_shape(ck: &mut Checker, entity: &str, s: &ShapeInput, offset: Vec3) -> Option<BodyShape> {
    let kind = s.kind.name();
    let (takes, needs): (&[&str], &str) = match s.kind {
        ShapeKind::Box => (&["size"], "size = [a, b, c], its edges"),
        ShapeKind::Plate => (
            &["size", "thickness"],
            "size = [a, b], its edges, and optionally thickness",
        ),
        ShapeKind::Cylinder => (&["radius", "length"], "radius and length"),
        ShapeKind::Point => (&[], "no dimension"),
    };
    let mut ok = true;
    let given = [
        ("size", s.size.is_some()),
        ("thickness", s.thickness.is_some()),
        ("radius", s.radius.is_some()),
        ("length", s.length.is_some()),
    ];
    for (name, present) in given {
        if present && !takes.contains(&name) {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("shape: a {kind} has no {name} (it takes {needs})"),
            );
            ok = false;
        }
    }
    // the dimensions: `count` edges, or one length, each checked
    let mut edges = |count: usize| -> Option<Vec<f64>> {
        match &s.size {
            Some(v) if v.len() == count => {
                let mut all = true;
                for &e in v {
                    all &= ck.positive(entity, "shape size (every edge)", e);
                }
                all.then(|| v.clone())
            }
            Some(v) => {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "shape: a {kind} takes {count} edges in size, got {}",
                        v.len()
                    ),
                );
                None
            }
            None => {
                ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    format!("shape: a {kind} needs {needs}"),
                );
                None
            }
        }
    };
    let solid = match s.kind {
        ShapeKind::Box => edges(3).map(|e| Solid::Box {
            size: [e[0], e[1], e[2]],
        }),
        ShapeKind::Plate => {
            let e = edges(2);
            let t = s.thickness.unwrap_or(0.0);
            let t_ok = ck.non_negative(entity, "shape thickness", t);
            e.filter(|_| t_ok).map(|e| Solid::Plate {
                size: [e[0], e[1]],
                thickness: t,
            })
        }
        ShapeKind::Cylinder => match (s.radius, s.length) {
            (Some(r), Some(l)) => {
                let r_ok = ck.positive(entity, "shape radius", r);
                let l_ok = ck.non_negative(entity, "shape length", l);
                (r_ok && l_ok).then_some(Solid::Cylinder {
                    radius: r,
                    length: l,
                })
            }
            _ => {
                ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    format!("shape: a cylinder needs {needs}"),
                );
                None
            }
        },
        ShapeKind::Point => Some(Solid::Point),
    };
    let center = s.center.map_or(offset, Vec3::from);
    ok &= ck.finite(entity, "shape center", center.as_slice());
    let rotation = s.rotation.unwrap_or([0.0; 3]);
    ok &= ck.finite(entity, "shape rotation", &rotation);
    let psi = Vec3::from(rotation) * s.unit.unwrap_or_default().radians();
    if ok && !psi.norm_squared().is_finite() {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            format!("shape rotation {rotation:?} is too large"),
        );
        ok = false;
    }
    if ok && s.unit.is_none() {
        ck.unitless_angle(
            entity,
            "shape rotation has the length",
            psi.norm(),
            AngleLimit::HalfTurn,
        );
    }
    let solid = solid?;
    ok.then(|| BodyShape::new(solid, center, so3::exp_matrix(&psi)))
}
