//! A reader of the VTK XML grids unfold writes, independent of the writer:
//! it parses the XML attributes and decodes ASCII arrays and appended raw
//! arrays compressed by `vtkZLibDataCompressor` (header_type UInt64), as
//! VTK's own reader does (vtkXMLDataParser: a header
//! `[blocks, block size, last block size or 0, compressed sizes…]` then the
//! zlib blocks, at `offset` bytes after the `_` that opens the appended
//! data). Every inconsistency panics with what is wrong.

use std::io::Read;

/// A grid file, read.
pub struct Grid {
    /// The XML part (everything before the appended data).
    pub xml: String,
    /// The appended data, from the byte after `_`.
    pub appended: Vec<u8>,
}

/// The value of attribute `name` in the XML start tag `tag`.
pub fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

impl Grid {
    /// Reads `bytes`, checking the envelope: XML declaration, VTKFile
    /// element, and for appended data the encoding and its end.
    pub fn parse(bytes: &[u8]) -> Self {
        assert!(bytes.starts_with(b"<?xml"), "no XML declaration");
        let end = b"</VTKFile>\n";
        assert!(
            bytes.ends_with(end),
            "the file does not end with </VTKFile>"
        );
        let marker = b"<AppendedData encoding=\"raw\">";
        match bytes.windows(marker.len()).position(|w| w == marker) {
            None => Self {
                xml: String::from_utf8(bytes.to_vec()).expect("ASCII grid is UTF-8"),
                appended: Vec::new(),
            },
            Some(at) => {
                let underscore = at
                    + marker.len()
                    + bytes[at + marker.len()..]
                        .iter()
                        .position(|&b| b == b'_')
                        .expect("appended data opens with _");
                let tail = b"\n  </AppendedData>\n</VTKFile>\n";
                assert!(bytes.ends_with(tail), "appended data is not closed");
                Self {
                    xml: String::from_utf8(bytes[..at].to_vec()).expect("XML part is UTF-8"),
                    appended: bytes[underscore + 1..bytes.len() - tail.len()].to_vec(),
                }
            }
        }
    }

    /// The VTKFile start tag.
    pub fn header(&self) -> &str {
        let start = self.xml.find("<VTKFile").expect("VTKFile element");
        &self.xml[start..start + self.xml[start..].find('>').unwrap()]
    }

    /// A `usize` attribute of the Piece.
    pub fn piece(&self, name: &str) -> usize {
        let start = self.xml.find("<Piece").expect("Piece element");
        let tag = &self.xml[start..start + self.xml[start..].find('>').unwrap()];
        attribute(tag, name).unwrap().parse().unwrap()
    }

    /// Start tags of every DataArray, in file order.
    pub fn array_tags(&self) -> Vec<&str> {
        self.xml
            .match_indices("<DataArray")
            .map(|(i, _)| &self.xml[i..i + self.xml[i..].find('>').unwrap()])
            .collect()
    }

    /// The values of array `name` (as f64), and its number of components.
    pub fn array(&self, name: &str) -> (Vec<f64>, usize) {
        let key = format!("Name=\"{name}\"");
        let at = self
            .xml
            .find(&key)
            .unwrap_or_else(|| panic!("no array {name}"));
        let start = self.xml[..at].rfind("<DataArray").unwrap();
        let tag_end = at + self.xml[at..].find('>').unwrap();
        let tag = &self.xml[start..tag_end];
        let ty = attribute(tag, "type").unwrap();
        let components: usize = attribute(tag, "NumberOfComponents")
            .unwrap()
            .parse()
            .unwrap();
        let values = match attribute(tag, "format").unwrap() {
            "ascii" => {
                let close = tag_end + self.xml[tag_end..].find("</DataArray>").unwrap();
                self.xml[tag_end + 1..close]
                    .split_whitespace()
                    .map(|v| v.parse().unwrap())
                    .collect()
            }
            "appended" => {
                assert!(tag.ends_with('/'), "{name}: appended array is not empty");
                let offset: usize = attribute(tag, "offset").unwrap().parse().unwrap();
                decode(ty, &self.inflate(name, offset).0)
            }
            f => panic!("{name}: unknown format {f}"),
        };
        assert_eq!(values.len() % components, 0, "{name}: partial tuple");
        (values, components)
    }

    /// The uncompressed bytes of the appended array at `offset`, and the
    /// offset just after it.
    pub fn inflate(&self, name: &str, offset: usize) -> (Vec<u8>, usize) {
        let word = |k: usize| {
            let b = &self.appended[offset + 8 * k..offset + 8 * k + 8];
            u64::from_le_bytes(b.try_into().unwrap()) as usize
        };
        let (blocks, block_size, last) = (word(0), word(1), word(2));
        assert!(block_size > 0, "{name}: block size 0");
        assert!(
            last < block_size,
            "{name}: last block {last} ≥ {block_size}"
        );
        let mut at = offset + 8 * (3 + blocks);
        let mut raw = Vec::new();
        for b in 0..blocks {
            let size = word(3 + b);
            let mut block = Vec::new();
            flate2::read::ZlibDecoder::new(&self.appended[at..at + size])
                .read_to_end(&mut block)
                .unwrap_or_else(|e| panic!("{name}: block {b} is not a zlib stream: {e}"));
            let expected = if b + 1 == blocks && last != 0 {
                last
            } else {
                block_size
            };
            assert_eq!(block.len(), expected, "{name}: block {b} size");
            raw.extend_from_slice(&block);
            at += size;
        }
        (raw, at)
    }

    /// Checks that the appended arrays follow one another with no gap and
    /// fill the appended data exactly; returns the number of blocks of the
    /// largest array.
    pub fn check_layout(&self) -> usize {
        let mut next = 0;
        let mut most_blocks = 0;
        for tag in self.array_tags() {
            let name = attribute(tag, "Name").unwrap();
            let offset: usize = attribute(tag, "offset")
                .unwrap_or_else(|| panic!("{name}: no offset"))
                .parse()
                .unwrap();
            assert_eq!(offset, next, "{name}: offset");
            let blocks = u64::from_le_bytes(self.appended[offset..offset + 8].try_into().unwrap());
            most_blocks = most_blocks.max(blocks as usize);
            next = self.inflate(name, offset).1;
        }
        assert_eq!(next, self.appended.len(), "bytes after the last array");
        most_blocks
    }
}

/// Little-endian values of VTK type `ty`.
fn decode(ty: &str, raw: &[u8]) -> Vec<f64> {
    match ty {
        "Float64" => raw
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        "Int64" => raw
            .chunks_exact(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect(),
        "Int32" => raw
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect(),
        "UInt8" => raw.iter().map(|&b| b as f64).collect(),
        t => panic!("unexpected type {t}"),
    }
}

/// Reads the grid file `path`.
pub fn read(path: &std::path::Path) -> Grid {
    Grid::parse(&std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
}
