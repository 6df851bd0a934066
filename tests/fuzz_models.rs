//! Fuzzing of model files: the example models (`examples/*.toml`, and
//! `tests/data/every_table.toml`, which uses every table) mutated at
//! random — numbers replaced by 0, −1, huge, tiny and non-finite values,
//! values by strings or by values of another type, ids swapped and
//! duplicated, fields and array entries deleted, entries (nodes,
//! elements, points) duplicated, arrays shortened, lines deleted — and
//! put through
//!
//! - the code path of `unfold check` (parse, validate and build the model,
//!   then `analysis::preflight`), in-process: it must return a model or an
//!   error with a message naming the file, and never panic;
//! - for a sample, the `unfold` binary's `run`: exit code 0, 1 or 2, a
//!   message on stderr when it is not 0, no panic, and no non-finite
//!   number in any result file.
//!
//! The cases are drawn by proptest from a fixed seed, so a run is
//! reproducible and a failure shrinks to a minimal mutation (see
//! [`runner`] for a longer search).

use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use toml::{Table, Value};

use unfold::analysis::preflight;
use unfold::io::model_file::parse_model;
use unfold::model::Model;

/// Longest a mutant may run.
const RUN_LIMIT: Duration = Duration::from_secs(30);

/// How soon a run interrupted at [`RUN_LIMIT`] must stop.
const INTERRUPT_LIMIT: Duration = Duration::from_secs(10);

/// The seed models, parsed: the example model files, and
/// `tests/data/every_table.toml`, which uses every table of the format.
fn examples() -> Vec<(String, Table)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("toml"))
        // the solar array's files: the array reads its panel as a body
        // file beside it, which a mutant written elsewhere cannot find,
        // and the panel alone is the sandwich panel's kind of model
        // (tests/solar_array.rs and tests/superelements.rs run them)
        .filter(|p| {
            !p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("solar_"))
        })
        .collect();
    files.sort();
    assert!(files.len() >= 4, "the examples are missing: {files:?}");
    files.push(root.join("tests/data/every_table.toml"));
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, text.parse::<Table>().unwrap())
        })
        .collect()
}

/// A step of a path into a TOML document.
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

/// Every path of the document, parents before children.
fn paths(v: &Value, prefix: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    out.push(prefix.clone());
    match v {
        Value::Table(t) => {
            for (k, c) in t {
                prefix.push(Step::Key(k.clone()));
                paths(c, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                prefix.push(Step::Index(i));
                paths(c, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(v: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    path.iter().try_fold(v, |v, s| match (s, v) {
        (Step::Key(k), Value::Table(t)) => t.get_mut(k),
        (Step::Index(i), Value::Array(a)) => a.get_mut(*i),
        _ => None,
    })
}

/// Replacement numbers: zero, −1, huge, tiny, non-finite, ids at the edge
/// of the integer range.
fn number(choice: usize, integer: bool) -> Value {
    const FLOATS: [f64; 16] = [
        0.0,
        -1.0,
        1.0,
        2.0,
        0.5,
        1e308,
        -1e308,
        1e-308,
        5e-324,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1e154,
        -2.5e-7,
        90.0,
        1e9,
    ];
    const INTEGERS: [i64; 12] = [
        0,
        1,
        2,
        3,
        100,
        i64::MAX,
        i64::MAX - 1,
        9_223_372_036_854_775_000,
        4_294_967_297,
        1_000_000_000,
        100_001,
        -1,
    ];
    if integer {
        Value::Integer(INTEGERS[choice % INTEGERS.len()])
    } else {
        Value::Float(FLOATS[choice % FLOATS.len()])
    }
}

/// Strings where numbers, names or lists belong.
const STRINGS: [&str; 6] = ["NaN", "inf", "1e400", "", "ramp", "constant"];

/// One mutation: which kind, at which path (an index into the candidate
/// paths, modulo their number), with which value or partner.
#[derive(Clone, Debug)]
struct Mutation {
    kind: u8,
    at: usize,
    choice: usize,
}

fn is_number(v: &Value) -> bool {
    matches!(v, Value::Integer(_) | Value::Float(_))
}

fn apply(doc: &mut Value, m: &Mutation) {
    let mut all = Vec::new();
    paths(doc, &mut Vec::new(), &mut all);
    let numbers: Vec<Vec<Step>> = all
        .iter()
        .filter(|p| get_mut(doc, p).is_some_and(|v| is_number(v)))
        .cloned()
        .collect();
    let path = all[m.at % all.len()].clone();
    match m.kind % 10 {
        // a number replaced by another of its type (four times in ten)
        0..=3 if !numbers.is_empty() => {
            let v = get_mut(doc, &numbers[m.at % numbers.len()]).unwrap();
            let integer = matches!(v, Value::Integer(_));
            *v = number(m.choice, integer);
        }
        // an integer replaced by another integer of the document: ids
        // swapped and duplicated
        4 => {
            let integers: Vec<(Vec<Step>, i64)> = numbers
                .iter()
                .filter_map(|p| match get_mut(doc, p) {
                    Some(Value::Integer(i)) => Some((p.clone(), *i)),
                    _ => None,
                })
                .collect();
            if !integers.is_empty() {
                let target = &integers[m.at % integers.len()].0;
                let value = integers[m.choice % integers.len()].1;
                *get_mut(doc, target).unwrap() = Value::Integer(value);
            }
        }
        // a field or an array element deleted
        5 => {
            if let Some((last, parent)) = path.split_last() {
                match (last, get_mut(doc, parent)) {
                    (Step::Key(k), Some(Value::Table(t))) => {
                        t.remove(k);
                    }
                    (Step::Index(i), Some(Value::Array(a))) => {
                        a.remove(*i);
                    }
                    _ => {}
                }
            }
        }
        // an array element duplicated (a node, an element, a point)
        6 => {
            if let Some((Step::Index(i), parent)) = path.split_last() {
                if let Some(Value::Array(a)) = get_mut(doc, parent) {
                    let copy = a[*i].clone();
                    a.insert(*i, copy);
                }
            }
        }
        // an array shortened
        7 => {
            if let Some(Value::Array(a)) = get_mut(doc, &path) {
                let keep = m.choice % (a.len() + 1);
                a.truncate(keep);
            }
        }
        // a string where a value belongs
        8 => {
            if let Some(v) = get_mut(doc, &path) {
                *v = Value::String(STRINGS[m.choice % STRINGS.len()].into());
            }
        }
        // a value given another type
        _ => {
            if let Some(v) = get_mut(doc, &path) {
                *v = match v {
                    Value::Array(_) => Value::Integer(3),
                    Value::Table(_) => Value::Array(Vec::new()),
                    Value::Integer(i) => Value::Float(*i as f64 + 0.5),
                    Value::Float(_) => Value::Array(vec![Value::Float(1.0)]),
                    _ => Value::Boolean(true),
                };
            }
        }
    }
}

/// The mutated text: mutations of the document, then lines deleted.
fn mutant(examples: &[(String, Table)], case: &Case) -> (String, String) {
    let (name, table) = &examples[case.example % examples.len()];
    let mut doc = Value::Table(table.clone());
    for m in &case.mutations {
        apply(&mut doc, m);
    }
    let text = toml::to_string(&doc).unwrap_or_default();
    let mut lines: Vec<&str> = text.lines().collect();
    for &k in &case.deleted_lines {
        if !lines.is_empty() {
            let k = k % lines.len();
            lines.remove(k);
        }
    }
    (name.clone(), lines.join("\n"))
}

#[derive(Clone, Debug)]
struct Case {
    example: usize,
    mutations: Vec<Mutation>,
    deleted_lines: Vec<usize>,
}

fn cases() -> impl Strategy<Value = Case> {
    let mutation = (any::<u8>(), any::<usize>(), any::<usize>())
        .prop_map(|(kind, at, choice)| Mutation { kind, at, choice });
    (
        any::<usize>(),
        prop::collection::vec(mutation, 1..4),
        // a line deleted in one case in four
        prop::collection::vec(any::<usize>(), 0..2).prop_map(|v| {
            if v.first().is_some_and(|k| k % 2 == 0) {
                v
            } else {
                Vec::new()
            }
        }),
    )
        .prop_map(|(example, mutations, deleted_lines)| Case {
            example,
            mutations,
            deleted_lines,
        })
}

/// A deterministic runner: the same cases on every run. The environment
/// variables `UNFOLD_FUZZ_SEED` (a number) and `UNFOLD_FUZZ_SCALE` (a
/// factor on the number of cases) draw other and more cases, for a longer
/// search by hand.
fn runner(cases: u32) -> TestRunner {
    let var = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<u32>().ok());
    let mut seed = [7u8; 32];
    if let Some(s) = var("UNFOLD_FUZZ_SEED") {
        seed[..4].copy_from_slice(&s.to_le_bytes());
    }
    let config = Config {
        cases: cases * var("UNFOLD_FUZZ_SCALE").unwrap_or(1),
        failure_persistence: None,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed))
}

/// What `unfold check` does with the text of a model file, in-process:
/// the model (when valid and sound) or the message.
fn check(text: &str, path: &Path) -> Result<Model, String> {
    let input = parse_model(text, path).map_err(|e| e.to_string())?;
    let model = Model::from_input(&input).map_err(|e| {
        unfold::io::model_file::ModelFileError::Invalid {
            path: path.to_path_buf(),
            errors: e,
        }
        .to_string()
    })?;
    let invalid = |e| {
        unfold::io::model_file::ModelFileError::Invalid {
            path: path.to_path_buf(),
            errors: e,
        }
        .to_string()
    };
    let analyses = input.analyses().map_err(invalid)?;
    // as `unfold check`: the mass of a model with modal analyses, then the
    // preflight of the first static analysis, if any
    if analyses.iter().any(|a| a.as_modal().is_some())
        && !unfold::analysis::ModalAnalysis::has_mass(&model)
    {
        return Err(format!(
            "{}: modal analysis: {}",
            path.display(),
            unfold::analysis::ModalError::NoMass
        ));
    }
    if let Some(settings) = analyses.iter().find_map(|a| a.as_static()) {
        preflight::check(&model, settings).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(model)
}

/// Mutants of every example through the checks: a model or a message
/// naming the file, never a panic (a panic fails the case, and proptest
/// shrinks it to the smallest mutation that panics).
#[test]
fn mutated_models_are_checked_without_panic() {
    let examples = examples();
    let path = Path::new("mutant.toml");
    let (valid, rejected) = (Cell::new(0), Cell::new(0));
    runner(3000)
        .run(&cases(), |case| {
            let (_, text) = mutant(&examples, &case);
            match check(&text, path) {
                Ok(model) => {
                    valid.set(valid.get() + 1);
                    // a valid model's values are finite
                    prop_assert!(model
                        .reference_x
                        .iter()
                        .all(|x| x.iter().all(|v| v.is_finite())));
                }
                Err(message) => {
                    rejected.set(rejected.get() + 1);
                    prop_assert!(
                        message.contains("mutant.toml") && message.len() > "mutant.toml: ".len(),
                        "no message naming the file: {message}"
                    );
                }
            }
            Ok(())
        })
        .unwrap();
    // the mutations must exercise both outcomes
    let (valid, rejected) = (valid.get(), rejected.get());
    eprintln!("{valid} valid, {rejected} rejected");
    assert!(
        valid > 50 && rejected > 50,
        "{valid} valid, {rejected} rejected"
    );
}

/// Every number of every CSV and VTK file in `dir` (recursively) is
/// finite; returns the first offending file and token.
fn non_finite_in_results(dir: &Path) -> Option<(PathBuf, String)> {
    for entry in std::fs::read_dir(dir).ok()?.flatten() {
        let p = entry.path();
        if p.is_dir() {
            if let Some(found) = non_finite_in_results(&p) {
                return Some(found);
            }
            continue;
        }
        if !matches!(
            p.extension().and_then(|e| e.to_str()),
            Some("csv" | "vtu" | "pvd")
        ) {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        for token in text.split(|c: char| c == ',' || c.is_whitespace() || c == '"') {
            if let Ok(v) = token.parse::<f64>() {
                if !v.is_finite() {
                    return Some((p, token.to_string()));
                }
            }
        }
    }
    None
}

/// A sample of mutants through `unfold run`: exit code 0, 1 or 2 with a
/// message when not 0, no panic, finite result files, and an end within
/// [`RUN_LIMIT`] (the examples run in a fraction of a second), or, for a
/// mutant still running then, a clean stop on SIGINT within
/// [`INTERRUPT_LIMIT`] (exit code 130, summary `interrupted`, finite
/// results): a run that does not answer hangs.
#[test]
fn mutated_models_run_without_panic_or_non_finite_results() {
    let examples = examples();
    let dir = std::env::temp_dir().join(format!("unfold-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let count = Cell::new(0);
    let codes = Cell::new([0usize; 3]);
    runner(150)
        .run(&cases(), |case| {
            count.set(count.get() + 1);
            let count = count.get();
            let (name, text) = mutant(&examples, &case);
            let file = dir.join(format!("{name}-{count}.toml"));
            std::fs::write(&file, &text).unwrap();
            let out = dir.join(format!("out-{count}"));
            let log = dir.join(format!("stderr-{count}.txt"));
            let mut child = Command::new(env!("CARGO_BIN_EXE_unfold"))
                .args([
                    "run",
                    file.to_str().unwrap(),
                    "--out",
                    out.to_str().unwrap(),
                    "--quiet",
                ])
                .stdout(Stdio::null())
                .stderr(std::fs::File::create(&log).unwrap())
                .spawn()
                .unwrap();
            let start = Instant::now();
            let mut interrupted = false;
            while child.try_wait().unwrap().is_none() {
                if start.elapsed() > RUN_LIMIT + INTERRUPT_LIMIT {
                    let _ = child.kill();
                    prop_assert!(false, "no end in {RUN_LIMIT:?}, nor {INTERRUPT_LIMIT:?} after SIGINT, for\n{text}");
                }
                if start.elapsed() > RUN_LIMIT && !interrupted {
                    // a long run (a mutant may ask for a million steps, as
                    // a gravity of 1e9 does of a double pendulum): it must
                    // stop cleanly when interrupted
                    // SAFETY: kill(2) on the child's process id
                    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
                    interrupted = true;
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            let code = child.wait().unwrap().code();
            if interrupted {
                // 128 + SIGINT, its summary saying so
                prop_assert_eq!(code, Some(130), "for\n{}", text);
                let summary = std::fs::read_to_string(out.join("summary.json")).unwrap_or_default();
                prop_assert!(summary.contains("\"interrupted\""), "{summary}");
                if let Some((f, token)) = non_finite_in_results(&out) {
                    prop_assert!(false, "{token} in {} for\n{text}", f.display());
                }
                let _ = std::fs::remove_dir_all(&out);
                return Ok(());
            }
            let stderr = std::fs::read_to_string(&log).unwrap_or_default();
            prop_assert!(
                matches!(code, Some(0..=2)),
                "exit {code:?} for\n{text}\nstderr: {stderr}"
            );
            prop_assert!(!stderr.contains("panicked"), "panic for\n{text}\n{stderr}");
            let code = code.unwrap() as usize;
            let mut c = codes.get();
            c[code] += 1;
            codes.set(c);
            if code != 0 {
                prop_assert!(
                    stderr.contains("error:"),
                    "no message for\n{text}\n{stderr}"
                );
            }
            if let Some((f, token)) = non_finite_in_results(&out) {
                prop_assert!(false, "{token} in {} for\n{text}", f.display());
            }
            let _ = std::fs::remove_dir_all(&out);
            Ok(())
        })
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let codes = codes.get();
    eprintln!("exit codes 0/1/2: {codes:?}");
    assert!(codes[0] > 0 && codes[2] > 0, "exit codes 0/1/2: {codes:?}");
}
