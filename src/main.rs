//! `unfold`: command-line front end.
//!
//! ```text
//! unfold run MODEL.toml [--out DIR] [--quiet] [--threads N]
//! unfold check MODEL.toml
//! ```
//! Exit codes: 0 success; 1 the analysis stopped before its end (results
//! written so far are kept) or results could not be written; 2 the command
//! line or the model file is invalid, including a model whose tangent is
//! singular from the start (a mechanism or an unrestrained structure).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use unfold::analysis::preflight;
use unfold::analysis::statics::StaticError;
use unfold::analysis::{
    CutbackInfo, IncrementInfo, IterationInfo, NewtonFailure, Observer, StaticAnalysis,
};
use unfold::elements::ElementKind;
use unfold::io::model_file::read_model;
use unfold::io::results::{ResultWriter, Summary};
use unfold::model::Model;
use unfold::state::State;

// `println!` and `eprintln!` that ignore a failed write instead of
// panicking: the std macros panic when the stream is closed or broken
// (`unfold check m.toml | head -0`, a closed stderr, a full disk). These
// shadow the std macros in the whole file.
macro_rules! println {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}
macro_rules! eprintln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

#[derive(Parser)]
#[command(
    name = "unfold",
    version,
    about = "Finite-element simulation of flexible mechanisms and deployable structures"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the analysis of a model file and write results.
    Run {
        /// Model file (TOML, see docs/model-format.md).
        model: PathBuf,
        /// Output directory (default: results/<model file stem>).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// Do not print a log line per increment.
        #[arg(long, short)]
        quiet: bool,
        /// Worker threads for assembly and factorisation (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Check a model file and print its size, without running it.
    Check {
        /// Model file.
        model: PathBuf,
    },
}

/// Exit code for an analysis that stopped early or unwritable results.
const EXIT_FAILED: u8 = 1;
/// Exit code for invalid input.
const EXIT_INPUT: u8 = 2;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { model } => check(&model),
        Command::Run {
            model,
            out,
            quiet,
            threads,
        } => {
            if let Some(n) = threads {
                if let Err(e) = rayon::ThreadPoolBuilder::new()
                    .num_threads(n.max(1))
                    .build_global()
                {
                    eprintln!("error: --threads: {e}");
                    return ExitCode::from(EXIT_INPUT);
                }
            }
            let out = out.unwrap_or_else(|| {
                let stem = model
                    .file_stem()
                    .map_or("model".into(), |s| s.to_string_lossy().into_owned());
                Path::new("results").join(stem)
            });
            run(&model, &out, quiet)
        }
    }
}

fn describe(model: &Model) -> String {
    let count = |k: ElementKind| model.elements.iter().filter(|e| e.kind() == k).count();
    format!(
        "{} nodes, {} beams, {} rigid bodies, {} point masses, {} springs, {} joints, {} joint springs, {} drivers, {} loads",
        model.n_nodes(),
        count(ElementKind::Beam),
        count(ElementKind::RigidBody),
        count(ElementKind::PointMass),
        count(ElementKind::Spring),
        count(ElementKind::Joint),
        count(ElementKind::JointSpring),
        count(ElementKind::Driver),
        count(ElementKind::NodalLoad),
    )
}

/// Prints the model's warnings to stderr.
fn print_warnings(path: &Path, model: &Model) {
    for w in &model.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
}

/// Validates a model file and runs every check that needs no analysis
/// (analysis::preflight): exit code 2, with the message a run would give,
/// when one fails.
fn check(path: &Path) -> ExitCode {
    let model = match read_model(path) {
        Ok((_, model)) => model,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    print_warnings(path, &model);
    match preflight::check(&model) {
        Ok(report) => {
            println!(
                "{}: valid model: {}; {} unknowns",
                path.display(),
                describe(&model),
                report.unknowns
            );
            for line in model.load_history() {
                println!("load history: {line}");
            }
            if report.redundant_constraints > 0 {
                println!(
                    "note: {} redundant constraint equation(s) will be removed (over-constrained loops)",
                    report.redundant_constraints
                );
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            ExitCode::from(EXIT_INPUT)
        }
    }
}

/// Turns analysis events into result files, log lines and a progress bar.
struct RunObserver {
    writer: ResultWriter,
    log: BufWriter<File>,
    bar: ProgressBar,
    quiet: bool,
    end_time: f64,
}

impl RunObserver {
    /// Writes a line to `log.txt` and, unless quiet, to the terminal.
    fn line(&mut self, text: &str) {
        let _ = writeln!(self.log, "{text}");
        if !self.quiet {
            self.print(text);
        }
    }

    /// Prints above the progress bar, or plainly when there is no bar
    /// (output not a terminal).
    fn print(&self, text: &str) {
        if self.bar.is_hidden() {
            println!("{text}");
        } else {
            self.bar.println(text);
        }
    }
}

impl Observer for RunObserver {
    fn iteration(&mut self, info: &IterationInfo) {
        let n = &info.norms;
        let _ = writeln!(
            self.log,
            "    increment {} iteration {}: |r_F| {:.3e} (flux {:.3e})  |r_M| {:.3e} (flux {:.3e})  relative {:.3e}  max|c| {:.3e}  max|dx| {:.3e}  max|dθ| {:.3e}",
            info.increment,
            info.iteration,
            n.residual_force,
            n.flux_force,
            n.residual_moment,
            n.flux_moment,
            n.relative_residual,
            n.residual_constraint,
            n.displacement_correction,
            n.rotation_correction
        );
    }

    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        reactions: &[f64],
    ) -> std::io::Result<()> {
        let residuals: Vec<String> = info.residuals.iter().map(|r| format!("{r:.1e}")).collect();
        self.line(&format!(
            "increment {:4}  t = {:.6}  dt = {:.3e}  iterations {:2}  relative residuals: {}",
            info.increment,
            info.time,
            info.step,
            info.iterations,
            residuals.join(" ")
        ));
        self.bar
            .set_position((1000.0 * info.time / self.end_time).round() as u64);
        self.bar.set_message(format!("t = {:.4}", info.time));
        self.writer.increment(info, model, state, reactions)
    }

    fn note(&mut self, text: &str) {
        self.line(&format!("note: {text}"));
    }

    fn cutback(&mut self, info: &CutbackInfo) {
        self.line(&format!(
            "increment {:4}  from t = {:.6}: step {:.3e} failed ({}); retrying with {:.3e}",
            info.increment, info.time, info.failed_step, info.reason, info.next_step
        ));
    }
}

fn run(path: &Path, out: &Path, quiet: bool) -> ExitCode {
    let (_, model) = match read_model(path) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    print_warnings(path, &model);
    let writer = match ResultWriter::create(out, &model) {
        Ok(w) => w,
        Err(e) => {
            eprintln!("error: {}: cannot create result files: {e}", out.display());
            return ExitCode::from(EXIT_FAILED);
        }
    };
    let log = match File::create(out.join("log.txt")) {
        Ok(f) => BufWriter::new(f),
        Err(e) => {
            eprintln!("error: {}: {e}", out.join("log.txt").display());
            return ExitCode::from(EXIT_FAILED);
        }
    };
    let mut analysis = StaticAnalysis::new(&model);
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] [{bar:40}] {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let mut observer = RunObserver {
        writer,
        log,
        bar,
        quiet,
        end_time: model.settings.end_time,
    };
    observer.line(&format!(
        "{}: {}; {} unknowns; {} analysis to t = {}",
        path.display(),
        describe(&model),
        analysis.n_equations(),
        if model.settings.kinematic {
            "kinematic"
        } else {
            "static"
        },
        model.settings.end_time
    ));
    for w in &model.warnings {
        let _ = writeln!(observer.log, "warning: {w}");
    }
    for line in model.load_history() {
        observer.line(&format!("load history: {line}"));
    }
    let outcome = analysis.run(&mut observer);
    observer.bar.finish_and_clear();

    let ok = outcome.error.is_none();
    let message = outcome.error.as_ref().map(|e| e.to_string());
    let summary = Summary {
        model: path.display().to_string(),
        title: model.title.clone(),
        status: if ok { "completed" } else { "failed" }.into(),
        message: message.clone(),
        nodes: model.n_nodes(),
        elements: model
            .elements
            .iter()
            .filter(|e| e.kind() != ElementKind::NodalLoad)
            .count(),
        beams: model
            .elements
            .iter()
            .filter(|e| e.kind() == ElementKind::Beam)
            .count(),
        joints: model
            .elements
            .iter()
            .filter(|e| e.kind() == ElementKind::Joint)
            .count(),
        drivers: model
            .elements
            .iter()
            .filter(|e| e.kind() == ElementKind::Driver)
            .count(),
        redundant_constraints: outcome.redundant_constraints,
        dofs: analysis.n_equations(),
        nonzeros: analysis.solver().nnz(),
        increments: outcome.increments,
        iterations: outcome.iterations,
        average_iterations: if outcome.increments > 0 {
            (outcome.iterations - observer.writer.log.first().map_or(0, |r| r.iterations)) as f64
                / outcome.increments as f64
        } else {
            0.0
        },
        wasted_iterations: outcome.wasted_iterations,
        cutbacks: outcome.cutbacks,
        final_time: outcome.time,
        end_time: model.settings.end_time,
        wall_time_s: outcome.wall_time,
        output_steps: observer.writer.output_steps(),
        increment_log: observer.writer.log.clone(),
    };
    let summary_written = observer.writer.write_summary(&summary);
    let tail = format!(
        "{}: {} increments, {} iterations ({:.2} per increment), {} cut-backs, t = {}, {:.3} s; results in {}",
        summary.status,
        summary.increments,
        summary.iterations,
        summary.average_iterations,
        summary.cutbacks,
        summary.final_time,
        summary.wall_time_s,
        out.display()
    );
    let _ = writeln!(observer.log, "{tail}");
    let _ = observer.log.flush();
    println!("{tail}");
    if let Some(m) = message {
        eprintln!("error: {}: {m}", path.display());
        // a model that is singular from the start is invalid input
        if let Some(
            StaticError::Initial(NewtonFailure::Singular { .. })
            | StaticError::Indeterminate { .. },
        ) = outcome.error
        {
            return ExitCode::from(EXIT_INPUT);
        }
        eprintln!(
            "note: results up to t = {:.6} are kept in {}",
            outcome.time,
            out.display()
        );
        return ExitCode::from(EXIT_FAILED);
    }
    if let Err(e) = summary_written {
        eprintln!("error: {}: cannot write summary.json: {e}", out.display());
        return ExitCode::from(EXIT_FAILED);
    }
    ExitCode::SUCCESS
}
