//! A dynamic analysis continued from any of its converged steps repeats
//! the run never stopped (src/io/restart.rs, docs/results.md "Restart
//! files"): at every accepted step of a run, its state and its
//! continuation ([`Observer::continuation`]: the step controller's next
//! size and memory, the regrowth after a lock, `a_{n−1}`), passed through
//! their JSON form as a restart file holds them, start a new analysis
//! ([`DynamicAnalysis::continued`]); every step it takes must be that of
//! the whole run, its time and its state to the last bit. The runs cover
//! adaptive and fixed steps, a rigid latch's lock and the steps growing
//! back after it, the landings on events, the impacts, rebounds and the
//! closure of a stop.

mod common;

use std::sync::Arc;

use common::events::parse;
use unfold::analysis::{
    Continuation, DynamicAnalysis, DynamicSettings, IncrementInfo, LockInfo, Observer, Step,
};
use unfold::model::Model;
use unfold::state::State;

/// Every accepted step, and the state and continuation reported once the
/// next step was sized.
#[derive(Default)]
struct Steps {
    increments: Vec<IncrementInfo>,
    continuations: Vec<(State, Continuation)>,
    /// The times of the latches' locks.
    locks: Vec<f64>,
}

impl Observer for Steps {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        _: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.increments.push(info.clone());
        Ok(())
    }

    fn lock(&mut self, info: &LockInfo) {
        self.locks.push(info.time);
    }

    fn continuation(&mut self, state: &State, continuation: &Continuation) -> std::io::Result<()> {
        self.continuations
            .push((state.clone(), continuation.clone()));
        Ok(())
    }
}

/// The run of `analysis` from `start` (continued with `from` if given):
/// its steps and continuations.
fn run(
    model: &Arc<Model>,
    settings: &DynamicSettings,
    start: State,
    from: Option<Continuation>,
) -> Steps {
    let mut analysis = DynamicAnalysis::new(model.clone(), settings.clone());
    if from.is_some() {
        analysis = analysis.continued(from);
    }
    let mut steps = Steps::default();
    let mut step = analysis.start(start, &mut steps);
    while let Step::Increment(_) = step {
        step = analysis.advance(&mut steps);
    }
    let out = analysis.finish();
    assert!(out.error.is_none(), "{:?}", out.error);
    steps
}

/// The bits of every number of a state.
fn bits(s: &State) -> Vec<u64> {
    let v = serde_json::to_value(s).unwrap();
    let mut out = Vec::new();
    fn flat(v: &serde_json::Value, out: &mut Vec<u64>) {
        match v {
            serde_json::Value::Number(n) => out.push(n.as_f64().unwrap().to_bits()),
            serde_json::Value::Array(a) => a.iter().for_each(|x| flat(x, out)),
            serde_json::Value::Object(o) => o.values().for_each(|x| flat(x, out)),
            _ => {}
        }
    }
    flat(&v, &mut out);
    out
}

/// Runs the first analysis of `text` whole, then continued from each of
/// its steps (every `stride`-th); returns the whole run's steps and how
/// many of its continuations were regrowing after a lock.
fn continued_from_every_step(text: &str, stride: usize) -> (Steps, usize) {
    let (model, analyses) = parse(text);
    let settings = analyses[0].as_dynamic().unwrap().clone();
    let whole = run(&model, &settings, model.initial_state(), None);
    // the start and each accepted step report one continuation
    assert_eq!(whole.continuations.len(), whole.increments.len());
    let regrowing = whole
        .continuations
        .iter()
        .filter(|(_, c)| c.regrowing)
        .count();
    let last = whole.continuations.len() - 1;
    for k in (1..last).step_by(stride) {
        // through the JSON of a restart file
        let (state, continuation) = &whole.continuations[k];
        let state: State = serde_json::from_str(&serde_json::to_string(state).unwrap()).unwrap();
        let continuation: Continuation =
            serde_json::from_str(&serde_json::to_string(continuation).unwrap()).unwrap();
        let part = run(&model, &settings, state, Some(continuation));
        // the same steps after k (the continued run's step 0 is step k)
        assert_eq!(
            part.increments.len(),
            whole.increments.len() - k,
            "continued from step {k} (t = {})",
            whole.increments[k].time
        );
        for (j, (a, b)) in whole.continuations[k + 1..]
            .iter()
            .zip(&part.continuations[1..])
            .enumerate()
        {
            let at = k + 1 + j;
            assert_eq!(
                a.0.time.to_bits(),
                b.0.time.to_bits(),
                "continued from step {k}: step {at} at t = {} instead of {}",
                b.0.time,
                a.0.time
            );
            assert!(
                bits(&a.0) == bits(&b.0),
                "continued from step {k}: the state of step {at} (t = {}) differs",
                a.0.time
            );
            assert_eq!(
                a.1, b.1,
                "continued from step {k}: the continuation of step {at} differs"
            );
        }
    }
    (whole, regrowing)
}

/// The panel of tests/common/hinged_panel.rs opened by its spring into a
/// rigid latch at 90° (locked at t ≈ 0.4275 s), to 0.5 s: continued from
/// every step, with adaptive steps (the landing on the lock, the steps
/// doubling after it) and with fixed steps of 0.01 s (the step after the
/// lock bounded to 4 times the landing step, the steps then growing by
/// 1.5 a step back to `time_step`), it repeats the whole run.
#[test]
fn a_run_continued_from_any_step_around_a_lock_repeats_the_whole_run() {
    for (analysis, fixed) in [("", false), ("adaptive = false", true)] {
        let text = common::hinged_panel::latched_panel(
            "panel on a rigid latch",
            &format!(
                "[analysis]\ntype = \"dynamic\"\nend_time = 0.5\ntime_step = 0.01\n{analysis}"
            ),
            90.0,
            "",
        );
        let (whole, regrowing) = continued_from_every_step(&text, 1);
        // the lock happened, and the steps after it were shorter than
        // time_step for a while (growing back from the landing step)
        assert_eq!(whole.locks.len(), 1);
        let lock = whole
            .increments
            .iter()
            .position(|i| i.time == whole.locks[0])
            .unwrap();
        assert!(whole.increments[lock].step < 1e-4);
        assert!(whole.increments[lock + 4].step < 1e-3);
        // with fixed steps the regrowth bound holds the step after the
        // lock (docs/theory.md §16)
        assert_eq!(regrowing > 0, fixed, "{regrowing}");
    }
}

/// The ball of tests/stops.rs (2 kg on a vertical slider under gravity)
/// dropped from 1 m on a stop with `e = 0.5`: continued from every step
/// through its impacts (each landed on, the step
/// after a rebound sized to the top of its flight) and the closure of
/// the stop (the steps resuming with the size before its landing), it
/// repeats the whole run.
#[test]
fn a_run_continued_from_any_step_around_impacts_and_a_closure_repeats_the_whole_run() {
    let text = common::ball::dropped(
        1.5,
        r#"[[nodes]]
id = 1
x = [0.0, 0.0, 0.0]

[[point_masses]]
id = 1
node = 1
mass = 2.0

[[joints]]
id = 10
type = "prismatic"
nodes = [1]
axis = [0.0, 0.0, 1.0]
position = [0.0, 0.0, 0.0]

[[stops]]
id = 20
joint = 10
lower = -1.0
restitution = 0.5"#,
        "",
    );
    let (whole, _) = continued_from_every_step(&text, 1);
    assert!(whole.increments.len() > 50, "{}", whole.increments.len());
}

/// The panel of tests/common/spring_latch.rs spinning at 2 rad/s into a
/// spring latch of 300 N·m/rad with a dead band of 0.1 rad, with adaptive
/// steps at ρ∞ = 0.5: continued from every step through its latching and
/// the landings on the edges of the band, it repeats the whole run.
#[test]
fn a_run_continued_from_any_step_of_a_rattle_repeats_the_whole_run() {
    let text = common::spring_latch::spinning_into_latch(
        "end_time = 0.6\ntime_step = 0.01",
        &format!("backlash = {}", common::spring_latch::BACKLASH),
        "",
    );
    let (whole, _) = continued_from_every_step(&text, 1);
    assert!(whole.increments.len() > 50, "{}", whole.increments.len());
}
