//! `blutrace bench`: photons/s and interactions/s per backend, as ratios measured in one
//! run (never a pass/fail timing).
//!
//! ```text
//! blutrace bench [--photons N] [--threads T] [--repeat R] [--scene DIR] [--box-scene DIR]
//! ```
//!
//! First, the speed of light: on the box-guide scene (`scenes/bench-box`), blutrace
//! (auto backend, convex path) against a hand-written kernel of the same physics
//! ([`reference`](mod@reference), built from the same loaded scene), the same photons on the same
//! threads, timed in interleaved rounds; the ratio says how far blutrace's general path
//! is from what the physics costs. The kernel as it was before issue 35 made it faster
//! ([`reference_before`]) is timed in the same rounds, so the ratio to it stays
//! comparable with the older measurements.
//!
//! Scenes: `scenes/notebook14` as bundled, and the same scene with its lamp reflectors
//! split into about 540k triangles (same surfaces, so the same physics). Every timing is
//! the median of `R` (default 3) rounds, each round measuring every configuration once in
//! turn, so a passing load on the machine does not favour one of them. For each backend
//! (with and without the convex-solid fast path) it traces the same photons and reports
//! rates and the ratio to obvhs, then the time to load the 540k-triangle scene from an OBJ
//! with every load check ([`load`]). A next table times nearest-hit queries of rays inside
//! the light guide alone: the convex path against each backend; a third, queries in the
//! lamp cavities against the 540k-triangle mesh alone ([`cavity`], at most 3 rounds): the
//! backends without the shared per-hit code, and Embree's ray packets on emission and
//! second-bounce rays. A next table gives the error reached in a fixed tracing time per backend and
//! estimator, with the figure of merit `1 / (error^2 * seconds)`; a last, the cost of
//! polarized transport on both scenes ([`polarization`]).

pub mod box_scene;
pub mod cavity;
pub mod load;
pub mod luminance;
pub mod polarization;
pub mod reference;
pub mod reference_before;

pub use cavity::large_mesh_table;
pub use load::large_load_row;
pub use polarization::polarization_table;

use anyhow::{Context, Result};
use blutrace::accel::{self, Accel, BackendChoice};
use blutrace::geometry::Ray;
use blutrace::optics::sampling;
use blutrace::optics::surface::Estimator;
use blutrace::rng::PhotonRng;
use blutrace::run::metrics::median;
use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
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

/// One row of the speed-of-light table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SpeedRow {
    /// What traced: blutrace (its backend), the reference kernel or the reference kernel
    /// as it was before issue 35.
    pub tracer: String,
    /// Photons per second.
    pub photons_per_s: f64,
    /// Surface interactions per second.
    pub interactions_per_s: f64,
    /// photons_per_s over the reference kernel's.
    pub ratio_to_reference: f64,
    /// photons_per_s over the old reference kernel's ([`reference_before`]).
    pub ratio_to_old_reference: f64,
}

/// blutrace (auto backend, convex path on), the reference kernel ([`reference`](mod@reference))
/// and the old one ([`reference_before`]) on the box-guide scene in `box_dir`: the same
/// photons of seed 1 on the same `threads`, `repeat` rounds each timing all three in turn
/// (medians). blutrace's rate is its run's (tracing and per-round metrics, without
/// loading); the kernels', their tracing. Rows: blutrace, the reference, the old reference.
pub fn reference_table(
    box_dir: &Path,
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<Vec<SpeedRow>> {
    let scene = Scene::load(&box_dir.join("scene.toml"))?;
    let kernel = reference::Reference::new(&scene)?;
    let old = reference_before::Reference::new(&scene)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    let o = RunOptions {
        photons,
        seed: 1,
        threads,
        backend: BackendChoice::Auto,
        convex: true,
        ..RunOptions::default()
    };
    let timed = |trace: &(dyn Fn() -> reference::Counts + Sync)| {
        let start = Instant::now();
        let c = pool.install(trace);
        let t = start.elapsed().as_secs_f64();
        (c.photons as f64 / t, c.interactions as f64 / t)
    };
    let (mut blutrace, mut hand, mut before) = (Vec::new(), Vec::new(), Vec::new());
    let mut backend = "";
    for _ in 0..repeat.max(1) {
        let r = run::trace(&scene, &o, &|_| {})?;
        let s = r.summary();
        blutrace.push((s.photons_per_s, s.interactions_per_s));
        backend = r.backend;
        hand.push(timed(&|| kernel.trace(1, photons)));
        before.push(timed(&|| old.trace(1, photons)));
    }
    let med = |v: &[(f64, f64)]| {
        (
            median(v.iter().map(|r| r.0).collect()),
            median(v.iter().map(|r| r.1).collect()),
        )
    };
    let (h, b) = (med(&hand), med(&before));
    let row = |tracer: String, (photons_per_s, interactions_per_s): (f64, f64)| SpeedRow {
        tracer,
        photons_per_s,
        interactions_per_s,
        ratio_to_reference: photons_per_s / h.0,
        ratio_to_old_reference: photons_per_s / b.0,
    };
    Ok(vec![
        row(format!("blutrace ({backend}, convex path)"), med(&blutrace)),
        row("reference kernel (f32, analytic planes)".into(), h),
        row("reference kernel before issue 35".into(), b),
    ])
}

/// Backends available here, obvhs first.
fn backends() -> Vec<BackendChoice> {
    let mut b = vec![BackendChoice::Bvh];
    if accel::embree::info().is_ok() {
        b.push(BackendChoice::Embree);
    }
    b
}

/// Trace `photons` through each backend on both scenes, `repeat` rounds (medians).
pub fn trace_table(
    scene_dir: &Path,
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<Vec<BenchRow>> {
    let base = Scene::load(&scene_dir.join("scene.toml"))?;
    let mut large = base.clone();
    crate::subdivide_tag(&mut large, "lamp_reflector", 5)?;
    let scenes = [
        ("notebook14", &base),
        ("notebook14, reflectors split to 540k triangles", &large),
    ];
    let mut configs = Vec::new();
    for (label, scene) in scenes {
        for backend in backends() {
            for convex in [false, true] {
                configs.push((label, scene, backend, convex));
            }
        }
    }
    // rates[c]: (photons/s, interactions/s) of config c, one per round.
    let mut rates: Vec<Vec<(f64, f64)>> = vec![Vec::new(); configs.len()];
    let mut names = vec![""; configs.len()];
    for _ in 0..repeat.max(1) {
        for (c, &(_, scene, backend, convex)) in configs.iter().enumerate() {
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
            rates[c].push((s.photons_per_s, s.interactions_per_s));
            names[c] = r.backend;
        }
    }
    let mut rows: Vec<BenchRow> = Vec::new();
    // Each scene's configurations start with obvhs without the convex path: the reference.
    let mut reference = f64::NAN;
    for (c, &(label, scene, backend, convex)) in configs.iter().enumerate() {
        let photons_per_s = median(rates[c].iter().map(|r| r.0).collect());
        let interactions_per_s = median(rates[c].iter().map(|r| r.1).collect());
        if backend == BackendChoice::Bvh && !convex {
            reference = photons_per_s;
        }
        rows.push(BenchRow {
            scene: label.into(),
            triangles: scene.mesh.len(),
            backend: names[c].into(),
            convex,
            photons_per_s,
            interactions_per_s,
            ratio_to_obvhs: photons_per_s / reference,
        });
    }
    Ok(rows)
}

/// Nearest-hit queries per second for rays inside the guide: each backend, and the convex
/// path, `repeat` rounds (medians). Returns (name, queries/s) with the convex path last.
pub fn in_guide_table(
    scene_dir: &Path,
    queries: usize,
    repeat: usize,
) -> Result<Vec<(String, f64)>> {
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
                sampling::around(glam::DVec3::Z, 2.0 * rng.uniform() - 1.0, rng.uniform()),
            ));
        }
    }
    let accels: Vec<Box<dyn Accel>> = backends()
        .into_iter()
        .map(|b| accel::build(b, scene.mesh.clone()))
        .collect::<Result<_>>()?;
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); accels.len() + 1];
    for _ in 0..repeat.max(1) {
        for (a, accel) in accels.iter().enumerate() {
            times[a].push(rate(&rays, |r| {
                accel.intersect(r, f64::INFINITY).map_or(0, |h| h.prim)
            }));
        }
        times[accels.len()].push(rate(&rays, |r| {
            solid.exit(&scene.mesh, r).map_or(0, |h| h.prim)
        }));
    }
    let names = accels
        .iter()
        .map(|a| a.name().to_string())
        .chain(["convex".to_string()]);
    Ok(names.zip(times).map(|(n, t)| (n, median(t))).collect())
}

/// One row of the error-against-time table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ErrorRow {
    /// Backend name.
    pub backend: String,
    /// Estimator.
    pub estimator: Estimator,
    /// Photons traced in the time budget.
    pub photons: u64,
    /// Tracing seconds.
    pub seconds: f64,
    /// Relative standard error of the mean flux.
    pub mean_rel_error: f64,
    /// Mean relative standard error of the bins.
    pub bin_rel_error: f64,
    /// 1 / (err^2 t) for the mean flux.
    pub fom_mean: f64,
    /// 1 / (err^2 t) for the bins.
    pub fom_bins: f64,
}

/// Error reached in `seconds` of tracing on `scene_dir`, per backend and estimator.
pub fn error_table(
    scene_dir: &Path,
    seconds: f64,
    threads: Option<usize>,
) -> Result<Vec<ErrorRow>> {
    let scene = Scene::load(&scene_dir.join("scene.toml"))?;
    let mut rows = Vec::new();
    for backend in backends() {
        for estimator in [Estimator::Analog, Estimator::Weighted] {
            let o = RunOptions {
                photons: u64::MAX / 2,
                max_time_s: Some(seconds),
                threads,
                backend,
                estimator,
                ..RunOptions::default()
            };
            let r = run::trace(&scene, &o, &|_| {})?;
            let s = r.summary();
            let mean_rel = s.uniformity_stderr.mean / s.uniformity.mean;
            let t = s.runtime_s;
            rows.push(ErrorRow {
                backend: r.backend.into(),
                estimator,
                photons: s.photons,
                seconds: t,
                mean_rel_error: mean_rel,
                bin_rel_error: s.mean_rel_stderr,
                fom_mean: 1.0 / (mean_rel * mean_rel * t),
                fom_bins: 1.0 / (s.mean_rel_stderr * s.mean_rel_stderr * t),
            });
        }
    }
    Ok(rows)
}

/// Queries per second of `f` over `rays`, single-threaded.
fn rate(rays: &[Ray], f: impl Fn(&Ray) -> u32) -> f64 {
    timed_rate(rays.len(), || rays.iter().map(|r| u64::from(f(r))).sum())
}

/// `queries` over the seconds `run` takes; its checksum is kept from the optimizer.
fn timed_rate(queries: usize, run: impl FnOnce() -> u64) -> f64 {
    let start = Instant::now();
    std::hint::black_box(run());
    queries as f64 / start.elapsed().as_secs_f64()
}

/// Split every triangle of `tag` into `4^levels` (edge midpoints): the same surface
/// with more triangles, for benchmarks and agreement tests on large meshes.
pub fn subdivide_tag(scene: &mut Scene, tag: &str, levels: u32) -> Result<()> {
    let id = scene
        .tags
        .iter()
        .position(|t| t == tag)
        .with_context(|| format!("no tag '{tag}' in {}", scene.path.display()))?;
    scene.edit_mesh(|mesh| {
        for _ in 0..levels {
            let old = std::mem::take(&mut mesh.triangles);
            let old_tags = std::mem::take(&mut mesh.tri_tag);
            for (tri, t) in old.into_iter().zip(old_tags) {
                if t as usize != id {
                    mesh.triangles.push(tri);
                    mesh.tri_tag.push(t);
                    continue;
                }
                let [a, b, c] = tri;
                let mut mid = |u: u32, v: u32| {
                    let p = 0.5 * (mesh.positions[u as usize] + mesh.positions[v as usize]);
                    mesh.positions.push(p);
                    mesh.positions.len() as u32 - 1
                };
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                for child in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
                    mesh.triangles.push(child);
                    mesh.tri_tag.push(t);
                }
            }
        }
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_of_light_table_has_blutrace_then_both_references() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/bench-box");
        let rows = reference_table(&dir, 4096, Some(1), 2).unwrap();
        assert_eq!(rows.len(), 3);
        assert!(rows[0].tracer.starts_with("blutrace ("));
        assert!(rows[1].tracer.starts_with("reference kernel ("));
        assert!(rows[2].tracer.starts_with("reference kernel before"));
        assert_eq!(rows[1].ratio_to_reference, 1.0);
        assert_eq!(rows[2].ratio_to_old_reference, 1.0);
        for r in &rows {
            assert_eq!(
                r.ratio_to_reference,
                r.photons_per_s / rows[1].photons_per_s
            );
            assert_eq!(
                r.ratio_to_old_reference,
                r.photons_per_s / rows[2].photons_per_s
            );
        }
        for r in &rows {
            assert!(r.photons_per_s > 0.0 && r.interactions_per_s > r.photons_per_s);
        }
        let notebook =
            Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/notebook14");
        let e = reference_table(&notebook, 4096, Some(1), 1).unwrap_err();
        assert!(e.to_string().contains("box-guide scenes"), "{e}");
    }

    #[test]
    fn tables_have_every_configuration_and_obvhs_as_reference() {
        let dir =
            Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/notebook14");
        let rows = trace_table(&dir, 4096, Some(1), 2).unwrap();
        let per_scene = 2 * backends().len();
        assert_eq!(rows.len(), 2 * per_scene);
        for scene in rows.chunks(per_scene) {
            assert_eq!((scene[0].backend.as_str(), scene[0].convex), ("bvh", false));
            assert_eq!(scene[0].ratio_to_obvhs, 1.0);
            for r in scene {
                assert!(r.photons_per_s > 0.0 && r.interactions_per_s > r.photons_per_s);
                let expected = r.photons_per_s / scene[0].photons_per_s;
                assert_eq!(r.ratio_to_obvhs, expected);
            }
        }
        let large = large_mesh_table(&dir, 1000, 2).unwrap();
        assert!(large.triangles > 500_000);
        let per_set = if backends().len() > 1 { 6 } else { 2 };
        assert_eq!(large.rows.len(), 2 * per_set);
        assert_eq!(large.native_packets.is_some(), backends().len() > 1);
        for set in large.rows.chunks(per_set) {
            assert_eq!(
                (set[0].method.as_str(), set[0].ratio_to_obvhs),
                ("bvh", 1.0)
            );
            assert!(
                set.iter()
                    .all(|r| r.rays == set[0].rays && r.queries_per_s > 0.0)
            );
        }
        let queries = in_guide_table(&dir, 1000, 2).unwrap();
        assert_eq!(queries.len(), backends().len() + 1);
        assert_eq!(queries.last().unwrap().0, "convex");
        assert!(queries.iter().all(|(_, q)| *q > 0.0));
    }
}
