//! Runs of the command line on a model text and readers of the result
//! files, shared by the command-line tests.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh scratch directory `<temp>/unfold-<group>-<pid>-<name>`.
pub fn scratch(group: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-{group}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `text` as `model.toml` in `dir` and runs `unfold run --quiet`
/// on it into `dir/out`, which must end with exit code 0.
pub fn run_text(dir: &Path, text: &str) -> (PathBuf, Output) {
    let model = dir.join("model.toml");
    std::fs::write(&model, text).unwrap();
    let out = dir.join("out");
    let o = run_model(&model, &out);
    (out, o)
}

/// Runs `unfold` with the arguments `args`, whatever its exit code.
pub fn unfold<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(args)
        .output()
        .unwrap()
}

/// Runs `unfold run --quiet` on the model file `model` into `out`, which
/// must end with exit code 0.
pub fn run_model(model: &Path, out: &Path) -> Output {
    let o = unfold(&[
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// The column `name` of a CSV file, as numbers.
pub fn column(path: &Path, name: &str) -> Vec<f64> {
    csv_rows(path).iter().map(|r| number(r, name)).collect()
}

/// The rows of a CSV file as maps from column name to text.
pub fn csv_rows(path: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            // every row has the header's columns
            assert_eq!(
                l.split(',').count(),
                header.len(),
                "{}: {l}",
                path.display()
            );
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

/// The number in column `column` of a row of [`csv_rows`].
pub fn number(row: &HashMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column} = {:?}", row[column]))
}

/// `summary.json` of the results in `out`.
pub fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}
