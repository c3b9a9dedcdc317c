//! The luminance map: cd/m² per target bin of the light leaving it within the detector's
//! luminance cone (`detector.luminance_cone_deg`, see [`crate::detector`]), as a
//! luminance meter aimed at the panel reads it, and its uniformity as a display lab
//! measures it (on luminance, not irradiance), with jackknife errors.
//!
//! ```toml
//! [detector]
//! luminance_cone_deg = 2.0   # the default
//! ```
//!
//! `L = K P_cone / (A_bin pi sin^2(c))`: the luminous power within the cone over the bin's
//! area and the cone's projected solid angle. `K P` is the Y tally's 683 lm/W times ȳ at
//! each photon's wavelength in a spectral run, else the radiant power times the sources'
//! given efficacy. For light whose luminance is constant within the cone (a diffuse
//! panel near the normal) this is the luminance on the axis; a cone of the first theta
//! row's width holds exactly the photons of that row, so the map's mean is then the
//! angular output's on-axis luminance.

use super::{Estimate, Map, Metric, Metrics, bin_value, jackknife_stderr};
use crate::color::KM_LM_PER_W;
use crate::scene::Scene;
use crate::tally::{Grid, Sign, Tally};
use serde::Serialize;

/// The meter's grid of view `k` in `t` and the lumens per unit of its weight (`None`:
/// no lumens or spectra).
fn cone_grid<'t>(scene: &Scene, t: &'t Tally, k: usize) -> Option<(&'t Grid, f64)> {
    let g = t.meter.as_ref()?.luminous(k);
    let efficacy = match &t.color {
        Some(_) => KM_LM_PER_W,
        None => scene.sources.luminous_efficacy()?,
    };
    Some((g, efficacy))
}

/// The luminance map of view `k`'s `grid` over `photons` photons (cd/m² per bin).
fn map_of(scene: &Scene, grid: &Grid, photons: u64, efficacy: f64, k: usize) -> Map {
    let d = &scene.detector;
    let per_bin = d.bin_area() * 1e-6 * d.cone_projected_solid_angle(k);
    let k = scene.sources.total_power() * efficacy / per_bin;
    let mut m = Map {
        nx: grid.nx,
        ny: grid.ny,
        value: Vec::with_capacity(grid.bins.len()),
        stderr: Vec::with_capacity(grid.bins.len()),
        hits: Vec::with_capacity(grid.bins.len()),
    };
    for b in &grid.bins {
        let (v, e) = bin_value(b, photons, k);
        m.value.push(v);
        m.stderr.push(e);
        m.hits.push(b.hits);
    }
    m
}

/// The luminance map of view `k` (cd/m² per bin), or `None` without lumens or spectra.
pub fn luminance_cone_map(scene: &Scene, t: &Tally, k: usize) -> Option<Map> {
    let (g, efficacy) = cone_grid(scene, t, k)?;
    Some(map_of(scene, g, t.ledger.photons, efficacy, k))
}

/// X, Y, Z maps of view `k` on the luminance map's scale (Y in cd/m²), in a spectral
/// run with a luminance map.
pub fn view_xyz_maps(scene: &Scene, t: &Tally, k: usize) -> Option<[Map; 3]> {
    let grids = t.meter.as_ref()?.xyz(k)?;
    let n = t.ledger.photons;
    Some(grids.map(|g| map_of(scene, g, n, KM_LM_PER_W, k)))
}

/// The chromaticity u', v' of view `k`'s whole map, with jackknife errors over
/// `groups`, in a spectral run.
fn view_chromaticity(t: &Tally, groups: &[Tally], k: usize) -> Option<[Estimate; 2]> {
    let sums = |t: &Tally| -> Option<[f64; 3]> {
        let g = t.meter.as_ref()?.xyz(k)?;
        Some(g.map(|g| g.bins.iter().map(|b| b.sum.value()).sum()))
    };
    let uv = |s: [f64; 3]| {
        let xyz = crate::color::Xyz {
            x: s[0],
            y: s[1],
            z: s[2],
        };
        xyz.uv_prime().map_or([f64::NAN; 2], |p| [p.u, p.v])
    };
    let total = sums(t)?;
    let leave_out: Vec<[f64; 2]> = groups
        .iter()
        .filter_map(sums)
        .map(|g| uv([0, 1, 2].map(|i| total[i] - g[i])))
        .collect();
    let own = uv(total);
    Some([0, 1].map(|i| Estimate {
        value: own[i],
        stderr: jackknife_stderr(&leave_out.iter().map(|l| l[i]).collect::<Vec<_>>()),
    }))
}

/// `summary.json`'s `luminance_map`: the luminance map's mean and uniformity. When no
/// photon fell within the cone (`photons_in_cone` 0) the map measured nothing: every
/// estimate is NaN (`null`), not 0 ± 0 cd/m².
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LuminanceMapSummary {
    /// The view: polar angle from the detector normal and azimuth from its u axis
    /// (degrees).
    pub view_deg: [f64; 2],
    /// Half-angle of the cone (degrees).
    pub cone_deg: f64,
    /// Photons that scored in the map (over every bin): under the cone estimator those
    /// that left the target within the cone; under the meter's also those whose peel-off
    /// reached it.
    pub photons_in_cone: u64,
    /// Mean luminance over the target (cd/m²).
    pub mean_cd_m2: Estimate,
    /// RMS deviation over mean of the map.
    pub cv: Estimate,
    /// The cv a perfectly uniform panel would show from noise alone.
    pub cv_noise_floor: f64,
    /// About how many photons a noise floor of 0.1 needs ([`photons_needed`]; NaN: no
    /// estimate).
    pub photons_needed: f64,
    /// `sqrt(max(cv^2 - floor^2, 0))`.
    pub cv_debiased: Estimate,
    /// Smallest bin over largest.
    pub min_over_max: Estimate,
    /// Min over max of the 9 standard 3x3-bin spots.
    pub nine_point_min_over_max: Estimate,
    /// Min over max of the 13 standard spots.
    pub thirteen_point_min_over_max: Estimate,
    /// Of the light every view's meter read, the fraction the cone count scored rather
    /// than the peel-off (1 under the cone estimator; NaN when the meter read nothing).
    pub cone_counted_fraction: f64,
    /// CIE 1976 u' and v' of the whole map's light, in a spectral run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uv_prime: Option<[Estimate; 2]>,
    /// What kept the peel-off from most of that light: a surface (`surfaces.TAG`: a
    /// model whose density is not evaluated, or faces that turn the light, such as
    /// grooves), a lamp body, `emission`, `volume scattering` or `a solid's walk`.
    pub cone_counted_mostly: Option<String>,
}

/// The name of the cause `k` of [`crate::tally::MeterTally::counted`].
fn cause_name(scene: &Scene, k: usize) -> String {
    let tags = scene.tags.len();
    let bodies = scene.sources.list.len();
    if k < tags {
        return format!("surfaces.{}", scene.tags[k]);
    }
    if k < tags + bodies {
        return format!("the lamp body of {}", scene.sources.list[k - tags].name);
    }
    let causes = crate::tally::meter::Cause::ALL;
    match causes[k - tags - bodies] {
        crate::tally::meter::Cause::Emission => "emission (no diffuse event)".into(),
        crate::tally::meter::Cause::Volume => "volume scattering".into(),
        crate::tally::meter::Cause::TurnedInWalk => "a face within a light guide's walk".into(),
    }
}

/// The luminance map's summary of view `k` with jackknife errors over `groups` (`None`
/// without lumens or spectra).
pub fn luminance_map_summary(
    scene: &Scene,
    total: &Tally,
    groups: &[Tally],
    k: usize,
) -> Option<LuminanceMapSummary> {
    let (grid, efficacy) = cone_grid(scene, total, k)?;
    let n = total.ledger.photons;
    let metrics = |m: &Map| Metrics::of_flux(m.nx, m.ny, &m.value, &m.stderr, f64::NAN);
    let own = metrics(&map_of(scene, grid, n, efficacy, k));
    let leave_out: Vec<Metrics> = groups
        .iter()
        .filter(|g| g.ledger.photons > 0)
        .filter_map(|g| {
            let mut rest = grid.clone();
            rest.merge_signed(g.meter.as_ref()?.luminous(k), Sign::Remove);
            Some(metrics(&map_of(
                scene,
                &rest,
                n - g.ledger.photons,
                efficacy,
                k,
            )))
        })
        .collect();
    let values = own.values();
    let photons_in_cone: u64 = grid.bins.iter().map(|b| b.hits).sum();
    let est = |m: Metric| match photons_in_cone {
        0 => Estimate {
            value: f64::NAN,
            stderr: f64::NAN,
        },
        _ => Estimate {
            value: values[m],
            stderr: jackknife_stderr(&leave_out.iter().map(|l| l.values()[m]).collect::<Vec<_>>()),
        },
    };
    let meter = total.meter.as_ref()?;
    let counted = meter.counted_fraction();
    Some(LuminanceMapSummary {
        uv_prime: view_chromaticity(total, groups, k),
        cone_counted_fraction: counted.map_or(f64::NAN, |c| c.0),
        cone_counted_mostly: counted
            .filter(|c| c.0 > 0.0)
            .map(|(_, top)| cause_name(scene, top)),
        view_deg: scene.detector.views[k],
        cone_deg: scene.detector.luminance_cone_deg,
        photons_in_cone,
        mean_cd_m2: est(Metric::Mean),
        cv: est(Metric::Cv),
        cv_noise_floor: own.cv_noise_floor,
        photons_needed: photons_needed(scene, total, photons_in_cone, own.cv_noise_floor),
        cv_debiased: est(Metric::CvDebiased),
        min_over_max: est(Metric::MinOverMax),
        nine_point_min_over_max: est(Metric::NinePoint),
        thirteen_point_min_over_max: est(Metric::ThirteenPoint),
    })
}

/// About how many photons the luminance map needs for a noise floor of 0.1 (NaN: no
/// estimate). The floor falls as 1/sqrt(photons), so a map with photons in its cone
/// (`in_cone`) and floor `floor` needs `(floor / 0.1)^2` times as many. An empty map is
/// estimated from the angular grid's first theta row: the cone holds its photons in the
/// ratio of their projected solid angles, `sin^2(cone) / sin^2(row)` (exact for light of
/// uniform radiance near the normal), and a floor of 0.1 takes about 100 photons a bin
/// (Poisson: 1/sqrt(100)).
pub fn photons_needed(scene: &Scene, t: &Tally, in_cone: u64, floor: f64) -> f64 {
    let n = t.ledger.photons as f64;
    if in_cone > 0 {
        return n * (floor / 0.1).powi(2);
    }
    let d = &scene.detector;
    let [nt, np] = d.angular_bins;
    let row: u64 = (0..np).map(|ip| t.angular.bins[ip * nt].hits).sum();
    let sin2 = |deg: f64| deg.to_radians().sin().powi(2);
    let per_photon = row as f64 / n * sin2(d.luminance_cone_deg) / sin2(90.0 / nt as f64);
    let bins = (d.bins[0] * d.bins[1]) as f64;
    match per_photon > 0.0 {
        true => 100.0 * bins / per_photon,
        false => f64::NAN,
    }
}
