//! Solver for nearly symmetric systems: the symmetric part factored, the
//! system solved by GMRES preconditioned with it, LU when that fails.
//!
//! The iteration matrix of the dynamic analysis and its constrained mass
//! system have a symmetric pattern and nearly symmetric values: mass,
//! stiffness and constraint blocks are symmetric, and what is not (the
//! gyroscopic and damping terms, the material-rotation tangent away from
//! equilibrium, follower loads) is small beside the mass scaled by
//! `1/(β h²)`. The pivoted LU of [`SparseLu`] works from George & Ng's
//! bound on the factors under any row pivoting, the Cholesky factor of
//! `AᵀA`, which for a symmetric pattern is that of `A²`: for the ERA
//! platform (7,788 unknowns) 1.18·10⁶ factor entries and 21 ms a
//! factorisation, against 1.8·10⁵ entries and 2 ms for the `LDLᵀ`
//! factorisation of a matrix of the pattern of `A` ordered by AMD.
//!
//! [`SymmetricFirst`] therefore factors the symmetric part
//! `S = (A + Aᵀ)/2` as `LDLᵀ` (faer's sparse Cholesky, AMD ordering; the
//! pattern permuted once, at the analysis, into the triangle faer's
//! kernel works on, so that a factorisation copies no matrix),
//! with dynamic regularisation: a pivot smaller than `ε max|aᵢᵢ|`
//! (ε = [`REGULARISATION`]) is replaced by `±ε max|aᵢᵢ|`, negative for the
//! rows whose diagonal entry is zero (the multipliers', whose pivots of
//! `[[M, Bᵀ], [B, 0]]` are `−B M⁻¹ Bᵀ`), of its own sign otherwise: a
//! redundant constraint or a massless unknown then gives a small pivot
//! rather than a breakdown (the regularised factorisation of saddle-point
//! systems, Vanderbei, "Symmetric quasidefinite matrices", SIAM J. Optim.
//! 5, 1995). AMD orders many multipliers before the unknowns their
//! constraint acts on (on the ERA triangle 420 of its 450, in the
//! iteration matrix): their pivot is then exactly zero, becomes `−ε
//! max|aᵢᵢ|`, and the factors are those of a penalty-regularised system,
//! which GMRES corrects. Ordering each multiplier after the last of its
//! unknowns (AMD's order otherwise kept) was measured to double the
//! factor (25,373 → 50,238 entries on the triangle) and to make the
//! deployment slower (7.7 → 12.8 s), with small pivots left all the
//! same. A matrix with a zero row (an unknown with neither stiffness nor
//! mass, a constraint acting on nothing) goes to the LU at once, whose
//! error it gets. Forcing every pivot to the sign of its diagonal entry made
//! the factors overflow on the ERA triangle after its locks (pivots of
//! the other sign replaced by `ε max|aᵢᵢ|` = 0.44). `A x = b` is then
//! solved by GMRES with right preconditioning by `M = LDLᵀ` (Saad,
//! *Iterative Methods for Sparse Linear Systems*, 2nd ed., algorithm 9.5),
//! which corrects both the skew part of `A` and the regularisation, to a
//! normwise backward error
//!
//! ```text
//! η = ‖b − A x‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞) ≤ BACKWARD_ERROR
//! ```
//!
//! checked on the true residual, that of a pivoted LU (Higham, *Accuracy
//! and Stability of Numerical Algorithms*, 2nd ed., §7.1). When GMRES does
//! not reach it in [`MAX_ITERATIONS`] (a strongly non-symmetric or
//! indefinite matrix, a singular one), the matrix is factored by the
//! pivoted LU of [`SparseLu`] and solved with it: the answer is that of
//! the LU, and so are the errors of a singular matrix. After such a
//! fall-back the next 8 matrices ([`SKIP`]) go to the LU, then the
//! symmetric part is tried again. That number was first doubled at each
//! further fall-back, up to 64: on the ERA platform the fall-backs come
//! in bursts (four in its first 0.03 s, whose first steps Newton cuts
//! back, four after its last lock), and 264 of its 2,360 matrices went to
//! the LU; with 8 each time, 16 fall-backs and 122 LU factorisations, the
//! same steps, 44.7 s to 2.5 s instead of 57.6 s and the last lock 31.9 s
//! into the run instead of 40.1 s (side by side, one thread each; 4 each
//! time: 24 fall-backs, 111 LU factorisations, slower). An LU
//! factorisation costing ten of the symmetric part, the LU factors of one
//! of these matrices serve the next ones as the preconditioner of GMRES
//! (the same iterations, to the same backward error) until a solve takes
//! more than [`REFRESH_AFTER`] iterations (the next matrix is then
//! factored) or does not finish in [`STALE_ITERATIONS`] (this one is).
//! Doing the same with the symmetric factors (a matrix factored only
//! when the last solve with the factors of an earlier one took more than
//! 6 iterations) was measured: on the ERA platform the factorisations of
//! the two systems fell from 4,375 to 1,305, but the GMRES iterations
//! doubled (16,642 → 34,906) and the deployment took as long (94.6 s
//! against 93.9 s); on the 320-element pendulum, whose factorisation
//! costs about one iteration, it was 5 to 12 % slower.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

use super::{
    internal, par_for, workspace, SolveError, SparseLu, SparseMatrix, DENSE_UP_TO_UNKNOWNS,
};

/// Normwise backward error that a solve must reach (module header),
/// unless [`SymmetricFirst::set_backward_error`] asks for another.
pub const BACKWARD_ERROR: f64 = 1e-14;

/// GMRES iterations (preconditioned solves) after which the pivoted LU
/// takes over.
pub const MAX_ITERATIONS: usize = 30;

/// Relative size of the regularised pivots, `ε` of the module header.
pub const REGULARISATION: f64 = 1e-9;

/// GMRES iterations a solve preconditioned by the LU factors of an
/// earlier matrix may take before the matrix is factored afresh.
pub const STALE_ITERATIONS: usize = 12;

/// A solve preconditioned by the LU factors of an earlier matrix that
/// took more GMRES iterations than this has the next matrix factored.
const REFRESH_AFTER: usize = 6;

/// Factorisations sent straight to the LU after a fall-back (module
/// header).
const SKIP: usize = 8;

/// Positions in `A`'s values of `a_ij` and `a_ji`, [`NONE`] if not stored.
const NONE: usize = usize::MAX;

/// What a [`SymmetricFirst`] did so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SolverCounts {
    /// `LDLᵀ` factorisations of the symmetric part.
    pub symmetric_factorisations: usize,
    /// Pivoted LU factorisations (fall-backs and skipped matrices).
    pub lu_factorisations: usize,
    /// Solves.
    pub solves: usize,
    /// GMRES iterations over all solves (one preconditioned solve each).
    pub iterations: usize,
    /// Solves that GMRES did not finish, handed to the LU.
    pub fallbacks: usize,
    /// Matrices with a zero column (singular), handed to the LU.
    pub singular: usize,
    /// Matrices sent to the LU and not factored: solved by GMRES
    /// preconditioned with the LU factors of an earlier one.
    pub reuses: usize,
}

impl std::ops::AddAssign for SolverCounts {
    fn add_assign(&mut self, o: Self) {
        self.symmetric_factorisations += o.symmetric_factorisations;
        self.lu_factorisations += o.lu_factorisations;
        self.solves += o.solves;
        self.iterations += o.iterations;
        self.fallbacks += o.fallbacks;
        self.singular += o.singular;
        self.reuses += o.reuses;
    }
}

/// Which factors hold the last factored matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Factored {
    None,
    Symmetric,
    Lu,
}

/// Sparse solver of nearly symmetric systems (module header): the
/// interface of [`SparseLu`] (analyse a pattern once, factor, solve).
pub struct SymmetricFirst {
    /// `A` as last factored: its values are those the GMRES residuals and
    /// the fall-back LU use.
    matrix: SparseMatrix,
    /// `S = (A + Aᵀ)/2` permuted by the AMD ordering, one triangle (that
    /// which faer's kernel works on, `side`), and the positions in `A`'s
    /// values of the two entries each of its entries is made of. Row `i`
    /// of `pattern` is row `forward[i]` of `A`; `permuted` holds a vector
    /// in that order.
    pattern: SymbolicSparseColMat<usize>,
    values: Vec<f64>,
    side: Side,
    forward: Vec<usize>,
    permuted: Vec<f64>,
    sources: Vec<[usize; 2]>,
    /// Position in `A`'s values of each diagonal entry (in the order of
    /// `pattern`).
    diagonal: Vec<usize>,
    signs: Vec<i8>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    par: Par,
    /// `‖A‖∞` of the last factored matrix.
    a_norm: f64,
    /// The backward error GMRES stops at ([`BACKWARD_ERROR`] unless set).
    backward_error: f64,
    lu: Option<SparseLu>,
    /// Small systems go to the dense LU (module header).
    lu_only: bool,
    factored: Factored,
    /// The LU factors are those of an earlier matrix than
    /// [`Self::matrix`]: a preconditioner only.
    stale: bool,
    /// The next matrix is factored afresh.
    refresh: bool,
    /// Factorisations still to send straight to the LU.
    skip: usize,
    krylov: Krylov,
    counts: SolverCounts,
}

/// GMRES workspace: the Arnoldi basis `V` (`m + 1` vectors), the
/// preconditioned directions `Z = M⁻¹V` (`m`), the Hessenberg matrix
/// reduced by Givens rotations, the right-hand side `b` and a spare vector.
struct Krylov {
    v: Vec<f64>,
    z: Vec<f64>,
    h: Vec<f64>,
    cs: Vec<f64>,
    sn: Vec<f64>,
    g: Vec<f64>,
    y: Vec<f64>,
    b: Vec<f64>,
    r: Vec<f64>,
}

impl std::fmt::Debug for SymmetricFirst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SymmetricFirst")
            .field("dim", &self.matrix.dim())
            .field("factor_entries", &self.l_values.len())
            .field("counts", &self.counts)
            .finish_non_exhaustive()
    }
}

impl SymmetricFirst {
    /// Symbolic analysis of the pattern of `a`: the pattern of `A + Aᵀ`,
    /// its AMD ordering and the structure of its `LDLᵀ` factor. The
    /// pivoted LU is analysed only when first needed.
    pub fn analyze(a: &SparseMatrix) -> Result<Self, SolveError> {
        Self::analyze_with(a, SupernodalThreshold::AUTO)
    }

    /// [`SymmetricFirst::analyze`] with faer's choice between its
    /// simplicial and supernodal factorisations made by `supernodal`.
    fn analyze_with(a: &SparseMatrix, supernodal: SupernodalThreshold) -> Result<Self, SolveError> {
        let n = a.dim();
        let (ptr, rows) = (a.symbolic.col_ptr(), a.symbolic.row_idx());
        // the lower triangle of the pattern of A + Aᵀ, column by column:
        // column j holds the rows i ≥ j of column j of A and the columns
        // i ≥ j of row j of A (column i of A holding row j)
        let mut entries: Vec<Vec<(usize, [usize; 2])>> = vec![Vec::new(); n];
        for j in 0..n {
            for k in ptr[j]..ptr[j + 1] {
                let i = rows[k];
                // a_ij at k: in column min(i, j), row max(i, j)
                let (r, c) = if i >= j { (i, j) } else { (j, i) };
                let column = &mut entries[c];
                if i == j {
                    column.push((r, [k, k]));
                    continue;
                }
                let side = usize::from(i < j);
                match column.iter_mut().find(|(row, _)| *row == r) {
                    Some((_, s)) => s[side] = k,
                    None => {
                        let mut s = [NONE; 2];
                        s[side] = k;
                        column.push((r, s));
                    }
                }
            }
        }
        let mut l_ptr = Vec::with_capacity(n + 1);
        let mut l_rows = Vec::new();
        let mut sources = Vec::new();
        let mut diagonal = vec![NONE; n];
        l_ptr.push(0);
        for (j, column) in entries.iter_mut().enumerate() {
            column.sort_unstable_by_key(|&(r, _)| r);
            for &(r, s) in column.iter() {
                if r == j {
                    diagonal[j] = s[0];
                }
                l_rows.push(r);
                sources.push(s);
            }
            l_ptr.push(l_rows.len());
        }
        let lower = SymbolicSparseColMat::new_checked(n, n, l_ptr, None, l_rows);
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: supernodal,
            ..Default::default()
        };
        let ordered = factorize_symbolic_cholesky(
            lower.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            params,
        )
        .map_err(|e| internal(&e))?;
        // the pattern permuted by the AMD ordering once, in the triangle
        // faer's kernel works on (upper for the simplicial, lower for the
        // supernodal), so that a factorisation copies no matrix
        let (forward, inverse): (Vec<usize>, Vec<usize>) = match ordered.perm() {
            Some(p) => (p.arrays().0.to_vec(), p.arrays().1.to_vec()),
            None => ((0..n).collect(), (0..n).collect()),
        };
        let side = match ordered.raw() {
            SymbolicCholeskyRaw::Simplicial(_) => Side::Upper,
            SymbolicCholeskyRaw::Supernodal(_) => Side::Lower,
        };
        // the permuted pattern in `side`'s triangle, with the sources of
        // each entry in A
        let permuted = |side: Side| {
            let mut columns: Vec<Vec<(usize, [usize; 2])>> = vec![Vec::new(); n];
            for (j, column) in entries.iter().enumerate() {
                for &(i, source) in column {
                    let (a, b) = (inverse[i], inverse[j]);
                    let (row, col) = match side {
                        Side::Lower => (a.max(b), a.min(b)),
                        Side::Upper => (a.min(b), a.max(b)),
                    };
                    columns[col].push((row, source));
                }
            }
            let mut ptr = Vec::with_capacity(n + 1);
            let mut rows = Vec::with_capacity(sources.len());
            let mut from = Vec::with_capacity(sources.len());
            ptr.push(0);
            for column in &mut columns {
                column.sort_unstable_by_key(|&(r, _)| r);
                for &(r, source) in column.iter() {
                    rows.push(r);
                    from.push(source);
                }
                ptr.push(rows.len());
            }
            (
                SymbolicSparseColMat::new_checked(n, n, ptr, None, rows),
                from,
            )
        };
        let diagonal: Vec<usize> = forward.iter().map(|&old| diagonal[old]).collect();
        let (pattern, sources) = permuted(side);
        // faer's symbolic analysis without an ordering reads the upper
        // triangle whatever the side it is given
        let upper = match side {
            Side::Upper => None,
            Side::Lower => Some(permuted(Side::Upper).0),
        };
        let symbolic = factorize_symbolic_cholesky(
            upper.as_ref().unwrap_or(&pattern).as_ref(),
            Side::Upper,
            SymmetricOrdering::Identity,
            params,
        )
        .map_err(|e| internal(&e))?;
        let par = par_for(n);
        let mem = workspace(
            StackReq::any_of(&[
                symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(1, par),
            ]),
            "symmetric factorisation",
        )?;
        let m = MAX_ITERATIONS;
        Ok(Self {
            matrix: a.clone(),
            values: vec![0.0; sources.len()],
            pattern,
            side,
            forward,
            permuted: vec![0.0; n],
            sources,
            diagonal,
            signs: vec![1; n],
            l_values: vec![0.0; symbolic.len_val()],
            symbolic,
            mem,
            par,
            a_norm: 0.0,
            backward_error: BACKWARD_ERROR,
            lu: None,
            lu_only: n <= DENSE_UP_TO_UNKNOWNS,
            factored: Factored::None,
            stale: false,
            refresh: false,
            skip: 0,
            krylov: Krylov {
                v: vec![0.0; n * (m + 1)],
                z: vec![0.0; n * m],
                h: vec![0.0; (m + 1) * m],
                cs: vec![0.0; m],
                sn: vec![0.0; m],
                g: vec![0.0; m + 1],
                y: vec![0.0; m],
                b: vec![0.0; n],
                r: vec![0.0; n],
            },
            counts: SolverCounts::default(),
        })
    }

    /// Sets the normwise backward error `η` at which GMRES stops (from
    /// [`BACKWARD_ERROR`] up to 10⁻⁶; [`BACKWARD_ERROR`] until set). A
    /// Newton correction needs no more than to leave a linearised residual
    /// well below Newton's own tolerance (docs/theory.md §8, "Inexact
    /// corrections"); a projection whose constraint rows must hold to
    /// round-off keeps the default. Solves by the LU are not affected.
    pub fn set_backward_error(&mut self, eta: f64) {
        self.backward_error = eta.clamp(BACKWARD_ERROR, 1e-6);
    }

    /// The backward error GMRES stops at.
    pub fn backward_error(&self) -> f64 {
        self.backward_error
    }

    /// What the solver did so far.
    pub fn counts(&self) -> SolverCounts {
        self.counts
    }

    /// Entries of the `LDLᵀ` factor (its memory in `f64`s).
    pub fn factor_entries(&self) -> usize {
        self.l_values.len()
    }

    /// Numeric factorisation of `a`, which must have the analysed
    /// pattern: of its symmetric part, or by the pivoted LU after a recent
    /// fall-back (module header). A singular matrix may show only at the
    /// solve.
    pub fn factor(&mut self, a: &SparseMatrix) -> Result<(), SolveError> {
        let held = std::mem::replace(&mut self.factored, Factored::None);
        self.stale = false;
        if a.values.iter().any(|v| !v.is_finite()) {
            return Err(SolveError::NonFinite);
        }
        self.matrix.values.copy_from_slice(&a.values);
        if self.lu_only {
            return self.factor_lu();
        }
        // ‖A‖∞ for the backward error of GMRES; a zero row: singular, and
        // its answer or error is the LU's (the regularised factors would
        // give one)
        let ones = &mut self.krylov.b;
        ones.fill(1.0);
        self.matrix.mul_abs_vec(ones, &mut self.krylov.r);
        self.a_norm = inf_norm(&self.krylov.r);
        if self.krylov.r.contains(&0.0) {
            self.counts.singular += 1;
            return self.factor_lu();
        }
        if self.skip > 0 {
            // a matrix sent to the LU after a fall-back: the LU factors of
            // an earlier one precondition GMRES, unless the last solve
            // with them found them too far from their matrix
            self.skip -= 1;
            if held == Factored::Lu && !self.refresh {
                self.factored = Factored::Lu;
                self.stale = true;
                self.counts.reuses += 1;
                return Ok(());
            }
            return self.factor_lu();
        }
        // s_ij = (a_ij + a_ji)/2 (a diagonal entry's two sources are itself)
        let values = &self.matrix.values;
        let at = |k: usize| if k == NONE { 0.0 } else { values[k] };
        for (v, &[lower, upper]) in self.values.iter_mut().zip(&self.sources) {
            *v = 0.5 * (at(lower) + at(upper));
        }
        // the multipliers' pivots negative, the others of their own sign
        let mut largest = 0.0f64;
        for (&k, sign) in self.diagonal.iter().zip(self.signs.iter_mut()) {
            let d = at(k);
            largest = largest.max(d.abs());
            *sign = if d == 0.0 { -1 } else { 0 };
        }
        let eps = REGULARISATION * largest.max(f64::MIN_POSITIVE);
        let regularisation = LdltRegularization {
            dynamic_regularization_signs: Some(&self.signs),
            dynamic_regularization_delta: eps,
            dynamic_regularization_epsilon: eps,
        };
        let factored = self
            .symbolic
            .factorize_numeric_ldlt(
                &mut self.l_values,
                SparseColMatRef::new(self.pattern.as_ref(), &self.values),
                self.side,
                regularisation,
                self.par,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .is_ok();
        self.counts.symmetric_factorisations += 1;
        if !factored {
            return self.factor_lu();
        }
        self.factored = Factored::Symmetric;
        Ok(())
    }

    /// Solves `A x = b` in place (`rhs` holds `b` on entry, `x` on exit):
    /// GMRES preconditioned by the symmetric factors, or the LU.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), SolveError> {
        assert!(
            self.factored != Factored::None,
            "solve before a successful factorisation"
        );
        self.counts.solves += 1;
        if self.stale {
            // GMRES preconditioned by the LU factors of an earlier
            // matrix; too slow, and the matrix is factored afresh
            self.krylov.b.copy_from_slice(rhs);
            let before = self.counts.iterations;
            if self.gmres(rhs, STALE_ITERATIONS) {
                self.refresh = self.counts.iterations - before > REFRESH_AFTER;
                return Ok(());
            }
            rhs.copy_from_slice(&self.krylov.b);
            self.factor_lu()?;
        }
        if self.factored == Factored::Symmetric {
            self.krylov.b.copy_from_slice(rhs);
            if self.gmres(rhs, MAX_ITERATIONS) {
                return Ok(());
            }
            self.counts.fallbacks += 1;
            rhs.copy_from_slice(&self.krylov.b);
            self.factor_lu()?;
            let lu = self.lu.as_mut().expect("factored by the LU");
            lu.solve_in_place(rhs)?;
            // the LU solved what GMRES did not: send the next matrices to
            // it (a matrix that neither solves is no reason to)
            self.skip = SKIP;
            return Ok(());
        }
        let lu = self.lu.as_mut().expect("factored by the LU");
        lu.solve_in_place(rhs)
    }

    fn factor_lu(&mut self) -> Result<(), SolveError> {
        if self.lu.is_none() {
            self.lu = Some(SparseLu::analyze(&self.matrix)?);
        }
        let lu = self.lu.as_mut().expect("analysed above");
        self.counts.lu_factorisations += 1;
        self.stale = false;
        self.refresh = false;
        lu.factor(&self.matrix)?;
        self.factored = Factored::Lu;
        Ok(())
    }

    /// Right-preconditioned GMRES from `x₀ = M⁻¹ b`, restarted every
    /// [`MAX_ITERATIONS`] preconditioned solves and stopped after that many
    /// in all; `x` holds `b` on entry and the solution on a successful exit
    /// (true residual within the backward error set, [`BACKWARD_ERROR`] by default).
    fn gmres(&mut self, x: &mut [f64], budget: usize) -> bool {
        let n = x.len();
        let m = MAX_ITERATIONS;
        let Self {
            matrix,
            symbolic,
            l_values,
            mem,
            par,
            a_norm,
            backward_error,
            krylov: k,
            counts,
            forward,
            permuted,
            lu,
            factored,
            ..
        } = self;
        let factors = LdltRef::new(symbolic, l_values);
        // a failed LU solve (not finite) ends the iterations
        let mut precondition = |x: &mut [f64]| -> bool {
            counts.iterations += 1;
            if *factored == Factored::Lu {
                let lu = lu.as_mut().expect("factored by the LU");
                return lu.solve_in_place(x).is_ok();
            }
            for (p, &i) in permuted.iter_mut().zip(forward.iter()) {
                *p = x[i];
            }
            factors.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(permuted, n, 1),
                *par,
                MemStack::new(mem),
            );
            for (p, &i) in permuted.iter().zip(forward.iter()) {
                x[i] = *p;
            }
            true
        };
        let b_norm = inf_norm(&k.b);
        if !precondition(x) {
            return false;
        }
        let mut spent = 1;
        loop {
            // the true residual r = b − A x and its backward error
            matrix.mul_vec(x, &mut k.r);
            for (r, b) in k.r.iter_mut().zip(&k.b) {
                *r = b - *r;
            }
            let x_norm = inf_norm(x);
            if !x_norm.is_finite() {
                return false;
            }
            let scale = *a_norm * x_norm + b_norm;
            if scale == 0.0 || inf_norm(&k.r) <= *backward_error * scale {
                return true;
            }
            if spent >= budget {
                return false;
            }
            // Arnoldi on A M⁻¹ from v₁ = r/‖r‖₂ (modified Gram–Schmidt),
            // min ‖β e₁ − H y‖₂ by Givens rotations (Saad, algorithm 6.9)
            let beta = two_norm(&k.r);
            for (v, r) in k.v[..n].iter_mut().zip(&k.r) {
                *v = r / beta;
            }
            k.g.fill(0.0);
            k.g[0] = beta;
            // ‖r‖∞ ≤ ‖r‖₂: aim at half the tolerance
            let target = 0.5 * *backward_error * scale;
            let mut j = 0;
            while spent + j < budget {
                let (basis, rest) = k.v.split_at_mut((j + 1) * n);
                let z = &mut k.z[j * n..(j + 1) * n];
                z.copy_from_slice(&basis[j * n..]);
                if !precondition(z) {
                    return false;
                }
                let w = &mut rest[..n];
                matrix.mul_vec(z, w);
                for i in 0..=j {
                    let vi = &basis[i * n..(i + 1) * n];
                    let hij = dot(w, vi);
                    k.h[i * m + j] = hij;
                    for (w, v) in w.iter_mut().zip(vi) {
                        *w -= hij * v;
                    }
                }
                let h_next = two_norm(w);
                if h_next > 0.0 {
                    for w in w.iter_mut() {
                        *w /= h_next;
                    }
                }
                // the earlier rotations on column j, then the one that
                // zeroes h_{j+1,j}
                for i in 0..j {
                    let (a, b) = (k.h[i * m + j], k.h[(i + 1) * m + j]);
                    k.h[i * m + j] = k.cs[i] * a + k.sn[i] * b;
                    k.h[(i + 1) * m + j] = -k.sn[i] * a + k.cs[i] * b;
                }
                let a = k.h[j * m + j];
                let rho = a.hypot(h_next);
                let (c, s) = if rho > 0.0 {
                    (a / rho, h_next / rho)
                } else {
                    (1.0, 0.0)
                };
                k.cs[j] = c;
                k.sn[j] = s;
                k.h[j * m + j] = rho;
                k.g[j + 1] = -s * k.g[j];
                k.g[j] *= c;
                j += 1;
                if k.g[j].abs() <= target || h_next == 0.0 {
                    break;
                }
            }
            spent += j;
            // y = H⁻¹ g (upper triangular), x += Z y
            for i in (0..j).rev() {
                let mut s = k.g[i];
                for l in i + 1..j {
                    s -= k.h[i * m + l] * k.y[l];
                }
                k.y[i] = if k.h[i * m + i] != 0.0 {
                    s / k.h[i * m + i]
                } else {
                    0.0
                };
            }
            for i in 0..j {
                let yi = k.y[i];
                for (x, z) in x.iter_mut().zip(&k.z[i * n..(i + 1) * n]) {
                    *x += yi * z;
                }
            }
        }
    }
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

fn two_norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dynamic-like saddle-point matrix of `nodes` unknowns on a chain
    /// and `nodes/4` constraint rows: `[[M/(βh²) + K + skew·G, Bᵀ], [B, 0]]`
    /// with `M` diagonal, `K` the 1-D Laplacian, `G` skew-symmetric.
    fn saddle(nodes: usize, skew: f64) -> SparseMatrix {
        let constraints = nodes / 4;
        let n = nodes + constraints;
        let mut entries = Vec::new();
        for i in 0..nodes {
            entries.push((i, i, 1e4 + 2.0));
            if i + 1 < nodes {
                entries.push((i, i + 1, -1.0 + skew));
                entries.push((i + 1, i, -1.0 - skew));
            }
        }
        for c in 0..constraints {
            // the constraint ties unknowns 4c and 4c + 2
            let row = nodes + c;
            for (col, b) in [(4 * c, 1.0), (4 * c + 2, -0.5)] {
                entries.push((row, col, b));
                entries.push((col, row, b));
            }
        }
        let mut a =
            SparseMatrix::from_pattern(n, entries.iter().map(|&(i, j, _)| (i, j)).collect());
        for &(i, j, v) in &entries {
            let p = a.position(i, j).unwrap();
            a.values_mut()[p] += v;
        }
        a
    }

    /// Applies `f(row, col, value)` to every stored entry of `a`.
    fn edit(a: &mut SparseMatrix, mut f: impl FnMut(usize, usize, &mut f64)) {
        let rows = a.row_indices().to_vec();
        for j in 0..a.dim() {
            let (start, end) = (a.column_start(j), a.column_start(j + 1));
            for (k, &i) in rows.iter().enumerate().take(end).skip(start) {
                f(i, j, &mut a.values_mut()[k]);
            }
        }
    }

    fn rhs(n: usize) -> Vec<f64> {
        (0..n).map(|i| ((7 * i + 3) % 13) as f64 - 6.0).collect()
    }

    fn lu_solution(a: &SparseMatrix, b: &[f64]) -> Vec<f64> {
        let mut lu = SparseLu::analyze(a).unwrap();
        lu.factor(a).unwrap();
        let mut x = b.to_vec();
        lu.solve_in_place(&mut x).unwrap();
        x
    }

    /// Factors `a` and solves `a x = b` with `solver`, and checks that
    /// `x` meets [`BACKWARD_ERROR`].
    fn solve_to_backward_error(solver: &mut SymmetricFirst, a: &SparseMatrix, b: &[f64]) {
        solver.factor(a).unwrap();
        let mut x = b.to_vec();
        solver.solve_in_place(&mut x).unwrap();
        let eta = backward_error(a, &x, b);
        assert!(eta <= BACKWARD_ERROR, "{eta:e}");
    }

    /// `‖b − A x‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞)`, as the module header.
    fn backward_error(a: &SparseMatrix, x: &[f64], b: &[f64]) -> f64 {
        let mut r = vec![0.0; b.len()];
        a.mul_vec(x, &mut r);
        let mut abs = vec![0.0; b.len()];
        a.mul_abs_vec(&vec![1.0; b.len()], &mut abs);
        let residual = r
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (r, b)| m.max((b - r).abs()));
        residual / (inf_norm(&abs) * inf_norm(x) + inf_norm(b))
    }

    fn relative_difference(x: &[f64], y: &[f64]) -> f64 {
        let diff = x
            .iter()
            .zip(y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        diff / inf_norm(y)
    }

    /// A nearly symmetric saddle-point system (the skew part 1e-3 of the
    /// diagonal's off-diagonal entries) is solved through the symmetric
    /// factors, without the LU, to the LU's answer within 1e-10 relative
    /// (both backward stable to 1e-14 on a well-conditioned matrix).
    #[test]
    fn nearly_symmetric_saddle_systems_are_solved_without_the_lu() {
        for skew in [0.0, 1e-3] {
            let a = saddle(400, skew);
            let b = rhs(a.dim());
            let mut solver = SymmetricFirst::analyze(&a).unwrap();
            for _ in 0..2 {
                solver.factor(&a).unwrap();
                let mut x = b.clone();
                solver.solve_in_place(&mut x).unwrap();
                let d = relative_difference(&x, &lu_solution(&a, &b));
                assert!(d < 1e-10, "skew {skew}: {d:e}");
            }
            let counts = solver.counts();
            assert_eq!(counts.symmetric_factorisations, 2, "{counts:?}");
            assert_eq!(counts.lu_factorisations, 0, "{counts:?}");
            assert_eq!(counts.fallbacks, 0, "{counts:?}");
        }
    }

    /// A looser backward error set for Newton's corrections is met, by
    /// fewer GMRES iterations than the default, and no looser than asked:
    /// on the skewed saddle system the solve stops between the default
    /// and the set value, and the default is restored to 1e-14.
    #[test]
    fn a_set_backward_error_is_met_with_fewer_iterations() {
        let a = saddle(400, 0.2);
        let b = rhs(a.dim());
        let mut iterations = Vec::new();
        for eta in [BACKWARD_ERROR, 1e-10] {
            let mut solver = SymmetricFirst::analyze(&a).unwrap();
            solver.set_backward_error(eta);
            assert_eq!(solver.backward_error(), eta);
            solver.factor(&a).unwrap();
            let mut x = b.clone();
            solver.solve_in_place(&mut x).unwrap();
            let reached = backward_error(&a, &x, &b);
            assert!(reached <= eta, "asked {eta:e}, reached {reached:e}");
            let counts = solver.counts();
            assert_eq!(counts.lu_factorisations, 0, "{counts:?}");
            iterations.push(counts.iterations);
        }
        assert!(iterations[1] < iterations[0], "{iterations:?}");
        let mut solver = SymmetricFirst::analyze(&a).unwrap();
        solver.set_backward_error(0.0);
        assert_eq!(solver.backward_error(), BACKWARD_ERROR);
    }

    /// faer's simplicial and supernodal factorisations, whichever its
    /// flop-ratio threshold picks for a model, give the LU's answer
    /// within 1e-10 relative through the same permuted pattern.
    #[test]
    fn simplicial_and_supernodal_factors_give_the_same_answer() {
        let a = saddle(400, 1e-3);
        let b = rhs(a.dim());
        let expected = lu_solution(&a, &b);
        for threshold in [
            SupernodalThreshold::FORCE_SIMPLICIAL,
            SupernodalThreshold::FORCE_SUPERNODAL,
        ] {
            let mut solver = SymmetricFirst::analyze_with(&a, threshold).unwrap();
            solver.factor(&a).unwrap();
            let mut x = b.clone();
            solver.solve_in_place(&mut x).unwrap();
            let d = relative_difference(&x, &expected);
            assert!(d < 1e-10, "{threshold:?}: {d:e}");
            let counts = solver.counts();
            assert_eq!(counts.lu_factorisations, 0, "{threshold:?}: {counts:?}");
        }
    }

    /// A strongly non-symmetric matrix (skew part 10 times the diagonal,
    /// whose symmetric part is a poor preconditioner) goes to the LU: the
    /// answer is the LU's, and the next matrices go straight to it, its
    /// factors of an earlier matrix preconditioning GMRES while they are
    /// close enough.
    #[test]
    fn strongly_non_symmetric_systems_fall_back_to_the_lu() {
        let mut a = saddle(400, 0.0);
        // a convection-like skew part of 1e5 per entry
        edit(&mut a, |i, j, v| {
            if i < 400 && j < 400 && i != j {
                *v += if i < j { 1e5 } else { -1e5 };
            }
        });
        let b = rhs(a.dim());
        let expected = lu_solution(&a, &b);
        let mut solver = SymmetricFirst::analyze(&a).unwrap();
        solver.factor(&a).unwrap();
        let mut x = b.clone();
        solver.solve_in_place(&mut x).unwrap();
        let d = relative_difference(&x, &expected);
        assert!(d < 1e-12, "{d:e} {:?}", solver.counts());
        let counts = solver.counts();
        assert_eq!(
            (counts.fallbacks, counts.lu_factorisations),
            (1, 1),
            "{counts:?}"
        );
        // the next matrix, 1 % off, goes to the LU: GMRES preconditioned
        // by the LU factors of the first
        let mut next = a.clone();
        edit(&mut next, |i, j, v| {
            if i == j {
                *v *= 1.01;
            }
        });
        solve_to_backward_error(&mut solver, &next, &b);
        let counts = solver.counts();
        assert_eq!(counts.symmetric_factorisations, 1, "{counts:?}");
        assert_eq!(counts.lu_factorisations, 1, "{counts:?}");
        assert_eq!(counts.reuses, 1, "{counts:?}");
        // one far from it (the skew part reversed) is factored afresh
        edit(&mut next, |i, j, v| {
            if i < 400 && j < 400 && i != j {
                *v = -*v;
            }
        });
        solve_to_backward_error(&mut solver, &next, &b);
        let counts = solver.counts();
        assert_eq!(counts.lu_factorisations, 2, "{counts:?}");
        assert_eq!(counts.reuses, 2, "{counts:?}");
    }

    /// A singular matrix (the row and column of a constraint zeroed) is
    /// handed to the LU at its factorisation and gives the LU's error, not
    /// the answer of the regularised factors.
    #[test]
    fn singular_systems_give_the_lu_error() {
        let mut a = saddle(40, 0.0);
        edit(&mut a, |i, j, v| {
            if i == 41 || j == 41 {
                *v = 0.0;
            }
        });
        let b = rhs(a.dim());
        let mut lu = SparseLu::analyze(&a).unwrap();
        let expected = lu
            .factor(&a)
            .and_then(|()| lu.solve_in_place(&mut b.clone()));
        assert!(expected.is_err(), "{expected:?}");
        let mut solver = SymmetricFirst::analyze(&a).unwrap();
        let result = solver
            .factor(&a)
            .and_then(|()| solver.solve_in_place(&mut b.clone()));
        assert_eq!(result, expected);
        let counts = solver.counts();
        assert_eq!(
            (counts.singular, counts.lu_factorisations),
            (1, 1),
            "{counts:?}"
        );
    }
}
