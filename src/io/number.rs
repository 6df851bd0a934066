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
    // the exponent of `a` or one less (no `log10`), and then the one that
    // puts `m` in [10^P, 10^(P+1))
    let mut e = exponent_estimate(a);
    let (mut m, mut err) = match scaled(e) {
        Some(s) => s,
        None => {
            e += 1;
            scaled(e)?
        }
    };
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
    // (in integers: above 2⁵³ not every integer is a double; `m > 0`, so
    // the conversion is its floor, through `i64`: one instruction,
    // `m < 2⁶³`)
    let mut floor = m as i64 as u64;
    let mut frac = (m - floor as f64) + err;
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

/// `⌊log₁₀ a⌋` or one less, for a normal `a > 0`: from its binary
/// exponent `b` (`2^b ≤ a < 2^(b+1)`), `⌊b log₁₀ 2⌋`, with
/// `log₁₀ 2 ≈ 78913 / 2¹⁸` (exact floors for `|b| < 1700`).
fn exponent_estimate(a: f64) -> i32 {
    let b = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    (b * 78913) >> 18
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

/// The two digits of 0 to 99: `00`, `01`, …, `99`.
const DIGIT_PAIRS: [u8; 200] = {
    let mut pairs = [0u8; 200];
    let mut i = 0;
    while i < 100 {
        pairs[2 * i] = b'0' + (i / 10) as u8;
        pairs[2 * i + 1] = b'0' + (i % 10) as u8;
        i += 1;
    }
    pairs
};

/// Writes `digits` (`count` of them, the first before the point) and the
/// exponent `e` into `buf` after the sign, as `{:e}` does; the length.
/// (Inlined: in `Sci<P>`, `count` is a constant and the loop unrolled.)
#[inline(always)]
fn write_scientific(
    buf: &mut [u8; TEXT],
    negative: bool,
    digits: u64,
    count: usize,
    e: i32,
) -> usize {
    // the sign, overwritten by the first digit when there is none
    buf[0] = b'-';
    let first = usize::from(negative);
    // the digits after the point (at `first + 2 ..`), from the last, two
    // at a time
    let mut v = digits;
    let mut k = first + count;
    while k >= first + 3 {
        let pair = 2 * (v % 100) as usize;
        v /= 100;
        buf[k - 1] = DIGIT_PAIRS[pair];
        buf[k] = DIGIT_PAIRS[pair + 1];
        k -= 2;
    }
    if k == first + 2 {
        buf[k] = b'0' + (v % 10) as u8;
        v /= 10;
    }
    buf[first] = b'0' + v as u8;
    buf[first + 1] = b'.';
    let mut n = if count > 1 {
        first + count + 1
    } else {
        first + 1
    };
    buf[n] = b'e';
    n += 1;
    if e < 0 {
        buf[n] = b'-';
        n += 1;
    }
    // at most three digits (|e| ≤ 324)
    let ev = e.unsigned_abs();
    if ev >= 100 {
        buf[n] = b'0' + (ev / 100) as u8;
        n += 1;
    }
    if ev >= 10 {
        buf[n] = b'0' + (ev / 10 % 10) as u8;
        n += 1;
    }
    buf[n] = b'0' + (ev % 10) as u8;
    n + 1
}

/// Appends the first `n` bytes of `buf` to `out`: the whole buffer is
/// copied (a fixed size, no call to `memcpy`) and the rest cut off.
#[inline]
fn push_text(out: &mut Vec<u8>, buf: &[u8; TEXT], n: usize) {
    let len = out.len();
    out.extend_from_slice(buf);
    out.truncate(len + n);
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

    /// Appends the text to `out`, as bytes.
    pub fn push_bytes(self, out: &mut Vec<u8>) {
        let mut buf = [0u8; TEXT];
        match self.text(&mut buf) {
            Some(n) => push_text(out, &buf, n),
            None => {
                use std::io::Write as _;
                let x = self.0;
                let _ = write!(out, "{x:.P$e}");
            }
        }
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
    /// The text into `buf` and its length, `None` where the standard
    /// library must write it (not finite).
    fn text(self, buf: &mut [u8; TEXT]) -> Option<usize> {
        let x = self.0;
        if !x.is_finite() {
            return None;
        }
        let (m, n, e) = if x == 0.0 {
            (0, 1, 0)
        } else {
            shortest(x.abs())
        };
        Some(write_scientific(
            buf,
            x.is_sign_negative(),
            m,
            n as usize,
            e,
        ))
    }

    /// Appends the text to `out`, as bytes.
    pub fn push_bytes(self, out: &mut Vec<u8>) {
        let mut buf = [0u8; TEXT];
        match self.text(&mut buf) {
            Some(n) => push_text(out, &buf, n),
            None => {
                use std::io::Write as _;
                let x = self.0;
                let _ = write!(out, "{x:e}");
            }
        }
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
                let _ = write!(out, "{x:e}");
            }
        }
    }
}

/// `x` with `P` digits after the point, exactly as `format!("{x:.P$}")`
/// (ties of the exact value, as `0.125` to two digits, to even).
#[derive(Clone, Copy, Debug)]
pub struct Fixed<const P: usize>(pub f64);

impl<const P: usize> Fixed<P> {
    /// Appends the text to `out`, as bytes.
    pub fn push_bytes(self, out: &mut Vec<u8>) {
        match self.scaled() {
            Some(q) => {
                let unit = 10u64.pow(P as u32);
                push_integer(out, q / unit, 0);
                if P > 0 {
                    out.push(b'.');
                    // the digits after the point, leading zeros kept
                    let mut digits = [b'0'; 20];
                    let mut v = q % unit;
                    for d in digits[..P].iter_mut().rev() {
                        *d = b'0' + (v % 10) as u8;
                        v /= 10;
                    }
                    out.extend_from_slice(&digits[..P]);
                }
            }
            None => {
                use std::io::Write as _;
                let x = self.0;
                let _ = write!(out, "{x:.P$}");
            }
        }
    }

    /// `x·10^P` rounded to an integer, for `0 ≤ x < 10⁶` (no sign to
    /// write) and `P ≤ 9`; `None` otherwise. The product of two doubles is
    /// exactly `m + err` (both doubles, `err` by a fused multiply–add) and
    /// `m < 2⁵⁰`, so `m`'s unit in the last place `u` is at most 1/8 and
    /// divides both `m`'s fraction `f` and one half: `f − ½` is 0 or at
    /// least `u` in size (exact unless it is near −½) against
    /// `|err| ≤ u/2`, which then cannot change the side of one half.
    fn scaled(self) -> Option<u64> {
        let x = self.0;
        if P > 9 || x.is_sign_negative() || !(0.0..1e6).contains(&x) {
            return None;
        }
        let p = POW10[P];
        let m = x * p;
        let err = x.mul_add(p, -m);
        // (through `i64`: one instruction)
        let floor = m as i64 as u64;
        let half = (m - floor as f64) - 0.5;
        let up = if half != 0.0 {
            half > 0.0
        } else if err != 0.0 {
            err > 0.0
        } else {
            // an exact tie: to the even integer
            floor % 2 == 1
        };
        Some(floor + u64::from(up))
    }
}

/// Appends `v` to `out` in decimal, right-aligned in `width` columns as
/// `format!("{v:width$}")`.
pub fn push_integer(out: &mut Vec<u8>, v: u64, width: usize) {
    let mut buffer = itoa::Buffer::new();
    let digits = buffer.format(v).as_bytes();
    for _ in digits.len()..width {
        out.push(b' ');
    }
    out.extend_from_slice(digits);
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

    fn fixed<const P: usize>(x: f64) -> String {
        let mut text = Vec::new();
        Fixed::<P>(x).push_bytes(&mut text);
        String::from_utf8(text).unwrap()
    }

    /// `Fixed` equals the standard library's `{:.P}`: at exact ties (to
    /// even), near them (multiples of a time step such as 0.0003125),
    /// at random, and outside its range (negative, large, NaN).
    #[test]
    fn fixed_matches_the_standard_library() {
        let mut seed = 5u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            seed
        };
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            1.5,
            2.5,
            0.125,
            0.375,
            0.0078125,
            0.0000005,
            0.9999995,
            999_999.9999995,
            999_999.999_999_9,
            1e6,
            -1.25,
            5e-324,
            f64::NAN,
            f64::INFINITY,
        ];
        for k in 0..20_000 {
            values.push(k as f64 * 0.0003125);
            values.push(k as f64 * 0.001);
            values.push(k as f64 / 1024.0);
        }
        for _ in 0..400_000 {
            let unit = (next() >> 11) as f64 / (1u64 << 53) as f64;
            let exp = (next() % 16) as i32 - 9;
            values.push(unit * 10f64.powi(exp));
            // dyadic numbers: exact ties
            values.push((next() % (1 << 30)) as f64 / (1u64 << (next() % 30)) as f64);
        }
        for x in values {
            assert_eq!(fixed::<6>(x), format!("{x:.6}"), "{x:?}");
            assert_eq!(fixed::<3>(x), format!("{x:.3}"), "{x:?}");
            assert_eq!(fixed::<1>(x), format!("{x:.1}"), "{x:?}");
            assert_eq!(fixed::<0>(x), format!("{x:.0}"), "{x:?}");
            assert_eq!(fixed::<9>(x), format!("{x:.9}"), "{x:?}");
        }
    }

    /// Integers as `{v}` and `{v:w}`.
    #[test]
    fn integers_match_the_standard_library() {
        for v in [0u64, 7, 10, 99, 100, 12345, u64::MAX] {
            for w in [0, 2, 4, 25] {
                let mut text = Vec::new();
                push_integer(&mut text, v, w);
                assert_eq!(String::from_utf8(text).unwrap(), format!("{v:w$}"));
            }
        }
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
            let mut bytes = Vec::new();
            Sci::<3>(x).push_bytes(&mut bytes);
            Shortest(x).push_bytes(&mut bytes);
            let mut text = String::new();
            Sci::<3>(x).push_to(&mut text);
            Shortest(x).push_to(&mut text);
            assert_eq!(bytes, text.as_bytes(), "{x:?}");
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
