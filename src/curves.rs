//! Load curves: scalar functions `f(t)` of the load parameter (pseudo-time
//! in statics) that scale loads, gravity and prescribed motions.

/// A piecewise-linear curve through points `(tᵢ, fᵢ)` with strictly
/// increasing `tᵢ`, held constant before the first and after the last point.
/// The built-in [`Curve::ramp`] is `f(t) = t` for every `t`.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    name: String,
    points: Vec<(f64, f64)>,
}

impl Curve {
    /// Name of the built-in ramp.
    pub const RAMP: &'static str = "ramp";

    /// The built-in ramp `f(t) = t` (no clamping).
    pub fn ramp() -> Self {
        Self {
            name: Self::RAMP.to_string(),
            points: Vec::new(),
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
        }
    }

    /// The curve's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Evaluates `f(t)`.
    pub fn value(&self, t: f64) -> f64 {
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
