//! `[[supports]]` and `[[prescribed]]`: fixed components of nodes, and
//! prescribed translations and rotations.

use std::collections::{HashMap, HashSet};

use super::curves::RAMP;
use super::{AngleLimit, Builder};
use crate::curves::CurveIndex;
use crate::model::{ModelErrorKind, Prescribed};
use crate::so3::Vec3;

impl Builder<'_> {
    /// `[[supports]]`, with a warning for a component fixed twice.
    pub(super) fn supports(&mut self) {
        self.fixed = vec![[false; 6]; self.nodes.len()];
        // the entry that first fixed each component
        let mut fixed_by: HashMap<(usize, usize), usize> = HashMap::new();
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
            // components fixed again: (component, entry that fixed it first)
            let mut again: Vec<(usize, usize)> = Vec::new();
            for name in &s.fixed {
                match component_set(name) {
                    Some(set) => {
                        for &c in set {
                            let first = *fixed_by.entry((node, c)).or_insert(k);
                            if self.fixed[node][c] && !again.iter().any(|a| a.0 == c)
                            {
                                again.push((c, first));
                            }
                            self.fixed[node][c] = true;
                        }
                    }
                    None => self.ck.push(
                        ModelErrorKind::Invalid,
                        &entity,
                        format!(
                            "unknown component \"{name}\" (expected x, y, z, rx, ry, rz, translations, rotations or all)"
                        ),
                    ),
                }
            }
            if !again.is_empty() {
                let names: Vec<&str> = again.iter().map(|a| COMPONENT_NAMES[a.0]).collect();
                let mut firsts: Vec<usize> = again.iter().map(|a| a.1).collect();
                firsts.dedup();
                let by: Vec<String> = firsts
                    .iter()
                    .map(|&j| {
                        if j == k {
                            "this entry".to_string()
                        } else {
                            format!("supports[{}]", j + 1)
                        }
                    })
                    .collect();
                self.ck.warn(
                    &entity,
                    format!(
                        "fixes {} again, already fixed by {}: harmless, but perhaps another node or component was meant",
                        names.join(", "),
                        by.join(" and ")
                    ),
                );
            }
        }
    }

    /// `[[prescribed]]` (which arc-length control does not take).
    pub(super) fn prescribed(&mut self) {
        let mut prescribed_components: HashSet<(usize, usize)> = HashSet::new();
        // the components fixed by supports (prescribed ones are added below)
        let supported = self.fixed.clone();
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
                    if supported[node][axis] {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            format!(
                                "component {dof} of node {} is also fixed by a support, which holds it at zero while this moves it: remove it from the support or remove this entry",
                                p.node
                            ),
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
                    let held: Vec<&str> = (3..6)
                        .filter(|&c| supported[node][c])
                        .map(|c| COMPONENT_NAMES[c])
                        .collect();
                    if !held.is_empty() {
                        self.ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            format!(
                                "the rotation of node {} is prescribed, but {} {} also fixed by a support, which holds {} at zero: remove {} from the support or remove this entry",
                                p.node,
                                held.join(", "),
                                if held.len() == 1 { "is" } else { "are" },
                                if held.len() == 1 { "it" } else { "them" },
                                if held.len() == 1 { "it" } else { "them" },
                            ),
                        );
                        continue;
                    }
                    // a rotation meant in degrees: the per-increment
                    // warning, when it applies, already says so
                    if !self.warn_fast_rotation(&entity, psi.norm(), curve, p.unit.is_none())
                        && p.unit.is_none()
                    {
                        self.ck.unitless_angle(
                            &entity,
                            "rotation reaches",
                            psi.norm() * m,
                            AngleLimit::HalfTurn,
                        );
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

impl Builder<'_> {
    /// Warns when a prescribed rotation of angle `angle` following `curve`
    /// changes by more than half a turn over one of the largest increments:
    /// within an increment the analysis cannot tell it from the same
    /// rotation less a full turn (docs/model-format.md, `[[prescribed]]`),
    /// so load control limits its increments
    /// (`Model::rotation_step_limit`); the warning suggests degrees if the
    /// rotation has no `unit`. Whether it warned.
    fn warn_fast_rotation(
        &mut self,
        entity: &str,
        angle: f64,
        curve: CurveIndex,
        unitless: bool,
    ) -> bool {
        let Some(h) = self.plan.max_increment else {
            return false;
        };
        if !(h.is_finite() && h > 0.0) {
            return false;
        }
        let change = angle * self.curves.curves[curve].largest_change(h, self.curves.end_time);
        if change > std::f64::consts::PI {
            let hint = if unitless {
                " If the rotation is in degrees, write unit = \"deg\"."
            } else {
                ""
            };
            self.ck.warn(
                entity,
                format!(
                    "turns the node by up to {change:.4} rad ({:.1}°) in one increment of t = {h} (max_increment): more than half a turn, which an increment cannot tell from the same rotation less a full turn; load increments are limited to {:.3e} (a quarter turn each).{hint}",
                    change.to_degrees(),
                    self.curves.curves[curve].largest_step(
                        angle,
                        std::f64::consts::FRAC_PI_2,
                        self.curves.end_time
                    )
                ),
            );
            return true;
        }
        false
    }
}

/// Names of the six components of a node.
const COMPONENT_NAMES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

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
