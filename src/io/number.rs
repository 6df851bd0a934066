//! Numbers in scientific notation for `log.txt` and the CSV result files,
//! written as the standard library's `{:.Pe}` and `{:e}` write them,
//! without its exact decimal expansion in the common case: a run of short
//! steps writes a line per Newton iteration with nine such numbers, and a
//! row of `nodes.csv` per node and output step with eleven.
//!
//! The digits come from the double scaled by an exact power of ten, the
//! product kept exactly as the sum of two doubles (below), and otherwise
//! from the shortest decimal that reads back to the same double (the
//! `zmij` crate: Schubfach, Giulietti 2020). Rounding those
//! digits to `P + 1` significant ones gives the rounding of the double
//! itself unless the double and its shortest decimal lie on two sides of a
//! rounding boundary; that cannot happen when the shortest decimal is
//! farther from the boundary than one unit in the last place of the
//! double (it is within half of one), and otherwise the standard library
//! decides.

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

/// A number for messages, as a person would write it in a model file:
/// plainly (`0.6`, `-1`, `2500`) from 1e-4 to 1e15, in exponent form
/// (`1e300`, `2.5e-7`) outside.
pub fn plain(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `x` in the shortest scientific notation that reads back to the same
/// double (at most 17 significant digits), as `format!("{x:e}")`: the
/// same text but where two shortest decimals are equally near `x`, which
/// the two may choose differently.
#[derive(Clone, Copy, Debug)]
pub struct Shortest(pub f64);

/// Room for a sign, 17 digits, a point, `e`, an exponent sign and three
/// exponent digits.
const TEXT: usize = 32;

/// The digits `q` (`P + 1` of them, `10^P ≤ q < 10^(P+1)`) and the
/// exponent `e` of `a > 0` rounded to `P + 1` significant digits, when the
/// scaled value `m = a·10^(P−e)` is found exactly enough: with an exact
/// power of ten (`|P − e| ≤ 22`), `m` is the unevaluated sum `m₁ + m₂` of
/// the rounded product (or quotient) and its error, found exactly by a
/// fused multiply–add (Dekker's product; the remainder of a division), to
/// about 2⁻¹⁰⁶ of `m`. Its rounding to an integer is that of the exact
/// decimal expansion unless its fraction is within 1e-9 of one half (then
/// `None`, as for exponents beyond the exact powers of ten).
fn digits_by_product<const P: usize>(a: f64) -> Option<(u64, i32)> {
    let lo = POW10[P];
    let hi = POW10[P + 1];
    let scaled = |e: i32| -> Option<(f64, f64)> {
        let k = P as i32 - e;
        let p = *POW10.get(k.unsigned_abs() as usize)?;
        Some(if k >= 0 {
            let m = a * p;
            (m, a.mul_add(p, -m))
        } else {
            let m = a / p;
            (m, (-m).mul_add(p, a) / p)
        })
    };
    let mut e = a.log10().floor() as i32;
    let (mut m, mut err) = scaled(e)?;
    if m < lo {
        e -= 1;
        (m, err) = scaled(e)?;
    } else if m >= hi {
        e += 1;
        (m, err) = scaled(e)?;
    }
    // the exact value within [10^P, 10^(P+1))
    if !(lo..hi).contains(&m) || (m == lo && err < 0.0) {
        return None;
    }
    // (in integers: above 2⁵³ not every integer is a double)
    let mut floor = m.floor() as u64;
    let mut frac = (m - m.floor()) + err;
    if frac < 0.0 {
        floor -= 1;
        frac += 1.0;
    } else if frac >= 1.0 {
        floor += 1;
        frac -= 1.0;
    }
    if (frac - 0.5).abs() < 1e-9 {
        return None;
    }
    let mut q = floor + u64::from(frac > 0.5);
    if q >= 10u64.pow(P as u32 + 1) {
        q /= 10;
        e += 1;
    }
    Some((q, e))
}

/// The shortest decimal that reads back to `a` (finite, `a > 0`): its
/// significant digits `m` (no trailing zero), their number `n` and the
/// exponent `e` of the first, `a ≈ m·10^(e−n+1)`.
fn shortest(a: f64) -> (u64, u32, i32) {
    let mut buffer = zmij::Buffer::new();
    // zmij writes `d.ddd`, `0.000ddd`, `ddd.d` or `d.ddde±x`
    let text = buffer.format_finite(a).as_bytes();
    let (mut m, mut n) = (0u64, 0u32);
    // digits after the point, and the exponent written after `e`
    let mut after_point = 0i32;
    let mut point = false;
    let mut exponent = 0i32;
    let mut k = 0;
    while k < text.len() {
        match text[k] {
            b'.' => point = true,
            b'e' => {
                let (sign, start) = match text.get(k + 1) {
                    Some(b'-') => (-1, k + 2),
                    Some(b'+') => (1, k + 2),
                    _ => (1, k + 1),
                };
                let e = text[start..]
                    .iter()
                    .fold(0i32, |e, d| 10 * e + i32::from(d - b'0'));
                exponent = sign * e;
                break;
            }
            d => {
                if m > 0 || d != b'0' {
                    m = 10 * m + u64::from(d - b'0');
                    n += 1;
                }
                if point {
                    after_point += 1;
                }
            }
        }
        k += 1;
    }
    // `a = m·10^(exponent − after_point)`, less its trailing zeros
    let mut scale = exponent - after_point;
    while m % 10 == 0 && n > 1 {
        m /= 10;
        n -= 1;
        scale += 1;
    }
    (m, n, scale + n as i32 - 1)
}

/// `P + 1` significant digits of `a > 0` and their exponent, rounded from
/// its shortest decimal when that is sure to round as the double itself
/// (module documentation), `None` otherwise.
fn digits_by_shortest<const P: usize>(a: f64) -> Option<(u64, i32)> {
    let (m, n, mut e) = shortest(a);
    let keep = P as u32 + 1;
    let (mut q, frac) = if n <= keep {
        (m * 10u64.pow(keep - n), 0.0)
    } else {
        let d = 10u64.pow(n - keep);
        (m / d, (m % d) as f64 / d as f64)
    };
    // distance of the shortest decimal from the nearest rounding boundary
    // against one unit in the last place of `a` (twice the largest
    // distance of `a` from its shortest decimal: room for the rounding of
    // this test)
    // (just below a power of ten the digits of the decade below are ten
    // times finer)
    let unit = 10f64.powi(e - P as i32);
    let unit = if q == 10u64.pow(P as u32) {
        0.1 * unit
    } else {
        unit
    };
    let boundary = (frac - 0.5).abs() * unit;
    let ulp = f64::from_bits(a.to_bits() + 1) - a;
    if e - (P as i32) < -290 || boundary.is_nan() || boundary <= ulp {
        return None;
    }
    if frac > 0.5 {
        q += 1;
        if q == 10u64.pow(keep) {
            q /= 10;
            e += 1;
        }
    }
    Some((q, e))
}

/// Writes `digits` (`count` of them, the first before the point) and the
/// exponent `e` into `buf` after the sign, as `{:e}` does; the length.
fn write_scientific(
    buf: &mut [u8; TEXT],
    negative: bool,
    digits: u64,
    count: usize,
    e: i32,
) -> usize {
    let mut n = 0;
    if negative {
        buf[n] = b'-';
        n += 1;
    }
    let mut d = [0u8; 20];
    let mut v = digits;
    for k in (0..count).rev() {
        d[k] = b'0' + (v % 10) as u8;
        v /= 10;
    }
    buf[n] = d[0];
    n += 1;
    if count > 1 {
        buf[n] = b'.';
        n += 1;
        buf[n..n + count - 1].copy_from_slice(&d[1..count]);
        n += count - 1;
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
    n
}

impl<const P: usize> Sci<P> {
    /// The text into `buf` and its length, `None` where the standard
    /// library must write it.
    fn text(self, buf: &mut [u8; TEXT]) -> Option<usize> {
        let x = self.0;
        let a = x.abs();
        let (q, e) = if a == 0.0 {
            (0, 0)
        } else if a.is_finite() && a > 1e-300 && P <= 15 {
            digits_by_product::<P>(a).or_else(|| digits_by_shortest::<P>(a))?
        } else {
            return None;
        };
        Some(write_scientific(buf, x.is_sign_negative(), q, P + 1, e))
    }

    /// Appends the text to `out`.
    pub fn push_to(self, out: &mut String) {
        let mut buf = [0u8; TEXT];
        match self.text(&mut buf) {
            // ASCII only
            Some(n) => out.push_str(std::str::from_utf8(&buf[..n]).unwrap_or_default()),
            None => {
                use std::fmt::Write as _;
                let x = self.0;
                let _ = write!(out, "{x:.P$e}");
            }
        }
    }
}

impl<const P: usize> fmt::Display for Sci<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut buf = [0u8; TEXT];
        match self.text(&mut buf) {
            // ASCII only
            Some(n) => f.write_str(std::str::from_utf8(&buf[..n]).map_err(|_| fmt::Error)?),
            None => {
                let x = self.0;
                write!(f, "{x:.P$e}")
            }
        }
    }
}

impl Shortest {
    /// Appends the text to `out`.
    pub fn push_to(self, out: &mut String) {
        let x = self.0;
        if !x.is_finite() {
            use std::fmt::Write as _;
            let _ = write!(out, "{x:e}");
            return;
        }
        let (m, n, e) = if x == 0.0 {
            (0, 1, 0)
        } else {
            shortest(x.abs())
        };
        let mut buf = [0u8; TEXT];
        let len = write_scientific(&mut buf, x.is_sign_negative(), m, n as usize, e);
        // ASCII only
        out.push_str(std::str::from_utf8(&buf[..len]).unwrap_or_default());
    }
}

impl fmt::Display for Shortest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut text = String::with_capacity(TEXT);
        self.push_to(&mut text);
        f.write_str(&text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sci<const P: usize>(x: f64) -> String {
        let mut text = String::new();
        Sci::<P>(x).push_to(&mut text);
        text
    }

    /// The text equals the standard library's for random numbers over the
    /// whole exponent range, the precisions used in `log.txt` and the result
    /// files and the shortest notation, and the
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
            // and computed numbers of every digit, as results are
            let unit = (next() >> 11) as f64 / (1u64 << 53) as f64;
            values.push((unit - 0.5) * 10f64.powi(exp));
        }
        for x in values {
            assert_eq!(format!("{}", Sci::<3>(x)), format!("{x:.3e}"), "{x:?}");
            assert_eq!(format!("{}", Sci::<1>(x)), format!("{x:.1e}"), "{x:?}");
            // the precisions of the result files
            for (text, std) in [
                (sci::<6>(x), format!("{x:.6e}")),
                (sci::<9>(x), format!("{x:.9e}")),
                (sci::<12>(x), format!("{x:.12e}")),
                (sci::<15>(x), format!("{x:.15e}")),
            ] {
                assert_eq!(text, std, "{x:?}");
            }
            // the shortest: as many digits as the standard library's, and
            // the same text but for the last digit of a tie
            let mut text = String::new();
            Shortest(x).push_to(&mut text);
            let std = format!("{x:e}");
            if x.is_finite() {
                assert_eq!(text.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{x:?}");
                let digits = |t: &str| t.split('e').next().unwrap().len();
                assert_eq!(digits(&text), digits(&std), "{x:?}: {text} {std}");
                if text != std {
                    // a tie: the last digit one apart, the rest the same
                    let (t, u) = (
                        text.split('e').next().unwrap(),
                        std.split('e').next().unwrap(),
                    );
                    let (tl, ul) = (t.as_bytes()[t.len() - 1], u.as_bytes()[u.len() - 1]);
                    assert_eq!(t[..t.len() - 1], u[..u.len() - 1], "{x:?}");
                    assert_eq!(tl.abs_diff(ul), 1, "{x:?}: {text} {std}");
                }
            } else {
                assert_eq!(text, std);
            }
        }
    }
}
