//! The home of wavelength: what a photon carries of its source's light ([`Light`]: its
//! wavelength) and the optical quantities read at it ([`Spectral`]), with their scene-file
//! form ([`SpectralValue`]).
//!
//! ```toml
//! [media.pmma]
//! n = { sellmeier = { b = [1.1819], c_um2 = [0.011313] } }   # or 1.49, or a table
//! absorption_per_mm = { table = [[400, 0.0009], [550, 0.0002], [700, 0.0004]] }
//!
//! [surfaces.sheet]
//! model = "lambert"
//! albedo = { table = [[380, 0.86], [780, 0.95]] }             # or one number
//! ```
//!
//! A number is the same at every wavelength; `{ table = [[nm, value], ...] }` is linear
//! between rows and holds its end rows' values beyond them (a material does not stop
//! existing outside its table); `{ cauchy = [A, B, C, ...] }` is n = A + B/λ² + C/λ⁴ + ...
//! and `{ sellmeier = { b = [...], c_um2 = [...] } }` is n² = 1 + Σ bᵢ λ²/(λ² − cᵢ), both
//! with λ in µm. Tables and formulas are read at 1 nm from 360 to 830 nm (the range of the
//! CIE colour-matching functions) and linearly between: exact for tables whose rows lie on
//! whole nanometres, within 1e-6 in n for the dispersion formulas of optical glasses and
//! polymers.
//!
//! Read through here: a medium's refractive index and absorption
//! ([`super::medium::Medium::index`], [`super::medium::Medium::absorption`]), every
//! reflectance and albedo of the surface models (lambert `albedo`, dots `ink_albedo`,
//! mirror and phong `reflectance`) and the weight a detection scores ([`Light::detected`]).
//! A photon of a monochrome scene (no source spectrum) carries [`Light::MONOCHROME`], and
//! a table in such a scene is read at its wavelength. A photon of a spectral source
//! carries [`WAVELENGTHS`] wavelengths along one path: [`Light`] is its hero, and the
//! others ride along as [`Secondaries`] (hero-wavelength sampling, `hero`).

mod hero;

pub use hero::{Secondaries, WAVELENGTHS};

use crate::color::cie_cmf::{CMF_FIRST_NM, CMF_STEP_NM};
use crate::spec_check::{Ctx, short};
use anyhow::Result;
use serde::{Deserialize, Deserializer, Serialize};
use std::sync::Arc;

/// What a photon carries of its source's emission, besides its weight: its wavelength in
/// air, in nm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    nm: f64,
}

/// The wavelength at which a monochrome scene's tables are read (nm): the peak of the
/// photopic V(λ), where a monochrome scene's lumens are meant.
pub const MONOCHROME_NM: f64 = 555.0;

impl Light {
    /// The one light of a monochrome scene ([`MONOCHROME_NM`]).
    pub const MONOCHROME: Light = Light { nm: MONOCHROME_NM };

    /// Light of wavelength `nm` (in air).
    #[inline]
    pub const fn at_nm(nm: f64) -> Light {
        Light { nm }
    }

    /// Its wavelength in air (nm).
    #[inline]
    pub fn nm(self) -> f64 {
        self.nm
    }

    /// The weight a detection of a photon of this light and weight `weight` scores in the
    /// radiant tallies (all of it: radiant power does not depend on the wavelength).
    #[inline]
    pub fn detected(self, weight: f64) -> f64 {
        weight
    }
}

/// Wavelengths a [`Spectral`] table holds: 1 nm from [`CMF_FIRST_NM`] (360 nm) to 830 nm.
const GRID_LEN: usize = 471;

/// An optical quantity that may depend on wavelength: one value, or a table read at a
/// photon's [`Light`]. Written to reports as its nominal value.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectral {
    /// The same value at every wavelength.
    Constant(f64),
    /// Values at 1 nm from 360 to 830 nm, linear between, the end values beyond.
    Sampled(Arc<[f64]>),
}

impl Spectral {
    /// The same `value` at every wavelength.
    pub const fn constant(value: f64) -> Spectral {
        Spectral::Constant(value)
    }

    /// A quantity given by `f(nm)` on the 1 nm grid from 360 to 830 nm.
    pub fn sampled(f: impl Fn(f64) -> f64) -> Spectral {
        Spectral::Sampled((0..GRID_LEN).map(|i| f(grid_nm(i))).collect())
    }

    /// The value for a photon of light `light`. Always inlined, with the table's read out
    /// of line: a monochrome scene's constants then cost what a plain `f64` field did
    /// (inlining the table's interpolation into the photon loop slowed bench-box by 7 %).
    #[inline(always)]
    pub fn at(&self, light: Light) -> f64 {
        match self {
            Spectral::Constant(v) => *v,
            Spectral::Sampled(t) => read_grid(t, light.nm),
        }
    }

    /// This quantity times `factor` at every wavelength.
    pub fn scaled(&self, factor: f64) -> Spectral {
        self.map(|v| v * factor)
    }

    /// This quantity plus `other` at every wavelength.
    pub fn plus(&self, other: &Spectral) -> Spectral {
        match (self, other) {
            (Spectral::Constant(a), Spectral::Constant(b)) => Spectral::Constant(a + b),
            _ => Spectral::sampled(|nm| {
                let l = Light::at_nm(nm);
                self.at(l) + other.at(l)
            }),
        }
    }

    /// `f` of this quantity at every wavelength.
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Spectral {
        match self {
            Spectral::Constant(v) => Spectral::Constant(f(*v)),
            Spectral::Sampled(t) => Spectral::Sampled(t.iter().map(|&v| f(v)).collect()),
        }
    }

    /// Whether it varies with wavelength.
    pub fn is_spectral(&self) -> bool {
        matches!(self, Spectral::Sampled(_))
    }

    /// The value reports show (`check`, summaries): the constant, or the value at
    /// [`MONOCHROME_NM`].
    pub fn nominal(&self) -> f64 {
        self.at(Light::MONOCHROME)
    }

    /// The smallest and largest value over 360-830 nm.
    pub fn range(&self) -> (f64, f64) {
        match self {
            Spectral::Constant(v) => (*v, *v),
            Spectral::Sampled(t) => t
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                }),
        }
    }
}

/// The wavelength of grid point `i` (nm).
fn grid_nm(i: usize) -> f64 {
    CMF_FIRST_NM + CMF_STEP_NM * i as f64
}

/// `t` (on the 1 nm grid) at `nm`: linear between grid points, the end values beyond.
/// Out of line: it keeps [`Spectral::at`] a load and one predictable branch where the
/// quantity is constant (monochrome scenes read mu_s, g and mu_a at every free flight),
/// for the price of a call where it is a table.
#[inline(never)]
fn read_grid(t: &[f64], nm: f64) -> f64 {
    let x = ((nm - CMF_FIRST_NM) / CMF_STEP_NM).clamp(0.0, (t.len() - 1) as f64);
    let i = (x as usize).min(t.len() - 2);
    let f = x - i as f64;
    t[i] + f * (t[i + 1] - t[i])
}

impl Serialize for Spectral {
    /// A constant as its number; a table as `{ nm_555, min, max }` (its value at
    /// [`MONOCHROME_NM`] and its range over 360-830 nm).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        match self {
            Spectral::Constant(v) => s.serialize_f64(*v),
            Spectral::Sampled(_) => {
                let (lo, hi) = self.range();
                let mut m = s.serialize_map(Some(3))?;
                m.serialize_entry("nm_555", &self.nominal())?;
                m.serialize_entry("min", &lo)?;
                m.serialize_entry("max", &hi)?;
                m.end()
            }
        }
    }
}

impl std::fmt::Display for Spectral {
    /// A constant as an `f64` is formatted when a precision is given, else in short form
    /// ([`short`]: `1e300`, not 301 digits); a table as its range over 360-830 nm.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Spectral::Constant(v) if f.precision().is_some() => std::fmt::Display::fmt(v, f),
            Spectral::Constant(v) => f.write_str(&short(*v)),
            Spectral::Sampled(_) => {
                let (lo, hi) = self.range();
                write!(f, "{}..{} over 360-830 nm", short(lo), short(hi))
            }
        }
    }
}

impl From<f64> for Spectral {
    fn from(value: f64) -> Spectral {
        Spectral::constant(value)
    }
}

/// A wavelength-dependent quantity as a scene file gives it (see the module header).
// The schema is the one-key tables `deserialize` below reads (a table with another key, or
// with two, is refused there too).
#[derive(Clone, Debug, PartialEq, Serialize, schemars::JsonSchema)]
#[serde(untagged)]
#[schemars(deny_unknown_fields)]
pub enum SpectralValue {
    /// The same at every wavelength.
    Constant(f64),
    /// `{ table = [[nm, value], ...] }`.
    Table {
        /// Rows `[nm, value]`, wavelengths increasing.
        table: Vec<[f64; 2]>,
    },
    /// `{ cauchy = [A, B, C, ...] }`: n = A + B/λ² + C/λ⁴ + ... (λ in µm).
    Cauchy {
        /// The coefficients A, B (µm²), C (µm⁴), ...
        cauchy: Vec<f64>,
    },
    /// `{ sellmeier = { b = [...], c_um2 = [...] } }`.
    Sellmeier {
        /// The terms.
        sellmeier: Sellmeier,
    },
}

/// n² = 1 + Σ bᵢ λ²/(λ² − cᵢ), λ in µm.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sellmeier {
    /// The oscillator strengths bᵢ.
    pub b: Vec<f64>,
    /// The resonance wavelengths squared cᵢ (µm²).
    pub c_um2: Vec<f64>,
}

/// What values a [`SpectralValue`] may take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// A fraction in [0, 1] (a reflectance, an albedo).
    Fraction,
    /// Zero or more (an absorption coefficient).
    NonNegative,
    /// A refractive index, positive (the only kind that may be a dispersion formula).
    Index,
}

impl<'de> Deserialize<'de> for SpectralValue {
    /// A number, or a table with exactly one of `table`, `cauchy`, `sellmeier` (anything
    /// else is an error that says what is allowed).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let allowed = "expected a number, { table = [[nm, value], ...] }, { cauchy = [A, B, ...] } or { sellmeier = { b = [...], c_um2 = [...] } }";
        let v = toml::Value::deserialize(d)?;
        if let Some(x) = v.as_float().or(v.as_integer().map(|i| i as f64)) {
            return Ok(SpectralValue::Constant(x));
        }
        let (key, value) = one_key_table(&v, allowed).map_err(D::Error::custom)?;
        let bad = |e: toml::de::Error| D::Error::custom(format!("{key}: {}", e.message()));
        match key {
            "table" => Ok(SpectralValue::Table {
                table: value.clone().try_into().map_err(bad)?,
            }),
            "cauchy" => Ok(SpectralValue::Cauchy {
                cauchy: value.clone().try_into().map_err(bad)?,
            }),
            "sellmeier" => Ok(SpectralValue::Sellmeier {
                sellmeier: value.clone().try_into().map_err(bad)?,
            }),
            other => Err(D::Error::custom(format!(
                "unknown key '{other}': {allowed}"
            ))),
        }
    }
}

/// The one key and its value of a scene-file table such as `{ table = ... }`, or the
/// error for anything else (`allowed` says what is accepted): how [`SpectralValue`] and a
/// source's spectrum read their forms.
pub(crate) fn one_key_table<'v>(
    v: &'v toml::Value,
    allowed: &str,
) -> Result<(&'v str, &'v toml::Value), String> {
    match v.as_table().filter(|t| t.len() == 1) {
        Some(t) => Ok(t
            .iter()
            .next()
            .map(|(k, v)| (k.as_str(), v))
            .expect("one entry")),
        None => Err(format!("invalid type: {} {v}, {allowed}", v.type_str())),
    }
}

impl From<f64> for SpectralValue {
    fn from(value: f64) -> SpectralValue {
        SpectralValue::Constant(value)
    }
}

impl SpectralValue {
    /// Check the value at `field` (every value it takes over 360-830 nm must be in
    /// `range`) and build the quantity.
    pub fn build(&self, ctx: &Ctx, field: &str, range: Range) -> Result<Spectral> {
        let q = match self {
            SpectralValue::Constant(v) => return check_constant(ctx, field, *v, range),
            SpectralValue::Table { table } => table_quantity(ctx, field, table)?,
            SpectralValue::Cauchy { cauchy } => {
                dispersion(ctx, field, range, || cauchy_quantity(ctx, field, cauchy))?
            }
            SpectralValue::Sellmeier { sellmeier } => {
                dispersion(ctx, field, range, || sellmeier.quantity(ctx, field))?
            }
        };
        check_range(ctx, field, &q, range)?;
        Ok(q)
    }

    /// The value if it is one number.
    pub fn constant(&self) -> Option<f64> {
        match self {
            SpectralValue::Constant(v) => Some(*v),
            _ => None,
        }
    }
}

fn check_constant(ctx: &Ctx, field: &str, v: f64, range: Range) -> Result<Spectral> {
    let v = match range {
        Range::Fraction => ctx.fraction(field, v)?,
        Range::NonNegative => ctx.non_negative(field, v)?,
        Range::Index => ctx.positive(field, v)?,
    };
    Ok(Spectral::constant(v))
}

/// A dispersion formula is for refractive indices only.
fn dispersion(
    ctx: &Ctx,
    field: &str,
    range: Range,
    build: impl FnOnce() -> Result<Spectral>,
) -> Result<Spectral> {
    if range != Range::Index {
        return Err(ctx.err(
            field,
            "cauchy and sellmeier are dispersion formulas for a refractive index; give a number or { table = [[nm, value], ...] }",
        ));
    }
    build()
}

fn table_quantity(ctx: &Ctx, field: &str, rows: &[[f64; 2]]) -> Result<Spectral> {
    let spectrum = crate::color::Spectrum::from_rows(rows).map_err(|e| ctx.err(field, e))?;
    let (first, last) = spectrum.range_nm();
    Ok(Spectral::sampled(|nm| spectrum.at(nm.clamp(first, last))))
}

fn cauchy_quantity(ctx: &Ctx, field: &str, c: &[f64]) -> Result<Spectral> {
    if c.is_empty() || c.iter().any(|x| !x.is_finite()) {
        return Err(ctx.err(field, "cauchy needs finite coefficients [A, B, C, ...]"));
    }
    Ok(Spectral::sampled(|nm| {
        let inv_l2 = 1.0 / (nm * 1e-3).powi(2);
        c.iter().rev().fold(0.0, |acc, &k| acc * inv_l2 + k)
    }))
}

impl Sellmeier {
    fn quantity(&self, ctx: &Ctx, field: &str) -> Result<Spectral> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if self.b.is_empty() || self.b.len() != self.c_um2.len() {
            return Err(ctx.err(
                field,
                "sellmeier needs b and c_um2 of the same non-zero length",
            ));
        }
        if !finite(&self.b) || !finite(&self.c_um2) || self.c_um2.iter().any(|&c| c < 0.0) {
            return Err(ctx.err(field, "sellmeier needs finite b and non-negative c_um2"));
        }
        let (lo, hi) = (grid_nm(0) * 1e-3, grid_nm(GRID_LEN - 1) * 1e-3);
        if let Some(c) = self
            .c_um2
            .iter()
            .find(|&&c| (lo * lo..=hi * hi).contains(&c))
        {
            return Err(ctx.err(
                field,
                format!("sellmeier has a resonance (c = {c} um^2) inside 360-830 nm"),
            ));
        }
        Ok(Spectral::sampled(|nm| {
            let l2 = (nm * 1e-3).powi(2);
            let s: f64 = self
                .b
                .iter()
                .zip(&self.c_um2)
                .map(|(b, c)| b * l2 / (l2 - c))
                .sum();
            (1.0 + s).max(0.0).sqrt()
        }))
    }
}

fn check_range(ctx: &Ctx, field: &str, q: &Spectral, range: Range) -> Result<()> {
    let (lo, hi) = q.range();
    let ok = match range {
        Range::Fraction => lo >= 0.0 && hi <= 1.0,
        Range::NonNegative => lo >= 0.0 && hi.is_finite(),
        Range::Index => lo > 0.0 && hi.is_finite(),
    };
    if ok {
        return Ok(());
    }
    let want = match range {
        Range::Fraction => "within [0, 1]",
        Range::NonNegative => "finite and non-negative",
        Range::Index => "positive",
    };
    Err(ctx.err(
        field,
        format!(
            "must be {want} at every wavelength from 360 to 830 nm, but ranges {}..{}",
            short(lo),
            short(hi)
        ),
    ))
}

#[cfg(test)]
mod tests;
