//! `[output]`: the restart times and the charts written with the results.

use super::{num, Checker};
use crate::model::input::OutputInput;
use crate::model::ModelErrorKind;

/// Checks `[output]` against the span of the analyses, `(0, end_time]`: the
/// state at t = 0 is the model itself, so a restart there would restart
/// nothing.
pub(super) fn check(ck: &mut Checker, output: Option<&OutputInput>, end_time: f64) {
    let Some(o) = output else {
        return;
    };
    for &t in &o.restart_times {
        if !(t.is_finite() && t > 0.0 && t <= end_time) {
            ck.push(
                ModelErrorKind::Invalid,
                "output",
                format!(
                    "restart_times must lie after the start of the analyses (t = 0, where the model itself is the start) and up to the end_time of the last ({}), got {}",
                    num(end_time),
                    num(t)
                ),
            );
        }
    }
    if o.restart_times.windows(2).any(|w| w[1] <= w[0]) {
        ck.push(
            ModelErrorKind::Invalid,
            "output",
            "restart_times must be in increasing order",
        );
    }
    for name in &o.plots {
        if crate::io::histories::Group::from_name(name).is_none() {
            ck.push(
                ModelErrorKind::Invalid,
                "output",
                format!(
                    "plots: {name:?} is not a kind of chart; give \"joints\", \"moments\", \"hinge_laws\" or \"energies\""
                ),
            );
        }
    }
}
