//! The polarization of the light on the target: its summed Stokes vector normalised by
//! `S0`, in the detector's frame (`u` made perpendicular to each photon's direction,
//! `S1 > 0` along it; `v = direction x u`), with jackknife errors over the photon groups.
//!
//! ```toml
//! [trace]
//! polarization = true   # on by default with a polarizer or a polarized source
//! ```
//!
//! Per flux bin too ([`stokes_maps`], `stokes.exr`): `S0` is the flux map, `S1`..`S3`
//! the irradiance of each Stokes component, each with its per-bin standard error.

use super::Map;
use super::{Estimate, jackknife_stderr};
use crate::scene::Scene;
use crate::tally::{ExactSum, Grid, Tally};
use serde::Serialize;

/// `summary.json`'s `polarization`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PolarizationSummary {
    /// `S1 / S0`: linear along `u` (positive) or across it (negative).
    pub s1: Estimate,
    /// `S2 / S0`: linear at +45 degrees from `u` towards `v` (positive) or at -45.
    pub s2: Estimate,
    /// `S3 / S0`: circular, turning from `u` towards `v` (positive).
    pub s3: Estimate,
    /// Degree of polarization of the summed light, `sqrt(S1^2 + S2^2 + S3^2) / S0`.
    pub dop: Estimate,
}

/// The normalised Stokes vector and degree of polarization of sums `s` over power `w`.
fn normalised(s: [f64; 3], w: f64) -> [f64; 4] {
    let [s1, s2, s3] = s.map(|x| x / w);
    [s1, s2, s3, (s1 * s1 + s2 * s2 + s3 * s3).sqrt()]
}

/// The sums and detected power of `t` (`None` without polarization): the bins' exact
/// sums added exactly.
fn sums(t: &Tally) -> Option<([f64; 3], f64)> {
    let grids = t.stokes.as_ref()?;
    let total = |g: &Grid| {
        let mut sum = ExactSum::default();
        g.bins.iter().for_each(|b| sum.merge(b.sum));
        sum.value()
    };
    Some((
        [total(&grids[0]), total(&grids[1]), total(&grids[2])],
        t.ledger.detected.sum.value(),
    ))
}

/// The maps of `S0` (the flux map) and of `S1`, `S2`, `S3` (W/mm² per bin, each with its
/// standard error), `None` without polarization.
pub fn stokes_maps(scene: &Scene, t: &Tally) -> Option<[Map; 4]> {
    let grids = t.stokes.as_ref()?;
    let area = scene.detector.bin_area();
    let map = |g: &Grid| super::grid_map(scene, t, g, |_| area);
    Some([
        super::flux_map(scene, t),
        map(&grids[0]),
        map(&grids[1]),
        map(&grids[2]),
    ])
}

/// The polarization of the detected light of `total`, errors by the jackknife over
/// `groups`; `None` when polarization is not traced, NaN values when nothing was detected.
pub fn polarization_summary(total: &Tally, groups: &[Tally]) -> Option<PolarizationSummary> {
    let (s, w) = sums(total)?;
    let own = normalised(s, w);
    let leave_out: Vec<[f64; 4]> = groups
        .iter()
        .filter(|g| g.ledger.photons > 0)
        .filter_map(|g| {
            let (gs, gw) = sums(g)?;
            Some(normalised([0, 1, 2].map(|k| s[k] - gs[k]), w - gw))
        })
        .collect();
    let est = |k: usize| Estimate {
        value: own[k],
        stderr: jackknife_stderr(&leave_out.iter().map(|l| l[k]).collect::<Vec<_>>()),
    };
    Some(PolarizationSummary {
        s1: est(0),
        s2: est(1),
        s3: est(2),
        dop: est(3),
    })
}
