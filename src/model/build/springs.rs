//! `[[springs]]`: linear springs between two nodes or to the ground.

use super::Builder;
use crate::elements::spring::{Spring, SpringKind};
use crate::model::input::StiffnessInput;
use crate::model::ModelErrorKind;
use crate::so3::{Rotation, Vec3};

impl Builder<'_> {
    /// `[[springs]]`.
    pub(super) fn springs(&mut self) {
        let input = self.input;
        for s in &input.springs {
            let entity = format!("spring {}", s.id);
            let id_ok = self.claim_id(&entity, s.id);
            if s.nodes.is_empty() || s.nodes.len() > 2 {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!(
                        "needs one node (spring to ground) or two nodes, got {}",
                        s.nodes.len()
                    ),
                );
                continue;
            }
            if s.nodes.len() == 2 && s.nodes[0] == s.nodes[1] {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("connects node {} to itself", s.nodes[0]),
                );
                continue;
            }
            let idx: Vec<Option<usize>> = s.nodes.iter().map(|&n| self.node(&entity, n)).collect();
            let k = match s.stiffness {
                StiffnessInput::Isotropic(k) => [k; 3],
                StiffnessInput::PerAxis(k) => {
                    if s.kind == SpringKind::Axial {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            "an axial spring takes a single stiffness value",
                        );
                        continue;
                    }
                    k
                }
            };
            let k_ok = k.iter().all(|&v| self.ck.positive(&entity, "stiffness", v));
            if !(id_ok && k_ok) || idx.iter().any(|i| i.is_none()) {
                continue;
            }
            let idx: Vec<usize> = idx.into_iter().flatten().collect();
            let x0: Vec<Vec3> = idx.iter().map(|&i| self.nodes[i].x).collect();
            let r0: Vec<Rotation> = idx.iter().map(|&i| self.nodes[i].q).collect();
            match Spring::new(s.id, s.kind, &idx, &x0, &r0, Vec3::from(k)) {
                Some(sp) => self.elements.push(Box::new(sp)),
                None if idx.len() == 1 => self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    "an axial spring needs two nodes",
                ),
                None => self.ck.push(
                    ModelErrorKind::ZeroLength,
                    &entity,
                    format!(
                        "zero length: nodes {} and {} coincide",
                        s.nodes[0], s.nodes[1]
                    ),
                ),
            }
        }
    }
}
