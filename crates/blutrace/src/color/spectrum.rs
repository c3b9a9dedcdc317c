//! [`Spectrum`]: a tabulated spectral quantity, linear between rows and zero outside them.

use std::fmt;

/// Planck's constant h, in J·s (exact in the SI since 2019).
const PLANCK_H: f64 = 6.626_070_15e-34;
/// The speed of light in vacuum c, in m/s (exact).
const LIGHT_C: f64 = 299_792_458.0;
/// The second radiation constant c2 = hc/k that CIE 015:2018 (§9.5, after ITS-90) uses for
/// the Planckian locus, in nm·K (1.4388e-2 m·K).
pub const C2_NM_K: f64 = 1.4388e7;
/// First and last wavelength of [`Spectrum::blackbody`], in nm: the range of the CIE 1931
/// colour-matching functions.
const BLACKBODY_RANGE_NM: (f64, f64) = (360.0, 830.0);

/// What is wrong with a spectral table, in words; the caller adds the file and the field.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SpectrumError(String);

impl fmt::Display for SpectrumError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SpectrumError {}

/// A non-negative spectral quantity tabulated over wavelength: a spectral power distribution
/// (relative or absolute, per nm), a colour-matching function, a reflectance.
///
/// Between rows it is linear; outside the first and last row it is **zero**, not clamped: a
/// source's table says where it emits, and light outside it is none (the CIE's own data sets
/// declare the same: linear interpolation, zero extrapolation). A table whose ends are not near
/// zero therefore ends in a step.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    nm: Vec<f64>,
    value: Vec<f64>,
}

impl Spectrum {
    /// A spectrum of rows `[nm, value]`: at least two, wavelengths finite, positive and
    /// strictly increasing, values finite and non-negative.
    pub fn from_rows(rows: &[[f64; 2]]) -> Result<Spectrum, SpectrumError> {
        if rows.len() < 2 {
            return Err(SpectrumError(format!(
                "a spectrum needs at least two rows [nm, value], got {}",
                rows.len()
            )));
        }
        for (i, &[nm, value]) in rows.iter().enumerate() {
            check_row(i, nm, value, i.checked_sub(1).map(|p| rows[p][0]))?;
        }
        Ok(Spectrum {
            nm: rows.iter().map(|r| r[0]).collect(),
            value: rows.iter().map(|r| r[1]).collect(),
        })
    }

    /// A spectrum tabulated at `first_nm`, `first_nm + step_nm`, ... (one row per value),
    /// with the checks of [`Spectrum::from_rows`].
    pub fn uniform(first_nm: f64, step_nm: f64, values: &[f64]) -> Result<Spectrum, SpectrumError> {
        let rows: Vec<[f64; 2]> = values
            .iter()
            .enumerate()
            .map(|(i, &v)| [first_nm + step_nm * i as f64, v])
            .collect();
        Spectrum::from_rows(&rows)
    }

    /// Planck's law: the spectral radiance of a blackbody at `kelvin`, in W/(m²·sr·nm), at
    /// every 1 nm from 360 to 830 nm. L(λ) = c1L λ⁻⁵ / (exp(c2/(λT)) − 1) with c1L = 2hc²
    /// and c2 = [`C2_NM_K`] (CIE 015:2018 §9.5).
    ///
    /// # Panics
    /// If `kelvin` is not finite and positive.
    pub fn blackbody(kelvin: f64) -> Spectrum {
        assert!(
            kelvin.is_finite() && kelvin > 0.0,
            "blackbody at {kelvin} K"
        );
        let (first, last) = BLACKBODY_RANGE_NM;
        let count = (last - first) as usize + 1;
        let c1l = 2.0 * PLANCK_H * LIGHT_C * LIGHT_C; // W·m²/sr
        let value = (0..count)
            .map(|i| {
                let nm = first + i as f64;
                let m = nm * 1e-9;
                c1l / m.powi(5) / (C2_NM_K / (nm * kelvin)).exp_m1() * 1e-9
            })
            .collect();
        Spectrum {
            nm: (0..count).map(|i| first + i as f64).collect(),
            value,
        }
    }

    /// The value at `nm`: linear between rows, zero outside the table.
    pub fn at(&self, nm: f64) -> f64 {
        let (first, last) = self.range_nm();
        if !(first..=last).contains(&nm) {
            return 0.0;
        }
        let i = self.nm.partition_point(|&k| k <= nm).min(self.nm.len() - 1);
        if i == 0 || self.nm[i - 1] == nm {
            return self.value[i.saturating_sub(1)];
        }
        let (a, b) = (self.nm[i - 1], self.nm[i]);
        let t = (nm - a) / (b - a);
        self.value[i - 1] + t * (self.value[i] - self.value[i - 1])
    }

    /// The first and last tabulated wavelength, in nm.
    pub fn range_nm(&self) -> (f64, f64) {
        (self.nm[0], self.nm[self.nm.len() - 1])
    }

    /// The rows `[nm, value]`.
    pub fn rows(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.nm.iter().zip(&self.value).map(|(&n, &v)| [n, v])
    }

    /// This spectrum times `factor` (finite, non-negative) at every wavelength.
    pub fn scaled(&self, factor: f64) -> Spectrum {
        assert!(factor.is_finite() && factor >= 0.0, "scale factor {factor}");
        Spectrum {
            nm: self.nm.clone(),
            value: self.value.iter().map(|v| v * factor).collect(),
        }
    }

    /// This spectrum divided by its largest value (`None` if every value is zero): the
    /// same distribution at a scale where integrals of it and products with it neither
    /// overflow (values near 1e306 summed over 400 nm) nor lose digits to subnormals.
    /// Dividing, not multiplying by the reciprocal, which overflows for a subnormal peak.
    pub fn normalized(&self) -> Option<Spectrum> {
        let peak = self.value.iter().copied().fold(0.0, f64::max);
        (peak > 0.0).then(|| Spectrum {
            nm: self.nm.clone(),
            value: self.value.iter().map(|v| v / peak).collect(),
        })
    }

    /// ∫ S(λ) dλ over the table (exact for the linear interpolant), in value·nm.
    pub fn integral(&self) -> f64 {
        self.rows()
            .zip(self.rows().skip(1))
            .map(|([a, fa], [b, fb])| 0.5 * (b - a) * (fa + fb))
            .sum()
    }

    /// ∫ S(λ) O(λ) dλ of this spectrum S and `other` O: the exact integral of the product of
    /// the two linear interpolants, segment by segment on the union of both tables' knots
    /// where both are tabulated (the product is zero elsewhere). On a shared uniform grid it
    /// differs from the CIE's summation Σ S O Δλ (see [`Spectrum::sum_product`]) only by the
    /// curvature term O(Δλ²), and it needs no common grid.
    pub fn integrate_product(&self, other: &Spectrum) -> f64 {
        let lo = self.nm[0].max(other.nm[0]);
        let hi = self.range_nm().1.min(other.range_nm().1);
        if lo >= hi {
            return 0.0;
        }
        let knots = union_knots(&self.nm, &other.nm, lo, hi);
        let f: Vec<[f64; 2]> = knots.iter().map(|&k| [self.at(k), other.at(k)]).collect();
        knots
            .windows(2)
            .zip(f.windows(2))
            .map(|(k, fg)| {
                let ([fa, ga], [fb, gb]) = (fg[0], fg[1]);
                (k[1] - k[0]) / 6.0 * (2.0 * fa * ga + fa * gb + fb * ga + 2.0 * fb * gb)
            })
            .sum()
    }

    /// The CIE's summation (CIE 015:2018 §7.1): Σ S(λᵢ) O(λᵢ) Δλ over λᵢ = `first_nm`,
    /// `first_nm + step_nm`, ... up to `last_nm`, both read by linear interpolation. The
    /// published colorimetric values of CIE 15 were computed this way at 5 nm.
    pub fn sum_product(&self, other: &Spectrum, first_nm: f64, step_nm: f64, last_nm: f64) -> f64 {
        assert!(step_nm > 0.0 && last_nm >= first_nm, "summation grid");
        let count = ((last_nm - first_nm) / step_nm + 1e-9).floor() as usize + 1;
        (0..count)
            .map(|i| first_nm + step_nm * i as f64)
            .map(|nm| self.at(nm) * other.at(nm) * step_nm)
            .sum()
    }
}

/// Checks row `i` of a table (`previous` is the wavelength of the row before it).
fn check_row(i: usize, nm: f64, value: f64, previous: Option<f64>) -> Result<(), SpectrumError> {
    let row = i + 1;
    if !nm.is_finite() || nm <= 0.0 {
        return Err(SpectrumError(format!(
            "row {row}: wavelength {nm} nm is not a finite positive number"
        )));
    }
    if let Some(p) = previous.filter(|&p| nm <= p) {
        return Err(SpectrumError(format!(
            "row {row}: wavelengths must increase strictly, but {nm} nm follows {p} nm"
        )));
    }
    if !value.is_finite() || value < 0.0 {
        return Err(SpectrumError(format!(
            "row {row} ({nm} nm): value {value} is not a finite non-negative number"
        )));
    }
    Ok(())
}

/// The sorted, deduplicated knots of `a` and `b` inside `[lo, hi]`, with `lo` and `hi`.
fn union_knots(a: &[f64], b: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let mut knots: Vec<f64> = std::iter::once(lo)
        .chain(a.iter().chain(b).copied().filter(|&k| k > lo && k < hi))
        .chain(std::iter::once(hi))
        .collect();
    knots.sort_by(f64::total_cmp);
    knots.dedup();
    knots
}
