//! A finished trace of one design, kept to write its outputs (`initial/`, `final/`).

use super::objective::Evaluation;
use super::search::dots_pattern;
use crate::run::metrics::MetricValues;
use crate::run::{
    self, ConvergenceRow, Interrupted, MeshBuildCache, RunOptions, RunResult, StoppedBy,
};
use crate::scene::Scene;
use crate::tally::Tally;
use anyhow::Result;

/// A finished trace kept for writing its outputs (`initial/`, `final/`).
#[derive(Clone, Debug)]
pub struct TracedRun {
    /// The traced scene.
    pub scene: Scene,
    backend: &'static str,
    options: RunOptions,
    threads: usize,
    tally: Tally,
    groups: Vec<Tally>,
    runtime_s: f64,
    stopped_by: StoppedBy,
    history: Vec<ConvergenceRow>,
    leave_out: Vec<MetricValues>,
}

impl TracedRun {
    /// Trace `scene`; returns the run and its evaluation.
    pub(super) fn trace(
        scene: Scene,
        options: &RunOptions,
        strips: usize,
        margin: f64,
        tag_id: usize,
        builds: &mut MeshBuildCache,
    ) -> Result<(TracedRun, Evaluation)> {
        let (run, evaluation) =
            Self::trace_judged(scene, options, builds, |r| -> Result<Evaluation> {
                let pattern = dots_pattern(r.scene, tag_id)?;
                Ok(Evaluation::of(
                    r.scene,
                    pattern,
                    r.flux_map(),
                    strips,
                    margin,
                    r.tally.ledger.photons,
                    r.runtime_s,
                ))
            })?;
        Ok((run, evaluation?))
    }

    /// Trace `scene` (reusing `builds` when the mesh is the last run's) and judge the
    /// finished run with `judge`; an [`Interrupted`] error when the options' interrupt
    /// stopped the trace before all its photons.
    pub(super) fn trace_judged<T>(
        scene: Scene,
        options: &RunOptions,
        builds: &mut MeshBuildCache,
        judge: impl FnOnce(&RunResult) -> T,
    ) -> Result<(TracedRun, T)> {
        let r = run::trace_reusing(&scene, options, builds, &|_| {})?;
        if r.stopped_by == StoppedBy::Interrupted {
            return Err(Interrupted.into());
        }
        let judged = judge(&r);
        let RunResult {
            scene: _,
            backend,
            options,
            threads,
            tally,
            groups,
            runtime_s,
            stopped_by,
            history,
            leave_out,
        } = r;
        let traced = TracedRun {
            scene,
            backend,
            options,
            threads,
            tally,
            groups,
            runtime_s,
            stopped_by,
            history,
            leave_out,
        };
        Ok((traced, judged))
    }

    /// The run as a [`RunResult`] (for its summary and output files).
    pub fn result(&self) -> RunResult<'_> {
        RunResult {
            scene: &self.scene,
            backend: self.backend,
            options: self.options.clone(),
            threads: self.threads,
            tally: self.tally.clone(),
            groups: self.groups.clone(),
            runtime_s: self.runtime_s,
            stopped_by: self.stopped_by,
            history: self.history.clone(),
            leave_out: self.leave_out.clone(),
        }
    }
}
