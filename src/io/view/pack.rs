//! The binary part of a viewer page: arrays laid one after the other in
//! one buffer (each at a multiple of 8 bytes), compressed as one zlib
//! stream and written in base64; the page's manifest gives each array's
//! place and encoding, which `assets/viewer/viewer.js` decodes.
//!
//! Values that change with time are **quantised**: a value `v` of an array
//! whose range over the whole run is `[lo, hi]` is the code
//! `round((v − lo)/(hi − lo) · 65534)` (a `u16`; 65535 marks a missing
//! value), a resolution of 1.5e-5 of the range, finer than a pixel or a
//! colour of the map can show. The codes of a frame are written as their
//! differences from the frame before (modulo 2¹⁶, lossless), low bytes of
//! the whole array then high bytes: a structure that moves little from one
//! output step to the next gives differences near zero, mostly zero high
//! bytes, which zlib compresses several times over.

use base64::Engine as _;
use flate2::write::ZlibEncoder;
use flate2::Compression;
use serde_json::{json, Value};
use std::io::Write as _;

/// The code of a missing value.
pub const MISSING: u16 = u16::MAX;

/// The largest code of a value: `hi`.
pub const TOP: f64 = 65534.0;

/// The code of `v` in `[lo, hi]` (module documentation); [`MISSING`] for
/// a value that is not finite.
pub fn code(v: f64, lo: f64, hi: f64) -> u16 {
    if !v.is_finite() {
        return MISSING;
    }
    if hi > lo {
        ((v - lo) / (hi - lo) * TOP).round().clamp(0.0, TOP) as u16
    } else {
        0
    }
}

/// The range `[lo, hi]` of the finite values; `None` if there are none.
pub fn range(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |r, v| match r {
            None => Some((v, v)),
            Some((lo, hi)) => Some((f64::min(lo, v), f64::max(hi, v))),
        })
}

/// The arrays of a page, being laid out.
#[derive(Default)]
pub struct Blob {
    bytes: Vec<u8>,
}

impl Blob {
    /// Pads to a multiple of 8 bytes and returns the offset.
    fn start(&mut self) -> usize {
        self.bytes.resize(self.bytes.len().next_multiple_of(8), 0);
        self.bytes.len()
    }

    /// Codes of `frames` frames of `width` values each (frame after
    /// frame), as differences between frames in two byte planes (module
    /// documentation).
    pub fn frames(&mut self, codes: &[u16], width: usize) -> Value {
        assert!(width > 0 && codes.len().is_multiple_of(width));
        let offset = self.start();
        let n = codes.len();
        self.bytes.resize(offset + 2 * n, 0);
        let (low, high) = self.bytes[offset..].split_at_mut(n);
        for i in 0..n {
            let d = if i >= width {
                codes[i].wrapping_sub(codes[i - width])
            } else {
                codes[i]
            };
            let [l, h] = d.to_le_bytes();
            low[i] = l;
            high[i] = h;
        }
        json!({ "encoding": "u16-delta", "offset": offset, "count": n, "width": width })
    }

    /// Bytes as they are.
    pub fn bytes(&mut self, values: &[u8]) -> Value {
        let offset = self.start();
        self.bytes.extend_from_slice(values);
        json!({ "encoding": "u8", "offset": offset, "count": values.len() })
    }

    /// 32-bit integers, little-endian.
    pub fn i32s(&mut self, values: &[i32]) -> Value {
        let offset = self.start();
        for v in values {
            self.bytes.extend_from_slice(&v.to_le_bytes());
        }
        json!({ "encoding": "i32", "offset": offset, "count": values.len() })
    }

    /// Doubles, little-endian.
    pub fn f64s(&mut self, values: &[f64]) -> Value {
        let offset = self.start();
        for v in values {
            self.bytes.extend_from_slice(&v.to_le_bytes());
        }
        json!({ "encoding": "f64", "offset": offset, "count": values.len() })
    }

    /// Uncompressed size, bytes.
    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    /// Whether nothing was laid out.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// The buffer compressed and in base64.
    pub fn finish(self) -> String {
        deflate_base64(&self.bytes)
    }
}

/// `bytes` compressed as one zlib stream and written in base64, as the
/// page's `DecompressionStream("deflate")` reads it. zlib's default level
/// (6): on the ERA cell's page, level 9 took 4 times as long for 1 % less.
pub fn deflate_base64(bytes: &[u8]) -> String {
    let mut z = ZlibEncoder::new(Vec::with_capacity(bytes.len() / 3), Compression::default());
    // writing into a Vec cannot fail
    let _ = z.write_all(bytes);
    let compressed = z.finish().unwrap_or_default();
    base64::engine::general_purpose::STANDARD.encode(compressed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read as _;

    /// Codes span `[0, 65534]` over the range; the frames' differences
    /// in byte planes add up again to the codes (as the page decodes
    /// them), and the buffer comes back from base64 and zlib.
    #[test]
    fn codes_and_frames_round_trip() {
        assert_eq!(code(1.0, 1.0, 3.0), 0);
        assert_eq!(code(3.0, 1.0, 3.0), 65534);
        assert_eq!(code(2.0, 1.0, 3.0), 32767);
        assert_eq!(code(f64::NAN, 1.0, 3.0), MISSING);
        assert_eq!(code(5.0, 2.0, 2.0), 0);
        assert_eq!(range([3.0, f64::NAN, -1.0, 2.0]), Some((-1.0, 3.0)));

        let codes: Vec<u16> = vec![10, 65535, 7, 12, 0, 9, 65534, 3, 9];
        let mut blob = Blob::default();
        blob.bytes(&[1, 2, 3]);
        let d = blob.frames(&codes, 3);
        let offset = d["offset"].as_u64().unwrap() as usize;
        assert_eq!(offset, 8);
        let text = blob.finish();
        let compressed = base64::engine::general_purpose::STANDARD
            .decode(text)
            .unwrap();
        let mut raw = Vec::new();
        flate2::read::ZlibDecoder::new(&compressed[..])
            .read_to_end(&mut raw)
            .unwrap();
        let n = codes.len();
        let mut decoded = vec![0u16; n];
        for i in 0..n {
            let d = u16::from_le_bytes([raw[offset + i], raw[offset + n + i]]);
            decoded[i] = if i >= 3 {
                d.wrapping_add(decoded[i - 3])
            } else {
                d
            };
        }
        assert_eq!(decoded, codes);
    }
}
