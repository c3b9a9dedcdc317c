//! Lambertian (perfectly diffuse) scatterers.
//!
//! ```toml
//! [surfaces.ink_sheet]
//! model = "lambert"
//! albedo = 0.9
//! ```
//!
//! The ink of [`super::dots`] and the diffuse part of [`super::phong`] reflect the same way.

use super::sampling;
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "lambert"`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LambertSpec {
    /// Albedo.
    pub albedo: f64,
}

impl LambertSpec {
    /// Check the table at `at` (`surfaces.TAG`, or a lamp's `sources[i].body`): its albedo.
    pub fn build(&self, ctx: &Ctx, at: &str) -> Result<f64> {
        ctx.fraction(&format!("{at}.albedo"), self.albedo)
    }
}

/// A Lambertian direction about the unit normal `facing` (the paper's equation (1)).
pub fn direction(facing: DVec3, rng: &mut PhotonRng) -> DVec3 {
    sampling::lambertian(facing, rng.uniform(), rng.uniform())
}
