//! How to optimize: the method and the options of `blutrace optimize`, checked.

use super::layout::{ObjectiveSpec, VarySpec};
use crate::accel::BackendChoice;
use crate::optics::dots::Placement;
use crate::optics::surface::Estimator;
use anyhow::{Result, bail};
use clap::{Args, FromArgMatches};
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
    /// With `--vary`: a scan of one or two variables on a grid of `--grid-points` each.
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

/// How to optimize: the options of `blutrace optimize` (their defaults are the `#[arg]`
/// defaults, also behind [`Default`]).
#[derive(Clone, Debug, Serialize, clap::Args)]
pub struct OptimizeOptions {
    /// Nelder-Mead over the density polynomial (the paper's), or per-strip feedback; with
    /// --vary: Nelder-Mead over the variables, or a grid scan of one or two.
    #[arg(long, value_enum, default_value = "nelder-mead")]
    pub method: Method,
    /// A number of the scene file to optimize, KEY=MIN..MAX (repeatable): KEY a dotted path
    /// such as sources.0.center.2, `*` for every element of an array (set together).
    #[arg(long, value_name = "KEY=MIN..MAX")]
    pub vary: Vec<VarySpec>,
    /// With --vary: cv (debiased area cv), thirteen-point (1 - 13-point min/max),
    /// efficiency (1 - extraction efficiency), or a weighted mix NAME=W,NAME=W.
    #[arg(long, default_value = "cv")]
    pub objective: ObjectiveSpec,
    /// With --method grid: points per variable, ends included.
    #[arg(long, default_value_t = 7)]
    pub grid_points: usize,
    /// Photons per evaluated design.
    #[arg(long, default_value_t = 1_000_000, value_parser = crate::count::parse_photons)]
    pub photons: u64,
    /// Seed shared by every evaluation (common random numbers); `blutrace optimize
    /// --seed`, whose default is the scene's `trace.seed`, sets it.
    #[arg(skip = 1u64)]
    pub seed: u64,
    /// Stops the search after the design it is tracing: the result keeps the designs
    /// traced before (set by the CLI's signal handler).
    #[arg(skip)]
    #[serde(skip)]
    pub interrupt: crate::run::Interrupt,
    /// Iteration cap (Nelder-Mead steps, or feedback rounds after the first trace);
    /// default 60 for Nelder-Mead, 15 for feedback.
    #[arg(
        long,
        default_value_t = 60,
        default_value_if("method", "feedback", "15"),
        hide_default_value = true
    )]
    pub max_iter: usize,
    /// Stop once the objective (cv of the profile along the axis) is at or below this.
    #[arg(long, value_parser = crate::count::parse_finite)]
    pub target_cv: Option<f64>,
    /// Degree of the density polynomial (default: the scene's, at least 3).
    #[arg(long)]
    pub degree: Option<usize>,
    /// Smallest printable density (area fraction).
    #[arg(long, default_value_t = 0.01, value_parser = crate::count::parse_finite)]
    pub min_density: f64,
    /// Largest density (default and at most: the lattice's packing limit).
    #[arg(long, value_parser = crate::count::parse_finite)]
    pub max_density: Option<f64>,
    /// The dots surface to optimize (default: the scene's only one).
    #[arg(long)]
    pub tag: Option<String>,
    /// Nelder-Mead: initial simplex step (density units at the far end; with --vary, a
    /// fraction of each variable's range).
    #[arg(long, default_value_t = 0.2, value_parser = crate::count::parse_finite)]
    pub initial_step: f64,
    /// Nelder-Mead: stop once the simplex is smaller than this (density units; with --vary,
    /// a fraction of each variable's range).
    #[arg(long, default_value_t = 2e-3, value_parser = crate::count::parse_finite)]
    pub simplex_tol: f64,
    /// Feedback: damping exponent of d <- d (target / measured)^alpha.
    #[arg(long, default_value_t = 0.7, value_parser = crate::count::parse_finite)]
    pub alpha: f64,
    /// Feedback: weight of the neighbours' mean in a smoothing pass (0: none).
    #[arg(long, default_value_t = 0.25, value_parser = crate::count::parse_finite)]
    pub smoothing: f64,
    /// Feedback: 1 (a table of knots along the axis) or 2 (a grid over the face, for
    /// non-uniformity across the axis too, such as LEDs on an edge).
    #[arg(long, default_value_t = 1)]
    pub dims: usize,
    /// Feedback with --dims 2: knots of the grid along and across the axis, as NX,NY
    /// (default 56,28).
    #[arg(long, value_parser = parse_cells)]
    pub cells: Option<(usize, usize)>,
    /// Profile strips along the axis (default: the detector's bins along it).
    #[arg(long)]
    pub strips: Option<usize>,
    /// Leave this many mm at either end of the span out of the objective.
    #[arg(long, default_value_t = 0.0, value_parser = crate::count::parse_finite)]
    pub edge_margin_mm: f64,
    /// Photons of the verification re-traces of the first and final design (0: none; the
    /// optimization's own traces of the first and best design are reported instead).
    #[arg(long, default_value_t = 10_000_000, value_parser = crate::count::parse_count)]
    pub verify_photons: u64,
    /// Seed of the verification re-traces (default: one no evaluation used).
    #[arg(long)]
    pub verify_seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Intersection backend.
    #[arg(long, value_enum, default_value = "auto")]
    #[serde(skip)]
    pub backend: BackendChoice,
    /// Analog roulette or absorption by weights.
    #[arg(long, value_enum, default_value = "analog")]
    pub estimator: Estimator,
    /// For a `placement = "virtual"` surface, which is not printable: write the dot files
    /// for this printable placement of the same density (lattice, jittered or stochastic,
    /// drawn with the surface's placement_seed). Without it, a virtual pattern gets no
    /// dot files.
    #[arg(long, value_parser = parse_printable)]
    pub export_placement: Option<Placement>,
}

impl OptimizeOptions {
    /// True for the 2-D feedback, which tunes a density grid over the whole face.
    pub fn tunes_grid(&self) -> bool {
        self.method == Method::Feedback && self.dims == 2
    }

    /// The seed of the verification re-traces.
    pub fn verification_seed(&self) -> u64 {
        self.verify_seed
            .unwrap_or_else(|| self.seed.wrapping_add(0x9E37_79B9))
    }
}

impl Default for OptimizeOptions {
    /// The options of `blutrace optimize` given no flags.
    fn default() -> Self {
        let command = Self::augment_args(clap::Command::new("optimize"));
        let matches = command
            .try_get_matches_from(["optimize"])
            .expect("no flags parse");
        Self::from_arg_matches(&matches).expect("the defaults are valid options")
    }
}

/// A printable placement named on the command line.
fn parse_printable(s: &str) -> Result<Placement, String> {
    match Placement::ALL.iter().find(|(n, _)| *n == s) {
        Some((_, p)) if p.printable() => Ok(*p),
        Some(_) => Err(format!(
            "\"{s}\" is not printable (it has no dots): use lattice, jittered or stochastic"
        )),
        None => Err(format!(
            "unknown placement \"{s}\": use lattice, jittered or stochastic"
        )),
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
            "--export-placement is for virtual patterns: surfaces.{tag} is printed as \"{}\", and its dots are exported as traced",
            traced.name()
        ),
        (false, asked) => Ok(asked),
    }
}

/// `NX,NY` of `--cells`.
fn parse_cells(s: &str) -> Result<(usize, usize), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    match parts[..] {
        [a, b] => match (a.parse::<usize>(), b.parse::<usize>()) {
            (Ok(a), Ok(b)) if a >= 2 && b >= 2 => Ok((a, b)),
            _ => Err(format!("expected NX,NY with both at least 2, got '{s}'")),
        },
        _ => Err(format!("expected NX,NY, got '{s}'")),
    }
}

/// Options that only one method takes must not be given to the other.
pub(super) fn check_method_options(options: &OptimizeOptions) -> Result<()> {
    if options.vary.is_empty() && options.method == Method::Grid {
        bail!("--method grid scans --vary variables: give at least one --vary KEY=MIN..MAX");
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The options `blutrace optimize` flags `args` give.
    fn parse(args: &[&str]) -> OptimizeOptions {
        let command = OptimizeOptions::augment_args(clap::Command::new("optimize"));
        let matches = command
            .try_get_matches_from(std::iter::once("optimize").chain(args.iter().copied()))
            .unwrap();
        OptimizeOptions::from_arg_matches(&matches).unwrap()
    }

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
        assert_eq!(parse(&["--method", "feedback"]).max_iter, 15);
        assert_eq!(
            parse(&["--method", "feedback", "--max-iter", "3"]).max_iter,
            3
        );
        assert_eq!(parse(&["--method", "nelder-mead"]).max_iter, 60);
        assert_eq!(parse(&["--cells", "14,7"]).cells, Some((14, 7)));
        assert!(
            OptimizeOptions::augment_args(clap::Command::new("optimize"))
                .try_get_matches_from(["optimize", "--cells", "1,7"])
                .is_err()
        );
    }
}
