//! Hinge laws with memory: a hysteretic moment on a joint coordinate `c`
//! (docs/joints.md §4.1), for the torsion springs of deployment hinges
//! whose moment near the locking angle depends on whether the hinge is
//! locking or unlocking (tape-spring hinges; reference paper §6.3,
//! figure 10).
//!
//! Two bounding branches `f_load(c) ≥ f_unload(c)` (equal outside the
//! hysteresis band) and an elastic slope `k_e` between them give the
//! one-dimensional return map
//!
//! ```text
//! M_trial = M_n + k_e (c − c_n),   M = clamp(M_trial, f_unload(c), f_load(c))
//! ```
//!
//! from the last converged state `(c_n, M_n)`, with the consistent tangent
//! `dM/dc = k_e` inside and `f′` on a bound. Like a joint spring, `M`
//! opposes an increase of `c`: the residual receives `M g`, `g = ∂c/∂q`,
//! the stiffness `(dM/dc) g gᵀ + M ∂g/∂q`.

use super::coordinate::PairCoordinate;
use super::kinematics::with_scratch;
use crate::elements::{CellShape, Element, ElementKind, ElementOutput, EvalContext, Offsets};
use crate::model::Id;
use crate::state::State;

/// A bounding branch: a polyline through points `(cᵢ, fᵢ)` (at least
/// two, strictly increasing `cᵢ`), extended beyond its end points with the
/// slopes of its end segments, whose interior corners are rounded by
/// parabolas: on `[cᵢ − hᵢ, cᵢ + hᵢ]`, with `s₋`, `s₊` the slopes of the
/// segments on either side,
///
/// ```text
/// f(c) = fᵢ + s₋ (c − cᵢ) + (s₊ − s₋) (c − cᵢ + hᵢ)² / (4 hᵢ),
/// ```
///
/// tangent to both segments at the ends of the interval (value and slope
/// continuous), `hᵢ = min(h, half of each adjacent segment)`. With `h = 0`
/// it is the piecewise-linear table of joint springs.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    points: Vec<(f64, f64)>,
    /// Half-width of the rounding of each point (0 at the end points).
    half: Vec<f64>,
}

impl Branch {
    /// The polyline through `points`, its corners rounded with half-width
    /// `rounding` (0: a piecewise-linear table). The caller checks the
    /// points (at least two, finite, strictly increasing abscissae).
    pub fn new(points: Vec<(f64, f64)>, rounding: f64) -> Self {
        let n = points.len();
        let half = (0..n)
            .map(|i| {
                if i == 0 || i + 1 == n {
                    0.0
                } else {
                    let left = points[i].0 - points[i - 1].0;
                    let right = points[i + 1].0 - points[i].0;
                    rounding.min(0.5 * left).min(0.5 * right).max(0.0)
                }
            })
            .collect();
        Self { points, half }
    }

    /// The points of the polyline.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    fn slope(&self, k: usize) -> f64 {
        let (a, b) = (self.points[k - 1], self.points[k]);
        (b.1 - a.1) / (b.0 - a.0)
    }

    /// `(f(c), f′(c))`.
    pub fn eval(&self, c: f64) -> (f64, f64) {
        let p = &self.points;
        let n = p.len();
        // segment k joins points k − 1 and k
        let k = p.partition_point(|&(xi, _)| xi <= c).clamp(1, n - 1);
        // the rounded corner c lies in, if any: at point k − 1 or k
        for i in [k - 1, k] {
            let h = self.half[i];
            if h > 0.0 && (c - p[i].0).abs() < h {
                let (sl, sr) = (self.slope(i), self.slope(i + 1));
                let t = c - p[i].0 + h;
                let f = p[i].1 + sl * (c - p[i].0) + (sr - sl) * t * t / (4.0 * h);
                return (f, sl + (sr - sl) * t / (2.0 * h));
            }
        }
        let s = self.slope(k);
        (p[k - 1].1 + s * (c - p[k - 1].0), s)
    }

    /// Abscissae where the branch changes piece: its points and the ends of
    /// its rounded corners.
    fn breaks(&self, out: &mut Vec<f64>) {
        for (&(x, _), &h) in self.points.iter().zip(&self.half) {
            out.push(x);
            if h > 0.0 {
                out.push(x - h);
                out.push(x + h);
            }
        }
    }

    /// Slopes beyond the first and the last point.
    fn end_slopes(&self) -> (f64, f64) {
        (self.slope(1), self.slope(self.points.len() - 1))
    }
}

/// The analytic tape-spring shape (docs/joints.md §4.1): parameters in
/// radians (or metres) and N·m (or N), all positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TapeSpring {
    /// `M_d`: moment that deploys the hinge over its travel (≥ 0).
    pub deployment_moment: f64,
    /// `c_L`: coordinate at which the hinge locks.
    pub locking_angle: f64,
    /// `M_L > M_d`: moment needed to unlock (fold) a locked hinge.
    pub locking_peak: f64,
    /// `K`: slope of the locked branch through `(c_L, 0)`.
    pub locked_stiffness: f64,
    /// `w`: width over which the moment falls from `M_L` back to `M_d`
    /// once the hinge unlocks (the snap).
    pub snap_width: f64,
    /// `h ≥ 0`: half-width of the rounding of the corners.
    pub rounding: f64,
}

impl TapeSpring {
    /// The two bounding branches `(f_load, f_unload)`, moments opposing an
    /// increase of `c` (negative while the hinge deploys):
    /// - `f_load` (deploying, `c` increasing): `−M_d` up to
    ///   `c_a = c_L − M_d/K`, then the locked branch `K (c − c_L)`;
    /// - `f_unload` (folding, `c` decreasing): the locked branch down to
    ///   `−M_L` at `c_u = c_L − M_L/K`, then back to `−M_d` at
    ///   `c_u − w` (a straight snap), `−M_d` below;
    ///
    /// every corner rounded with half-width `h` ([`Branch`]).
    pub fn branches(&self) -> (Branch, Branch) {
        let (md, ml, k) = (
            self.deployment_moment,
            self.locking_peak,
            self.locked_stiffness,
        );
        let cl = self.locking_angle;
        // end segments long enough not to limit the rounding
        let reach = (2.0 * self.rounding)
            .max(self.snap_width)
            .max(1e-3 * cl.abs().max(1.0));
        let ca = cl - md / k;
        let load = vec![(ca - reach, -md), (ca, -md), (ca + reach, -md + k * reach)];
        let cu = cl - ml / k;
        let cs = cu - self.snap_width;
        let unload = vec![
            (cs - reach, -md),
            (cs, -md),
            (cu, -ml),
            (cu + reach, -ml + k * reach),
        ];
        (
            Branch::new(load, self.rounding),
            Branch::new(unload, self.rounding),
        )
    }
}

/// The response of the law at a coordinate: moment, tangent and which
/// part of the law gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// `M`, opposing an increase of `c`.
    pub moment: f64,
    /// Consistent tangent `dM/dc`.
    pub tangent: f64,
    /// 1 on the loading bound, −1 on the unloading bound, 0 inside.
    pub branch: f64,
}

/// The hysteretic law: two bounding branches and the elastic slope.
#[derive(Clone, Debug, PartialEq)]
pub struct Hysteresis {
    /// `f_load`, the upper bound, followed while `c` increases.
    pub load: Branch,
    /// `f_unload`, the lower bound, followed while `c` decreases.
    pub unload: Branch,
    /// `k_e > 0`, the slope inside the band.
    pub elastic: f64,
}

impl Hysteresis {
    /// The return map from the converged state `(c_n, M_n)`:
    /// `M = clamp(M_n + k_e (c − c_n), f_unload(c), f_load(c))` and its
    /// consistent tangent. Where the bounds meet, the loading bound is
    /// reported when the trial reaches it.
    pub fn respond(&self, c: f64, c_n: f64, m_n: f64) -> Response {
        let trial = m_n + self.elastic * (c - c_n);
        let (hi, dhi) = self.load.eval(c);
        if trial >= hi {
            return Response {
                moment: hi,
                tangent: dhi,
                branch: 1.0,
            };
        }
        let (lo, dlo) = self.unload.eval(c);
        if trial <= lo {
            return Response {
                moment: lo,
                tangent: dlo,
                branch: -1.0,
            };
        }
        Response {
            moment: trial,
            tangent: self.elastic,
            branch: 0.0,
        }
    }

    /// Relative difference below which two end slopes are taken as equal
    /// ([`Hysteresis::crossing`]).
    pub const SLOPE_TOLERANCE: f64 = 1e-9;

    /// Where `f_load < f_unload`, if anywhere: the first abscissa found.
    /// Both branches are piecewise quadratic, so their difference is
    /// checked exactly: at every break of either, at the minimum of the
    /// quadratic between consecutive breaks, and beyond the ends through
    /// the end slopes.
    pub fn crossing(&self) -> Option<f64> {
        let mut x = Vec::new();
        self.load.breaks(&mut x);
        self.unload.breaks(&mut x);
        x.sort_by(f64::total_cmp);
        x.dedup();
        let d = |c: f64| self.load.eval(c).0 - self.unload.eval(c).0;
        // a tolerance for round-off in the evaluation of equal branches
        let scale = x
            .iter()
            .map(|&c| self.load.eval(c).0.abs().max(self.unload.eval(c).0.abs()))
            .fold(0.0f64, f64::max);
        let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
        for &c in &x {
            if d(c) < -tol {
                return Some(c);
            }
        }
        for w in x.windows(2) {
            let (a, b) = (w[0], w[1]);
            let m = 0.5 * (a + b);
            let (da, dm, db) = (d(a), d(m), d(b));
            // the quadratic through the three values, t ∈ [−1, 1]
            let curv = da + db - 2.0 * dm;
            if curv > 0.0 {
                let t = (da - db) / (2.0 * curv);
                if t.abs() < 1.0 {
                    let c = m + t * 0.5 * (b - a);
                    if d(c) < -tol {
                        return Some(c);
                    }
                }
            }
        }
        let (lo_l, hi_l) = self.load.end_slopes();
        let (lo_u, hi_u) = self.unload.end_slopes();
        let (first, last) = (x[0], x[x.len() - 1]);
        // beyond the ends the difference is linear: its slope decides,
        // compared to a relative tolerance for the round-off of slopes
        // computed from the points of two branches that share their end
        // segment (the locked branch of a tape spring, in any units)
        let below = |a: f64, b: f64| a < b - Self::SLOPE_TOLERANCE * a.abs().max(b.abs());
        if below(lo_u, lo_l) {
            return Some(first - 1.0);
        }
        if below(hi_l, hi_u) {
            return Some(last + 1.0);
        }
        None
    }

    /// The interval where the bounds differ (the hysteresis band), `None`
    /// if they are equal everywhere.
    pub fn band(&self) -> Option<(f64, f64)> {
        let mut x = Vec::new();
        self.load.breaks(&mut x);
        self.unload.breaks(&mut x);
        x.sort_by(f64::total_cmp);
        let d = |c: f64| self.load.eval(c).0 - self.unload.eval(c).0;
        let (first, last) = (x[0], x[x.len() - 1]);
        let open = |c: f64| d(c) > 0.0;
        if open(first - 1.0) || open(last + 1.0) {
            return Some((f64::NEG_INFINITY, f64::INFINITY));
        }
        let mut band: Option<(f64, f64)> = None;
        for w in x.windows(2) {
            if open(0.5 * (w[0] + w[1])) {
                band = Some(band.map_or((w[0], w[1]), |(a, _)| (a, w[1])));
            }
        }
        band
    }
}

/// A hysteretic law on a pair coordinate.
#[derive(Clone, Debug)]
pub struct HingeLaw {
    id: Id,
    source: PairCoordinate,
    law: Hysteresis,
    /// Moment in the reference configuration, before any converged state.
    start: f64,
    internal: usize,
}

/// Names of hinge-law results.
pub const HINGE_RESULTS: [&str; 3] = ["coordinate", "moment", "branch"];

impl HingeLaw {
    /// `law` on `source`, starting at moment `start` in the reference
    /// configuration (`c = 0`).
    pub fn new(id: Id, source: PairCoordinate, law: Hysteresis, start: f64) -> Self {
        Self {
            id,
            source,
            law,
            start,
            internal: 0,
        }
    }

    /// The law.
    pub fn law(&self) -> &Hysteresis {
        &self.law
    }

    /// The converged state `(c_n, M_n)` in `state`. The internal variables
    /// are `[c_n, M_n − M_start, branch]`: all zero before the first
    /// converged state, when the hinge is at `c = 0` with the moment
    /// `M_start`.
    fn converged(&self, state: &State) -> (f64, f64) {
        let v = &state.internal[self.internal..self.internal + 2];
        (v[0], v[1] + self.start)
    }

    fn reference(&self, c_n: f64) -> f64 {
        if self.source.is_angle() {
            c_n
        } else {
            0.0
        }
    }

    /// `(c, response)` at `state`.
    fn response(&self, state: &State) -> (f64, Response) {
        let (c_n, m_n) = self.converged(state);
        let c = self.source.value(state, self.reference(c_n));
        (c, self.law.respond(c, c_n, m_n))
    }
}

impl Element for HingeLaw {
    fn kind(&self) -> ElementKind {
        ElementKind::HingeLaw
    }
    fn id(&self) -> Id {
        self.id
    }
    fn nodes(&self) -> &[usize] {
        &self.source.nodes
    }
    fn n_internal(&self) -> usize {
        3
    }
    fn set_offsets(&mut self, offsets: Offsets) {
        self.internal = offsets.internal;
    }
    fn evaluate(&self, _ctx: &EvalContext, state: &State, out: &mut ElementOutput) {
        with_scratch(|sc| {
            let (c_n, m_n) = self.converged(state);
            // g = ∂c/∂q; H = ∂g/∂q when the stiffness is asked for
            let c =
                self.source
                    .evaluate_into(sc, state, self.reference(c_n), out.stiffness.is_some());
            let (n, g, h) = (sc.local.n(), &sc.grad, &sc.hess);
            let r = self.law.respond(c, c_n, m_n);
            for i in 0..n {
                out.residual[i] += r.moment * g[i];
            }
            let Some(stiffness) = out.stiffness.as_deref_mut() else {
                return;
            };
            // K = (dM/dc) g gᵀ + M ∂g/∂q
            for col in 0..n {
                for row in 0..n {
                    stiffness[col * n + row] +=
                        r.tangent * g[row] * g[col] + r.moment * h[col * n + row];
                }
            }
        });
    }
    fn update_internal(&self, _ctx: &EvalContext, state: &State, internal: &mut [f64]) {
        let (c_n, m_n) = (internal[0], internal[1] + self.start);
        let c = self.source.value(state, self.reference(c_n));
        let r = self.law.respond(c, c_n, m_n);
        internal[0] = c;
        internal[1] = r.moment - self.start;
        internal[2] = r.branch;
    }
    fn result_names(&self) -> &'static [&'static str] {
        &HINGE_RESULTS
    }
    fn results(&self, _ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let (c, r) = self.response(state);
        // at a converged state (c = c_n) the trial is M_n itself and says
        // nothing of the direction of motion: the branch is the one the
        // increment that led there ended on (where the bounds meet, 1 if
        // c increased, −1 if it decreased)
        let branch = if c == state.internal[self.internal] {
            state.internal[self.internal + 2]
        } else {
            r.branch
        };
        out[..3].copy_from_slice(&[c, r.moment, branch]);
    }
    /// The law's moment, `M g`: the whole of its residual (a hinge law
    /// has no potential).
    fn nonconservative_forces(&self, ctx: &EvalContext, state: &State, out: &mut [f64]) {
        let ctx = ctx.with_need(crate::elements::Need::RESIDUAL);
        self.evaluate(&ctx, state, &mut ElementOutput::residual(out));
    }
    fn cell_shape(&self) -> CellShape {
        CellShape::None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rounded corner is C¹ and lies on the parabola of its definition:
    /// corner of slopes 0 → 2 at (1, 0), h = 0.1: f(1) = Δs h/4 = 0.05,
    /// value and slope continuous at 1 ± h (to round-off, 1e-14).
    #[test]
    fn rounded_corner_is_c1() {
        let b = Branch::new(vec![(0.0, 0.0), (1.0, 0.0), (2.0, 2.0)], 0.1);
        assert!((b.eval(1.0).0 - 0.05).abs() < 1e-15);
        assert!((b.eval(1.0).1 - 1.0).abs() < 1e-15);
        for x in [0.9, 1.1] {
            let e = 1e-12;
            let (l, r) = (b.eval(x - e), b.eval(x + e));
            assert!(
                (l.0 - r.0).abs() < 1e-11 && (l.1 - r.1).abs() < 1e-10,
                "{x}"
            );
        }
        assert_eq!(b.eval(0.5), (0.0, 0.0));
        assert_eq!(b.eval(3.0), (4.0, 2.0));
    }

    /// `crossing` finds where a rounded corner of the unloading bound
    /// rises above the loading bound: bounds 0.01 apart with the same
    /// corner at c = 1 (slopes −1 → 1), the loading one sharp, the
    /// unloading one rounded with h = 0.2, whose parabola reaches
    /// −0.01 + 2·0.2/4 = 0.09 > 0 at c = 1.
    /// A tape spring in kN·mm-like magnitudes (M_d = 3e-4, M_L = 0.01,
    /// K = 5e-3): both bounds end on the same locked line K (c − c_L),
    /// whose slopes computed from two different pairs of points differ by
    /// round-off. The law is valid (it was refused as crossing), and it is
    /// the N·m law scaled by 1e-3, which is accepted too.
    #[test]
    fn a_tape_spring_in_small_units_is_not_refused_by_round_off() {
        for scale in [1.0, 1e-3, 1e-6, 1e3] {
            for (cl, w) in [
                (1.5, 0.1),
                (std::f64::consts::FRAC_PI_2 - 2.7e-8, 0.05),
                (3.0, 0.5),
                (2.0, 0.2),
            ] {
                let t = TapeSpring {
                    deployment_moment: 0.3 * scale,
                    locking_angle: cl,
                    locking_peak: 10.0 * scale,
                    locked_stiffness: 5.0 * scale,
                    snap_width: w,
                    rounding: 0.25 * w.min(0.3 / 5.0),
                };
                let (load, unload) = t.branches();
                let law = Hysteresis {
                    load,
                    unload,
                    elastic: 10.0 * scale,
                };
                assert_eq!(law.crossing(), None, "scale {scale}, c_L {cl}, w {w}");
            }
        }
        // a real difference of the end slopes is still found
        let load = Branch::new(vec![(0.0, 0.0), (1.0, 1.0)], 0.0);
        let unload = Branch::new(vec![(0.0, -1.0), (1.0, 1.0 - 1e-6)], 0.0);
        let law = Hysteresis {
            load,
            unload,
            elastic: 10.0,
        };
        assert!(law.crossing().is_some());
    }

    #[test]
    fn crossing_is_found_inside_a_rounded_corner() {
        let load = Branch::new(vec![(0.0, 1.0), (1.0, 0.0), (2.0, 1.0)], 0.0);
        let unload = Branch::new(vec![(0.0, 0.99), (1.0, -0.01), (2.0, 0.99)], 0.2);
        let law = Hysteresis {
            load,
            unload,
            elastic: 10.0,
        };
        let c = law.crossing().expect("the dip is found");
        assert!((c - 1.0).abs() < 0.2, "{c}");
        // touching bounds are accepted
        let same = Branch::new(vec![(0.0, 0.0), (1.0, 1.0), (2.0, 0.0)], 0.3);
        let law = Hysteresis {
            load: same.clone(),
            unload: same,
            elastic: 1.0,
        };
        assert_eq!(law.crossing(), None);
        assert_eq!(law.band(), None);
    }
}
