//! `[output]`: the restart times and the charts written with the results.

use super::{num, Checker};
use crate::model::input::OutputInput;
use crate::model::ModelErrorKind;

/// The most `restart_times` a model may give: each is a file holding the
/// whole state (about 300 bytes a node) and a time the analyses land on.
pub const MAX_RESTART_TIMES: usize = 1000;

/// Checks `[output]` against the span of the analyses, `(0, end_time]`: the
/// state at t = 0 is the model itself, so a restart there would restart
/// nothing.
pub(super) fn check(ck: &mut Checker, output: Option<&OutputInput>, end_time: f64) {
    let Some(o) = output else {
        return;
    };
    let times = &o.restart_times;
    if times.len() > MAX_RESTART_TIMES {
        ck.push(
            ModelErrorKind::Invalid,
            "output",
            format!(
                "restart_times has {} times: a run writes at most {MAX_RESTART_TIMES} restart files (each holds the whole state of the model, and the analyses land on each time); give fewer times (restart.json, written at the end of every run, continues any run)",
                times.len()
            ),
        );
        return;
    }
    // the first time outside the run, and how many more
    let outside: Vec<f64> = times
        .iter()
        .copied()
        .filter(|t| !(t.is_finite() && *t > 0.0 && *t <= end_time))
        .collect();
    if let Some(&t) = outside.first() {
        let more = match outside.len() {
            1 => String::new(),
            n => format!(" (and {} more)", n - 1),
        };
        ck.push(
            ModelErrorKind::Invalid,
            "output",
            format!(
                "restart_times must lie after the start of the analyses (t = 0, where the model itself is the start) and up to the end_time of the last ({}), got {}{more}",
                num(end_time),
                num(t)
            ),
        );
    }
    if times.windows(2).any(|w| w[1] <= w[0]) {
        ck.push(
            ModelErrorKind::Invalid,
            "output",
            "restart_times must be in increasing order",
        );
    }
    if o.vtk_every == Some(0) {
        ck.push(
            ModelErrorKind::Invalid,
            "output",
            "vtk_every must be 1 or more (a grid every N-th output step); write vtk = false for no grid",
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
