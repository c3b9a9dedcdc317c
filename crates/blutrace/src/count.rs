//! Counts as engineers write them on a command line: `400000`, `1_000_000`, `1e5`,
//! `2.5e6` (the way the README and the printed reports write photon counts).
//!
//! ```text
//! blutrace trace scenes/notebook14 --photons 2e6
//! blutrace optimize scenes/phone-led --photons 5e5 --verify-photons 0
//! ```
//!
//! A count is a whole number: `1.5` or `1e-3` is an error, and so is anything past
//! `u64::MAX`. Parsed exactly (the mantissa's digits and the exponent as integers), so
//! `123456789012345678e0` is that integer, not the nearest f64.

/// Parse a number option (`--target-cv 0.03`, `--max-time 60`): a finite number; `NaN`
/// and `inf` are refused here, so no option downstream sees one.
pub fn parse_finite(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!("{text:?} is not a finite number")),
        Err(_) => Err(format!("{text:?} is not a number")),
    }
}

/// Parse a count (`0` allowed): digits with optional `_` separators, an optional
/// fraction and an optional `e` exponent, whose value must be a whole number.
pub fn parse_count(text: &str) -> Result<u64, String> {
    let s = text.trim().replace('_', "");
    let bad = || format!("{text:?} is not a count (write e.g. 400000, 1_000_000, 1e5 or 2.5e6)");
    let (mantissa, exp) = match s.split_once(['e', 'E']) {
        Some((m, e)) => (m, e.parse::<i32>().map_err(|_| bad())?),
        None => (s.as_str(), 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = format!("{int}{frac}");
    if int.is_empty() && frac.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(bad());
    }
    // value = digits * 10^(exp - frac.len())
    let shift = exp as i64 - frac.len() as i64;
    let digits = digits.trim_start_matches('0');
    let (kept, dropped) = if shift >= 0 {
        (digits.to_string() + &"0".repeat(shift.min(40) as usize), "")
    } else {
        let cut = digits.len().saturating_sub(shift.unsigned_abs() as usize);
        (digits[..cut].to_string(), &digits[cut..])
    };
    if dropped.bytes().any(|b| b != b'0') {
        return Err(format!("{text:?}: a count must be a whole number"));
    }
    if kept.is_empty() {
        return Ok(0);
    }
    kept.parse::<u64>()
        .map_err(|_| format!("{text:?} is too large (at most {})", u64::MAX))
}

/// [`parse_count`], at least 1: a photon budget of zero traces nothing to report.
pub fn parse_photons(text: &str) -> Result<u64, String> {
    match parse_count(text)? {
        0 => Err(format!("{text:?}: at least 1 photon")),
        n => Ok(n),
    }
}

/// [`parse_count`], from 1 to 1000: rounds of a benchmark.
pub fn parse_rounds(text: &str) -> Result<usize, String> {
    match parse_count(text)? {
        n @ 1..=1000 => Ok(n as usize),
        n => Err(format!("{n} rounds: give 1 to 1000")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_read_as_written() {
        for (text, want) in [
            ("400000", 400_000),
            ("1_000_000", 1_000_000),
            ("1e5", 100_000),
            ("1E5", 100_000),
            ("2.5e6", 2_500_000),
            ("2.50e1", 25),
            ("0", 0),
            ("0.0e3", 0),
            ("007", 7),
            ("1.0", 1),
            ("123456789012345678e0", 123_456_789_012_345_678),
            ("18446744073709551615", u64::MAX),
            ("1e19", 10_000_000_000_000_000_000),
        ] {
            assert_eq!(parse_count(text), Ok(want), "{text}");
        }
    }

    #[test]
    fn fractions_signs_and_overflow_are_refused() {
        for text in [
            "1.5",
            "1e-3",
            "2.55e1",
            "-1",
            "+",
            "",
            "e5",
            "1e",
            "0x10",
            "1e20",
            "18446744073709551616",
            "1,000",
            "nan",
            "inf",
            "1e99999999999",
        ] {
            assert!(parse_count(text).is_err(), "{text}");
        }
        assert!(
            parse_photons("0")
                .unwrap_err()
                .contains("at least 1 photon")
        );
        assert_eq!(parse_photons("1e0"), Ok(1));
    }
}
