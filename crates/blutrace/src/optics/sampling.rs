//! Direction sampling: Lambertian (cosine-weighted) hemispheres and Phong lobes.
//!
//! The paper's equation (1), `(phi, theta) = (2 pi x_phi, asin(sqrt(x_theta)))`, is the
//! cosine-weighted hemisphere: the density of `sin^2 theta` is uniform. [`cos_power`]
//! generalizes it to `cos^m` lobes (`m = 1` is Lambertian), used by LEDs and Phong.

use crate::geometry::orthonormal_basis;
use glam::DVec3;
use std::f64::consts::TAU;

/// Taylor coefficients `(-1)^k / (2k+1)!` of `sin x / x` in powers of `x^2`.
const SIN_TAYLOR: [f64; 9] = [
    1.0,
    -0.16666666666666666,
    0.008333333333333333,
    -0.0001984126984126984,
    2.7557319223985893e-06,
    -2.505210838544172e-08,
    1.6059043836821613e-10,
    -7.647163731819816e-13,
    2.8114572543455206e-15,
];

/// Taylor coefficients `(-1)^k / (2k)!` of `cos x` in powers of `x^2`.
const COS_TAYLOR: [f64; 10] = [
    1.0,
    -0.5,
    0.041666666666666664,
    -0.001388888888888889,
    2.48015873015873e-05,
    -2.755731922398589e-07,
    2.08767569878681e-09,
    -1.1470745597729725e-11,
    4.779477332387385e-14,
    -1.5619206968586225e-16,
];

/// `(cos, sin)` of the angle `2 pi u`, for `u` in `[0, 1)` (a fraction of a turn).
///
/// Hand-written rather than `f64::sin_cos` for two measured reasons: libm's `sincos` took
/// about 5 % of a photon's time on notebook14 (every emission and diffuse bounce draws an
/// azimuth), and its last bit may differ between C libraries, which would break
/// bit-identical results between machines of a Slurm job. Here the quarter turn is taken
/// off exactly (`u - q/4` is exact in f64), the remaining angle lies in `[-pi/4, pi/4]`,
/// and Taylor series to degree 17 / 18 are below half an ulp there.
pub fn turn(u: f64) -> (f64, f64) {
    let q = (4.0 * u).round_ties_even();
    let x = TAU * (u - 0.25 * q);
    let x2 = x * x;
    let horner = |coef: &[f64]| coef.iter().rev().fold(0.0, |acc, &c| acc * x2 + c);
    let (c, s) = (horner(&COS_TAYLOR), x * horner(&SIN_TAYLOR));
    match q as i64 & 3 {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    }
}

/// A direction around the unit vector `axis` with density proportional to
/// `cos^m(theta)` over the hemisphere, from two uniform numbers in `[0, 1)`.
///
/// At `m = 1` (a Lambertian LED, the common case) the root is a square root: exact in
/// IEEE arithmetic on every machine, where libm's `pow` may differ in the last bit
/// between C libraries, and a fifth of its cost.
pub fn cos_power(axis: DVec3, m: f64, u1: f64, u2: f64) -> DVec3 {
    let k = 1.0 / (m + 1.0);
    let cos_t = if k == 0.5 {
        (1.0 - u1).sqrt()
    } else {
        (1.0 - u1).powf(k)
    };
    around(axis, cos_t, u2)
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
    let (cos_p, sin_p) = turn(u2);
    t * (sin_t * cos_p) + b * (sin_t * sin_p) + n * cos_t
}

/// The unit vector at polar cosine `cos_t` and azimuth `2 pi u` around the unit vector
/// `axis` (`u` in `[0, 1)`, a fraction of a turn: see [`turn`]).
///
/// Neither this nor [`lambertian`] renormalizes: the basis is orthonormal and
/// `sin^2 + cos^2 = 1` to a few ulps, so the result is unit to ~1e-16, and a square root
/// and a division less sit on every diffuse bounce's critical path (2 % of a photon).
pub fn around(axis: DVec3, cos_t: f64, u: f64) -> DVec3 {
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (t, b) = orthonormal_basis(axis);
    let (cos_p, sin_p) = turn(u);
    t * (sin_t * cos_p) + b * (sin_t * sin_p) + axis * cos_t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turn_matches_libm_to_an_ulp_everywhere() {
        // Quarter-turn boundaries, their neighbours, and a dense sweep.
        let mut us: Vec<f64> = (0..=8).map(|k| k as f64 / 8.0).collect();
        us.extend(
            us.clone()
                .iter()
                .flat_map(|&u| [u.next_up(), u.next_down()]),
        );
        us.extend((0..200_000).map(|i| (i as f64 + 0.37) / 200_000.0));
        for u in us.into_iter().filter(|u| (0.0..1.0).contains(u)) {
            let (c, s) = turn(u);
            let (s_ref, c_ref) = (TAU * u).sin_cos();
            // TAU * u itself rounds (by up to 2.2e-16 x 2 pi): libm's answer carries that.
            assert!(
                (c - c_ref).abs() < 2e-15 && (s - s_ref).abs() < 2e-15,
                "{u}"
            );
            assert!((c * c + s * s - 1.0).abs() < 4e-16, "{u}");
        }
        assert_eq!(turn(0.0), (1.0, 0.0));
        assert_eq!(turn(0.25), (0.0, 1.0));
        assert_eq!(turn(0.5), (-1.0, 0.0));
    }

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
