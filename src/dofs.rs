//! Degrees of freedom: which node components, coordinates and multipliers
//! are free, and their equation numbers.
//!
//! A model has `6·n_nodes + n_coordinates + n_multipliers` degrees of
//! freedom ("dofs"), numbered in this order: dof `6·i + c` is component `c`
//! (x, y, z, rx, ry, rz) of node `i`; then come the generalised coordinates
//! of the elements, in element order ([`crate::state::State::coordinates`]),
//! then their multipliers ([`crate::state::State::multipliers`]). Fixed and
//! prescribed components get no equation, nor do the multipliers of
//! redundant constraints. Free node components are numbered node by node in
//! reverse Cuthill–McKee order of the node graph, which keeps the equations
//! of neighbouring nodes close (a banded pattern and local memory access in
//! assembly); the sparse LU then applies its own fill-reducing column
//! ordering (COLAMD, on the same blocks) on top.
//!
//! The equations come in *blocks*: the free components of one node, or the
//! kept coordinates and multipliers of one element (coordinates first),
//! always have consecutive equation numbers in local order. Assembly builds
//! the tangent's pattern block by block from this
//! ([`DofMap::node_equations`], [`DofMap::element_equations`]), and the
//! local vector of an element maps onto it directly.

use std::collections::VecDeque;
use std::ops::Range;

use crate::elements::ConstraintKind;
use crate::model::Model;

/// Marks a dof without an equation.
pub const NO_EQUATION: usize = usize::MAX;

/// What a dof is: its units, its residual group and its tolerance in the
/// convergence test (docs/theory.md §7.1), and its place in messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DofKind {
    /// Node translation (a force is its dual).
    Translation,
    /// Node rotation (a moment is its dual).
    Rotation,
    /// Generalised coordinate of an element; a unit of it moves the model
    /// by `length` (1 for a coordinate that is itself a length, such as a
    /// slider's parameter).
    Coordinate {
        /// Displacement per unit of the coordinate.
        length: f64,
    },
    /// Multiplier of a constraint on a distance or an angle (its
    /// equation is `−k Φ = 0`).
    Multiplier(ConstraintKind),
}

/// Numbering of the free dofs.
#[derive(Clone, Debug)]
pub struct DofMap {
    n_nodes: usize,
    n_coordinates: usize,
    /// Equation of each dof, or [`NO_EQUATION`].
    equation: Vec<usize>,
    /// Dof of each equation.
    dof: Vec<usize>,
    /// Kind of each coordinate and multiplier (from `6·n_nodes` on).
    extra_kinds: Vec<DofKind>,
    /// Offset of each element's coordinates in `State::coordinates`.
    coordinate_offset: Vec<usize>,
    /// Offset of each element's multipliers in `State::multipliers`.
    multiplier_offset: Vec<usize>,
    /// First equation of each node's free components and one past the
    /// last (equal if the node is fixed).
    node_equations: Vec<[usize; 2]>,
    /// The same for the kept coordinates and multipliers of each element.
    element_equations: Vec<[usize; 2]>,
}

impl DofMap {
    /// Numbers the free dofs of `model`.
    pub fn new(model: &Model) -> Self {
        Self::with_suppressed(model, &[])
    }

    /// Numbers the free dofs of `model`, leaving out the multipliers
    /// listed in `suppressed` (indices into [`crate::state::State::multipliers`]):
    /// those of redundant constraints, which stay at zero.
    pub fn with_suppressed(model: &Model, suppressed: &[usize]) -> Self {
        let n_nodes = model.n_nodes();
        let n_el = model.elements.len();
        let mut coordinate_offset = Vec::with_capacity(n_el);
        let mut multiplier_offset = Vec::with_capacity(n_el);
        let (mut nc, mut nm) = (0, 0);
        for e in &model.elements {
            coordinate_offset.push(nc);
            multiplier_offset.push(nm);
            nc += e.n_coordinates();
            nm += e.n_multipliers();
        }
        let mut extra_kinds = Vec::with_capacity(nc + nm);
        for e in &model.elements {
            extra_kinds.extend((0..e.n_coordinates()).map(|k| DofKind::Coordinate {
                length: e.coordinate_length(k),
            }));
        }
        for e in &model.elements {
            extra_kinds
                .extend((0..e.n_multipliers()).map(|k| DofKind::Multiplier(e.multiplier_kind(k))));
        }
        let n_dofs = 6 * n_nodes + nc + nm;
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
        let mut kept = vec![true; nm];
        for &k in suppressed {
            if let Some(keep) = kept.get_mut(k) {
                *keep = false;
            }
        }
        let mut element_equations = Vec::with_capacity(n_el);
        let (first_c, first_m) = (6 * n_nodes, 6 * n_nodes + nc);
        for (e, element) in model.elements.iter().enumerate() {
            let first = dof.len();
            let c0 = coordinate_offset[e];
            for d in first_c + c0..first_c + c0 + element.n_coordinates() {
                equation[d] = dof.len();
                dof.push(d);
            }
            let m0 = multiplier_offset[e];
            for k in m0..m0 + element.n_multipliers() {
                if kept[k] {
                    equation[first_m + k] = dof.len();
                    dof.push(first_m + k);
                }
            }
            element_equations.push([first, dof.len()]);
        }
        Self {
            n_nodes,
            n_coordinates: nc,
            equation,
            dof,
            extra_kinds,
            coordinate_offset,
            multiplier_offset,
            node_equations,
            element_equations,
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

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    /// Dof of the first coordinate (`6·n_nodes`).
    pub fn first_coordinate(&self) -> usize {
        6 * self.n_nodes
    }

    /// Dof of the first multiplier.
    pub fn first_multiplier(&self) -> usize {
        6 * self.n_nodes + self.n_coordinates
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

    /// Equations of the coordinates and kept multipliers of `element`,
    /// consecutive and in local order.
    #[inline]
    pub fn element_equations(&self, element: usize) -> Range<usize> {
        let [a, b] = self.element_equations[element];
        a..b
    }

    /// Kind of a dof.
    #[inline]
    pub fn kind(&self, dof: usize) -> DofKind {
        if dof >= 6 * self.n_nodes {
            self.extra_kinds[dof - 6 * self.n_nodes]
        } else if dof % 6 < 3 {
            DofKind::Translation
        } else {
            DofKind::Rotation
        }
    }

    /// Kind of the dof of an equation.
    #[inline]
    pub fn equation_kind(&self, equation: usize) -> DofKind {
        self.kind(self.dof[equation])
    }

    /// Node and component of a node dof.
    pub fn node_component(&self, dof: usize) -> Option<(usize, usize)> {
        (dof < 6 * self.n_nodes).then_some((dof / 6, dof % 6))
    }

    /// Index in [`crate::state::State::multipliers`] of a multiplier dof.
    pub fn multiplier_index(&self, dof: usize) -> Option<usize> {
        dof.checked_sub(self.first_multiplier())
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

    /// Dofs of an element's coordinates then multipliers, in local order.
    pub fn element_extra_dofs(
        &self,
        model: &Model,
        element: usize,
    ) -> impl Iterator<Item = usize> + Clone {
        let e = &model.elements[element];
        let c = self.first_coordinate() + self.coordinate_offset[element];
        let m = self.first_multiplier() + self.multiplier_offset[element];
        (c..c + e.n_coordinates()).chain(m..m + e.n_multipliers())
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
