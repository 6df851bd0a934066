//! `unfold`: command-line front end.
//!
//! ```text
//! unfold run MODEL.toml [--out DIR] [--quiet] [--threads N] [--vtk-ascii]
//! unfold check MODEL.toml
//! ```
//! A model file with a sequence of analyses (`[[analysis]]`) runs them in
//! order, each from the final state of the one before, into one set of
//! result files.
//! Exit codes: 0 success; 1 the analysis stopped before its end (results
//! written so far are kept) or results could not be written (each error
//! names its file; the output directory in use by another run); 2 the
//! command line or the model file is invalid, including a model whose
//! tangent is singular from the start (a mechanism or an unrestrained
//! structure); 128 + the signal number (130 SIGINT, 143 SIGTERM, 129
//! SIGHUP) the run was interrupted, with consistent results up to the last
//! converged increment and `summary.json` saying `interrupted`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use unfold::analysis::preflight;
use unfold::analysis::statics::StaticError;
use unfold::analysis::{
    AnalysisSettings, IncrementInfo, NewtonFailure, StaticAnalysis, StaticSettings,
};
use unfold::io::model_file::read_model;
use unfold::io::run::{
    format_time, signal_name, stop_on_signals, Console, Recorder, SignalEvent, StopRequest,
};
use unfold::io::vtk::Encoding;
use unfold::model::Model;

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
        /// Write the VTK grids as text instead of compressed binary.
        #[arg(long)]
        vtk_ascii: bool,
    },
    /// Check a model file and print its size, without running it.
    Check {
        /// Model file.
        model: PathBuf,
    },
}

/// Exit code for an analysis that stopped early or unwritable results
/// (an interrupted run exits with 128 + the signal number instead).
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
            vtk_ascii,
        } => {
            if let Some(n) = threads {
                if n == 0 {
                    eprintln!(
                        "error: --threads 0: give at least 1 (or leave it out to use every core)"
                    );
                    return ExitCode::from(EXIT_INPUT);
                }
                let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
                if n > cores {
                    eprintln!("warning: --threads {n}: more threads than the {cores} cores available, which only slows the run down");
                }
                if let Err(e) = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
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
            if out.exists() && !out.is_dir() {
                eprintln!(
                    "error: --out {}: is a file; results are written into a directory (created if missing)",
                    out.display()
                );
                return ExitCode::from(EXIT_INPUT);
            }
            let encoding = if vtk_ascii {
                Encoding::Ascii
            } else {
                Encoding::Binary
            };
            run(&model, &out, quiet, encoding)
        }
    }
}

fn describe(model: &Model) -> String {
    unfold::io::run::describe(model)
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
    let (model, analyses) = match read_model(path) {
        Ok(file) => (file.model, file.analyses),
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    print_warnings(path, &model);
    let Some(settings) = static_settings(path, &analyses) else {
        return ExitCode::from(EXIT_INPUT);
    };
    match preflight::check(&model, &settings[0]) {
        Ok(report) => {
            for w in &report.warnings {
                eprintln!("warning: {}: {w}", path.display());
            }
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

/// The settings of the analyses, all static ones (the analyses this tool
/// runs); `None`, after an error message, if one is of another type.
fn static_settings(path: &Path, plan: &[AnalysisSettings]) -> Option<Vec<StaticSettings>> {
    let settings: Option<Vec<StaticSettings>> =
        plan.iter().map(|a| a.as_static().cloned()).collect();
    if settings.is_none() || plan.is_empty() {
        eprintln!(
            "error: {}: an analysis of this model is not one this version runs",
            path.display()
        );
    }
    settings.filter(|s| !s.is_empty())
}

/// Shows a run in the terminal: log lines (unless quiet) above a progress
/// bar, and the last line.
struct Terminal {
    bar: ProgressBar,
    quiet: bool,
    end_time: f64,
}

impl Console for Terminal {
    fn line(&mut self, text: &str) {
        if self.quiet {
            return;
        }
        // plainly when there is no bar (output not a terminal)
        if self.bar.is_hidden() {
            println!("{text}");
        } else {
            self.bar.println(text);
        }
    }

    fn progress(&mut self, info: &IncrementInfo) {
        self.bar
            .set_position((1000.0 * info.time / self.end_time).round() as u64);
        self.bar.set_message(format!("t = {:.4}", info.time));
    }

    fn finish(&mut self, text: &str) {
        self.bar.finish_and_clear();
        println!("{text}");
    }

    fn warning(&mut self, text: &str) {
        self.bar.suspend(|| eprintln!("warning: {text}"));
    }
}

fn run(path: &Path, out: &Path, quiet: bool, encoding: Encoding) -> ExitCode {
    // from now on SIGINT, SIGTERM and SIGHUP stop the run after the
    // current increment, with consistent result files
    let stop = StopRequest::new();
    let handled = stop_on_signals(&stop, |event| match event {
        SignalEvent::Stopping(s) => eprintln!(
            "\n{}: stopping after the current increment (again to stop at once)",
            signal_name(s)
        ),
        SignalEvent::Ending(s) => eprintln!(
            "\n{}: stopping at once; summary.json is left saying \"running\"",
            signal_name(s)
        ),
    });
    if let Err(e) = handled {
        eprintln!(
            "warning: signals cannot be handled ({e}): an interrupted run will leave no summary"
        );
    }

    let (mut model, plan) = match read_model(path) {
        Ok(file) => (file.model, file.analyses),
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    // the start-of-run checks (those of `check`) for the first analysis,
    // before any result file
    let checked = match plan.first().and_then(|a| a.as_static()) {
        Some(first) => preflight::check(&model, first).map(Some),
        None => Ok(None),
    };
    if let (Ok(Some(report)), Some(m)) = (&checked, Arc::get_mut(&mut model)) {
        m.warnings.extend(report.warnings.iter().cloned());
    }
    print_warnings(path, &model);
    let Some(settings) = static_settings(path, &plan) else {
        return ExitCode::from(EXIT_INPUT);
    };
    let mut analyses = settings
        .into_iter()
        .map(|s| StaticAnalysis::new(model.clone(), s));
    let Some(mut analysis) = analyses.next() else {
        return ExitCode::SUCCESS;
    };
    let label = path.display().to_string();
    if let Err(e) = checked {
        // invalid input: summary.json alone says why
        eprintln!("error: {}: {e}", path.display());
        let rejected = unfold::io::results::write_rejected(
            out,
            &label,
            &model,
            &analysis,
            &plan,
            &e.to_string(),
        );
        if let Err(w) = rejected {
            eprintln!("error: cannot write results: {w}");
        }
        return ExitCode::from(EXIT_INPUT);
    }
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] [{bar:40}] {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let terminal = Terminal {
        bar,
        quiet,
        end_time: plan.last().map_or(1.0, |a| a.end_time()),
    };
    let recorder = Recorder::create_sequence(out, &label, &analysis, &plan, terminal);
    let mut recorder = match recorder {
        Ok(r) => r.with_stop(&stop).with_vtk_encoding(encoding),
        Err(e) => {
            eprintln!("error: cannot write results: {e}");
            return ExitCode::from(EXIT_FAILED);
        }
    };
    // the analyses in order, each from the final state of the one before
    let mut outcome = analysis.run(model.initial_state(), &mut recorder);
    for mut next in analyses {
        if outcome.error.is_some() {
            break;
        }
        recorder.next_analysis(&outcome, &next);
        let start = std::mem::take(&mut outcome.state);
        outcome = next.run(start, &mut recorder);
    }
    let report = recorder.finish(&outcome);

    for e in &report.output_errors {
        eprintln!("error: cannot write results: {e}");
    }
    // what the result files hold: up to the last step written
    let kept = match report.last_output_time {
        Some(t) => format!(
            "results up to t = {} are kept in {}",
            format_time(t),
            out.display()
        ),
        None => format!("no result step was written in {}", out.display()),
    };
    if let Some(i) = report.interrupted {
        eprintln!(
            "{}: {i} at t = {}; {kept}",
            path.display(),
            format_time(outcome.time)
        );
        return ExitCode::from(i.exit_code());
    }
    if let Some(e) = &outcome.error {
        eprintln!("error: {}: {e}", path.display());
        // a model that is singular from the start is invalid input
        if let StaticError::Initial {
            failure: NewtonFailure::Singular { .. },
            ..
        }
        | StaticError::Indeterminate { .. } = e
        {
            return ExitCode::from(EXIT_INPUT);
        }
        eprintln!("note: {kept}");
        return ExitCode::from(EXIT_FAILED);
    }
    if !report.output_errors.is_empty() {
        return ExitCode::from(EXIT_FAILED);
    }
    ExitCode::SUCCESS
}
