//! A line of `log.txt` built as bytes: fixed texts and numbers are
//! appended straight to a buffer kept from line to line, without the
//! `core::fmt` machinery, which on a small model costs more than the
//! physics of a step (a line per Newton iteration, nine numbers each).

use super::number::{push_integer, Fixed, Sci, Shortest};

/// The bytes of one line (UTF-8: every piece is a `&str` or ASCII).
#[derive(Debug, Default)]
pub struct Line(Vec<u8>);

impl Line {
    /// Empties the line, keeping its buffer.
    pub fn clear(&mut self) -> &mut Self {
        self.0.clear();
        self
    }

    /// Appends `text`.
    pub fn text(&mut self, text: &str) -> &mut Self {
        self.0.extend_from_slice(text.as_bytes());
        self
    }

    /// Appends `v` as `{v}`.
    pub fn int(&mut self, v: usize) -> &mut Self {
        push_integer(&mut self.0, v as u64, 0);
        self
    }

    /// Appends `v` right-aligned in `width` columns, as `{v:width$}`.
    pub fn padded(&mut self, v: usize, width: usize) -> &mut Self {
        push_integer(&mut self.0, v as u64, width);
        self
    }

    /// Appends `x` as `{x:.P$e}`.
    pub fn sci<const P: usize>(&mut self, x: f64) -> &mut Self {
        Sci::<P>(x).push_bytes(&mut self.0);
        self
    }

    /// Appends `x` as `{x:.P$}`.
    pub fn fixed<const P: usize>(&mut self, x: f64) -> &mut Self {
        Fixed::<P>(x).push_bytes(&mut self.0);
        self
    }

    /// Appends `x` in the shortest scientific notation ([`Shortest`]).
    pub fn shortest(&mut self, x: f64) -> &mut Self {
        Shortest(x).push_bytes(&mut self.0);
        self
    }

    /// The line's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.0
    }

    /// The line as text (UTF-8, made of `&str` and ASCII pieces).
    pub fn as_text(&self) -> &str {
        std::str::from_utf8(&self.0).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each piece as `format!` writes it.
    #[test]
    fn pieces_are_written_as_format_writes_them() {
        let mut line = Line::default();
        line.text("step ")
            .padded(7, 4)
            .text("  t = ")
            .fixed::<6>(0.0003125)
            .text("  h = ")
            .sci::<3>(3.125e-4)
            .text(" ")
            .int(12345)
            .text(" ")
            .padded(123, 2)
            .text(" max|dθ| ")
            .shortest(0.1);
        let std = format!(
            "step {:4}  t = {:.6}  h = {:.3e} {} {:2} max|dθ| {:e}",
            7, 0.0003125, 3.125e-4, 12345, 123, 0.1
        );
        assert_eq!(line.as_text(), std);
        line.clear().int(0);
        assert_eq!(line.bytes(), b"0");
    }
}
