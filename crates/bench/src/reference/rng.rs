//! The reference kernel's random numbers: xoshiro128++ (Blackman and Vigna, "Scrambled
//! linear pseudorandom number generators", ACM TOMS 47, 2021), one start per photon.

/// xoshiro128++ with a per-photon start.
pub(super) struct Rng([u32; 4]);

impl Rng {
    /// Photon `index`'s generator under `key`, SplitMix64 of the seed.
    #[inline]
    pub(super) fn new(key: u64, index: u64) -> Self {
        let a = splitmix64(key ^ index);
        let b = splitmix64(a ^ 0xD1B5_4A32_D192_ED03);
        let s = [a as u32, (a >> 32) as u32, b as u32, (b >> 32) as u32];
        Rng(if s == [0; 4] { [1, 0, 0, 0] } else { s })
    }

    #[inline]
    pub(super) fn next_u32(&mut self) -> u32 {
        let s = &mut self.0;
        let out = s[0].wrapping_add(s[3]).rotate_left(7).wrapping_add(s[0]);
        let t = s[1] << 9;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(11);
        out
    }

    /// A uniform number in `[0, 1)` with 24 random bits.
    #[inline]
    pub(super) fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// SplitMix64's finalizer (Steele, Lea and Flood 2014): a bijective 64-bit mixer.
pub(super) fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
