//! Hyper-dual numbers `a + b ε₁ + c ε₂ + d ε₁ε₂` (ε₁² = ε₂² = 0) and the
//! small generic 3-vector and 3×3 algebra the joint formulas are written in.
//!
//! Evaluating a function `f` with one input seeded along `ε₁` and
//! another along `ε₂` gives, exactly and without truncation error, `f`, its
//! two first derivatives and the mixed second derivative (Fike & Alonso
//! 2011). Joint constraints and coordinates are written once, generically
//! over [`Real`], and differentiated this way (docs/joints.md §2): the
//! gradient `B` of eq. 18 and the second-derivative term `∂(Bᵀμ)/∂q` follow
//! from the same formula, so they cannot disagree with it.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The scalar operations joint formulas use.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Mul<f64, Output = Self>
    + Add<f64, Output = Self>
{
    /// A constant.
    fn cst(v: f64) -> Self;
    /// The real part.
    fn re(self) -> f64;
    /// `atan2(self, x)`.
    fn atan2(self, x: Self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
}

impl Real for f64 {
    #[inline]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline]
    fn re(self) -> f64 {
        self
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        f64::atan2(self, x)
    }
    #[inline]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

/// A hyper-dual number.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HyperDual {
    /// Real part.
    pub re: f64,
    /// Coefficient of ε₁.
    pub e1: f64,
    /// Coefficient of ε₂.
    pub e2: f64,
    /// Coefficient of ε₁ε₂.
    pub e12: f64,
}

impl HyperDual {
    /// `v + ε₁·d1 + ε₂·d2`.
    #[inline]
    pub fn new(v: f64, d1: f64, d2: f64) -> Self {
        Self {
            re: v,
            e1: d1,
            e2: d2,
            e12: 0.0,
        }
    }

    /// Applies a scalar function with value `f`, derivative `df` and second
    /// derivative `d2f` at the real part.
    #[inline]
    fn chain(self, f: f64, df: f64, d2f: f64) -> Self {
        Self {
            re: f,
            e1: df * self.e1,
            e2: df * self.e2,
            e12: df * self.e12 + d2f * self.e1 * self.e2,
        }
    }
}

impl Add for HyperDual {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self {
            re: self.re + o.re,
            e1: self.e1 + o.e1,
            e2: self.e2 + o.e2,
            e12: self.e12 + o.e12,
        }
    }
}

impl Add<f64> for HyperDual {
    type Output = Self;
    #[inline]
    fn add(mut self, o: f64) -> Self {
        self.re += o;
        self
    }
}

impl Sub for HyperDual {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self {
            re: self.re - o.re,
            e1: self.e1 - o.e1,
            e2: self.e2 - o.e2,
            e12: self.e12 - o.e12,
        }
    }
}

impl Neg for HyperDual {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            re: -self.re,
            e1: -self.e1,
            e2: -self.e2,
            e12: -self.e12,
        }
    }
}

impl Mul for HyperDual {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Self {
            re: self.re * o.re,
            e1: self.re * o.e1 + self.e1 * o.re,
            e2: self.re * o.e2 + self.e2 * o.re,
            e12: self.re * o.e12 + self.e1 * o.e2 + self.e2 * o.e1 + self.e12 * o.re,
        }
    }
}

impl Mul<f64> for HyperDual {
    type Output = Self;
    #[inline]
    fn mul(self, o: f64) -> Self {
        Self {
            re: self.re * o,
            e1: self.e1 * o,
            e2: self.e2 * o,
            e12: self.e12 * o,
        }
    }
}

impl Div for HyperDual {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        // self · (1/o), 1/x has derivatives −1/x², 2/x³
        let inv = 1.0 / o.re;
        self * o.chain(inv, -inv * inv, 2.0 * inv * inv * inv)
    }
}

impl Real for HyperDual {
    #[inline]
    fn cst(v: f64) -> Self {
        Self::new(v, 0.0, 0.0)
    }
    #[inline]
    fn re(self) -> f64 {
        self.re
    }
    fn atan2(self, x: Self) -> Self {
        // θ = atan2(y, x): dθ = (x dy − y dx)/r², and the mixed second
        // derivative from differentiating that once more
        let (y, r2) = (self, self.re * self.re + x.re * x.re);
        let th = self.re.atan2(x.re);
        let (gy, gx) = (x.re / r2, -y.re / r2);
        // Hessian of atan2 in (y, x)
        let r4 = r2 * r2;
        let hyy = -2.0 * x.re * y.re / r4;
        let hxx = 2.0 * x.re * y.re / r4;
        let hxy = (y.re * y.re - x.re * x.re) / r4;
        Self {
            re: th,
            e1: gy * y.e1 + gx * x.e1,
            e2: gy * y.e2 + gx * x.e2,
            e12: gy * y.e12
                + gx * x.e12
                + hyy * y.e1 * y.e2
                + hxx * x.e1 * x.e2
                + hxy * (y.e1 * x.e2 + x.e1 * y.e2),
        }
    }
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.re))
    }
}

/// A 3-vector of [`Real`]s.
#[derive(Clone, Copy, Debug)]
pub struct V3<T>(pub [T; 3]);

impl<T: Real> V3<T> {
    /// From an `f64` vector.
    pub fn cst(v: &crate::so3::Vec3) -> Self {
        Self([T::cst(v.x), T::cst(v.y), T::cst(v.z)])
    }
    /// Dot product.
    #[inline]
    pub fn dot(&self, o: &Self) -> T {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    /// Cross product.
    #[inline]
    pub fn cross(&self, o: &Self) -> Self {
        let (a, b) = (&self.0, &o.0);
        Self([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ])
    }
    /// `self + o`.
    #[inline]
    pub fn add(&self, o: &Self) -> Self {
        Self([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
    /// `self − o`.
    #[inline]
    pub fn sub(&self, o: &Self) -> Self {
        Self([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
    /// `s · self`.
    #[inline]
    pub fn scale(&self, s: T) -> Self {
        Self([self.0[0] * s, self.0[1] * s, self.0[2] * s])
    }
    /// Euclidean norm.
    #[inline]
    pub fn norm(&self) -> T {
        self.dot(self).sqrt()
    }
    /// Real parts.
    pub fn re(&self) -> crate::so3::Vec3 {
        crate::so3::Vec3::new(self.0[0].re(), self.0[1].re(), self.0[2].re())
    }
}

/// A 3×3 matrix of [`Real`]s, stored by columns.
#[derive(Clone, Copy, Debug)]
pub struct M3<T>(pub [V3<T>; 3]);

impl<T: Real> M3<T> {
    /// From an `f64` matrix.
    pub fn cst(m: &crate::so3::Mat3) -> Self {
        let c = |j: usize| V3([T::cst(m[(0, j)]), T::cst(m[(1, j)]), T::cst(m[(2, j)])]);
        Self([c(0), c(1), c(2)])
    }
    /// Column `j`.
    #[inline]
    pub fn col(&self, j: usize) -> V3<T> {
        self.0[j]
    }
    /// `self · v` with a constant vector.
    #[inline]
    pub fn apply(&self, v: &crate::so3::Vec3) -> V3<T> {
        let c = &self.0;
        V3([
            c[0].0[0] * v.x + c[1].0[0] * v.y + c[2].0[0] * v.z,
            c[0].0[1] * v.x + c[1].0[1] * v.y + c[2].0[1] * v.z,
            c[0].0[2] * v.x + c[1].0[2] * v.y + c[2].0[2] * v.z,
        ])
    }
    /// `self · m` with a constant matrix.
    pub fn mul_cst(&self, m: &crate::so3::Mat3) -> Self {
        Self([
            self.apply(&m.column(0).into_owned()),
            self.apply(&m.column(1).into_owned()),
            self.apply(&m.column(2).into_owned()),
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mixed second derivatives of atan2, sqrt and division against
    /// central differences of the first derivatives (h = 1e-6, tolerance
    /// 1e-8: the truncation error of the differences).
    #[test]
    fn second_derivatives_match_finite_differences() {
        let f = |a: HyperDual, b: HyperDual| {
            (a * b + a).atan2(b - a * a) + (a * a + b * b).sqrt() / (b + 3.0)
        };
        let (a0, b0) = (0.7, -0.4);
        let v = f(HyperDual::new(a0, 1.0, 0.0), HyperDual::new(b0, 0.0, 1.0));
        let h = 1e-6;
        let dfda = |b: f64| f(HyperDual::new(a0, 1.0, 0.0), HyperDual::new(b, 0.0, 0.0)).e1;
        let fd = (dfda(b0 + h) - dfda(b0 - h)) / (2.0 * h);
        assert!((v.e12 - fd).abs() < 1e-8, "{} vs {fd}", v.e12);
        let fa = |a: f64| f(HyperDual::cst(a), HyperDual::cst(b0)).re;
        assert!((v.e1 - (fa(a0 + h) - fa(a0 - h)) / (2.0 * h)).abs() < 1e-8);
    }
}
