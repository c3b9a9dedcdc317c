//! Black absorbers: every photon that meets the surface ends there.
//!
//! ```toml
//! [surfaces.housing]
//! model = "absorber"
//! ```

use super::medium::Medium;
use super::model::{Arrival, Feature, Outcome, Surface, SurfaceSpecOf};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "absorber"`: no parameters, nothing to check.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AbsorberSpec {}

/// A black absorber.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Absorber;

impl SurfaceSpecOf for AbsorberSpec {
    type Model = Absorber;

    fn build(&self, _ctx: &Ctx, _at: &str, _media: &[Medium]) -> Result<Absorber> {
        Ok(Absorber)
    }
}

impl Surface for Absorber {
    #[inline]
    fn interact(&self, _at: &Arrival, _rng: &mut PhotonRng) -> (Outcome, Feature) {
        (Outcome::Absorbed, Feature::Plain)
    }
}
