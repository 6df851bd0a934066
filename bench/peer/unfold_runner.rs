//! unfold's side of the peer benchmark (bench/peer/README.md): runs the
//! dynamic analysis of one model file through the library and writes the
//! motion of one node at the output times.
//!
//! ```text
//! peer_dynamics MODEL.toml OUT_DIR NODE_ID [--threads N]
//! ```
//!
//! writes `OUT_DIR/nodes.csv` (`time,node,x,y,z,energy,balance_error` of
//! node `NODE_ID` at every output step: position, total energy `T + V` and
//! the energy balance error of the analysis) and `OUT_DIR/summary.json`
//! (`wall_time_s` of the analysis alone, `increments`, `iterations`,
//! `cutbacks`, `rejected_steps`, `first_cutbacks`, `error`). The exit code is 0 when the
//! analysis reaches its end time, 1 when it stops early, 2 for bad input.
//!
//! It stands in for `unfold run` until the command-line tool runs dynamic
//! analyses; the harness (`unfold_side.py`) builds it with
//! `cargo bench --no-run --bench peer_dynamics`. Run without a model (as
//! `cargo bench` does) it prints this usage and does nothing.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;

use unfold::analysis::{CutbackInfo, DynamicAnalysis, Observer, Step};
use unfold::model::input::ModelInput;
use unfold::model::Model;

/// The analysis's cut-backs (the state is read between steps): how many,
/// and the first few with their reason.
#[derive(Default)]
struct Cutbacks {
    first: Vec<String>,
}

impl Observer for Cutbacks {
    fn cutback(&mut self, info: &CutbackInfo) {
        if self.first.len() < 5 {
            self.first.push(format!(
                "t = {:.6}, h = {:.3e}: {}",
                info.time, info.failed_step, info.reason
            ));
        }
    }
}

struct Args {
    model: PathBuf,
    out: PathBuf,
    node: u64,
    threads: usize,
}

fn parse_args() -> Result<Option<Args>, String> {
    let mut positional = Vec::new();
    let mut threads = 1;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--threads" => {
                let v = args.next().ok_or("--threads needs a value")?;
                threads = v
                    .parse()
                    .map_err(|_| format!("--threads {v}: not a count"))?;
            }
            // `cargo bench` passes `--bench`
            s if s.starts_with("--") => {}
            _ => positional.push(a),
        }
    }
    match positional.as_slice() {
        [] => Ok(None),
        [model, out, node] => Ok(Some(Args {
            model: model.into(),
            out: out.into(),
            node: node
                .parse()
                .map_err(|_| format!("node id {node}: not an id"))?,
            threads,
        })),
        _ => Err("expected MODEL.toml OUT_DIR NODE_ID".into()),
    }
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(Some(a)) => a,
        Ok(None) => {
            println!("usage: peer_dynamics MODEL.toml OUT_DIR NODE_ID [--threads N] (run through bench/peer/run.sh)");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build_global()
    {
        eprintln!("error: thread pool: {e}");
        return ExitCode::from(2);
    }
    match unfold::assembly::on_worker_thread(|| run(&args)) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {}: {e}", args.model.display());
            ExitCode::from(2)
        }
    }
}

/// Runs the model's dynamic analysis; `Ok(false)` when it stopped early.
fn run(args: &Args) -> Result<bool, String> {
    let text = std::fs::read_to_string(&args.model).map_err(|e| e.to_string())?;
    let input: ModelInput = toml::from_str(&text).map_err(|e| e.to_string())?;
    let model = Model::from_input(&input).map_err(|e| e.to_string())?;
    let analyses = input.analyses().map_err(|e| e.to_string())?;
    let settings = match analyses.as_slice() {
        [a] => a
            .as_dynamic()
            .ok_or("the analysis is not a dynamic one")?
            .clone(),
        _ => return Err("expected one [analysis]".into()),
    };
    let node = model
        .node_index(args.node)
        .ok_or(format!("no node {}", args.node))?;
    let model = Arc::new(model);

    let mut analysis = DynamicAnalysis::new(model.clone(), settings);
    let mut observer = Cutbacks::default();
    // time, position, T + V, energy balance error at the output steps
    let mut rows: Vec<(f64, [f64; 3], f64, f64)> = Vec::new();
    let mut step = analysis.start(model.initial_state(), &mut observer);
    while let Step::Increment(info) = &step {
        if info.output {
            if let (Some(s), Some(e)) = (analysis.state(), analysis.energies()) {
                let x = s.x[node];
                rows.push((s.time, [x.x, x.y, x.z], e.total(), e.balance_error));
            }
        }
        step = analysis.advance(&mut observer);
    }
    let outcome = analysis.finish();

    let mut csv = String::from("time,node,x,y,z,energy,balance_error\n");
    for (t, x, e, b) in &rows {
        let _ = writeln!(
            csv,
            "{t:.12e},{},{:.15e},{:.15e},{:.15e},{e:.15e},{b:.6e}",
            args.node, x[0], x[1], x[2]
        );
    }
    std::fs::create_dir_all(&args.out).map_err(|e| e.to_string())?;
    std::fs::write(args.out.join("nodes.csv"), csv).map_err(|e| e.to_string())?;
    let summary = serde_json::json!({
        "wall_time_s": outcome.wall_time,
        "increments": outcome.steps,
        "iterations": outcome.iterations,
        "cutbacks": outcome.cutbacks,
        "rejected_steps": outcome.rejected_steps,
        "first_cutbacks": observer.first,
        "time": outcome.time,
        "error": outcome.error.as_ref().map(|e| e.to_string()),
    });
    std::fs::write(
        args.out.join("summary.json"),
        serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())?,
    )
    .map_err(|e| e.to_string())?;
    let finished = outcome.error.is_none();
    if let Some(e) = &outcome.error {
        eprintln!("error: {e}");
    }
    Ok(finished)
}
