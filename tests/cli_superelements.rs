//! Superelements from the command line: bad input of a `[[superelements]]`
//! entry is refused with a message naming the file, the entity and the
//! problem, and exit code 2 (as tests/cli.rs for the other entities); a
//! body of imported matrices runs.

mod common;

use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    common::cli::scratch("cli-se", name)
}

/// `unfold ARGS`: exit code, stdout and stderr.
fn unfold(args: &[&str]) -> (i32, String, String) {
    let out = common::cli::unfold(args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A cantilever of 10 beams (ids 1–10) from node 1 (clamped) to node 2,
/// 1 m along x, and `superelement` (its tables).
fn cantilever(superelement: &str) -> String {
    format!(
        r#"title = "reduced cantilever"

[[sections]]
name = "s"
EA = 1.0e7
GA2 = 4.0e6
GA3 = 4.0e6
GJ = 1.0e3
EI2 = 1.0e3
EI3 = 1.0e3
mass_per_length = 1.0

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]

[[beam_lines]]
nodes = [1, 2]
elements = 10
section = "s"
first_element = 1
first_node = 3

[[supports]]
node = 1
fixed = ["all"]

[[loads]]
node = 2
force = [0.0, 0.0, -1.0]
{superelement}"#
    )
}

const ELEMENTS: &str = "elements = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]";

/// Writes `text` as `name` in `dir`, runs `unfold run` and `unfold check`
/// on it: both must refuse it with exit code 2 and a message naming the
/// file and holding every fragment.
fn assert_rejected(name: &str, text: &str, files: &[(&str, &str)], fragments: &[&str]) {
    let dir = scratch(name);
    for (file, content) in files {
        std::fs::write(dir.join(file), content).unwrap();
    }
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    for args in [
        vec![
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        vec!["check", path.to_str().unwrap()],
    ] {
        let (code, _, err) = unfold(&args);
        assert_eq!(
            code, 2,
            "{name} ({}): exit code {code}, stderr: {err}",
            args[0]
        );
        assert!(
            err.contains(&format!("{name}.toml")),
            "{name}: the file is not named: {err}"
        );
        for f in fragments {
            assert!(err.contains(f), "{name}: message lacks «{f}»: {err}");
        }
        assert!(!err.contains("panicked"), "{name}: panic: {err}");
    }
}

#[test]
fn a_superelement_without_boundary_node_is_refused() {
    let text = cantilever(&format!(
        "[[superelements]]\nid = 100\n{ELEMENTS}\nboundary = []\nmodes = 2\n"
    ));
    assert_rejected(
        "no_boundary",
        &text,
        &[],
        &["superelement 100", "no boundary node"],
    );
}

#[test]
fn more_modes_than_interior_dofs_are_refused() {
    // 9 interior nodes: 54 interior dofs
    let text = cantilever(&format!(
        "[[superelements]]\nid = 100\n{ELEMENTS}\nboundary = [1, 2]\nmodes = 60\n"
    ));
    assert_rejected(
        "too_many_modes",
        &text,
        &[],
        &[
            "superelement 100",
            "60 fixed-interface modes asked",
            "interior has only 54",
        ],
    );
}

/// Two beams not connected to each other, reduced on an end of each: with
/// the frame node held, the other part moves freely: the reduced
/// stiffness is singular.
#[test]
fn a_singular_reduced_stiffness_is_refused() {
    let text = cantilever(
        "[[nodes]]\nid = 20\nx = [0.0, 1.0, 0.0]\n\n[[nodes]]\nid = 21\nx = [1.0, 1.0, 0.0]\n\n[[beams]]\nid = 20\nnodes = [20, 21]\nsection = \"s\"\n\n[[supports]]\nnode = 21\nfixed = [\"all\"]\n\n[[superelements]]\nid = 100\nelements = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 20]\nboundary = [1, 2, 21]\nmodes = 2\n",
    );
    assert_rejected(
        "singular_stiffness",
        &text,
        &[],
        &[
            "superelement 100",
            "the reduced stiffness is singular",
            "frame node 1",
        ],
    );
}

/// A part of the body connected to no boundary node: the interior
/// stiffness is singular.
#[test]
fn a_body_part_off_the_boundary_is_refused() {
    let text = cantilever(
        "[[nodes]]\nid = 20\nx = [0.0, 1.0, 0.0]\n\n[[nodes]]\nid = 21\nx = [1.0, 1.0, 0.0]\n\n[[beams]]\nid = 20\nnodes = [20, 21]\nsection = \"s\"\n\n[[superelements]]\nid = 100\nelements = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 20]\nboundary = [1, 2]\nmodes = 2\n",
    );
    assert_rejected(
        "part_off_boundary",
        &text,
        &[],
        &["superelement 100", "not connected to its boundary nodes"],
    );
}

/// Imported matrices of mismatched sizes, an asymmetric stiffness, a dof
/// map too short, a NaN: each refused naming the file and the problem.
#[test]
fn mismatched_imported_matrices_are_refused() {
    let k6 = "%%MatrixMarket matrix coordinate real symmetric\n6 6 6\n1 1 1.0\n2 2 1.0\n3 3 1.0\n4 4 1.0\n5 5 1.0\n6 6 1.0\n";
    let m3 = "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 1.0\n2 2 1.0\n3 3 1.0\n";
    let dofs6 = "2 1\n2 2\n2 3\n2 4\n2 5\n2 6\n";
    let se = "[[superelements]]\nid = 100\nstiffness = \"k.mtx\"\nmass = \"m.mtx\"\ndofs = \"dofs.txt\"\nboundary = [2]\nmodes = 0\n";
    let text = cantilever(se);
    // the body replaces nothing of the cantilever: its node 2 is the
    // model's node 2
    assert_rejected(
        "sizes",
        &text,
        &[("k.mtx", k6), ("m.mtx", m3), ("dofs.txt", dofs6)],
        &[
            "superelement 100",
            "m.mtx",
            "the mass is 3 × 3, the stiffness",
            "6 × 6",
        ],
    );
    let asym = "%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1.0\n1 2 0.5\n2 1 0.25\n";
    assert_rejected(
        "asymmetric",
        &text,
        &[("k.mtx", asym), ("m.mtx", m3), ("dofs.txt", dofs6)],
        &["superelement 100", "k.mtx", "not symmetric"],
    );
    assert_rejected(
        "short_map",
        &text,
        &[("k.mtx", k6), ("m.mtx", k6), ("dofs.txt", "2 1\n2 2\n")],
        &[
            "superelement 100",
            "dofs.txt",
            "the dof map has 2 lines, the matrices 6 rows",
        ],
    );
    let nan = k6.replace("3 3 1.0", "3 3 NaN");
    assert_rejected(
        "nan",
        &text,
        &[("k.mtx", &nan), ("m.mtx", k6), ("dofs.txt", dofs6)],
        &["superelement 100", "k.mtx, line 5", "not finite"],
    );
}

/// Entries that use a node inside the superelement are told so.
#[test]
fn a_load_on_an_interior_node_is_refused() {
    let text = cantilever(&format!(
        "[[superelements]]\nid = 100\n{ELEMENTS}\nboundary = [1, 2]\nmodes = 2\n\n[[loads]]\nnode = 5\nforce = [0.0, 0.0, 1.0]\n"
    ));
    assert_rejected(
        "interior_load",
        &text,
        &[],
        &[
            "node 5 is inside superelement 100",
            "make it one of its boundary nodes",
        ],
    );
}

#[allow(dead_code)]
#[path = "vtk_reader/mod.rs"]
mod vtk_reader;

/// Runs `text` (with `files` beside it) with `unfold run --quiet`;
/// returns the output directory.
fn run_ok(name: &str, text: &str) -> PathBuf {
    let dir = scratch(name);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let (code, _, err) = unfold(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{name}: {err}");
    out
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The recovery (docs/results.md, "Superelements"): a tip-loaded
/// cantilever reduced on its ends. The VTK files draw the original mesh
/// (its 11 nodes, its 10 beams with their kind, id and section forces,
/// `superelement_id` 100), its recovered tip where the model's node 2 is
/// (1e-12 m: both are the boundary node); summary.json gives the peak of
/// each section force with where and when: the root moment, `P (L −
/// L/20)` = 0.95 N·m at the midpoint of element 1 (one-point
/// integration), as the beams give it (the same model in beams: 1e-6
/// relative, the beams' geometric nonlinearity at a tip deflection of
/// 3e-4 of the length).
#[test]
fn recovered_mesh_is_drawn_and_its_peak_section_forces_are_reported() {
    let se = format!("[[superelements]]\nid = 100\n{ELEMENTS}\nboundary = [1, 2]\nmodes = 2\n");
    let out = run_ok("recovery", &cantilever(&se));
    let beams = run_ok("recovery_beams", &cantilever(""));

    // summary.json
    let summary = json(&out.join("summary.json"));
    let record = &summary["superelements"][0];
    assert_eq!(record["superelement"], 100);
    assert_eq!(record["boundary_nodes"], serde_json::json!([1, 2]));
    assert_eq!(record["modes"], 2);
    let peaks = record["peaks"].as_array().unwrap();
    let moment = peaks
        .iter()
        .filter(|p| p["quantity"] == "M2" || p["quantity"] == "M3")
        .max_by(|a, b| {
            a["value"]
                .as_f64()
                .unwrap()
                .abs()
                .total_cmp(&b["value"].as_f64().unwrap().abs())
        })
        .unwrap();
    println!("{moment}");
    assert_eq!(moment["element"], 1);
    assert_eq!(moment["kind"], "beam");
    assert_eq!(moment["nodes"], serde_json::json!([1, 3]));
    assert!((moment["value"].as_f64().unwrap().abs() - 0.95).abs() < 1e-6);
    assert!(moment["time"].as_f64().unwrap() > 0.0);

    // the beams' moment at element 1, last step
    let text = std::fs::read_to_string(beams.join("beams.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let q = moment["quantity"].as_str().unwrap();
    let (col, id) = (
        header.iter().position(|h| *h == q).unwrap(),
        header.iter().position(|h| *h == "element").unwrap(),
    );
    let last = lines.rfind(|l| l.split(',').nth(id) == Some("1")).unwrap();
    let m_beams: f64 = last.split(',').nth(col).unwrap().parse().unwrap();
    assert!(
        (moment["value"].as_f64().unwrap() - m_beams).abs() < 1e-6 * m_beams.abs(),
        "{m_beams}"
    );

    // superelements.csv
    let csv = std::fs::read_to_string(out.join("superelements.csv")).unwrap();
    assert!(
        csv.starts_with("step,time,superelement,strain_energy,elastic_displacement"),
        "{csv}"
    );

    // the last grid
    let mut grids: Vec<PathBuf> = std::fs::read_dir(out.join("vtk"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "vtu"))
        .collect();
    grids.sort();
    let grid = vtk_reader::read(grids.last().unwrap());
    let (positions, _) = grid.array("position");
    let (mesh_ids, _) = grid.array("mesh_node_id");
    assert_eq!(
        mesh_ids.len(),
        2 + 11,
        "two model nodes and the 11 nodes of the mesh"
    );
    let (kinds, _) = grid.array("kind");
    let (owners, _) = grid.array("superelement_id");
    let (ids, _) = grid.array("element_id");
    let drawn: Vec<usize> = (0..kinds.len()).filter(|&c| owners[c] == 100.0).collect();
    assert_eq!(drawn.len(), 10);
    assert!(drawn.iter().all(|&c| kinds[c] == 1.0), "beam cells");
    let mut elements: Vec<f64> = drawn.iter().map(|&c| ids[c]).collect();
    elements.sort_by(f64::total_cmp);
    assert_eq!(elements, (1..=10).map(f64::from).collect::<Vec<_>>());
    let (m, _) = grid.array(q);
    let root_cell = drawn.iter().find(|&&c| ids[c] == 1.0).unwrap();
    assert!((m[*root_cell] - m_beams).abs() < 1e-6 * m_beams.abs());
    // the recovered tip (mesh node 2) where the model's node 2 is
    let point = |k: usize| [positions[3 * k], positions[3 * k + 1], positions[3 * k + 2]];
    let tip = (0..mesh_ids.len()).find(|&k| mesh_ids[k] == 2.0).unwrap();
    let (node_ids, _) = grid.array("node_id");
    let node2 = (0..node_ids.len()).find(|&k| node_ids[k] == 2.0).unwrap();
    for c in 0..3 {
        assert!((point(tip)[c] - point(node2)[c]).abs() < 1e-12);
    }
}
