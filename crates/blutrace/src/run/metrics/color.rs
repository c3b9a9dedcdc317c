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
//! non-uniformity). Being the largest of 13 noisy distances, `delta_uv_13pt` is biased up
//! by the noise; `delta_uv_13pt_noise_floor` is what noise alone would give, and
//! `delta_uv_13pt_debiased` removes it in quadrature (`debiased`), as `cv_debiased` does
//! for the cv. Errors: delete-one-group jackknife over the run's photon groups, as
//! for every non-linear metric ([`super::jackknife`]).

pub use super::Estimate;
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

/// CIE 1976 u' and v' per flux bin (NaN where no light), each with its delete-one-group
/// jackknife standard error over `groups` (X, Y and Z of a bin are correlated, so their
/// own errors do not give u'v''s), or `None` for a monochrome run. The values are those
/// of `color.exr` (from [`xyz_maps`]); `hits` are the bins' photons.
pub fn uv_prime_maps(scene: &Scene, total: &Tally, groups: &[Tally]) -> Option<[Map; 2]> {
    let xyz = xyz_maps(scene, total)?;
    let sums = |t: &Tally, i: usize| -> Option<[f64; 3]> {
        let c = t.color.as_ref()?;
        Some([0, 1, 2].map(|k| c.flux[k].bins[i].sum.value()))
    };
    let uv = |[x, y, z]: [f64; 3]| {
        Xyz { x, y, z }
            .uv_prime()
            .map_or([f64::NAN; 2], |p| [p.u, p.v])
    };
    let lit: Vec<&Tally> = groups.iter().filter(|g| g.ledger.photons > 0).collect();
    let n = xyz[0].value.len();
    let mut maps = [0, 1].map(|_| Map {
        nx: xyz[0].nx,
        ny: xyz[0].ny,
        value: Vec::with_capacity(n),
        stderr: Vec::with_capacity(n),
        hits: xyz[1].hits.clone(),
    });
    for i in 0..n {
        let own = uv([0, 1, 2].map(|k| xyz[k].value[i]));
        let all = sums(total, i)?;
        let leave_out: Vec<[f64; 2]> = lit
            .iter()
            .filter_map(|g| sums(g, i))
            .map(|s| uv([0, 1, 2].map(|k| all[k] - s[k])))
            .collect();
        for (c, m) in maps.iter_mut().enumerate() {
            m.value.push(own[c]);
            m.stderr.push(jackknife_stderr(
                &leave_out.iter().map(|l| l[c]).collect::<Vec<_>>(),
            ));
        }
    }
    Some(maps)
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
    /// The `delta_uv_13pt` noise alone would give (each spot's offset drawn from its
    /// jackknife covariance), over the spots lit in every photon group.
    pub delta_uv_13pt_noise_floor: f64,
    /// `sqrt(max(d² - floor², 0))`, `d` the largest Δu'v' of a spot lit in every group:
    /// the colour spread with the noise removed; what the optimizer's colour objective
    /// reads.
    pub delta_uv_13pt_debiased: Estimate,
    /// Largest Δu'v' between any two of the 13 spots.
    pub delta_uv_max: Estimate,
    /// Mean illuminance over the target (lux).
    pub illuminance_lux: Estimate,
    /// u', v' of the light leaving the target per theta row (all phi): `[theta_deg, u',
    /// u' error, v', v' error]`.
    pub by_theta: Vec<[f64; 5]>,
}

/// Where [`values`] puts Δu'v' 13-point.
const DELTA_UV_13PT: usize = 6;
/// Where [`values`] puts the 13 spots' offsets from the target's chromaticity, (u', v')
/// per spot (NaN for a spot without light).
const SPOT_OFFSETS: usize = 9;
/// Where [`values`] puts u', v' per theta row.
const THETA_ROWS: usize = SPOT_OFFSETS + 2 * 13;

/// The colour values of one tally (the total or a leave-one-out), in a fixed order:
/// x, y, u', v', CCT, Duv, Δu'v' 13-point, Δu'v' max, mean Y, the 13 spots' u'v' offsets
/// from the target's, then u', v' per theta row.
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
    let lit: Vec<UvPrime> = spots.iter().flatten().copied().collect();
    let (d13, dmax) = match uv {
        Some(uv) => spread(uv, &lit),
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
    v.extend(spots.iter().flat_map(|s| match (s, uv) {
        (Some(s), Some(uv)) => [s.u - uv.u, s.v - uv.v],
        _ => [f64::NAN; 2],
    }));
    v.extend(theta_rows(color).into_iter().flat_map(|uv| match uv {
        Some(p) => [p.u, p.v],
        None => [f64::NAN; 2],
    }));
    v
}

/// The u'v' of each of the 13 spots (`None` for a spot without light).
fn spot_chromaticities(scene: &Scene, maps: &[Vec<f64>; 3]) -> Vec<Option<UvPrime>> {
    let [nx, ny] = scene.detector.bins;
    thirteen_points()
        .iter()
        .map(|&(fx, fy)| {
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

/// Draws of the noise-floor simulation ([`noise_floor`]): its own noise is then about 1 %
/// of the floor.
const FLOOR_DRAWS: u64 = 4096;

/// The noise-floor simulation's seed.
const FLOOR_SEED: u64 = 0xC010_F100;

/// The spots' offsets from the target's chromaticity in `v` (a [`values`] vector).
fn spot_offsets(v: &[f64]) -> impl Iterator<Item = [f64; 2]> + '_ {
    (0..13).map(|i| [v[SPOT_OFFSETS + 2 * i], v[SPOT_OFFSETS + 2 * i + 1]])
}

/// The largest distance from the target's chromaticity in `v` among the spots `used`.
fn largest_offset(v: &[f64], used: &[bool]) -> f64 {
    spot_offsets(v)
        .zip(used)
        .filter(|(_, u)| **u)
        .map(|([du, dv], _)| du.hypot(dv))
        .fold(0.0, f64::max)
}

/// The Δu'v' 13-point that noise alone would give: the mean over [`FLOOR_DRAWS`] draws of
/// the largest distance when each spot's offset is Gaussian with zero mean and its
/// jackknife covariance (`cov` = [σ_u'², σ_v'², cov(u', v')] per spot). A fixed seed, so
/// equal tallies give equal bits.
fn noise_floor(cov: &[[f64; 3]]) -> f64 {
    let mut rng = crate::rng::PhotonRng::new(FLOOR_SEED, 0);
    let chol: Vec<[f64; 3]> = cov
        .iter()
        .map(|&[a, b, c]| {
            let l11 = a.sqrt();
            let l21 = if l11 > 0.0 { c / l11 } else { 0.0 };
            [l11, l21, (b - l21 * l21).max(0.0).sqrt()]
        })
        .collect();
    let mut sum = 0.0;
    for _ in 0..FLOOR_DRAWS {
        let mut largest = 0.0f64;
        for [l11, l21, l22] in &chol {
            // Box-Muller: two independent standard normals.
            let r = (-2.0 * (1.0 - rng.uniform()).ln()).sqrt();
            let (z1, z2) = (std::f64::consts::TAU * rng.uniform()).sin_cos();
            let (g1, g2) = (r * z1, r * z2);
            largest = largest.max((l11 * g1).hypot(l21 * g1 + l22 * g2));
        }
        sum += largest;
    }
    sum / FLOOR_DRAWS as f64
}

/// The jackknife covariance [σ_u'², σ_v'², cov] of each spot's offset over `leave_out`
/// (NaN for a spot dark in some group).
fn offset_covariances(leave_out: &[Vec<f64>]) -> Vec<[f64; 3]> {
    let k = leave_out.len() as f64;
    (0..13)
        .map(|i| {
            let col = |c: usize| -> Vec<f64> {
                leave_out
                    .iter()
                    .map(|v| v[SPOT_OFFSETS + 2 * i + c])
                    .collect()
            };
            let (u, v) = (col(0), col(1));
            let mean = |x: &[f64]| x.iter().sum::<f64>() / k;
            let (mu, mv) = (mean(&u), mean(&v));
            let co = |x: &[f64], mx: f64, y: &[f64], my: f64| {
                (k - 1.0) / k
                    * x.iter()
                        .zip(y)
                        .map(|(a, b)| (a - mx) * (b - my))
                        .sum::<f64>()
            };
            [co(&u, mu, &u, mu), co(&v, mv, &v, mv), co(&u, mu, &v, mv)]
        })
        .collect()
}

/// Δu'v' 13-point with the noise removed, as the cv is debiased: `sqrt(max(d² - f², 0))`,
/// `d` the largest distance of a spot from the target's chromaticity and `f` its
/// [`noise_floor`], over the spots lit in every group; its value for `own` and each
/// leave-one-out (with the same floor), and the floor.
fn debiased(own: &[f64], leave_out: &[Vec<f64>]) -> (f64, Vec<f64>, f64) {
    let cov = offset_covariances(leave_out);
    let used: Vec<bool> = cov
        .iter()
        .zip(spot_offsets(own))
        .map(|(c, [du, dv])| c.iter().all(|x| x.is_finite()) && du.is_finite() && dv.is_finite())
        .collect();
    let lit: Vec<[f64; 3]> = cov
        .iter()
        .zip(&used)
        .filter(|(_, u)| **u)
        .map(|(c, _)| *c)
        .collect();
    let floor = if lit.is_empty() {
        f64::NAN
    } else {
        noise_floor(&lit)
    };
    let debias = |v: &[f64]| super::debiased(largest_offset(v, &used), floor);
    let lo = leave_out.iter().map(|v| debias(v)).collect();
    (debias(own), lo, floor)
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

/// The colour [`values`] of `total`, and of `total` with each group that holds photons
/// left out in turn (the order of [`super::Estimates::leave_out`]); `None` for a
/// monochrome run.
fn with_leave_out(
    scene: &Scene,
    total: &Tally,
    groups: &[Tally],
) -> Option<(Vec<f64>, Vec<Vec<f64>>)> {
    let color = total.color.as_ref()?;
    let n = total.ledger.photons;
    let own = values(scene, color, n);
    let leave_out = groups
        .iter()
        .filter(|g| g.ledger.photons > 0)
        .filter_map(|g| {
            let mut rest = color.clone();
            rest.merge_signed(g.color.as_ref()?, Sign::Remove);
            Some(values(scene, &rest, n - g.ledger.photons))
        })
        .collect();
    Some((own, leave_out))
}

/// Δu'v' 13-point of `total` debiased by the spots' noise (`debiased`), and its
/// leave-one-out values over `groups` (in the order of [`super::Estimates::leave_out`], so
/// a function of it and the flux metrics gets its jackknife error); `None` for a
/// monochrome run.
pub fn delta_uv_13pt_debiased(
    scene: &Scene,
    total: &Tally,
    groups: &[Tally],
) -> Option<(f64, Vec<f64>)> {
    let (own, leave_out) = with_leave_out(scene, total, groups)?;
    let (value, lo, _) = debiased(&own, &leave_out);
    Some((value, lo))
}

/// The colour summary of `total` with jackknife errors over `groups` (`None` for a
/// monochrome run).
pub fn color_summary(scene: &Scene, total: &Tally, groups: &[Tally]) -> Option<ColorSummary> {
    let color = total.color.as_ref()?;
    let (own, leave_out) = with_leave_out(scene, total, groups)?;
    let duv = debiased(&own, &leave_out);
    let est = |i: usize| Estimate {
        value: own[i],
        stderr: jackknife_stderr(&leave_out.iter().map(|v| v[i]).collect::<Vec<_>>()),
    };
    let d = &scene.detector;
    let by_theta = (0..color.angular[0].nx)
        .map(|it| {
            let (u, v) = (est(THETA_ROWS + 2 * it), est(THETA_ROWS + 1 + 2 * it));
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
        delta_uv_13pt: est(DELTA_UV_13PT),
        delta_uv_13pt_debiased: Estimate {
            value: duv.0,
            stderr: jackknife_stderr(&duv.1),
        },
        delta_uv_13pt_noise_floor: duv.2,
        delta_uv_max: est(7),
        illuminance_lux: est(8),
        by_theta,
    })
}
