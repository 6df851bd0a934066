//! `unfold view` (docs/viewer.md): the page of a run holds every output
//! step of its grids, the colour fields, the histories and the events, as
//! the page's script decodes them (checked here against the `.vtu` and CSV
//! files, within the quantisation); results directories that are not are
//! refused; and the page runs in a real headless Chromium: it loads with no
//! script error, draws the structure, and the picture changes with time.
//!
//! The browser test needs Chromium (`chromium`, `chromium-browser`,
//! `google-chrome` on the PATH, or the path in `UNFOLD_CHROMIUM`). Without
//! it the test says so loudly and checks nothing in a browser; with
//! `UNFOLD_CI` set (by `.ci/run`) its absence is a failure. Its
//! screenshots and the page are kept in `target/artifacts/viewer/`.

mod common;
#[allow(dead_code)] // the reader serves several test files
mod vtk_reader;

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use base64::Engine as _;
use common::cli::{column, csv_rows, number, scratch, unfold};
use serde_json::Value;

/// Runs tests/data/viewer_deployment.toml (a panel unfolding at the tip
/// of a boom, locked by a latch) into `dir/out`.
fn deployment(dir: &Path) -> PathBuf {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/viewer_deployment.toml");
    let out = dir.join("out");
    common::cli::run_model(&model, &out);
    out
}

/// A page's manifest and its data, inflated (as its script does).
struct Page {
    html: String,
    manifest: Value,
    data: Vec<u8>,
}

/// The text of the element that opens with `open`.
fn element<'a>(html: &'a str, open: &str) -> &'a str {
    let start = html.find(open).unwrap_or_else(|| panic!("no {open}")) + open.len();
    &html[start..start + html[start..].find("</script>").unwrap()]
}

fn inflate(base64: &str) -> Vec<u8> {
    let compressed = base64::engine::general_purpose::STANDARD
        .decode(base64.trim())
        .unwrap();
    let mut raw = Vec::new();
    flate2::read::ZlibDecoder::new(&compressed[..])
        .read_to_end(&mut raw)
        .unwrap();
    raw
}

impl Page {
    fn read(path: &Path) -> Self {
        let html = std::fs::read_to_string(path).unwrap();
        let manifest = serde_json::from_str(element(
            &html,
            "<script type=\"application/json\" id=\"manifest\">",
        ))
        .unwrap();
        let data = inflate(element(
            &html,
            "<script type=\"application/octet-stream\" id=\"data\">",
        ));
        Self {
            html,
            manifest,
            data,
        }
    }

    /// The codes of frames written as differences (src/io/view/pack.rs),
    /// decoded as assets/viewer/viewer.js does.
    fn frames(&self, d: &Value) -> Vec<u16> {
        assert_eq!(d["encoding"], "u16-delta");
        let (offset, n, w) = (
            d["offset"].as_u64().unwrap() as usize,
            d["count"].as_u64().unwrap() as usize,
            d["width"].as_u64().unwrap() as usize,
        );
        let mut out = vec![0u16; n];
        for i in 0..n {
            let v = u16::from_le_bytes([self.data[offset + i], self.data[offset + n + i]]);
            out[i] = if i >= w {
                v.wrapping_add(out[i - w])
            } else {
                v
            };
        }
        out
    }

    /// Numbers of a plain array (`i32`, `f64`, `u8`).
    fn numbers(&self, d: &Value) -> Vec<f64> {
        let (offset, n) = (
            d["offset"].as_u64().unwrap() as usize,
            d["count"].as_u64().unwrap() as usize,
        );
        let bytes = &self.data[offset..];
        match d["encoding"].as_str().unwrap() {
            "u8" => bytes[..n].iter().map(|&b| b as f64).collect(),
            "i32" => (0..n)
                .map(|i| i32::from_le_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap()) as f64)
                .collect(),
            "f64" => (0..n)
                .map(|i| f64::from_le_bytes(bytes[8 * i..8 * i + 8].try_into().unwrap()))
                .collect(),
            e => panic!("{e}"),
        }
    }

    /// The field named `name`.
    fn field(&self, name: &str) -> &Value {
        self.manifest["fields"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == name)
            .unwrap_or_else(|| panic!("no field {name}"))
    }
}

/// Runs `unfold view` with `args`; its output.
fn view(args: &[&str]) -> std::process::Output {
    let mut all = vec!["view"];
    all.extend_from_slice(args);
    unfold(&all)
}

/// The page of the deployment holds every output step: its times, the
/// positions of every point (within half a code of the range: 1/131068 of
/// the box), the cells of the grids, the beams' `M3` and the joints' load
/// (within half a code of their ranges), the histories of energies.csv,
/// the lock of events.csv, and the libraries with their licences.
#[test]
fn the_page_holds_the_steps_fields_histories_and_events_of_the_run() {
    let dir = scratch("view", "page");
    let out = deployment(&dir);
    let page_path = out.join("view.html");
    let o = view(&[out.to_str().unwrap(), "--no-open"]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let times = column(&out.join("steps.csv"), "time");
    let n = times.len();
    assert!(
        stdout.contains(&format!("{n} frames of {n} output steps")),
        "{stdout}"
    );
    let page = Page::read(&page_path);
    let m = &page.manifest;
    assert_eq!(m["format"], "unfold view");
    assert_eq!(m["title"], "Panel unfolding at the tip of a boom");
    assert_eq!(m["status"], "completed");
    assert_eq!(m["time_name"], "time");

    // times: those of steps.csv (the collection's 13 digits)
    let frame_times: Vec<f64> = m["frames"]["times"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    assert_eq!(frame_times.len(), times.len());
    for (a, b) in frame_times.iter().zip(&times) {
        assert!((a - b).abs() < 1e-12, "{a} {b}");
    }

    // every frame's points against its grid, the cells against the grid's
    let n_points = m["points"]["count"].as_u64().unwrap() as usize;
    let lo: Vec<f64> = m["points"]["lo"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let hi: Vec<f64> = m["points"]["hi"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let positions = page.frames(&m["points"]["positions"]);
    assert_eq!(positions.len(), times.len() * 3 * n_points);
    let m3 = page.field("M3");
    let m3_codes = page.frames(&m3["values"]);
    let (m3_lo, m3_hi) = (m3["min"].as_f64().unwrap(), m3["max"].as_f64().unwrap());
    let mut worst_position = 0.0f64;
    let mut worst_m3 = 0.0f64;
    for (k, _) in times.iter().enumerate() {
        let grid = vtk_reader::read(&out.join(format!("vtk/step_{k:05}.vtu")));
        assert_eq!(grid.piece("NumberOfPoints"), n_points);
        let (x, _) = grid.array("position");
        for (i, &xi) in x.iter().enumerate() {
            let c = i % 3;
            let code = positions[k * 3 * n_points + i] as f64;
            let decoded = lo[c] + code / 65534.0 * (hi[c] - lo[c]);
            worst_position = worst_position.max((decoded - xi).abs() / (hi[c] - lo[c]));
        }
        let (values, _) = grid.array("M3");
        let cells = values.len();
        for (c, &v) in values.iter().enumerate() {
            let decoded = m3_lo + m3_codes[k * cells + c] as f64 / 65534.0 * (m3_hi - m3_lo);
            worst_m3 = worst_m3.max((decoded - v).abs() / (m3_hi - m3_lo));
        }
        if k == 0 {
            for name in ["types", "offsets", "connectivity", "kind", "element_id"] {
                let (expected, _) = grid.array(name);
                assert_eq!(page.numbers(&m["cells"][name]), expected, "{name}");
            }
        }
    }
    println!("largest error of a decoded position: {worst_position:.2e} of the box; of M3: {worst_m3:.2e} of its range");
    assert!(worst_position <= 0.5 / 65534.0 + 1e-12, "{worst_position}");
    assert!(worst_m3 <= 0.5 / 65534.0 + 1e-12, "{worst_m3}");
    // M3 colours the beams, not the panel, the hub nor the joint marker
    let kinds = page.numbers(&m["cells"]["kind"]);
    let mask = page.numbers(&m3["mask"]);
    for (k, carried) in kinds.iter().zip(&mask) {
        assert_eq!(*carried == 1.0, *k == 1.0, "kind {k}");
    }

    // the hinge's load on its marker: |(Fx, Fy, Fz)| of joints.csv
    let force = page.field("joint force |F|");
    let codes = page.frames(&force["values"]);
    let (f_lo, f_hi) = (
        force["min"].as_f64().unwrap(),
        force["max"].as_f64().unwrap(),
    );
    let ids = page.numbers(&m["cells"]["element_id"]);
    let marker = (0..kinds.len())
        .find(|&c| kinds[c] == 7.0 && ids[c] == 30.0)
        .expect("the hinge's marker");
    let cells = kinds.len();
    for row in csv_rows(&out.join("joints.csv")) {
        let k = number(&row, "step") as usize;
        let f = ["Fx", "Fy", "Fz"].map(|c| number(&row, c));
        let expected = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        let decoded = f_lo + codes[k * cells + marker] as f64 / 65534.0 * (f_hi - f_lo);
        assert!((decoded - expected).abs() <= 0.5 / 65534.0 * (f_hi - f_lo) + 1e-12);
    }

    // the kinetic energy, as energies.csv has it
    let energies = m["histories"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "energies.csv")
        .expect("energies.csv");
    assert!(energies["entity"].is_null());
    let kinetic = energies["entities"][0]["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["column"] == "kinetic")
        .unwrap();
    let (k_lo, k_hi) = (
        kinetic["min"].as_f64().unwrap(),
        kinetic["max"].as_f64().unwrap(),
    );
    let codes = page.frames(&kinetic["values"]);
    for (code, expected) in codes
        .iter()
        .zip(column(&out.join("energies.csv"), "kinetic"))
    {
        let decoded = k_lo + *code as f64 / 65534.0 * (k_hi - k_lo);
        assert!((decoded - expected).abs() <= 0.5 / 65534.0 * (k_hi - k_lo) + 1e-12);
    }
    // the latch's history, one entity per latch
    let latches = m["histories"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "latches.csv")
        .unwrap();
    assert_eq!(latches["entity"], "latch");
    assert_eq!(latches["entities"][0]["id"], 32);
    // the hinge's, named by its type, its angle a series and its type not
    let joints = m["histories"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "joints.csv")
        .unwrap();
    assert_eq!(joints["entity"], "joint");
    let hinge = &joints["entities"][0];
    assert_eq!(
        (&hinge["id"], &hinge["type"]),
        (&30.into(), &"revolute".into())
    );
    let columns: Vec<&str> = hinge["series"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["column"].as_str().unwrap())
        .collect();
    assert!(
        columns.contains(&"angle") && columns.contains(&"M3"),
        "{columns:?}"
    );
    assert!(!columns.contains(&"type"), "{columns:?}");

    // the lock, as events.csv has it
    let events = m["events"].as_array().unwrap();
    let rows = csv_rows(&out.join("events.csv"));
    assert_eq!(events.len(), 1);
    assert_eq!(events[0]["kind"], "lock");
    assert_eq!(
        events[0]["time"].as_f64().unwrap(),
        number(&rows[0], "time")
    );
    assert_eq!(events[0]["label"], "latch 32: lock of joint 30");

    // the libraries, compressed, and their licences
    let libraries: Vec<String> = page
        .html
        .match_indices("data-library=\"")
        .map(|(at, _)| {
            let from = page.html[at..].find('>').unwrap() + at + 1;
            let text = &page.html[from..from + page.html[from..].find("</script>").unwrap()];
            String::from_utf8(inflate(text)).unwrap()
        })
        .collect();
    assert_eq!(libraries.len(), 2);
    assert!(libraries[0].contains("WebGLRenderer") && libraries[1].contains("uPlot"));
    assert!(page.html.contains("Copyright © 2010-2026 three.js authors"));
    assert!(page.html.contains("Copyright (c) 2022 Leon Sorokin"));
    println!("page: {} bytes", page.html.len());

    // a new run in the directory removes the page of the earlier results
    deployment(&dir);
    assert!(!page_path.exists());
}

/// Fewer frames than steps: evenly spaced ones, the first, the last and
/// the step of the lock; `--histories` chooses the files (a missing one
/// is an error that lists those there).
#[test]
fn frames_and_histories_can_be_chosen() {
    let dir = scratch("view", "choose");
    let out = deployment(&dir);
    let page_path = dir.join("ten.html");
    let o = view(&[
        out.to_str().unwrap(),
        "--out",
        page_path.to_str().unwrap(),
        "--max-frames",
        "10",
        "--histories",
        "energies,latches.csv",
        "--no-open",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let page = Page::read(&page_path);
    let steps: Vec<u64> = page.manifest["frames"]["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_u64().unwrap())
        .collect();
    // ten evenly spaced among the n steps, and the lock's
    let n = column(&out.join("steps.csv"), "time").len() as u64;
    let lock = number(&csv_rows(&out.join("events.csv"))[0], "step") as u64;
    let mut expected: Vec<u64> = (0..10).map(|k| k * (n - 1) / 9).chain([lock]).collect();
    expected.sort_unstable();
    expected.dedup();
    assert_eq!(steps, expected);
    let err = String::from_utf8_lossy(&o.stderr);
    let note = format!(
        "note: {} of the {n} output steps are frames",
        expected.len()
    );
    assert!(err.contains(&note), "{err}");
    let files: Vec<&str> = page.manifest["histories"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["file"].as_str().unwrap())
        .collect();
    assert_eq!(files, ["energies.csv", "latches.csv"]);

    let o = view(&[out.to_str().unwrap(), "--histories", "torques", "--no-open"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "torques.csv: no such history file (the histories of this run: beams.csv, energies.csv"
        ),
        "{err}"
    );
}

/// What is not a results directory is refused with exit code 2 and a
/// message that says what it is and what to give instead.
#[test]
fn what_is_not_a_results_directory_is_refused() {
    let dir = scratch("view", "refused");
    let check = |args: &[&str], expected: &str| {
        let o = view(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
    };
    let missing = dir.join("nothing");
    check(&[missing.to_str().unwrap()], "nothing: no such directory");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/four_bar.toml");
    check(
        &[model.to_str().unwrap()],
        "four_bar.toml: is a file, not a results directory: run the model first",
    );
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    check(
        &[empty.to_str().unwrap()],
        "not a results directory of `unfold run`: it has neither unfold.pvd nor summary.json",
    );
    // a run rejected at its start leaves summary.json alone
    let rejected = dir.join("rejected");
    std::fs::create_dir_all(&rejected).unwrap();
    std::fs::write(
        rejected.join("summary.json"),
        r#"{"status": "failed", "message": "the structure is a mechanism"}"#,
    )
    .unwrap();
    check(
        &[rejected.to_str().unwrap()],
        "the run wrote no output step (no unfold.pvd); summary.json says status \"failed\": the structure is a mechanism",
    );
    // a damaged grid is named
    let out = deployment(&dir);
    let grid = out.join("vtk/step_00007.vtu");
    let bytes = std::fs::read(&grid).unwrap();
    std::fs::write(&grid, &bytes[..bytes.len() / 2]).unwrap();
    check(&[out.to_str().unwrap(), "--no-open"], "step_00007.vtu: ");
    check(
        &[out.to_str().unwrap(), "--max-frames", "1"],
        "--max-frames 1: give at least 2",
    );
    check(
        &[out.to_str().unwrap(), "--out", out.to_str().unwrap()],
        "is a directory",
    );
}

/// The browser to test the page in, if there is one.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("UNFOLD_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).find_map(|dir| {
        [
            "chromium",
            "chromium-browser",
            "google-chrome",
            "google-chrome-stable",
        ]
        .iter()
        .map(|n| dir.join(n))
        .find(|p| p.is_file())
    })
}

/// Window of the headless browser, CSS pixels.
const WINDOW: (u32, u32) = (1200, 800);

/// Runs headless Chromium on `url` with `what` (`--dump-dom`,
/// `--screenshot=…`), stdout into a file; its stdout. Software WebGL
/// (SwiftShader through ANGLE, which Chromium asks to be allowed
/// explicitly since version 137); `--virtual-time-budget` lets the page
/// inflate its data and draw before the picture is taken. Killed after 3
/// minutes.
fn headless(browser: &Path, profile: &Path, what: &str, url: &str) -> String {
    let stdout_path = profile.with_extension("stdout");
    let stdout = std::fs::File::create(&stdout_path).unwrap();
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--hide-scrollbars",
            "--mute-audio",
            "--no-first-run",
            "--force-device-scale-factor=1",
            &format!("--user-data-dir={}", profile.display()),
            &format!("--window-size={},{}", WINDOW.0, WINDOW.1),
            "--virtual-time-budget=5000",
            what,
            url,
        ])
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("{}: {e}", browser.display()));
    let deadline = Instant::now() + Duration::from_secs(180);
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "{} {what}: {status}", browser.display());
            break;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{} {what} {url}: no answer in 3 minutes", browser.display());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    std::fs::read_to_string(&stdout_path).unwrap()
}

/// The value of attribute `name` of the `<html>` element of a dumped DOM.
fn html_attribute<'a>(dom: &'a str, name: &str) -> Option<&'a str> {
    let start = dom.find("<html")?;
    let tag = &dom[start..start + dom[start..].find('>')?];
    let key = format!(" {name}=\"");
    let at = tag.find(&key)? + key.len();
    Some(&tag[at..at + tag[at..].find('"')?])
}

/// An RGBA picture.
struct Picture {
    width: usize,
    pixels: Vec<u8>,
}

impl Picture {
    fn read(path: &Path) -> Self {
        let mut decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().unwrap();
        let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buffer).unwrap();
        buffer.truncate(info.buffer_size());
        let channels = info.color_type.samples();
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        let pixels = buffer
            .chunks_exact(channels)
            .flat_map(|p| match channels {
                3 => [p[0], p[1], p[2], 255],
                4 => [p[0], p[1], p[2], p[3]],
                _ => panic!("{channels} channels"),
            })
            .collect();
        Self {
            width: info.width as usize,
            pixels,
        }
    }

    fn rgb(&self, x: usize, y: usize) -> [i32; 3] {
        let at = 4 * (y * self.width + x);
        [0, 1, 2].map(|c| self.pixels[at + c] as i32)
    }
}

/// The page of the deployment in headless Chromium: it loads with no
/// script error (the page records errors in `data-errors` of `<html>`;
/// that it does is checked on a page with damaged data), shows the frame
/// the address asks for, its 3-D view is not blank (pixels unlike the
/// background, of several colours), and the picture at the end differs
/// from the one at the start (the panel turned by 90°).
#[test]
fn the_page_runs_in_a_headless_browser() {
    let Some(browser) = chromium() else {
        if std::env::var_os("UNFOLD_CI").is_some() {
            panic!("UNFOLD_CI is set but no Chromium was found: .ci/run installs it (apt-get install -y chromium), or set UNFOLD_CHROMIUM to its path");
        }
        eprintln!(
            "\n\
             ************************************************************************\n\
             * SKIPPED: the viewer page was NOT tested in a browser: no Chromium on  *\n\
             * the PATH (chromium, chromium-browser, google-chrome) and no           *\n\
             * UNFOLD_CHROMIUM. Install it (apt-get install chromium) to run it.     *\n\
             ************************************************************************\n"
        );
        return;
    };
    let dir = scratch("view", "browser");
    let out = deployment(&dir);
    let page = out.join("view.html");
    let o = view(&[out.to_str().unwrap(), "--no-open"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let artifacts = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .unwrap()
        .join("artifacts/viewer");
    std::fs::create_dir_all(&artifacts).unwrap();
    std::fs::copy(&page, artifacts.join("deployment.html")).unwrap();
    let url = |fragment: &str| {
        format!(
            "file://{}#{fragment}",
            page.canonicalize().unwrap().display()
        )
    };
    let profile = |name: &str| dir.join(format!("profile-{name}"));

    // the DOM at the end, and pictures at the start and at the end, one
    // browser after the other (two headless Chromium 148 at once with a
    // virtual time budget both hung here)
    let shots = [("start", "t=0&field=M3"), ("end", "t=end&field=M3")].map(|(name, fragment)| {
        let png = artifacts.join(format!("deployment_{name}.png"));
        let _ = std::fs::remove_file(&png);
        headless(
            &browser,
            &profile(name),
            &format!("--screenshot={}", png.display()),
            &url(fragment),
        );
        png
    });
    let dom = headless(
        &browser,
        &profile("dom"),
        "--dump-dom",
        &url("t=end&field=M3&history=joints.csv:30:angle"),
    );

    // loads, with no script error, at the frame asked for
    assert_eq!(
        html_attribute(&dom, "data-errors"),
        None,
        "script errors: {}",
        &dom[..dom.len().min(4000)]
    );
    assert_eq!(
        html_attribute(&dom, "data-state"),
        Some("ready"),
        "{}",
        &dom[..dom.len().min(2000)]
    );
    let last = column(&out.join("steps.csv"), "time").len() - 1;
    assert_eq!(
        html_attribute(&dom, "data-frame"),
        Some(last.to_string().as_str())
    );
    let canvas: Vec<usize> = html_attribute(&dom, "data-canvas")
        .expect("the view's rectangle")
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let (x0, y0, w, h) = (canvas[0], canvas[1], canvas[2], canvas[3]);
    assert!(w > 300 && h > 300, "{canvas:?}");
    // the hinge's angle plotted, the hinge named by its type
    for text in [">joint 30 (revolute)<", "angle (joint 30, revolute)"] {
        assert!(dom.contains(text), "the page lacks {text:?}");
    }

    // the view drawn in each picture
    let pictures: Vec<Picture> = shots.iter().map(|png| Picture::read(png)).collect();
    let background = [247, 248, 250];
    let region = || (y0..y0 + h).flat_map(|y| (x0..x0 + w).map(move |x| (x, y)));
    let n = (w * h) as f64;
    for (name, p) in ["start", "end"].iter().zip(&pictures) {
        let mut drawn = 0;
        let mut colours = std::collections::HashSet::new();
        for (x, y) in region() {
            let c = p.rgb(x, y);
            if (0..3).any(|k| (c[k] - background[k]).abs() > 16) {
                drawn += 1;
                colours.insert(c.map(|v| v >> 4));
            }
        }
        println!(
            "{name}: {:.1} % of the view drawn, {} colours (4 bits a channel)",
            100.0 * drawn as f64 / n,
            colours.len()
        );
        assert!(drawn as f64 > 0.02 * n, "{name}: the view is blank");
        assert!(colours.len() >= 8, "{name}: {} colours", colours.len());
    }
    let changed = region()
        .filter(|&(x, y)| {
            let (a, b) = (pictures[0].rgb(x, y), pictures[1].rgb(x, y));
            (0..3).map(|k| (a[k] - b[k]).abs()).sum::<i32>() > 40
        })
        .count();
    println!(
        "{:.1} % of the view changed from the start to the end",
        100.0 * changed as f64 / n
    );
    assert!(
        changed as f64 > 0.01 * n,
        "the picture does not change with time"
    );

    // a page whose data is damaged reports the error in the DOM
    let html = std::fs::read_to_string(&page).unwrap();
    let at = html.find("id=\"data\">").unwrap() + 10;
    let broken = dir.join("broken.html");
    std::fs::write(&broken, format!("{}AAAA{}", &html[..at], &html[at + 40..])).unwrap();
    let dom = headless(
        &browser,
        &profile("broken"),
        "--dump-dom",
        &format!("file://{}#t=0", broken.canonicalize().unwrap().display()),
    );
    assert_eq!(
        html_attribute(&dom, "data-errors"),
        Some("1"),
        "{}",
        &dom[..dom.len().min(2000)]
    );
    assert_eq!(html_attribute(&dom, "data-state"), None);
    println!("pictures and page in {}", artifacts.display());
}
