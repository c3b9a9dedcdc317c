//! Direction sampling: Lambertian (cosine-weighted) hemispheres and Phong lobes.
//!
//! The paper's equation (1), `(phi, theta) = (2 pi x_phi, asin(sqrt(x_theta)))`, is the
//! cosine-weighted hemisphere: the density of `sin^2 theta` is uniform. [`cos_power`]
//! generalizes it to `cos^m` lobes (`m = 1` is Lambertian), used by LEDs and Phong.

use crate::geometry::orthonormal_basis;
use glam::DVec3;
use std::f64::consts::TAU;

/// A direction around the unit vector `axis` with density proportional to
/// `cos^m(theta)` over the hemisphere, from two uniform numbers in `[0, 1)`.
pub fn cos_power(axis: DVec3, m: f64, u1: f64, u2: f64) -> DVec3 {
    let cos_t = (1.0 - u1).powf(1.0 / (m + 1.0));
    around(axis, cos_t, TAU * u2)
}

/// The paper's equation (1): a Lambertian direction around the unit normal `n`.
///
/// The same distribution as [`cos_power`] with `m = 1`, but not the same numbers: this
/// takes `sin theta = sqrt(u1)` directly where `cos_power` derives it from
/// `cos theta = (1 - u1)^(1/2)`, which rounds differently. Kept separate so that traced
/// outputs stay bit-identical to the paper's formula (surfaces and CCFLs) and to LEDs'
/// `cos_exponent = 1`.
pub fn lambertian(n: DVec3, u1: f64, u2: f64) -> DVec3 {
    let sin_t = u1.sqrt();
    let cos_t = (1.0 - u1).max(0.0).sqrt();
    let (t, b) = orthonormal_basis(n);
    let phi = TAU * u2;
    (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + n * cos_t).normalize()
}

/// The unit vector at polar cosine `cos_t` and azimuth `phi` around `axis`.
pub fn around(axis: DVec3, cos_t: f64, phi: f64) -> DVec3 {
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (t, b) = orthonormal_basis(axis);
    (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + axis * cos_t).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambertian_stays_in_hemisphere() {
        let n = DVec3::new(0.2, -0.5, 0.8).normalize();
        for i in 0..1000 {
            let u1 = (i as f64 + 0.5) / 1000.0;
            let d = lambertian(n, u1, (i as f64 * 0.618).fract());
            assert!(d.dot(n) >= 0.0 && (d.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn cos_power_one_has_mean_cosine_two_thirds() {
        // For a cos(theta) density, E[cos theta] = 2/3; stratified, so the error is tiny.
        let n = 100_000;
        let mean: f64 = (0..n)
            .map(|i| cos_power(DVec3::Z, 1.0, (i as f64 + 0.5) / n as f64, 0.3).z)
            .sum::<f64>()
            / n as f64;
        assert!((mean - 2.0 / 3.0).abs() < 1e-6, "{mean}");
    }
}
