//! `[output]`: the restart times.

use super::{num, Checker};
use crate::model::input::OutputInput;
use crate::model::ModelErrorKind;

/// Checks `[output]` against the span of the analyses, `[0, end_time]`.
pub(super) fn check(ck: &mut Checker, output: Option<&OutputInput>, end_time: f64) {
    let Some(o) = output else {
        return;
    };
    for &t in &o.restart_times {
        if !(t.is_finite() && (0.0..=end_time).contains(&t)) {
            ck.push(
                ModelErrorKind::Invalid,
                "output",
                format!(
                    "restart_times must lie within the analyses, from t = 0 to the end_time of the last ({}), got {}",
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
}
