//! Joint constraints as dot products, differentiated in closed form.
//!
//! Every equation of the joint library but the helical joint's and the
//! slider's is a dot product `Φ = V·W` of two vectors of the form
//!
//! ```text
//! V = c + Σ_N (s_N x_N + R_N α_N)
//! ```
//!
//! over the element's nodes `N` (at most two): a constant, node positions
//! and material vectors carried by the nodes (joint points, joint axes;
//! docs/joints.md §2). Along the update of the unknowns (`x ← x + Δx`,
//! `R ← R exp(ΔΘ~)`, docs/theory.md §2):
//!
//! ```text
//! ∂V/∂x_N = s_N I          ∂V/∂Θ_N,k = R_N (e_k × α_N)
//! ∂²V/∂Θ_N,a ∂Θ_N,b = R_N (e_b × (e_a × α_N))      (zero between other pairs)
//! ```
//!
//! so that `∂Φ/∂q_r = V_r·W + V·W_r` and
//! `∂²Φ/∂q_r∂q_c = V_r·W_c + V_c·W_r + W·V_rc + V·W_rc`, where
//! `W·V_rc = ŵ_a α_b − δ_ab ŵ·α` with `ŵ = R_Nᵀ W`. These are the
//! derivatives the hyper-dual evaluation of [`super::kinematics::Local`]
//! gives (same order of the rotation updates, the tangent the residual's
//! finite differences see), without its one evaluation of the formula per
//! pair of unknowns.

use super::kinematics::{Local, Pair};
use super::types::{Coordinate, JointType};
use crate::so3::Vec3;

/// Most local nodes of a joint written as dot products.
const NODES: usize = 2;
/// Most local unknowns (6 per node).
const DOFS: usize = 6 * NODES;

/// A vector `c + Σ_N (s_N x_N + R_N α_N)` of the configuration of an
/// element's local nodes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Affine {
    /// Constant part (global).
    pub c: Vec3,
    /// Coefficient of each node's position.
    pub s: [f64; NODES],
    /// Material vector carried by each node.
    pub alpha: [Vec3; NODES],
}

impl Affine {
    fn constant(c: Vec3) -> Self {
        Self {
            c,
            ..Self::default()
        }
    }

    fn on(node: usize, s: f64, alpha: Vec3) -> Self {
        let mut v = Self::default();
        v.s[node] = s;
        v.alpha[node] = alpha;
        v
    }

    fn sub(&self, o: &Self) -> Self {
        Self {
            c: self.c - o.c,
            s: [self.s[0] - o.s[0], self.s[1] - o.s[1]],
            alpha: [self.alpha[0] - o.alpha[0], self.alpha[1] - o.alpha[1]],
        }
    }

    /// Whether it depends on the configuration.
    fn moves(&self) -> bool {
        self.s.iter().any(|&s| s != 0.0) || self.alpha.iter().any(|a| *a != Vec3::zeros())
    }

    /// Value and first derivatives (`cols[r] = ∂V/∂q_r`) at `local`.
    fn evaluate(&self, local: &Local, cols: &mut [Vec3; DOFS]) -> Vec3 {
        let mut v = self.c;
        for (n, (x, r)) in local.x.iter().zip(&local.r).enumerate() {
            let (s, a) = (self.s[n], &self.alpha[n]);
            v += x * s + r * a;
            for k in 0..3 {
                cols[6 * n + k] = Vec3::ith(k, s);
            }
            // R (e_k × α): e₁ × α = (0, −α₃, α₂), e₂ × α = (α₃, 0, −α₁),
            // e₃ × α = (−α₂, α₁, 0)
            cols[6 * n + 3] = r * Vec3::new(0.0, -a.z, a.y);
            cols[6 * n + 4] = r * Vec3::new(a.z, 0.0, -a.x);
            cols[6 * n + 5] = r * Vec3::new(-a.y, a.x, 0.0);
        }
        v
    }

    /// Adds `w · o·∂²V/∂Θ_N,a∂Θ_N,b` (row `a`, column `b` of node `N`'s
    /// rotations) to the column-major `tangent` of leading dimension `ld`:
    /// `w (ô_a α_b − δ_ab ô·α)`, `ô = R_Nᵀ o`.
    fn add_second(&self, local: &Local, o: &Vec3, w: f64, tangent: &mut [f64], ld: usize) {
        for (n, r) in local.r.iter().enumerate() {
            let a = &self.alpha[n];
            if *a == Vec3::zeros() {
                continue;
            }
            let oh: Vec3 = r.transpose() * o;
            let d = oh.dot(a);
            for col in 0..3 {
                for row in 0..3 {
                    let diag = if row == col { d } else { 0.0 };
                    tangent[(6 * n + 3 + col) * ld + 6 * n + 3 + row] +=
                        w * (oh[row] * a[col] - diag);
                }
            }
        }
    }
}

/// The constraint equations of a joint as dot products `V·W`.
#[derive(Clone, Debug, PartialEq)]
pub struct Products {
    /// One `(V, W)` per equation, in the order of [`super::types::constraints`].
    pub equations: Vec<(Affine, Affine)>,
}

impl Products {
    /// The equations of a joint of type `t` placed by `pair`, in the order
    /// of [`super::types::constraints`]; `None` for the helical joint (its
    /// equation holds the joint angle) and the slider.
    pub fn of(t: JointType, pair: &Pair, lock_rotations: bool) -> Option<Self> {
        let PairVectors { ea, eb, d, .. } = PairVectors::of(pair);
        let unit = |k: usize| Affine::constant(Vec3::ith(k, 1.0));
        let point = [(unit(0), d), (unit(1), d), (unit(2), d)];
        let axis = [(ea[0], eb[2]), (ea[1], eb[2])];
        let equations: Vec<(Affine, Affine)> = match t {
            JointType::Spherical => point.to_vec(),
            JointType::Revolute => [&point[..], &axis[..]].concat(),
            JointType::Universal => [&point[..], &[(ea[0], eb[1])]].concat(),
            JointType::Cylindrical => [&axis[..], &[(d, ea[0]), (d, ea[1])]].concat(),
            JointType::Prismatic => [&axis[..], &[(d, ea[0]), (d, ea[1]), (ea[0], eb[1])]].concat(),
            JointType::Planar => [&axis[..], &[(d, ea[2])]].concat(),
            JointType::Rigid | JointType::Glue => {
                if t == JointType::Rigid || lock_rotations {
                    [
                        &point[..],
                        &[(ea[0], eb[1]), (ea[1], eb[2]), (ea[2], eb[0])],
                    ]
                    .concat()
                } else {
                    point.to_vec()
                }
            }
            JointType::Helical | JointType::Slider => return None,
        };
        Some(Self { equations })
    }

    /// Number of equations.
    pub fn len(&self) -> usize {
        self.equations.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.equations.is_empty()
    }

    /// Values `Φᵢ` and gradients `grad[i·n + r] = ∂Φᵢ/∂q_r` at `local`
    /// (`n = local.n()`, every unknown).
    pub fn gradient(&self, local: &Local, value: &mut [f64], grad: &mut [f64]) {
        let n = local.n();
        for (i, (v, w)) in self.equations.iter().enumerate() {
            value[i] = product(v, w, local, &mut grad[i * n..(i + 1) * n]);
        }
    }

    /// Adds `Σᵢ wᵢ ∂²Φᵢ/∂q_r∂q_c` to `tangent[c·ld + r]` for every pair of
    /// unknowns (column-major, leading dimension `ld`).
    pub fn add_weighted_hessian(&self, local: &Local, w: &[f64], tangent: &mut [f64], ld: usize) {
        for (i, (v, wv)) in self.equations.iter().enumerate() {
            if w[i] != 0.0 {
                add_product_hessian(v, wv, local, w[i], tangent, ld);
            }
        }
    }
}

/// The joint points and axes of a pair as [`Affine`] vectors: node A is
/// local node 0 and B local node 1, or A is the ground and B local node 0.
struct PairVectors {
    ea: [Affine; 3],
    eb: [Affine; 3],
    /// `d = pB − pA`.
    d: Affine,
}

impl PairVectors {
    fn of(pair: &Pair) -> Self {
        let (pa, ea, nb): (Affine, [Affine; 3], usize) = match &pair.ground {
            Some((p, e)) => (
                Affine::constant(*p),
                [0, 1, 2].map(|i| Affine::constant(e.column(i).into_owned())),
                0,
            ),
            None => (
                Affine::on(0, 1.0, pair.a),
                [0, 1, 2].map(|i| Affine::on(0, 0.0, pair.ea.column(i).into_owned())),
                1,
            ),
        };
        let pb = Affine::on(nb, 1.0, pair.b);
        let eb = [0, 1, 2].map(|i| Affine::on(nb, 0.0, pair.eb.column(i).into_owned()));
        Self {
            ea,
            eb,
            d: pb.sub(&pa),
        }
    }
}

/// `V·W` at `local` and its gradient `grad[r] = V_r·W + V·W_r`
/// (`local.n()` entries).
fn product(v: &Affine, w: &Affine, local: &Local, grad: &mut [f64]) -> f64 {
    debug_assert!(local.n() <= DOFS && local.x.len() <= NODES);
    let mut cv = [Vec3::zeros(); DOFS];
    let mut cw = [Vec3::zeros(); DOFS];
    let vv = v.evaluate(local, &mut cv);
    let wv = w.evaluate(local, &mut cw);
    for (r, g) in grad.iter_mut().enumerate().take(local.n()) {
        *g = cv[r].dot(&wv) + cw[r].dot(&vv);
    }
    vv.dot(&wv)
}

/// Adds `weight · ∂²(V·W)/∂q_r∂q_c` to `tangent[c·ld + r]`.
fn add_product_hessian(
    v: &Affine,
    w: &Affine,
    local: &Local,
    weight: f64,
    tangent: &mut [f64],
    ld: usize,
) {
    let n = local.n();
    let mut cv = [Vec3::zeros(); DOFS];
    let mut cw = [Vec3::zeros(); DOFS];
    let vv = v.evaluate(local, &mut cv);
    let wv = w.evaluate(local, &mut cw);
    // V_r·W_c + V_c·W_r: zero unless both vectors move
    if v.moves() && w.moves() {
        for c in 0..n {
            for r in 0..n {
                tangent[c * ld + r] += weight * (cv[r].dot(&cw[c]) + cv[c].dot(&cw[r]));
            }
        }
    }
    v.add_second(local, &wv, weight, tangent, ld);
    w.add_second(local, &vv, weight, tangent, ld);
}

/// A relative coordinate of a pair (docs/joints.md §3) written with dot
/// products: one product (a stroke), or the angle `atan2(y, x)` of two.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoordinateForm {
    /// `V·W`.
    Product(Affine, Affine),
    /// `atan2(V_y·W_y, V_x·W_x)`.
    Angle([(Affine, Affine); 2]),
}

impl CoordinateForm {
    /// The form of `coordinate` (as [`Coordinate::value`] writes it) for
    /// `pair`; `None` for a slider's curve parameter.
    pub fn of(coordinate: Coordinate, pair: &Pair) -> Option<Self> {
        let PairVectors { ea: a, eb: b, d } = PairVectors::of(pair);
        Some(match coordinate {
            Coordinate::Angle => Self::Angle([(b[0], a[1]), (b[0], a[0])]),
            Coordinate::Slide1 => Self::Product(d, a[0]),
            Coordinate::Slide2 => Self::Product(d, a[1]),
            Coordinate::Slide3 => Self::Product(d, a[2]),
            Coordinate::Cardan1 => Self::Angle([(b[1], a[2]), (b[1], a[1])]),
            Coordinate::Cardan2 => Self::Angle([(a[0], b[2]), (a[0], b[0])]),
            Coordinate::CurveParameter => return None,
        })
    }

    /// The coordinate at `local` (angles on the branch nearest
    /// `reference`, as [`super::kinematics::unwrap`]), its gradient
    /// `grad[r] = ∂c/∂q_r` and, with `hessian`, `∂²c/∂q_r∂q_c` added to
    /// `hessian[c·n + r]` (`n = local.n()`). For `θ = atan2(y, x)`,
    /// `ρ² = x² + y²`:
    ///
    /// ```text
    /// θ_r  = (x y_r − y x_r)/ρ²
    /// θ_rc = (x y_rc − y x_rc)/ρ² − 2xy (y_r y_c − x_r x_c)/ρ⁴ + (y² − x²)(y_r x_c + x_r y_c)/ρ⁴
    /// ```
    pub fn evaluate(
        &self,
        local: &Local,
        reference: f64,
        grad: &mut [f64],
        hessian: Option<&mut [f64]>,
    ) -> f64 {
        let n = local.n();
        match self {
            Self::Product(v, w) => {
                let c = product(v, w, local, grad);
                if let Some(h) = hessian {
                    add_product_hessian(v, w, local, 1.0, h, n);
                }
                c
            }
            Self::Angle([(vy, wy), (vx, wx)]) => {
                let mut gy = [0.0; DOFS];
                let mut gx = [0.0; DOFS];
                let y = product(vy, wy, local, &mut gy);
                let x = product(vx, wx, local, &mut gx);
                let r2 = x * x + y * y;
                let (ay, ax) = (x / r2, -y / r2);
                for r in 0..n {
                    grad[r] = ay * gy[r] + ax * gx[r];
                }
                if let Some(h) = hessian {
                    add_product_hessian(vy, wy, local, ay, h, n);
                    add_product_hessian(vx, wx, local, ax, h, n);
                    let r4 = r2 * r2;
                    let hyy = -2.0 * x * y / r4;
                    let hxx = 2.0 * x * y / r4;
                    let hxy = (y * y - x * x) / r4;
                    for c in 0..n {
                        for r in 0..n {
                            h[c * n + r] += hyy * gy[r] * gy[c]
                                + hxx * gx[r] * gx[c]
                                + hxy * (gy[r] * gx[c] + gx[r] * gy[c]);
                        }
                    }
                }
                let theta = y.atan2(x);
                let turns = ((reference - theta) / std::f64::consts::TAU).round();
                theta + turns * std::f64::consts::TAU
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joints::hyperdual::HyperDual;
    use crate::joints::kinematics::Conf;
    use crate::joints::tests::Lcg;
    use crate::joints::types::{constraint_kinds, constraints, JointParameters};
    use crate::so3::{self, Rotation};
    use crate::state::State;

    /// The closed-form values, gradients and weighted second derivatives
    /// equal those of the hyper-dual evaluation of the same equations
    /// (`types::constraints`), for every joint type written as dot
    /// products, between two nodes and to the ground, on random
    /// configurations. Both are exact: the tolerance, 1e-12 of the largest
    /// entry, is round-off.
    #[test]
    fn closed_form_matches_hyper_dual_evaluation() {
        let mut rng = Lcg(11);
        let types = [
            JointType::Revolute,
            JointType::Prismatic,
            JointType::Cylindrical,
            JointType::Spherical,
            JointType::Planar,
            JointType::Universal,
            JointType::Rigid,
            JointType::Glue,
        ];
        let mut compared = 0;
        for t in types {
            for grounded in [false, true] {
                for lock_rotations in [true, false] {
                    for _ in 0..8 {
                        let x: Vec<Vec3> = (0..2).map(|_| rng.vec(1.0)).collect();
                        let q: Vec<Rotation> = (0..2).map(|_| so3::exp(&rng.vec(2.0))).collect();
                        let e = so3::matrix(&so3::exp(&rng.vec(2.0)));
                        let p = rng.vec(1.0);
                        let (ra, rb) = (so3::matrix(&q[0]), so3::matrix(&q[1]));
                        let pair = Pair::from_reference(
                            &p,
                            &e,
                            (&x[0], &ra),
                            (!grounded).then_some((&x[1], &rb)),
                        );
                        let products = Products::of(t, &pair, lock_rotations).unwrap();
                        let m = constraint_kinds(t, lock_rotations).len();
                        assert_eq!(products.len(), m, "{}", t.name());
                        let nn = if grounded { 1 } else { 2 };
                        let xs = x[..nn].iter().map(|x| x + rng.vec(0.3)).collect();
                        let qs = q[..nn]
                            .iter()
                            .map(|q| q * so3::exp(&rng.vec(0.6)))
                            .collect();
                        let state = State::at_rest(0.0, xs, qs);
                        let nodes: Vec<usize> = (0..nn).collect();
                        let mut local = Local::default();
                        local.gather(&state, &nodes, 0..0);
                        let n = local.n();
                        let params = JointParameters {
                            lead: 0.0,
                            lock_rotations,
                            curve: None,
                        };
                        let f = |c: &Conf, out: &mut [HyperDual]| {
                            constraints(t, &pair.frames(c), HyperDual::default(), &params, out)
                        };
                        let w: Vec<f64> = (0..m).map(|_| rng.next()).collect();
                        let active: Vec<usize> = (0..n).collect();
                        let (mut v1, mut g1, mut h1) =
                            (vec![0.0; m], vec![0.0; m * n], vec![0.0; n * n]);
                        local.gradient(m, &active, &f, &mut v1, &mut g1);
                        local.add_weighted_hessian(m, &active, &f, &w, &g1, true, &mut h1, n);
                        let (mut v2, mut g2, mut h2) =
                            (vec![0.0; m], vec![0.0; m * n], vec![0.0; n * n]);
                        products.gradient(&local, &mut v2, &mut g2);
                        products.add_weighted_hessian(&local, &w, &mut h2, n);
                        let err = |a: &[f64], b: &[f64]| {
                            let scale = a.iter().fold(1.0f64, |s, v| s.max(v.abs()));
                            a.iter()
                                .zip(b)
                                .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()))
                                / scale
                        };
                        let what = format!("{} grounded {grounded}", t.name());
                        assert!(err(&v1, &v2) < 1e-12, "{what}: values {v1:?} {v2:?}");
                        assert!(err(&g1, &g2) < 1e-12, "{what}: gradients");
                        assert!(
                            err(&h1, &h2) < 1e-12,
                            "{what}: second derivatives {:.2e}",
                            err(&h1, &h2)
                        );
                        compared += 1;
                    }
                }
            }
        }
        assert_eq!(compared, 8 * 2 * 2 * 8);
    }

    /// The closed-form coordinates (value, gradient, second derivatives)
    /// equal the hyper-dual evaluation of `Coordinate::unwrapped`, for
    /// every coordinate but a slider's, between two nodes and to the
    /// ground, on random configurations, angles unwrapped about a
    /// reference up to two turns away. Tolerance 1e-12 of the value,
    /// 1e-10 of the largest derivative (both are exact; the derivatives of
    /// an angle divide by `ρ²` and `ρ⁴`, which magnifies round-off).
    #[test]
    fn closed_form_coordinates_match_hyper_dual_evaluation() {
        use crate::joints::coordinate::PairCoordinate;
        let mut rng = Lcg(5);
        let coordinates = [
            Coordinate::Angle,
            Coordinate::Slide1,
            Coordinate::Slide2,
            Coordinate::Slide3,
            Coordinate::Cardan1,
            Coordinate::Cardan2,
        ];
        let mut compared = 0;
        for coordinate in coordinates {
            for grounded in [false, true] {
                for k in 0..8 {
                    let x: Vec<Vec3> = (0..2).map(|_| rng.vec(1.0)).collect();
                    let q: Vec<Rotation> = (0..2).map(|_| so3::exp(&rng.vec(2.0))).collect();
                    let e = so3::matrix(&so3::exp(&rng.vec(2.0)));
                    let p = rng.vec(1.0);
                    let (ra, rb) = (so3::matrix(&q[0]), so3::matrix(&q[1]));
                    let pair = Pair::from_reference(
                        &p,
                        &e,
                        (&x[0], &ra),
                        (!grounded).then_some((&x[1], &rb)),
                    );
                    let nn = if grounded { 1 } else { 2 };
                    let xs = x[..nn].iter().map(|x| x + rng.vec(0.3)).collect();
                    let qs = q[..nn]
                        .iter()
                        .map(|q| q * so3::exp(&rng.vec(0.6)))
                        .collect();
                    let state = State::at_rest(0.0, xs, qs);
                    let source = PairCoordinate {
                        nodes: (0..nn).collect(),
                        pair: pair.clone(),
                        coordinate,
                    };
                    let mut local = Local::default();
                    local.gather(&state, &source.nodes, 0..0);
                    let n = local.n();
                    let reference = (k as f64 - 4.0) * 1.7;
                    let f = source.function(reference);
                    let active: Vec<usize> = (0..n).collect();
                    let (mut v1, mut g1, mut h1) = ([0.0], vec![0.0; n], vec![0.0; n * n]);
                    local.gradient(1, &active, &f, &mut v1, &mut g1);
                    local.add_weighted_hessian(1, &active, &f, &[1.0], &g1, true, &mut h1, n);
                    let form = CoordinateForm::of(coordinate, &pair).unwrap();
                    let (mut g2, mut h2) = (vec![0.0; n], vec![0.0; n * n]);
                    let v2 = form.evaluate(&local, reference, &mut g2, Some(&mut h2));
                    let err = |a: &[f64], b: &[f64]| {
                        let scale = a.iter().fold(1.0f64, |s, v| s.max(v.abs()));
                        a.iter()
                            .zip(b)
                            .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()))
                            / scale
                    };
                    let what = format!("{} grounded {grounded}", coordinate.name());
                    assert!((v1[0] - v2).abs() < 1e-12, "{what}: value {} {v2}", v1[0]);
                    assert!(
                        err(&g1, &g2) < 1e-10,
                        "{what}: gradient {:.2e}",
                        err(&g1, &g2)
                    );
                    assert!(
                        err(&h1, &h2) < 1e-10,
                        "{what}: second derivatives {:.2e}",
                        err(&h1, &h2)
                    );
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, 6 * 2 * 8);
    }
}
