//! The Nelder-Mead driver: the simplex over the density polynomial's scaled coefficients.

use super::nelder_mead::{self, Cost};
use super::report::IterationReport;
use super::search::{Search, violation};
use crate::optics::dots::Density;
use anyhow::Result;
use std::cell::RefCell;

/// The polynomial coefficients Nelder-Mead starts from: the scene's (padded to `degree`),
/// or a constant at the mean density when the scene's is a table, not a polynomial of at
/// most `degree`, or leaves the allowed range.
fn start_coefficients(s: &Search, degree: usize) -> Vec<f64> {
    let p = &s.pattern;
    let mut c = match &p.grade.density {
        Density::Polynomial(c) if c.len() <= degree + 1 => c.clone(),
        _ => vec![],
    };
    if c.is_empty() || violation(p, &Density::Polynomial(c.clone()), s.min, s.max) > 0.0 {
        let n = 256;
        let mean = (0..n)
            .map(|i| p.density_at(p.grade.length * (i as f64 + 0.5) / n as f64))
            .sum::<f64>()
            / n as f64;
        c = vec![mean.clamp(s.min, s.max)];
    }
    c.resize(degree + 1, 0.0);
    c
}

/// The scaled coefficients `z_k = c_k x_max^k`: each term's contribution at the far end,
/// in density units.
struct Scaling(Vec<f64>);

impl Scaling {
    fn new(x_max: f64, degree: usize) -> Self {
        Scaling((0..=degree).map(|k| x_max.powi(k as i32)).collect())
    }

    /// Coefficients `c` of scaled coefficients `z`.
    fn to_c(&self, z: &[f64]) -> Vec<f64> {
        z.iter().zip(&self.0).map(|(z, s)| z / s).collect()
    }

    /// Scaled coefficients `z` of coefficients `c`.
    fn to_z(&self, c: &[f64]) -> Vec<f64> {
        c.iter().zip(&self.0).map(|(c, s)| c * s).collect()
    }
}

/// The polynomial degree: `--degree`, else the scene's, at least 3.
fn degree(search: &Search) -> usize {
    let scene_degree = match &search.pattern.grade.density {
        Density::Polynomial(c) => c.len().saturating_sub(1),
        Density::Table(_) | Density::Grid(_) => 0,
    };
    search.options.degree.unwrap_or(scene_degree.max(3))
}

/// Initial steps of `--initial-step` that keep the first simplex feasible where a sign
/// allows it.
fn initial_steps(search: &Search, scaling: &Scaling, z0: &[f64]) -> Vec<f64> {
    let h = search.options.initial_step;
    (0..z0.len())
        .map(|k| {
            let mut z = z0.to_vec();
            z[k] += h;
            let up = violation(
                &search.pattern,
                &Density::Polynomial(scaling.to_c(&z)),
                search.min,
                search.max,
            );
            if up > 0.0 { -h } else { h }
        })
        .collect()
}

/// The key of a parameter vector in `Search::seen`.
fn key(z: &[f64]) -> Vec<u64> {
    z.iter().map(|v| v.to_bits()).collect()
}

/// The cost of scaled coefficients `z`: the objective, or infeasible by its violation for
/// a design that leaves the allowed density range (not traced); a traced design without
/// light on the profile (no objective) is infeasible too.
fn cost(s: &mut Search, scaling: &Scaling, z: &[f64]) -> Result<Cost> {
    let density = Density::Polynomial(scaling.to_c(z));
    let v = violation(&s.pattern, &density, s.min, s.max);
    if v > 0.0 {
        s.evaluations += 1;
        return Ok(Cost::Infeasible(v));
    }
    let ev = s.evaluate(&density)?;
    let objective = ev.objective;
    s.seen.insert(key(z), ev);
    Ok(Cost::Feasible(objective))
}

/// Run Nelder-Mead on `search`; returns why it stopped.
pub(super) fn run_nelder_mead(
    search: &mut Search,
    progress: &mut dyn FnMut(&IterationReport),
) -> Result<String> {
    let degree = degree(search);
    let scaling = Scaling::new(search.pattern.x_max(), degree);
    let z0 = scaling.to_z(&start_coefficients(search, degree));
    let steps = initial_steps(search, &scaling, &z0);
    let settings = nelder_mead::Settings {
        max_iter: search.options.max_iter,
        target: search.options.target_cv,
        x_tol: search.options.simplex_tol,
        ..nelder_mead::Settings::default()
    };
    let cell = RefCell::new(search);
    let mut cost = |z: &[f64]| cost(&mut cell.borrow_mut(), &scaling, z);
    let mut on_iter = |it: &nelder_mead::Iteration| {
        let mut s = cell.borrow_mut();
        if let Some(ev) = s.seen.get(&key(it.best)).cloned() {
            let c = scaling.to_c(it.best);
            s.report(it.iteration, it.step.to_string(), c, &ev, progress);
        }
    };
    let outcome = nelder_mead::minimize_ranked(&mut cost, &z0, &steps, &settings, &mut on_iter)?;
    Ok(format!(
        "{} after {} iterations",
        outcome.termination, outcome.iterations
    ))
}
