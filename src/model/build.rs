//! Validation of a [`ModelInput`] and construction of the [`Model`].

use std::collections::{HashMap, HashSet};

mod joints;

use super::input::*;
use super::{Model, ModelError, ModelErrorKind, ModelErrors, Prescribed, StaticSettings};
use crate::curves::{Curve, CurveIndex};
use crate::elements::beam::{Beam, BeamSection, InitialStrain, SectionStiffness};
use crate::elements::load::NodalLoad;
use crate::elements::mass::RigidBody;
use crate::elements::spring::Spring;
use crate::elements::Element;
use crate::so3::{self, Mat3, Rotation, Vec3};

/// Collects problems while the model is built.
struct Checker {
    errors: Vec<ModelError>,
}

impl Checker {
    fn push(
        &mut self,
        kind: ModelErrorKind,
        entity: impl Into<String>,
        message: impl Into<String>,
    ) {
        self.errors.push(ModelError {
            kind,
            entity: entity.into(),
            message: message.into(),
        });
    }

    /// Checks that every value is finite.
    fn finite(&mut self, entity: &str, what: &str, values: &[f64]) -> bool {
        if values.iter().all(|v| v.is_finite()) {
            true
        } else {
            self.push(
                ModelErrorKind::Invalid,
                entity,
                format!("{what} must be finite, got {values:?}"),
            );
            false
        }
    }

    /// Checks that a value is finite and strictly positive.
    fn positive(&mut self, entity: &str, what: &str, value: f64) -> bool {
        if value.is_finite() && value > 0.0 {
            true
        } else {
            self.push(
                ModelErrorKind::NonPositive,
                entity,
                format!("{what} must be positive, got {value}"),
            );
            false
        }
    }
}

/// A node being built: reference position and orientation.
struct NodeData {
    x: Vec3,
    q: Rotation,
}

/// Default reference vector for local axis 2: global z, or global x for a
/// beam (nearly) along z.
fn default_orientation(axis: &Vec3) -> Vec3 {
    let e = axis.normalize();
    if e.cross(&Vec3::z()).norm() < 1e-3 {
        Vec3::x()
    } else {
        Vec3::z()
    }
}

impl Model {
    /// Validates `input` and builds the model. On failure returns every
    /// problem found.
    pub fn from_input(input: &ModelInput) -> Result<Model, ModelErrors> {
        let mut ck = Checker { errors: Vec::new() };

        // ---------- analysis settings ----------
        let settings = settings(&mut ck, &input.analysis);

        // ---------- curves ----------
        let mut curves = vec![Curve::ramp()];
        let mut curve_index: HashMap<String, CurveIndex> = HashMap::new();
        curve_index.insert(Curve::RAMP.to_string(), 0);
        for c in &input.curves {
            let entity = format!("curve \"{}\"", c.name);
            if curve_index.contains_key(&c.name) {
                let msg = if c.name == Curve::RAMP {
                    "the name \"ramp\" is reserved for the built-in curve f(t) = t"
                } else {
                    "duplicate curve name"
                };
                ck.push(ModelErrorKind::DuplicateId, &entity, msg);
                continue;
            }
            if let Some(f) = &c.function {
                if let Some(function) = curve_function(&mut ck, &entity, f, c) {
                    curve_index.insert(c.name.clone(), curves.len());
                    curves.push(Curve::function(&c.name, function));
                }
                continue;
            }
            if c.points.is_empty() {
                ck.push(
                    ModelErrorKind::Missing,
                    &entity,
                    "needs at least one point [t, f], or a function",
                );
                continue;
            }
            let flat: Vec<f64> = c.points.iter().flatten().copied().collect();
            if !ck.finite(&entity, "points", &flat) {
                continue;
            }
            if let Some(w) = c.points.windows(2).find(|w| w[1][0] <= w[0][0]) {
                ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!(
                        "abscissae must increase strictly, but t = {} is followed by t = {}",
                        w[0][0], w[1][0]
                    ),
                );
                continue;
            }
            curve_index.insert(c.name.clone(), curves.len());
            curves.push(Curve::piecewise_linear(
                &c.name,
                c.points.iter().map(|p| (p[0], p[1])).collect(),
            ));
        }
        let find_curve = |ck: &mut Checker, entity: &str, name: &Option<String>| -> CurveIndex {
            match name {
                None => 0,
                Some(n) => match curve_index.get(n) {
                    Some(&i) => i,
                    None => {
                        ck.push(
                            ModelErrorKind::UnknownCurve,
                            entity,
                            format!("curve \"{n}\" is not defined"),
                        );
                        0
                    }
                },
            }
        };

        // ---------- nodes ----------
        let mut node_ids: Vec<Id> = Vec::new();
        let mut nodes: Vec<NodeData> = Vec::new();
        let mut node_index: HashMap<Id, usize> = HashMap::new();
        for n in &input.nodes {
            let entity = format!("node {}", n.id);
            if node_index.contains_key(&n.id) {
                ck.push(ModelErrorKind::DuplicateId, &entity, "duplicate node id");
                continue;
            }
            let rot = n.rotation.unwrap_or([0.0; 3]);
            if !ck.finite(&entity, "x", &n.x) | !ck.finite(&entity, "rotation", &rot) {
                continue;
            }
            node_index.insert(n.id, nodes.len());
            node_ids.push(n.id);
            nodes.push(NodeData {
                x: Vec3::from(n.x),
                q: so3::exp(&Vec3::from(rot)),
            });
        }

        // ---------- sections ----------
        let mut sections: HashMap<String, BeamSection> = HashMap::new();
        let mut bad_sections: HashSet<String> = HashSet::new();
        for s in &input.sections {
            let entity = format!("section \"{}\"", s.name);
            if sections.contains_key(&s.name) || bad_sections.contains(&s.name) {
                ck.push(
                    ModelErrorKind::DuplicateId,
                    &entity,
                    "duplicate section name",
                );
                continue;
            }
            match section(&mut ck, &entity, s) {
                Some(sec) => {
                    sections.insert(s.name.clone(), sec);
                }
                None => {
                    bad_sections.insert(s.name.clone());
                }
            }
        }

        // ---------- element ids ----------
        let mut element_ids: HashSet<Id> = HashSet::new();
        let mut claim_id = |ck: &mut Checker, entity: &str, id: Id| -> bool {
            if element_ids.insert(id) {
                true
            } else {
                ck.push(ModelErrorKind::DuplicateId, entity, "duplicate element id");
                false
            }
        };
        let resolve = |ck: &mut Checker,
                       node_index: &HashMap<Id, usize>,
                       entity: &str,
                       id: Id|
         -> Option<usize> {
            let found = node_index.get(&id).copied();
            if found.is_none() {
                ck.push(
                    ModelErrorKind::UnknownNode,
                    entity,
                    format!("node {id} does not exist"),
                );
            }
            found
        };

        let mut elements: Vec<Box<dyn Element>> = Vec::new();

        // ---------- beams ----------
        // (entity, node indices, section, orientation, initial strain)
        struct BeamSpec {
            entity: String,
            id: Id,
            nodes: [usize; 2],
            section: String,
            orientation: Option<[f64; 3]>,
            initial_strain: [f64; 6],
            initial_curve: Option<String>,
        }
        let mut beam_specs: Vec<BeamSpec> = Vec::new();
        for b in &input.beams {
            let entity = format!("beam {}", b.id);
            let id_ok = claim_id(&mut ck, &entity, b.id);
            let n0 = resolve(&mut ck, &node_index, &entity, b.nodes[0]);
            let n1 = resolve(&mut ck, &node_index, &entity, b.nodes[1]);
            if b.nodes[0] == b.nodes[1] {
                ck.push(
                    ModelErrorKind::ZeroLength,
                    &entity,
                    format!("both ends are node {}", b.nodes[0]),
                );
                continue;
            }
            if let (true, Some(n0), Some(n1)) = (id_ok, n0, n1) {
                beam_specs.push(BeamSpec {
                    entity,
                    id: b.id,
                    nodes: [n0, n1],
                    section: b.section.clone(),
                    orientation: b.orientation,
                    initial_strain: b.initial_strain.unwrap_or([0.0; 6]),
                    initial_curve: b.initial_strain_curve.clone(),
                });
            }
        }

        // ---------- beam lines (mesh generation) ----------
        let mut next_node = node_ids.iter().copied().max().map_or(1, |m| m + 1);
        let mut next_element = input
            .beams
            .iter()
            .map(|b| b.id)
            .chain(input.rigid_bodies.iter().map(|b| b.id))
            .chain(input.point_masses.iter().map(|b| b.id))
            .chain(input.springs.iter().map(|b| b.id))
            .max()
            .map_or(1, |m| m + 1);
        for (k, line) in input.beam_lines.iter().enumerate() {
            let entity = format!(
                "beam_lines[{}] (nodes {} to {})",
                k + 1,
                line.nodes[0],
                line.nodes[1]
            );
            let a = resolve(&mut ck, &node_index, &entity, line.nodes[0]);
            let b = resolve(&mut ck, &node_index, &entity, line.nodes[1]);
            let (Some(a), Some(b)) = (a, b) else { continue };
            if a == b {
                ck.push(
                    ModelErrorKind::ZeroLength,
                    &entity,
                    "both ends are the same node",
                );
                continue;
            }
            if line.elements == 0 {
                ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    "needs at least one element",
                );
                continue;
            }
            let (xa, xb) = (nodes[a].x, nodes[b].x);
            let points = match line.arc_center {
                None => (1..line.elements)
                    .map(|i| xa + (xb - xa) * (i as f64 / line.elements as f64))
                    .collect::<Vec<_>>(),
                Some(c) => {
                    if !ck.finite(&entity, "arc_center", &c) {
                        continue;
                    }
                    match arc_points(Vec3::from(c), xa, xb, line.elements) {
                        Ok(p) => p,
                        Err(msg) => {
                            ck.push(ModelErrorKind::Invalid, &entity, msg);
                            continue;
                        }
                    }
                }
            };
            // interior nodes
            let mut first = line.first_node.unwrap_or(next_node);
            let mut chain = vec![a];
            for p in points {
                if node_index.contains_key(&first) {
                    ck.push(
                        ModelErrorKind::DuplicateId,
                        &entity,
                        format!("generated node id {first} is already used (set first_node)"),
                    );
                    break;
                }
                node_index.insert(first, nodes.len());
                node_ids.push(first);
                chain.push(nodes.len());
                nodes.push(NodeData {
                    x: p,
                    q: Rotation::identity(),
                });
                first += 1;
            }
            next_node = next_node.max(first);
            if chain.len() != line.elements {
                continue;
            }
            chain.push(b);
            let mut eid = line.first_element.unwrap_or(next_element);
            for w in chain.windows(2) {
                let ent = format!("beam {eid} (of {entity})");
                if claim_id(&mut ck, &ent, eid) {
                    beam_specs.push(BeamSpec {
                        entity: ent,
                        id: eid,
                        nodes: [w[0], w[1]],
                        section: line.section.clone(),
                        orientation: line.orientation,
                        initial_strain: line.initial_strain.unwrap_or([0.0; 6]),
                        initial_curve: line.initial_strain_curve.clone(),
                    });
                }
                eid += 1;
            }
            next_element = next_element.max(eid);
        }

        for spec in &beam_specs {
            let entity = &spec.entity;
            let Some(sec) = sections.get(&spec.section) else {
                if !bad_sections.contains(&spec.section) {
                    ck.push(
                        ModelErrorKind::UnknownSection,
                        entity,
                        format!("section \"{}\" is not defined", spec.section),
                    );
                }
                continue;
            };
            let [a, b] = spec.nodes;
            let axis = nodes[b].x - nodes[a].x;
            if axis.norm() <= 1e-12 * (1.0 + nodes[a].x.norm()) {
                ck.push(
                    ModelErrorKind::ZeroLength,
                    entity,
                    format!(
                        "zero length: nodes {} and {} coincide",
                        node_ids[a], node_ids[b]
                    ),
                );
                continue;
            }
            if !ck.finite(entity, "initial_strain", &spec.initial_strain) {
                continue;
            }
            let orientation = match spec.orientation {
                Some(o) => {
                    if !ck.finite(entity, "orientation", &o) {
                        continue;
                    }
                    Vec3::from(o)
                }
                None => default_orientation(&axis),
            };
            let initial = InitialStrain {
                strain: spec.initial_strain,
                curve: spec
                    .initial_curve
                    .as_ref()
                    .map(|name| find_curve(&mut ck, entity, &Some(name.clone()))),
            };
            match Beam::new(
                spec.id,
                [a, b],
                [nodes[a].x, nodes[b].x],
                [nodes[a].q, nodes[b].q],
                orientation,
                sec.clone(),
                initial,
            ) {
                Some(beam) => elements.push(Box::new(beam)),
                None => ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("orientation vector {orientation:?} is zero or parallel to the beam axis {axis:?}"),
                ),
            }
        }

        // ---------- rigid bodies and point masses ----------
        for rb in &input.rigid_bodies {
            let entity = format!("rigid body {}", rb.id);
            let id_ok = claim_id(&mut ck, &entity, rb.id);
            let node = resolve(&mut ck, &node_index, &entity, rb.node);
            let mass_ok = ck.positive(&entity, "mass", rb.mass);
            let inertia = match &rb.inertia {
                None => Some(Mat3::zeros()),
                Some(i) => inertia_tensor(&mut ck, &entity, i),
            };
            let offset = rb.center_of_mass.unwrap_or([0.0; 3]);
            let offset_ok = ck.finite(&entity, "center_of_mass", &offset);
            if let (true, Some(node), true, Some(inertia), true) =
                (id_ok, node, mass_ok, inertia, offset_ok)
            {
                elements.push(Box::new(RigidBody::new(
                    rb.id,
                    node,
                    rb.mass,
                    inertia,
                    Vec3::from(offset),
                )));
            }
        }
        for pm in &input.point_masses {
            let entity = format!("point mass {}", pm.id);
            let id_ok = claim_id(&mut ck, &entity, pm.id);
            let node = resolve(&mut ck, &node_index, &entity, pm.node);
            let mass_ok = ck.positive(&entity, "mass", pm.mass);
            if let (true, Some(node), true) = (id_ok, node, mass_ok) {
                elements.push(Box::new(RigidBody::point_mass(pm.id, node, pm.mass)));
            }
        }

        // ---------- springs ----------
        for s in &input.springs {
            let entity = format!("spring {}", s.id);
            let id_ok = claim_id(&mut ck, &entity, s.id);
            if s.nodes.is_empty() || s.nodes.len() > 2 {
                ck.push(
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
                ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    format!("connects node {} to itself", s.nodes[0]),
                );
                continue;
            }
            let idx: Vec<Option<usize>> = s
                .nodes
                .iter()
                .map(|&n| resolve(&mut ck, &node_index, &entity, n))
                .collect();
            let k = match s.stiffness {
                StiffnessInput::Isotropic(k) => [k; 3],
                StiffnessInput::PerAxis(k) => {
                    if s.kind == SpringKind::Axial {
                        ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            "an axial spring takes a single stiffness value",
                        );
                        continue;
                    }
                    k
                }
            };
            let k_ok = k.iter().all(|&v| ck.positive(&entity, "stiffness", v));
            if !(id_ok && k_ok) || idx.iter().any(|i| i.is_none()) {
                continue;
            }
            let idx: Vec<usize> = idx.into_iter().flatten().collect();
            let x0: Vec<Vec3> = idx.iter().map(|&i| nodes[i].x).collect();
            let r0: Vec<Rotation> = idx.iter().map(|&i| nodes[i].q).collect();
            match Spring::new(s.id, s.kind, &idx, &x0, &r0, Vec3::from(k)) {
                Some(sp) => elements.push(Box::new(sp)),
                None if idx.len() == 1 => ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    "an axial spring needs two nodes",
                ),
                None => ck.push(
                    ModelErrorKind::ZeroLength,
                    &entity,
                    format!(
                        "zero length: nodes {} and {} coincide",
                        s.nodes[0], s.nodes[1]
                    ),
                ),
            }
        }

        // ---------- loads ----------
        for (k, l) in input.loads.iter().enumerate() {
            let entity = format!("loads[{}] (node {})", k + 1, l.node);
            let node = resolve(&mut ck, &node_index, &entity, l.node);
            let curve = find_curve(&mut ck, &entity, &l.curve);
            if l.force.is_none() && l.moment.is_none() {
                ck.push(
                    ModelErrorKind::Missing,
                    &entity,
                    "needs a force, a moment or both",
                );
                continue;
            }
            let f = l.force.unwrap_or([0.0; 3]);
            let m = l.moment.unwrap_or([0.0; 3]);
            let ok = ck.finite(&entity, "force", &f) & ck.finite(&entity, "moment", &m);
            if let (Some(node), true) = (node, ok) {
                elements.push(Box::new(NodalLoad::new(
                    (k + 1) as Id,
                    node,
                    Vec3::from(f),
                    Vec3::from(m),
                    l.follower,
                    curve,
                )));
            }
        }

        // ---------- joints, joint springs, drivers ----------
        joints::build(
            &mut joints::Context {
                ck: &mut ck,
                node_index: &node_index,
                nodes: &nodes,
                claim_id: &mut claim_id,
                find_curve: &find_curve,
                elements: &mut elements,
            },
            input,
        );

        // ---------- gravity ----------
        let gravity = input.gravity.as_ref().and_then(|g| {
            let curve = find_curve(&mut ck, "gravity", &g.curve);
            ck.finite("gravity", "acceleration", &g.acceleration)
                .then(|| (Vec3::from(g.acceleration), curve))
        });

        // ---------- supports and prescribed motions ----------
        let mut fixed = vec![[false; 6]; nodes.len()];
        for (k, s) in input.supports.iter().enumerate() {
            let entity = format!("supports[{}] (node {})", k + 1, s.node);
            let Some(node) = resolve(&mut ck, &node_index, &entity, s.node) else {
                continue;
            };
            if s.fixed.is_empty() {
                ck.push(
                    ModelErrorKind::Missing,
                    &entity,
                    "lists no component to fix",
                );
            }
            for name in &s.fixed {
                match component_set(name) {
                    Some(set) => set.iter().for_each(|&c| fixed[node][c] = true),
                    None => ck.push(
                        ModelErrorKind::Invalid,
                        &entity,
                        format!(
                            "unknown component \"{name}\" (expected x, y, z, rx, ry, rz, translations, rotations or all)"
                        ),
                    ),
                }
            }
        }
        let mut prescribed = Vec::new();
        let mut prescribed_components: HashSet<(usize, usize)> = HashSet::new();
        for (k, p) in input.prescribed.iter().enumerate() {
            let entity = format!("prescribed[{}] (node {})", k + 1, p.node);
            let node = resolve(&mut ck, &node_index, &entity, p.node);
            let curve = find_curve(&mut ck, &entity, &p.curve);
            let Some(node) = node else { continue };
            match (&p.dof, p.value, p.rotation) {
                (Some(dof), Some(value), None) => {
                    let axis = match dof.as_str() {
                        "x" => 0,
                        "y" => 1,
                        "z" => 2,
                        _ => {
                            ck.push(
                                ModelErrorKind::Invalid,
                                &entity,
                                format!("dof must be x, y or z (use `rotation` for rotations), got \"{dof}\""),
                            );
                            continue;
                        }
                    };
                    if !ck.finite(&entity, "value", &[value]) {
                        continue;
                    }
                    if !prescribed_components.insert((node, axis)) {
                        ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            format!("component {dof} is prescribed twice"),
                        );
                        continue;
                    }
                    fixed[node][axis] = true;
                    prescribed.push(Prescribed::Translation {
                        node,
                        axis,
                        value,
                        curve,
                    });
                }
                (None, None, Some(rot)) => {
                    if !ck.finite(&entity, "rotation", &rot) {
                        continue;
                    }
                    if !prescribed_components.insert((node, 3)) {
                        ck.push(
                            ModelErrorKind::Invalid,
                            &entity,
                            "the rotation is prescribed twice",
                        );
                        continue;
                    }
                    fixed[node][3..].fill(true);
                    prescribed.push(Prescribed::Rotation {
                        node,
                        psi: Vec3::from(rot),
                        curve,
                    });
                }
                _ => ck.push(
                    ModelErrorKind::Invalid,
                    &entity,
                    "give either `dof` and `value` (a translation) or `rotation`",
                ),
            }
        }

        if settings.arc_length && !input.prescribed.is_empty() {
            ck.push(
                ModelErrorKind::Invalid,
                "analysis",
                "arc-length control does not take prescribed motions: use drivers instead",
            );
        }

        // ---------- global checks ----------
        if ck.errors.is_empty() {
            if elements
                .iter()
                .all(|e| e.kind() == crate::elements::ElementKind::NodalLoad)
            {
                ck.push(ModelErrorKind::Missing, "model", "has no elements");
            } else {
                check_restraint(&mut ck, &node_ids, &elements, &fixed);
            }
        }
        if !ck.errors.is_empty() {
            return Err(ModelErrors(ck.errors));
        }

        let length_scale = {
            let mut lo = Vec3::repeat(f64::INFINITY);
            let mut hi = Vec3::repeat(f64::NEG_INFINITY);
            for n in &nodes {
                lo = lo.inf(&n.x);
                hi = hi.sup(&n.x);
            }
            let d = (hi - lo).norm();
            if d > 0.0 && d.is_finite() {
                d
            } else {
                1.0
            }
        };
        let (mut extra, mut internal) = (0, 0);
        for e in &mut elements {
            e.set_offsets(extra, internal);
            extra += e.n_extra();
            internal += e.n_internal();
        }
        Ok(Model {
            title: input.title.clone().unwrap_or_default(),
            node_ids,
            node_lookup: node_index,
            reference_x: nodes.iter().map(|n| n.x).collect(),
            reference_q: nodes.iter().map(|n| n.q).collect(),
            elements,
            fixed,
            prescribed,
            curves,
            gravity,
            settings,
            length_scale,
            scaling: Default::default(),
        }
        .with_default_scaling(
            input.analysis.constraint_scale,
            input.analysis.constraint_penalty,
        ))
    }
}

/// The function of a curve given by `function` and its parameters.
fn curve_function(
    ck: &mut Checker,
    entity: &str,
    name: &str,
    c: &CurveInput,
) -> Option<crate::curves::Function> {
    use crate::curves::Function;
    if !c.points.is_empty() {
        ck.push(
            ModelErrorKind::Invalid,
            entity,
            "give either points or a function, not both",
        );
        return None;
    }
    let given: [(&str, Option<f64>); 9] = [
        ("offset", c.offset),
        ("slope", c.slope),
        ("amplitude", c.amplitude),
        ("frequency", c.frequency),
        ("phase", c.phase),
        ("start", c.start),
        ("end", c.end),
        ("from", c.from),
        ("to", c.to),
    ];
    let allowed: &[&str] = match name {
        "linear" => &["offset", "slope"],
        "sine" => &["offset", "amplitude", "frequency", "phase"],
        "smooth_step" => &["start", "end", "from", "to"],
        _ => {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!("unknown function \"{name}\" (available: linear, sine, smooth_step)"),
            );
            return None;
        }
    };
    let mut ok = true;
    for (key, v) in given {
        if let Some(v) = v {
            if !allowed.contains(&key) {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("`{key}` does not apply to a {name} curve"),
                );
                ok = false;
            } else {
                ok &= ck.finite(entity, key, &[v]);
            }
        }
    }
    let required = |ck: &mut Checker, key: &str, v: Option<f64>| {
        if v.is_none() {
            ck.push(
                ModelErrorKind::Missing,
                entity,
                format!("a {name} curve needs `{key}`"),
            );
        }
        v
    };
    let f = match name {
        "linear" => Function::Linear {
            offset: c.offset.unwrap_or(0.0),
            slope: c.slope.unwrap_or(1.0),
        },
        "sine" => Function::Sine {
            offset: c.offset.unwrap_or(0.0),
            amplitude: c.amplitude.unwrap_or(1.0),
            frequency: required(ck, "frequency", c.frequency)?,
            phase: c.phase.unwrap_or(0.0),
        },
        _ => {
            let (start, end) = (required(ck, "start", c.start), required(ck, "end", c.end));
            let (start, end) = (start?, end?);
            if start >= end {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    format!("start must be before end, got {start} and {end}"),
                );
                return None;
            }
            Function::SmoothStep {
                start,
                end,
                from: c.from.unwrap_or(0.0),
                to: c.to.unwrap_or(1.0),
            }
        }
    };
    ok.then_some(f)
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

/// Analysis settings with defaults (docs/model-format.md).
fn settings(ck: &mut Checker, a: &AnalysisInput) -> StaticSettings {
    if !matches!(a.kind.as_str(), "static" | "kinetostatic" | "kinematic") {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "unknown analysis type \"{}\" (available: static, kinetostatic, kinematic)",
                a.kind
            ),
        );
    }
    let end = a.end_time;
    ck.positive("analysis", "end_time", end);
    let initial = a.initial_increment.unwrap_or(end / 10.0);
    let s = StaticSettings {
        end_time: end,
        initial_increment: initial,
        min_increment: a.min_increment.unwrap_or(end * 1e-6),
        max_increment: a.max_increment.unwrap_or(initial),
        max_iterations: a.max_iterations.unwrap_or(25),
        // quadratic convergence makes 1e-8 cheap: one iteration more than 1e-4
        residual_tolerance: a.residual_tolerance.unwrap_or(1e-8),
        displacement_tolerance: a.displacement_tolerance.unwrap_or(1e-6),
        rotation_tolerance: a.rotation_tolerance.unwrap_or(1e-6),
        output_every: a.output_every.unwrap_or(1),
        kinematic: a.kind == "kinematic",
        arc_length: a.control.as_deref() == Some("arc_length"),
        max_increments: a.max_increments.unwrap_or(1000),
    };
    if !matches!(
        a.control.as_deref(),
        None | Some("load") | Some("arc_length")
    ) {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "unknown control \"{}\" (available: load, arc_length)",
                a.control.as_deref().unwrap_or("")
            ),
        );
    }
    if s.arc_length && s.kinematic {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            "a kinematic analysis follows its drivers: arc-length control does not apply",
        );
    }
    if let Some(k) = a.constraint_scale {
        ck.positive("analysis", "constraint_scale", k);
    }
    if let Some(p) = a.constraint_penalty {
        if !(p.is_finite() && p >= 0.0) {
            ck.push(
                ModelErrorKind::NonPositive,
                "analysis",
                format!("constraint_penalty must be zero or positive, got {p}"),
            );
        }
    }
    if s.max_increments == 0 {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            "max_increments must be at least 1",
        );
    }
    ck.positive("analysis", "initial_increment", s.initial_increment);
    ck.positive("analysis", "min_increment", s.min_increment);
    ck.positive("analysis", "max_increment", s.max_increment);
    ck.positive("analysis", "residual_tolerance", s.residual_tolerance);
    ck.positive(
        "analysis",
        "displacement_tolerance",
        s.displacement_tolerance,
    );
    ck.positive("analysis", "rotation_tolerance", s.rotation_tolerance);
    if s.max_iterations == 0 {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            "max_iterations must be at least 1",
        );
    }
    if s.output_every == 0 {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            "output_every must be at least 1",
        );
    }
    if s.min_increment > s.initial_increment || s.initial_increment > s.max_increment {
        ck.push(
            ModelErrorKind::Invalid,
            "analysis",
            format!(
                "increments must satisfy min_increment ≤ initial_increment ≤ max_increment, got {} ≤ {} ≤ {}",
                s.min_increment, s.initial_increment, s.max_increment
            ),
        );
    }
    s
}

/// Validated section properties.
fn section(ck: &mut Checker, entity: &str, s: &SectionInput) -> Option<BeamSection> {
    let diagonal = [
        ("EA", s.ea),
        ("GA2", s.ga2),
        ("GA3", s.ga3),
        ("GJ", s.gj),
        ("EI2", s.ei2),
        ("EI3", s.ei3),
    ];
    let given: Vec<&str> = diagonal
        .iter()
        .filter(|d| d.1.is_some())
        .map(|d| d.0)
        .collect();
    let stiffness = match (&s.stiffness, given.len()) {
        (Some(_), n) if n > 0 => {
            ck.push(
                ModelErrorKind::Invalid,
                entity,
                format!(
                    "give either the diagonal stiffnesses or `stiffness`, not both (found {})",
                    given.join(", ")
                ),
            );
            return None;
        }
        (Some(c), _) => {
            let m = SectionStiffness::from_fn(|i, j| c[i][j]);
            let flat: Vec<f64> = m.iter().copied().collect();
            if !ck.finite(entity, "stiffness", &flat) {
                return None;
            }
            let asym = (m - m.transpose()).abs().max();
            if asym > 1e-9 * m.abs().max() {
                ck.push(
                    ModelErrorKind::Invalid,
                    entity,
                    "the 6×6 stiffness matrix is not symmetric",
                );
                return None;
            }
            if m.cholesky().is_none() {
                ck.push(
                    ModelErrorKind::NonPositive,
                    entity,
                    "the 6×6 stiffness matrix is not positive definite",
                );
                return None;
            }
            m
        }
        (None, 0) => {
            ck.push(
                ModelErrorKind::Missing,
                entity,
                "no stiffness: give EA, GA2, GA3, GJ, EI2, EI3 or a 6×6 `stiffness`",
            );
            return None;
        }
        (None, _) => {
            let missing: Vec<&str> = diagonal
                .iter()
                .filter(|d| d.1.is_none())
                .map(|d| d.0)
                .collect();
            if !missing.is_empty() {
                ck.push(
                    ModelErrorKind::Missing,
                    entity,
                    format!("missing {}", missing.join(", ")),
                );
                return None;
            }
            let mut ok = true;
            for (name, v) in diagonal {
                ok &= ck.positive(entity, name, v.unwrap());
            }
            if !ok {
                return None;
            }
            SectionStiffness::from_diagonal(&nalgebra::Vector6::from_fn(|i, _| {
                diagonal[i].1.unwrap()
            }))
        }
    };
    let mass = s.mass_per_length.unwrap_or(0.0);
    let inertia = s.inertia_per_length.unwrap_or([0.0; 3]);
    let mut ok = true;
    if !(mass.is_finite() && mass >= 0.0) {
        ck.push(
            ModelErrorKind::NonPositive,
            entity,
            format!("mass_per_length must be ≥ 0, got {mass}"),
        );
        ok = false;
    }
    if inertia.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        ck.push(
            ModelErrorKind::NonPositive,
            entity,
            format!("inertia_per_length must be ≥ 0, got {inertia:?}"),
        );
        ok = false;
    }
    ok.then(|| BeamSection {
        stiffness,
        mass_per_length: mass,
        inertia_per_length: Vec3::from(inertia),
    })
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

/// Points strictly inside a circular arc from `a` to `b` about `c`.
fn arc_points(c: Vec3, a: Vec3, b: Vec3, n: usize) -> Result<Vec<Vec3>, String> {
    let (ra, rb) = (a - c, b - c);
    let (la, lb) = (ra.norm(), rb.norm());
    if la <= 0.0 || (la - lb).abs() > 1e-6 * la {
        return Err(format!(
            "arc_center is not equidistant from the end nodes (radii {la} and {lb})"
        ));
    }
    let axis = ra.cross(&rb);
    if axis.norm() <= 1e-9 * la * lb {
        return Err(
            "the end nodes and arc_center are aligned: the arc's plane is undefined".into(),
        );
    }
    let angle = axis.norm().atan2(ra.dot(&rb));
    let axis = axis.normalize();
    Ok((1..n)
        .map(|i| c + so3::exp_matrix(&(axis * (angle * i as f64 / n as f64))) * ra)
        .collect())
}

/// Every group of connected nodes must be held by a support, a prescribed
/// motion or a spring to ground; otherwise it is free to move as a rigid
/// body and the tangent is singular.
fn check_restraint(
    ck: &mut Checker,
    node_ids: &[Id],
    elements: &[Box<dyn Element>],
    fixed: &[[bool; 6]],
) {
    let n = node_ids.len();
    // union-find over nodes connected by elements
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let mut connected = vec![false; n];
    let mut grounded = vec![false; n];
    for e in elements {
        let kind = e.kind();
        if kind == crate::elements::ElementKind::NodalLoad {
            continue;
        }
        let nodes = e.nodes();
        for &a in nodes {
            connected[a] |= kind != crate::elements::ElementKind::PointMass
                && kind != crate::elements::ElementKind::RigidBody;
        }
        if nodes.len() == 1
            && matches!(
                kind,
                crate::elements::ElementKind::Spring
                    | crate::elements::ElementKind::Joint
                    | crate::elements::ElementKind::Driver
            )
        {
            grounded[nodes[0]] = true;
        }
        for w in nodes.windows(2) {
            let (ra, rb) = (find(&mut parent, w[0]), find(&mut parent, w[1]));
            parent[ra] = rb;
        }
    }
    for i in 0..n {
        if !connected[i] && !fixed[i].iter().all(|&f| f) {
            ck.push(
                ModelErrorKind::Unrestrained,
                format!("node {}", node_ids[i]),
                "is not connected to any beam, spring or joint and not fully fixed: it has no stiffness",
            );
        }
    }
    let mut held: HashMap<usize, bool> = HashMap::new();
    for i in 0..n {
        let root = find(&mut parent, i);
        let h = fixed[i].iter().any(|&f| f) || grounded[i];
        *held.entry(root).or_insert(false) |= h;
    }
    let mut free_groups: Vec<Vec<Id>> = Vec::new();
    let mut group_of: HashMap<usize, usize> = HashMap::new();
    for i in 0..n {
        if !connected[i] {
            continue;
        }
        let root = find(&mut parent, i);
        if !held[&root] {
            let g = *group_of.entry(root).or_insert_with(|| {
                free_groups.push(Vec::new());
                free_groups.len() - 1
            });
            free_groups[g].push(node_ids[i]);
        }
    }
    for g in free_groups {
        let shown: Vec<String> = g.iter().take(8).map(|i| i.to_string()).collect();
        let more = if g.len() > 8 {
            format!(" and {} more", g.len() - 8)
        } else {
            String::new()
        };
        ck.push(
            ModelErrorKind::Unrestrained,
            format!("nodes {}{more}", shown.join(", ")),
            "form a free body: no support, prescribed motion or spring to ground restrains them (unrestrained rigid-body motion)",
        );
    }
}
