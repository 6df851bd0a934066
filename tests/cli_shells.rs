//! Shells through the command line: a panel model file runs (statics and
//! modes) and writes its shell results and quadrilateral cells; bad
//! laminates, plies, quadrilaterals and references are refused with a
//! message naming the file and the entity, exit code 2.

mod common;

use common::cli::{column, csv_rows, scratch, unfold};

/// A plate of two shells on six nodes and a 4 × 2 panel beside it.
const MODEL: &str = r#"
title = "shells"

[[ply_materials]]
name = "carbon"
E1 = 181e9
E2 = 10.3e9
nu12 = 0.28
G12 = 7.17e9
G13 = 7.17e9
G23 = 3.78e9
density = 1600.0

[[ply_materials]]
name = "aluminium"
E = 70e9
nu = 0.33
density = 2800.0

[[laminates]]
name = "face"
unit = "deg"
plies = [
  { material = "carbon", thickness = 0.125e-3, angle = 0.0 },
  { material = "carbon", thickness = 0.125e-3, angle = 90.0 },
]

[[laminates]]
name = "sandwich"
faces = "face"
core = { thickness = 10e-3, G13 = 190e6, G23 = 90e6, density = 32.0 }

[[laminates]]
name = "sheet"
plies = [{ material = "aluminium", thickness = 1e-3 }]

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [0.5, 0.0, 0.0]

[[nodes]]
id = 3
x = [0.5, 0.5, 0.0]

[[nodes]]
id = 4
x = [0.0, 0.5, 0.0]

[[nodes]]
id = 5
x = [1.0, 0.0, 0.0]

[[nodes]]
id = 6
x = [1.0, 0.5, 0.0]

[[shells]]
id = 1
nodes = [1, 2, 3, 4]
laminate = "sandwich"

[[shells]]
id = 2
nodes = [2, 5, 6, 3]
laminate = "sandwich"
pressure = 10.0

[[panels]]
name = "p"
size = [1.0, 0.5]
elements = [4, 2]
laminate = "sheet"
origin = [0.0, 1.0, 0.0]
first_node = 100
first_element = 100
node_ids = { west = 50 }

[[supports]]
node = 1
fixed = ["all"]

[[supports]]
node = 4
fixed = ["all"]

[[supports]]
node = 50
fixed = ["all"]

[[loads]]
node = 6
force = [0.0, 0.0, -0.01]
"#;

/// A bad-input rejection: exit code 2, a message naming the file and
/// holding every fragment, no panic; `unfold check` says the same.
fn rejected(name: &str, text: &str, fragments: &[&str]) {
    let dir = scratch("cli-shells", name);
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let out_dir = dir.join("out");
    let runs: [&[&str]; 2] = [
        &[
            "run",
            file.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
        ],
        &["check", file.to_str().unwrap()],
    ];
    for args in runs {
        let command = args[0];
        let out = unfold(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name} ({command}): {err}");
        assert!(
            err.contains(&format!("{name}.toml")),
            "{name}: the file is not named: {err}"
        );
        for f in fragments {
            assert!(
                err.contains(f),
                "{name} ({command}): message lacks «{f}»: {err}"
            );
        }
        assert!(!err.contains("panicked"), "{name}: {err}");
        // the nodes of a panel with errors are not reported again
        assert!(!err.contains("node 50 does not exist"), "{name}: {err}");
    }
}

/// The model runs: a static analysis in one increment (one Newton
/// iteration: every element is linear and no beam is there) then six
/// modes; `shells.csv` holds the resultants of the 10 shells at both
/// output steps; the VTK grid draws them as quadrilaterals (VTK type 9)
/// with the shell cell arrays.
#[test]
fn a_shell_model_runs_and_writes_its_results() {
    let text = format!(
        "{MODEL}\n[[analysis]]\ntype = \"static\"\ninitial_increment = 1.0\n\n[[analysis]]\ntype = \"modal\"\nmodes = 6\n"
    );
    let dir = scratch("cli-shells", "runs");
    let model = dir.join("model.toml");
    std::fs::write(&model, text).unwrap();
    let out = dir.join("out");
    let o = unfold(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--vtk-ascii",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains("10 shells"), "{log}");
    assert!(
        log.contains("increment    1  t = 1.000000  dt = 1.000e0  iterations  1"),
        "{log}"
    );
    let rows = csv_rows(&out.join("shells.csv"));
    assert_eq!(rows.len(), 2 * 10);
    for name in [
        "Nxx",
        "Nyy",
        "Nxy",
        "Mxx",
        "Myy",
        "Mxy",
        "Qx",
        "Qy",
        "von_mises",
    ] {
        assert!(rows[0].contains_key(name), "{name}");
    }
    // the loaded plate bends: the shells next to the load carry a moment
    let mxx = column(&out.join("shells.csv"), "Mxx");
    assert!(mxx[10..].iter().any(|m| m.abs() > 0.0));
    assert_eq!(csv_rows(&out.join("modes.csv")).len(), 6);
    let vtk = std::fs::read_to_string(out.join("vtk/step_00001.vtu")).unwrap();
    for array in ["shell_N", "shell_M", "shell_Q", "shell_von_mises"] {
        assert!(vtk.contains(&format!("Name=\"{array}\"")), "{array}");
    }
    let start = vtk.find("Name=\"types\"").unwrap();
    let body = &vtk[start..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    let quads = body.split_whitespace().filter(|t| *t == "9").count();
    assert_eq!(quads, 10);
}

#[test]
fn negative_ply_thickness() {
    let text = MODEL.replace(
        "thickness = 0.125e-3, angle = 90.0",
        "thickness = -0.125e-3, angle = 90.0",
    );
    rejected(
        "negative_thickness",
        &text,
        &[
            "laminate \"face\"",
            "ply 2: thickness must be positive and finite, got -0.000125",
        ],
    );
}

#[test]
fn poisson_ratio_beyond_the_stiffness_ratio() {
    // E1/E2 = 17.6: ν12 = 4.3 gives ν12² = 18.5
    let text = MODEL.replace("nu12 = 0.28", "nu12 = 4.3");
    rejected(
        "poisson",
        &text,
        &[
            "ply_material \"carbon\"",
            "ν12 = 4.3",
            "must be below E1/E2",
        ],
    );
}

#[test]
fn zero_area_quadrilateral() {
    // nodes 1, 2, 5 and a fourth on the same line
    let text = MODEL
        .replace("nodes = [1, 2, 3, 4]", "nodes = [1, 2, 5, 7]")
        .replacen(
            "[[shells]]",
            "[[nodes]]\nid = 7\nx = [1.5, 0.0, 0.0]\n\n[[shells]]",
            1,
        );
    rejected("zero_area", &text, &["shell 1", "has zero area"]);
}

#[test]
fn self_intersecting_quadrilateral() {
    let text = MODEL.replace("nodes = [2, 5, 6, 3]", "nodes = [2, 6, 5, 3]");
    // a symmetric bow-tie: its diagonals are parallel
    rejected("bow_tie", &text, &["shell 2", "sides cross"]);
    // an unsymmetric one: a corner turns the wrong way
    let text = text.replace("x = [1.0, 0.5, 0.0]", "x = [1.2, 0.6, 0.0]");
    rejected(
        "bow_tie_2",
        &text,
        &[
            "shell 2",
            "is not a convex quadrilateral",
            "self-intersecting",
        ],
    );
}

#[test]
fn unknown_laminate() {
    let text = MODEL.replace("laminate = \"sheet\"", "laminate = \"sheets\"");
    rejected(
        "unknown_laminate",
        &text,
        &["panel \"p\"", "laminate \"sheets\" is not defined"],
    );
    let text = MODEL.replace("faces = \"face\"", "faces = \"facing\"");
    rejected(
        "unknown_face",
        &text,
        &[
            "laminate \"sandwich\"",
            "face sheet laminate \"facing\" is not defined",
        ],
    );
    let text = MODEL.replace("{ material = \"aluminium\"", "{ material = \"steel\"");
    rejected(
        "unknown_material",
        &text,
        &[
            "laminate \"sheet\"",
            "ply material \"steel\" is not defined",
        ],
    );
}

#[test]
fn other_bad_shell_input() {
    let text = MODEL.replace("elements = [4, 2]", "elements = [5, 2]");
    rejected(
        "odd_panel",
        &text,
        &["panel \"p\"", "elements = [5, 2]", "even"],
    );
    let text = MODEL.replace("faces = \"face\"", "faces = \"sandwich\"");
    rejected(
        "sandwich_face",
        &text,
        &["face sheet \"sandwich\" is a sandwich"],
    );
    let text = MODEL.replace("E = 70e9", "E = 70e9\nE1 = 70e9");
    rejected(
        "mixed_moduli",
        &text,
        &["ply_material \"aluminium\"", "not both"],
    );
    let text = MODEL.replace("nodes = [2, 5, 6, 3]", "nodes = [2, 5, 5, 3]");
    rejected("repeated_node", &text, &["shell 2", "node 5 appears twice"]);
    let text = MODEL.replace(
        "first_element = 100",
        "first_element = 100\nstiffeners = [{ side = \"north\", section = \"rail\" }]",
    );
    rejected(
        "unknown_section",
        &text,
        &[
            "stiffener 1 (north side)",
            "section \"rail\" is not defined",
        ],
    );
    let text = MODEL.replace("x = [1.0, 0.5, 0.0]", "x = [1.0, 0.5, 0.2]");
    rejected("warped", &text, &["shell 2", "is warped"]);
}
