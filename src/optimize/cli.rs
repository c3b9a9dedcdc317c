//! The `optimize` subcommand.
//!
//! ```text
//! blutrace optimize scenes/notebook14 --method feedback --photons 1000000 --target-cv 0.03
//! blutrace optimize scenes/notebook14 --method nelder-mead --max-iter 60 --out out/nm
//! ```
//!
//! Prints one line per iteration (best objective with its noise, whole-map cv and 13-point
//! ratio of the best design, photons and time so far), then the verification of the
//! first and final design with error bars, and the files written.

use super::{Method, OptimizeOptions, OptimizeResult, VerifiedDesign, optimize};
use crate::accel::BackendChoice;
use crate::optics::surface::Estimator;
use crate::scene::Scene;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Arguments of `blutrace optimize`.
#[derive(Debug, clap::Args)]
pub struct OptimizeArgs {
    /// Scene file (or a folder holding scene.toml).
    pub scene: PathBuf,
    /// Nelder-Mead over the density polynomial (the paper's), or per-strip feedback.
    #[arg(long, value_enum, default_value = "nelder-mead")]
    pub method: Method,
    /// Photons per evaluated design.
    #[arg(long, default_value_t = 1_000_000)]
    pub photons: u64,
    /// Iteration cap (Nelder-Mead steps, or feedback rounds).
    #[arg(long)]
    pub max_iter: Option<usize>,
    /// Stop once the objective (cv of the profile along the axis) is at or below this.
    #[arg(long)]
    pub target_cv: Option<f64>,
    /// Seed shared by every evaluation (default: the scene's trace.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Output folder (default: out/NAME-optimize-METHOD, NAME being the scene's name).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Degree of the density polynomial (default: the scene's, at least 3).
    #[arg(long)]
    pub degree: Option<usize>,
    /// Smallest printable density (area fraction).
    #[arg(long, default_value_t = 0.01)]
    pub min_density: f64,
    /// Largest density (default and at most: the lattice's packing limit).
    #[arg(long)]
    pub max_density: Option<f64>,
    /// The dots surface to optimize (default: the scene's only one).
    #[arg(long)]
    pub tag: Option<String>,
    /// Nelder-Mead: initial simplex step (density units at the far end).
    #[arg(long, default_value_t = 0.2)]
    pub initial_step: f64,
    /// Nelder-Mead: stop once the simplex is smaller than this (density units).
    #[arg(long, default_value_t = 2e-3)]
    pub simplex_tol: f64,
    /// Feedback: damping exponent of d <- d (target / measured)^alpha.
    #[arg(long, default_value_t = 0.7)]
    pub alpha: f64,
    /// Feedback: weight of the neighbours' mean in a smoothing pass (0: none).
    #[arg(long, default_value_t = 0.25)]
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
    #[arg(long, default_value_t = 0.0)]
    pub edge_margin_mm: f64,
    /// Photons of the verification re-traces of the first and final design (0: none).
    #[arg(long, default_value_t = 10_000_000)]
    pub verify_photons: u64,
    /// Seed of the verification re-traces (default: one no evaluation used).
    #[arg(long)]
    pub verify_seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Intersection backend.
    #[arg(long, value_enum, default_value = "auto")]
    pub backend: BackendChoice,
    /// Analog roulette or absorption by weights.
    #[arg(long, value_enum, default_value = "analog")]
    pub estimator: Estimator,
    /// No per-iteration lines.
    #[arg(long)]
    pub quiet: bool,
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

/// Accept a scene folder as well as the file itself.
fn scene_path(p: &Path) -> PathBuf {
    if p.is_dir() {
        p.join("scene.toml")
    } else {
        p.to_path_buf()
    }
}

impl OptimizeArgs {
    /// The options these arguments ask for, with the scene's defaults.
    pub fn options(&self, scene: &Scene) -> OptimizeOptions {
        let d = OptimizeOptions::default();
        OptimizeOptions {
            method: self.method,
            photons: self.photons,
            seed: self.seed.unwrap_or(scene.default_seed),
            max_iter: self.max_iter.unwrap_or(match self.method {
                Method::NelderMead => d.max_iter,
                Method::Feedback => 15,
            }),
            target_cv: self.target_cv,
            degree: self.degree,
            min_density: self.min_density,
            max_density: self.max_density,
            tag: self.tag.clone(),
            initial_step: self.initial_step,
            simplex_tol: self.simplex_tol,
            alpha: self.alpha,
            smoothing: self.smoothing,
            dims: self.dims,
            cells: self.cells,
            strips: self.strips,
            edge_margin_mm: self.edge_margin_mm,
            verify_photons: self.verify_photons,
            verify_seed: self.verify_seed,
            threads: self.threads,
            backend: self.backend,
            estimator: self.estimator,
        }
    }
}

/// Run `blutrace optimize`.
pub fn run(args: OptimizeArgs) -> Result<()> {
    let scene = Scene::load(&scene_path(&args.scene))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let options = args.options(&scene);
    let out = args.out.clone().unwrap_or_else(|| {
        let suffix = if options.tunes_grid() { "-2d" } else { "" };
        PathBuf::from("out").join(format!(
            "{}-optimize-{}{suffix}",
            scene.name, options.method
        ))
    });
    let objective = if options.tunes_grid() {
        "area cv of the flux map (2-D density grid)"
    } else {
        "cv of the flux profile along the axis"
    };
    println!(
        "optimize   {} ({}) by {}: {} photons per design, seed {}, objective = {objective}",
        scene.name,
        scene.path.display(),
        options.method,
        options.photons,
        options.seed
    );
    let quiet = args.quiet;
    let result = optimize(&scene, &options, &mut |r| {
        if !quiet {
            println!("{r}");
        }
    })?;
    print_report(&result);
    for f in result.write(&out)? {
        println!("wrote      {}", f.display());
    }
    Ok(())
}

fn print_verified(label: &str, v: &VerifiedDesign, margin: f64) {
    let (u, e) = (&v.summary.uniformity, &v.summary.uniformity_stderr);
    let ev = &v.evaluation;
    let debiased = (ev.area_cv.powi(2) - ev.area_noise_floor.powi(2))
        .max(0.0)
        .sqrt();
    println!(
        "{label:<10} area cv {:.4} ± {:.4} (noise floor {:.4}, debiased {debiased:.4}) over the map without {margin} mm at the ends",
        ev.area_cv, ev.area_cv_noise, ev.area_noise_floor
    );
    println!(
        "{label:<10} profile cv {:.4} ± {:.4}; map cv {:.4} ± {:.4} (noise floor {:.4}, debiased {:.4} ± {:.4}), 13-pt {:.3} ± {:.3}, 9-pt {:.3} ± {:.3}, efficiency {:.4} ± {:.4}",
        v.evaluation.objective,
        v.evaluation.noise,
        u.cv,
        e.cv,
        v.summary.cv_noise_floor,
        v.summary.cv_debiased,
        v.summary.cv_debiased_stderr,
        u.thirteen_point_min_over_max,
        e.thirteen_point_min_over_max,
        u.nine_point_min_over_max,
        e.nine_point_min_over_max,
        v.summary.extraction_efficiency,
        v.summary.extraction_efficiency_stderr,
    );
}

/// Print the search's totals and the verification.
pub fn print_report(r: &OptimizeResult) {
    println!(
        "search     {}: {} iterations, {} designs, {} photons ({:.2}M), {:.1} s",
        r.termination,
        r.iterations,
        r.evaluations,
        r.photons,
        r.photons as f64 * 1e-6,
        r.seconds
    );
    println!(
        "objective  {:.4} ± {:.4} -> {:.4} ± {:.4} (seed {}; noise floor {:.4}: the cv of noise alone at {} photons)",
        r.initial.objective,
        r.initial.noise,
        r.best.objective,
        r.best.noise,
        r.options.seed,
        r.best.noise_floor,
        r.options.photons
    );
    match &r.final_density {
        crate::optics::dots::Density::Polynomial(c) => {
            let c: Vec<String> = c.iter().map(|v| format!("{v:.6}")).collect();
            println!("density    polynomial [{}]", c.join(", "));
        }
        crate::optics::dots::Density::Table(k) => {
            println!("density    table of {} knots", k.len());
        }
        crate::optics::dots::Density::Grid(g) => {
            let (nx, ny) = g.shape();
            println!("density    grid of {nx} x {ny} knots (along x across)");
        }
    }
    println!("dots       {} on {}", r.dots.len(), r.tag);
    if let Some(v) = &r.verification {
        println!(
            "verify     re-traced with seed {} and {} photons:",
            v.seed, v.photons
        );
        let m = r.options.edge_margin_mm;
        print_verified("  initial", &v.initial, m);
        print_verified("  final", &v.final_design, m);
    }
}
