//! The Henyey-Greenstein phase function: the direction a photon takes at a scattering
//! event inside a medium (see [`super::medium`] for the scene-file entry).
//!
//! `p(cos theta) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2))` per steradian, with
//! mean cosine `g` (the anisotropy): 0 isotropic, towards 1 forward, towards -1 backward.
//! Sampled by inverting its cumulative distribution in `cos theta` (exact, no rejection).

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
    sampling::around(dir, hg_cos_theta(g, u1), TAU * u2)
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
