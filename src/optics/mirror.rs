//! Specular mirrors.
//!
//! ```toml
//! [surfaces.silver]
//! model = "mirror"
//! reflectance = 0.97   # default 1
//! ```

use super::fresnel;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// `[surfaces.TAG]` with `model = "mirror"`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MirrorSpec {
    /// Reflectance.
    #[serde(default = "one")]
    pub reflectance: f64,
}

fn one() -> f64 {
    1.0
}

impl MirrorSpec {
    /// Check the table at `at` (`surfaces.TAG`, or a lamp's `sources[i].body`): its
    /// reflectance.
    pub fn build(&self, ctx: &Ctx, at: &str) -> Result<f64> {
        ctx.fraction(&format!("{at}.reflectance"), self.reflectance)
    }
}

/// The mirror direction of `dir` at the unit normal `facing`.
pub fn direction(dir: DVec3, facing: DVec3) -> DVec3 {
    fresnel::reflect(dir, facing)
}
