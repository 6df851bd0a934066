//! The checks of the whole model, once every entity is built: every part
//! of the structure is held, and every element gives finite forces and
//! stiffness in the reference configuration.

use std::collections::HashMap;

use super::{Checker, LARGEST_ELEMENT_VALUE};
use crate::elements::{Element, ElementKind};
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
