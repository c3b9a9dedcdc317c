//! Layout and shape optimization: any numbers of the scene file (lamp height and pitch, a
//! source row's lamp count, a procedural reflector's ridge height, even the dot density's
//! coefficients) as the variables of a search.
//!
//! ```text
//! blutrace optimize scenes/direct-lit --vary 'sources.*.center.2=4..20' \
//!     --vary procedural.0.ridge_height_mm=0..15 [--objective cv] [--method nelder-mead|grid]
//! ```
//!
//! - [`vary`]: `--vary KEY=MIN..MAX`, the dotted paths into the scene file.
//! - [`objective`]: the `--objective` ([`crate::optimize::ObjectiveSpec`]: debiased area
//!   cv, 13-point ratio, efficiency, colour Δu'v' or a weighted mix) with jackknife errors.
//! - The search: integer variables (a row's `count`) are enumerated, and for each of their
//!   combinations the continuous ones are searched by Nelder-Mead (the dots optimizer's,
//!   in coordinates scaled to each variable's range, `--initial-step` and `--simplex-tol`
//!   being fractions of the range) or scanned on a grid of `--grid-points` per variable
//!   (one or two variables). Every design is traced with the same seed and photons
//!   (common random numbers). Infeasible designs rank after every feasible one
//!   ([`crate::optimize::nelder_mead::Cost`]), whatever the objective's weights: a point
//!   outside the bounds (not traced; by its distance, so the simplex is pulled back in), a
//!   design whose scene does not load (a lamp row wider than its box; its reason is
//!   reported), and one that puts no light on the target (its uniformity undefined).
//!   None of them is ever the best design.
//! - After the search the scene's own design and the best one are re-traced with a fresh
//!   seed and `--verify-photons`.

pub mod objective;
mod result;
mod search;
pub mod vary;
mod write;

pub use objective::LayoutEvaluation;
pub use result::{IntegerCase, LayoutResult, LayoutVerification, VariableResult, VerifiedLayout};
pub use search::EvaluationRecord;
pub use vary::{Variable, VarySpec};
pub use write::OUTPUT_NAMES;

use super::nelder_mead::Cost;
use super::nelder_mead::{self, Settings};
use super::{Method, OptimizeOptions};
use crate::run::is_interrupted;
use crate::scene::Scene;
use crate::spec_check::short;
use anyhow::{Result, bail};
use search::LayoutSearch;
use std::collections::HashMap;
use std::time::Instant;
use toml::Value;

/// Most combinations of integer values a search enumerates.
const MAX_CASES: usize = 1000;

/// Optimize the `--vary` variables of `scene`; `progress` sees every evaluated design with
/// the variables' names.
pub fn optimize_layout(
    scene: &Scene,
    options: &OptimizeOptions,
    progress: &mut dyn FnMut(&EvaluationRecord, &[String]),
) -> Result<LayoutResult> {
    // The file as the scene was loaded from it (not read again: it may have changed).
    let doc: Value = scene.source().clone();
    let vars = resolve_variables(&doc, options)?;
    check_method(options, &vars)?;
    options.objective.check(scene, true, options.method)?;
    crate::optimize::scene_edit::check_exportable(scene)?;
    if options.photons == 0 {
        bail!("option `photons` must be at least 1");
    }
    let mut search = LayoutSearch {
        scene,
        doc,
        vars,
        objective: options.objective.clone(),
        options,
        run_options: options.search_run(),
        start: Instant::now(),
        photons: 0,
        history: Vec::new(),
        first: None,
        best: None,
        seen: Default::default(),
        builds: Default::default(),
        reads: Default::default(),
        interrupted: false,
    };
    let initial_x: Vec<f64> = search.vars.iter().map(|v| v.initial).collect();
    search.evaluate(&initial_x, progress)?;
    let Some((initial_run, initial)) = search.first.clone() else {
        bail!("the scene's own design was not traced");
    };
    if search.vars.iter().any(|v| !v.contains(v.initial)) {
        // The scene's count lies outside the enumerated range: not a candidate.
        search.best = None;
    }
    let mut cases = Vec::new();
    for ints in integer_cases(&search.vars)? {
        cases.push(search_case(&mut search, &ints, progress)?);
        if search.interrupted {
            break;
        }
    }
    let Some((_, best, best_x)) = search.best.clone() else {
        bail!(
            "the search found no feasible design: every design it traced put no light on the target (no uniformity to compare) or did not load"
        );
    };
    result::finish(search, (initial_run, initial), best, best_x, cases)
}

/// The variables of `--vary`, resolved; continuous ones must start inside their range.
fn resolve_variables(doc: &Value, options: &OptimizeOptions) -> Result<Vec<Variable>> {
    let vars: Vec<Variable> = options
        .vary
        .iter()
        .map(|s| Variable::resolve(doc, s))
        .collect::<Result<_>>()?;
    for (i, v) in vars.iter().enumerate() {
        if let Some(w) = vars[..i].iter().find(|w| w.overlaps(v)) {
            bail!(
                "option `vary` {} and option `vary` {} set the same number",
                w.name,
                v.name
            );
        }
        if !v.integer && !(v.min..=v.max).contains(&v.initial) {
            bail!(
                "option `vary` {}: the scene's value {} is outside {}..{} (the search starts from the scene's design)",
                v.name,
                short(v.initial),
                short(v.min),
                short(v.max)
            );
        }
    }
    Ok(vars)
}

/// The method must suit the variables, and options of the dots objective are not given.
fn check_method(options: &OptimizeOptions, vars: &[Variable]) -> Result<()> {
    let o = options;
    for (given, flag) in [
        (o.tag.is_some(), "option `tag`"),
        (o.degree.is_some(), "option `degree`"),
        (o.strips.is_some(), "option `strips`"),
        (o.cells.is_some(), "option `cells`"),
        (o.max_density.is_some(), "option `max_density`"),
        (o.target_cv.is_some(), "option `target_cv`"),
        (o.dims != 1, "option `dims`"),
    ] {
        if given {
            bail!(
                "{flag} is an option of the dot-density search, not of option `vary` (vary the density's keys instead)"
            );
        }
    }
    let continuous = vars.iter().filter(|v| !v.integer).count();
    match options.method {
        Method::Feedback => {
            bail!(
                "option `method` feedback tunes dot densities; with option `vary` use nelder-mead or grid"
            )
        }
        Method::Grid if !(1..=2).contains(&continuous) => {
            bail!("option `method` grid scans one or two continuous variables, got {continuous}")
        }
        Method::Grid if options.grid_points < 2 => {
            bail!(
                "option `grid_points` must be at least 2, got {}",
                options.grid_points
            )
        }
        _ => Ok(()),
    }
}

/// Every combination of the integer variables' values (one empty case when there are
/// none), at most [`MAX_CASES`].
fn integer_cases(vars: &[Variable]) -> Result<Vec<Vec<Option<f64>>>> {
    let mut cases: Vec<Vec<Option<f64>>> = vec![Vec::new()];
    for v in vars {
        let values: Vec<Option<f64>> = if v.integer {
            v.integers().into_iter().map(Some).collect()
        } else {
            vec![None]
        };
        if cases.len() * values.len() > MAX_CASES {
            bail!(
                "the integer variables have more than {MAX_CASES} combinations: narrow their ranges"
            );
        }
        cases = cases
            .into_iter()
            .flat_map(|c| {
                values.iter().map(move |x| {
                    let mut c = c.clone();
                    c.push(*x);
                    c
                })
            })
            .collect();
    }
    Ok(cases)
}

/// Search the continuous variables with the integer ones fixed at `ints` (None for the
/// continuous ones).
fn search_case(
    search: &mut LayoutSearch,
    ints: &[Option<f64>],
    progress: &mut dyn FnMut(&EvaluationRecord, &[String]),
) -> Result<IntegerCase> {
    let free: Vec<usize> = (0..ints.len()).filter(|&i| ints[i].is_none()).collect();
    let full = |search: &LayoutSearch, z: &[f64]| -> Vec<f64> {
        let mut x: Vec<f64> = ints.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
        for (&i, z) in free.iter().zip(z) {
            let v = &search.vars[i];
            x[i] = v.min + z * (v.max - v.min);
        }
        x
    };
    let scaled: Vec<f64> = free
        .iter()
        .map(|&i| {
            let v = &search.vars[i];
            (v.initial - v.min) / (v.max - v.min)
        })
        .collect();
    let evaluations = search.history.len();
    let mut case_best: Option<(Cost, f64, Vec<f64>)> = None;
    // Every point asked for, by its scaled coordinates' bits: the simplex may ask for a
    // point again (a rejected one, or a shrink back onto a vertex); with common random
    // numbers its objective is the same, so it is neither traced nor reported twice.
    let mut asked: HashMap<Vec<u64>, Cost> = HashMap::new();
    let mut eval = |search: &mut LayoutSearch, z: &[f64]| -> Result<Cost> {
        // Bounds are inclusive as written: a point past an end by rounding (a few ulps of
        // the scaled coordinate) is that end.
        let z: Vec<f64> = z
            .iter()
            .map(|&z| {
                if (-BOUND_SLACK..=1.0 + BOUND_SLACK).contains(&z) {
                    z.clamp(0.0, 1.0)
                } else {
                    z
                }
            })
            .collect();
        let key: Vec<u64> = z.iter().map(|z| z.to_bits()).collect();
        if let Some(&value) = asked.get(&key) {
            return Ok(value);
        }
        let x = full(search, &z);
        let outside = z.iter().map(|z| (-z).max(z - 1.0)).fold(0.0, f64::max);
        if outside > 0.0 {
            search.reject_out_of_bounds(&x, progress);
            asked.insert(key, Cost::Infeasible(outside));
            return Ok(Cost::Infeasible(outside));
        }
        let (value, noise) = search.evaluate(&x, progress)?;
        asked.insert(key, value);
        let better = case_best.as_ref().is_none_or(|(b, _, _)| value < *b);
        if value.is_feasible() && better {
            case_best = Some((value, noise, x));
        }
        Ok(value)
    };
    let mut scan = |search: &mut LayoutSearch| -> Result<String> {
        scan_case(search, &free, &scaled, &mut eval)
    };
    let termination = match scan(search) {
        Ok(t) => t,
        Err(e) if is_interrupted(&e) => {
            search.interrupted = true;
            "interrupted (the design being traced is dropped)".to_string()
        }
        Err(e) => return Err(e),
    };
    let (objective, noise, values) = match case_best {
        Some((cost, noise, x)) => (cost.value(), noise, x),
        None => (f64::NAN, f64::NAN, full(search, &scaled)),
    };

    Ok(IntegerCase {
        integers: ints.iter().flatten().copied().collect(),
        values,
        objective,
        noise,
        evaluations: search.history.len() - evaluations,
        termination,
    })
}

/// Scan or search one case's continuous variables `free` from `scaled` with `eval`;
/// returns how it ended.
fn scan_case(
    search: &mut LayoutSearch,
    free: &[usize],
    scaled: &[f64],
    eval: &mut dyn FnMut(&mut LayoutSearch, &[f64]) -> Result<Cost>,
) -> Result<String> {
    let termination = match (free.is_empty(), search.options.method) {
        (true, _) => {
            eval(search, &[])?;
            "no continuous variable: traced once".to_string()
        }
        (false, Method::Grid) => {
            let points = grid(free.len(), search.options.grid_points);
            for z in &points {
                eval(search, z)?;
            }
            format!("grid of {} designs scanned", points.len())
        }
        (false, _) => {
            let o = search.options;
            // A start that does not load (the scene's pitch with more lamps than fit)
            // gives the simplex nothing to follow: start from the best design of a
            // coarse grid instead (one or two variables).
            let mut start = scaled.to_vec();
            let mut how = String::new();
            if !eval(search, &start)?.is_feasible() && free.len() <= 2 {
                let mut best: Option<(Cost, Vec<f64>)> = None;
                for z in grid(free.len(), o.grid_points) {
                    let v = eval(search, &z)?;
                    if v.is_feasible() && best.as_ref().is_none_or(|(b, _)| v < *b) {
                        best = Some((v, z));
                    }
                }
                if let Some((_, z)) = best {
                    start = z;
                    how = "; started from the best of a grid, the scene's design being infeasible"
                        .into();
                }
            }
            let scaled = start;
            let steps: Vec<f64> = scaled
                .iter()
                .map(|z| {
                    if z + o.initial_step <= 1.0 {
                        o.initial_step
                    } else {
                        -o.initial_step
                    }
                })
                .collect();
            let settings = Settings {
                max_iter: o.max_iter,
                x_tol: o.simplex_tol,
                ..Settings::default()
            };
            let out = nelder_mead::minimize_ranked(
                &mut |z| eval(search, z),
                &scaled,
                &steps,
                &settings,
                &mut |_| {},
            )?;
            format!(
                "{} after {} iterations{how}",
                out.termination, out.iterations
            )
        }
    };
    Ok(termination)
}

/// How far past a range's end (in the range's unit scale) a point still counts as on it:
/// far above the rounding of a few steps of the simplex, far below any step it takes.
const BOUND_SLACK: f64 = 1e-9;

/// The points of a grid of `k` per axis over the unit square (or segment), ends included.
fn grid(dims: usize, k: usize) -> Vec<Vec<f64>> {
    let axis: Vec<f64> = (0..k).map(|j| j as f64 / (k - 1) as f64).collect();
    match dims {
        1 => axis.iter().map(|&a| vec![a]).collect(),
        _ => axis
            .iter()
            .flat_map(|&b| axis.iter().map(move |&a| vec![a, b]))
            .collect(),
    }
}
