//! The outcome of a layout search, and its verification.

use super::objective::LayoutEvaluation;
use super::search::{EvaluationRecord, LayoutSearch};
use crate::optimize::design::Design;

use crate::optimize::{Method, OptimizeOptions};
use crate::run::RunResult;
use crate::run::is_interrupted;
use crate::run::summary::Summary;
use anyhow::Result;
use serde::Serialize;
use std::path::PathBuf;
use toml::Value;

/// A variable of the search, before and after.
#[derive(Clone, Debug, Serialize)]
pub struct VariableResult {
    /// The key.
    pub name: String,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// The scene file's value.
    pub initial: f64,
    /// The best design's value.
    #[serde(rename = "final")]
    pub final_value: f64,
    /// Whether it was enumerated as an integer.
    pub integer: bool,
}

impl VariableResult {
    /// `"lower"` or `"upper"` when the best design's value of a continuous variable lies
    /// within 1 % of the range of that end: the optimum may lie beyond it.
    pub fn at_range_end(&self) -> Option<&'static str> {
        let margin = 0.01 * (self.max - self.min);
        match self.integer {
            true => None,
            false if self.final_value <= self.min + margin => Some("lower"),
            false if self.final_value >= self.max - margin => Some("upper"),
            false => None,
        }
    }
}

/// The search of the continuous variables for one combination of the integer ones.
#[derive(Clone, Debug, Serialize)]
pub struct IntegerCase {
    /// The integer variables' values (in the order given).
    pub integers: Vec<f64>,
    /// Every variable's value in this case's best design.
    pub values: Vec<f64>,
    /// Its objective at the search's seed and photons.
    pub objective: f64,
    /// Its standard error.
    pub noise: f64,
    /// Designs this case evaluated.
    pub evaluations: usize,
    /// How its search ended.
    pub termination: String,
}

/// A design re-traced with the verification seed and photons.
#[derive(Clone, Debug, Serialize)]
pub struct VerifiedLayout {
    /// The objective and metrics of the re-trace.
    pub evaluation: LayoutEvaluation,
    /// The re-trace's summary.
    pub summary: Summary,
}

/// The scene's own design and the best one, re-traced.
#[derive(Clone, Debug, Serialize)]
pub struct LayoutVerification {
    /// Seed of the re-traces (no evaluation used it).
    pub seed: u64,
    /// Photons per re-trace.
    pub photons: u64,
    /// The scene's own design.
    pub initial: VerifiedLayout,
    /// The best design.
    #[serde(rename = "final")]
    pub final_design: VerifiedLayout,
}

/// The outcome of [`optimize_layout`](super::optimize_layout).
#[derive(Clone, Debug, Serialize)]
pub struct LayoutResult {
    /// The method.
    pub method: Method,
    /// The options used.
    pub options: OptimizeOptions,
    /// The original scene file.
    pub scene_file: PathBuf,
    /// The objective, as `--objective` names it.
    pub objective: String,
    /// The variables, before and after.
    pub variables: Vec<VariableResult>,
    /// One search per combination of the integer variables (one when there are none).
    pub cases: Vec<IntegerCase>,
    /// Every design evaluated.
    pub history: Vec<EvaluationRecord>,
    /// Photons traced by the search (verification excluded).
    pub photons: u64,
    /// Wall time of the search (s, verification excluded).
    pub seconds: f64,
    /// The scene's own design at the search's seed and photons.
    pub initial: LayoutEvaluation,
    /// The best design at the search's seed and photons.
    pub best: LayoutEvaluation,
    /// The re-traces with a fresh seed (None with `--verify-photons 0` or after an
    /// interrupt).
    pub verification: Option<LayoutVerification>,
    /// Stopped by an interrupt (Ctrl-C): the best design is the best of those fully
    /// traced.
    pub interrupted: bool,
    /// The best design's scene file as a value tree (paths as in the original).
    #[serde(skip)]
    pub(super) final_doc: Value,
    #[serde(skip)]
    pub(super) initial_run: RunResult,
    #[serde(skip)]
    pub(super) final_run: RunResult,
}

/// Verify the scene's own design and the best one and gather the result.
pub(super) fn finish(
    search: LayoutSearch,
    (first_run, initial): (RunResult, LayoutEvaluation),
    best: LayoutEvaluation,
    best_x: Vec<f64>,
    cases: Vec<IntegerCase>,
) -> Result<LayoutResult> {
    let seconds = search.start.elapsed().as_secs_f64();
    let options = search.options;
    let initial_x: Vec<f64> = search.vars.iter().map(|v| v.initial).collect();
    let best_run = || search.best.as_ref().map(|b| b.0.clone());
    let mut interrupted = search.interrupted;
    let verified = if options.verify_photons == 0 || interrupted {
        None
    } else {
        let run_options = options.verification_run();
        let verify = |x: &[f64]| -> Result<(RunResult, VerifiedLayout)> {
            let (run, evaluation) = search.trace(x, &run_options)?;
            let summary = run.summary();
            Ok((
                run,
                VerifiedLayout {
                    evaluation,
                    summary,
                },
            ))
        };
        let both = verify(&initial_x).and_then(|i| Ok((i, verify(&best_x)?)));
        match both {
            Ok(((initial_run, i), (final_run, f))) => {
                let v = LayoutVerification {
                    seed: run_options.seed,
                    photons: options.verify_photons,
                    initial: i,
                    final_design: f,
                };
                Some((initial_run, final_run, v))
            }
            Err(e) if is_interrupted(&e) => {
                interrupted = true;
                None
            }
            Err(e) => return Err(e),
        }
    };
    let (initial_run, final_run, verification) = match verified {
        Some((i, f, v)) => (i, f, Some(v)),
        None => (first_run, best_run().expect("a best design"), None),
    };
    let variables = search
        .vars
        .iter()
        .zip(&best_x)
        .map(|(v, &x)| VariableResult {
            name: v.name.clone(),
            min: v.min,
            max: v.max,
            initial: v.initial,
            final_value: x,
            integer: v.integer,
        })
        .collect();
    Ok(LayoutResult {
        method: options.method,
        options: options.clone(),
        scene_file: search.scene.path.clone(),
        objective: search.objective.to_string(),
        variables,
        cases,
        final_doc: search.document(&best_x),
        history: search.history,
        photons: search.photons,
        seconds,
        initial,
        best,
        verification,
        interrupted,
        initial_run,
        final_run,
    })
}
