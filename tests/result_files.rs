//! The result files: CSV headers and sizes, support reactions in global
//! equilibrium with the loads, VTK grids that ParaView can read (checked
//! structurally), the PVD collection and summary.json.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run_example(name: &str) -> PathBuf {
    let model = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    let out = std::env::temp_dir().join(format!("unfold-results-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
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
    assert!(status.success());
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

/// The numbers inside the `<DataArray ... Name="name" ...>` element.
fn vtk_array(text: &str, name: &str) -> Vec<f64> {
    let start = text
        .find(&format!("Name=\"{name}\""))
        .unwrap_or_else(|| panic!("no array {name}"));
    let open = start + text[start..].find('>').unwrap() + 1;
    let close = open + text[open..].find("</DataArray>").unwrap();
    text[open..close]
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect()
}

fn attribute(text: &str, name: &str) -> usize {
    let key = format!("{name}=\"");
    let start = text.find(&key).unwrap() + key.len();
    text[start..start + text[start..].find('"').unwrap()]
        .parse()
        .unwrap()
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
    let last = std::fs::read_to_string(out.join(files[10])).unwrap();
    assert!(last.starts_with("<?xml") && last.trim_end().ends_with("</VTKFile>"));
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
