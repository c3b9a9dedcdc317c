//! How to optimize: the method and the options of `blutrace optimize`, checked.

use crate::accel::BackendChoice;
use crate::optics::surface::Estimator;
use anyhow::{Result, bail};
use serde::Serialize;

/// The optimization method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Nelder-Mead over the density polynomial's coefficients (the paper's method).
    #[default]
    NelderMead,
    /// Damped per-strip ratio updates of a tabulated density.
    Feedback,
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Method::NelderMead => "nelder-mead",
            Method::Feedback => "feedback",
        })
    }
}

/// How to optimize.
#[derive(Clone, Debug, Serialize)]
pub struct OptimizeOptions {
    /// The method.
    pub method: Method,
    /// Photons per evaluation (per traced design).
    pub photons: u64,
    /// Seed shared by every evaluation (common random numbers).
    pub seed: u64,
    /// Iteration cap (Nelder-Mead steps, or feedback rounds after the first trace).
    pub max_iter: usize,
    /// Stop once the objective is at or below this (the objective bound).
    pub target_cv: Option<f64>,
    /// Degree of the density polynomial (Nelder-Mead); default: the scene's, at least 3.
    pub degree: Option<usize>,
    /// Smallest printable density (area fraction).
    pub min_density: f64,
    /// Largest density; default (and at most): the lattice's packing limit.
    pub max_density: Option<f64>,
    /// The dots surface to optimize (default: the scene's only one).
    pub tag: Option<String>,
    /// Nelder-Mead: initial simplex step, in density units at the far end.
    pub initial_step: f64,
    /// Nelder-Mead: stop when the simplex is smaller than this (density units).
    pub simplex_tol: f64,
    /// Feedback: damping exponent.
    pub alpha: f64,
    /// Feedback: smoothing weight of the neighbours (0: none).
    pub smoothing: f64,
    /// Feedback: 1 (a table along the axis) or 2 (a grid over the face).
    pub dims: usize,
    /// Feedback in 2-D: knots of the grid along and across the axis (default 56 x 28).
    pub cells: Option<(usize, usize)>,
    /// Profile strips along the axis (default: the detector's bins along it).
    pub strips: Option<usize>,
    /// Leave strips within this many mm of either end of the span out of the objective.
    pub edge_margin_mm: f64,
    /// Photons of the verification re-traces (0: no re-trace; the optimization's own
    /// traces of the first and best design are reported instead).
    pub verify_photons: u64,
    /// Seed of the verification re-traces (default: a seed no evaluation used).
    pub verify_seed: Option<u64>,
    /// Worker threads (None: all cores).
    pub threads: Option<usize>,
    /// Intersection backend.
    #[serde(skip)]
    pub backend: BackendChoice,
    /// Estimator.
    pub estimator: Estimator,
}

impl OptimizeOptions {
    /// True for the 2-D feedback, which tunes a density grid over the whole face.
    pub fn tunes_grid(&self) -> bool {
        self.method == Method::Feedback && self.dims == 2
    }
}

impl Default for OptimizeOptions {
    fn default() -> Self {
        Self {
            method: Method::NelderMead,
            photons: 1_000_000,
            seed: 1,
            max_iter: 60,
            target_cv: None,
            degree: None,
            min_density: 0.01,
            max_density: None,
            tag: None,
            initial_step: 0.2,
            simplex_tol: 2e-3,
            alpha: 0.7,
            smoothing: 0.25,
            dims: 1,
            cells: None,
            strips: None,
            edge_margin_mm: 0.0,
            verify_photons: 10_000_000,
            verify_seed: None,
            threads: None,
            backend: BackendChoice::Auto,
            estimator: Estimator::Analog,
        }
    }
}

impl OptimizeOptions {
    /// The seed of the verification re-traces.
    pub fn verification_seed(&self) -> u64 {
        self.verify_seed
            .unwrap_or_else(|| self.seed.wrapping_add(0x9E37_79B9))
    }
}

/// Options that only one method takes must not be given to the other.
pub(super) fn check_method_options(options: &OptimizeOptions) -> Result<()> {
    if !(1..=2).contains(&options.dims) {
        bail!("--dims must be 1 or 2, got {}", options.dims);
    }
    if options.dims == 2 && !options.tunes_grid() {
        bail!("--dims 2 needs --method feedback (Nelder-Mead tunes a polynomial along the axis)");
    }
    match options.cells {
        Some(_) if !options.tunes_grid() => bail!("--cells needs --method feedback --dims 2"),
        Some((nx, ny)) if nx < 2 || ny < 2 => {
            bail!("--cells needs at least 2 knots each way, got {nx},{ny}")
        }
        _ => Ok(()),
    }
}
