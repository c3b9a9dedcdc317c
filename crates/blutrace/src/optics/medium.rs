//! Optical media and the interface between two of them.
//!
//! ```toml
//! [media.pmma]
//! n = 1.49
//! absorption_per_mm = 0.0002   # Beer-Lambert coefficient (natural log), 0 = lossless
//!
//! [media.diffuser_pc]          # a bulk diffuser: scatters inside
//! n = 1.585
//! absorption_per_mm = 0.001
//! scattering_per_mm = 4.0      # mu_s, 1/mm (default 0: clear)
//! anisotropy = 0.9             # Henyey-Greenstein g in (-1, 1) (default 0: isotropic)
//!
//! [media.measured]             # or a measured phase function instead of g
//! n = 1.49
//! scattering_per_mm = 0.5
//! phase_table = [[0.0, 10.0], [10.0, 2.0], [90.0, 0.05], [180.0, 0.02]]  # [deg, per sr]
//!
//! [media.diffusion_pmma]       # or mu_s and g from particles (Mie, see `mie`)
//! n = 1.49
//! particles = { radius_um = 2.0, n = 1.43, volume_fraction = 0.001, wavelength_nm = 550.0 }
//! ```
//!
//! `n` and `absorption_per_mm` may be tables (and `n` a dispersion formula, see
//! [`super::spectrum`]); particles' coefficients are tabulated over wavelength in a
//! spectral scene ([`super::particles`]), so mu_s and g are [`Spectral`] too.
//!
//! The medium `air` (n = 1, lossless, clear) exists unless the file redefines it; it is
//! the unbounded ambient medium, so it may absorb but not scatter. Surfaces and sources
//! name media, the scene numbers them ([`MediumId`]). How a photon crosses a medium
//! (free paths, scattering events) is the tracer's (`tracer::flight`); the phase
//! function is [`super::phase`].

pub use super::particles::{MAX_VOLUME_FRACTION, ParticlesSpec};
use super::phase::{self, PhaseTable};
use super::sampling;
use super::spectrum::{Light, Range, Spectral, SpectralValue};
use crate::spec_check::{Ctx, short};
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Index of a medium in the scene's medium table (0 is the ambient medium, air).
pub type MediumId = u16;

/// A homogeneous optical medium.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    /// Name from the scene file.
    pub name: String,
    /// Refractive index (read at a photon's light with [`Medium::index`]).
    pub n: Spectral,
    /// Beer-Lambert absorption coefficient (1/mm): the bulk's and its particles' (read at
    /// a photon's light with [`Medium::absorption`]).
    pub absorption_per_mm: Spectral,
    /// Scattering inside the medium ([`Scattering::NONE`] for a clear one).
    pub scattering: Scattering,
    /// The particles the scattering was computed from, if any (for reports).
    pub particles: Option<ParticlesSpec>,
}

/// Absorption (1/mm) from which a clear medium is a black backing: whatever enters it is
/// absorbed within 37 nm (the analog tracer's longest free path, -ln(2^-53) / mu), so it
/// needs no closed solid of its own; see [`Medium::is_backing`].
pub const BACKING_PER_MM: f64 = 1e6;

impl Medium {
    /// A medium that absorbs at once whatever enters it (at least [`BACKING_PER_MM`], no
    /// scattering): a face may name it outside with no solid around it, as an
    /// index-matched black coating of no thickness.
    pub fn is_backing(&self) -> bool {
        self.absorption_per_mm.nominal() >= BACKING_PER_MM && !self.scattering.scatters()
    }

    /// The refractive index for a photon of light `light`.
    #[inline]
    pub fn index(&self, light: Light) -> f64 {
        self.n.at(light)
    }

    /// The absorption coefficient (1/mm) for a photon of light `light`.
    #[inline]
    pub fn absorption(&self, light: Light) -> f64 {
        self.absorption_per_mm.at(light)
    }

    /// A medium that does not scatter.
    pub fn clear(name: &str, n: f64, absorption_per_mm: f64) -> Medium {
        Medium {
            name: name.to_string(),
            n: Spectral::constant(n),
            absorption_per_mm: Spectral::constant(absorption_per_mm),
            scattering: Scattering::NONE,
            particles: None,
        }
    }
}

/// Volume scattering: free paths of mean `1 / per_mm` between events, and the phase
/// function: Henyey-Greenstein with the anisotropy, or a measured table. Both are read
/// at a photon's light (tables only where particles in a spectral scene made them).
#[derive(Clone, Debug, PartialEq)]
pub struct Scattering {
    /// Scattering coefficient mu_s (1/mm); 0 = clear.
    pub per_mm: Spectral,
    /// The mean cosine of the scattering angle: the Henyey-Greenstein g, or the table's.
    pub anisotropy: Spectral,
    /// A measured phase function, used instead of Henyey-Greenstein.
    pub table: Option<Arc<PhaseTable>>,
}

impl Scattering {
    /// A clear medium.
    pub const NONE: Scattering = Scattering {
        per_mm: Spectral::constant(0.0),
        anisotropy: Spectral::constant(0.0),
        table: None,
    };

    /// Whether it scatters at all (a table is built only for a medium that does).
    #[inline]
    pub fn scatters(&self) -> bool {
        match &self.per_mm {
            Spectral::Constant(v) => *v > 0.0,
            Spectral::Sampled(_) => true,
        }
    }

    /// The scattering coefficient mu_s (1/mm) for a photon of light `light`.
    #[inline]
    pub fn coefficient(&self, light: Light) -> f64 {
        self.per_mm.at(light)
    }

    /// The direction after scattering a photon of light `light` travelling along unit
    /// `dir`, from two uniform numbers.
    pub fn scatter(&self, dir: DVec3, light: Light, u1: f64, u2: f64) -> DVec3 {
        match &self.table {
            Some(t) => sampling::around(dir, t.cos_theta(u1), u2),
            None => phase::scatter(dir, self.anisotropy.at(light), u1, u2),
        }
    }

    /// The reduced scattering coefficient `mu_s (1 - g)` (1/mm): what decides diffusion.
    pub fn reduced_per_mm(&self) -> Spectral {
        match (&self.per_mm, &self.anisotropy) {
            (Spectral::Constant(s), Spectral::Constant(g)) => Spectral::constant(s * (1.0 - g)),
            _ => Spectral::sampled(|nm| {
                let l = Light::at_nm(nm);
                self.per_mm.at(l) * (1.0 - self.anisotropy.at(l))
            }),
        }
    }
}

/// The two media either side of a dielectric face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// The medium behind the face (the normal points away from it).
    pub inside: MediumId,
    /// The medium in front of the face.
    pub outside: MediumId,
}

/// `[media.NAME]`: a homogeneous medium in the scene file.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MediumSpec {
    /// Refractive index: a number, a table or a dispersion formula ([`super::spectrum`]).
    pub n: SpectralValue,
    /// Beer-Lambert absorption coefficient (1/mm): a number or a table.
    #[serde(default = "no_absorption")]
    pub absorption_per_mm: SpectralValue,
    /// Scattering coefficient mu_s (1/mm).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub scattering_per_mm: f64,
    /// Henyey-Greenstein anisotropy g in (-1, 1).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub anisotropy: f64,
    /// A measured phase function, `[angle_deg, value per steradian]` rows from 0 to 180
    /// degrees (instead of `anisotropy`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_table: Option<Vec<[f64; 2]>>,
    /// Scattering particles (instead of `scattering_per_mm` and `anisotropy`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub particles: Option<ParticlesSpec>,
}

fn no_absorption() -> SpectralValue {
    SpectralValue::Constant(0.0)
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// The default of a face's or source's `outside`/`medium`: the ambient medium.
pub fn air() -> String {
    "air".into()
}

/// The scene's medium table from its `[media.*]` sections: air first (index 0, redefined
/// if the file names it), then the others in name order; particles' coefficients over
/// wavelength if `spectral` (some source has a spectrum), else at their `wavelength_nm`.
pub fn build_media(
    ctx: &Ctx,
    specs: &BTreeMap<String, MediumSpec>,
    spectral: bool,
) -> Result<Vec<Medium>> {
    let mut media = vec![Medium::clear("air", 1.0, 0.0)];
    for (name, spec) in specs {
        let m = spec.build(ctx, name, spectral)?;
        if name == "air" {
            if m.scattering.scatters() {
                return Err(ctx.err(
                    "media.air",
                    "the ambient medium is unbounded and cannot scatter \
                     (a photon in it would never leave); scatter in a closed solid",
                ));
            }
            media[0] = m;
        } else {
            media.push(m);
        }
    }
    if media.len() > MediumId::MAX as usize {
        return Err(ctx.err("media", "too many media"));
    }
    Ok(media)
}

impl MediumSpec {
    /// The checked medium `name` (its particles over wavelength if `spectral`).
    fn build(&self, ctx: &Ctx, name: &str, spectral: bool) -> Result<Medium> {
        let field = |f: &str| format!("media.{name}.{f}");
        let n = self.n.build(ctx, &field("n"), Range::Index)?;
        let mut absorption =
            self.absorption_per_mm
                .build(ctx, &field("absorption_per_mm"), Range::NonNegative)?;
        let mu_s = ctx.non_negative(&field("scattering_per_mm"), self.scattering_per_mm)?;
        let g = ctx.finite(&field("anisotropy"), self.anisotropy)?;
        if g.abs() >= 1.0 {
            return Err(ctx.err(
                &field("anisotropy"),
                format!("must be within (-1, 1), got {}", short(g)),
            ));
        }
        let mut scattering = Scattering {
            per_mm: Spectral::constant(mu_s),
            anisotropy: Spectral::constant(g),
            table: None,
        };
        if let Some(rows) = &self.phase_table {
            let f = field("phase_table");
            if g != 0.0 || self.particles.is_some() {
                return Err(ctx.err(&f, "replaces anisotropy and particles: give one of them"));
            }
            if mu_s == 0.0 {
                return Err(ctx.err(&f, "needs scattering_per_mm > 0"));
            }
            let t = PhaseTable::new(rows).map_err(|e| ctx.err(&f, e))?;
            scattering.anisotropy = Spectral::constant(t.mean_cosine);
            scattering.table = Some(Arc::new(t));
        }
        if let Some(p) = &self.particles {
            if mu_s != 0.0 || g != 0.0 {
                return Err(ctx.err(
                    &field("particles"),
                    "give either particles or scattering_per_mm and anisotropy, not both",
                ));
            }
            let bulk = p.optics(ctx, &field("particles"), &n, spectral)?;
            absorption = absorption.plus(&bulk.absorption_per_mm);
            scattering = Scattering {
                per_mm: bulk.scattering_per_mm,
                anisotropy: bulk.anisotropy,
                table: None,
            };
        }
        Ok(Medium {
            name: name.to_string(),
            n,
            absorption_per_mm: absorption,
            scattering,
            particles: self.particles.clone(),
        })
    }
}

/// Warnings for a spectral scene's media: a particles' `wavelength_nm` it does not use.
pub fn spectral_warnings(specs: &BTreeMap<String, MediumSpec>) -> Vec<String> {
    specs
        .iter()
        .filter_map(|(name, m)| {
            let field = format!("media.{name}.particles");
            m.particles.as_ref()?.spectral_warning(&field)
        })
        .collect()
}

/// The id of the medium named `name` (given at `field`).
pub fn medium_id(ctx: &Ctx, field: &str, name: &str, media: &[Medium]) -> Result<MediumId> {
    media
        .iter()
        .position(|m| m.name == name)
        .map(|i| i as MediumId)
        .ok_or_else(|| {
            let known: Vec<&str> = media.iter().map(|m| m.name.as_str()).collect();
            ctx.err(
                field,
                format!("unknown medium '{name}' (known: {})", known.join(", ")),
            )
        })
}

impl Interface {
    /// The interface of the table at `at` (`surfaces.TAG`) from its `inside` and
    /// `outside` medium names.
    pub fn build(
        ctx: &Ctx,
        at: &str,
        inside: &str,
        outside: &str,
        media: &[Medium],
    ) -> Result<Interface> {
        let face = Interface {
            inside: medium_id(ctx, &format!("{at}.inside"), inside, media)?,
            outside: medium_id(ctx, &format!("{at}.outside"), outside, media)?,
        };
        if face.inside == face.outside {
            return Err(ctx.err(
                &format!("{at}.outside"),
                format!(
                    "is '{outside}', the medium inside too: a face between a medium and itself is no interface (name the medium in front of the face)"
                ),
            ));
        }
        Ok(face)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn a_scattering_medium_survives_a_toml_round_trip() {
        // The optimizer writes scenes back (optimized.toml): particles and coefficients
        // must come back unchanged, and a clear medium must not grow new keys.
        let text = "[a]\nn = 1.49\nparticles = { radius_um = 1.0, n = 1.42, volume_fraction = 0.001 }\n\
                    [b]\nn = 1.585\nscattering_per_mm = 4.0\nanisotropy = 0.9\n[c]\nn = 1.5\n";
        let specs: BTreeMap<String, MediumSpec> = toml::from_str(text).unwrap();
        let again: BTreeMap<String, MediumSpec> =
            toml::from_str(&toml::to_string(&specs).unwrap()).unwrap();
        let ctx = Ctx(Path::new("scene.toml"));
        assert_eq!(
            build_media(&ctx, &specs, false).unwrap(),
            build_media(&ctx, &again, false).unwrap()
        );
        let clear = toml::to_string(&specs["c"]).unwrap();
        assert!(
            !clear.contains("scattering") && !clear.contains("anisotropy"),
            "{clear}"
        );
        let media = build_media(&ctx, &specs, false).unwrap();
        assert_eq!(media[2].scattering.per_mm, Spectral::constant(4.0));
        assert_eq!(media[1].particles.as_ref().unwrap().monochrome_nm(), 550.0);
        let spectral = build_media(&ctx, &specs, true).unwrap();
        assert!(spectral[1].scattering.per_mm.is_spectral());
        assert_eq!(spectral[2], media[2], "no particles: nothing to tabulate");
    }
}
