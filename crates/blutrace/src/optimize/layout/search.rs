//! The state of one layout search: the scene file as a value tree, the variables, the
//! traces so far and the best design.

use super::objective::{self, LayoutEvaluation};
use super::vary::Variable;
use crate::optimize::ObjectiveSpec;
use crate::optimize::OptimizeOptions;
use crate::optimize::design::Design;
use crate::optimize::nelder_mead::Cost;
use crate::run::RunResult;
use crate::run::{MeshBuildCache, RunOptions};
use crate::scene::Scene;
use crate::scene::config::SceneFile;
use crate::scene::meshio::ReadCache;
use anyhow::Result;
use serde::Serialize;
use std::cell::RefCell;
use std::collections::HashMap;
use std::time::Instant;
use toml::Value;

/// One evaluated design: a row of `history.csv` and a progress line.
#[derive(Clone, Debug, Serialize)]
pub struct EvaluationRecord {
    /// Designs evaluated so far, this one included.
    pub evaluation: usize,
    /// The variables' values, in the order given.
    pub values: Vec<f64>,
    /// The traced design's objective and metrics (None: not traced).
    pub result: Option<LayoutEvaluation>,
    /// Why the design was not traced.
    pub rejected: Option<String>,
    /// Photons traced so far.
    pub photons: u64,
    /// Wall time so far (s).
    pub seconds: f64,
}

impl EvaluationRecord {
    /// `name = value` of every variable.
    pub fn assignment(&self, names: &[String]) -> String {
        names
            .iter()
            .zip(&self.values)
            .map(|(n, v)| format!("{n} = {v:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// What the search needs while it runs.
pub(super) struct LayoutSearch<'a> {
    pub(super) scene: &'a Scene,
    pub(super) doc: Value,
    pub(super) vars: Vec<Variable>,
    pub(super) objective: ObjectiveSpec,
    pub(super) options: &'a OptimizeOptions,
    pub(super) run_options: RunOptions,
    pub(super) start: Instant,
    pub(super) photons: u64,
    pub(super) history: Vec<EvaluationRecord>,
    /// The first traced design (the scene's own): its run and evaluation.
    pub(super) first: Option<(RunResult, LayoutEvaluation)>,
    /// The best feasible design (light on the target, an objective): its run,
    /// evaluation and variables.
    pub(super) best: Option<(RunResult, LayoutEvaluation, Vec<f64>)>,
    /// Cost and objective noise of every design evaluated, by the bits of its variables:
    /// a design met again (the scene's own at the start of each case) is not traced
    /// twice.
    pub(super) seen: HashMap<Vec<u64>, (Cost, f64)>,
    /// The last design's backend and triangle records, reused by the next design when
    /// its mesh is the same (a search that moves only the lamps).
    pub(super) builds: RefCell<MeshBuildCache>,
    /// The geometry files as read for the first design, copied for the others.
    pub(super) reads: ReadCache,
    /// An interrupt stopped the search: the design it was tracing is dropped.
    pub(super) interrupted: bool,
}

impl<'a> LayoutSearch<'a> {
    /// The variables' names.
    pub(super) fn names(&self) -> Vec<String> {
        self.vars.iter().map(|v| v.name.clone()).collect()
    }

    /// The scene file with the variables set to `x`.
    pub(super) fn document(&self, x: &[f64]) -> Value {
        let mut doc = self.doc.clone();
        for (v, &x) in self.vars.iter().zip(x) {
            v.set(&mut doc, x);
        }
        doc
    }

    /// Evaluate the design `x` (inside the bounds): its cost (the objective; infeasible
    /// when the scene does not load, or when no light reaches the target and the
    /// objective is undefined) and the objective's standard error. Keeps the first and
    /// the best feasible design; `progress` sees the record.
    pub(super) fn evaluate(
        &mut self,
        x: &[f64],
        progress: &mut dyn FnMut(&EvaluationRecord, &[String]),
    ) -> Result<(Cost, f64)> {
        let key: Vec<u64> = x.iter().map(|v| v.to_bits()).collect();
        if let Some(&seen) = self.seen.get(&key) {
            return Ok(seen);
        }
        let (result, rejected, value) = match self.scene(x) {
            Ok(scene) => {
                let (run, ev) = self.trace_scene(scene, &self.run_options.clone())?;
                self.photons += ev.photons;
                let value = Cost::Feasible(ev.objective);
                if self.first.is_none() {
                    self.first = Some((run.clone(), ev.clone()));
                }
                let better = self
                    .best
                    .as_ref()
                    .is_none_or(|(_, b, _)| value < Cost::Feasible(b.objective));
                if value.is_feasible() && better {
                    self.best = Some((run, ev.clone(), x.to_vec()));
                }
                (Some(ev), None, value)
            }
            // No distance to feasible: ranked before the points outside the bounds, as
            // the bounds' distance is what pulls the simplex back in.
            Err(e) => (None, Some(format!("{e:#}")), Cost::Infeasible(0.0)),
        };
        let noise = result.as_ref().map_or(f64::NAN, |r| r.noise);
        self.seen.insert(key, (value, noise));
        self.record(x, result, rejected, progress);
        Ok((value, noise))
    }

    /// Record a design out of the bounds (not traced).
    pub(super) fn reject_out_of_bounds(
        &mut self,
        x: &[f64],
        progress: &mut dyn FnMut(&EvaluationRecord, &[String]),
    ) {
        self.record(x, None, Some("outside the bounds".into()), progress);
    }

    fn record(
        &mut self,
        x: &[f64],
        result: Option<LayoutEvaluation>,
        rejected: Option<String>,
        progress: &mut dyn FnMut(&EvaluationRecord, &[String]),
    ) {
        let r = EvaluationRecord {
            evaluation: self.history.len() + 1,
            values: x.to_vec(),
            result,
            rejected,
            photons: self.photons,
            seconds: self.start.elapsed().as_secs_f64(),
        };
        progress(&r, &self.names());
        self.history.push(r);
    }
}

/// A layout design: the scene file with the varied keys set to the point's values,
/// loaded (reusing the geometry files as first read), judged by the `--objective`.
impl Design for LayoutSearch<'_> {
    type Point = [f64];
    type Judged = LayoutEvaluation;

    fn scene(&self, x: &[f64]) -> Result<Scene> {
        let file: SceneFile = self
            .document(x)
            .try_into()
            .map_err(|e| anyhow::anyhow!("{}: {e}", self.scene.path.display()))?;
        Scene::from_file_reading(&file, &self.scene.path, &self.reads)
    }

    fn judge(&self, run: &RunResult) -> Result<LayoutEvaluation> {
        objective::evaluate(&self.objective, run)
    }

    fn builds(&self) -> &RefCell<MeshBuildCache> {
        &self.builds
    }
}
