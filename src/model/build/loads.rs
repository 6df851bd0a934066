//! `[[loads]]` and `[gravity]`: nodal forces and moments, and the uniform
//! gravity field, each following a curve.

use super::{num, Builder};
use crate::curves::CurveIndex;
use crate::elements::load::NodalLoad;
use crate::model::input::Id;
use crate::model::ModelErrorKind;
use crate::so3::Vec3;

impl Builder<'_> {
    /// `[[loads]]`.
    pub(super) fn loads(&mut self) {
        let default = self.load_default();
        for (k, l) in self.input.loads.iter().enumerate() {
            let entity = format!("loads[{}] (node {})", k + 1, l.node);
            let node = self.node(&entity, l.node);
            let curve = self.curve(&entity, &l.curve, default);
            if l.force.is_none() && l.moment.is_none() {
                self.ck.push(
                    ModelErrorKind::Missing,
                    &entity,
                    "needs a force, a moment or both",
                );
                continue;
            }
            let f = l.force.unwrap_or([0.0; 3]);
            let m = l.moment.unwrap_or([0.0; 3]);
            let mut ok =
                self.ck.finite(&entity, "force", &f) & self.ck.finite(&entity, "moment", &m);
            if let (Some(c), true) = (curve, ok) {
                ok &= self.curves.check_range(
                    &mut self.ck,
                    &entity,
                    "force",
                    Vec3::from(f).amax(),
                    c,
                ) & self.curves.check_range(
                    &mut self.ck,
                    &entity,
                    "moment",
                    Vec3::from(m).amax(),
                    c,
                );
            }
            if ok && l.curve.is_none() {
                self.ramp_through_dynamics(&entity);
            }
            if let (Some(node), Some(curve), true) = (node, curve, ok) {
                self.elements.push(Box::new(NodalLoad::new(
                    (k + 1) as Id,
                    node,
                    Vec3::from(f),
                    Vec3::from(m),
                    l.follower,
                    curve,
                )));
            }
        }
    }

    /// `[gravity]`, with warnings where its curve makes the loads of the
    /// drivers a fraction of the real ones.
    pub(super) fn gravity(&mut self) -> Option<(Vec3, CurveIndex)> {
        let g = self.input.gravity.as_ref()?;
        let curve = self.curve("gravity", &g.curve, self.load_default());
        let ok = self.ck.finite("gravity", "acceleration", &g.acceleration);
        let (curve, true) = (curve?, ok) else {
            return None;
        };
        let a = Vec3::from(g.acceleration);
        if !self
            .curves
            .check_range(&mut self.ck, "gravity", "acceleration", a.amax(), curve)
        {
            return None;
        }
        if a.norm() > 0.0 && self.elements.iter().all(|e| e.mass() == 0.0) {
            self.ck.warn(
                "gravity",
                "acts on no mass: no beam's section has mass_per_length and the model has no rigid body or point mass, so gravity loads nothing; give the masses, or remove [gravity]",
            );
        }
        let end = self.curves.end_time;
        let c = &self.curves.curves[curve];
        let has_drivers = !self.input.drivers.is_empty();
        if a.norm() > 0.0 && self.plan.kinematic && !c.is_constant_on(end) {
            self.ck.warn(
                "gravity",
                format!(
                    "follows curve \"{}\" in a kinematic analysis: the loads of the drivers and joints are those of a gravity scaled by f(t), not of the full gravity (use curve = \"constant\", the default)",
                    c.name()
                ),
            );
        } else if a.norm() > 0.0
            && !self.plan.kinematic
            && !self.plan.first_dynamic
            && has_drivers
            && g.curve.is_none()
        {
            self.ck.warn(
                "gravity",
                "follows the default ramp f = t while drivers move the model: their loads before the end include only f(t) of the gravity; write curve = \"ramp\" to confirm, or curve = \"constant\" for the full gravity throughout",
            );
        }
        if a.norm() > 0.0 && g.curve.is_none() {
            self.ramp_through_dynamics("gravity");
        }
        Some((a, curve))
    }

    /// A warning for a load or gravity (`entity`) without a curve in a
    /// sequence whose first analysis is static and a later one dynamic:
    /// the default ramp `f = t` goes on growing through the motion
    /// (docs/model-format.md, "Loads in time").
    pub(super) fn ramp_through_dynamics(&mut self, entity: &str) {
        let Some((analysis, start, end)) = self.plan.dynamic_after_static.clone() else {
            return;
        };
        if self.plan.first_dynamic || self.plan.kinematic || start <= 0.0 {
            return;
        }
        self.ck.warn(
            entity,
            format!(
                "follows the default ramp f = t, which goes on growing through the dynamic {analysis} (t = {} to {}): the load there grows from {} to {} times its full value; give it a curve (a preload held: points = [[0, 0], [{}, 1], [{}, 1]]), or write curve = \"ramp\" to confirm",
                num(start),
                num(end),
                num(start),
                num(end),
                num(start),
                num(end),
            ),
        );
    }
}
