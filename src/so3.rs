//! Finite rotations: the rotation group SO(3) with the Cartesian rotation
//! vector as local chart.
//!
//! Conventions (docs/theory.md §1, reference paper eqs. 1–5):
//! - a rotation vector `ψ = n ψ` maps to `R = exp(ψ~)` (eq. 1–2), where `a~`
//!   is the skew-symmetric matrix with `a~ b = a × b`;
//! - variations are *material* (right): `δR = R δΘ~` (eq. 3), and
//!   `δΘ = T(ψ) δψ` (eq. 4) with the tangent operator
//!   `T(ψ) = I − (1−cos ψ)/ψ² ψ~ + (ψ−sin ψ)/ψ³ ψ~²` (eq. T1 of theory.md);
//! - `T⁻¹(ψ) = I + ½ ψ~ + (1/ψ²)(1 − (ψ/2) cot(ψ/2)) ψ~²` (eq. T2).
//!
//! Orientations are stored as unit quaternions and updated multiplicatively,
//! `R ← R exp(ΔΘ~)`, so no total rotation vector is ever integrated and
//! there is no singularity at ψ = 2π.
//!
//! Every operator used here has the form `f(ψ) = I + c₁(ψ) ψ~ + c₂(ψ) ψ~²`
//! with coefficients that are even functions of `ψ = |ψ|`; [`SkewSeries`]
//! evaluates such an operator, its action on a vector and the derivative of
//! that action with respect to `ψ`, which is what the consistent tangents of
//! beams and springs need (theory.md eq. T3). Near `ψ = 0` the coefficients
//! are evaluated by their Taylor series, so every function is smooth there.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

/// 3-vector of `f64`.
pub type Vec3 = Vector3<f64>;
/// 3×3 matrix of `f64`.
pub type Mat3 = Matrix3<f64>;
/// Unit quaternion representing a rotation.
pub type Rotation = UnitQuaternion<f64>;

/// Below this angle the coefficients are evaluated by Taylor series.
///
/// At 1 rad the ten series terms kept are exact to round-off (the first
/// neglected term is below 1e-16 relative, the slowest series being that of
/// T⁻¹ with radius 2π), while the closed forms above it lose at most a few
/// 1e-13 relative to cancellation.
const SERIES_ANGLE: f64 = 1.0;

/// Returns `a~`, the skew-symmetric matrix such that `a~ b = a × b`.
#[inline]
pub fn skew(a: &Vec3) -> Mat3 {
    Mat3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Returns the axial vector of the skew-symmetric part of `m`,
/// `axial(a~) = a`.
#[inline]
pub fn axial(m: &Mat3) -> Vec3 {
    Vec3::new(
        0.5 * (m[(2, 1)] - m[(1, 2)]),
        0.5 * (m[(0, 2)] - m[(2, 0)]),
        0.5 * (m[(1, 0)] - m[(0, 1)]),
    )
}

/// Evaluates a polynomial in `x = ψ²` with the given coefficients.
#[inline]
fn poly(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

// Taylor coefficients in powers of ψ² (generated with sympy; see
// docs/theory.md §1.3). `*_D` are the series of c'(ψ)/ψ.
const EXP_C1: [f64; 10] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362880.0,
    -1.0 / 39916800.0,
    1.0 / 6227020800.0,
    -1.0 / 1307674368000.0,
    1.0 / 355687428096000.0,
    -1.0 / 121645100408832000.0,
];
const EXP_C1_D: [f64; 10] = [
    -1.0 / 3.0,
    1.0 / 30.0,
    -1.0 / 840.0,
    1.0 / 45360.0,
    -1.0 / 3991680.0,
    1.0 / 518918400.0,
    -1.0 / 93405312000.0,
    1.0 / 22230464256000.0,
    -1.0 / 6758061133824000.0,
    1.0 / 2554547108585472000.0,
];
const EXP_C2: [f64; 10] = [
    1.0 / 2.0,
    -1.0 / 24.0,
    1.0 / 720.0,
    -1.0 / 40320.0,
    1.0 / 3628800.0,
    -1.0 / 479001600.0,
    1.0 / 87178291200.0,
    -1.0 / 20922789888000.0,
    1.0 / 6402373705728000.0,
    -1.0 / 2432902008176640000.0,
];
const EXP_C2_D: [f64; 10] = [
    -1.0 / 12.0,
    1.0 / 180.0,
    -1.0 / 6720.0,
    1.0 / 453600.0,
    -1.0 / 47900160.0,
    1.0 / 7264857600.0,
    -1.0 / 1494484992000.0,
    1.0 / 400148356608000.0,
    -1.0 / 135161222676480000.0,
    1.0 / 56200036388880384000.0,
];
const TAN_C2: [f64; 10] = [
    1.0 / 6.0,
    -1.0 / 120.0,
    1.0 / 5040.0,
    -1.0 / 362880.0,
    1.0 / 39916800.0,
    -1.0 / 6227020800.0,
    1.0 / 1307674368000.0,
    -1.0 / 355687428096000.0,
    1.0 / 121645100408832000.0,
    -1.0 / 51090942171709440000.0,
];
const TAN_C2_D: [f64; 10] = [
    -1.0 / 60.0,
    1.0 / 1260.0,
    -1.0 / 60480.0,
    1.0 / 4989600.0,
    -1.0 / 622702080.0,
    1.0 / 108972864000.0,
    -1.0 / 25406244864000.0,
    1.0 / 7602818775552000.0,
    -1.0 / 2838385676206080000.0,
    1.0 / 1292600836944248832000.0,
];
const TINV_C2: [f64; 10] = [
    1.0 / 12.0,
    1.0 / 720.0,
    1.0 / 30240.0,
    1.0 / 1209600.0,
    1.0 / 47900160.0,
    691.0 / 1307674368000.0,
    1.0 / 74724249600.0,
    3617.0 / 10670622842880000.0,
    43867.0 / 5109094217170944000.0,
    174611.0 / 802857662698291200000.0,
];
const TINV_C2_D: [f64; 10] = [
    1.0 / 360.0,
    1.0 / 7560.0,
    1.0 / 201600.0,
    1.0 / 5987520.0,
    691.0 / 130767436800.0,
    1.0 / 6227020800.0,
    3617.0 / 762187345920000.0,
    43867.0 / 319318388573184000.0,
    174611.0 / 44603203483238400000.0,
    77683.0 / 705055001969590272000.0,
];

/// The operators of the rotation-vector chart, all of the form
/// `I + c₁ ψ~ + c₂ ψ~²`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Operator {
    /// `exp(ψ~)`, the rotation matrix (eq. 2).
    Exp,
    /// `T(ψ)`, the material tangent operator, `δΘ = T δψ` (eq. 4).
    Tangent,
    /// `T⁻¹(ψ)`, its inverse.
    TangentInv,
}

/// An operator `f(ψ) = I + c₁ ψ~ + c₂ ψ~²` evaluated at one rotation vector,
/// with the derivatives `d₁ = c₁'(ψ)/ψ`, `d₂ = c₂'(ψ)/ψ` of its coefficients.
#[derive(Clone, Copy, Debug)]
pub struct SkewSeries {
    psi: Vec3,
    c1: f64,
    c2: f64,
    d1: f64,
    d2: f64,
}

impl SkewSeries {
    /// Evaluates `op` at the rotation vector `psi`.
    pub fn new(op: Operator, psi: &Vec3) -> Self {
        let t = psi.norm();
        let (c1, c2, d1, d2) = coefficients(op, t, t < SERIES_ANGLE);
        Self {
            psi: *psi,
            c1,
            c2,
            d1,
            d2,
        }
    }

    /// `T(ψ)` and `exp(ψ~)` at one rotation vector, with one norm and one
    /// set of sines for both: the same as [`Self::new`] for each.
    pub fn tangent_and_exp(psi: &Vec3) -> [Self; 2] {
        let t = psi.norm();
        let series = t < SERIES_ANGLE;
        let (tangent, exp) = if series {
            (
                coefficients(Operator::Tangent, t, true),
                coefficients(Operator::Exp, t, true),
            )
        } else {
            let (s, c) = t.sin_cos();
            let omc = one_minus_cos(t);
            (
                tangent_coefficients(t, s, omc),
                exp_coefficients(t, s, c, omc),
            )
        };
        [tangent, exp].map(|(c1, c2, d1, d2)| Self {
            psi: *psi,
            c1,
            c2,
            d1,
            d2,
        })
    }

    /// The operator as a matrix, `I + c₁ ψ~ + c₂ ψ~²`.
    pub fn matrix(&self) -> Mat3 {
        let s = skew(&self.psi);
        Mat3::identity() + s * self.c1 + s * s * self.c2
    }

    /// Applies the operator to `v`: `f(ψ) v`.
    pub fn apply(&self, v: &Vec3) -> Vec3 {
        let pv = self.psi.cross(v);
        v + pv * self.c1 + self.psi.cross(&pv) * self.c2
    }

    /// Applies the transposed operator to `v`: `f(ψ)ᵀ v = f(−ψ) v`.
    pub fn apply_transpose(&self, v: &Vec3) -> Vec3 {
        let pv = self.psi.cross(v);
        v - pv * self.c1 + self.psi.cross(&pv) * self.c2
    }

    /// Derivative of `f(ψ) v` with respect to `ψ` at fixed `v` (theory.md
    /// eq. T3):
    /// `−c₁ v~ + d₁ (ψ×v) ψᵀ + c₂ [(ψ·v) I + ψ vᵀ − 2 v ψᵀ] + d₂ (ψ×(ψ×v)) ψᵀ`.
    pub fn derivative_of_apply(&self, v: &Vec3) -> Mat3 {
        let p = &self.psi;
        let pv = p.cross(v);
        let ppv = p.cross(&pv);
        -skew(v) * self.c1
            + (pv * self.d1 + ppv * self.d2) * p.transpose()
            + (Mat3::identity() * p.dot(v) + p * v.transpose() - v * p.transpose() * 2.0) * self.c2
    }

    /// Derivative of `f(ψ)ᵀ v` with respect to `ψ` at fixed `v`.
    pub fn derivative_of_apply_transpose(&self, v: &Vec3) -> Mat3 {
        // f(ψ)ᵀ v = v − c₁ ψ×v + c₂ ψ×(ψ×v): only the c₁ terms change sign
        let p = &self.psi;
        let pv = p.cross(v);
        let ppv = p.cross(&pv);
        skew(v) * self.c1
            + (ppv * self.d2 - pv * self.d1) * p.transpose()
            + (Mat3::identity() * p.dot(v) + p * v.transpose() - v * p.transpose() * 2.0) * self.c2
    }
}

/// Coefficients `(c₁, c₂, d₁, d₂)` of `op` at angle `t`, by Taylor series
/// (`series`) or closed form.
fn coefficients(op: Operator, t: f64, series: bool) -> (f64, f64, f64, f64) {
    let t2 = t * t;
    match op {
        Operator::Exp => {
            if series {
                (
                    poly(&EXP_C1, t2),
                    poly(&EXP_C2, t2),
                    poly(&EXP_C1_D, t2),
                    poly(&EXP_C2_D, t2),
                )
            } else {
                let (s, c) = t.sin_cos();
                exp_coefficients(t, s, c, one_minus_cos(t))
            }
        }
        Operator::Tangent => {
            if series {
                (
                    -poly(&EXP_C2, t2),
                    poly(&TAN_C2, t2),
                    -poly(&EXP_C2_D, t2),
                    poly(&TAN_C2_D, t2),
                )
            } else {
                tangent_coefficients(t, t.sin(), one_minus_cos(t))
            }
        }
        Operator::TangentInv => {
            if series {
                (0.5, poly(&TINV_C2, t2), 0.0, poly(&TINV_C2_D, t2))
            } else {
                // h = (ψ/2) cot(ψ/2), c₂ = (1 − h)/ψ²
                let half = 0.5 * t;
                let (sh, ch) = half.sin_cos();
                let h = half * ch / sh;
                let dh = 0.5 * ch / sh - 0.25 * t / (sh * sh);
                let c2 = (1.0 - h) / t2;
                let dc2 = -dh / t2 - 2.0 * (1.0 - h) / (t2 * t);
                (0.5, c2, 0.0, dc2 / t)
            }
        }
    }
}

/// `1 − cos ψ = 2 sin²(ψ/2)`, without the cancellation near 0.
#[inline]
fn one_minus_cos(t: f64) -> f64 {
    2.0 * (0.5 * t).sin().powi(2)
}

/// The coefficients of `exp(ψ~)` (eq. 2) at `ψ = t` from `sin t`, `cos t`
/// and `1 − cos t`.
#[inline]
fn exp_coefficients(t: f64, s: f64, c: f64, omc: f64) -> (f64, f64, f64, f64) {
    let t2 = t * t;
    (
        s / t,
        omc / t2,
        (t * c - s) / (t2 * t),
        (t * s - 2.0 * omc) / (t2 * t2),
    )
}

/// The coefficients of `T(ψ)` (eq. 4) at `ψ = t` from `sin t` and
/// `1 − cos t`.
#[inline]
fn tangent_coefficients(t: f64, s: f64, omc: f64) -> (f64, f64, f64, f64) {
    let t2 = t * t;
    (
        -omc / t2,
        (t - s) / (t2 * t),
        -(t * s - 2.0 * omc) / (t2 * t2),
        (t * omc - 3.0 * (t - s)) / (t2 * t2 * t),
    )
}

/// The exponential map: the rotation `exp(ψ~)` as a unit quaternion.
pub fn exp(psi: &Vec3) -> Rotation {
    let t2 = psi.norm_squared();
    let t = t2.sqrt();
    let half = 0.5 * t;
    // sin(ψ/2)/ψ, by series below 1e-4 rad
    let s = if t < 1e-4 {
        0.5 - t2 / 48.0
    } else {
        half.sin() / t
    };
    Rotation::new_unchecked(Quaternion::new(half.cos(), s * psi.x, s * psi.y, s * psi.z))
}

/// The logarithm map: the rotation vector `ψ` with `|ψ| ≤ π` such that
/// `exp(ψ~) = R`. At `|ψ| = π` either of the two opposite vectors may be
/// returned.
pub fn log(r: &Rotation) -> Vec3 {
    let q = r.quaternion();
    // choose the hemisphere w ≥ 0 so that |ψ| ≤ π
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let s = v.norm();
    // ψ = 2 atan2(s, w) v / s; the factor by series when s is tiny
    let factor = if s < 1e-8 {
        2.0 / w * (1.0 - s * s / (3.0 * w * w))
    } else {
        2.0 * s.atan2(w) / s
    };
    v * factor
}

/// `T(ψ)`, the material tangent operator of the exponential map (eq. 4).
pub fn tangent(psi: &Vec3) -> Mat3 {
    SkewSeries::new(Operator::Tangent, psi).matrix()
}

/// `T⁻¹(ψ)`, the inverse of the tangent operator.
pub fn tangent_inv(psi: &Vec3) -> Mat3 {
    SkewSeries::new(Operator::TangentInv, psi).matrix()
}

/// The rotation matrix `exp(ψ~)`, computed directly from the series form.
pub fn exp_matrix(psi: &Vec3) -> Mat3 {
    SkewSeries::new(Operator::Exp, psi).matrix()
}

/// Rotation matrix of a unit quaternion.
#[inline]
pub fn matrix(r: &Rotation) -> Mat3 {
    r.to_rotation_matrix().into_inner()
}

/// Unit quaternion of a rotation matrix (which must be orthonormal).
pub fn from_matrix(m: &Mat3) -> Rotation {
    Rotation::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(*m))
}

/// The rotation whose first column is the unit vector along `e1` and whose
/// second column is the part of `v2` orthogonal to `e1`. Returns `None` when
/// `e1` is zero or `v2` is (nearly) parallel to it.
pub fn frame_from_axis_and_vector(e1: &Vec3, v2: &Vec3) -> Option<Mat3> {
    let n1 = e1.norm();
    if n1 == 0.0 || !n1.is_finite() {
        return None;
    }
    let t1 = e1 / n1;
    let w = v2 - t1 * t1.dot(v2);
    let n2 = w.norm();
    if n2 <= 1e-8 * v2.norm() || n2 == 0.0 {
        return None;
    }
    let t2 = w / n2;
    let t3 = t1.cross(&t2);
    Some(Mat3::from_columns(&[t1, t2, t3]))
}

/// The smallest rotation taking the direction of `a` to that of `b`:
/// about `a × b` by the angle between them, `atan2(|a × b|, a·b)`. Two
/// opposite directions give a half turn about a direction normal to `a`;
/// a zero vector gives the identity.
pub fn rotation_between(a: &Vec3, b: &Vec3) -> Rotation {
    let (la, lb) = (a.norm(), b.norm());
    if la == 0.0 || lb == 0.0 {
        return Rotation::identity();
    }
    let (a, b) = (a / la, b / lb);
    let c = a.cross(&b);
    let s = c.norm();
    let angle = s.atan2(a.dot(&b));
    if s > 0.0 {
        exp(&(c * (angle / s)))
    } else if angle == 0.0 {
        Rotation::identity()
    } else {
        let other = if a.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        exp(&(a.cross(&other).normalize() * angle))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `tangent_and_exp` gives the two operators of `new`, to the bit, on
    /// both sides of the series angle.
    #[test]
    fn tangent_and_exp_equal_new() {
        for t in [
            0.0,
            1e-9,
            0.5 * SERIES_ANGLE,
            2.0 * SERIES_ANGLE,
            0.3,
            1.7,
            3.1,
        ] {
            let psi = Vec3::new(0.6, -0.48, 0.64) * t;
            let [tangent, exp] = SkewSeries::tangent_and_exp(&psi);
            for (a, op) in [(tangent, Operator::Tangent), (exp, Operator::Exp)] {
                let b = SkewSeries::new(op, &psi);
                assert_eq!(
                    [a.c1, a.c2, a.d1, a.d2].map(f64::to_bits),
                    [b.c1, b.c2, b.d1, b.d2].map(f64::to_bits),
                    "{op:?} at {t}"
                );
            }
        }
    }
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    proptest! {
        /// `rotation_between` takes `a` to `b` about an axis normal to both.
        #[test]
        fn rotation_between_takes_one_direction_to_the_other(a in vec3(2.0), b in vec3(2.0)) {
            prop_assume!(a.norm() > 1e-3 && b.norm() > 1e-3);
            let r = rotation_between(&a, &b);
            let (ea, eb) = (a.normalize(), b.normalize());
            prop_assert!((r * ea - eb).norm() < 1e-14);
            let psi = log(&r);
            prop_assert!(psi.dot(&ea).abs() < 1e-13 && psi.dot(&eb).abs() < 1e-13);
        }
    }

    #[test]
    fn rotation_between_opposite_and_equal_directions() {
        let a = Vec3::new(0.3, -1.0, 2.0);
        assert_eq!(rotation_between(&a, &(2.0 * a)), Rotation::identity());
        let r = rotation_between(&a, &(-a));
        assert_relative_eq!(r * a, -a, epsilon = 1e-14);
        assert_relative_eq!(log(&r).norm(), PI, epsilon = 1e-14);
    }

    fn vec3(max: f64) -> impl Strategy<Value = Vec3> {
        (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
    }

    /// A rotation vector with a prescribed angle in `[lo, hi]` and a random axis.
    fn angle_vector(lo: f64, hi: f64) -> impl Strategy<Value = Vec3> {
        (vec3(1.0), lo..hi).prop_filter_map("zero axis", |(a, t)| {
            let n = a.norm();
            (n > 1e-3).then(|| a * (t / n))
        })
    }

    // the exp of the series form must equal the quaternion exp
    proptest! {
        #[test]
        fn exp_matrix_matches_quaternion(psi in vec3(3.0)) {
            let a = exp_matrix(&psi);
            let b = matrix(&exp(&psi));
            prop_assert!((a - b).norm() < 1e-14);
        }

        #[test]
        fn exp_log_round_trip(psi in angle_vector(0.0, PI - 1e-6)) {
            // log(exp ψ) = ψ for |ψ| < π
            let back = log(&exp(&psi));
            prop_assert!((back - psi).norm() < 1e-13 * (1.0 + psi.norm()));
        }

        #[test]
        fn log_exp_round_trip(a in vec3(1.0), b in vec3(1.0), c in -1.0..1.0f64) {
            // exp(log R) = R for any R, including angles beyond π
            let q = Quaternion::new(c, a.x, b.y, a.z + b.x);
            prop_assume!(q.norm() > 1e-3);
            let r = Rotation::from_quaternion(q);
            let back = exp(&log(&r));
            prop_assert!((matrix(&back) - matrix(&r)).norm() < 1e-13);
        }

        #[test]
        fn tangent_times_inverse_is_identity(psi in angle_vector(0.0, 2.0 * PI - 0.1)) {
            let p = tangent(&psi) * tangent_inv(&psi);
            prop_assert!((p - Mat3::identity()).norm() < 1e-12 * (1.0 + tangent_inv(&psi).norm()));
        }

        #[test]
        fn tangent_identities(psi in angle_vector(0.0, 3.0)) {
            // T(ψ) ψ = ψ, and Tᵀ = R T (spatial and material tangents)
            let t = tangent(&psi);
            prop_assert!((t * psi - psi).norm() < 1e-14 * (1.0 + psi.norm()));
            prop_assert!((t.transpose() - exp_matrix(&psi) * t).norm() < 1e-13);
        }

        #[test]
        fn tangent_is_derivative_of_exp(psi in angle_vector(0.0, 3.0), d in vec3(1.0)) {
            // exp(ψ + h d) ≈ exp(ψ) exp(h T(ψ) d): central differences of the
            // material spin must match T d to O(h²)
            let h = 1e-6;
            let rp = exp(&(psi + d * h));
            let rm = exp(&(psi - d * h));
            let spin = log(&(rm.inverse() * rp)) / (2.0 * h);
            // rm⁻¹ rp = exp(2h T d) + O(h³)
            let expected = tangent(&(psi)) * d;
            prop_assert!((spin - expected).norm() < 1e-7 * (1.0 + d.norm()));
        }

        #[test]
        fn derivative_of_apply_matches_finite_differences(
            psi in angle_vector(0.0, 3.0), v in vec3(2.0), d in vec3(1.0)
        ) {
            let h = 1e-6;
            for op in [Operator::Exp, Operator::Tangent, Operator::TangentInv] {
                let s = SkewSeries::new(op, &psi);
                let fd = (SkewSeries::new(op, &(psi + d * h)).apply(&v)
                    - SkewSeries::new(op, &(psi - d * h)).apply(&v)) / (2.0 * h);
                let an = s.derivative_of_apply(&v) * d;
                prop_assert!((fd - an).norm() < 1e-7 * (1.0 + an.norm()), "{:?}", op);
                let fdt = (SkewSeries::new(op, &(psi + d * h)).apply_transpose(&v)
                    - SkewSeries::new(op, &(psi - d * h)).apply_transpose(&v)) / (2.0 * h);
                let ant = s.derivative_of_apply_transpose(&v) * d;
                prop_assert!((fdt - ant).norm() < 1e-7 * (1.0 + ant.norm()), "{:?}ᵀ", op);
            }
        }
    }

    #[test]
    fn series_and_closed_forms_agree_at_the_switch() {
        // both branches evaluated just around SERIES_ANGLE must agree
        for op in [Operator::Exp, Operator::Tangent, Operator::TangentInv] {
            let a = coefficients(op, SERIES_ANGLE, true);
            let b = coefficients(op, SERIES_ANGLE, false);
            for (x, y) in [(a.0, b.0), (a.1, b.1), (a.2, b.2), (a.3, b.3)] {
                assert_relative_eq!(x, y, max_relative = 1e-12, epsilon = 1e-15);
            }
        }
    }

    #[test]
    fn behaviour_near_zero() {
        // at ψ = 0: exp = I, T = I, T⁻¹ = I, log = 0, and the derivative of
        // exp(ψ) v is −v~ (first-order term of exp)
        let z = Vec3::zeros();
        assert_eq!(exp_matrix(&z), Mat3::identity());
        assert_eq!(tangent(&z), Mat3::identity());
        assert_eq!(tangent_inv(&z), Mat3::identity());
        assert_eq!(log(&Rotation::identity()), z);
        let v = Vec3::new(1.0, 2.0, 3.0);
        let d = SkewSeries::new(Operator::Exp, &z).derivative_of_apply(&v);
        assert_relative_eq!(d, -skew(&v), epsilon = 1e-15);
        // tiny angles: no loss of accuracy
        let psi = Vec3::new(1e-10, -2e-10, 3e-11);
        assert_relative_eq!(log(&exp(&psi)), psi, max_relative = 1e-12);
    }

    #[test]
    fn behaviour_near_pi() {
        // rotation by π − ε about an axis, and by exactly π
        let axis = Vec3::new(1.0, -2.0, 0.5).normalize();
        for eps in [1e-3, 1e-6, 1e-9] {
            let psi = axis * (PI - eps);
            assert_relative_eq!(log(&exp(&psi)), psi, epsilon = 1e-12);
        }
        let r = exp(&(axis * PI));
        let back = log(&r);
        assert_relative_eq!(back.norm(), PI, epsilon = 1e-12);
        assert_relative_eq!(back.normalize().dot(&axis).abs(), 1.0, epsilon = 1e-12);
        // just past π, log returns the shorter opposite rotation
        let psi = axis * (PI + 1e-3);
        let back = log(&exp(&psi));
        assert_relative_eq!(back, -axis * (PI - 1e-3), epsilon = 1e-12);
    }

    #[test]
    fn composition_follows_material_convention() {
        // R exp(ΔΘ~) with ΔΘ about the body axis 3 of R
        let r = exp(&Vec3::new(0.0, 0.0, PI / 2.0));
        let d = exp(&Vec3::new(PI / 2.0, 0.0, 0.0));
        let rd = matrix(&(r * d));
        let expected = matrix(&r) * matrix(&d);
        assert_relative_eq!(rd, expected, epsilon = 1e-15);
        // quaternion ↔ matrix round trip
        assert_relative_eq!(matrix(&from_matrix(&rd)), rd, epsilon = 1e-15);
    }

    #[test]
    fn frame_from_axis_and_vector_rejects_parallel_vectors() {
        let x = Vec3::x();
        assert!(frame_from_axis_and_vector(&x, &(x * 2.0)).is_none());
        assert!(frame_from_axis_and_vector(&Vec3::zeros(), &x).is_none());
        let f = frame_from_axis_and_vector(&Vec3::new(0.0, 0.0, 2.0), &Vec3::new(1.0, 0.0, 1.0))
            .unwrap();
        assert_relative_eq!(f * f.transpose(), Mat3::identity(), epsilon = 1e-15);
        assert_relative_eq!(f.determinant(), 1.0, epsilon = 1e-15);
    }
}
