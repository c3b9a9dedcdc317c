//! Fresnel reflection, Snell refraction and total internal reflection.
//!
//! The paper's equation (3) writes R_s and R_p as ratios of sines and tangents, which is
//! 0/0 at normal incidence. Here they are written with cosines (Born & Wolf), exact at
//! every angle: normal, grazing and either side of the critical angle.
//!
//! [`roulette`] chooses between reflection and refraction by Russian roulette on R: every
//! dielectric face (smooth, grooved, rough) uses it.

use crate::rng::PhotonRng;
use glam::DVec3;

/// Unpolarized Fresnel reflectance `(R_s + R_p) / 2` for light going from index `n1`
/// into index `n2`, with `cos_i` the cosine of the incidence angle (in `[0, 1]`).
/// Returns 1 beyond the critical angle (total internal reflection).
pub fn reflectance(cos_i: f64, n1: f64, n2: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    match cos_transmitted(cos_i, n1, n2) {
        None => 1.0,
        Some(cos_t) => reflectance_with(cos_i, cos_t, n1, n2),
    }
}

/// [`reflectance`] below the critical angle, given the refraction cosine `cos_t` of
/// `cos_i` (in `[0, 1]`).
fn reflectance_with(cos_i: f64, cos_t: f64, n1: f64, n2: f64) -> f64 {
    if n1 == n2 {
        return 0.0; // no interface, at every angle including grazing
    }
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Cosine of the refraction angle by Snell's law, or `None` under total internal reflection
/// (beyond the critical angle; at it the cosine is 0, where [`reflectance`] is 1).
///
/// `cos_t^2 = 1 - eta^2 (1 - cos_i^2)` is evaluated as `(1 - eta)(1 + eta) + eta^2 cos_i^2`:
/// the same number, without the cancellation of `1 - sin_t^2` at grazing incidence (at
/// eta = 1 it is exactly `cos_i^2`, so an index-matched interface never bends a ray, nor
/// reflects one, even at grazing incidence).
pub fn cos_transmitted(cos_i: f64, n1: f64, n2: f64) -> Option<f64> {
    let eta = n1 / n2;
    let cos2_t = (1.0 - eta) * (1.0 + eta) + eta * eta * (cos_i * cos_i).min(1.0);
    (cos2_t >= 0.0).then(|| cos2_t.sqrt())
}

/// The critical angle (radians) going from `n1` into `n2 < n1`; `None` when `n2 >= n1`.
pub fn critical_angle(n1: f64, n2: f64) -> Option<f64> {
    (n2 < n1).then(|| (n2 / n1).asin())
}

/// Mirror reflection of `dir` about the unit normal `n` (either orientation).
#[inline]
pub fn reflect(dir: DVec3, n: DVec3) -> DVec3 {
    dir - 2.0 * dir.dot(n) * n
}

/// Refracted direction of unit `dir` through a surface with unit normal `n` facing the
/// incident side (`dir · n < 0`), from `n1` into `n2`; `None` under total internal reflection.
pub fn refract(dir: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let cos_i = -dir.dot(n);
    let cos_t = cos_transmitted(cos_i, n1, n2)?;
    Some(refracted(dir, n, cos_i, cos_t, n1 / n2))
}

/// The refracted direction of unit `dir` through unit `n` (facing the incident side)
/// with incidence and refraction cosines `cos_i`, `cos_t` and `eta = n1 / n2`.
fn refracted(dir: DVec3, n: DVec3, cos_i: f64, cos_t: f64, eta: f64) -> DVec3 {
    (eta * dir + (eta * cos_i - cos_t) * n).normalize()
}

/// The Fresnel roulette of unit `dir` meeting a surface of unit normal `facing` (facing
/// the incident side, `dir · facing < 0`) from index `n1` into `n2`: reflected with
/// probability R (always under total internal reflection), else refracted. `Some(t)`:
/// refracted along `t`; `None`: reflected (the caller mirrors `dir` about `facing`).
///
/// One uniform is drawn, unless R = 1.
#[inline]
pub fn roulette(dir: DVec3, facing: DVec3, n1: f64, n2: f64, rng: &mut PhotonRng) -> Option<DVec3> {
    // [`reflectance`] then [`refract`], sharing the cosines: total internal reflection
    // (most hits inside a guide) leaves after one square root and no draw.
    let cos_i = -dir.dot(facing);
    let cos_t = cos_transmitted(cos_i, n1, n2)?;
    let r = reflectance_with(cos_i.clamp(0.0, 1.0), cos_t, n1, n2);
    if r >= 1.0 || rng.uniform() < r {
        return None;
    }
    Some(refracted(dir, facing, cos_i, cos_t, n1 / n2))
}

#[cfg(test)]
mod tests {
    use super::*;
    const PMMA: f64 = 1.49;

    #[test]
    fn normal_incidence_matches_closed_form() {
        let r0 = ((PMMA - 1.0) / (PMMA + 1.0)).powi(2);
        assert!((reflectance(1.0, 1.0, PMMA) - r0).abs() < 1e-15);
        assert!((reflectance(1.0, PMMA, 1.0) - r0).abs() < 1e-15);
        assert!((r0 - 0.0387).abs() < 5e-5, "R0 = {r0}");
    }

    #[test]
    fn grazing_incidence_reflects_everything() {
        assert!((reflectance(0.0, 1.0, PMMA) - 1.0).abs() < 1e-12);
        assert!(reflectance(1e-6, 1.0, PMMA) > 0.99);
    }

    #[test]
    fn critical_angle_of_pmma() {
        let c = critical_angle(PMMA, 1.0).unwrap().to_degrees();
        assert!((c - 42.16).abs() < 0.01, "critical angle {c}");
        let theta = critical_angle(PMMA, 1.0).unwrap();
        assert_eq!(reflectance((theta + 1e-6).cos(), PMMA, 1.0), 1.0);
        let below = reflectance((theta - 1e-6).cos(), PMMA, 1.0);
        assert!(below < 1.0 && below > 0.9, "just below critical: {below}");
    }

    #[test]
    fn no_interface_when_indices_match() {
        for k in 0..=100 {
            let cos_i = k as f64 / 100.0;
            assert_eq!(reflectance(cos_i, 1.3, 1.3), 0.0);
        }
        // The roulette agrees, at grazing incidence too: the photon goes straight on.
        let mut rng = PhotonRng::new(1, 2);
        for dir in [DVec3::X, DVec3::new(0.6, 0.0, -0.8)] {
            assert_eq!(roulette(dir, DVec3::Z, 1.3, 1.3, &mut rng), Some(dir));
        }
    }

    #[test]
    fn the_critical_angle_itself_reflects_everything() {
        // Where Snell's cosine is exactly 0 the reflectance is exactly 1: the roulette
        // reflects without a draw, as beyond the critical angle.
        let (n1, n2, cos_i) = (1.25, 1.0, 0.6); // sin_i = 0.8 = n2/n1, and in f64 too
        assert_eq!(cos_transmitted(cos_i, n1, n2), Some(0.0));
        assert_eq!(reflectance(cos_i, n1, n2), 1.0);
        let dir = DVec3::new(0.8, 0.0, cos_i);
        let (mut rng, mut fresh) = (PhotonRng::new(1, 2), PhotonRng::new(1, 2));
        assert_eq!(roulette(dir, DVec3::NEG_Z, n1, n2, &mut rng), None);
        assert_eq!(rng.uniform(), fresh.uniform());
    }

    #[test]
    fn snell_law_holds() {
        let theta_i = 30f64.to_radians();
        let dir = DVec3::new(theta_i.sin(), 0.0, -theta_i.cos());
        let t = refract(dir, DVec3::Z, 1.0, PMMA).unwrap();
        let sin_t = (t.x * t.x + t.y * t.y).sqrt();
        assert!((theta_i.sin() - PMMA * sin_t).abs() < 1e-14);
        assert!(t.z < 0.0 && (t.length() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn total_internal_reflection_has_no_refracted_ray() {
        let theta_i = 50f64.to_radians();
        let dir = DVec3::new(theta_i.sin(), 0.0, theta_i.cos());
        assert!(refract(dir, DVec3::NEG_Z, PMMA, 1.0).is_none());
    }
}
