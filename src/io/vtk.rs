//! VTK XML writers for ParaView: one unstructured grid (`.vtu`, ASCII) per
//! output step, gathered by a collection file (`.pvd`) whose time values are
//! the load parameter.
//!
//! Grid contents:
//! - points: the nodes, with point data `node_id`, `displacement`
//!   (from the reference) and `rotation` (rotation vector of `R R₀ᵀ`,
//!   global frame);
//! - cells: beams and two-node springs as lines, rigid bodies, point masses
//!   and springs to ground as vertices, with cell data `kind` (1 beam,
//!   2 rigid body, 3 point mass, 4 spring, 6 constraint), `element_id`, the beam section
//!   forces `N`, `V2`, `V3`, `T`, `M2`, `M3` (zero on other cells) and the
//!   spring force and deformation `spring_F`, `spring_D` (zero on other
//!   cells).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use crate::elements::{CellShape, ElementKind, EvalContext};
use crate::model::Model;
use crate::so3;
use crate::state::State;

/// VTK cell type codes.
const VTK_VERTEX: u8 = 1;
const VTK_LINE: u8 = 3;

fn data_array(
    out: &mut String,
    ty: &str,
    name: &str,
    components: usize,
    values: impl Iterator<Item = String>,
) {
    let _ = write!(
        out,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{components}\" format=\"ascii\">\n         "
    );
    for (i, v) in values.enumerate() {
        out.push(' ');
        out.push_str(&v);
        if i % 12 == 11 {
            out.push_str("\n         ");
        }
    }
    out.push_str("\n        </DataArray>\n");
}

/// Writes the grid of `state` to `path`.
pub fn write_vtu(
    path: &Path,
    model: &Model,
    ctx: &EvalContext,
    state: &State,
) -> std::io::Result<()> {
    // cells
    let mut connectivity = Vec::new();
    let mut offsets = Vec::new();
    let mut types = Vec::new();
    let mut kinds = Vec::new();
    let mut ids = Vec::new();
    let mut beam = Vec::new(); // 6 per cell
    let mut spring = Vec::new(); // 6 per cell
    let mut results = [0.0; 6];
    for e in &model.elements {
        let shape = e.cell_shape();
        let nodes = e.nodes();
        match shape {
            CellShape::Line => {
                connectivity.extend_from_slice(&nodes[..2]);
                types.push(VTK_LINE);
            }
            CellShape::Vertex => {
                connectivity.push(nodes[0]);
                types.push(VTK_VERTEX);
            }
            CellShape::None => continue,
        }
        offsets.push(connectivity.len());
        kinds.push(e.kind().code());
        ids.push(e.id());
        results.fill(0.0);
        if matches!(e.kind(), ElementKind::Beam | ElementKind::Spring) {
            e.results(ctx, state, &mut results);
        }
        let (b, s) = match e.kind() {
            ElementKind::Beam => (results, [0.0; 6]),
            ElementKind::Spring => ([0.0; 6], results),
            _ => ([0.0; 6], [0.0; 6]),
        };
        beam.extend_from_slice(&b);
        spring.extend_from_slice(&s);
    }

    let n_points = model.n_nodes();
    let n_cells = types.len();
    let mut out = String::with_capacity(64 * n_points + 128 * n_cells + 1024);
    out.push_str("<?xml version=\"1.0\"?>\n");
    out.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    out.push_str("  <UnstructuredGrid>\n");
    let _ = writeln!(
        out,
        "    <Piece NumberOfPoints=\"{n_points}\" NumberOfCells=\"{n_cells}\">"
    );

    // point data
    out.push_str("      <PointData Scalars=\"node_id\" Vectors=\"displacement\">\n");
    data_array(
        &mut out,
        "Int64",
        "node_id",
        1,
        model.node_ids.iter().map(|i| i.to_string()),
    );
    data_array(
        &mut out,
        "Float64",
        "displacement",
        3,
        (0..n_points).flat_map(|i| {
            let u = state.x[i] - model.reference_x[i];
            [u.x, u.y, u.z].map(|v| format!("{v:.9e}"))
        }),
    );
    data_array(
        &mut out,
        "Float64",
        "rotation",
        3,
        (0..n_points).flat_map(|i| {
            let psi = so3::log(&(state.q[i] * model.reference_q[i].inverse()));
            [psi.x, psi.y, psi.z].map(|v| format!("{v:.9e}"))
        }),
    );
    out.push_str("      </PointData>\n");

    // cell data
    out.push_str("      <CellData Scalars=\"kind\">\n");
    data_array(
        &mut out,
        "Int32",
        "kind",
        1,
        kinds.iter().map(|k| k.to_string()),
    );
    data_array(
        &mut out,
        "Int64",
        "element_id",
        1,
        ids.iter().map(|k| k.to_string()),
    );
    for (c, name) in ["N", "V2", "V3", "T", "M2", "M3"].iter().enumerate() {
        data_array(
            &mut out,
            "Float64",
            name,
            1,
            (0..n_cells).map(|k| format!("{:.9e}", beam[6 * k + c])),
        );
    }
    data_array(
        &mut out,
        "Float64",
        "spring_F",
        3,
        (0..n_cells)
            .flat_map(|k| (0..3).map(move |c| (k, c)))
            .map(|(k, c)| format!("{:.9e}", spring[6 * k + c])),
    );
    data_array(
        &mut out,
        "Float64",
        "spring_D",
        3,
        (0..n_cells)
            .flat_map(|k| (3..6).map(move |c| (k, c)))
            .map(|(k, c)| format!("{:.9e}", spring[6 * k + c])),
    );
    out.push_str("      </CellData>\n");

    // geometry
    out.push_str("      <Points>\n");
    data_array(
        &mut out,
        "Float64",
        "position",
        3,
        state
            .x
            .iter()
            .flat_map(|x| [x.x, x.y, x.z].map(|v| format!("{v:.12e}"))),
    );
    out.push_str("      </Points>\n      <Cells>\n");
    data_array(
        &mut out,
        "Int64",
        "connectivity",
        1,
        connectivity.iter().map(|v| v.to_string()),
    );
    data_array(
        &mut out,
        "Int64",
        "offsets",
        1,
        offsets.iter().map(|v| v.to_string()),
    );
    data_array(
        &mut out,
        "UInt8",
        "types",
        1,
        types.iter().map(|v| v.to_string()),
    );
    out.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
    write_atomically(path, out.as_bytes())
}

/// Writes the collection file listing `(time, file name)` pairs.
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> std::io::Result<()> {
    let mut out = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, file) in entries {
        let _ = writeln!(
            out,
            "    <DataSet timestep=\"{t:.12e}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        );
    }
    out.push_str("  </Collection>\n</VTKFile>\n");
    write_atomically(path, out.as_bytes())
}

/// Writes to a temporary file then renames it, so a reader (or a crash)
/// never sees a half-written file.
fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = path.with_extension("tmp");
    {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
    }
    std::fs::rename(&tmp, path)
}
