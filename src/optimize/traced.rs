//! A finished trace of one design, judged: the run (kept whole to write its outputs,
//! `initial/` and `final/`) and what the search makes of it.

use super::objective::Evaluation;
use crate::optics::dots::DotPattern;
use crate::optics::surface::SurfaceModel;
use crate::run::{self, Interrupted, MeshBuildCache, RunOptions, RunResult, StoppedBy};
use crate::scene::Scene;
use anyhow::{Result, bail};

/// Trace `scene`; returns the run and its evaluation.
pub(super) fn trace_design(
    scene: Scene,
    options: &RunOptions,
    strips: usize,
    margin: f64,
    tag_id: usize,
    builds: &mut MeshBuildCache,
) -> Result<(RunResult, Evaluation)> {
    let (run, evaluation) = trace_judged(scene, options, builds, |r| -> Result<Evaluation> {
        let pattern = dots_pattern(&r.scene, tag_id)?;
        Ok(Evaluation::of(
            &r.scene,
            pattern,
            r.flux_map(),
            strips,
            margin,
            r.tally.ledger.photons,
            r.runtime_s,
        ))
    })?;
    Ok((run, evaluation?))
}

/// Trace `scene` (reusing `builds` when the mesh is the last run's) and judge the
/// finished run with `judge`; an [`Interrupted`] error when the options' interrupt
/// stopped the trace before all its photons.
pub(super) fn trace_judged<T>(
    scene: Scene,
    options: &RunOptions,
    builds: &mut MeshBuildCache,
    judge: impl FnOnce(&RunResult) -> T,
) -> Result<(RunResult, T)> {
    let r = run::trace_reusing(scene, options, builds, &|_| {})?;
    if r.stopped_by == StoppedBy::Interrupted {
        return Err(Interrupted.into());
    }
    let judged = judge(&r);
    Ok((r, judged))
}

/// The dot pattern of tag `tag_id`.
pub(super) fn dots_pattern(scene: &Scene, tag_id: usize) -> Result<&DotPattern> {
    match scene.surfaces.get(tag_id) {
        Some(SurfaceModel::Dots(d)) => Ok(&d.pattern),
        _ => bail!("tag {tag_id} is not a dots surface"),
    }
}
