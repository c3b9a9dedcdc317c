//! Nearest-hit queries in the lamp cavities of the large scene (notebook14 with its lamp
//! reflectors split into about 540k triangles), against the mesh alone: the backends
//! without the shared per-hit code of whole photon paths, one thread.
//!
//! Two ray sets of `queries` rays each: the lamps' own emission (rays from the tubes into
//! their reflector cavities), and second-bounce rays (each emission ray's first hit,
//! reflected diffusely with the tracer's Lambertian sampling from the side it came from),
//! which is what most of a photon's queries look like. On each: obvhs and Embree one ray
//! at a time, then Embree's packets of 8 (`rtcIntersect8`) on the rays in their own order
//! (as a photon-by-photon tracer would hand them over: incoherent), and on the rays sorted
//! by lamp, direction octant and position (the best case a wavefront tracer could arrange
//! by sorting; the sort is not timed), with Embree one ray at a time on the same sorted
//! rays beside it, to tell what the packets gain from what the order alone gains (cache),
//! and obvhs on the sorted rays too: sorting helps both backends.

use super::{median, rate, timed_rate};
use anyhow::Result;
use blutrace::accel::Accel;
use blutrace::accel::bvh::ObvhsBvh;
use blutrace::accel::embree::{self, EmbreeAccel, packet::NativePackets};
use blutrace::geometry::{Aabb, Ray};
use blutrace::optics::sampling;
use blutrace::rng::PhotonRng;
use blutrace::scene::Scene;
use std::path::Path;

/// One row of the lamp-cavity table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CavityRow {
    /// The ray set: "emission" or "second bounce".
    pub rays: &'static str,
    /// Backend and how the rays were handed to it.
    pub method: String,
    /// Nearest-hit queries per second (median of the rounds).
    pub queries_per_s: f64,
    /// queries_per_s over obvhs's on the same rays.
    pub ratio_to_obvhs: f64,
}

/// The lamp-cavity table and what it was measured on.
#[derive(Clone, Debug)]
pub struct CavityTable {
    /// Triangles in the mesh.
    pub triangles: usize,
    /// The Embree packet widths traced natively here (`None` without Embree).
    pub native_packets: Option<NativePackets>,
    /// Per ray set: obvhs first, then the Embree rows.
    pub rows: Vec<CavityRow>,
}

/// A ray and the lamp it came from.
#[derive(Clone, Copy)]
struct LampRay {
    ray: Ray,
    lamp: usize,
}

/// How a ray set is ordered and handed to a backend.
#[derive(Clone, Copy, PartialEq)]
enum Order {
    /// As produced, photon after photon.
    Produced,
    /// Grouped by lamp and direction octant, then by position (Morton order).
    Sorted,
}

/// Rounds of this table at most (see [`large_mesh_table`]).
const MAX_ROUNDS: usize = 3;

/// How a row queries: obvhs, Embree one ray at a time, or Embree's packets of 8.
#[derive(Clone, Copy, PartialEq)]
enum Query {
    Bvh,
    Embree,
    EmbreePackets,
}

/// The timed configurations: (label, how, order). obvhs first: the ratios' reference.
const ROWS: [(&str, Query, Order); 6] = [
    ("bvh", Query::Bvh, Order::Produced),
    (
        "bvh (sorted: by lamp, direction octant, position)",
        Query::Bvh,
        Order::Sorted,
    ),
    ("embree, one ray at a time", Query::Embree, Order::Produced),
    (
        "embree, one ray at a time (sorted: by lamp, direction octant, position)",
        Query::Embree,
        Order::Sorted,
    ),
    (
        "embree, packets of 8 (incoherent: rays in the order produced)",
        Query::EmbreePackets,
        Order::Produced,
    ),
    (
        "embree, packets of 8 (sorted: by lamp, direction octant, position)",
        Query::EmbreePackets,
        Order::Sorted,
    ),
];

/// Queries per second on the large scene of `scene_dir`, for `queries` emission rays and
/// the second-bounce rays of those that hit, in `min(repeat, 3)` rounds (medians; each
/// round times every row in turn). Three rounds: ten rows of a million queries each last
/// a few seconds a round, long enough that a median of three is steady, and five would
/// add half a minute to `blutrace bench`.
pub fn large_mesh_table(scene_dir: &Path, queries: usize, repeat: usize) -> Result<CavityTable> {
    let mut scene = Scene::load(&scene_dir.join("scene.toml"))?;
    crate::subdivide_tag(&mut scene, "lamp_reflector", 5)?;
    let bvh = ObvhsBvh::new(scene.mesh.clone());
    let embree = match embree::info() {
        Ok(_) => Some(EmbreeAccel::new(scene.mesh.clone())?),
        Err(_) => None,
    };
    let mut rng = PhotonRng::new(11, 0);
    let emitted = emission(&scene, queries, &mut rng);
    // The first hits from obvhs: the same rays whether or not Embree is here.
    let bounced = second_bounce(&scene, &bvh, &emitted, &mut rng);
    let bounds = scene.mesh.bounds();
    let mut rows = Vec::new();
    for (label, set) in [("emission", &emitted), ("second bounce", &bounced)] {
        let produced: Vec<Ray> = set.iter().map(|r| r.ray).collect();
        let sorted = sorted(set, &bounds);
        let medians = medians(&bvh, embree.as_ref(), [&produced, &sorted], repeat);
        for (name, q) in medians.iter() {
            rows.push(CavityRow {
                rays: label,
                method: (*name).into(),
                queries_per_s: *q,
                ratio_to_obvhs: q / medians[0].1,
            });
        }
    }
    Ok(CavityTable {
        triangles: scene.mesh.len(),
        native_packets: embree.as_ref().map(EmbreeAccel::native_packets),
        rows,
    })
}

/// Median queries per second of each of [`ROWS`] (the Embree rows when Embree is here)
/// over `min(repeat, 3)` rounds, with the rows' labels.
fn medians(
    bvh: &ObvhsBvh,
    embree: Option<&EmbreeAccel>,
    [produced, sorted]: [&[Ray]; 2],
    repeat: usize,
) -> Vec<(&'static str, f64)> {
    let rows: Vec<_> = ROWS
        .iter()
        .filter(|r| r.1 == Query::Bvh || embree.is_some())
        .collect();
    let mut times = vec![Vec::new(); rows.len()];
    for _ in 0..repeat.clamp(1, MAX_ROUNDS) {
        for (k, &&(_, query, order)) in rows.iter().enumerate() {
            let rays = if order == Order::Sorted {
                sorted
            } else {
                produced
            };
            let nearest = |a: &dyn Accel| {
                rate(rays, |r| {
                    a.intersect(r, f64::INFINITY).map_or(0, |h| h.prim)
                })
            };
            times[k].push(match (query, embree) {
                (Query::EmbreePackets, Some(e)) => packet_rate(e, rays),
                (Query::Embree, Some(e)) => nearest(e),
                // Only the obvhs rows are kept without Embree.
                _ => nearest(bvh),
            });
        }
    }
    rows.iter()
        .zip(times)
        .map(|(r, t)| (r.0, median(t)))
        .collect()
}

/// `n` rays the lamps emit, each with the lamp that emitted it.
fn emission(scene: &Scene, n: usize, rng: &mut PhotonRng) -> Vec<LampRay> {
    (0..n)
        .map(|_| {
            let e = scene.sources.sample(rng);
            LampRay {
                ray: e.ray,
                lamp: e.source,
            }
        })
        .collect()
}

/// Each hitting ray of `emitted`, reflected diffusely where it first meets the mesh (the
/// paper's Lambertian direction around the normal facing it, spawned off the surface as
/// the tracer does). Rays that miss the mesh are left out.
fn second_bounce(
    scene: &Scene,
    accel: &dyn Accel,
    emitted: &[LampRay],
    rng: &mut PhotonRng,
) -> Vec<LampRay> {
    let mesh = &scene.mesh;
    emitted
        .iter()
        .filter_map(|e| {
            let hit = accel.intersect(&e.ray, f64::INFINITY)?;
            let facet = mesh.facet(hit.prim);
            let (normal, point) = (
                facet.normal,
                facet.refine_hit(&e.ray, hit.prim, hit.t).point,
            );
            let facing = if normal.dot(e.ray.dir) < 0.0 {
                normal
            } else {
                -normal
            };
            let dir = sampling::lambertian(facing, rng.uniform(), rng.uniform());
            let origin = scene.spawn_point(point, facing, dir);
            Some(LampRay {
                ray: Ray::new(origin, dir),
                lamp: e.lamp,
            })
        })
        .collect()
}

/// The rays grouped by lamp and direction octant, each group in Morton order of the
/// origins (10 bits per axis over `bounds`).
fn sorted(rays: &[LampRay], bounds: &Aabb) -> Vec<Ray> {
    let size = (bounds.max - bounds.min).max(glam::DVec3::splat(1e-9));
    let key = |r: &LampRay| {
        let d = r.ray.dir;
        let octant = u32::from(d.x < 0.0) | u32::from(d.y < 0.0) << 1 | u32::from(d.z < 0.0) << 2;
        let cell = ((r.ray.origin - bounds.min) / size * 1023.0)
            .clamp(glam::DVec3::ZERO, glam::DVec3::splat(1023.0));
        let morton = [cell.x, cell.y, cell.z]
            .iter()
            .enumerate()
            .map(|(axis, &c)| spread_bits(c as u32) << axis)
            .fold(0, |a, b| a | b);
        (r.lamp, octant, morton)
    };
    let mut sorted = rays.to_vec();
    sorted.sort_by_key(key);
    sorted.into_iter().map(|r| r.ray).collect()
}

/// The low 10 bits of `v`, two zero bits after each (Morton interleaving).
fn spread_bits(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | x << 16) & 0x0300_00ff;
    x = (x | x << 8) & 0x0300_f00f;
    x = (x | x << 4) & 0x030c_30c3;
    (x | x << 2) & 0x0924_9249
}

/// Queries per second of `rtcIntersect8` over `rays`, eight at a time, single-threaded
/// (packing the rays into the packet's layout included).
fn packet_rate(e: &EmbreeAccel, rays: &[Ray]) -> f64 {
    let queries: Vec<(Ray, f64)> = rays.iter().map(|&r| (r, f64::INFINITY)).collect();
    timed_rate(rays.len(), || {
        let packets = queries
            .chunks(8)
            .map(|chunk| e.intersect_packet::<8>(chunk));
        packets.flatten().flatten().map(|h| u64::from(h.prim)).sum()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_bits_interleave() {
        assert_eq!(spread_bits(0b1), 0b1);
        assert_eq!(spread_bits(0b11), 0b1001);
        assert_eq!(spread_bits(0x3ff), 0x0924_9249);
        assert_eq!(spread_bits(0x400), 0);
    }
}
