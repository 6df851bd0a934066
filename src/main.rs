//! `unfold`: command-line front end.
//!
//! ```text
//! unfold run MODEL.toml [--out DIR] [--quiet | --verbose] [--threads N] [--vtk-ascii] [--restart FILE]
//! unfold check MODEL.toml [--threads N]
//! unfold plot RESULTS_DIR [joints|moments|energies|hinge_laws ...] [--joint ID ...] [--format png|svg|both]
//!             [--out DIR] [--degrees] [--units si|model] [--model MODEL.toml]
//! unfold view RESULTS_DIR [--out FILE] [--open | --no-open] [--histories FILES] [--max-frames N]
//! ```
//! `unfold view` writes one self-contained HTML page that animates the run
//! in 3-D in a web browser (docs/viewer.md), and opens it when asked or
//! when run in a terminal on a display.
//! `unfold plot` draws the time histories of a run from its result files
//! (docs/plots.md): joint coordinates with the lock instants, moments
//! along the joint coordinates, energies and the energy balance error.
//! A model file with a sequence of analyses (`[[analysis]]`) runs them in
//! order, each from the final state of the one before, into one set of
//! result files. A modal analysis (`type = "modal"`) linearises about the
//! state it is given and leaves it unchanged; its first frequencies are
//! printed on stderr. A dynamic analysis (`type = "dynamic"`) integrates
//! the motion from the state it is given (with the velocities it has) and
//! adds velocities and energies to the results; its last line gives its
//! steps and its energy balance error. A static analysis after a dynamic
//! one seeks an equilibrium at rest: it starts with zero velocities. Every run writes `restart.json` (the state at its
//! last converged step) into its output directory; `--restart FILE`
//! continues a run from such a file (docs/results.md, "Restart files").
//! Exit codes: 0 success; 1 the analysis stopped before its end (results
//! written so far are kept) or results could not be written (each error
//! names its file; the output directory in use by another run); 2 the
//! command line or the model file is invalid, including a model whose
//! tangent is singular from the start (a mechanism or an unrestrained
//! structure), a modal analysis of a model without mass and initial
//! velocities that the joints do not allow; 128 + the signal number (130 SIGINT, 143 SIGTERM, 129
//! SIGHUP) the run was interrupted, with consistent results up to the last
//! converged increment and `summary.json` saying `interrupted`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use unfold::analysis::preflight;
use unfold::analysis::statics::StaticError;
use unfold::analysis::{
    AnalysisSettings, DynamicAnalysis, DynamicError, DynamicSettings, IncrementInfo, ModalAnalysis,
    ModalError, ModalOutcome, ModalSettings, NewtonFailure, StaticAnalysis,
};
use unfold::assembly::on_worker_thread;
use unfold::io::histories::{Format, Group, Histories, HistoryError, Request, UnitLabels};
use unfold::io::model_file::read_model;
use unfold::io::restart::{fingerprint, Restart, RestartError, RestartWriter, Resume};
use unfold::io::results::{AnalysisEnd, Summary};
use unfold::io::run::{
    dynamic_error_message, format_time, signal_name, stop_on_signals, Console, Recorder,
    SignalEvent, StopRequest,
};
use unfold::io::vtk::Encoding;
use unfold::model::input::{ModelInput, OutputInput};
use unfold::model::{overlaps, Model};

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
        /// Print every increment's line even when the output is not a
        /// terminal (by default a redirected run prints a progress line
        /// every 10 s instead; log.txt has every line either way).
        #[arg(long, short, conflicts_with = "quiet")]
        verbose: bool,
        /// Worker threads for assembly and factorisation (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Write the VTK grids as text instead of compressed binary.
        #[arg(long)]
        vtk_ascii: bool,
        /// Continue from a restart file of an earlier run of this model
        /// (its `restart.json`, or a `restart-<t>.json`).
        #[arg(long, value_name = "FILE")]
        restart: Option<PathBuf>,
    },
    /// Check a model file and print its size, without running it.
    Check {
        /// Model file.
        model: PathBuf,
        /// Worker threads for the factorisation of the checks (default:
        /// every core), as for `run`.
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Draw the time histories of a run from its result files: joint
    /// coordinates, moments along them, energies (docs/plots.md).
    Plot {
        /// Results directory of a run (`unfold run MODEL --out DIR`).
        results: PathBuf,
        /// Charts to draw: `joints`, `moments`, `energies`, `hinge_laws`
        /// (default: every one the results allow).
        #[arg(value_name = "WHAT")]
        what: Vec<String>,
        /// Only the joint and moment charts of this joint (repeatable).
        #[arg(long = "joint", value_name = "ID")]
        joints: Vec<u64>,
        /// File format of the charts.
        #[arg(long, value_enum, default_value = "both")]
        format: PlotFormat,
        /// Directory for the charts (default: RESULTS/plots).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// Angles in degrees (the result files give radians).
        #[arg(long)]
        degrees: bool,
        /// Unit names on the axes: `si` (s, m, N, N·m, J) or `model`
        /// (named by dimension, for a model in other units).
        #[arg(long, value_enum, default_value = "si")]
        units: PlotUnits,
        /// The model file, which says which joint coordinate each spring,
        /// hinge law, latch and driver acts on (default: the one named in
        /// summary.json).
        #[arg(long, value_name = "FILE")]
        model: Option<PathBuf>,
    },
    /// Write one HTML page that animates the run in 3-D in a web browser,
    /// with a time line, its events and a time-history plot
    /// (docs/viewer.md); it works offline.
    View {
        /// Results directory of a run (`unfold run MODEL --out DIR`).
        results: PathBuf,
        /// The page to write (default: RESULTS/view.html).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// Open the page in a web browser (by default it is opened when the
        /// command runs in a terminal on a display).
        #[arg(long, conflicts_with = "no_open")]
        open: bool,
        /// Do not open the page.
        #[arg(long)]
        no_open: bool,
        /// The history files to embed for the plot, comma-separated
        /// (`joints,energies`; `all` for every CSV file; default: every one
        /// but nodes, nodes_velocities and beams).
        #[arg(long, value_delimiter = ',', value_name = "FILES")]
        histories: Vec<String>,
        /// At most this many frames (evenly spaced output steps, and the
        /// steps of the events).
        #[arg(long, default_value_t = unfold::io::view::MAX_FRAMES, value_name = "N")]
        max_frames: usize,
    },
}

/// `--format` of `unfold plot`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum PlotFormat {
    Png,
    Svg,
    Both,
}

/// `--units` of `unfold plot`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum PlotUnits {
    Si,
    Model,
}

/// Exit code for an analysis that stopped early or unwritable results
/// (an interrupted run exits with 128 + the signal number instead).
const EXIT_FAILED: u8 = 1;
/// Exit code for invalid input.
const EXIT_INPUT: u8 = 2;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { model, threads } => match thread_pool(threads) {
            Ok(()) => check(&model),
            Err(code) => code,
        },
        Command::Plot {
            results,
            what,
            joints,
            format,
            out,
            degrees,
            units,
            model,
        } => {
            let format = match format {
                PlotFormat::Png => Format::Png,
                PlotFormat::Svg => Format::Svg,
                PlotFormat::Both => Format::Both,
            };
            let units = match units {
                PlotUnits::Si => UnitLabels::Si,
                PlotUnits::Model => UnitLabels::Model,
            };
            let mut groups = Vec::new();
            for w in &what {
                match Group::from_name(w) {
                    Some(g) => groups.push(g),
                    None => {
                        eprintln!("error: {w:?}: not a kind of chart; give {}", Group::NAMES);
                        return ExitCode::from(EXIT_INPUT);
                    }
                }
            }
            let request = Request {
                groups,
                joints,
                degrees,
                units,
            };
            let out = out.unwrap_or_else(|| results.join("plots"));
            plot(&results, model.as_deref(), &request, &out, format)
        }
        Command::View {
            results,
            out,
            open,
            no_open,
            histories,
            max_frames,
        } => {
            let options = unfold::io::view::ViewOptions {
                histories,
                max_frames,
            };
            let open = if open {
                Some(true)
            } else if no_open {
                Some(false)
            } else {
                None
            };
            view(&results, out, open, &options)
        }
        Command::Run {
            model,
            out,
            quiet,
            verbose,
            threads,
            vtk_ascii,
            restart,
        } => {
            if let Err(code) = thread_pool(threads) {
                return code;
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
            // a restart into the directory of the run it continues would
            // replace that run's histories (steps.csv, events.csv, …) with
            // those from the restart's t on
            if let Some(r) = restart.as_deref() {
                if restart_in_output(r, &out) {
                    let stem = out
                        .file_name()
                        .map_or("results".into(), |s| s.to_string_lossy().into_owned());
                    eprintln!(
                        "error: --restart {}: the restart file is in the output directory {}, whose results this run would replace; give the continued run a directory of its own, e.g. --out {}",
                        r.display(),
                        out.display(),
                        out.with_file_name(format!("{stem}-continued")).display()
                    );
                    return ExitCode::from(EXIT_INPUT);
                }
            }
            let encoding = if vtk_ascii {
                Encoding::Ascii
            } else {
                Encoding::Binary
            };
            // on a worker of the thread pool (unfold::assembly::on_worker_thread)
            let echo = Echo { quiet, verbose };
            on_worker_thread(|| run(&model, &out, echo, encoding, restart.as_deref()))
        }
    }
}

/// The global thread pool with `threads` workers (`--threads`; rayon's
/// default, one per core, when not given).
fn thread_pool(threads: Option<usize>) -> Result<(), ExitCode> {
    let Some(n) = threads else {
        return Ok(());
    };
    if n == 0 {
        eprintln!("error: --threads 0: give at least 1 (or leave it out to use every core)");
        return Err(ExitCode::from(EXIT_INPUT));
    }
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    if n > cores {
        eprintln!("warning: --threads {n}: more threads than the {cores} cores available, which only slows the run down");
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build_global()
        .map_err(|e| {
            eprintln!("error: --threads: {e}");
            ExitCode::from(EXIT_INPUT)
        })
}

/// Whether the restart file `restart` lies in the output directory `out`
/// (compared as canonical paths; an output directory that does not exist
/// yet holds nothing).
fn restart_in_output(restart: &Path, out: &Path) -> bool {
    let (Ok(file), Ok(dir)) = (restart.canonicalize(), out.canonicalize()) else {
        return false;
    };
    file.parent() == Some(dir.as_path())
}

/// `unfold plot`: draws the charts of `request` from the results in
/// `dir` into `out`, one line per file written; exit code 2 for results
/// that cannot be read or do not have what is asked, 1 if a chart cannot
/// be written.
fn plot(
    dir: &Path,
    model: Option<&Path>,
    request: &Request,
    out: &Path,
    format: Format,
) -> ExitCode {
    // a model file named on the command line must be there: the charts
    // would otherwise mix angles and lengths without a word
    if let Some(m) = model {
        let parsed = std::fs::read_to_string(m)
            .map_err(|e| e.to_string())
            .and_then(|text| {
                unfold::io::model_file::parse_model(&text, m)
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            });
        if let Err(e) = parsed {
            eprintln!(
                "error: --model {}: cannot read the model file: {e}",
                m.display()
            );
            return ExitCode::from(EXIT_INPUT);
        }
    }
    let drawn = Histories::read(dir, model).and_then(|h| {
        for note in h.notes() {
            eprintln!("note: {note}");
        }
        let figures = h.figures(request)?;
        Histories::write(&figures, out, format)
    });
    match drawn {
        Ok(files) => {
            for f in files {
                println!("{}", f.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            let code = match e {
                HistoryError::Write { .. } | HistoryError::Plot(_) => EXIT_FAILED,
                _ => EXIT_INPUT,
            };
            ExitCode::from(code)
        }
    }
}

/// `unfold view`: writes the page of the results in `dir` to `out`
/// (default `dir/view.html`) and opens it if `open` says so (by default
/// when run in a terminal on a display); exit code 2 for results that
/// cannot be read, 1 if the page cannot be written.
fn view(
    dir: &Path,
    out: Option<PathBuf>,
    open: Option<bool>,
    options: &unfold::io::view::ViewOptions,
) -> ExitCode {
    if options.max_frames < 2 {
        eprintln!(
            "error: --max-frames {}: give at least 2 (the first and the last step)",
            options.max_frames
        );
        return ExitCode::from(EXIT_INPUT);
    }
    let out = out.unwrap_or_else(|| dir.join("view.html"));
    if out.is_dir() {
        eprintln!(
            "error: --out {}: is a directory; give the file of the page (e.g. {})",
            out.display(),
            out.join("view.html").display()
        );
        return ExitCode::from(EXIT_INPUT);
    }
    let start = std::time::Instant::now();
    let report = match unfold::io::view::write_view(dir, &out, options) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(if e.is_input() {
                EXIT_INPUT
            } else {
                EXIT_FAILED
            });
        }
    };
    for note in &report.notes {
        eprintln!("note: {note}");
    }
    println!(
        "{}: {} frames of {} output steps, {} points, {} cells, {} colour fields, {} history series, {} events; {:.2} MB, written in {:.2} s",
        out.display(),
        report.frames,
        report.steps,
        report.points,
        report.cells,
        report.fields.len(),
        report.series,
        report.events,
        report.bytes as f64 / 1e6,
        start.elapsed().as_secs_f64()
    );
    let open = open.unwrap_or_else(|| {
        use std::io::IsTerminal as _;
        std::io::stdout().is_terminal() && has_display()
    });
    if open {
        match open_in_browser(&out) {
            Ok(how) => eprintln!("opened with {how}"),
            Err(e) => eprintln!("note: {e}; open {} in a web browser", out.display()),
        }
    }
    ExitCode::SUCCESS
}

/// Whether pages can be shown: a graphical session (X11 or Wayland on
/// Linux and the like; always on macOS and Windows).
fn has_display() -> bool {
    if cfg!(any(target_os = "macos", target_os = "windows")) {
        return true;
    }
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()))
}

/// Opens `page` in the web browser (`$BROWSER`, else `xdg-open`, `open` on
/// macOS, `start` on Windows), without waiting for it; the command used.
fn open_in_browser(page: &Path) -> Result<String, String> {
    let mut command = if let Some(b) = std::env::var_os("BROWSER").filter(|b| !b.is_empty()) {
        std::process::Command::new(b)
    } else if cfg!(target_os = "macos") {
        std::process::Command::new("open")
    } else if cfg!(target_os = "windows") {
        let mut c = std::process::Command::new("cmd");
        c.args(["/C", "start", ""]);
        c
    } else {
        std::process::Command::new("xdg-open")
    };
    let how = format!("{:?}", command.get_program());
    command
        .arg(page)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .map(|_| how.clone())
        .map_err(|e| format!("no web browser could be started ({how}: {e})"))
}

fn describe(model: &Model) -> String {
    unfold::io::run::describe(model)
}

/// Prints the model's warnings and notes to stderr.
fn print_warnings(path: &Path, model: &Model) {
    for w in &model.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    for n in &model.notes {
        eprintln!("note: {}: {n}", path.display());
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
    if !supported(path, &analyses) {
        return ExitCode::from(EXIT_INPUT);
    }
    if analyses.iter().any(|a| a.as_modal().is_some()) && !ModalAnalysis::has_mass(&model) {
        eprintln!(
            "error: {}: modal analysis: {}",
            path.display(),
            ModalError::NoMass
        );
        return ExitCode::from(EXIT_INPUT);
    }
    // a run that starts with a motion: the start of its dynamic analysis
    if let Some(settings) = first_motion(&analyses) {
        if let Err(e) = preflight::check_motion(&model, settings) {
            eprintln!(
                "error: {}: dynamic analysis at t = 0: {}",
                path.display(),
                dynamic_error_message(&model, &model.initial_state(), &e)
            );
            return ExitCode::from(dynamic_exit_code(&e));
        }
    }
    let Some(first_static) = analyses.iter().find_map(|a| a.as_static()) else {
        // modal and dynamic analyses only: no equilibrium to check
        println!(
            "{}: valid model: {}; {} unknowns",
            path.display(),
            describe(&model),
            ModalAnalysis::new(model.clone(), ModalSettings::lowest(1)).n_equations()
        );
        if analyses.iter().any(|a| a.as_dynamic().is_some()) {
            for line in model.load_history() {
                println!("load history: {line}");
            }
        }
        print_plan(&analyses);
        return ExitCode::SUCCESS;
    };
    match preflight::check(&model, first_static) {
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
                    "note: {} redundant constraint equation(s) will be removed (over-constrained: joints, supports or drivers that repeat one another)",
                    report.redundant_constraints
                );
            }
            print_plan(&analyses);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            ExitCode::from(EXIT_INPUT)
        }
    }
}

/// Whether every analysis of `plan` is one this tool runs (static,
/// kinematic, dynamic, modal); if not, after an error message.
fn supported(path: &Path, plan: &[AnalysisSettings]) -> bool {
    let all = !plan.is_empty()
        && plan
            .iter()
            .all(|a| a.as_static().is_some() || a.as_modal().is_some() || a.as_dynamic().is_some());
    if !all {
        eprintln!(
            "error: {}: an analysis of this model is not one this version runs",
            path.display()
        );
    }
    all
}

/// The dynamic analysis that a run of `plan` starts with, modal analyses
/// before it aside (they leave the state as it is): its start, from the
/// model's initial state and velocities, needs no analysis before it.
fn first_motion(plan: &[AnalysisSettings]) -> Option<&DynamicSettings> {
    plan.iter().find(|a| a.as_modal().is_none())?.as_dynamic()
}

/// The exit code of a run whose dynamic analysis stopped with `error`:
/// initial velocities that the constraints forbid, or a model without
/// mass or stiffness somewhere (a singular matrix of the initial
/// accelerations), are invalid input.
fn dynamic_exit_code(error: &DynamicError) -> u8 {
    match error {
        DynamicError::InconsistentVelocity { .. }
        | DynamicError::NoMass
        | DynamicError::StartsBeyondLimit { .. }
        | DynamicError::Initial {
            failure: NewtonFailure::Singular { .. },
            ..
        } => EXIT_INPUT,
        _ => EXIT_FAILED,
    }
}

/// One line per modal and dynamic analysis of `plan`, for `unfold check`.
fn print_plan(plan: &[AnalysisSettings]) {
    for (k, a) in plan.iter().enumerate() {
        if let Some(d) = a.as_dynamic() {
            println!(
                "analysis {}: dynamic to t = {}: time step {} ({}), min_step {}, max_step {}, rho_infinity {}; {}",
                k + 1,
                format_time(d.end_time),
                format_time(d.time_step),
                if d.adaptive {
                    format!("adaptive, error tolerance {}", d.error_tolerance)
                } else {
                    "fixed".to_string()
                },
                format_time(d.min_step),
                format_time(d.max_step),
                d.rho_infinity,
                output_plan(d)
            );
        }
        if let Some(m) = a.as_modal() {
            let mut what = format!("{} modes", m.modes);
            if let Some(f) = m.shift {
                what += &format!(" nearest {f} Hz");
            }
            if let Some((lo, hi)) = m.frequency_range {
                what += &format!(" in [{lo}, {hi}] Hz");
            }
            println!(
                "analysis {}: modal at t = {}: {what}, solver {}",
                k + 1,
                m.time,
                unfold::io::modes::solver_name(m.solver)
            );
        }
    }
}

/// When a dynamic analysis writes its results, for `unfold check`.
fn output_plan(d: &DynamicSettings) -> String {
    match d.output_interval {
        Some(dt) => format!(
            "output every {} ({} times, with output_times and the end)",
            format_time(dt),
            d.output_times.iter().filter(|&&t| t < d.end_time).count() + 1
        ),
        None => {
            let every = match d.output_every {
                1 => "output every step".to_string(),
                n => format!("output every {n} steps"),
            };
            if d.output_times.is_empty() {
                every
            } else {
                format!("{every} and at {} output_times", d.output_times.len())
            }
        }
    }
}

/// Prints the first frequencies of a modal analysis on stderr.
fn print_modes(outcome: &ModalOutcome) {
    const SHOWN: usize = 10;
    eprintln!(
        "modal analysis at t = {}: {} modes ({} rigid-body or mechanism), {} unknowns, {:.3} s",
        outcome.time,
        outcome.modes.len(),
        outcome.zero_modes,
        outcome.unknowns,
        outcome.wall_time
    );
    for (k, m) in outcome.modes.iter().take(SHOWN).enumerate() {
        eprintln!(
            "  mode {:3}  {:>14.6e} Hz  {:>14.6e} rad/s{}",
            k + 1,
            m.frequency,
            m.angular_frequency,
            if m.is_zero() { "  (zero mode)" } else { "" }
        );
    }
    if outcome.modes.len() > SHOWN {
        eprintln!("  ... {} more in modes.csv", outcome.modes.len() - SHOWN);
    }
}

/// An analysis of the plan, ready to run.
enum Planned {
    Static(Box<StaticAnalysis>),
    Dynamic(Box<DynamicAnalysis>),
    Modal(Box<ModalAnalysis>),
}

/// Shows a run in the terminal: log lines (unless quiet) above a progress
/// bar, and the last line.
struct Terminal {
    bar: ProgressBar,
    echo: Echo,
    end_time: f64,
    /// When the run started and when the last progress line was printed
    /// (output not a terminal).
    started: Instant,
    last_progress: Instant,
}

/// Which lines a run prints (`--quiet`, `--verbose`).
#[derive(Clone, Copy, Debug)]
struct Echo {
    quiet: bool,
    verbose: bool,
}

/// Between two progress lines of a run whose output is not a terminal.
const PROGRESS_INTERVAL: Duration = Duration::from_secs(10);

/// Whether `text` is the line of one converged increment or step
/// (`step 12  t = … iterations …`), which a redirected run leaves to
/// log.txt unless `--verbose`.
fn is_increment_line(text: &str) -> bool {
    let mut words = text.split_whitespace();
    matches!(words.next(), Some("step" | "increment"))
        && words.next().is_some_and(|n| n.parse::<usize>().is_ok())
        && text.contains(" iterations ")
}

impl Console for Terminal {
    fn line(&mut self, text: &str) {
        if self.echo.quiet {
            return;
        }
        // plainly when there is no bar (output not a terminal), without
        // the increments' lines unless asked
        if self.bar.is_hidden() {
            if self.echo.verbose || !is_increment_line(text) {
                println!("{text}");
            }
        } else {
            self.bar.println(text);
        }
    }

    fn progress(&mut self, info: &IncrementInfo) {
        // output not a terminal: a line every PROGRESS_INTERVAL
        if self.bar.is_hidden() {
            if !self.echo.quiet
                && !self.echo.verbose
                && self.last_progress.elapsed() >= PROGRESS_INTERVAL
            {
                self.last_progress = Instant::now();
                println!(
                    "progress: t = {:.6} of {} ({:.0} %), increment {}, {:.0} s",
                    info.time,
                    format_time(self.end_time),
                    100.0 * info.time / self.end_time,
                    info.increment,
                    self.started.elapsed().as_secs_f64()
                );
            }
            return;
        }
        self.bar
            .set_position((1000.0 * info.time / self.end_time).round() as u64);
        self.bar.set_message(format!(
            "t = {:.4} / {}",
            info.time,
            format_time(self.end_time)
        ));
    }

    fn finish(&mut self, text: &str) {
        self.bar.finish_and_clear();
        println!("{text}");
    }

    fn warning(&mut self, text: &str) {
        self.bar.suspend(|| eprintln!("warning: {text}"));
    }

    fn note(&mut self, text: &str) {
        if self.bar.is_hidden() {
            println!("{text}");
        } else {
            self.bar.println(text);
        }
    }
}

fn run(
    path: &Path,
    out: &Path,
    echo: Echo,
    encoding: Encoding,
    restart: Option<&Path>,
) -> ExitCode {
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

    let (input, mut model, plan) = match read_model(path) {
        Ok(file) => (file.input, file.model, file.analyses),
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
    if !supported(path, &plan) {
        return ExitCode::from(EXIT_INPUT);
    }
    let label = path.display().to_string();
    if let (Err(e), Some(first)) = (&checked, plan.first().and_then(|a| a.as_static())) {
        // invalid input: summary.json alone says why
        eprintln!("error: {}: {e}", path.display());
        let analysis = StaticAnalysis::new(model.clone(), first.clone());
        let rejected = unfold::io::results::write_rejected(
            out,
            Summary::start(&label, &model, &analysis, &plan),
            &e.to_string(),
            restart,
        );
        if let Err(w) = rejected {
            eprintln!("error: cannot write results: {w}");
        }
        return ExitCode::from(EXIT_INPUT);
    }
    // a run that starts with a motion: the checks of its start (those of
    // `check`), before any result file; a restart continues a run that
    // passed them
    if let (None, Some(settings)) = (restart, first_motion(&plan)) {
        if let Err(e) = preflight::check_motion(&model, settings) {
            if dynamic_exit_code(&e) == EXIT_INPUT {
                // invalid input: summary.json alone says why
                let message = format!(
                    "dynamic analysis at t = 0: {}",
                    dynamic_error_message(&model, &model.initial_state(), &e)
                );
                eprintln!("error: {}: {message}", path.display());
                let analysis = DynamicAnalysis::new(model.clone(), settings.clone());
                let end_time = plan.last().map_or(settings.end_time, |a| a.end_time());
                let summary = Summary::start_with(
                    &label,
                    &model,
                    analysis.n_equations(),
                    analysis.nnz(),
                    end_time,
                );
                if let Err(w) = unfold::io::results::write_rejected(out, summary, &message, None) {
                    eprintln!("error: cannot write results: {w}");
                }
                return ExitCode::from(EXIT_INPUT);
            }
        }
    }
    // a restart: the analysis it continues and its start state
    let (first, start, continued) = match restart.map(|r| resume(r, &input, &model, &plan)) {
        None => (0, model.initial_state(), None),
        Some(Ok(resume)) => (
            resume.analysis,
            resume.state,
            resume.continues.then_some(resume.motion),
        ),
        Some(Err(e)) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_INPUT);
        }
    };
    let restarts = RestartWriter::new(out, &input).starting_at(start.time);
    let restart_note = restart.map(|r| {
        format!(
            "restarted from {} at t = {} in analysis {} of {}",
            r.display(),
            format_time(start.time),
            first + 1,
            plan.len()
        )
    });
    // whether a dynamic analysis comes before each analysis of the run
    let after_motion: Vec<bool> = (first..plan.len())
        .map(|k| plan[..k].iter().any(|a| a.as_dynamic().is_some()))
        .collect();
    let plan = &plan[first..];
    let mut analyses = plan.iter().enumerate().filter_map(|(k, a)| {
        if let Some(s) = a.as_static() {
            Some(Planned::Static(Box::new(StaticAnalysis::new(
                model.clone(),
                s.clone(),
            ))))
        } else if let Some(d) = a.as_dynamic() {
            let analysis = DynamicAnalysis::new(model.clone(), d.clone());
            // a restart inside this analysis keeps its velocities and
            // accelerations
            Some(Planned::Dynamic(Box::new(match &continued {
                Some(motion) if k == 0 => analysis.continued(motion.clone()),
                _ => analysis,
            })))
        } else {
            a.as_modal()
                .map(|m| Planned::Modal(Box::new(ModalAnalysis::new(model.clone(), m.clone()))))
        }
    });
    let Some(first_planned) = analyses.next() else {
        return ExitCode::SUCCESS;
    };
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] [{bar:40}] {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let terminal = Terminal {
        bar,
        echo,
        end_time: plan.last().map_or(1.0, |a| a.end_time()),
        started: Instant::now(),
        last_progress: Instant::now(),
    };
    let recorder = match &first_planned {
        Planned::Static(a) => Recorder::create_sequence(out, &label, a, plan, terminal),
        Planned::Dynamic(a) => Recorder::create_dynamic_first(out, &label, a, plan, terminal),
        Planned::Modal(a) => Recorder::create_modal_first(out, &label, a, plan, terminal),
    };
    let mut recorder = match recorder {
        Ok(r) => r
            .with_stop(&stop)
            .with_vtk_encoding(encoding)
            .with_vtk_every(OutputInput::vtk_interval(input.output.as_ref()))
            .with_restart(restarts, first),
        Err(e) => {
            eprintln!("error: cannot write results: {e}");
            return ExitCode::from(EXIT_FAILED);
        }
    };
    if let Some(note) = restart_note {
        recorder.line(&note);
    }
    // the analyses in order, each from the final state of the one before;
    // none after one that failed
    let start_state = start.clone();
    let mut state = start;
    // the last static or dynamic analysis: how it ended, and its error
    let mut last: Option<AnalysisEnd> = None;
    let mut failure: Option<Failure> = None;
    let mut modal_error: Option<ModalError> = None;
    let mut modal_output_error = false;
    for (k, planned) in std::iter::once(first_planned).chain(analyses).enumerate() {
        match planned {
            Planned::Static(mut analysis) => {
                if k > 0 {
                    recorder.open_static(&analysis, state.time);
                }
                // an equilibrium after a motion is at rest: the velocities
                // a later dynamic analysis starts with are zero
                if after_motion[k] {
                    bring_to_rest(&mut state);
                }
                let mut outcome = analysis.run(std::mem::take(&mut state), &mut recorder);
                state = std::mem::take(&mut outcome.state);
                let end = AnalysisEnd::from(&outcome);
                recorder.end_analysis(&end);
                last = Some(end);
                if let Some(e) = outcome.error.take() {
                    failure = Some(Failure::Static(e));
                    break;
                }
            }
            Planned::Dynamic(mut analysis) => {
                if k > 0 {
                    recorder.open_dynamic(&analysis, state.time);
                }
                let mut outcome = analysis.run(std::mem::take(&mut state), &mut recorder);
                state = std::mem::take(&mut outcome.state);
                let end = AnalysisEnd::from(&outcome);
                recorder.end_analysis(&end);
                last = Some(end);
                if let Some(e) = outcome.error.take() {
                    failure = Some(Failure::Dynamic(e));
                    break;
                }
            }
            Planned::Modal(mut analysis) => {
                let mut outcome = analysis.run(std::mem::take(&mut state), &mut recorder);
                if let Err(e) = recorder.record_modal(None, &analysis, &outcome) {
                    eprintln!("error: cannot write results: {e}");
                    modal_output_error = true;
                }
                state = std::mem::take(&mut outcome.state);
                if let Some(e) = outcome.error.take() {
                    eprintln!(
                        "error: {}: modal analysis at t = {}: {e}",
                        path.display(),
                        state.time
                    );
                    modal_error = Some(e);
                    break;
                }
                print_modes(&outcome);
                if modal_output_error {
                    break;
                }
            }
        }
    }
    if failure.is_none() && modal_error.is_none() {
        for w in overlaps::overlap_warnings(&model, &start_state, &state) {
            recorder.outcome_warning(&w);
        }
    }
    let report = recorder.finish_after(last.as_ref(), &state);
    // the charts of `[output] plots`, from the files as they now stand
    let plotted = write_plots(path, out, &input);

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
            format_time(state.time)
        );
        return ExitCode::from(i.exit_code());
    }
    match modal_error {
        Some(ModalError::NoMass) => return ExitCode::from(EXIT_INPUT),
        Some(_) => return ExitCode::from(EXIT_FAILED),
        None => {}
    }
    if modal_output_error {
        return ExitCode::from(EXIT_FAILED);
    }
    match &failure {
        Some(Failure::Static(e)) => {
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
        Some(Failure::Dynamic(e)) => {
            eprintln!(
                "error: {}: dynamic analysis at t = {}: {}",
                path.display(),
                format_time(state.time),
                dynamic_error_message(&model, &state, e)
            );
            let code = dynamic_exit_code(e);
            if code == EXIT_FAILED {
                eprintln!("note: {kept}");
            }
            return ExitCode::from(code);
        }
        None => {}
    }
    if !report.output_errors.is_empty() || !plotted {
        return ExitCode::from(EXIT_FAILED);
    }
    ExitCode::SUCCESS
}

/// Writes the charts `[output] plots` of the model file into `out/plots`
/// (replacing the pictures there), leaving out with a note those the
/// results do not have (energies of a static run); whether it succeeded.
fn write_plots(model: &Path, out: &Path, input: &ModelInput) -> bool {
    let Some(names) = input.output.as_ref().map(|o| &o.plots) else {
        return true;
    };
    if names.is_empty() {
        return true;
    }
    let dir = out.join("plots");
    let drawn = Histories::read(out, Some(model)).and_then(|h| {
        let available = h.available();
        let mut groups = Vec::new();
        for name in names {
            match Group::from_name(name) {
                Some(g) if available.contains(&g) => groups.push(g),
                _ => {
                    eprintln!("note: plots: no {name} chart: the results have no histories for it")
                }
            }
        }
        if groups.is_empty() {
            return Ok(Vec::new());
        }
        let figures = h.figures(&Request {
            groups,
            ..Request::default()
        })?;
        remove_pictures(&dir);
        Histories::write(&figures, &dir, Format::Both)
    });
    match drawn {
        Ok(files) => {
            if !files.is_empty() {
                eprintln!("plots: {} files in {}", files.len(), dir.display());
            }
            true
        }
        Err(e @ HistoryError::Unavailable { .. }) => {
            eprintln!("note: plots: {e}");
            true
        }
        Err(e) => {
            eprintln!("error: cannot write plots: {e}");
            false
        }
    }
}

/// Removes the pictures (`.png`, `.svg`) of an earlier run from `dir`.
fn remove_pictures(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("png" | "svg")
        ) {
            let _ = std::fs::remove_file(&path);
        }
    }
}

/// Sets the velocities and accelerations of `state` to zero.
fn bring_to_rest(state: &mut unfold::state::State) {
    for v in [
        &mut state.velocity,
        &mut state.acceleration,
        &mut state.pseudo_acceleration,
    ] {
        v.fill([0.0; 6]);
    }
    for v in [
        &mut state.coordinate_rates,
        &mut state.coordinate_accelerations,
        &mut state.coordinate_pseudo_accelerations,
    ] {
        v.fill(0.0);
    }
}

/// Why the static or dynamic analysis of a run stopped early.
enum Failure {
    Static(StaticError),
    Dynamic(DynamicError),
}

/// Reads the restart file `path` and finds where the run of `model`
/// continues from it.
fn resume(
    path: &Path,
    input: &ModelInput,
    model: &Model,
    plan: &[AnalysisSettings],
) -> Result<Resume, RestartError> {
    Restart::read(path)?.resume(path, &fingerprint(input), model, plan)
}
