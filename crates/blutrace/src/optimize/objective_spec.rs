//! `--objective`: what a search minimizes, a weighted sum of loss terms. Both searches read
//! it: the dot density's and `--vary`'s layouts.
//!
//! ```text
//! blutrace optimize SCENE --vary ... --objective cv                   # the default
//! blutrace optimize SCENE --vary ... --objective cv=1,efficiency=0.5  # a weighted mix
//! blutrace optimize SCENE --objective cv=1,delta-uv-13pt=20           # dots, in colour
//! ```
//!
//! Every term is a loss to minimize, dimensionless and 0 at its ideal:
//! - `cv`: the flux uniformity. For the dots, the cv of the profile along the pattern's
//!   axis ([`super::objective`]); with `--vary`, the debiased cv of the whole flux map.
//! - `thirteen-point` (`--vary` only): `1 - ` the 13-point min/max ratio.
//! - `efficiency` (`--vary` only): `1 - ` the extraction efficiency.
//! - `delta-uv-13pt` (spectral scenes): the colour non-uniformity, the largest Δu'v' of a
//!   13-point spot from the whole target's chromaticity with each spot's own noise removed
//!   (`summary.json`'s `color.delta_uv_13pt_debiased`; the raw largest of 13 noisy
//!   distances would reward noise). Display practice bounds Δu'v' at 0.02-0.03 (IDMS),
//!   about a tenth of a typical cv, so a weight of 10-20 makes the two terms count alike.
//!
//! The feedback method steers the flux profile strip by strip; it has no update for the
//! colour, so it takes only `cv`.

use super::Method;
use crate::scene::Scene;
use anyhow::{Result, bail};
use serde::Serialize;

/// One loss term of the objective.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Term {
    /// The flux cv: the profile's for the dots, the debiased map's with `--vary`.
    Cv,
    /// 1 - the 13-point min/max ratio.
    ThirteenPoint,
    /// 1 - the extraction efficiency.
    Efficiency,
    /// The largest Δu'v' of a 13-point spot from the target's chromaticity, debiased.
    DeltaUv13pt,
}

impl Term {
    const ALL: [Term; 4] = [
        Term::Cv,
        Term::ThirteenPoint,
        Term::Efficiency,
        Term::DeltaUv13pt,
    ];

    /// The term's name in `--objective`.
    pub fn name(self) -> &'static str {
        match self {
            Term::Cv => "cv",
            Term::ThirteenPoint => "thirteen-point",
            Term::Efficiency => "efficiency",
            Term::DeltaUv13pt => "delta-uv-13pt",
        }
    }

    /// The term's loss.
    fn loss(self, v: &TermValues) -> f64 {
        match self {
            Term::Cv => v.cv,
            Term::ThirteenPoint => 1.0 - v.thirteen_point,
            Term::Efficiency => 1.0 - v.efficiency,
            Term::DeltaUv13pt => v.delta_uv_13pt_debiased,
        }
    }
}

/// What the terms read from one traced design (or one leave-one-out of it); a term the
/// objective does not use may be NaN.
#[derive(Clone, Copy, Debug)]
pub struct TermValues {
    /// The flux cv (see [`Term::Cv`]).
    pub cv: f64,
    /// The 13-point min/max ratio.
    pub thirteen_point: f64,
    /// The extraction efficiency.
    pub efficiency: f64,
    /// The colour non-uniformity Δu'v' 13-point, debiased.
    pub delta_uv_13pt_debiased: f64,
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

    /// `cv`, `thirteen-point`, `efficiency`, `delta-uv-13pt`, or `NAME=WEIGHT,...`.
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
                    format!("'{name}': expected cv, thirteen-point, efficiency or delta-uv-13pt (as NAME or NAME=WEIGHT,...)")
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
    /// The objective's value.
    pub fn value(&self, v: &TermValues) -> f64 {
        self.terms.iter().map(|(t, w)| w * t.loss(v)).sum()
    }

    /// The weight of `term` (0 when the objective leaves it out).
    pub fn weight(&self, term: Term) -> f64 {
        self.terms
            .iter()
            .find(|(t, _)| *t == term)
            .map_or(0.0, |(_, w)| *w)
    }

    /// True when a term reads the target's colour.
    pub fn reads_color(&self) -> bool {
        self.weight(Term::DeltaUv13pt) > 0.0
    }

    /// Checks the objective against the scene and the search: a colour term needs a
    /// spectral scene; the dots search (`vary_search` false) takes `cv` and
    /// `delta-uv-13pt`, and its feedback method `cv` only.
    pub fn check(&self, scene: &Scene, vary_search: bool, method: Method) -> Result<()> {
        if self.reads_color() && !scene.sources.spectral() {
            bail!(
                "option `objective` delta-uv-13pt needs a spectral scene: the sources of {} give no `spectrum` (README: Colour)",
                scene.path.display()
            );
        }
        if vary_search {
            return Ok(());
        }
        if let Some((t, _)) = self
            .terms
            .iter()
            .find(|(t, _)| matches!(t, Term::ThirteenPoint | Term::Efficiency))
        {
            bail!(
                "option `objective` {} is for --vary searches; the dot density's objective takes cv and delta-uv-13pt",
                t.name()
            );
        }
        if method == Method::Feedback && self.reads_color() {
            bail!(
                "option `objective` delta-uv-13pt needs option `method` nelder-mead: the feedback method steers the flux profile and has no update for the colour"
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values() -> TermValues {
        TermValues {
            cv: 0.1,
            thirteen_point: 0.8,
            efficiency: 0.6,
            delta_uv_13pt_debiased: 0.004,
        }
    }

    #[test]
    fn objectives_parse_and_weigh_their_terms() {
        let o: ObjectiveSpec = "cv=2, efficiency=0.5".parse().unwrap();
        assert_eq!(o.terms, vec![(Term::Cv, 2.0), (Term::Efficiency, 0.5)]);
        assert_eq!(o.to_string(), "cv=2,efficiency=0.5");
        assert!((o.value(&values()) - (2.0 * 0.1 + 0.5 * 0.4)).abs() < 1e-15);
        let t: ObjectiveSpec = "thirteen-point".parse().unwrap();
        assert!((t.value(&values()) - 0.2).abs() < 1e-15);
        assert_eq!(ObjectiveSpec::default().to_string(), "cv");
        for bad in ["uniformity", "cv=0", "cv=-1", "cv=x", "cv,cv", "delta-uv"] {
            assert!(bad.parse::<ObjectiveSpec>().is_err(), "{bad}");
        }
    }

    #[test]
    fn the_colour_term_weighs_delta_uv() {
        let o: ObjectiveSpec = "cv=1,delta-uv-13pt=20".parse().unwrap();
        assert!(o.reads_color() && !ObjectiveSpec::default().reads_color());
        assert_eq!((o.weight(Term::Cv), o.weight(Term::Efficiency)), (1.0, 0.0));
        assert!((o.value(&values()) - (0.1 + 20.0 * 0.004)).abs() < 1e-15);
        assert_eq!(o.to_string(), "cv=1,delta-uv-13pt=20");
    }
}
