//! A reader of the VTK XML unstructured grids (`.vtu`) that `unfold run`
//! writes ([`crate::io::vtk`]): the XML attributes of each `DataArray`,
//! its values as text (`format="ascii"`) or appended raw data, compressed
//! by `vtkZLibDataCompressor` or not, with a `UInt64` or `UInt32` header
//! (VTK's `vtkXMLDataParser`: `[blocks, block size, last block size (0 if
//! full), compressed size of each block]` then the zlib blocks, at
//! `offset` bytes after the `_` that opens the appended data).

use std::io::Read;

/// Where an array is in the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    /// `<PointData>`: one tuple per point.
    Points,
    /// `<CellData>`: one tuple per cell.
    Cells,
    /// `<Points>`: the positions.
    Geometry,
    /// `<Cells>`: connectivity, offsets, types.
    Topology,
}

/// A data array, its values as `f64` (every VTK number type fits, ids up
/// to 2⁵³ exactly).
#[derive(Clone, Debug)]
pub struct Array {
    /// `Name`.
    pub name: String,
    /// The section it is in.
    pub section: Section,
    /// `NumberOfComponents`.
    pub components: usize,
    /// Whether its type is a floating-point one (`Float32`, `Float64`).
    pub float: bool,
    /// The values, tuple after tuple.
    pub values: Vec<f64>,
}

/// A grid, read.
#[derive(Clone, Debug)]
pub struct Grid {
    /// `NumberOfPoints`.
    pub points: usize,
    /// `NumberOfCells`.
    pub cells: usize,
    /// Every data array, in file order.
    pub arrays: Vec<Array>,
}

impl Grid {
    /// The array `name` of `section`.
    pub fn array(&self, section: Section, name: &str) -> Option<&Array> {
        self.arrays
            .iter()
            .find(|a| a.section == section && a.name == name)
    }

    /// The array `name` of `section`, which must be there: an error naming
    /// it otherwise.
    pub fn require(&self, section: Section, name: &str) -> Result<&Array, String> {
        self.array(section, name)
            .ok_or_else(|| format!("no {} array {name:?}", section_name(section)))
    }

    /// Reads the grid in `bytes`; the error says what is wrong.
    pub fn parse(bytes: &[u8]) -> Result<Self, String> {
        let marker = b"<AppendedData";
        let (xml_end, appended) = match find(bytes, marker) {
            None => (bytes.len(), &[][..]),
            Some(at) => {
                let underscore = bytes[at..]
                    .iter()
                    .position(|&b| b == b'_')
                    .ok_or("the appended data does not open with _")?;
                (at, &bytes[at + underscore + 1..])
            }
        };
        let xml = std::str::from_utf8(&bytes[..xml_end])
            .map_err(|_| "the XML part is not UTF-8 text".to_string())?;
        let head = tag_at(xml, "<VTKFile").ok_or("not a VTK XML file (no <VTKFile>)")?;
        if attribute(head, "type") != Some("UnstructuredGrid") {
            return Err("not an unstructured grid (VTKFile type is not UnstructuredGrid)".into());
        }
        if attribute(head, "byte_order").is_some_and(|o| o != "LittleEndian") {
            return Err("big-endian data is not read".into());
        }
        let wide = match attribute(head, "header_type") {
            None | Some("UInt32") => false,
            Some("UInt64") => true,
            Some(t) => return Err(format!("header_type {t} is not read")),
        };
        let compressed = match attribute(head, "compressor") {
            None => false,
            Some("vtkZLibDataCompressor") => true,
            Some(c) => return Err(format!("compressor {c} is not read")),
        };
        let piece = tag_at(xml, "<Piece").ok_or("no <Piece>")?;
        let count = |name: &str| -> Result<usize, String> {
            attribute(piece, name)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("<Piece> has no {name}"))
        };
        let (points, cells) = (count("NumberOfPoints")?, count("NumberOfCells")?);
        let appended = Appended {
            data: appended,
            wide,
            compressed,
        };

        let mut arrays = Vec::new();
        for (at, _) in xml.match_indices("<DataArray") {
            let tag = &xml[at..at + xml[at..].find('>').ok_or("an unclosed <DataArray>")?];
            let name = attribute(tag, "Name").unwrap_or("").to_string();
            let section = section_of(&xml[..at])
                .ok_or_else(|| format!("{name:?}: a DataArray outside any section"))?;
            let ty = attribute(tag, "type").ok_or_else(|| format!("{name:?}: no type"))?;
            let components = attribute(tag, "NumberOfComponents")
                .map_or(Ok(1), |c| c.parse::<usize>())
                .map_err(|_| format!("{name:?}: NumberOfComponents is not a number"))?
                .max(1);
            let values = match attribute(tag, "format") {
                Some("ascii") => {
                    let body = &xml[at + tag.len() + 1..];
                    let close = body
                        .find("</DataArray>")
                        .ok_or_else(|| format!("{name:?}: no </DataArray>"))?;
                    body[..close]
                        .split_whitespace()
                        .map(|v| v.parse::<f64>())
                        .collect::<Result<Vec<_>, _>>()
                        .map_err(|_| format!("{name:?}: a value is not a number"))?
                }
                Some("appended") => {
                    let offset: usize = attribute(tag, "offset")
                        .and_then(|o| o.parse().ok())
                        .ok_or_else(|| format!("{name:?}: no offset"))?;
                    let raw = appended
                        .array(offset)
                        .map_err(|e| format!("{name:?}: {e}"))?;
                    decode(ty, &raw).map_err(|e| format!("{name:?}: {e}"))?
                }
                Some(f) => return Err(format!("{name:?}: format {f} is not read")),
                None => return Err(format!("{name:?}: no format")),
            };
            let tuples = match section {
                Section::Points | Section::Geometry => Some(points),
                Section::Cells => Some(cells),
                Section::Topology => None,
            };
            if let Some(n) = tuples {
                if values.len() != n * components {
                    return Err(format!(
                        "{name:?}: {} values for {n} tuples of {components}",
                        values.len()
                    ));
                }
            }
            arrays.push(Array {
                name,
                section,
                components,
                float: ty.starts_with("Float"),
                values,
            });
        }
        Ok(Self {
            points,
            cells,
            arrays,
        })
    }
}

/// Name of a section in messages.
fn section_name(section: Section) -> &'static str {
    match section {
        Section::Points => "point data",
        Section::Cells => "cell data",
        Section::Geometry => "points",
        Section::Topology => "cells",
    }
}

/// The section open at the end of `before` (the XML up to a DataArray).
fn section_of(before: &str) -> Option<Section> {
    [
        ("<PointData", Section::Points),
        ("<CellData", Section::Cells),
        ("<Points>", Section::Geometry),
        ("<Cells>", Section::Topology),
    ]
    .into_iter()
    .filter_map(|(tag, s)| before.rfind(tag).map(|at| (at, s)))
    .max_by_key(|(at, _)| *at)
    .map(|(_, s)| s)
}

/// The appended data of a grid.
struct Appended<'a> {
    data: &'a [u8],
    /// `UInt64` header words (else `UInt32`).
    wide: bool,
    compressed: bool,
}

impl Appended<'_> {
    /// Header word `k` of the array at `offset`.
    fn word(&self, offset: usize, k: usize) -> Result<usize, String> {
        let size = if self.wide { 8 } else { 4 };
        let at = offset + size * k;
        let bytes = self
            .data
            .get(at..at + size)
            .ok_or("its header runs past the end of the file")?;
        Ok(if self.wide {
            u64::from_le_bytes(bytes.try_into().expect("8 bytes")) as usize
        } else {
            u32::from_le_bytes(bytes.try_into().expect("4 bytes")) as usize
        })
    }

    /// The bytes of the array at `offset`, inflated.
    fn array(&self, offset: usize) -> Result<Vec<u8>, String> {
        let size = if self.wide { 8 } else { 4 };
        if !self.compressed {
            let n = self.word(offset, 0)?;
            return self
                .data
                .get(offset + size..offset + size + n)
                .map(<[u8]>::to_vec)
                .ok_or_else(|| "its data runs past the end of the file".to_string());
        }
        let blocks = self.word(offset, 0)?;
        let mut at = offset + size * (3 + blocks);
        let mut raw = Vec::new();
        for b in 0..blocks {
            let n = self.word(offset, 3 + b)?;
            let block = self
                .data
                .get(at..at + n)
                .ok_or("its data runs past the end of the file")?;
            flate2::read::ZlibDecoder::new(block)
                .read_to_end(&mut raw)
                .map_err(|e| format!("block {b} is not a zlib stream ({e})"))?;
            at += n;
        }
        Ok(raw)
    }
}

/// Little-endian values of VTK type `ty`, as `f64`.
fn decode(ty: &str, raw: &[u8]) -> Result<Vec<f64>, String> {
    fn each<const N: usize>(raw: &[u8], f: impl Fn([u8; N]) -> f64) -> Result<Vec<f64>, String> {
        if !raw.len().is_multiple_of(N) {
            return Err(format!(
                "{} bytes is not a whole number of values",
                raw.len()
            ));
        }
        Ok(raw
            .chunks_exact(N)
            .map(|c| f(c.try_into().expect("N bytes")))
            .collect())
    }
    match ty {
        "Float64" => each(raw, f64::from_le_bytes),
        "Float32" => each(raw, |b| f32::from_le_bytes(b) as f64),
        "Int64" => each(raw, |b| i64::from_le_bytes(b) as f64),
        "UInt64" => each(raw, |b| u64::from_le_bytes(b) as f64),
        "Int32" => each(raw, |b| i32::from_le_bytes(b) as f64),
        "UInt32" => each(raw, |b| u32::from_le_bytes(b) as f64),
        "Int16" => each(raw, |b| i16::from_le_bytes(b) as f64),
        "UInt16" => each(raw, |b| u16::from_le_bytes(b) as f64),
        "Int8" => each(raw, |b: [u8; 1]| b[0] as i8 as f64),
        "UInt8" => each(raw, |b: [u8; 1]| b[0] as f64),
        t => Err(format!("type {t} is not read")),
    }
}

/// The first position of `needle` in `haystack`.
fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// The start tag that begins with `open` (up to its `>`).
fn tag_at<'a>(xml: &'a str, open: &str) -> Option<&'a str> {
    let at = xml.find(open)?;
    Some(&xml[at..at + xml[at..].find('>')?])
}

/// The value of attribute `name` in the start tag `tag`.
pub fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    Some(&tag[start..start + tag[start..].find('"')?])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::vtk::{write_vtu, Encoding};
    use crate::model::input::ModelInput;

    /// A grid written by the VTK writer reads back with the same values,
    /// binary and ASCII alike.
    #[test]
    fn reads_back_what_the_writer_wrote() {
        let mut m = ModelInput::new("frame");
        m.add_node(1, [0.0, 0.0, 0.0]);
        m.add_node(2, [1.0, 0.5, 0.0]);
        m.add_section("s", [1e6, 4e5, 4e5, 80.0, 100.0, 100.0]);
        m.add_beam(1, [1, 2], "s", None);
        m.fix(1, &["all"]);
        let model = crate::model::Model::from_input(&m).unwrap();
        let state = model.initial_state();
        let ctx = model.context(0.0, crate::elements::Need::RESIDUAL);
        let mut read = Vec::new();
        for (k, encoding) in [Encoding::Binary, Encoding::Ascii].into_iter().enumerate() {
            let path = std::env::temp_dir()
                .join(format!("unfold-view-grid-{}-{k}.vtu", std::process::id()));
            write_vtu(&path, &model, &ctx, &state, encoding).unwrap();
            let grid = Grid::parse(&std::fs::read(&path).unwrap()).unwrap();
            std::fs::remove_file(&path).unwrap();
            assert_eq!((grid.points, grid.cells), (2, 1));
            let p = grid.require(Section::Geometry, "position").unwrap();
            assert_eq!(p.values, vec![0.0, 0.0, 0.0, 1.0, 0.5, 0.0]);
            assert_eq!(p.components, 3);
            let types = grid.require(Section::Topology, "types").unwrap();
            assert_eq!(types.values, vec![3.0]);
            assert!(grid.require(Section::Cells, "M3").unwrap().float);
            assert!(!grid.require(Section::Cells, "kind").unwrap().float);
            read.push(grid);
        }
        for (a, b) in read[0].arrays.iter().zip(&read[1].arrays) {
            assert_eq!(
                (&a.name, a.section, &a.values),
                (&b.name, b.section, &b.values)
            );
        }
        assert!(Grid::parse(b"<html></html>").is_err());
    }
}
