//! The drawn shapes of rigid bodies (docs/model-format.md, `shape`; docs/results.md,
//! "VTK files"): the cells of a body's box, cylinder, plate and the box of
//! its inertia follow the body as it turns, read back from the `.vtu`
//! files with the independent reader of `tests/vtk_reader`; bad shapes are
//! refused naming the file, the body and the field.

mod common;
#[allow(dead_code)] // the reader serves several test files
mod vtk_reader;

use std::path::Path;

use common::cli::{run_text, scratch, unfold};

/// `v` turned by the angle `theta` about the unit axis `n` (Rodrigues).
fn turn(n: [f64; 3], theta: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    let dot = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    let cross = [
        n[1] * v[2] - n[2] * v[1],
        n[2] * v[0] - n[0] * v[2],
        n[0] * v[1] - n[1] * v[0],
    ];
    std::array::from_fn(|i| v[i] * c + cross[i] * s + n[i] * dot * (1.0 - c))
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] + b[i])
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// The hinge axis (unit, oblique so that every coordinate moves), the
/// node's reference position and the driven angle at `t = 1`.
const AXIS: [f64; 3] = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0];
const X0: [f64; 3] = [0.5, 0.1, -0.2];
const ANGLE: f64 = 2.0;

/// A node hinged to the ground at the origin about `AXIS`, turned by a
/// driver through 2 rad in a kinematic analysis, carrying five bodies: an
/// explicit box turned about its axis 3 and off its node, a cylinder at
/// the centre of mass, a body drawn as the box of its full (rotated)
/// inertia tensor, a plate, and a body without inertia (a vertex).
fn model() -> String {
    // the inertia of a uniform box of 2 kg, edges 0.4 × 0.2 × 0.1, turned
    // by the rotation vector (0.3, −0.2, 0.4): computed here, not by unfold
    let (m, e) = (2.0, [0.4, 0.2, 0.1]);
    let q = rotation_matrix([0.3, -0.2, 0.4]);
    let principal = [
        m * (e[1] * e[1] + e[2] * e[2]) / 12.0,
        m * (e[0] * e[0] + e[2] * e[2]) / 12.0,
        m * (e[0] * e[0] + e[1] * e[1]) / 12.0,
    ];
    let j: [[f64; 3]; 3] = std::array::from_fn(|r| {
        std::array::from_fn(|c| (0..3).map(|k| q[r][k] * principal[k] * q[c][k]).sum())
    });
    let rows = |r: [f64; 3]| format!("[{:e}, {:e}, {:e}]", r[0], r[1], r[2]);
    format!(
        r#"
title = "bodies drawn with their shapes, turned about an oblique hinge"

[analysis]
type = "kinematic"
end_time = 1.0
initial_increment = 0.25
max_increment = 0.25

[[nodes]]
id = 1
x = [{x0}, {x1}, {x2}]

[[joints]]
id = 10
type = "revolute"
nodes = [1]
axis = [{a0}, {a1}, {a2}]
position = [0.0, 0.0, 0.0]

[[drivers]]
id = 11
joint = 10
value = {ANGLE}

[[rigid_bodies]]
id = 1
node = 1
mass = 1.0
inertia = [0.01, 0.01, 0.01]
shape = {{ type = "box", size = [0.3, 0.2, 0.1], center = [0.1, 0.0, 0.0], rotation = [0.0, 0.0, 30.0], unit = "deg" }}

[[rigid_bodies]]
id = 2
node = 1
mass = 1.0
center_of_mass = [0.0, 0.1, 0.0]
shape = {{ type = "cylinder", radius = 0.05, length = 0.2 }}

[[rigid_bodies]]
id = 3
node = 1
mass = {m}
inertia = [{r0}, {r1}, {r2}]
center_of_mass = [0.0, 0.0, 0.05]

[[rigid_bodies]]
id = 4
node = 1
mass = 1.0
shape = {{ type = "plate", size = [0.5, 0.3] }}

[[rigid_bodies]]
id = 5
node = 1
mass = 1.0
"#,
        x0 = X0[0],
        x1 = X0[1],
        x2 = X0[2],
        a0 = AXIS[0],
        a1 = AXIS[1],
        a2 = AXIS[2],
        r0 = rows(j[0]),
        r1 = rows(j[1]),
        r2 = rows(j[2]),
    )
}

/// The rotation matrix of the rotation vector `psi` (rows).
fn rotation_matrix(psi: [f64; 3]) -> [[f64; 3]; 3] {
    let angle = distance(psi, [0.0; 3]);
    let n = psi.map(|p| p / angle);
    let columns = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| turn(n, angle, e));
    std::array::from_fn(|r| std::array::from_fn(|c| columns[c][r]))
}

fn apply(q: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| (0..3).map(|c| q[r][c] * v[c]).sum())
}

/// The corners of a box of edges `e` in VTK's hexahedron order (the face
/// at −e₃/2 counter-clockwise about axis 3, then the one above it), or
/// the four of a plate (`e[2] = 0`).
fn corners(e: [f64; 3]) -> Vec<[f64; 3]> {
    let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let layers: &[f64] = if e[2] == 0.0 { &[0.0] } else { &[-1.0, 1.0] };
    layers
        .iter()
        .flat_map(|&z| square.map(|(s, t)| [0.5 * s * e[0], 0.5 * t * e[1], 0.5 * z * e[2]]))
        .collect()
}

/// A cell of a grid: its VTK type and points.
struct Cell {
    vtk_type: u8,
    kind: i64,
    points: Vec<[f64; 3]>,
}

/// The cells of element `id` in the grid.
fn cells_of(grid: &vtk_reader::Grid, id: i64) -> Vec<Cell> {
    let (position, _) = grid.array("position");
    let (connectivity, _) = grid.array("connectivity");
    let (offsets, _) = grid.array("offsets");
    let (types, _) = grid.array("types");
    let (ids, _) = grid.array("element_id");
    let (kinds, _) = grid.array("kind");
    let mut start = 0;
    let mut out = Vec::new();
    for c in 0..offsets.len() {
        let end = offsets[c] as usize;
        if ids[c] as i64 == id {
            out.push(Cell {
                vtk_type: types[c] as u8,
                kind: kinds[c] as i64,
                points: connectivity[start..end]
                    .iter()
                    .map(|&p| {
                        let p = p as usize;
                        [position[3 * p], position[3 * p + 1], position[3 * p + 2]]
                    })
                    .collect(),
            });
        }
        start = end;
    }
    out
}

/// The largest distance between the points of `cell` and `expected`
/// (the same points in the same order).
fn gap(points: &[[f64; 3]], expected: &[[f64; 3]]) -> f64 {
    assert_eq!(points.len(), expected.len());
    points
        .iter()
        .zip(expected)
        .map(|(a, b)| distance(*a, *b))
        .fold(0.0, f64::max)
}

/// Every cell of every body at every output step is where the body's
/// turn puts it: `x(t) + R(t) (c + Q p)` with `R(t)` the turn by the
/// driven angle `2t` about the hinge (the kinematic analysis holds the
/// hinge and the driver to 1e-10; 1e-8 m bounds the points, 0.1 m to
/// 0.6 m from the hinge). The cells carry the rigid body's `kind` (2), its
/// `element_id` and every cell array of the grid.
#[test]
fn the_cells_of_a_body_follow_its_rotation() {
    let dir = scratch("shapes", "turn");
    let (out, _) = run_text(&dir, &model());
    let times = common::cli::column(&out.join("steps.csv"), "time");
    assert_eq!(times.len(), 5);
    let cylinder: Vec<[f64; 3]> = [-0.1, 0.1]
        .iter()
        .flat_map(|&z| {
            (0..24).map(move |k| {
                let a = std::f64::consts::TAU * k as f64 / 24.0;
                [0.05 * a.cos(), 0.1 + 0.05 * a.sin(), z]
            })
        })
        .collect();
    let box_axes = rotation_matrix([0.0, 0.0, 30f64.to_radians()]);
    let inertia_axes = rotation_matrix([0.3, -0.2, 0.4]);
    let mut largest = 0.0f64;
    for (step, &t) in times.iter().enumerate() {
        let grid = vtk_reader::read(&out.join(format!("vtk/step_{step:05}.vtu")));
        let theta = ANGLE * t;
        // a point of the node's frame (the global frame at the reference)
        let place = |p: [f64; 3]| add(turn(AXIS, theta, X0), turn(AXIS, theta, p));
        let n_cells = grid.piece("NumberOfCells");
        for name in ["kind", "element_id", "N", "M3", "spring_F"] {
            let (v, c) = grid.array(name);
            assert_eq!(v.len(), c * n_cells, "{name}: one tuple per cell");
        }

        // the box: one hexahedron, turned by 30° about axis 3, off the node
        let cells = cells_of(&grid, 1);
        assert_eq!(cells.len(), 1);
        assert_eq!((cells[0].vtk_type, cells[0].kind), (12, 2));
        let expected: Vec<_> = corners([0.3, 0.2, 0.1])
            .into_iter()
            .map(|p| place(add([0.1, 0.0, 0.0], apply(&box_axes, p))))
            .collect();
        largest = largest.max(gap(&cells[0].points, &expected));

        // the cylinder: 24 side quadrilaterals and two 24-gons, about the
        // node's axis 3 at the centre of mass
        let cells = cells_of(&grid, 2);
        assert_eq!(cells.len(), 26);
        assert!(cells[..24].iter().all(|c| c.vtk_type == 9));
        assert!(cells[24..]
            .iter()
            .all(|c| c.vtk_type == 7 && c.points.len() == 24));
        let ring: Vec<_> = cylinder.iter().map(|&p| place(p)).collect();
        for (k, c) in cells[..24].iter().enumerate() {
            let next = (k + 1) % 24;
            let expected = [ring[k], ring[next], ring[24 + next], ring[24 + k]];
            largest = largest.max(gap(&c.points, &expected));
        }
        let top: Vec<_> = ring[24..].to_vec();
        largest = largest.max(gap(&cells[25].points, &top));

        // the box of the inertia: the same eight corners as the box whose
        // inertia it is (as a set: its axes may be any of that box's)
        let cells = cells_of(&grid, 3);
        assert_eq!(cells.len(), 1);
        assert_eq!(cells[0].vtk_type, 12);
        for p in corners([0.4, 0.2, 0.1]) {
            let expected = place(add([0.0, 0.0, 0.05], apply(&inertia_axes, p)));
            let nearest = cells[0]
                .points
                .iter()
                .map(|&q| distance(q, expected))
                .fold(f64::INFINITY, f64::min);
            largest = largest.max(nearest);
        }

        // the plate: one quadrilateral in the node's 1–2 plane
        let cells = cells_of(&grid, 4);
        assert_eq!(cells.len(), 1);
        assert_eq!(cells[0].vtk_type, 9);
        let expected: Vec<_> = corners([0.5, 0.3, 0.0]).into_iter().map(place).collect();
        largest = largest.max(gap(&cells[0].points, &expected));

        // no inertia, no shape: a vertex at the node, as before shapes
        let cells = cells_of(&grid, 5);
        assert_eq!(cells.len(), 1);
        assert_eq!(cells[0].vtk_type, 1);
        largest = largest.max(gap(&cells[0].points, &[place([0.0; 3])]));

        // a shape point's displacement is its motion from the reference
        let (position, _) = grid.array("position");
        let (displacement, _) = grid.array("displacement");
        let (node_id, _) = grid.array("node_id");
        let first_shape_point = 1 + 1; // the node, the joint's point
        assert_eq!(node_id[first_shape_point], -1.0);
        let p = |a: &[f64], i: usize| [a[3 * i], a[3 * i + 1], a[3 * i + 2]];
        let x = p(&position, first_shape_point);
        let u = p(&displacement, first_shape_point);
        let x_ref = turn(AXIS, -theta, x);
        assert!(distance(add(x_ref, u), x) < 1e-8);
    }
    println!("largest distance of a shape point from its place: {largest:.3e} m");
    assert!(largest < 1e-8, "{largest}");
}

/// Bad shapes are refused with exit code 2, naming the model file, the
/// body and what is wrong; an unknown kind of shape by the parser.
#[test]
fn bad_shapes_are_refused_naming_the_body_and_the_field() {
    let dir = scratch("shapes", "bad");
    let base = "[analysis]\ntype = \"static\"\n\n[[nodes]]\nid = 1\nx = [0.0, 0.0, 0.0]\n\n[[supports]]\nnode = 1\nfixed = [\"all\"]\n\n[[rigid_bodies]]\nid = 7\nnode = 1\nmass = 1.0\n";
    let cases = [
        (
            "shape = { type = \"box\", size = [0.1, -0.2, 0.3] }",
            "rigid body 7: shape size (every edge) must be positive, got -0.2",
        ),
        (
            "shape = { type = \"box\", size = [0.1, 0.2] }",
            "rigid body 7: shape: a box takes 3 edges in size, got 2",
        ),
        (
            "shape = { type = \"cylinder\", radius = -0.1, length = 0.2 }",
            "rigid body 7: shape radius must be positive, got -0.1",
        ),
        (
            "shape = { type = \"cylinder\", radius = 0.1 }",
            "rigid body 7: shape: a cylinder needs radius and length",
        ),
        (
            "shape = { type = \"plate\", size = [0.1, 0.2], thickness = -0.01 }",
            "rigid body 7: shape thickness must be zero or positive and finite, got -0.01",
        ),
        (
            "shape = { type = \"box\", size = [0.1, 0.2, 0.3], radius = 0.1 }",
            "rigid body 7: shape: a box has no radius (it takes size = [a, b, c], its edges)",
        ),
        ("shape = { type = \"sphere\", radius = 0.1 }", "sphere"),
    ];
    for (k, (shape, message)) in cases.iter().enumerate() {
        let model = dir.join(format!("bad{k}.toml"));
        std::fs::write(&model, format!("{base}{shape}\n")).unwrap();
        let o = unfold(&["check", model.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{shape}: {err}");
        assert!(err.contains(&*model.to_string_lossy()), "{shape}: {err}");
        assert!(err.contains(message), "{shape}: {err}");
    }
}

/// The builder gives a body its shape, and the model file it writes
/// carries it: built again from that file, the body is drawn the same.
#[test]
fn the_builder_writes_the_shape_into_the_model_file() {
    use unfold::model::builder::*;
    let mut m = ModelBuilder::new("hub");
    let n = m.node([0.0, 0.0, 0.0]);
    m.add(RigidBody::at(n, 2.0).shape(Shape::cylinder(0.07, 0.06).center([0.0, 0.0, 0.1])));
    m.fix(n, Dofs::ALL);
    let text = m.to_toml().unwrap();
    assert!(
        text.contains("type = \"cylinder\"") && text.contains("radius = 0.07"),
        "{text}"
    );
    let model = m.build().unwrap();
    let shape = model.elements[0].body_shape().unwrap();
    assert_eq!(
        shape.solid,
        unfold::elements::shape::Solid::Cylinder {
            radius: 0.07,
            length: 0.06
        }
    );
    let dir = scratch("shapes", "builder");
    let file = dir.join("hub.toml");
    std::fs::write(&file, &text).unwrap();
    let again = unfold::io::model_file::read_model(Path::new(&file)).unwrap();
    assert_eq!(again.model.elements[0].body_shape(), Some(shape));
}
