//! The solar array of the reference paper (§6.3; examples/solar_array.toml
//! and examples/solar_array_rigid.toml, examples/solar_array.md): both
//! models run to the paper's 47 s through the command line, and what can
//! be checked against the paper and against mechanics is checked.

use std::path::{Path, PathBuf};
use std::process::Command;

#[allow(dead_code)]
#[path = "vtk_reader/mod.rs"]
mod vtk_reader;

fn run(example: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("unfold-solar-{}-{example}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            root.join("examples")
                .join(format!("{example}.toml"))
                .to_str()
                .unwrap(),
        ])
        .args(["--out", out.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    out
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// The lock time of each active hinge's latch (32, 33, 34).
fn locks(s: &serde_json::Value) -> Vec<f64> {
    let latches = s["latches"].as_array().unwrap();
    assert_eq!(latches.len(), 3);
    latches
        .iter()
        .map(|l| l["locked_at"].as_f64().expect("every active hinge locks"))
        .collect()
}

/// The angle of each active hinge (joints 2, 3, 4) at the last step.
fn final_angles(out: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(out.join("joints.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let angle = header.iter().position(|c| *c == "angle").unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let last = rows.last().unwrap()[0];
    [2, 3, 4]
        .iter()
        .map(|j| {
            let r = rows
                .iter()
                .find(|r| r[0] == last && r[2] == j.to_string())
                .unwrap();
            r[angle].parse().unwrap()
        })
        .collect()
}

/// Both models to 47 s.
///
/// - The flexible array has 28 dofs a panel, as the paper's (§6.3: four
///   connection nodes and four internal modes).
/// - Every active hinge deploys and locks. Its regulator makes the
///   deployment quasi-steady: the rate is `M_d / c` = 1/25 rad/s while
///   the spring drives, so the lock comes at `c_L c / M_d` = 39.27 s;
///   measured 39.04 to 40.31 s, within 5 % (the estimate leaves out the
///   panels' acceleration at the start and the last 5 mrad before the
///   lock, where the tape spring's locked branch takes the moment down
///   to zero). The paper's lock at 41 s is within the same 5 %: its law
///   and regulator are not given (figure 10 has no values), ours are
///   chosen for its timing (examples/solar_array.md).
/// - After 47 s each hinge stays locked at 90° (within 0.01 rad: the
///   locked branch and the pawl hold it; measured within 1e-3).
/// - The rigid panels give the same lock times within 1 % (measured
///   0.003 to 0.06 s): the panels' first free-free mode, 51 Hz, is three
///   orders above the deployment's rates; the flexibility shows in the
///   stresses, not in the kinematics.
/// - The energy balance closes within 1e-3 of the work of the springs
///   (3 × 1 N·m × π/2 = 4.7 J; measured 2.2e-4 J).
/// - The flexible run reports the peak skin stresses of every panel with
///   the element, the layer and the time (paper figure 15), and the VTK
///   files draw the panels' shells with their skin stresses.
/// - Newton takes fewer iterations a step than the paper's 5.1 (measured
///   2.9).
#[test]
fn solar_array_deploys_and_locks_as_the_paper_says() {
    let flexible = run("solar_array");
    let rigid = run("solar_array_rigid");
    let (sf, sr) = (summary(&flexible), summary(&rigid));
    for s in [&sf, &sr] {
        assert_eq!(s["status"], "completed");
        assert_eq!(s["final_time"].as_f64().unwrap(), 47.0);
    }

    // 28 dofs a panel
    let panels = sf["superelements"].as_array().unwrap();
    assert_eq!(panels.len(), 5);
    for p in panels {
        let dofs = 6 * p["boundary_nodes"].as_array().unwrap().len()
            + p["modes"].as_u64().unwrap() as usize;
        assert_eq!(dofs, 28);
    }

    // lock times against the quasi-steady estimate and the paper
    let (lf, lr) = (locks(&sf), locks(&sr));
    println!(
        "unknowns {} (rigid {}), steps {}, iterations a step {:.2}, wall {:.2} s (rigid {:.2} s); locks {lf:?} (rigid {lr:?})",
        sf["dofs"], sr["dofs"], sf["increments"], sf["average_iterations"].as_f64().unwrap(),
        sf["wall_time_s"].as_f64().unwrap(), sr["wall_time_s"].as_f64().unwrap()
    );
    let estimate = std::f64::consts::FRAC_PI_2 * 25.0 / 1.0;
    for (f, r) in lf.iter().zip(&lr) {
        assert!(
            (f / estimate - 1.0).abs() < 0.05,
            "lock at {f} s against {estimate}"
        );
        assert!(
            (f / 41.0 - 1.0).abs() < 0.05,
            "lock at {f} s against the paper's 41 s"
        );
        assert!((f - r).abs() < 0.01 * f, "flexible {f} s, rigid {r} s");
    }
    for out in [&flexible, &rigid] {
        for c in final_angles(out) {
            assert!(
                (c - std::f64::consts::FRAC_PI_2).abs() < 0.01,
                "final angle {c}"
            );
        }
    }

    // energy balance
    let work = 3.0 * std::f64::consts::FRAC_PI_2;
    for s in [&sf, &sr] {
        let e = s["analyses"][0]["dynamic"]["energy_balance_error"]
            .as_f64()
            .unwrap();
        assert!(e.abs() < 1e-3 * work, "energy balance error {e} J");
    }

    // skin stresses: every panel's peak, where and when
    for p in panels {
        let peaks = p["peaks"].as_array().unwrap();
        let top = peaks
            .iter()
            .find(|q| q["quantity"] == "top_skin_von_mises")
            .expect("top skin peak");
        println!("superelement {}: {top}", p["superelement"]);
        assert!(top["value"].as_f64().unwrap() > 0.0);
        assert_eq!(top["kind"], "shell");
        assert!(top["layer"].as_u64().is_some());
        assert!(top["time"].as_f64().unwrap() > 0.0);
    }
    let mut grids: Vec<PathBuf> = std::fs::read_dir(flexible.join("vtk"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "vtu"))
        .collect();
    grids.sort();
    // the last grid: the central panel's shells (superelement 103) drawn
    // with their skin stresses
    let grid = vtk_reader::read(grids.last().unwrap());
    let (owners, _) = grid.array("superelement_id");
    let (kinds, _) = grid.array("kind");
    let (skins, _) = grid.array("skin_von_mises");
    let (principal, _) = grid.array("top_skin_principal");
    let central: Vec<usize> = (0..owners.len())
        .filter(|&c| owners[c] == 103.0 && kinds[c] == 15.0)
        .collect();
    assert_eq!(central.len(), 96, "12 × 8 shells");
    let top = central
        .iter()
        .map(|&c| skins[2 * c + 1])
        .fold(0.0, f64::max);
    println!("central panel at 47 s: top skin von Mises up to {top:.4e} Pa");
    assert!(top > 0.0 && top.is_finite());
    for &c in &central {
        // von Mises within the principal stresses' bounds:
        // max(|σ₁|, |σ₂|, |σ₁ − σ₂|) ≥ σ_vm ≥ … ≥ 0
        let (s1, s2) = (principal[2 * c], principal[2 * c + 1]);
        assert!(s1 >= s2);
        let vm = (s1 * s1 - s1 * s2 + s2 * s2).sqrt();
        assert!((vm - skins[2 * c + 1]).abs() <= 1e-9 * vm.max(1.0));
    }

    assert!(sf["average_iterations"].as_f64().unwrap() < 5.1);
}
