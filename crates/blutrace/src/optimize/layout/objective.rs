//! The layout search's objective: a weighted sum of losses of the whole flux map and the
//! ledger, from one fixed-seed trace, with its jackknife standard error.
//!
//! ```text
//! blutrace optimize SCENE --vary ... --objective cv                   # the default
//! blutrace optimize SCENE --vary ... --objective thirteen-point
//! blutrace optimize SCENE --vary ... --objective cv=1,efficiency=0.5  # a weighted mix
//! ```
//!
//! Every term is a loss to minimize, dimensionless and 0 at its ideal:
//! - `cv`: the area uniformity, the debiased cv of the flux map
//!   `sqrt(max(cv^2 - floor^2, 0))` (the map's own Monte Carlo noise removed, so designs
//!   traced with few photons are compared on their uniformity, not on their noise);
//! - `thirteen-point`: `1 - ` the 13-point min/max ratio;
//! - `efficiency`: `1 - ` the extraction efficiency (detected over emitted power).
//!
//! The objective's standard error is the jackknife over the run's photon groups of the
//! whole weighted sum, so the terms' correlations are in it. Its *noise floor* is the cv a
//! perfectly uniform map would show at the search's photons, as for the dots objective.

use crate::run::RunResult;
use crate::run::metrics::{Metric, MetricValues, Metrics, jackknife_stderr};
use serde::Serialize;

/// One loss term of the objective.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Term {
    /// Debiased cv of the flux map.
    Cv,
    /// 1 - the 13-point min/max ratio.
    ThirteenPoint,
    /// 1 - the extraction efficiency.
    Efficiency,
}

impl Term {
    const ALL: [Term; 3] = [Term::Cv, Term::ThirteenPoint, Term::Efficiency];

    fn name(self) -> &'static str {
        match self {
            Term::Cv => "cv",
            Term::ThirteenPoint => "thirteen-point",
            Term::Efficiency => "efficiency",
        }
    }

    /// The term's loss from a run's metrics.
    fn loss(self, m: &MetricValues) -> f64 {
        match self {
            Term::Cv => m[Metric::CvDebiased],
            Term::ThirteenPoint => 1.0 - m[Metric::ThirteenPoint],
            Term::Efficiency => 1.0 - m[Metric::Efficiency],
        }
    }
}

/// `--objective`: weighted loss terms.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjectiveSpec {
    /// The terms and their weights.
    pub terms: Vec<(Term, f64)>,
}

impl Default for ObjectiveSpec {
    fn default() -> Self {
        ObjectiveSpec {
            terms: vec![(Term::Cv, 1.0)],
        }
    }
}

impl std::fmt::Display for ObjectiveSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t: Vec<String> = self
            .terms
            .iter()
            .map(|(t, w)| match self.terms.len() {
                1 if *w == 1.0 => t.name().to_string(),
                _ => format!("{}={w}", t.name()),
            })
            .collect();
        f.write_str(&t.join(","))
    }
}

impl std::str::FromStr for ObjectiveSpec {
    type Err = String;

    /// `cv`, `thirteen-point`, `efficiency`, or `NAME=WEIGHT,...`.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut terms = Vec::new();
        for part in s.split(',').map(str::trim) {
            let (name, weight) = match part.split_once('=') {
                Some((n, w)) => (n.trim(), w.trim()),
                None => (part, "1"),
            };
            let term = Term::ALL
                .into_iter()
                .find(|t| t.name() == name)
                .ok_or_else(|| {
                    format!("'{name}': expected cv, thirteen-point or efficiency (as NAME or NAME=WEIGHT,...)")
                })?;
            let w: f64 = weight
                .parse()
                .ok()
                .filter(|w: &f64| w.is_finite() && *w > 0.0)
                .ok_or_else(|| {
                    format!("{name}: the weight must be a number > 0, got '{weight}'")
                })?;
            if terms.iter().any(|(t, _)| *t == term) {
                return Err(format!("{name} is given twice"));
            }
            terms.push((term, w));
        }
        Ok(ObjectiveSpec { terms })
    }
}

impl ObjectiveSpec {
    /// The objective's value for a run's metrics.
    pub fn value(&self, m: &MetricValues) -> f64 {
        self.terms.iter().map(|(t, w)| w * t.loss(m)).sum()
    }

    /// Evaluate a finished trace.
    pub fn evaluate(&self, run: &RunResult) -> LayoutEvaluation {
        let metrics = Metrics::of(&run.scene, &run.tally);
        let values = metrics.values();
        let leave_out = &run.leave_out;
        let se = |f: &dyn Fn(&MetricValues) -> f64| {
            jackknife_stderr(&leave_out.iter().map(f).collect::<Vec<_>>())
        };
        let l = &run.tally.ledger;
        LayoutEvaluation {
            objective: self.value(&values),
            noise: se(&|m| self.value(m)),
            noise_floor: metrics.cv_noise_floor,
            cv_debiased: values[Metric::CvDebiased],
            cv_debiased_stderr: se(&|m| m[Metric::CvDebiased]),
            thirteen_point: values[Metric::ThirteenPoint],
            thirteen_point_stderr: se(&|m| m[Metric::ThirteenPoint]),
            efficiency: values[Metric::Efficiency],
            efficiency_stderr: l.detected.mean_and_stderr(l.photons).1,
            photons: l.photons,
            seconds: run.runtime_s,
        }
    }
}

/// One traced design, judged.
#[derive(Clone, Debug, Serialize)]
pub struct LayoutEvaluation {
    /// The objective (to minimize).
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
    /// Photons traced.
    pub photons: u64,
    /// Tracing time (s).
    pub seconds: f64,
}

impl std::fmt::Display for LayoutEvaluation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "objective {:.4} ± {:.4}  (cv {:.4} ± {:.4}, floor {:.4}; 13-pt {:.3} ± {:.3}; efficiency {:.4} ± {:.4})",
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
        if self.below_noise_floor() {
            f.write_str("  [cv below its noise floor: trace more photons]")?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objectives_parse_and_weigh_their_terms() {
        let o: ObjectiveSpec = "cv=2, efficiency=0.5".parse().unwrap();
        assert_eq!(o.terms, vec![(Term::Cv, 2.0), (Term::Efficiency, 0.5)]);
        assert_eq!(o.to_string(), "cv=2,efficiency=0.5");
        let m = MetricValues::from_fn(|m| match m {
            Metric::CvDebiased => 0.1,
            Metric::ThirteenPoint => 0.8,
            Metric::Efficiency => 0.6,
            _ => f64::NAN,
        });
        assert!((o.value(&m) - (2.0 * 0.1 + 0.5 * 0.4)).abs() < 1e-15);
        let t: ObjectiveSpec = "thirteen-point".parse().unwrap();
        assert!((t.value(&m) - 0.2).abs() < 1e-15);
        assert_eq!(ObjectiveSpec::default().to_string(), "cv");
        for bad in ["uniformity", "cv=0", "cv=-1", "cv=x", "cv,cv"] {
            assert!(bad.parse::<ObjectiveSpec>().is_err(), "{bad}");
        }
    }
}
