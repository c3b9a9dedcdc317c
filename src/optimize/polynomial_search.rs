//! The Nelder-Mead driver: the simplex over the density polynomial's scaled coefficients.

use super::nelder_mead;
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

/// Run Nelder-Mead on `search`; returns why it stopped.
pub(super) fn run_nelder_mead(
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
