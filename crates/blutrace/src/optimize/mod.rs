//! Optimization. With `--vary`, any numbers of the scene file ([`layout`]); otherwise the
//! dot density. Dot-density optimization: find the ink-dot density `d(x)` that makes the backlight
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
//!   `[min printable, max packing]` anywhere on the face is not traced: it ranks after
//!   every feasible design, by its violation ([`nelder_mead::Cost`]), as does a design
//!   that puts no light on the profile; so weighting the objective changes no step.
//! - [`feedback`]: per-strip damped ratio updates of a tabulated density (or per cell of a
//!   density grid with `--dims 2`).
//! - [`export`]: `dots.csv`, `dots.svg`, `dots.dxf`, placed as the surface's `placement`
//!   says. A `placement = "virtual"` surface has no dots to print: optimize writes no dot
//!   files for it unless `--export-placement lattice|jittered|stochastic` asks for a
//!   printable sheet of the same density.
//!
//! After the search, the first and the final design are both re-traced with a fresh seed
//! and more photons (`--verify-photons`), and [`OptimizeResult::write`] writes
//! `optimized.toml`, `history.csv`, `density.png`, `profile.png` (and `density_map.png` for
//! a density grid), `optimize.json`, the dot files and the two traces' outputs in
//! `initial/` and `final/`.
//!
//! Inside: the options (`options`), the search state shared by both methods (`search`),
//! the two drivers (`polynomial_search` for Nelder-Mead, `feedback_search`), the
//! verification (`verify`), the outcome (`result`, `report`, `traced`) and its files
//! (`write`, with `scene_edit` for `optimized.toml` and `charts` for the PNG charts).

mod charts;
mod design;
pub mod export;
pub mod feedback;
mod feedback_search;
pub mod layout;
pub mod nelder_mead;
pub mod objective;
pub mod objective_spec;
mod options;
mod polynomial_search;
mod report;
mod result;
mod scene_edit;
mod search;
mod verify;
mod write;

pub use layout::{LayoutResult, OUTPUT_NAMES as LAYOUT_OUTPUT_NAMES, optimize_layout};
pub use objective_spec::{ObjectiveSpec, Term};
pub use options::{Method, OptimizeOptions};
pub use report::IterationReport;
pub use result::{OptimizeResult, Verification, VerifiedDesign};
pub use search::violation;
pub use write::OUTPUT_NAMES;

use crate::optics::dots::DotPattern;
use crate::run::is_interrupted;
use crate::scene::Scene;
use anyhow::{Result, bail};
use feedback_search::run_feedback;
use options::{check_method_options, export_placement};
use polynomial_search::run_nelder_mead;
use search::Search;

/// Optimize the dot density of `scene`'s dots surface; `progress` sees every iteration.
pub fn optimize(
    scene: &Scene,
    options: &OptimizeOptions,
    progress: &mut dyn FnMut(&IterationReport),
) -> Result<OptimizeResult> {
    check_method_options(options)?;
    if !options.vary.is_empty() {
        bail!("option `vary` variables are optimized by optimize_layout");
    }
    let mut search = Search::new(scene, options)?;
    scene_edit::check_exportable(scene)?;
    let tag = scene.tags[search.tag_id].clone();
    let dots_placement = export_placement(search.pattern.placement, &tag, options)?;
    let initial_density = search.pattern.grade.density.clone();
    let searched = match options.method {
        Method::NelderMead => run_nelder_mead(&mut search, progress),
        Method::Feedback => run_feedback(&mut search, progress),
        Method::Grid => bail!("option `method` grid needs option `vary`"),
    };
    let mut interrupted = false;
    let termination = match searched {
        Ok(t) => t,
        Err(e) if is_interrupted(&e) && search.best.is_some() => {
            interrupted = true;
            "interrupted (the design being traced is dropped)".to_string()
        }
        Err(e) => return Err(e),
    };
    let seconds = search.start.elapsed().as_secs_f64();
    let (Some((first_run, first_ev)), Some((best_run, best_ev, final_density))) =
        (search.first.take(), search.best.take())
    else {
        bail!(
            "the search found no feasible design: every design it traced put no light on the profile (no uniformity to compare)"
        );
    };
    let mut pattern = search.pattern.clone();
    pattern.grade.density = final_density.clone();
    let face = search.face_triangles();
    let dots = match dots_placement {
        Some(placement) => Some(export::dots_on_face(
            &DotPattern {
                placement,
                ..pattern.clone()
            },
            &face,
        )?),
        None => None,
    };
    let sheet = export::SheetFrame::of_face(&pattern, &face, search.scene.offset);
    let verified = match interrupted {
        true => None,
        false => match verify::verify(&search, &initial_density, &final_density) {
            Err(e) if is_interrupted(&e) => {
                interrupted = true;
                None
            }
            v => v?,
        },
    };
    let (initial_run, final_run, verification) = match verified {
        Some((i, f, v)) => (i, f, Some(v)),
        None => (first_run, best_run, None),
    };
    Ok(OptimizeResult {
        method: options.method,
        options: options.clone(),
        scene_file: scene.path.clone(),
        tag,
        initial_density,
        final_density,
        iterations: search.history.last().map_or(0, |r| r.iteration),
        evaluations: search.evaluations,
        photons: search.photons,
        history: std::mem::take(&mut search.history),
        seconds,
        termination,
        interrupted,
        initial: first_ev,
        best: best_ev,
        verification,
        dots,
        dots_placement,
        sheet,
        pattern,
        initial_run,
        final_run,
    })
}
