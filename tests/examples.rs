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
