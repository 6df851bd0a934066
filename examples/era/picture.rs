//! Line drawings of configurations of the model: the members as lines,
//! the corner bodies as the arms from the longerons' end nodes to their
//! hinge points, the mid-hinges as dots.

use unfold::io::plot::{Panel, Segment, Wireframe};
use unfold::model::builder::NodeHandle;
use unfold::model::Model;
use unfold::state::State;

use super::model::{Built, Member};

/// Names of the groups of lines, in the order of their indices.
pub const GROUPS: [&str; 5] = [
    "longerons",
    "horizontals",
    "diagonals",
    "corner bodies (to the hinge points)",
    "mid-hinges",
];

/// The lines of a member's elements.
fn chain(m: &Member, group: usize, lines: &mut Vec<(NodeHandle, NodeHandle, usize)>) {
    for w in m.nodes.windows(2) {
        lines.push((w[0], w[1], group));
    }
}

/// The configuration `state` of the model of `built`, captioned `label`.
pub fn panel(built: &Built, model: &Model, state: &State, label: &str) -> Panel {
    let at = |n: NodeHandle| {
        let x = state.x[model.node(n)];
        [x.x, x.y, x.z]
    };
    let parts = &built.parts;
    let mut lines = Vec::new();
    let mut points = Vec::new();
    for c in &parts.columns {
        chain(&c.longeron, 0, &mut lines);
    }
    for face in &parts.faces {
        let [a, b] = face.columns.map(|k| &parts.columns[k]);
        for h in [&face.top, &face.bottom] {
            for half in &h.halves {
                chain(half, 1, &mut lines);
            }
            points.push((at(h.halves[0].end()), 4));
        }
        for d in &face.diagonals {
            chain(d, 2, &mut lines);
        }
        // corner bodies: from the longeron's end node to each hinge point
        lines.extend([
            (a.top, face.top.halves[0].start(), 3),
            (b.top, face.top.halves[1].start(), 3),
            (a.bottom, face.bottom.halves[0].start(), 3),
            (b.bottom, face.bottom.halves[1].start(), 3),
            (a.bottom, face.diagonals[0].start(), 3),
            (b.bottom, face.diagonals[1].start(), 3),
        ]);
    }
    Panel {
        label: label.into(),
        segments: lines
            .into_iter()
            .map(|(a, b, group)| Segment {
                from: at(a),
                to: at(b),
                group,
            })
            .collect(),
        points,
    }
}

/// A drawing of `panels` titled `title`.
pub fn drawing(title: &str, panels: Vec<Panel>) -> Wireframe {
    panels
        .into_iter()
        .fold(Wireframe::new(title, GROUPS), Wireframe::panel)
}
