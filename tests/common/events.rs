//! A dynamic run of a model file's text that records every accepted state
//! and every event of its stops, contacts and latches (tests/stops.rs,
//! tests/contact.rs, tests/latches.rs, tests/latch_spring.rs).

use std::sync::Arc;

use unfold::analysis::{
    AnalysisSettings, ContactInfo, DynamicAnalysis, DynamicOutcome, IncrementInfo, LockInfo,
    Observer,
};
use unfold::model::input::ModelInput;
use unfold::model::Model;
use unfold::state::State;

/// Every accepted state, every event of a stop or contact and every event
/// of a latch.
#[derive(Default)]
pub struct Record {
    pub steps: Vec<(IncrementInfo, State)>,
    pub contacts: Vec<ContactInfo>,
    pub locks: Vec<LockInfo>,
    /// Spring latches' band crossings (engage, disengage, rearm).
    pub crossings: Vec<LockInfo>,
}

impl Observer for Record {
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
    fn contact(&mut self, info: &ContactInfo) {
        self.contacts.push(info.clone());
    }
    fn lock(&mut self, info: &LockInfo) {
        self.locks.push(info.clone());
    }
    fn band_crossing(&mut self, info: &LockInfo) {
        self.crossings.push(info.clone());
    }
}

/// The model of a model file's text and its analyses.
pub fn parse(text: &str) -> (Arc<Model>, Vec<AnalysisSettings>) {
    let input: ModelInput = toml::from_str(text).expect("valid toml");
    let model = Model::from_input(&input).expect("valid model");
    (Arc::new(model), input.analyses().expect("valid analyses"))
}

/// Runs the first analysis of a model file's text, a dynamic one, from
/// the initial state; the run must end without error.
pub fn run(text: &str) -> (Arc<Model>, DynamicOutcome, Record) {
    let (model, analyses) = parse(text);
    let settings = analyses[0].as_dynamic().unwrap().clone();
    let mut a = DynamicAnalysis::new(model.clone(), settings);
    let mut record = Record::default();
    let out = a.run(model.initial_state(), &mut record);
    assert!(out.error.is_none(), "{:?}", out.error);
    (model, out, record)
}

/// The message of a model file's text that must not build.
pub fn error_of(text: &str) -> String {
    let input: ModelInput = toml::from_str(text).expect("valid toml");
    match Model::from_input(&input) {
        Ok(_) => panic!("the model was accepted"),
        Err(e) => e.to_string(),
    }
}
