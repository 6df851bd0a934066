//! `[[superelements]]`: flexible bodies reduced by Craig–Bampton
//! ([`crate::reduction`]) and moved as superelements
//! ([`crate::elements::superelement`]).
//!
//! Runs after the beams are queued (`[[beams]]`, `[[beam_lines]]`) and
//! before any other element is built: a body made of elements of this
//! model takes its beams out of the queue (and its rigid bodies and point
//! masses out of the model), and its interior nodes leave the model, so
//! that every entity built after refers to the nodes that remain.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::Builder;
use crate::elements::beam::Beam;
use crate::elements::mass::RigidBody;
use crate::elements::superelement::Superelement;
use crate::elements::{Element, ElementKind};
use crate::model::input::{AnalysisInput, DampingRatioInput, Id, SuperelementInput};
use crate::model::{Model, ModelErrorKind};
use crate::reduction::import::{import_body, ImportedFiles};
use crate::reduction::{
    reduce, FlexibleBody, InertiaModel, ModeSelection, ReducedBody, ReductionSettings,
};
use crate::so3::{self, Mat3, Rotation, Vec3};

/// Whether elements of this kind can be reduced into a superelement: the
/// linear elements of a body's structure (beams, shells) and its masses.
/// A new structural element joins the list here.
pub fn reducible(kind: ElementKind) -> bool {
    matches!(
        kind,
        ElementKind::Beam | ElementKind::Shell | ElementKind::RigidBody | ElementKind::PointMass
    )
}

/// Where a boundary node of a body from a file may be from its model
/// node, relative to the body's size.
const PLACEMENT_TOLERANCE: f64 = 1e-6;

/// A reduced body waiting for its element (after the interior nodes of
/// every body of this model have left).
struct Pending {
    id: Id,
    model_nodes: Vec<Id>,
    body: ReducedBody,
}

impl Builder<'_> {
    /// `[[superelements]]` (see the module documentation).
    pub(super) fn superelements(&mut self) {
        let input = self.input;
        let mut pending = Vec::new();
        let mut interior: HashSet<Id> = HashSet::new();
        for se in &input.superelements {
            let entity = format!("superelement {}", se.id);
            if let Some(p) = self.superelement(&entity, se, &mut interior) {
                pending.push(p);
            }
        }
        if !interior.is_empty() {
            self.remove_nodes(&interior);
        }
        for p in pending {
            let Some(idx): Option<Vec<usize>> = p
                .model_nodes
                .iter()
                .map(|id| self.node_index.get(id).copied())
                .collect()
            else {
                continue;
            };
            let x: Vec<Vec3> = idx.iter().map(|&i| self.nodes[i].x).collect();
            let r: Vec<Rotation> = idx.iter().map(|&i| self.nodes[i].q).collect();
            self.elements.push(Box::new(Superelement::new(
                p.id,
                idx,
                &x,
                &r,
                Arc::new(p.body),
            )));
        }
    }

    /// Checks, builds and reduces one superelement's body.
    fn superelement(
        &mut self,
        entity: &str,
        se: &SuperelementInput,
        interior: &mut HashSet<Id>,
    ) -> Option<Pending> {
        let id_ok = self.claim_id(entity, se.id);
        let mut ok = id_ok;

        // the boundary and the frame node
        if se.boundary.is_empty() {
            // the body's elements stay in the model: no node is taken out
            self.ck.push(
                ModelErrorKind::Missing,
                entity,
                "boundary: no boundary node; list at least one (the node its floating frame is attached to)",
            );
            return None;
        }
        for (k, b) in se.boundary.iter().enumerate() {
            if se.boundary[..k].contains(b) {
                self.ck.push(
                    ModelErrorKind::DuplicateId,
                    entity,
                    format!("boundary: node {b} is listed twice"),
                );
                ok = false;
            }
        }
        let frame = match se.frame_node {
            None => 0,
            Some(f) => match se.boundary.iter().position(|&b| b == f) {
                Some(k) => k,
                None => {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!(
                            "frame_node {f} is not one of its boundary nodes {:?}",
                            se.boundary
                        ),
                    );
                    ok = false;
                    0
                }
            },
        };

        // modes, damping, inertia
        let modes = match (se.modes, se.cutoff_frequency) {
            (Some(n), None) => Some(ModeSelection::Count(n)),
            (None, Some(f)) => self
                .ck
                .positive(entity, "cutoff_frequency", f)
                .then_some(ModeSelection::CutOff(f)),
            (Some(_), Some(_)) => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "give modes (a count) or cutoff_frequency (Hz), not both",
                );
                None
            }
            (None, None) => {
                self.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "give modes (the number of fixed-interface modes kept, 0 for a static reduction) or cutoff_frequency (Hz)",
                );
                None
            }
        };
        ok &= modes.is_some();
        let damping_ratios = match &se.damping_ratio {
            None => Vec::new(),
            Some(DampingRatioInput::All(z)) => vec![*z],
            Some(DampingRatioInput::PerMode(z)) => z.clone(),
        };
        for z in &damping_ratios {
            ok &= self.ck.non_negative(entity, "damping_ratio", *z);
        }

        // the body
        let sources = [
            se.elements.is_some(),
            se.model.is_some(),
            se.stiffness.is_some() || se.mass.is_some() || se.dofs.is_some(),
            se.dmig.is_some(),
        ];
        let from_file = !sources[0];
        match sources.iter().filter(|&&s| s).count() {
            1 => {}
            0 => {
                self.ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    "no body: give elements (of this model), model (a file of the body), stiffness, mass and dofs (Matrix Market), or dmig (a Nastran punch file)",
                );
                return None;
            }
            _ => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "more than one body: give one of elements, model, stiffness/mass/dofs, dmig",
                );
                return None;
            }
        }
        if !from_file {
            for (given, key) in [
                (se.nodes.is_some(), "nodes"),
                (se.position.is_some(), "position"),
                (se.rotation.is_some(), "rotation"),
                (se.coordinates.is_some(), "coordinates"),
                (se.cells.is_some(), "cells"),
            ] {
                if given {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!("{key} is for a body from a file; a body of this model's elements is where its nodes are"),
                    );
                    ok = false;
                }
            }
        }
        let body = if let Some(elements) = &se.elements {
            self.body_of_elements(entity, elements, &se.boundary, interior)
        } else if let Some(file) = &se.model {
            self.body_of_file(entity, file)
        } else {
            self.imported_body(entity, se)
        };
        let mut body = body?;
        if from_file {
            let position = se.position.unwrap_or([0.0; 3]);
            let rotation = se.rotation.unwrap_or([0.0; 3]);
            if !self.ck.finite(entity, "position", &position)
                | !self.ck.finite(entity, "rotation", &rotation)
            {
                return None;
            }
            let unit = se.unit.unwrap_or_default().radians();
            let q = so3::exp(&(Vec3::from(rotation) * unit));
            body = match body.placed(Vec3::from(position), &q) {
                Ok(b) => b,
                Err(node) => {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!("rotation: node {node} of the body has some of its translations or rotations as dofs but not all three, which a rotation would mix"),
                    );
                    return None;
                }
            };
        }

        // boundary nodes in the body, and the model nodes they are
        let mut boundary = Vec::with_capacity(se.boundary.len());
        for &b in &se.boundary {
            match body.node_index(b) {
                Some(i) => boundary.push(i),
                None => {
                    self.ck.push(
                        ModelErrorKind::UnknownNode,
                        entity,
                        format!("boundary node {b} is not a node of the body"),
                    );
                    ok = false;
                }
            }
        }
        let model_nodes = match &se.nodes {
            Some(n) if n.len() != se.boundary.len() => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!(
                        "nodes lists {} model nodes for {} boundary nodes",
                        n.len(),
                        se.boundary.len()
                    ),
                );
                return None;
            }
            Some(n) => n.clone(),
            None => se.boundary.clone(),
        };
        if from_file && ok {
            let size = bounding_diagonal(&body.positions);
            for (k, &m) in model_nodes.iter().enumerate() {
                let Some(i) = self.node(entity, m) else {
                    ok = false;
                    continue;
                };
                let (x, xb) = (self.nodes[i].x, body.positions[boundary[k]]);
                if (x - xb).norm() > PLACEMENT_TOLERANCE * size {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!(
                            "model node {m} is at {:?}, its boundary node {} of the body is placed at {:?}: they must coincide (check position and rotation)",
                            x.as_slice(),
                            se.boundary[k],
                            xb.as_slice()
                        ),
                    );
                    ok = false;
                }
            }
        }
        if !ok {
            return None;
        }
        let settings = ReductionSettings {
            boundary,
            frame,
            modes: modes?,
            inertia: se.inertia.unwrap_or(InertiaModel::Consistent),
            damping_ratios,
            compare_free_free: se.check_frequencies.unwrap_or(true),
        };
        match reduce(body, &settings) {
            Ok(body) => {
                self.ck.note(entity, reduction_summary(&body));
                Some(Pending {
                    id: se.id,
                    model_nodes,
                    body,
                })
            }
            Err(e) => {
                self.ck.push(ModelErrorKind::Invalid, entity, e.to_string());
                None
            }
        }
    }

    /// The body of `elements` of this model: their beams taken out of the
    /// queue, their rigid bodies and point masses out of the model, their
    /// nodes but the boundary ones added to `interior`.
    fn body_of_elements(
        &mut self,
        entity: &str,
        ids: &[Id],
        boundary: &[Id],
        interior: &mut HashSet<Id>,
    ) -> Option<FlexibleBody> {
        let input = self.input;
        if ids.is_empty() {
            self.ck
                .push(ModelErrorKind::Missing, entity, "elements: none listed");
            return None;
        }
        let mut ok = true;
        let mut specs = Vec::new();
        let mut masses = Vec::new();
        for &id in ids {
            if let Some(k) = self.beam_specs.iter().position(|s| s.id == id) {
                specs.push(self.beam_specs.remove(k));
            } else if let Some(rb) = input.rigid_bodies.iter().find(|b| b.id == id) {
                masses.push((id, rb.node, rb.mass, rb.inertia.clone(), rb.center_of_mass));
            } else if let Some(pm) = input.point_masses.iter().find(|b| b.id == id) {
                masses.push((id, pm.node, pm.mass, None, None));
            } else {
                let what = match self.element_ids.get(&id) {
                    Some(holder) => format!("elements: {holder} cannot be reduced from this model (beams, rigid bodies and point masses can; shells and panels from a body file, `model`)"),
                    None => format!("elements: no beam, rigid body or point mass has id {id}"),
                };
                self.ck.push(ModelErrorKind::Invalid, entity, what);
                ok = false;
            }
        }
        for s in &specs {
            if s.initial.strain != [0.0; 6] || s.initial.curve.is_some() {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("{} has an initial strain: a superelement is reduced from a stress-free body", s.entity),
                );
                ok = false;
            }
        }
        for &(id, ..) in &masses {
            let holder = if input.rigid_bodies.iter().any(|b| b.id == id) {
                format!("rigid body {id}")
            } else {
                format!("point mass {id}")
            };
            ok &= self.claim_id(&holder, id);
            self.absorbed_elements.insert(id);
        }
        // the part's nodes, boundary first
        let mut part: Vec<usize> = Vec::new();
        let add = |part: &mut Vec<usize>, n: usize| {
            if !part.contains(&n) {
                part.push(n);
            }
        };
        for s in &specs {
            add(&mut part, s.nodes[0]);
            add(&mut part, s.nodes[1]);
        }
        for &(id, node, ..) in &masses {
            match self.node_index.get(&node) {
                Some(&n) => add(&mut part, n),
                None => {
                    self.ck.push(
                        ModelErrorKind::UnknownNode,
                        entity,
                        format!("elements: the node {node} of element {id} does not exist"),
                    );
                    ok = false;
                }
            }
        }
        for &b in boundary {
            let inside = self.node_index.get(&b).is_some_and(|i| part.contains(i));
            if !inside {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("boundary node {b} is not a node of its elements"),
                );
                ok = false;
            }
        }
        // a node of the part used by a beam outside it must be a boundary
        // node
        for s in &self.beam_specs {
            for n in s.nodes {
                let id = self.node_ids[n];
                if part.contains(&n) && !boundary.contains(&id) {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        entity,
                        format!("node {id} is inside it but {} (not one of its elements) uses it: make it a boundary node", s.entity),
                    );
                    ok = false;
                }
            }
        }
        if !ok {
            return None;
        }
        for &n in &part {
            let id = self.node_ids[n];
            if !boundary.contains(&id) {
                interior.insert(id);
                self.absorbed_nodes.insert(id, entity.to_string());
            }
        }

        // the part as a model of its own
        let local: HashMap<usize, usize> = part.iter().enumerate().map(|(k, &n)| (n, k)).collect();
        let mut elements: Vec<Box<dyn Element>> = Vec::new();
        for s in specs {
            let [a, b] = s.nodes;
            let section = self.sections.get(&s.section)?.clone();
            let axis = self.nodes[b].x - self.nodes[a].x;
            let orientation = s
                .orientation
                .unwrap_or_else(|| super::beams::default_orientation(&axis));
            let beam = Beam::new(
                s.id,
                [local[&a], local[&b]],
                [self.nodes[a].x, self.nodes[b].x],
                [self.nodes[a].q, self.nodes[b].q],
                orientation,
                section,
                s.initial,
            );
            match beam {
                Some(beam) => elements.push(Box::new(beam)),
                None => {
                    self.ck.push(
                        ModelErrorKind::Invalid,
                        &s.entity,
                        "zero length, or orientation vector parallel to the beam axis",
                    );
                    return None;
                }
            }
        }
        for (id, node, mass, inertia, offset) in masses {
            let n = local[&self.node_index[&node]];
            let inertia = match inertia {
                None => Mat3::zeros(),
                Some(crate::model::input::InertiaInput::Diagonal(d)) => {
                    Mat3::from_diagonal(&Vec3::from(d))
                }
                Some(crate::model::input::InertiaInput::Full(f)) => Mat3::from_fn(|r, c| f[r][c]),
            };
            if !(mass > 0.0 && mass.is_finite()) {
                self.ck.push(
                    ModelErrorKind::NonPositive,
                    format!("element {id}"),
                    format!("mass must be positive, got {mass}"),
                );
                return None;
            }
            elements.push(Box::new(RigidBody::new(
                id,
                n,
                mass,
                inertia,
                Vec3::from(offset.unwrap_or([0.0; 3])),
            )));
        }
        let nodes: Vec<(Id, Vec3, Rotation)> = part
            .iter()
            .map(|&n| (self.node_ids[n], self.nodes[n].x, self.nodes[n].q))
            .collect();
        Some(FlexibleBody::from_model(part_model(
            entity, &nodes, elements,
        )))
    }

    /// The body of a model file (its path relative to this model file's
    /// directory).
    fn body_of_file(&mut self, entity: &str, file: &str) -> Option<FlexibleBody> {
        let path = self.resolve(file);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) => {
                self.ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("model: {}: cannot read the file: {e}", path.display()),
                );
                return None;
            }
        };
        let mut input = match crate::io::model_file::parse_model(&text, &path) {
            Ok(i) => i,
            Err(e) => {
                self.ck
                    .push(ModelErrorKind::Invalid, entity, format!("model: {e}"));
                return None;
            }
        };
        if !input.superelements.is_empty() {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "model: {}: a body holds no superelement of its own",
                    path.display()
                ),
            );
            return None;
        }
        // a body is reduced free and unloaded (the model it joins gives
        // its supports, loads and gravity): no static analysis of it
        input.supports.clear();
        input.prescribed.clear();
        input.loads.clear();
        input.gravity = None;
        input.initial_motion.clear();
        input.analysis = AnalysisInput {
            kind: "modal".into(),
            ..AnalysisInput::default()
        }
        .into();
        input.base_dir = path.parent().map(Path::to_path_buf);
        let model = match Model::from_input(&input) {
            Ok(m) => m,
            Err(errors) => {
                for e in errors.0 {
                    self.ck
                        .push(e.kind, entity, format!("model: {}: {e}", path.display()));
                }
                return None;
            }
        };
        if let Some(e) = model.elements.iter().find(|e| !reducible(e.kind())) {
            self.ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "model: {}: {} {} cannot be part of a reduced body (beams, shells, rigid bodies and point masses can)",
                    path.display(),
                    e.kind().name(),
                    e.id()
                ),
            );
            return None;
        }
        Some(FlexibleBody::from_model(model))
    }

    /// The body of imported matrices.
    fn imported_body(&mut self, entity: &str, se: &SuperelementInput) -> Option<FlexibleBody> {
        let files = ImportedFiles {
            stiffness: se.stiffness.as_deref().map(|f| self.resolve(f)),
            mass: se.mass.as_deref().map(|f| self.resolve(f)),
            dofs: se.dofs.as_deref().map(|f| self.resolve(f)),
            dmig: se.dmig.as_deref().map(|f| {
                (
                    self.resolve(f),
                    se.dmig_stiffness.clone().unwrap_or_else(|| "KAAX".into()),
                    se.dmig_mass.clone().unwrap_or_else(|| "MAAX".into()),
                )
            }),
            nodes: se.coordinates.as_deref().map(|f| self.resolve(f)),
            cells: se.cells.as_deref().map(|f| self.resolve(f)),
        };
        if files.dmig.is_none() {
            for (given, key) in [
                (files.stiffness.is_some(), "stiffness"),
                (files.mass.is_some(), "mass"),
                (files.dofs.is_some(), "dofs"),
            ] {
                if !given {
                    self.ck.push(
                        ModelErrorKind::Missing,
                        entity,
                        format!(
                            "{key}: imported Matrix Market matrices need stiffness, mass and dofs"
                        ),
                    );
                    return None;
                }
            }
        }
        let nodes = &self.nodes;
        let index = &self.node_index;
        let model_node = |id: Id| index.get(&id).map(|&i| nodes[i].x);
        match import_body(&files, &model_node) {
            Ok(b) => Some(b),
            Err(e) => {
                self.ck.push(ModelErrorKind::Invalid, entity, e.to_string());
                None
            }
        }
    }

    /// A file named in the model, found from the model file's directory.
    fn resolve(&self, file: &str) -> PathBuf {
        match &self.input.base_dir {
            Some(dir) => dir.join(file),
            None => PathBuf::from(file),
        }
    }

    /// Takes the nodes of `ids` out of the model (the interior nodes of
    /// reduced bodies), renumbering the others and the queued beams.
    fn remove_nodes(&mut self, ids: &HashSet<Id>) {
        let mut new_index = vec![usize::MAX; self.nodes.len()];
        let old_nodes = std::mem::take(&mut self.nodes);
        let old_ids = std::mem::take(&mut self.node_ids);
        for (k, (node, id)) in old_nodes.into_iter().zip(old_ids).enumerate() {
            if !ids.contains(&id) {
                new_index[k] = self.nodes.len();
                self.nodes.push(node);
                self.node_ids.push(id);
            }
        }
        self.node_index = self
            .node_ids
            .iter()
            .enumerate()
            .map(|(k, &id)| (id, k))
            .collect();
        for s in &mut self.beam_specs {
            s.nodes = s.nodes.map(|n| new_index[n]);
        }
    }
}

/// The reduction in one line, for the notes of `unfold check` and
/// `unfold run`.
fn reduction_summary(b: &ReducedBody) -> String {
    let r = &b.report;
    let hz = |w2: &f64| w2.sqrt() / std::f64::consts::TAU;
    let modes = match (b.omega_squared.first(), b.omega_squared.last()) {
        (Some(lo), Some(hi)) => format!(" ({:.4} to {:.4} Hz)", hz(lo), hz(hi)),
        _ => String::new(),
    };
    let free = if r.free.is_empty() {
        String::new()
    } else {
        let worst = r
            .free
            .iter()
            .fold(0.0f64, |a, p| a.max(p.relative_error().abs()));
        format!(
            "; its {} free-free modes up to {:.4} Hz within {:.2} % of the full model's",
            r.free.len(),
            r.free.last().map_or(0.0, |p| p.full),
            100.0 * worst
        )
    };
    format!(
        "{} dofs reduced to {} boundary nodes and {} fixed-interface modes{modes} in {:.3} s, {} inertia, mass {:.6e}{free}",
        r.dofs,
        b.n_boundary(),
        b.n_modes(),
        r.seconds,
        b.inertia.name(),
        r.mass
    )
}

/// The diagonal of the box around `x` (1 if it is empty or a point).
fn bounding_diagonal(x: &[Vec3]) -> f64 {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in x {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let d = (hi - lo).norm();
    if d > 0.0 && d.is_finite() {
        d
    } else {
        1.0
    }
}

/// A model of the nodes `(id, x, R)` and `elements` of a part.
fn part_model(
    title: &str,
    nodes: &[(Id, Vec3, Rotation)],
    elements: Vec<Box<dyn Element>>,
) -> Model {
    let node_ids: Vec<Id> = nodes.iter().map(|n| n.0).collect();
    let mut model = Model {
        title: title.to_string(),
        node_lookup: node_ids
            .iter()
            .enumerate()
            .map(|(k, &id)| (id, k))
            .collect(),
        node_ids,
        reference_x: nodes.iter().map(|n| n.1).collect(),
        reference_q: nodes.iter().map(|n| n.2).collect(),
        element_lookup: elements
            .iter()
            .enumerate()
            .map(|(i, e)| ((e.kind(), e.id()), i))
            .collect(),
        elements,
        fixed: vec![[false; 6]; nodes.len()],
        prescribed: Vec::new(),
        curves: Vec::new(),
        curve_uses: Vec::new(),
        warnings: Vec::new(),
        notes: Vec::new(),
        gravity: None,
        length_scale: bounding_diagonal(&nodes.iter().map(|n| n.1).collect::<Vec<_>>()),
        scaling: Default::default(),
        initial_velocity: Vec::new(),
        offsets: Vec::new(),
        sizes: Default::default(),
    };
    model.place_elements();
    model
}
