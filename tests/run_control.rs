//! A run that is interrupted, that cannot write a file, or that meets
//! another run on its output directory stops cleanly: every result file
//! holds the same steps, every grid listed in `unfold.pvd` exists and
//! every grid is listed, no temporary file is left, `summary.json` says
//! what happened, the error names the file, and the exit code says how
//! the run ended (docs/results.md).

#![cfg(unix)]

use std::collections::BTreeSet;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-run-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The roll-up cantilever with `elements` elements, in increments of
/// `increment`: a run of `1/increment` increments.
fn rollup(elements: usize, increment: f64) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever_rollup.toml"),
    )
    .unwrap()
    .replace("elements = 10\n", &format!("elements = {elements}\n"))
    .replace("first_node = 2\n", "first_node = 100\n")
    .replace(
        "initial_increment = 0.1",
        &format!("initial_increment = {increment}\nmax_increment = {increment}"),
    )
}

/// A run of `unfold` in the background, killed if the test fails.
struct Run {
    child: Child,
}

impl Drop for Run {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Run {
    fn start(model: &Path, out: &Path) -> Self {
        Self {
            child: Command::new(env!("CARGO_BIN_EXE_unfold"))
                .args([
                    "run",
                    model.to_str().unwrap(),
                    "--out",
                    out.to_str().unwrap(),
                ])
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap(),
        }
    }

    fn signal(&self, signal: i32) {
        // SAFETY: kill(2) on our own child's pid
        let r = unsafe { libc::kill(self.child.id() as libc::pid_t, signal) };
        assert_eq!(r, 0, "kill failed");
    }

    /// Waits for the end (at most a minute); exit code and stderr.
    fn finish(mut self) -> (i32, String) {
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                let mut err = String::new();
                use std::io::Read;
                self.child
                    .stderr
                    .take()
                    .unwrap()
                    .read_to_string(&mut err)
                    .unwrap();
                return (status.code().unwrap_or(-1), err);
            }
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "the run did not stop"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

/// Waits until `steps.csv` in `out` lists at least `n` steps.
fn wait_for_steps(out: &Path, n: usize) {
    let start = Instant::now();
    loop {
        let steps = std::fs::read_to_string(out.join("steps.csv"))
            .map(|t| t.lines().count().saturating_sub(1))
            .unwrap_or(0);
        if steps >= n {
            return;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no step written");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The steps of a CSV file (its `step` column); panics on a row cut short.
fn steps_in(path: &Path) -> BTreeSet<usize> {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(
        text.ends_with('\n'),
        "{}: last row cut short",
        path.display()
    );
    let mut lines = text.lines();
    let width = lines.next().unwrap().split(',').count();
    lines
        .map(|l| {
            assert_eq!(l.split(',').count(), width, "{}: row {l}", path.display());
            l.split(',').next().unwrap().parse().unwrap()
        })
        .collect()
}

/// Checks that the result files in `out` agree: the same steps in every
/// CSV file, one grid per step listed in the collection and present, no
/// temporary file. Returns the number of steps and the last time.
fn assert_consistent(out: &Path) -> (usize, f64) {
    let steps = steps_in(&out.join("steps.csv"));
    let n = steps.len();
    assert_eq!(steps, (0..n).collect(), "steps.csv numbering");
    for entry in std::fs::read_dir(out).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp"), "temporary file {name} left");
        if name.ends_with(".csv") {
            assert_eq!(steps_in(&path), steps, "{name} has other steps");
        }
    }
    // no collection before the first grid
    let pvd = std::fs::read_to_string(out.join("unfold.pvd")).unwrap_or_default();
    let listed: BTreeSet<String> = pvd
        .split("file=\"")
        .skip(1)
        .map(|s| s[..s.find('"').unwrap()].to_string())
        .collect();
    let grids: BTreeSet<String> = std::fs::read_dir(out.join("vtk"))
        .unwrap()
        .map(|e| format!("vtk/{}", e.unwrap().file_name().to_string_lossy()))
        .collect();
    assert_eq!(listed, grids, "grids and collection differ");
    assert_eq!(grids.len(), n);
    if n == 0 {
        return (0, f64::NAN);
    }
    let last_row = std::fs::read_to_string(out.join("steps.csv")).unwrap();
    let last_time = last_row.lines().last().unwrap().split(',').nth(2).unwrap();
    (n, last_time.parse().unwrap())
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// Interrupts a long run with `signal` once it has written a few steps.
fn interrupt(name: &str, signal: i32) -> (PathBuf, i32, String) {
    let dir = scratch(name);
    let model = dir.join("long.toml");
    // 5000 increments: minutes if not interrupted
    std::fs::write(&model, rollup(200, 2e-4)).unwrap();
    let out = dir.join("out");
    let run = Run::start(&model, &out);
    wait_for_steps(&out, 3);
    run.signal(signal);
    let (code, err) = run.finish();
    (out, code, err)
}

#[test]
fn sigint_stops_after_a_step_with_consistent_files() {
    let (out, code, err) = interrupt("sigint", libc::SIGINT);
    assert_eq!(code, 130, "{err}");
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    let (steps, last) = assert_consistent(&out);
    assert!(steps >= 3);
    let s = summary(&out);
    assert_eq!(s["status"], "interrupted");
    // steps.csv holds the time to 13 significant digits, summary.json in full
    let final_time = s["final_time"].as_f64().unwrap();
    assert!(
        (final_time - last).abs() <= 1e-11 * last.abs(),
        "{final_time} vs {last}"
    );
    assert_eq!(s["output_steps"].as_u64().unwrap() as usize, steps);
    assert!(s["message"].as_str().unwrap().contains("SIGINT"));
    assert_counts_include_the_last_step(&out, &s);
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(
        log.lines().last().unwrap().starts_with("interrupted:"),
        "{log}"
    );
}

#[test]
fn sigterm_stops_after_a_step_with_consistent_files() {
    let (out, code, err) = interrupt("sigterm", libc::SIGTERM);
    assert_eq!(code, 143, "{err}");
    assert!(err.contains("interrupted by SIGTERM"), "{err}");
    assert_consistent(&out);
    assert_eq!(summary(&out)["status"], "interrupted");
}

/// A second signal ends the process at once, between steps: the files
/// still agree, and the summary is left saying `running`.
#[test]
fn a_second_signal_ends_the_run_at_once() {
    let dir = scratch("twice");
    let model = dir.join("long.toml");
    // a beam of 20,000 elements in two increments: the first increment
    // takes seconds; the first signal waits for its end, the second does
    // not
    std::fs::write(&model, rollup(20_000, 0.5)).unwrap();
    let out = dir.join("out");
    let run = Run::start(&model, &out);
    wait_for_steps(&out, 1);
    run.signal(libc::SIGINT);
    // later than unfold::io::run::SAME_REQUEST (250 ms): a second request
    std::thread::sleep(Duration::from_millis(600));
    run.signal(libc::SIGINT);
    let (code, err) = run.finish();
    assert_eq!(code, 130, "{err}");
    assert!(err.contains("stopping at once"), "{err}");
    assert_eq!(assert_consistent(&out).0, 1);
    assert_eq!(summary(&out)["status"], "running");
}

/// GNU `timeout -s INT` sends its signal to the run and then to the
/// run's process group: two signals microseconds apart are one request
/// (`unfold::io::run::SAME_REQUEST`), and the run stops cleanly after its
/// step, with its summary and its restart file.
#[test]
fn a_signal_sent_twice_at_once_is_one_request() {
    let dir = scratch("doubled");
    let model = dir.join("long.toml");
    std::fs::write(&model, rollup(200, 2e-4)).unwrap();
    let out = dir.join("out");
    let run = Run::start(&model, &out);
    wait_for_steps(&out, 3);
    run.signal(libc::SIGINT);
    run.signal(libc::SIGINT);
    let (code, err) = run.finish();
    assert_eq!(code, 130, "{err}");
    assert!(!err.contains("stopping at once"), "{err}");
    assert!(err.contains("interrupted by SIGINT"), "{err}");
    let (steps, _) = assert_consistent(&out);
    let s = summary(&out);
    assert_eq!(s["status"], "interrupted");
    assert_eq!(s["output_steps"].as_u64().unwrap() as usize, steps);
    assert!(out.join("restart.json").exists());
    assert_counts_include_the_last_step(&out, &s);
}

/// The summary's counts of an interrupted run include the step finished
/// after the signal, the last one written: its number is the last row's
/// `increment` in `steps.csv`, and its iterations are the sum of those of
/// `increment_log`.
fn assert_counts_include_the_last_step(out: &Path, s: &serde_json::Value) {
    let steps = std::fs::read_to_string(out.join("steps.csv")).unwrap();
    let last: u64 = steps
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(s["increments"].as_u64().unwrap(), last, "{steps}");
    let logged: u64 = s["increment_log"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["iterations"].as_u64().unwrap())
        .sum();
    assert_eq!(s["iterations"].as_u64().unwrap(), logged);
}

/// Another run holding the directory: refused at once, naming the
/// directory and the other process; the other run goes on undisturbed.
#[test]
fn a_second_run_on_the_same_directory_is_refused() {
    let dir = scratch("busy");
    let model = dir.join("long.toml");
    std::fs::write(&model, rollup(200, 2e-4)).unwrap();
    let out = dir.join("out");
    let first = Run::start(&model, &out);
    wait_for_steps(&out, 2);
    let second = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(1), "{err}");
    assert!(
        err.contains(out.to_str().unwrap())
            && err.contains("another run")
            && err.contains(&first.child.id().to_string()),
        "{err}"
    );
    first.signal(libc::SIGINT);
    let (code, err) = first.finish();
    assert_eq!(code, 130, "{err}");
    assert_consistent(&out);
}

/// `/dev/full` behaves as a full disk: every write fails with ENOSPC.
#[cfg(target_os = "linux")]
fn on_full_disk(file: &str) -> (PathBuf, i32, String) {
    let dir = scratch(&format!("full-{file}"));
    let model = dir.join("model.toml");
    std::fs::write(&model, rollup(10, 0.1)).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink("/dev/full", out.join(file)).unwrap();
    let result = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    (
        out,
        result.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&result.stderr).into_owned(),
    )
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_is_reported_with_the_file_name() {
    for file in ["log.txt", "nodes.csv", "steps.csv"] {
        let (out, code, err) = on_full_disk(file);
        assert_eq!(code, 1, "{file}: {err}");
        assert!(
            err.contains(&format!(
                "{}: No space left on device",
                out.join(file).display()
            )),
            "{file}: {err}"
        );
        for entry in std::fs::read_dir(&out).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.ends_with(".tmp"), "{file}: {name} left");
        }
        // nothing was run: no summary claims a run
        assert!(!out.join("summary.json").exists(), "{file}");
    }
}

/// A file that fills up during the run (the file-size limit, `ulimit -f`,
/// stands for a disk that fills): the step being written is removed from
/// every file, the run stops with exit code 1, the summary says failed
/// and names the file.
#[test]
fn a_write_failing_mid_run_leaves_every_file_with_the_same_steps() {
    let dir = scratch("fsize");
    let model = dir.join("model.toml");
    // 401 nodes, about 80 kB of nodes.csv per step: the limit falls in the
    // fourth step, long before log.txt or a grid reaches it
    std::fs::write(&model, rollup(400, 0.05)).unwrap();
    let out = dir.join("out");
    let limit = 300_000;
    let mut command = Command::new(env!("CARGO_BIN_EXE_unfold"));
    command.args([
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    // SAFETY: setrlimit is async-signal-safe
    unsafe {
        command.pre_exec(move || {
            let l = libc::rlimit {
                rlim_cur: limit,
                rlim_max: limit,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &l) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let result = command.output().unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(1), "{err}");
    let nodes = out.join("nodes.csv");
    assert!(
        err.contains(&format!("{}: File too large", nodes.display())),
        "{err}"
    );
    let (steps, last) = assert_consistent(&out);
    assert!(steps >= 2, "{steps} steps");
    assert!(std::fs::metadata(&nodes).unwrap().len() <= limit);
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    assert!(s["message"].as_str().unwrap().contains("nodes.csv"));
    assert_eq!(s["output_steps"].as_u64().unwrap() as usize, steps);
    assert!(s["final_time"].as_f64().unwrap() >= last);
}

/// After a write failure the note on stderr gives the time of the last
/// step actually written (the files stop there), not that of the
/// increment whose step could not be written; and the lock file is gone.
#[test]
fn the_note_after_a_write_failure_gives_the_last_step_written() {
    let dir = scratch("fsize-note");
    let model = dir.join("model.toml");
    // as above: nodes.csv passes the limit in the fourth step
    std::fs::write(&model, rollup(400, 0.05)).unwrap();
    let out = dir.join("out");
    let limit = 300_000;
    let mut command = Command::new(env!("CARGO_BIN_EXE_unfold"));
    command.args([
        "run",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    // SAFETY: setrlimit is async-signal-safe
    unsafe {
        command.pre_exec(move || {
            let l = libc::rlimit {
                rlim_cur: limit,
                rlim_max: limit,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &l) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let result = command.output().unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(1), "{err}");
    let (_, last) = assert_consistent(&out);
    let final_time = summary(&out)["final_time"].as_f64().unwrap();
    assert!(
        final_time > last,
        "the failed step is after the last written"
    );
    let note = err
        .lines()
        .find(|l| l.starts_with("note: results up to t = "))
        .unwrap_or_else(|| panic!("no note: {err}"));
    let t: f64 = note["note: results up to t = ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    // the note prints six decimals
    assert!(
        (t - last).abs() < 1e-6,
        "note {t}, last step written {last}: {err}"
    );
    assert!(!out.join(".unfold.lock").exists());
}

/// Runs `unfold run model --out out` with `out` on a disk of `size` bytes
/// (a tmpfs mounted in a mount namespace of its own, `unshare -Urm`), and
/// copies what the run left there to `copy` (the disk goes with the
/// namespace). Exit code and stderr; `None` where this machine cannot
/// make such a disk (said on stderr; in CI, `UNFOLD_CI` set, a failure).
#[cfg(target_os = "linux")]
fn run_on_a_small_disk(
    size: usize,
    model: &Path,
    out: &Path,
    copy: &Path,
) -> Option<(i32, String)> {
    std::fs::create_dir_all(out).unwrap();
    std::fs::create_dir_all(copy).unwrap();
    let script = r#"mount -t tmpfs -o size="$1" tmpfs "$2" || exit 99
"$4" run "$5" --out "$2"; code=$?; cp -a "$2/." "$3"; exit $code"#;
    let result = Command::new("unshare")
        .args(["-Urm", "sh", "-c", script, "sh", &size.to_string()])
        .args([out, copy, Path::new(env!("CARGO_BIN_EXE_unfold")), model])
        .output();
    let unavailable = match &result {
        Err(e) => Some(e.to_string()),
        Ok(r)
            if r.status.code() == Some(99)
                || (r.status.code() == Some(1)
                    && r.stdout.is_empty()
                    && String::from_utf8_lossy(&r.stderr).contains("unshare")) =>
        {
            Some(String::from_utf8_lossy(&r.stderr).into_owned())
        }
        Ok(_) => None,
    };
    if let Some(why) = unavailable {
        assert!(
            std::env::var_os("UNFOLD_CI").is_none(),
            "CI: no small disk can be made here (unshare -Urm and a tmpfs): {why}"
        );
        eprintln!(
            "SKIPPED: no small disk can be made on this machine (unshare -Urm and a tmpfs): {why}"
        );
        return None;
    }
    let r = result.unwrap();
    Some((
        r.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&r.stderr).into_owned(),
    ))
}

/// A disk that fills up during the run (a real one: a tmpfs of a few
/// hundred kB), at several points of the run (a step's grid or rows, the
/// restart file at the end): the run stops with exit code 1, every result
/// file holds the same steps, no temporary file or lock file is left, and
/// `summary.json` says the run failed and names the file, written into
/// the space the lock reserved when the disk has none left.
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_leaves_no_temporary_file_and_a_failed_summary() {
    let dir = scratch("tmpfs");
    let model = dir.join("model.toml");
    // 401 nodes, about 80 kB of nodes.csv and 40 kB of beams.csv a step,
    // and a restart file of about 130 kB: 20 steps fill any of these disks
    std::fs::write(&model, rollup(400, 0.05)).unwrap();
    let mut failures = BTreeSet::new();
    let mut restart_failed = false;
    for size in [250_000, 400_000, 700_000, 1_000_000, 1_500_000, 2_500_000] {
        let (out, copy) = (
            dir.join(format!("out{size}")),
            dir.join(format!("copy{size}")),
        );
        let Some((code, err)) = run_on_a_small_disk(size, &model, &out, &copy) else {
            return;
        };
        assert_eq!(code, 1, "{size} B: {err}");
        assert!(err.contains("No space left on device"), "{size} B: {err}");
        assert!(
            !copy.join(".unfold.lock").exists(),
            "{size} B: lock file left"
        );
        let s = summary(&copy);
        assert_eq!(s["status"], "failed", "{size} B: {s}");
        let message = s["message"].as_str().unwrap();
        assert!(
            message.contains("No space left on device"),
            "{size} B: {message}"
        );
        // the file that could not be written, by kind
        let file = message
            .split(": No space")
            .next()
            .unwrap()
            .rsplit('/')
            .next()
            .unwrap();
        failures.insert(file.split('_').next().unwrap().to_string());
        restart_failed |= message.contains("restart.json: No space left on device");
        if copy.join("steps.csv").exists() {
            let (steps, _) = assert_consistent(&copy);
            println!("{size} B: {steps} steps, then {file}");
            assert_eq!(
                s["output_steps"].as_u64().unwrap() as usize,
                steps,
                "{size} B"
            );
        }
        for entry in std::fs::read_dir(&copy).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.ends_with(".tmp"), "{size} B: {name} left");
        }
    }
    println!("files that filled the disk: {failures:?}");
    // the sizes reach more than one file, and the restart file written at
    // the end (whose temporary file was left behind)
    assert!(failures.len() >= 2, "{failures:?}");
    assert!(restart_failed, "no run failed on restart.json");
}

/// A run killed with SIGKILL leaves its lock file (nothing of it runs to
/// remove the file); the next run into that directory finds that no
/// process holds it, says so, naming the killed process, and goes on.
#[test]
fn a_killed_runs_lock_file_is_taken_over_with_a_note() {
    let dir = scratch("sigkill");
    let model = dir.join("long.toml");
    std::fs::write(&model, rollup(200, 2e-4)).unwrap();
    let out = dir.join("out");
    let run = Run::start(&model, &out);
    let killed = run.child.id();
    wait_for_steps(&out, 2);
    run.signal(libc::SIGKILL);
    let (code, _) = run.finish();
    assert_eq!(code, -1, "killed by a signal");
    let lock = std::fs::read_to_string(out.join(".unfold.lock")).expect("lock file left");
    assert_eq!(lock.trim(), killed.to_string());
    assert_eq!(summary(&out)["status"], "running");

    let short = dir.join("short.toml");
    std::fs::write(&short, rollup(10, 0.5)).unwrap();
    let next = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            short.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&next.stderr);
    let stdout = String::from_utf8_lossy(&next.stdout);
    assert_eq!(next.status.code(), Some(0), "{err}");
    let said = format!("{stdout}{err}");
    assert!(
        said.contains(&format!(
            "an earlier run (process {killed}) did not end there"
        )),
        "{said}"
    );
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains(&format!("process {killed}")), "{log}");
    assert_eq!(summary(&out)["status"], "completed");
    assert!(!out.join(".unfold.lock").exists());
    assert_consistent(&out);
}
