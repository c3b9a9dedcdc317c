//! The objective: non-uniformity of the flux profile along the propagation axis, from one
//! fixed-seed trace, with its own Monte Carlo noise.
//!
//! ```text
//! blutrace optimize SCENE --photons 1000000 --seed 1 [--edge-margin-mm 0]
//! ```
//!
//! The flux map's bins are grouped into strips across the propagation axis (by where each
//! bin's centre projects on the dot pattern's `axis`): a strip's value is the mean of its
//! bins, so it averages out the noise across the axis, which the density `d(x)` cannot
//! change anyway. The objective is the coefficient of variation (RMS deviation over mean)
//! of the strip values. Its standard error follows from the bins' standard errors by the
//! delta method; the *noise floor* is the cv a perfectly uniform profile would show from
//! noise alone. Every evaluation of one optimization uses the same seed (common random
//! numbers), so two designs are compared on the same photon histories.
//!
//! With `--objective cv=W1,delta-uv-13pt=W2` ([`ObjectiveSpec`]) in a spectral scene the
//! objective is `W1 cv + W2 Δu'v'_13pt`, the colour non-uniformity with its jackknife
//! error; the two errors add in quadrature (the profile cv's error is the delta method's,
//! which has no leave-one-out values to pair with the colour's).

use super::objective_spec::{ObjectiveSpec, Term, TermValues};
use crate::optics::dots::DotPattern;
use crate::run::metrics::color::Estimate;
use crate::run::metrics::{Map, Uniformity, median};
use crate::scene::Scene;
use serde::Serialize;

/// The flux profile along the dot pattern's axis.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Profile {
    /// Strip centres: distance (mm) from the pattern origin along its axis.
    pub u: Vec<f64>,
    /// Mean irradiance of each strip (W/mm^2).
    pub value: Vec<f64>,
    /// Standard error of each strip's value.
    pub stderr: Vec<f64>,
    /// Whether a strip holds any bin.
    pub populated: Vec<bool>,
    /// Whether a strip enters the objective (holds bins and lies outside the margins).
    pub used: Vec<bool>,
}

/// For every bin of a `nx` x `ny` map of `scene`'s detector: the strip (of `strips` over
/// `[0, length]` along `pattern`'s axis) holding the bin's centre, if any.
fn strip_of_bins(
    scene: &Scene,
    pattern: &DotPattern,
    nx: usize,
    ny: usize,
    strips: usize,
) -> Vec<Option<usize>> {
    let strips = strips.max(1);
    let d = &scene.detector;
    let width = pattern.grade.length / strips as f64;
    let mut out = Vec::with_capacity(nx * ny);
    for iy in 0..ny {
        for ix in 0..nx {
            let centre = d.grid_centre([nx, ny], ix, iy);
            let u = (centre - pattern.origin).dot(pattern.axis);
            out.push(
                (0.0..pattern.grade.length)
                    .contains(&u)
                    .then(|| ((u / width) as usize).min(strips - 1)),
            );
        }
    }
    out
}

/// cv (RMS deviation over mean) of `values`, its standard error by the delta method from
/// the values' independent standard errors, and the noise floor `sqrt(mean(se^2)) / mean`.
pub fn cv_with_noise(values: &[f64], stderr: &[f64]) -> (f64, f64, f64) {
    let k = values.len() as f64;
    let mean = values.iter().sum::<f64>() / k;
    if values.is_empty() || mean <= 0.0 || !mean.is_finite() {
        return (f64::INFINITY, f64::NAN, f64::NAN);
    }
    let sd = (values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / k).sqrt();
    let cv = sd / mean;
    // d cv / d p_j = ((p_j - mean) / (k sd) - cv / k) / mean
    let se = values
        .iter()
        .zip(stderr)
        .map(|(x, e)| {
            let slope = if sd > 0.0 { (x - mean) / (k * sd) } else { 0.0 };
            ((slope - cv / k) / mean * e).powi(2)
        })
        .sum::<f64>()
        .sqrt();
    let floor = (stderr.iter().map(|e| e * e).sum::<f64>() / k).sqrt() / mean;
    (cv, se, floor)
}

impl Profile {
    /// Group `map`'s bins (of `scene`'s detector) into `strips` strips along `pattern`'s
    /// axis over `[0, length]`; strips within `margin` mm of either end are kept but
    /// marked unused.
    pub fn of(scene: &Scene, pattern: &DotPattern, map: &Map, strips: usize, margin: f64) -> Self {
        let strips = strips.max(1);
        let width = pattern.grade.length / strips as f64;
        let mut sum = vec![0.0; strips];
        let mut var = vec![0.0; strips];
        let mut count = vec![0usize; strips];
        for (i, k) in strip_of_bins(scene, pattern, map.nx, map.ny, strips)
            .into_iter()
            .enumerate()
        {
            if let Some(k) = k {
                sum[k] += map.value[i];
                var[k] += map.stderr[i] * map.stderr[i];
                count[k] += 1;
            }
        }
        let mut p = Profile::default();
        for k in 0..strips {
            let u = (k as f64 + 0.5) * width;
            let n = count[k].max(1) as f64;
            p.u.push(u);
            p.value.push(sum[k] / n);
            p.stderr.push(var[k].sqrt() / n);
            p.populated.push(count[k] > 0);
            p.used
                .push(count[k] > 0 && u >= margin && u <= pattern.grade.length - margin);
        }
        p
    }

    /// The used strips' (value, stderr).
    fn used_values(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.value
            .iter()
            .zip(&self.stderr)
            .zip(&self.used)
            .filter(|(_, u)| **u)
            .map(|((v, s), _)| (*v, *s))
    }

    /// cv of the used strips, its standard error (delta method) and the noise floor.
    pub fn cv(&self) -> (f64, f64, f64) {
        let (v, s): (Vec<f64>, Vec<f64>) = self.used_values().unzip();
        cv_with_noise(&v, &s)
    }

    /// Median of the used strips' values.
    pub fn median(&self) -> f64 {
        median(self.used_values().map(|(v, _)| v).collect())
    }
}

/// One evaluated design.
#[derive(Clone, Debug, Serialize)]
pub struct Evaluation {
    /// The objective: the `--objective`'s weighted terms (by default the profile cv).
    pub objective: f64,
    /// Its standard error (1 sigma).
    pub noise: f64,
    /// The cv that noise alone would give a perfectly uniform profile.
    pub noise_floor: f64,
    /// cv of the profile's used strips.
    pub cv: f64,
    /// Its standard error (from the bins' standard errors).
    pub cv_noise: f64,
    /// Colour non-uniformity Δu'v' 13-point with its jackknife error (spectral scenes).
    pub delta_uv_13pt_debiased: Option<Estimate>,
    /// The profile along the propagation axis.
    pub profile: Profile,
    /// Uniformity metrics of the whole flux map (point estimates).
    pub uniformity: Uniformity,
    /// cv of the map's bins over the used strips (the whole map without the margins).
    pub area_cv: f64,
    /// Its standard error.
    pub area_cv_noise: f64,
    /// The area cv that noise alone would give.
    pub area_noise_floor: f64,
    /// Photons traced.
    pub photons: u64,
    /// Tracing time (s).
    pub seconds: f64,
    /// The traced flux map (for the 2-D feedback).
    #[serde(skip)]
    pub map: Map,
}

/// What a dots evaluation reads from a trace.
pub struct Traced {
    /// The flux map.
    pub map: Map,
    /// Δu'v' 13-point with its error (spectral scenes).
    pub delta_uv_13pt_debiased: Option<Estimate>,
    /// Photons traced.
    pub photons: u64,
    /// Tracing time (s).
    pub seconds: f64,
}

/// What the dots search judges by: the objective and its strips.
pub struct Judging<'a> {
    /// The `--objective`.
    pub spec: &'a ObjectiveSpec,
    /// Profile strips along the pattern's axis.
    pub strips: usize,
    /// mm at either end of the span left out.
    pub margin: f64,
}

impl Evaluation {
    /// Evaluate a trace of `scene` (whose dots are `pattern`).
    pub fn of(scene: &Scene, pattern: &DotPattern, traced: Traced, judging: &Judging) -> Self {
        let Traced {
            map,
            delta_uv_13pt_debiased,
            photons,
            seconds,
        } = traced;
        let (strips, margin) = (judging.strips, judging.margin);
        let profile = Profile::of(scene, pattern, &map, strips, margin);
        let (cv, cv_noise, noise_floor) = profile.cv();
        let spec = judging.spec;
        let duv = delta_uv_13pt_debiased.map_or(f64::NAN, |d| d.value);
        let objective = spec.value(&TermValues {
            cv,
            thirteen_point: f64::NAN,
            efficiency: f64::NAN,
            delta_uv_13pt_debiased: duv,
        });
        let duv_se = delta_uv_13pt_debiased.map_or(0.0, |d| d.stderr);
        let noise =
            (spec.weight(Term::Cv) * cv_noise).hypot(spec.weight(Term::DeltaUv13pt) * duv_se);
        let (mut v, mut e) = (Vec::new(), Vec::new());
        for (i, k) in strip_of_bins(scene, pattern, map.nx, map.ny, strips)
            .into_iter()
            .enumerate()
        {
            if k.is_some_and(|k| profile.used[k]) {
                v.push(map.value[i]);
                e.push(map.stderr[i]);
            }
        }
        let (area_cv, area_cv_noise, area_noise_floor) = cv_with_noise(&v, &e);
        Evaluation {
            objective,
            noise,
            noise_floor,
            cv,
            cv_noise,
            delta_uv_13pt_debiased,
            profile,
            uniformity: Uniformity::of(&map),
            area_cv,
            area_cv_noise,
            area_noise_floor,
            photons,
            seconds,
            map,
        }
    }
}

/// Strips to use by default: the detector's bins along the direction closer to `axis`.
pub fn default_strips(scene: &Scene, pattern: &DotPattern) -> usize {
    scene.detector.bins_along(pattern.axis)
}
