//! Per-photon random streams.
//!
//! Photon `i` of a run with seed `s` draws from a PCG64 generator (128-bit LCG, XSL-RR
//! output) whose 128-bit starting state is a strong hash of `(s, i)`. Its numbers depend
//! on `(s, i)` only, never on which thread traced it or what was traced before, so any
//! thread count or sharding gives bit-identical results.
//!
//! Why a hashed state and not one stream per photon: streams of one LCG that share a
//! starting state and differ only in their increment are closely related (the first
//! states of consecutive streams are evenly spaced), which made the draws of neighbouring
//! photons behave like a stratified sequence and the reported errors too small. Here the
//! starting points are scattered over a cycle of 2^128 states: for a fixed seed,
//! `index -> state` is injective (SplitMix64's finalizer is a bijection), and two photons
//! share part of their draws only if their starting states fall within a few thousand
//! steps of each other, with probability about `n^2 * 2^12 / 2^128` for `n` photons.
//! This is how Mitsuba seeds each lane (a hash of seed and index into PCG's state).

use rand::Rng;
use rand_pcg::Pcg64;

/// PCG's default increment: one fixed stream, hashed starting points on it.
const STREAM: u128 = 0x0a02_bdbf_7bb3_c0a7_ac28_fa16_a64a_bf96;
/// The side stream's increment (odd, as PCG needs; another stream of the same states).
const SIDE_STREAM: u128 = 0x5851_f42d_4c95_7f2d_1405_7b7e_f767_814f;
/// Odd constant that separates the two 64-bit halves of a photon's starting state.
const HALF_KEY: u64 = 0xD1B5_4A32_D192_ED03;

/// The random stream of one photon.
pub struct PhotonRng(Pcg64);

impl PhotonRng {
    /// The stream of photon `index` in a run seeded with `seed`.
    pub fn new(seed: u64, index: u64) -> Self {
        Self(Pcg64::new(start_state(seed, index), STREAM))
    }

    /// A second stream of photon `index`, independent of [`PhotonRng::new`]'s (another
    /// PCG stream increment): the luminance meter's peel-off draws from it, so the
    /// photon's own path is the same whichever luminance estimator runs.
    pub fn side_stream(seed: u64, index: u64) -> Self {
        Self(Pcg64::new(start_state(seed, index), SIDE_STREAM))
    }

    /// A uniform number in `[0, 1)` with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The 128-bit starting state of photon `index` under `seed`: two independent keys from
/// the seed, each XORed with the index and finalized, so every bit of the state depends
/// on every bit of both.
fn start_state(seed: u64, index: u64) -> u128 {
    let k_hi = splitmix64(seed);
    let k_lo = splitmix64(seed ^ HALF_KEY);
    let hi = splitmix64(k_hi ^ index);
    let lo = splitmix64(k_lo ^ index.rotate_left(32));
    (u128::from(hi) << 64) | u128::from(lo)
}

/// SplitMix64: a bijective 64-bit mixer (Steele, Lea and Flood 2014).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_depends_only_on_seed_and_index() {
        let a: Vec<f64> = (0..4).map(|_| PhotonRng::new(7, 3).uniform()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        let mut x = PhotonRng::new(7, 3);
        let mut y = PhotonRng::new(7, 4);
        assert_ne!(x.uniform(), y.uniform());
    }

    #[test]
    fn uniform_in_unit_interval() {
        let mut r = PhotonRng::new(1, 0);
        for _ in 0..10_000 {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
        }
    }

    #[test]
    fn starting_states_differ_for_every_index_of_a_seed() {
        let mut states: Vec<u128> = (0..200_000).map(|i| start_state(9, i)).collect();
        states.sort_unstable();
        states.dedup();
        assert_eq!(states.len(), 200_000);
        assert_ne!(start_state(1, 5), start_state(2, 5));
    }
}
