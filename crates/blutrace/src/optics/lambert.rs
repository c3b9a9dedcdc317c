//! Lambertian (perfectly diffuse) scatterers.
//!
//! ```toml
//! [surfaces.ink_sheet]
//! model = "lambert"
//! albedo = 0.9
//! ```
//!
//! The ink of [`super::dots`] and the diffuse part of [`super::phong`] reflect the same way.

use super::medium::Medium;
use super::model::{Arrival, Feature, MeterVertex, Outcome, Surface, SurfaceSpecOf};
use super::sampling;
use super::spectrum::{Range, Spectral, SpectralValue};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "lambert"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LambertSpec {
    /// Albedo: a number or a table over wavelength ([`super::spectrum`]).
    pub albedo: SpectralValue,
}

/// A Lambertian scatterer.
#[derive(Clone, Debug, PartialEq)]
pub struct Lambert {
    /// Diffuse reflectance.
    pub albedo: Spectral,
}

impl SurfaceSpecOf for LambertSpec {
    type Model = Lambert;

    fn build(&self, ctx: &Ctx, at: &str, _media: &[Medium]) -> Result<Lambert> {
        let albedo = self
            .albedo
            .build(ctx, &format!("{at}.albedo"), Range::Fraction)?;
        Ok(Lambert { albedo })
    }
}

impl Surface for Lambert {
    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        (
            at.reflect(&self.albedo, rng, |rng| back(at, rng)),
            Feature::Plain,
        )
    }

    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Diffuse
    }

    fn meter_density(&self, at: &Arrival, _feature: Feature, out: DVec3) -> f64 {
        self.albedo.at(at.light) * density(at.facing(), out)
    }
}

/// The Lambertian density (per sr) of leaving along unit `out` about the unit normal
/// `facing`: `cos / pi` on its side, 0 behind it.
#[inline]
pub fn density(facing: DVec3, out: DVec3) -> f64 {
    out.dot(facing).max(0.0) * std::f64::consts::FRAC_1_PI
}

/// A Lambertian direction back into the side the photon of `at` came from.
#[inline]
pub fn back(at: &Arrival, rng: &mut PhotonRng) -> Option<DVec3> {
    Some(direction(at.facing(), rng))
}

/// A Lambertian direction about the unit normal `facing` (the paper's equation (1)).
pub fn direction(facing: DVec3, rng: &mut PhotonRng) -> DVec3 {
    sampling::lambertian(facing, rng.uniform(), rng.uniform())
}
