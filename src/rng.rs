//! Per-photon random streams.
//!
//! Photon `i` of a run with seed `s` draws from PCG32 stream `i` started at a state hashed
//! from `s`: its numbers depend on `(s, i)` only, never on which thread traced it or what
//! was traced before, so any thread count or sharding gives bit-identical results.

use rand::Rng;
use rand_pcg::Pcg32;

/// The random stream of one photon.
pub struct PhotonRng(Pcg32);

impl PhotonRng {
    /// The stream of photon `index` in a run seeded with `seed`.
    pub fn new(seed: u64, index: u64) -> Self {
        Self(Pcg32::new(splitmix64(seed), index))
    }

    /// A uniform number in `[0, 1)` with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// SplitMix64 finalizer: spreads a user seed over the whole state space.
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
}
