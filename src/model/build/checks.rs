//! The checks of the whole model, once every entity is built: every part
//! of the structure is held, and every element gives finite forces and
//! stiffness in the reference configuration.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use super::{Checker, LARGEST_ELEMENT_VALUE};
use crate::elements::{Element, ElementKind};
use crate::io::number::plain;
use crate::io::run::format_time;
use crate::model::input::ModelInput;
use crate::model::{Id, Model, ModelError, ModelErrorKind};

/// Elements whose forces or tangent are not finite, or beyond
/// [`LARGEST_ELEMENT_VALUE`], in the reference configuration at the start,
/// the middle or the end of the analysis: values each acceptable whose
/// products are not (a mass times the gravity, a stiffness over a length,
/// a load times its curve), on which the analysis could only stop. One
/// error per kind of element and time, naming the first element and
/// counting the others.
pub(super) fn non_finite_elements(model: &Model, end: f64) -> Vec<ModelError> {
    let mut errors = Vec::new();
    let mut bad = vec![false; model.elements.len()];
    for t in [0.0, 0.5 * end, end] {
        let mut state = model.initial_state();
        state.time = t;
        model.apply_prescribed(&mut state, t);
        let ctx = model.context(t, crate::elements::Need::STIFFNESS);
        // (kind, first entity, count) of the elements found at this time
        let mut found: Vec<(ElementKind, String, usize)> = Vec::new();
        for (k, e) in model.elements.iter().enumerate() {
            if bad[k] {
                continue;
            }
            let n = e.n_local();
            let (mut r, mut tangent) = (vec![0.0; n], vec![0.0; n * n]);
            e.evaluate(
                &ctx,
                &state,
                &mut crate::elements::ElementOutput::with_stiffness(&mut r, &mut tangent),
            );
            if r.iter()
                .chain(&tangent)
                .all(|v| v.abs() <= LARGEST_ELEMENT_VALUE)
            {
                continue;
            }
            bad[k] = true;
            match found.iter_mut().find(|f| f.0 == e.kind()) {
                Some(f) => f.2 += 1,
                None => {
                    let entity = match e.kind() {
                        ElementKind::NodalLoad => {
                            format!("loads[{}] (node {})", e.id(), model.node_ids[e.nodes()[0]])
                        }
                        kind => format!("{} {}", kind.name(), e.id()),
                    };
                    found.push((e.kind(), entity, 1));
                }
            }
        }
        for (kind, entity, count) in found {
            let others = match count {
                1 => String::new(),
                n => format!(" (and {} other {} elements)", n - 1, kind.name()),
            };
            errors.push(ModelError {
                kind: ModelErrorKind::Invalid,
                entity: format!("{entity}{others}"),
                message: format!(
                    "its forces or stiffness in the reference configuration at t = {t} are not finite or exceed {LARGEST_ELEMENT_VALUE:e}: its values, or their products with the gravity, the loads and the curves, are out of range"
                ),
            });
        }
    }
    errors
}

/// Every group of connected nodes must be held by a support, a prescribed
/// motion or a spring to ground; otherwise it is free to move as a rigid
/// body and the tangent is singular.
pub(super) fn check_restraint(
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
                    | crate::elements::ElementKind::RollingDisc
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

/// A joint point farther from a body's node than this many times the
/// body's reach (the farthest point of its shape from its node) is
/// warned of as a likely slip in `position` or in the nodes joined.
pub const JOINT_REACH_FACTOR: f64 = 2.0;

/// Rigid bodies and point masses whose masses differ by this factor or
/// more are warned of as a likely unit slip (grams among kilograms).
pub const MASS_RATIO_WARNING: f64 = 500.0;

/// Warnings about a model that is valid but likely not the one meant
/// (docs/model-format.md, "Checks, warnings and limits"):
///
/// - a joint whose point lies far from a rigid body it joins, beyond
///   [`JOINT_REACH_FACTOR`] times the body's reach from its node (the
///   farthest point of its drawn shape: by default the box of its mass
///   and inertia) and beyond a tenth of the model's size: a hinge 4.5 m
///   from the panels it joins, or an axis given through the wrong point.
///   Nodes without a body of finite extent (a beam's node, a point mass,
///   the bob of a pendulum modelled as a node with joints) are not
///   judged: their links to their joints are rigid by construction;
/// - bodies and point masses (not held fixed) whose masses span [`MASS_RATIO_WARNING`] or
///   more: grams among kilograms;
/// - a rigid body (not held fixed) given a mass and no `inertia`: it turns
///   without rotational inertia;
/// - two latches on one joint at the same value: the second locks nothing
///   the first does not (a latch put on the wrong joint);
/// - a joint driven by a joint spring or a hinge law with neither latch
///   nor stop, in a model whose other driven joints have them: its latch
///   is missing, or on another joint.
pub(super) fn suspect_model(model: &Model, input: &ModelInput) -> Vec<(String, String)> {
    let mut warnings = Vec::new();
    latched_joints(model, input, &mut warnings);
    for b in &input.rigid_bodies {
        let fixed = model
            .node_index(b.node)
            .is_some_and(|n| model.fixed[n].iter().all(|&f| f));
        if b.inertia.is_none() && b.mass > 0.0 && !fixed {
            warnings.push((
                format!("rigid body {}", b.id),
                "has a mass and no `inertia` (zero by default): it turns without rotational inertia, as a point mass would, and is drawn as a point; give its inertia about its centre of mass, or `inertia = [0, 0, 0]` if that is meant".to_string(),
            ));
        }
    }
    let state = model.initial_state();
    // the reach of the bodies on each node, and the body
    let mut reach: HashMap<usize, (f64, Id)> = HashMap::new();
    for e in &model.elements {
        let (Some(shape), Some(&node)) = (e.body_shape(), e.nodes().first()) else {
            continue;
        };
        let r = shape.reach();
        let entry = reach.entry(node).or_insert((0.0, e.id()));
        if r > entry.0 {
            *entry = (r, e.id());
        }
    }
    let size = model.length_scale;
    let mut points = Vec::new();
    for e in &model.elements {
        if e.kind() != ElementKind::Joint {
            continue;
        }
        points.clear();
        e.attachments(&state, &mut points);
        // the first far point of the joint, if any
        let far = points.iter().find_map(|a| {
            let node = a.node?;
            let &(r, body) = reach.get(&node)?;
            let d = (a.point - state.x[node]).norm();
            (r > 0.0 && d > JOINT_REACH_FACTOR * r && d > 0.1 * size).then_some((node, d, r, body))
        });
        if let Some((node, d, r, body)) = far {
            warnings.push((
                format!("joint {}", e.id()),
                format!(
                    "its point lies {} from node {}, whose rigid body {body} reaches {} from it (the farthest point of its shape, by default the box of its mass and inertia): a joint is usually on or near the bodies it joins; check the joint's position and nodes, and the body's inertia",
                    format_time(d),
                    model.node_ids[node],
                    format_time(r)
                ),
            ));
        }
    }
    // masses of the bodies and point masses
    let masses: Vec<(f64, &dyn Element)> = model
        .elements
        .iter()
        .filter(|e| matches!(e.kind(), ElementKind::RigidBody | ElementKind::PointMass))
        // a body held fixed (a spacecraft drawn for the view) moves no mass
        .filter(|e| {
            e.nodes()
                .first()
                .is_none_or(|&n| !model.fixed[n].iter().all(|&f| f))
        })
        .map(|e| (e.mass(), e.as_ref()))
        .filter(|(m, _)| *m > 0.0)
        .collect();
    let lightest = masses.iter().min_by(|a, b| a.0.total_cmp(&b.0));
    let heaviest = masses.iter().max_by(|a, b| a.0.total_cmp(&b.0));
    if let (Some(&(low, light)), Some(&(high, heavy))) = (lightest, heaviest) {
        if high >= MASS_RATIO_WARNING * low {
            warnings.push((
                "model".to_string(),
                format!(
                    "the masses of its bodies span a factor of {}: {} {} has {} and {} {} has {}; if that is not meant, a mass is in other units than the rest (grams among kilograms)",
                    plain((high / low).round()),
                    light.kind().name(),
                    light.id(),
                    plain(low),
                    heavy.kind().name(),
                    heavy.id(),
                    plain(high)
                ),
            ));
        }
    }
    warnings
}

/// The latches of a model against its joints ([`suspect_model`]): two
/// latches at one value on one joint, and driven joints left without a
/// latch or a stop where the others have one.
fn latched_joints(model: &Model, input: &ModelInput, warnings: &mut Vec<(String, String)>) {
    // (latch id, value, is angle) by joint, in the order of the elements
    let mut by_joint: BTreeMap<Id, Vec<(Id, f64, bool)>> = BTreeMap::new();
    for e in &model.elements {
        if let Some(l) = e.as_latch() {
            by_joint
                .entry(l.joint())
                .or_default()
                .push((e.id(), l.value(), l.is_angle()));
        }
    }
    for (joint, latches) in &by_joint {
        for (k, &(id, value, angle)) in latches.iter().enumerate() {
            // the same value to 1e-9 rad, or 1e-9 of the model's size
            let scale = if angle { 1.0 } else { model.length_scale };
            let twin = latches[..k]
                .iter()
                .find(|l| (l.1 - value).abs() <= 1e-9 * scale);
            if let Some(&(first, _, _)) = twin {
                warnings.push((
                    format!("latch {id}"),
                    format!(
                        "locks joint {joint} at the value at which latch {first} locks it already: it locks nothing latch {first} does not; if it is meant for another joint, its `joint` is wrong"
                    ),
                ));
            }
        }
    }
    let ended: BTreeSet<Id> = by_joint
        .keys()
        .copied()
        .chain(input.stops.iter().map(|s| s.joint))
        .collect();
    // joints driven by a spring or a hinge law, with the element that drives each
    let mut driven: BTreeMap<Id, String> = BTreeMap::new();
    for s in &input.joint_springs {
        driven
            .entry(s.joint)
            .or_insert_with(|| format!("joint spring {}", s.id));
    }
    for h in &input.hinge_laws {
        driven
            .entry(h.joint)
            .or_insert_with(|| format!("hinge law {}", h.id));
    }
    let with = driven.keys().filter(|j| ended.contains(j)).count();
    if with == 0 {
        return;
    }
    for (joint, by) in driven.iter().filter(|(j, _)| !ended.contains(j)) {
        warnings.push((
            format!("joint {joint}"),
            format!(
                "is driven by {by} and has neither latch nor stop, where {with} other driven joint{} {}: if it is meant to lock at the end of its travel, its latch is missing or was given another joint",
                if with == 1 { "" } else { "s" },
                if with == 1 { "has one" } else { "have one" }
            ),
        ));
    }
}
