//! The kernels of the flat four-node shell in its own plane
//! (docs/theory.md §17.1): bilinear shape functions, the strain–displacement
//! matrices of the membrane, the bending and the MITC4 transverse shear,
//! the drilling penalty, and the 24 × 24 stiffness and the area
//! integrals of the mass.
//!
//! Local unknowns, node by node: `(u, v, w, θx, θy, θz)` in the element's
//! axes `(x, y, n)`. The Reissner–Mindlin kinematics
//! `u(z) = u₀ + z βx`, `v(z) = v₀ + z βy` take the fibre rotations
//! `βx = θy`, `βy = −θx` (a right-handed rotation `θy` about `y` tilts the
//! normal towards `+x`), so that
//!
//! ```text
//! (S1)  ε = (u,x ; v,y ; u,y + v,x)
//!       κ = (θy,x ; −θx,y ; θy,y − θx,x)
//!       γ = (w,x + θy ; w,y − θx)          (before the MITC4 interpolation)
//! ```

use nalgebra::{Matrix2, Matrix3, Matrix4, SMatrix, SVector, Vector2, Vector3};

use crate::elements::laminate::Laminate;

/// 24 × 24 element matrix.
pub(crate) type Mat24 = SMatrix<f64, 24, 24>;
/// 24 local unknowns.
pub(crate) type Vec24 = SVector<f64, 24>;
type Mat3x24 = SMatrix<f64, 3, 24>;
type Mat2x24 = SMatrix<f64, 2, 24>;
type Row24 = SMatrix<f64, 1, 24>;

/// Natural coordinates `(ξ, η)` of the corners, counterclockwise.
pub(crate) const CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// `1/√3`: the 2 × 2 Gauss points are `(±g, ±g)`, weight 1.
const G: f64 = 0.577_350_269_189_625_8;

/// The 2 × 2 Gauss points, in the order of the corners.
pub(crate) const GAUSS_POINTS: [[f64; 2]; 4] = [[-G, -G], [G, -G], [G, G], [-G, G]];

/// `N` and `(∂N/∂ξ, ∂N/∂η)` of the bilinear shape functions at `(ξ, η)`.
fn shape(xi: f64, eta: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    let mut n = [0.0; 4];
    let mut dn = [[0.0; 2]; 4];
    for (i, c) in CORNERS.iter().enumerate() {
        n[i] = 0.25 * (1.0 + c[0] * xi) * (1.0 + c[1] * eta);
        dn[i] = [
            0.25 * c[0] * (1.0 + c[1] * eta),
            0.25 * c[1] * (1.0 + c[0] * xi),
        ];
    }
    (n, dn)
}

/// What the matrices need at one point `(ξ, η)`.
pub(crate) struct Point {
    /// Shape functions.
    pub n: [f64; 4],
    /// `(∂N/∂x, ∂N/∂y)`.
    pub dn: [[f64; 2]; 4],
    /// `J = [[x,ξ, y,ξ], [x,η, y,η]]`.
    pub jacobian: Matrix2<f64>,
    /// `det J`.
    pub det: f64,
}

/// The element's corners in its own plane.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Geometry {
    /// `(x, y)` of the corners.
    pub xy: [[f64; 2]; 4],
}

impl Geometry {
    /// `J` at `(ξ, η)` from the derivatives `dn` in natural coordinates.
    fn jacobian(&self, dn: &[[f64; 2]; 4]) -> Matrix2<f64> {
        let mut j = Matrix2::zeros();
        for (p, d) in self.xy.iter().zip(dn) {
            for r in 0..2 {
                j[(r, 0)] += d[r] * p[0];
                j[(r, 1)] += d[r] * p[1];
            }
        }
        j
    }

    /// The point `(ξ, η)` (det J > 0 is checked where the element is
    /// built).
    pub fn point(&self, xi: f64, eta: f64) -> Point {
        let (n, dnat) = shape(xi, eta);
        let jacobian = self.jacobian(&dnat);
        let det = jacobian.determinant();
        // [N,x; N,y] = J⁻¹ [N,ξ; N,η]
        let inv = Matrix2::new(
            jacobian[(1, 1)],
            -jacobian[(0, 1)],
            -jacobian[(1, 0)],
            jacobian[(0, 0)],
        ) / det;
        let dn = dnat.map(|d| {
            let g = inv * Vector2::new(d[0], d[1]);
            [g.x, g.y]
        });
        Point {
            n,
            dn,
            jacobian,
            det,
        }
    }

    /// `det J` at the corners (positive for a convex quadrilateral whose
    /// corners run counterclockwise about the normal).
    pub fn corner_determinants(&self) -> [f64; 4] {
        CORNERS.map(|c| self.jacobian(&shape(c[0], c[1]).1).determinant())
    }

    /// Membrane strains `ε = B_m d` (S1).
    pub fn membrane(&self, p: &Point) -> Mat3x24 {
        let mut b = Mat3x24::zeros();
        for i in 0..4 {
            let [dx, dy] = p.dn[i];
            b[(0, 6 * i)] = dx;
            b[(1, 6 * i + 1)] = dy;
            b[(2, 6 * i)] = dy;
            b[(2, 6 * i + 1)] = dx;
        }
        b
    }

    /// Curvatures `κ = B_b d` (S1).
    pub fn bending(&self, p: &Point) -> Mat3x24 {
        let mut b = Mat3x24::zeros();
        for i in 0..4 {
            let [dx, dy] = p.dn[i];
            b[(0, 6 * i + 4)] = dx;
            b[(1, 6 * i + 3)] = -dy;
            b[(2, 6 * i + 4)] = dy;
            b[(2, 6 * i + 3)] = -dx;
        }
        b
    }

    /// The covariant transverse shear strain along natural direction
    /// `dir` (0: ξ, 1: η) at the tying point `(ξ, η)`:
    /// `e_dir = w,dir + βx x,dir + βy y,dir` (S2).
    fn covariant_shear(&self, xi: f64, eta: f64, dir: usize) -> Row24 {
        let (n, dn) = shape(xi, eta);
        let (x_d, y_d) = self.xy.iter().zip(&dn).fold((0.0, 0.0), |(a, b), (p, d)| {
            (a + d[dir] * p[0], b + d[dir] * p[1])
        });
        let mut row = Row24::zeros();
        for i in 0..4 {
            row[6 * i + 2] = dn[i][dir];
            // βx = θy, βy = −θx
            row[6 * i + 4] = n[i] * x_d;
            row[6 * i + 3] = -n[i] * y_d;
        }
        row
    }

    /// Transverse shear strains `γ = (γxz, γyz) = B_s d` at `(ξ, η)` by the
    /// MITC4 interpolation (Bathe & Dvorkin 1985; S3): the covariant
    /// strains tied at the middles of the sides, `e_ξ` linear in `η`
    /// between A (0, 1) and C (0, −1), `e_η` linear in `ξ` between
    /// D (1, 0) and B (−1, 0), then `γ = J⁻¹ (e_ξ, e_η)`.
    pub fn shear(&self, xi: f64, eta: f64, p: &Point) -> Mat2x24 {
        let a = self.covariant_shear(0.0, 1.0, 0);
        let c = self.covariant_shear(0.0, -1.0, 0);
        let d = self.covariant_shear(1.0, 0.0, 1);
        let b = self.covariant_shear(-1.0, 0.0, 1);
        let e_xi = a * (0.5 * (1.0 + eta)) + c * (0.5 * (1.0 - eta));
        let e_eta = d * (0.5 * (1.0 + xi)) + b * (0.5 * (1.0 - xi));
        let inv = p.jacobian.try_inverse().unwrap_or_else(Matrix2::zeros);
        let mut out = Mat2x24::zeros();
        for k in 0..24 {
            let g = inv * Vector2::new(e_xi[k], e_eta[k]);
            out[(0, k)] = g.x;
            out[(1, k)] = g.y;
        }
        out
    }

    /// The drilling strain `θz − ω`, `ω = ½ (v,x − u,y)` the in-plane
    /// rotation of the membrane (S4).
    pub fn drilling(&self, p: &Point) -> Row24 {
        let mut row = Row24::zeros();
        for i in 0..4 {
            let [dx, dy] = p.dn[i];
            row[6 * i] = 0.5 * dy;
            row[6 * i + 1] = -0.5 * dx;
            row[6 * i + 5] = p.n[i];
        }
        row
    }

    /// The stiffness in the element's axes (S5):
    /// `K = Σ_gp det J [B_mᵀ(A B_m + B B_b) + B_bᵀ(B B_m + D B_b)
    /// + B_sᵀ H B_s + γ_d B_dᵀ B_d]`, 2 × 2 Gauss points for every part.
    pub fn stiffness(&self, lam: &Laminate, drilling: f64) -> Mat24 {
        let mut k = Mat24::zeros();
        let (a, b, d, h) = (lam.a(), lam.b(), lam.d(), lam.shear());
        for [xi, eta] in GAUSS_POINTS {
            let p = self.point(xi, eta);
            let bm = self.membrane(&p);
            let bb = self.bending(&p);
            let bs = self.shear(xi, eta, &p);
            let bd = self.drilling(&p);
            let n = a * bm + b * bb;
            let m = b * bm + d * bb;
            k += (bm.transpose() * n + bb.transpose() * m + bs.transpose() * (h * bs)) * p.det;
            k += bd.transpose() * bd * (drilling * p.det);
        }
        // symmetric by construction; make it so to the last bit
        (k + k.transpose()) * 0.5
    }

    /// `Sᵢⱼ = ∫ Nᵢ Nⱼ dA` (2 × 2 Gauss points: exact, `Nᵢ Nⱼ det J` is at
    /// most cubic in each of `ξ`, `η`).
    pub fn overlap(&self) -> Matrix4<f64> {
        let mut s = Matrix4::zeros();
        for [xi, eta] in GAUSS_POINTS {
            let p = self.point(xi, eta);
            for i in 0..4 {
                for j in 0..4 {
                    s[(i, j)] += p.n[i] * p.n[j] * p.det;
                }
            }
        }
        s
    }

    /// The area.
    pub fn area(&self) -> f64 {
        GAUSS_POINTS
            .iter()
            .map(|[xi, eta]| self.point(*xi, *eta).det)
            .sum()
    }

    /// Membrane strains, curvatures and transverse shear strains at
    /// `(ξ, η)` for the local unknowns `d`.
    pub fn strains(
        &self,
        d: &Vec24,
        xi: f64,
        eta: f64,
    ) -> (Vector3<f64>, Vector3<f64>, Vector2<f64>) {
        let p = self.point(xi, eta);
        (
            self.membrane(&p) * d,
            self.bending(&p) * d,
            self.shear(xi, eta, &p) * d,
        )
    }
}

/// The 6 × 6 mass density of a node pair in the element's axes, per unit
/// of `∫ Nᵢ Nⱼ dA` (S6): `ρ₀` on the translations, `ρ₂` on the fibre
/// rotations `θx`, `θy`, and the coupling `ρ₁` of `u` with `βx = θy` and
/// of `v` with `βy = −θx`, from the kinetic energy
/// `½ ∫∫ ρ |u̇₀ + z β̇|² dz dA`. The drilling rotation carries no inertia.
pub(crate) fn mass_density(lam: &Laminate) -> SMatrix<f64, 6, 6> {
    let (r0, r1, r2) = (
        lam.mass_per_area(),
        lam.first_moment(),
        lam.rotary_inertia(),
    );
    let mut m = SMatrix::<f64, 6, 6>::zeros();
    for c in 0..3 {
        m[(c, c)] = r0;
    }
    m[(3, 3)] = r2;
    m[(4, 4)] = r2;
    m[(0, 4)] = r1;
    m[(4, 0)] = r1;
    m[(1, 3)] = -r1;
    m[(3, 1)] = -r1;
    m
}

/// A 3 × 3 block of a matrix (rows and columns from `r`, `c`).
pub(crate) fn block(m: &Mat24, r: usize, c: usize) -> Matrix3<f64> {
    m.fixed_view::<3, 3>(r, c).into_owned()
}
