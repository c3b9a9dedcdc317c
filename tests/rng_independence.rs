//! Photons are independent: the random streams of different photons show no relation
//! that a seed-to-seed spread or a neighbour correlation can detect.
//!
//! Each check is also run on the construction blutrace used before (PCG32 streams that
//! share one starting state and differ only in their increment) as a negative control:
//! the checks must catch it, or they would pass with the streams wrong.

mod support;

use blutrace::rng::PhotonRng;
use rand::Rng;
use rand_pcg::Pcg32;
use rayon::prelude::*;
use support::chi2_quantile;

/// Photons per seed and seeds for the spread test.
const PHOTONS: u64 = 131_072;
const SEEDS: u64 = 1024;
/// The draws whose distribution over photons is checked (1-based).
const DRAWS: [usize; 4] = [1, 2, 8, 30];
/// Threshold of the "draw below p" indicator.
const P: f64 = 0.35;

/// A stream constructor: (seed, photon index) -> the photon's uniforms.
type Streams = fn(u64, u64) -> Box<dyn FnMut() -> f64>;

fn blutrace_streams(seed: u64, index: u64) -> Box<dyn FnMut() -> f64> {
    let mut r = PhotonRng::new(seed, index);
    Box::new(move || r.uniform())
}

/// The old construction: one shared state per seed, the photon index as PCG32 stream.
fn shared_state_streams(seed: u64, index: u64) -> Box<dyn FnMut() -> f64> {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    let mut r = Pcg32::new(z ^ (z >> 31), index);
    Box::new(move || (r.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64))
}

/// The `DRAWS` uniforms of one photon.
fn draws(streams: Streams, seed: u64, index: u64) -> [f64; 4] {
    let mut next = streams(seed, index);
    let mut out = [0.0; 4];
    for k in 1..=DRAWS[3] {
        let u = next();
        if let Some(j) = DRAWS.iter().position(|&d| d == k) {
            out[j] = u;
        }
    }
    out
}

/// For each of `DRAWS`: the seed-to-seed spread of the count of photons whose draw is
/// below `P`, as a chi-square over seeds divided by its degrees of freedom (1 for
/// binomial spread).
fn spread_ratios(streams: Streams) -> [f64; 4] {
    let counts: Vec<[u64; 4]> = (0..SEEDS)
        .into_par_iter()
        .map(|seed| {
            let mut c = [0u64; 4];
            for i in 0..PHOTONS {
                for (cj, u) in c.iter_mut().zip(draws(streams, seed, i)) {
                    *cj += u64::from(u < P);
                }
            }
            c
        })
        .collect();
    let n = PHOTONS as f64;
    let var = n * P * (1.0 - P);
    std::array::from_fn(|j| {
        let chi2: f64 = counts
            .iter()
            .map(|c| (c[j] as f64 - n * P).powi(2) / var)
            .sum();
        chi2 / SEEDS as f64
    })
}

/// The central 99.9 % of chi-square / dof for `dof` degrees of freedom.
fn acceptance(dof: f64) -> (f64, f64) {
    (
        chi2_quantile(dof, -3.29) / dof,
        chi2_quantile(dof, 3.29) / dof,
    )
}

#[test]
fn seed_to_seed_spread_is_binomial_for_every_draw() {
    let (lo, hi) = acceptance(SEEDS as f64);
    let ratios = spread_ratios(blutrace_streams);
    for (k, r) in DRAWS.iter().zip(ratios) {
        assert!(
            r > lo && r < hi,
            "draw {k}: spread / binomial = {r:.3}, outside [{lo:.3}, {hi:.3}]"
        );
    }
    // Negative control: the shared-state streams do not spread binomially (less at the
    // first draws, more at later ones).
    let old = spread_ratios(shared_state_streams);
    eprintln!("spread / binomial: {ratios:.3?}; shared-state streams {old:.3?}");
    for (k, r) in DRAWS.iter().zip(old) {
        assert!(
            r < lo || r > hi,
            "the check misses the shared-state streams at draw {k} (ratio {r:.3})"
        );
    }
}

/// Pearson correlations of the `DRAWS` uniforms of photons `i` and `i + lag`, over
/// `n` photons, as z-scores (standard normal for independent photons).
fn neighbour_z_scores(streams: Streams, seed: u64, n: u64, lags: &[u64]) -> Vec<f64> {
    let max_lag = *lags.iter().max().unwrap();
    let u: Vec<[f64; 4]> = (0..n + max_lag)
        .into_par_iter()
        .map(|i| draws(streams, seed, i))
        .collect();
    let mut z = Vec::new();
    for &lag in lags {
        let pairs = u.iter().zip(&u[lag as usize..]).take(n as usize);
        let mut cov = [0.0; 4];
        for (a, b) in pairs {
            for (c, (x, y)) in cov.iter_mut().zip(a.iter().zip(b)) {
                *c += (x - 0.5) * (y - 0.5);
            }
        }
        // Uniforms have mean 1/2 and variance 1/12 exactly.
        z.extend(cov.iter().map(|c| c / n as f64 * 12.0 * (n as f64).sqrt()));
    }
    z
}

#[test]
fn neighbouring_photons_are_uncorrelated() {
    const N: u64 = 1 << 20;
    let lags = [1, 4096, 131_072];
    let check = |streams: Streams| -> f64 {
        // Sum of squared z-scores over seeds, lags and draws: chi-square.
        (1..=4)
            .flat_map(|seed| neighbour_z_scores(streams, seed, N, &lags))
            .map(|z| z * z)
            .sum()
    };
    let dof = (4 * lags.len() * DRAWS.len()) as f64;
    let limit = chi2_quantile(dof, 3.29);
    let chi2 = check(blutrace_streams);
    assert!(
        chi2 < limit,
        "neighbour correlations: chi-square {chi2:.1} > {limit:.1} ({dof} dof)"
    );
    let old = check(shared_state_streams);
    eprintln!("neighbour chi-square {chi2:.1}, shared-state streams {old:.1} ({dof} dof)");
    assert!(
        old > limit,
        "the check misses the shared-state streams (chi-square {old:.1})"
    );
}
