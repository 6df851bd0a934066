//! `[[ply_materials]]`, `[[laminates]]`, `[[shells]]` and `[[panels]]`:
//! the shell elements, their sections, and the panel mesher (a
//! rectangular panel of shells with property zones, edge stiffeners and
//! named nodes, docs/model-format.md).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::Arc;

use super::{AngleLimit, Builder, NodeData, MAX_MODEL_SIZE};
use crate::curves::CurveIndex;
use crate::elements::beam::{Beam, BeamSection, InitialStrain, SectionStiffness};
use crate::elements::laminate::{Core, Laminate, LaminateError, Ply, PlyMaterial};
use crate::elements::load::NodalLoad;
use crate::elements::shell::Shell;
use crate::elements::Element;
use crate::model::input::{
    Id, LaminateInput, PanelInput, PanelPoint, PanelSide, PlyInput, PlyMaterialInput, MAX_ID,
};
use crate::model::ModelErrorKind;
use crate::so3::{skew, Rotation, Vec3};

/// The laminates and ply materials read so far, and what the shells
/// loaded by a pressure put on their nodes.
#[derive(Default)]
pub(super) struct ShellTables {
    materials: HashMap<String, PlyMaterial>,
    invalid_materials: HashSet<String>,
    laminates: HashMap<String, Arc<Laminate>>,
    /// The plies of the laminates that are stacks (for the faces of
    /// sandwiches).
    stacks: HashMap<String, Vec<Ply>>,
    invalid_laminates: HashSet<String>,
    /// Pressure loads by node and curve: the nodal forces `p n ∫Nᵢ dA`.
    pressure: BTreeMap<(usize, CurveIndex), Vec3>,
}

impl Builder<'_> {
    /// `[[ply_materials]]`.
    pub(super) fn ply_materials(&mut self) {
        for m in &self.input.ply_materials {
            let entity = format!("ply_material \"{}\"", m.name);
            let t = &mut self.shell_tables;
            if t.materials.contains_key(&m.name) || t.invalid_materials.contains(&m.name) {
                self.ck
                    .push(ModelErrorKind::DuplicateId, &entity, "duplicate name");
                continue;
            }
            match self.ply_material(&entity, m) {
                Some(p) => {
                    self.shell_tables.materials.insert(m.name.clone(), p);
                }
                None => {
                    self.shell_tables.invalid_materials.insert(m.name.clone());
                }
            }
        }
    }

    fn ply_material(&mut self, entity: &str, m: &PlyMaterialInput) -> Option<PlyMaterial> {
        let orthotropic = [
            ("E1", m.e1),
            ("E2", m.e2),
            ("nu12", m.nu12),
            ("G12", m.g12),
            ("G13", m.g13),
            ("G23", m.g23),
        ];
        let isotropic = [("E", m.e), ("nu", m.nu)];
        let given = |list: &[(&'static str, Option<f64>)]| -> Vec<&'static str> {
            list.iter().filter(|v| v.1.is_some()).map(|v| v.0).collect()
        };
        let (o, i) = (given(&orthotropic), given(&isotropic));
        let density = m.density.unwrap_or(0.0);
        let result = match (o.is_empty(), i.is_empty()) {
            (false, false) => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "give either the orthotropic E1, E2, nu12, G12, G13, G23 or the isotropic E, nu, not both (found {} and {})",
                        o.join(", "),
                        i.join(", ")
                    ),
                );
                return None;
            }
            (true, true) => {
                self.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "no moduli: give E1, E2, nu12, G12, G13, G23 (orthotropic) or E, nu (isotropic)",
                );
                return None;
            }
            (false, true) => {
                let missing: Vec<&str> = orthotropic
                    .iter()
                    .filter(|v| v.1.is_none())
                    .map(|v| v.0)
                    .collect();
                if !missing.is_empty() {
                    self.ck.push(
                        ModelErrorKind::Missing,
                        entity,
                        format!("missing {}", missing.join(", ")),
                    );
                    return None;
                }
                let v = orthotropic.map(|v| v.1.unwrap());
                PlyMaterial::orthotropic(v[0], v[1], v[2], v[3], v[4], v[5], density)
            }
            (true, false) => {
                let (Some(e), Some(nu)) = (m.e, m.nu) else {
                    let missing = if m.e.is_none() { "E" } else { "nu" };
                    self.ck.push(
                        ModelErrorKind::Missing,
                        entity,
                        format!("missing {missing}"),
                    );
                    return None;
                };
                PlyMaterial::isotropic(e, nu, density)
            }
        };
        result.map_err(|e| self.laminate_error(entity, e)).ok()
    }

    /// Reports a laminate error at `entity`.
    fn laminate_error(&mut self, entity: &str, e: LaminateError) {
        let kind = match &e {
            LaminateError::Empty => ModelErrorKind::Missing,
            LaminateError::NotFinite { .. } | LaminateError::Poisson { .. } => {
                ModelErrorKind::Invalid
            }
            _ => ModelErrorKind::NonPositive,
        };
        self.ck.push(kind, entity, e.to_string());
    }

    /// `[[laminates]]`: the stacks first, then the sandwiches (whose faces
    /// are stacks, defined anywhere in the file).
    pub(super) fn laminates(&mut self) {
        let input = self.input;
        let mut seen = HashSet::new();
        for (pass, sandwiches) in [(0, false), (1, true)] {
            for l in &input.laminates {
                let entity = format!("laminate \"{}\"", l.name);
                if pass == 0 && !seen.insert(l.name.clone()) {
                    self.ck
                        .push(ModelErrorKind::DuplicateId, &entity, "duplicate name");
                    self.shell_tables.invalid_laminates.insert(l.name.clone());
                    continue;
                }
                let is_sandwich = l.core.is_some() || faces_given(l);
                if is_sandwich != sandwiches || self.shell_tables.has_laminate(&l.name) {
                    continue;
                }
                let built = if sandwiches {
                    self.sandwich(&entity, l)
                } else {
                    self.stack(&entity, l)
                };
                match built {
                    Some(lam) => {
                        self.shell_tables
                            .laminates
                            .insert(l.name.clone(), Arc::new(lam));
                    }
                    None => {
                        self.shell_tables.invalid_laminates.insert(l.name.clone());
                    }
                }
            }
        }
    }

    /// The plies of `l` (materials resolved, angles in radians).
    fn plies(&mut self, entity: &str, l: &LaminateInput, plies: &[PlyInput]) -> Option<Vec<Ply>> {
        let unit = l.unit.map_or(1.0, |u| u.radians());
        let mut out = Vec::with_capacity(plies.len());
        let mut ok = true;
        for (k, p) in plies.iter().enumerate() {
            let angle = p.angle.unwrap_or(0.0);
            if l.unit.is_none() && angle.is_finite() {
                self.ck.unitless_angle(
                    entity,
                    &format!("ply {} has the angle", k + 1),
                    angle,
                    AngleLimit::HalfTurn,
                );
            }
            match self.shell_tables.materials.get(&p.material) {
                Some(m) => out.push(Ply::new(*m, p.thickness, angle * unit)),
                None => {
                    if !self.shell_tables.invalid_materials.contains(&p.material) {
                        self.ck.push(
                            ModelErrorKind::UnknownLaminate,
                            entity,
                            format!(
                                "ply {}: ply material \"{}\" is not defined (see [[ply_materials]])",
                                k + 1,
                                p.material
                            ),
                        );
                    }
                    ok = false;
                }
            }
        }
        ok.then_some(out)
    }

    fn stack(&mut self, entity: &str, l: &LaminateInput) -> Option<Laminate> {
        let plies = self.plies(entity, l, &l.plies)?;
        match Laminate::stack(&plies) {
            Ok(lam) => {
                self.shell_tables.stacks.insert(l.name.clone(), plies);
                Some(lam)
            }
            Err(e) => {
                self.laminate_error(entity, e);
                None
            }
        }
    }

    fn sandwich(&mut self, entity: &str, l: &LaminateInput) -> Option<Laminate> {
        if !l.plies.is_empty() {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                "give either plies (a stack) or a core with its faces (a sandwich), not both",
            );
            return None;
        }
        let Some(core) = &l.core else {
            self.ck.push(
                ModelErrorKind::Missing,
                entity,
                "has faces but no core: a sandwich needs a core (or give plies for a stack)",
            );
            return None;
        };
        let (bottom, top) = match (&l.faces, &l.bottom_face, &l.top_face) {
            (Some(f), None, None) => (f.clone(), f.clone()),
            (None, Some(b), Some(t)) => (b.clone(), t.clone()),
            (None, None, None) => {
                self.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "a sandwich needs its face sheets: faces = \"<laminate>\" (both), or bottom_face and top_face",
                );
                return None;
            }
            _ => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "give faces (both face sheets alike) or both bottom_face and top_face, not a mix",
                );
                return None;
            }
        };
        let face = |b: &mut Self, name: &str| -> Option<Vec<Ply>> {
            if let Some(p) = b.shell_tables.stacks.get(name) {
                return Some(p.clone());
            }
            match b.input.laminates.iter().find(|x| x.name == name) {
                Some(x) if x.core.is_some() || faces_given(x) => b.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("face sheet \"{name}\" is a sandwich: a face sheet must be a stack of plies"),
                ),
                // a stack with errors, reported where it is defined
                Some(_) => {}
                None => b.ck.push(
                    ModelErrorKind::UnknownLaminate,
                    entity,
                    format!("face sheet laminate \"{name}\" is not defined"),
                ),
            }
            None
        };
        let b = face(self, &bottom);
        let t = if top == bottom {
            b.clone()
        } else {
            face(self, &top)
        };
        let unit = l.unit.map_or(1.0, |u| u.radians());
        let angle = core.angle.unwrap_or(0.0);
        if l.unit.is_none() && angle.is_finite() {
            self.ck.unitless_angle(
                entity,
                "the core has the angle",
                angle,
                AngleLimit::HalfTurn,
            );
        }
        let core = Core {
            thickness: core.thickness,
            g13: core.g13,
            g23: core.g23,
            density: core.density.unwrap_or(0.0),
            modulus: core.e.unwrap_or(0.0),
            poisson: core.nu.unwrap_or(0.0),
            angle: angle * unit,
        };
        let (b, t) = (b?, t?);
        Laminate::sandwich(&b, &core, &t)
            .map_err(|e| self.laminate_error(entity, e))
            .ok()
    }

    /// The laminate `name` for `entity`; an error if it does not exist
    /// (unless its own definition was reported).
    fn laminate(&mut self, entity: &str, name: &str) -> Option<Arc<Laminate>> {
        let found = self.shell_tables.laminates.get(name).cloned();
        if found.is_none() && !self.shell_tables.invalid_laminates.contains(name) {
            self.ck.push(
                ModelErrorKind::UnknownLaminate,
                entity,
                format!("laminate \"{name}\" is not defined"),
            );
        }
        found
    }

    /// The curve of a pressure, checked with its magnitude.
    fn pressure_curve(
        &mut self,
        entity: &str,
        pressure: Option<f64>,
        curve: &Option<String>,
    ) -> Option<Option<(f64, CurveIndex)>> {
        let Some(p) = pressure else {
            if curve.is_some() {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "pressure_curve is given without a pressure",
                );
                return None;
            }
            return Some(None);
        };
        if !self.ck.finite(entity, "pressure", &[p]) {
            return None;
        }
        let what = format!("pressure of {entity}");
        let c = self.curve(&what, curve, self.load_default())?;
        if !self
            .curves
            .check_range(&mut self.ck, entity, "pressure", p.abs(), c)
        {
            return None;
        }
        if curve.is_none() && p != 0.0 {
            self.ramp_through_dynamics(&what);
        }
        Some(Some((p, c)))
    }

    /// Adds the nodal forces of a pressure `p` (curve `c`) on `shell`:
    /// `p n ∫ Nᵢ dA` at each node, the consistent load of a uniform normal
    /// load on this element (its rotations are interpolated apart from
    /// its deflection, so a uniform load gives them no moment).
    fn add_pressure(&mut self, shell: &Shell, (p, c): (f64, CurveIndex)) {
        let n: Vec3 = shell.axes().column(2).into();
        for (k, a) in shell.nodal_areas().into_iter().enumerate() {
            *self
                .shell_tables
                .pressure
                .entry((shell.nodes()[k], c))
                .or_insert_with(Vec3::zeros) += n * (p * a);
        }
    }

    /// `[[shells]]`.
    pub(super) fn shells(&mut self) {
        let input = self.input;
        for s in &input.shells {
            let entity = format!("shell {}", s.id);
            let id_ok = self.claim_id(&entity, s.id);
            let nodes: Vec<Option<usize>> =
                s.nodes.iter().map(|&n| self.node(&entity, n)).collect();
            let mut ok = id_ok;
            for i in 0..4 {
                if s.nodes[..i].contains(&s.nodes[i]) {
                    self.ck.push(
                        ModelErrorKind::ZeroLength,
                        &entity,
                        format!(
                            "node {} appears twice: a shell needs four distinct nodes",
                            s.nodes[i]
                        ),
                    );
                    ok = false;
                    break;
                }
            }
            let lam = self.laminate(&entity, &s.laminate);
            if let Some(a) = s.material_axis {
                ok &= self.ck.finite(&entity, "material_axis", &a);
            }
            let pressure = self.pressure_curve(&entity, s.pressure, &s.pressure_curve);
            let (true, Some(lam), Some(pressure)) = (ok, lam, pressure) else {
                continue;
            };
            let Some(nodes): Option<Vec<usize>> = nodes.into_iter().collect() else {
                continue;
            };
            let nodes = [nodes[0], nodes[1], nodes[2], nodes[3]];
            let x = nodes.map(|n| self.nodes[n].x);
            let q = nodes.map(|n| self.nodes[n].q);
            match Shell::with_node_ids(
                s.id,
                nodes,
                s.nodes,
                x,
                q,
                s.material_axis.map(Vec3::from),
                lam,
            ) {
                Ok(shell) => {
                    if let Some(p) = pressure {
                        self.add_pressure(&shell, p);
                    }
                    self.elements.push(Box::new(shell));
                }
                Err(e) => self
                    .ck
                    .push(ModelErrorKind::Invalid, &entity, e.to_string()),
            }
        }
    }

    /// One more than the largest element id given or claimed so far.
    fn next_element_id(&self) -> Id {
        let i = self.input;
        let given = i
            .beams
            .iter()
            .map(|e| e.id)
            .chain(i.shells.iter().map(|e| e.id))
            .chain(i.rigid_bodies.iter().map(|e| e.id))
            .chain(i.point_masses.iter().map(|e| e.id))
            .chain(i.springs.iter().map(|e| e.id))
            .chain(i.joints.iter().map(|e| e.id))
            .chain(i.joint_springs.iter().map(|e| e.id))
            .chain(i.hinge_laws.iter().map(|e| e.id))
            .chain(i.drivers.iter().map(|e| e.id))
            .chain(i.latches.iter().map(|e| e.id))
            .chain(i.stops.iter().map(|e| e.id))
            .chain(i.contacts.iter().map(|e| e.id))
            .chain(i.rolling_discs.iter().map(|e| e.id))
            .chain(self.element_ids.keys().copied());
        given.max().map_or(1, |m| m.saturating_add(1))
    }

    /// `[[panels]]`: every check of a panel, then its nodes, shells,
    /// stiffeners and pressure. With `mesh` false (the model is too
    /// large) nothing is generated.
    pub(super) fn panels(&mut self, mesh: bool) {
        let input = self.input;
        for p in &input.panels {
            let entity = format!("panel \"{}\"", p.name);
            match self.panel_plan(&entity, p) {
                Some(plan) if mesh => self.mesh_panel(&entity, p, plan),
                Some(_) => {}
                // its nodes are not reported again where they are used
                None => self.invalid_panel_nodes(p),
            }
        }
    }

    /// The pressures of shells and panels, as nodal loads numbered after
    /// the `[[loads]]` (once both are built).
    pub(super) fn pressure_loads(&mut self) {
        let mut id = self.input.loads.len() as Id;
        for ((node, curve), f) in std::mem::take(&mut self.shell_tables.pressure) {
            id += 1;
            self.elements.push(Box::new(NodalLoad::new(
                id,
                node,
                f,
                Vec3::zeros(),
                false,
                curve,
            )));
        }
    }

    /// Marks the nodes a panel with errors would have made (its named
    /// nodes, and its grid when its size is known) as invalid, so that a
    /// support or a joint on them is not reported again.
    fn invalid_panel_nodes(&mut self, p: &PanelInput) {
        if let Some(ids) = &p.node_ids {
            self.invalid_nodes
                .extend(PanelPoint::ALL.iter().filter_map(|&k| ids.get(k)));
        }
        let [nx, ny] = p.elements;
        let count = nx.saturating_add(1).saturating_mul(ny.saturating_add(1));
        if count <= MAX_MODEL_SIZE {
            let first = p.first_node.unwrap_or_else(|| {
                self.node_ids
                    .iter()
                    .chain(&self.invalid_nodes)
                    .copied()
                    .max()
                    .map_or(1, |m| m.saturating_add(1))
            });
            self.invalid_nodes
                .extend((0..count as Id).filter_map(|k| first.checked_add(k)));
        }
    }

    /// Checks a panel; its geometry and properties when they are sound.
    fn panel_plan(&mut self, entity: &str, p: &PanelInput) -> Option<PanelPlan> {
        let mut ok = true;
        for (k, v) in p.size.iter().enumerate() {
            ok &= self.ck.positive(entity, ["size a", "size b"][k], *v);
        }
        let [nx, ny] = p.elements;
        if nx < 2 || ny < 2 || !nx.is_multiple_of(2) || !ny.is_multiple_of(2) {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "elements = [{nx}, {ny}]: give even numbers of at least 2, so that the middle of each side is a node"
                ),
            );
            ok = false;
        } else if (nx + 1).saturating_mul(ny + 1) > MAX_MODEL_SIZE {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("elements = [{nx}, {ny}]: more nodes than the limit of {MAX_MODEL_SIZE}"),
            );
            ok = false;
        }
        let origin = p.origin.unwrap_or([0.0; 3]);
        let a = p.axis_a.unwrap_or([1.0, 0.0, 0.0]);
        let b = p.axis_b.unwrap_or([0.0, 1.0, 0.0]);
        ok &= self.ck.finite(entity, "origin", &origin);
        let axes_ok = self.ck.finite(entity, "axis_a", &a) & self.ck.finite(entity, "axis_b", &b);
        let mut axes = None;
        if axes_ok {
            let (a, b) = (Vec3::from(a), Vec3::from(b));
            if a.norm() == 0.0 {
                self.ck
                    .push(ModelErrorKind::Invalid, entity, "axis_a is zero");
            } else {
                let ea = a.normalize();
                let bn = b - ea * b.dot(&ea);
                if bn.norm() <= 1e-3 * b.norm() {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!(
                            "axis_b {:?} is zero or along axis_a {:?}: it must point across the panel",
                            b.as_slice(),
                            a.as_slice()
                        ),
                    );
                } else {
                    axes = Some([ea, bn.normalize()]);
                }
            }
        }
        ok &= axes.is_some();
        let laminate = self.laminate(entity, &p.laminate);
        ok &= laminate.is_some();
        let mut zones = Vec::with_capacity(p.zones.len());
        for (k, z) in p.zones.iter().enumerate() {
            let what = format!("{entity} zone {}", k + 1);
            let mut zone_ok =
                self.ck.finite(&what, "from", &z.from) & self.ck.finite(&what, "to", &z.to);
            if zone_ok && (z.from[0] > z.to[0] || z.from[1] > z.to[1]) {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    &what,
                    format!(
                        "from = {:?} must be below to = {:?} in both directions",
                        z.from, z.to
                    ),
                );
                zone_ok = false;
            }
            let lam = self.laminate(&what, &z.laminate);
            ok &= zone_ok;
            if let Some(lam) = lam {
                zones.push((z.from, z.to, lam));
            } else {
                ok = false;
            }
        }
        let mut stiffeners = Vec::with_capacity(p.stiffeners.len());
        for (k, s) in p.stiffeners.iter().enumerate() {
            let what = format!("{entity} stiffener {} ({} side)", k + 1, s.side.name());
            let offset = s.offset.unwrap_or(0.0);
            ok &= self.ck.finite(&what, "offset", &[offset]);
            match self.sections.get(&s.section) {
                Some(sec) => stiffeners.push((s.side, offset, sec.clone())),
                None => {
                    if !self.invalid_sections.contains(&s.section) {
                        self.ck.push(
                            ModelErrorKind::UnknownSection,
                            &what,
                            format!("section \"{}\" is not defined", s.section),
                        );
                    }
                    ok = false;
                }
            }
        }
        let pressure = self.pressure_curve(entity, p.pressure, &p.pressure_curve);
        ok &= pressure.is_some();
        if !ok {
            return None;
        }
        Some(PanelPlan {
            origin: Vec3::from(origin),
            axes: axes?,
            laminate: laminate?,
            zones,
            stiffeners,
            pressure: pressure?,
        })
    }

    /// The nodes, shells, stiffeners and pressure of a checked panel.
    fn mesh_panel(&mut self, entity: &str, p: &PanelInput, plan: PanelPlan) {
        let [nx, ny] = p.elements;
        let [a, b] = p.size;
        let [ea, eb] = plan.axes;
        let normal = ea.cross(&eb);
        // node ids: the grid from first_node, the named points as given
        let first = p.first_node.unwrap_or_else(|| {
            self.node_ids
                .iter()
                .chain(&self.invalid_nodes)
                .copied()
                .max()
                .map_or(1, |m| m.saturating_add(1))
        });
        let count = ((nx + 1) * (ny + 1)) as Id;
        if first.checked_add(count - 1).is_none_or(|l| l > MAX_ID) {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("its nodes would get ids above {MAX_ID}, the largest a model file can hold (set first_node)"),
            );
            return;
        }
        let named = p.node_ids.clone().unwrap_or_default();
        let id_of = |i: usize, j: usize| -> Id {
            PanelPoint::at(nx, ny, i, j)
                .and_then(|k| named.get(k))
                .unwrap_or(first + (j * (nx + 1) + i) as Id)
        };
        let mut index = vec![0usize; (nx + 1) * (ny + 1)];
        let mut taken = HashSet::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let id = id_of(i, j);
                if self.node_index.contains_key(&id)
                    || self.invalid_nodes.contains(&id)
                    || !taken.insert(id)
                {
                    self.ck.push(
                        ModelErrorKind::DuplicateId,
                        entity,
                        format!(
                            "its node ({i}, {j}) would take id {id}, which is already used (set first_node or node_ids)"
                        ),
                    );
                    return;
                }
            }
        }
        for j in 0..=ny {
            for i in 0..=nx {
                let id = id_of(i, j);
                let x =
                    plan.origin + ea * (a * i as f64 / nx as f64) + eb * (b * j as f64 / ny as f64);
                index[j * (nx + 1) + i] = self.nodes.len();
                self.node_index.insert(id, self.nodes.len());
                self.node_ids.push(id);
                self.nodes.push(NodeData {
                    x,
                    q: Rotation::identity(),
                });
            }
        }
        let node = |i: usize, j: usize| index[j * (nx + 1) + i];

        // shells, each with the laminate of the last zone holding its centre
        let first_element = p.first_element.unwrap_or_else(|| self.next_element_id());
        let beams: usize = plan
            .stiffeners
            .iter()
            .map(|(side, ..)| match side {
                PanelSide::South | PanelSide::North => nx,
                PanelSide::East | PanelSide::West => ny,
            })
            .sum();
        if first_element
            .checked_add((nx * ny + beams) as Id - 1)
            .is_none_or(|l| l > MAX_ID)
        {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("its elements would get ids above {MAX_ID}, the largest a model file can hold (set first_element)"),
            );
            return;
        }
        let mut used = vec![false; plan.zones.len()];
        for j in 0..ny {
            for i in 0..nx {
                let centre = [
                    a * (i as f64 + 0.5) / nx as f64,
                    b * (j as f64 + 0.5) / ny as f64,
                ];
                let lam = match plan
                    .zones
                    .iter()
                    .enumerate()
                    .rev()
                    .find(|(_, (lo, hi, _))| {
                        (lo[0]..=hi[0]).contains(&centre[0]) && (lo[1]..=hi[1]).contains(&centre[1])
                    }) {
                    Some((k, (.., lam))) => {
                        used[k] = true;
                        lam.clone()
                    }
                    None => plan.laminate.clone(),
                };
                let id = first_element + (j * nx + i) as Id;
                let what = format!("shell {id} of {entity}");
                if !self.claim_id(&what, id) {
                    continue;
                }
                let corners = [
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ];
                let ids = [
                    id_of(i, j),
                    id_of(i + 1, j),
                    id_of(i + 1, j + 1),
                    id_of(i, j + 1),
                ];
                let x = corners.map(|n| self.nodes[n].x);
                let q = corners.map(|n| self.nodes[n].q);
                match Shell::with_node_ids(id, corners, ids, x, q, Some(ea), lam) {
                    Ok(shell) => {
                        if let Some(p) = plan.pressure {
                            self.add_pressure(&shell, p);
                        }
                        self.elements.push(Box::new(shell));
                    }
                    Err(e) => {
                        self.ck.push(ModelErrorKind::Invalid, &what, e.to_string());
                        return;
                    }
                }
            }
        }
        for (k, u) in used.iter().enumerate() {
            if !u {
                self.ck.warn(
                    format!("{entity} zone {}", k + 1),
                    "holds the centre of no element: its laminate is used nowhere (zones are in panel coordinates, lengths from the origin along axis_a and axis_b)",
                );
            }
        }

        // stiffeners: beams on the side's nodes, their section moved to
        // the offset axis
        let mut next = first_element + (nx * ny) as Id;
        for (side, offset, section) in &plan.stiffeners {
            let line: Vec<usize> = match side {
                PanelSide::South => (0..=nx).map(|i| node(i, 0)).collect(),
                PanelSide::North => (0..=nx).map(|i| node(i, ny)).collect(),
                PanelSide::West => (0..=ny).map(|j| node(0, j)).collect(),
                PanelSide::East => (0..=ny).map(|j| node(nx, j)).collect(),
            };
            let section = offset_section(section, *offset);
            for w in line.windows(2) {
                let what = format!("beam {next} of {entity} ({} stiffener)", side.name());
                let id = next;
                next += 1;
                if !self.claim_id(&what, id) {
                    continue;
                }
                let (xa, xb) = (self.nodes[w[0]].x, self.nodes[w[1]].x);
                let (qa, qb) = (self.nodes[w[0]].q, self.nodes[w[1]].q);
                match Beam::new(
                    id,
                    [w[0], w[1]],
                    [xa, xb],
                    [qa, qb],
                    normal,
                    section.clone(),
                    InitialStrain::default(),
                ) {
                    Some(beam) => self.elements.push(Box::new(beam)),
                    None => self.ck.push(
                        ModelErrorKind::Invalid,
                        &what,
                        "its axis is along the panel's normal",
                    ),
                }
            }
        }
    }
}

impl ShellTables {
    fn has_laminate(&self, name: &str) -> bool {
        self.laminates.contains_key(name) || self.invalid_laminates.contains(name)
    }
}

/// Whether a laminate names face sheets.
fn faces_given(l: &LaminateInput) -> bool {
    l.faces.is_some() || l.bottom_face.is_some() || l.top_face.is_some()
}

/// What a checked panel is made of.
struct PanelPlan {
    origin: Vec3,
    /// Unit vectors along sides `a` and `b`.
    axes: [Vec3; 2],
    laminate: Arc<Laminate>,
    zones: Vec<([f64; 2], [f64; 2], Arc<Laminate>)>,
    stiffeners: Vec<(PanelSide, f64, BeamSection)>,
    pressure: Option<(f64, CurveIndex)>,
}

/// The section of a beam whose axis is offset by `e` along its local axis
/// 2 from the line of its nodes: with `d = (0, e, 0)` the strains of the
/// offset axis are `Γ_d = Γ + K × d = Γ − d~ K`, so the stiffness on the
/// nodes' line is `Hᵀ C H`, `H = [[I, −d~], [0, I]]` (docs/theory.md
/// §17.4), and the rotational inertia gains the parallel-axis term
/// `ρA e²` about axes 1 and 3 (the coupling of the translations with the
/// rotations through the offset is left out).
pub(super) fn offset_section(section: &BeamSection, e: f64) -> BeamSection {
    if e == 0.0 {
        return section.clone();
    }
    let d = Vec3::new(0.0, e, 0.0);
    let mut h = SectionStiffness::identity();
    h.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew(&d)));
    let c = h.transpose() * section.stiffness * h;
    let m = section.mass_per_length * e * e;
    let mut out = section.clone();
    out.stiffness = (c + c.transpose()) * 0.5;
    out.inertia_per_length += Vec3::new(m, 0.0, m);
    out
}

/// Nodes and elements a set of panels generates (for the size limit).
pub(super) fn panels_size(panels: &[PanelInput]) -> usize {
    panels
        .iter()
        .map(|p| {
            let [nx, ny] = p.elements;
            let n = (nx.saturating_add(1))
                .saturating_mul(ny.saturating_add(1))
                .saturating_add(nx.saturating_mul(ny));
            n.saturating_add(p.stiffeners.len().saturating_mul(nx.max(ny)))
        })
        .fold(0usize, usize::saturating_add)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The named points of a 4 × 2 panel sit at the corners and the
    /// middles of the sides.
    #[test]
    fn named_points_of_a_grid() {
        let names: Vec<Option<&str>> = [
            (0, 0),
            (2, 0),
            (4, 0),
            (4, 1),
            (4, 2),
            (2, 2),
            (0, 2),
            (0, 1),
            (1, 1),
            (3, 0),
        ]
        .iter()
        .map(|&(i, j)| PanelPoint::at(4, 2, i, j).map(|p| p.name()))
        .collect();
        assert_eq!(
            names,
            [
                Some("south_west"),
                Some("south"),
                Some("south_east"),
                Some("east"),
                Some("north_east"),
                Some("north"),
                Some("north_west"),
                Some("west"),
                None,
                None
            ]
        );
    }

    /// An offset stiffener: a beam of axial stiffness `EA` and bending
    /// stiffness `EI` about its centroid, its axis at `e` from the nodes'
    /// line, stiffens the line in bending by `EI + EA e²` (the
    /// parallel-axis term) and couples its stretching with that bending
    /// by `−EA e` (an offset beam bent about local axis 3 stretches its
    /// node line), to round-off.
    #[test]
    fn offset_section_adds_the_parallel_axis_terms() {
        let s = BeamSection {
            stiffness: SectionStiffness::from_diagonal(&nalgebra::Vector6::new(
                1e7, 4e6, 4e6, 2e3, 3e3, 5e3,
            )),
            mass_per_length: 2.0,
            inertia_per_length: Vec3::new(1e-3, 5e-4, 5e-4),
            damping: Default::default(),
        };
        let e = 0.02;
        let o = offset_section(&s, e);
        let c = &o.stiffness;
        assert!((c[(5, 5)] - (5e3 + 1e7 * e * e)).abs() < 1e-9 * c[(5, 5)]);
        assert!((c[(0, 5)] + 1e7 * e).abs() < 1e-9 * 1e7 * e);
        assert_eq!(c[(4, 4)], 3e3);
        // the shear 3 strain of the offset axis takes the twist: GJ + GA3 e²
        assert!((c[(3, 3)] - (2e3 + 4e6 * e * e)).abs() < 1e-9 * c[(3, 3)]);
        assert!(
            (o.inertia_per_length - Vec3::new(1e-3 + 2.0 * e * e, 5e-4, 5e-4 + 2.0 * e * e)).norm()
                < 1e-15
        );
        assert!(c.cholesky().is_some());
    }
}
