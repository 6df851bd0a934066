//! Validation of the eigen-solvers of modal analysis (`src/eigen.rs`,
//! docs/theory.md §14) against closed-form spectra of spring–mass chains,
//! with supports, constraints, massless unknowns and rigid-body modes, and
//! the dense solver against Lanczos on a beam-like finite-element pencil.
//!
//! Closed forms (e.g. Géradin & Rixen, *Mechanical Vibrations*, 3rd ed.,
//! §4.7; any text on lattice vibrations): a chain of `n` masses `m` joined
//! by `n + 1` springs `k`, both ends fixed, has
//! `ω_j = 2 √(k/m) sin(jπ / (2(n + 1)))`, `j = 1..n`; with both ends free
//! (`n − 1` springs), `ω_j = 2 √(k/m) sin(jπ / (2n))`, `j = 0..n−1`.

use unfold::eigen::{
    solve, solve_dense, solve_lanczos, EigenError, EigenSettings, Method, ModalSolution, Pencil,
};
use unfold::linalg::SparseMatrix;

mod pencils;
use pencils::{beam, chain, sparse, spring};

/// `ω_j²` of the fixed–fixed chain (`j = 1..=n`) or the free–free chain
/// (`j = 0..n`, shifted by one).
fn chain_omega2(n: usize, k: f64, m: f64, fixed: bool, j: usize) -> f64 {
    let s = if fixed {
        (j as f64 * std::f64::consts::PI / (2.0 * (n + 1) as f64)).sin()
    } else {
        (j as f64 * std::f64::consts::PI / (2.0 * n as f64)).sin()
    };
    4.0 * k / m * s * s
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// `max |XᵀMX − I|` over the unknowns' entries of the modes.
fn orthonormality(sol: &ModalSolution, m: &SparseMatrix, multiplier: &[bool]) -> f64 {
    let mut worst = 0.0f64;
    let mut mx = vec![0.0; m.dim()];
    let unknowns = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .zip(multiplier)
            .map(|(&x, &q)| if q { 0.0 } else { x })
            .collect()
    };
    for (i, a) in sol.modes.iter().enumerate() {
        let xa = unknowns(&a.shape);
        m.mul_vec(&xa, &mut mx);
        for (j, b) in sol.modes.iter().enumerate() {
            let xb = unknowns(&b.shape);
            let d: f64 = xb.iter().zip(&mx).map(|(p, q)| p * q).sum();
            let e = if i == j { d - 1.0 } else { d };
            worst = worst.max(e.abs());
        }
    }
    worst
}

fn settings(modes: usize, method: Method) -> EigenSettings {
    EigenSettings {
        method,
        ..EigenSettings::lowest(modes)
    }
}

fn residuals_pass(sol: &ModalSolution, tol: f64) {
    for (i, mode) in sol.modes.iter().enumerate() {
        assert!(
            mode.residual <= tol + 16.0 * mode.round_off,
            "mode {i}: residual {:.3e}, round-off {:.3e}",
            mode.residual,
            mode.round_off
        );
    }
}

#[test]
fn fixed_chain_matches_the_closed_form() {
    // dense: every mode of a 60-mass chain; Lanczos: the first 20 of 500
    let (k, m) = (3.0e4, 2.5);
    let (kk, mm, mult) = chain(60, k, m, true);
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &mult,
    };
    let dense = solve_dense(&p, &settings(60, Method::Dense)).unwrap();
    assert_eq!(dense.zero_modes, 0);
    assert_eq!(dense.infinite_modes, Some(0));
    let mut worst = 0.0f64;
    for (j, mode) in dense.modes.iter().enumerate() {
        worst = worst.max(relative(
            mode.omega_squared,
            chain_omega2(60, k, m, true, j + 1),
        ));
    }
    // closed form to 1e-10 relative (round-off is ~1e-14 here)
    assert!(worst < 1e-10, "dense: {worst:e}");
    assert!(orthonormality(&dense, &mm, &mult) < 1e-10);
    residuals_pass(&dense, 1e-10);

    let (kk, mm, mult) = chain(500, k, m, true);
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &mult,
    };
    let lanczos = solve_lanczos(&p, &settings(20, Method::Lanczos)).unwrap();
    assert_eq!(lanczos.modes.len(), 20);
    let mut worst = 0.0f64;
    for (j, mode) in lanczos.modes.iter().enumerate() {
        worst = worst.max(relative(
            mode.omega_squared,
            chain_omega2(500, k, m, true, j + 1),
        ));
    }
    // closed form to 1e-10 relative
    assert!(worst < 1e-10, "Lanczos: {worst:e}");
    assert!(orthonormality(&lanczos, &mm, &mult) < 1e-10);
    residuals_pass(&lanczos, 1e-10);
}

#[test]
fn free_chain_has_one_zero_mode() {
    let (k, m, n) = (7.0, 0.3, 200);
    let (kk, mm, mult) = chain(n, k, m, false);
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &mult,
    };
    for method in [Method::Dense, Method::Lanczos] {
        let sol = solve(&p, &settings(12, method)).unwrap();
        // the rigid translation is reported as exactly zero, and only it
        assert_eq!(sol.zero_modes, 1, "{method:?}");
        assert_eq!(sol.modes[0].omega_squared, 0.0, "{method:?}");
        // its shape is the uniform translation, M-normalised: 1/√(n m)
        let u = 1.0 / ((n as f64) * m).sqrt();
        for x in &sol.modes[0].shape {
            assert!((x.abs() - u).abs() < 1e-10 * u, "{method:?}");
        }
        for j in 1..12 {
            let e = relative(sol.modes[j].omega_squared, chain_omega2(n, k, m, false, j));
            // closed form to 1e-10 relative
            assert!(e < 1e-10, "{method:?} mode {j}: {e:e}");
        }
        assert!(orthonormality(&sol, &mm, &mult) < 1e-10, "{method:?}");
        residuals_pass(&sol, 1e-10);
    }
}

/// Two chains tied by a constraint row: chain A (ground–a₁–…–a_p, its
/// last mass m/2) and chain B (b₁–…–b_p–ground, its first mass m/2) with
/// `a_p = b₁`, in the augmented-Lagrangian saddle form of the joints
/// (rows `−k B`, `p BᵀB` in the tangent), the multiplier numbered between
/// them and a non-symmetric part added to the tangent: the fixed–fixed
/// chain of `2p − 1` masses.
fn tied_chains(
    p: usize,
    k: f64,
    m: f64,
    scale: f64,
    penalty: f64,
    skew: f64,
) -> (SparseMatrix, SparseMatrix, Vec<bool>) {
    // numbering: a_1..a_p = 0..p, multiplier = p, b_1..b_p = p+1..2p+1
    let n = 2 * p + 1;
    let a = |i: usize| i;
    let b = |i: usize| p + 1 + i;
    let lam = p;
    let mut kt = Vec::new();
    spring(&mut kt, None, Some(a(0)), k);
    for i in 0..p - 1 {
        spring(&mut kt, Some(a(i)), Some(a(i + 1)), k);
        spring(&mut kt, Some(b(i)), Some(b(i + 1)), k);
    }
    spring(&mut kt, Some(b(p - 1)), None, k);
    // Φ = x_{a_p} − x_{b_1}: rows −k B, and p BᵀB
    let (ia, ib) = (a(p - 1), b(0));
    for (i, s) in [(ia, 1.0), (ib, -1.0)] {
        kt.push((lam, i, -scale * s));
        kt.push((i, lam, -scale * s));
    }
    spring(&mut kt, Some(ia), Some(ib), penalty);
    // a non-symmetric part (as in a tangent away from equilibrium): the
    // solvers use the symmetric part
    for i in 0..p - 1 {
        kt.push((a(i), a(i + 1), skew));
        kt.push((a(i + 1), a(i), -skew));
    }
    let mut mt = Vec::new();
    for i in 0..p {
        mt.push((a(i), a(i), if i == p - 1 { 0.5 * m } else { m }));
        mt.push((b(i), b(i), if i == 0 { 0.5 * m } else { m }));
    }
    let mut mult = vec![false; n];
    mult[lam] = true;
    (sparse(n, &kt), sparse(n, &mt), mult)
}

#[test]
fn tied_chains_are_one_chain() {
    let (p, k, m) = (40, 12.0, 0.8);
    let n_single = 2 * p - 1;
    for (scale, penalty, skew) in [(1.0, 0.0, 0.0), (1e3, 5e4, 0.0), (1.0, 0.0, 3.0)] {
        let (kk, mm, mult) = tied_chains(p, k, m, scale, penalty, skew);
        let pencil = Pencil {
            stiffness: &kk,
            mass: &mm,
            multiplier: &mult,
        };
        for method in [Method::Dense, Method::Lanczos] {
            let sol = solve(&pencil, &settings(15, method)).unwrap();
            for (j, mode) in sol.modes.iter().enumerate() {
                let e = relative(
                    mode.omega_squared,
                    chain_omega2(n_single, k, m, true, j + 1),
                );
                // the single chain's closed form to 1e-10 relative,
                // whatever the scaling k and the penalty p of the
                // constraint, and with the non-symmetric part
                assert!(
                    e < 1e-10,
                    "{method:?} k={scale} p={penalty} mode {j}: {e:e}"
                );
                // the constraint holds: x_{a_p} = x_{b_1}
                let (xa, xb) = (mode.shape[p - 1], mode.shape[p + 1]);
                assert!((xa - xb).abs() < 1e-12, "{method:?}: {xa} {xb}");
            }
            if method == Method::Dense {
                assert_eq!(sol.constraint_rank, 1);
            }
            assert!(orthonormality(&sol, &mm, &mult) < 1e-10);
            residuals_pass(&sol, 1e-10);
            // the multiplier is the force in the tie: Kx + Bᵀμ = ω²Mx at
            // a_p, with the row −k B: −k μ = ω² (m/2) x_{a_p} − k (x_{a_p}
            // − x_{a_{p−1}}) (the penalty adds nothing, x_{a_p} = x_{b_1})
            // (the second mode: in the first, symmetric about the tie, the
            // tie carries nothing)
            let mode = &sol.modes[1];
            let x = &mode.shape;
            let kx_ap = k * (x[p - 1] - x[p - 2]);
            let force = mode.omega_squared * 0.5 * m * x[p - 1] - kx_ap;
            let mu = x[p];
            assert!(
                (-scale * mu - force).abs() < 1e-8 * force.abs().max(1e-300),
                "{method:?}: −kμ = {}, force {force}",
                -scale * mu
            );
        }
    }
}

/// A fixed–fixed chain whose masses `m` alternate with massless nodes
/// (the first and the last node massless): static condensation of each
/// massless node turns two springs `k` into one `k/2`, so the `n` massive
/// nodes form the chain of springs `k/2`.
#[test]
fn massless_unknowns_are_condensed() {
    let (k, m, n) = (5.0e3, 1.2, 50);
    let total = 2 * n + 1;
    let mut kt = Vec::new();
    spring(&mut kt, None, Some(0), k);
    for i in 0..total - 1 {
        spring(&mut kt, Some(i), Some(i + 1), k);
    }
    spring(&mut kt, Some(total - 1), None, k);
    let mt: Vec<_> = (0..n).map(|i| (2 * i + 1, 2 * i + 1, m)).collect();
    let (kk, mm) = (sparse(total, &kt), sparse(total, &mt));
    let mult = vec![false; total];
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &mult,
    };
    for method in [Method::Dense, Method::Lanczos] {
        let sol = solve(&p, &settings(20, method)).unwrap();
        if method == Method::Dense {
            // the n + 1 massless nodes are infinite frequencies
            assert_eq!(sol.infinite_modes, Some(n + 1));
        }
        for (j, mode) in sol.modes.iter().enumerate() {
            let e = relative(mode.omega_squared, chain_omega2(n, 0.5 * k, m, true, j + 1));
            // closed form of the condensed chain to 1e-10 relative
            assert!(e < 1e-10, "{method:?} mode {j}: {e:e}");
        }
        assert!(orthonormality(&sol, &mm, &mult) < 1e-10);
        residuals_pass(&sol, 1e-10);
    }
}

#[test]
fn dense_and_lanczos_agree_on_a_beam_pencil() {
    for (pinned, supported, zero) in [(true, true, 0), (true, false, 1), (false, false, 3)] {
        // 200 elements: 603 unknowns, 1 to 4 constraints; without the
        // last support the beam turns freely about its pin (one mechanism
        // mode), without the pin it is free (three rigid-body modes)
        let (kk, mm, mult) = beam(200, pinned, supported, 7);
        let p = Pencil {
            stiffness: &kk,
            mass: &mm,
            multiplier: &mult,
        };
        let dense = solve(&p, &settings(10, Method::Dense)).unwrap();
        let lanczos = solve(&p, &settings(10, Method::Lanczos)).unwrap();
        assert_eq!(dense.zero_modes, zero);
        assert_eq!(lanczos.zero_modes, zero);
        for (j, (a, b)) in dense.modes.iter().zip(&lanczos.modes).enumerate() {
            if j < zero {
                continue;
            }
            let e = relative(b.omega_squared, a.omega_squared);
            // the two solvers to 1e-8 relative on the first 10 modes
            assert!(e < 1e-8, "supported {supported}, mode {j}: {e:e}");
            // and the same shapes (up to sign) to 1e-6 of their size
            let sign = a
                .shape
                .iter()
                .zip(&b.shape)
                .map(|(x, y)| x * y)
                .sum::<f64>()
                .signum();
            let size = a.shape.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let diff = a
                .shape
                .iter()
                .zip(&b.shape)
                .zip(&mult)
                .filter(|(_, &q)| !q)
                .fold(0.0f64, |m, ((x, y), _)| m.max((x - sign * y).abs()));
            assert!(diff < 1e-6 * size, "mode {j}: {diff:e}");
        }
        for sol in [&dense, &lanczos] {
            assert!(orthonormality(sol, &mm, &mult) < 1e-10);
            residuals_pass(sol, 1e-10);
        }
    }
}

#[test]
fn lanczos_finds_the_modes_nearest_an_inner_shift() {
    // a shift between modes 30 and 31 of the fixed chain: the 8 nearest
    let (k, m, n) = (1.0, 1.0, 300);
    let (kk, mm, mult) = chain(n, k, m, true);
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &mult,
    };
    let exact: Vec<f64> = (1..=n).map(|j| chain_omega2(n, k, m, true, j)).collect();
    let sigma = 0.5 * (exact[29] + exact[30]);
    let sol = solve_lanczos(
        &p,
        &EigenSettings {
            shift: Some(sigma),
            ..settings(8, Method::Lanczos)
        },
    )
    .unwrap();
    let mut nearest = exact.clone();
    nearest.sort_by(|a, b| (a - sigma).abs().total_cmp(&(b - sigma).abs()));
    let mut nearest = nearest[..8].to_vec();
    nearest.sort_by(f64::total_cmp);
    for (mode, e) in sol.modes.iter().zip(&nearest) {
        // closed form to 1e-10 relative
        assert!(relative(mode.omega_squared, *e) < 1e-10);
    }
}

#[test]
fn bad_pencils_are_errors() {
    // a massless node without stiffness: a massless mechanism
    let (kk, _, mult) = chain(3, 1.0, 1.0, true);
    let k2 = sparse(4, &kk.entries().collect::<Vec<_>>());
    let m2 = sparse(4, &[(0, 0, 1.0), (1, 1, 1.0), (2, 2, 1.0)]);
    let mult2 = vec![false; 4];
    let p = Pencil {
        stiffness: &k2,
        mass: &m2,
        multiplier: &mult2,
    };
    assert!(matches!(
        solve_dense(&p, &settings(2, Method::Dense)),
        Err(EigenError::SingularPencil { .. })
    ));
    assert!(matches!(
        solve_lanczos(&p, &settings(2, Method::Lanczos)),
        Err(EigenError::Solve { .. })
    ));
    // more modes than the model has
    let (kk, mm, _) = chain(3, 1.0, 1.0, true);
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &mult,
    };
    for method in [Method::Dense, Method::Lanczos] {
        assert!(matches!(
            solve(&p, &settings(4, method)),
            Err(EigenError::TooManyModes {
                requested: 4,
                available: 3
            })
        ));
    }
    // no mass; a negative mass; mismatched sizes; a NaN
    let zero = sparse(3, &[]);
    let negative = sparse(3, &[(0, 0, 1.0), (1, 1, -1.0)]);
    for mass in [&zero, &negative] {
        let p = Pencil {
            stiffness: &kk,
            mass,
            multiplier: &mult,
        };
        assert!(matches!(
            solve(&p, &settings(1, Method::Auto)),
            Err(EigenError::Mass(_))
        ));
    }
    let short = vec![false; 2];
    let p = Pencil {
        stiffness: &kk,
        mass: &mm,
        multiplier: &short,
    };
    assert!(matches!(
        solve(&p, &settings(1, Method::Auto)),
        Err(EigenError::InvalidInput(_))
    ));
    let nan = sparse(3, &[(0, 0, f64::NAN)]);
    let p = Pencil {
        stiffness: &nan,
        mass: &mm,
        multiplier: &mult,
    };
    assert!(matches!(
        solve(&p, &settings(1, Method::Auto)),
        Err(EigenError::InvalidInput(_))
    ));
}
