//! The feedback method: a tabulated density, one knot per strip, updated by damped ratios
//! after each trace.
//!
//! ```text
//! blutrace optimize SCENE --method feedback [--alpha 0.7] [--smoothing 0.25] [--max-iter 15]
//! ```
//!
//! Each round traces the current design and updates every knot by
//! `d <- d * (target / measured)^alpha`, where `measured` is the mean flux of the profile
//! strips over the knot's interval and `target` the median of the strips inside the
//! objective's margins (`--edge-margin-mm`; the median, not the mean, so a few strips that
//! cannot be fixed, such as light leaking at a lamp edge, do not pull the level); then `d`
//! is clamped to `[min printable, max packing]` and optionally smoothed with its
//! neighbours. The rounds stop at the objective bound (`--target-cv`), the iteration cap,
//! or after [`STALL_ROUNDS`] rounds that gain less than the objective's noise. With
//! mirrored patterns (lamps on both edges) the two halves share their knots, which halves
//! the noise per knot.
//!
//! The result is written as a `density_table`:
//!
//! ```toml
//! [surfaces.lgp_back]
//! density_table = [[0.01, 0.013], [0.03, 0.011], ...]   # [x, d], x as x_unit says
//! ```

use super::objective::Profile;
use crate::optics::dots::DotPattern;

/// The search stops after this many rounds in a row that do not beat the best objective
/// by more than its standard error (the design has converged to the noise level).
pub const STALL_ROUNDS: usize = 3;

/// Settings of one update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Damping exponent (1: full ratio; smaller is slower and steadier).
    pub alpha: f64,
    /// Weight of the neighbours' mean in the smoothing pass (0: none).
    pub smoothing: f64,
    /// Smallest printable density.
    pub min: f64,
    /// Largest density (the lattice's packing limit).
    pub max: f64,
}

/// `n` knot positions (polynomial variable) at the centres of equal intervals over the
/// pattern's span of x.
pub fn knot_positions(pattern: &DotPattern, n: usize) -> Vec<f64> {
    let x_max = pattern.x_max();
    (0..n.max(2))
        .map(|j| (j as f64 + 0.5) / n.max(2) as f64 * x_max)
        .collect()
}

/// The number of knots for `strips` profile strips: one per strip, or one per mirrored
/// pair of strips.
pub fn knot_count(pattern: &DotPattern, strips: usize) -> usize {
    if pattern.mirror {
        strips.div_ceil(2).max(2)
    } else {
        strips.max(2)
    }
}

/// Mean measured flux per knot interval (NaN where no strip falls). Strips in the
/// objective's margins count here too: their density is still steered towards the
/// target, it just does not enter the objective.
pub fn measured_per_knot(pattern: &DotPattern, knots: &[f64], profile: &Profile) -> Vec<f64> {
    let n = knots.len();
    let x_max = pattern.x_max();
    let mut sum = vec![0.0; n];
    let mut count = vec![0usize; n];
    for k in 0..profile.u.len() {
        if !profile.populated[k] {
            continue;
        }
        let x = pattern.x_of(profile.u[k]);
        let j = ((x / x_max * n as f64).max(0.0) as usize).min(n - 1);
        sum[j] += profile.value[k];
        count[j] += 1;
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
        .collect()
}

/// One feedback update of the knot densities `d` from a traced profile.
pub fn update(pattern: &DotPattern, knots: &[f64], d: &mut [f64], profile: &Profile, s: &Settings) {
    let target = profile.median();
    let measured = measured_per_knot(pattern, knots, profile);
    if !(target > 0.0 && target.is_finite()) {
        return;
    }
    for (dj, m) in d.iter_mut().zip(&measured) {
        if m.is_nan() {
            continue;
        }
        // A dark strip (no flux at all) gets the largest step the damping allows.
        let ratio = if *m > 0.0 { target / m } else { 4.0 };
        *dj = (*dj * ratio.clamp(0.25, 4.0).powf(s.alpha)).clamp(s.min, s.max);
    }
    if s.smoothing > 0.0 && d.len() > 2 {
        let old = d.to_vec();
        for j in 0..d.len() {
            let nb: Vec<f64> = [j.checked_sub(1), Some(j + 1)]
                .into_iter()
                .flatten()
                .filter_map(|i| old.get(i).copied())
                .collect();
            let mean = nb.iter().sum::<f64>() / nb.len() as f64;
            d[j] = ((1.0 - s.smoothing) * old[j] + s.smoothing * mean).clamp(s.min, s.max);
        }
    }
}
