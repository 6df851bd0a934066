//! `[[supports]]` and `[[prescribed]]`: fixed components of nodes, and
//! prescribed translations and rotations.

use std::collections::HashSet;

use super::curves::RAMP;
use super::Builder;
use crate::model::{ModelErrorKind, Prescribed};
use crate::so3::Vec3;

impl Builder<'_> {
    /// `[[supports]]`.
    pub(super) fn supports(&mut self) {
        self.fixed = vec![[false; 6]; self.nodes.len()];
        for (k, s) in self.input.supports.iter().enumerate() {
            let entity = format!("supports[{}] (node {})", k + 1, s.node);
            let Some(node) = self.node(&entity, s.node) else {
                continue;
            };
            if s.fixed.is_empty() {
                self.ck.push(
                    ModelErrorKind::Missing,
                    &entity,
                    "lists no component to fix",
                );
            }
            for name in &s.fixed {
                match component_set(name) {
                    Some(set) => set.iter().for_each(|&c| self.fixed[node][c] = true),
                    None => self.ck.push(
                        ModelErrorKind::Invalid,
                        &entity,
                        format!(
                            "unknown component \"{name}\" (expected x, y, z, rx, ry, rz, translations, rotations or all)"
                        ),
                    ),
                }
            }
        }
    }

    /// `[[prescribed]]` (which arc-length control does not take).
    pub(super) fn prescribed(&mut self) {
        let mut prescribed_components: HashSet<(usize, usize)> = HashSet::new();
        for (k, p) in self.input.prescribed.iter().enumerate() {
            let entity = format!("prescribed[{}] (node {})", k + 1, p.node);
            let node = self.node(&entity, p.node);
            let curve = self.curve(&entity, &p.curve, RAMP);
            let (Some(node), Some(curve)) = (node, curve) else {
                continue;
            };
            match (&p.dof, p.value, p.rotation) {
                (Some(dof), Some(value), None) => {
                    let axis = match dof.as_str() {
                        "x" => 0,
                        "y" => 1,
                        "z" => 2,
                        _ => {
                            self.ck.push(
                                ModelErrorKind::Invalid,
                                &entity,
                                format!("dof must be x, y or z (use `rotation` for rotations), got \"{dof}\""),
                            );
                            continue;
                        }
                    };
                    if let Some(u) = p.unit {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            format!(
                                "unit = \"{}\" applies to `rotation`, not to a translation",
                                u.name()
                            ),
                        );
                        continue;
                    }
                    if !(self.ck.finite(&entity, "value", &[value])
                        && self.curves.check_range(
                            &mut self.ck,
                            &entity,
                            "value",
                            value.abs(),
                            curve,
                        ))
                    {
                        continue;
                    }
                    if !prescribed_components.insert((node, axis)) {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            format!("component {dof} is prescribed twice"),
                        );
                        continue;
                    }
                    self.fixed[node][axis] = true;
                    self.prescribed.push(Prescribed::Translation {
                        node,
                        axis,
                        value,
                        curve,
                    });
                }
                (None, None, Some(rot)) => {
                    let psi = Vec3::from(rot) * p.unit.unwrap_or_default().radians();
                    if !self.ck.finite(&entity, "rotation", &rot) {
                        continue;
                    }
                    // the exponential map squares the angle
                    let c = &self.curves.curves[curve];
                    let m = c.magnitude(self.curves.end_time);
                    if !(psi.norm() * m).powi(2).is_finite() {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            format!(
                                "a rotation of {:e} rad times curve \"{}\" (up to {m:e}) exceeds the range of floating-point numbers",
                                psi.norm(),
                                c.name()
                            ),
                        );
                        continue;
                    }
                    if !prescribed_components.insert((node, 3)) {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            "the rotation is prescribed twice",
                        );
                        continue;
                    }
                    self.fixed[node][3..].fill(true);
                    self.prescribed
                        .push(Prescribed::Rotation { node, psi, curve });
                }
                _ => self.ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    "give either `dof` and `value` (a translation) or `rotation`",
                ),
            }
        }
        if self.plan.arc_length && !self.input.prescribed.is_empty() {
            self.ck.push(
                ModelErrorKind::Invalid,
                "analysis",
                "arc-length control does not take prescribed motions: use drivers instead",
            );
        }
    }
}

/// Components named by a support entry.
fn component_set(name: &str) -> Option<&'static [usize]> {
    Some(match name {
        "x" => &[0],
        "y" => &[1],
        "z" => &[2],
        "rx" => &[3],
        "ry" => &[4],
        "rz" => &[5],
        "translations" => &[0, 1, 2],
        "rotations" => &[3, 4, 5],
        "all" => &[0, 1, 2, 3, 4, 5],
        _ => return None,
    })
}
