//! Initial velocities: `velocity` and `angular_velocity` of `[[nodes]]`,
//! and the rigid motions of `[[initial_motion]]` (global frame).

use super::Builder;
use crate::model::ModelErrorKind;
use crate::so3::Vec3;

impl Builder<'_> {
    /// The initial velocity `(ẋ, ω)` of every node (global): finite
    /// values, known nodes, each node given one velocity at most.
    pub(super) fn initial_velocities(&mut self) -> Vec<[f64; 6]> {
        let mut out = vec![[0.0; 6]; self.nodes.len()];
        let mut given: Vec<Option<String>> = vec![None; self.nodes.len()];
        for n in &self.input.nodes {
            if n.velocity.is_none() && n.angular_velocity.is_none() {
                continue;
            }
            let entity = format!("node {}", n.id);
            let (v, w) = (
                n.velocity.unwrap_or([0.0; 3]),
                n.angular_velocity.unwrap_or([0.0; 3]),
            );
            let ok = self.ck.finite(&entity, "velocity", &v)
                & self.ck.finite(&entity, "angular_velocity", &w);
            let Some(&i) = self.node_index.get(&n.id) else {
                if let Some(holder) = self.absorbed_nodes.get(&n.id) {
                    self.ck.warn(
                        &entity,
                        format!("is inside {holder}: its initial velocity is not used (a superelement starts with the velocities of its boundary nodes, its modes at rest)"),
                    );
                }
                continue;
            };
            if ok {
                out[i] = [v[0], v[1], v[2], w[0], w[1], w[2]];
                given[i] = Some(entity);
            }
        }
        for (k, m) in self.input.initial_motion.iter().enumerate() {
            let entity = format!("initial_motion[{}]", k + 1);
            let (v, w, about) = (
                m.velocity.unwrap_or([0.0; 3]),
                m.angular_velocity.unwrap_or([0.0; 3]),
                m.about.unwrap_or([0.0; 3]),
            );
            let ok = self.ck.finite(&entity, "velocity", &v)
                & self.ck.finite(&entity, "angular_velocity", &w)
                & self.ck.finite(&entity, "about", &about);
            if m.nodes.is_empty() {
                self.ck
                    .push(ModelErrorKind::Missing, &entity, "nodes: no node given");
            }
            let (v, w, about) = (Vec3::from(v), Vec3::from(w), Vec3::from(about));
            for id in &m.nodes {
                let Some(&i) = self.node_index.get(id) else {
                    if !self.invalid_nodes.contains(id) {
                        let message = match self.absorbed_nodes.get(id) {
                            Some(holder) => format!("nodes: node {id} is inside {holder}, reduced away: list its boundary nodes"),
                            None => format!("nodes: node {id} does not exist"),
                        };
                        self.ck.push(ModelErrorKind::UnknownNode, &entity, message);
                    }
                    continue;
                };
                if let Some(first) = &given[i] {
                    // the first is the node's own entry or an earlier
                    // initial_motion
                    let from = if first.starts_with("node ") {
                        "its [[nodes]] entry (velocity, angular_velocity)".to_string()
                    } else {
                        first.clone()
                    };
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        &entity,
                        format!("node {id} already has an initial velocity from {from}; give each node its initial velocity once"),
                    );
                    continue;
                }
                if ok {
                    // v(x) = v + ω × (x − about)
                    let vi = v + w.cross(&(self.nodes[i].x - about));
                    out[i] = [vi.x, vi.y, vi.z, w.x, w.y, w.z];
                    given[i] = Some(entity.clone());
                }
            }
        }
        // a supported component does not move: its velocity must be zero
        // (rotations are fixed about the node's material axes)
        const AXES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];
        for (i, entity) in given.iter().enumerate() {
            let (Some(entity), Some(fixed)) = (entity, self.fixed.get(i)) else {
                continue;
            };
            let v = &out[i];
            let w = Vec3::new(v[3], v[4], v[5]);
            let w_material = self.nodes[i].q.inverse() * w;
            let scale = w.norm();
            for (c, &f) in fixed.iter().enumerate() {
                let moving = if c < 3 {
                    v[c] != 0.0
                } else {
                    w_material[c - 3].abs() > 1e-12 * scale
                };
                if f && moving {
                    // the node is named once: by the entity, or after an
                    // initial_motion that lists it
                    let node = if entity.starts_with("node ") {
                        "the node".to_string()
                    } else {
                        format!("node {}", self.node_ids[i])
                    };
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!(
                            "{node} is supported in {} but is given {} there; a supported component does not move",
                            AXES[c],
                            if c < 3 {
                                "a velocity"
                            } else {
                                "an angular velocity"
                            }
                        ),
                    );
                }
            }
        }
        out
    }
}
