//! Correlated colour temperature: the temperature of the Planckian radiator nearest in the
//! CIE 1960 UCS diagram (CIE 015:2018 §9.5), and the signed distance Δuv from its locus.

use std::sync::OnceLock;

use super::spectrum::Spectrum;
use super::tristimulus::{UvPrime, Xyz};

/// The range searched, in K: 1000 K to 100000 K.
const RANGE_K: (f64, f64) = (1000.0, 100_000.0);
/// Ratio of neighbouring temperatures of the coarse table (1 %, as in Ohno 2014).
const COARSE_RATIO: f64 = 1.01;
/// Points of each refinement of the cascade.
const CASCADE_POINTS: usize = 10;
/// The cascade stops when its bracket is narrower than this, in K.
const TOLERANCE_K: f64 = 1e-3;

/// A correlated colour temperature and the chromaticity's distance from the Planckian locus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cct {
    /// The temperature of the nearest Planckian chromaticity, in K.
    pub kelvin: f64,
    /// The CIE 1960 (u, v) distance to it, positive above the locus (greener), negative
    /// below (pinker), as Ohno (2014) signs it.
    pub delta_uv: f64,
}

/// The CIE 1960 (u, v) of a blackbody at `kelvin` ([`Spectrum::blackbody`] integrated against
/// the 1 nm colour-matching functions).
pub fn planckian_uv(kelvin: f64) -> [f64; 2] {
    Xyz::of(&Spectrum::blackbody(kelvin))
        .uv_prime()
        .expect("a blackbody has a chromaticity")
        .uv_1960()
}

/// The CCT of chromaticity `uv` and its Δuv, or None if the nearest Planckian temperature is
/// outside 1000-100000 K.
///
/// Ohno's (2014) cascade: the nearest entry of a table of the locus at 1 % steps brackets the
/// answer between its neighbours; that bracket is divided into `CASCADE_POINTS` steps, and
/// the nearest point's neighbours are the next bracket, until it is narrower than 0.001 K.
/// Every point of the locus is computed from Planck's law and the CMFs, so the CCT is the
/// minimum-distance one of the definition, to the precision of the tables.
pub fn cct(uv_prime: UvPrime) -> Option<Cct> {
    let target = uv_prime.uv_1960();
    let table = coarse_table();
    let nearest = argmin(table.iter().map(|&(_, uv)| distance(uv, target)));
    if nearest == 0 || nearest == table.len() - 1 {
        return None;
    }
    let (mut lo, mut hi) = (table[nearest - 1].0, table[nearest + 1].0);
    while hi - lo > TOLERANCE_K {
        let step = (hi - lo) / CASCADE_POINTS as f64;
        let points = (0..=CASCADE_POINTS).map(|i| lo + step * i as f64);
        let i = argmin(points.map(|t| distance(planckian_uv(t), target)));
        (lo, hi) = (
            lo + step * i.saturating_sub(1) as f64,
            lo + step * (i + 1).min(CASCADE_POINTS) as f64,
        );
    }
    let kelvin = 0.5 * (lo + hi);
    let locus = planckian_uv(kelvin);
    let delta_uv = distance(locus, target).copysign(target[1] - locus[1]);
    Some(Cct { kelvin, delta_uv })
}

/// The locus at 1000 K, 1010 K, ... (1 % steps) up to 100000 K, built once.
fn coarse_table() -> &'static [(f64, [f64; 2])] {
    static TABLE: OnceLock<Vec<(f64, [f64; 2])>> = OnceLock::new();
    TABLE.get_or_init(|| {
        std::iter::successors(Some(RANGE_K.0), |t| Some(t * COARSE_RATIO))
            .take_while(|&t| t <= RANGE_K.1)
            .map(|t| (t, planckian_uv(t)))
            .collect()
    })
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The index of the smallest value (the first of equals).
fn argmin(values: impl Iterator<Item = f64>) -> usize {
    values
        .enumerate()
        .fold(
            (0, f64::INFINITY),
            |best, (i, d)| if d < best.1 { (i, d) } else { best },
        )
        .0
}
