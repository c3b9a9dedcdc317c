//! Embree's ray packets (`EmbreeAccel::intersect_packet`, `rtcIntersect4/8/16`) answer
//! every lane exactly as `rtcIntersect1` answers the same ray alone: the same triangle and
//! the same distance, bit for bit, on the mesh `blutrace bench` times them on (notebook14
//! with its lamp reflectors split into 540k triangles).
//!
//! The rays are those the bench times: the lamps' emission and second-bounce rays (each
//! emission ray's first hit reflected diffusely), plus rays that miss the mesh, short
//! segments that end before their hit, and empty or NaN segments; packets come full and
//! partly filled. Every ray is different, so a lane answered from another lane, or a ray
//! field read from the wrong place (origin and direction components, segment ends), gives
//! a different triangle or distance for many of them; `crates/blutrace/src/accel/embree/packet.rs`
//! compares the whole hit record (normal, u, v included) on a smaller mesh.
//!
//! Without the Embree library this test FAILS, saying how to get it, unless
//! `BLUTRACE_SKIP_EMBREE=1` (then it is skipped with a note on stderr).

use blutrace::accel::embree::EmbreeAccel;
use blutrace::accel::embree::packet::{Lanes, PacketWidth};
use blutrace::accel::{Accel, Hit};
use blutrace::geometry::Ray;
use blutrace::optics::sampling;
use blutrace::rng::PhotonRng;
use blutrace::scene::Scene;
use glam::DVec3;
use std::path::Path;

/// The queries: `n` emission rays, their second bounces, misses and cut segments, mixed.
fn queries(scene: &Scene, accel: &EmbreeAccel, n: usize) -> Vec<(Ray, f64)> {
    let mut rng = PhotonRng::new(23, 0);
    let mesh = &scene.mesh;
    let far = 2.0 * scene.mesh.bounds().max_abs_coordinate();
    let mut out = Vec::new();
    for k in 0..n {
        let ray = scene.sources.sample(&mut rng).ray;
        out.push((ray, f64::INFINITY));
        if let Some(hit) = accel.intersect(&ray, f64::INFINITY) {
            let facet = mesh.facet(hit.prim);
            let (normal, point) = (facet.normal, facet.refine_hit(&ray, hit.prim, hit.t).point);
            let facing = normal * -normal.dot(ray.dir).signum();
            let dir = sampling::lambertian(facing, rng.uniform(), rng.uniform());
            let bounce = Ray::new(scene.spawn_point(point, facing, dir), dir);
            // Every third bounce is cut short: at a random fraction of its hit distance,
            // or at a random length when it misses.
            let tmax = match (k % 3, accel.intersect(&bounce, f64::INFINITY)) {
                (0, Some(h)) => h.t * 2.0 * rng.uniform(),
                (0, None) => 100.0 * rng.uniform(),
                _ => f64::INFINITY,
            };
            out.push((bounce, tmax));
        }
        // A ray from outside the scene pointing away from it: a miss.
        if k % 4 == 0 {
            let away = sampling::around(DVec3::Z, 2.0 * rng.uniform() - 1.0, rng.uniform());
            out.push((Ray::new(far * away, away), f64::INFINITY));
        }
    }
    out
}

/// Lane by lane, packets of N (every seventh packet filled with fewer queries) against
/// single rays: (packets, hits, misses).
fn compare<const N: usize>(accel: &EmbreeAccel, queries: &[(Ray, f64)]) -> (usize, usize, usize)
where
    Lanes<N>: PacketWidth,
{
    let bits = |h: Option<Hit>| h.map(|h| (h.prim, h.t.to_bits()));
    let (mut packets, mut hits, mut misses) = (0, 0, 0);
    let mut rest = queries;
    while !rest.is_empty() {
        let take = if packets % 7 == 6 { 1 + packets % N } else { N };
        let (packet, tail) = rest.split_at(take.min(rest.len()));
        rest = tail;
        let got = accel.intersect_packet::<N>(packet);
        for (i, (ray, tmax)) in packet.iter().enumerate() {
            let one = accel.intersect(ray, *tmax);
            assert_eq!(
                bits(got[i]),
                bits(one),
                "packet {packets} of {N}, lane {i}: {ray:?} up to {tmax}"
            );
            if one.is_some() {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        assert!(got[packet.len()..].iter().all(Option::is_none));
        packets += 1;
    }
    (packets, hits, misses)
}

#[test]
fn packets_answer_each_lane_as_single_rays_do() {
    if std::env::var("BLUTRACE_SKIP_EMBREE").is_ok_and(|v| v == "1") {
        eprintln!("BLUTRACE_SKIP_EMBREE=1: Embree packets not checked");
        return;
    }
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/notebook14");
    let mut scene = Scene::load(&dir.join("scene.toml")).unwrap();
    blutrace_bench::subdivide_tag(&mut scene, "lamp_reflector", 5).unwrap();
    assert!(scene.mesh.len() > 500_000);
    let accel = EmbreeAccel::new(scene.mesh.clone()).unwrap_or_else(|e| {
        panic!(
            "the Embree backend is unavailable: {e:#}\n(on a machine without network, set \
             BLUTRACE_SKIP_EMBREE=1 to skip the Embree checks)"
        )
    });
    let queries = queries(&scene, &accel, 4000);
    let mut reversed = queries.clone();
    reversed.reverse();
    for (width, (packets, hits, misses)) in [
        (4, compare::<4>(&accel, &queries)),
        (8, compare::<8>(&accel, &queries)),
        (16, compare::<16>(&accel, &reversed)),
    ] {
        eprintln!("packets of {width}: {packets} packets, {hits} hits, {misses} misses");
        assert!(hits > 6000 && misses > 1000, "{hits} hits, {misses} misses");
    }
    eprintln!("native widths: {}", accel.native_packets());
}
