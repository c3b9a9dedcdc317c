//! The content hash of a scene: shards of one run must agree on it.
//!
//! It covers everything that decides the physics, in canonical form: the scene file's
//! geometry, media, surfaces, sources, detector and bounce cap as serde JSON of the typed
//! [`SceneFile`] (fixed field order, sorted maps, shortest round-trip floats), the bytes
//! of the measured tables it names (every file a surface model or a source declares, a
//! lamp body's model's included: [`crate::optics::surface::SurfaceSpecOf::files`],
//! [`SourceSpec::files`]), and the loaded mesh (vertex coordinates, triangles and tags
//! as little-endian bytes). Not the name, description or the default photon count and
//! seed.

use super::config::{GeometrySpec, MediumSpec, SceneFile, SourceSpec, SurfaceEntry};
use crate::geometry::Mesh;
use anyhow::Result;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The physics sections of a scene file, as hashed.
#[derive(Serialize)]
struct Physics<'a> {
    geometry: &'a [GeometrySpec],
    media: &'a BTreeMap<String, MediumSpec>,
    surfaces: &'a BTreeMap<String, SurfaceEntry>,
    sources: &'a [SourceSpec],
    detector: &'a super::config::DetectorSpec,
    max_bounces: u32,
    /// Whether polarization is traced (the file's key resolved).
    polarized: bool,
}

/// Hash of the scene file `file` (read from `path`) and the intensity tables it names;
/// `polarized`: whether the scene traces polarization.
pub(super) fn file_hash(file: &SceneFile, path: &Path, polarized: bool) -> Result<u64> {
    let physics = Physics {
        geometry: &file.geometry,
        media: &file.media,
        surfaces: &file.surfaces,
        sources: &file.sources,
        detector: &file.detector,
        max_bounces: file.trace.max_bounces,
        polarized,
    };
    let mut h = Fnv1a::default();
    h.write(&serde_json::to_vec(&physics)?);
    let dir = path.parent().unwrap_or(Path::new("."));
    for f in super::inputs::table_files(file) {
        h.write(&crate::input_file::read_bytes(
            &dir.join(f),
            "measured table",
        )?);
    }
    Ok(h.0)
}

/// [`file_hash`] combined with the loaded mesh.
pub(super) fn content_hash(file_hash: u64, mesh: &Mesh) -> u64 {
    let mut h = Fnv1a::default();
    h.write(&file_hash.to_le_bytes());
    for p in &mesh.positions {
        p.to_array().iter().for_each(|c| h.write(&c.to_le_bytes()));
    }
    for (t, tag) in mesh.triangles.iter().zip(&mesh.tri_tag) {
        t.iter()
            .chain(std::iter::once(tag))
            .for_each(|i| h.write(&i.to_le_bytes()));
    }
    h.0
}

/// 64-bit FNV-1a.
struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}
