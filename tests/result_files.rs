//! The result files: CSV headers and sizes, rows in id order, support
//! reactions in global equilibrium with the loads, joint and driver loads
//! in global axes, VTK grids that ParaView can read (decoded and checked
//! structurally, binary against ASCII), mechanisms drawn with their links,
//! the PVD collection, summary.json, and an output directory that holds
//! one run only.

mod common;
mod vtk_reader;

use std::path::{Path, PathBuf};
use std::process::Command;

use vtk_reader::Grid;

fn run_example(name: &str) -> PathBuf {
    run_example_into(name, name)
}

/// Runs an example into a directory of its own, named by `tag` (tests
/// that run at the same time need different ones).
fn run_example_into(name: &str, tag: &str) -> PathBuf {
    let model = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    let out = std::env::temp_dir().join(format!("unfold-results-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    common::cli::run_model(&model, &out);
    out
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// The values of the data array `name` of a grid.
fn vtk_array(grid: &Grid, name: &str) -> Vec<f64> {
    grid.array(name).0
}

/// A size attribute of the grid's piece.
fn attribute(grid: &Grid, name: &str) -> usize {
    grid.piece(name)
}

#[test]
fn rollup_results_are_complete_and_consistent() {
    let out = run_example("cantilever_rollup.toml");

    // nodes.csv: 11 output steps (initial state + 10 increments) × 11 nodes
    let (header, rows) = csv(&out.join("nodes.csv"));
    assert_eq!(
        header.join(","),
        "step,time,node,x,y,z,ux,uy,uz,qw,qx,qy,qz"
    );
    assert_eq!(rows.len(), 11 * 11);
    // unit quaternions
    for r in &rows {
        let n = (r[9] * r[9] + r[10] * r[10] + r[11] * r[11] + r[12] * r[12]).sqrt();
        assert!((n - 1.0).abs() < 1e-12);
    }

    // beams.csv: section forces; a pure end moment gives M3 = M everywhere
    // and no force (the moment is about global z = local axis 3 here)
    let (header, rows) = csv(&out.join("beams.csv"));
    assert_eq!(header.join(","), "step,time,element,N,V2,V3,T,M2,M3");
    assert_eq!(rows.len(), 11 * 10);
    let m = 2.0 * std::f64::consts::PI * 10.0;
    for r in rows.iter().filter(|r| r[0] == 10.0) {
        assert!((r[8].abs() - m).abs() < 1e-6 * m, "M3 = {}", r[8]);
        assert!(r[3].abs() < 1e-6 && r[4].abs() < 1e-6);
    }

    // reactions.csv: the clamp balances the applied moment (global
    // equilibrium, to the Newton tolerance)
    let (header, rows) = csv(&out.join("reactions.csv"));
    assert_eq!(header.join(","), "step,time,node,Fx,Fy,Fz,Mx,My,Mz");
    let last = rows.last().unwrap();
    assert!(
        (last[8] + m).abs() < 1e-6 * m,
        "reaction moment {}",
        last[8]
    );
    assert!(last[3..6].iter().all(|f| f.abs() < 1e-6));

    // VTK: one grid per step, listed in the PVD with increasing times
    let pvd = std::fs::read_to_string(out.join("unfold.pvd")).unwrap();
    assert!(pvd.contains("type=\"Collection\""));
    let files: Vec<&str> = pvd
        .split("file=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    assert_eq!(files.len(), 11);
    let bytes = std::fs::read(out.join(files[10])).unwrap();
    assert!(bytes.starts_with(b"<?xml") && bytes.trim_ascii_end().ends_with(b"</VTKFile>"));
    let last = Grid::parse(&bytes);
    assert_eq!(attribute(&last, "NumberOfPoints"), 11);
    assert_eq!(attribute(&last, "NumberOfCells"), 10);
    let points = vtk_array(&last, "position");
    assert_eq!(points.len(), 33);
    assert_eq!(vtk_array(&last, "connectivity").len(), 20);
    assert_eq!(vtk_array(&last, "types"), vec![3.0; 10]);
    let m3 = vtk_array(&last, "M3");
    assert!(m3.iter().all(|v| (v.abs() - m).abs() < 1e-6 * m));
    assert_eq!(vtk_array(&last, "displacement").len(), 33);

    // summary.json
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["dofs"], 60);
    assert_eq!(summary["increments"], 10);
    assert_eq!(summary["output_steps"], 11);
    assert!(summary["iterations"].as_u64().unwrap() >= 10);
    assert!(summary["wall_time_s"].as_f64().unwrap() > 0.0);
    assert_eq!(summary["increment_log"].as_array().unwrap().len(), 11);
    // log.txt has a line per increment
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert_eq!(
        log.lines().filter(|l| l.starts_with("increment")).count(),
        11
    );
}

/// Global equilibrium of the 45° bend: the clamp reaction balances the tip
/// force and its moment about the clamp, in the deformed configuration.
#[test]
fn bend_reactions_balance_the_load() {
    let out = run_example("bend_45.toml");
    let (_, reactions) = csv(&out.join("reactions.csv"));
    let r = reactions.last().unwrap();
    let (_, nodes) = csv(&out.join("nodes.csv"));
    let tip = nodes.iter().rev().find(|n| n[2] == 9.0).unwrap();
    let p = 600.0;
    // force: R + P = 0
    assert!(r[3].abs() < 1e-6 * p && r[4].abs() < 1e-6 * p);
    assert!((r[5] + p).abs() < 1e-6 * p, "Fz = {}", r[5]);
    // moment about the clamp (at the origin): M_R + x_tip × P = 0
    let (x, y) = (tip[3], tip[4]);
    let moment = [y * p, -x * p, 0.0];
    for k in 0..3 {
        assert!(
            (r[6 + k] + moment[k]).abs() < 1e-6 * p * 100.0,
            "M{k}: {} vs {}",
            r[6 + k],
            -moment[k]
        );
    }
}

/// Writes `text` as a model file and runs it into a fresh directory with
/// `args`; returns the directory, the exit code and stderr.
fn run_text(name: &str, text: &str, args: &[&str]) -> (PathBuf, i32, String) {
    let dir = std::env::temp_dir().join(format!("unfold-results-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join(format!("{name}.toml"));
    std::fs::write(&model, text).unwrap();
    let out = dir.join("out");
    let result = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(args)
        .output()
        .unwrap();
    (
        out,
        result.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&result.stderr).into_owned(),
    )
}

/// A CSV file with named columns; empty values are NaN, and so is the
/// text of column `type` (a joint's type, [`Table::text`]).
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<f64>>,
    /// The fields of each row as text.
    cells: Vec<Vec<String>>,
}

impl Table {
    fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let cells: Vec<Vec<String>> = lines
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        let rows = cells
            .iter()
            .map(|l| {
                assert_eq!(l.len(), header.len(), "{l:?}");
                l.iter()
                    .zip(&header)
                    .map(|(v, h)| {
                        if v.is_empty() || h == "type" {
                            f64::NAN
                        } else {
                            v.parse().unwrap()
                        }
                    })
                    .collect()
            })
            .collect();
        Self {
            header,
            rows,
            cells,
        }
    }

    /// The text of `column` in row `r`.
    fn text(&self, r: usize, column: &str) -> &str {
        let k = self.header.iter().position(|h| h == column).unwrap();
        &self.cells[r][k]
    }

    /// Value of `column` in `row`.
    fn get(&self, row: &[f64], column: &str) -> f64 {
        let k = self
            .header
            .iter()
            .position(|h| h == column)
            .unwrap_or_else(|| panic!("no column {column}"));
        row[k]
    }
}

/// A pendulum: a rigid body of mass m = 2 at (L, 0, 0), L = 0.5, hinged
/// to the ground about y at the origin and held horizontal by a driver on
/// the hinge angle, under gravity g = 9.81 along −z.
const HELD_PENDULUM: &str = r#"
title = "pendulum held horizontal by a driver"

[analysis]
end_time = 1.0
initial_increment = 0.5

[[nodes]]
id = 1
x = [0.5, 0.0, 0.0]

[[rigid_bodies]]
id = 1
node = 1
mass = 2.0
inertia = [0.01, 0.01, 0.01]

[[joints]]
id = 2
type = "revolute"
nodes = [1]
axis = [0.0, 1.0, 0.0]
position = [0.0, 0.0, 0.0]

[[drivers]]
id = 3
joint = 2
value = 0.0

[gravity]
acceleration = [0.0, 0.0, -9.81]
"#;

/// Joint and driver loads in the global axes next to the joint axes.
/// Statics of the held pendulum: the pin carries the weight, `F = (0, 0,
/// m g)` on the body, and no moment about the pin; the driver carries the
/// moment of the weight about the pin, `M = −(L, 0, 0) × (0, 0, −m g) =
/// (0, −L m g, 0)`, which is also its load along the hinge axis. In the
/// joint axes of a ground hinge about y (a₁ = x, a₃ = y, a₂ = a₃ × a₁ =
/// −z) the pin force is `F2 = −m g`. Tolerance 1e-6 of m g: the Newton
/// tolerance on the residual.
#[test]
fn joint_and_driver_loads_in_global_axes() {
    let (out, code, err) = run_text("held_pendulum", HELD_PENDULUM, &["--quiet"]);
    assert_eq!(code, 0, "{err}");
    let (m, g, l) = (2.0, 9.81, 0.5);
    let tol = 1e-6 * m * g;
    let joints = Table::read(&out.join("joints.csv"));
    // a model of revolute joints has their angle, and no other coordinate
    assert_eq!(
        joints.header.join(","),
        "step,time,joint,type,angle,F1,F2,F3,M1,M2,M3,Fx,Fy,Fz,Mx,My,Mz"
    );
    assert!((0..joints.rows.len()).all(|r| joints.text(r, "type") == "revolute"));
    let last = joints.rows.last().unwrap();
    assert!(joints.get(last, "angle").abs() < 1e-9);
    assert_eq!(joints.get(last, "time"), 1.0);
    assert!(
        (joints.get(last, "F2") + m * g).abs() < tol,
        "F2 {}",
        joints.get(last, "F2")
    );
    assert!(
        (joints.get(last, "Fz") - m * g).abs() < tol,
        "Fz {}",
        joints.get(last, "Fz")
    );
    for c in ["Fx", "Fy", "Mx", "My", "Mz"] {
        assert!(
            joints.get(last, c).abs() < tol,
            "{c} = {}",
            joints.get(last, c)
        );
    }
    let drivers = Table::read(&out.join("drivers.csv"));
    assert_eq!(
        drivers.header.join(","),
        "step,time,driver,coordinate,target,load,Fx,Fy,Fz,Mx,My,Mz"
    );
    let last = drivers.rows.last().unwrap();
    assert!(
        (drivers.get(last, "My") + l * m * g).abs() < tol,
        "My {}",
        drivers.get(last, "My")
    );
    assert!((drivers.get(last, "load") - drivers.get(last, "My")).abs() < tol);
    for c in ["Fx", "Fy", "Fz", "Mx", "Mz"] {
        assert!(
            drivers.get(last, c).abs() < tol,
            "{c} = {}",
            drivers.get(last, c)
        );
    }
}

/// A body hinged to the ground about y (the held pendulum's, let go) and a
/// block of mass 1 falling freely along z on a prismatic joint to the
/// ground, over 0.2 s.
const HINGE_AND_SLIDE: &str = r#"
title = "a pendulum and a falling block"

[analysis]
type = "dynamic"
end_time = 0.2
time_step = 0.01

[[nodes]]
id = 1
x = [0.5, 0.0, 0.0]

[[rigid_bodies]]
id = 1
node = 1
mass = 2.0
inertia = [0.01, 0.01, 0.01]

[[joints]]
id = 2
type = "revolute"
nodes = [1]
axis = [0.0, 1.0, 0.0]
position = [0.0, 0.0, 0.0]

[[nodes]]
id = 3
x = [0.0, 0.0, 2.0]

[[point_masses]]
id = 4
node = 3
mass = 1.0

[[joints]]
id = 5
type = "prismatic"
nodes = [3]
axis = [0.0, 0.0, 1.0]

[gravity]
acceleration = [0.0, 0.0, -9.81]
"#;

/// The coordinate columns of joints.csv are named after the coordinates
/// the model's joints have, after the joint's `type`: a revolute and a
/// prismatic joint give `angle,slide` (and `angle_rate,slide_rate` in
/// dynamics), each joint's row empty in the other's. The values: the
/// block falls by `½ g t²` at `−g t`, and the hinge's rate is the body's
/// angular velocity about y (nodes_velocities.csv), to the ten
/// significant digits of the files (the block: measured 5.0e-11 m and
/// 4.8e-10 m/s, the rounding of the file; within 2e-9 (1 + |v|)).
#[test]
fn joint_columns_are_named_after_the_coordinates() {
    let (out, code, err) = run_text("hinge_and_slide", HINGE_AND_SLIDE, &["--quiet"]);
    assert_eq!(code, 0, "{err}");
    let joints = Table::read(&out.join("joints.csv"));
    assert_eq!(
        joints.header.join(","),
        "step,time,joint,type,angle,slide,F1,F2,F3,M1,M2,M3,Fx,Fy,Fz,Mx,My,Mz,angle_rate,slide_rate"
    );
    let velocities = Table::read(&out.join("nodes_velocities.csv"));
    let g = 9.81;
    let last = joints.rows.last().unwrap();
    assert_eq!(joints.get(last, "time"), 0.2);
    assert!(joints.rows.len() > 20 && joints.rows.len().is_multiple_of(2));
    for (r, row) in joints.rows.iter().enumerate() {
        let t = joints.get(row, "time");
        match joints.get(row, "joint") as u32 {
            2 => {
                assert_eq!(joints.text(r, "type"), "revolute");
                assert_eq!(joints.text(r, "slide"), "");
                assert_eq!(joints.text(r, "slide_rate"), "");
                // the weight turns the body about +y, from rest
                let (angle, rate) = (joints.get(row, "angle"), joints.get(row, "angle_rate"));
                assert_eq!(
                    angle > 0.0 && rate > 0.0,
                    t > 0.0,
                    "t = {t}: {angle}, {rate}"
                );
                let node = velocities
                    .rows
                    .iter()
                    .find(|v| velocities.get(v, "time") == t && velocities.get(v, "node") == 1.0)
                    .unwrap();
                let wy = velocities.get(node, "wy");
                assert!(
                    (rate - wy).abs() <= 1e-8 * (1.0 + wy.abs()),
                    "{rate} vs {wy}"
                );
            }
            5 => {
                assert_eq!(joints.text(r, "type"), "prismatic");
                assert_eq!(joints.text(r, "angle"), "");
                assert_eq!(joints.text(r, "angle_rate"), "");
                let (slide, rate) = (joints.get(row, "slide"), joints.get(row, "slide_rate"));
                let (fall, speed) = (0.5 * g * t * t, g * t);
                assert!(
                    (slide + fall).abs() <= 2e-9 * (1.0 + fall),
                    "t = {t}: {slide}"
                );
                assert!(
                    (rate + speed).abs() <= 2e-9 * (1.0 + speed),
                    "t = {t}: {rate}"
                );
            }
            j => panic!("joint {j}"),
        }
    }
}

/// Rows of every step are in increasing id, whatever the order of the
/// model file.
#[test]
fn rows_follow_node_and_element_ids() {
    let text = r#"
[[sections]]
name = "s"
EA = 1.0e7
GA2 = 4.0e6
GA3 = 4.0e6
GJ = 1.0e3
EI2 = 1.0e3
EI3 = 1.0e3

[[nodes]]
id = 30
x = [1.0, 0.0, 0.0]

[[nodes]]
id = 10
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 20
x = [0.5, 0.0, 0.0]

[[nodes]]
id = 5
x = [1.5, 0.0, 0.0]

[[beams]]
id = 9
nodes = [30, 5]
section = "s"

[[beams]]
id = 2
nodes = [10, 20]
section = "s"

[[beams]]
id = 4
nodes = [20, 30]
section = "s"

[[supports]]
node = 10
fixed = ["all"]

[[supports]]
node = 5
fixed = ["z"]

[[loads]]
node = 30
force = [0.0, 0.0, -1.0]
"#;
    let (out, code, err) = run_text("id_order", text, &["--quiet"]);
    assert_eq!(code, 0, "{err}");
    let ids = |file: &str, column: &str| -> Vec<f64> {
        let t = Table::read(&out.join(file));
        t.rows
            .iter()
            .filter(|r| t.get(r, "step") == 0.0)
            .map(|r| t.get(r, column))
            .collect()
    };
    assert_eq!(ids("nodes.csv", "node"), vec![5.0, 10.0, 20.0, 30.0]);
    assert_eq!(ids("beams.csv", "element"), vec![2.0, 4.0, 9.0]);
    assert_eq!(ids("reactions.csv", "node"), vec![5.0, 10.0]);
}

/// Binary grids (appended raw, zlib) decode to the same numbers as the
/// ASCII ones, with a layout VTK's reader accepts: header_type UInt64, the
/// zlib compressor named, block headers whose sizes match the blocks,
/// arrays packed one after the other. 3000 beam elements make arrays of
/// several 32 KiB blocks.
#[test]
fn binary_grids_decode_to_the_ascii_values() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever_rollup.toml"),
    )
    .unwrap()
    .replace("elements = 10\n", "elements = 3000\n")
    .replace("first_node = 2\n", "first_node = 100\n")
    .replace("initial_increment = 0.1", "initial_increment = 0.5");
    let (binary, code, err) = run_text("grid_binary", &text, &["--quiet"]);
    assert_eq!(code, 0, "{err}");
    let (ascii, code, err) = run_text("grid_ascii", &text, &["--quiet", "--vtk-ascii"]);
    assert_eq!(code, 0, "{err}");
    let name = "vtk/step_00002.vtu";
    let b = vtk_reader::read(&binary.join(name));
    let a = vtk_reader::read(&ascii.join(name));
    let header = b.header();
    for (key, value) in [
        ("type", "UnstructuredGrid"),
        ("byte_order", "LittleEndian"),
        ("header_type", "UInt64"),
        ("compressor", "vtkZLibDataCompressor"),
    ] {
        assert_eq!(vtk_reader::attribute(header, key), Some(value), "{key}");
    }
    assert_eq!(vtk_reader::attribute(a.header(), "compressor"), None);
    assert!(b.check_layout() >= 3, "the positions span several blocks");
    assert_eq!(b.piece("NumberOfPoints"), 3001);
    assert_eq!(b.piece("NumberOfCells"), 3000);
    let names: Vec<&str> = a
        .array_tags()
        .iter()
        .map(|t| vtk_reader::attribute(t, "Name").unwrap())
        .collect();
    assert!(names.len() >= 17, "{names:?}");
    for name in names {
        let (va, ca) = a.array(name);
        let (vb, cb) = b.array(name);
        assert_eq!(ca, cb, "{name}");
        // the text holds the shortest decimal that reads back to each
        // number: equal bit for bit
        assert_eq!(va, vb, "{name}");
    }
    let sizes = |dir: &Path| -> u64 {
        std::fs::read_dir(dir.join("vtk"))
            .unwrap()
            .map(|e| e.unwrap().metadata().unwrap().len())
            .sum()
    };
    assert!(
        4 * sizes(&binary) < sizes(&ascii),
        "binary {} bytes, ASCII {} bytes",
        sizes(&binary),
        sizes(&ascii)
    );
}

/// A mechanism is drawn with its links: the four-bar's four joints each
/// give their two joint points (coinciding for a revolute joint), a line
/// from each link's node to its joint points and a marker at the joint;
/// the joint points carry the hinge axis as `axis_3`.
#[test]
fn mechanisms_are_drawn_with_links_and_joint_points() {
    let out = run_example("four_bar.toml");
    let grid = vtk_reader::read(&out.join("vtk/step_00009.vtu"));
    let nodes = 4;
    assert_eq!(grid.piece("NumberOfPoints"), nodes + 2 * 4);
    let (position, _) = grid.array("position");
    let (joint_id, _) = grid.array("joint_id");
    let (axis_3, _) = grid.array("axis_3");
    let point = |p: usize| [position[3 * p], position[3 * p + 1], position[3 * p + 2]];
    for p in nodes..grid.piece("NumberOfPoints") {
        assert!(joint_id[p] >= 1.0, "point {p} is a joint point");
        assert!((axis_3[3 * p + 2] - 1.0).abs() < 1e-12, "hinge axis z");
    }
    // the two points of each revolute joint coincide (to the constraint
    // tolerance); joint 1 stays at the ground pin O2 = (0, 0, 0)
    for j in 0..4 {
        let (a, b) = (point(nodes + 2 * j), point(nodes + 2 * j + 1));
        let gap = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
        assert!(gap < 1e-8, "joint {} gap {gap}", j + 1);
    }
    assert!(point(nodes).iter().all(|c| c.abs() < 1e-8));
    // cells: per joint two links (kind 10) and a marker (kind 7)
    let (kind, _) = grid.array("kind");
    let (connectivity, _) = grid.array("connectivity");
    let (types, _) = grid.array("types");
    assert_eq!(kind.iter().filter(|&&k| k == 10.0).count(), 8);
    assert_eq!(kind.iter().filter(|&&k| k == 7.0).count(), 4);
    let (offsets, _) = grid.array("offsets");
    let mut start = 0;
    for (c, &end) in offsets.iter().enumerate() {
        let cell = &connectivity[start..end as usize];
        if kind[c] == 10.0 {
            // from a node to a joint point
            assert_eq!(types[c], 3.0);
            assert!(cell[0] < nodes as f64 && cell[1] >= nodes as f64);
        }
        start = end as usize;
    }
}

/// A new run in a directory that holds the results of another model
/// leaves none of them behind (files unfold writes and grids), and keeps
/// the files it does not own.
#[test]
fn earlier_results_are_removed_and_other_files_kept() {
    let out = std::env::temp_dir().join(format!("unfold-results-{}-reuse", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let run = |example: &str| {
        let model = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples")
            .join(example);
        let status = Command::new(env!("CARGO_BIN_EXE_unfold"))
            .args([
                "run",
                model.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--quiet",
            ])
            .status()
            .unwrap();
        assert!(status.success(), "{example}");
    };
    run("four_bar.toml");
    assert!(out.join("joints.csv").exists() && out.join("vtk/step_00072.vtu").exists());
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    // temporary files left by a run killed while writing
    std::fs::write(out.join("unfold.pvd.tmp"), "").unwrap();
    std::fs::write(out.join("unfold.tmp"), "").unwrap();
    std::fs::write(out.join("vtk/step_00003.vtu.tmp"), "").unwrap();
    std::fs::write(out.join("vtk/mine.vtu"), "mine").unwrap();
    run("cantilever_rollup.toml");
    for gone in [
        "joints.csv",
        "drivers.csv",
        "vtk/step_00011.vtu",
        "vtk/step_00072.vtu",
    ] {
        assert!(!out.join(gone).exists(), "{gone} left from the first run");
    }
    let grids = std::fs::read_dir(out.join("vtk"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with("step_")
        })
        .count();
    assert_eq!(grids, 11);
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    assert!(out.join("vtk/mine.vtu").exists());
}

/// `dofs` in summary.json counts the equations solved, after the
/// redundant constraint equations are removed (docs/results.md): for the
/// four-bar of 3-D hinges, 39 unknowns in the first log line, 3 of them
/// redundant (the planar loop), 36 solved. The last line counts the
/// iterations of the initial equilibrium apart from the average per
/// increment.
#[test]
fn summary_counts_the_equations_solved() {
    let out = run_example_into("four_bar.toml", "dofs");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let first = log.lines().next().unwrap();
    assert!(first.contains("; 39 unknowns;"), "{first}");
    assert_eq!(summary["redundant_constraints"], 3);
    assert_eq!(summary["dofs"], 36);
    assert!(!out.join(".unfold.lock").exists());

    let out = run_example_into("cantilever_rollup.toml", "last_line");
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let initial = summary["increment_log"][0]["iterations"].as_u64().unwrap();
    let last = log.lines().last().unwrap();
    let expected = format!(
        "completed: 10 increments, {} iterations ({initial} for the initial equilibrium; {:.2} per increment), 0 cut-backs, t = 1, ",
        summary["iterations"],
        summary["average_iterations"].as_f64().unwrap()
    );
    assert!(last.starts_with(&expected), "{last}\nexpected {expected}");
}
