//! How to optimize: the method and the options of `blutrace optimize`, checked.

use super::ObjectiveSpec;
use super::layout::VarySpec;
use crate::accel::BackendChoice;
use crate::optics::dots::Placement;
use crate::optics::surface::Estimator;
use crate::run::RunOptions;
use anyhow::{Result, bail};
use serde::Serialize;

/// The optimization method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Nelder-Mead over the density polynomial's coefficients (the paper's method).
    #[default]
    NelderMead,
    /// Damped per-strip ratio updates of a tabulated density.
    Feedback,
    /// With `vary`: a scan of one or two variables on a grid of `grid_points` each.
    Grid,
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Method::NelderMead => "nelder-mead",
            Method::Feedback => "feedback",
            Method::Grid => "grid",
        })
    }
}

impl Method {
    /// The iteration cap a search by this method takes unless told otherwise: Nelder-Mead
    /// steps, or feedback rounds after the first trace (a feedback round converges about
    /// four times as far as a simplex step).
    pub fn default_max_iter(self) -> usize {
        match self {
            Method::Feedback => 15,
            Method::NelderMead | Method::Grid => 60,
        }
    }
}

/// How to optimize (the command line's `blutrace optimize` flags map onto these fields
/// one to one; [`OptimizeOptions::for_method`] gives a method's defaults).
#[derive(Clone, Debug, Serialize)]
pub struct OptimizeOptions {
    /// Nelder-Mead over the density polynomial (the paper's), or per-strip feedback; with
    /// `vary`: Nelder-Mead over the variables, or a grid scan of one or two.
    pub method: Method,
    /// Numbers of the scene file to optimize, each a dotted key path and a range.
    pub vary: Vec<VarySpec>,
    /// What to minimize (see [`ObjectiveSpec`]).
    pub objective: ObjectiveSpec,
    /// With the grid method: points per variable, ends included.
    pub grid_points: usize,
    /// Photons per evaluated design.
    pub photons: u64,
    /// Seed shared by every evaluation (common random numbers).
    pub seed: u64,
    /// Stops the search after the design it is tracing: the result keeps the designs
    /// traced before (set from a signal handler or another thread).
    #[serde(skip)]
    pub interrupt: crate::run::Interrupt,
    /// Iteration cap (Nelder-Mead steps, or feedback rounds after the first trace); see
    /// [`Method::default_max_iter`].
    pub max_iter: usize,
    /// Stop once the objective (cv of the profile along the axis) is at or below this.
    pub target_cv: Option<f64>,
    /// Degree of the density polynomial (default: the scene's, at least 3).
    pub degree: Option<usize>,
    /// Smallest printable density (area fraction).
    pub min_density: f64,
    /// Largest density (default and at most: the lattice's packing limit).
    pub max_density: Option<f64>,
    /// The dots surface to optimize (default: the scene's only one).
    pub tag: Option<String>,
    /// Nelder-Mead: initial simplex step (density units at the far end; with `vary`, a
    /// fraction of each variable's range).
    pub initial_step: f64,
    /// Nelder-Mead: stop once the simplex is smaller than this (density units; with
    /// `vary`, a fraction of each variable's range).
    pub simplex_tol: f64,
    /// Feedback: damping exponent of d <- d (target / measured)^alpha.
    pub alpha: f64,
    /// Feedback: weight of the neighbours' mean in a smoothing pass (0: none).
    pub smoothing: f64,
    /// Feedback: 1 (a table of knots along the axis) or 2 (a grid over the face).
    pub dims: usize,
    /// Feedback in 2 dimensions: knots of the grid along and across the axis (default
    /// 56, 28).
    pub cells: Option<(usize, usize)>,
    /// Profile strips along the axis (default: the detector's bins along it).
    pub strips: Option<usize>,
    /// Leave this many mm at either end of the span out of the objective.
    pub edge_margin_mm: f64,
    /// Photons of the verification re-traces of the first and final design (0: none).
    pub verify_photons: u64,
    /// Seed of the verification re-traces (default: one no evaluation used).
    pub verify_seed: Option<u64>,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Intersection backend.
    #[serde(skip)]
    pub backend: BackendChoice,
    /// Analog roulette or absorption by weights.
    pub estimator: Estimator,
    /// For a `placement = "virtual"` surface, which is not printable: the printable
    /// placement of the dot files (none: no dot files).
    pub export_placement: Option<Placement>,
}

impl OptimizeOptions {
    /// The defaults of a search by `method`.
    pub fn for_method(method: Method) -> Self {
        Self {
            method,
            vary: Vec::new(),
            objective: ObjectiveSpec::default(),
            grid_points: 7,
            photons: 1_000_000,
            seed: 1,
            interrupt: crate::run::Interrupt::default(),
            max_iter: method.default_max_iter(),
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
            export_placement: None,
        }
    }

    /// True for the 2-D feedback, which tunes a density grid over the whole face.
    pub fn tunes_grid(&self) -> bool {
        self.method == Method::Feedback && self.dims == 2
    }

    /// The seed of the verification re-traces.
    pub fn verification_seed(&self) -> u64 {
        self.verify_seed
            .unwrap_or_else(|| self.seed.wrapping_add(0x9E37_79B9))
    }

    /// How the search traces each design (both searches: dots and layout).
    pub fn search_run(&self) -> RunOptions {
        RunOptions {
            photons: self.photons,
            seed: self.seed,
            threads: self.threads,
            backend: self.backend,
            estimator: self.estimator,
            interrupt: self.interrupt.clone(),
            ..RunOptions::default()
        }
    }

    /// How the first and final designs are traced again with a fresh seed.
    pub fn verification_run(&self) -> RunOptions {
        RunOptions {
            photons: self.verify_photons,
            seed: self.verification_seed(),
            ..self.search_run()
        }
    }
}

impl Default for OptimizeOptions {
    /// The defaults of a Nelder-Mead search.
    fn default() -> Self {
        Self::for_method(Method::NelderMead)
    }
}

/// The placement of the dot files: the traced pattern's when it is printable (then
/// `--export-placement` must not be given), else the one `--export-placement` asks for,
/// or none (`virtual` without it: no dot files).
pub(super) fn export_placement(
    traced: Placement,
    tag: &str,
    options: &OptimizeOptions,
) -> Result<Option<Placement>> {
    match (traced.printable(), options.export_placement) {
        (true, None) => Ok(Some(traced)),
        (true, Some(_)) => bail!(
            "option `export_placement` is for virtual patterns: surfaces.{tag} is printed as \"{}\", and its dots are exported as traced",
            traced.name()
        ),
        (false, asked) => Ok(asked),
    }
}

/// Options that only one method takes must not be given to the other.
pub(super) fn check_method_options(options: &OptimizeOptions) -> Result<()> {
    if options.vary.is_empty() && options.method == Method::Grid {
        bail!(
            "option `method` grid scans option `vary` variables: give at least one option `vary` KEY=MIN..MAX"
        );
    }
    if !(1..=2).contains(&options.dims) {
        bail!("option `dims` must be 1 or 2, got {}", options.dims);
    }
    if options.dims == 2 && !options.tunes_grid() {
        bail!(
            "option `dims` 2 needs option `method` feedback (Nelder-Mead tunes a polynomial along the axis)"
        );
    }
    match options.cells {
        Some(_) if !options.tunes_grid() => {
            bail!("option `cells` needs option `method` feedback option `dims` 2")
        }
        Some((nx, ny)) if nx < 2 || ny < 2 => {
            bail!("option `cells` needs at least 2 knots each way, got {nx},{ny}")
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_documented_ones() {
        let d = OptimizeOptions::default();
        assert_eq!(d.method, Method::NelderMead);
        assert_eq!((d.photons, d.seed, d.max_iter), (1_000_000, 1, 60));
        assert_eq!(
            (d.min_density, d.initial_step, d.simplex_tol),
            (0.01, 0.2, 2e-3)
        );
        assert_eq!((d.alpha, d.smoothing, d.dims), (0.7, 0.25, 1));
        assert_eq!((d.edge_margin_mm, d.verify_photons), (0.0, 10_000_000));
        assert_eq!(
            (d.backend, d.estimator),
            (BackendChoice::Auto, Estimator::Analog)
        );
        assert!(d.target_cv.is_none() && d.degree.is_none() && d.max_density.is_none());
        assert!(d.tag.is_none() && d.cells.is_none() && d.strips.is_none());
        assert!(d.verify_seed.is_none() && d.threads.is_none());
        assert!(d.vary.is_empty() && d.grid_points == 7);
        assert_eq!(d.objective, ObjectiveSpec::default());
    }

    #[test]
    fn feedback_has_its_own_round_cap() {
        assert_eq!(OptimizeOptions::for_method(Method::Feedback).max_iter, 15);
        assert_eq!(OptimizeOptions::for_method(Method::Grid).max_iter, 60);
    }
}
