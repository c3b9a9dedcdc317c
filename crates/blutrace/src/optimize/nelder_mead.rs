//! The Nelder-Mead simplex method (Nelder & Mead 1965) with the standard coefficients
//! (reflection 1, expansion 2, contraction 1/2, shrink 1/2) and the founding paper's
//! termination tests: a bound on the objective, the size of the simplex, plus an
//! iteration cap.
//!
//! ```text
//! blutrace optimize SCENE --method nelder-mead --target-cv 0.05 --max-iter 60
//! ```
//!
//! Why not `argmin`'s `NelderMead`: it has no simplex-size test and keeps its simplex
//! private, so the paper's second test cannot be added from outside; it unwraps the cost
//! function's result while building the first simplex (a failed trace would panic); and
//! its observers must be `'static`, so a borrowed progress callback cannot see the
//! iterations. The method itself is short; [`minimize`] is tested on Rosenbrock's function
//! and a quadratic (`tests/optimize.rs`).
//!
//! A constrained search ranks its points by [`Cost`]: every feasible point before every
//! infeasible one, feasible ones by their value, infeasible ones by how far they are from
//! feasible. The method only ever compares two costs, so scaling the objective by a
//! positive constant changes no comparison and no point the search visits (a fixed
//! penalty added to the violation would: an objective scaled past it ranks the
//! infeasible points first).

use anyhow::Result;
use serde::Serialize;
use std::cmp::Ordering;

/// Settings of [`minimize`].
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Iteration cap (one iteration = one reflection/expansion/contraction/shrink step).
    pub max_iter: usize,
    /// Stop as soon as the best value is at or below this (the objective bound).
    pub target: Option<f64>,
    /// Stop once every vertex is within this distance (max norm) of the best one.
    pub x_tol: f64,
    /// Stop once the values at the vertices differ by at most this (0: never).
    pub f_tol: f64,
    /// Reflection coefficient (standard: 1).
    pub reflection: f64,
    /// Expansion coefficient (standard: 2).
    pub expansion: f64,
    /// Contraction coefficient (standard: 1/2).
    pub contraction: f64,
    /// Shrink coefficient (standard: 1/2).
    pub shrink: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            max_iter: 200,
            target: None,
            x_tol: 1e-6,
            f_tol: 0.0,
            reflection: 1.0,
            expansion: 2.0,
            contraction: 0.5,
            shrink: 0.5,
        }
    }
}

/// What an iteration did to the simplex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Step {
    /// The initial simplex was evaluated.
    Initial,
    /// The worst vertex was reflected through the centroid of the others.
    Reflection,
    /// The reflection was extended further.
    Expansion,
    /// A point between the centroid and the reflected point replaced the worst vertex.
    OutsideContraction,
    /// A point between the centroid and the worst vertex replaced it.
    InsideContraction,
    /// Every vertex moved halfway towards the best one.
    Shrink,
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Step::Initial => "initial",
            Step::Reflection => "reflect",
            Step::Expansion => "expand",
            Step::OutsideContraction => "contract-out",
            Step::InsideContraction => "contract-in",
            Step::Shrink => "shrink",
        })
    }
}

/// Why [`minimize`] stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The best value reached the objective bound.
    ObjectiveBound,
    /// The simplex became smaller than `x_tol`.
    SimplexSize,
    /// The values at the vertices agree within `f_tol`.
    ValueSpread,
    /// The iteration cap was reached.
    MaxIterations,
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Termination::ObjectiveBound => "objective bound reached",
            Termination::SimplexSize => "simplex size below tolerance",
            Termination::ValueSpread => "objective spread below tolerance",
            Termination::MaxIterations => "iteration cap reached",
        })
    }
}

/// What a point of a constrained search costs, in the order [`minimize_ranked`] ranks
/// points: every `Feasible` before every `Infeasible`.
#[derive(Clone, Copy, Debug)]
pub enum Cost {
    /// A feasible point's objective (NaN and infinities count as infeasible).
    Feasible(f64),
    /// A point outside the feasible set, by how far (>= 0; infinite: no distance to
    /// rank it by).
    Infeasible(f64),
}

impl Cost {
    /// The same cost with a non-finite objective or a NaN distance made
    /// `Infeasible(inf)`, so that the order is total.
    fn ranked(self) -> Cost {
        match self {
            Cost::Feasible(v) if !v.is_finite() => Cost::Infeasible(f64::INFINITY),
            Cost::Infeasible(d) if d.is_nan() => Cost::Infeasible(f64::INFINITY),
            c => c,
        }
    }

    /// The objective of a feasible point, `+inf` for an infeasible one.
    pub fn value(self) -> f64 {
        match self {
            Cost::Feasible(v) => v,
            Cost::Infeasible(_) => f64::INFINITY,
        }
    }

    /// Whether the point is feasible.
    pub fn is_feasible(self) -> bool {
        matches!(self.ranked(), Cost::Feasible(_))
    }

    /// The search's order, lexicographic: feasibility first, then the objective or the
    /// distance.
    pub fn total_cmp(&self, other: &Cost) -> Ordering {
        match (self.ranked(), other.ranked()) {
            (Cost::Feasible(a), Cost::Feasible(b)) => a.total_cmp(&b),
            (Cost::Infeasible(a), Cost::Infeasible(b)) => a.total_cmp(&b),
            (Cost::Feasible(_), Cost::Infeasible(_)) => Ordering::Less,
            (Cost::Infeasible(_), Cost::Feasible(_)) => Ordering::Greater,
        }
    }
}

impl PartialEq for Cost {
    fn eq(&self, other: &Cost) -> bool {
        self.total_cmp(other) == Ordering::Equal
    }
}

impl PartialOrd for Cost {
    fn partial_cmp(&self, other: &Cost) -> Option<Ordering> {
        Some(self.total_cmp(other))
    }
}

/// The state after one iteration, for progress reports.
#[derive(Clone, Debug)]
pub struct Iteration<'a> {
    /// Iterations done (0 after the initial simplex).
    pub iteration: usize,
    /// Objective evaluations so far.
    pub evaluations: usize,
    /// What this iteration did.
    pub step: Step,
    /// The best vertex.
    pub best: &'a [f64],
    /// Its cost.
    pub best_value: Cost,
    /// The worst vertex's cost.
    pub worst_value: Cost,
    /// Largest max-norm distance of a vertex from the best one.
    pub size: f64,
}

/// The result of [`minimize`].
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The best point found.
    pub x: Vec<f64>,
    /// Its value ([`Cost::value`]: `+inf` when no point was feasible).
    pub value: f64,
    /// Iterations done.
    pub iterations: usize,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Why it stopped.
    pub termination: Termination,
}

/// Minimize `f` from `x0`, with an initial simplex of `x0` and `x0 + steps[i] e_i`.
///
/// `f` may return `f64::INFINITY` or NaN for points it rejects (both rank as worst);
/// an `Err` from `f` stops the search and is returned. `on_iter` sees the simplex after
/// the initial evaluation and after every iteration.
pub fn minimize(
    f: &mut dyn FnMut(&[f64]) -> Result<f64>,
    x0: &[f64],
    steps: &[f64],
    settings: &Settings,
    on_iter: &mut dyn FnMut(&Iteration),
) -> Result<Outcome> {
    minimize_ranked(
        &mut |x| f(x).map(Cost::Feasible),
        x0,
        steps,
        settings,
        on_iter,
    )
}

/// [`minimize`] of a constrained problem: `f` says for each point whether it is feasible
/// ([`Cost`]); the objective bound and `f_tol` apply to feasible values only.
pub fn minimize_ranked(
    f: &mut dyn FnMut(&[f64]) -> Result<Cost>,
    x0: &[f64],
    steps: &[f64],
    settings: &Settings,
    on_iter: &mut dyn FnMut(&Iteration),
) -> Result<Outcome> {
    anyhow::ensure!(!x0.is_empty(), "Nelder-Mead needs at least one variable");
    anyhow::ensure!(
        steps.len() == x0.len() && steps.iter().all(|s| s.is_finite() && *s != 0.0),
        "Nelder-Mead needs one non-zero finite initial step per variable"
    );
    let n = x0.len();
    let mut cost = Counted { f, evaluations: 0 };
    let mut simplex: Vec<(Vec<f64>, Cost)> = Vec::with_capacity(n + 1);
    simplex.push((x0.to_vec(), cost.eval(x0)?));
    for (i, s) in steps.iter().enumerate() {
        let mut x = x0.to_vec();
        x[i] += s;
        let v = cost.eval(&x)?;
        simplex.push((x, v));
    }
    sort(&mut simplex);
    let mut iteration = 0usize;
    let mut step = Step::Initial;
    loop {
        let (best, worst) = (&simplex[0], &simplex[n]);
        let size = simplex_size(&simplex);
        let spread = match (best.1, worst.1) {
            (Cost::Feasible(b), Cost::Feasible(w)) => (w - b).abs(),
            _ => f64::INFINITY,
        };
        let termination = if settings.target.is_some_and(|t| best.1 <= Cost::Feasible(t)) {
            Some(Termination::ObjectiveBound)
        } else if size <= settings.x_tol {
            Some(Termination::SimplexSize)
        } else if settings.f_tol > 0.0 && spread <= settings.f_tol {
            Some(Termination::ValueSpread)
        } else if iteration >= settings.max_iter {
            Some(Termination::MaxIterations)
        } else {
            None
        };
        on_iter(&Iteration {
            iteration,
            evaluations: cost.evaluations,
            step,
            best: &best.0,
            best_value: best.1,
            worst_value: worst.1,
            size,
        });
        if let Some(termination) = termination {
            let (x, value) = simplex.swap_remove(0);
            return Ok(Outcome {
                x,
                value: value.value(),
                iterations: iteration,
                evaluations: cost.evaluations,
                termination,
            });
        }
        step = iterate(&mut simplex, &mut cost, settings)?;
        sort(&mut simplex);
        iteration += 1;
    }
}

/// The objective with an evaluation counter; a non-finite objective ranks as infeasible.
struct Counted<'a> {
    f: &'a mut dyn FnMut(&[f64]) -> Result<Cost>,
    evaluations: usize,
}

impl Counted<'_> {
    fn eval(&mut self, x: &[f64]) -> Result<Cost> {
        self.evaluations += 1;
        Ok((self.f)(x)?.ranked())
    }
}

/// Order vertices by cost, best first (stable, so ties keep their order).
fn sort(simplex: &mut [(Vec<f64>, Cost)]) {
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
}

/// Largest max-norm distance of a vertex from the best (first) one.
fn simplex_size(simplex: &[(Vec<f64>, Cost)]) -> f64 {
    let best = &simplex[0].0;
    simplex[1..]
        .iter()
        .flat_map(|(x, _)| x.iter().zip(best).map(|(a, b)| (a - b).abs()))
        .fold(0.0, f64::max)
}

/// `a + t (b - a)`.
fn lerp(a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(a, b)| a + t * (b - a)).collect()
}

/// One Nelder-Mead step on a sorted simplex.
fn iterate(simplex: &mut [(Vec<f64>, Cost)], cost: &mut Counted, s: &Settings) -> Result<Step> {
    let n = simplex.len() - 1;
    let mut centroid = vec![0.0; n];
    for (x, _) in &simplex[..n] {
        centroid
            .iter_mut()
            .zip(x)
            .for_each(|(c, v)| *c += v / n as f64);
    }
    let (f_best, f_second, f_worst) = (simplex[0].1, simplex[n - 1].1, simplex[n].1);
    let worst = simplex[n].0.clone();
    let xr = lerp(&centroid, &worst, -s.reflection);
    let fr = cost.eval(&xr)?;
    if fr < f_best {
        let xe = lerp(&centroid, &xr, s.expansion);
        let fe = cost.eval(&xe)?;
        if fe < fr {
            simplex[n] = (xe, fe);
            return Ok(Step::Expansion);
        }
        simplex[n] = (xr, fr);
        return Ok(Step::Reflection);
    }
    if fr < f_second {
        simplex[n] = (xr, fr);
        return Ok(Step::Reflection);
    }
    if fr < f_worst {
        let xc = lerp(&centroid, &xr, s.contraction);
        let fc = cost.eval(&xc)?;
        if fc <= fr {
            simplex[n] = (xc, fc);
            return Ok(Step::OutsideContraction);
        }
    } else {
        let xc = lerp(&centroid, &worst, s.contraction);
        let fc = cost.eval(&xc)?;
        if fc < f_worst {
            simplex[n] = (xc, fc);
            return Ok(Step::InsideContraction);
        }
    }
    let best = simplex[0].0.clone();
    for vertex in simplex[1..].iter_mut() {
        let x = lerp(&best, &vertex.0, s.shrink);
        let v = cost.eval(&x)?;
        *vertex = (x, v);
    }
    Ok(Step::Shrink)
}
