//! The typed, versioned scene file (TOML, millimetres). Unknown keys are errors.
//!
//! ```toml
//! version = 1
//! name = "notebook14"
//!
//! [[geometry]]                # see `geometry_file` for units, up axis, rotation, tag
//! file = "notebook14.obj"    # OBJ (usemtl names, else group/object names, are tags)
//! translate = [0.0, 0.0, 0.0]
//!
//! [[procedural]]              # parametric reflectors generated at load: see `procedural`
//! type = "direct_lit_box"
//! tag = "box_reflector"
//! origin = [0.0, 0.0, 0.0]
//! size_mm = [400.0, 250.0, 25.0]
//! ridge_height_mm = 6.0
//!
//! [media.pmma]
//! n = 1.49
//! absorption_per_mm = 0.0
//!
//! [surfaces.lgp]
//! model = "dielectric"
//! inside = "pmma"
//!
//! [[sources]]
//! type = "ccfl"
//! center = [-3.0, 100.0, 1.5]
//! axis = [0.0, 1.0, 0.0]
//! radius_mm = 1.0
//! length_mm = 200.0
//! power_w = 1.0
//!
//! [detector]
//! origin = [0.0, 0.0, 3.5]
//! u = [1.0, 0.0, 0.0]
//! v = [0.0, 1.0, 0.0]
//! size_mm = [300.0, 200.0]
//! ```
//!
//! Sections `[surfaces.*]`, `[[sources]]`, `[detector]` and `[trace]` are documented in
//! the modules that implement them.

pub use super::geometry_file::GeometrySpec;
pub use super::procedural::ProceduralSpec;
pub use crate::detector::DetectorSpec;
pub use crate::optics::medium::MediumSpec;
pub use crate::optics::surface::SurfaceSpec;
pub use crate::optics::two_sided::SurfaceEntry;
pub use crate::sources::SourceSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The only scene-file version this build reads.
pub const SCENE_VERSION: u32 = 1;

/// A whole scene file.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Format version; must be [`SCENE_VERSION`].
    pub version: u32,
    /// Scene name for reports (defaults to the file's folder name).
    pub name: Option<String>,
    /// Free text.
    pub description: Option<String>,
    /// Geometry files, relative to the scene file.
    #[serde(default)]
    pub geometry: Vec<GeometrySpec>,
    /// Parts generated at load ([`super::procedural`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub procedural: Vec<ProceduralSpec>,
    /// Named media (`air` exists unless redefined).
    #[serde(default)]
    pub media: BTreeMap<String, MediumSpec>,
    /// Optical model per material tag (and its back's, [`crate::optics::two_sided`]).
    pub surfaces: BTreeMap<String, SurfaceEntry>,
    /// Light sources.
    pub sources: Vec<SourceSpec>,
    /// The target plane.
    pub detector: DetectorSpec,
    /// Tracing defaults.
    #[serde(default)]
    pub trace: TraceSpec,
}

/// Tracing defaults.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TraceSpec {
    /// Default photon count.
    #[serde(default = "default_photons")]
    pub photons: u64,
    /// Default seed.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Surface events before a photon is killed.
    #[serde(default = "default_max_bounces")]
    pub max_bounces: u32,
    /// Trace polarization (Stokes vectors, exact Fresnel): `true`, `false`, or unset for
    /// on exactly when the scene has a polarizer ([`crate::optics::polarization`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<bool>,
}

impl Default for TraceSpec {
    fn default() -> Self {
        Self {
            photons: default_photons(),
            seed: default_seed(),
            max_bounces: default_max_bounces(),
            polarization: None,
        }
    }
}

fn default_photons() -> u64 {
    400_000
}

fn default_seed() -> u64 {
    1
}

fn default_max_bounces() -> u32 {
    100_000
}
