//! `blutrace bench`: photons/s and interactions/s per backend, as ratios measured in one
//! run (never a pass/fail timing).
//!
//! ```text
//! blutrace bench [--photons N] [--threads T]
//! ```
//!
//! Scenes: `scenes/notebook14` as bundled, and the same scene with its lamp reflectors
//! split into about 200k triangles (same surfaces, so the same physics). For each backend
//! (with and without the convex-solid fast path) it traces the same photons and reports
//! rates and the ratio to obvhs. A second table times nearest-hit queries of rays inside
//! the light guide alone: the convex path against each backend.

use crate::accel::{self, Accel, BackendChoice};
use crate::geometry::Ray;
use crate::optics::sampling;
use crate::rng::PhotonRng;
use crate::run::{self, RunOptions};
use crate::scene::Scene;
use anyhow::Result;
use std::path::Path;
use std::time::Instant;

/// One measured configuration.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchRow {
    /// Scene label.
    pub scene: String,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Backend name.
    pub backend: String,
    /// Convex fast path on.
    pub convex: bool,
    /// Photons per second.
    pub photons_per_s: f64,
    /// Surface interactions per second.
    pub interactions_per_s: f64,
    /// photons_per_s over that of obvhs without the convex path, same scene.
    pub ratio_to_obvhs: f64,
}

/// Backends available here, obvhs first.
fn backends() -> Vec<BackendChoice> {
    let mut b = vec![BackendChoice::Bvh];
    if accel::embree::info().is_ok() {
        b.push(BackendChoice::Embree);
    }
    b
}

/// Trace `photons` through each backend on both scenes.
pub fn trace_table(
    scene_dir: &Path,
    photons: u64,
    threads: Option<usize>,
) -> Result<Vec<BenchRow>> {
    let base = Scene::load(&scene_dir.join("scene.toml"))?;
    let mut large = base.clone();
    large.subdivide_tag("lamp_reflector", 5)?;
    let mut rows = Vec::new();
    for (label, scene) in [
        ("notebook14", &base),
        ("notebook14, reflectors split to 540k triangles", &large),
    ] {
        let mut reference = f64::NAN;
        for backend in backends() {
            for convex in [false, true] {
                let o = RunOptions {
                    photons,
                    seed: 1,
                    threads,
                    backend,
                    convex,
                    ..RunOptions::default()
                };
                let r = run::trace(scene, &o, &|_| {})?;
                let s = r.summary();
                if backend == BackendChoice::Bvh && !convex {
                    reference = s.photons_per_s;
                }
                rows.push(BenchRow {
                    scene: label.into(),
                    triangles: scene.mesh.len(),
                    backend: r.backend.into(),
                    convex,
                    photons_per_s: s.photons_per_s,
                    interactions_per_s: s.interactions_per_s,
                    ratio_to_obvhs: s.photons_per_s / reference,
                });
            }
        }
    }
    Ok(rows)
}

/// Nearest-hit queries per second for rays inside the guide: each backend, and the convex
/// path. Returns (name, queries/s) with the convex path last.
pub fn in_guide_table(scene_dir: &Path, queries: usize) -> Result<Vec<(String, f64)>> {
    let scene = Scene::load(&scene_dir.join("scene.toml"))?;
    let medium = (0..scene.media.len() as u16).find(|&m| scene.convex_solid(m).is_some());
    let Some(solid) = medium.and_then(|m| scene.convex_solid(m)) else {
        anyhow::bail!(
            "{}: no convex light guide to benchmark",
            scene_dir.display()
        );
    };
    let bounds = scene.mesh.bounds();
    let mut rng = PhotonRng::new(7, 0);
    let mut rays = Vec::with_capacity(queries);
    while rays.len() < queries {
        let p = bounds.min
            + (bounds.max - bounds.min)
                * glam::DVec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        if solid.contains(p, 1e-6) {
            rays.push(Ray::new(
                p,
                sampling::around(
                    glam::DVec3::Z,
                    2.0 * rng.uniform() - 1.0,
                    std::f64::consts::TAU * rng.uniform(),
                ),
            ));
        }
    }
    let mut out = Vec::new();
    for backend in backends() {
        let accel: Box<dyn Accel> = accel::build(backend, scene.mesh.clone())?;
        out.push((
            accel.name().to_string(),
            rate(&rays, |r| {
                accel.intersect(r, f64::INFINITY).map_or(0, |h| h.prim)
            }),
        ));
    }
    out.push((
        "convex".into(),
        rate(&rays, |r| solid.exit(&scene.mesh, r).map_or(0, |h| h.prim)),
    ));
    Ok(out)
}

/// Queries per second of `f` over `rays`, single-threaded.
fn rate(rays: &[Ray], f: impl Fn(&Ray) -> u32) -> f64 {
    let start = Instant::now();
    let checksum: u64 = rays.iter().map(|r| u64::from(f(r))).sum();
    std::hint::black_box(checksum);
    rays.len() as f64 / start.elapsed().as_secs_f64()
}
