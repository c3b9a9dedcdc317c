//! Specular mirrors.
//!
//! ```toml
//! [surfaces.silver]
//! model = "mirror"
//! reflectance = 0.97   # default 1
//! ```

use super::medium::Medium;
use super::model::{Arrival, Feature, MeterLayer, MeterVertex, Outcome, Surface, SurfaceSpecOf};
use super::spectrum::{Range, Spectral, SpectralValue};
use super::{fresnel, polarization};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "mirror"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MirrorSpec {
    /// Reflectance.
    #[serde(default = "one")]
    pub reflectance: SpectralValue,
}

fn one() -> SpectralValue {
    SpectralValue::Constant(1.0)
}

/// A specular mirror.
#[derive(Clone, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance.
    pub reflectance: Spectral,
}

impl SurfaceSpecOf for MirrorSpec {
    type Model = Mirror;

    fn build(&self, ctx: &Ctx, at: &str, _media: &[Medium]) -> Result<Mirror> {
        let reflectance =
            self.reflectance
                .build(ctx, &format!("{at}.reflectance"), Range::Fraction)?;
        Ok(Mirror { reflectance })
    }
}

impl Surface for Mirror {
    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        let facing = at.facing();
        let out = at.reflect(&self.reflectance, rng, |_| Some(direction(at.dir, facing)));
        // A perfect conductor's Mueller matrix, scaled to the reflectance (a stand-in:
        // a metal's retardance is left out).
        let mirrored = at.pol.map(|p| polarization::mirrored(&p, at.dir, facing));
        at.pol_out.set(mirrored);
        (out, Feature::Plain)
    }

    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Specular
    }

    fn meter_layer(&self) -> MeterLayer {
        MeterLayer::Flat
    }
}

/// The mirror direction of `dir` at the unit normal `facing`.
pub fn direction(dir: DVec3, facing: DVec3) -> DVec3 {
    fresnel::reflect(dir, facing)
}
