//! Float-to-integer rounding without a call into libm.
//!
//! The x86-64 baseline has no rounding instruction (`roundsd` is SSE4.1), so `f64::floor`
//! and `f64::round` are calls into the C library; the dot and groove lookups round on
//! every hit of a patterned face (about 1 % of a photon on bench-box). A conversion
//! truncates toward zero in one instruction, and these fix it up to the same integer
//! `floor` and `round` give (checked against them in the tests), so outputs do not change.

/// `x.floor() as i64` for finite `x` of magnitude below 2^62 (NaN gives 0, as there).
#[inline]
pub fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    t - ((t as f64) > x) as i64
}

/// `x.round() as i64` (halves away from zero) for finite `x` of magnitude below 2^52.
#[inline]
pub fn round_i64(x: f64) -> i64 {
    let t = x as i64;
    // Exact: `t` and `x` share their integer part, so the difference is `x`'s fraction.
    let frac = x - t as f64;
    // Flags, not branches: which way a hit's coordinate rounds is a coin toss.
    t + i64::from(frac >= 0.5) - i64::from(frac <= -0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples() -> Vec<f64> {
        let mut v = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
            1.0 - f64::EPSILON / 2.0,
            -1.0 + f64::EPSILON / 2.0,
            4503599627370495.5,
            -4503599627370495.5,
            1e15 + 0.5,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        // A spread of magnitudes and fractions, integers and their neighbours.
        let mut x = 0.37_f64;
        for _ in 0..20000 {
            x = (x * 1.61803398875 + 0.1234567).fract();
            let scale = 10f64.powi((x * 31.0) as i32 - 15);
            v.push((x - 0.5) * scale);
            let k = ((x - 0.5) * 2000.0).round();
            v.extend([
                k,
                k.next_up(),
                k.next_down(),
                k + 0.5,
                (k + 0.5).next_down(),
            ]);
        }
        v
    }

    #[test]
    fn floor_matches_libm() {
        for x in samples() {
            assert_eq!(floor_i64(x), x.floor() as i64, "floor {x:e}");
        }
        assert_eq!(floor_i64(f64::NAN), f64::NAN.floor() as i64);
    }

    #[test]
    fn round_matches_libm() {
        for x in samples() {
            assert_eq!(round_i64(x), x.round() as i64, "round {x:e}");
        }
    }
}
