//! Craig–Bampton reduction of a flexible body (Craig & Bampton 1968;
//! reference paper eq. 21–24; docs/theory.md §18.1–18.3).
//!
//! The dofs are split into those of the boundary nodes `B` (six per node,
//! in the order the boundary lists them) and the interior `I`. The basis
//!
//! ```text
//! Φ = [ I    0  ]      Ψ = −K_II⁻¹ K_IB      (static constraint modes)
//!     [ Ψ    Φ_N]      K_II Φ_N = M_II Φ_N Ω² (fixed-interface modes)
//! ```
//!
//! with `Φ_Nᵀ M_II Φ_N = I`, gives the reduced matrices of eq. 24,
//!
//! ```text
//! K̄ = ΦᵀKΦ = [ K_BB + K_BI Ψ   0  ],   M̄ = ΦᵀMΦ.
//!             [ 0             Ω² ]
//! ```
//!
//! The constraint modes come from the sparse LU of `K_II` (one symbolic
//! analysis, one factorisation, a solve per boundary dof); the
//! fixed-interface modes from the eigen-solvers of [`crate::eigen`]
//! (shift-invert Lanczos over the sparse LU above 500 interior dofs, the
//! dense solver below), by count or up to a cut-off frequency. Checked
//! after the reduction (an error beyond [`ORTHOGONALITY_TOLERANCE`]):
//! `Φ_NᵀM_IIΦ_N = I`, `Φ_NᵀK_IIΦ_N = Ω²` and the constraint modes
//! `K`-orthogonal to the fixed-interface ones (the zero block of `K̄`).
//! Reported: the frequencies of the reduced body clamped at its boundary
//! and free-free against those of the full model.
//!
//! The superelement moves the body on the frame of one of its boundary
//! nodes (the *frame node*, paper eq. 20): its six columns leave the basis
//! (the frame carries them, rigid-body motion included), and the elastic
//! coordinates `y` are the boundary dofs of the other boundary nodes then
//! the modal amplitudes `η` ([`ReducedBody::y_columns`]). The inertia
//! invariants of the floating frame ([`Invariants`], docs/theory.md §18.5)
//! are computed here once, from `M` and the basis.

use std::time::Instant;

use nalgebra::{DMatrix, DVector};

use super::body::{from_triplets, FlexibleBody};
use crate::eigen::{self, EigenError, EigenSettings, Method, Pencil};
use crate::linalg::{SparseLu, SparseMatrix};
use crate::model::Id;
use crate::so3::Vec3;

/// Largest error of the orthogonality checks, relative (see
/// [`ReductionReport`]): the eigen-solver's residuals of 1e-10 and the
/// round-off of the LU solves leave 1e-12 to 1e-9 (measured on beams of
/// 20 to 10,000 elements); an error above 1e-6 means a mode or a
/// constraint mode is wrong, and the reduction is refused.
pub const ORTHOGONALITY_TOLERANCE: f64 = 1e-6;

/// The smallest eigenvalue of the reduced boundary stiffness scaled by its
/// diagonal (`D^{-1/2} K̄ D^{-1/2}`, dimensionless, largest eigenvalue of
/// order 1), below which it is singular: the boundary nodes then move
/// relative to the frame node without straining the body. A sound body's
/// value is its smallest relative stiffness (1e-8 for a slender beam of
/// slenderness 1,000 between its ends); round-off leaves ~1e-15.
pub const SINGULAR_BOUNDARY: f64 = 1e-12;

/// `‖K r‖ / (‖|K|‖ ‖r‖)` of the rigid-body motions below which the body
/// is free (its matrices hold no support): round-off leaves 1e-17 to
/// 1e-15 (measured on beams and imported matrices written to 16 digits),
/// 8-digit matrices ~1e-8.
pub const FREE_BODY: f64 = 1e-6;

/// How the fixed-interface modes are chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModeSelection {
    /// The `n` lowest.
    Count(usize),
    /// Every mode up to this frequency (Hz).
    CutOff(f64),
}

/// Which mass matrix the inertia invariants are computed from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InertiaModel {
    /// The body's own mass matrix (consistent): docs/theory.md §18.5.
    #[default]
    Consistent,
    /// Point masses at the nodes (the row sums of the translational mass,
    /// no rotational inertia): the lumped-mass approximation of the
    /// reference paper, eq. 27–29.
    Lumped,
}

impl InertiaModel {
    /// Name in files and messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Consistent => "consistent",
            Self::Lumped => "lumped",
        }
    }
}

/// What a reduction is asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct ReductionSettings {
    /// The boundary nodes (indices into the body's mesh nodes), in the
    /// order of the superelement's nodes.
    pub boundary: Vec<usize>,
    /// Which of them carries the floating frame (index into `boundary`).
    pub frame: usize,
    /// The fixed-interface modes kept.
    pub modes: ModeSelection,
    /// The mass matrix of the inertia invariants.
    pub inertia: InertiaModel,
    /// Modal damping ratio of each kept mode; one value for all of them,
    /// or none (undamped).
    pub damping_ratios: Vec<f64>,
    /// Whether to compute the free-free frequencies of the full model for
    /// the report (a Lanczos solve of the whole body; off for speed).
    pub compare_free_free: bool,
}

impl ReductionSettings {
    /// Settings for `modes` modes with the first boundary node as frame,
    /// consistent inertia, no damping, the full comparison.
    pub fn new(boundary: Vec<usize>, modes: ModeSelection) -> Self {
        Self {
            boundary,
            frame: 0,
            modes,
            inertia: InertiaModel::Consistent,
            damping_ratios: Vec::new(),
            compare_free_free: true,
        }
    }
}

/// Why a body could not be reduced.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ReductionError {
    /// No boundary node.
    #[error(
        "has no boundary node: list at least one (the node its floating frame is attached to)"
    )]
    NoBoundary,
    /// A boundary node listed twice.
    #[error("boundary node {0} is listed twice")]
    DuplicateBoundary(Id),
    /// A boundary node without its six dofs.
    #[error("boundary node {node} has no dof {missing} in the body's matrices: a boundary node keeps its six dofs (x, y, z, rx, ry, rz)")]
    BoundaryDofs {
        /// The node.
        node: Id,
        /// The components it lacks.
        missing: String,
    },
    /// More modes asked than the interior has dofs (with mass).
    #[error("{requested} fixed-interface modes asked, but the interior has only {available} dofs with mass")]
    TooManyModes {
        /// Modes asked.
        requested: usize,
        /// Interior dofs (with mass, when the eigen-solver could tell).
        available: usize,
    },
    /// `K_II` is singular.
    #[error("the stiffness of the interior with the boundary nodes clamped is singular: part of the body is not connected to its boundary nodes, or has a dof without stiffness")]
    SingularInterior,
    /// The body clamped at its boundary still has a zero-frequency mode.
    #[error("the body clamped at its boundary nodes still moves without straining ({zero} zero-frequency mode(s)): a mechanism inside it, or a part not connected to the boundary")]
    Mechanism {
        /// Zero modes found.
        zero: usize,
    },
    /// The reduced stiffness of the boundary (frame node clamped) is
    /// singular.
    #[error("the reduced stiffness is singular: with the frame node {frame} held, the boundary nodes move without straining the body (smallest scaled eigenvalue {value:.3e}); a mechanism between boundary nodes, or matrices with a dof without stiffness")]
    SingularBoundary {
        /// The frame node.
        frame: Id,
        /// The smallest eigenvalue of the scaled reduced stiffness.
        value: f64,
    },
    /// An orthogonality check failed.
    #[error("the reduced basis fails its check: {0}")]
    Orthogonality(String),
    /// The eigen-solver failed.
    #[error("eigen-solver: {0}")]
    Eigen(EigenError),
    /// The damping ratios do not match the modes.
    #[error("{given} damping ratios for {modes} modes: give one for all modes or one per mode")]
    DampingRatios {
        /// Ratios given.
        given: usize,
        /// Modes kept.
        modes: usize,
    },
}

/// A frequency of the full model and of the reduced body (Hz).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FrequencyPair {
    /// The full model's.
    pub full: f64,
    /// The reduced body's.
    pub reduced: f64,
}

impl FrequencyPair {
    /// `(reduced − full)/full`.
    pub fn relative_error(&self) -> f64 {
        (self.reduced - self.full) / self.full
    }
}

/// What a reduction found.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct ReductionReport {
    /// Dofs of the full model.
    pub dofs: usize,
    /// Dofs of the boundary nodes.
    pub boundary_dofs: usize,
    /// Fixed-interface modes kept.
    pub modes: usize,
    /// Frequencies with the boundary clamped, full model and reduced body,
    /// for the kept modes.
    pub clamped: Vec<FrequencyPair>,
    /// Frequencies of the flexible free-free modes, full model and reduced
    /// body, for the reduced body's modes up to the highest kept
    /// fixed-interface frequency (empty if not compared).
    pub free: Vec<FrequencyPair>,
    /// Zero-frequency modes of the reduced body free-free (6 for a free
    /// body).
    pub free_zero_modes: usize,
    /// `max |Φ_NᵀM_IIΦ_N − I|`.
    pub mass_orthogonality: f64,
    /// `max |Φ_NᵀK_IIΦ_N − Ω²| / max ω²`.
    pub stiffness_orthogonality: f64,
    /// `max |K̄_BN(i, k)| / √(K_BB(i, i) ω²_k)`: the constraint modes
    /// against the fixed-interface ones, relative to the size of the terms
    /// that cancel in `K̄_BN`.
    pub coupling_orthogonality: f64,
    /// `‖K r‖ / (‖|K|‖ ‖r‖)` over the six rigid-body motions `r` of the
    /// body: about 1e-16 for a free body; larger if the matrices hold
    /// supports or grounded springs.
    pub rigid_body_residual: f64,
    /// Total mass.
    pub mass: f64,
    /// Wall-clock time of the reduction, seconds.
    pub seconds: f64,
}

/// The inertia invariants of the floating-frame formulation
/// (docs/theory.md §18.5), for the velocities `ξ = (v̄, ω, ẏ)` of the
/// frame origin and the frame's angular velocity (both in frame axes)
/// and of the elastic coordinates: with `B = [Γ₀ Φ_y]` (rigid-body modes
/// about the frame node and the elastic basis) and `Φ_k = W(e_k) Φ_y`
/// (`e_k ×` the translations of `Φ_y`),
///
/// ```text
/// 𝕄₀ = BᵀMB,   D_k = BᵀMΦ_k,   H_kl = Φ_kᵀMΦ_l,
/// T = ½ ξᵀ𝕄₀ξ + Σ_k ω_k (D_k y)·ξ + ½ Σ_kl ω_k ω_l yᵀH_kl y.
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Invariants {
    /// `𝕄₀`, `(6 + n_y)²`: mass, first moment and inertia tensor about
    /// the frame node, the coupling of the rigid motion with the elastic
    /// coordinates, and their mass.
    pub m0: DMatrix<f64>,
    /// `D_k`, `(6 + n_y) × n_y`.
    pub d: [DMatrix<f64>; 3],
    /// `H_kl`, `n_y × n_y` (`H_lk = H_klᵀ`).
    pub h: [[DMatrix<f64>; 3]; 3],
    /// Total mass `m`.
    pub mass: f64,
    /// First moment about the frame node at the reference, frame axes:
    /// `m c₀`.
    pub first_moment: Vec3,
}

/// A reduced flexible body: what the superelement needs, and what the
/// recovery needs.
#[derive(Debug)]
pub struct ReducedBody {
    /// The mesh (its matrices emptied).
    pub body: FlexibleBody,
    /// Boundary nodes (mesh indices).
    pub boundary: Vec<usize>,
    /// The frame node (index into `boundary`).
    pub frame: usize,
    /// `ω²` of the kept fixed-interface modes.
    pub omega_squared: Vec<f64>,
    /// The Craig–Bampton basis `Φ`, `n_dofs × (6 n_boundary + n_modes)`:
    /// the boundary dofs node by node, then the modes.
    pub basis: DMatrix<f64>,
    /// `K̄` of the whole basis (eq. 24).
    pub reduced_stiffness: DMatrix<f64>,
    /// `M̄ = ΦᵀMΦ` of the whole basis.
    pub reduced_mass: DMatrix<f64>,
    /// The column of the basis of each elastic coordinate `y`: the six
    /// boundary columns of each boundary node but the frame node, then
    /// the modes.
    pub y_columns: Vec<usize>,
    /// `K̄` on the elastic coordinates.
    pub stiffness_y: DMatrix<f64>,
    /// Modal damping on the elastic coordinates, `2 ζ_k ω_k` on the modes'
    /// diagonal (zero on the boundary dofs).
    pub damping_y: DVector<f64>,
    /// The largest translation of each fixed-interface mode over the mesh
    /// nodes (its displacement per unit amplitude).
    pub mode_lengths: Vec<f64>,
    /// The inertia invariants.
    pub invariants: Invariants,
    /// The inertia model of the invariants.
    pub inertia: InertiaModel,
    /// What the reduction found.
    pub report: ReductionReport,
}

impl ReducedBody {
    /// Number of boundary nodes.
    pub fn n_boundary(&self) -> usize {
        self.boundary.len()
    }

    /// Number of fixed-interface modes.
    pub fn n_modes(&self) -> usize {
        self.omega_squared.len()
    }

    /// Number of elastic coordinates `y`.
    pub fn n_y(&self) -> usize {
        self.y_columns.len()
    }
}

/// Dense `Aᵀ (S x)` helpers: the columns of `S X` for a sparse `S`.
fn sparse_times(a: &SparseMatrix, x: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(x.nrows(), x.ncols());
    for j in 0..x.ncols() {
        let col = x.column(j);
        let mut y = vec![0.0; x.nrows()];
        a.mul_vec(col.as_slice(), &mut y);
        out.column_mut(j).copy_from_slice(&y);
    }
    out
}

/// The lumped mass of `body`: at each translational dof the row sum of
/// `M` over the translational columns of the same direction; no
/// rotational inertia.
fn lumped_mass(body: &FlexibleBody) -> SparseMatrix {
    let n = body.n_dofs();
    let mut diag = vec![0.0; n];
    for (r, c, v) in body.mass.entries() {
        let (cr, cc) = (body.dofs[r].1, body.dofs[c].1);
        if cr < 3 && cr == cc {
            diag[r] += v;
        }
    }
    let triplets: Vec<(usize, usize, f64)> = (0..n).map(|i| (i, i, diag[i])).collect();
    from_triplets(n, &triplets)
}

/// The six rigid-body motions of `body` about `origin`, `n_dofs × 6`:
/// unit translations, then unit rotations (`e_k × (X − X₀)` on the
/// translations, `e_k` on the rotations).
fn rigid_modes(body: &FlexibleBody, origin: &Vec3) -> DMatrix<f64> {
    let mut g = DMatrix::zeros(body.n_dofs(), 6);
    for (r, &(node, c)) in body.dofs.iter().enumerate() {
        if c < 3 {
            g[(r, c)] = 1.0;
            let arm = body.positions[node] - origin;
            for k in 0..3 {
                // (e_k × arm)_c
                g[(r, 3 + k)] = Vec3::ith(k, 1.0).cross(&arm)[c];
            }
        } else {
            g[(r, c)] = 1.0;
        }
    }
    g
}

/// Reduces `body` as `settings` say (see the module documentation).
pub fn reduce(
    mut body: FlexibleBody,
    settings: &ReductionSettings,
) -> Result<ReducedBody, ReductionError> {
    let started = Instant::now();
    let n = body.n_dofs();
    let rows = body.dof_rows();
    let boundary = &settings.boundary;
    if boundary.is_empty() {
        return Err(ReductionError::NoBoundary);
    }
    for (k, &b) in boundary.iter().enumerate() {
        if boundary[..k].contains(&b) {
            return Err(ReductionError::DuplicateBoundary(body.node_ids[b]));
        }
        let missing: Vec<&str> = (0..6)
            .filter(|&c| rows[b][c].is_none())
            .map(|c| crate::model::COMPONENT_NAMES[c])
            .collect();
        if !missing.is_empty() {
            return Err(ReductionError::BoundaryDofs {
                node: body.node_ids[b],
                missing: missing.join(", "),
            });
        }
    }

    // partition: boundary rows node by node, interior rows in body order
    let b_rows: Vec<usize> = boundary
        .iter()
        .flat_map(|&b| (0..6).map(move |c| (b, c)))
        .map(|(b, c)| rows[b][c].expect("checked above"))
        .collect();
    let mut place = vec![usize::MAX; n]; // index in B or I
    let mut is_boundary = vec![false; n];
    for (k, &r) in b_rows.iter().enumerate() {
        place[r] = k;
        is_boundary[r] = true;
    }
    let i_rows: Vec<usize> = (0..n).filter(|&r| !is_boundary[r]).collect();
    for (k, &r) in i_rows.iter().enumerate() {
        place[r] = k;
    }
    let (nb, ni) = (b_rows.len(), i_rows.len());
    let split = |a: &SparseMatrix| {
        let mut ii = Vec::new();
        let mut ib = DMatrix::zeros(ni, nb);
        let mut bb = DMatrix::zeros(nb, nb);
        for (r, c, v) in a.entries() {
            match (is_boundary[r], is_boundary[c]) {
                (false, false) => ii.push((place[r], place[c], v)),
                (false, true) => ib[(place[r], place[c])] += v,
                (true, true) => bb[(place[r], place[c])] += v,
                (true, false) => {}
            }
        }
        (from_triplets(ni, &ii), ib, bb)
    };
    let (k_ii, k_ib, k_bb) = split(&body.stiffness);
    let (m_ii, _, _) = split(&body.mass);

    // static constraint modes Ψ = −K_II⁻¹ K_IB
    let mut psi = DMatrix::zeros(ni, nb);
    if ni > 0 {
        let mut lu = SparseLu::analyze(&k_ii).map_err(|_| ReductionError::SingularInterior)?;
        lu.factor(&k_ii)
            .map_err(|_| ReductionError::SingularInterior)?;
        let mut rhs = vec![0.0; ni];
        for j in 0..nb {
            for (r, v) in rhs.iter_mut().zip(k_ib.column(j).iter()) {
                *r = -v;
            }
            lu.solve_in_place(&mut rhs)
                .map_err(|_| ReductionError::SingularInterior)?;
            psi.column_mut(j).copy_from_slice(&rhs);
        }
    }

    // fixed-interface modes
    let multiplier = vec![false; ni];
    let pencil = Pencil {
        stiffness: &k_ii,
        mass: &m_ii,
        multiplier: &multiplier,
    };
    let has_mass = m_ii.entries().any(|(i, j, v)| i == j && v > 0.0);
    let modes = match settings.modes {
        ModeSelection::Count(c) if c > ni => {
            return Err(ReductionError::TooManyModes {
                requested: c,
                available: ni,
            })
        }
        ModeSelection::Count(c) if c > 0 && !has_mass => {
            return Err(ReductionError::TooManyModes {
                requested: c,
                available: 0,
            })
        }
        _ if ni == 0 || !has_mass => Vec::new(),
        ModeSelection::Count(c) => fixed_interface_modes(&pencil, c.max(1), Some(c))?,
        ModeSelection::CutOff(f) => {
            let cut = (2.0 * std::f64::consts::PI * f).powi(2);
            let mut wanted = 8.min(ni);
            loop {
                let found = fixed_interface_modes(&pencil, wanted, None)?;
                let last = found.last().map_or(0.0, |m| m.omega_squared);
                if last > cut || found.len() < wanted || wanted == ni {
                    break found
                        .into_iter()
                        .filter(|m| m.omega_squared <= cut)
                        .collect();
                }
                wanted = (2 * wanted).min(ni);
            }
        }
    };
    let requested = match settings.modes {
        ModeSelection::Count(c) => c,
        ModeSelection::CutOff(_) => modes.len(),
    };
    let modes = &modes[..requested.min(modes.len())];
    let nm = modes.len();
    let omega_squared: Vec<f64> = modes.iter().map(|m| m.omega_squared).collect();
    let mut phi_n = DMatrix::zeros(ni, nm);
    for (k, m) in modes.iter().enumerate() {
        phi_n.column_mut(k).copy_from_slice(&m.shape);
    }

    // the basis Φ on the body's rows
    let ncb = nb + nm;
    let mut basis = DMatrix::zeros(n, ncb);
    for (k, &r) in b_rows.iter().enumerate() {
        basis[(r, k)] = 1.0;
    }
    for (k, &r) in i_rows.iter().enumerate() {
        for j in 0..nb {
            basis[(r, j)] = psi[(k, j)];
        }
        for j in 0..nm {
            basis[(r, nb + j)] = phi_n[(k, j)];
        }
    }

    // reduced matrices, eq. 24: K̄_BB = K_BB + K_BI Ψ
    let mut k_bar_bb = &k_bb + k_ib.transpose() * &psi;
    k_bar_bb = (&k_bar_bb + k_bar_bb.transpose()) * 0.5;
    let mut reduced_stiffness = DMatrix::zeros(ncb, ncb);
    reduced_stiffness
        .view_mut((0, 0), (nb, nb))
        .copy_from(&k_bar_bb);
    for (k, &w2) in omega_squared.iter().enumerate() {
        reduced_stiffness[(nb + k, nb + k)] = w2;
    }
    let m_phi = sparse_times(&body.mass, &basis);
    let mut reduced_mass = basis.transpose() * &m_phi;
    reduced_mass = (&reduced_mass + reduced_mass.transpose()) * 0.5;

    // orthogonality checks
    let mut report = ReductionReport {
        dofs: n,
        boundary_dofs: nb,
        modes: nm,
        ..Default::default()
    };
    if nm > 0 {
        let mm = phi_n.transpose() * sparse_times(&m_ii, &phi_n);
        let kk = phi_n.transpose() * sparse_times(&k_ii, &phi_n);
        let top = omega_squared.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        for i in 0..nm {
            for j in 0..nm {
                let delta = if i == j { 1.0 } else { 0.0 };
                report.mass_orthogonality =
                    report.mass_orthogonality.max((mm[(i, j)] - delta).abs());
                let w = if i == j { omega_squared[i] } else { 0.0 };
                report.stiffness_orthogonality = report
                    .stiffness_orthogonality
                    .max((kk[(i, j)] - w).abs() / top);
            }
        }
        // K̄_BN = (K_IB + K_II Ψ)ᵀ Φ_N
        let coupling = (&k_ib + sparse_times(&k_ii, &psi)).transpose() * &phi_n;
        for i in 0..nb {
            for k in 0..nm {
                // the size of the terms that cancel: the boundary dof's own
                // stiffness (its reduced one vanishes for a rigid motion)
                let scale = (k_bb[(i, i)].abs() * omega_squared[k]).sqrt();
                if scale > 0.0 {
                    report.coupling_orthogonality = report
                        .coupling_orthogonality
                        .max(coupling[(i, k)].abs() / scale);
                }
            }
        }
        let worst = report
            .mass_orthogonality
            .max(report.stiffness_orthogonality)
            .max(report.coupling_orthogonality);
        if worst.is_nan() || worst > ORTHOGONALITY_TOLERANCE {
            return Err(ReductionError::Orthogonality(format!(
                "Φ_NᵀMΦ_N − I: {:.3e}, Φ_NᵀKΦ_N − Ω²: {:.3e}, constraint against fixed-interface modes: {:.3e} (tolerance {ORTHOGONALITY_TOLERANCE:e})",
                report.mass_orthogonality, report.stiffness_orthogonality, report.coupling_orthogonality
            )));
        }
    }

    // the boundary stiffness with the frame node held: positive definite
    let y_columns: Vec<usize> = (0..boundary.len())
        .filter(|&k| k != settings.frame)
        .flat_map(|k| 6 * k..6 * k + 6)
        .chain(nb..ncb)
        .collect();
    let elastic_b: Vec<usize> = y_columns.iter().copied().filter(|&c| c < nb).collect();
    if !elastic_b.is_empty() {
        let kb = DMatrix::from_fn(elastic_b.len(), elastic_b.len(), |i, j| {
            k_bar_bb[(elastic_b[i], elastic_b[j])]
        });
        let d: Vec<f64> = (0..kb.nrows()).map(|i| kb[(i, i)]).collect();
        let smallest = if d.iter().all(|&v| v > 0.0 && v.is_finite()) {
            let scaled = DMatrix::from_fn(kb.nrows(), kb.ncols(), |i, j| {
                kb[(i, j)] / (d[i] * d[j]).sqrt()
            });
            scaled
                .symmetric_eigenvalues()
                .iter()
                .fold(f64::INFINITY, |a, &b| a.min(b))
        } else {
            d.iter().fold(f64::INFINITY, |a, &b| a.min(b))
        };
        if smallest.is_nan() || smallest <= SINGULAR_BOUNDARY {
            return Err(ReductionError::SingularBoundary {
                frame: body.node_ids[boundary[settings.frame]],
                value: smallest,
            });
        }
    }
    let ny = y_columns.len();
    let stiffness_y = DMatrix::from_fn(ny, ny, |i, j| {
        reduced_stiffness[(y_columns[i], y_columns[j])]
    });

    // modal damping 2 ζ ω on the modes
    let ratios = &settings.damping_ratios;
    let ratio = |k: usize| -> Result<f64, ReductionError> {
        match ratios.len() {
            0 => Ok(0.0),
            1 => Ok(ratios[0]),
            l if l == nm => Ok(ratios[k]),
            l => Err(ReductionError::DampingRatios {
                given: l,
                modes: nm,
            }),
        }
    };
    let mut damping_y = DVector::zeros(ny);
    for k in 0..nm {
        damping_y[ny - nm + k] = 2.0 * ratio(k)? * omega_squared[k].sqrt();
    }

    // largest nodal translation of each mode
    let mode_lengths: Vec<f64> = (0..nm)
        .map(|k| {
            let mut t = vec![Vec3::zeros(); body.node_ids.len()];
            for (r, &(node, c)) in body.dofs.iter().enumerate() {
                if c < 3 {
                    t[node][c] = basis[(r, nb + k)];
                }
            }
            t.iter().fold(0.0f64, |a, v| a.max(v.norm()))
        })
        .collect();

    // frequencies of the reduced body against the full model's
    report.clamped = omega_squared
        .iter()
        .zip(reduced_frequencies(
            &reduced_stiffness.view((nb, nb), (nm, nm)).into_owned(),
            &reduced_mass.view((nb, nb), (nm, nm)).into_owned(),
        )?)
        .map(|(&full, reduced)| FrequencyPair {
            full: hz(full),
            reduced,
        })
        .collect();
    // the rigid-body motions leave the body unstrained
    let origin = body.positions[boundary[settings.frame]];
    let gamma = rigid_modes(&body, &origin);
    let k_gamma = sparse_times(&body.stiffness, &gamma);
    let abs_k = {
        let mut a = body.stiffness.clone();
        a.values_mut().iter_mut().for_each(|v| *v = v.abs());
        a
    };
    let abs_gamma = gamma.map(f64::abs);
    let ak_gamma = sparse_times(&abs_k, &abs_gamma);
    report.rigid_body_residual = (0..6)
        .map(|j| {
            let scale = ak_gamma.column(j).norm();
            if scale > 0.0 {
                k_gamma.column(j).norm() / scale
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max);

    // free-free: a free body's six rigid-body motions (the boundary dofs
    // moving rigidly, the modes still) are taken out of the reduced
    // pencil exactly, where round-off of K_BB + K_BI Ψ would leave them at
    // ~1e-8 of ω² instead of zero
    let rigid = (report.rigid_body_residual <= FREE_BODY).then(|| {
        DMatrix::from_fn(
            ncb,
            6,
            |i, j| if i < nb { gamma[(b_rows[i], j)] } else { 0.0 },
        )
    });
    let free = free_frequencies(&reduced_stiffness, &reduced_mass, rigid.as_ref())?;
    report.free_zero_modes = free.0;
    if settings.compare_free_free && !free.1.is_empty() {
        let top = omega_squared.last().map_or(f64::INFINITY, |&w| hz(w));
        let kept: Vec<f64> = free.1.iter().copied().filter(|&f| f <= top).collect();
        let want = kept.len().max(1).min(free.1.len());
        let full = full_free_frequencies(&body, free.0 + want)?;
        report.free = full
            .iter()
            .zip(&free.1[..want])
            .map(|(&full, &reduced)| FrequencyPair { full, reduced })
            .collect();
    }

    // inertia invariants
    let mass_matrix = match settings.inertia {
        InertiaModel::Consistent => body.mass.clone(),
        InertiaModel::Lumped => lumped_mass(&body),
    };
    let phi_y = DMatrix::from_fn(n, ny, |r, j| basis[(r, y_columns[j])]);
    let invariants = invariants(&body, &mass_matrix, &gamma, &phi_y);
    report.mass = invariants.mass;

    // keep the mesh, not the matrices
    body.stiffness = from_triplets(0, &[]);
    body.mass = from_triplets(0, &[]);
    report.seconds = started.elapsed().as_secs_f64();
    Ok(ReducedBody {
        body,
        boundary: boundary.clone(),
        frame: settings.frame,
        omega_squared,
        basis,
        reduced_stiffness,
        reduced_mass,
        y_columns,
        stiffness_y,
        damping_y,
        mode_lengths,
        invariants,
        inertia: settings.inertia,
        report,
    })
}

/// `f = ω/2π` of `ω²`.
fn hz(omega_squared: f64) -> f64 {
    omega_squared.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// The lowest `count` modes of `K_II x = ω² M_II x` (all of them up to the
/// first `wanted`, when the caller needs them), refused if any is zero
/// (a mechanism with the boundary clamped).
fn fixed_interface_modes(
    pencil: &Pencil,
    count: usize,
    requested: Option<usize>,
) -> Result<Vec<eigen::Mode>, ReductionError> {
    let settings = EigenSettings::lowest(count);
    let solution = match eigen::solve(pencil, &settings) {
        Ok(s) => s,
        Err(EigenError::TooManyModes { available, .. }) => {
            if requested.is_some_and(|r| r > available) {
                return Err(ReductionError::TooManyModes {
                    requested: requested.unwrap_or(count),
                    available,
                });
            }
            if available == 0 {
                return Ok(Vec::new());
            }
            eigen::solve(
                pencil,
                &EigenSettings {
                    modes: available,
                    ..settings
                },
            )
            .map_err(ReductionError::Eigen)?
        }
        Err(EigenError::SingularPencil { .. }) => {
            return Err(ReductionError::Mechanism { zero: 1 })
        }
        Err(e) => return Err(ReductionError::Eigen(e)),
    };
    let zero = solution
        .modes
        .iter()
        .filter(|m| m.omega_squared <= 0.0)
        .count();
    if zero > 0 {
        return Err(ReductionError::Mechanism { zero });
    }
    Ok(solution.modes)
}

/// A dense symmetric matrix as a [`SparseMatrix`] with every entry.
fn dense_to_sparse(a: &DMatrix<f64>) -> SparseMatrix {
    let n = a.nrows();
    let mut s = SparseMatrix::from_pattern(
        n,
        (0..n).flat_map(|j| (0..n).map(move |i| (i, j))).collect(),
    );
    for j in 0..n {
        for i in 0..n {
            let p = s.position(i, j).expect("full pattern");
            s.values_mut()[p] = a[(i, j)];
        }
    }
    s
}

/// Frequencies (Hz) of the dense pencil `(k, m)`, every mode.
fn reduced_frequencies(k: &DMatrix<f64>, m: &DMatrix<f64>) -> Result<Vec<f64>, ReductionError> {
    Ok(reduced_frequencies_with_zero(k, m)?.1)
}

/// The number of zero modes and the frequencies (Hz) of the others of the
/// dense pencil `(k, m)` free-free: with the rigid-body motions `rigid`
/// (columns) taken out, in the `m`-orthogonal complement of them, when
/// given (six zero modes then).
fn free_frequencies(
    k: &DMatrix<f64>,
    m: &DMatrix<f64>,
    rigid: Option<&DMatrix<f64>>,
) -> Result<(usize, Vec<f64>), ReductionError> {
    let Some(r) = rigid else {
        return reduced_frequencies_with_zero(k, m);
    };
    let n = k.nrows();
    // an orthonormal basis Z of the complement of M r (Zᵀ M r = 0), by
    // Gram–Schmidt with reorthogonalisation
    let w = m * r;
    let mut basis: Vec<DVector<f64>> = Vec::with_capacity(n);
    let push = |basis: &mut Vec<DVector<f64>>, mut v: DVector<f64>| -> bool {
        let size = v.norm();
        for _ in 0..2 {
            for b in basis.iter() {
                let c = b.dot(&v);
                v.axpy(-c, b, 1.0);
            }
        }
        let left = v.norm();
        if left > 1e-8 * size && left > 0.0 {
            basis.push(v / left);
            true
        } else {
            false
        }
    };
    let mut rank = 0;
    for j in 0..w.ncols() {
        rank += usize::from(push(&mut basis, w.column(j).into_owned()));
    }
    for i in 0..n {
        if basis.len() == n {
            break;
        }
        push(
            &mut basis,
            DVector::from_fn(n, |r, _| if r == i { 1.0 } else { 0.0 }),
        );
    }
    let z = DMatrix::from_columns(&basis[rank..]);
    let kz = z.transpose() * k * &z;
    let mz = z.transpose() * m * &z;
    let (zero, f) = reduced_frequencies_with_zero(
        &((&kz + kz.transpose()) * 0.5),
        &((&mz + mz.transpose()) * 0.5),
    )?;
    Ok((zero + rank, f))
}

/// The number of zero modes and the frequencies (Hz) of the others of the
/// dense pencil `(k, m)`.
fn reduced_frequencies_with_zero(
    k: &DMatrix<f64>,
    m: &DMatrix<f64>,
) -> Result<(usize, Vec<f64>), ReductionError> {
    let n = k.nrows();
    if n == 0 {
        return Ok((0, Vec::new()));
    }
    let (ks, ms) = (dense_to_sparse(k), dense_to_sparse(m));
    let multiplier = vec![false; n];
    let pencil = Pencil {
        stiffness: &ks,
        mass: &ms,
        multiplier: &multiplier,
    };
    let settings = EigenSettings {
        method: Method::Dense,
        ..EigenSettings::lowest(n)
    };
    let solution = match eigen::solve(&pencil, &settings) {
        Err(EigenError::TooManyModes { available, .. }) => eigen::solve(
            &pencil,
            &EigenSettings {
                modes: available,
                ..settings
            },
        ),
        other => other,
    }
    .map_err(ReductionError::Eigen)?;
    let zero = solution.modes.iter().filter(|m| m.is_zero()).count();
    Ok((
        zero,
        solution
            .modes
            .iter()
            .filter(|m| !m.is_zero())
            .map(|m| hz(m.omega_squared))
            .collect(),
    ))
}

/// The largest body whose free-free frequencies are computed with the
/// dense solver (0.1 s at 702 dofs) rather than by Lanczos, which may not
/// separate the six zero modes just below its shift from the modes just
/// above (a 702-dof shell panel: 6 of 8 modes after 200 restarts, 1 s).
const DENSE_FALLBACK: usize = 1500;

/// The frequencies (Hz) of the lowest `count` modes of the full body
/// free-free, zero modes left out.
fn full_free_frequencies(body: &FlexibleBody, count: usize) -> Result<Vec<f64>, ReductionError> {
    let n = body.n_dofs();
    let multiplier = vec![false; n];
    let pencil = Pencil {
        stiffness: &body.stiffness,
        mass: &body.mass,
        multiplier: &multiplier,
    };
    let settings = EigenSettings {
        method: if n <= DENSE_FALLBACK {
            Method::Dense
        } else {
            Method::Auto
        },
        ..EigenSettings::lowest(count.min(n))
    };
    let solution = match eigen::solve(&pencil, &settings) {
        Err(EigenError::TooManyModes { available, .. }) => eigen::solve(
            &pencil,
            &EigenSettings {
                modes: available,
                ..settings
            },
        ),
        // six zero modes (rigid motions) just below the shift, the modes
        // asked just above: the Ritz values may not separate them (a
        // 702-dof shell panel, 200 restarts); the dense solver for a body
        // small enough, a longer basis otherwise
        Err(EigenError::NotConverged { .. }) => {
            let method = if n <= DENSE_FALLBACK {
                Method::Dense
            } else {
                Method::Lanczos
            };
            eigen::solve(
                &pencil,
                &EigenSettings {
                    method,
                    basis_size: Some(4 * settings.modes + 40),
                    ..settings
                },
            )
        }
        other => other,
    }
    .map_err(ReductionError::Eigen)?;
    Ok(solution
        .modes
        .iter()
        .filter(|m| !m.is_zero())
        .map(|m| hz(m.omega_squared))
        .collect())
}

/// The inertia invariants of [`Invariants`] from the mass matrix `m`, the
/// rigid-body modes `gamma` about the frame node and the elastic basis
/// `phi_y`.
fn invariants(
    body: &FlexibleBody,
    m: &SparseMatrix,
    gamma: &DMatrix<f64>,
    phi_y: &DMatrix<f64>,
) -> Invariants {
    let (n, ny) = (body.n_dofs(), phi_y.ncols());
    let nz = 6 + ny;
    let mut b = DMatrix::zeros(n, nz);
    b.view_mut((0, 0), (n, 6)).copy_from(gamma);
    b.view_mut((0, 6), (n, ny)).copy_from(phi_y);
    let mb = sparse_times(m, &b);
    let mut m0 = b.transpose() * &mb;
    m0 = (&m0 + m0.transpose()) * 0.5;

    // Φ_k = e_k × (translations of Φ_y), zero on the rotations
    let rows = body.dof_rows();
    let mut phi_k: [DMatrix<f64>; 3] = std::array::from_fn(|_| DMatrix::zeros(n, ny));
    for r in &rows {
        for j in 0..ny {
            let t = Vec3::from_fn(|c, _| r[c].map_or(0.0, |row| phi_y[(row, j)]));
            if t == Vec3::zeros() {
                continue;
            }
            for (k, pk) in phi_k.iter_mut().enumerate() {
                let w = Vec3::ith(k, 1.0).cross(&t);
                for c in 0..3 {
                    if let Some(row) = r[c] {
                        pk[(row, j)] = w[c];
                    }
                }
            }
        }
    }
    let m_phi_k: [DMatrix<f64>; 3] = std::array::from_fn(|k| sparse_times(m, &phi_k[k]));
    let d: [DMatrix<f64>; 3] = std::array::from_fn(|k| b.transpose() * &m_phi_k[k]);
    let h: [[DMatrix<f64>; 3]; 3] =
        std::array::from_fn(|k| std::array::from_fn(|l| phi_k[k].transpose() * &m_phi_k[l]));
    let mass = (m0[(0, 0)] + m0[(1, 1)] + m0[(2, 2)]) / 3.0;
    // 𝕄₀[v̄, ω] = −(m c₀)~ for a mass matrix with the rigid motions exact
    let c = m0.view((0, 3), (3, 3)).into_owned();
    let first_moment = -Vec3::new(
        0.5 * (c[(2, 1)] - c[(1, 2)]),
        0.5 * (c[(0, 2)] - c[(2, 0)]),
        0.5 * (c[(1, 0)] - c[(0, 1)]),
    );
    Invariants {
        m0,
        d,
        h,
        mass,
        first_moment,
    }
}
