//! Implicit dynamics (Lie-group generalised-α, src/analysis/dynamics.rs,
//! docs/theory.md §15): periods, conservation, step control, sequences and
//! input errors.

mod common;

use std::sync::Arc;

use common::elliptic::complete_k;

use unfold::analysis::{AnalysisSettings, DynamicAnalysis, IncrementInfo, IterationInfo, Observer};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// Every accepted step with its state, and the residual history.
#[derive(Default)]
struct Trace {
    steps: Vec<(IncrementInfo, State)>,
    iterations: Vec<IterationInfo>,
}

impl Observer for Trace {
    fn iteration(&mut self, info: &IterationInfo) {
        self.iterations.push(info.clone());
    }
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _: &Model,
        state: &State,
        _: &[f64],
    ) -> std::io::Result<()> {
        self.steps.push((info.clone(), state.clone()));
        Ok(())
    }
}

fn parse(text: &str) -> (Arc<Model>, Vec<AnalysisSettings>) {
    let input: ModelInput = toml::from_str(text).expect("valid toml");
    let model = Model::from_input(&input).expect("valid model");
    (Arc::new(model), input.analyses().expect("valid analyses"))
}

/// The pendulum of tests/common/pendulum.rs: a body of mass 2 kg, centre
/// of mass at 0.5 m from a revolute joint (id 2) about z at the origin,
/// inertia 0.1 kg·m² about the centre, released from the horizontal under
/// g = 9.81.
fn pendulum(analysis: &str) -> String {
    common::pendulum::pendulum(analysis, 2, None, "")
}

/// The events of a run.
#[derive(Default)]
struct Events {
    trace: Trace,
    times: Vec<f64>,
}

impl Observer for Events {
    fn iteration(&mut self, info: &IterationInfo) {
        self.trace.iteration(info);
    }
    fn increment(
        &mut self,
        i: &IncrementInfo,
        m: &Model,
        s: &State,
        r: &[f64],
    ) -> std::io::Result<()> {
        self.trace.increment(i, m, s, r)
    }
}

/// A physical pendulum released from the horizontal: the period against
/// the exact `4 √(I_O/(m g d)) K(sin(θ₀/2))`, θ₀ = 90°; Newton converges
/// in at most 3 iterations per step (quadratically).
#[test]
fn pendulum_period_matches_the_elliptic_integral() {
    let (model, analyses) = parse(&pendulum(
        "[analysis]\ntype = \"dynamic\"\nend_time = 2.0\ntime_step = 0.01\nerror_tolerance = 1e-5\n",
    ));
    let settings = analyses[0].as_dynamic().unwrap().clone();
    let mut a = DynamicAnalysis::new(model.clone(), settings);
    let mut obs = Events::default();
    let out = a.run(model.initial_state(), &mut obs);
    // the bottom (x = 0) passed within a step: the root of the cubic
    // Hermite interpolant of x(t) from x and ẋ at both ends
    for w in obs.trace.steps.windows(2) {
        let ((i0, s0), (i1, s1)) = (&w[0], &w[1]);
        let (x0, x1) = (s0.x[1].x, s1.x[1].x);
        if x0 * x1 > 0.0 || x0 == x1 {
            continue;
        }
        let h = i1.time - i0.time;
        let (d0, d1) = (s0.velocity[1][0] * h, s1.velocity[1][0] * h);
        let p = |u: f64| {
            let (u2, u3) = (u * u, u * u * u);
            (2.0 * u3 - 3.0 * u2 + 1.0) * x0
                + (u3 - 2.0 * u2 + u) * d0
                + (-2.0 * u3 + 3.0 * u2) * x1
                + (u3 - u2) * d1
        };
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if p(lo) * p(mid) <= 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        obs.times.push(i0.time + lo * h);
    }
    assert!(out.error.is_none(), "{:?}", out.error);
    // I_O = J + m d² = 0.1 + 2·0.25, m g d = 2·9.81·0.5
    let (i_o, mgd) = (0.6f64, 9.81f64);
    let exact = 4.0 * (i_o / mgd).sqrt() * complete_k(0.5) /* m = sin²(θ₀/2) = 1/2 */;
    // the bottom is passed at T/4 and 3T/4
    assert!(obs.times.len() >= 2, "{:?}", obs.times);
    let period = 2.0 * (obs.times[1] - obs.times[0]);
    let error = (period - exact).abs() / exact;
    eprintln!("period {period} exact {exact} relative error {error:.3e}; steps {} rejected {} iterations {}", out.steps, out.rejected_steps, out.iterations);
    // source: the exact period of the physical pendulum; 1e-4 relative
    assert!(error < 1e-4, "period {period}, exact {exact}");
    // quadratic Newton: at most 3 corrections per step
    let most = obs
        .trace
        .steps
        .iter()
        .map(|(i, _)| i.iterations)
        .max()
        .unwrap();
    assert!(most <= 3, "{most} iterations");
}
