//! Degrees of freedom: which node components and extra unknowns are free,
//! and their equation numbers.
//!
//! A model has `6·n_nodes + n_extra` degrees of freedom ("dofs"): dof
//! `6·i + c` is component `c` (x, y, z, rx, ry, rz) of node `i`, then come
//! the extra unknowns of the elements in element order. Fixed and
//! prescribed components get no equation. Free node components are
//! numbered node by node in reverse Cuthill–McKee order of the node graph,
//! which keeps the equations of neighbouring nodes close (a banded pattern
//! and local memory access in assembly); the sparse LU then applies its own
//! fill-reducing column ordering (COLAMD, on the same blocks) on top.
//!
//! The equations come in *blocks*: the free components of one node, or the
//! kept extra unknowns of one element, always have consecutive equation
//! numbers in local order. Assembly builds the tangent's pattern block by
//! block from this ([`DofMap::node_equations`],
//! [`DofMap::extra_equations`]).

use std::collections::VecDeque;
use std::ops::Range;

use crate::model::Model;

/// Marks a dof without an equation.
pub const NO_EQUATION: usize = usize::MAX;

/// What a dof is, for norms and messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DofKind {
    /// Node translation (a force is its dual).
    Translation,
    /// Node rotation (a moment is its dual).
    Rotation,
    /// Extra unknown of an element.
    Extra,
}

/// Numbering of the free dofs.
#[derive(Clone, Debug)]
pub struct DofMap {
    n_nodes: usize,
    /// Equation of each dof, or [`NO_EQUATION`].
    equation: Vec<usize>,
    /// Dof of each equation.
    dof: Vec<usize>,
    /// Offset of each element's extra unknowns in the extra block.
    extra_offset: Vec<usize>,
    /// First equation of each node's free components and one past the
    /// last (equal if the node is fixed).
    node_equations: Vec<[usize; 2]>,
    /// The same for the kept extra unknowns of each element.
    extra_equations: Vec<[usize; 2]>,
}

impl DofMap {
    /// Numbers the free dofs of `model`.
    pub fn new(model: &Model) -> Self {
        Self::with_suppressed(model, &[])
    }

    /// Numbers the free dofs of `model`, leaving out the extra unknowns
    /// listed in `suppressed` (indices into the extra block): the
    /// multipliers of redundant constraints, which stay at zero.
    pub fn with_suppressed(model: &Model, suppressed: &[usize]) -> Self {
        let n_nodes = model.n_nodes();
        let mut extra_offset = Vec::with_capacity(model.elements.len());
        let mut n_extra = 0;
        for e in &model.elements {
            extra_offset.push(n_extra);
            n_extra += e.n_extra();
        }
        let n_dofs = 6 * n_nodes + n_extra;
        let mut equation = vec![NO_EQUATION; n_dofs];
        let mut dof = Vec::with_capacity(n_dofs);
        let mut node_equations = vec![[0, 0]; n_nodes];
        for node in node_order(model) {
            let first = dof.len();
            for c in 0..6 {
                if !model.fixed[node][c] {
                    equation[6 * node + c] = dof.len();
                    dof.push(6 * node + c);
                }
            }
            node_equations[node] = [first, dof.len()];
        }
        let mut kept = vec![true; n_extra];
        for &k in suppressed {
            if let Some(keep) = kept.get_mut(k) {
                *keep = false;
            }
        }
        let mut extra_equations = Vec::with_capacity(model.elements.len());
        for (e, element) in model.elements.iter().enumerate() {
            let first = dof.len();
            for k in extra_offset[e]..extra_offset[e] + element.n_extra() {
                if kept[k] {
                    equation[6 * n_nodes + k] = dof.len();
                    dof.push(6 * n_nodes + k);
                }
            }
            extra_equations.push([first, dof.len()]);
        }
        Self {
            n_nodes,
            equation,
            dof,
            extra_offset,
            node_equations,
            extra_equations,
        }
    }

    /// Number of equations (free unknowns).
    pub fn n_equations(&self) -> usize {
        self.dof.len()
    }

    /// Total number of dofs, free or not.
    pub fn n_dofs(&self) -> usize {
        self.equation.len()
    }

    /// Equation of a dof, or [`NO_EQUATION`].
    #[inline]
    pub fn equation(&self, dof: usize) -> usize {
        self.equation[dof]
    }

    /// Dof of an equation.
    #[inline]
    pub fn dof(&self, equation: usize) -> usize {
        self.dof[equation]
    }

    /// Equations of the free components of `node`, consecutive and in
    /// component order (empty if the node is fixed).
    #[inline]
    pub fn node_equations(&self, node: usize) -> Range<usize> {
        let [a, b] = self.node_equations[node];
        a..b
    }

    /// Equations of the kept extra unknowns of `element`, consecutive and
    /// in local order.
    #[inline]
    pub fn extra_equations(&self, element: usize) -> Range<usize> {
        let [a, b] = self.extra_equations[element];
        a..b
    }

    /// Kind of a dof.
    #[inline]
    pub fn kind(&self, dof: usize) -> DofKind {
        if dof >= 6 * self.n_nodes {
            DofKind::Extra
        } else if dof % 6 < 3 {
            DofKind::Translation
        } else {
            DofKind::Rotation
        }
    }

    /// Node and component of a node dof.
    pub fn node_component(&self, dof: usize) -> Option<(usize, usize)> {
        (dof < 6 * self.n_nodes).then_some((dof / 6, dof % 6))
    }

    /// Dofs of an element's local unknowns, in local order.
    pub fn element_dofs(&self, model: &Model, element: usize) -> Vec<usize> {
        let mut d: Vec<usize> = model.elements[element]
            .nodes()
            .iter()
            .flat_map(|&n| (0..6).map(move |c| 6 * n + c))
            .collect();
        d.extend(self.element_extra_dofs(model, element));
        d
    }

    /// Dofs of an element's extra unknowns, in local order.
    pub fn element_extra_dofs(&self, model: &Model, element: usize) -> Range<usize> {
        let base = 6 * self.n_nodes + self.extra_offset[element];
        base..base + model.elements[element].n_extra()
    }
}

/// Node order: reverse Cuthill–McKee on the graph of nodes sharing an
/// element, each connected component started from a node of minimum
/// degree.
fn node_order(model: &Model) -> Vec<usize> {
    let n = model.n_nodes();
    // adjacency in compressed form
    let mut degree = vec![0usize; n];
    for e in &model.elements {
        let k = e.nodes().len();
        for &a in e.nodes() {
            degree[a] += k - 1;
        }
    }
    let mut start = vec![0usize; n + 1];
    for i in 0..n {
        start[i + 1] = start[i] + degree[i];
    }
    let mut fill = start.clone();
    let mut adj = vec![0usize; start[n]];
    for e in &model.elements {
        for &a in e.nodes() {
            for &b in e.nodes() {
                if a != b {
                    adj[fill[a]] = b;
                    fill[a] += 1;
                }
            }
        }
    }
    let mut visited = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut by_degree: Vec<usize> = (0..n).collect();
    by_degree.sort_by_key(|&i| degree[i]);
    let mut queue = VecDeque::new();
    let mut neighbours = Vec::new();
    for &root in &by_degree {
        if visited[root] {
            continue;
        }
        visited[root] = true;
        queue.push_back(root);
        while let Some(a) = queue.pop_front() {
            order.push(a);
            neighbours.clear();
            neighbours.extend(
                adj[start[a]..start[a + 1]]
                    .iter()
                    .copied()
                    .filter(|&b| !visited[b]),
            );
            neighbours.sort_by_key(|&b| degree[b]);
            for &b in &neighbours {
                if !visited[b] {
                    visited[b] = true;
                    queue.push_back(b);
                }
            }
        }
    }
    order.reverse();
    order
}
