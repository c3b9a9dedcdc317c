//! The colour of the light on the target, from the X, Y, Z tallies of a spectral scene
//! ([`crate::tally::ColorTally`]): maps of X, Y, Z, and the colour summary with
//! jackknife errors.
//!
//! Units: X, Y, Z are photometric, with K_m = 683 lm/W ([`KM_LM_PER_W`]): Y per bin is the
//! illuminance in lux (lm/m²), X and Z on the same scale. Chromaticity x, y and CIE 1976
//! u', v' of the whole target come from its summed X, Y, Z; the 13 uniformity spots are
//! the 3x3-bin spots of the 13-point luminance check ([`super::thirteen_points`]);
//! `delta_uv_13pt` is the largest Δu'v' of a spot from the whole target's chromaticity,
//! `delta_uv_max` the largest between any two spots (the display-lab colour
//! non-uniformity). Errors: delete-one-group jackknife over the run's photon groups, as
//! for every non-linear metric ([`super::jackknife`]).

use super::{Map, grid_map, jackknife_stderr, spot_mean, thirteen_points};
use crate::color::{KM_LM_PER_W, UvPrime, Xyz, cct};
use crate::scene::Scene;
use crate::tally::{ColorTally, Grid, Sign, Tally};
use serde::Serialize;

/// X, Y, Z maps of the target (lux-scaled), or `None` for a monochrome run.
pub fn xyz_maps(scene: &Scene, t: &Tally) -> Option<[Map; 3]> {
    let color = t.color.as_ref()?;
    let area_m2 = scene.detector.bin_area() * 1e-6;
    Some(std::array::from_fn(|k| {
        grid_map(scene, t, &color.flux[k], |_| area_m2 / KM_LM_PER_W)
    }))
}

/// A value and its standard error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Its standard error.
    pub stderr: f64,
}

/// `summary.json`'s `color`: the target's colour and its non-uniformity.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColorSummary {
    /// CIE 1931 x of the whole target's light.
    pub x: Estimate,
    /// CIE 1931 y.
    pub y: Estimate,
    /// CIE 1976 u'.
    pub u_prime: Estimate,
    /// CIE 1976 v'.
    pub v_prime: Estimate,
    /// Correlated colour temperature (K), Ohno 2014 (NaN off the 1000-100000 K range).
    pub cct_k: Estimate,
    /// Signed distance from the Planckian locus in CIE 1960 (u, v).
    pub duv: Estimate,
    /// Largest Δu'v' of a 13-point spot from the whole target's chromaticity.
    pub delta_uv_13pt: Estimate,
    /// Largest Δu'v' between any two of the 13 spots.
    pub delta_uv_max: Estimate,
    /// Mean illuminance over the target (lux).
    pub illuminance_lux: Estimate,
    /// u', v' of the light leaving the target per theta row (all phi): `[theta_deg, u',
    /// u' error, v', v' error]`.
    pub by_theta: Vec<[f64; 5]>,
}

/// The colour values of one tally (the total or a leave-one-out), in a fixed order:
/// x, y, u', v', CCT, Duv, Δu'v' 13-point, Δu'v' max, mean Y, then u', v' per theta row.
fn values(scene: &Scene, color: &ColorTally, photons: u64) -> Vec<f64> {
    let mean = |g: &Grid| -> Vec<f64> {
        let n = photons.max(1) as f64;
        g.bins.iter().map(|b| b.sum.value() / n).collect()
    };
    let maps: [Vec<f64>; 3] = std::array::from_fn(|k| mean(&color.flux[k]));
    let total = |k: usize| maps[k].iter().sum::<f64>();
    let xyz = Xyz {
        x: total(0),
        y: total(1),
        z: total(2),
    };
    let (xy, uv) = (xyz.xy(), xyz.uv_prime());
    let c = uv.and_then(cct);
    let spots = spot_chromaticities(scene, &maps);
    let (d13, dmax) = match uv {
        Some(uv) => spread(uv, &spots),
        None => (f64::NAN, f64::NAN),
    };
    let area_m2 = scene.detector.area_m2();
    let lux = xyz.y * scene.sources.total_power() * KM_LM_PER_W / area_m2;
    let mut v = vec![
        xy.map_or(f64::NAN, |p| p.x),
        xy.map_or(f64::NAN, |p| p.y),
        uv.map_or(f64::NAN, |p| p.u),
        uv.map_or(f64::NAN, |p| p.v),
        c.map_or(f64::NAN, |c| c.kelvin),
        c.map_or(f64::NAN, |c| c.delta_uv),
        d13,
        dmax,
        lux,
    ];
    v.extend(theta_rows(color).into_iter().flat_map(|uv| match uv {
        Some(p) => [p.u, p.v],
        None => [f64::NAN; 2],
    }));
    v
}

/// The u'v' of each of the 13 spots that have light.
fn spot_chromaticities(scene: &Scene, maps: &[Vec<f64>; 3]) -> Vec<UvPrime> {
    let [nx, ny] = scene.detector.bins;
    thirteen_points()
        .iter()
        .filter_map(|&(fx, fy)| {
            let s = |k: usize| spot_mean(nx, ny, &maps[k], fx, fy);
            Xyz {
                x: s(0),
                y: s(1),
                z: s(2),
            }
            .uv_prime()
        })
        .collect()
}

/// The largest distance of a spot from `whole`, and between two spots.
fn spread(whole: UvPrime, spots: &[UvPrime]) -> (f64, f64) {
    let from_whole = spots.iter().map(|s| s.delta(whole)).fold(0.0, f64::max);
    let between = spots
        .iter()
        .enumerate()
        .flat_map(|(i, a)| spots[i + 1..].iter().map(move |b| a.delta(*b)))
        .fold(0.0, f64::max);
    (from_whole, between)
}

/// The u'v' of each theta row of the angular X, Y, Z (summed over phi).
fn theta_rows(color: &ColorTally) -> Vec<Option<UvPrime>> {
    let (nt, np) = (color.angular[0].nx, color.angular[0].ny);
    (0..nt)
        .map(|it| {
            let row = |k: usize| -> f64 {
                (0..np)
                    .map(|ip| color.angular[k].bins[ip * nt + it].sum.value())
                    .sum()
            };
            Xyz {
                x: row(0),
                y: row(1),
                z: row(2),
            }
            .uv_prime()
        })
        .collect()
}

/// The colour summary of `total` with jackknife errors over `groups` (`None` for a
/// monochrome run).
pub fn color_summary(scene: &Scene, total: &Tally, groups: &[Tally]) -> Option<ColorSummary> {
    let color = total.color.as_ref()?;
    let n = total.ledger.photons;
    let own = values(scene, color, n);
    let leave_out: Vec<Vec<f64>> = groups
        .iter()
        .filter(|g| g.ledger.photons > 0)
        .filter_map(|g| {
            let mut rest = color.clone();
            rest.merge_signed(g.color.as_ref()?, Sign::Remove);
            Some(values(scene, &rest, n - g.ledger.photons))
        })
        .collect();
    let est = |i: usize| Estimate {
        value: own[i],
        stderr: jackknife_stderr(&leave_out.iter().map(|v| v[i]).collect::<Vec<_>>()),
    };
    let d = &scene.detector;
    let by_theta = (0..color.angular[0].nx)
        .map(|it| {
            let (u, v) = (est(9 + 2 * it), est(10 + 2 * it));
            [d.theta_centre_deg(it), u.value, u.stderr, v.value, v.stderr]
        })
        .collect();
    Some(ColorSummary {
        x: est(0),
        y: est(1),
        u_prime: est(2),
        v_prime: est(3),
        cct_k: est(4),
        duv: est(5),
        delta_uv_13pt: est(6),
        delta_uv_max: est(7),
        illuminance_lux: est(8),
        by_theta,
    })
}
