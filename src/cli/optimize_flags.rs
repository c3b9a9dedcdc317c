//! The flags of `blutrace optimize` and how they map onto the library's
//! [`OptimizeOptions`] (one field each; the defaults are the library's, stated here for
//! `--help`).

use super::enums;
use blutrace::accel::BackendChoice;
use blutrace::estimator::Estimator;
use blutrace::optics::dots::Placement;
use blutrace::optimize::ObjectiveSpec;
use blutrace::optimize::layout::VarySpec;
use blutrace::optimize::{Method, OptimizeOptions};

/// How to optimize, as flags.
#[derive(Clone, Debug, clap::Args)]
pub struct OptimizeFlags {
    /// Nelder-Mead over the density polynomial (the paper's), or per-strip feedback; with
    /// --vary: Nelder-Mead over the variables, or a grid scan of one or two.
    #[arg(long, value_parser = enums::method(), default_value = "nelder-mead")]
    method: Method,
    /// A number of the scene file to optimize, KEY=MIN..MAX (repeatable): KEY a dotted path
    /// such as sources.0.center.2, `*` for every element of an array (set together).
    #[arg(long, value_name = "KEY=MIN..MAX")]
    vary: Vec<VarySpec>,
    /// What to minimize: cv (dots: the profile cv; with --vary: the debiased area cv),
    /// thirteen-point (--vary: 1 - 13-point min/max), efficiency (--vary: 1 - extraction
    /// efficiency), delta-uv-13pt (spectral scenes: the colour non-uniformity Δu'v'), or a
    /// weighted mix NAME=W,NAME=W.
    #[arg(long, default_value = "cv")]
    objective: ObjectiveSpec,
    /// With --method grid: points per variable, ends included.
    #[arg(long, default_value_t = 7)]
    grid_points: usize,
    /// Photons per evaluated design.
    #[arg(long, default_value_t = 1_000_000, value_parser = blutrace::count::parse_photons)]
    photons: u64,
    /// Iteration cap (Nelder-Mead steps, or feedback rounds after the first trace);
    /// default 60 for Nelder-Mead, 15 for feedback.
    #[arg(long)]
    max_iter: Option<usize>,
    /// Stop once the objective (cv of the profile along the axis) is at or below this.
    #[arg(long, value_parser = blutrace::count::parse_finite)]
    target_cv: Option<f64>,
    /// Degree of the density polynomial (default: the scene's, at least 3).
    #[arg(long)]
    degree: Option<usize>,
    /// Smallest printable density (area fraction).
    #[arg(long, default_value_t = 0.01, value_parser = blutrace::count::parse_finite)]
    min_density: f64,
    /// Largest density (default and at most: the lattice's packing limit).
    #[arg(long, value_parser = blutrace::count::parse_finite)]
    max_density: Option<f64>,
    /// The dots surface to optimize (default: the scene's only one).
    #[arg(long)]
    tag: Option<String>,
    /// Nelder-Mead: initial simplex step (density units at the far end; with --vary, a
    /// fraction of each variable's range).
    #[arg(long, default_value_t = 0.2, value_parser = blutrace::count::parse_finite)]
    initial_step: f64,
    /// Nelder-Mead: stop once the simplex is smaller than this (density units; with --vary,
    /// a fraction of each variable's range).
    #[arg(long, default_value_t = 2e-3, value_parser = blutrace::count::parse_finite)]
    simplex_tol: f64,
    /// Feedback: damping exponent of d <- d (target / measured)^alpha.
    #[arg(long, default_value_t = 0.7, value_parser = blutrace::count::parse_finite)]
    alpha: f64,
    /// Feedback: weight of the neighbours' mean in a smoothing pass (0: none).
    #[arg(long, default_value_t = 0.25, value_parser = blutrace::count::parse_finite)]
    smoothing: f64,
    /// Feedback: 1 (a table of knots along the axis) or 2 (a grid over the face, for
    /// non-uniformity across the axis too, such as LEDs on an edge).
    #[arg(long, default_value_t = 1)]
    dims: usize,
    /// Feedback with --dims 2: knots of the grid along and across the axis, as NX,NY
    /// (default 56,28).
    #[arg(long, value_parser = parse_cells)]
    cells: Option<(usize, usize)>,
    /// Profile strips along the axis (default: the detector's bins along it).
    #[arg(long)]
    strips: Option<usize>,
    /// Leave this many mm at either end of the span out of the objective.
    #[arg(long, default_value_t = 0.0, value_parser = blutrace::count::parse_finite)]
    edge_margin_mm: f64,
    /// Photons of the verification re-traces of the first and final design (0: none; the
    /// optimization's own traces of the first and best design are reported instead).
    #[arg(long, default_value_t = 10_000_000, value_parser = blutrace::count::parse_count)]
    verify_photons: u64,
    /// Seed of the verification re-traces (default: one no evaluation used).
    #[arg(long)]
    verify_seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Intersection backend.
    #[arg(long, value_parser = enums::backend(), default_value = "auto")]
    backend: BackendChoice,
    /// Analog roulette or absorption by weights.
    #[arg(long, value_parser = enums::estimator(), default_value = "analog")]
    estimator: Estimator,
    /// For a `placement = "virtual"` surface, which is not printable: write the dot files
    /// for this printable placement of the same density (lattice, jittered or stochastic,
    /// drawn with the surface's placement_seed). Without it, a virtual pattern gets no
    /// dot files.
    #[arg(long, value_parser = parse_printable)]
    export_placement: Option<Placement>,
}

impl OptimizeFlags {
    /// The library's options these flags ask for, with the evaluations' `seed`.
    pub fn options(&self, seed: u64) -> OptimizeOptions {
        let f = self.clone();
        OptimizeOptions {
            method: f.method,
            vary: f.vary,
            objective: f.objective,
            grid_points: f.grid_points,
            photons: f.photons,
            seed,
            interrupt: blutrace::run::Interrupt::default(),
            max_iter: f.max_iter.unwrap_or(f.method.default_max_iter()),
            target_cv: f.target_cv,
            degree: f.degree,
            min_density: f.min_density,
            max_density: f.max_density,
            tag: f.tag,
            initial_step: f.initial_step,
            simplex_tol: f.simplex_tol,
            alpha: f.alpha,
            smoothing: f.smoothing,
            dims: f.dims,
            cells: f.cells,
            strips: f.strips,
            edge_margin_mm: f.edge_margin_mm,
            verify_photons: f.verify_photons,
            verify_seed: f.verify_seed,
            threads: f.threads,
            backend: f.backend,
            estimator: f.estimator,
            export_placement: f.export_placement,
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{Args, FromArgMatches};

    /// The options `blutrace optimize` flags `args` give.
    fn parse(args: &[&str]) -> Result<OptimizeOptions, clap::Error> {
        let command = OptimizeFlags::augment_args(clap::Command::new("optimize"));
        let matches = command
            .try_get_matches_from(std::iter::once("optimize").chain(args.iter().copied()))?;
        Ok(OptimizeFlags::from_arg_matches(&matches)?.options(1))
    }

    /// No flags give the library's defaults: one set of defaults, whatever the caller.
    #[test]
    fn no_flags_give_the_library_defaults() {
        let (flags, lib) = (parse(&[]).unwrap(), OptimizeOptions::default());
        let json = |o: &OptimizeOptions| serde_json::to_string(o).unwrap();
        assert_eq!(json(&flags), json(&lib));
        assert_eq!(flags.backend, lib.backend);
        let fb = parse(&["--method", "feedback"]).unwrap();
        assert_eq!(
            json(&fb),
            json(&OptimizeOptions::for_method(Method::Feedback))
        );
    }

    #[test]
    fn feedback_has_its_own_round_cap() {
        assert_eq!(parse(&["--method", "feedback"]).unwrap().max_iter, 15);
        let asked = parse(&["--method", "feedback", "--max-iter", "3"]).unwrap();
        assert_eq!(asked.max_iter, 3);
        assert_eq!(parse(&["--method", "nelder-mead"]).unwrap().max_iter, 60);
        assert_eq!(parse(&["--cells", "14,7"]).unwrap().cells, Some((14, 7)));
        assert!(parse(&["--cells", "1,7"]).is_err());
    }
}
