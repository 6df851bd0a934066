//! VTK XML writers for ParaView: one unstructured grid (`.vtu`) per output
//! step, gathered by a collection file (`.pvd`) whose time values are the
//! load parameter.
//!
//! Encoding ([`Encoding`]): binary by default, as VTK writes it itself:
//! every array in one `<AppendedData encoding="raw">` block, compressed
//! with zlib (`compressor="vtkZLibDataCompressor"`, `header_type="UInt64"`).
//! Each array there is a header of little-endian `u64`,
//! `[blocks, block size, size of the last block (0 if full), compressed
//! size of each block]`, then its blocks, each a zlib stream of up to
//! [`BLOCK_SIZE`] bytes of little-endian values (a stored, uncompressed
//! stream for an array under `STORED_BELOW` bytes); the `offset` attribute of
//! the `DataArray` counts from the byte after the `_` that opens the
//! block. [`Encoding::Ascii`] writes every number as text instead.
//!
//! Grid contents (docs/results.md, "VTK files"):
//! - points: the nodes, then the joint points (each joint's point on body
//!   A, unless A is the ground, and on body B), then the points of the
//!   rigid bodies' shapes (corners of boxes and plates, points around
//!   cylinders), with point data `node_id` (−1 at joint and shape
//!   points), `joint_id` (−1 at nodes and shape points), `displacement`
//!   (from the reference), `rotation` (rotation vector of `R R₀ᵀ`, global
//!   frame; at a joint or shape point that of its node) and `axis_1`,
//!   `axis_2`, `axis_3` (unit vectors: a node's material axes, a joint
//!   point's joint axes, a shape point's shape axes);
//! - cells: each element as its [`CellShape`] says (beams and two-node
//!   springs as lines, point masses and springs to ground as vertices,
//!   four-node elements as quadrilaterals), a rigid body as the cells of
//!   its shape ([`crate::elements::shape`]: a hexahedron for a box or a
//!   thick plate, a quadrilateral for a thin plate, quadrilaterals and
//!   polygons for a cylinder, a line for a rod; a vertex at its node for a
//!   body without inertia or of shape `point`), each point of which moves
//!   with the body's node; for each joint, a
//!   line from each of its nodes to its joint point on that node (a rigid
//!   link) and a vertex at its point on body B (the joint marker). Cell
//!   data `kind` ([`ElementKind::code`]; 10 for a rigid link),
//!   `element_id`, and the arrays each kind fills from its results
//!   ([`ElementKind::cell_fields`]: the beam section forces `N`, `V2`,
//!   `V3`, `T`, `M2`, `M3`, the spring force and deformation `spring_F`,
//!   `spring_D`), zero on the cells of other kinds.

use std::fmt::Write as _;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};

use flate2::{Compress, Compression, FlushCompress, Status};

use super::results::file_error;
use crate::elements::shape::Outline;
use crate::elements::shell::SkinStress;
use crate::elements::{Attachment, CellField, CellShape, Element, ElementKind, EvalContext};
use crate::model::Model;
use crate::so3::{self, Vec3};
use crate::state::State;

/// VTK cell type code of a vertex.
const VTK_VERTEX: u8 = 1;

/// Cell `kind` of a rigid link from a node to a joint point.
pub const KIND_LINK: i32 = 10;

/// Uncompressed size of a compressed block, bytes (VTK's default).
pub const BLOCK_SIZE: usize = 1 << 15;

/// How the arrays of a grid are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Numbers as text (larger and slower; readable in an editor).
    Ascii,
    /// Raw appended data, zlib-compressed (see the module documentation).
    #[default]
    Binary,
}

/// A number type of a data array.
trait Value: Copy {
    /// VTK type name.
    const TYPE: &'static str;
    fn push_le(self, out: &mut Vec<u8>);
    fn push_text(self, out: &mut String);
}

impl Value for f64 {
    const TYPE: &'static str = "Float64";
    fn push_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn push_text(self, out: &mut String) {
        // shortest text that reads back to the same number
        super::number::Shortest(self).push_to(out);
    }
}

impl Value for i64 {
    const TYPE: &'static str = "Int64";
    fn push_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn push_text(self, out: &mut String) {
        let _ = write!(out, "{self}");
    }
}

impl Value for i32 {
    const TYPE: &'static str = "Int32";
    fn push_le(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn push_text(self, out: &mut String) {
        let _ = write!(out, "{self}");
    }
}

impl Value for u8 {
    const TYPE: &'static str = "UInt8";
    fn push_le(self, out: &mut Vec<u8>) {
        out.push(self);
    }
    fn push_text(self, out: &mut String) {
        let _ = write!(out, "{self}");
    }
}

/// A VTK XML file being built: the XML text and, for binary encoding, the
/// appended data.
struct Document {
    encoding: Encoding,
    xml: String,
    appended: Vec<u8>,
    raw: Vec<u8>,
}

impl Document {
    fn new(encoding: Encoding) -> Self {
        Self {
            encoding,
            xml: String::new(),
            appended: Vec::new(),
            raw: Vec::new(),
        }
    }

    /// Adds a `DataArray` of `values` with `components` per tuple.
    fn array<T: Value>(&mut self, name: &str, components: usize, values: &[T]) {
        // `<DataArray type="Float64" Name="x" NumberOfComponents="3"`,
        // piece by piece (no `core::fmt`: a grid per output step)
        let mut count = itoa::Buffer::new();
        for piece in [
            "        <DataArray type=\"",
            T::TYPE,
            "\" Name=\"",
            name,
            "\" NumberOfComponents=\"",
            count.format(components),
            "\"",
        ] {
            self.xml.push_str(piece);
        }
        match self.encoding {
            Encoding::Ascii => {
                self.xml.push_str(" format=\"ascii\">\n         ");
                for (i, v) in values.iter().enumerate() {
                    self.xml.push(' ');
                    v.push_text(&mut self.xml);
                    if i % 12 == 11 {
                        self.xml.push_str("\n         ");
                    }
                }
                self.xml.push_str("\n        </DataArray>\n");
            }
            Encoding::Binary => {
                let mut offset = itoa::Buffer::new();
                for piece in [
                    " format=\"appended\" offset=\"",
                    offset.format(self.appended.len()),
                    "\"/>\n",
                ] {
                    self.xml.push_str(piece);
                }
                self.raw.clear();
                for v in values {
                    v.push_le(&mut self.raw);
                }
                compress_blocks(&self.raw, &mut self.appended);
            }
        }
    }

    /// The whole file.
    fn finish(mut self) -> Vec<u8> {
        if self.encoding == Encoding::Binary {
            self.xml.push_str("  <AppendedData encoding=\"raw\">\n   _");
        }
        let mut bytes = self.xml.into_bytes();
        if self.encoding == Encoding::Binary {
            bytes.extend_from_slice(&self.appended);
            bytes.extend_from_slice(b"\n  </AppendedData>\n");
        }
        bytes.extend_from_slice(b"</VTKFile>\n");
        bytes
    }
}

/// Arrays of fewer bytes than this are written as stored (uncompressed)
/// zlib streams: resetting the compressor zeroes its ~300 kB of tables,
/// more work than compressing a few kilobytes of values saves (on the
/// beam pendulum of 80 elements, 10 % of the instructions of a whole
/// dynamic run went into those resets).
const STORED_BELOW: usize = 16 * 1024;

/// Appends `raw` to `out` as VTK compressed blocks: the `u64` header
/// `[blocks, BLOCK_SIZE, last block size (0 if full), compressed sizes…]`
/// then the zlib stream of each block. Level 1 (fast): on a grid of 20,000
/// beams it writes in about the time of the ASCII text, 10 % larger than
/// level 6 at half its time. Below [`STORED_BELOW`] bytes, one stored
/// stream ([`store_block`]).
fn compress_blocks(raw: &[u8], out: &mut Vec<u8>) {
    if !raw.is_empty() && raw.len() < STORED_BELOW {
        for h in [1, BLOCK_SIZE, raw.len() % BLOCK_SIZE] {
            out.extend_from_slice(&(h as u64).to_le_bytes());
        }
        let sizes_at = out.len();
        out.extend_from_slice(&[0; 8]);
        store_block(raw, out);
        let size = (out.len() - sizes_at - 8) as u64;
        out[sizes_at..sizes_at + 8].copy_from_slice(&size.to_le_bytes());
        return;
    }
    // One compressor per thread, reset for each block: a new one per block
    // allocates (and frees) its ~300 kB of state every time, which made
    // the allocator grow and trim the heap tens of times per output step.
    thread_local! {
        static ZLIB: std::cell::RefCell<Compress> =
            std::cell::RefCell::new(Compress::new(Compression::fast(), true));
    }
    let start = out.len();
    let n_blocks = raw.len().div_ceil(BLOCK_SIZE);
    let last = raw.len() % BLOCK_SIZE;
    for h in [n_blocks, BLOCK_SIZE, last] {
        out.extend_from_slice(&(h as u64).to_le_bytes());
    }
    // the compressed sizes, filled in below
    let sizes_at = out.len();
    out.resize(sizes_at + 8 * n_blocks, 0);
    ZLIB.with(|z| {
        let mut z = z.borrow_mut();
        for (i, chunk) in raw.chunks(BLOCK_SIZE).enumerate() {
            z.reset();
            let before = out.len();
            loop {
                out.reserve(chunk.len() / 2 + 64);
                let read = z.total_in() as usize;
                // compressing into a Vec with spare room cannot fail
                let status = z
                    .compress_vec(&chunk[read..], out, FlushCompress::Finish)
                    .unwrap_or(Status::StreamEnd);
                if status == Status::StreamEnd {
                    break;
                }
            }
            let size = (out.len() - before) as u64;
            let at = sizes_at + 8 * i;
            out[at..at + 8].copy_from_slice(&size.to_le_bytes());
        }
    });
    debug_assert!(out.len() >= start + 24);
}

/// Appends `block` (at most 65,535 bytes) to `out` as a zlib stream
/// holding one stored deflate block (RFC 1950 §2.2, RFC 1951 §3.2.4):
/// header `78 01`, then `BFINAL = 1, BTYPE = 00`, `LEN`, `!LEN`
/// (little-endian), the bytes, and their Adler-32 (big-endian).
fn store_block(block: &[u8], out: &mut Vec<u8>) {
    let len = u16::try_from(block.len()).expect("a stored block holds at most 65,535 bytes");
    out.extend_from_slice(&[0x78, 0x01, 0x01]);
    out.extend_from_slice(&len.to_le_bytes());
    out.extend_from_slice(&(!len).to_le_bytes());
    out.extend_from_slice(block);
    // Adler-32: sums modulo 65,521, reduced every 5,552 bytes (the most
    // that cannot overflow a u32)
    let (mut a, mut b) = (1u32, 0u32);
    for chunk in block.chunks(5552) {
        for &byte in chunk {
            a += u32::from(byte);
            b += a;
        }
        a %= 65521;
        b %= 65521;
    }
    out.extend_from_slice(&((b << 16) | a).to_be_bytes());
}

/// The joint points of every element at `state`, with the element's
/// index.
fn attachments(model: &Model, state: &State) -> Vec<(usize, Attachment)> {
    let mut all = Vec::new();
    let mut one = Vec::new();
    for (k, e) in model.elements.iter().enumerate() {
        one.clear();
        e.attachments(state, &mut one);
        all.extend(one.iter().map(|a| (k, *a)));
    }
    all
}

/// The outline of every rigid body drawn with a solid shape, with the
/// element's index and node (points in the node's material frame).
fn body_outlines(model: &Model) -> Vec<(usize, usize, Outline)> {
    model
        .elements
        .iter()
        .enumerate()
        .filter_map(|(k, e)| {
            let shape = e.body_shape().filter(|s| s.is_solid())?;
            Some((k, e.nodes()[0], shape.outline()))
        })
        .collect()
}

fn push3(out: &mut Vec<f64>, v: &Vec3) {
    out.extend_from_slice(&[v.x, v.y, v.z]);
}

/// The recovered mesh of a superelement in a grid: the element, its first
/// point and the results of its original elements.
struct Recovered {
    element: usize,
    first: usize,
    results: Vec<Vec<f64>>,
    /// The skin stresses of its shells (`None` for its other elements).
    skins: Vec<Option<[SkinStress; 2]>>,
}

/// A cell's skin stresses in the grid: von Mises of the bottom and top
/// skins, then the principal stresses of each.
fn skin_row(skins: &[SkinStress; 2]) -> [f64; 6] {
    let [b, t] = skins;
    [
        b.von_mises,
        t.von_mises,
        b.principal[0],
        b.principal[1],
        t.principal[0],
        t.principal[1],
    ]
}

/// Writes the grid of `state` to `path`.
pub fn write_vtu(
    path: &Path,
    model: &Model,
    ctx: &EvalContext,
    state: &State,
    encoding: Encoding,
) -> io::Result<()> {
    write_grid(path, model, ctx, state, encoding, None, None)
}

/// Writes the grid of an output step of a run: as [`write_vtu`], with
/// the point vectors `velocity` and `angular_velocity` (global) if
/// `velocities` is given: the state's if `Some(true)` (a step of a dynamic
/// analysis), zeros if `Some(false)` (a step at rest in a run with
/// dynamics, so that every grid of the run has the same fields). A joint
/// point moves with its node, `v + ω × (p − x)`, and with the ground not
/// at all.
pub fn write_step_vtu(
    path: &Path,
    model: &Model,
    ctx: &EvalContext,
    state: &State,
    encoding: Encoding,
    velocities: Option<bool>,
) -> io::Result<()> {
    write_grid(path, model, ctx, state, encoding, None, velocities)
}

/// A mode shape on the nodes: translation and rotation (global frame) of
/// each node, and the generalised coordinates of the elements (a
/// superelement's modal amplitudes; empty: zero).
#[derive(Clone, Copy, Debug)]
pub struct ModeField<'a> {
    /// Translation of each node.
    pub translation: &'a [Vec3],
    /// Rotation (small rotation vector) of each node.
    pub rotation: &'a [Vec3],
    /// Coordinates of the elements, as in [`State::coordinates`].
    pub coordinates: &'a [f64],
}

/// Writes the grid of `state` to `path` with a mode shape as the point
/// vectors `mode_displacement` (the default vectors of the file, for
/// ParaView's Warp By Vector) and `mode_rotation`; a joint point moves
/// with its node, `u + θ × (p − x)`, and with the ground not at all.
pub fn write_mode_vtu(
    path: &Path,
    model: &Model,
    ctx: &EvalContext,
    state: &State,
    encoding: Encoding,
    mode: ModeField,
) -> io::Result<()> {
    assert!(mode.translation.len() == model.n_nodes() && mode.rotation.len() == model.n_nodes());
    write_grid(path, model, ctx, state, encoding, Some(mode), None)
}

fn write_grid(
    path: &Path,
    model: &Model,
    ctx: &EvalContext,
    state: &State,
    encoding: Encoding,
    mode: Option<ModeField>,
    velocities: Option<bool>,
) -> io::Result<()> {
    let n_nodes = model.n_nodes();
    let joints = attachments(model, state);
    let joints_at_reference = if joints.is_empty() {
        Vec::new()
    } else {
        attachments(model, &model.initial_state())
    };

    let bodies = body_outlines(model);
    let n_body_points: usize = bodies.iter().map(|(_, _, o)| o.points.len()).sum();

    // points: nodes, joint points, then the points of the bodies' shapes
    let n_joint_points = n_nodes + joints.len();
    let n_points = n_joint_points + n_body_points;
    let mut position = Vec::with_capacity(3 * n_points);
    let mut displacement = Vec::with_capacity(3 * n_points);
    let mut rotation = Vec::with_capacity(3 * n_points);
    let mut axes: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(3 * n_points));
    let mut node_id: Vec<i64> = model.node_ids.iter().map(|&i| i as i64).collect();
    let mut joint_id = vec![-1i64; n_nodes];
    let node_rotation = |i: usize| so3::log(&(state.q[i] * model.reference_q[i].inverse()));
    for i in 0..n_nodes {
        push3(&mut position, &state.x[i]);
        push3(&mut displacement, &(state.x[i] - model.reference_x[i]));
        push3(&mut rotation, &node_rotation(i));
        let r = so3::matrix(&state.q[i]);
        for (c, a) in axes.iter_mut().enumerate() {
            push3(a, &r.column(c).into_owned());
        }
    }
    // the mode shape at the nodes, then at the joint points
    let mut mode_u = Vec::new();
    let mut mode_theta = Vec::new();
    if let Some(m) = &mode {
        for i in 0..n_nodes {
            push3(&mut mode_u, &m.translation[i]);
            push3(&mut mode_theta, &m.rotation[i]);
        }
        for (_, a) in &joints {
            let (u, theta) = a.node.map_or((Vec3::zeros(), Vec3::zeros()), |n| {
                let theta = m.rotation[n];
                (
                    m.translation[n] + theta.cross(&(a.point - state.x[n])),
                    theta,
                )
            });
            push3(&mut mode_u, &u);
            push3(&mut mode_theta, &theta);
        }
        for (_, n, outline) in &bodies {
            let theta = m.rotation[*n];
            for p in &outline.points {
                let arm = state.q[*n] * p;
                push3(&mut mode_u, &(m.translation[*n] + theta.cross(&arm)));
                push3(&mut mode_theta, &theta);
            }
        }
    }
    // velocities (global) at the nodes, then at the joint points
    let mut velocity = Vec::new();
    let mut angular_velocity = Vec::new();
    if let Some(moving) = velocities {
        let omega = |i: usize| -> (Vec3, Vec3) {
            if !moving {
                return (Vec3::zeros(), Vec3::zeros());
            }
            let v = state.velocity[i];
            let w = so3::matrix(&state.q[i]) * Vec3::new(v[3], v[4], v[5]);
            (Vec3::new(v[0], v[1], v[2]), w)
        };
        for i in 0..n_nodes {
            let (v, w) = omega(i);
            push3(&mut velocity, &v);
            push3(&mut angular_velocity, &w);
        }
        for (_, a) in &joints {
            let (v, w) = a.node.map_or((Vec3::zeros(), Vec3::zeros()), |n| {
                let (v, w) = omega(n);
                (v + w.cross(&(a.point - state.x[n])), w)
            });
            push3(&mut velocity, &v);
            push3(&mut angular_velocity, &w);
        }
        for (_, n, outline) in &bodies {
            let (v, w) = omega(*n);
            for p in &outline.points {
                push3(&mut velocity, &(v + w.cross(&(state.q[*n] * p))));
                push3(&mut angular_velocity, &w);
            }
        }
    }
    for (j, (k, a)) in joints.iter().enumerate() {
        push3(&mut position, &a.point);
        let reference = joints_at_reference.get(j).map_or(a.point, |r| r.1.point);
        push3(&mut displacement, &(a.point - reference));
        push3(&mut rotation, &a.node.map_or(Vec3::zeros(), node_rotation));
        for (c, ax) in axes.iter_mut().enumerate() {
            push3(ax, &a.axes.column(c).into_owned());
        }
        node_id.push(-1);
        joint_id.push(model.elements[*k].id() as i64);
    }
    // a shape's point p (node frame) at x + R p, from x₀ + R₀ p
    for (k, n, outline) in &bodies {
        let q_shape = model.elements[*k]
            .body_shape()
            .map_or(so3::Mat3::identity(), |s| s.axes);
        let r = so3::matrix(&state.q[*n]);
        let shape_axes = r * q_shape;
        for p in &outline.points {
            let x = state.x[*n] + r * p;
            push3(&mut position, &x);
            let x0 = model.reference_x[*n] + model.reference_q[*n] * p;
            push3(&mut displacement, &(x - x0));
            push3(&mut rotation, &node_rotation(*n));
            for (c, ax) in axes.iter_mut().enumerate() {
                push3(ax, &shape_axes.column(c).into_owned());
            }
            node_id.push(-1);
            joint_id.push(-1);
        }
    }
    // the original meshes of superelements, recovered (docs/results.md,
    // "VTK files"): their points after the joint points
    let recovered: Vec<Recovered> = model
        .elements
        .iter()
        .enumerate()
        .filter_map(|(k, e)| e.as_superelement().map(|s| (k, s)))
        .map(|(k, s)| {
            let first = node_id.len();
            let mesh = s.recovered_mesh(state);
            let body = &s.body().body;
            for (i, x) in mesh.position.iter().enumerate() {
                push3(&mut position, x);
                push3(&mut displacement, &(x - body.positions[i]));
                push3(
                    &mut rotation,
                    &so3::log(&(mesh.orientation[i] * body.orientations[i].inverse())),
                );
                let r = so3::matrix(&mesh.orientation[i]);
                for (c, ax) in axes.iter_mut().enumerate() {
                    push3(ax, &r.column(c).into_owned());
                }
                node_id.push(-1);
                joint_id.push(-1);
            }
            if let Some(m) = &mode {
                let boundary: Vec<(Vec3, Vec3)> = s
                    .nodes()
                    .iter()
                    .map(|&n| (m.translation[n], m.rotation[n]))
                    .collect();
                let o = model.offsets(k).coordinates;
                let eta: Vec<f64> = (0..s.n_coordinates())
                    .map(|j| m.coordinates.get(o + j).copied().unwrap_or(0.0))
                    .collect();
                for (u, theta) in s.mode_shape(state, &boundary, &eta) {
                    push3(&mut mode_u, &u);
                    push3(&mut mode_theta, &theta);
                }
            }
            if let Some(moving) = velocities {
                for i in 0..mesh.position.len() {
                    let (v, w) = if moving {
                        (mesh.velocity[i], mesh.angular_velocity[i])
                    } else {
                        (Vec3::zeros(), Vec3::zeros())
                    };
                    push3(&mut velocity, &v);
                    push3(&mut angular_velocity, &w);
                }
            }
            let results = s.element_results(&mesh);
            let skins = s.skin_stresses(&mesh);
            Recovered {
                element: k,
                first,
                results,
                skins,
            }
        })
        .collect();
    let mut mesh_node_id = vec![-1i64; node_id.len()];
    for r in &recovered {
        let s = model.elements[r.element]
            .as_superelement()
            .expect("a superelement");
        for (i, id) in s.body().body.node_ids.iter().enumerate() {
            mesh_node_id[r.first + i] = *id as i64;
        }
    }
    let n_points = node_id.len();

    // cells: the shape of each element, its results in the cell arrays of
    // its kind (ElementKind::cell_fields), zeros in the others
    let fields: Vec<(ElementKind, &CellField)> = ElementKind::ALL
        .into_iter()
        .flat_map(|k| k.cell_fields().iter().map(move |f| (k, f)))
        .collect();
    let mut field_values: Vec<Vec<f64>> = vec![Vec::new(); fields.len()];
    let mut connectivity: Vec<i64> = Vec::new();
    let mut offsets: Vec<i64> = Vec::new();
    let mut types: Vec<u8> = Vec::new();
    let mut kinds: Vec<i32> = Vec::new();
    let mut ids: Vec<i64> = Vec::new();
    let mut superelement_ids: Vec<i64> = Vec::new();
    // the skin stresses of the shells of recovered meshes (docs/results.md,
    // "VTK files"), six a cell
    let with_skins = recovered
        .iter()
        .any(|r| r.skins.iter().any(Option::is_some));
    let mut skin_values: Vec<f64> = Vec::new();
    let longest = model
        .elements
        .iter()
        .map(|e| e.result_names().len())
        .max()
        .unwrap_or(0);
    let mut results = vec![0.0; longest];
    let mut cell = |points: &[usize],
                    vtk_type: u8,
                    kind: i32,
                    id: i64,
                    superelement: i64,
                    values: Option<(ElementKind, &[f64])>,
                    skin: Option<[f64; 6]>| {
        connectivity.extend(points.iter().map(|&p| p as i64));
        offsets.push(connectivity.len() as i64);
        types.push(vtk_type);
        kinds.push(kind);
        ids.push(id);
        superelement_ids.push(superelement);
        if with_skins {
            skin_values.extend(skin.unwrap_or([0.0; 6]));
        }
        for ((k, f), column) in fields.iter().zip(&mut field_values) {
            match values {
                Some((of, v)) if of == *k && f.first + f.components <= v.len() => {
                    column.extend_from_slice(&v[f.first..f.first + f.components])
                }
                _ => column.extend(std::iter::repeat_n(0.0, f.components)),
            }
        }
    };
    let line = CellShape::Line.vtk_type().unwrap_or(VTK_VERTEX);
    let mut next_joint_point = n_nodes;
    let mut next_body = bodies.iter().peekable();
    let mut next_body_point = n_joint_points;
    let mut shape_cell = Vec::new();
    for (k, e) in model.elements.iter().enumerate() {
        let id = e.id() as i64;
        let nodes = e.nodes();
        // joints: links from the nodes to the joint points, a marker at B's
        let first = next_joint_point;
        while next_joint_point < n_joint_points && joints[next_joint_point - n_nodes].0 == k {
            let a = &joints[next_joint_point - n_nodes].1;
            if let Some(node) = a.node {
                cell(
                    &[node, next_joint_point],
                    line,
                    KIND_LINK,
                    id,
                    -1,
                    None,
                    None,
                );
            }
            next_joint_point += 1;
        }
        if next_joint_point > first {
            cell(
                &[next_joint_point - 1],
                VTK_VERTEX,
                e.kind().code(),
                id,
                -1,
                None,
                None,
            );
            continue;
        }
        // a superelement: the cells of its original mesh, each with its
        // original element's kind, id and results
        if let Some(r) = recovered.iter().find(|r| r.element == k) {
            let s = e.as_superelement().expect("a superelement");
            let body = &s.body().body;
            let mut points = Vec::new();
            for c in &body.cells {
                points.clear();
                points.extend(c.nodes.iter().map(|&i| r.first + i));
                let original = c
                    .element
                    .zip(body.elements.as_ref())
                    .map(|(el, m)| &m.elements[el]);
                let vtk_type = CellShape::with_nodes(points.len())
                    .vtk_type()
                    .unwrap_or(VTK_VERTEX);
                match original {
                    Some(o) => {
                        let at = c.element.unwrap_or(0);
                        let values = r.results.get(at).map(|v| (o.kind(), &v[..]));
                        let skin = r.skins.get(at).copied().flatten().map(|s| skin_row(&s));
                        cell(
                            &points,
                            vtk_type,
                            o.kind().code(),
                            o.id() as i64,
                            id,
                            values,
                            skin,
                        );
                    }
                    None => cell(&points, vtk_type, e.kind().code(), id, id, None, None),
                }
            }
            continue;
        }
        let kind = e.kind();
        let values = if kind.cell_fields().is_empty() {
            None
        } else {
            let r = &mut results[..e.result_names().len()];
            r.fill(0.0);
            e.results(ctx, state, r);
            Some((kind, &*r))
        };
        // a body's shape: its cells through its points
        if let Some((_, _, outline)) = next_body.next_if(|(b, _, _)| *b == k) {
            for c in &outline.cells {
                shape_cell.clear();
                shape_cell.extend(c.points.iter().map(|p| next_body_point + p));
                cell(&shape_cell, c.vtk_type, kind.code(), id, -1, values, None);
            }
            next_body_point += outline.points.len();
            continue;
        }
        let shape = e.cell_shape();
        let Some(vtk_type) = shape.vtk_type() else {
            continue;
        };
        cell(
            &nodes[..shape.nodes()],
            vtk_type,
            kind.code(),
            id,
            -1,
            values,
            None,
        );
    }
    let n_cells = types.len();

    let mut doc = Document::new(encoding);
    doc.xml.push_str("<?xml version=\"1.0\"?>\n");
    doc.xml.push_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"",
    );
    if encoding == Encoding::Binary {
        doc.xml.push_str(" compressor=\"vtkZLibDataCompressor\"");
    }
    doc.xml.push_str(">\n  <UnstructuredGrid>\n");
    let _ = writeln!(
        doc.xml,
        "    <Piece NumberOfPoints=\"{n_points}\" NumberOfCells=\"{n_cells}\">"
    );

    // point data
    let vectors = if mode.is_some() {
        "mode_displacement"
    } else {
        "displacement"
    };
    let _ = writeln!(
        doc.xml,
        "      <PointData Scalars=\"node_id\" Vectors=\"{vectors}\">"
    );
    doc.array("node_id", 1, &node_id);
    doc.array("joint_id", 1, &joint_id);
    doc.array("displacement", 3, &displacement);
    doc.array("rotation", 3, &rotation);
    for (c, a) in axes.iter().enumerate() {
        doc.array(&format!("axis_{}", c + 1), 3, a);
    }
    if mode.is_some() {
        doc.array("mode_displacement", 3, &mode_u);
        doc.array("mode_rotation", 3, &mode_theta);
    }
    if velocities.is_some() {
        doc.array("velocity", 3, &velocity);
        doc.array("angular_velocity", 3, &angular_velocity);
    }
    if !recovered.is_empty() {
        doc.array("mesh_node_id", 1, &mesh_node_id);
    }
    doc.xml.push_str("      </PointData>\n");

    // cell data
    doc.xml.push_str("      <CellData Scalars=\"kind\">\n");
    doc.array("kind", 1, &kinds);
    doc.array("element_id", 1, &ids);
    if !recovered.is_empty() {
        doc.array("superelement_id", 1, &superelement_ids);
    }
    if with_skins {
        let column = |first: usize, n: usize| -> Vec<f64> {
            skin_values
                .chunks_exact(6)
                .flat_map(|row| row[first..first + n].iter().copied())
                .collect()
        };
        doc.array("skin_von_mises", 2, &column(0, 2));
        doc.array("bottom_skin_principal", 2, &column(2, 2));
        doc.array("top_skin_principal", 2, &column(4, 2));
    }
    for ((_, f), column) in fields.iter().zip(&field_values) {
        doc.array(f.name, f.components, column);
    }
    doc.xml.push_str("      </CellData>\n");

    // geometry
    doc.xml.push_str("      <Points>\n");
    doc.array("position", 3, &position);
    doc.xml.push_str("      </Points>\n      <Cells>\n");
    doc.array("connectivity", 1, &connectivity);
    doc.array("offsets", 1, &offsets);
    doc.array("types", 1, &types);
    doc.xml
        .push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n");
    write_atomically(path, &doc.finish())
}

/// The closing tags of a collection file.
const PVD_TAIL: &str = "  </Collection>\n</VTKFile>\n";

/// A collection file written as the steps come: each step's entry is
/// written over the closing tags, which follow it again, so that the file
/// on disk is complete after every step at a cost independent of the
/// number of steps before it (rewriting the whole list at every step costs
/// their square).
#[derive(Debug)]
pub struct PvdFile {
    path: PathBuf,
    file: Option<std::fs::File>,
    /// Where the closing tags begin.
    tail_at: u64,
}

impl PvdFile {
    /// The collection file at `path`, created with its first entry.
    pub fn new(path: PathBuf) -> Self {
        Self {
            path,
            file: None,
            tail_at: 0,
        }
    }

    /// Adds the data set `file` at time `t`. On failure the file keeps
    /// the entries before (as far as the disk allows) and the error names
    /// it.
    pub fn append(&mut self, t: f64, file: &str) -> io::Result<()> {
        use std::io::{Seek, SeekFrom};
        let path = self.path.clone();
        let named = |e: io::Error| io::Error::new(e.kind(), format!("{}: {e}", path.display()));
        if self.file.is_none() {
            let head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
            let mut f = std::fs::File::create(&self.path).map_err(named)?;
            if let Err(e) = f.write_all(head.as_bytes()) {
                // no collection rather than a broken one
                let _ = std::fs::remove_file(&self.path);
                return Err(named(e));
            }
            self.tail_at = head.len() as u64;
            self.file = Some(f);
        }
        let f = self.file.as_mut().expect("opened above");
        let entry = format!(
            "    <DataSet timestep=\"{t:.12e}\" group=\"\" part=\"0\" file=\"{file}\"/>\n{PVD_TAIL}"
        );
        let result = f
            .seek(SeekFrom::Start(self.tail_at))
            .and_then(|_| f.write_all(entry.as_bytes()));
        match result {
            Ok(()) => {
                self.tail_at += (entry.len() - PVD_TAIL.len()) as u64;
                Ok(())
            }
            Err(e) => {
                // put the closing tags back after the entries before
                let _ = f
                    .set_len(self.tail_at)
                    .and_then(|()| f.seek(SeekFrom::Start(self.tail_at)))
                    .and_then(|_| f.write_all(PVD_TAIL.as_bytes()));
                Err(named(e))
            }
        }
    }
}

/// Writes the collection file listing `(time, file name)` pairs.
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> io::Result<()> {
    let mut out = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, file) in entries {
        let _ = writeln!(
            out,
            "    <DataSet timestep=\"{t:.12e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        );
    }
    out.push_str(PVD_TAIL);
    write_atomically(path, out.as_bytes())
}

/// The temporary file of `path`: `NAME.tmp` beside it.
fn temporary(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".tmp");
    path.with_file_name(name)
}

/// Writes to a temporary file then renames it, so a reader (or a crash)
/// never sees a half-written file. On failure the temporary file is
/// removed and the error names `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let tmp = temporary(path);
    let result = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes))
        .and_then(|()| std::fs::rename(&tmp, path));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        file_error(path, e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::{Element, ElementOutput};
    use crate::model::input::ModelInput;
    use crate::model::Id;

    /// Decodes the VTK compressed blocks of one array with flate2's zlib
    /// decoder (which checks each stream's Adler-32).
    fn decode_blocks(data: &[u8]) -> Vec<u8> {
        use std::io::Read;
        let word = |k: usize| u64::from_le_bytes(data[8 * k..8 * k + 8].try_into().unwrap());
        let blocks = word(0) as usize;
        let mut at = 8 * (3 + blocks);
        let mut raw = Vec::new();
        for b in 0..blocks {
            let size = word(3 + b) as usize;
            flate2::read::ZlibDecoder::new(&data[at..at + size])
                .read_to_end(&mut raw)
                .expect("a valid zlib stream");
            at += size;
        }
        assert_eq!(at, data.len(), "nothing after the last block");
        raw
    }

    /// Arrays below STORED_BELOW are stored, the others compressed, and
    /// both decode to their bytes, with the block header VTK reads:
    /// empty, one byte, the Adler-32 reductions (over 5,552 bytes of 0xff),
    /// the limit, and several blocks.
    #[test]
    fn stored_and_compressed_blocks_decode_to_their_bytes() {
        for n in [
            0,
            1,
            5553,
            STORED_BELOW - 1,
            STORED_BELOW,
            3 * BLOCK_SIZE + 7,
        ] {
            let raw: Vec<u8> = (0..n)
                .map(|i| if n == 5553 { 0xff } else { (i * 7 % 251) as u8 })
                .collect();
            let mut out = Vec::new();
            compress_blocks(&raw, &mut out);
            assert_eq!(decode_blocks(&out), raw, "{n} bytes");
            let word = |k: usize| u64::from_le_bytes(out[8 * k..8 * k + 8].try_into().unwrap());
            assert_eq!(
                word(0) as usize,
                n.div_ceil(BLOCK_SIZE),
                "{n} bytes: blocks"
            );
            assert_eq!(word(2) as usize, n % BLOCK_SIZE, "{n} bytes: last block");
            if n > 0 && n < STORED_BELOW {
                // stored: 2 + 5 + n + 4 bytes
                assert_eq!(out.len(), 32 + n + 11, "{n} bytes: stored");
            }
        }
    }

    /// A four-node element drawn as a quadrilateral (as a shell is), with
    /// no stiffness.
    struct Panel {
        nodes: [usize; 4],
    }

    impl Element for Panel {
        fn kind(&self) -> ElementKind {
            ElementKind::Constraint
        }
        fn id(&self) -> Id {
            99
        }
        fn nodes(&self) -> &[usize] {
            &self.nodes
        }
        fn evaluate(&self, _: &EvalContext, _: &State, _: &mut ElementOutput) {}
        fn cell_shape(&self) -> CellShape {
            CellShape::Quad
        }
    }

    /// A square frame of four beams with a panel on its corners: the
    /// panel is a VTK_QUAD cell (type 9) through the four corner points in
    /// order, after the four beam lines.
    #[test]
    fn a_four_node_element_is_written_as_a_quad_cell() {
        let mut m = ModelInput::new("panel");
        let corners = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        for (i, x) in corners.into_iter().enumerate() {
            m.add_node(i as Id + 1, x);
        }
        m.add_section("s", [1e6, 4e5, 4e5, 80.0, 100.0, 100.0]);
        for i in 0..4 {
            m.add_beam(i + 1, [i + 1, (i + 1) % 4 + 1], "s", None);
        }
        m.fix(1, &["all"]);
        let mut model = crate::model::Model::from_input(&m).unwrap();
        let nodes = [0, 1, 2, 3].map(|id| model.node_index(id + 1).unwrap());
        model.push_element(Box::new(Panel { nodes }));
        let state = model.initial_state();
        let path = std::env::temp_dir().join(format!("unfold-quad-{}.vtu", std::process::id()));
        write_vtu(
            &path,
            &model,
            &model.context(0.0, crate::elements::Need::RESIDUAL),
            &state,
            Encoding::Ascii,
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let array = |name: &str| -> Vec<f64> {
            let start = text.find(&format!("Name=\"{name}\"")).unwrap();
            let body = &text[start..];
            let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
            body.split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect()
        };
        assert_eq!(array("types"), vec![3.0, 3.0, 3.0, 3.0, 9.0]);
        assert_eq!(array("offsets"), vec![2.0, 4.0, 6.0, 8.0, 12.0]);
        assert_eq!(&array("connectivity")[8..], &nodes.map(|n| n as f64));
        assert_eq!(array("kind")[4], ElementKind::Constraint.code() as f64);
        assert_eq!(array("element_id"), vec![1.0, 2.0, 3.0, 4.0, 99.0]);
        // the beam resultants and spring values are zero on the panel
        assert_eq!(array("M3").len(), 5);
        assert_eq!(array("M3")[4], 0.0);
        assert_eq!(array("spring_F"), vec![0.0; 15]);
    }
}
