//! Scattering particles in a medium: the scene-file entry and the coefficients it gives,
//! at one wavelength (monochrome scenes) or over wavelength (spectral scenes).
//!
//! ```toml
//! [media.diffusion_pmma]
//! n = { sellmeier = { b = [1.1819], c_um2 = [0.011313] } }
//! particles = { radius_um = 1.0, n = 1.42, volume_fraction = 0.001 }
//! # n = { table = [[400, 1.43], [700, 1.41]] }   # the spheres' index may be spectral too
//! # k = 0.0             # their imaginary index (absorbing if > 0), a number or a table
//! # wavelength_nm = 550 # monochrome scenes only: where the coefficients are evaluated
//! ```
//!
//! A monochrome scene (no source has a spectrum) evaluates the Mie sum once, at
//! `wavelength_nm` (default 550 nm), with every index read there. A spectral scene
//! tabulates mu_s, the particles' absorption and g over 360-830 nm
//! ([`super::mie::bulk_spectra`]): the relative index `m = (n_p + i k_p) / n_host` and the
//! size parameter `2 pi r n_host / lambda` at each wavelength; `wavelength_nm` is then not
//! used (a warning says so).

use super::mie::{self, BulkSpectra};
use super::spectrum::{Light, Range, Spectral, SpectralValue};
use crate::spec_check::{Ctx, short};
use anyhow::Result;
use serde::{Deserialize, Serialize};

/// `particles = { ... }`: spheres of one size dispersed in the medium (see [`super::mie`]).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParticlesSpec {
    /// Sphere radius (micrometres).
    pub radius_um: f64,
    /// Real refractive index of the particles: a number, a table or a dispersion formula.
    pub n: SpectralValue,
    /// Imaginary refractive index of the particles (absorbing if > 0): a number or a table.
    #[serde(default = "no_k", skip_serializing_if = "is_no_k")]
    pub k: SpectralValue,
    /// Fraction of the medium's volume the particles take.
    pub volume_fraction: f64,
    /// Vacuum wavelength a monochrome scene evaluates the coefficients at (nm; default
    /// [`DEFAULT_WAVELENGTH_NM`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wavelength_nm: Option<f64>,
}

/// Above this volume fraction particles scatter dependently (near neighbours interfere),
/// which the independent-scattering Mie sum does not describe.
pub const MAX_VOLUME_FRACTION: f64 = 0.1;

/// Where a monochrome scene evaluates particles without `wavelength_nm` (nm).
pub const DEFAULT_WAVELENGTH_NM: f64 = 550.0;

fn no_k() -> SpectralValue {
    SpectralValue::Constant(0.0)
}

fn is_no_k(k: &SpectralValue) -> bool {
    *k == no_k()
}

impl ParticlesSpec {
    /// A warning if a spectral scene's particles at `field` give a `wavelength_nm`, which
    /// it does not use.
    pub fn spectral_warning(&self, field: &str) -> Option<String> {
        let nm = self.wavelength_nm?;
        Some(format!(
            "{field}.wavelength_nm = {nm} is not used: the scene is spectral, so the \
             particles' Mie coefficients are tabulated over 360-830 nm"
        ))
    }

    /// The wavelength a monochrome scene evaluates the particles at (nm).
    pub fn monochrome_nm(&self) -> f64 {
        self.wavelength_nm.unwrap_or(DEFAULT_WAVELENGTH_NM)
    }

    /// The checked particles' coefficients (mu_s, their absorption, g) at `field` in a
    /// host of index `n_host`: over wavelength if `spectral`, else constants at
    /// [`ParticlesSpec::monochrome_nm`].
    pub fn optics(
        &self,
        ctx: &Ctx,
        field: &str,
        n_host: &Spectral,
        spectral: bool,
    ) -> Result<BulkSpectra> {
        let f = |s: &str| format!("{field}.{s}");
        let r = ctx.positive(&f("radius_um"), self.radius_um)?;
        if r > 1e4 {
            return Err(ctx.err(
                &f("radius_um"),
                format!("must be at most 1e4 um (10 mm), got {}", short(r)),
            ));
        }
        let n_p = self.n.build(ctx, &f("n"), Range::Index)?;
        let k_p = self.k.build(ctx, &f("k"), Range::NonNegative)?;
        let fv = self.checked_volume_fraction(ctx, &f("volume_fraction"))?;
        let wl = match self.wavelength_nm {
            Some(w) => ctx.positive(&f("wavelength_nm"), w)?,
            None => DEFAULT_WAVELENGTH_NM,
        };
        if spectral {
            let (_, n_max) = n_host.range();
            check_size_parameter(ctx, field, r, n_max, mie::TABLE_NM.0)?;
            return Ok(mie::bulk_spectra(r, &n_p, &k_p, fv, n_host));
        }
        let l = Light::at_nm(wl);
        check_size_parameter(ctx, field, r, n_host.at(l), wl)?;
        let b = mie::bulk(r, n_p.at(l), k_p.at(l), fv, wl, n_host.at(l));
        Ok(BulkSpectra {
            scattering_per_mm: Spectral::constant(b.scattering_per_mm),
            absorption_per_mm: Spectral::constant(b.absorption_per_mm),
            anisotropy: Spectral::constant(b.anisotropy),
        })
    }

    fn checked_volume_fraction(&self, ctx: &Ctx, field: &str) -> Result<f64> {
        let fv = ctx.positive(field, self.volume_fraction)?;
        if fv > MAX_VOLUME_FRACTION {
            return Err(ctx.err(
                field,
                format!(
                    "must be at most {MAX_VOLUME_FRACTION} (beyond it particles scatter \
                     dependently, which the Mie sum does not describe), got {}",
                    short(fv)
                ),
            ));
        }
        Ok(fv)
    }

    /// "r = 1 um, n = 1.42, volume fraction 0.01" and where the coefficients come from,
    /// for `check`.
    pub fn describe(&self, spectral: bool) -> String {
        let value = |v: &SpectralValue| match v.constant() {
            Some(x) => x.to_string(),
            None => "spectral".to_string(),
        };
        let k = match self.k.constant() {
            Some(0.0) => String::new(),
            _ => format!(" + {}i", value(&self.k)),
        };
        let at = if spectral {
            format!(
                "tabulated every {} nm over {}-{} nm",
                mie::TABLE_STEP_NM,
                mie::TABLE_NM.0,
                mie::TABLE_NM.1
            )
        } else {
            format!("at {} nm", self.monochrome_nm())
        };
        format!(
            "spheres r = {} um, n = {}{k}, volume fraction {}, {at}",
            self.radius_um,
            value(&self.n),
            self.volume_fraction
        )
    }
}

/// The size parameter `2 pi r n / lambda` must stay within the Mie sum's reach.
fn check_size_parameter(ctx: &Ctx, field: &str, r: f64, n_host: f64, nm: f64) -> Result<()> {
    let x = 2.0 * std::f64::consts::PI * r * 1e3 * n_host / nm;
    if x > 2e4 {
        return Err(ctx.err(
            field,
            format!(
                "size parameter 2 pi r n / lambda = {x:.0} (at {nm} nm) is beyond 2e4: \
                 geometric optics, not Mie, describes such particles"
            ),
        ));
    }
    Ok(())
}
