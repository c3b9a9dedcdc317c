//! The Henyey-Greenstein phase function: the direction a photon takes at a scattering
//! event inside a medium (see [`super::medium`] for the scene-file entry).
//!
//! `p(cos theta) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2))` per steradian, with
//! mean cosine `g` (the anisotropy): 0 isotropic, towards 1 forward, towards -1 backward.
//! Sampled by inverting its cumulative distribution in `cos theta` (exact, no rejection).
//!
//! Or a measured phase function, `phase_table = [[angle_deg, value], ...]` ([`PhaseTable`]):
//! values per steradian (any scale) at scattering angles from 0 to 180 degrees, linear
//! between knots.

use super::sampling;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Below this |g| the inversion formula loses digits to cancellation; the phase function
/// differs from isotropic by less than 3 |g| there, and the isotropic draw is used.
const ISOTROPIC_BELOW: f64 = 1e-9;

/// The density of the scattering direction per steradian at `cos_t` for anisotropy `g`.
pub fn hg_density(g: f64, cos_t: f64) -> f64 {
    let d = 1.0 + g * g - 2.0 * g * cos_t;
    (1.0 - g * g) / (4.0 * PI * d * d.sqrt())
}

/// `cos theta` of a Henyey-Greenstein direction from one uniform number `u` in `[0, 1)`.
pub fn hg_cos_theta(g: f64, u: f64) -> f64 {
    if g.abs() < ISOTROPIC_BELOW {
        return 2.0 * u - 1.0;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// The direction after scattering a photon travelling along unit `dir`, from two uniform
/// numbers: polar angle from the phase function, azimuth uniform.
pub fn scatter(dir: DVec3, g: f64, u1: f64, u2: f64) -> DVec3 {
    sampling::around(dir, hg_cos_theta(g, u1), u2)
}

/// Fine cells over 0..180 degrees for sampling a [`PhaseTable`]: the density is taken as
/// constant in theta within a cell of 0.044 degrees, far finer than any measured table.
const TABLE_CELLS: usize = 4096;

/// A tabulated phase function: value per steradian, piecewise linear in the scattering
/// angle, normalized; sampled by inverse CDF over fine cells in theta.
#[derive(Clone, Debug, PartialEq)]
pub struct PhaseTable {
    /// Knots: angle (radians), value (per steradian, normalized to integrate to 1).
    knots: Vec<(f64, f64)>,
    /// Cumulative probability at the fine cells' edges (`TABLE_CELLS + 1`, from 0 to 1).
    cdf: Vec<f64>,
    /// The mean cosine of the scattering angle.
    pub mean_cosine: f64,
}

impl PhaseTable {
    /// From `[angle_deg, value]` rows: angles strictly increasing from 0 to 180, values
    /// finite and >= 0, not all 0. `Err` says what is wrong.
    pub fn new(rows: &[[f64; 2]]) -> Result<PhaseTable, String> {
        if rows.len() < 2 {
            return Err("needs at least two rows, at 0 and 180 degrees".into());
        }
        for (i, [a, v]) in rows.iter().enumerate() {
            if !a.is_finite() || !v.is_finite() || *v < 0.0 {
                return Err(format!(
                    "row {i}: angle and value must be finite, value >= 0, got [{a}, {v}]"
                ));
            }
            if i > 0 && *a <= rows[i - 1][0] {
                return Err(format!(
                    "row {i}: angles must increase, got {a} after {}",
                    rows[i - 1][0]
                ));
            }
        }
        if rows[0][0] != 0.0 || rows[rows.len() - 1][0] != 180.0 {
            return Err("angles must run from 0 to 180 degrees".into());
        }
        // Values relative to the largest: the scale is free, and the sums below would
        // overflow near 1e306 or lose digits to subnormals.
        let peak = rows.iter().map(|r| r[1]).fold(0.0, f64::max);
        if peak <= 0.0 {
            return Err("the values are all 0".into());
        }
        let mut t = PhaseTable {
            knots: rows
                .iter()
                .map(|[a, v]| (a.to_radians(), v / peak))
                .collect(),
            cdf: Vec::with_capacity(TABLE_CELLS + 1),
            mean_cosine: 0.0,
        };
        // Per-cell probability 2 pi v(theta) sin(theta) dtheta at the cell's midpoint.
        let d = PI / TABLE_CELLS as f64;
        let (mut sum, mut mean) = (0.0, 0.0);
        t.cdf.push(0.0);
        for i in 0..TABLE_CELLS {
            let th = (i as f64 + 0.5) * d;
            let p = TAU * t.value(th) * th.sin() * d;
            sum += p;
            mean += p * th.cos();
            t.cdf.push(sum);
        }
        if sum <= 0.0 {
            return Err("the values are all 0".into());
        }
        t.cdf.iter_mut().for_each(|c| *c /= sum);
        t.knots.iter_mut().for_each(|k| k.1 /= sum);
        t.mean_cosine = mean / sum;
        Ok(t)
    }

    /// The normalized value (per steradian) at scattering angle `theta` (radians).
    fn value(&self, theta: f64) -> f64 {
        let i = self
            .knots
            .partition_point(|k| k.0 <= theta)
            .clamp(1, self.knots.len() - 1);
        let ((a0, v0), (a1, v1)) = (self.knots[i - 1], self.knots[i]);
        v0 + (v1 - v0) * ((theta - a0) / (a1 - a0)).clamp(0.0, 1.0)
    }

    /// The density per steradian at `cos_t` (as sampled: constant within a fine cell).
    pub fn density(&self, cos_t: f64) -> f64 {
        let d = PI / TABLE_CELLS as f64;
        let th = cos_t.clamp(-1.0, 1.0).acos();
        let i = ((th / d) as usize).min(TABLE_CELLS - 1);
        let mid = (i as f64 + 0.5) * d;
        self.value(mid) * mid.sin() / th.sin().max(1e-300)
    }

    /// `cos theta` of a draw from one uniform number `u` in `[0, 1)`: the fine cell by
    /// the CDF, theta uniform within it.
    pub fn cos_theta(&self, u: f64) -> f64 {
        let i = (self.cdf.partition_point(|&c| c <= u) - 1).min(TABLE_CELLS - 1);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let f = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.5 };
        ((i as f64 + f) * PI / TABLE_CELLS as f64).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn density_integrates_to_one_and_has_mean_cosine_g() {
        for g in [-0.7, 0.0, 0.5, 0.95] {
            // Midpoint rule over cos theta (2 pi from the azimuth).
            let n = 200_000;
            let (mut norm, mut mean) = (0.0, 0.0);
            for i in 0..n {
                let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let p = hg_density(g, c) * TAU * 2.0 / n as f64;
                norm += p;
                mean += p * c;
            }
            assert!((norm - 1.0).abs() < 1e-4, "g {g}: norm {norm}");
            assert!((mean - g).abs() < 1e-4, "g {g}: mean cosine {mean}");
        }
    }

    /// A table's scale is free: at 1e308 (whose sums overflow) or a subnormal 1e-310 it
    /// draws the directions, and has the mean cosine, of the same table at 1.
    #[test]
    fn a_phase_table_at_any_scale_is_the_same_distribution() {
        let rows = [[0.0, 1.7], [10.0, 1.5], [60.0, 1.0], [180.0, 0.5]];
        let at = |s: f64| {
            let scaled: Vec<[f64; 2]> = rows.iter().map(|&[a, v]| [a, v * s]).collect();
            PhaseTable::new(&scaled).unwrap()
        };
        let one = at(1.0);
        for s in [1e308, 1e300, 1e-300, 1e-310] {
            let t = at(s);
            assert!(
                (t.mean_cosine - one.mean_cosine).abs() < 1e-12,
                "scale {s:e}: mean cosine {} against {}",
                t.mean_cosine,
                one.mean_cosine
            );
            for k in 0..100 {
                let u = (k as f64 + 0.5) / 100.0;
                let (a, b) = (t.cos_theta(u), one.cos_theta(u));
                assert!((a - b).abs() < 1e-12, "scale {s:e}, u {u}: {a} against {b}");
            }
            assert!((t.density(0.3) - one.density(0.3)).abs() < 1e-12 * one.density(0.3));
        }
        assert!(PhaseTable::new(&[[0.0, 0.0], [180.0, 0.0]]).is_err());
    }

    #[test]
    fn inversion_is_monotone_and_covers_the_sphere() {
        for g in [-0.9, -1e-12, 0.3, 0.99] {
            assert!((hg_cos_theta(g, 0.0) + 1.0).abs() < 1e-12, "g {g}");
            assert!((hg_cos_theta(g, 1.0 - 1e-16) - 1.0).abs() < 1e-9, "g {g}");
            let mut last = -1.0;
            for i in 1..1000 {
                let c = hg_cos_theta(g, i as f64 / 1000.0);
                assert!(c >= last, "g {g}: not monotone at {i}");
                last = c;
            }
        }
    }
}
