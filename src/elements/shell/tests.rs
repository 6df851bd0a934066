//! Checks of the shell element: its tangent and mass against finite
//! differences, its rigid-body modes, the MacNeal–Harder patch tests
//! (membrane and bending, thin and thick) on the distorted five-element
//! patch, invariance under a rotation of the whole element, and the
//! refusal of bad quadrilaterals.

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

use super::mitc4::Geometry;
use super::*;
use crate::elements::laminate::{Laminate, LayerRole, Ply, PlyMaterial};
use crate::elements::testing::{eval_all, motion, rate_errors, scaled_tangent_error, set_motion};
use crate::elements::Need;

fn ctx(gravity: Vec3) -> EvalContext<'static> {
    EvalContext {
        time: 1.0,
        curves: &[],
        gravity,
        need: Need::STIFFNESS,
        dynamics: false,
        scaling: Default::default(),
    }
}

/// An unsymmetric stack, carbon/epoxy at 0° and 45° on an aluminium
/// layer: every block of `A, B, D, H` and of the mass (`ρ₁ ≠ 0`) is
/// filled.
fn coupled_laminate() -> Arc<Laminate> {
    let m = PlyMaterial::orthotropic(181e9, 10.3e9, 0.28, 7.17e9, 7.17e9, 3.78e9, 1600.0).unwrap();
    let al = PlyMaterial::isotropic(70e9, 0.33, 2800.0).unwrap();
    let deg = std::f64::consts::PI / 180.0;
    Arc::new(
        Laminate::stack(&[
            Ply::new(m, 0.5e-3, 0.0),
            Ply::new(m, 0.25e-3, 45.0 * deg),
            Ply::new(al, 1.0e-3, 90.0 * deg),
        ])
        .unwrap(),
    )
}

/// A distorted quadrilateral (corner 2 of the MacNeal–Harder patch,
/// scaled), tilted out of the x–y plane, with node frames turned
/// arbitrarily.
fn distorted(lam: Arc<Laminate>) -> Shell {
    let tilt = so3::exp_matrix(&Vec3::new(0.3, -0.2, 0.5));
    let x = [[0.24, 0.0], [0.24, 0.12], [0.16, 0.08], [0.18, 0.03]]
        .map(|[a, b]| tilt * Vec3::new(a, b, 0.0));
    let q = [
        Vec3::new(0.1, 0.2, -0.3),
        Vec3::zeros(),
        Vec3::new(-1.0, 0.5, 2.0),
        Vec3::new(0.0, 0.0, 1.2),
    ]
    .map(|p| so3::exp(&p));
    Shell::new(7, [0, 1, 2, 3], x, q, Some(Vec3::new(1.0, 0.3, 0.0)), lam).unwrap()
}

fn state_of(shell: &Shell) -> State {
    State::at_rest(0.0, shell.reference_x.to_vec(), shell.reference_q.to_vec())
}

fn small_vec(max: f64) -> impl Strategy<Value = Vec3> {
    (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// The tangent (S8) is the derivative of the residual along the
    /// update `R ← R exp(ΔΘ~)`: central differences (h = 1e-6) agree to
    /// 1e-6 relative, entry by entry against its row and column scales,
    /// at displaced states with node rotations up to 0.5 rad from the
    /// reference (where `T⁻¹(ψ)` is far from the identity), under
    /// gravity, for a fully coupled unsymmetric laminate.
    #[test]
    fn tangent_matches_finite_differences(
        u in prop::array::uniform4(small_vec(0.01)),
        r in prop::array::uniform4(small_vec(0.3)),
    ) {
        let shell = distorted(coupled_laminate());
        let mut s = state_of(&shell);
        for i in 0..4 {
            s.displace_node(i, &u[i], &r[i]);
        }
        let e = scaled_tangent_error(&shell, &ctx(Vec3::new(1.0, -2.0, -9.81)), &s, 1e-6);
        prop_assert!(e < 1e-6, "tangent error {e:e}");
    }

    /// In dynamics the inertia forces `M a` join the residual: the
    /// inertia matrix with weights (0, 1) is their derivative in the
    /// accelerations (the consistent mass, S6), the damping part (1, 0)
    /// is zero as is the derivative in the velocities, and the stiffness
    /// is still the derivative in q; central differences, 1e-6 relative
    /// (steps of 10 in the rates: the residual is linear in them, and the
    /// static forces, 1e5 times the inertia forces here, leave a smaller
    /// step to round-off).
    #[test]
    fn mass_matches_finite_differences(
        u in prop::array::uniform4(small_vec(0.01)),
        r in prop::array::uniform4(small_vec(0.03)),
        m in prop::array::uniform4(motion()),
    ) {
        let shell = distorted(coupled_laminate());
        let mut s = state_of(&shell);
        for i in 0..4 {
            s.displace_node(i, &u[i], &r[i]);
            set_motion(&mut s, i, &m[i]);
        }
        let cx = EvalContext { dynamics: true, ..ctx(Vec3::new(0.0, 0.0, -9.81)) };
        let (ev, ea) = rate_errors(&shell, &cx, &s, 10.0, 10.0);
        prop_assert!(ev < 1e-6, "∂r/∂v: {ev:e}");
        prop_assert!(ea < 1e-6, "∂r/∂v̇: {ea:e}");
        let eq = scaled_tangent_error(&shell, &cx, &s, 1e-6);
        prop_assert!(eq < 1e-6, "∂r/∂q: {eq:e}");
    }
}

/// The residual is `K d − f_g` with `d = (x − X, log(R₀ᵀR))` at a state
/// with rotations (S7), to round-off; the strain energy is `½ dᵀ K d` and
/// the weight potential `−m g·X_c − f_g·d`, whose gradient in `d` is the
/// weight's share of the residual.
#[test]
fn residual_is_linear_in_the_displacements() {
    let shell = distorted(coupled_laminate());
    let g = Vec3::new(0.5, 1.0, -9.81);
    let c = ctx(g);
    let mut s = state_of(&shell);
    for i in 0..4 {
        s.displace_node(
            i,
            &Vec3::new(0.003 * i as f64, -0.002, 0.001),
            &Vec3::new(0.01, -0.005 * i as f64, 0.02),
        );
    }
    let [r, ..] = eval_all(&shell, &c.with_need(Need::RESIDUAL), &s);
    let (d, _) = shell.unknowns(&s);
    let k = shell.stiffness_matrix();
    let expected = k * d - shell.gravity_load * g;
    let r = Vec24::from_column_slice(&r);
    assert!((r - expected).amax() <= 1e-12 * (k * d).amax());
    let energy = shell.strain_energy(&c, &s);
    assert!((energy - 0.5 * d.dot(&(k * d))).abs() <= 1e-14 * energy);
    let v0 = shell.weight_potential(&c, &state_of(&shell));
    assert!((v0 + shell.mass() * g.dot(&shell.mass_centre)).abs() <= 1e-14 * v0.abs());
    let v = shell.weight_potential(&c, &s);
    assert!((v - v0 + (shell.gravity_load * g).dot(&d)).abs() <= 1e-12 * v0.abs());
}

/// Eigenvalues of a symmetric matrix, increasing.
fn eigenvalues(k: &Mat24) -> Vec<f64> {
    let mut e: Vec<f64> = DMatrix::from_column_slice(24, 24, k.as_slice())
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .copied()
        .collect();
    e.sort_by(f64::total_cmp);
    e
}

/// A free element has exactly six zero eigenvalues (below 1e-12 of the
/// largest), the rigid motions: `K r = 0` to 1e-12 relative for the
/// three translations and the three rotations (`u = a × (X − c)`, node
/// rotations `R₀ᵀ a`); the seventh eigenvalue, the softest deformation,
/// is well above round-off (no spurious mode of the drilling rotations or
/// of the MITC4 shear).
#[test]
fn free_element_has_six_rigid_modes() {
    let lam = Arc::new(Laminate::isotropic(70e9, 0.3, 5e-3, 2700.0).unwrap());
    for shell in [distorted(lam.clone()), distorted(coupled_laminate())] {
        let k = shell.stiffness_matrix();
        let e = eigenvalues(k);
        let top = e[23];
        println!(
            "eigenvalues / largest: {:?}",
            e.iter().map(|v| v / top).collect::<Vec<_>>()
        );
        let zero = e.iter().filter(|v| v.abs() <= 1e-12 * top).count();
        assert_eq!(zero, 6);
        assert!(e[6] > 1e-9 * top, "seventh eigenvalue {:e}", e[6] / top);
        let c = shell.mass_centre;
        for a in [Vec3::x(), Vec3::y(), Vec3::z()] {
            let mut t = Vec24::zeros();
            let mut r = Vec24::zeros();
            for i in 0..4 {
                t.fixed_rows_mut::<3>(6 * i).copy_from(&a);
                let arm = shell.reference_x[i] - c;
                r.fixed_rows_mut::<3>(6 * i).copy_from(&a.cross(&arm));
                r.fixed_rows_mut::<3>(6 * i + 3)
                    .copy_from(&(shell.reference_r[i].transpose() * a));
            }
            for v in [t, r] {
                let f = k * v;
                assert!(
                    f.amax() <= 1e-12 * k.amax() * v.amax(),
                    "rigid motion loads the element: {:e}",
                    f.amax() / (k.amax() * v.amax())
                );
            }
        }
    }
}

/// The element turned and moved as a whole (positions, node frames and
/// material axis) has the same stiffness in the turned frames: `K` on
/// `(u, ψ)` transforms as `Qᵀ K' Q` with `Q` the rotation on the
/// translations and identity on the node-frame rotations, to 1e-12.
#[test]
fn stiffness_is_objective() {
    let lam = coupled_laminate();
    let a = distorted(lam.clone());
    let turn = so3::exp(&Vec3::new(-0.7, 1.1, 0.4));
    let tm = so3::matrix(&turn);
    let x = a.reference_x.map(|p| tm * p + Vec3::new(3.0, -1.0, 2.0));
    let q = a.reference_q.map(|r| turn * r);
    let axis = tm * Vec3::new(1.0, 0.3, 0.0);
    let b = Shell::new(7, [0, 1, 2, 3], x, q, Some(axis), lam).unwrap();
    let mut back = Mat24::identity();
    for i in 0..4 {
        back.fixed_view_mut::<3, 3>(6 * i, 6 * i).copy_from(&tm);
    }
    let kb = back.transpose() * b.stiffness_matrix() * back;
    let ka = a.stiffness_matrix();
    assert!((kb - ka).amax() <= 1e-12 * ka.amax());
    let mb = back.transpose() * b.mass_matrix() * back;
    let ma = a.mass_matrix();
    assert!((mb - ma).amax() <= 1e-12 * ma.amax());
}

/// The mass matrix carries the element's mass in each direction
/// (`rᵀ M r = ρ₀ A` for a unit translation `r`), its rotary inertia
/// (`ρ₂ A` for a unit rotation of every fibre about an in-plane axis,
/// `ψ = x`: `β` uniform) and the first moment `ρ₁ A` between both; and the
/// weight on a node sums to `ρ₀ A g`.
#[test]
fn mass_matrix_moments() {
    let shell = distorted(coupled_laminate());
    let lam = shell.laminate();
    let m = shell.mass_matrix();
    let area = shell.area();
    let e = shell.axes;
    let mut t = Vec24::zeros();
    let mut r = Vec24::zeros();
    for i in 0..4 {
        t.fixed_rows_mut::<3>(6 * i).copy_from(&e.column(0));
        // θy = 1 in the element's axes: βx = 1
        r.fixed_rows_mut::<3>(6 * i + 3)
            .copy_from(&(shell.reference_r[i].transpose() * e.column(1)));
    }
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(t.dot(&(m * t)), lam.mass_per_area() * area) < 1e-13);
    assert!(rel(r.dot(&(m * r)), lam.rotary_inertia() * area) < 1e-13);
    assert!(rel(t.dot(&(m * r)), lam.first_moment() * area) < 1e-12);
    let g = Vec3::new(0.0, 0.0, -9.81);
    let w = shell.gravity_load * g;
    let total: Vec3 = (0..4).map(|i| Vec3::from(w.fixed_rows::<3>(6 * i))).sum();
    assert!((total - g * shell.mass()).norm() <= 1e-13 * shell.mass() * 9.81);
}

// ---------- the MacNeal–Harder patch (MacNeal & Harder, A proposed
// standard set of problems to test finite element accuracy, Finite
// Elements in Analysis and Design 1, 1985, fig. 2) ----------

/// Corners and interior nodes of the patch, 0.24 × 0.12.
const PATCH_NODES: [[f64; 2]; 8] = [
    [0.0, 0.0],
    [0.24, 0.0],
    [0.24, 0.12],
    [0.0, 0.12],
    [0.04, 0.02],
    [0.18, 0.03],
    [0.16, 0.08],
    [0.08, 0.08],
];

/// The five elements (node indices, counterclockwise).
const PATCH_ELEMENTS: [[usize; 4]; 5] = [
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
    [4, 5, 6, 7],
];

/// The patch of `lam` (E = 1e6, ν = 0.25 in the tests), in the x–y plane.
fn patch(lam: &Arc<Laminate>) -> Vec<Shell> {
    PATCH_ELEMENTS
        .iter()
        .enumerate()
        .map(|(k, n)| {
            let x = n.map(|i| Vec3::new(PATCH_NODES[i][0], PATCH_NODES[i][1], 0.0));
            Shell::new(
                k as Id + 1,
                *n,
                x,
                [Rotation::identity(); 4],
                None,
                lam.clone(),
            )
            .unwrap()
        })
        .collect()
}

/// Solves the patch with every unknown of the corners 0–3 given by
/// `exact(x, y)` and the interior ones free; returns the unknowns of all
/// nodes and the condition number of the interior stiffness (the bound
/// of round-off: errors of `ε κ` relative are round-off, not the
/// element).
fn solve_patch(shells: &[Shell], exact: impl Fn(f64, f64) -> [f64; 6]) -> (DVector<f64>, f64) {
    let n = 6 * PATCH_NODES.len();
    let mut k = DMatrix::<f64>::zeros(n, n);
    for s in shells {
        let ke = s.stiffness_matrix();
        for (a, &na) in s.nodes.iter().enumerate() {
            for (b, &nb) in s.nodes.iter().enumerate() {
                for i in 0..6 {
                    for j in 0..6 {
                        k[(6 * na + i, 6 * nb + j)] += ke[(6 * a + i, 6 * b + j)];
                    }
                }
            }
        }
    }
    let mut d = DVector::zeros(n);
    for (i, p) in PATCH_NODES.iter().enumerate().take(4) {
        for (c, v) in exact(p[0], p[1]).iter().enumerate() {
            d[6 * i + c] = *v;
        }
    }
    // K_ff d_f = −K_fp d_p
    let free: Vec<usize> = (24..n).collect();
    let fixed: Vec<usize> = (0..24).collect();
    let kff = k.select_rows(&free).select_columns(&free);
    let kfp = k.select_rows(&free).select_columns(&fixed);
    let dp = d.select_rows(&fixed);
    let eig = kff.clone().symmetric_eigen().eigenvalues;
    let condition = eig.amax() / eig.iter().fold(f64::INFINITY, |a, v| a.min(v.abs()));
    let df = kff.lu().solve(&(-kfp * dp)).expect("a regular patch");
    for (k, &i) in free.iter().enumerate() {
        d[i] = df[k];
    }
    (d, condition)
}

/// The displacements of shell `s` in `d`.
fn element_displacements(s: &Shell, d: &DVector<f64>) -> NodalDisplacements {
    NodalDisplacements(s.nodes.map(|n| std::array::from_fn(|c| d[6 * n + c])))
}

/// Membrane patch test: `u = 10⁻³(x + y/2)`, `v = 10⁻³(y + x/2)` on the
/// corners, E = 10⁶, ν = 0.25, t = 0.001: the interior nodes take the
/// exact displacements and every element the stresses
/// `σxx = σyy = 1333.33`, `τxy = 400` (MacNeal & Harder table 2) at each
/// Gauss point, to round-off: errors below `ε κ`, `κ` the condition
/// number of the interior stiffness (printed); no bending, no drilling.
#[test]
fn membrane_patch_test() {
    let lam = Arc::new(Laminate::isotropic(1e6, 0.25, 0.001, 0.0).unwrap());
    let shells = patch(&lam);
    let exact = |x: f64, y: f64| {
        [
            1e-3 * (x + y / 2.0),
            1e-3 * (y + x / 2.0),
            0.0,
            0.0,
            0.0,
            0.0,
        ]
    };
    let (d, condition) = solve_patch(&shells, exact);
    let round_off = f64::EPSILON * condition;
    let mut worst = 0.0f64;
    for (i, p) in PATCH_NODES.iter().enumerate() {
        let e = exact(p[0], p[1]);
        for c in 0..6 {
            worst = worst.max((d[6 * i + c] - e[c]).abs() / 1e-3);
        }
    }
    println!("membrane patch: largest error of the unknowns {worst:e} (of 1e-3), κ = {condition:.2e}, ε κ = {round_off:.1e}");
    assert!(worst < round_off);
    let sigma = [4000.0 / 3.0, 4000.0 / 3.0, 400.0];
    for s in &shells {
        let de = element_displacements(s, &d);
        for g in 0..4 {
            for layer in s.layer_stresses(&de, StressPoint::Gauss(g)) {
                for side in [layer.bottom, layer.top] {
                    for c in 0..3 {
                        assert!(
                            (side.sigma[c] - sigma[c]).abs() < round_off * 1333.0,
                            "element {}: σ = {:?}",
                            s.id,
                            side.sigma
                        );
                    }
                }
            }
            let r = s.resultants(&de, StressPoint::Gauss(g));
            assert!(r.moment.iter().all(|m| m.abs() < 1e-12));
        }
    }
}

/// Bending patch test: `w = 10⁻³(1 + x + y + x² + xy + y²)/2` with the
/// rotations of Kirchhoff's normal (`θx = w,y`, `θy = −w,x`) on the
/// corners, E = 10⁶, ν = 0.25: the interior nodes take the exact values
/// and every element the constant moments `|Mxx| = |Myy| = 1.111e-7`,
/// `|Mxy| = 0.333e-7` (MacNeal & Harder table 2; here
/// `M = D κ` with `κ = (θy,x, −θx,y, θy,y − θx,x) = −10⁻³(1, 1, 1)`) and
/// no transverse shear, at every Gauss point, to round-off (below
/// `ε κ` relative, `κ` the condition number of the interior
/// stiffness), for a thin (t = 0.001, as the reference) and a thick
/// (t = 0.05) plate: MITC4 ties its shear strains where they are exact.
#[test]
fn bending_patch_test() {
    for t in [0.001, 0.05] {
        let lam = Arc::new(Laminate::isotropic(1e6, 0.25, t, 0.0).unwrap());
        let shells = patch(&lam);
        let exact = |x: f64, y: f64| {
            [
                0.0,
                0.0,
                1e-3 * (1.0 + x + y + x * x + x * y + y * y) / 2.0,
                1e-3 * (1.0 + x + 2.0 * y) / 2.0,
                -1e-3 * (1.0 + 2.0 * x + y) / 2.0,
                0.0,
            ]
        };
        let (d, condition) = solve_patch(&shells, exact);
        let round_off = f64::EPSILON * condition;
        let mut worst = 0.0f64;
        for (i, p) in PATCH_NODES.iter().enumerate() {
            let e = exact(p[0], p[1]);
            for c in 0..6 {
                worst = worst.max((d[6 * i + c] - e[c]).abs() / 1e-3);
            }
        }
        println!("bending patch, t = {t}: largest error of the unknowns {worst:e} (of 1e-3), κ = {condition:.2e}, ε κ = {round_off:.1e}");
        assert!(worst < round_off);
        let dd = 1e6 * t.powi(3) / (12.0 * (1.0 - 0.0625));
        let m = [-dd * 1.25e-3, -dd * 1.25e-3, -dd * 0.375e-3];
        if t == 0.001 {
            // the reference's figures
            assert!((m[0].abs() - 1.111e-7).abs() < 1e-3 * 1.111e-7);
            assert!((m[2].abs() - 0.3333e-7).abs() < 1e-3 * 0.3333e-7);
        }
        for s in &shells {
            let de = element_displacements(s, &d);
            for g in 0..4 {
                let r = s.resultants(&de, StressPoint::Gauss(g));
                for c in 0..3 {
                    assert!(
                        (r.moment[c] - m[c]).abs() < round_off * m[0].abs(),
                        "t = {t}, element {}: M = {:?} against {m:?}",
                        s.id,
                        r.moment
                    );
                }
                assert!(r
                    .shear
                    .iter()
                    .all(|q| q.abs() < round_off * m[0].abs() / 0.01));
                assert!(r
                    .membrane
                    .iter()
                    .all(|n| n.abs() < round_off * m[0].abs() / t));
                // the surface stresses are those of the moments: σ = ±6M/t²
                let layers = s.layer_stresses(&de, StressPoint::Gauss(g));
                let top = layers[0].top.sigma[0];
                assert!((top - 6.0 * m[0] / (t * t)).abs() < round_off * top.abs());
            }
        }
    }
}

/// The drilling penalty does not spoil a membrane in bending: a
/// cantilever of 8 × 2 patch-like distorted elements loaded in its plane
/// deflects by the same amount to 1e-3 with `γ_d = 10⁻³ A₆₆` (the value
/// used) and 10⁻⁵ A₆₆.
#[test]
fn drilling_penalty_leaves_the_membrane_alone() {
    let lam = Laminate::isotropic(1e6, 0.25, 0.1, 0.0).unwrap();
    let (nx, ny, l, h) = (8usize, 2usize, 6.0, 1.0);
    // nodes on a grid, interior nodes shifted to distort the elements
    let node = |i: usize, j: usize| j * (nx + 1) + i;
    let pos = |i: usize, j: usize| {
        let shift = if i > 0 && i < nx && j > 0 && j < ny {
            0.15 * (if (i + j).is_multiple_of(2) { 1.0 } else { -1.0 })
        } else {
            0.0
        };
        [l * i as f64 / nx as f64 + shift, h * j as f64 / ny as f64]
    };
    let tip = |alpha: f64| {
        let n = 6 * (nx + 1) * (ny + 1);
        let mut k = DMatrix::<f64>::zeros(n, n);
        for i in 0..nx {
            for j in 0..ny {
                let ids = [
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ];
                let xy = [pos(i, j), pos(i + 1, j), pos(i + 1, j + 1), pos(i, j + 1)];
                let g = Geometry { xy };
                let ke = g.stiffness(&lam, alpha * lam.a()[(2, 2)]);
                for (a, &na) in ids.iter().enumerate() {
                    for (b, &nb) in ids.iter().enumerate() {
                        for p in 0..6 {
                            for q in 0..6 {
                                k[(6 * na + p, 6 * nb + q)] += ke[(6 * a + p, 6 * b + q)];
                            }
                        }
                    }
                }
            }
        }
        // clamp the root (every unknown), keep the plate in its plane
        let mut free = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                for c in [0, 1, 5] {
                    if i > 0 {
                        free.push(6 * node(i, j) + c);
                    }
                }
            }
        }
        let kff = k.select_rows(&free).select_columns(&free);
        let mut f = DVector::zeros(free.len());
        for j in 0..=ny {
            let dof = 6 * node(nx, j) + 1;
            let k = free.iter().position(|&d| d == dof).unwrap();
            f[k] = 1.0 / (ny + 1) as f64;
        }
        let d = kff.lu().solve(&f).unwrap();
        let dof = 6 * node(nx, ny / 2) + 1;
        d[free.iter().position(|&x| x == dof).unwrap()]
    };
    let (a, b) = (tip(1e-3), tip(1e-5));
    println!("in-plane cantilever tip: {a:.6e} (γ_d = 1e-3 A66), {b:.6e} (1e-5 A66)");
    assert!((a - b).abs() < 1e-3 * b.abs());
}

/// Bad quadrilaterals are refused: zero area (coincident diagonals), a
/// bow-tie (sides crossing), a re-entrant corner, a warped element, a
/// material axis along the normal.
#[test]
fn bad_quadrilaterals_are_refused() {
    let lam = Arc::new(Laminate::isotropic(1e6, 0.25, 0.01, 0.0).unwrap());
    let q = [Rotation::identity(); 4];
    let make = |p: [[f64; 3]; 4], axis: Option<Vec3>| {
        Shell::with_node_ids(
            1,
            [0, 1, 2, 3],
            [11, 12, 13, 14],
            p.map(Vec3::from),
            q,
            axis,
            lam.clone(),
        )
    };
    let square = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    assert!(make(square, None).is_ok());
    // all four nodes on a line
    let line = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
    ];
    assert_eq!(make(line, None).unwrap_err(), ShellGeometryError::ZeroArea);
    // the square's nodes out of order: a symmetric bow-tie has no area
    let bow = [square[0], square[1], square[3], square[2]];
    assert_eq!(make(bow, None).unwrap_err(), ShellGeometryError::ZeroArea);
    // an unsymmetric bow-tie has an area, but a corner turns the wrong way
    let bow = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.3, 1.2, 0.0],
    ];
    let e = make(bow, None).unwrap_err();
    assert!(matches!(e, ShellGeometryError::NotConvex { .. }), "{e}");
    assert!(e.to_string().contains("self-intersecting"));
    // a re-entrant corner 3
    let dart = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.3, 0.3, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let e = make(dart, None).unwrap_err();
    assert_eq!(
        e,
        ShellGeometryError::NotConvex {
            corner: 3,
            node: 13
        }
    );
    // two coincident nodes
    let degenerate = [square[0], square[1], square[2], square[2]];
    assert!(make(degenerate, None).is_err());
    let mut warped = square;
    warped[2][2] = 0.1;
    let e = make(warped, None).unwrap_err();
    assert!(matches!(e, ShellGeometryError::Warped { .. }), "{e}");
    warped[2][2] = 1e-3;
    assert!(make(warped, None).is_ok());
    let e = make(square, Some(Vec3::z())).unwrap_err();
    assert!(matches!(e, ShellGeometryError::AxisNormal { .. }), "{e}");
}

/// A node turned past `ROTATION_LIMIT` from its reference stops the
/// analysis, naming the node; below it the element holds.
#[test]
fn large_rotations_are_refused() {
    let mut shell = distorted(coupled_laminate());
    shell.node_ids = [21, 22, 23, 24];
    let s0 = state_of(&shell);
    let mut s1 = s0.clone();
    s1.displace_node(2, &Vec3::zeros(), &Vec3::new(0.0, 0.04, 0.0));
    assert!(shell.law_violated(&s0, &s1).is_none());
    s1.displace_node(2, &Vec3::zeros(), &Vec3::new(0.0, 0.02, 0.0));
    let why = shell.law_violated(&s0, &s1).expect("beyond the limit");
    assert!(why.starts_with("its node 23 turned by 0.0600 rad"), "{why}");
}

/// The layers of a sandwich are reported with their roles, and a
/// bending curvature stresses the faces in opposite senses and the core
/// (without in-plane stiffness) not at all.
#[test]
fn sandwich_layers_in_bending() {
    use crate::elements::laminate::Core;
    let al = PlyMaterial::isotropic(70e9, 0.33, 2800.0).unwrap();
    let face = [Ply::new(al, 0.3e-3, 0.0)];
    let lam = Arc::new(Laminate::sandwich(&face, &Core::new(20e-3, 190e6, 90e6), &face).unwrap());
    let x = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]].map(|[a, b]| Vec3::new(a, b, 0.0));
    let shell = Shell::new(1, [0, 1, 2, 3], x, [Rotation::identity(); 4], None, lam).unwrap();
    // θy = 0.001 x: κxx = 0.001
    let mut d = NodalDisplacements::default();
    for (i, p) in x.iter().enumerate() {
        d.0[i][4] = 1e-3 * p.x;
        d.0[i][2] = -0.5e-3 * p.x * p.x;
    }
    let layers = shell.layer_stresses(&d, StressPoint::Centre);
    let roles: Vec<LayerRole> = layers.iter().map(|l| l.role).collect();
    assert_eq!(
        roles,
        [LayerRole::BottomFace, LayerRole::Core, LayerRole::TopFace]
    );
    assert!(layers[0].bottom.sigma[0] < 0.0 && layers[2].top.sigma[0] > 0.0);
    assert!(
        (layers[0].bottom.sigma[0] + layers[2].top.sigma[0]).abs() < 1e-9 * layers[2].top.sigma[0]
    );
    assert_eq!(layers[1].von_mises(), 0.0);
}
