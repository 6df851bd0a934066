//! Numbers in scientific notation for the lines of `log.txt`, written as
//! the standard library's `{:.Pe}` writes them, without its exact decimal
//! expansion in the common case: a run of short steps writes a line per
//! Newton iteration with nine such numbers.

use std::fmt;

/// Exact powers of ten in `f64` (up to 10²²).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// `x` with `P` digits after the point in scientific notation, exactly as
/// `format!("{x:.P$e}")`.
#[derive(Clone, Copy, Debug)]
pub struct Sci<const P: usize>(pub f64);

/// The digits `q` (`P + 1` of them, `10^P ≤ q < 10^(P+1)`) and the
/// exponent of `a > 0` rounded to `P + 1` significant digits, when one
/// floating-point product decides them: `m = a·10^(P−e)` is within
/// `10^(P+1)·2⁻⁵³` of the exact scaled value, so its rounding to an
/// integer is that of the exact decimal expansion unless its fraction is
/// within 1e-6 of one half (then `None`, as for exponents beyond the exact
/// powers of ten).
fn digits<const P: usize>(a: f64) -> Option<(u64, i32)> {
    let lo = POW10[P];
    let hi = POW10[P + 1];
    let scaled = |e: i32| -> Option<f64> {
        let k = P as i32 - e;
        let p = *POW10.get(k.unsigned_abs() as usize)?;
        Some(if k >= 0 { a * p } else { a / p })
    };
    let mut e = a.log10().floor() as i32;
    let mut m = scaled(e)?;
    if m < lo {
        e -= 1;
        m = scaled(e)?;
    } else if m >= hi {
        e += 1;
        m = scaled(e)?;
    }
    if !(lo..hi).contains(&m) {
        return None;
    }
    let floor = m.floor();
    let frac = m - floor;
    if (frac - 0.5).abs() < 1e-6 {
        return None;
    }
    let mut q = floor as u64 + u64::from(frac > 0.5);
    if q as f64 >= hi {
        q /= 10;
        e += 1;
    }
    Some((q, e))
}

impl<const P: usize> fmt::Display for Sci<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        let (q, e) = if a == 0.0 {
            (0, 0)
        } else if a.is_finite() && a > 1e-300 {
            match digits::<P>(a) {
                Some(d) => d,
                None => return write!(f, "{x:.P$e}"),
            }
        } else {
            return write!(f, "{x:.P$e}");
        };
        // sign, first digit, point, P digits, 'e', exponent
        let mut buf = [0u8; 40];
        let mut n = 0;
        if x.is_sign_negative() {
            buf[n] = b'-';
            n += 1;
        }
        let mut d = [0u8; 20];
        let mut v = q;
        for k in (0..=P).rev() {
            d[k] = b'0' + (v % 10) as u8;
            v /= 10;
        }
        buf[n] = d[0];
        n += 1;
        if P > 0 {
            buf[n] = b'.';
            n += 1;
            buf[n..n + P].copy_from_slice(&d[1..=P]);
            n += P;
        }
        buf[n] = b'e';
        n += 1;
        if e < 0 {
            buf[n] = b'-';
            n += 1;
        }
        let mut ed = [0u8; 4];
        let mut ev = e.unsigned_abs();
        let mut len = 0;
        loop {
            ed[len] = b'0' + (ev % 10) as u8;
            ev /= 10;
            len += 1;
            if ev == 0 {
                break;
            }
        }
        for k in (0..len).rev() {
            buf[n] = ed[k];
            n += 1;
        }
        // ASCII only
        f.write_str(std::str::from_utf8(&buf[..n]).map_err(|_| fmt::Error)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text equals the standard library's for random numbers over the
    /// whole exponent range, both precisions used in `log.txt`, and the
    /// edge cases: zeros, ties, numbers that round up to the next power of
    /// ten, the smallest and largest magnitudes, NaN and infinities.
    #[test]
    fn matches_the_standard_library() {
        let mut seed = 3u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed
        };
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            9.9995,
            9.9994999,
            9.99951,
            0.99995,
            1.0005,
            1.0015,
            2.5e-7,
            1.25,
            1.35,
            9.95,
            99.95,
            1e22,
            1e23,
            1e-22,
            1e-23,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            1e-300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for _ in 0..400_000 {
            // random bits: every exponent and mantissa
            values.push(f64::from_bits(next()));
            // and numbers of a few digits, where ties are
            let digits = (next() % 100_000) as f64;
            let exp = (next() % 40) as i32 - 20;
            values.push(digits * 10f64.powi(exp) / 8.0);
        }
        for x in values {
            assert_eq!(format!("{}", Sci::<3>(x)), format!("{x:.3e}"), "{x:?}");
            assert_eq!(format!("{}", Sci::<1>(x)), format!("{x:.1e}"), "{x:?}");
        }
    }
}
