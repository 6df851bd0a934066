//! Assembly of the global residual and tangent.
//!
//! The sparsity pattern is built once from the element connectivity, with a
//! map from every local tangent entry of every element to its position in
//! the compressed-column value array. Each evaluation then
//! 1. evaluates all elements in parallel, each into its own preallocated
//!    slice of one buffer (no locks, no allocation);
//! 2. scatters the local residuals and tangents through the maps.
//!
//! Besides the residual `r`, assembly accumulates the *force flux*
//! `Σₑ |rₑ|` at every dof: the magnitude of the forces flowing through it,
//! which does not cancel at equilibrium and is the reference for the
//! relative residual tolerance.

use crate::dofs::{DofMap, NO_EQUATION};
use crate::elements::{Element, ElementOutput, EvalContext};
use crate::linalg::SparseMatrix;
use crate::model::Model;
use crate::state::State;

const NONE: u32 = u32::MAX;

/// Global system storage and the maps that fill it.
pub struct Assembler {
    /// The tangent, in equation numbering.
    pub matrix: SparseMatrix,
    /// Residual at every dof (free or not): at fixed dofs it is the
    /// reaction.
    pub residual: Vec<f64>,
    /// Force flux at every dof.
    pub flux: Vec<f64>,
    /// Start of each element's block in `buffer` (n² tangent then n
    /// residual entries); one more entry for the end.
    offsets: Vec<usize>,
    buffer: Vec<f64>,
    /// Position in the matrix values of each local tangent entry, or NONE.
    tangent_map: Vec<u32>,
    /// Start of each element's entries in `tangent_map`.
    tangent_offsets: Vec<usize>,
    /// Dof of each local residual entry.
    residual_map: Vec<u32>,
    /// Start of each element's entries in `residual_map`.
    residual_offsets: Vec<usize>,
}

/// The sparsity pattern of the tangent, in equation numbering.
pub struct TangentPattern {
    matrix: SparseMatrix,
}

impl TangentPattern {
    /// Builds the pattern from the element connectivity: every pair of
    /// free equations of one element, and every diagonal entry.
    pub fn new(model: &Model, dofs: &DofMap) -> Self {
        let mut entries = Vec::new();
        for e in 0..model.elements.len() {
            let d = dofs.element_dofs(model, e);
            for &dj in &d {
                let cj = dofs.equation(dj);
                if cj == NO_EQUATION {
                    continue;
                }
                for &di in &d {
                    let ri = dofs.equation(di);
                    if ri != NO_EQUATION {
                        entries.push((ri, cj));
                    }
                }
            }
        }
        // every free equation has a diagonal entry, even if no element
        // touches it (a singular system is then reported, not a panic)
        let neq = dofs.n_equations();
        entries.extend((0..neq).map(|i| (i, i)));
        Self {
            matrix: SparseMatrix::from_pattern(neq, entries),
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.matrix.nnz()
    }
}

impl Assembler {
    /// Builds the pattern and the scatter maps.
    pub fn new(model: &Model, dofs: &DofMap) -> Self {
        Self::with_pattern(model, dofs, TangentPattern::new(model, dofs))
    }

    /// Builds the scatter maps from the element entries to `pattern`,
    /// which must be the pattern of `model` and `dofs`.
    pub fn with_pattern(model: &Model, dofs: &DofMap, pattern: TangentPattern) -> Self {
        let matrix = pattern.matrix;
        let n_el = model.elements.len();
        let mut offsets = Vec::with_capacity(n_el + 1);
        let mut tangent_offsets = Vec::with_capacity(n_el + 1);
        let mut residual_offsets = Vec::with_capacity(n_el + 1);
        let (mut o, mut to, mut ro) = (0, 0, 0);
        let mut residual_map = Vec::new();
        let element_dofs: Vec<Vec<usize>> =
            (0..n_el).map(|e| dofs.element_dofs(model, e)).collect();
        for d in &element_dofs {
            let n = d.len();
            offsets.push(o);
            tangent_offsets.push(to);
            residual_offsets.push(ro);
            o += n * n + n;
            to += n * n;
            ro += n;
            residual_map.extend(d.iter().map(|&x| x as u32));
        }
        offsets.push(o);
        tangent_offsets.push(to);
        residual_offsets.push(ro);
        assert!(
            matrix.nnz() < NONE as usize,
            "too many non-zeros for 32-bit maps"
        );
        let mut tangent_map = vec![NONE; to];
        for (e, d) in element_dofs.iter().enumerate() {
            let n = d.len();
            let base = tangent_offsets[e];
            for (j, &dj) in d.iter().enumerate() {
                let cj = dofs.equation(dj);
                if cj == NO_EQUATION {
                    continue;
                }
                for (i, &di) in d.iter().enumerate() {
                    let ri = dofs.equation(di);
                    if ri != NO_EQUATION {
                        tangent_map[base + j * n + i] =
                            matrix.position(ri, cj).expect("entry in pattern") as u32;
                    }
                }
            }
        }
        Self {
            matrix,
            residual: vec![0.0; dofs.n_dofs()],
            flux: vec![0.0; dofs.n_dofs()],
            offsets,
            buffer: vec![0.0; o],
            tangent_map,
            tangent_offsets,
            residual_offsets,
            residual_map,
        }
    }

    /// Evaluates every element for `state` and assembles the residual, the
    /// flux and (if `ctx.need_tangent`) the tangent.
    pub fn assemble(&mut self, model: &Model, ctx: &EvalContext, state: &State) {
        // evaluate elements in parallel, each into its own buffer slice
        evaluate_range(&model.elements, &mut self.buffer, &self.offsets, ctx, state);

        // scatter
        self.residual.fill(0.0);
        self.flux.fill(0.0);
        if ctx.need_tangent {
            self.matrix.values_mut().fill(0.0);
        }
        let values = self.matrix.values_mut();
        for e in 0..model.elements.len() {
            let start = self.offsets[e];
            let n = self.residual_offsets[e + 1] - self.residual_offsets[e];
            let block = &self.buffer[start..start + n * n + n];
            let (tangent, residual) = block.split_at(n * n);
            let rmap = &self.residual_map[self.residual_offsets[e]..self.residual_offsets[e + 1]];
            for (r, &d) in residual.iter().zip(rmap) {
                self.residual[d as usize] += r;
                self.flux[d as usize] += r.abs();
            }
            if ctx.need_tangent {
                let tmap = &self.tangent_map[self.tangent_offsets[e]..self.tangent_offsets[e + 1]];
                for (k, &p) in tmap.iter().enumerate() {
                    if p != NONE {
                        values[p as usize] += tangent[k];
                    }
                }
            }
        }
    }
}

/// Elements per task below which the evaluation runs sequentially.
const SEQUENTIAL_CHUNK: usize = 256;

/// Evaluates `elements` into `buffer`, whose layout is given by `offsets`
/// (absolute, `offsets[0]` is the start of `buffer`), splitting the work
/// recursively over rayon tasks.
fn evaluate_range(
    elements: &[Box<dyn Element>],
    buffer: &mut [f64],
    offsets: &[usize],
    ctx: &EvalContext,
    state: &State,
) {
    if elements.len() <= SEQUENTIAL_CHUNK {
        let base = offsets[0];
        for (k, e) in elements.iter().enumerate() {
            let block = &mut buffer[offsets[k] - base..offsets[k + 1] - base];
            let n = e.n_local();
            let (tangent, residual) = block.split_at_mut(n * n);
            residual.fill(0.0);
            if ctx.need_tangent {
                tangent.fill(0.0);
            }
            e.evaluate(ctx, state, &mut ElementOutput { residual, tangent });
        }
        return;
    }
    let mid = elements.len() / 2;
    let (left, right) = buffer.split_at_mut(offsets[mid] - offsets[0]);
    rayon::join(
        || evaluate_range(&elements[..mid], left, &offsets[..=mid], ctx, state),
        || evaluate_range(&elements[mid..], right, &offsets[mid..], ctx, state),
    );
}
