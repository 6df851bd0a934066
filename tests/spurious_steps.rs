//! The checks of a converged dynamic step that its residual cannot make
//! (src/analysis/dynamics.rs, docs/theory.md §15.5–15.6): a step whose
//! Newton iterations converged to a spurious root, in which a light node
//! turns by whole turns per step while every position looks right, is cut
//! back instead of accepted; and fixed steps stay at `time_step`.

mod common;

use std::sync::Arc;

use common::pendulum;
use unfold::analysis::{
    CutbackInfo, DynamicAnalysis, DynamicSettings, Energies, IncrementInfo, NewtonFailure,
    Observer, WarningInfo,
};
use unfold::model::Model;
use unfold::state::State;

/// What the tests look at: every accepted step, the largest kinetic
/// energy, the largest turn of a node in a step (`h |Ω|`), cut-backs and
/// warnings.
#[derive(Default)]
struct Record {
    steps: Vec<IncrementInfo>,
    largest_kinetic: f64,
    largest_turn: f64,
    cutbacks: Vec<CutbackInfo>,
    warnings: Vec<WarningInfo>,
}

impl Observer for Record {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        for v in &state.velocity {
            let w = (v[3] * v[3] + v[4] * v[4] + v[5] * v[5]).sqrt();
            self.largest_turn = self.largest_turn.max(info.step * w);
        }
        self.steps.push(info.clone());
        Ok(())
    }
    fn energies(&mut self, e: &Energies) {
        self.largest_kinetic = self.largest_kinetic.max(e.kinetic);
    }
    fn cutback(&mut self, info: &CutbackInfo) {
        self.cutbacks.push(info.clone());
    }
    fn warning(&mut self, info: &WarningInfo) {
        self.warnings.push(info.clone());
    }
}

/// A model of tests/data and its first analysis.
fn data_model(name: &str) -> (Arc<Model>, DynamicSettings) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let input = unfold::io::model_file::parse_model(&text, &path).unwrap();
    let model = Arc::new(Model::from_input(&input).unwrap());
    let settings = input.analyses().unwrap()[0].as_dynamic().unwrap().clone();
    (model, settings)
}

/// tests/data/flexible_hinge_fixed_step.toml: a flexible boom and panel
/// opened by a hinge spring (k = 2 N·m/rad from π to 0: 9.8696 J at most)
/// in fixed steps of 1 ms that do not follow the ~1e5 rad/s vibration of
/// the hinge nodes' rotations. Without the checks of the converged step,
/// step 25 converged (14 iterations) to a spurious root where nodes 11
/// and 12 turn by h|Ω| = 12.5 rad, then 25.2 rad per step: kinetic energy
/// 673 J, energy balance error 7.9e2 J, and the run completed.
///
/// With them, that step is cut back (a `Spurious` failure naming a hinge
/// node) and the run reaches t = 0.03 with
/// - no node turning by more than 1 rad in a step (the limit);
/// - the kinetic energy below the spring's energy kπ²/2 = 9.8696 J
///   (energy conservation: no work is done on the model);
/// - the energy balance error within 1e-3 of kπ²/2 (measured −4.3e-3 J,
///   4.4e-4 of it: the numerical dissipation of ρ∞ = 0.9 on the hinge
///   vibration the step does not follow; the spurious root gave 80 times
///   kπ²/2);
/// - no energy-jump warning.
#[test]
fn a_spurious_root_with_nodes_spinning_is_cut_back() {
    let (model, settings) = data_model("flexible_hinge_fixed_step.toml");
    assert!(!settings.adaptive);
    let spring = 2.0 * std::f64::consts::PI.powi(2) / 2.0;
    let mut record = Record::default();
    let out = DynamicAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut record);
    assert!(out.error.is_none(), "{:?}", out.error);
    assert!((out.time - 0.03).abs() < 1e-12);
    assert!(
        record.largest_kinetic < spring,
        "largest kinetic energy {} above the spring's {spring}",
        record.largest_kinetic
    );
    let e = out.energies.balance_error;
    assert!(e.abs() <= 1e-3 * spring, "energy balance error {e}");
    assert!(
        record.largest_turn <= 1.0,
        "largest turn {}",
        record.largest_turn
    );
    let spurious: Vec<&CutbackInfo> = record
        .cutbacks
        .iter()
        .filter(|c| matches!(c.reason, NewtonFailure::Spurious { .. }))
        .collect();
    // since the normal velocities are rescaled at changes of step (D15,
    // docs/theory.md §15.8) Newton no longer finds the spurious root at
    // step 25 of this model: the step failed and was cut back instead;
    // since the first step is limited by the hinge nodes' initial angular
    // accelerations (§15.5, "First step") the run takes no cut-back. A
    // spurious root, if any, names a hinge node.
    eprintln!(
        "{} steps, {} cut-backs ({} spurious), energy balance error {e:.3e} J, largest turn {:.3e} rad, largest kinetic energy {:.4} J",
        record.steps.len(),
        record.cutbacks.len(),
        spurious.len(),
        record.largest_turn,
        record.largest_kinetic
    );
    for c in &spurious {
        let text = c.reason.to_string();
        assert!(
            text.contains("node 11") || text.contains("node 12"),
            "{text}"
        );
    }
    assert!(record.warnings.is_empty(), "{:?}", record.warnings);
}

/// With `adaptive = false` the steps are `time_step` whatever `max_step`
/// says (docs/model-format.md): cut back only when Newton fails, grown
/// back after it to `time_step` and no further, shortened only to land on
/// the end. The model above starts with a first step shorter than
/// `time_step` (its hinge nodes' initial angular accelerations, docs/
/// theory.md §15.5, "First step"); given `max_step` = 10 `time_step`,
/// every step is at most `time_step` and the steps after it return to it.
#[test]
fn fixed_steps_grow_back_to_time_step_and_no_further() {
    let (model, mut settings) = data_model("flexible_hinge_fixed_step.toml");
    settings.max_step = 10.0 * settings.time_step;
    let h = settings.time_step;
    let mut record = Record::default();
    let out = DynamicAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut record);
    assert!(out.error.is_none(), "{:?}", out.error);
    // every step at most time_step (to the round-off of t)
    assert!(
        record.steps.iter().all(|s| s.step <= h * (1.0 + 1e-9)),
        "{:?}",
        record.steps.iter().map(|s| s.step).collect::<Vec<_>>()
    );
    // grown back to time_step after the first step shorter than it (by
    // 1.5 per step that converges in few iterations,
    // docs/model-format.md)
    let first_cut = record
        .steps
        .iter()
        .position(|s| s.step > 0.0 && s.step < h * (1.0 - 1e-9))
        .expect("a step shorter than time_step");
    assert!(record.steps[first_cut..]
        .iter()
        .any(|s| (s.step - h).abs() <= 1e-9 * h));
}

/// The hanging pendulum of tests/common/pendulum.rs (a body of m = 2 kg,
/// J_c = 0.01 kg·m² at d = 0.5 m below a hinge on z, J_O = 0.51 kg·m²)
/// launched from the bottom at `rate` rad/s, in fixed steps of `h` with
/// ρ∞ = 0.5 over 10 s: steps far too long for the motion (a small swing
/// has a period of 1.43 s), whose numerical dissipation takes energy out
/// but never puts any in.
fn pendulum(rate: f64, h: f64) -> (Arc<Model>, DynamicSettings) {
    let text = pendulum::hanging(
        &format!(
            r#"title = "pendulum in long fixed steps"
[analysis]
type = "dynamic"
end_time = 10.0
time_step = {h}
adaptive = false
rho_infinity = 0.5"#
        ),
        &format!(
            "angular_velocity = [0.0, 0.0, {rate}]\nvelocity = [{v}, 0.0, 0.0]",
            v = 0.5 * rate
        ),
        "",
    );
    let input =
        unfold::io::model_file::parse_model(&text, std::path::Path::new("pendulum.toml")).unwrap();
    let model = Arc::new(Model::from_input(&input).unwrap());
    let settings = input.analyses().unwrap()[0].as_dynamic().unwrap().clone();
    (model, settings)
}

/// The spurious failures among the cut-backs, as text.
fn spurious_reasons(record: &Record) -> Vec<String> {
    record
        .cutbacks
        .iter()
        .filter(|c| matches!(c.reason, NewtonFailure::Spurious { .. }))
        .map(|c| c.reason.to_string())
        .collect()
}

/// The pendulum launched at 10 rad/s goes over the top (kinetic energy
/// ½(J_c θ̇² + m v²) = 25.5 J at the bottom against 2mgd = 19.62 J to
/// climb). In fixed steps of 0.2 s the first step converges (7 Newton
/// iterations) to a false root in which the body spins at h|Ω| = 29 rad
/// per step (145 rad/s: 5e3 J of kinetic energy from nothing). The turn
/// check of docs/theory.md §15.5 rejects it and the step is cut back;
/// the run completes with every accepted step turning the body by at
/// most [`unfold::analysis::dynamics::MAX_ROTATION_STEP`] = 1 rad and the
/// kinetic energy never above the 25.5 J it started with (no work is done
/// on the pendulum: gravity only exchanges it; the scheme's dissipation
/// only takes it out). Without the check (measured by disabling it) the
/// false roots are accepted: the kinetic energy reaches 4.2e4 J and
/// the body turns by 582 rad in a step.
#[test]
fn a_false_root_turning_the_body_by_whole_turns_is_rejected() {
    let (model, settings) = pendulum(10.0, 0.2);
    let start = 0.5 * (0.01 * 100.0 + 2.0 * 25.0);
    let mut record = Record::default();
    let out = DynamicAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut record);
    assert!(out.error.is_none(), "{:?}", out.error);
    assert!((out.time - 10.0).abs() < 1e-12);
    // the first attempt, from t = 0, is the false root
    let first = &record.cutbacks[0];
    assert_eq!(first.increment, 1);
    assert_eq!(first.time, 0.0);
    let text = first.reason.to_string();
    assert!(
        matches!(first.reason, NewtonFailure::Spurious { .. })
            && text.contains("node 2 turned by")
            && text.contains("more than the 1 rad a step may follow"),
        "{text}"
    );
    assert!(
        record.largest_turn <= 1.0,
        "largest turn {}",
        record.largest_turn
    );
    // measured 25.5 J (the start, to the digits printed): within 1e-9
    assert!(
        record.largest_kinetic <= start * (1.0 + 1e-9),
        "largest kinetic energy {} above the {start} J of the start",
        record.largest_kinetic
    );
}

/// Launched at 5 rad/s (6.375 J, a swing to 1.5 rad) in fixed steps of
/// 0.7 s, Newton converges to false roots of both kinds of
/// docs/theory.md §15.5: a turn of more than 1 rad in the step, and a
/// root more than the model's size (0.5 m, the pendulum's length) away
/// from the predictor. Both are rejected and cut back, and the run
/// completes with the kinetic energy never above the 6.375 J it started
/// with. Without the checks (measured by disabling them) the false roots
/// are accepted (at 0.5 s steps: the kinetic energy reaches 5.2e2 J and
/// the body turns by 155 rad in a step). Which false roots Newton finds
/// depends on the whole step sequence: measured with this settings, 1
/// root beyond the model's size and 8 turns beyond 1 rad.
#[test]
fn false_roots_far_from_the_predictor_are_rejected() {
    let (model, settings) = pendulum(5.0, 0.7);
    let start = 0.5 * (0.01 * 25.0 + 2.0 * 6.25);
    let mut record = Record::default();
    let out = DynamicAnalysis::new(model.clone(), settings).run(model.initial_state(), &mut record);
    assert!(out.error.is_none(), "{:?}", out.error);
    assert!((out.time - 10.0).abs() < 1e-12);
    let reasons = spurious_reasons(&record);
    assert!(
        reasons.iter().any(|r| r.contains("Newton moved node 2 by")
            && r.contains("away from the predictor, more than the model's size 5.000e-1")),
        "{reasons:?}"
    );
    assert!(
        reasons.iter().any(|r| r.contains("node 2 turned by")),
        "{reasons:?}"
    );
    assert!(
        record.largest_turn <= 1.0,
        "largest turn {}",
        record.largest_turn
    );
    assert!(
        record.largest_kinetic <= start * (1.0 + 1e-9),
        "largest kinetic energy {} above the {start} J of the start",
        record.largest_kinetic
    );
}
