//! The feedback driver: damped-ratio rounds on a table along the axis or a grid over the
//! face (the update rules are in [`super::feedback`]).

use super::feedback;
use super::objective::Evaluation;
use super::report::IterationReport;
use super::search::Search;
use crate::optics::dots::{Density, DensityGrid, DotPattern};
use crate::scene::Scene;
use anyhow::{Result, bail};

/// Run the feedback rounds on `search`; returns why they stopped.
pub(super) fn run_feedback(
    search: &mut Search,
    progress: &mut dyn FnMut(&IterationReport),
) -> Result<String> {
    let settings = feedback_settings(search)?;
    let p = search.pattern.clone();
    match search.options.dims {
        1 => {
            let knots = feedback::knot_positions(&p, feedback::knot_count(&p, search.strips));
            let d = knots
                .iter()
                .map(|&x| p.grade.density.eval(x).clamp(search.min, search.max))
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
            let (v_lo, v_hi) = match &p.grade.density {
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
        d => bail!("option `dims` must be 1 or 2, got {d}"),
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
            search.pattern.grade.density.clone()
        } else {
            design.density()
        };
        let before = search.best.as_ref().map(|(_, b, _)| search.score(b));
        let ev = search.evaluate(&density)?;
        let (score, _) = search.score(&ev);
        // A round without light on the profile (NaN score) gains nothing either.
        match before {
            Some((b, noise)) if score > b - noise || score.is_nan() => stalled += 1,
            _ => stalled = 0,
        }
        let best = search
            .best
            .as_ref()
            .map_or(ev.clone(), |(_, b, _)| b.clone());
        let step = if iteration == 0 { "initial" } else { step };
        search.report(iteration, step.into(), design.params(), &best, progress);
        if let Some(reason) = stop_reason(search, score, stalled, iteration, score_name) {
            return Ok(reason);
        }
        design.update(search.scene, &ev);
        iteration += 1;
    }
}

/// Why the rounds stop after round `iteration` (scored `score`, `stalled` rounds in a
/// row without a gain), or None to go on.
fn stop_reason(
    search: &Search,
    score: f64,
    stalled: usize,
    iteration: usize,
    score_name: &str,
) -> Option<String> {
    if search.options.target_cv.is_some_and(|t| score <= t) {
        Some(format!("objective bound reached after {iteration} rounds"))
    } else if stalled >= feedback::STALL_ROUNDS {
        Some(format!(
            "no gain beyond the {score_name}'s noise in {stalled} rounds, after {iteration} rounds"
        ))
    } else if iteration >= search.options.max_iter {
        Some(format!("iteration cap reached after {iteration} rounds"))
    } else {
        None
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
        bail!(
            "option `alpha` must be within (0, 2], got {}",
            settings.alpha
        );
    }
    if !(0.0..=1.0).contains(&settings.smoothing) {
        bail!(
            "option `smoothing` must be within [0, 1], got {}",
            settings.smoothing
        );
    }
    Ok(settings)
}

/// The extent of the optimized face across the pattern's axis (mm along `across`).
fn face_v_range(search: &Search) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for c in search.face_triangles().into_iter().flatten() {
        let v = search.pattern.face_coords(c).y;
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}
