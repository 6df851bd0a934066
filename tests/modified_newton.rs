//! Modified Newton in dynamics (src/analysis/dynamics.rs, docs/theory.md
//! §15.1): the factors of the iteration matrix kept across iterations and
//! steps give the same motion as full Newton within the effect of the
//! Newton tolerances, a step whose kept factors fail is retried with fresh
//! ones instead of being cut back, and nothing is factored again while
//! nothing changes.

use std::sync::Arc;

use unfold::analysis::{
    AnalysisSettings, DynamicAnalysis, DynamicOutcome, IncrementInfo, NewtonMethod, Observer,
};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// The largest node translation of every accepted step.
#[derive(Default)]
struct Motion {
    last: Option<Vec<[f64; 3]>>,
    steps: Vec<f64>,
}

impl Observer for Motion {
    fn increment(
        &mut self,
        _: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        let x: Vec<[f64; 3]> = state.x.iter().map(|p| [p.x, p.y, p.z]).collect();
        if let Some(before) = &self.last {
            let d = x
                .iter()
                .zip(before)
                .map(|(a, b)| {
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
                })
                .fold(0.0, f64::max);
            self.steps.push(d);
        }
        self.last = Some(x);
        Ok(())
    }
}

/// The flexible pendulum of bench/peer (a beam of 1 m, EA 4e5 N, EI 1 N·m²,
/// 1 kg/m, pinned about y at x = 0, falling from the horizontal under
/// gravity) with 20 elements, fixed steps of 2.5 ms without cut-backs, to
/// `end_time`; `extra` is appended (loads, curves) and `analysis` to the
/// `[analysis]` table.
fn pendulum(end_time: f64, analysis: &str, extra: &str) -> String {
    format!(
        r#"
[analysis]
type = "dynamic"
end_time = {end_time}
time_step = 0.0025
min_step = 0.0025
adaptive = false
{analysis}

[[sections]]
name = "beam"
EA = 400000.0
GA2 = 150000.0
GA3 = 150000.0
GJ = 0.8
EI2 = 1.0
EI3 = 1.0
mass_per_length = 1.0
inertia_per_length = [5e-06, 2.5e-06, 2.5e-06]

[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[nodes]]
id = 2
x = [1.0, 0.0, 0.0]

[[beam_lines]]
nodes = [1, 2]
elements = 20
section = "beam"
orientation = [0.0, 0.0, 1.0]
first_node = 3
first_element = 2

[[joints]]
id = 1
type = "revolute"
nodes = [1]
axis = [0.0, 1.0, 0.0]

[gravity]
acceleration = [0.0, 0.0, -9.81]
curve = "constant"
{extra}
"#
    )
}

fn run(text: &str, method: NewtonMethod) -> (DynamicOutcome, Motion) {
    let input: ModelInput = toml::from_str(text).expect("valid toml");
    let model = Arc::new(Model::from_input(&input).expect("valid model"));
    let analyses = input.analyses().expect("valid analyses");
    let AnalysisSettings::Dynamic(mut settings) = analyses[0].clone() else {
        panic!("a dynamic analysis");
    };
    settings.newton = method;
    let start = model.initial_state();
    let mut motion = Motion::default();
    let mut analysis = DynamicAnalysis::new(model, settings);
    let outcome = analysis.run(start, &mut motion);
    (outcome, motion)
}

fn largest_difference(a: &State, b: &State) -> f64 {
    a.x.iter()
        .zip(&b.x)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

/// Both methods stop where the residual is within `ε_r = 1e-8` of the flux
/// and the next correction, estimated from the last one and the residual's
/// contraction, within `ε_u = 1e-6` of the step's largest translation
/// `Δx` (docs/theory.md §15.1). Two converged iterates of one step are
/// then within about `2 ε_u Δx` of each other, and over the run (the
/// scheme does not amplify a perturbation of the positions over 0.3 s of
/// a swing) the nodes within `2 ε_u Σ Δx`, a few 1e-7 m here; the bound
/// asserted is that sum.
#[test]
fn modified_newton_follows_full_newton_within_the_tolerances() {
    let text = pendulum(0.3, "", "");
    let (full, motion) = run(&text, NewtonMethod::Full);
    let (modified, _) = run(&text, NewtonMethod::Modified);
    assert!(full.error.is_none() && modified.error.is_none());
    assert_eq!(full.steps, 120);
    assert_eq!(modified.steps, full.steps);
    let path: f64 = motion.steps.iter().sum();
    let bound = 2.0 * 1e-6 * path;
    let difference = largest_difference(&full.state, &modified.state);
    assert!(
        difference <= bound,
        "nodes {difference:.3e} m apart, more than 2 ε_u Σ Δx = {bound:.3e} m"
    );
    // full Newton factors at every iteration, modified Newton less often
    assert_eq!(full.factorisations, full.iterations);
    assert!(
        modified.factorisations < full.factorisations,
        "{} factorisations with modified Newton, {} with full",
        modified.factorisations,
        full.factorisations
    );
}

/// A tip force of 40 N switched on within 0.1 µs at t = 0.1 s whips the
/// falling pendulum round: at max_iterations = 8, full Newton fails at
/// step 73 (that step takes it 12 iterations) and the run stops (no
/// cut-back: min_step = time_step). Modified Newton's factors, kept from
/// the step before or from an earlier iterate, fail at a dozen steps; each
/// is retried from its predictor with fresh factors and converges at the
/// same step (at most 16 iterations, two attempts), so the run ends with
/// no step rejected.
#[test]
fn a_step_whose_kept_factors_fail_is_retried_with_fresh_ones() {
    let kick = r#"
[[curves]]
name = "kick"
points = [[0.0, 0.0], [0.1, 0.0], [0.1000001, 1.0]]

[[loads]]
node = 2
force = [0.0, 0.0, 40.0]
curve = "kick"
"#;
    let text = pendulum(0.25, "max_iterations = 8", kick);
    let (full, _) = run(&text, NewtonMethod::Full);
    assert!(full.error.is_some(), "full Newton fails at 8 iterations");
    let (modified, _) = run(&text, NewtonMethod::Modified);
    assert!(modified.error.is_none(), "{:?}", modified.error);
    assert_eq!(modified.steps, 100);
    assert_eq!(modified.rejected_steps, 0);
    assert_eq!(modified.cutbacks, 0);
    assert!(modified.newton_retries >= 1);
}

/// A cantilever of the pendulum's section clamped at x = 0, vibrating
/// under a tip load of 1 mN from rest (a tip deflection of 0.33 mm, a
/// rotation of 5e-4 rad): its iteration matrix changes by ~1e-7 from step
/// to step, and the factors made at the first steps serve every step
/// after them: two factorisations for the 40 steps (one at the first
/// step, from rest), against 80 with full Newton. At
/// `residual_tolerance = 1e-6`: at the default 1e-8 the residual of this
/// stiff beam stops at its round-off, ~1e-8 of the flux (docs/theory.md
/// §15.1), where no factors contract it and new ones are made.
#[test]
fn nothing_is_factored_again_while_nothing_changes() {
    let text = pendulum(0.1, "residual_tolerance = 1e-6", "")
        .replace(
            "[[joints]]\nid = 1\ntype = \"revolute\"\nnodes = [1]\naxis = [0.0, 1.0, 0.0]",
            "[[supports]]\nnode = 1\nfixed = [\"all\"]\n\n[[loads]]\nnode = 2\nforce = [0.0, 0.0, -0.001]\ncurve = \"constant\"",
        )
        .replace(
            "[gravity]\nacceleration = [0.0, 0.0, -9.81]\ncurve = \"constant\"",
            "",
        );
    let (modified, _) = run(&text, NewtonMethod::Modified);
    assert!(modified.error.is_none(), "{:?}", modified.error);
    assert_eq!(modified.steps, 40);
    assert_eq!(modified.newton_retries, 0);
    assert!(
        modified.factorisations <= 2,
        "{} factorisations",
        modified.factorisations
    );
    let (full, _) = run(&text, NewtonMethod::Full);
    assert_eq!(full.factorisations, full.iterations);
}

/// `newton` takes `modified` or `full`; anything else is an input error
/// naming the analysis and the values available.
#[test]
fn an_unknown_newton_method_is_refused() {
    let text = pendulum(0.1, "newton = \"exact\"", "");
    let input: ModelInput = toml::from_str(&text).expect("valid toml");
    let error = input.analyses().expect_err("refused").to_string();
    assert!(
        error.contains("analysis")
            && error.contains("unknown newton \"exact\" (available: modified, full)"),
        "{error}"
    );
    let text = pendulum(0.1, "newton = \"full\"", "");
    let input: ModelInput = toml::from_str(&text).expect("valid toml");
    let AnalysisSettings::Dynamic(settings) = &input.analyses().expect("valid")[0] else {
        panic!("a dynamic analysis");
    };
    assert_eq!(settings.newton, NewtonMethod::Full);
}
