//! Complete elliptic integral of the first kind and the Jacobi elliptic
//! functions, by the arithmetic–geometric mean (AGM): independent
//! references for the closed-form solutions of the pendulum and of the
//! torque-free rigid body.
//!
//! The parameter is `m = k²` throughout (Abramowitz & Stegun, ch. 16–17).

use std::f64::consts::FRAC_PI_2;

/// Largest number of AGM steps: the AGM converges quadratically, so 1e-16
/// is reached in 5–6 steps for m ≤ 1 − 1e-12; the bound only guards
/// against a non-terminating loop on bad input.
const MAX_AGM_STEPS: usize = 64;

/// Complete elliptic integral of the first kind
/// `K(m) = ∫₀^{π/2} dφ / √(1 − m sin²φ)`, `0 ≤ m < 1`:
/// `K(m) = π / (2 AGM(1, √(1 − m)))` (Abramowitz & Stegun 17.6.1–17.6.4).
pub fn complete_k(m: f64) -> f64 {
    assert!((0.0..1.0).contains(&m), "K(m) needs 0 ≤ m < 1, got {m}");
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    for _ in 0..MAX_AGM_STEPS {
        if (a - b).abs() <= 1e-16 * a {
            break;
        }
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    FRAC_PI_2 / a
}

/// Jacobi elliptic functions `(sn, cn, dn)(u | m)`, `0 ≤ m ≤ 1`, by the
/// descending Landen transformation / AGM scale (Abramowitz & Stegun
/// 16.4.1–16.4.4):
///
/// ```text
/// a₀ = 1, b₀ = √(1 − m), c₀ = √m;  aₙ = (aₙ₋₁ + bₙ₋₁)/2, bₙ = √(aₙ₋₁ bₙ₋₁), cₙ = (aₙ₋₁ − bₙ₋₁)/2
/// φ_N = 2ᴺ a_N u;  φₙ₋₁ = ½ (φₙ + asin(cₙ sin φₙ / aₙ))
/// sn = sin φ₀,  cn = cos φ₀,  dn = √(cn² + (1 − m) sn²)
/// ```
///
/// (dn from dn² = 1 − m sn² (A&S 16.9.1) written without cancellation;
/// A&S's `cos φ₀ / cos(φ₁ − φ₀)` is 0/0 at `u = K`).
pub fn jacobi(u: f64, m: f64) -> (f64, f64, f64) {
    assert!(
        (0.0..=1.0).contains(&m),
        "sn, cn, dn need 0 ≤ m ≤ 1, got {m}"
    );
    if m == 0.0 {
        return (u.sin(), u.cos(), 1.0);
    }
    if m == 1.0 {
        // the limit: sn = tanh, cn = dn = sech (A&S 16.6)
        let sech = 1.0 / u.cosh();
        return (u.tanh(), sech, sech);
    }
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    let mut aa = vec![a];
    let mut cc = vec![m.sqrt()];
    for _ in 0..MAX_AGM_STEPS {
        let c = 0.5 * (a - b);
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
        aa.push(a);
        cc.push(c);
        if c.abs() <= 1e-16 * a {
            break;
        }
    }
    let n = aa.len() - 1;
    let mut phi = 2f64.powi(n as i32) * aa[n] * u;
    for k in (1..=n).rev() {
        phi = 0.5 * (phi + (cc[k] * phi.sin() / aa[k]).asin());
    }
    let (sn, cn) = phi.sin_cos();
    (sn, cn, (cn * cn + (1.0 - m) * sn * sn).sqrt())
}
