//! The polarization of the light on the target: its summed Stokes vector normalised by
//! `S0`, in the detector's frame (`u` made perpendicular to each photon's direction,
//! `S1 > 0` along it; `v = direction x u`), with jackknife errors over the photon groups.
//!
//! ```toml
//! [trace]
//! polarization = true   # on by default when a surface is a polarizer
//! ```

use super::{Estimate, jackknife_stderr};
use crate::tally::{ExactSum, Tally};
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

/// The sums and detected power of `t` (`None` without polarization).
fn sums(t: &Tally) -> Option<([f64; 3], f64)> {
    let s = t.stokes?;
    Some((s.map(ExactSum::value), t.ledger.detected.sum.value()))
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
