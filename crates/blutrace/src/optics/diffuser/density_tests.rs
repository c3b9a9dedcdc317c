//! The walk's density, estimated, against the directions the walk draws.

use super::*;
use crate::optics::diffuser::scatter_carrying;
use crate::optics::polarization::Stokes;

/// Bins over the sphere: 10 bands of `cos theta` (to the mean normal) by 8 of `phi`.
const BANDS: usize = 10;
const SECTORS: usize = 8;

fn bin_of(d: DVec3) -> usize {
    let band = (((d.z + 1.0) / 2.0 * BANDS as f64) as usize).min(BANDS - 1);
    let phi = d.y.atan2(d.x).rem_euclid(std::f64::consts::TAU);
    let sector = ((phi / std::f64::consts::TAU * SECTORS as f64) as usize).min(SECTORS - 1);
    band * SECTORS + sector
}

/// A direction drawn uniformly within bin `b`.
fn in_bin(b: usize, rng: &mut PhotonRng) -> DVec3 {
    let (band, sector) = (b / SECTORS, b % SECTORS);
    let z = -1.0 + 2.0 * (band as f64 + rng.uniform()) / BANDS as f64;
    let phi = std::f64::consts::TAU * (sector as f64 + rng.uniform()) / SECTORS as f64;
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Histogram of the walk's exits against the estimated density integrated over each bin
/// (by Monte Carlo): every bin within 4.5 standard errors, and the integral over the
/// sphere 1 (the face is lossless) within 4.
fn check(face: Face, dir: DVec3, pol: Option<Polarization>) {
    let n = 200_000u64;
    let mut counts = [0.0f64; BANDS * SECTORS];
    for i in 0..n {
        let mut rng = PhotonRng::new(21, i);
        let mut p = pol;
        let (d, _) = scatter_carrying(
            face.alpha,
            face.indices,
            face.normal,
            dir,
            p.as_mut(),
            &mut rng,
        );
        counts[bin_of(d)] += 1.0;
    }
    let omega = 4.0 * PI / (BANDS * SECTORS) as f64;
    let k = 3000u64;
    let (mut total, mut total_var) = (0.0, 0.0);
    for (b, &count) in counts.iter().enumerate() {
        let mut rng = PhotonRng::new(22, b as u64);
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..k {
            let out = in_bin(b, &mut rng);
            let f = face.exit_density(dir, pol, out, &|_| 1.0, &mut rng) * omega;
            (s, s2) = (s + f, s2 + f * f);
        }
        let mean = s / k as f64;
        let var_est = (s2 / k as f64 - mean * mean).max(0.0) / k as f64;
        let frac = count / n as f64;
        let var_hist = frac * (1.0 - frac) / n as f64;
        let sigma = (var_est + var_hist).sqrt().max(1e-12);
        assert!(
            (frac - mean).abs() < 4.5 * sigma,
            "bin {b}: walk {frac:.5}, density {mean:.5} ± {sigma:.5}"
        );
        (total, total_var) = (total + mean, total_var + var_est);
    }
    assert!(
        (total - 1.0).abs() < 4.0 * total_var.sqrt() + 1e-3,
        "integral {total} ± {}",
        total_var.sqrt()
    );
}

fn at(theta_deg: f64, from_inside: bool) -> DVec3 {
    let t = theta_deg.to_radians();
    DVec3::new(t.sin(), 0.0, if from_inside { t.cos() } else { -t.cos() })
}

const PET: Face = Face {
    alpha: 0.6,
    indices: (1.58, 1.0),
    normal: DVec3::Z,
};

#[test]
fn density_matches_the_walk_from_inside() {
    check(PET, at(20.0, true), None);
}

#[test]
fn density_matches_the_walk_from_outside_at_a_slant() {
    check(PET, at(60.0, false), None);
}

#[test]
fn density_matches_the_walk_of_polarized_light_on_a_very_rough_face() {
    let dir = at(35.0, true);
    let pol = Polarization {
        stokes: Stokes::linear_deg(30.0),
        u: crate::optics::polarization::any_frame(dir),
    };
    check(Face { alpha: 1.5, ..PET }, dir, Some(pol));
}
