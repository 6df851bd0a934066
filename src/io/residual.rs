//! The relative residual as `log.txt` reports it.
//!
//! The solver's measure ([`ConvergenceNorms::relative_residual`]) is the
//! largest, over the groups of equations (forces, moments, the
//! generalised forces of coordinates), of the residual above its
//! round-off floor over the flux of its group (docs/theory.md §7.1). A
//! group through which no force flows has a flux at round-off too, and
//! the ratio of two round-off values is any number: a panel held by a
//! rigid latch, at rest, has force residuals of 1e-16 N over a force flux
//! of 1.6e-16 N while the latch carries a moment of π N·m; the ratio,
//! 0.71, says nothing about convergence.
//!
//! So the log reports a group whose residual and flux are both within
//! `c ε` of the largest flux of the iteration ([`load_scale`], moments
//! counted as forces over the model's length scale `L`) as at round-off,
//! and the relative residual as the largest ratio over the other groups;
//! when nothing is left above round-off it writes `round-off`. The
//! convergence test is the solver's and is not changed by this.

use std::fmt;

use super::line::Line;
use super::number::Sci;
use crate::analysis::newton::ConvergenceNorms;

/// `c`: a group's residual and flux within `c ε` of the iteration's
/// largest flux are round-off. The solver takes a residual that stopped
/// decreasing within this many `ε` of its floor for its round-off plateau
/// (`PLATEAU_FACTOR` of src/analysis/newton.rs and dynamics.rs, 1024):
/// forces that small move the nodes by less than ~1e-12 of their sizes.
pub const ROUND_OFF_FACTOR: f64 = 1024.0;

/// The relative residual of one iteration as the log reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reported {
    /// The measure: the largest ratio over the groups above round-off.
    Ratio(f64),
    /// Every group at round-off (or the solver's measure 0: every
    /// residual below its floor).
    RoundOff,
}

impl Reported {
    /// The report of `norms`, with `length` the model's length scale
    /// (which turns moments into forces to compare them).
    pub fn of(norms: &ConvergenceNorms, length: f64) -> Self {
        let n = norms;
        let relative = n.relative_residual;
        if relative == 0.0 {
            return Self::RoundOff;
        }
        if !relative.is_finite() {
            return Self::Ratio(relative);
        }
        let round = ROUND_OFF_FACTOR * f64::EPSILON * load_scale(n, length);
        // forces and the coordinates' generalised forces (over their
        // lengths) share the force flux
        let forces_round_off =
            n.flux_force <= round && n.residual_force <= round && n.residual_coordinate <= round;
        let moments_round_off =
            n.flux_moment <= round * length && n.residual_moment <= round * length;
        if !forces_round_off && !moments_round_off {
            return Self::Ratio(relative);
        }
        // the raw ratios of the groups above round-off bound their part
        // of the measure
        let ratio = |r: f64, f: f64| if r == 0.0 { 0.0 } else { r / f };
        let mut others = 0.0f64;
        if !forces_round_off {
            others = others
                .max(ratio(n.residual_force, n.flux_force))
                .max(ratio(n.residual_coordinate, n.flux_force));
        }
        if !moments_round_off {
            others = others.max(ratio(n.residual_moment, n.flux_moment));
        }
        // the measure if it comes from a group above round-off, else the
        // bound of those groups
        let value = relative.min(others);
        if value <= ROUND_OFF_FACTOR * f64::EPSILON {
            Self::RoundOff
        } else {
            Self::Ratio(value)
        }
    }

    /// The value written in result files: the ratio, 0 at round-off.
    pub fn value(self) -> f64 {
        match self {
            Self::Ratio(r) => r,
            Self::RoundOff => 0.0,
        }
    }
}

/// The largest flux of an iteration as a force: `max(‖flux_F‖,
/// ‖flux_M‖/L)`, the scale of the forces whose round-off the residuals
/// carry.
pub fn load_scale(norms: &ConvergenceNorms, length: f64) -> f64 {
    norms.flux_force.max(norms.flux_moment / length)
}

/// [`Reported`] in the log, `P` digits after the point.
#[derive(Clone, Copy, Debug)]
pub struct Shown<const P: usize>(pub Reported);

impl<const P: usize> Shown<P> {
    /// Appends the report to `line`.
    pub fn push_to(self, line: &mut Line) {
        match self.0 {
            Reported::Ratio(r) => line.sci::<P>(r),
            Reported::RoundOff => line.text("round-off"),
        };
    }
}

impl<const P: usize> fmt::Display for Shown<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Reported::Ratio(r) => Sci::<P>(r).fmt(f),
            Reported::RoundOff => f.write_str("round-off"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn norms(rf: f64, ff: f64, rm: f64, fm: f64, relative: f64) -> ConvergenceNorms {
        ConvergenceNorms {
            residual_force: rf,
            flux_force: ff,
            residual_moment: rm,
            flux_moment: fm,
            relative_residual: relative,
            ..ConvergenceNorms::default()
        }
    }

    /// The iterate after a rigid latch's lock (log.txt of the latched
    /// panel, L = 0.5 m): force residual 1.136e-16 N over a force flux of
    /// 1.606e-16 N, moment residual 8.9e-16 N·m over 8.886 N·m. The
    /// solver's ratio 0.71 comes from the forces, both at round-off of
    /// the 17.8 N that the moment stands for: the report is `round-off`
    /// (the moments' own ratio, 1e-16, is round-off as well).
    #[test]
    fn round_off_over_round_off_is_reported_as_round_off() {
        let n = norms(
            1.136e-16,
            1.606e-16,
            8.882e-16,
            8.886,
            std::f64::consts::FRAC_1_SQRT_2,
        );
        assert_eq!(Reported::of(&n, 0.5), Reported::RoundOff);
        assert_eq!(
            format!("{}", Shown::<1>(Reported::of(&n, 0.5))),
            "round-off"
        );
        // in other units (mm, N·mm): the same report
        let mm = norms(
            1.136e-16,
            1.606e-16,
            8.882e-13,
            8.886e3,
            std::f64::consts::FRAC_1_SQRT_2,
        );
        assert_eq!(Reported::of(&mm, 500.0), Reported::RoundOff);
    }

    /// A force group above round-off keeps the solver's measure: the
    /// predictor of a step of the moving panel (22.5 N over 31.9 N), and
    /// a small but real force (3.7e-7 N over 5.2e-7 N with 17.8 N in the
    /// moments: 2e-8 of the loads, far above 1024 ε = 2.3e-13).
    #[test]
    fn residuals_above_round_off_keep_the_measure() {
        let moving = norms(22.54, 31.88, 0.5559, 6.532, std::f64::consts::FRAC_1_SQRT_2);
        assert_eq!(
            Reported::of(&moving, 0.5),
            Reported::Ratio(std::f64::consts::FRAC_1_SQRT_2)
        );
        let small = norms(
            3.689e-7,
            5.217e-7,
            5.341e-7,
            8.886,
            std::f64::consts::FRAC_1_SQRT_2,
        );
        assert_eq!(
            Reported::of(&small, 0.5),
            Reported::Ratio(std::f64::consts::FRAC_1_SQRT_2)
        );
    }

    /// Forces at round-off, moments not converged: the moments' ratio
    /// is reported, not the forces'.
    #[test]
    fn the_groups_above_round_off_give_the_ratio() {
        let n = norms(1e-16, 1.5e-16, 1e-3, 8.886, 0.6667);
        assert_eq!(Reported::of(&n, 0.5), Reported::Ratio(1e-3 / 8.886));
        // and a measure that comes from the moments is kept as it is
        let m = norms(1e-16, 1.5e-16, 1e-3, 8.886, 1.1e-4);
        assert_eq!(Reported::of(&m, 0.5), Reported::Ratio(1.1e-4));
    }

    /// The solver's 0 (every residual below its floor) is round-off; a
    /// model with no flux at all reports its measure as it is.
    #[test]
    fn zero_is_round_off_and_no_flux_keeps_the_measure() {
        assert_eq!(
            Reported::of(&norms(1e-15, 50.0, 0.0, 7.0, 0.0), 1.0),
            Reported::RoundOff
        );
        let none = norms(1e-300, 2e-300, 0.0, 0.0, 0.5);
        assert_eq!(Reported::of(&none, 1.0), Reported::Ratio(0.5));
        assert_eq!(format!("{}", Shown::<3>(Reported::Ratio(0.5))), "5.000e-1");
        let mut line = Line::default();
        Shown::<3>(Reported::Ratio(0.5)).push_to(&mut line);
        line.text(" ");
        Shown::<1>(Reported::RoundOff).push_to(&mut line);
        assert_eq!(line.bytes(), b"5.000e-1 round-off");
    }
}
