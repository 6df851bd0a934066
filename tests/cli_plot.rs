//! `unfold plot` (docs/plots.md): the charts of a dynamic run with a latch
//! and of a static run, drawn from their result files — the files, their
//! size and content, the axes with their units, the lock instants — and
//! its errors on bad input (exit code 2, the file named).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("unfold-plot-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn unfold(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs the model `text` (written into `dir/model.toml`) into `dir/out`.
fn run_model(dir: &Path, text: &str) -> (PathBuf, Output) {
    let model = dir.join("model.toml");
    std::fs::write(&model, text).unwrap();
    let out = dir.join("out");
    let o = unfold(&["run", s(&model), "--out", s(&out), "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    (out, o)
}

/// The two panels of tests/data/latched_panels.toml, run to 0.05 s (the
/// latch locks at about 0.04 s), with `output` appended.
fn latched_panels(dir: &Path, output: &str) -> (PathBuf, Output) {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/latched_panels.toml"),
    )
    .unwrap()
    .replace("end_time = 0.1", "end_time = 0.05");
    run_model(dir, &(text + output))
}

/// A static run with a hinge law and a driver on one revolute joint: the
/// link of examples/hinge_lock_cycle.toml driven to 96° and back in 40
/// increments.
fn driven_hinge(dir: &Path, output: &str) -> (PathBuf, Output) {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hinge_lock_cycle.toml"),
    )
    .unwrap()
    .replace("initial_increment = 0.01", "initial_increment = 0.1")
    .replace("max_increment = 0.01", "max_increment = 0.1");
    run_model(dir, &(text + output))
}

/// Decodes a PNG file: its size and RGB pixels.
fn decode_png(path: &Path) -> ((u32, u32), Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
    pixels.truncate(info.buffer_size());
    ((info.width, info.height), pixels)
}

/// A PNG chart of the stated size with the first series' colour on it
/// (plot.rs: COLOURS[0]) and a fair share of non-white pixels.
fn assert_drawn_png(path: &Path) {
    let (size, pixels) = decode_png(path);
    assert_eq!(size, unfold::io::plot::SIZE, "{}", path.display());
    let rgb: Vec<&[u8]> = pixels.chunks(3).collect();
    let inked = rgb.iter().filter(|p| p != &&[255, 255, 255]).count();
    // axes, grid, labels and curves cover well over 1 % of the picture
    assert!(
        inked > rgb.len() / 100,
        "{}: {inked} of {} pixels drawn",
        path.display(),
        rgb.len()
    );
    let series = rgb.iter().filter(|p| p == &&[31, 119, 180]).count();
    assert!(series > 100, "{}: first series {series} px", path.display());
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The dynamic run: every chart in both formats, PNG of the stated size
/// and drawn, SVG with titles, axes with units, legends and the lock
/// instant; angles in degrees on request; the events of `events.csv`.
#[test]
fn dynamic_run_with_a_latch() {
    let dir = scratch("dynamic");
    let (out, run) = latched_panels(&dir, "\n[output]\nplots = [\"joints\", \"energies\"]\n");

    // the charts of `[output] plots`, written by the run
    let mut written: Vec<String> = std::fs::read_dir(out.join("plots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    assert_eq!(
        written,
        [
            "energies.png",
            "energies.svg",
            "energy_balance_error.png",
            "energy_balance_error.svg",
            "joint_10.png",
            "joint_10.svg"
        ]
    );
    assert!(
        stderr(&run).contains("plots: 6 files in"),
        "{}",
        stderr(&run)
    );
    assert_drawn_png(&out.join("plots/joint_10.png"));

    let plots = dir.join("plots");
    let o = unfold(&["plot", s(&out), "--out", s(&plots)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let listed = String::from_utf8_lossy(&o.stdout).into_owned();
    for name in [
        "joint_10",
        "moments_joint_10",
        "energies",
        "energy_balance_error",
    ] {
        for ext in ["png", "svg"] {
            let path = plots.join(format!("{name}.{ext}"));
            assert!(path.is_file(), "{} missing", path.display());
            assert!(listed.contains(s(&path)), "{listed}");
        }
        assert_drawn_png(&plots.join(format!("{name}.png")));
    }
    assert_eq!(std::fs::read_dir(&plots).unwrap().count(), 8);

    let joint = read(&plots.join("joint_10.svg"));
    for text in [
        "Joint 10 (revolute): angle",
        "time t (s)",
        "angle (rad)",
        "latch 20 locks",
    ] {
        assert!(joint.contains(text), "joint_10.svg lacks {text:?}");
    }
    let moments = read(&plots.join("moments_joint_10.svg"));
    for text in [
        "moment (N·m)",
        "spring 11, angle",
        "latch 20, angle",
        "latch 20 locks",
    ] {
        assert!(
            moments.contains(text),
            "moments_joint_10.svg lacks {text:?}"
        );
    }
    let energies = read(&plots.join("energies.svg"));
    for text in [
        "energy (J)",
        "kinetic T",
        "springs",
        "dissipated D",
        "latch 20 locks",
    ] {
        assert!(energies.contains(text), "energies.svg lacks {text:?}");
    }
    let balance = read(&plots.join("energy_balance_error.svg"));
    assert!(balance.contains("E (J)") && balance.contains("balance error E"));

    // in degrees, only the joints, SVG only
    let deg = dir.join("deg");
    let o = unfold(&[
        "plot",
        s(&out),
        "joints",
        "--degrees",
        "--format",
        "svg",
        "--out",
        s(&deg),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<String> = std::fs::read_dir(&deg)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["joint_10.svg"]);
    assert!(read(&deg.join("joint_10.svg")).contains("angle (°)"));

    // events.csv: one at the lock (the latch's line takes its energy), one
    // later at the joint
    let lock_time: f64 = read(&out.join("latches.csv"))
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|f| f[4].parse::<f64>().unwrap() == 1.0)
        .map(|f| f[1].parse().unwrap())
        .expect("the latch locks");
    std::fs::write(
        out.join("events.csv"),
        format!("time,joint,energy_lost\n{lock_time:e},10,2.25\n0.045,10,\n"),
    )
    .unwrap();
    let ev = dir.join("events");
    let o = unfold(&["plot", s(&out), "--format", "svg", "--out", s(&ev)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let joint = read(&ev.join("joint_10.svg"));
    assert!(joint.contains("latch 20 locks, 2.25 J lost"), "{joint}");
    assert_eq!(joint.matches("locks").count(), 1);
    assert!(joint.contains("event at joint 10"));
}

/// The static run: the load parameter on the x axis, the hinge law's and
/// the driver's moments, no energies; bad input fails with exit code 2
/// and names what is wrong.
#[test]
fn static_run_and_bad_input() {
    let dir = scratch("static");
    // `[output] plots` asks for energies, which a static run does not have
    let (out, run) = driven_hinge(&dir, "\n[output]\nplots = [\"energies\"]\n");
    assert!(
        stderr(&run).contains("note: plots: no energies chart"),
        "{}",
        stderr(&run)
    );
    assert!(!out.join("plots").exists());
    let plots = dir.join("plots");
    let o = unfold(&["plot", s(&out), "--out", s(&plots), "--format", "both"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["joint_1", "moments_joint_1"] {
        assert_drawn_png(&plots.join(format!("{name}.png")));
    }
    assert!(!plots.join("energies.svg").exists());
    let joint = read(&plots.join("joint_1.svg"));
    assert!(joint.contains("load parameter t (–)") && joint.contains("angle (rad)"));
    let moments = read(&plots.join("moments_joint_1.svg"));
    for text in ["moment (N·m)", "hinge law 2, angle", "driver 3, angle"] {
        assert!(moments.contains(text), "moments_joint_1.svg lacks {text:?}");
    }

    let fails = |args: &[&str], expected: &[&str]| {
        let o = unfold(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        for text in expected {
            assert!(e.contains(text), "{args:?}: {e:?} lacks {text:?}");
        }
    };
    // energies of a static run
    fails(
        &["plot", s(&out), "energies"],
        &["energies", "energies.csv"],
    );
    // a joint that is not in the results
    fails(
        &["plot", s(&out), "--joint", "7"],
        &["joint 7", "joints.csv", "its joints: 1"],
    );
    // an unknown kind of chart
    fails(
        &["plot", s(&out), "stresses"],
        &["stresses", "joints, moments or energies"],
    );
    // a missing directory, a directory without results
    let missing = dir.join("nowhere");
    fails(&["plot", s(&missing)], &[s(&missing), "no such directory"]);
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    fails(&["plot", s(&empty)], &[s(&empty), "no results"]);
    // a malformed line of joints.csv, and a missing column
    let joints = read(&out.join("joints.csv"));
    let mut lines: Vec<String> = joints.lines().map(str::to_string).collect();
    lines[2] = lines[2].replacen(",1,", ",1,x.5,", 1);
    std::fs::write(out.join("joints.csv"), lines.join("\n")).unwrap();
    fails(&["plot", s(&out)], &["joints.csv, line 3", "fields"]);
    let mut cells: Vec<String> = joints
        .lines()
        .nth(2)
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    assert_eq!(lines[0].split(',').nth(4), Some("angle"));
    cells[4] = "1.2.3".into();
    lines[2] = cells.join(",");
    std::fs::write(out.join("joints.csv"), lines.join("\n")).unwrap();
    fails(
        &["plot", s(&out)],
        &["joints.csv, line 3", "`angle`", "\"1.2.3\" is not a number"],
    );
    let mut cells: Vec<&str> = joints.lines().nth(2).unwrap().split(',').collect();
    cells[3] = "hinge";
    lines[2] = cells.join(",");
    std::fs::write(out.join("joints.csv"), lines.join("\n")).unwrap();
    fails(
        &["plot", s(&out)],
        &[
            "joints.csv, line 3",
            "`type`",
            "\"hinge\" is not a joint type",
        ],
    );
    // a joints.csv of an earlier version, with coordinates c1…c3
    std::fs::write(
        out.join("joints.csv"),
        "step,time,joint,c1,c2,c3\n0,0,10,0.5,,\n",
    )
    .unwrap();
    fails(
        &["plot", s(&out)],
        &["joints.csv, line 1", "`c1`", "run the model again"],
    );
    std::fs::write(out.join("joints.csv"), "step,joint\n0,1\n").unwrap();
    fails(
        &["plot", s(&out)],
        &["joints.csv, line 1", "no column `time`"],
    );
}

/// One sign convention on the moments chart: each curve is the moment its
/// element applies on the joint's second body, positive increasing the
/// coordinate. In the static equilibrium of the driven hinge (no other
/// load on the link) the driver's moment balances the hinge law's, so the
/// two curves are opposite at every step (to the residual tolerance,
/// 1e-6 of the 10 N·m peak). The hinge-law chart draws `M` (as in
/// hinge_laws.csv) against the angle, with `∫ M dc` over the run in the
/// legend and the latch's angle marked.
#[test]
fn moments_share_one_sign_convention_and_hinge_laws_draw_their_loop() {
    use unfold::io::histories::{Group, Histories, Request};

    let dir = scratch("convention");
    // a latch at 90° on the hinge (a static run passes it with a note)
    let latch = "\n[[latches]]\nid = 9\njoint = 1\nvalue = 90.0\nunit = \"deg\"\n";
    let (out, _) = driven_hinge(&dir, latch);
    let h = Histories::read(&out, None).unwrap();
    let figures = h
        .figures(&Request {
            groups: vec![Group::Moments, Group::HingeLaws],
            ..Request::default()
        })
        .unwrap();
    let moments = &figures
        .iter()
        .find(|f| f.name == "moments_joint_1")
        .expect("moments chart")
        .chart;
    let series = |label: &str| {
        moments
            .series
            .iter()
            .find(|s| s.label == label)
            .unwrap_or_else(|| panic!("no {label:?}"))
            .points
            .clone()
    };
    let (law, driver) = (series("hinge law 2, angle"), series("driver 3, angle"));
    assert_eq!(law.len(), driver.len());
    let peak = law.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    assert!(peak > 9.0, "the law reaches its locking peak: {peak}");
    for (a, b) in law.iter().zip(&driver) {
        assert!(
            (a.1 + b.1).abs() < 1e-6 * peak,
            "t = {}: {} + {}",
            a.0,
            a.1,
            b.1
        );
    }
    // the law's curve is minus the file's M (positive resisting an increase)
    let file = read(&out.join("hinge_laws.csv"));
    let rows: Vec<(f64, f64)> = file
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (f[3], f[4])
        })
        .collect();
    assert_eq!(rows.len(), law.len());
    for (r, p) in rows.iter().zip(&law) {
        assert_eq!(p.1, -r.1);
    }

    // the loop: (c, M) of the file, the work by the trapezoidal rule
    let hinge = &figures
        .iter()
        .find(|f| f.name == "hinge_law_2")
        .expect("hinge-law chart")
        .chart;
    assert_eq!(hinge.series[0].points, rows);
    let work: f64 = rows
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum();
    assert!(work > 0.0, "a hysteresis loop dissipates: {work}");
    assert!(
        hinge.series[0].label.contains("∫ M dc = "),
        "{:?}",
        hinge.series[0].label
    );
    assert_eq!(hinge.x.label(), "angle (rad)");
    assert_eq!(hinge.y.label(), "moment M (N·m)");
    assert_eq!(hinge.events.len(), 1);
    assert!((hinge.events[0].0 - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(hinge.events[0].1, "latch 9 locks at 1.571 rad");

    // the command line: `hinge_laws` is a kind of chart, in degrees
    let plots = dir.join("plots");
    let o = unfold(&[
        "plot",
        s(&out),
        "hinge_laws",
        "--degrees",
        "--out",
        s(&plots),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_drawn_png(&plots.join("hinge_law_2.png"));
    let svg = read(&plots.join("hinge_law_2.svg"));
    for text in ["angle (°)", "moment M (N·m)", "latch 9 locks at 90 °"] {
        assert!(svg.contains(text), "hinge_law_2.svg lacks {text:?}");
    }
}

/// Many events close together are labelled once as a group: 13 impacts
/// whose intervals halve (a ball coming to rest) give a few labels, the
/// last of which counts the group and gives its interval and loss; every
/// impact keeps its line.
#[test]
fn close_events_are_labelled_as_a_group() {
    use unfold::io::histories::{Group, Histories, Request};

    let dir = scratch("groups");
    let (out, _) = latched_panels(&dir, "");
    let mut csv = String::from("time,joint,event,energy_lost\n");
    for k in 0..13 {
        let t = 0.005 + 0.03 * (1.0 - 0.5f64.powi(k));
        csv += &format!("{t:e},10,impact,1.0\n");
    }
    std::fs::write(out.join("events.csv"), csv).unwrap();
    let h = Histories::read(&out, None).unwrap();
    let figures = h
        .figures(&Request {
            groups: vec![Group::Joints],
            ..Request::default()
        })
        .unwrap();
    let chart = &figures[0].chart;
    let impacts = chart
        .events
        .iter()
        .filter(|e| e.1 != "latch 20 locks")
        .count();
    // 13 impact lines, and the lock's (its label may join a group)
    assert_eq!(chart.events.len(), 14);
    assert!(impacts >= 13);
    let labels: Vec<&str> = chart
        .events
        .iter()
        .map(|e| e.1.as_str())
        .filter(|l| !l.is_empty())
        .collect();
    assert!(labels.len() <= 6, "{labels:?}");
    let group = labels
        .iter()
        .find(|l| l.contains("impacts at joint 10"))
        .unwrap_or_else(|| panic!("no group label in {labels:?}"));
    assert!(
        group.contains(" s, ") && group.contains(" J lost"),
        "{group}"
    );
}

/// `--model` naming a file that cannot be read is an error (exit 2), and
/// a missing joints.csv is named as missing, not as a model without
/// joints.
#[test]
fn a_missing_model_file_or_joints_csv_is_named() {
    let dir = scratch("missing");
    let (out, _) = latched_panels(&dir, "");
    let none = dir.join("none.toml");
    let o = unfold(&["plot", s(&out), "--model", s(&none)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!(
            "error: --model {}: cannot read the model file",
            s(&none)
        )),
        "{}",
        stderr(&o)
    );
    std::fs::remove_file(out.join("joints.csv")).unwrap();
    let o = unfold(&["plot", s(&out), "joints"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("joints.csv is missing from")
            && stderr(&o).contains("although the model has joints"),
        "{}",
        stderr(&o)
    );
}
