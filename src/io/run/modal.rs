//! Modal analyses in a run's record: a run that starts with one, the
//! static analysis that follows one, and the record of its modes (files,
//! log lines, `summary.json`).

use std::io;
use std::path::Path;

use super::{Console, Recorder, Running};
use crate::analysis::AnalysisSettings;
use crate::analysis::{ModalAnalysis, ModalOutcome, StaticOutcome};
use crate::io::modes::{solver_name, ModalRecord};
use crate::io::results::{AnalysisRecord, Summary};

impl Recorder {
    /// As [`Recorder::create_sequence`], for a run whose first analysis
    /// is the modal analysis `first`.
    pub fn create_modal_first(
        dir: &Path,
        model_file: &str,
        first: &ModalAnalysis,
        plan: &[AnalysisSettings],
        console: impl Console + 'static,
    ) -> io::Result<Self> {
        let model = &**first.model();
        let end_time = plan.last().map_or(0.0, |a| a.end_time());
        let summary = Summary::start_with(
            model_file,
            model,
            first.n_equations(),
            first.solver().nnz(),
            end_time,
        );
        let running = Running {
            index: 0,
            kind: "modal",
            start_time: first.settings().time,
            end_time: first.settings().time,
            initial_iterations: 0,
            // a modal analysis iterates on no residual
            residual_tolerance: f64::INFINITY,
        };
        let unknowns = first.n_equations();
        Self::create_with(
            dir, model_file, model, summary, running, unknowns, plan, console,
        )
    }

    /// Records the modal analysis `analysis`, which returned `outcome`:
    /// closes the static analysis before it (`before`, if it is still
    /// open), writes its result files (docs/results.md, "Modes"), a line
    /// per mode in `log.txt` and its record in the summary. A failed
    /// modal analysis fails the run ([`Recorder::finish_with`]). Write
    /// errors name their file.
    pub fn record_modal(
        &mut self,
        before: Option<&StaticOutcome>,
        analysis: &ModalAnalysis,
        outcome: &ModalOutcome,
    ) -> io::Result<()> {
        // a run that starts with this analysis has its record open already
        let first = self.current.kind == "modal" && self.summary.analyses.is_empty();
        if let Some(b) = before {
            self.close(b);
        }
        if !first {
            self.writer.set_dynamic(false);
            self.current = Running {
                index: self.current.index + 1,
                kind: "modal",
                start_time: outcome.time,
                end_time: outcome.time,
                initial_iterations: 0,
                residual_tolerance: f64::INFINITY,
            };
        }
        let index = self.current.index + 1;
        let s = analysis.settings();
        self.line(&format!(
            "analysis {index} of {}: modal at t = {}: {} modes asked, {} unknowns, solver {}",
            self.analyses,
            outcome.time,
            s.modes,
            outcome.unknowns,
            solver_name(outcome.method),
        ));

        // the summary: the analysis and its modes
        self.summary.analyses.push(AnalysisRecord {
            kind: "modal".into(),
            start_time: outcome.time,
            end_time: outcome.time,
            final_time: outcome.time,
            increments: 0,
            iterations: 0,
            cutbacks: 0,
            failed: outcome.error.is_some(),
            wall_time_s: outcome.wall_time,
            dynamic: None,
        });
        self.summary.final_time = outcome.time;
        self.summary.wall_time_s += outcome.wall_time;
        self.summary.modes.push(ModalRecord::of(index, outcome));
        self.summary.redundant_constraints = self
            .summary
            .redundant_constraints
            .max(outcome.redundant_constraints);

        if let Some(e) = &outcome.error {
            let message = format!("modal analysis at t = {}: {e}", outcome.time);
            self.line(&format!("error: {message}"));
            self.failure = Some(message);
            return self.log.flush();
        }
        for (k, m) in outcome.modes.iter().enumerate() {
            self.log.line(&format!(
                "mode {:4}  f = {:.6e} Hz  ω = {:.6e} rad/s  generalised mass {:.4e}  effective mass x {:.3e} y {:.3e} z {:.3e}{}",
                k + 1,
                m.frequency,
                m.angular_frequency,
                m.generalized_mass,
                m.effective_mass[0],
                m.effective_mass[1],
                m.effective_mass[2],
                if m.is_zero() { "  (rigid-body or mechanism mode)" } else { "" }
            ));
        }
        // the console gets the frequencies from the caller; the log keeps
        // the line with the run
        self.log.line(&format!(
            "modal analysis at t = {}: {} modes ({} zero) in {:.3} s",
            outcome.time,
            outcome.modes.len(),
            outcome.zero_modes,
            outcome.wall_time
        ));
        let dir = self.writer.dir().to_path_buf();
        let written = {
            let _writing = self.stop.output();
            self.modal
                .write(&dir, analysis.model(), index, outcome, self.encoding)
        };
        if let Err(e) = written {
            self.failure = Some(format!("writing the modes: {e}"));
            return Err(e);
        }
        self.log.flush()
    }
}
