//! Smooth dielectric interfaces: Fresnel reflection, Snell refraction and total internal
//! reflection between two media.
//!
//! ```toml
//! [surfaces.lgp]               # a tag used by the geometry files
//! model = "dielectric"
//! inside = "pmma"              # medium the face normal points away from
//! outside = "air"              # default "air" (n = 1)
//! ```

use super::medium::{Interface, Medium, MediumId, air};
use super::model::{Arrival, Feature, MeterLayer, MeterVertex, Outcome, Surface, SurfaceSpecOf};
use super::{fresnel, polarization};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "dielectric"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DielectricSpec {
    /// Medium behind the face.
    pub inside: String,
    /// Medium in front of the face.
    #[serde(default = "air")]
    pub outside: String,
}

impl SurfaceSpecOf for DielectricSpec {
    type Model = Interface;

    /// Check `[surfaces.TAG]`: its media.
    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<Interface> {
        Interface::build(ctx, at, &self.inside, &self.outside, media)
    }
}

impl Surface for Interface {
    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        (smooth(at, self, rng), Feature::Plain)
    }

    fn interface(&self) -> Option<Interface> {
        Some(*self)
    }

    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Specular
    }

    fn meter_layer(&self) -> MeterLayer {
        MeterLayer::Flat
    }
}

/// Fresnel roulette at the smooth interface `i` for the photon of `at`.
#[inline]
pub fn smooth(at: &Arrival, i: &Interface, rng: &mut PhotonRng) -> Outcome {
    let (dir, medium) = scatter(at, i, rng);
    Outcome::Scattered {
        dir,
        medium,
        weight: 1.0,
    }
}

/// Fresnel roulette of the photon of `at` at the smooth interface `iface`: its new
/// direction and the medium it now travels in.
pub fn scatter(at: &Arrival, iface: &Interface, rng: &mut PhotonRng) -> (DVec3, MediumId) {
    let (normal, dir) = (at.hit.normal, at.dir);
    let (n_inside, n_outside) = at.indices(iface);
    let entering = dir.dot(normal) < 0.0;
    let (from, to, facing, n1, n2) = if entering {
        (iface.outside, iface.inside, normal, n_outside, n_inside)
    } else {
        (iface.inside, iface.outside, -normal, n_inside, n_outside)
    };
    let mut pol = at.pol;
    let refracted = polarization::fresnel_roulette(dir, facing, (n1, n2), pol.as_mut(), rng);
    at.pol_out.set(pol);
    match refracted {
        Some(t) => (t, to),
        None => (fresnel::reflect(dir, facing), from),
    }
}
