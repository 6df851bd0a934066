//! The steps after a stop closes on a flexible member (docs/theory.md
//! §16.4, "Resuming after a closure"): they resume with the size of the
//! step that first crossed the stop, not growing back from the landing
//! step as after a latch's lock; measured here, they create no energy and
//! the stop's peak load does not depend on round-off.
//!
//! The arm of tests/latch_peaks.rs (a tube of 0.2 m in 4 beams, EI = 297
//! N·m², 0.0955 kg/m, a tip mass of 0.01 kg, hinged about z at its root
//! and opened from rest by a torsion spring of 0.2 N·m/rad unloaded at
//! 3 rad: work `E = ½ k (3² − 1²) = 0.8 J` up to 2 rad), stopped at 2 rad
//! by a plastic stop (`e = 0`) on its hinge instead of a latch. The stop
//! holds the hinge's node, the arm bends on, the stop's load swings
//! back to zero as the bent arm unloads, and the stop releases there
//! (docs/theory.md §16.4). Fixed steps of 0.01 s (those of the ERA
//! platform), to 0.1 s.

mod common;

use std::path::PathBuf;

use common::cli::{self, summary};
use common::stop_arm;

/// The model at `rho` (ρ∞) with a gravity `g` (m/s², along y, in the
/// plane of the motion).
fn arm(name: &str, rho: f64, g: f64) -> PathBuf {
    let dir = cli::scratch("stop-closure", name);
    let analysis = format!(
        "[analysis]
type = \"dynamic\"
end_time = 0.1
time_step = 0.01
max_step = 0.01
adaptive = false
rho_infinity = {rho:?}
"
    );
    let text = stop_arm::arm(&analysis, Some(g));
    cli::run_text(&dir, &text).0
}

/// At ρ∞ = 0.5 and 0.9, the step after each closure of the stop (which
/// resumes with the step that first crossed it: at ρ∞ = 0.9, 2.5e-3 s
/// after a landing step of 2.4e-10 s) creates at most 0.5 % of the
/// spring's work in the energy balance (measured: at ρ∞ = 0.5, E
/// unchanged in those steps, which the location of the release keeps to
/// 4e-8 s; at ρ∞ = 0.9, one closure to 0.1 s, the step after it losing
/// 7.7e-3 J, the ringing the long step damps); and a gravity of
/// 1e-14 m/s², a perturbation at round-off, leaves the stop's peak load
/// unchanged to 1e-9 relative (measured 2.0e-14 at ρ∞ = 0.5 and 1.7e-12
/// at 0.9; the locks' peaks before their regrowth bound moved by tens of
/// percent under the same perturbation, tests/latch_peaks.rs).
#[test]
fn the_steps_after_a_stop_closes_on_a_flexible_arm_create_no_energy() {
    let work = stop_arm::WORK;
    for rho in [0.5, 0.9] {
        let mut peaks = Vec::new();
        for (name, g) in [("exact", 0.0), ("perturbed", 1e-14)] {
            let out = arm(&format!("{rho}-{name}"), rho, g);
            let balance = cli::column(&out.join("energies.csv"), "balance_error");
            let events = cli::csv_rows(&out.join("events.csv"));
            let closures: Vec<usize> = events
                .iter()
                .filter(|e| e["kind"] == "contact")
                .map(|e| e["step"].parse().unwrap())
                .collect();
            // at least the arrival (at ρ∞ = 0.5 the hinge node is struck
            // once more as the arm leaves; at 0.9 the release leaves at once)
            assert!(!closures.is_empty(), "{rho} {name}: {closures:?}");
            for &k in &closures {
                let Some(after) = balance.get(k + 1) else {
                    continue;
                };
                let rise = after - balance[k];
                eprintln!(
                    "ρ∞ = {rho} {name}: the step after the closure at step {k}: E {rise:+.3e} J"
                );
                assert!(
                    rise <= 5e-3 * work,
                    "ρ∞ = {rho} {name}: the step after the closure at step {k} created {rise} J"
                );
            }
            let s = summary(&out);
            let stop = &s["stops"][0];
            peaks.push(stop["peak_load"].as_f64().unwrap());
        }
        eprintln!("ρ∞ = {rho}: peaks {peaks:?}");
        assert!(
            (peaks[0] - peaks[1]).abs() <= 1e-9 * peaks[0].abs(),
            "ρ∞ = {rho}: {peaks:?}"
        );
    }
}
