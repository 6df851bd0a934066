//! Load control watching its own validity: the sign of the tangent's
//! determinant (a limit or bifurcation point passed within an increment is
//! warned about, docs/theory.md §9), prescribed rotations kept below a
//! quarter turn per increment (docs/model-format.md, `[[prescribed]]`), and
//! laws that hold below half a turn of a relative rotation (docs/theory.md
//! §3.1, §5).

mod common;

use std::sync::Arc;

use unfold::analysis::newton::NewtonSolver;
use unfold::analysis::observers::History;
use unfold::analysis::statics::StaticError;
use unfold::analysis::LIMIT_POINT_WARNING;
use unfold::io::model_file::parse_model;
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// The shallow clamped arch of the new-user trial: two straight bars of
/// length ≈ 1 rising 0.1 to an apex loaded by `200 t` downwards (EA = 1e6,
/// every bending and torsional stiffness 1), ten elements each.
fn arch(analysis: &str) -> ModelInput {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/shallow_arch.toml");
    let text = std::fs::read_to_string(path)
        .expect("the arch model")
        .replace("initial_increment = 0.05\n", &format!("{analysis}\n"));
    parse_model(&text, std::path::Path::new("arch.toml")).unwrap()
}

/// The sign of the determinant of the tangent at `state`, assembled by a
/// solver of its own and computed densely (nalgebra's LU): the reference
/// for the analysis's sparse one.
fn dense_sign(model: &Model, state: &State) -> f64 {
    let mut solver = NewtonSolver::new(model);
    solver.assemble(model, state, state.time, true);
    let a = solver.tangent();
    let n = a.dim();
    let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
    for (i, j, v) in a.entries() {
        dense[(i, j)] += v;
    }
    // the determinant itself overflows; the sign of the product of the
    // pivots is that of the determinant
    let lu = dense.lu();
    let pivots: f64 = (0..n).map(|k| lu.u()[(k, k)].signum()).product();
    let parity = if lu.p().determinant::<f64>() < 0.0 {
        -1.0
    } else {
        1.0
    };
    pivots * parity
}

/// Runs `input` keeping the states.
fn run(input: &ModelInput) -> (Arc<Model>, History, Option<StaticError>) {
    let model = Arc::new(Model::from_input(input).expect("valid model"));
    let mut history = History::with_states();
    let outcome = common::analysis(&model, input).run(model.initial_state(), &mut history);
    (model, history, outcome.error)
}

/// The arch under load control in increments of 0.05, as the trial ran it
/// (exit 0, snapped at t = 0.125 with no word of the limit point): the
/// increments whose tangent changed the sign of its determinant are warned
/// about, exactly those where a dense determinant of the converged tangents
/// changes sign, and one of them is the increment across the limit load of
/// the path followed by arc length (t ≈ 0.0845). The first comes earlier,
/// at increment 1: each bar, compressed by N ≈ P/(2 sin α) ≈ 5 P, buckles
/// out of its plane near P ≈ 2 (t ≈ 0.01, N ≈ π² EI/L² ≈ 10), a bifurcation
/// that load control passes on the plane path.
#[test]
fn limit_points_under_load_control_are_warned_about() {
    let (model, history, error) = run(&arch("initial_increment = 0.05"));
    assert!(error.is_none(), "{error:?}");
    let warned: Vec<usize> = history.warnings.iter().map(|w| w.increment).collect();
    // the reference: a change of sign of the dense determinant
    let signs: Vec<f64> = history
        .states
        .iter()
        .map(|s| dense_sign(&model, s))
        .collect();
    let changed: Vec<usize> = (1..signs.len())
        .filter(|&k| signs[k] != signs[k - 1])
        .map(|k| history.increments[k].increment)
        .collect();
    println!("arch, load control by 0.05: warnings at increments {warned:?}, dense determinant changes sign at {changed:?}");
    assert_eq!(warned, changed);
    assert!(!warned.is_empty());
    for w in &history.warnings {
        assert_eq!(w.message, LIMIT_POINT_WARNING);
        let step = &history.increments[w.increment];
        assert!((w.from - (step.time - step.step)).abs() < 1e-12 && w.time == step.time);
    }

    // the limit load: the first maximum of t along the arc-length path
    let (_, path, error) = run(&arch(
        "control = \"arc_length\"\ninitial_increment = 0.005\nend_time = 0.2",
    ));
    // (past the limit the path winds through the bifurcated branches and
    // may use up its increments before t = 0.2: only its first maximum is
    // wanted here)
    let _ = error;
    let t: Vec<f64> = path.increments.iter().map(|i| i.time).collect();
    let limit = (1..t.len() - 1)
        .find(|&k| t[k] >= t[k - 1] && t[k] > t[k + 1])
        .map(|k| t[k])
        .expect("a limit point");
    println!("arch, arc length: limit load t = {limit:.4}");
    // the trial's figure, from the same path
    assert!((limit - 0.0845).abs() < 0.002, "{limit}");
    assert!(
        history
            .warnings
            .iter()
            .any(|w| w.from < limit && limit <= w.time),
        "no warning across t = {limit}: {:?}",
        history.warnings
    );
    // arc-length control is not watched: it follows limit points
    assert!(path.warnings.is_empty(), "{:?}", path.warnings);
}

/// No warning where nothing is passed: the arch loaded to t = 0.005 (below
/// the first bifurcation) and the roll-up of a cantilever into a full
/// circle, stable all the way.
#[test]
fn stable_paths_are_not_warned_about() {
    let (_, history, error) = run(&arch("initial_increment = 0.001\nend_time = 0.005"));
    assert!(error.is_none(), "{error:?}");
    assert!(history.warnings.is_empty(), "{:?}", history.warnings);
    let (_, history, error) = run(&common::example("cantilever_rollup.toml"));
    assert!(error.is_none(), "{error:?}");
    assert!(history.warnings.is_empty(), "{:?}", history.warnings);
}

/// The cantilever of the trial (L = 2, GJ = 5920, ten elements) twisted by
/// a prescribed end rotation of two full turns, 4π about its axis. Asked
/// for increments of 0.5 (a full turn each, which the trial's run could
/// not tell from no turn at all: no torque), load control takes
/// increments of 0.125 (a quarter turn each), and the end state is that
/// of increments of 0.1 (0.4π each): a uniform twist, node k turned by
/// 4π k/10 (the exact solution, to 1e-9 in the quaternion).
#[test]
fn prescribed_rotations_turn_by_at_most_a_quarter_turn_per_increment() {
    let twisted = |increment: f64| {
        let text = common::model_text("twisted_cantilever.toml").replace(
            "initial_increment = 0.5\n",
            &format!("initial_increment = {increment}\n"),
        );
        run(&parse_model(&text, std::path::Path::new("twist.toml")).unwrap())
    };
    let (model, coarse, error) = twisted(0.5);
    assert!(error.is_none(), "{error:?}");
    let (_, fine, error) = twisted(0.1);
    assert!(error.is_none(), "{error:?}");
    // a quarter turn of 4π per increment: Δt = 1/8
    let steps: Vec<f64> = coarse.increments[1..].iter().map(|i| i.step).collect();
    assert_eq!(steps.len(), 8, "{steps:?}");
    assert!(steps.iter().all(|&h| (h - 0.125).abs() < 1e-9), "{steps:?}");
    assert!(coarse
        .notes
        .iter()
        .any(|n| n.contains("load increments limited to 1.2500e-1")));
    assert_eq!(fine.increments.len(), 11);
    // node k at x = 0.2 k turned by 4π k/10 about x: q = ±(cos θ/2, sin θ/2, 0, 0)
    let (a, b) = (coarse.last_state().unwrap(), fine.last_state().unwrap());
    let mut worst = 0.0f64;
    for node in 0..model.n_nodes() {
        let k = (model.reference_x[node].x / 0.2).round();
        let theta = 4.0 * std::f64::consts::PI * k / 10.0;
        for s in [a, b] {
            let q = s.q[node];
            let dot = q.w * (theta / 2.0).cos() + q.i * (theta / 2.0).sin();
            worst = worst.max(1.0 - dot.abs());
        }
    }
    assert!(worst < 1e-9, "{worst:e}");
}
