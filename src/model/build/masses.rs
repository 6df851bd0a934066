//! `[[rigid_bodies]]` and `[[point_masses]]`.

use super::{Builder, Checker};
use crate::elements::mass::RigidBody;
use crate::model::input::InertiaInput;
use crate::model::ModelErrorKind;
use crate::so3::{Mat3, Vec3};

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
            if let (true, Some(node), true, Some(inertia), true) =
                (id_ok, node, mass_ok, inertia, offset_ok)
            {
                self.elements.push(Box::new(RigidBody::new(
                    rb.id,
                    node,
                    rb.mass,
                    inertia,
                    Vec3::from(offset),
                )));
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
