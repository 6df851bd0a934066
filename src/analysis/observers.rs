//! Ready-made observers for programs that drive an analysis from Rust: a
//! [`History`] that keeps what an analysis reports, and [`OnIncrement`],
//! which calls a closure at every converged increment.
//!
//! ```
//! use unfold::analysis::observers::OnIncrement;
//! use unfold::analysis::IncrementInfo;
//! use unfold::model::Model;
//! use unfold::state::State;
//!
//! let mut times = Vec::new();
//! let observer = OnIncrement(|info: &IncrementInfo, _: &Model, _: &State| times.push(info.time));
//! # drop(observer);
//! ```

use super::{CutbackInfo, EventInfo, IncrementInfo, Observer, WarningInfo};
use crate::model::Model;
use crate::state::State;

/// Keeps every converged increment, and on request every converged state,
/// with the cut-backs, events, notes and warnings of the analysis.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// The converged increments, increment 0 (the start) included.
    pub increments: Vec<IncrementInfo>,
    /// The converged states, one per increment, if kept
    /// ([`History::with_states`]).
    pub states: Vec<State>,
    /// The increments cut back.
    pub cutbacks: Vec<CutbackInfo>,
    /// The events landed on.
    pub events: Vec<EventInfo>,
    /// The remarks of the analysis (redundant constraints removed).
    pub notes: Vec<String>,
    /// The suspect increments (a limit point passed under load control).
    pub warnings: Vec<WarningInfo>,
    keep_states: bool,
}

impl History {
    /// A history of the increments, without their states.
    pub fn new() -> Self {
        Self::default()
    }

    /// A history that also keeps a copy of every converged state.
    pub fn with_states() -> Self {
        Self {
            keep_states: true,
            ..Self::default()
        }
    }

    /// Newton iterations over the converged increments (increment 0
    /// included).
    pub fn iterations(&self) -> usize {
        self.increments.iter().map(|i| i.iterations).sum()
    }

    /// The converged increments with their states (empty unless states
    /// are kept).
    pub fn steps(&self) -> impl Iterator<Item = (&IncrementInfo, &State)> {
        self.increments.iter().zip(&self.states)
    }

    /// The last converged state, if states are kept.
    pub fn last_state(&self) -> Option<&State> {
        self.states.last()
    }
}

impl Observer for History {
    fn increment(
        &mut self,
        info: &IncrementInfo,
        _model: &Model,
        state: &State,
        _residual: &[f64],
    ) -> std::io::Result<()> {
        self.increments.push(info.clone());
        if self.keep_states {
            self.states.push(state.clone());
        }
        Ok(())
    }

    fn cutback(&mut self, info: &CutbackInfo) {
        self.cutbacks.push(info.clone());
    }

    fn event(&mut self, info: &EventInfo) {
        self.events.push(info.clone());
    }

    fn note(&mut self, text: &str) {
        self.notes.push(text.to_string());
    }

    fn warning(&mut self, info: &WarningInfo) {
        self.warnings.push(info.clone());
    }
}

/// Calls its closure with every converged increment, the model and the
/// converged state.
pub struct OnIncrement<F>(pub F);

impl<F> Observer for OnIncrement<F>
where
    F: FnMut(&IncrementInfo, &Model, &State),
{
    fn increment(
        &mut self,
        info: &IncrementInfo,
        model: &Model,
        state: &State,
        _residual: &[f64],
    ) -> std::io::Result<()> {
        (self.0)(info, model, state);
        Ok(())
    }
}
