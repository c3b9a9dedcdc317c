//! From tallies to physical maps and scalar metrics, each with its standard error.
//!
//! Per-bin errors come from the per-photon sums of squares (photons are independent).
//! Scalar metrics that are non-linear in the map (cv, min/max, 9- and 13-point ratios)
//! get their errors from a delete-one-group jackknife over [`GROUPS`] interleaved photon
//! groups (chunk `c` belongs to group `c mod GROUPS`), so they too are independent of the
//! thread count.
//!
//! cv and min/max of a noisy map are biased by the noise itself. Beside cv we report its
//! noise floor, the cv a perfectly uniform source would show at this photon count
//! (`sqrt(mean(stderr^2)) / mean`), and the debiased `sqrt(cv^2 - floor^2)`.
//!
//! A map that no photon reached has no uniformity: its cv, debiased cv, noise floor and
//! ratios are NaN (`null` in summary.json), never the 0 of a perfectly uniform map, and
//! the optimizers rank such a design infeasible. So are the cv and min/max of a map of
//! one bin, and the 9- and 13-point ratios of a map with 2 bins along a side (their
//! spots all cover both, [`spots_apart`]): a map too coarse to measure them is not a
//! perfectly uniform one.

pub mod color;
pub mod cone;
mod jackknife;
pub mod stokes;

pub use jackknife::{
    BinSet, Estimates, ScoredBins, estimates, jackknife, jackknife_stderr, leave_one_out,
    with_errors,
};

use crate::scene::Scene;
use crate::tally::{BinStats, Grid, Tally};
use serde::Serialize;

/// Whether the 9- and 13-point spots (3x3 bins about the points at 1/6, 1/2 and 5/6 of
/// a side) tell a side of `n` bins apart: not on 2 bins, where every spot covers both
/// and hides the variation the map resolves (a side of 1 bin resolves none: a profile
/// map's ratio is the one along its other side).
pub fn spots_apart(n: usize) -> bool {
    n != 2
}

/// Number of interleaved photon groups kept for jackknife errors.
pub const GROUPS: usize = 32;

/// A value and its standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub stderr: f64,
}

/// A map of values with standard errors and photon counts, row-major (x fastest).
#[derive(Clone, Debug)]
pub struct Map {
    /// Bins along x.
    pub nx: usize,
    /// Bins along y.
    pub ny: usize,
    /// Value per bin.
    pub value: Vec<f64>,
    /// Standard error per bin.
    pub stderr: Vec<f64>,
    /// Photons scored per bin.
    pub hits: Vec<u64>,
}

/// Target-plane irradiance (W/mm^2) per bin.
pub fn flux_map(scene: &Scene, t: &Tally) -> Map {
    let area = scene.detector.bin_area();
    grid_map(scene, t, &t.flux, |_| area)
}

/// Radiant intensity (W/sr) per (theta, phi) bin; x = phi, y = theta.
pub fn angular_map(scene: &Scene, t: &Tally) -> Map {
    let g = &t.angular;
    phi_fastest(grid_map(scene, t, g, |i| {
        scene.detector.angular_bin_solid_angle(i % g.nx)
    }))
}

/// The angular grid luminance is read from, and lumens per watt of its weights: in a
/// spectral scene the Y tally (683 lm/W times ȳ at each photon's wavelength, so the
/// colour shifts along the way count), else the radiant weights times the sources' given
/// efficacy (`None` without lumens).
fn luminous_grid<'t>(scene: &Scene, t: &'t Tally) -> Option<(&'t Grid, f64)> {
    match &t.color {
        Some(c) => Some((&c.angular[1], crate::color::KM_LM_PER_W)),
        None => Some((&t.angular, scene.sources.luminous_efficacy()?)),
    }
}

/// Luminance (cd/m^2) averaged over the target, per (theta, phi) bin; x = phi, y = theta.
/// Needs the sources' lumens or spectra; `None` otherwise. L = K P / (A * projected solid
/// angle).
pub fn luminance_map(scene: &Scene, t: &Tally) -> Option<Map> {
    let (g, efficacy) = luminous_grid(scene, t)?;
    let d = &scene.detector;
    let area_m2 = d.area_m2();
    let m = grid_map(scene, t, g, |i| {
        d.angular_bin_projected_solid_angle(i % g.nx) * area_m2 / efficacy
    });
    Some(phi_fastest(m))
}

/// Luminance (cd/m^2) per theta row, averaged over phi: (theta centre in degrees, value,
/// standard error). Each photon lands in one bin, so row sums of squares are exact.
pub fn luminance_by_theta(scene: &Scene, t: &Tally) -> Option<Vec<[f64; 3]>> {
    let (g, efficacy) = luminous_grid(scene, t)?;
    let d = &scene.detector;
    let area_m2 = d.area_m2();
    let (nt, np) = (g.nx, g.ny);
    let watts = scene.sources.total_power();
    let rows = (0..nt).map(|it| {
        let mut row = crate::tally::BinStats::default();
        (0..np).for_each(|ip| row.merge(&g.bins[ip * nt + it]));
        let (mean, se) = row.mean_and_stderr(t.ledger.photons);
        let k = watts * efficacy / (area_m2 * d.angular_bin_projected_solid_angle(it) * np as f64);
        [d.theta_centre_deg(it), mean * k, se * k]
    });
    Some(rows.collect())
}

/// Re-order a (theta fastest) angular grid map so that phi runs fastest.
fn phi_fastest(by_theta: Map) -> Map {
    let (nt, np) = (by_theta.nx, by_theta.ny);
    let mut m = Map {
        nx: np,
        ny: nt,
        value: vec![0.0; nt * np],
        stderr: vec![0.0; nt * np],
        hits: vec![0; nt * np],
    };
    for ip in 0..np {
        for it in 0..nt {
            let (src, dst) = (ip * nt + it, it * np + ip);
            m.value[dst] = by_theta.value[src];
            m.stderr[dst] = by_theta.stderr[src];
            m.hits[dst] = by_theta.hits[src];
        }
    }
    m
}

fn grid_map(scene: &Scene, t: &Tally, g: &Grid, measure: impl Fn(usize) -> f64) -> Map {
    let n = t.ledger.photons;
    let total = scene.sources.total_power();
    let mut m = Map {
        nx: g.nx,
        ny: g.ny,
        value: Vec::new(),
        stderr: Vec::new(),
        hits: Vec::new(),
    };
    for (i, b) in g.bins.iter().enumerate() {
        let (value, stderr) = bin_value(b, n, total / measure(i));
        m.value.push(value);
        m.stderr.push(stderr);
        m.hits.push(b.hits);
    }
    m
}

/// A bin's value and standard error over `n` photons, times `k` (watts per unit photon
/// weight, over the bin's measure). Every map and every leave-one-out map reads its bins
/// through this one function, so equal sums give equal bits.
fn bin_value(b: &BinStats, n: u64, k: f64) -> (f64, f64) {
    let (mean, se) = b.mean_and_stderr(n);
    (mean * k, se * k)
}

/// Uniformity metrics of a flux map.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Uniformity {
    /// Mean irradiance over all bins (W/mm^2).
    pub mean: f64,
    /// RMS deviation over mean.
    pub cv: f64,
    /// Smallest bin over largest bin.
    pub min_over_max: f64,
    /// Min over max of the 9 standard points (3x3-bin spots at 1/6, 1/2, 5/6 of each side).
    pub nine_point_min_over_max: f64,
    /// As nine-point, plus the 4 points at 1/4 and 3/4 of each side.
    pub thirteen_point_min_over_max: f64,
}

impl Uniformity {
    /// Metrics of `m`'s values.
    pub fn of(m: &Map) -> Self {
        Self::of_values(m.nx, m.ny, &m.value, &MapSums::of(&m.value, &m.stderr))
    }

    /// Metrics of the values `v` of an `nx` x `ny` map (row-major, x fastest) whose sums
    /// are `sums`.
    fn of_values(nx: usize, ny: usize, v: &[f64], sums: &MapSums) -> Self {
        let n = v.len() as f64;
        let mean = sums.value / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        let points = thirteen_points();
        let spot =
            |pts: &[(f64, f64)]| min_over_max(pts.iter().map(|&(x, y)| spot_mean(nx, ny, v, x, y)));
        // A map of one bin has no spread to measure, and the 3x3-bin spots about the
        // points at 1/6, 1/2 and 5/6 of a side of 2 bins all cover both: those metrics
        // are NaN there, never the 0 or 1 of a perfectly uniform map.
        let spread = v.len() > 1;
        let spots = spread && spots_apart(nx) && spots_apart(ny);
        let nine_point = if spots { spot(&points[..9]) } else { f64::NAN };
        Uniformity {
            mean,
            cv: if mean > 0.0 && spread {
                var.sqrt() / mean
            } else {
                f64::NAN
            },
            min_over_max: if spread {
                ratio(sums.lo, sums.hi)
            } else {
                f64::NAN
            },
            nine_point_min_over_max: nine_point,
            thirteen_point_min_over_max: if spots { spot(&points) } else { f64::NAN },
        }
    }
}

/// The sums and extremes over a map that the metrics read, taken in one pass over the
/// bins (the metrics of every leave-one-out map read them). Each sum runs in bin order
/// from -0.0, as `Iterator::sum` does, so each equals its plain expression bit for bit.
struct MapSums {
    /// Sum of the values.
    value: f64,
    /// Sum of the squared standard errors.
    stderr_sq: f64,
    /// Smallest and largest value (from +inf and 0).
    lo: f64,
    hi: f64,
    /// Sum of stderr / value over the lit bins (value > 0), and their number.
    rel: f64,
    lit: usize,
}

impl MapSums {
    fn of(value: &[f64], stderr: &[f64]) -> Self {
        let mut s = MapSums {
            value: -0.0,
            stderr_sq: -0.0,
            lo: f64::INFINITY,
            hi: 0.0,
            rel: -0.0,
            lit: 0,
        };
        for (&v, &e) in value.iter().zip(stderr) {
            s.value += v;
            s.stderr_sq += e * e;
            // `f64::min`/`max` as plain selects (twice as fast a loop): the same
            // result for any `v`, NaN included, as values are never -0.0.
            s.lo = if v < s.lo { v } else { s.lo };
            s.hi = if v > s.hi { v } else { s.hi };
            if v > 0.0 {
                s.rel += e / v;
                s.lit += 1;
            }
        }
        s
    }
}

fn min_over_max(values: impl Iterator<Item = f64>) -> f64 {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    ratio(lo, hi)
}

/// Smallest over largest (NaN when nothing is lit).
fn ratio(lo: f64, hi: f64) -> f64 {
    if hi > 0.0 { lo / hi } else { f64::NAN }
}

/// The 13 standard points as fractions of the map's sides: the 9 at 1/6, 1/2 and 5/6 of
/// each side (y slowest), then the 4 at 1/4 and 3/4.
pub fn thirteen_points() -> [(f64, f64); 13] {
    let nine = [1.0 / 6.0, 0.5, 5.0 / 6.0];
    let mut p = [(0.0, 0.0); 13];
    for (i, &y) in nine.iter().enumerate() {
        for (j, &x) in nine.iter().enumerate() {
            p[3 * i + j] = (x, y);
        }
    }
    p[9..].copy_from_slice(&[(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]);
    p
}

/// Mean of the 3x3 bins around the fractional position (fx, fy) of an `nx` x `ny` map.
fn spot_mean(nx: usize, ny: usize, v: &[f64], fx: f64, fy: f64) -> f64 {
    let cx = ((fx * nx as f64) as usize).min(nx - 1);
    let cy = ((fy * ny as f64) as usize).min(ny - 1);
    let (mut sum, mut n) = (0.0, 0);
    for y in cy.saturating_sub(1)..=(cy + 1).min(ny - 1) {
        for x in cx.saturating_sub(1)..=(cx + 1).min(nx - 1) {
            sum += v[y * nx + x];
            n += 1;
        }
    }
    sum / n as f64
}

/// The scalar results of a run.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Metrics {
    /// Flux-map uniformity.
    pub uniformity: Uniformity,
    /// Detected over emitted power.
    pub extraction_efficiency: f64,
    /// The cv a perfectly uniform source would show at this photon count.
    pub cv_noise_floor: f64,
    /// `sqrt(max(cv^2 - floor^2, 0))`: cv with the noise's own contribution removed.
    pub cv_debiased: f64,
    /// Mean over lit bins of stderr / flux.
    pub mean_rel_stderr: f64,
}

impl Metrics {
    /// Point estimates from a tally.
    pub fn of(scene: &Scene, t: &Tally) -> Self {
        let m = flux_map(scene, t);
        let (eff, _) = t.ledger.detected.mean_and_stderr(t.ledger.photons);
        Self::of_flux(m.nx, m.ny, &m.value, &m.stderr, eff)
    }

    /// Point estimates from a flux map's values and errors and the efficiency.
    fn of_flux(nx: usize, ny: usize, value: &[f64], stderr: &[f64], eff: f64) -> Self {
        let sums = MapSums::of(value, stderr);
        let u = Uniformity::of_values(nx, ny, value, &sums);
        let floor = (sums.stderr_sq / stderr.len() as f64).sqrt() / u.mean;
        Metrics {
            uniformity: u,
            extraction_efficiency: eff,
            cv_noise_floor: floor,
            cv_debiased: debiased(u.cv, floor),
            mean_rel_stderr: if sums.lit == 0 {
                f64::NAN
            } else {
                sums.rel / sums.lit as f64
            },
        }
    }

    /// Whether any light reached the map: without it there is no uniformity (the cv and
    /// the ratios are NaN).
    pub fn has_light(&self) -> bool {
        self.uniformity.mean > 0.0
    }

    /// Every [`Metric`]'s value.
    pub fn values(&self) -> MetricValues {
        let u = &self.uniformity;
        MetricValues::from_fn(|m| match m {
            Metric::Mean => u.mean,
            Metric::Efficiency => self.extraction_efficiency,
            Metric::Cv => u.cv,
            Metric::CvDebiased => self.cv_debiased,
            Metric::MinOverMax => u.min_over_max,
            Metric::NinePoint => u.nine_point_min_over_max,
            Metric::ThirteenPoint => u.thirteen_point_min_over_max,
            Metric::MeanRelStderr => self.mean_rel_stderr,
        })
    }
}

/// `sqrt(max(x^2 - floor^2, 0))`: a noisy metric `x` with its noise floor removed in
/// quadrature. NaN when either is NaN (a map without light has neither), not the 0 that
/// `f64::max` would make of it.
pub fn debiased(x: f64, floor: f64) -> f64 {
    let d = x * x - floor * floor;
    if d.is_nan() {
        f64::NAN
    } else {
        d.max(0.0).sqrt()
    }
}

/// The scalar metrics of a run, in their fixed order (of the CSV columns).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metric {
    /// Mean irradiance over the target (W/mm^2).
    Mean,
    /// Detected over emitted power.
    Efficiency,
    /// RMS deviation over mean of the flux map.
    Cv,
    /// cv with the noise floor removed in quadrature.
    CvDebiased,
    /// Smallest bin over largest bin.
    MinOverMax,
    /// 9-point min/max.
    NinePoint,
    /// 13-point min/max.
    ThirteenPoint,
    /// Mean over lit bins of stderr / flux (itself an error: it has no error of its own).
    MeanRelStderr,
}

impl Metric {
    /// Every metric, in order.
    pub const ALL: [Metric; 8] = [
        Metric::Mean,
        Metric::Efficiency,
        Metric::Cv,
        Metric::CvDebiased,
        Metric::MinOverMax,
        Metric::NinePoint,
        Metric::ThirteenPoint,
        Metric::MeanRelStderr,
    ];

    /// The metric's name (its CSV column).
    pub fn name(self) -> &'static str {
        match self {
            Metric::Mean => "mean",
            Metric::Efficiency => "efficiency",
            Metric::Cv => "cv",
            Metric::CvDebiased => "cv_debiased",
            Metric::MinOverMax => "min_over_max",
            Metric::NinePoint => "nine_point",
            Metric::ThirteenPoint => "thirteen_point",
            Metric::MeanRelStderr => "mean_rel_stderr",
        }
    }
}

/// One number per [`Metric`] (values, or their standard errors), indexed by metric.
/// Serialized as an array in [`Metric::ALL`] order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MetricValues([f64; Metric::ALL.len()]);

impl MetricValues {
    /// `f(metric)` for every metric.
    pub fn from_fn(f: impl FnMut(Metric) -> f64) -> Self {
        MetricValues(Metric::ALL.map(f))
    }

    /// The same number for every metric.
    pub fn splat(x: f64) -> Self {
        MetricValues([x; Metric::ALL.len()])
    }

    /// `(metric, number)` in [`Metric::ALL`] order.
    pub fn iter(&self) -> impl Iterator<Item = (Metric, f64)> + '_ {
        Metric::ALL.into_iter().zip(self.0)
    }
}

impl std::ops::Index<Metric> for MetricValues {
    type Output = f64;

    fn index(&self, m: Metric) -> &f64 {
        &self.0[m as usize]
    }
}

impl std::ops::IndexMut<Metric> for MetricValues {
    fn index_mut(&mut self, m: Metric) -> &mut f64 {
        &mut self.0[m as usize]
    }
}

/// The median of `values` (NaN when empty).
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    match values.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => values[n / 2],
        n => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// A flux map's values and errors, without hit counts: what the scalar metrics read.
#[derive(Clone, Default)]
struct FluxValues {
    nx: usize,
    ny: usize,
    value: Vec<f64>,
    stderr: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(nx: usize, ny: usize, value: Vec<f64>) -> Map {
        let n = value.len();
        Map {
            nx,
            ny,
            stderr: vec![0.0; n],
            hits: vec![1; n],
            value,
        }
    }

    /// A map too coarse to measure a metric gives no value (NaN), never the 1 or 0 of a
    /// perfectly uniform map: the 9- and 13-point spots of a 2 x 2 map all cover the
    /// whole map, and one bin has no spread.
    #[test]
    fn coarse_maps_measure_no_uniformity_they_cannot_see() {
        let u = Uniformity::of(&map(2, 2, vec![1.0, 3.0, 1.0, 3.0]));
        assert!((u.min_over_max - 1.0 / 3.0).abs() < 1e-12, "{u:?}");
        assert!(u.cv > 0.0, "{u:?}");
        assert!(u.nine_point_min_over_max.is_nan(), "{u:?}");
        assert!(u.thirteen_point_min_over_max.is_nan(), "{u:?}");
        let strips = Uniformity::of(&map(2, 4, [1.0, 3.0].repeat(4)));
        assert!(strips.nine_point_min_over_max.is_nan(), "{strips:?}");

        let one = Uniformity::of(&map(1, 1, vec![2.0]));
        assert_eq!(one.mean, 2.0);
        assert!(one.cv.is_nan() && one.min_over_max.is_nan(), "{one:?}");
        assert!(one.nine_point_min_over_max.is_nan(), "{one:?}");

        // A profile map (one bin across) keeps its ratio along the other side.
        let profile = Uniformity::of(&map(20, 1, (1..=20).map(f64::from).collect()));
        assert!(profile.nine_point_min_over_max > 0.0, "{profile:?}");
        let fine = Uniformity::of(&map(3, 3, vec![1.0; 9]));
        assert_eq!(fine.nine_point_min_over_max, 1.0);
        assert_eq!(fine.cv, 0.0);
    }
}
