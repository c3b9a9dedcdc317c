//! The state of one search: the design space, the traces so far, the best design.

use super::OptimizeOptions;
use super::design::{Design, dots_pattern};
use super::objective::{self, Evaluation, Judging, Traced};
use super::report::IterationReport;
use crate::optics::dots::{Density, DotPattern, Gradation};
use crate::optics::surface::SurfaceModel;
use crate::run::RunResult;
use crate::run::metrics::color::{self, Estimate};
use crate::run::metrics::{debiased, jackknife_stderr};
use crate::run::{MeshBuildCache, RunOptions};
use crate::scene::Scene;
use anyhow::{Context, Result, bail};
use glam::DVec3;
use std::cell::RefCell;
use std::collections::HashMap;
use std::time::Instant;

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
            let i =
                scene.tags.iter().position(|x| x == t).with_context(|| {
                    format!("{}: option `tag`: no tag '{t}'", scene.path.display())
                })?;
            if !dots.contains(&i) {
                bail!(
                    "{}: option `tag`: surface '{t}' is not model = \"dots\" (dots surfaces: {})",
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
                "{}: several dots surfaces ({}): pick one with option `tag`",
                scene.path.display(),
                names()
            ),
        },
    }
}

/// How far `density` leaves `[min, max]` anywhere on the pattern's span (0: feasible;
/// infinite for non-finite values).
pub fn violation(pattern: &DotPattern, density: &Density, min: f64, max: f64) -> f64 {
    let grade = Gradation {
        density: density.clone(),
        ..pattern.grade.clone()
    };
    grade.worst_excess(min, max, 2048)
}

/// The allowed density range `[min printable, max packing]`, checked.
fn density_range(options: &OptimizeOptions, pattern: &DotPattern) -> Result<(f64, f64)> {
    let packing = pattern.lattice.max_packing();
    let max = options.max_density.unwrap_or(packing).min(packing);
    let min = options.min_density;
    if !(min.is_finite() && min >= 0.0 && min < max) {
        bail!(
            "option `min_density` {min} must be within [0, {max:.4}) (the largest density allowed)"
        );
    }
    Ok((min, max))
}

/// The profile strips; checks them with `--photons` and `--edge-margin-mm`.
fn checked_strips(scene: &Scene, options: &OptimizeOptions, pattern: &DotPattern) -> Result<usize> {
    if options.photons == 0 {
        bail!("option `photons` must be at least 1");
    }
    let strips = options
        .strips
        .unwrap_or_else(|| objective::default_strips(scene, pattern));
    if strips < 2 {
        bail!("need at least 2 profile strips, got {strips}");
    }
    if !(options.edge_margin_mm >= 0.0 && 2.0 * options.edge_margin_mm < pattern.grade.length) {
        bail!(
            "option `edge_margin_mm` {} must be >= 0 and leave part of the {:.1} mm span",
            options.edge_margin_mm,
            pattern.grade.length
        );
    }
    Ok(strips)
}

/// What the search needs while it runs.
pub(super) struct Search<'a> {
    pub(super) scene: &'a Scene,
    pub(super) tag_id: usize,
    pub(super) pattern: DotPattern,
    pub(super) options: &'a OptimizeOptions,
    pub(super) run_options: RunOptions,
    pub(super) strips: usize,
    pub(super) min: f64,
    pub(super) max: f64,
    pub(super) start: Instant,
    pub(super) photons: u64,
    pub(super) evaluations: usize,
    /// The first traced design.
    pub(super) first: Option<(RunResult, Evaluation)>,
    /// The best traced design and its density.
    pub(super) best: Option<(RunResult, Evaluation, Density)>,
    /// Objective facts per evaluated parameter vector (for progress reports).
    pub(super) seen: HashMap<Vec<u64>, Evaluation>,
    pub(super) history: Vec<IterationReport>,
    /// The backend and triangle records of the scene's mesh, built by the first trace and
    /// reused by every design after it (only the dots change).
    pub(super) builds: RefCell<MeshBuildCache>,
}

impl<'a> Search<'a> {
    pub(super) fn new(scene: &'a Scene, options: &'a OptimizeOptions) -> Result<Self> {
        let tag_id = dots_tag(scene, options.tag.as_deref())?;
        let pattern = dots_pattern(scene, tag_id)?.clone();
        let (min, max) = density_range(options, &pattern)?;
        let strips = checked_strips(scene, options, &pattern)?;
        options.objective.check(scene, false, options.method)?;
        let run_options = options.search_run();
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
            builds: RefCell::default(),
        })
    }

    /// The figure of merit and its standard error: for the 2-D feedback the area cv (the
    /// non-uniformity it can fix is across the axis too) debiased by its noise floor
    /// `sqrt(cv^2 - floor^2)` (per-bin noise dominates the raw area cv at few photons),
    /// else the profile cv.
    /// NaN or infinite for a design that puts no light on the profile: it has no
    /// uniformity, and is never the best.
    pub(super) fn score(&self, ev: &Evaluation) -> (f64, f64) {
        if self.options.tunes_grid() {
            let debiased = debiased(ev.area_cv, ev.area_noise_floor);
            let noise = ev.area_cv_noise * ev.area_cv / debiased.max(ev.area_cv_noise);
            (debiased, noise)
        } else {
            (ev.objective, ev.noise)
        }
    }

    /// Trace a design with the search's seed and photons; keeps the first and the best
    /// feasible one (light on the profile: a finite score).
    pub(super) fn evaluate(&mut self, density: &Density) -> Result<Evaluation> {
        self.evaluations += 1;
        let (run, ev) = self.trace(density, &self.run_options)?;
        self.photons += ev.photons;
        if self.first.is_none() {
            self.first = Some((run.clone(), ev.clone()));
        }
        let score = self.score(&ev).0;
        let better = self
            .best
            .as_ref()
            .is_none_or(|(_, b, _)| score < self.score(b).0);
        if score.is_finite() && better {
            self.best = Some((run, ev.clone(), density.clone()));
        }
        Ok(ev)
    }

    /// The corners of the optimized face's triangles (scene frame).
    pub(super) fn face_triangles(&self) -> Vec<[DVec3; 3]> {
        let mesh = &self.scene.mesh;
        (0..mesh.len() as u32)
            .filter(|&p| mesh.tri_tag[p as usize] as usize == self.tag_id)
            .map(|p| mesh.corners(p))
            .collect()
    }

    /// Record and announce one iteration.
    pub(super) fn report(
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
            cv: ev.cv,
            delta_uv_13pt_debiased: ev.delta_uv_13pt_debiased.map_or(f64::NAN, |d| d.value),
            step,
            params,
        };
        progress(&r);
        self.history.push(r);
    }
}

/// A dot-density design: the scene with the dots surface's density replaced, judged by
/// its profile (or area) uniformity.
impl Design for Search<'_> {
    type Point = Density;
    type Judged = Evaluation;

    fn scene(&self, density: &Density) -> Result<Scene> {
        let mut scene = self.scene.clone();
        if let Some(SurfaceModel::Dots(d)) = scene.surfaces.get_mut(self.tag_id) {
            d.pattern.grade.density = density.clone();
        }
        Ok(scene)
    }

    fn judge(&self, r: &RunResult) -> Result<Evaluation> {
        let pattern = dots_pattern(&r.scene, self.tag_id)?;
        let delta_uv_13pt_debiased = color::delta_uv_13pt_debiased(&r.scene, &r.tally, &r.groups)
            .map(|(value, lo)| Estimate {
                value,
                stderr: jackknife_stderr(&lo),
            });
        let traced = Traced {
            map: r.flux_map(),
            delta_uv_13pt_debiased,
            photons: r.tally.ledger.photons,
            seconds: r.runtime_s,
        };
        let judging = Judging {
            spec: &self.options.objective,
            strips: self.strips,
            margin: self.options.edge_margin_mm,
        };
        Ok(Evaluation::of(&r.scene, pattern, traced, &judging))
    }

    fn builds(&self) -> &RefCell<MeshBuildCache> {
        &self.builds
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Designs that differ only in their dots share one backend build; the first builds it.
    #[test]
    fn designs_reuse_the_first_designs_backend() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/bench-box");
        let scene = Scene::load(&dir.join("scene.toml")).unwrap();
        let options = OptimizeOptions {
            photons: 4096,
            threads: Some(1),
            ..OptimizeOptions::default()
        };
        let mut search = Search::new(&scene, &options).unwrap();
        for d in [0.1, 0.2, 0.3] {
            search.evaluate(&Density::Polynomial(vec![d])).unwrap();
        }
        assert_eq!(search.evaluations, 3);
        assert_eq!(search.builds.borrow().builds(), 1);
    }
}
