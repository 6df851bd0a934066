//! `[[springs]]`: linear springs between two nodes or to the ground, with
//! an optional damper in parallel given by its coefficients or by a
//! damping ratio.

use super::Builder;
use crate::elements::spring::{Spring, SpringKind};
use crate::model::input::{InertiaInput, StiffnessInput};
use crate::model::{Id, ModelErrorKind};
use crate::so3::{self, Mat3, Rotation, Vec3};

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
            let Some(c) = self.spring_damping(&entity, s, k, &r0) else {
                continue;
            };
            match Spring::new(s.id, s.kind, &idx, &x0, &r0, Vec3::from(k)) {
                Some(sp) => self.elements.push(Box::new(sp.with_damping(c))),
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

impl Builder<'_> {
    /// The damper coefficients of spring `s` (zero without a damper), from
    /// `damping` or from `damping_ratio`; `None` after an input error.
    fn spring_damping(
        &mut self,
        entity: &str,
        s: &crate::model::input::SpringInput,
        k: [f64; 3],
        r0: &[Rotation],
    ) -> Option<Vec3> {
        match (&s.damping, s.damping_ratio) {
            (None, None) => Some(Vec3::zeros()),
            (Some(_), Some(_)) => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "give `damping` (the coefficients) or `damping_ratio`, not both",
                );
                None
            }
            (Some(c), None) => {
                let c = match *c {
                    StiffnessInput::Isotropic(c) => [c; 3],
                    StiffnessInput::PerAxis(c) if s.kind != SpringKind::Axial => c,
                    StiffnessInput::PerAxis(_) => {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            entity,
                            "an axial spring's damper takes a single coefficient",
                        );
                        return None;
                    }
                };
                let ok = c
                    .iter()
                    .all(|&v| self.ck.non_negative(entity, "damping", v));
                ok.then(|| Vec3::from(c))
            }
            (None, Some(zeta)) => {
                if !self.ck.non_negative(entity, "damping_ratio", zeta) {
                    return None;
                }
                let m = self.spring_mass(entity, s, r0)?;
                // c = 2ζ√(k m), axis by axis
                Some(Vec3::from_fn(|i, _| 2.0 * zeta * (k[i] * m[i]).sqrt()))
            }
        }
    }

    /// The mass (translational and axial springs) or the inertia about
    /// each axis (rotational springs) that a damping ratio refers to: that
    /// of the point masses and rigid bodies on the spring's node, or the
    /// reduced value `m_a m_b/(m_a + m_b)` of its two nodes; a node with no
    /// mass of its own is taken as anchored (docs/model-format.md).
    fn spring_mass(
        &mut self,
        entity: &str,
        s: &crate::model::input::SpringInput,
        r0: &[Rotation],
    ) -> Option<Vec3> {
        let rotational = s.kind == SpringKind::Rotational;
        // each node's mass, or its inertia tensor about the node in the
        // spring's axes (node a's material frame; global to ground)
        let to_axes = |i: usize| -> Mat3 {
            if s.nodes.len() == 1 {
                so3::matrix(&r0[0])
            } else {
                so3::matrix(&(r0[0].inverse() * r0[i]))
            }
        };
        let per_node: Vec<Vec3> = s
            .nodes
            .iter()
            .enumerate()
            .map(|(i, &node)| {
                let (m, j) = self.carried(node);
                if rotational {
                    let r = to_axes(i);
                    (r * j * r.transpose()).diagonal()
                } else {
                    Vec3::repeat(m)
                }
            })
            .collect();
        let reduced = |a: f64, b: f64| match (a > 0.0, b > 0.0) {
            (true, true) => a * b / (a + b),
            (true, false) => a,
            _ => b,
        };
        let m = match per_node.as_slice() {
            [b] => *b,
            [a, b] => Vec3::from_fn(|i, _| reduced(a[i], b[i])),
            _ => return None,
        };
        let axes = if s.kind == SpringKind::Axial { 1 } else { 3 };
        if let Some(axis) = (0..axes).find(|&i| m[i] <= 0.0) {
            let nodes = s
                .nodes
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(" and ");
            let what = if rotational {
                format!("an inertia about axis {} of the spring", axis + 1)
            } else {
                "a mass".to_string()
            };
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "damping_ratio needs {what} on node {nodes}: no point mass or rigid body there provides one (give the coefficient with `damping` instead)"
                ),
            );
            return None;
        }
        Some(m)
    }

    /// Mass and inertia tensor about the node (node material frame) of the
    /// point masses and rigid bodies on node `node`: `J_c + m(|c|² I − c cᵀ)`
    /// for a body whose centre of mass is at `c`.
    fn carried(&self, node: Id) -> (f64, Mat3) {
        let mut m = 0.0;
        let mut j = Mat3::zeros();
        for rb in self.input.rigid_bodies.iter().filter(|b| b.node == node) {
            let jc = match &rb.inertia {
                None => Mat3::zeros(),
                Some(InertiaInput::Diagonal(d)) => Mat3::from_diagonal(&Vec3::from(*d)),
                Some(InertiaInput::Full(r)) => Mat3::from_fn(|i, k| r[i][k]),
            };
            let c = Vec3::from(rb.center_of_mass.unwrap_or([0.0; 3]));
            m += rb.mass;
            j += jc + (Mat3::identity() * c.norm_squared() - c * c.transpose()) * rb.mass;
        }
        for pm in self.input.point_masses.iter().filter(|p| p.node == node) {
            m += pm.mass;
        }
        (m, j)
    }
}
