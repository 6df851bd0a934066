//! Sparse linear algebra: the compressed-column system matrix and a sparse
//! direct solver behind a three-phase interface (analyse the pattern once,
//! factor each Newton iteration, solve).
//!
//! The solver is faer's sparse LU with partial (row) pivoting and a COLAMD
//! fill-reducing column ordering. LU rather than Cholesky because the
//! tangent of a material-rotation formulation is not symmetric away from
//! equilibrium, follower loads are not symmetric either, and the saddle-point
//! systems of Lagrange-multiplier constraints are indefinite. The symbolic
//! analysis (ordering, elimination tree, supernodes) is computed once per
//! sparsity pattern and reused; the numeric factor and its workspace are
//! kept between factorisations, so a Newton iteration allocates little.
//! Only this file knows faer's API.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::{LuError, SupernodalThreshold};
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
}

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
        }
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
        for (j, &xj) in x.iter().enumerate() {
            for k in ptr[j]..ptr[j + 1] {
                y[rows[k]] += self.values[k] * xj;
            }
        }
    }

    /// Every stored entry as `(row, col, value)`.
    pub fn entries(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        let ptr = self.symbolic.col_ptr();
        let rows = self.symbolic.row_idx();
        (0..self.dim())
            .flat_map(move |j| (ptr[j]..ptr[j + 1]).map(move |k| (rows[k], j, self.values[k])))
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

/// Sparse LU factorisation with a reusable symbolic analysis.
pub struct SparseLu {
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_mem: MemBuffer,
    solve_mem: MemBuffer,
    par: Par,
    factored: bool,
}

impl std::fmt::Debug for SparseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseLu")
            .field("dim", &self.symbolic.nrows())
            .field("factored", &self.factored)
            .finish()
    }
}

fn par_from_threads() -> Par {
    let n = rayon::current_num_threads();
    if n > 1 {
        Par::rayon(n)
    } else {
        Par::Seq
    }
}

impl SparseLu {
    /// Symbolic analysis of the pattern of `a` (fill-reducing ordering,
    /// elimination tree, supernodes). Valid for every matrix with the same
    /// pattern.
    pub fn analyze(a: &SparseMatrix) -> Result<Self, SolveError> {
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::AUTO,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_lu(a.symbolic.as_ref(), params)
            .map_err(|e| SolveError::Internal(format!("{e:?}")))?;
        let par = par_from_threads();
        let lu_params: Spec<PartialPivLuParams, f64> = Default::default();
        let factor_mem =
            MemBuffer::try_new(symbolic.factorize_numeric_lu_scratch::<f64>(par, lu_params))
                .map_err(|_| {
                    SolveError::Internal("out of memory for the factorisation workspace".into())
                })?;
        let solve_mem = MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(1, par))
            .map_err(|_| SolveError::Internal("out of memory for the solve workspace".into()))?;
        Ok(Self {
            symbolic,
            numeric: NumericLu::new(),
            factor_mem,
            solve_mem,
            par,
            factored: false,
        })
    }

    /// Numeric factorisation of `a`, which must have the analysed pattern.
    pub fn factor(&mut self, a: &SparseMatrix) -> Result<(), SolveError> {
        self.factored = false;
        if a.values.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        let stack = MemStack::new(&mut self.factor_mem);
        match self.symbolic.factorize_numeric_lu(
            &mut self.numeric,
            a.as_faer(),
            self.par,
            stack,
            Default::default(),
        ) {
            Ok(_) => {}
            Err(LuError::SymbolicSingular { index }) => {
                return Err(SolveError::Singular {
                    equation: self.symbolic.col_perm().arrays().0[index],
                    pivot: 0.0,
                })
            }
            Err(e) => return Err(SolveError::Internal(format!("{e:?}"))),
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
        // `numeric` comes from `factorize_numeric_lu` of this `symbolic`
        let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let stack = MemStack::new(&mut self.solve_mem);
        let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
        lu.solve_in_place_with_conj(Conj::No, x, self.par, stack);
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        Ok(())
    }
}

/// Finds the equation with the smallest pivot, relative to the largest
/// entry of its column, in an LU factorisation of `a`. Used to say *where*
/// a system is singular after a solve has failed: it runs a slower
/// simplicial factorisation whose factors can be inspected, and is never
/// called on the Newton hot path.
pub fn smallest_relative_pivot(a: &SparseMatrix) -> Result<(usize, f64), SolveError> {
    use faer::sparse::linalg::lu::simplicial;
    let internal = |e: &dyn std::fmt::Debug| SolveError::Internal(format!("{e:?}"));
    let symbolic =
        factorize_symbolic_lu(a.symbolic.as_ref(), Default::default()).map_err(|e| internal(&e))?;
    let n = a.dim();
    let mut lu = simplicial::SimplicialLu::<usize, f64>::new();
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
        let mut lu = SparseLu::analyze(&a).unwrap();
        for scale in [1.0, 3.5] {
            // new values, same pattern: the symbolic analysis is reused
            let (a, _) = saddle(scale);
            lu.factor(&a).unwrap();
            let mut x = b.clone();
            lu.solve_in_place(&mut x).unwrap();
            let mut ax = vec![0.0; 6];
            a.mul_vec(&x, &mut ax);
            let err = ax
                .iter()
                .zip(&b)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-13, "residual {err:e}");
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
        // and a regular one is not flagged
        let p = a.position(2, 2).unwrap();
        a.values_mut()[p] = 5.0;
        let (_, pivot) = smallest_relative_pivot(&a).unwrap();
        assert!(pivot > 0.1);
    }
}
