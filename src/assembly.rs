//! Assembly of the global residual and matrices.
//!
//! The sparsity pattern is built once from the element connectivity, by
//! blocks of equations (a node's, an element's coordinates and
//! multipliers: see [`TangentPattern`]), with a map from every local matrix
//! entry of every element to its position in the compressed-column value
//! array, read off the block structure. Each evaluation then
//! 1. evaluates all elements in parallel, each into its own preallocated
//!    slices (residual, stiffness, inertia matrix: no locks, no
//!    allocation), and applies the optional per-node right factors to the
//!    rotation columns of each local stiffness;
//! 2. scatters the local residuals and matrices through the maps: the sum
//!    of the stiffness and the inertia matrix into the assembler's own
//!    matrix ([`Assembler::assemble`], the iteration matrix of statics and
//!    dynamics), or each into a matrix of its own on the same pattern
//!    ([`Assembler::assemble_split`], for modal analysis).
//!
//! Besides the residual `r`, assembly accumulates the *force flux*
//! `Σₑ |rₑ|` at every dof: the magnitude of the forces flowing through it,
//! which does not cancel at equilibrium and is the reference for the
//! relative residual tolerance.

use crate::dofs::{DofMap, NO_EQUATION};
use crate::elements::{Element, ElementOutput, EvalContext, InertiaWeights, Need};
use crate::linalg::SparseMatrix;
use crate::model::Model;
use crate::so3::{Mat3, Vec3};
use crate::state::State;

const NONE: u32 = u32::MAX;

/// Global system storage and the maps that fill it.
pub struct Assembler {
    /// The iteration matrix (stiffness plus inertia matrix), in equation
    /// numbering.
    pub matrix: SparseMatrix,
    /// Residual at every dof (free or not): at fixed dofs it is the
    /// reaction.
    pub residual: Vec<f64>,
    /// Force flux at every dof.
    pub flux: Vec<f64>,
    /// Start of each element's block in `buffer` (n² stiffness then n
    /// residual entries); one more entry for the end.
    offsets: Vec<usize>,
    buffer: Vec<f64>,
    /// The elements' inertia matrices (n² each, at `tangent_offsets`);
    /// allocated at the first assembly that asks for them.
    inertia: Vec<f64>,
    /// Position in the matrix values of each local tangent entry, or NONE.
    tangent_map: Vec<u32>,
    /// Start of each element's entries in `tangent_map`.
    tangent_offsets: Vec<usize>,
    /// Dof of each local residual entry.
    residual_map: Vec<u32>,
    /// Start of each element's entries in `residual_map`.
    residual_offsets: Vec<usize>,
}

/// The sparsity pattern of the tangent, in equation numbering, built by
/// blocks from the element graph.
///
/// A *block* is a node (its free components) or the coordinates and
/// multipliers of an element: its equations are consecutive
/// ([`DofMap::node_equations`], [`DofMap::element_equations`]),
/// so the pattern is a block pattern. Block `b` couples with block `c`
/// when an element has both; every column of block `b` then has the same
/// rows: the equations of the blocks coupled with `b`, in equation order.
/// The pattern is built block column by block column, without sorting the
/// entries globally, and the position of the element entry `(i, j)` in
/// the value array is the start of column `j`, plus the offset of the
/// block of `i` in the block column of `j`, plus the place of `i` in its
/// block.
pub struct TangentPattern {
    matrix: SparseMatrix,
    /// Equations of each block: nodes first, then the coordinates and
    /// multipliers of each element.
    blocks: Vec<[usize; 2]>,
    /// Start of each block column in `coupled` (one more for the end).
    coupled_ptr: Vec<usize>,
    /// Blocks coupled with each block, in equation order.
    coupled: Vec<usize>,
    /// Offset of each coupled block's first row in the columns of the
    /// block column.
    coupled_offset: Vec<usize>,
}

impl TangentPattern {
    /// Builds the pattern from the element connectivity: every pair of
    /// free equations of one element, and every diagonal entry (even of an
    /// equation that no element touches: a singular system is then
    /// reported, not a panic).
    pub fn new(model: &Model, dofs: &DofMap) -> Self {
        let n_nodes = model.n_nodes();
        let n_el = model.elements.len();
        let n_blocks = n_nodes + n_el;
        let blocks: Vec<[usize; 2]> = (0..n_nodes)
            .map(|i| dofs.node_equations(i))
            .chain((0..n_el).map(|e| dofs.element_equations(e)))
            .map(|r| [r.start, r.end])
            .collect();
        let is_empty = |b: usize| blocks[b][0] == blocks[b][1];

        // elements touching each block (compressed rows)
        let mut touch_ptr = vec![0usize; n_blocks + 1];
        for (e, element) in model.elements.iter().enumerate() {
            for b in element_blocks(element.nodes(), n_nodes + e) {
                touch_ptr[b + 1] += 1;
            }
        }
        for b in 0..n_blocks {
            touch_ptr[b + 1] += touch_ptr[b];
        }
        let mut fill = touch_ptr.clone();
        let mut touching = vec![0usize; touch_ptr[n_blocks]];
        for (e, element) in model.elements.iter().enumerate() {
            for b in element_blocks(element.nodes(), n_nodes + e) {
                touching[fill[b]] = e;
                fill[b] += 1;
            }
        }

        // blocks coupled with each block: itself and the blocks of the
        // elements touching it, each once (marked with the column block),
        // sorted by first equation; and the rows of the block column
        let mut coupled_ptr = Vec::with_capacity(n_blocks + 1);
        let mut coupled = Vec::with_capacity(2 * touching.len() + n_blocks);
        let mut coupled_offset = Vec::with_capacity(coupled.capacity());
        let mut column_rows = vec![0usize; n_blocks];
        let mut mark = vec![usize::MAX; n_blocks];
        coupled_ptr.push(0);
        for b in 0..n_blocks {
            let start = coupled.len();
            if !is_empty(b) {
                mark[b] = b;
                coupled.push(b);
                for &e in &touching[touch_ptr[b]..touch_ptr[b + 1]] {
                    for c in element_blocks(model.elements[e].nodes(), n_nodes + e) {
                        if mark[c] != b && !is_empty(c) {
                            mark[c] = b;
                            coupled.push(c);
                        }
                    }
                }
                coupled[start..].sort_unstable_by_key(|&c| blocks[c][0]);
                let mut rows = 0;
                for &c in &coupled[start..] {
                    coupled_offset.push(rows);
                    rows += blocks[c][1] - blocks[c][0];
                }
                column_rows[b] = rows;
            }
            coupled_ptr.push(coupled.len());
        }

        // compressed columns: every column of a block has its block's rows
        let neq = dofs.n_equations();
        let mut col_ptr = vec![0usize; neq + 1];
        for (b, &[first, end]) in blocks.iter().enumerate() {
            for j in first..end {
                col_ptr[j + 1] = column_rows[b];
            }
        }
        for j in 0..neq {
            col_ptr[j + 1] += col_ptr[j];
        }
        let mut row_idx = vec![0usize; col_ptr[neq]];
        for (b, &[first, end]) in blocks.iter().enumerate() {
            let coupled_rows = coupled[coupled_ptr[b]..coupled_ptr[b + 1]]
                .iter()
                .flat_map(|&c| blocks[c][0]..blocks[c][1]);
            for j in first..end {
                for (slot, r) in row_idx[col_ptr[j]..col_ptr[j + 1]]
                    .iter_mut()
                    .zip(coupled_rows.clone())
                {
                    *slot = r;
                }
            }
        }
        Self {
            matrix: SparseMatrix::from_columns(neq, col_ptr, row_idx),
            blocks,
            coupled_ptr,
            coupled,
            coupled_offset,
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.matrix.nnz()
    }

    /// Whether block `b` has no equation.
    fn is_empty(&self, b: usize) -> bool {
        self.blocks[b][0] == self.blocks[b][1]
    }

    /// Offset of the rows of block `row_block` in the columns of block
    /// `column_block`, which must be coupled.
    fn offset(&self, column_block: usize, row_block: usize) -> usize {
        let range = self.coupled_ptr[column_block]..self.coupled_ptr[column_block + 1];
        let first = self.blocks[row_block][0];
        let k = self.coupled[range.clone()]
            .binary_search_by_key(&first, |&c| self.blocks[c][0])
            .expect("coupled blocks");
        self.coupled_offset[range.start + k]
    }
}

/// Blocks of an element: its nodes, then its coordinates and multipliers
/// (block `extra_block`).
fn element_blocks(nodes: &[usize], extra_block: usize) -> impl Iterator<Item = usize> + '_ {
    nodes.iter().copied().chain(std::iter::once(extra_block))
}

impl Assembler {
    /// Builds the pattern and the scatter maps.
    pub fn new(model: &Model, dofs: &DofMap) -> Self {
        Self::with_pattern(model, dofs, TangentPattern::new(model, dofs))
    }

    /// Builds the scatter maps from the element entries to `pattern`,
    /// which must be the pattern of `model` and `dofs`.
    pub fn with_pattern(model: &Model, dofs: &DofMap, pattern: TangentPattern) -> Self {
        let n_nodes = model.n_nodes();
        let n_el = model.elements.len();
        let mut offsets = Vec::with_capacity(n_el + 1);
        let mut tangent_offsets = Vec::with_capacity(n_el + 1);
        let mut residual_offsets = Vec::with_capacity(n_el + 1);
        let (mut o, mut to, mut ro) = (0, 0, 0);
        for element in &model.elements {
            let n = element.n_local();
            offsets.push(o);
            tangent_offsets.push(to);
            residual_offsets.push(ro);
            o += n * n + n;
            to += n * n;
            ro += n;
        }
        offsets.push(o);
        tangent_offsets.push(to);
        residual_offsets.push(ro);
        assert!(
            pattern.nnz() < NONE as usize && dofs.n_dofs() < NONE as usize,
            "too many non-zeros or dofs for 32-bit maps"
        );

        let mut residual_map = Vec::with_capacity(ro);
        let mut tangent_map = vec![NONE; to];
        // per element: the dof, the equation and the block (index into
        // `element_blocks`) of each local unknown, and the offset of every
        // pair of blocks
        let mut local: Vec<(usize, usize, usize)> = Vec::new();
        let mut element_blocks: Vec<usize> = Vec::new();
        let mut pair_offset: Vec<usize> = Vec::new();
        for (e, element) in model.elements.iter().enumerate() {
            local.clear();
            element_blocks.clear();
            for (k, &node) in element.nodes().iter().enumerate() {
                element_blocks.push(node);
                local.extend((6 * node..6 * node + 6).map(|d| (d, dofs.equation(d), k)));
            }
            let mut extra = dofs.element_extra_dofs(model, e).peekable();
            if extra.peek().is_some() {
                let k = element_blocks.len();
                element_blocks.push(n_nodes + e);
                local.extend(extra.map(|d| (d, dofs.equation(d), k)));
            }
            residual_map.extend(local.iter().map(|&(d, _, _)| d as u32));

            // offsets of the rows of block a in the columns of block b
            let nb = element_blocks.len();
            pair_offset.clear();
            for &b in &element_blocks {
                for &a in &element_blocks {
                    let coupled = !pattern.is_empty(a) && !pattern.is_empty(b);
                    pair_offset.push(if coupled { pattern.offset(b, a) } else { 0 });
                }
            }

            let n = local.len();
            let map = &mut tangent_map[tangent_offsets[e]..tangent_offsets[e + 1]];
            for (j, &(_, cj, kb)) in local.iter().enumerate() {
                if cj == NO_EQUATION {
                    continue;
                }
                let column = pattern.matrix.column_start(cj);
                for (i, &(_, ri, ka)) in local.iter().enumerate() {
                    if ri != NO_EQUATION {
                        let first = pattern.blocks[element_blocks[ka]][0];
                        let p = column + pair_offset[kb * nb + ka] + (ri - first);
                        map[j * n + i] = p as u32;
                    }
                }
            }
        }
        Self {
            matrix: pattern.matrix,
            residual: vec![0.0; dofs.n_dofs()],
            flux: vec![0.0; dofs.n_dofs()],
            offsets,
            buffer: vec![0.0; o],
            inertia: Vec::new(),
            tangent_map,
            tangent_offsets,
            residual_offsets,
            residual_map,
        }
    }

    /// Evaluates every element for `state` and assembles the residual, the
    /// flux and the matrices `ctx.need` asks for, summed into
    /// [`Assembler::matrix`]: the stiffness, plus the inertia matrix
    /// `w_d ∂r/∂v + w_m ∂r/∂v̇` when asked.
    pub fn assemble(&mut self, model: &Model, ctx: &EvalContext, state: &State) {
        self.assemble_into(model, ctx, state, Columns::NONE, Target::Own);
    }

    /// As [`Assembler::assemble`], with the rotation columns of every local
    /// stiffness multiplied on the right by the 3×3 factor of their node,
    /// `K_{·Θᵢ} ← K_{·Θᵢ} Tᵢ` (the tangent operator of the generalised-α
    /// update, docs/theory.md §12), before it is added to the inertia matrix.
    /// The inertia matrix is not factored. `factors` has one entry per
    /// node.
    pub fn assemble_factored(
        &mut self,
        model: &Model,
        ctx: &EvalContext,
        state: &State,
        factors: &[Mat3],
    ) {
        assert_eq!(factors.len(), model.n_nodes(), "one factor per node");
        let columns = Columns {
            tangent: Some(factors),
            spatial: None,
        };
        self.assemble_into(model, ctx, state, columns, Target::Own);
    }

    /// As [`Assembler::assemble_factored`], for the spatial scheme of the
    /// dynamic analysis (docs/theory.md §15.9): the rotation columns of
    /// each node with `spatial[i] = Some(c)` become
    ///
    /// ```text
    /// S_{·Θᵢ} = K_{·Θᵢ} Tᵢ + D_{·Θᵢ} Λᵢ + C_{·Θᵢ} Ω~ Tᵢ + M_{·Θᵢ} Ω̇~ Tᵢ,
    /// ```
    ///
    /// `D = w_d C + w_m M` the inertia matrix asked for (both weights
    /// positive), `C = ∂r/∂v`, `M = ∂r/∂v̇`: an element with such a node is
    /// evaluated a second time for `w_d C` alone.
    pub fn assemble_spatial(
        &mut self,
        model: &Model,
        ctx: &EvalContext,
        state: &State,
        factors: &[Mat3],
        spatial: &[Option<SpatialColumns>],
    ) {
        assert_eq!(factors.len(), model.n_nodes(), "one factor per node");
        assert_eq!(spatial.len(), model.n_nodes(), "one entry per node");
        assert!(
            ctx.need
                .inertia
                .is_some_and(|w| w.damping > 0.0 && w.mass > 0.0),
            "the spatial columns need both inertia weights"
        );
        let columns = Columns {
            tangent: Some(factors),
            spatial: Some(spatial),
        };
        self.assemble_into(model, ctx, state, columns, Target::Own);
    }

    /// Evaluates every element once and assembles the residual and the flux
    /// (in [`Assembler::residual`], [`Assembler::flux`]), the stiffness
    /// into `stiffness` and the inertia matrix into `inertia`, two matrices
    /// with the pattern of [`Assembler::matrix`] (a clone of it). `ctx`
    /// must ask for both: `ctx.need.inertia` gives the weights (`(0, 1)`
    /// for the mass matrix).
    pub fn assemble_split(
        &mut self,
        model: &Model,
        ctx: &EvalContext,
        state: &State,
        stiffness: &mut SparseMatrix,
        inertia: &mut SparseMatrix,
    ) {
        assert!(
            ctx.need.stiffness && ctx.need.inertia.is_some(),
            "a split assembly asks for both matrices"
        );
        assert!(
            stiffness.nnz() == self.matrix.nnz() && inertia.nnz() == self.matrix.nnz(),
            "matrices on the assembler's pattern"
        );
        self.assemble_into(
            model,
            ctx,
            state,
            Columns::NONE,
            Target::Split(stiffness, inertia),
        );
    }

    /// Evaluates every element without its stiffness and assembles the
    /// residual and the flux (in [`Assembler::residual`],
    /// [`Assembler::flux`]) and the inertia matrix alone into `inertia`, a
    /// matrix with the pattern of [`Assembler::matrix`] (a clone of it),
    /// with the weights of `ctx.need.inertia` (`(0, 1)` for the mass
    /// matrix). [`Assembler::matrix`] is left as it was.
    pub fn assemble_inertia(
        &mut self,
        model: &Model,
        ctx: &EvalContext,
        state: &State,
        inertia: &mut SparseMatrix,
    ) {
        assert!(
            ctx.need.inertia.is_some(),
            "an inertia assembly asks for it"
        );
        assert!(
            inertia.nnz() == self.matrix.nnz(),
            "matrix on the assembler's pattern"
        );
        let ctx = EvalContext {
            need: Need {
                stiffness: false,
                ..ctx.need
            },
            ..*ctx
        };
        self.assemble_into(model, &ctx, state, Columns::NONE, Target::Inertia(inertia));
    }

    fn assemble_into(
        &mut self,
        model: &Model,
        ctx: &EvalContext,
        state: &State,
        columns: Columns,
        target: Target,
    ) {
        let need = ctx.need;
        let total = *self.tangent_offsets.last().unwrap_or(&0);
        if need.inertia.is_some() && self.inertia.len() != total {
            self.inertia = vec![0.0; total];
        }
        // evaluate elements, in parallel in a large model, each into its
        // own buffer slices
        let inertia = need.inertia.map(|_| &mut self.inertia[..]);
        let parallel =
            model.elements.len() >= PARALLEL_ELEMENTS && rayon::current_num_threads() > 1;
        let layout = Layout {
            offsets: &self.offsets,
            inertia_offsets: &self.tangent_offsets,
        };
        let evaluate = if parallel {
            evaluate_range
        } else {
            evaluate_sequentially
        };
        evaluate(
            &model.elements,
            &mut self.buffer,
            inertia,
            layout,
            ctx,
            state,
            columns,
        );

        // scatter
        self.residual.fill(0.0);
        self.flux.fill(0.0);
        let (stiffness, inertia_matrix) = match target {
            Target::Own => {
                if need.any_matrix() {
                    self.matrix.values_mut().fill(0.0);
                }
                (self.matrix.values_mut(), None)
            }
            Target::Split(k, d) => {
                k.values_mut().fill(0.0);
                d.values_mut().fill(0.0);
                (k.values_mut(), Some(d.values_mut()))
            }
            Target::Inertia(d) => {
                d.values_mut().fill(0.0);
                (&mut [][..], Some(d.values_mut()))
            }
        };
        let mut inertia_matrix = inertia_matrix;
        for e in 0..model.elements.len() {
            let start = self.offsets[e];
            let n = self.residual_offsets[e + 1] - self.residual_offsets[e];
            let block = &self.buffer[start..start + n * n + n];
            let (local_k, residual) = block.split_at(n * n);
            let rmap = &self.residual_map[self.residual_offsets[e]..self.residual_offsets[e + 1]];
            for (r, &d) in residual.iter().zip(rmap) {
                self.residual[d as usize] += r;
                self.flux[d as usize] += r.abs();
            }
            if !need.any_matrix() {
                continue;
            }
            let range = self.tangent_offsets[e]..self.tangent_offsets[e + 1];
            let tmap = &self.tangent_map[range.clone()];
            if need.stiffness {
                for (&p, &v) in tmap.iter().zip(local_k) {
                    if p != NONE {
                        stiffness[p as usize] += v;
                    }
                }
            }
            if need.inertia.is_some() {
                let local_d = &self.inertia[range];
                let values = match inertia_matrix.as_deref_mut() {
                    Some(d) => d,
                    None => &mut *stiffness,
                };
                for (&p, &v) in tmap.iter().zip(local_d) {
                    if p != NONE {
                        values[p as usize] += v;
                    }
                }
            }
        }
    }
}

/// Where an assembly puts its matrices.
enum Target<'a> {
    /// Their sum into the assembler's own matrix.
    Own,
    /// The stiffness and the inertia matrix into these two.
    Split(&'a mut SparseMatrix, &'a mut SparseMatrix),
    /// The inertia matrix alone into this one (no stiffness asked).
    Inertia(&'a mut SparseMatrix),
}

/// Where each element's slices start in the evaluation buffers (absolute
/// offsets; entry 0 is the start of the slices given).
#[derive(Clone, Copy)]
struct Layout<'a> {
    /// Stiffness and residual of each element (n² + n).
    offsets: &'a [usize],
    /// Inertia matrix of each element (n²).
    inertia_offsets: &'a [usize],
}

impl<'a> Layout<'a> {
    fn split(self, mid: usize) -> (Self, Self) {
        (
            Self {
                offsets: &self.offsets[..=mid],
                inertia_offsets: &self.inertia_offsets[..=mid],
            },
            Self {
                offsets: &self.offsets[mid..],
                inertia_offsets: &self.inertia_offsets[mid..],
            },
        )
    }
}

/// Elements per task below which the evaluation runs sequentially (as
/// it does whatever their number on one thread: a task handed to the
/// pool's only worker costs two context switches).
const SEQUENTIAL_CHUNK: usize = 256;

/// Elements of a model below which its evaluation runs sequentially
/// whatever the threads. Measured on 2 cores, runs taken in turn: the
/// ERA platform's deployment (7,788 unknowns) took 92–97 s with its
/// assembly on two threads (its factorisations on one), 68.6 s with both
/// on one (docs/theory.md §8); a cantilever of 100,000 beams assembles in
/// 125–135 ms on two threads against 179–180 ms on one.
pub const PARALLEL_ELEMENTS: usize = 10_000;

/// Runs `f` on a worker thread of rayon's global pool (at once when the
/// pool has one thread or the caller is one of its workers), so that the
/// parallel sections of the assembly and the factorisation fork from a
/// worker. Forked from a thread outside the pool, each section is handed
/// to the pool while the caller sleeps on a lock until it is done: two
/// context switches per section, several per Newton iteration. Measured
/// with `unfold run` on the flexible pendulum of bench/peer (320 beams,
/// 400 steps, 2 threads on the 2 cores, three runs each): 2.22–2.29 s
/// forked from the main thread, 1.96–1.97 s from a worker, 2.11–2.18 s on
/// one thread; the heavy top and the 20-beam pendulum, which have no
/// parallel section, the same either way (models of fewer than
/// [`PARALLEL_ELEMENTS`] elements and systems of fewer than
/// [`crate::linalg::PARALLEL_UNKNOWNS`] unknowns have none since: the
/// 320-beam pendulum took 1.90–2.30 s on two threads and 1.93–2.18 s on
/// one). Programs driving an analysis
/// call their whole run through it (`unfold run`, the examples).
pub fn on_worker_thread<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_num_threads() == 1 || rayon::current_thread_index().is_some() {
        f()
    } else {
        rayon::scope(|_| f())
    }
}

/// Evaluates `elements` into `buffer` (stiffness and residual) and
/// `inertia` (when asked), whose layouts `layout` gives, splitting the work
/// recursively over rayon tasks; applies `factors` to the rotation columns
/// of each stiffness.
fn evaluate_range(
    elements: &[Box<dyn Element>],
    buffer: &mut [f64],
    inertia: Option<&mut [f64]>,
    layout: Layout,
    ctx: &EvalContext,
    state: &State,
    columns: Columns,
) {
    if elements.len() <= SEQUENTIAL_CHUNK {
        evaluate_sequentially(elements, buffer, inertia, layout, ctx, state, columns);
        return;
    }
    let mid = elements.len() / 2;
    let (left, right) = buffer.split_at_mut(layout.offsets[mid] - layout.offsets[0]);
    let (il, ir) = match inertia {
        Some(d) => {
            let (l, r) = d.split_at_mut(layout.inertia_offsets[mid] - layout.inertia_offsets[0]);
            (Some(l), Some(r))
        }
        None => (None, None),
    };
    let (ll, lr) = layout.split(mid);
    rayon::join(
        || evaluate_range(&elements[..mid], left, il, ll, ctx, state, columns),
        || evaluate_range(&elements[mid..], right, ir, lr, ctx, state, columns),
    );
}

/// [`evaluate_range`] on the calling thread.
fn evaluate_sequentially(
    elements: &[Box<dyn Element>],
    buffer: &mut [f64],
    inertia: Option<&mut [f64]>,
    layout: Layout,
    ctx: &EvalContext,
    state: &State,
    columns: Columns,
) {
    let (base, ibase) = (layout.offsets[0], layout.inertia_offsets[0]);
    let mut inertia = inertia;
    for (k, e) in elements.iter().enumerate() {
        let block = &mut buffer[layout.offsets[k] - base..layout.offsets[k + 1] - base];
        let n = e.n_local();
        let (stiffness, residual) = block.split_at_mut(n * n);
        residual.fill(0.0);
        let stiffness = ctx.need.stiffness.then(|| {
            stiffness.fill(0.0);
            stiffness
        });
        let local_inertia = inertia.as_deref_mut().map(|d| {
            let d =
                &mut d[layout.inertia_offsets[k] - ibase..layout.inertia_offsets[k + 1] - ibase];
            d.fill(0.0);
            d
        });
        let mut out = ElementOutput {
            residual,
            stiffness,
            inertia: local_inertia,
        };
        e.evaluate(ctx, state, &mut out);
        if let (Some(f), Some(k)) = (columns.tangent, out.stiffness) {
            factor_rotation_columns(k, n, e.nodes(), f);
        }
        if let (Some(spatial), Some(d)) = (columns.spatial, out.inertia) {
            // an element without inertia or damping on the rotations of
            // its spatial nodes (a joint without damper) has nothing to add
            let moving = e.nodes().iter().enumerate().any(|(i, &node)| {
                spatial[node].is_some()
                    && d[(6 * i + 3) * n..(6 * i + 6) * n]
                        .iter()
                        .any(|&v| v != 0.0)
            });
            if moving {
                spatial_rotation_columns(e.as_ref(), ctx, state, d, spatial);
            }
        }
    }
}

/// The right factors of the rotation columns in an assembly: `T` of every
/// node on the stiffness, and the spatial scheme's columns of the inertia
/// matrix at some nodes ([`Assembler::assemble_spatial`]).
#[derive(Clone, Copy)]
struct Columns<'a> {
    tangent: Option<&'a [Mat3]>,
    spatial: Option<&'a [Option<SpatialColumns>]>,
}

impl Columns<'_> {
    const NONE: Columns<'static> = Columns {
        tangent: None,
        spatial: None,
    };
}

/// The right factors of a node's rotation columns of the inertia matrix in
/// the spatial scheme (docs/theory.md §15.9): `Ω = Λ Ω′` and `Ω̇ = Λ Ω̇′`
/// with `Λ = exp(−hΔΘ~)` give `δΩ = (γ′Λ + Ω~T) x` and
/// `δΩ̇ = (β′Λ + Ω̇~T) x` for a correction `x = h δΔΘ`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialColumns {
    /// `Λ`, on `D = w_d C + w_m M`.
    pub turn: Mat3,
    /// `Ω~ T`, on `C`.
    pub damping: Mat3,
    /// `Ω̇~ T`, on `M`.
    pub mass: Mat3,
}

thread_local! {
    /// `w_d C` and the residual of one element, for the spatial columns.
    static DAMPING: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// `D_{·Θ} ← D_{·Θ} Λ + C_{·Θ} Ω~T + M_{·Θ} Ω̇~T` for the nodes of `e` in
/// the spatial scheme, `d` its inertia matrix `w_d C + w_m M` (column
/// major, `n × n`); `C` from a second evaluation of `e`, `M = (D − w_d C)/w_m`.
fn spatial_rotation_columns(
    e: &dyn Element,
    ctx: &EvalContext,
    state: &State,
    d: &mut [f64],
    spatial: &[Option<SpatialColumns>],
) {
    let n = e.n_local();
    let w = ctx.need.inertia.expect("asked for by assemble_spatial");
    DAMPING.with(|buffer| {
        let mut buffer = buffer.borrow_mut();
        buffer.clear();
        buffer.resize(n * n + n, 0.0);
        let (c, residual) = buffer.split_at_mut(n * n);
        let damping = EvalContext {
            need: Need {
                stiffness: false,
                inertia: Some(InertiaWeights {
                    damping: w.damping,
                    mass: 0.0,
                }),
            },
            ..*ctx
        };
        e.evaluate(
            &damping,
            state,
            &mut ElementOutput {
                residual,
                stiffness: None,
                inertia: Some(c),
            },
        );
        for (i, &node) in e.nodes().iter().enumerate() {
            let Some(f) = &spatial[node] else {
                continue;
            };
            let c0 = 6 * i + 3;
            for r in 0..n {
                let column = |m: &[f64], j: usize| m[(c0 + j) * n + r];
                let dv = Vec3::new(column(d, 0), column(d, 1), column(d, 2));
                let cv = Vec3::new(column(c, 0), column(c, 1), column(c, 2));
                // rows of C and M: w_d C / w_d, (D − w_d C)/w_m
                let mv = (dv - cv) / w.mass;
                let cv = cv / w.damping;
                let row = f.turn.tr_mul(&dv) + f.damping.tr_mul(&cv) + f.mass.tr_mul(&mv);
                for j in 0..3 {
                    d[(c0 + j) * n + r] = row[j];
                }
            }
        }
    });
}

/// `K_{·Θᵢ} ← K_{·Θᵢ} Fᵢ` for every node `i` of an element: the three
/// rotation columns of each node (local columns `6i+3..6i+6` of the
/// column-major `n × n` matrix `k`) times the node's factor.
fn factor_rotation_columns(k: &mut [f64], n: usize, nodes: &[usize], factors: &[Mat3]) {
    for (i, &node) in nodes.iter().enumerate() {
        let f = &factors[node];
        let c0 = 6 * i + 3;
        for r in 0..n {
            let a = [k[c0 * n + r], k[(c0 + 1) * n + r], k[(c0 + 2) * n + r]];
            for j in 0..3 {
                k[(c0 + j) * n + r] = a[0] * f[(0, j)] + a[1] * f[(1, j)] + a[2] * f[(2, j)];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joints::JointType;
    use crate::model::input::{JointInput, JointSpringInput, ModelInput};
    use std::collections::BTreeSet;

    /// Three beam links hinged to each other and to the ground (revolute
    /// joints with multipliers), hinge springs, a partly fixed node, a
    /// fully fixed node that no element touches, and a load.
    fn hinged_links() -> Model {
        Model::from_input(&hinged_input()).expect("valid model")
    }

    /// The input of [`hinged_links`].
    fn hinged_input() -> ModelInput {
        let mut m = ModelInput::new("hinged links");
        m.add_section("s", [2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5]);
        for i in 0..3u64 {
            let x0 = 0.1 * i as f64;
            m.add_node(2 * i + 1, [x0, 0.0, 0.0]);
            m.add_node(2 * i + 2, [x0 + 0.1, 0.0, 0.0]);
            m.add_beam(i + 1, [2 * i + 1, 2 * i + 2], "s", Some([0.0, 0.0, 1.0]));
            let nodes = if i == 0 {
                vec![1]
            } else {
                vec![2 * i, 2 * i + 1]
            };
            m.joints.push(JointInput {
                id: 100 + i,
                kind: JointType::Revolute,
                nodes,
                axis: Some([0.0, 0.0, 1.0]),
                ..Default::default()
            });
            m.joint_springs.push(JointSpringInput {
                id: 200 + i,
                joint: 100 + i,
                stiffness: Some(10.0),
                ..Default::default()
            });
        }
        m.add_node(99, [1.0, 1.0, 0.0]);
        m.fix(99, &["all"]);
        m.fix(4, &["z", "rx"]);
        m.add_load(6, [0.0, 1.0, 0.0], [0.0; 3]);
        m
    }

    /// A model of [`PARALLEL_ELEMENTS`] beams (a bent cantilever) is
    /// assembled on two threads, its elements split over rayon tasks: the
    /// residual, flux and matrix (stiffness and inertia, factored rotation
    /// columns) are those of the sequential assembly, bit for bit (each
    /// element writes its own slices, scattered in one order).
    #[test]
    fn parallel_assembly_of_a_large_model_equals_the_sequential_one() {
        use crate::so3::{skew, Vec3};
        let mut m = ModelInput::new("long cantilever");
        m.add_node(1, [0.0; 3]);
        m.add_node(2, [10.0, 0.0, 0.0]);
        m.add_section("s", [2.1e8, 8.1e7, 8.1e7, 1.6e5, 2.1e5, 2.1e5]);
        m.beam_lines.push(crate::model::input::BeamLineInput {
            nodes: [1, 2],
            elements: PARALLEL_ELEMENTS,
            section: "s".into(),
            orientation: Some([0.0, 0.0, 1.0]),
            first_node: Some(3),
            first_element: Some(1),
            arc_center: None,
            initial_strain: None,
            initial_strain_curve: None,
        });
        m.fix(1, &["all"]);
        let model = Model::from_input(&m).expect("valid model");
        assert!(model.elements.len() >= PARALLEL_ELEMENTS);
        let dofs = DofMap::new(&model);
        let mut state = model.initial_state();
        for i in 0..model.n_nodes() {
            let s = i as f64 * 1e-3;
            let d = Vec3::new(0.01 * s.sin(), 0.02 * s, 0.005 * s * s);
            state.displace_node(i, &d, &Vec3::new(0.3 * s.sin(), -0.2 * s, 0.1 * s.cos()));
        }
        let factors: Vec<Mat3> = (0..model.n_nodes())
            .map(|i| Mat3::identity() + skew(&Vec3::new(1e-3 * i as f64, 0.1, 0.0)) * 0.3)
            .collect();
        let ctx = model.context(1.0, Need::with_inertia(30.0, 900.0));
        let assemble = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut assembler = Assembler::new(&model, &dofs);
                assembler.assemble_factored(&model, &ctx, &state, &factors);
                (
                    assembler.residual.clone(),
                    assembler.flux.clone(),
                    assembler.matrix.values().to_vec(),
                )
            })
        };
        let (parallel, sequential) = (assemble(2), assemble(1));
        assert!(parallel.2.iter().any(|&v| v != 0.0));
        assert!(parallel == sequential, "the parallel assembly differs");
    }

    /// The block pattern is the set of equation pairs of every element plus
    /// the diagonal, and every scatter-map entry points at its own pair:
    /// checked against a direct enumeration and a search in each column.
    fn check_pattern_and_maps(model: &Model, dofs: &DofMap) {
        let assembler = Assembler::new(model, dofs);
        let matrix = &assembler.matrix;
        let mut expected = BTreeSet::new();
        for e in 0..model.elements.len() {
            let d = dofs.element_dofs(model, e);
            let n = d.len();
            let map = &assembler.tangent_map
                [assembler.tangent_offsets[e]..assembler.tangent_offsets[e + 1]];
            assert_eq!(map.len(), n * n);
            let rmap = &assembler.residual_map
                [assembler.residual_offsets[e]..assembler.residual_offsets[e + 1]];
            assert_eq!(rmap, d.iter().map(|&x| x as u32).collect::<Vec<_>>());
            for (j, &dj) in d.iter().enumerate() {
                for (i, &di) in d.iter().enumerate() {
                    let (r, c) = (dofs.equation(di), dofs.equation(dj));
                    if r == NO_EQUATION || c == NO_EQUATION {
                        assert_eq!(map[j * n + i], NONE);
                    } else {
                        expected.insert((r, c));
                        assert_eq!(Some(map[j * n + i] as usize), matrix.position(r, c));
                    }
                }
            }
        }
        expected.extend((0..dofs.n_equations()).map(|i| (i, i)));
        let stored: BTreeSet<_> = matrix.entries().map(|(r, c, _)| (r, c)).collect();
        assert_eq!(stored, expected);
        assert_eq!(matrix.nnz(), expected.len());
    }

    /// The combined assembly with per-node right factors on the rotation
    /// columns of the element stiffnesses equals a dense assembly written
    /// out independently: each element's `K_e`, its rotation columns times
    /// the factor of their node, plus its inertia matrix `D_e` (beams with
    /// mass and rotational inertia, a rigid body off its node, joints,
    /// springs, a partly fixed node), scattered by the dof numbering; to
    /// round-off (1e-14 of the largest entry). The factors are arbitrary
    /// 3×3 matrices, so the rows of a node's three columns mix.
    #[test]
    fn factored_assembly_equals_the_elements_factored_one_by_one() {
        use crate::elements::{ElementOutput, Need};
        use crate::model::input::{InertiaInput, RigidBodyInput};
        use crate::so3::{skew, Vec3};
        let model = {
            let mut m = hinged_input();
            m.sections[0].mass_per_length = Some(0.4);
            m.sections[0].inertia_per_length = Some([0.01, 0.02, 0.03]);
            m.rigid_bodies.push(RigidBodyInput {
                id: 50,
                node: 3,
                mass: 1.5,
                inertia: Some(InertiaInput::Diagonal([0.1, 0.2, 0.3])),
                center_of_mass: Some([0.02, -0.01, 0.03]),
                shape: None,
            });
            Model::from_input(&m).expect("valid model")
        };
        let dofs = DofMap::new(&model);
        let mut state = model.initial_state();
        for i in 0..model.n_nodes() {
            let s = i as f64;
            let d = Vec3::new(0.01 * s.sin(), 0.02 * s.cos(), 0.005 * s);
            state.displace_node(i, &d, &Vec3::new(0.3 * s.sin(), -0.2 * s, 0.1 * s.cos()));
            state.velocity[i] = [s.sin(), s.cos(), 0.5, 20.0 * s.cos(), -15.0, 10.0 * s.sin()];
            state.acceleration[i] = [3.0, -s, 2.0 * s.cos(), 100.0, 50.0 * s.sin(), -80.0];
        }
        for (k, l) in state.multipliers.iter_mut().enumerate() {
            *l = 0.1 * (k as f64 - 4.0);
        }
        let factors: Vec<Mat3> = (0..model.n_nodes())
            .map(|i| {
                let v = Vec3::new((i as f64).sin(), 0.5, (2.0 * i as f64).cos());
                Mat3::identity() + skew(&v) * 0.3 + v * v.transpose() * 0.1
            })
            .collect();
        let ctx = EvalContext {
            dynamics: true,
            ..model.context(0.5, Need::with_inertia(30.0, 900.0))
        };
        let mut assembler = Assembler::new(&model, &dofs);
        assembler.assemble_factored(&model, &ctx, &state, &factors);

        // dense, element by element
        let n = dofs.n_equations();
        let mut dense = vec![0.0; n * n];
        for (e, element) in model.elements.iter().enumerate() {
            let nl = element.n_local();
            let (mut r, mut k, mut d) = (vec![0.0; nl], vec![0.0; nl * nl], vec![0.0; nl * nl]);
            element.evaluate(
                &ctx,
                &state,
                &mut ElementOutput {
                    residual: &mut r,
                    stiffness: Some(&mut k),
                    inertia: Some(&mut d),
                },
            );
            let local = dofs.element_dofs(&model, e);
            for (j, &dj) in local.iter().enumerate() {
                let cj = dofs.equation(dj);
                if cj == NO_EQUATION {
                    continue;
                }
                for (i, &di) in local.iter().enumerate() {
                    let ri = dofs.equation(di);
                    if ri == NO_EQUATION {
                        continue;
                    }
                    // (K F)_ij: column j of a node rotation mixes the node's
                    // three rotation columns
                    let kf = match (j < 6 * element.nodes().len(), j % 6) {
                        (true, c) if c >= 3 => {
                            let f = &factors[element.nodes()[j / 6]];
                            let first = j - c + 3;
                            (0..3)
                                .map(|a| k[(first + a) * nl + i] * f[(a, c - 3)])
                                .sum()
                        }
                        _ => k[j * nl + i],
                    };
                    dense[cj * n + ri] += kf + d[j * nl + i];
                }
            }
        }
        let scale = dense.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut worst = 0.0f64;
        for (r, c, v) in assembler.matrix.entries() {
            worst = worst.max((v - dense[c * n + r]).abs());
            dense[c * n + r] = 0.0;
        }
        // nothing outside the pattern
        assert!(dense.iter().all(|&v| v == 0.0));
        assert!(worst <= 1e-14 * scale, "{worst:e} of {scale:e}");
        // the factors matter: without them the matrix differs
        let mut plain = Assembler::new(&model, &dofs);
        plain.assemble(&model, &ctx, &state);
        let diff = plain
            .matrix
            .values()
            .iter()
            .zip(assembler.matrix.values())
            .fold(0.0f64, |w, (a, b)| w.max((a - b).abs()));
        assert!(diff > 1e-3 * scale);
        // the residual and flux alone are those of the assembly with the
        // matrices, bit for bit, and leave the matrix as it was: the
        // dynamics tests convergence on them before it asks for S
        let before = assembler.matrix.values().to_vec();
        let (residual, flux) = (assembler.residual.clone(), assembler.flux.clone());
        assembler.assemble(&model, &ctx.with_need(Need::RESIDUAL), &state);
        assert_eq!(assembler.residual, residual);
        assert_eq!(assembler.flux, flux);
        assert_eq!(assembler.matrix.values(), &before[..]);
    }

    #[test]
    fn block_pattern_and_scatter_maps_match_the_element_entries() {
        let model = hinged_links();
        let dofs = DofMap::new(&model);
        assert!(dofs.n_equations() < dofs.n_dofs());
        check_pattern_and_maps(&model, &dofs);
        // with some multipliers left out (a whole joint's and single ones)
        let n_extra = dofs.n_dofs() - 6 * model.n_nodes();
        assert!(n_extra >= 15);
        let suppressed: Vec<usize> = (0..5).chain([7, 12, 14]).collect();
        let dofs = DofMap::with_suppressed(&model, &suppressed);
        assert_eq!(dofs.n_equations(), DofMap::new(&model).n_equations() - 8);
        check_pattern_and_maps(&model, &dofs);
    }
}
