//! Every example runs: the model files in `examples/` through the
//! command-line tool, and the model built by `examples/lattice_mast.rs`
//! through the library (after a round trip through its TOML text).

mod common;

use std::process::Command;

#[allow(dead_code)]
#[path = "../examples/lattice_mast.rs"]
mod lattice_mast;

#[test]
fn every_model_file_runs_to_completion() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let out = std::env::temp_dir().join(format!(
            "unfold-example-{}-{}",
            std::process::id(),
            path.file_stem().unwrap().to_string_lossy()
        ));
        let result = Command::new(env!("CARGO_BIN_EXE_unfold"))
            .args([
                "run",
                path.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--quiet",
            ])
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(result.status.success(), "{}: {stderr}", path.display());
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["status"], "completed", "{}", path.display());
        assert_eq!(summary["final_time"], summary["end_time"]);
        count += 1;
    }
    assert!(count >= 3, "only {count} example model files");
}

#[test]
fn rust_built_mast_round_trips_and_runs() {
    let input = lattice_mast::build(3);
    // the written model file reads back to the same definition
    let text = input.to_toml().unwrap();
    let back =
        unfold::io::model_file::parse_model(&text, std::path::Path::new("lattice_mast.toml"))
            .unwrap();
    assert_eq!(back, input);
    let (model, outcome, _) = common::run(&back);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    // 3 bays: 12 corners, 3 × 12 + 3 members of 2 elements with one
    // interior node each
    assert_eq!(model.n_nodes(), 12 + 39);
    // the lateral force bends the mast towards +x
    let top = model.node_index(301).unwrap();
    assert!(outcome.state.x[top].x > model.reference_x[top].x);
}

/// The lattice mast's command line: a number of bays from 1 to 10 000, an
/// output directory; anything else is a usage error (0 bays ran a mast
/// without members, with its loads on clamped nodes).
#[test]
fn lattice_mast_arguments_are_checked() {
    let args = |a: &[&str]| lattice_mast::arguments(a.iter().map(|s| s.to_string()));
    assert_eq!(
        args(&[]).unwrap(),
        (8, std::path::PathBuf::from("results/lattice_mast"))
    );
    assert_eq!(args(&["3", "out"]).unwrap(), (3, "out".into()));
    for bad in [
        &["0"][..],
        &["abc"],
        &["-3"],
        &["1e3"],
        &["10001"],
        &["2", "out", "more"],
    ] {
        let e = args(bad).unwrap_err();
        assert!(
            e.contains("BAYS must be a whole number from 1 to 10000")
                || e.contains("unexpected argument"),
            "{bad:?}: {e}"
        );
    }
}
