//! Hinge laws with memory (docs/joints.md §4.1): the consistent tangent on
//! every branch, the energy dissipated by closed quasi-static cycles, the
//! branch state across cut-back increments, the tape-spring shape, and the
//! input errors.
//!
//! The test hinge is a node hinged to the ground about z (its translations
//! fixed), its angle `c` moved by a driver, with a tape-spring law:
//! `M_d = 0.3 N·m`, `c_L = 1.5 rad`, `M_L = 10 N·m`, `K = 100 N·m/rad`,
//! `w = 0.1 rad`. Then `c_a = c_L − M_d/K = 1.497`,
//! `c_u = c_L − M_L/K = 1.4` and the snap starts at `c_u − w = 1.3`; the
//! hysteresis band is `[1.3 − h, 1.497 + h]`. The elastic slope
//! `k_e = 200 N·m/rad` is steeper than every slope of the bounds (100 and
//! 97), so the return map is exact for any increment over which `c` is
//! monotone (docs/joints.md §4.1).

use std::sync::Arc;

use unfold::analysis::observers::History;
use unfold::analysis::{IncrementInfo, StaticAnalysis, StaticSettings};
use unfold::elements::{ElementKind, ElementOutput, Need};
use unfold::model::builder::*;
use unfold::model::Model;
use unfold::state::State;

const MD: f64 = 0.3;
const CL: f64 = 1.5;
const ML: f64 = 10.0;
const K: f64 = 100.0;
const W: f64 = 0.1;
const KE: f64 = 200.0;

fn tape(rounding: Option<f64>) -> TapeSpring {
    TapeSpring {
        deployment_moment: MD,
        locking_angle: CL,
        locking_peak: ML,
        locked_stiffness: K,
        snap_width: W,
        rounding,
    }
}

/// The driven hinge: the driver's angle is `curve(t)` (rad).
fn driven_hinge(law: impl FnOnce(JointHandle) -> HingeLaw, curve: &[[f64; 2]]) -> ModelBuilder {
    let mut m = ModelBuilder::new("driven hinge");
    let n = m.node([0.0, 0.0, 0.0]);
    let hinge = m.add(Joint::revolute(n, Ground).axis([0.0, 0.0, 1.0]));
    m.add(law(hinge).id(50));
    let path = m.curve(LoadCurve::points(curve.to_vec()).named("path"));
    m.add(Driver::on(hinge).angle(1.0, AngleUnit::Rad).curve(path));
    m.fix(n, Dofs::TRANSLATIONS);
    m
}

fn settings(m: &ModelBuilder, analysis: Analysis) -> StaticSettings {
    let mut m = m.clone();
    m.analysis(
        analysis
            .residual_tolerance(1e-12)
            .displacement_tolerance(1e-12)
            .rotation_tolerance(1e-12),
    );
    m.analyses().unwrap()[0].as_static().unwrap().clone()
}

/// A row of hinge_laws.csv: (t, coordinate, moment, branch).
type Row = (f64, f64, f64, f64);

/// The hinge-law results at every converged increment, and the history.
fn run(m: &ModelBuilder, s: StaticSettings) -> (Vec<Row>, History) {
    let model = Arc::new(m.build().expect("valid model"));
    let mut history = History::with_states();
    let outcome = StaticAnalysis::new(model.clone(), s).run(model.initial_state(), &mut history);
    assert!(outcome.error.is_none(), "{:?}", outcome.error);
    let rows = history
        .increments
        .iter()
        .zip(&history.states)
        .map(|(i, st): (&IncrementInfo, &State)| {
            let r = hinge_results(&model, i.time, st);
            (i.time, r[0], r[1], r[2])
        })
        .collect();
    (rows, history)
}

fn hinge_results(model: &Model, t: f64, s: &State) -> [f64; 3] {
    let ctx = model.context(t, Need::RESIDUAL);
    let e = model
        .elements
        .iter()
        .find(|e| e.kind() == ElementKind::HingeLaw)
        .unwrap();
    assert_eq!(e.result_names(), ["coordinate", "moment", "branch"]);
    let mut out = [0.0; 3];
    e.results(&ctx, s, &mut out);
    out
}

/// `∮ M dc` by the trapezoidal rule over `rows`.
fn work(rows: &[Row]) -> f64 {
    rows.windows(2)
        .map(|w| 0.5 * (w[0].2 + w[1].2) * (w[1].1 - w[0].1))
        .sum()
}

/// Area enclosed by the tape-spring loop: between `f_load` and
/// `f_unload`, `½(M_L − M_d)(w + (M_L − M_d)/K)` for sharp corners (a
/// triangle over the snap, one over the locked branch); the rounding of a
/// corner where the slope jumps by `Δs` changes the area under its branch
/// by `Δs h²/6`, and these changes cancel: `+K` on the loading bound,
/// `−S` and `K + S` on the unloading bound.
fn loop_area() -> f64 {
    0.5 * (ML - MD) * (W + (ML - MD) / K)
}

/// A full quasi-static cycle 0 → 1.6 → 0 rad through the band and the
/// locked branch: the work done on the hinge equals the loop area. The
/// path is coarse outside the band (where the moment is constant) and
/// fine through it: Δc ≈ 9e-5 rad, for which the trapezoidal error at the
/// kinks of M(c) (slope jumps ≤ 300 N·m/rad) is ≤ 300·Δc²/8 ≈ 3e-7 N·m·rad
/// each. Tolerance: 1e-6 of the area (brief), measured ~1e-8.
#[test]
fn closed_cycle_dissipates_the_loop_area() {
    let curve = [[0.0, 0.0], [1.0, 1.25], [3.0, 1.6], [5.0, 1.25], [6.0, 0.0]];
    let m = driven_hinge(|j| HingeLaw::on(j, KE).tape_spring(tape(None)), &curve);
    let dt = 5e-4;
    let s = settings(
        &m,
        Analysis::statics()
            .end_time(6.0)
            .initial_increment(dt)
            .max_increment(dt)
            .output_times([1.0, 3.0, 5.0, 6.0]),
    );
    let (rows, history) = run(&m, s);
    assert!(history.cutbacks.is_empty());
    let computed = work(&rows);
    let area = loop_area();
    let err = (computed - area).abs() / area;
    println!("loop area {area:.12} N·m·rad, ∮M dc {computed:.12}, relative error {err:.2e}");
    // source: the loop area above; tolerance 1e-6 relative (brief)
    assert!(err < 1e-6, "∮ M dc = {computed}, area {area}");
    // the cycle visits both bounds inside the band (turning outside it,
    // on the locked branch, it is never elastic: k_e is steeper than the
    // bounds)
    for b in [1.0, -1.0] {
        assert!(
            rows.iter().any(|r| r.3 == b && r.1 > 1.31 && r.1 < 1.49),
            "branch {b} never seen in the band"
        );
    }
    // back at c = 0 on the deployment moment
    let last = rows.last().unwrap();
    assert!(
        last.1.abs() < 1e-10 && (last.2 + MD).abs() < 1e-12,
        "{last:?}"
    );
}

/// A cycle 1.2 → 1.45 → 1.2 rad that turns inside the band, sharp
/// corners: up on `f_load = −M_d`; down elastic (slope k_e) from
/// `(1.45, −M_d)` until it meets the locked branch at
/// `c* = (M_d + k_e·1.45 − K c_L)/(k_e − K) = 1.403`, then `f_unload`
/// through `(c_u, −M_L)` and the snap back to `(1.3, −M_d)`. The work done
/// on the hinge is `∮ M dc` along this polygon (exact for straight edges).
/// Step Δc = 6.25e-5 rad in the cycle; tolerance 1e-6 relative (brief).
#[test]
fn cycle_turning_inside_the_band_dissipates_its_loop_area() {
    let curve = [[0.0, 0.0], [1.0, 1.2], [3.0, 1.45], [5.0, 1.2]];
    let m = driven_hinge(|j| HingeLaw::on(j, KE).tape_spring(tape(Some(0.0))), &curve);
    let dt = 5e-4;
    let s = settings(
        &m,
        Analysis::statics()
            .end_time(5.0)
            .initial_increment(dt)
            .max_increment(dt)
            .output_times([1.0, 3.0, 5.0]),
    );
    let (rows, _) = run(&m, s);
    let cycle: Vec<Row> = rows.into_iter().filter(|r| r.0 >= 1.0 - 1e-12).collect();
    let computed = work(&cycle);
    let c_star = (MD + KE * 1.45 - K * CL) / (KE - K);
    let (cu, cs) = (CL - ML / K, CL - ML / K - W);
    let polygon = [
        (1.2, -MD),
        (1.45, -MD),
        (c_star, K * (c_star - CL)),
        (cu, -ML),
        (cs, -MD),
        (1.2, -MD),
    ];
    let area: f64 = polygon
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum();
    let err = (computed - area).abs() / area;
    println!(
        "c* = {c_star:.6}: loop area {area:.12}, ∮M dc {computed:.12}, relative error {err:.2e}"
    );
    // source: the polygon above; tolerance 1e-6 relative (brief)
    assert!(err < 1e-6, "∮ M dc = {computed}, area {area}");
    // the descent starts elastic, then follows the unloading bound
    assert!(cycle.iter().any(|r| r.3 == 0.0 && r.1 > c_star));
    assert!(cycle.iter().any(|r| r.3 == -1.0 && r.1 < c_star));
}

/// The same loop with sharp corners (rounding 0) and with wide rounded
/// corners (h = 0.02 rad): the area does not depend on the rounding
/// (`loop_area`). Tolerance 1e-6 relative as above.
#[test]
fn loop_area_does_not_depend_on_the_rounding() {
    let curve = [[0.0, 0.0], [1.0, 1.25], [3.0, 1.6], [5.0, 1.25], [6.0, 0.0]];
    for h in [0.0, 0.02] {
        let m = driven_hinge(|j| HingeLaw::on(j, KE).tape_spring(tape(Some(h))), &curve);
        let dt = 5e-4;
        let s = settings(
            &m,
            Analysis::statics()
                .end_time(6.0)
                .initial_increment(dt)
                .max_increment(dt)
                .output_times([1.0, 3.0, 5.0, 6.0]),
        );
        let (rows, _) = run(&m, s);
        let (computed, area) = (work(&rows), loop_area());
        let err = (computed - area).abs() / area;
        println!("rounding {h}: ∮M dc {computed:.12}, area {area:.12}, relative error {err:.2e}");
        // source: loop_area; tolerance 1e-6 relative (brief)
        assert!(err < 1e-6, "rounding {h}: ∮ M dc = {computed}, area {area}");
    }
}

/// Cycles that stay on one branch dissipate nothing: 0 → 1.2 → 0 rad
/// below the band (both bounds −M_d), 1.55 → 1.6 → 1.55 on the locked
/// branch, and an elastic excursion inside the band (1.35 → 1.34 → 1.35
/// from the loading bound, which stays above the unloading bound at
/// −4.18 N·m). Tolerance: |∮ M dc| ≤ 1e-9 × the scale max|M|·Δc.
#[test]
fn cycles_on_one_branch_dissipate_nothing() {
    let cases: [(&str, Vec<[f64; 2]>, f64, f64); 3] = [
        (
            "below the band",
            vec![[0.0, 0.0], [1.0, 1.2], [2.0, 0.0]],
            0.0,
            2.0,
        ),
        (
            "locked branch",
            vec![[0.0, 0.0], [1.0, 1.55], [2.0, 1.6], [3.0, 1.55]],
            1.0,
            3.0,
        ),
        (
            "elastic inside the band",
            vec![[0.0, 0.0], [1.0, 1.35], [2.0, 1.34], [3.0, 1.35]],
            1.0,
            3.0,
        ),
    ];
    for (name, curve, from, to) in cases {
        let m = driven_hinge(|j| HingeLaw::on(j, KE).tape_spring(tape(None)), &curve);
        let s = settings(
            &m,
            Analysis::statics()
                .end_time(to)
                .initial_increment(0.01)
                .max_increment(0.01)
                .output_times(if to > 2.0 {
                    vec![1.0, 2.0, to]
                } else {
                    vec![1.0, to]
                }),
        );
        let (rows, _) = run(&m, s);
        let cycle: Vec<Row> = rows
            .into_iter()
            .filter(|r| r.0 >= from - 1e-12 && r.0 <= to + 1e-12)
            .collect();
        let (first, last) = (cycle[0], *cycle.last().unwrap());
        assert!((first.1 - last.1).abs() < 1e-10, "{name}: not closed");
        let c_range = cycle.iter().map(|r| r.1).fold(f64::NEG_INFINITY, f64::max)
            - cycle.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
        let scale = cycle.iter().map(|r| r.2.abs()).fold(0.0, f64::max) * c_range;
        let w = work(&cycle);

        println!(
            "{name}: ∮M dc = {w:.3e} (scale {scale:.3e}), branches {:?}",
            {
                let mut b: Vec<i64> = cycle.iter().map(|r| r.3 as i64).collect();
                b.dedup();
                b
            }
        );
        // source: a closed path on one branch encloses no area; 1e-9 × scale
        assert!(w.abs() <= 1e-9 * scale, "{name}: ∮ M dc = {w}");
        if name.starts_with("locked") {
            // both bounds meet: the branch tells the direction
            assert!(cycle.iter().any(|r| r.3 == 1.0) && cycle.iter().any(|r| r.3 == -1.0));
        }
        if name.starts_with("elastic") {
            assert!(cycle.iter().any(|r| r.3 == 0.0), "never elastic");
            // back on the loading bound at the end of the excursion
            assert!((last.2 + MD).abs() < 1e-9, "{last:?}");
        }
    }
}

/// A hinge turned through a torsion spring (stiffness 1000 N·m/rad,
/// steeper than the snap's softening of 97 N·m/rad, so that the hinge
/// angle follows the spring's end monotonically) whose other end has the
/// prescribed rotation `ψ = curve(t)` about z: Newton iterates through
/// the law's branches.
fn spring_driven_hinge(curve: &[[f64; 2]]) -> ModelBuilder {
    let mut m = ModelBuilder::new("spring-driven hinge");
    let n = m.node([0.0, 0.0, 0.0]);
    let end = m.node([0.0, 0.0, 0.0]);
    let hinge = m.add(Joint::revolute(n, Ground).axis([0.0, 0.0, 1.0]));
    m.add(HingeLaw::on(hinge, KE).tape_spring(tape(None)).id(50));
    m.add(Spring::rotational(n, end, 1000.0));
    let path = m.curve(LoadCurve::points(curve.to_vec()).named("path"));
    m.add(PrescribedMotion::rotation(end, [0.0, 0.0, 1.0]).curve(path));
    m.fix(n, Dofs::TRANSLATIONS);
    m.fix(end, Dofs::TRANSLATIONS);
    m
}

/// A cut-back increment through the band leaves no trace: the spring-
/// driven hinge turned 0 → 1.6 → 0 rad with large increments and at most
/// 4 Newton iterations (increments through the band fail and are
/// halved), compared at every converged time with a run of small
/// increments that lands on the same times and is never cut back: the
/// same coordinate, moment and branch (tolerance 1e-9 rad and 1e-9·M_L,
/// Newton tolerances 1e-12).
#[test]
fn rejected_increments_restore_the_branch_state() {
    let curve = [[0.0, 0.0], [1.0, 1.6], [2.0, 0.0]];
    let m = spring_driven_hinge(&curve);
    let coarse = settings(
        &m,
        Analysis::statics()
            .end_time(2.0)
            .initial_increment(0.22)
            .max_increment(0.22)
            .max_iterations(1)
            .output_times([1.0]),
    );
    let (rows_b, history_b) = run(&m, coarse);
    for (i, r) in history_b.increments.iter().zip(&rows_b) {
        println!(
            "t {} step {} iterations {}: {r:?}",
            i.time, i.step, i.iterations
        );
    }
    // the band in time: c ∈ [1.29, 1.51] at t = c/1.6 and 2 − c/1.6
    let in_band = |t0: f64, dt: f64| {
        let (a, b) = (1.29 / 1.6, 1.51 / 1.6);
        let overlaps = |lo: f64, hi: f64| t0 < hi && t0 + dt > lo;
        overlaps(a, b) || overlaps(2.0 - b, 2.0 - a)
    };
    let through_band = history_b
        .cutbacks
        .iter()
        .filter(|c| in_band(c.time, c.failed_step))
        .count();
    println!(
        "coarse run: {} increments, {} cut-backs ({through_band} through the band)",
        rows_b.len() - 1,
        history_b.cutbacks.len()
    );
    for c in &history_b.cutbacks {
        println!(
            "cut back at t = {}: step {} ({:?})",
            c.time, c.failed_step, c.reason
        );
    }
    assert!(
        through_band > 0,
        "no increment through the band was cut back"
    );
    let times: Vec<f64> = rows_b.iter().skip(1).map(|r| r.0).collect();
    let fine = settings(
        &m,
        Analysis::statics()
            .end_time(2.0)
            .initial_increment(0.01)
            .max_increment(0.01)
            .output_times(times),
    );
    let (rows_a, history_a) = run(&m, fine);
    assert!(history_a.cutbacks.is_empty());
    let mut compared = 0;
    for b in &rows_b {
        let a = rows_a
            .iter()
            .find(|a| (a.0 - b.0).abs() < 1e-12)
            .expect("landed on the time");
        println!(
            "t {:.6}: c {:.9} M {:.9} branch {} | {a:?}",
            b.0, b.1, b.2, b.3
        );
        assert!((a.1 - b.1).abs() < 1e-9, "{a:?} {b:?}");
        assert!((a.2 - b.2).abs() < 1e-9 * ML, "{a:?} {b:?}");
        assert_eq!(a.3, b.3, "{a:?} {b:?}");
        compared += 1;
    }
    assert_eq!(compared, rows_b.len());
}

/// The tape-spring shape as defined in docs/joints.md §4.1, written out
/// independently: the polylines of `f_load` and `f_unload` and the
/// parabola `f_i + s₋(c − cᵢ) + (s₊ − s₋)(c − cᵢ + h)²/(4h)` on
/// `[cᵢ − h, cᵢ + h]` at each corner.
fn tape_shape(c: f64, h: f64, loading: bool) -> f64 {
    let ca = CL - MD / K;
    let cu = CL - ML / K;
    let cs = cu - W;
    let s = (ML - MD) / W;
    let corner = |c: f64, ci: f64, fi: f64, sl: f64, sr: f64| -> Option<f64> {
        ((c - ci).abs() < h).then(|| {
            let t = c - ci + h;
            fi + sl * (c - ci) + (sr - sl) * t * t / (4.0 * h)
        })
    };
    if loading {
        corner(c, ca, -MD, 0.0, K).unwrap_or((-MD).max(K * (c - CL)))
    } else {
        corner(c, cs, -MD, 0.0, -s)
            .or_else(|| corner(c, cu, -ML, -s, K))
            .unwrap_or(if c <= cs {
                -MD
            } else if c <= cu {
                -MD - s * (c - cs)
            } else {
                K * (c - CL)
            })
    }
}

/// The moment along a cycle 0 → 1.6 → 0 with k_e = 1e6 N·m/rad (the
/// elastic parts negligible: the moment jumps from bound to bound within
/// 1e-5 rad) follows `f_load` going up and `f_unload` coming down:
/// sharp (h = 0) and rounded (h = 0.02 rad) corners. Tolerance 1e-9·M_L
/// (the same formulas evaluated in another order), the points within
/// 1e-5 rad of the turning point being elastic.
#[test]
fn tape_spring_shape_matches_its_definition() {
    let curve = [[0.0, 0.0], [1.0, 1.6], [2.0, 0.0]];
    for h in [0.0, 0.02] {
        let m = driven_hinge(|j| HingeLaw::on(j, 1e6).tape_spring(tape(Some(h))), &curve);
        let s = settings(
            &m,
            Analysis::statics()
                .end_time(2.0)
                .initial_increment(1e-3)
                .max_increment(1e-3)
                .output_times([1.0]),
        );
        let (rows, _) = run(&m, s);
        let mut worst = 0.0f64;
        for &(t, c, moment, branch) in &rows[1..] {
            let loading = t <= 1.0;
            let expected = tape_shape(c, h, loading);
            let e = (moment - expected).abs();
            worst = worst.max(e);
            // source: tape_shape; 1e-9·M_L
            assert!(
                e < 1e-9 * ML,
                "h {h}, t {t}: c {c}, M {moment}, expected {expected} (branch {branch})"
            );
        }
        // the peaks: −M_L at c_u with sharp corners, less with rounded
        // ones (by (K + S)h/4 at the corner point)
        let low = rows.iter().map(|r| r.2).fold(f64::INFINITY, f64::min);
        println!("rounding {h}: largest deviation {worst:.2e} N·m, lowest moment {low:.6}");
    }
}

/// The element tangent against central differences of its residual, on
/// a revolute joint between two free nodes in a general configuration (the
/// joint bent off its axis, so that `∂g/∂q` matters), on every part of the
/// law: the loading bound in the travel (flat) and in the band, the snap
/// (softening) of the unloading bound, a rounded corner, the locked
/// branch, and the elastic state inside the band. h = 1e-6 (rad or m);
/// tolerance 1e-6 of the largest entry (central differences: truncation
/// ~1e-10, round-off ~1e-8 relative), as for the other elements.
#[test]
fn tangent_matches_finite_differences_on_every_branch() {
    let mut m = ModelBuilder::new("hinge pair");
    let a = m.node([0.0, 0.0, 0.0]);
    let b = m.node([0.3, 0.1, -0.2]);
    let hinge = m.add(Joint::revolute(a, b).axis([0.0, 0.0, 1.0]));
    m.add(HingeLaw::on(hinge, KE).tape_spring(tape(Some(0.02))).id(50));
    // supports do not enter the element's residual; they make the model
    // valid
    m.fix(a, Dofs::ALL);
    let model = m.build().unwrap();
    let (index, e) = model
        .elements
        .iter()
        .enumerate()
        .find(|(_, e)| e.kind() == ElementKind::HingeLaw)
        .unwrap();
    let offsets = model.offsets(index);
    let nodes = e.nodes().to_vec();
    let n = e.n_local();
    let ctx = model.context(0.0, Need::STIFFNESS);
    let eval = |s: &State, stiffness: bool| {
        let mut r = vec![0.0; n];
        let mut k = vec![0.0; n * n];
        let mut out = if stiffness {
            ElementOutput::with_stiffness(&mut r, &mut k)
        } else {
            ElementOutput::residual(&mut r)
        };
        e.evaluate(&ctx, s, &mut out);
        (r, k)
    };
    // (target angle, moment at the last converged state relative to the
    // bounds, expected branch)
    #[derive(Clone, Copy)]
    enum Memory {
        Above,
        Below,
        Between,
    }
    let cases = [
        ("travel, loading bound", 0.8, Memory::Above, 1.0),
        ("band, loading bound", 1.35, Memory::Above, 1.0),
        ("snap, unloading bound", 1.35, Memory::Below, -1.0),
        ("rounded corner at c_u", 1.405, Memory::Below, -1.0),
        ("locked branch", 1.55, Memory::Below, -1.0),
        ("elastic inside the band", 1.45, Memory::Between, 0.0),
    ];
    for (name, angle, memory, branch) in cases {
        let mut s = model.initial_state();
        // B turned by `angle` about the axis and bent off it by 0.02 rad,
        // both bodies turned and moved together
        for i in 0..2 {
            s.displace_node(i, &[0.1, -0.2, 0.3].into(), &[0.3, -0.4, 0.5].into());
        }
        s.displace_node(1, &[0.0, 0.0, 0.0].into(), &[0.02, -0.01, angle].into());
        let c = hinge_results(&model, 0.0, &s)[0];
        let internal = offsets.internal;
        // the bounds at c, from the response to extreme memories
        s.internal[internal..internal + 2].copy_from_slice(&[c, 1e4 - start_moment()]);
        let hi = hinge_results(&model, 0.0, &s)[1];
        s.internal[internal + 1] = -1e4 - start_moment();
        let lo = hinge_results(&model, 0.0, &s)[1];
        let m_n = match memory {
            Memory::Above => 1e4,
            Memory::Below => -1e4,
            Memory::Between => 0.5 * (hi + lo),
        };
        // the last converged state slightly behind c, so that the trial
        // moves with c
        s.internal[internal..internal + 2].copy_from_slice(&[c - 1e-3, m_n - start_moment()]);
        let got = hinge_results(&model, 0.0, &s);
        assert_eq!(got[2], branch, "{name}: branch {} at c = {c}", got[2]);
        let (_, k) = eval(&s, true);
        let h = 1e-6;
        let mut fd = vec![0.0; n * n];
        for j in 0..n {
            let mut plus = s.clone();
            plus.displace_local(&nodes, 0, &offsets, j, h);
            let mut minus = s.clone();
            minus.displace_local(&nodes, 0, &offsets, j, -h);
            let (rp, _) = eval(&plus, false);
            let (rm, _) = eval(&minus, false);
            for i in 0..n {
                fd[j * n + i] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        // the largest entry of either matrix (the differences' when the
        // tangent misses terms)
        let scale = k.iter().chain(&fd).fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = k
            .iter()
            .zip(&fd)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / scale));
        println!(
            "{name}: c = {c:.5}, M = {:.6}, branch {}: largest tangent error {worst:.2e} of {scale:.2e}",
            got[1], got[2]
        );
        // source: central differences; 1e-6 of the largest entry
        assert!(worst < 1e-6, "{name}: {worst:e}");
    }
}

/// The moment of the reference configuration (`f_load(0) = −M_d`), from
/// which the stored moment is counted.
fn start_moment() -> f64 {
    -MD
}

/// Bad input: each error names the hinge law and what is wrong.
#[test]
fn bad_input_is_reported() {
    let law = |j| HingeLaw::on(j, KE);
    type Make = Box<dyn Fn(JointHandle) -> HingeLaw>;
    let cases: Vec<(Make, &str)> = vec![
        (
            Box::new(move |j| law(j).tables([[0.0, 1.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 2.0]])),
            "hinge law 50: the loading bound must not be below the unloading bound",
        ),
        (
            Box::new(move |j| law(j).tables([[0.0, 1.0], [0.0, 2.0]], [[0.0, 0.0], [1.0, 0.0]])),
            "hinge law 50: load_table: the abscissae must be strictly increasing",
        ),
        (
            Box::new(move |j| law(j).tables([[0.0, 1.0], [1.0, 2.0]], [[1.0, 0.0], [0.5, 0.0]])),
            "hinge law 50: unload_table: the abscissae must be strictly increasing",
        ),
        (
            Box::new(|j| HingeLaw::on(j, 0.0).tape_spring(tape(None))),
            "hinge law 50: elastic_slope must be positive and finite, got 0",
        ),
        (
            Box::new(|j| HingeLaw::on(j, -2.0).tape_spring(tape(None))),
            "hinge law 50: elastic_slope must be positive and finite, got -2",
        ),
        (
            Box::new(law),
            "hinge law 50: needs its bounds",
        ),
        (
            Box::new(move |j| {
                law(j).tape_spring(TapeSpring {
                    locking_peak: 0.1,
                    ..tape(None)
                })
            }),
            "hinge law 50: tape_spring: locking_peak must be finite and larger than deployment_moment",
        ),
        (
            Box::new(move |j| law(j).tape_spring(tape(None)).tables([[0.0, 1.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 0.0]])),
            "hinge law 50: give either load_table and unload_table or tape_spring, not both",
        ),
        (
            Box::new(move |j| law(j).coordinate(Coordinate::Slide3).tape_spring(tape(None))),
            "hinge law 50: joint 1 (revolute) has no coordinate \"slide\"",
        ),
    ];
    for (make, expected) in cases {
        let m = driven_hinge(make, &[[0.0, 0.0], [1.0, 0.1]]);
        let err = m.build().unwrap_err().to_string();
        println!("{err}");
        assert!(err.contains(expected), "{err}\nexpected: {expected}");
    }
    // an unknown joint, from a model file
    let text = r#"
title = "unknown joint"
[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]
[[hinge_laws]]
id = 7
joint = 99
elastic_slope = 10.0
load_table = [[0.0, 1.0], [1.0, 1.0]]
unload_table = [[0.0, 0.0], [1.0, 0.0]]
"#;
    let input =
        unfold::io::model_file::parse_model(text, std::path::Path::new("model.toml")).unwrap();
    let err = Model::from_input(&input).unwrap_err().to_string();
    println!("{err}");
    assert!(
        err.contains("hinge law 7: joint 99 does not exist"),
        "{err}"
    );
}

/// `unit = "deg"`: the same law in degrees gives the same moments as in
/// radians (tables scaled, slopes per degree). Tolerance 1e-12·M_L.
#[test]
fn degrees_and_radians_give_the_same_law() {
    let d = 180.0 / std::f64::consts::PI;
    let curve = [[0.0, 0.0], [1.0, 1.6], [2.0, 0.0]];
    let run_with = |law: Box<dyn FnOnce(JointHandle) -> HingeLaw>| {
        let m = driven_hinge(law, &curve);
        let s = settings(
            &m,
            Analysis::statics()
                .end_time(2.0)
                .initial_increment(0.01)
                .max_increment(0.01)
                .output_times([1.0]),
        );
        run(&m, s).0
    };
    let rad = run_with(Box::new(|j| {
        HingeLaw::on(j, KE).tape_spring(tape(Some(0.01)))
    }));
    let deg = run_with(Box::new(move |j| {
        HingeLaw::on(j, KE / d)
            .unit(AngleUnit::Deg)
            .tape_spring(TapeSpring {
                locking_angle: CL * d,
                locked_stiffness: K / d,
                snap_width: W * d,
                rounding: Some(0.01 * d),
                ..tape(None)
            })
    }));
    assert_eq!(rad.len(), deg.len());
    for (a, b) in rad.iter().zip(&deg) {
        // source: the same law; 1e-12·M_L (round-off of the unit scaling)
        assert!((a.2 - b.2).abs() < 1e-12 * ML, "{a:?} {b:?}");
        assert_eq!(a.3, b.3, "{a:?} {b:?}");
    }
}

/// The example model file through the command-line tool: hinge_laws.csv
/// has the columns `coordinate, moment, branch` (radians whatever the
/// entry's unit), and the loop it traces encloses the area of the
/// tape-spring loop, `½(M_L − M_d)(w + (M_L − M_d)/K)` with
/// `K = 5 N·m/deg`, `w = 6°`. Tolerance 2e-3 relative: the trapezoidal
/// error at the corners of M(c) on the example's path (Δc = 2.8e-3 rad
/// through the band) is at most Σ Δs·Δc²/8 ≈ 7.4e-4 N·m·rad (slope
/// jumps Δs of 286, 379 and 93 N·m/rad), 1.1e-3 of the area; the
/// accuracy itself is checked above at 1e-6.
#[test]
fn example_writes_the_loop_to_hinge_laws_csv() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hinge_lock_cycle.toml");
    let out = std::env::temp_dir().join(format!("unfold-hinge-example-{}", std::process::id()));
    let result = std::process::Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{stderr}");
    let text = std::fs::read_to_string(out.join("hinge_laws.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "step,time,element,coordinate,moment,branch"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let rows: Vec<Row> = rows.iter().map(|r| (r[1], r[3], r[4], r[5])).collect();
    assert!(rows.iter().all(|r| [1.0, 0.0, -1.0].contains(&r.3)));
    let d = std::f64::consts::PI / 180.0;
    let (k, w) = (5.0 / d, 6.0 * d);
    let area = 0.5 * (ML - MD) * (w + (ML - MD) / k);
    let computed = work(&rows);
    let err = (computed - area).abs() / area;
    println!("example: ∮M dc {computed:.9}, area {area:.9}, relative error {err:.2e}");
    // source: the loop area; 2e-3 relative (see above)
    assert!(err < 2e-3, "∮ M dc = {computed}, area {area}");
    // the peak of the unloading bound is reached (−M_L within the rounding
    // and the sampling: 2%)
    let low = rows.iter().map(|r| r.2).fold(f64::INFINITY, f64::min);
    assert!((low + ML).abs() < 0.02 * ML, "lowest moment {low}");
    let _ = std::fs::remove_dir_all(&out);
}

/// Bad input in a model file stops the command-line tool with exit code
/// 2 and a message naming the file and the hinge law.
#[test]
fn bad_model_file_exits_with_code_2() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/hinge_lock_cycle.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("elastic_slope = 10.0", "elastic_slope = -1.0");
    let dir = std::env::temp_dir().join(format!("unfold-hinge-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("bad_hinge.toml");
    std::fs::write(&model, text).unwrap();
    let result = std::process::Command::new(env!("CARGO_BIN_EXE_unfold"))
        .args([
            "run",
            model.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    println!("{stderr}");
    assert_eq!(result.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad_hinge.toml")
            && stderr.contains("hinge law 2: elastic_slope must be positive and finite, got -1"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The bound the law starts on: bounds `f_load = 1`, `f_unload = −1`
/// (N·m, constant), `k_e = 10`, the hinge turned 0 → 0.1 rad. Starting on
/// the loading bound the moment stays at 1 (branch 1); starting on the
/// unloading bound it rises elastically, `−1 + 10 c`, and reaches 0 at
/// 0.1 rad (branch 0). Tolerance 1e-12 N·m (Newton tolerances 1e-12).
#[test]
fn start_selects_the_initial_bound() {
    for (start, expected, branch) in [
        (StartBranch::Load, 1.0, 1.0),
        (StartBranch::Unload, 0.0, 0.0),
    ] {
        let m = driven_hinge(
            |j| {
                HingeLaw::on(j, 10.0)
                    .tables([[0.0, 1.0], [1.0, 1.0]], [[0.0, -1.0], [1.0, -1.0]])
                    .start(start)
            },
            &[[0.0, 0.0], [1.0, 0.1]],
        );
        let s = settings(
            &m,
            Analysis::statics()
                .initial_increment(0.25)
                .max_increment(0.25),
        );
        let (rows, _) = run(&m, s);
        let first = rows[0];
        assert!(
            (first.2
                - if start == StartBranch::Load {
                    1.0
                } else {
                    -1.0
                })
            .abs()
                < 1e-12
        );
        let last = *rows.last().unwrap();
        // source: the return map by hand (above); 1e-12 N·m
        assert!((last.2 - expected).abs() < 1e-12, "{start:?}: {last:?}");
        assert_eq!(last.3, branch, "{start:?}: {last:?}");
    }
}

/// The builder's model file reads back to the same definition (the tape
/// spring as an inline table, the tables, `start`, `unit`).
#[test]
fn model_file_round_trip() {
    let mut m = driven_hinge(
        |j| {
            HingeLaw::on(j, KE / 57.0)
                .unit(AngleUnit::Deg)
                .tape_spring(tape(Some(0.5)))
                .start(StartBranch::Unload)
        },
        &[[0.0, 0.0], [1.0, 0.1]],
    );
    let n = m.node([1.0, 0.0, 0.0]);
    let j = m.add(Joint::revolute(n, Ground).axis([0.0, 0.0, 1.0]));
    m.add(HingeLaw::on(j, KE).tables([[0.0, 1.0], [1.0, 1.0]], [[0.0, -1.0], [1.0, -1.0]]));
    m.fix(n, Dofs::TRANSLATIONS);
    let text = m.to_toml().unwrap();
    assert!(text.contains("[[hinge_laws]]"), "{text}");
    let back =
        unfold::io::model_file::parse_model(&text, std::path::Path::new("hinge.toml")).unwrap();
    assert_eq!(&back, m.input());
    Model::from_input(&back).expect("valid model");
}
