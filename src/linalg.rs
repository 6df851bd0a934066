//! Sparse linear algebra: the compressed-column system matrix and a sparse
//! direct solver behind a three-phase interface (analyse the pattern once,
//! factor each Newton iteration, solve).
//!
//! The solver is faer's sparse LU with partial (row) pivoting and a COLAMD
//! fill-reducing column ordering. LU rather than Cholesky because the
//! tangent of a material-rotation formulation is not symmetric away from
//! equilibrium, follower loads are not symmetric either, and the saddle-point
//! systems of Lagrange-multiplier constraints are indefinite. The symbolic
//! analysis (ordering, column elimination tree, predicted fill, supernodes)
//! is computed once per sparsity pattern and reused; the numeric factor and
//! its workspace are kept between factorisations, so a Newton iteration
//! allocates little. The dynamic analysis, whose matrices are nearly
//! symmetric, solves with [`SymmetricFirst`] (`symmetric.rs`): the `LDLᵀ`
//! factors of the symmetric part as preconditioner of GMRES, this LU when
//! that fails. Only these files and the eigen-solvers (`src/eigen.rs`)
//! know faer's API.
//!
//! # Column ordering
//!
//! COLAMD orders the *supervariables*: runs of consecutive columns with
//! the same rows, which the assembly produces for the components of a node
//! and the multipliers of a joint. Ordering the compressed matrix (about
//! 1/36 of the entries for blocks of 6) and expanding each block in place
//! halves the symbolic analysis of a 100,000-element cantilever (1.2 s →
//! 0.5 s) with the same predicted fill, and gives less fill on the mast
//! cell (predicted factor entries −27 %, flops −47 %), the lattice mast
//! (−16 to −17 %, flops −35 to −38 %) and beam grids (−10 to −23 %, flops
//! −28 % to +4 %) than COLAMD on the scalar columns.
//!
//! # Choice of the numeric kernel
//!
//! faer factors either column by column (*simplicial*) or by supernodes
//! with dense block kernels (*supernodal*). The analysis predicts the work
//! of the factorisation from the column counts of the Cholesky factor of
//! `(AQ)ᵀ(AQ)` (George & Ng's bound on `L` and `U` under any row pivoting):
//! with `h_j` and `r_j` the entries of column `j` of `L` and of `U`, the
//! flops per factor entry are `Σ h_j (1 + r_j) / Σ (h_j + r_j)`, faer's own
//! estimate. The supernodal kernel is chosen above
//! [`SUPERNODAL_FLOPS_PER_ENTRY`] = 9 flops per entry (faer's default cut
//! is 40) or below [`SUPERNODAL_BELOW_UNKNOWNS`] = 5,000 unknowns.
//!
//! Measured factor + solve (`cargo bench --bench lu_kernel`, 2 cores
//! shared with other work, median of alternated repetitions; times in ms;
//! the time ratio supernodal/simplicial of a second run in brackets):
//!
//! | tangent | unknowns | flops/entry | simplicial | supernodal | ratio | rule |
//! |---|---|---|---|---|---|---|
//! | cantilever, 1,000 beams | 6,000 | 6.4 | 2.9 | 2.6 | 0.89 (1.05) | simplicial |
//! | cantilever, 10,000 beams | 60,000 | 6.4 | 47 | 46 | 0.96 (0.91) | simplicial |
//! | cantilever, 100,000 beams | 600,000 | 6.4 | 394 | 289 | 0.73 (0.87) | simplicial |
//! | joint chain, 100 joints | 1,700 | 7.6 | 1.00 | 0.69 | 0.69 (0.78) | supernodal |
//! | joint chain, 1,000 joints | 17,000 | 7.6 | 16.2 | 17.6 | 1.09 (1.15) | simplicial |
//! | joint chain, 10,000 joints | 170,000 | 7.6 | 146 | 166 | 1.14 (1.11) | simplicial |
//! | mast cell, folded | 417 | 7.6 | 0.37 | 0.24 | 0.65 (0.59) | supernodal |
//! | lattice mast, 8 bays | 738 | 27 | 5.7 | 2.9 | 0.51 (0.55) | supernodal |
//! | lattice mast, 30 bays | 2,718 | 27 | 24 | 11 | 0.46 (0.40) | supernodal |
//! | lattice mast, 99 bays | 8,928 | 28 | 79 | 37 | 0.47 (0.37) | supernodal |
//! | beam grid, 20 × 20 nodes | 2,280 | 65 | 77 | 19 | 0.25 (0.19) | supernodal |
//! | beam grid, 40 × 40 nodes | 9,360 | 129 | 798 | 104 | 0.13 (0.09) | supernodal |
//! | beam grid, 60 × 60 nodes | 21,240 | 180 | 3,710 | 312 | 0.08 (0.07) | supernodal |
//!
//! Wide fronts (lattices, grids: 27 flops per entry and more) factor 1.8
//! to 14 times faster with the supernodal kernel at every size, and every
//! system under 5,000 unknowns faster too (time −22 to −81 %). Thin
//! factors (beams, chains of links: 6.4–7.6) are close: the chains of
//! 1,000 and more joints are 9–15 % slower with the supernodal kernel, the
//! cantilevers from 5 % slower to 27 % faster. No quantity of
//! the analysis tells the two apart (the cantilever predicts less work
//! per entry than the chain), so both stay simplicial, the safe side for
//! saddle-point systems. The cut at 9 lies between them and the lattices.
//!
//! ## Small systems: the dense kernel
//!
//! Up to [`DENSE_UP_TO_UNKNOWNS`] = 48 unknowns the matrix is copied into
//! a dense array and factored by Gaussian elimination with partial
//! pivoting ([`LuKernel::Dense`], no column ordering): at these sizes the
//! bookkeeping of the sparse kernels costs more than the arithmetic they
//! save. Measured factor + solve (`cargo bench --bench lu_kernel -- small`,
//! load average 12 from other work, median of alternated repetitions;
//! times in µs):
//!
//! | tangent | unknowns | simplicial | supernodal | dense |
//! |---|---|---|---|---|
//! | cantilever, 1 beam | 6 | 0.82 | 1.09 | 0.28 |
//! | cantilever, 2 beams | 12 | 2.73 | 2.23 | 0.77 |
//! | joint chain, 1 joint | 17 | 5.59 | 3.63 | 1.17 |
//! | cantilever, 4 beams | 24 | 9.37 | 6.44 | 2.31 |
//! | joint chain, 2 joints | 34 | 12.7 | 10.1 | 3.42 |
//! | cantilever, 10 beams | 60 | 52 | 17.6 | 11.3 |
//! | joint chain, 5 joints | 85 | 41 | 29 | 26 |
//! | cantilever, 20 beams | 120 | 83 | 59 | 76 |
//! | joint chain, 20 joints | 340 | 215 | 150 | 790 |
//!
//! The dense kernel is 3 to 4 times faster than the supernodal one up to
//! 34 unknowns, close to it at 60 and 85 (faster in this run; in the runs
//! before, with faer's dense LU in its place, the supernodal kernel was
//! ahead at 85), and slower from 120 on (its work grows as `n³`); the cut
//! at 48 lies between 34 and 60. The heavy top of bench/peer (11 unknowns,
//! 12,800 steps) runs on 28 % fewer instructions in all with it
//! (callgrind: 2.29·10⁹ → 1.65·10⁹), its results the same within
//! 4·10⁻¹¹ m.

mod symmetric;

pub use symmetric::{SolverCounts, SymmetricFirst};

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::perm::PermRef;
use faer::sparse::linalg::lu::factorize_symbolic_lu;
use faer::sparse::linalg::lu::simplicial::{self, SimplicialLu};
use faer::sparse::linalg::lu::supernodal::{self, SupernodalLu, SymbolicSupernodalLu};
use faer::sparse::linalg::{colamd, qr, LuError};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Spec};

/// Why a linear solve failed.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum SolveError {
    /// The matrix is singular: the equation `equation` has no stiffness
    /// after elimination (relative pivot size `pivot`).
    #[error("singular matrix: pivot {pivot:.3e} (relative) at equation {equation}")]
    Singular {
        /// Equation (column of the system matrix) with the vanishing pivot.
        equation: usize,
        /// Pivot magnitude relative to the largest entry of its column.
        pivot: f64,
    },
    /// The factorisation produced non-finite values.
    #[error(
        "the factorisation produced non-finite values (NaN or infinite entries in the matrix?)"
    )]
    NonFinite,
    /// The solver could not allocate its workspace or failed otherwise.
    #[error("sparse solver failure: {0}")]
    Internal(String),
}

/// A square sparse matrix in compressed-column form with a fixed pattern
/// (sorted row indices in each column) and mutable values.
#[derive(Debug, Clone)]
pub struct SparseMatrix {
    symbolic: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
    /// Which pattern this is: unique to each pattern built, kept by its
    /// clones ([`Self::same_pattern`]).
    pattern: u64,
}

/// The identity of the next pattern built.
static NEXT_PATTERN: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl SparseMatrix {
    /// Builds the pattern from `(row, col)` pairs (duplicates allowed) of an
    /// `n × n` matrix; all values start at zero.
    pub fn from_pattern(n: usize, entries: Vec<(usize, usize)>) -> Self {
        // bucket the rows by column (counting sort), then sort and
        // deduplicate each column on its own
        let mut col_ptr = vec![0usize; n + 1];
        for &(_, c) in &entries {
            col_ptr[c + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let mut fill = col_ptr.clone();
        let mut rows = vec![0usize; entries.len()];
        for &(r, c) in &entries {
            rows[fill[c]] = r;
            fill[c] += 1;
        }
        let mut row_idx = Vec::with_capacity(rows.len());
        let mut unique_ptr = Vec::with_capacity(n + 1);
        unique_ptr.push(0);
        for j in 0..n {
            let column = &mut rows[col_ptr[j]..col_ptr[j + 1]];
            column.sort_unstable();
            let start = row_idx.len();
            for &r in column.iter() {
                if row_idx.len() == start || row_idx.last() != Some(&r) {
                    row_idx.push(r);
                }
            }
            unique_ptr.push(row_idx.len());
        }
        Self::from_columns(n, unique_ptr, row_idx)
    }

    /// Builds an `n × n` pattern from its compressed columns: column `j`
    /// has the rows `row_idx[col_ptr[j]..col_ptr[j + 1]]`, strictly
    /// increasing. All values start at zero.
    #[track_caller]
    pub fn from_columns(n: usize, col_ptr: Vec<usize>, row_idx: Vec<usize>) -> Self {
        let nnz = row_idx.len();
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Self {
            symbolic,
            values: vec![0.0; nnz],
            pattern: NEXT_PATTERN.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        }
    }

    /// Whether `other` has this matrix's pattern because it is a clone of
    /// it (or of its clones): a check in O(1) where comparing the row
    /// indices costs a pass over them. Two patterns built apart are not
    /// the same, even if equal.
    #[inline]
    pub fn same_pattern(&self, other: &SparseMatrix) -> bool {
        self.pattern == other.pattern
    }

    /// Start of column `j` in the value array.
    #[inline]
    pub fn column_start(&self, j: usize) -> usize {
        self.symbolic.col_ptr()[j]
    }

    /// Number of rows (and columns).
    pub fn dim(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Position of entry `(row, col)` in the value array, if it is in the
    /// pattern.
    pub fn position(&self, row: usize, col: usize) -> Option<usize> {
        let ptr = self.symbolic.col_ptr();
        let rows = &self.symbolic.row_idx()[ptr[col]..ptr[col + 1]];
        rows.binary_search(&row).ok().map(|k| ptr[col] + k)
    }

    /// The stored values, in pattern order.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The stored values, for assembly.
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Computes `y = A x`.
    pub fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        let ptr = self.symbolic.col_ptr();
        let rows = self.symbolic.row_idx();
        for (&xj, range) in x.iter().zip(ptr.windows(2)) {
            let (rows, values) = (&rows[range[0]..range[1]], &self.values[range[0]..range[1]]);
            for (&i, &a) in rows.iter().zip(values) {
                y[i] += a * xj;
            }
        }
    }

    /// Computes `y = |A| x`, with `|A|` the entrywise absolute values: the
    /// size of the terms that cancel in `A x`, from which its round-off is
    /// estimated.
    pub fn mul_abs_vec(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        let ptr = self.symbolic.col_ptr();
        let rows = self.symbolic.row_idx();
        for (j, &xj) in x.iter().enumerate() {
            for k in ptr[j]..ptr[j + 1] {
                y[rows[k]] += self.values[k].abs() * xj;
            }
        }
    }

    /// Row indices of the stored entries, in pattern order (column by
    /// column; the entries of column `j` start at [`Self::column_start`]).
    pub fn row_indices(&self) -> &[usize] {
        self.symbolic.row_idx()
    }

    /// Every stored entry as `(row, col, value)`, column by column.
    pub fn entries(&self) -> Entries<'_> {
        Entries {
            col_ptr: self.symbolic.col_ptr(),
            rows: self.symbolic.row_idx(),
            values: &self.values,
            col: 0,
            k: 0,
        }
    }

    /// Largest absolute value in column `j`.
    pub fn column_max_abs(&self, j: usize) -> f64 {
        let ptr = self.symbolic.col_ptr();
        self.values[ptr[j]..ptr[j + 1]]
            .iter()
            .fold(0.0, |m, v| m.max(v.abs()))
    }

    fn as_faer(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(self.symbolic.as_ref(), &self.values)
    }
}

/// The stored entries of a [`SparseMatrix`] as `(row, col, value)`,
/// column by column ([`SparseMatrix::entries`]): one position in the value
/// array and the column it is in, advanced past empty columns.
pub struct Entries<'a> {
    col_ptr: &'a [usize],
    rows: &'a [usize],
    values: &'a [f64],
    col: usize,
    k: usize,
}

impl Iterator for Entries<'_> {
    type Item = (usize, usize, f64);

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        if self.k >= self.values.len() {
            return None;
        }
        while self.col_ptr[self.col + 1] <= self.k {
            self.col += 1;
        }
        let k = self.k;
        self.k += 1;
        Some((self.rows[k], self.col, self.values[k]))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.values.len() - self.k;
        (left, Some(left))
    }
}

impl ExactSizeIterator for Entries<'_> {}

/// The numeric kernel of the sparse LU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LuKernel {
    /// Column by column (left-looking, sparse triangular solves): no dense
    /// blocks, cheapest when the factors stay thin.
    Simplicial,
    /// By supernodes (columns with a common structure) with dense block
    /// kernels: pays off when the fronts are wide.
    Supernodal,
    /// The matrix copied into a dense array and factored by the dense LU
    /// with partial pivoting: no symbolic bookkeeping at all, cheapest for
    /// the smallest systems (a rigid body on a joint, a few links).
    Dense,
}

/// Number of unknowns up to which the dense kernel is chosen
/// ([`LuKernel::Dense`]); the measurements are in the module header.
pub const DENSE_UP_TO_UNKNOWNS: usize = 48;

/// Predicted flops per factor entry above which the supernodal kernel is
/// chosen: above the beams and chains of links (6.4–7.6, where neither
/// kernel is clearly faster on large systems) and below the lattices and
/// grids (27 and more, where the supernodal kernel is 1.8 to 14 times
/// faster); the measurements are in the module header.
pub const SUPERNODAL_FLOPS_PER_ENTRY: f64 = 9.0;

/// Number of unknowns below which the supernodal kernel is chosen
/// whatever the predicted work: every system measured below it factored
/// faster with it (time −22 to −81 %, the mast cell −35 to −41 %), and the
/// joint chains above it slower (module header).
pub const SUPERNODAL_BELOW_UNKNOWNS: usize = 5_000;

/// Sparse LU factorisation with a reusable symbolic analysis.
pub struct SparseLu {
    /// Fill-reducing column ordering (COLAMD), `A Q`.
    col_perm_fwd: Vec<usize>,
    col_perm_inv: Vec<usize>,
    /// Row pivoting of the last factorisation, `P A Q = L U`.
    row_perm_fwd: Vec<usize>,
    row_perm_inv: Vec<usize>,
    /// Predicted flops per entry of `L + U` (without pivoting).
    flops_per_entry: f64,
    factors: Factors,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    par: Par,
    factored: bool,
}

/// The factors of either kernel, with what each needs.
enum Factors {
    Simplicial(SimplicialLu<usize, f64>),
    Supernodal(Box<SupernodalFactors>),
    Dense(DenseLu),
}

/// `P A = L U` of a small matrix stored dense, by Gaussian elimination with
/// partial (row) pivoting (Golub & Van Loan, *Matrix Computations*, 4th
/// ed., algorithm 3.4.1, column-oriented): `L` unit lower, below the
/// diagonal, and `U`, on and above it, in one column-major array; `P` as
/// the row interchanges of each step. Written out rather than taken from
/// faer's dense LU, whose blocked, recursive and vectorised kernel costs
/// about 8,000 instructions for a factorisation of 11 unknowns and 3,600
/// for a solve (the heavy top, bench/peer), several times the arithmetic.
/// An exactly zero pivot is divided by like any other: its infinite or
/// undefined entries come out of the solve, which reports them
/// ([`SolveError::NonFinite`]), as the sparse kernels' do.
struct DenseLu {
    n: usize,
    /// The factors, column-major `n × n`.
    lu: Vec<f64>,
    /// Row interchanged with row `k` at step `k`.
    pivots: Vec<usize>,
}

impl DenseLu {
    fn new(n: usize) -> Self {
        Self {
            n,
            lu: vec![0.0; n * n],
            pivots: vec![0; n],
        }
    }

    fn factor(&mut self, a: &SparseMatrix) {
        let n = self.n;
        let lu = &mut self.lu;
        lu.fill(0.0);
        let (ptr, rows) = (a.symbolic.col_ptr(), a.symbolic.row_idx());
        for j in 0..n {
            for k in ptr[j]..ptr[j + 1] {
                lu[j * n + rows[k]] = a.values[k];
            }
        }
        for k in 0..n {
            // pivot: the largest entry of column k on or below the diagonal
            let column = &lu[k * n..(k + 1) * n];
            let p = (k..n).fold(k, |p, i| {
                if column[i].abs() > column[p].abs() {
                    i
                } else {
                    p
                }
            });
            self.pivots[k] = p;
            if p != k {
                for j in 0..n {
                    lu.swap(j * n + k, j * n + p);
                }
            }
            // multipliers l_ik = a_ik / a_kk, then the update of the
            // trailing columns a_ij -= l_ik a_kj
            let inv = 1.0 / lu[k * n + k];
            for v in &mut lu[k * n + k + 1..(k + 1) * n] {
                *v *= inv;
            }
            let (head, tail) = lu.split_at_mut((k + 1) * n);
            let l = &head[k * n + k + 1..];
            for column in tail.chunks_exact_mut(n) {
                let u = column[k];
                if u != 0.0 {
                    for (c, &m) in column[k + 1..].iter_mut().zip(l) {
                        *c -= m * u;
                    }
                }
            }
        }
    }

    /// Solves `A x = b` in place with the factors.
    fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        for (k, &p) in self.pivots.iter().enumerate() {
            b.swap(k, p);
        }
        // L y = P b (unit diagonal), then U x = y
        for k in 0..n {
            let bk = b[k];
            for (v, &m) in b[k + 1..]
                .iter_mut()
                .zip(&self.lu[k * n + k + 1..(k + 1) * n])
            {
                *v -= m * bk;
            }
        }
        for k in (0..n).rev() {
            b[k] /= self.lu[k * n + k];
            let bk = b[k];
            for (v, &u) in b[..k].iter_mut().zip(&self.lu[k * n..k * n + k]) {
                *v -= u * bk;
            }
        }
    }

    /// `sgn det A = sgn P · Π sgn uₖₖ` (0 if a pivot is zero).
    fn determinant_sign(&self) -> f64 {
        let n = self.n;
        let swaps = self
            .pivots
            .iter()
            .enumerate()
            .filter(|&(k, &p)| p != k)
            .count();
        let mut sign = if swaps.is_multiple_of(2) { 1.0 } else { -1.0 };
        for k in 0..n {
            let d = self.lu[k * n + k];
            sign *= d.signum() * f64::from(u8::from(d != 0.0));
        }
        sign
    }
}

struct SupernodalFactors {
    symbolic: SymbolicSupernodalLu<usize>,
    lu: SupernodalLu<usize, f64>,
    /// `Aᵀ`, which the supernodal kernel reads besides `A`: its pattern,
    /// its values, and the position in `A`'s values of each of them.
    transpose: SymbolicSparseColMat<usize>,
    transpose_values: Vec<f64>,
    transpose_source: Vec<usize>,
}

impl std::fmt::Debug for SparseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseLu")
            .field("dim", &self.col_perm_fwd.len())
            .field("kernel", &self.kernel())
            .field("flops_per_entry", &self.flops_per_entry)
            .field("factored", &self.factored)
            .finish()
    }
}

/// Unknowns of a system below which faer factors and solves it on one
/// thread whatever the threads of the pool. Measured on 2 cores: the ERA
/// platform's deployment (7,788 unknowns) took 89–91 s with its
/// factorisations on two threads and its assembly on one, 68 s with both
/// on one (runs taken in turn); the factorisation and solve of a
/// cantilever of 600,000 unknowns took 444–464 ms either way.
pub const PARALLEL_UNKNOWNS: usize = 100_000;

/// faer's parallelism for a system of `n` unknowns.
fn par_for(n: usize) -> Par {
    let threads = rayon::current_num_threads();
    if threads > 1 && n >= PARALLEL_UNKNOWNS {
        Par::rayon(threads)
    } else {
        Par::Seq
    }
}

fn internal(e: &dyn std::fmt::Debug) -> SolveError {
    SolveError::Internal(format!("{e:?}"))
}

fn workspace(req: StackReq, what: &str) -> Result<MemBuffer, SolveError> {
    MemBuffer::try_new(req)
        .map_err(|_| SolveError::Internal(format!("out of memory for the {what} workspace")))
}

/// The pattern of `Aᵀ` (sorted columns) and, if `with_source`, the
/// position in `A`'s values of each of its entries.
fn transpose_pattern(
    a: &SparseMatrix,
    with_source: bool,
) -> (SymbolicSparseColMat<usize>, Vec<usize>) {
    let n = a.dim();
    let (ptr, rows) = (a.symbolic.col_ptr(), a.symbolic.row_idx());
    let mut t_ptr = vec![0usize; n + 1];
    for &r in rows {
        t_ptr[r + 1] += 1;
    }
    for i in 0..n {
        t_ptr[i + 1] += t_ptr[i];
    }
    let mut fill = t_ptr.clone();
    let mut t_rows = vec![0usize; rows.len()];
    let mut source = if with_source {
        vec![0usize; rows.len()]
    } else {
        Vec::new()
    };
    for j in 0..n {
        for k in ptr[j]..ptr[j + 1] {
            let r = rows[k];
            t_rows[fill[r]] = j;
            if with_source {
                source[fill[r]] = k;
            }
            fill[r] += 1;
        }
    }
    let t = SymbolicSparseColMat::new_checked(n, n, t_ptr, None, t_rows);
    (t, source)
}

/// COLAMD ordering of `a` computed on its supervariables: runs of
/// consecutive columns with the same rows (the components of a node, the
/// multipliers of a joint) are ordered as one column, on the matrix whose
/// rows are merged the same way, and then expanded in their own order.
/// The compressed matrix has about `1/b²` of the entries for blocks of
/// `b` unknowns, and COLAMD's time goes down with it.
fn supervariable_ordering(
    a: &SparseMatrix,
    stack: &mut MemStack,
) -> Result<(Vec<usize>, Vec<usize>), SolveError> {
    let n = a.dim();
    let (ptr, rows) = (a.symbolic.col_ptr(), a.symbolic.row_idx());
    let column = |j: usize| &rows[ptr[j]..ptr[j + 1]];
    // supervariable of each index and the first index of each
    let mut group = vec![0usize; n];
    let mut first = Vec::with_capacity(n + 1);
    for j in 0..n {
        if j == 0 || column(j) != column(j - 1) {
            first.push(j);
        }
        group[j] = first.len() - 1;
    }
    let ns = first.len();
    first.push(n);
    // the compressed pattern: rows of each supervariable's first column,
    // merged by supervariable (non-decreasing, so duplicates are adjacent)
    let mut s_ptr = Vec::with_capacity(ns + 1);
    let mut s_rows = Vec::new();
    s_ptr.push(0);
    for &j in &first[..ns] {
        for &r in column(j) {
            if s_rows.len() == *s_ptr.last().unwrap() || s_rows.last() != Some(&group[r]) {
                s_rows.push(group[r]);
            }
        }
        s_ptr.push(s_rows.len());
    }
    let compressed = SymbolicSparseColMat::new_checked(ns, ns, s_ptr, None, s_rows);
    let mut s_fwd = vec![0usize; ns];
    let mut s_inv = vec![0usize; ns];
    colamd::order(
        &mut s_fwd,
        &mut s_inv,
        compressed.as_ref(),
        Default::default(),
        stack,
    )
    .map_err(|e| internal(&e))?;
    // expand: the unknowns of each supervariable in their own order
    let mut fwd = Vec::with_capacity(n);
    for &sv in &s_fwd {
        fwd.extend(first[sv]..first[sv + 1]);
    }
    let mut inv = vec![0usize; n];
    for (k, &j) in fwd.iter().enumerate() {
        inv[j] = k;
    }
    Ok((fwd, inv))
}

impl SparseLu {
    /// Symbolic analysis of the pattern of `a` (fill-reducing ordering,
    /// elimination tree, predicted fill, supernodes), with the kernel the
    /// predicted work calls for ([`SUPERNODAL_FLOPS_PER_ENTRY`]). Valid for
    /// every matrix with the same pattern.
    pub fn analyze(a: &SparseMatrix) -> Result<Self, SolveError> {
        Self::analyze_for(a, None)
    }

    /// Symbolic analysis for the numeric kernel `kernel`, whatever the
    /// prediction.
    pub fn analyze_with(a: &SparseMatrix, kernel: LuKernel) -> Result<Self, SolveError> {
        Self::analyze_for(a, Some(kernel))
    }

    fn analyze_for(a: &SparseMatrix, kernel: Option<LuKernel>) -> Result<Self, SolveError> {
        let n = a.dim();
        let pattern = a.symbolic.as_ref();
        let (transpose, _) = transpose_pattern(a, false);
        let mut mem = workspace(
            StackReq::any_of(&[
                colamd::order_scratch::<usize>(n, n, a.nnz()),
                qr::col_etree_scratch::<usize>(n, n),
                qr::postorder_scratch::<usize>(n),
                qr::column_counts_aat_scratch::<usize>(n, n),
                supernodal::factorize_supernodal_symbolic_lu_scratch::<usize>(n, n),
            ]),
            "symbolic analysis",
        )?;
        let stack = MemStack::new(&mut mem);

        // fill-reducing column ordering Q (COLAMD), of the supervariables
        let (col_perm_fwd, col_perm_inv) = supervariable_ordering(a, stack)?;
        let col_perm = PermRef::new_checked(&col_perm_fwd, &col_perm_inv, n);

        // column elimination tree (that of (AQ)ᵀ(AQ)), its postorder, and
        // the column counts of its Cholesky factor: the structure of U
        // and an upper bound on L whatever the row pivoting (George & Ng)
        let mut etree = vec![0usize; n];
        let etree = qr::col_etree(pattern, Some(col_perm), &mut etree, stack);
        let mut post = vec![0usize; n];
        qr::postorder(&mut post, etree, stack);
        let mut col_counts = vec![0usize; n];
        let mut min_col = vec![0usize; n];
        qr::column_counts_ata(
            &mut col_counts,
            &mut min_col,
            transpose.as_ref(),
            Some(col_perm),
            etree,
            &post,
            stack,
        );

        // predicted work per factor entry, as faer estimates it: column j
        // of L has h_j entries (rows whose first column is j, plus those
        // inherited from its children in the tree), column j of U r_j;
        // flops Σ h_j (1 + r_j) over entries Σ (h_j + r_j)
        let parent = etree.into_inner();
        let mut h = vec![0usize; n];
        for &first in &min_col {
            if (first as isize) >= 0 {
                h[first] += 1;
            }
        }
        for j in 0..n {
            if parent[j] >= 0 {
                h[parent[j] as usize] += h[j].saturating_sub(1);
            }
        }
        let (mut flops, mut entries) = (0.0f64, 0.0f64);
        for (&hj, &rj) in h.iter().zip(&col_counts) {
            let (hj, rj) = (hj as f64, rj as f64);
            flops += hj + hj * rj;
            entries += hj + rj;
        }
        let flops_per_entry = if entries > 0.0 { flops / entries } else { 0.0 };
        let kernel = kernel.unwrap_or(if n <= DENSE_UP_TO_UNKNOWNS {
            LuKernel::Dense
        } else if flops_per_entry > SUPERNODAL_FLOPS_PER_ENTRY || n < SUPERNODAL_BELOW_UNKNOWNS {
            LuKernel::Supernodal
        } else {
            LuKernel::Simplicial
        });

        let par = par_for(n);
        let lu_params: Spec<PartialPivLuParams, f64> = Default::default();
        let (factors, factor_req, solve_req) = match kernel {
            LuKernel::Dense => (
                Factors::Dense(DenseLu::new(n)),
                StackReq::EMPTY,
                StackReq::EMPTY,
            ),
            LuKernel::Simplicial => (
                Factors::Simplicial(SimplicialLu::new()),
                simplicial::factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n),
                simplicial::solve_in_place_scratch::<usize, f64>(n, 1, par),
            ),
            LuKernel::Supernodal => {
                let symbolic = supernodal::factorize_supernodal_symbolic_lu(
                    pattern,
                    Some(col_perm),
                    &min_col,
                    etree,
                    &col_counts,
                    stack,
                    Default::default(),
                )
                .map_err(|e| internal(&e))?;
                let factor_req = supernodal::factorize_supernodal_numeric_lu_scratch::<usize, f64>(
                    &symbolic, lu_params,
                );
                let (transpose, transpose_source) = transpose_pattern(a, true);
                (
                    Factors::Supernodal(Box::new(SupernodalFactors {
                        symbolic,
                        lu: SupernodalLu::new(),
                        transpose,
                        transpose_values: vec![0.0; a.nnz()],
                        transpose_source,
                    })),
                    factor_req,
                    supernodal::solve_in_place_scratch::<usize, f64>(n, 1, par),
                )
            }
        };
        // the dense kernel factors A itself: no column ordering
        let (col_perm_fwd, col_perm_inv) = if kernel == LuKernel::Dense {
            ((0..n).collect(), (0..n).collect())
        } else {
            (col_perm_fwd, col_perm_inv)
        };
        Ok(Self {
            col_perm_fwd,
            col_perm_inv,
            row_perm_fwd: vec![0; n],
            row_perm_inv: vec![0; n],
            flops_per_entry,
            factors,
            factor_mem: workspace(factor_req, "factorisation")?,
            solve_mem: workspace(solve_req, "solve")?,
            par,
            factored: false,
        })
    }

    /// The numeric kernel of this analysis.
    pub fn kernel(&self) -> LuKernel {
        match self.factors {
            Factors::Simplicial(_) => LuKernel::Simplicial,
            Factors::Supernodal(_) => LuKernel::Supernodal,
            Factors::Dense(_) => LuKernel::Dense,
        }
    }

    /// Predicted flops per entry of the factors (without pivoting), the
    /// quantity that chooses the kernel.
    pub fn flops_per_entry(&self) -> f64 {
        self.flops_per_entry
    }

    /// Numeric factorisation of `a`, which must have the analysed pattern.
    pub fn factor(&mut self, a: &SparseMatrix) -> Result<(), SolveError> {
        self.factored = false;
        if a.values.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        let n = self.col_perm_fwd.len();
        let col_perm = PermRef::new_checked(&self.col_perm_fwd, &self.col_perm_inv, n);
        let stack = MemStack::new(&mut self.factor_mem);
        let result = match &mut self.factors {
            Factors::Simplicial(lu) => simplicial::factorize_simplicial_numeric_lu(
                &mut self.row_perm_fwd,
                &mut self.row_perm_inv,
                lu,
                a.as_faer(),
                col_perm,
                stack,
            ),
            Factors::Supernodal(f) => {
                let SupernodalFactors {
                    symbolic,
                    lu,
                    transpose,
                    transpose_values,
                    transpose_source,
                } = &mut **f;
                for (v, &k) in transpose_values.iter_mut().zip(transpose_source.iter()) {
                    *v = a.values[k];
                }
                supernodal::factorize_supernodal_numeric_lu(
                    &mut self.row_perm_fwd,
                    &mut self.row_perm_inv,
                    lu,
                    a.as_faer(),
                    SparseColMatRef::new(transpose.as_ref(), transpose_values),
                    col_perm,
                    symbolic,
                    self.par,
                    stack,
                    Default::default(),
                )
            }
            Factors::Dense(lu) => {
                lu.factor(a);
                Ok(())
            }
        };
        match result {
            Ok(()) => {}
            Err(LuError::SymbolicSingular { index }) => {
                return Err(SolveError::Singular {
                    equation: self.col_perm_fwd[index],
                    pivot: 0.0,
                })
            }
            Err(e) => return Err(internal(&e)),
        }
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = b` in place (`rhs` holds `b` on entry, `x` on exit).
    /// Returns [`SolveError::NonFinite`] when the solution is not finite,
    /// which is how an exactly singular matrix shows.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), SolveError> {
        assert!(self.factored, "solve before a successful factorisation");
        let n = rhs.len();
        if let Factors::Dense(lu) = &self.factors {
            lu.solve(rhs);
        } else {
            let row_perm = PermRef::new_checked(&self.row_perm_fwd, &self.row_perm_inv, n);
            let col_perm = PermRef::new_checked(&self.col_perm_fwd, &self.col_perm_inv, n);
            let stack = MemStack::new(&mut self.solve_mem);
            let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
            match &self.factors {
                Factors::Simplicial(lu) => {
                    lu.solve_in_place_with_conj(row_perm, col_perm, Conj::No, x, self.par, stack)
                }
                Factors::Supernodal(f) => {
                    f.lu.solve_in_place_with_conj(row_perm, col_perm, Conj::No, x, self.par, stack)
                }
                Factors::Dense(_) => {} // solved above
            }
        }
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        Ok(())
    }
}

/// Parity of a permutation given by its forward array: `1.0` if even,
/// `-1.0` if odd (`n` minus the number of cycles, mod 2).
fn permutation_sign(perm: &[usize]) -> f64 {
    let mut seen = vec![false; perm.len()];
    let mut transpositions = 0usize;
    for start in 0..perm.len() {
        let mut i = start;
        let mut length = 0usize;
        while !seen[i] {
            seen[i] = true;
            i = perm[i];
            length += 1;
        }
        transpositions += length.saturating_sub(1);
    }
    if transpositions.is_multiple_of(2) {
        1.0
    } else {
        -1.0
    }
}

/// Sign of the product of the diagonals of `L` and `U` of a simplicial
/// factorisation (0 if a pivot is zero).
fn simplicial_diagonal_sign(lu: &SimplicialLu<usize, f64>) -> f64 {
    let mut sign = 1.0;
    for m in [lu.l_factor_unsorted(), lu.u_factor_unsorted()] {
        let (ptr, rows, vals) = (m.col_ptr(), m.row_idx(), m.val());
        for j in 0..ptr.len() - 1 {
            let d = (ptr[j]..ptr[j + 1])
                .find(|&k| rows[k] == j)
                .map_or(0.0, |k| vals[k]);
            sign *= d.signum() * f64::from(u8::from(d != 0.0));
        }
    }
    sign
}

/// The sign of the determinant of matrices of one pattern, from an LU
/// factorisation `P A Q = L U`: `sgn det A = sgn P · sgn Q · Π sgn lⱼⱼ
/// uⱼⱼ`. A change of sign between two matrices means that an odd number of
/// eigenvalues crossed zero between them (a limit or bifurcation point of
/// an equilibrium path).
///
/// faer's supernodal factors cannot be read, so the sign is taken from a
/// simplicial factorisation with the same column ordering: the factors of
/// the last [`SparseLu::factor`] when its kernel is simplicial (no extra
/// work), a factorisation of its own otherwise (kept workspace; a few
/// milliseconds below [`SUPERNODAL_BELOW_UNKNOWNS`] unknowns, and not
/// attempted above: [`DeterminantSign::of`] returns `None`).
#[derive(Default)]
pub struct DeterminantSign {
    own: Option<SimplicialSide>,
}

struct SimplicialSide {
    lu: SimplicialLu<usize, f64>,
    row_fwd: Vec<usize>,
    row_inv: Vec<usize>,
    mem: MemBuffer,
}

impl DeterminantSign {
    /// `sgn det a`, with `lu` the factorisation analysed for `a`'s
    /// pattern; when `lu`'s kernel is simplicial, `lu` must hold the
    /// factors of `a` (or of the matrix whose sign is wanted). `None` if it
    /// cannot be had (a supernodal system of [`SUPERNODAL_BELOW_UNKNOWNS`]
    /// unknowns or more, a structurally singular matrix, no factors).
    pub fn of(&mut self, lu: &SparseLu, a: &SparseMatrix) -> Option<f64> {
        let n = a.dim();
        let col = permutation_sign(&lu.col_perm_fwd);
        match &lu.factors {
            Factors::Simplicial(f) => {
                if !lu.factored {
                    return None;
                }
                Some(col * permutation_sign(&lu.row_perm_fwd) * simplicial_diagonal_sign(f))
            }
            Factors::Dense(f) => {
                if !lu.factored {
                    return None;
                }
                Some(f.determinant_sign())
            }
            Factors::Supernodal(_) => {
                if n >= SUPERNODAL_BELOW_UNKNOWNS || a.values.iter().any(|v| !v.is_finite()) {
                    return None;
                }
                if self.own.as_ref().is_none_or(|o| o.row_fwd.len() != n) {
                    let mem =
                        MemBuffer::try_new(simplicial::factorize_simplicial_numeric_lu_scratch::<
                            usize,
                            f64,
                        >(n, n))
                        .ok()?;
                    self.own = Some(SimplicialSide {
                        lu: SimplicialLu::new(),
                        row_fwd: vec![0; n],
                        row_inv: vec![0; n],
                        mem,
                    });
                }
                let side = self.own.as_mut()?;
                let col_perm = PermRef::new_checked(&lu.col_perm_fwd, &lu.col_perm_inv, n);
                simplicial::factorize_simplicial_numeric_lu(
                    &mut side.row_fwd,
                    &mut side.row_inv,
                    &mut side.lu,
                    a.as_faer(),
                    col_perm,
                    MemStack::new(&mut side.mem),
                )
                .ok()?;
                Some(col * permutation_sign(&side.row_fwd) * simplicial_diagonal_sign(&side.lu))
            }
        }
    }
}

/// Finds the equation with the smallest pivot, relative to the largest
/// entry of its column, in an LU factorisation of `a`. Used to say *where*
/// a system is singular after a solve has failed: it runs a slower
/// simplicial factorisation whose factors can be inspected, and is never
/// called on the Newton hot path.
pub fn smallest_relative_pivot(a: &SparseMatrix) -> Result<(usize, f64), SolveError> {
    let symbolic =
        factorize_symbolic_lu(a.symbolic.as_ref(), Default::default()).map_err(|e| internal(&e))?;
    let n = a.dim();
    let mut lu = SimplicialLu::<usize, f64>::new();
    let mut row_perm = vec![0usize; n];
    let mut row_perm_inv = vec![0usize; n];
    let mut mem = MemBuffer::try_new(simplicial::factorize_simplicial_numeric_lu_scratch::<
        usize,
        f64,
    >(n, n))
    .map_err(|e| internal(&e))?;
    let col_perm = symbolic.col_perm();
    let (col_fwd, _) = col_perm.arrays();
    match simplicial::factorize_simplicial_numeric_lu(
        &mut row_perm,
        &mut row_perm_inv,
        &mut lu,
        a.as_faer(),
        col_perm,
        MemStack::new(&mut mem),
    ) {
        Ok(()) => {}
        Err(LuError::SymbolicSingular { index }) => return Ok((col_fwd[index], 0.0)),
        Err(e) => return Err(internal(&e)),
    }
    let u = lu.u_factor_unsorted();
    let (ptr, rows, vals) = (u.col_ptr(), u.row_idx(), u.val());
    let mut worst = (0usize, f64::INFINITY);
    for j in 0..n {
        // column j of U belongs to column col_fwd[j] of A
        let col = col_fwd[j];
        let scale = a.column_max_abs(col).max(f64::MIN_POSITIVE);
        let diag = (ptr[j]..ptr[j + 1])
            .find(|&k| rows[k] == j)
            .map(|k| vals[k].abs())
            .unwrap_or(0.0);
        let rel = if diag.is_finite() { diag / scale } else { 0.0 };
        if rel < worst.1 {
            worst = (col, rel);
        }
    }
    Ok(worst)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sign of the determinant from either kernel against the dense
    /// determinant (nalgebra's LU) of the saddle-point matrix and of
    /// random sparse matrices with both signs: equal signs every time.
    #[test]
    fn determinant_signs_match_the_dense_determinant() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut matrices = vec![saddle(1.0).0, saddle(-1.0).0];
        for n in [5usize, 9, 14] {
            for _ in 0..4 {
                let mut entries: Vec<(usize, usize)> = (0..n).map(|i| (i, i)).collect();
                entries.extend((0..n - 1).map(|i| (i, i + 1)));
                entries.extend((0..n - 1).map(|i| (i + 1, i)));
                entries.extend((0..n).map(|i| (i, (i * 7 + 3) % n)));
                let mut a = SparseMatrix::from_pattern(n, entries);
                a.values_mut().iter_mut().for_each(|v| *v = random());
                matrices.push(a);
            }
        }
        let mut signs = Vec::new();
        for a in &matrices {
            let n = a.dim();
            let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
            for (i, j, v) in a.entries() {
                dense[(i, j)] += v;
            }
            let det = dense.clone().lu().determinant();
            if det.abs() < 1e-8 {
                continue;
            }
            for kernel in [LuKernel::Simplicial, LuKernel::Supernodal, LuKernel::Dense] {
                let mut lu = SparseLu::analyze_with(a, kernel).unwrap();
                lu.factor(a).unwrap();
                let sign = DeterminantSign::default().of(&lu, a);
                assert_eq!(sign, Some(det.signum()), "{kernel:?}, n = {n}, det = {det}");
            }
            signs.push(det.signum());
        }
        // both signs met, on most of the matrices
        assert!(
            signs.len() >= 10 && signs.contains(&1.0) && signs.contains(&-1.0),
            "{signs:?}"
        );
    }

    /// `[[K, Bᵀ], [B, 0]]` with K the 1-D Laplacian (4 unknowns) and two
    /// constraint rows: an indefinite saddle-point matrix.
    fn saddle(scale: f64) -> (SparseMatrix, Vec<f64>) {
        let k = [
            (0, 0, 2.0),
            (0, 1, -1.0),
            (1, 0, -1.0),
            (1, 1, 2.0),
            (1, 2, -1.0),
            (2, 1, -1.0),
            (2, 2, 2.0),
            (2, 3, -1.0),
            (3, 2, -1.0),
            (3, 3, 2.0),
            // constraints x0 − x3 = …, x1 + x2 = …
            (4, 0, 1.0),
            (4, 3, -1.0),
            (0, 4, 1.0),
            (3, 4, -1.0),
            (5, 1, 1.0),
            (5, 2, 1.0),
            (1, 5, 1.0),
            (2, 5, 1.0),
        ];
        let mut a = SparseMatrix::from_pattern(6, k.iter().map(|&(i, j, _)| (i, j)).collect());
        for &(i, j, v) in &k {
            let p = a.position(i, j).unwrap();
            a.values_mut()[p] = v * scale;
        }
        (a, vec![1.0, -2.0, 0.5, 3.0, 0.25, -1.0])
    }

    #[test]
    fn lu_solves_saddle_point_systems_and_reuses_the_analysis() {
        let (a, b) = saddle(1.0);
        for kernel in [LuKernel::Simplicial, LuKernel::Supernodal, LuKernel::Dense] {
            let mut lu = SparseLu::analyze_with(&a, kernel).unwrap();
            assert_eq!(lu.kernel(), kernel);
            solves_for_two_scales(&mut lu, &b);
        }
        let mut lu = SparseLu::analyze(&a).unwrap();
        solves_for_two_scales(&mut lu, &b);
    }

    fn solves_for_two_scales(lu: &mut SparseLu, b: &[f64]) {
        for scale in [1.0, 3.5] {
            // new values, same pattern: the symbolic analysis is reused
            let (a, _) = saddle(scale);
            lu.factor(&a).unwrap();
            let mut x = b.to_vec();
            lu.solve_in_place(&mut x).unwrap();
            let mut ax = vec![0.0; 6];
            a.mul_vec(&x, &mut ax);
            let err = ax
                .iter()
                .zip(b)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-13, "residual {err:e}");
        }
    }

    /// An `n × n` matrix with the pattern of `pairs` and non-symmetric
    /// values, diagonally dominant.
    fn matrix(n: usize, pairs: Vec<(usize, usize)>) -> SparseMatrix {
        let mut a = SparseMatrix::from_pattern(n, pairs);
        let entries: Vec<(usize, usize)> = a.entries().map(|(i, j, _)| (i, j)).collect();
        for (i, j) in entries {
            let p = a.position(i, j).unwrap();
            a.values_mut()[p] = if i == j {
                4.0 * n as f64
            } else {
                1.0 + 0.1 * ((3 * i + 7 * j) % 11) as f64
            };
        }
        a
    }

    /// Tridiagonal pattern of size `n`.
    fn band(n: usize) -> SparseMatrix {
        matrix(
            n,
            (0..n)
                .flat_map(|i| [(i, i), (i, i + 1), (i + 1, i)])
                .filter(|&(i, j)| i.max(j) < n)
                .collect(),
        )
    }

    #[test]
    fn kernel_follows_the_predicted_work_and_the_size() {
        // a tridiagonal matrix factors without fill, about one flop per
        // entry: simplicial when large, supernodal when small; dense blocks
        // of 90 cost ~15 flops per entry: supernodal
        let large_band = band(6000);
        let blocks = matrix(
            56 * 90,
            (0..56 * 90)
                .flat_map(|i| (90 * (i / 90)..90 * (i / 90 + 1)).map(move |j| (i, j)))
                .collect(),
        );
        let lu = SparseLu::analyze(&large_band).unwrap();
        assert_eq!(lu.kernel(), LuKernel::Simplicial);
        assert!(lu.flops_per_entry() < 2.0, "{}", lu.flops_per_entry());
        let lu = SparseLu::analyze(&band(200)).unwrap();
        assert_eq!(lu.kernel(), LuKernel::Supernodal);
        let lu = SparseLu::analyze(&band(DENSE_UP_TO_UNKNOWNS)).unwrap();
        assert_eq!(lu.kernel(), LuKernel::Dense);
        let lu = SparseLu::analyze(&band(DENSE_UP_TO_UNKNOWNS + 1)).unwrap();
        assert_eq!(lu.kernel(), LuKernel::Supernodal);
        let lu = SparseLu::analyze(&blocks).unwrap();
        assert_eq!(lu.kernel(), LuKernel::Supernodal);
        assert!(lu.flops_per_entry() > 10.0, "{}", lu.flops_per_entry());
        // every kernel solves both, and a small one (the dense kernel only
        // that: its work grows as the cube of the size)
        let small = band(DENSE_UP_TO_UNKNOWNS);
        for a in [&large_band, &blocks, &small] {
            let b: Vec<f64> = (0..a.dim()).map(|i| (i % 7) as f64 - 3.0).collect();
            let kernels = [LuKernel::Simplicial, LuKernel::Supernodal, LuKernel::Dense];
            for kernel in kernels
                .into_iter()
                .filter(|&k| k != LuKernel::Dense || a.dim() < 100)
            {
                let mut lu = SparseLu::analyze_with(a, kernel).unwrap();
                lu.factor(a).unwrap();
                let mut x = b.clone();
                lu.solve_in_place(&mut x).unwrap();
                let mut ax = vec![0.0; a.dim()];
                a.mul_vec(&x, &mut ax);
                let err = ax
                    .iter()
                    .zip(&b)
                    .map(|(p, q)| (p - q).abs())
                    .fold(0.0, f64::max);
                assert!(err < 1e-12, "{kernel:?}: residual {err:e}");
            }
        }
    }

    #[test]
    fn supervariables_are_ordered_together() {
        // blocks of 3 equal columns: each block stays contiguous and in
        // its own order in the column ordering
        let n = 30;
        let a = matrix(
            n,
            (0..n)
                .flat_map(|i| {
                    let b = i / 3;
                    (3 * b.saturating_sub(1)..(3 * (b + 2)).min(n)).map(move |j| (i, j))
                })
                .collect(),
        );
        let mut mem = MemBuffer::new(colamd::order_scratch::<usize>(n, n, a.nnz()));
        let (fwd, inv) = supervariable_ordering(&a, MemStack::new(&mut mem)).unwrap();
        for k in (0..n).step_by(3) {
            assert_eq!(fwd[k] % 3, 0);
            assert_eq!([fwd[k + 1], fwd[k + 2]], [fwd[k] + 1, fwd[k] + 2]);
        }
        for (k, &j) in fwd.iter().enumerate() {
            assert_eq!(inv[j], k);
        }
    }

    #[test]
    fn pattern_from_unsorted_pairs_with_duplicates() {
        let a = SparseMatrix::from_pattern(
            3,
            vec![
                (2, 0),
                (0, 0),
                (2, 0),
                (1, 2),
                (0, 2),
                (1, 2),
                (2, 2),
                (0, 0),
            ],
        );
        let stored: Vec<(usize, usize)> = a.entries().map(|(r, c, _)| (r, c)).collect();
        assert_eq!(stored, [(0, 0), (2, 0), (0, 2), (1, 2), (2, 2)]);
        assert_eq!(a.position(1, 2), Some(3));
        assert_eq!(a.column_start(1), 2);
        assert_eq!(a.column_start(2), 2);
        assert_eq!(a.position(1, 1), None);
    }

    #[test]
    fn singular_matrix_is_located() {
        // two uncoupled springs, the second without stiffness
        let mut a = SparseMatrix::from_pattern(3, vec![(0, 0), (0, 1), (1, 0), (1, 1), (2, 2)]);
        for (i, j, v) in [
            (0, 0, 2.0),
            (0, 1, -1.0),
            (1, 0, -1.0),
            (1, 1, 2.0),
            (2, 2, 0.0),
        ] {
            let p = a.position(i, j).unwrap();
            a.values_mut()[p] = v;
        }
        let (eq, pivot) = smallest_relative_pivot(&a).unwrap();
        assert_eq!(eq, 2);
        assert!(pivot < 1e-12);
        // the dense kernel of so small a system shows it as a non-finite
        // solution, which the callers then locate as above
        let mut lu = SparseLu::analyze(&a).unwrap();
        assert_eq!(lu.kernel(), LuKernel::Dense);
        lu.factor(&a).unwrap();
        let mut x = vec![1.0, 1.0, 1.0];
        assert_eq!(lu.solve_in_place(&mut x), Err(SolveError::NonFinite));
        // and a regular one is not flagged
        let p = a.position(2, 2).unwrap();
        a.values_mut()[p] = 5.0;
        let (_, pivot) = smallest_relative_pivot(&a).unwrap();
        assert!(pivot > 0.1);
    }
}
