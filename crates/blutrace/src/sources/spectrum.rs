//! A source's emission spectrum: what wavelength each of its photons carries.
//!
//! ```toml
//! [[sources]]
//! type = "led"
//! spectrum = "cie-led-b5"        # a named spectrum (below), or one of:
//! # spectrum = { table = [[450, 1.0], [550, 0.4], [600, 0.6]] }   # relative power per nm
//! # spectrum = { file = "led.csv" }                                # rows "nm, value"
//! # spectrum = { blackbody_k = 6500 }
//! ```
//!
//! Named spectra, all CIE 015:2018 (DOI 10.25039/TR.015.2018) relative spectral power
//! distributions: `"cie-led-b1"` ... `"cie-led-b5"` (phosphor-converted white LEDs, 2700 to
//! 6500 K), `"cie-led-bh1"`, `"cie-led-rgb1"`, `"cie-led-v1"`, `"cie-led-v2"`, `"cie-d65"`,
//! `"cie-a"`, `"cie-fl11"`; and `"ccfl-triphosphor"`, which is FL11, the CIE's narrow-band
//! tri-phosphor fluorescent lamp: backlight CCFLs use the same three rare-earth phosphors
//! and mercury lines, but are made bluer (6000-10000 K against FL11's 4000 K), so it is a
//! stand-in for a lamp maker's measured spectrum, not one.
//!
//! A table (or file) is linear between rows and zero outside them; its absolute scale does
//! not matter (`power_w` is the radiant power). Only 360-830 nm is kept, the range of the
//! CIE colour-matching functions: a blackbody's `power_w` is its power within it. A
//! photon's wavelength is drawn from the spectrum exactly (inverting its piecewise-linear
//! cumulative integral), with one uniform number after its position and direction.

use crate::color::cie_cmf::{CMF_FIRST_NM, CMF_STEP_NM, X_BAR, Y_BAR, Z_BAR};
use crate::color::{CieIlluminant, KM_LM_PER_W, Spectrum, Xyz};
use crate::spec_check::Ctx;
use anyhow::Result;
use serde::{Deserialize, Deserializer, Serialize};
use std::path::{Path, PathBuf};

/// The wavelengths kept of a source's spectrum (nm): the CIE 1931 observer's range.
pub const VISIBLE_NM: (f64, f64) = (360.0, 830.0);

/// How far (nm) [`EmissionSpectrum::mixture`] spreads a part's step at its ends (a table
/// that starts or ends above zero): the mixture's table gains at most half this times the
/// step's height there (its colour and efficacy are exact regardless).
pub const MIX_STEP_NM: f64 = 1e-6;

/// `spectrum = ...` of a `[[sources]]` entry.
// The schema is the one-key tables `deserialize` below reads.
#[derive(Clone, Debug, PartialEq, Serialize, schemars::JsonSchema)]
#[serde(untagged)]
#[schemars(deny_unknown_fields)]
pub enum SpectrumSpec {
    /// A named spectrum.
    Named(String),
    /// `{ table = [[nm, value], ...] }`.
    Table {
        /// Rows `[nm, relative power per nm]`.
        table: Vec<[f64; 2]>,
    },
    /// `{ file = "x.csv" }`: rows `nm, value` (comma or blanks; `#` starts a comment).
    File {
        /// Relative to the scene file.
        file: PathBuf,
    },
    /// `{ blackbody_k = 6500 }`: Planck's law.
    Blackbody {
        /// The temperature (K).
        blackbody_k: f64,
    },
}

impl<'de> Deserialize<'de> for SpectrumSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let allowed = "expected a name (\"cie-led-b5\", ...), { table = [[nm, value], ...] }, { file = \"x.csv\" } or { blackbody_k = 6500 }";
        let v = toml::Value::deserialize(d)?;
        if let Some(name) = v.as_str() {
            return Ok(SpectrumSpec::Named(name.to_string()));
        }
        let (key, value) =
            crate::optics::spectrum::one_key_table(&v, allowed).map_err(D::Error::custom)?;
        let bad = |e: toml::de::Error| D::Error::custom(format!("{key}: {}", e.message()));
        let value = value.clone();
        match key {
            "table" => Ok(SpectrumSpec::Table {
                table: value.try_into().map_err(bad)?,
            }),
            "file" => Ok(SpectrumSpec::File {
                file: value.try_into().map_err(bad)?,
            }),
            "blackbody_k" => Ok(SpectrumSpec::Blackbody {
                blackbody_k: value.try_into().map_err(bad)?,
            }),
            other => Err(D::Error::custom(format!(
                "unknown key '{other}': {allowed}"
            ))),
        }
    }
}

/// The names a scene file may give, with their spectra.
pub fn named(name: &str) -> Option<Spectrum> {
    let name = if name == "ccfl-triphosphor" {
        "cie-fl11"
    } else {
        name
    };
    CieIlluminant::from_name(name).map(CieIlluminant::spectrum)
}

/// Every name [`named`] knows.
pub fn names() -> Vec<&'static str> {
    let mut v: Vec<&str> = CieIlluminant::ALL.iter().map(|i| i.name()).collect();
    v.push("ccfl-triphosphor");
    v
}

impl SpectrumSpec {
    /// The file it reads, if any (relative to the scene file).
    pub fn file(&self) -> Option<&Path> {
        match self {
            SpectrumSpec::File { file } => Some(file),
            _ => None,
        }
    }

    /// Check the spectrum at `field` (`sources[i].spectrum`) and build its sampler.
    pub fn build(&self, ctx: &Ctx, field: &str) -> Result<EmissionSpectrum> {
        let spectrum = match self {
            SpectrumSpec::Named(name) => named(name).ok_or_else(|| {
                ctx.err(
                    field,
                    format!("unknown spectrum '{name}' (known: {})", names().join(", ")),
                )
            })?,
            SpectrumSpec::Table { table } => {
                Spectrum::from_rows(table).map_err(|e| ctx.err(field, e))?
            }
            SpectrumSpec::File { file } => read_file(ctx, field, file)?,
            SpectrumSpec::Blackbody { blackbody_k } => {
                let k = ctx.positive(&format!("{field}.blackbody_k"), *blackbody_k)?;
                if !(100.0..=1e6).contains(&k) {
                    return Err(ctx.err(field, format!("blackbody_k {k} K is outside 100..1e6 K")));
                }
                Spectrum::blackbody(k)
            }
        };
        EmissionSpectrum::new(&spectrum)
            .ok_or_else(|| ctx.err(field, "the spectrum has no power within 360-830 nm"))
    }
}

/// Rows `nm, value` of a spectrum file.
fn read_file(ctx: &Ctx, field: &str, file: &Path) -> Result<Spectrum> {
    let path = ctx.0.parent().unwrap_or(Path::new(".")).join(file);
    let text = crate::input_file::read_text(&path, "spectrum file")
        .map_err(|e| ctx.err(field, format!("{e:#}")))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let cells: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|c| !c.is_empty())
            .collect();
        let nums: Option<Vec<f64>> = cells.iter().map(|c| c.parse().ok()).collect();
        match nums.as_deref() {
            Some(&[nm, v]) => rows.push([nm, v]),
            _ if rows.is_empty() && nums.is_none() => continue, // a header line
            _ => {
                return Err(ctx.err(
                    field,
                    format!(
                        "{} line {}: expected two numbers 'nm, value', got '{line}'",
                        path.display(),
                        i + 1
                    ),
                ));
            }
        }
    }
    Spectrum::from_rows(&rows).map_err(|e| ctx.err(field, format!("{}: {e}", path.display())))
}

/// A source's spectrum within 360-830 nm, ready to draw wavelengths from.
#[derive(Clone, Debug, PartialEq)]
pub struct EmissionSpectrum {
    /// Knots (nm) and values of the piecewise-linear spectrum.
    nm: Vec<f64>,
    value: Vec<f64>,
    /// The integral up to each knot, divided by the total.
    cdf: Vec<f64>,
    /// The total integral (value·nm).
    total: f64,
    /// X, Y, Z per watt of radiant power (Y in lm/W divided by 683).
    xyz_per_w: Xyz,
}

impl EmissionSpectrum {
    /// The part of `spectrum` within [`VISIBLE_NM`] (`None` if it has no power there).
    /// Its absolute scale is dropped first ([`Spectrum::normalized`]): the sampler squares
    /// values and the colour sums products, which a table at 1e200 or 1e-310 would
    /// overflow or round away.
    pub fn new(spectrum: &Spectrum) -> Option<EmissionSpectrum> {
        let spectrum = &spectrum.normalized()?;
        let (lo, hi) = VISIBLE_NM;
        let (first, last) = spectrum.range_nm();
        let (a, b) = (first.max(lo), last.min(hi));
        if a >= b {
            return None;
        }
        let mut nm: Vec<f64> = std::iter::once(a)
            .chain(spectrum.rows().map(|r| r[0]).filter(|&k| k > a && k < b))
            .chain(std::iter::once(b))
            .collect();
        nm.dedup();
        let value: Vec<f64> = nm.iter().map(|&k| spectrum.at(k)).collect();
        let mut cdf = vec![0.0];
        for i in 1..nm.len() {
            let seg = 0.5 * (nm[i] - nm[i - 1]) * (value[i] + value[i - 1]);
            cdf.push(cdf[i - 1] + seg);
        }
        let total = *cdf.last().expect("two knots");
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        cdf.iter_mut().for_each(|c| *c /= total);
        let clipped = Spectrum::from_rows(
            &nm.iter()
                .zip(&value)
                .map(|(&n, &v)| [n, v])
                .collect::<Vec<_>>(),
        )
        .ok()?;
        let xyz_per_w = Xyz::of(&clipped).scaled(1.0 / total);
        Some(EmissionSpectrum {
            nm,
            value,
            cdf,
            total,
            xyz_per_w,
        })
    }

    /// The mixture of `parts` in proportion to their weights (watts, say): the spectrum of
    /// light drawn from part k with probability `w_k / sum(w)`. Its colour and efficacy
    /// are exact (`sum(w_k xyz_k) / sum(w)`); its table is the parts' densities added on
    /// the union of their knots, a part's step at an end taken over [`MIX_STEP_NM`]. `None`
    /// if no weight is positive.
    pub fn mixture(parts: &[(f64, &EmissionSpectrum)]) -> Option<EmissionSpectrum> {
        // Weights relative to the largest: only their ratios matter, and a sum of weights
        // near f64::MAX would overflow.
        let top = parts.iter().map(|(w, _)| *w).fold(0.0, f64::max);
        let parts: Vec<(f64, &EmissionSpectrum)> = parts
            .iter()
            .filter(|(w, _)| *w > 0.0)
            .map(|&(w, s)| (w / top, s))
            .collect();
        let total: f64 = parts.iter().map(|(w, _)| w).sum();
        if parts.is_empty() || !total.is_finite() {
            return None;
        }
        // The mixture's ends are the outermost part's: a step there is the table's own.
        let lo = parts
            .iter()
            .map(|(_, s)| s.nm[0])
            .fold(f64::INFINITY, f64::min);
        let hi = parts
            .iter()
            .map(|(_, s)| s.range_nm().1)
            .fold(0.0, f64::max);
        let mut knots: Vec<f64> = Vec::new();
        for (_, s) in &parts {
            knots.extend(&s.nm);
            let (a, b) = s.range_nm();
            if s.value[0] > 0.0 && a - MIX_STEP_NM > lo {
                knots.push(a - MIX_STEP_NM);
            }
            if s.value[s.value.len() - 1] > 0.0 && b + MIX_STEP_NM < hi {
                knots.push(b + MIX_STEP_NM);
            }
        }
        knots.sort_by(f64::total_cmp);
        knots.dedup();
        let rows: Vec<[f64; 2]> = knots
            .iter()
            .map(|&k| [k, parts.iter().map(|(w, s)| w / total * s.density(k)).sum()])
            .collect();
        let mut mix = EmissionSpectrum::new(&Spectrum::from_rows(&rows).ok()?)?;
        mix.xyz_per_w = parts
            .iter()
            .map(|(w, s)| s.xyz_per_w.scaled(w / total))
            .fold(Xyz::ZERO, |a, b| a + b);
        Some(mix)
    }

    /// The probability density per nm at `nm` (zero outside the knots).
    fn density(&self, nm: f64) -> f64 {
        let n = self.nm.len();
        if !(self.nm[0]..=self.nm[n - 1]).contains(&nm) {
            return 0.0;
        }
        let i = self.nm.partition_point(|&k| k <= nm).clamp(1, n - 1);
        let (x0, x1) = (self.nm[i - 1], self.nm[i]);
        let t = ((nm - x0) / (x1 - x0)).clamp(0.0, 1.0);
        (self.value[i - 1] + t * (self.value[i] - self.value[i - 1])) / self.total
    }

    /// The wavelength (nm) at cumulative fraction `u` in [0, 1): the inverse of the
    /// cumulative integral, exact for the linear interpolant.
    pub fn sample(&self, u: f64) -> f64 {
        let k = self
            .cdf
            .partition_point(|&c| c <= u)
            .clamp(1, self.nm.len() - 1)
            - 1;
        let (x0, x1) = (self.nm[k], self.nm[k + 1]);
        let (a, b) = (self.value[k], self.value[k + 1]);
        let r = (u - self.cdf[k]) * self.total;
        let slope = (b - a) / (x1 - x0);
        // a t + slope t²/2 = r, in the form that is stable for slope -> 0 and a -> 0.
        let disc = (a * a + 2.0 * slope * r).max(0.0);
        let t = if r > 0.0 {
            2.0 * r / (a + disc.sqrt())
        } else {
            0.0
        };
        (x0 + t).min(x1)
    }

    /// CIE 1931 X, Y, Z of one watt of this light (Y times 683 lm/W is its efficacy).
    pub fn xyz_per_w(&self) -> Xyz {
        self.xyz_per_w
    }

    /// Luminous efficacy of the radiation (lm/W): 683 lm/W times ∫ S V / ∫ S.
    pub fn efficacy_lm_per_w(&self) -> f64 {
        KM_LM_PER_W * self.xyz_per_w.y
    }

    /// The first and last wavelength with power (nm).
    pub fn range_nm(&self) -> (f64, f64) {
        (self.nm[0], self.nm[self.nm.len() - 1])
    }

    /// What `check` says of it: range, chromaticity, CCT and efficacy.
    pub fn report(&self) -> serde_json::Value {
        let xy = self.xyz_per_w.xy();
        let cct = self.xyz_per_w.uv_prime().and_then(crate::color::cct);
        serde_json::json!({
            "range_nm": self.range_nm(),
            "x": xy.map(|p| p.x),
            "y": xy.map(|p| p.y),
            "cct_k": cct.map(|c| c.kelvin),
            "efficacy_lm_per_w": self.efficacy_lm_per_w(),
        })
    }

    /// [`EmissionSpectrum::report`] in one line.
    pub fn describe(&self) -> String {
        let (lo, hi) = self.range_nm();
        let xy = self.xyz_per_w.xy();
        let cct = self.xyz_per_w.uv_prime().and_then(crate::color::cct);
        format!(
            "spectrum {lo}-{hi} nm, x {:.4} y {:.4}, CCT {}, {:.1} lm/W",
            xy.map_or(f64::NAN, |p| p.x),
            xy.map_or(f64::NAN, |p| p.y),
            cct.map_or("-".into(), |c| format!("{:.0} K", c.kelvin)),
            self.efficacy_lm_per_w()
        )
    }
}

/// The observer's x̄, ȳ, z̄ at `nm`, linear between the 1 nm rows, zero outside 360-830 nm
/// (what [`crate::color::observer`] gives, read straight from the uniform table: a
/// detection reads it per photon).
#[inline]
pub fn cmf_at(nm: f64) -> [f64; 3] {
    let x = (nm - CMF_FIRST_NM) / CMF_STEP_NM;
    if !(0.0..=(X_BAR.len() - 1) as f64).contains(&x) {
        return [0.0; 3];
    }
    let i = (x as usize).min(X_BAR.len() - 2);
    let f = x - i as f64;
    let lerp = |t: &[f64]| t[i] + f * (t[i + 1] - t[i]);
    [lerp(&X_BAR), lerp(&Y_BAR), lerp(&Z_BAR)]
}

#[cfg(test)]
mod tests;
