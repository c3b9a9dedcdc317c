//! A design of a search and its trace. Both searches, the dot density's and `--vary`'s
//! layouts, are a [`Design`]: a point of the search becomes the scene to trace (a dots
//! surface with a new density; the scene file with the varied values set), the scene is
//! traced, and the finished run is judged; [`Design::trace`] does the three in one place,
//! for the search's evaluations and the verification's re-traces alike.

use crate::optics::dots::DotPattern;
use crate::optics::surface::SurfaceModel;
use crate::run::{self, Interrupted, MeshBuildCache, RunOptions, RunResult, StoppedBy};
use crate::scene::Scene;
use anyhow::{Result, bail};
use std::cell::RefCell;

/// What a search varies, and how it judges a traced design.
pub(super) trait Design {
    /// A point of the search: a density, or the values of the varied keys.
    type Point: ?Sized;
    /// What the search makes of a finished run.
    type Judged;

    /// The scene of the design at `point`, or why it does not load.
    fn scene(&self, point: &Self::Point) -> Result<Scene>;

    /// Judge the finished run of a design.
    fn judge(&self, run: &RunResult) -> Result<Self::Judged>;

    /// The last design's backend and triangle records, reused by the next design when
    /// its mesh is the same (designs that differ in dots or lamp positions only).
    fn builds(&self) -> &RefCell<MeshBuildCache>;

    /// Trace the design at `point` with `options` and judge it.
    fn trace(
        &self,
        point: &Self::Point,
        options: &RunOptions,
    ) -> Result<(RunResult, Self::Judged)> {
        self.trace_scene(self.scene(point)?, options)
    }

    /// Trace `scene`, a design's, and judge it; an [`Interrupted`] error when the options'
    /// interrupt stopped the trace before all its photons (a partly traced design is not
    /// compared with the others).
    fn trace_scene(&self, scene: Scene, options: &RunOptions) -> Result<(RunResult, Self::Judged)> {
        let builds = &mut self.builds().borrow_mut();
        let run = run::trace_reusing(scene, options, builds, &|_| {})?;
        if run.stopped_by == StoppedBy::Interrupted {
            return Err(Interrupted.into());
        }
        let judged = self.judge(&run)?;
        Ok((run, judged))
    }
}

/// The dot pattern of tag `tag_id`.
pub(super) fn dots_pattern(scene: &Scene, tag_id: usize) -> Result<&DotPattern> {
    match scene.surfaces.get(tag_id) {
        Some(SurfaceModel::Dots(d)) => Ok(&d.pattern),
        _ => bail!("tag {tag_id} is not a dots surface"),
    }
}
