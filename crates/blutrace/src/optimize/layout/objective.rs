//! The layout search's objective ([`ObjectiveSpec`]: weighted losses of the whole flux
//! map, the ledger and the colour) from one fixed-seed trace, with its jackknife standard
//! error.
//!
//! ```text
//! blutrace optimize SCENE --vary ... --objective cv=1,efficiency=0.5
//! ```
//!
//! Here the `cv` term is the area uniformity, the debiased cv of the flux map
//! `sqrt(max(cv^2 - floor^2, 0))` (the map's own Monte Carlo noise removed, so designs
//! traced with few photons are compared on their uniformity, not on their noise).
//!
//! The objective's standard error is the jackknife over the run's photon groups of the
//! whole weighted sum, so the terms' correlations are in it. Its *noise floor* is the cv a
//! perfectly uniform map would show at the search's photons, as for the dots objective.

use crate::optimize::objective_spec::{ObjectiveSpec, TermValues};
use crate::run::RunResult;
use crate::run::metrics::{Metric, MetricValues, Metrics, color, jackknife_stderr};
use anyhow::{Result, bail};
use serde::Serialize;

/// The terms' values from a run's metrics and its Δu'v' 13-point.
fn term_values(m: &MetricValues, delta_uv_13pt_debiased: f64) -> TermValues {
    TermValues {
        cv: m[Metric::CvDebiased],
        thirteen_point: m[Metric::ThirteenPoint],
        efficiency: m[Metric::Efficiency],
        delta_uv_13pt_debiased,
    }
}

/// Judge a finished trace by `spec`.
pub fn evaluate(spec: &ObjectiveSpec, run: &RunResult) -> Result<LayoutEvaluation> {
    let metrics = Metrics::of(&run.scene, &run.tally);
    let values = metrics.values();
    let leave_out = &run.leave_out;
    let (duv, duv_leave_out) =
        match color::delta_uv_13pt_debiased(&run.scene, &run.tally, &run.groups) {
            Some((d, lo)) => (Some(d), lo),
            None if spec.reads_color() => {
                bail!("the objective reads the colour of a monochrome run")
            }
            None => (None, vec![f64::NAN; leave_out.len()]),
        };
    let se = |f: &dyn Fn(&MetricValues, f64) -> f64| {
        let lo: Vec<f64> = leave_out
            .iter()
            .zip(&duv_leave_out)
            .map(|(m, d)| f(m, *d))
            .collect();
        jackknife_stderr(&lo)
    };
    // Without light on the target no term means anything (an efficiency of 0 included):
    // the design is infeasible, its objective NaN.
    let lit = metrics.has_light();
    let objective = |m: &MetricValues, d: f64| match lit {
        true => spec.value(&term_values(m, d)),
        false => f64::NAN,
    };
    let l = &run.tally.ledger;
    Ok(LayoutEvaluation {
        objective: objective(&values, duv.unwrap_or(f64::NAN)),
        noise: se(&objective),
        noise_floor: metrics.cv_noise_floor,
        cv_debiased: values[Metric::CvDebiased],
        cv_debiased_stderr: se(&|m, _| m[Metric::CvDebiased]),
        thirteen_point: values[Metric::ThirteenPoint],
        thirteen_point_stderr: se(&|m, _| m[Metric::ThirteenPoint]),
        efficiency: values[Metric::Efficiency],
        efficiency_stderr: l.detected.mean_and_stderr(l.photons).1,
        delta_uv_13pt_debiased: duv,
        delta_uv_13pt_debiased_stderr: duv.map(|_| se(&|_, d| d)),
        photons: l.photons,
        seconds: run.runtime_s,
    })
}

/// One traced design, judged.
#[derive(Clone, Debug, Serialize)]
pub struct LayoutEvaluation {
    /// The objective (to minimize); NaN when no light reached the target (the design is
    /// infeasible).
    pub objective: f64,
    /// Its standard error (jackknife).
    pub noise: f64,
    /// The cv a perfectly uniform map would show from noise alone at these photons.
    pub noise_floor: f64,
    /// Debiased cv of the flux map.
    pub cv_debiased: f64,
    /// Its standard error.
    pub cv_debiased_stderr: f64,
    /// 13-point min/max.
    pub thirteen_point: f64,
    /// Its standard error.
    pub thirteen_point_stderr: f64,
    /// Extraction efficiency.
    pub efficiency: f64,
    /// Its standard error (per photon).
    pub efficiency_stderr: f64,
    /// Colour non-uniformity Δu'v' 13-point (spectral scenes).
    pub delta_uv_13pt_debiased: Option<f64>,
    /// Its standard error (jackknife).
    pub delta_uv_13pt_debiased_stderr: Option<f64>,
    /// Photons traced.
    pub photons: u64,
    /// Tracing time (s).
    pub seconds: f64,
}

impl std::fmt::Display for LayoutEvaluation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "objective {:.4} ± {:.4}  (cv {:.4} ± {:.4}, floor {:.4}; 13-pt {:.3} ± {:.3}; efficiency {:.4} ± {:.4}",
            self.objective,
            self.noise,
            self.cv_debiased,
            self.cv_debiased_stderr,
            self.noise_floor,
            self.thirteen_point,
            self.thirteen_point_stderr,
            self.efficiency,
            self.efficiency_stderr
        )?;
        if let (Some(d), Some(e)) = (
            self.delta_uv_13pt_debiased,
            self.delta_uv_13pt_debiased_stderr,
        ) {
            write!(f, "; Δu'v' 13-pt {d:.4} ± {e:.4}")?;
        }
        f.write_str(")")?;
        if self.below_noise_floor() {
            f.write_str("  [cv below its noise floor: trace more photons]")?;
        }
        if self.efficiency == 0.0 {
            f.write_str("  [no light on the target: infeasible]")?;
        }
        Ok(())
    }
}

impl LayoutEvaluation {
    /// True when the map's noise alone accounts for all of its cv: the debiased cv is
    /// clamped at 0 and says nothing about the design.
    pub fn below_noise_floor(&self) -> bool {
        self.cv_debiased == 0.0
    }
}
