//! Load curves: scalar functions `f(t)` of the load parameter (pseudo-time
//! in statics) that scale loads, gravity, prescribed motions and drivers:
//! piecewise-linear tables or simple functions.

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
/// `f(t) = t` for every `t`.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    name: String,
    points: Vec<(f64, f64)>,
    function: Option<Function>,
}

impl Curve {
    /// Name of the built-in ramp.
    pub const RAMP: &'static str = "ramp";

    /// The built-in ramp `f(t) = t` (no clamping).
    pub fn ramp() -> Self {
        Self {
            name: Self::RAMP.to_string(),
            points: Vec::new(),
            function: None,
        }
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
