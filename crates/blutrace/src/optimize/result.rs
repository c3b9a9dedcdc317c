//! The outcome of an optimization: designs, history, verification.

use super::export::{Dot, SheetFrame};
use super::objective::Evaluation;
use super::report::IterationReport;
use super::{Method, OptimizeOptions};
use crate::optics::dots::{Density, DotPattern, Placement};
use crate::run::RunResult;
use crate::run::summary::Summary;
use serde::Serialize;
use std::path::PathBuf;

/// A design re-traced with the verification seed and photons.
#[derive(Clone, Debug, Serialize)]
pub struct VerifiedDesign {
    /// The objective and profile of the re-trace.
    pub evaluation: Evaluation,
    /// The re-trace's summary (uniformity with jackknife standard errors).
    pub summary: Summary,
}

/// The verification of the first and the final design.
#[derive(Clone, Debug, Serialize)]
pub struct Verification {
    /// Seed of the re-traces (no evaluation used it).
    pub seed: u64,
    /// Photons per re-trace.
    pub photons: u64,
    /// The first design.
    pub initial: VerifiedDesign,
    /// The final design.
    pub final_design: VerifiedDesign,
}

/// The outcome of [`optimize`](super::optimize()).
#[derive(Clone, Debug, Serialize)]
pub struct OptimizeResult {
    /// The method.
    pub method: Method,
    /// The options used.
    pub options: OptimizeOptions,
    /// The original scene file.
    pub scene_file: PathBuf,
    /// The optimized surface's tag.
    pub tag: String,
    /// The first design's density.
    pub initial_density: Density,
    /// The final design's density.
    pub final_density: Density,
    /// One report per iteration.
    pub history: Vec<IterationReport>,
    /// Iterations done.
    pub iterations: usize,
    /// Designs evaluated.
    pub evaluations: usize,
    /// Photons traced by the search (verification excluded).
    pub photons: u64,
    /// Wall time of the search (s, verification excluded).
    pub seconds: f64,
    /// Why the search stopped.
    pub termination: String,
    /// Stopped by an interrupt (Ctrl-C): the best design is the best of those fully
    /// traced, and the verification was not traced (or not finished).
    pub interrupted: bool,
    /// The first design at the search's seed and photons.
    pub initial: Evaluation,
    /// The final design at the search's seed and photons.
    pub best: Evaluation,
    /// The re-traces with a fresh seed (None with `verify_photons = 0`).
    pub verification: Option<Verification>,
    /// Every dot of the final pattern (face coordinates); none for a virtual pattern
    /// without `--export-placement`.
    #[serde(skip)]
    pub dots: Option<Vec<Dot>>,
    /// The placement of the dot files (null: none written, the pattern is virtual).
    pub dots_placement: Option<Placement>,
    /// The printed sheet's frame the exports use.
    #[serde(skip)]
    pub sheet: SheetFrame,
    /// The final pattern (scene frame).
    #[serde(skip)]
    pub pattern: DotPattern,
    #[serde(skip)]
    pub(super) initial_run: RunResult,
    #[serde(skip)]
    pub(super) final_run: RunResult,
}
