//! Load curves: scalar functions `f(t)` of the load parameter (pseudo-time
//! in statics) that scale loads, gravity, prescribed motions and drivers:
//! piecewise-linear tables or simple functions, and the built-in `ramp`
//! (`f = t`) and `constant` (`f = 1`).
//!
//! Besides evaluation, a curve gives two bounds the model builder checks
//! before a run (docs/model-format.md, "Curves"): the largest `|f|` over
//! the analysis ([`Curve::magnitude`]), so that `value·f(t)` is known to
//! stay finite, and the largest change of `f` over one increment
//! ([`Curve::largest_change`]), so that a driver asking for more than half
//! a turn per increment is noticed.

/// A simple function of `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Function {
    /// `offset + slope·t`.
    Linear {
        /// Value at `t = 0`.
        offset: f64,
        /// Slope.
        slope: f64,
    },
    /// `offset + amplitude·sin(2π·frequency·t + phase)`.
    Sine {
        /// Mean value.
        offset: f64,
        /// Amplitude.
        amplitude: f64,
        /// Frequency (cycles per unit of `t`).
        frequency: f64,
        /// Phase (rad).
        phase: f64,
    },
    /// From `from` at `t ≤ start` to `to` at `t ≥ end` along the quintic
    /// `s(τ) = τ³(10 − 15τ + 6τ²)`, `τ = (t − start)/(end − start)`: zero
    /// rate and acceleration at both ends (a smooth actuator stroke).
    SmoothStep {
        /// Start of the transition.
        start: f64,
        /// End of the transition.
        end: f64,
        /// Value before.
        from: f64,
        /// Value after.
        to: f64,
    },
}

impl Function {
    /// Largest `|f(t)|` for `t` in `[0, t_end]`: exact for a linear
    /// function and a smooth step (monotone), `|offset| + |amplitude|` for a
    /// sine.
    pub fn magnitude(&self, t_end: f64) -> f64 {
        match *self {
            Self::Linear { .. } => self.value(0.0).abs().max(self.value(t_end).abs()),
            Self::Sine {
                offset, amplitude, ..
            } => offset.abs() + amplitude.abs(),
            Self::SmoothStep { from, to, .. } => from.abs().max(to.abs()),
        }
    }

    /// Smallest and largest `f(t)` for `t` in `[0, t_end]`, exactly
    /// (both are reached).
    pub fn range(&self, t_end: f64) -> (f64, f64) {
        let (f0, f1) = (self.value(0.0), self.value(t_end));
        let (mut lo, mut hi) = (f0.min(f1), f0.max(f1));
        if let Self::Sine {
            offset,
            amplitude,
            frequency,
            phase,
        } = *self
        {
            // the phase θ = 2π·frequency·t + phase sweeps [a, b]; sin θ = ±1
            // where θ = ±π/2 + 2πk
            let theta = std::f64::consts::TAU * frequency * t_end + phase;
            let (a, b) = (phase.min(theta), phase.max(theta));
            let reaches = |c: f64| {
                let tau = std::f64::consts::TAU;
                ((a - c) / tau).ceil() <= ((b - c) / tau).floor()
            };
            for (c, sign) in [
                (std::f64::consts::FRAC_PI_2, 1.0),
                (-std::f64::consts::FRAC_PI_2, -1.0),
            ] {
                if reaches(c) {
                    let v = offset + sign * amplitude;
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
        }
        // a linear function and a smooth step are monotone
        (lo, hi)
    }

    /// Largest `|f(t + h) − f(t)|` for `0 ≤ t ≤ t + h ≤ t_end` (an upper
    /// bound for a sine).
    pub fn largest_change(&self, h: f64, t_end: f64) -> f64 {
        let h = h.min(t_end).max(0.0);
        match *self {
            Self::Linear { slope, .. } => slope.abs() * h,
            // |sin(a + 2πfh) − sin(a)| = 2|sin(πfh)|·|cos(a + πfh)| ≤ 2|sin(πfh)|
            Self::Sine {
                amplitude,
                frequency,
                ..
            } => {
                let half = std::f64::consts::PI * (frequency * h).abs();
                let s = if half < std::f64::consts::FRAC_PI_2 {
                    half.sin()
                } else {
                    1.0
                };
                2.0 * amplitude.abs() * s
            }
            // the steepest window is centred on the middle of the
            // transition (the rate s'(τ) = 30τ²(1 − τ)² peaks at τ = ½)
            Self::SmoothStep { start, end, .. } => {
                let mid = 0.5 * (start + end);
                (self.value(mid + 0.5 * h) - self.value(mid - 0.5 * h)).abs()
            }
        }
    }

    /// Evaluates the function.
    pub fn value(&self, t: f64) -> f64 {
        match *self {
            Self::Linear { offset, slope } => offset + slope * t,
            Self::Sine {
                offset,
                amplitude,
                frequency,
                phase,
            } => offset + amplitude * (std::f64::consts::TAU * frequency * t + phase).sin(),
            Self::SmoothStep {
                start,
                end,
                from,
                to,
            } => {
                let tau = ((t - start) / (end - start)).clamp(0.0, 1.0);
                from + (to - from) * tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)
            }
        }
    }
}

/// A curve `f(t)`: a piecewise-linear table through points `(tᵢ, fᵢ)` with
/// strictly increasing `tᵢ`, held constant before the first and after the
/// last point, or a [`Function`]. The built-in [`Curve::ramp`] is
/// `f(t) = t` for every `t`, the built-in [`Curve::constant`] `f(t) = 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    name: String,
    points: Vec<(f64, f64)>,
    function: Option<Function>,
}

impl Curve {
    /// Name of the built-in ramp.
    pub const RAMP: &'static str = "ramp";

    /// Name of the built-in constant.
    pub const CONSTANT: &'static str = "constant";

    /// The built-in ramp `f(t) = t` (no clamping).
    pub fn ramp() -> Self {
        Self {
            name: Self::RAMP.to_string(),
            points: Vec::new(),
            function: None,
        }
    }

    /// The built-in constant `f(t) = 1`: a load applied in full from
    /// `t = 0`.
    pub fn constant() -> Self {
        Self::function(
            Self::CONSTANT,
            Function::Linear {
                offset: 1.0,
                slope: 0.0,
            },
        )
    }

    /// A piecewise-linear curve. The caller guarantees at least one point
    /// and strictly increasing abscissae (see `model::build`).
    pub fn piecewise_linear(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        debug_assert!(!points.is_empty());
        debug_assert!(points.windows(2).all(|w| w[1].0 > w[0].0));
        Self {
            name: name.into(),
            points,
            function: None,
        }
    }

    /// A curve given by a function. The caller guarantees finite
    /// parameters (and `start < end` for a smooth step).
    pub fn function(name: impl Into<String>, function: Function) -> Self {
        Self {
            name: name.into(),
            points: Vec::new(),
            function: Some(function),
        }
    }

    /// The curve's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A short description for messages: `f = t` for the ramp, `f = 1`
    /// for the constant, the kind of curve otherwise.
    pub fn describe(&self) -> &'static str {
        match (&self.function, self.points.is_empty()) {
            (None, true) => "f = t",
            (Some(_), _) if self.name == Self::CONSTANT => "f = 1",
            (Some(Function::Linear { .. }), _) => "linear",
            (Some(Function::Sine { .. }), _) => "sine",
            (Some(Function::SmoothStep { .. }), _) => "smooth step",
            (None, false) => "table",
        }
    }

    /// Largest `|f(t)|` for `t` in `[0, t_end]` (an upper bound for a
    /// sine).
    pub fn magnitude(&self, t_end: f64) -> f64 {
        match &self.function {
            Some(f) => f.magnitude(t_end),
            None if self.points.is_empty() => t_end.abs(),
            None => self.points.iter().fold(0.0, |m, p| m.max(p.1.abs())),
        }
    }

    /// Smallest and largest `f(t)` for `t` in `[0, t_end]` (both reached).
    pub fn range(&self, t_end: f64) -> (f64, f64) {
        match &self.function {
            Some(f) => f.range(t_end),
            None => {
                // piecewise linear (or the ramp): the extremes are at the
                // ends or at breakpoints
                let mut values = vec![self.value(0.0), self.value(t_end)];
                values.extend(
                    self.points
                        .iter()
                        .filter(|p| p.0 > 0.0 && p.0 < t_end)
                        .map(|p| p.1),
                );
                values
                    .into_iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v), hi.max(v))
                    })
            }
        }
    }

    /// Largest `|f(t + h) − f(t)|` for `0 ≤ t ≤ t + h ≤ t_end`: what one
    /// increment `h` asks of a quantity following the curve (an upper bound
    /// for a sine).
    pub fn largest_change(&self, h: f64, t_end: f64) -> f64 {
        let h = h.min(t_end).max(0.0);
        match &self.function {
            Some(f) => f.largest_change(h, t_end),
            None if self.points.is_empty() => h,
            None => {
                // piecewise linear: the largest change over a window of
                // width h is found with a window end on a breakpoint or on
                // an end of [0, t_end]
                let mut starts: Vec<f64> = vec![0.0, t_end - h];
                for p in &self.points {
                    starts.push(p.0);
                    starts.push(p.0 - h);
                }
                starts
                    .into_iter()
                    .map(|t| t.clamp(0.0, t_end - h))
                    .map(|t| (self.value(t + h) - self.value(t)).abs())
                    .fold(0.0, f64::max)
            }
        }
    }

    /// The largest step `h` (at most `t_end`) over which a quantity
    /// `amplitude·f(t)` changes by at most `limit` anywhere in
    /// `[0, t_end]`: bisection on [`Self::largest_change`], which grows
    /// with `h`, to a relative 1e-9 (the `h` returned is on the safe
    /// side). `t_end` when the whole range changes by less.
    pub fn largest_step(&self, amplitude: f64, limit: f64, t_end: f64) -> f64 {
        let change = |h: f64| amplitude.abs() * self.largest_change(h, t_end);
        if t_end.is_nan() || t_end <= 0.0 || change(t_end) <= limit {
            return t_end.max(0.0);
        }
        let (mut lo, mut hi) = (0.0, t_end);
        while hi - lo > 1e-9 * hi {
            let mid = 0.5 * (lo + hi);
            if change(mid) <= limit {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Whether `f` takes one value over `[0, t_end]`.
    pub fn is_constant_on(&self, t_end: f64) -> bool {
        match self.function {
            Some(Function::Linear { slope, .. }) => slope == 0.0,
            Some(Function::Sine {
                amplitude,
                frequency,
                ..
            }) => amplitude == 0.0 || frequency == 0.0,
            Some(Function::SmoothStep {
                start,
                end,
                from,
                to,
            }) => from == to || end <= 0.0 || start >= t_end,
            None if self.points.is_empty() => t_end == 0.0,
            None => {
                let f0 = self.value(0.0);
                self.value(t_end) == f0
                    && self
                        .points
                        .iter()
                        .filter(|p| p.0 > 0.0 && p.0 < t_end)
                        .all(|p| p.1 == f0)
            }
        }
    }

    /// Evaluates `f(t)`.
    pub fn value(&self, t: f64) -> f64 {
        if let Some(f) = &self.function {
            return f.value(t);
        }
        let p = &self.points;
        if p.is_empty() {
            return t;
        }
        if t <= p[0].0 {
            return p[0].1;
        }
        if t >= p[p.len() - 1].0 {
            return p[p.len() - 1].1;
        }
        // first point with abscissa > t
        let k = p.partition_point(|&(ti, _)| ti <= t);
        let (t0, f0) = p[k - 1];
        let (t1, f1) = p[k];
        f0 + (f1 - f0) * (t - t0) / (t1 - t0)
    }
}

/// Index of a curve in [`crate::model::Model::curves`].
pub type CurveIndex = usize;

#[cfg(test)]
mod tests {
    use super::*;

    /// The range against a dense sampling of `[0, t_end]`: never narrower,
    /// and wider by less than 1e-6 (the sampling steps of the sines' phase
    /// are at most 1.3e-4 rad, so their samples fall short of the
    /// extremes by at most 1e-8 of the amplitude).
    #[test]
    fn ranges_are_exact() {
        let curves = [
            Curve::ramp(),
            Curve::constant(),
            Curve::piecewise_linear("t", vec![(0.5, -2.0), (0.7, 3.0), (2.0, 1.0)]),
            Curve::function(
                "s",
                Function::Sine {
                    offset: 0.5,
                    amplitude: -2.0,
                    frequency: 0.3,
                    phase: 0.2,
                },
            ),
            Curve::function(
                "s2",
                Function::Sine {
                    offset: 0.0,
                    amplitude: 1.0,
                    frequency: 2.0,
                    phase: 0.0,
                },
            ),
            Curve::function(
                "st",
                Function::SmoothStep {
                    start: 0.2,
                    end: 0.6,
                    from: 1.0,
                    to: -1.0,
                },
            ),
            Curve::function(
                "l",
                Function::Linear {
                    offset: 1.0,
                    slope: -3.0,
                },
            ),
        ];
        for c in &curves {
            let (lo, hi) = c.range(1.0);
            let n = 100_000;
            let (mut slo, mut shi) = (f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..=n {
                let v = c.value(i as f64 / n as f64);
                slo = slo.min(v);
                shi = shi.max(v);
            }
            assert!(
                lo <= slo && hi >= shi,
                "{}: {lo} {hi} vs {slo} {shi}",
                c.name()
            );
            assert!(
                slo - lo < 1e-6 && hi - shi < 1e-6,
                "{}: {lo} {hi} vs {slo} {shi}",
                c.name()
            );
        }
    }

    /// The largest step keeps the change within the limit and is the
    /// largest that does: for the ramp `h = limit/amplitude`; for a table
    /// the steepest segment sets it; a slow curve allows the whole range.
    #[test]
    fn largest_step_bounds_the_change() {
        let ramp = Curve::ramp();
        let h = ramp.largest_step(4.0 * std::f64::consts::PI, 0.5 * std::f64::consts::PI, 1.0);
        assert!((h - 0.125).abs() <= 1e-9 * 0.125, "{h}");
        let table =
            Curve::piecewise_linear("t", vec![(0.0, 0.0), (0.5, 0.1), (0.6, 1.1), (1.0, 1.2)]);
        // steepest segment: slope 10 over 0.1
        let h = table.largest_step(1.0, 0.5, 1.0);
        assert!((h - 0.05).abs() <= 1e-9, "{h}");
        assert!(table.largest_change(h, 1.0) <= 0.5);
        assert!(table.largest_change(h * (1.0 + 1e-6), 1.0) > 0.5);
        assert_eq!(ramp.largest_step(1.0, 2.0, 1.0), 1.0);
    }

    #[test]
    fn functions() {
        let s = Function::SmoothStep {
            start: 1.0,
            end: 3.0,
            from: 2.0,
            to: -1.0,
        };
        assert_eq!(s.value(0.0), 2.0);
        assert_eq!(s.value(1.0), 2.0);
        assert_eq!(s.value(2.0), 0.5);
        assert_eq!(s.value(3.0), -1.0);
        assert_eq!(s.value(9.0), -1.0);
        // zero slope at the ends
        let h = 1e-6;
        assert!((s.value(1.0 + h) - s.value(1.0)).abs() < 1e-12);
        let w = Function::Sine {
            offset: 1.0,
            amplitude: 2.0,
            frequency: 0.25,
            phase: 0.0,
        };
        assert!((w.value(1.0) - 3.0).abs() < 1e-15);
        let l = Function::Linear {
            offset: 1.0,
            slope: -2.0,
        };
        assert_eq!(Curve::function("l", l).value(2.0), -3.0);
    }

    #[test]
    fn constant_is_one() {
        let c = Curve::constant();
        assert_eq!(c.name(), "constant");
        assert_eq!(c.value(0.0), 1.0);
        assert_eq!(c.value(7.5), 1.0);
        assert!(c.is_constant_on(3.0));
        assert!(!Curve::ramp().is_constant_on(3.0));
        assert_eq!(c.largest_change(0.5, 3.0), 0.0);
    }

    /// The bounds against a brute-force scan of the curve (a fine sampling
    /// of every window; the bounds must hold and, except for the sine,
    /// which is bounded, be reached within the sampling error).
    #[test]
    fn magnitude_and_largest_change_bound_the_curve() {
        let curves = [
            Curve::ramp(),
            Curve::constant(),
            Curve::function(
                "l",
                Function::Linear {
                    offset: -1.0,
                    slope: 3.0,
                },
            ),
            Curve::function(
                "s",
                Function::SmoothStep {
                    start: 0.5,
                    end: 1.5,
                    from: 2.0,
                    to: -1.0,
                },
            ),
            Curve::function(
                "w",
                Function::Sine {
                    offset: 0.5,
                    amplitude: 2.0,
                    frequency: 0.7,
                    phase: 0.3,
                },
            ),
            Curve::piecewise_linear("p", vec![(0.2, 0.0), (0.3, 4.0), (1.0, 4.5), (1.6, -2.0)]),
        ];
        let (t_end, h) = (2.0, 0.25);
        let n = 8000;
        for c in &curves {
            let t = |k: usize| t_end * k as f64 / n as f64;
            let magnitude = (0..=n).map(|k| c.value(t(k)).abs()).fold(0.0, f64::max);
            let m = (h / t_end * n as f64) as usize;
            let change = (0..=n - m)
                .map(|k| (c.value(t(k + m)) - c.value(t(k))).abs())
                .fold(0.0, f64::max);
            let (mb, cb) = (c.magnitude(t_end), c.largest_change(h, t_end));
            assert!(mb >= magnitude - 1e-12, "{}: {mb} < {magnitude}", c.name());
            assert!(cb >= change - 1e-12, "{}: {cb} < {change}", c.name());
            if c.name() != "w" {
                // exact bounds, up to the sampling step t_end/n
                assert!(mb - magnitude < 1e-2, "{}: {mb} vs {magnitude}", c.name());
                assert!(cb - change < 1e-2, "{}: {cb} vs {change}", c.name());
            }
        }
    }

    #[test]
    fn ramp_is_identity() {
        let r = Curve::ramp();
        assert_eq!(r.value(0.3), 0.3);
        assert_eq!(r.value(2.5), 2.5);
    }

    #[test]
    fn piecewise_linear_interpolates_and_holds_ends() {
        let c = Curve::piecewise_linear("c", vec![(0.0, 0.0), (1.0, 2.0), (3.0, 2.0), (4.0, -1.0)]);
        assert_eq!(c.value(-1.0), 0.0);
        assert_eq!(c.value(0.5), 1.0);
        assert_eq!(c.value(1.0), 2.0);
        assert_eq!(c.value(2.0), 2.0);
        assert_eq!(c.value(3.5), 0.5);
        assert_eq!(c.value(10.0), -1.0);
    }
}
