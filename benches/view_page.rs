//! Benchmark: the page of `unfold view` (src/io/view): reading a run's
//! grids and CSV files, quantising, compressing and assembling the HTML,
//! without writing it. By default on the results of
//! `tests/data/viewer_deployment.toml` (run first into
//! `target/bench-view`), or on the results directories given:
//!
//! ```text
//! cargo bench --bench view_page
//! cargo bench --bench view_page -- results/era_cell/deployment_0g
//! ```
//!
//! Prints, for each directory, the median wall time of at least 5 pages
//! (about 3 s of repetitions), the size of the page and of its data
//! before compression.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use unfold::io::view::{page, ViewOptions};

fn main() {
    let args: Vec<PathBuf> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .collect();
    let dirs = if args.is_empty() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let out = root.join("target/bench-view");
        let status = Command::new(env!("CARGO_BIN_EXE_unfold"))
            .args(["run", "--quiet", "--out"])
            .arg(&out)
            .arg(root.join("tests/data/viewer_deployment.toml"))
            .status()
            .expect("unfold runs");
        assert!(status.success());
        vec![out]
    } else {
        args
    };
    let options = ViewOptions::default();
    for dir in dirs {
        let mut times = Vec::new();
        let start = Instant::now();
        let mut last = None;
        while times.len() < 5 || start.elapsed().as_secs_f64() < 3.0 {
            let t = Instant::now();
            let made = page(&dir, &options).unwrap_or_else(|e| panic!("{e}"));
            times.push(t.elapsed().as_secs_f64());
            last = Some(made);
        }
        times.sort_by(f64::total_cmp);
        let (html, report) = last.expect("a page");
        println!(
            "{}: {} frames, {} points, {} cells, {} fields, {} series: page {:.3} s (median of {}), {} bytes ({} bytes of data before compression)",
            dir.display(),
            report.frames,
            report.points,
            report.cells,
            report.fields.len(),
            report.series,
            times[times.len() / 2],
            times.len(),
            html.len(),
            report.raw_data_bytes
        );
    }
}
