//! Dot-density optimization: find the ink-dot density `d(x)` that makes the backlight
//! uniform (the founding paper's section 4), by Nelder-Mead over the density polynomial's
//! coefficients or by a faster feedback on a tabulated density.
//!
//! ```text
//! blutrace optimize SCENE [--method nelder-mead|feedback] [--photons N] [--max-iter K]
//!                         [--target-cv X] [--seed S] [--out DIR]
//! ```
//!
//! The optimized surface is the scene's `model = "dots"` surface (`--tag` picks one when
//! there are several):
//!
//! ```toml
//! [surfaces.lgp_back]
//! model = "dots"
//! density = [0.2]                 # the start; Nelder-Mead varies c0..c3 (cubic by default)
//! # density_table = [[x, d], ...] # what the feedback method writes
//! x_unit = "normalized"
//! mirror = true
//! ```
//!
//! - [`objective`]: the cv of the flux profile along the propagation axis, with its noise;
//!   every evaluation of one optimization uses the same seed (common random numbers).
//! - [`nelder_mead`]: the simplex method with standard coefficients and the paper's
//!   termination tests. It works on scaled coefficients `z_k = c_k x_max^k` (each is the
//!   term's density contribution at the far end), so the initial step and the simplex-size
//!   tolerance are in density units whatever `x_unit` is. A design whose density leaves
//!   `[min printable, max packing]` anywhere on the face is not traced: it gets the penalty
//!   `1000 + violation`.
//! - [`feedback`]: per-strip damped ratio updates of a tabulated density (or per cell of a
//!   density grid with `--dims 2`).
//! - [`export`]: `dots.csv`, `dots.svg`, `dots.dxf`.
//!
//! After the search, the first and the final design are both re-traced with a fresh seed
//! and more photons (`--verify-photons`), and [`OptimizeResult::write`] writes
//! `optimized.toml`, `history.csv`, `density.png`, `profile.png` (and `density_map.png` for
//! a density grid), `optimize.json`, the dot files and the two traces' outputs in
//! `initial/` and `final/`.

pub mod cli;
pub mod export;
pub mod feedback;
pub mod nelder_mead;
pub mod objective;

use crate::accel::BackendChoice;
use crate::optics::dots::{Density, DensityGrid, DotPattern};
use crate::optics::surface::{Estimator, SurfaceModel};
use crate::output::atomic::StagedDir;
use crate::output::plot::{Chart, Scale, Series, write_chart};
use crate::output::png::{PreviewOptions, write_false_colour};
use crate::run::summary::Summary;
use crate::run::{self, ConvergenceRow, RunOptions, RunResult, StoppedBy};
use crate::scene::Scene;
use crate::scene::config::SceneFile;
use crate::tracer::Tally;
use anyhow::{Context, Result, bail};
use export::Dot;
use glam::DVec3;
use objective::Evaluation;
use serde::Serialize;
use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

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

/// The state after one iteration, for progress lines and `history.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct IterationReport {
    /// The method.
    pub method: Method,
    /// Iteration (0: the first design, or the initial simplex).
    pub iteration: usize,
    /// Designs evaluated so far (traced or rejected as infeasible).
    pub evaluations: usize,
    /// Photons traced so far.
    pub photons: u64,
    /// Wall time so far (s).
    pub seconds: f64,
    /// The best objective so far (profile cv).
    pub objective: f64,
    /// Its standard error.
    pub noise: f64,
    /// The cv noise alone would give.
    pub noise_floor: f64,
    /// cv of the whole flux map of the best design.
    pub map_cv: f64,
    /// cv of the flux map without the edge margins, of the best design.
    pub area_cv: f64,
    /// 13-point min/max of the best design.
    pub thirteen_point: f64,
    /// What the iteration did (Nelder-Mead step, or "feedback").
    pub step: String,
    /// The best design's parameters: polynomial coefficients, or knot densities.
    pub params: Vec<f64>,
}

impl std::fmt::Display for IterationReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "iter {:>3}  evals {:>4}  photons {:>7.2}M  {:>6.1} s  cv {:.4} ± {:.4} (floor {:.4})  area cv {:.3}  map cv {:.3}  13-pt {:.3}  {:<12}",
            self.iteration,
            self.evaluations,
            self.photons as f64 * 1e-6,
            self.seconds,
            self.objective,
            self.noise,
            self.noise_floor,
            self.area_cv,
            self.map_cv,
            self.thirteen_point,
            self.step
        )?;
        match self.method {
            Method::NelderMead => {
                let c: Vec<String> = self.params.iter().map(|c| format!("{c:.4}")).collect();
                write!(f, "  c = [{}]", c.join(", "))
            }
            Method::Feedback => {
                let (lo, hi) = self
                    .params
                    .iter()
                    .fold((f64::INFINITY, 0.0f64), |(l, h), d| (l.min(*d), h.max(*d)));
                write!(f, "  d {lo:.3}..{hi:.3}")
            }
        }
    }
}

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
}

impl TracedRun {
    /// Trace `scene`; returns the run and its evaluation.
    fn trace(
        scene: Scene,
        options: &RunOptions,
        strips: usize,
        margin: f64,
        tag_id: usize,
    ) -> Result<(TracedRun, Evaluation)> {
        let r = run::trace(&scene, options, &|_| {})?;
        let pattern = dots_pattern(&scene, tag_id)?;
        let evaluation = Evaluation::of(
            &scene,
            pattern,
            r.flux_map(),
            strips,
            margin,
            r.tally.ledger.photons,
            r.runtime_s,
        );
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
        };
        Ok((traced, evaluation))
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
        }
    }
}

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

/// The outcome of [`optimize`].
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
    #[serde(serialize_with = "ser_density")]
    pub initial_density: Density,
    /// The final design's density.
    #[serde(serialize_with = "ser_density")]
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
    /// The first design at the search's seed and photons.
    pub initial: Evaluation,
    /// The final design at the search's seed and photons.
    pub best: Evaluation,
    /// The re-traces with a fresh seed (None with `verify_photons = 0`).
    pub verification: Option<Verification>,
    /// Every dot of the final pattern.
    #[serde(skip)]
    pub dots: Vec<Dot>,
    /// The final pattern (scene frame).
    #[serde(skip)]
    pub pattern: DotPattern,
    #[serde(skip)]
    initial_run: TracedRun,
    #[serde(skip)]
    final_run: TracedRun,
}

fn ser_density<S: serde::Serializer>(d: &Density, s: S) -> Result<S::Ok, S::Error> {
    #[derive(Serialize)]
    #[serde(rename_all = "snake_case")]
    enum D<'a> {
        Polynomial(&'a [f64]),
        Table(&'a [[f64; 2]]),
        Grid {
            x_max: f64,
            v_min: f64,
            width: f64,
            values: &'a [Vec<f64>],
        },
    }
    match d {
        Density::Polynomial(c) => D::Polynomial(c).serialize(s),
        Density::Table(k) => D::Table(k).serialize(s),
        Density::Grid(g) => D::Grid {
            x_max: g.x_max,
            v_min: g.v_min,
            width: g.width,
            values: &g.values,
        }
        .serialize(s),
    }
}

/// The dot pattern of tag `tag_id`.
fn dots_pattern(scene: &Scene, tag_id: usize) -> Result<&DotPattern> {
    match scene.surfaces.get(tag_id) {
        Some(SurfaceModel::Dots { pattern, .. }) => Ok(pattern),
        _ => bail!("tag {tag_id} is not a dots surface"),
    }
}

/// The tag index of the dots surface to optimize.
fn dots_tag(scene: &Scene, tag: Option<&str>) -> Result<usize> {
    let dots: Vec<usize> = (0..scene.surfaces.len())
        .filter(|&i| matches!(scene.surfaces[i], SurfaceModel::Dots { .. }))
        .collect();
    let names = || {
        dots.iter()
            .map(|&i| scene.tags[i].as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    match tag {
        Some(t) => {
            let i = scene
                .tags
                .iter()
                .position(|x| x == t)
                .with_context(|| format!("{}: no tag '{t}'", scene.path.display()))?;
            if !dots.contains(&i) {
                bail!(
                    "{}: surface '{t}' is not model = \"dots\" (dots surfaces: {})",
                    scene.path.display(),
                    names()
                );
            }
            Ok(i)
        }
        None => match dots[..] {
            [i] => Ok(i),
            [] => bail!(
                "{}: no model = \"dots\" surface to optimize",
                scene.path.display()
            ),
            _ => bail!(
                "{}: several dots surfaces ({}): pick one with --tag",
                scene.path.display(),
                names()
            ),
        },
    }
}

/// How far `density` leaves `[min, max]` anywhere on the pattern's span (0: feasible;
/// infinite for non-finite values).
pub fn violation(pattern: &DotPattern, density: &Density, min: f64, max: f64) -> f64 {
    if let Density::Grid(g) = density {
        // Bilinear values lie between the knots'.
        return g
            .values
            .iter()
            .flatten()
            .map(|&d| {
                if d.is_finite() {
                    (min - d).max(d - max).max(0.0)
                } else {
                    f64::INFINITY
                }
            })
            .fold(0.0, f64::max);
    }
    let samples = 2048;
    let mut p = pattern.clone();
    p.density = density.clone();
    (0..=samples)
        .map(|i| p.density_at(p.length * i as f64 / samples as f64))
        .map(|d| {
            if d.is_finite() {
                (min - d).max(d - max).max(0.0)
            } else {
                f64::INFINITY
            }
        })
        .fold(0.0, f64::max)
}

/// What the search needs while it runs.
struct Search<'a> {
    scene: &'a Scene,
    tag_id: usize,
    pattern: DotPattern,
    options: &'a OptimizeOptions,
    run_options: RunOptions,
    strips: usize,
    min: f64,
    max: f64,
    start: Instant,
    photons: u64,
    evaluations: usize,
    /// The first traced design.
    first: Option<(TracedRun, Evaluation)>,
    /// The best traced design and its density.
    best: Option<(TracedRun, Evaluation, Density)>,
    /// Objective facts per evaluated parameter vector (for progress reports).
    seen: HashMap<Vec<u64>, Evaluation>,
    history: Vec<IterationReport>,
}

impl<'a> Search<'a> {
    fn new(scene: &'a Scene, options: &'a OptimizeOptions) -> Result<Self> {
        let tag_id = dots_tag(scene, options.tag.as_deref())?;
        let pattern = dots_pattern(scene, tag_id)?.clone();
        let packing = pattern.lattice.max_packing();
        let max = options.max_density.unwrap_or(packing).min(packing);
        let min = options.min_density;
        if !(min.is_finite() && min >= 0.0 && min < max) {
            bail!("--min-density {min} must be within [0, {max:.4}) (the largest density allowed)");
        }
        if options.photons == 0 {
            bail!("--photons must be at least 1");
        }
        let strips = options
            .strips
            .unwrap_or_else(|| objective::default_strips(scene, &pattern));
        if strips < 2 {
            bail!("need at least 2 profile strips, got {strips}");
        }
        if !(options.edge_margin_mm >= 0.0 && 2.0 * options.edge_margin_mm < pattern.length) {
            bail!(
                "--edge-margin-mm {} must be >= 0 and leave part of the {:.1} mm span",
                options.edge_margin_mm,
                pattern.length
            );
        }
        let run_options = RunOptions {
            photons: options.photons,
            seed: options.seed,
            threads: options.threads,
            backend: options.backend,
            estimator: options.estimator,
            ..RunOptions::default()
        };
        Ok(Search {
            scene,
            tag_id,
            pattern,
            options,
            run_options,
            strips,
            min,
            max,
            start: Instant::now(),
            photons: 0,
            evaluations: 0,
            first: None,
            best: None,
            seen: HashMap::new(),
            history: Vec::new(),
        })
    }

    /// The scene with the dots surface's density replaced.
    fn scene_with(&self, density: &Density) -> Scene {
        let mut scene = self.scene.clone();
        if let Some(SurfaceModel::Dots { pattern, .. }) = scene.surfaces.get_mut(self.tag_id) {
            pattern.density = density.clone();
        }
        scene
    }

    /// The figure of merit and its standard error: for the 2-D feedback the area cv (the
    /// non-uniformity it can fix is across the axis too) debiased by its noise floor
    /// `sqrt(cv^2 - floor^2)` (per-bin noise dominates the raw area cv at few photons),
    /// else the profile cv.
    fn score(&self, ev: &Evaluation) -> (f64, f64) {
        if self.options.tunes_grid() {
            let debiased = (ev.area_cv.powi(2) - ev.area_noise_floor.powi(2))
                .max(0.0)
                .sqrt();
            let noise = ev.area_cv_noise * ev.area_cv / debiased.max(ev.area_cv_noise);
            (debiased, noise)
        } else {
            (ev.objective, ev.noise)
        }
    }

    /// Trace a design with the search's seed and photons; keeps the first and the best.
    fn evaluate(&mut self, density: &Density) -> Result<Evaluation> {
        self.evaluations += 1;
        let (run, ev) = TracedRun::trace(
            self.scene_with(density),
            &self.run_options,
            self.strips,
            self.options.edge_margin_mm,
            self.tag_id,
        )?;
        self.photons += ev.photons;
        if self.first.is_none() {
            self.first = Some((run.clone(), ev.clone()));
        }
        let better = self
            .best
            .as_ref()
            .is_none_or(|(_, b, _)| self.score(&ev).0 < self.score(b).0);
        if better {
            self.best = Some((run, ev.clone(), density.clone()));
        }
        Ok(ev)
    }

    /// Record and announce one iteration.
    fn report(
        &mut self,
        iteration: usize,
        step: String,
        params: Vec<f64>,
        ev: &Evaluation,
        progress: &mut dyn FnMut(&IterationReport),
    ) {
        let r = IterationReport {
            method: self.options.method,
            iteration,
            evaluations: self.evaluations,
            photons: self.photons,
            seconds: self.start.elapsed().as_secs_f64(),
            objective: ev.objective,
            noise: ev.noise,
            noise_floor: ev.noise_floor,
            map_cv: ev.uniformity.cv,
            area_cv: ev.area_cv,
            thirteen_point: ev.uniformity.thirteen_point_min_over_max,
            step,
            params,
        };
        progress(&r);
        self.history.push(r);
    }
}

/// Optimize the dot density of `scene`'s dots surface; `progress` sees every iteration.
pub fn optimize(
    scene: &Scene,
    options: &OptimizeOptions,
    progress: &mut dyn FnMut(&IterationReport),
) -> Result<OptimizeResult> {
    check_method_options(options)?;
    let mut search = Search::new(scene, options)?;
    let initial_density = search.pattern.density.clone();
    let termination = match options.method {
        Method::NelderMead => run_nelder_mead(&mut search, progress)?,
        Method::Feedback => run_feedback(&mut search, progress)?,
    };
    let seconds = search.start.elapsed().as_secs_f64();
    let (Some((first_run, first_ev)), Some((best_run, best_ev, final_density))) =
        (search.first.take(), search.best.take())
    else {
        bail!("the search traced no design");
    };
    let mut pattern = search.pattern.clone();
    pattern.density = final_density.clone();
    let verification = if options.verify_photons > 0 {
        let run_options = RunOptions {
            photons: options.verify_photons,
            seed: options.verification_seed(),
            ..search.run_options.clone()
        };
        let verify = |density: &Density| -> Result<(TracedRun, VerifiedDesign)> {
            let (run, evaluation) = TracedRun::trace(
                search.scene_with(density),
                &run_options,
                search.strips,
                options.edge_margin_mm,
                search.tag_id,
            )?;
            let summary = run.result().summary();
            Ok((
                run,
                VerifiedDesign {
                    evaluation,
                    summary,
                },
            ))
        };
        let (initial_run, initial) = verify(&initial_density)?;
        let (final_run, final_design) = verify(&final_density)?;
        Some((
            initial_run,
            final_run,
            Verification {
                seed: run_options.seed,
                photons: options.verify_photons,
                initial,
                final_design,
            },
        ))
    } else {
        None
    };
    let triangles: Vec<[DVec3; 3]> = (0..scene.mesh.len() as u32)
        .filter(|&p| scene.mesh.tri_tag[p as usize] as usize == search.tag_id)
        .map(|p| scene.mesh.corners(p))
        .collect();
    let dots = export::dots_on_face(&pattern, &triangles);
    let (initial_run, final_run, verification) = match verification {
        Some((i, f, v)) => (i, f, Some(v)),
        None => (first_run, best_run, None),
    };
    Ok(OptimizeResult {
        method: options.method,
        options: options.clone(),
        scene_file: scene.path.clone(),
        tag: scene.tags[search.tag_id].clone(),
        initial_density,
        final_density,
        iterations: search.history.last().map_or(0, |r| r.iteration),
        evaluations: search.evaluations,
        photons: search.photons,
        history: std::mem::take(&mut search.history),
        seconds,
        termination,
        initial: first_ev,
        best: best_ev,
        verification,
        dots,
        pattern,
        initial_run,
        final_run,
    })
}

/// The polynomial coefficients Nelder-Mead starts from: the scene's (padded to `degree`),
/// or a constant at the mean density when the scene's is a table, not a polynomial of at
/// most `degree`, or leaves the allowed range.
fn start_coefficients(s: &Search, degree: usize) -> Vec<f64> {
    let p = &s.pattern;
    let mut c = match &p.density {
        Density::Polynomial(c) if c.len() <= degree + 1 => c.clone(),
        _ => vec![],
    };
    if c.is_empty() || violation(p, &Density::Polynomial(c.clone()), s.min, s.max) > 0.0 {
        let n = 256;
        let mean = (0..n)
            .map(|i| p.density_at(p.length * (i as f64 + 0.5) / n as f64))
            .sum::<f64>()
            / n as f64;
        c = vec![mean.clamp(s.min, s.max)];
    }
    c.resize(degree + 1, 0.0);
    c
}

fn run_nelder_mead(
    search: &mut Search,
    progress: &mut dyn FnMut(&IterationReport),
) -> Result<String> {
    let scene_degree = match &search.pattern.density {
        Density::Polynomial(c) => c.len().saturating_sub(1),
        Density::Table(_) | Density::Grid(_) => 0,
    };
    let degree = search.options.degree.unwrap_or(scene_degree.max(3));
    let c0 = start_coefficients(search, degree);
    let x_max = search.pattern.x_max();
    // z_k = c_k x_max^k: the term's contribution at the far end, in density units.
    let scale: Vec<f64> = (0..=degree).map(|k| x_max.powi(k as i32)).collect();
    let to_c = |z: &[f64]| -> Vec<f64> { z.iter().zip(&scale).map(|(z, s)| z / s).collect() };
    let z0: Vec<f64> = c0.iter().zip(&scale).map(|(c, s)| c * s).collect();
    // Steps that keep the first simplex feasible where a sign allows it.
    let h = search.options.initial_step;
    let steps: Vec<f64> = (0..=degree)
        .map(|k| {
            let mut z = z0.clone();
            z[k] += h;
            let up = violation(
                &search.pattern,
                &Density::Polynomial(to_c(&z)),
                search.min,
                search.max,
            );
            if up > 0.0 { -h } else { h }
        })
        .collect();
    let settings = nelder_mead::Settings {
        max_iter: search.options.max_iter,
        target: search.options.target_cv,
        x_tol: search.options.simplex_tol,
        ..nelder_mead::Settings::default()
    };
    let cell = RefCell::new(search);
    let key = |z: &[f64]| z.iter().map(|v| v.to_bits()).collect::<Vec<u64>>();
    let mut cost = |z: &[f64]| -> Result<f64> {
        let mut s = cell.borrow_mut();
        let density = Density::Polynomial(to_c(z));
        let v = violation(&s.pattern, &density, s.min, s.max);
        if v > 0.0 {
            s.evaluations += 1;
            return Ok(1000.0 + v.min(1e6));
        }
        let ev = s.evaluate(&density)?;
        let objective = ev.objective;
        s.seen.insert(key(z), ev);
        Ok(objective)
    };
    let mut on_iter = |it: &nelder_mead::Iteration| {
        let mut s = cell.borrow_mut();
        let Some(ev) = s.seen.get(&key(it.best)).cloned() else {
            return;
        };
        s.report(
            it.iteration,
            it.step.to_string(),
            to_c(it.best),
            &ev,
            progress,
        );
    };
    let outcome = nelder_mead::minimize(&mut cost, &z0, &steps, &settings, &mut on_iter)?;
    Ok(format!(
        "{} after {} iterations",
        outcome.termination, outcome.iterations
    ))
}

fn run_feedback(search: &mut Search, progress: &mut dyn FnMut(&IterationReport)) -> Result<String> {
    let settings = feedback_settings(search)?;
    let p = search.pattern.clone();
    match search.options.dims {
        1 => {
            let knots = feedback::knot_positions(&p, feedback::knot_count(&p, search.strips));
            let d = knots
                .iter()
                .map(|&x| p.density.eval(x).clamp(search.min, search.max))
                .collect();
            let mut table = TableFeedback {
                pattern: p,
                knots,
                d,
                settings,
            };
            feedback_rounds(search, &mut table, "feedback", "objective", progress)
        }
        2 => {
            let cells = search.options.cells.unwrap_or((56, 28));
            let (v_lo, v_hi) = match &p.density {
                Density::Grid(g) => (g.v_min, g.v_min + g.width),
                _ => face_v_range(search),
            };
            let grid = feedback::initial_grid(&p, v_lo, v_hi - v_lo, cells, search.min, search.max);
            let mut grid = GridFeedback {
                pattern: p,
                grid,
                settings,
            };
            feedback_rounds(search, &mut grid, "feedback-2d", "area cv", progress)
        }
        d => bail!("--dims must be 1 or 2, got {d}"),
    }
}

/// What a feedback search tunes: a table along the axis or a grid over the face.
trait FeedbackDesign {
    /// The design to trace next.
    fn density(&self) -> Density;
    /// Its parameters, for the history.
    fn params(&self) -> Vec<f64>;
    /// One damped-ratio update from a trace of the current design.
    fn update(&mut self, scene: &Scene, ev: &Evaluation);
}

/// 1-D feedback: one knot per strip along the axis.
struct TableFeedback {
    pattern: DotPattern,
    knots: Vec<f64>,
    d: Vec<f64>,
    settings: feedback::Settings,
}

impl FeedbackDesign for TableFeedback {
    fn density(&self) -> Density {
        Density::Table(
            self.knots
                .iter()
                .zip(&self.d)
                .map(|(x, d)| [*x, *d])
                .collect(),
        )
    }
    fn params(&self) -> Vec<f64> {
        self.d.clone()
    }
    fn update(&mut self, _scene: &Scene, ev: &Evaluation) {
        feedback::update(
            &self.pattern,
            &self.knots,
            &mut self.d,
            &ev.profile,
            &self.settings,
        );
    }
}

/// 2-D feedback: a grid of knots over the face.
struct GridFeedback {
    pattern: DotPattern,
    grid: DensityGrid,
    settings: feedback::Settings,
}

impl FeedbackDesign for GridFeedback {
    fn density(&self) -> Density {
        Density::Grid(self.grid.clone())
    }
    fn params(&self) -> Vec<f64> {
        self.grid.values.iter().flatten().copied().collect()
    }
    fn update(&mut self, scene: &Scene, ev: &Evaluation) {
        let measured = feedback::measured_per_cell(scene, &self.pattern, &self.grid, &ev.map);
        feedback::update_grid(&mut self.grid, &measured, &self.settings);
    }
}

/// The feedback rounds: round 0 traces the scene's own density, every later round the
/// design updated from the round before; stops at the objective bound, the round cap or
/// after [`feedback::STALL_ROUNDS`] rounds without a gain beyond the score's noise.
fn feedback_rounds(
    search: &mut Search,
    design: &mut dyn FeedbackDesign,
    step: &str,
    score_name: &str,
    progress: &mut dyn FnMut(&IterationReport),
) -> Result<String> {
    let mut iteration = 0;
    let mut stalled = 0;
    loop {
        let density = if iteration == 0 {
            search.pattern.density.clone()
        } else {
            design.density()
        };
        let before = search.best.as_ref().map(|(_, b, _)| search.score(b));
        let ev = search.evaluate(&density)?;
        let (score, _) = search.score(&ev);
        match before {
            Some((b, noise)) if score > b - noise => stalled += 1,
            _ => stalled = 0,
        }
        let best = search
            .best
            .as_ref()
            .map_or(ev.clone(), |(_, b, _)| b.clone());
        let step = if iteration == 0 { "initial" } else { step };
        search.report(iteration, step.into(), design.params(), &best, progress);
        if search.options.target_cv.is_some_and(|t| score <= t) {
            return Ok(format!("objective bound reached after {iteration} rounds"));
        }
        if stalled >= feedback::STALL_ROUNDS {
            return Ok(format!(
                "no gain beyond the {score_name}'s noise in {stalled} rounds, after {iteration} rounds"
            ));
        }
        if iteration >= search.options.max_iter {
            return Ok(format!("iteration cap reached after {iteration} rounds"));
        }
        design.update(search.scene, &ev);
        iteration += 1;
    }
}

/// Options that only one method takes must not be given to the other.
fn check_method_options(options: &OptimizeOptions) -> Result<()> {
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

/// The feedback settings of `search`'s options, checked.
fn feedback_settings(search: &Search) -> Result<feedback::Settings> {
    let settings = feedback::Settings {
        alpha: search.options.alpha,
        smoothing: search.options.smoothing,
        min: search.min,
        max: search.max,
    };
    if !(settings.alpha > 0.0 && settings.alpha <= 2.0) {
        bail!("--alpha must be within (0, 2], got {}", settings.alpha);
    }
    if !(0.0..=1.0).contains(&settings.smoothing) {
        bail!(
            "--smoothing must be within [0, 1], got {}",
            settings.smoothing
        );
    }
    Ok(settings)
}

/// The extent of the optimized face across the pattern's axis (mm along `across`).
fn face_v_range(search: &Search) -> (f64, f64) {
    let mesh = &search.scene.mesh;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for prim in 0..mesh.len() as u32 {
        if mesh.tri_tag[prim as usize] as usize != search.tag_id {
            continue;
        }
        for c in mesh.corners(prim) {
            let v = search.pattern.face_coords(c).y;
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}

impl OptimizeResult {
    /// The scene file of the final design: the original with the new density, geometry
    /// and other file paths made absolute, so it traces from anywhere.
    pub fn optimized_toml(&self) -> Result<String> {
        let path = &self.scene_file;
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("{}: cannot read scene file", path.display()))?;
        let mut doc: toml::Table =
            toml::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let absolute = |v: &mut toml::Value| -> Result<()> {
            if let toml::Value::String(s) = v {
                let p = base.join(&*s);
                let p = p
                    .canonicalize()
                    .with_context(|| format!("{}: cannot find {}", path.display(), p.display()))?;
                *s = p.to_string_lossy().into_owned();
            }
            Ok(())
        };
        for section in ["geometry", "sources"] {
            if let Some(toml::Value::Array(items)) = doc.get_mut(section) {
                for item in items.iter_mut() {
                    if let toml::Value::Table(t) = item {
                        for (k, v) in t.iter_mut() {
                            if k == "file" || k.ends_with("_file") {
                                absolute(v)?;
                            }
                        }
                    }
                }
            }
        }
        let surface = doc
            .get_mut("surfaces")
            .and_then(|s| s.as_table_mut())
            .and_then(|s| s.get_mut(&self.tag))
            .and_then(|s| s.as_table_mut())
            .with_context(|| format!("{}: no [surfaces.{}]", path.display(), self.tag))?;
        surface.remove("density");
        surface.remove("density_table");
        surface.remove("density_grid");
        match &self.final_density {
            Density::Polynomial(c) => {
                let c = c.iter().map(|&v| toml::Value::Float(v)).collect();
                surface.insert("density".into(), toml::Value::Array(c));
            }
            Density::Table(k) => {
                let knots = k
                    .iter()
                    .map(|[x, d]| {
                        toml::Value::Array(vec![toml::Value::Float(*x), toml::Value::Float(*d)])
                    })
                    .collect();
                surface.insert("density_table".into(), toml::Value::Array(knots));
            }
            Density::Grid(g) => {
                let mut t = toml::Table::new();
                t.insert("width_mm".into(), toml::Value::Float(g.width));
                t.insert("v_min_mm".into(), toml::Value::Float(g.v_min));
                let rows = g
                    .values
                    .iter()
                    .map(|r| toml::Value::Array(r.iter().map(|&v| toml::Value::Float(v)).collect()))
                    .collect();
                t.insert("values".into(), toml::Value::Array(rows));
                surface.insert("density_grid".into(), toml::Value::Table(t));
            }
        }
        let name = doc
            .get("name")
            .and_then(|n| n.as_str())
            .map(str::to_owned)
            .unwrap_or_else(|| {
                base.file_name()
                    .map_or("scene".into(), |n| n.to_string_lossy().into_owned())
            });
        doc.insert(
            "name".into(),
            toml::Value::String(format!("{name}-optimized")),
        );
        let body = toml::to_string(&doc).context("cannot write the optimized scene as TOML")?;
        let mut out = String::new();
        let _ = writeln!(
            out,
            "# Written by `blutrace optimize --method {}` from {}.\n# Only [surfaces.{}] density changed; file paths are absolute.\n",
            self.method,
            path.display(),
            self.tag
        );
        out.push_str(&body);
        Ok(out)
    }

    /// `history.csv`: one row per iteration.
    pub fn history_csv(&self) -> String {
        let mut s = String::from(
            "iteration,evaluations,photons,seconds,objective,objective_noise,noise_floor,area_cv,map_cv,thirteen_point,step",
        );
        match &self.final_density {
            Density::Polynomial(c) => (0..c.len()).for_each(|k| {
                let _ = write!(s, ",c{k}");
            }),
            Density::Table(k) => k.iter().for_each(|[x, _]| {
                let _ = write!(s, ",d@{x:.5}");
            }),
            Density::Grid(g) => {
                let (nx, ny) = g.shape();
                for j in 0..ny {
                    for i in 0..nx {
                        let _ = write!(s, ",d{i}_{j}");
                    }
                }
            }
        }
        s.push('\n');
        for r in &self.history {
            let _ = write!(
                s,
                "{},{},{},{:.3},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{}",
                r.iteration,
                r.evaluations,
                r.photons,
                r.seconds,
                r.objective,
                r.noise,
                r.noise_floor,
                r.area_cv,
                r.map_cv,
                r.thirteen_point,
                r.step
            );
            for p in &r.params {
                let _ = write!(s, ",{p:.9e}");
            }
            s.push('\n');
        }
        s
    }

    /// Density against position along the axis, initial and final.
    fn density_chart(&self) -> Chart {
        let p = &self.pattern;
        let n = 400;
        let curve = |d: &Density| -> Vec<(f64, f64)> {
            let mut q = p.clone();
            q.density = d.clone();
            (0..=n)
                .map(|i| {
                    let u = p.length * i as f64 / n as f64;
                    (u, q.density_at(u))
                })
                .collect()
        };
        let across = match self.final_density {
            Density::Grid(_) => ", mean across the axis",
            _ => "",
        };
        Chart {
            title: format!("Dot density d(x) on {} ({}{across})", self.tag, self.method),
            x_label: "position along the propagation axis (mm)".into(),
            y_label: "dot density d (area fraction)".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: vec![
                Series::new("initial", curve(&self.initial_density)),
                Series::new("final", curve(&self.final_density)),
            ],
        }
    }

    /// Flux profile along the axis (relative to its mean), initial and final.
    fn profile_chart(&self) -> Chart {
        let (a, b, what) = match &self.verification {
            Some(v) => (
                &v.initial.evaluation,
                &v.final_design.evaluation,
                "verification re-trace",
            ),
            None => (&self.initial, &self.best, "search traces"),
        };
        let rel = |e: &Evaluation| -> Vec<(f64, f64)> {
            let used: Vec<f64> = e
                .profile
                .value
                .iter()
                .zip(&e.profile.used)
                .filter(|(_, u)| **u)
                .map(|(v, _)| *v)
                .collect();
            let mean = used.iter().sum::<f64>() / used.len().max(1) as f64;
            e.profile
                .u
                .iter()
                .zip(&e.profile.value)
                .map(|(u, v)| (*u, v / mean))
                .collect()
        };
        Chart {
            title: format!("Flux profile along the axis ({what})"),
            x_label: "position along the propagation axis (mm)".into(),
            y_label: "flux / mean".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            series: vec![
                Series::new(format!("initial, cv {:.3}", a.objective), rel(a)),
                Series::new(format!("final, cv {:.3}", b.objective), rel(b)),
            ],
        }
    }

    /// Write every output into `dir`: all files are staged and moved into place only
    /// when everything has been written; returns the files and folders written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let toml_text = self.optimized_toml()?;
        // The optimized scene must load as it is.
        let dest = dir.join("optimized.toml");
        let file: SceneFile = toml::from_str(&toml_text)
            .map_err(|e| anyhow::anyhow!("optimized scene does not parse: {e}"))?;
        Scene::from_file(&file, &dest).context("the optimized scene does not load")?;

        let mut staged = StagedDir::new(dir)?;
        staged.write_bytes("optimized.toml", toml_text.as_bytes())?;
        staged.write_bytes("history.csv", self.history_csv().as_bytes())?;
        write_chart(&staged.stage_path("density.png"), &self.density_chart())?;
        write_chart(&staged.stage_path("profile.png"), &self.profile_chart())?;
        if let Density::Grid(g) = &self.final_density {
            write_density_map(&staged.stage_path("density_map.png"), g)?;
        }
        staged.write_bytes("dots.csv", export::to_csv(&self.dots).as_bytes())?;
        staged.write_bytes("dots.svg", export::to_svg(&self.dots).as_bytes())?;
        staged.write_bytes("dots.dxf", export::to_dxf(&self.dots).as_bytes())?;
        staged.write_bytes("optimize.json", &serde_json::to_vec_pretty(self)?)?;

        // initial/ and final/ are written into hidden folders first and renamed at the end.
        let mut temps = TempDirs(Vec::new());
        let mut subdirs = Vec::new();
        for (name, run) in [("initial", &self.initial_run), ("final", &self.final_run)] {
            let temp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
            if temp.exists() {
                std::fs::remove_dir_all(&temp)
                    .with_context(|| format!("cannot remove {}", temp.display()))?;
            }
            temps.0.push(temp.clone());
            run.result().write(&temp)?;
            subdirs.push((temp, dir.join(name)));
        }
        let mut written = Vec::new();
        for (temp, dest) in &subdirs {
            if dest.exists() {
                std::fs::remove_dir_all(dest)
                    .with_context(|| format!("cannot replace {}", dest.display()))?;
            }
            std::fs::rename(temp, dest)
                .with_context(|| format!("cannot move {} to {}", temp.display(), dest.display()))?;
            written.push(dest.clone());
        }
        temps.0.clear();
        let mut files = staged.commit()?;
        files.extend(written);
        Ok(files)
    }
}

/// False-colour map of a 2-D density grid's knots: columns along the axis (left to right
/// from the lamps), rows across it (the first row at the bottom).
fn write_density_map(path: &Path, g: &DensityGrid) -> Result<()> {
    let (nx, ny) = g.shape();
    let values: Vec<f64> = g.values.iter().flatten().copied().collect();
    let opts = PreviewOptions {
        min: Some(0.0),
        max: None,
    };
    write_false_colour(path, nx, ny, &values, &opts)
}

/// Folders removed when dropped (the staging folders of `initial/` and `final/`).
struct TempDirs(Vec<PathBuf>);

impl Drop for TempDirs {
    fn drop(&mut self) {
        for d in &self.0 {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}
