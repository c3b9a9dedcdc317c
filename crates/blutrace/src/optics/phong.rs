//! Phong reflectors: lamp reflectors and reflector sheets.
//!
//! ```toml
//! [surfaces.lamp_reflector]
//! model = "phong"              # reflectance, specular fraction, cos^exponent lobe
//! reflectance = 0.95
//! specular = 0.8
//! exponent = 100.0
//! ```
//!
//! Of the light it reflects (the fraction `reflectance`), the fraction `specular` goes
//! into a `cos^exponent` lobe about the mirror direction and the rest is Lambertian.

use super::medium::Medium;
use super::model::{Arrival, Feature, MeterVertex, Outcome, Surface, SurfaceSpecOf};
use super::spectrum::{Range, Spectral, SpectralValue};
use super::{fresnel, lambert, sampling};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "phong"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PhongSpec {
    /// Total reflectance.
    pub reflectance: SpectralValue,
    /// Specular fraction of the reflected energy.
    pub specular: f64,
    /// Phong exponent.
    pub exponent: f64,
}

/// A Phong reflector (lamp reflector, reflector sheet).
#[derive(Clone, Debug, PartialEq)]
pub struct Phong {
    /// Total reflectance (diffuse + specular).
    pub reflectance: Spectral,
    /// Fraction of the reflected energy in the specular lobe.
    pub specular: f64,
    /// Phong exponent of the specular lobe.
    pub exponent: f64,
}

impl SurfaceSpecOf for PhongSpec {
    type Model = Phong;

    fn build(&self, ctx: &Ctx, at: &str, _media: &[Medium]) -> Result<Phong> {
        let f = |k: &str| format!("{at}.{k}");
        Ok(Phong {
            reflectance: self
                .reflectance
                .build(ctx, &f("reflectance"), Range::Fraction)?,
            specular: ctx.fraction(&f("specular"), self.specular)?,
            exponent: ctx.positive(&f("exponent"), self.exponent)?,
        })
    }
}

impl Surface for Phong {
    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        let facing = at.facing();
        let out = at.reflect(&self.reflectance, rng, |rng| {
            self.direction(facing, at.dir, rng)
        });
        (out, Feature::Plain)
    }

    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Diffuse
    }

    fn meter_density(&self, at: &Arrival, _feature: Feature, out: DVec3) -> f64 {
        self.reflectance.at(at.light) * self.density(at.facing(), at.dir, out)
    }
}

impl Phong {
    /// The density (per sr) of [`Phong::direction`] leaving along unit `out`: the
    /// Lambertian part's `cos / pi` and the lobe's `(m + 1) / (2 pi) cos^m` about the
    /// mirror direction ([`sampling::cos_power`]'s), both zero below the surface.
    pub fn density(&self, facing: DVec3, dir: DVec3, out: DVec3) -> f64 {
        if out.dot(facing) <= 0.0 {
            return 0.0;
        }
        let mirror = fresnel::reflect(dir, facing);
        let m = self.exponent;
        let lobe = (m + 1.0) / std::f64::consts::TAU * out.dot(mirror).max(0.0).powf(m);
        (1.0 - self.specular) * lambert::density(facing, out) + self.specular * lobe
    }

    /// A reflected direction from the Phong BRDF, given that the photon arriving along
    /// `dir` is reflected (`facing`: the unit normal on its side): diffuse with
    /// probability `1 - specular`, else in the cos^n lobe around the mirror direction. A
    /// lobe direction below the surface carries no BRDF value: `None` (absorbed there).
    pub fn direction(&self, facing: DVec3, dir: DVec3, rng: &mut PhotonRng) -> Option<DVec3> {
        if rng.uniform() >= self.specular {
            return Some(lambert::direction(facing, rng));
        }
        let mirror = fresnel::reflect(dir, facing);
        let out = sampling::cos_power(mirror, self.exponent, rng.uniform(), rng.uniform());
        (out.dot(facing) > 0.0).then_some(out)
    }
}
