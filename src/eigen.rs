//! Eigen-solvers of modal analysis: undamped natural frequencies and mode
//! shapes of a constrained mechanism linearised about a configuration
//! (docs/theory.md §14).
//!
//! The problem, in the equation numbering of the analysis, is the
//! generalized eigenproblem of the constrained pencil
//!
//! ```text
//! K x + Bᵀ μ = ω² M x,        B x = 0
//! ```
//!
//! with `K` the tangent stiffness, `M` the mass (symmetric, positive
//! semi-definite: massless nodes and beams without rotational inertia make
//! it singular), `B` the constraint gradients of the joints and `μ` the
//! multipliers of the mode. It is handed over as the assembler delivers
//! it ([`Pencil`]): the tangent in saddle-point form
//! `A = [[K, Bᵀ], [B, 0]]` with the multiplier equations interleaved in the
//! numbering (their rows carry `−k B`, the tangent block `K` the penalty
//! `p BᵀB` and the constraint Hessian terms, paper eq. 18), the mass on
//! the same numbering, and which equations are multipliers. Supports have
//! no equation. The scaling `k` changes only the multipliers, and `p BᵀB`
//! vanishes on `B x = 0`: neither changes a frequency.
//!
//! `A` is the tangent of a nonlinear residual, not symmetric away from
//! equilibrium (material rotations, follower loads); the solvers use its
//! symmetric part `(A + Aᵀ)/2` and that of `M`, the linearisation of the
//! conservative part of the system. Entries of the mass in multiplier rows
//! and columns are ignored.
//!
//! Two solvers:
//! - [`solve_dense`], for small models: null-space basis `N` of `B` from a
//!   column-pivoted QR of `Bᵀ` (faer), `K_r = NᵀKN`, `M_r = NᵀMN`; a shift
//!   `σ` below the spectrum makes `K_r − σM_r` positive definite, and the
//!   symmetric eigenproblem of `L⁻¹M_rL⁻ᵀ` (faer's self-adjoint
//!   eigen-decomposition) gives `1/(ω² − σ)`; massless directions come out
//!   at `1/(ω² − σ) = 0` (infinite frequencies), dropped and counted.
//! - [`solve_lanczos`], for the lowest modes of large models: shift-invert
//!   Lanczos in the `M` inner product on the operator
//!   `S = (A − σM)⁻¹M` (the sparse LU of the saddle-point matrix, one
//!   symbolic analysis, one factorisation), with full reorthogonalisation
//!   and thick restarts, started in the range of `S` and purified at the
//!   end so that massless directions never enter a mode.
//!
//! Both end the same way: a Rayleigh–Ritz step on the computed modes
//! (eigenvalues from `xᵀKx`, modes `M`-orthonormal to round-off), the
//! multipliers of each mode, and its residual `‖Kx + Bᵀμ − ω²Mx‖`
//! against `‖Kx‖`, checked above the round-off floor of the mode.
//! Eigenvalues within round-off of zero (rigid-body and mechanism modes)
//! are reported as exactly zero and counted; negative ones (a configuration
//! that is not stable) are reported as they are.
//!
//! ```
//! use unfold::eigen::{solve, EigenSettings, Pencil};
//! use unfold::linalg::SparseMatrix;
//!
//! // two masses m = 2 on springs k = 8: ground–x₀–x₁, and a multiplier
//! // (equation 2) holding x₁ = 0: one mass on two springs, ω² = 2k/m
//! let entries = [(0, 0, 16.0), (0, 1, -8.0), (1, 0, -8.0), (1, 1, 8.0), (2, 1, 1.0), (1, 2, 1.0)];
//! let mut k = SparseMatrix::from_pattern(3, entries.iter().map(|e| (e.0, e.1)).collect());
//! for (i, j, v) in entries {
//!     let p = k.position(i, j).unwrap();
//!     k.values_mut()[p] = v;
//! }
//! let mut m = SparseMatrix::from_pattern(3, vec![(0, 0), (1, 1)]);
//! m.values_mut().copy_from_slice(&[2.0, 2.0]);
//! let pencil = Pencil { stiffness: &k, mass: &m, multiplier: &[false, false, true] };
//! let modes = solve(&pencil, &EigenSettings::lowest(1)).unwrap();
//! assert!((modes.modes[0].omega_squared - 8.0).abs() < 1e-12);
//! ```

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::householder;
use faer::linalg::triangular_solve;
use faer::{Conj, Mat, MatMut, MatRef, Par, Side};

use crate::linalg::{SolveError, SparseLu, SparseMatrix};

/// `σ = −SHIFT_FRACTION λ_ref` is the default shift, with `λ_ref =
/// Σ|Kᵢᵢ| / ΣMᵢᵢ` the mean diagonal stiffness over the mean diagonal mass
/// (of the order of the highest eigenvalues of the model; independent of
/// the units and of the extent of the model). Below zero, so that
/// rigid-body and mechanism modes (`ω² = 0`) do not make `K − σM`
/// singular; small, so that the lowest flexible modes stay far from the
/// shift compared with the rest of the spectrum, which keeps shift-invert
/// Lanczos converging as from a shift at zero. The lowest flexible mode
/// of a slender space structure can be 1e-9 of `λ_ref` or less (a beam of
/// slenderness 1,000 in 20 elements: `(r h / L²)² ≈ 2.5e-9`). With
/// rigid-body modes `K − σM` then has a condition number of about
/// `1/SHIFT_FRACTION`; the error of its solutions lies along those modes,
/// which the reorthogonalisation of Lanczos removes.
pub const SHIFT_FRACTION: f64 = 1e-10;

/// An eigenvalue `ω²` with `|ω²| ≤ ZERO_FLOOR ε ‖x ∘ |K||x|‖₂` (`x` the
/// `M`-normalised mode, `∘` the entrywise product, `ε` the machine
/// epsilon) is reported as exactly zero: it is within what round-off of
/// the Rayleigh quotient `xᵀKx` produces, the terms `xᵢ Kᵢⱼ xⱼ` that cancel
/// added with random signs. Measured (`tests/eigen.rs`, `benches/eigen.rs`:
/// chains, beams of 200 to 3,333 elements with 1 to 3 rigid-body or
/// mechanism modes, dense and Lanczos): zero modes at 0.02 to 0.35 of
/// this floor, the lowest flexible modes at 3.1e3 (a beam of slenderness
/// 3e4 in 3,333 elements, `ω²₁ ≈ 6e-15 λ_ref`) and above 4e6 for all
/// others. 30 lies between them with a margin of about 100 on each side.
pub const ZERO_FLOOR: f64 = 30.0;

/// A mode passes the residual check when `‖r‖ ≤ tol ‖Kx‖ + ROUND_OFF_FACTOR
/// ε ‖|A||x, μ| + |ω²||M||x|‖`: the second term is what round-off alone
/// leaves in the residual of an exact mode (the terms that cancel, times
/// `ε`), so that a stiff model whose attainable residual is above `tol`
/// is not failed.
pub const ROUND_OFF_FACTOR: f64 = 16.0;

/// Constraint rows keeping less than this fraction of the largest pivot of
/// the column-pivoted QR of `Bᵀ` are dependent (redundant): the same
/// threshold as the rank analysis of the constraints (constraint gradients
/// of a sound mechanism are independent to O(1), round-off leaves ~1e-15).
const RANK_THRESHOLD: f64 = 1e-8;

/// Eigenvalues `θ = 1/(ω² − σ)` of the dense shifted problem below this
/// times `n ε` times the largest are massless directions (infinite
/// frequencies): round-off of a zero eigenvalue of `L⁻¹M_rL⁻ᵀ` is about
/// `n ε` times its largest. Modes with `ω² − σ` above `1/(100 n ε)` times
/// that of the lowest (about 4e10 for 1,000 unknowns) are not resolved
/// and are counted with them.
const MASSLESS_FACTOR: f64 = 100.0;

/// A dense pass whose shift is further than this factor from the best one
/// (`−d` below the lowest eigenvalue, `d` the smallest non-zero `|ω²|`) is
/// repeated with the best shift, when that matters: modes far above a
/// shift close to a zero eigenvalue, or far below a distant shift, lose
/// accuracy in proportion (docs/theory.md §14.3).
const SHIFT_MISMATCH: f64 = 100.0;

/// The Cholesky factorisation of `K_r − σM_r` failing (an eigenvalue below
/// `σ`), `σ` is moved this many times further down, at most
/// `MAX_SHIFT_TRIES` times.
const SHIFT_GROWTH: f64 = 100.0;
const MAX_SHIFT_TRIES: usize = 12;

/// Number of unknowns up to which [`solve`] uses the dense solver, which
/// gives every mode and cannot fail to converge: measured (`cargo bench
/// --bench eigen`, 20 modes), 0.37 s dense against 8 ms Lanczos at 1,002
/// unknowns and 1.8–2.4 s against 18–23 ms at 2,000; at 500 the dense
/// solve is an eighth of the former (`O(n³)`).
pub const DENSE_UNKNOWNS: usize = 500;

/// The generalized eigenproblem of a linearised constrained system, as the
/// assembler delivers it.
#[derive(Clone, Copy, Debug)]
pub struct Pencil<'a> {
    /// Tangent stiffness in saddle-point form `[[K, Bᵀ], [B, 0]]` with the
    /// multiplier equations interleaved in the numbering (their rows and
    /// columns carry the constraint gradients, in any scaling). Only its
    /// symmetric part is used.
    pub stiffness: &'a SparseMatrix,
    /// Mass on the same numbering (any pattern; entries in multiplier rows
    /// and columns are ignored). Only its symmetric part is used.
    pub mass: &'a SparseMatrix,
    /// Whether each equation is a multiplier's.
    pub multiplier: &'a [bool],
}

/// Which solver [`solve`] uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Dense up to [`DENSE_UNKNOWNS`] unknowns, Lanczos above.
    Auto,
    /// Null-space reduction and dense symmetric eigen-decomposition.
    Dense,
    /// Shift-invert Lanczos with the sparse LU.
    Lanczos,
}

/// Settings of the eigen-solvers.
#[derive(Clone, Debug, PartialEq)]
pub struct EigenSettings {
    /// Number of modes wanted: the lowest (dense), the nearest to the
    /// shift (Lanczos; the same when the shift is below the spectrum).
    pub modes: usize,
    /// Shift `σ` (in the units of `ω²`); `None` for `−SHIFT_FRACTION
    /// λ_ref`. Lanczos finds the modes nearest to it; the dense solver
    /// starts from it and moves it below the spectrum if needed.
    pub shift: Option<f64>,
    /// Relative residual `‖Kx + Bᵀμ − ω²Mx‖ / ‖Kx‖` a mode must reach
    /// (above its round-off, [`ROUND_OFF_FACTOR`]).
    pub tolerance: f64,
    /// Solver.
    pub method: Method,
    /// Lanczos: restarts before giving up.
    pub max_restarts: usize,
    /// Lanczos: vectors in the basis before a restart; `None` for
    /// `max(2 modes, modes + 20)`.
    pub basis_size: Option<usize>,
}

impl Default for EigenSettings {
    fn default() -> Self {
        Self {
            modes: 10,
            shift: None,
            // residuals of 1e-10 give eigenvalues to ~1e-20 relative
            // (quadratic in the residual for a symmetric pencil) and mode
            // shapes to 1e-10 relative to the gap to the next mode
            tolerance: 1e-10,
            method: Method::Auto,
            max_restarts: 200,
            basis_size: None,
        }
    }
}

impl EigenSettings {
    /// Default settings for the `modes` lowest modes.
    pub fn lowest(modes: usize) -> Self {
        Self {
            modes,
            ..Self::default()
        }
    }
}

/// A natural mode.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// `ω²` (rad²/s² in SI units); exactly zero for a rigid-body or
    /// mechanism mode, negative in a direction that is not stable.
    pub omega_squared: f64,
    /// The mode in the equation numbering: the unknowns' entries hold the
    /// shape, `M`-normalised (`xᵀMx = 1`), the multipliers' entries the
    /// multipliers `μ` of the mode (`Kx + Bᵀμ = ω²Mx`, in the scaling of
    /// the pencil).
    pub shape: Vec<f64>,
    /// `‖Kx + Bᵀμ − ω²Mx‖ / ‖Kx‖`; for a zero mode, relative to `‖|K||x|‖`
    /// (the size of the terms that cancel in `Kx`).
    pub residual: f64,
    /// The residual round-off alone would leave, `ε ‖|A||x, μ| +
    /// |ω²||M||x|‖`, relative to the same norm.
    pub round_off: f64,
}

impl Mode {
    /// `ω` (rad/s); for a negative `ω²`, `−√|ω²|` (the growth rate of the
    /// unstable motion, with a minus sign to tell it apart).
    pub fn angular_frequency(&self) -> f64 {
        self.omega_squared.signum() * self.omega_squared.abs().sqrt()
    }

    /// `f = ω / 2π` (Hz), with the sign of [`Self::angular_frequency`].
    pub fn frequency(&self) -> f64 {
        self.angular_frequency() / (2.0 * std::f64::consts::PI)
    }

    /// Whether this is a rigid-body or mechanism mode (`ω² = 0`).
    pub fn is_zero(&self) -> bool {
        self.omega_squared == 0.0
    }
}

/// The modes found and how.
#[derive(Clone, Debug, PartialEq)]
pub struct ModalSolution {
    /// The modes, by increasing `ω²`.
    pub modes: Vec<Mode>,
    /// How many of them are zero (rigid-body and mechanism modes).
    pub zero_modes: usize,
    /// Dense solver: massless directions (infinite frequencies), dropped.
    /// `None` for Lanczos, which never sees them.
    pub infinite_modes: Option<usize>,
    /// Number of independent constraint equations (the dense solver's rank
    /// of `B`; Lanczos: the multiplier equations).
    pub constraint_rank: usize,
    /// Shift used at the end.
    pub shift: f64,
    /// Solver used ([`Method::Dense`] or [`Method::Lanczos`]).
    pub method: Method,
    /// Lanczos: applications of the operator (solves with the LU).
    pub operator_applications: usize,
    /// Lanczos: restarts; dense: passes with a new shift.
    pub restarts: usize,
}

/// Why the modes could not be found.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum EigenError {
    /// The pencil is malformed (sizes, non-finite values).
    #[error("invalid eigenproblem: {0}")]
    InvalidInput(String),
    /// The mass matrix is zero, or not positive semi-definite.
    #[error("the mass matrix {0}")]
    Mass(String),
    /// No shift makes the stiffness positive definite where the mass is:
    /// the stiffness is singular or negative in a massless direction (a
    /// massless mechanism), and the pencil has no discrete spectrum there.
    #[error(
        "the stiffness is singular or negative on the massless directions \
         (a mechanism without mass?): no shift down to {shift:.3e} makes K − σM positive definite"
    )]
    SingularPencil {
        /// Last shift tried.
        shift: f64,
    },
    /// More modes were asked than the model has (finite ones).
    #[error("{requested} modes requested, the model has {available}")]
    TooManyModes {
        /// Modes asked.
        requested: usize,
        /// Finite modes of the model.
        available: usize,
    },
    /// The sparse factorisation of `A − σM` failed.
    #[error("factorisation of the shifted matrix (σ = {shift:.3e}): {source}")]
    Solve {
        /// The shift.
        shift: f64,
        /// What the solver said.
        source: SolveError,
    },
    /// Lanczos did not converge the requested modes.
    #[error(
        "Lanczos converged {converged} of {requested} modes in {restarts} restarts \
         (largest relative residual {residual:.3e})"
    )]
    NotConverged {
        /// Modes that passed the residual check.
        converged: usize,
        /// Modes asked.
        requested: usize,
        /// Restarts made.
        restarts: usize,
        /// Largest relative residual of the requested modes.
        residual: f64,
    },
    /// A dense factorisation failed where it cannot (a defect).
    #[error("dense eigen-solver: {0}")]
    Dense(String),
}

/// Finds the lowest modes of `pencil` with the solver of
/// `settings.method` ([`Method::Auto`]: dense up to [`DENSE_UNKNOWNS`]
/// unknowns).
pub fn solve(pencil: &Pencil, settings: &EigenSettings) -> Result<ModalSolution, EigenError> {
    let unknowns = pencil.multiplier.iter().filter(|&&m| !m).count();
    match settings.method {
        Method::Dense => solve_dense(pencil, settings),
        Method::Lanczos => solve_lanczos(pencil, settings),
        Method::Auto if unknowns <= DENSE_UNKNOWNS => solve_dense(pencil, settings),
        Method::Auto => solve_lanczos(pencil, settings),
    }
}

//------ the symmetrised pencil ------

/// The symmetric parts of the tangent and the mass on one pattern (the
/// union of both and their transposes), with the mass zero in the
/// multiplier rows and columns.
struct Symmetric {
    k: SparseMatrix,
    m: SparseMatrix,
    multiplier: Vec<bool>,
    /// Equations of the unknowns (not multipliers), in order.
    unknowns: Vec<usize>,
    /// `λ_ref = Σ|Kᵢᵢ| / ΣMᵢᵢ` over the unknowns.
    lambda_ref: f64,
}

impl Symmetric {
    fn new(p: &Pencil) -> Result<Self, EigenError> {
        let n = p.stiffness.dim();
        if p.mass.dim() != n || p.multiplier.len() != n {
            return Err(EigenError::InvalidInput(format!(
                "stiffness {n}×{n}, mass {m}×{m}, {l} equation kinds",
                m = p.mass.dim(),
                l = p.multiplier.len()
            )));
        }
        for (what, a) in [("stiffness", p.stiffness), ("mass", p.mass)] {
            if let Some((r, c, v)) = a.entries().find(|e| !e.2.is_finite()) {
                return Err(EigenError::InvalidInput(format!(
                    "the {what} has the non-finite entry {v} at ({r}, {c})"
                )));
            }
        }
        let multiplier = p.multiplier.to_vec();
        let is_mass = |r: usize, c: usize| !multiplier[r] && !multiplier[c];
        let mut pattern = Vec::with_capacity(2 * (p.stiffness.nnz() + p.mass.nnz()));
        for (r, c, _) in p.stiffness.entries() {
            pattern.extend([(r, c), (c, r)]);
        }
        for (r, c, _) in p.mass.entries().filter(|e| is_mass(e.0, e.1)) {
            pattern.extend([(r, c), (c, r)]);
        }
        let mut k = SparseMatrix::from_pattern(n, pattern);
        let mut m = k.clone();
        for (a, out, mass) in [(p.stiffness, &mut k, false), (p.mass, &mut m, true)] {
            for (r, c, v) in a.entries() {
                if mass && !is_mass(r, c) {
                    continue;
                }
                // (A + Aᵀ)/2
                for (i, j) in [(r, c), (c, r)] {
                    let pos = out.position(i, j).expect("entry of the union pattern");
                    out.values_mut()[pos] += 0.5 * v;
                }
            }
        }
        let unknowns: Vec<usize> = (0..n).filter(|&i| !multiplier[i]).collect();
        let diag = |a: &SparseMatrix, i: usize| a.position(i, i).map_or(0.0, |p| a.values()[p]);
        let (mut sk, mut sm) = (0.0, 0.0);
        for &i in &unknowns {
            sk += diag(&k, i).abs();
            let mi = diag(&m, i);
            if mi < 0.0 {
                return Err(EigenError::Mass(format!(
                    "has the negative diagonal entry {mi:.3e} at equation {i}: it is not positive semi-definite"
                )));
            }
            sm += mi;
        }
        if sm <= 0.0 {
            return Err(EigenError::Mass("is zero: no mode has a frequency".into()));
        }
        // an unloaded, unsupported model without stiffness: every mode is
        // zero, any positive scale will do
        let lambda_ref = if sk > 0.0 { sk / sm } else { 1.0 };
        Ok(Self {
            k,
            m,
            multiplier,
            unknowns,
            lambda_ref,
        })
    }

    fn dim(&self) -> usize {
        self.k.dim()
    }

    fn default_shift(&self) -> f64 {
        -SHIFT_FRACTION * self.lambda_ref
    }

    /// `A − σM`, on the same pattern.
    fn shifted(&self, sigma: f64) -> SparseMatrix {
        let mut a = self.k.clone();
        for (v, m) in a.values_mut().iter_mut().zip(self.m.values()) {
            *v -= sigma * m;
        }
        a
    }

    /// Keeps the unknowns' entries of `x` and zeroes the multipliers'.
    fn unknowns_only(&self, x: &mut [f64]) {
        for (v, &m) in x.iter_mut().zip(&self.multiplier) {
            if m {
                *v = 0.0;
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// `a += s b`.
fn axpy(a: &mut [f64], s: f64, b: &[f64]) {
    a.iter_mut().zip(b).for_each(|(x, y)| *x += s * y);
}

//------ Rayleigh–Ritz and the residual check ------

/// Rayleigh–Ritz on the span of `z` (unknowns only): the eigenvalues of
/// `(ZᵀKZ, ZᵀMZ)`, ascending, and the coefficients of the Ritz vectors
/// (`M`-orthonormal) in the columns of `z`.
fn rayleigh_ritz(s: &Symmetric, z: &[Vec<f64>]) -> Result<(Vec<f64>, Mat<f64>), EigenError> {
    let k = z.len();
    let n = s.dim();
    let mut kz = vec![vec![0.0; n]; k];
    let mut mz = vec![vec![0.0; n]; k];
    for i in 0..k {
        s.k.mul_vec(&z[i], &mut kz[i]);
        s.unknowns_only(&mut kz[i]);
        s.m.mul_vec(&z[i], &mut mz[i]);
    }
    let ks = Mat::from_fn(k, k, |i, j| 0.5 * (dot(&z[i], &kz[j]) + dot(&z[j], &kz[i])));
    let ms = Mat::from_fn(k, k, |i, j| 0.5 * (dot(&z[i], &mz[j]) + dot(&z[j], &mz[i])));
    let (theta, coefficients) = symmetric_definite(ks.as_ref(), ms.as_ref())
        .ok_or_else(|| EigenError::Dense("the computed modes are linearly dependent".into()))?;
    Ok((theta, coefficients))
}

/// The Rayleigh quotient `zᵀKz / zᵀMz` of each vector and the vector
/// `M`-normalised.
fn rayleigh_quotients(s: &Symmetric, z: &[Vec<f64>]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = s.dim();
    let (mut kz, mut mz) = (vec![0.0; n], vec![0.0; n]);
    z.iter()
        .map(|zi| {
            s.k.mul_vec(zi, &mut kz);
            s.unknowns_only(&mut kz);
            s.m.mul_vec(zi, &mut mz);
            s.unknowns_only(&mut mz);
            let mass = dot(zi, &mz);
            let scale = 1.0 / mass.sqrt();
            (dot(zi, &kz) / mass, zi.iter().map(|v| v * scale).collect())
        })
        .unzip()
}

/// Eigenvalues (ascending) and `B`-orthonormal eigenvectors of the
/// symmetric-definite pencil `(A, B)`, by the Cholesky factor `B = LLᵀ`
/// and the symmetric eigenproblem of `L⁻¹AL⁻ᵀ`; `None` if `B` is not
/// positive definite.
fn symmetric_definite(a: MatRef<f64>, b: MatRef<f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let par = faer::get_global_parallelism();
    let llt = b.llt(Side::Lower).ok()?;
    let l = llt.L();
    let mut c = a.to_owned();
    triangular_solve::solve_lower_triangular_in_place(l, c.as_mut(), par);
    let mut c = c.transpose().to_owned();
    triangular_solve::solve_lower_triangular_in_place(l, c.as_mut(), par);
    symmetrise(c.as_mut());
    let evd = c.self_adjoint_eigen(Side::Lower).ok()?;
    let mut u = evd.U().to_owned();
    triangular_solve::solve_upper_triangular_in_place(l.transpose(), u.as_mut(), par);
    let theta = (0..c.nrows()).map(|i| evd.S()[i]).collect();
    Some((theta, u))
}

fn symmetrise(mut a: MatMut<f64>) {
    for j in 0..a.ncols() {
        for i in 0..j {
            let v = 0.5 * (a[(i, j)] + a[(j, i)]);
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
}

/// Builds the modes from eigenvalues `lambda`, shapes `x` (unknowns'
/// entries, `M`-normalised) and multipliers `mu` (multipliers' entries):
/// zero eigenvalues, residuals and their round-off. Returns the modes and
/// whether every one passed the residual check with `tolerance`.
fn finish(
    s: &Symmetric,
    lambda: &[f64],
    x: Vec<Vec<f64>>,
    mu: &[Vec<f64>],
    tolerance: f64,
) -> (Vec<Mode>, bool) {
    let n = s.dim();
    let eps = f64::EPSILON;
    let mut modes = Vec::with_capacity(lambda.len());
    let mut all_pass = true;
    let (mut kx, mut akx, mut mx, mut amx, mut full, mut afull, mut a_full) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    for ((&l, mut shape), mu) in lambda.iter().zip(x).zip(mu) {
        let abs_x: Vec<f64> = shape.iter().map(|v| v.abs()).collect();
        s.k.mul_vec(&shape, &mut kx);
        s.k.mul_abs_vec(&abs_x, &mut akx);
        s.m.mul_vec(&shape, &mut mx);
        s.m.mul_abs_vec(&abs_x, &mut amx);
        s.unknowns_only(&mut kx);
        s.unknowns_only(&mut akx);
        // the round-off of xᵀKx: ε ‖x ∘ |K||x|‖₂, the terms that cancel,
        // added with random signs
        let floor = eps
            * abs_x
                .iter()
                .zip(&akx)
                .map(|(a, b)| (a * b) * (a * b))
                .sum::<f64>()
                .sqrt();
        let is_zero = l.abs() <= ZERO_FLOOR * floor;
        let l = if is_zero { 0.0 } else { l };
        // A [x, μ] on the unknowns: Kx + Bᵀμ
        for i in 0..n {
            full[i] = if s.multiplier[i] { mu[i] } else { shape[i] };
        }
        let abs_full: Vec<f64> = full.iter().map(|v| v.abs()).collect();
        s.k.mul_vec(&full, &mut a_full);
        s.k.mul_abs_vec(&abs_full, &mut afull);
        let (mut r2, mut round2) = (0.0, 0.0);
        for &i in &s.unknowns {
            let r = a_full[i] - l * mx[i];
            r2 += r * r;
            let f = eps * (afull[i] + l.abs() * amx[i]);
            round2 += f * f;
        }
        let scale = if is_zero { norm(&akx) } else { norm(&kx) };
        let scale = if scale > 0.0 {
            scale
        } else {
            f64::MIN_POSITIVE
        };
        let residual = r2.sqrt() / scale;
        let round_off = round2.sqrt() / scale;
        all_pass &= residual <= tolerance + ROUND_OFF_FACTOR * round_off;
        for i in 0..n {
            if s.multiplier[i] {
                shape[i] = mu[i];
            }
        }
        modes.push(Mode {
            omega_squared: l,
            shape,
            residual,
            round_off,
        });
    }
    (modes, all_pass)
}

fn count_zero(modes: &[Mode]) -> usize {
    modes.iter().filter(|m| m.is_zero()).count()
}

//------ dense solver ------

/// The lowest `settings.modes` modes by null-space reduction and a dense
/// symmetric eigen-decomposition (docs/theory.md §14.2): every mode of the
/// model is computed, so this is for models of up to a few thousand
/// unknowns. `settings.shift` is only a starting value.
pub fn solve_dense(pencil: &Pencil, settings: &EigenSettings) -> Result<ModalSolution, EigenError> {
    let s = Symmetric::new(pencil)?;
    let par = faer::get_global_parallelism();
    let nu = s.unknowns.len();
    let mut local = vec![usize::MAX; s.dim()];
    for (k, &i) in s.unknowns.iter().enumerate() {
        local[i] = k;
    }

    // dense K and M over the unknowns, constraint rows B over the unknowns
    let mut kd = Mat::<f64>::zeros(nu, nu);
    let mut md = Mat::<f64>::zeros(nu, nu);
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); s.dim()];
    let mut coupled = vec![false; s.dim()];
    for (r, c, v) in s.k.entries() {
        match (s.multiplier[r], s.multiplier[c]) {
            (false, false) => kd[(local[r], local[c])] = v,
            (true, false) if v != 0.0 => rows[r].push((local[c], v)),
            (true, true) if v != 0.0 => coupled[r] = true,
            _ => {}
        }
    }
    for (r, c, v) in s.m.entries() {
        if !s.multiplier[r] && !s.multiplier[c] {
            md[(local[r], local[c])] = v;
        }
    }
    // a multiplier row without gradient (a released driver, `k λ = 0`)
    // only says that its multiplier is zero
    let mut active = Vec::new();
    for eq in 0..s.dim() {
        if !s.multiplier[eq] || rows[eq].is_empty() {
            continue;
        }
        if coupled[eq] {
            return Err(EigenError::InvalidInput(format!(
                "the multiplier equation {eq} has both a constraint gradient and a \
                 multiplier–multiplier entry; only [[K, Bᵀ], [B, 0]] is supported"
            )));
        }
        active.push(eq);
    }

    let row_norm: Vec<f64> = rows
        .iter()
        .map(|r| r.iter().map(|&(_, v)| v * v).sum::<f64>().sqrt())
        .collect();
    // null space of B: Bᵀ P = Q R, N = the last nu − rank columns of Q
    let null_space = if active.is_empty() {
        None
    } else {
        // each constraint row scaled to unit norm, so that the rank does
        // not depend on the scaling `k` of its kind of constraint (a force
        // against a moment: the units chosen); μ is scaled back below
        let mut bt = Mat::<f64>::zeros(nu, active.len());
        for (j, &eq) in active.iter().enumerate() {
            let norm = row_norm[eq];
            for &(i, v) in &rows[eq] {
                bt[(i, j)] = v / norm;
            }
        }
        let qr = bt.col_piv_qr();
        let r = qr.R();
        let size = nu.min(active.len());
        let r00 = if size > 0 { r[(0, 0)].abs() } else { 0.0 };
        let rank = (0..size)
            .take_while(|&i| r[(i, i)].abs() > RANK_THRESHOLD * r00)
            .count();
        Some((qr, rank))
    };
    let rank = null_space.as_ref().map_or(0, |q| q.1);
    let nr = nu - rank;
    let (kr, mr) = match &null_space {
        None => (kd.clone(), md.clone()),
        Some((qr, rank)) => {
            let reduce = |a: &Mat<f64>| -> Mat<f64> {
                let mut a = a.clone();
                apply_q(qr.Q_basis(), qr.Q_coeff(), a.as_mut(), true, par);
                let mut at = a.transpose().to_owned();
                apply_q(qr.Q_basis(), qr.Q_coeff(), at.as_mut(), true, par);
                let mut r = at.get(*rank.., *rank..).to_owned();
                symmetrise(r.as_mut());
                r
            };
            (reduce(&kd), reduce(&md))
        }
    };
    if nr == 0 {
        return Err(EigenError::TooManyModes {
            requested: settings.modes,
            available: 0,
        });
    }

    // σ below the spectrum (eigenvalues only), then, if it is far from
    // the best shift, a second pass at the best shift
    let mut sigma = settings.shift.unwrap_or_else(|| s.default_shift());
    let (mut l_factor, mut c) = shifted_inverse(&kr, &mr, &mut sigma, s.lambda_ref, par)?;
    let mu = c
        .self_adjoint_eigenvalues(Side::Lower)
        .map_err(|e| EigenError::Dense(format!("{e:?}")))?;
    let mut passes = 1;
    if let Some(best) = best_shift(&mu, sigma, nr, s.lambda_ref) {
        sigma = best;
        (l_factor, c) = shifted_inverse(&kr, &mr, &mut sigma, s.lambda_ref, par)?;
        passes += 1;
    }
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| EigenError::Dense(format!("{e:?}")))?;

    // the wanted modes: the largest 1/(ω² − σ), i.e. the lowest ω²
    let mu: Vec<f64> = (0..nr).map(|i| evd.S()[i]).collect();
    let mu_max = mu.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    let massless = MASSLESS_FACTOR * nr as f64 * f64::EPSILON * mu_max;
    if let Some(&bad) = mu.iter().find(|&&m| m < -massless) {
        return Err(EigenError::Mass(format!(
            "is not positive semi-definite (eigenvalue {bad:.3e} of L⁻¹M L⁻ᵀ)"
        )));
    }
    let finite = mu.iter().filter(|&&m| m > massless).count();
    if settings.modes > finite {
        return Err(EigenError::TooManyModes {
            requested: settings.modes,
            available: finite,
        });
    }
    let wanted: Vec<usize> = (0..settings.modes).map(|k| nr - 1 - k).collect();
    // x_r = L⁻ᵀ y / √μ (M_r-normalised)
    let mut xr = Mat::from_fn(nr, wanted.len(), |i, k| evd.U()[(i, wanted[k])]);
    triangular_solve::solve_upper_triangular_in_place(l_factor.transpose(), xr.as_mut(), par);
    for (k, &w) in wanted.iter().enumerate() {
        let scale = 1.0 / mu[w].sqrt();
        for i in 0..nr {
            xr[(i, k)] *= scale;
        }
    }
    // back to the unknowns: x = Q [0; x_r]
    let mut xu = Mat::<f64>::zeros(nu, wanted.len());
    xu.as_mut().get_mut(rank.., ..).copy_from(xr.as_ref());
    if let Some((qr, _)) = &null_space {
        apply_q(qr.Q_basis(), qr.Q_coeff(), xu.as_mut(), false, par);
    }
    let to_full = |col: usize, a: &Mat<f64>| -> Vec<f64> {
        let mut v = vec![0.0; s.dim()];
        for (k, &i) in s.unknowns.iter().enumerate() {
            v[i] = a[(k, col)];
        }
        v
    };
    let z: Vec<Vec<f64>> = (0..wanted.len()).map(|k| to_full(k, &xu)).collect();

    // Rayleigh quotients, then the multipliers: least squares
    // Bᵀμ = −(Kx − ω²Mx). Not a Rayleigh–Ritz step over all the modes: the
    // dense modes are already Ritz vectors of the whole space, and with
    // many modes the projected stiffness spans the whole spectrum, whose
    // eigenvectors then carry errors of ε ‖K‖ / gap along the stiff modes
    // (measured: residuals of 1 on the lowest modes of a 234-unknown beam
    // when all its modes were asked)
    let (mut lambda, mut x) = rayleigh_quotients(&s, &z);
    // by increasing ω² (members of a degenerate pair may swap by round-off)
    let mut order: Vec<usize> = (0..lambda.len()).collect();
    order.sort_by(|&a, &b| lambda[a].total_cmp(&lambda[b]));
    (lambda, x) = order
        .into_iter()
        .map(|k| (lambda[k], std::mem::take(&mut x[k])))
        .unzip();
    let mut mus = vec![vec![0.0; s.dim()]; x.len()];
    if let Some((qr, rank)) = &null_space {
        let mut rhs = Mat::<f64>::zeros(nu, x.len());
        let (mut kx, mut mx) = (vec![0.0; s.dim()], vec![0.0; s.dim()]);
        for (j, xj) in x.iter().enumerate() {
            s.k.mul_vec(xj, &mut kx);
            s.m.mul_vec(xj, &mut mx);
            for (k, &i) in s.unknowns.iter().enumerate() {
                rhs[(k, j)] = -(kx[i] - lambda[j] * mx[i]);
            }
        }
        apply_q(qr.Q_basis(), qr.Q_coeff(), rhs.as_mut(), true, par);
        let mut t = rhs.get(..*rank, ..).to_owned();
        let r11 = qr.R().get(..*rank, ..*rank);
        triangular_solve::solve_upper_triangular_in_place(r11, t.as_mut(), par);
        let (fwd, _) = qr.P().arrays();
        for (j, mu) in mus.iter_mut().enumerate() {
            for p in 0..*rank {
                let eq = active[fwd[p]];
                mu[eq] = t[(p, j)] / row_norm[eq];
            }
        }
    }
    let (modes, _) = finish(&s, &lambda, x, &mus, settings.tolerance);
    Ok(ModalSolution {
        zero_modes: count_zero(&modes),
        modes,
        infinite_modes: Some(nr - finite),
        constraint_rank: rank,
        shift: sigma,
        method: Method::Dense,
        operator_applications: 0,
        restarts: passes - 1,
    })
}

/// Applies `Qᵀ` (`transpose`) or `Q` of a Householder sequence to `a` from
/// the left.
fn apply_q(basis: MatRef<f64>, coeff: MatRef<f64>, a: MatMut<f64>, transpose: bool, par: Par) {
    let req =
        StackReq::any_of(&[
            householder::apply_block_householder_sequence_transpose_on_the_left_in_place_scratch::<
                f64,
            >(basis.nrows(), coeff.nrows(), a.ncols()),
            householder::apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(
                basis.nrows(),
                coeff.nrows(),
                a.ncols(),
            ),
        ]);
    let mut mem = MemBuffer::new(req);
    let stack = MemStack::new(&mut mem);
    if transpose {
        householder::apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj(
            basis,
            coeff,
            Conj::No,
            a,
            par,
            stack,
        );
    } else {
        householder::apply_block_householder_sequence_on_the_left_in_place_with_conj(
            basis,
            coeff,
            Conj::No,
            a,
            par,
            stack,
        );
    }
}

/// `C = L⁻¹M_rL⁻ᵀ` with `LLᵀ = K_r − σM_r`; `σ` is moved down until the
/// Cholesky factorisation succeeds.
fn shifted_inverse(
    kr: &Mat<f64>,
    mr: &Mat<f64>,
    sigma: &mut f64,
    lambda_ref: f64,
    par: Par,
) -> Result<(Mat<f64>, Mat<f64>), EigenError> {
    for _ in 0..MAX_SHIFT_TRIES {
        let a = Mat::from_fn(kr.nrows(), kr.ncols(), |i, j| {
            kr[(i, j)] - *sigma * mr[(i, j)]
        });
        if let Ok(llt) = a.llt(Side::Lower) {
            let l = llt.L().to_owned();
            let mut c = mr.clone();
            triangular_solve::solve_lower_triangular_in_place(l.as_ref(), c.as_mut(), par);
            let mut c = c.transpose().to_owned();
            triangular_solve::solve_lower_triangular_in_place(l.as_ref(), c.as_mut(), par);
            symmetrise(c.as_mut());
            return Ok((l, c));
        }
        *sigma = if *sigma < 0.0 {
            SHIFT_GROWTH * *sigma
        } else {
            -SHIFT_FRACTION * lambda_ref
        };
    }
    Err(EigenError::SingularPencil { shift: *sigma })
}

/// The shift for another dense pass, if this one (`σ`, eigenvalues `mu`
/// of `L⁻¹M_rL⁻ᵀ`, ascending) was too far from the best one `σ* =
/// min(ω²_min, 0) − d` (`d` the smallest `|ω²|` not at round-off of
/// zero): modes far above a shift close to zero eigenvalues, or far below
/// a distant shift, lose accuracy in proportion (docs/theory.md §14.3).
fn best_shift(mu: &[f64], sigma: f64, n: usize, lambda_ref: f64) -> Option<f64> {
    let mu_max = mu.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    let massless = MASSLESS_FACTOR * n as f64 * f64::EPSILON * mu_max;
    let lambda: Vec<f64> = mu
        .iter()
        .filter(|&&m| m > massless)
        .map(|&m| sigma + 1.0 / m)
        .collect();
    // zero at this pass: round-off of ω² near zero from the shifted
    // problem is about n ε |σ|, and from K_r itself about ε λ_ref
    let zero = (1e-3 * sigma.abs()).max(ZERO_FLOOR * f64::EPSILON * lambda_ref);
    let d = lambda
        .iter()
        .filter(|l| l.abs() > zero)
        .fold(f64::INFINITY, |a, l| a.min(l.abs()));
    if !d.is_finite() {
        return None;
    }
    let has_zero = lambda.iter().any(|l| l.abs() <= zero);
    let lowest = lambda.iter().fold(f64::INFINITY, |a, &l| a.min(l));
    let best = lowest.min(0.0) - d;
    let far_below = sigma < SHIFT_MISMATCH * best;
    let too_close = has_zero && sigma > best / SHIFT_MISMATCH;
    (far_below || too_close).then_some(best)
}

/// `xⱼ = Σᵢ cᵢⱼ zᵢ`.
fn combine(z: &[Vec<f64>], c: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..c.ncols())
        .map(|j| {
            let mut x = vec![0.0; z[0].len()];
            for (i, zi) in z.iter().enumerate() {
                axpy(&mut x, c[(i, j)], zi);
            }
            x
        })
        .collect()
}

//------ shift-invert Lanczos ------

/// The operator `S = (A − σM)⁻¹M` of shift-invert Lanczos, with its sparse
/// LU.
struct ShiftInvert<'s> {
    s: &'s Symmetric,
    lu: SparseLu,
    sigma: f64,
    rhs: Vec<f64>,
    applications: usize,
}

impl<'s> ShiftInvert<'s> {
    fn new(s: &'s Symmetric, sigma: f64) -> Result<Self, EigenError> {
        let a = s.shifted(sigma);
        let err = |source| EigenError::Solve {
            shift: sigma,
            source,
        };
        let mut lu = SparseLu::analyze(&a).map_err(err)?;
        lu.factor(&a).map_err(err)?;
        Ok(Self {
            s,
            lu,
            sigma,
            rhs: vec![0.0; s.dim()],
            applications: 0,
        })
    }

    /// `w = S v` on the unknowns; the multipliers of the solve
    /// `(A − σM)[w, ν] = [Mv, 0]` go to `nu` if given.
    fn apply(
        &mut self,
        v: &[f64],
        w: &mut [f64],
        nu: Option<&mut [f64]>,
    ) -> Result<(), EigenError> {
        self.s.m.mul_vec(v, &mut self.rhs);
        self.lu
            .solve_in_place(&mut self.rhs)
            .map_err(|source| EigenError::Solve {
                shift: self.sigma,
                source,
            })?;
        self.applications += 1;
        w.copy_from_slice(&self.rhs);
        if let Some(nu) = nu {
            nu.copy_from_slice(&self.rhs);
            for (x, &m) in nu.iter_mut().zip(&self.s.multiplier) {
                if !m {
                    *x = 0.0;
                }
            }
        }
        self.s.unknowns_only(w);
        Ok(())
    }
}

/// A deterministic pseudo-random vector on the unknowns (splitmix64), the
/// start of Lanczos.
fn random_unknowns(s: &Symmetric, seed: u64) -> Vec<f64> {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut v: Vec<f64> = (0..s.dim()).map(|_| next()).collect();
    s.unknowns_only(&mut v);
    v
}

/// The Lanczos basis in the `M` inner product: vectors `v` and `M v`.
struct Basis {
    v: Vec<Vec<f64>>,
    mv: Vec<Vec<f64>>,
}

impl Basis {
    /// Orthogonalises `w` against the basis in the `M` inner product
    /// (classical Gram–Schmidt, twice: Daniel, Gragg, Kaufman & Stewart
    /// 1976) and returns the coefficients; `mw` receives `M w`.
    fn orthogonalise(&self, s: &Symmetric, w: &mut [f64], mw: &mut [f64]) -> Vec<f64> {
        let mut h = vec![0.0; self.v.len()];
        for _ in 0..2 {
            let c: Vec<f64> = self.mv.iter().map(|mv| dot(mv, w)).collect();
            for (i, ci) in c.iter().enumerate() {
                axpy(w, -ci, &self.v[i]);
                h[i] += ci;
            }
        }
        s.m.mul_vec(w, mw);
        h
    }

    /// Appends `w / ‖w‖_M` (with `mw = M w`).
    fn push(&mut self, mut w: Vec<f64>, mut mw: Vec<f64>, beta: f64) {
        w.iter_mut().for_each(|x| *x /= beta);
        mw.iter_mut().for_each(|x| *x /= beta);
        self.v.push(w);
        self.mv.push(mw);
    }
}

/// The `settings.modes` modes nearest to the shift by shift-invert
/// Lanczos with thick restarts (docs/theory.md §14.4).
pub fn solve_lanczos(
    pencil: &Pencil,
    settings: &EigenSettings,
) -> Result<ModalSolution, EigenError> {
    let s = Symmetric::new(pencil)?;
    let nu = s.unknowns.len();
    let nev = settings.modes;
    let sigma = settings.shift.unwrap_or_else(|| s.default_shift());
    let constraint_rank = s.multiplier.iter().filter(|&&m| m).count();
    if nev == 0 {
        return Ok(ModalSolution {
            modes: Vec::new(),
            zero_modes: 0,
            infinite_modes: None,
            constraint_rank,
            shift: sigma,
            method: Method::Lanczos,
            operator_applications: 0,
            restarts: 0,
        });
    }
    if nev > nu {
        return Err(EigenError::TooManyModes {
            requested: nev,
            available: nu,
        });
    }
    let m = settings
        .basis_size
        .unwrap_or((2 * nev).max(nev + 20))
        .clamp(nev + 1, nu.max(nev + 1));
    let mut op = ShiftInvert::new(&s, sigma)?;
    let n = s.dim();

    // start in the range of S (no massless component)
    let mut seed = 1u64;
    let mut basis = Basis {
        v: Vec::with_capacity(m + 1),
        mv: Vec::with_capacity(m + 1),
    };
    let (mut w, mut mw) = (vec![0.0; n], vec![0.0; n]);
    op.apply(&random_unknowns(&s, seed), &mut w, None)?;
    s.m.mul_vec(&w, &mut mw);
    let beta0 = dot(&w, &mw).max(0.0).sqrt();
    if beta0 == 0.0 {
        return Err(EigenError::Mass(
            "is zero on the range of the operator".into(),
        ));
    }
    basis.push(w.clone(), mw.clone(), beta0);

    // H[i][j] = ⟨vᵢ, S vⱼ⟩_M, column-major m × m
    let mut h = Mat::<f64>::zeros(m, m);
    let mut tol_ritz = settings.tolerance;
    let mut restarts = 0;
    // when the Krylov space is exhausted (fewer finite modes than m)
    let mut exhausted: Option<usize> = None;
    loop {
        // extend the basis to m vectors (+ the residual vector)
        let mut beta = 0.0;
        let mut size = m;
        let mut j = basis.v.len() - 1;
        while j < m {
            op.apply(&basis.v[j], &mut w, None)?;
            let hj = basis.orthogonalise(&s, &mut w, &mut mw);
            for (i, &hij) in hj.iter().enumerate() {
                if i < m {
                    h[(i, j)] += hij;
                }
            }
            beta = dot(&w, &mw).max(0.0).sqrt();
            let scale = hj
                .iter()
                .fold(0.0f64, |a, b| a.max(b.abs()))
                .max(h[(j, j)].abs());
            if beta <= 1e-12 * scale {
                // invariant subspace: go on from a new random direction
                // (in the range of S), or stop if there is none
                beta = 0.0;
                seed += 1;
                op.apply(&random_unknowns(&s, seed), &mut w, None)?;
                s.m.mul_vec(&w, &mut mw);
                let before = dot(&w, &mw).max(0.0).sqrt();
                basis.orthogonalise(&s, &mut w, &mut mw);
                let after = dot(&w, &mw).max(0.0).sqrt();
                if after <= 1e-10 * before || j + 1 == nu {
                    size = j + 1;
                    exhausted = Some(size);
                    break;
                }
                basis.push(w.clone(), mw.clone(), after);
                j += 1;
                continue;
            }
            if j + 1 < m {
                h[(j + 1, j)] = beta;
            }
            basis.push(w.clone(), mw.clone(), beta);
            j += 1;
        }

        // Ritz values and vectors of the symmetric part of H
        let mut hs = h.get(..size, ..size).to_owned();
        symmetrise(hs.as_mut());
        let evd = hs
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| EigenError::Dense(format!("{e:?}")))?;
        let mut order: Vec<usize> = (0..size).collect();
        order.sort_by(|&a, &b| evd.S()[b].abs().total_cmp(&evd.S()[a].abs()));
        if nev > size {
            return Err(EigenError::TooManyModes {
                requested: nev,
                available: size,
            });
        }
        let theta = |i: usize| evd.S()[order[i]];
        let last = |i: usize| evd.U()[(size - 1, order[i])];
        let converged = (0..nev).all(|i| (beta * last(i)).abs() <= tol_ritz * theta(i).abs());

        if converged {
            // Ritz vectors, purified by one more application of S
            let mut z = Vec::with_capacity(nev);
            let mut nus = Vec::with_capacity(nev);
            for i in 0..nev {
                let mut y = vec![0.0; n];
                for (k, v) in basis.v.iter().take(size).enumerate() {
                    axpy(&mut y, evd.U()[(k, order[i])], v);
                }
                let mut zi = vec![0.0; n];
                let mut nu_i = vec![0.0; n];
                op.apply(&y, &mut zi, Some(&mut nu_i))?;
                z.push(zi);
                nus.push(nu_i);
            }
            let (lambda, c) = rayleigh_ritz(&s, &z)?;
            let x = combine(&z, &c);
            let mus = combine(&nus, &c);
            let (modes, pass) = finish(&s, &lambda, x, &mus, settings.tolerance);
            if pass {
                return Ok(ModalSolution {
                    zero_modes: count_zero(&modes),
                    modes,
                    infinite_modes: None,
                    constraint_rank,
                    shift: sigma,
                    method: Method::Lanczos,
                    operator_applications: op.applications,
                    restarts,
                });
            }
            if exhausted.is_some() || tol_ritz < 1e-15 || restarts >= settings.max_restarts {
                return Err(not_converged(&modes, settings, restarts));
            }
            // the Ritz estimate was optimistic for the physical residual
            tol_ritz *= 1e-2;
        } else if restarts >= settings.max_restarts {
            let nconv = (0..nev)
                .filter(|&i| (beta * last(i)).abs() <= tol_ritz * theta(i).abs())
                .count();
            return Err(EigenError::NotConverged {
                converged: nconv,
                requested: nev,
                restarts,
                residual: (0..nev)
                    .map(|i| (beta * last(i)).abs() / theta(i).abs())
                    .fold(0.0, f64::max),
            });
        }

        // thick restart: keep the wanted Ritz vectors and some more, and
        // the residual vector
        let keep = ((nev + size) / 2).clamp(nev, size - 1);
        let mut v_new = Vec::with_capacity(m + 1);
        let mut mv_new = Vec::with_capacity(m + 1);
        for i in 0..keep {
            let (mut y, mut my) = (vec![0.0; n], vec![0.0; n]);
            for k in 0..size {
                let c = evd.U()[(k, order[i])];
                axpy(&mut y, c, &basis.v[k]);
                axpy(&mut my, c, &basis.mv[k]);
            }
            v_new.push(y);
            mv_new.push(my);
        }
        v_new.push(basis.v[size].clone());
        mv_new.push(basis.mv[size].clone());
        basis.v = v_new;
        basis.mv = mv_new;
        h.fill(0.0);
        for i in 0..keep {
            h[(i, i)] = theta(i);
            h[(keep, i)] = beta * last(i);
        }
        restarts += 1;
    }
}

fn not_converged(modes: &[Mode], settings: &EigenSettings, restarts: usize) -> EigenError {
    let pass = |m: &Mode| m.residual <= settings.tolerance + ROUND_OFF_FACTOR * m.round_off;
    EigenError::NotConverged {
        converged: modes.iter().filter(|m| pass(m)).count(),
        requested: settings.modes,
        restarts,
        residual: modes.iter().map(|m| m.residual).fold(0.0, f64::max),
    }
}
