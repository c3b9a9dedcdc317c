//! The intersection backends agree: Embree (`accel::embree`), the obvhs BVH and the brute
//! force oracle find the same triangle at the same distance for fixed, seeded rays, on
//! meshes built here (boxes, a 100k-triangle sphere, a curved reflector, a mesh with
//! degenerate triangles, an empty mesh) and on the bundled scenes under `scenes/`.
//!
//! Agreement means: both miss, or both hit the same triangle with distances equal within
//! f32 precision (relative 1e-5 of the distance plus the scene's extent, divided by the
//! grazing cosine: rounding a ray to f32 moves a grazing hit along the ray by ulp/cos).
//! A different triangle is accepted only at the same distance and with the hit point on
//! that triangle within the same tolerance: a tie on a shared edge.
//!
//! Embree is a run-time loaded library (`bash tools/fetch-embree.sh` fetches it). Without
//! it these tests FAIL, saying how to get it. On a machine without network, where the
//! script cannot run, set `BLUTRACE_SKIP_EMBREE=1`: the Embree side is then skipped (with a
//! note on stderr) and only the BVH is checked against the oracle.

use blutrace::accel::brute::BruteForce;
use blutrace::accel::bvh::ObvhsBvh;
use blutrace::accel::culled::Culled;
use blutrace::accel::embree::EmbreeAccel;
use blutrace::accel::{self, Accel, BackendChoice, Hit};
use blutrace::geometry::{Mesh, Ray, orthonormal_basis, spawn_epsilon};
use blutrace::rng::PhotonRng;
use blutrace::scene::Scene;
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// True when the machine opted out of Embree (no network to fetch it).
fn skip_embree() -> bool {
    std::env::var("BLUTRACE_SKIP_EMBREE").is_ok_and(|v| v == "1")
}

/// Embree over `mesh`; panics loudly when the library is missing, unless opted out.
fn embree(mesh: &Arc<Mesh>) -> Option<EmbreeAccel> {
    if skip_embree() {
        eprintln!("BLUTRACE_SKIP_EMBREE=1: Embree not checked, only the BVH against brute force");
        return None;
    }
    Some(EmbreeAccel::new(mesh.clone()).unwrap_or_else(|e| {
        panic!(
            "the Embree backend is unavailable: {e:#}\n(on a machine without network, set \
             BLUTRACE_SKIP_EMBREE=1 to skip the Embree checks)"
        )
    }))
}

/// The backends under test, each to be checked against the oracle.
fn candidates(mesh: &Arc<Mesh>) -> Vec<Box<dyn Accel>> {
    let mut list: Vec<Box<dyn Accel>> = vec![Box::new(ObvhsBvh::new(mesh.clone()))];
    if let Some(e) = embree(mesh) {
        list.push(Box::new(e));
    }
    list
}

// ---------------------------------------------------------------------------------------
// Comparison

/// A query: a ray and its `tmax`.
type Query = (Ray, f64);

/// Closest point to `p` on the triangle `[a, b, c]` (Ericson, Real-Time Collision
/// Detection 5.1.5); degenerate triangles fall back to their edges.
fn closest_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> DVec3 {
    if (b - a).cross(c - a).length_squared() == 0.0 {
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(s, e)| closest_on_segment(p, s, e))
            .min_by(|x, y| (*x - p).length().total_cmp(&(*y - p).length()))
            .unwrap();
    }
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

fn closest_on_segment(p: DVec3, s: DVec3, e: DVec3) -> DVec3 {
    let d = e - s;
    let l2 = d.length_squared();
    if l2 == 0.0 {
        return s;
    }
    s + d * ((p - s).dot(d) / l2).clamp(0.0, 1.0)
}

/// The oracle's answers for a set of queries.
struct Oracle {
    /// Brute force over the mesh as it is.
    raw: Vec<Option<Hit>>,
    /// Brute force over the mesh with its zero-area triangles collapsed to a point: the
    /// f64 test's determinant of a zero-area triangle is rounding noise, not always 0, so
    /// the raw oracle can "hit" one; Embree never does.
    clean: Vec<Option<Hit>>,
}

impl Oracle {
    fn new(mesh: &Arc<Mesh>, queries: &[Query]) -> Self {
        let raw = BruteForce::new(mesh.clone());
        let raw: Vec<_> = queries
            .par_iter()
            .map(|(r, tmax)| raw.intersect(r, *tmax))
            .collect();
        let mut collapsed = (**mesh).clone();
        for p in 0..collapsed.len() {
            if mesh.area_normal(p as u32) == DVec3::ZERO {
                let [a, _, _] = collapsed.triangles[p];
                collapsed.triangles[p] = [a, a, a];
            }
        }
        let clean = BruteForce::new(Arc::new(collapsed));
        let clean = queries
            .par_iter()
            .map(|(r, tmax)| clean.intersect(r, *tmax))
            .collect();
        Self { raw, clean }
    }
}

/// Checks of one backend against the oracle on one mesh.
struct Checker<'a> {
    mesh: &'a Mesh,
    /// Largest absolute coordinate (>= 1): the scale of f32 rounding.
    scale: f64,
    /// Edges of exactly one non-degenerate triangle (by position): the mesh's open border.
    border: Vec<(DVec3, DVec3)>,
}

/// How a backend's answer relates to the oracle's.
enum Verdict {
    /// Same triangle (or both miss).
    Same,
    /// Another triangle at the same distance, the oracle's point on it.
    Tie,
    /// The raw oracle hit a zero-area triangle; the backend agrees with the clean oracle.
    OracleDegenerate,
    /// A hit on a shared edge through which the f64 oracle leaked.
    OracleLeak,
    /// One side hit, the other missed, within f32 precision of the mesh's open border.
    BorderGraze,
}

impl<'a> Checker<'a> {
    fn new(mesh: &'a Mesh) -> Self {
        let key = |p: DVec3| p.to_array().map(f64::to_bits);
        let mut edges = std::collections::HashMap::new();
        for prim in 0..mesh.len() as u32 {
            if mesh.area_normal(prim) == DVec3::ZERO {
                continue;
            }
            let c = mesh.corners(prim);
            for (a, b) in [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])] {
                let (a, b) = if key(a) <= key(b) { (a, b) } else { (b, a) };
                edges.entry((key(a), key(b))).or_insert((a, b, 0u32)).2 += 1;
            }
        }
        let border = edges
            .into_values()
            .filter(|e| e.2 == 1)
            .map(|e| (e.0, e.1))
            .collect();
        Self {
            mesh,
            scale: mesh.bounds().max_abs_coordinate().max(1.0),
            border,
        }
    }

    /// Allowed distance error at distance `t` for a ray meeting triangle `prim`.
    fn tol(&self, ray: &Ray, prim: u32, t: f64) -> f64 {
        let cos = self.mesh.normal(prim).dot(ray.dir).abs().max(1e-6);
        1e-5 * (t.abs() + self.scale) / cos
    }

    /// Distance from `p` to triangle `prim`.
    fn off(&self, p: DVec3, prim: u32) -> f64 {
        (closest_on_triangle(p, self.mesh.corners(prim)) - p).length()
    }

    /// True when `p`, on triangle `prim`, also lies on another (non-degenerate) triangle
    /// within `tol`: a point on a shared edge or vertex.
    fn on_shared_edge(&self, p: DVec3, prim: u32, tol: f64) -> bool {
        self.off(p, prim) <= tol
            && (0..self.mesh.len() as u32).any(|q| {
                q != prim && self.mesh.area_normal(q) != DVec3::ZERO && self.off(p, q) <= tol
            })
    }

    /// True when `p` is within `tol` of the mesh's open border.
    fn on_border(&self, p: DVec3, tol: f64) -> bool {
        self.border
            .iter()
            .any(|&(a, b)| (closest_on_segment(p, a, b) - p).length() <= tol)
    }

    /// How `got` compares with the oracle; `Err` says why they disagree.
    fn judge(
        &self,
        ray: &Ray,
        raw: Option<Hit>,
        clean: Option<Hit>,
        got: Option<Hit>,
    ) -> Result<Verdict, String> {
        if let Some(w) = raw.filter(|w| self.mesh.area_normal(w.prim) == DVec3::ZERO) {
            if got.is_some_and(|g| g.prim == w.prim) {
                return Ok(Verdict::Same);
            }
            return match self.judge(ray, clean, clean, got)? {
                Verdict::Same => Ok(Verdict::OracleDegenerate),
                other => Ok(other),
            };
        }
        match (raw, got) {
            (None, None) => Ok(Verdict::Same),
            (Some(w), Some(g)) => {
                let tol = self.tol(ray, w.prim, w.t);
                let g_tol = self.tol(ray, g.prim, g.t);
                if g.t < w.t - tol && self.on_shared_edge(ray.at(g.t), g.prim, g_tol) {
                    // The oracle slipped through a shared edge nearer than its hit.
                    return Ok(Verdict::OracleLeak);
                }
                if (g.t - w.t).abs() > tol {
                    return Err(format!(
                        "distance {} vs oracle {} (prims {} / {}, tol {tol:.3e})",
                        g.t, w.t, g.prim, w.prim
                    ));
                }
                if g.prim == w.prim {
                    return Ok(Verdict::Same);
                }
                // A tie: the oracle's hit point must lie on the other triangle too.
                let off = self.off(ray.at(w.t), g.prim);
                if off <= tol {
                    Ok(Verdict::Tie)
                } else {
                    Err(format!(
                        "prim {} vs oracle {} at t {} (the oracle's point is {off:.3e} off \
                         prim {}, tol {tol:.3e})",
                        g.prim, w.prim, w.t, g.prim
                    ))
                }
            }
            (None, Some(g)) => {
                let (p, tol) = (ray.at(g.t), self.tol(ray, g.prim, g.t));
                if self.off(p, g.prim) <= tol && self.on_border(p, tol) {
                    Ok(Verdict::BorderGraze)
                } else if self.on_shared_edge(p, g.prim, tol) {
                    // The f64 Moller-Trumbore oracle is not watertight: a ray through a
                    // shared edge can slip between both triangles, where Embree's robust
                    // (watertight) test hits one of them.
                    Ok(Verdict::OracleLeak)
                } else {
                    Err(format!("hit prim {} at t {}, oracle misses", g.prim, g.t))
                }
            }
            (Some(w), None) => {
                // A miss is excused only at the open border (the ray rounded to f32 passes
                // it); through a shared edge it would be a leak.
                let (p, tol) = (ray.at(w.t), self.tol(ray, w.prim, w.t));
                if self.on_border(p, tol) {
                    Ok(Verdict::BorderGraze)
                } else {
                    Err(format!("miss, oracle hits prim {} at t {}", w.prim, w.t))
                }
            }
        }
    }
}

/// Outcome counts of one comparison, for the log.
#[derive(Default, Debug)]
struct Tally {
    hits: usize,
    ties: usize,
    oracle_degenerate: usize,
    oracle_leaks: usize,
    border_grazes: usize,
}

/// Compare every candidate with the oracle on `queries`; panics listing disagreements.
fn compare(label: &str, mesh: &Arc<Mesh>, queries: &[Query]) {
    let oracle = Oracle::new(mesh, queries);
    let checker = Checker::new(mesh);
    for accel in candidates(mesh) {
        compare_one(label, &checker, accel.as_ref(), queries, &oracle);
    }
}

fn compare_one(
    label: &str,
    checker: &Checker,
    accel: &dyn Accel,
    queries: &[Query],
    oracle: &Oracle,
) {
    let got: Vec<Option<Hit>> = queries
        .par_iter()
        .map(|(r, tmax)| accel.intersect(r, *tmax))
        .collect();
    let verdicts: Vec<Result<Verdict, String>> = (0..queries.len())
        .into_par_iter()
        .map(|i| checker.judge(&queries[i].0, oracle.raw[i], oracle.clean[i], got[i]))
        .collect();
    let mut tally = Tally::default();
    let mut report = String::new();
    let mut bad = 0;
    for (i, v) in verdicts.into_iter().enumerate() {
        tally.hits += oracle.raw[i].is_some() as usize;
        match v {
            Ok(Verdict::Same) => {}
            Ok(Verdict::Tie) => tally.ties += 1,
            Ok(Verdict::OracleDegenerate) => tally.oracle_degenerate += 1,
            Ok(Verdict::OracleLeak) => tally.oracle_leaks += 1,
            Ok(Verdict::BorderGraze) => tally.border_grazes += 1,
            Err(why) => {
                bad += 1;
                if bad <= 12 {
                    let (r, tmax) = &queries[i];
                    let _ = writeln!(
                        report,
                        "  ray {i}: origin {:?} dir {:?} tmax {tmax}: {why}",
                        r.origin.to_array(),
                        r.dir.to_array()
                    );
                }
            }
        }
    }
    eprintln!(
        "{label}: {} vs brute on {} rays: {tally:?}, {bad} disagreements",
        accel.name(),
        queries.len()
    );
    assert!(
        bad == 0,
        "{label}: {} disagrees with brute force on {bad} of {} rays:\n{report}",
        accel.name(),
        queries.len()
    );
}

// ---------------------------------------------------------------------------------------
// Deterministic rays

fn unit_sphere(rng: &mut PhotonRng) -> DVec3 {
    let z = 2.0 * rng.uniform() - 1.0;
    let phi = TAU * rng.uniform();
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

fn point_on_triangle(mesh: &Mesh, prim: u32, rng: &mut PhotonRng) -> DVec3 {
    let [a, b, c] = mesh.corners(prim);
    let (mut u, mut v) = (rng.uniform(), rng.uniform());
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    a + (b - a) * u + (c - a) * v
}

/// `n` seeded queries around `mesh`: a third from random points in random directions, a
/// third aimed at random points of random triangles, a third leaving a random surface
/// point (started the scene's spawn offset off it, as the tracer does). A quarter get a
/// finite `tmax`.
fn queries(mesh: &Mesh, n: usize, seed: u64) -> Vec<Query> {
    let b = mesh.bounds();
    let (center, half) = if b.is_empty() {
        (DVec3::ZERO, DVec3::ONE)
    } else {
        (
            0.5 * (b.min + b.max),
            (0.5 * (b.max - b.min)).max(DVec3::splat(0.5)),
        )
    };
    let eps = spawn_epsilon(b.max_abs_coordinate());
    (0..n as u64)
        .map(|i| {
            let mut rng = PhotonRng::new(seed, i);
            let mut inside = || {
                center
                    + half
                        * 1.5
                        * DVec3::new(rng.uniform(), rng.uniform(), rng.uniform())
                            .map(|x| 2.0 * x - 1.0)
            };
            let kind = if mesh.is_empty() { 0 } else { i % 3 };
            let ray = match kind {
                0 => {
                    let o = inside();
                    Ray::new(o, unit_sphere(&mut rng))
                }
                1 => {
                    let o = inside();
                    let prim = (rng.uniform() * mesh.len() as f64) as u32;
                    let target = point_on_triangle(mesh, prim, &mut rng);
                    let d = (target - o).normalize_or(DVec3::Z);
                    Ray::new(o, d)
                }
                _ => {
                    // A real surface (the tracer never leaves a degenerate triangle).
                    let mut prim = (rng.uniform() * mesh.len() as f64) as u32;
                    while mesh.area_normal(prim) == DVec3::ZERO {
                        prim = (rng.uniform() * mesh.len() as f64) as u32;
                    }
                    let p = point_on_triangle(mesh, prim, &mut rng);
                    let n = mesh.normal(prim);
                    let mut d = unit_sphere(&mut rng);
                    if d.dot(n) == 0.0 {
                        d = n;
                    }
                    Ray::new(p + n * eps.copysign(d.dot(n)), d)
                }
            };
            let tmax = if i % 4 == 3 {
                rng.uniform() * 4.0 * half.length()
            } else {
                f64::INFINITY
            };
            (ray, tmax)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Test meshes

/// An indexed mesh from positions and triangles (one tag for all).
fn mesh(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Mesh {
    let tri_tag = vec![0; triangles.len()];
    Mesh {
        positions,
        triangles,
        tri_tag,
    }
}

/// A closed box of 12 triangles, wound outward, moved by `xf` then `shift`.
fn box_mesh(half: DVec3, xf: DMat3, shift: DVec3) -> Mesh {
    let positions = (0..8)
        .map(|i| {
            let s = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            xf * (s * half) + shift
        })
        .collect();
    let faces = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let triangles = faces
        .iter()
        .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
        .collect();
    mesh(positions, triangles)
}

/// A UV sphere: `lon` segments around, `lat` bands from pole to pole.
fn uv_sphere(radius: f64, center: DVec3, lon: u32, lat: u32) -> Mesh {
    let mut positions = vec![center + DVec3::Z * radius, center - DVec3::Z * radius];
    for j in 1..lat {
        let theta = PI * j as f64 / lat as f64;
        for i in 0..lon {
            let phi = TAU * i as f64 / lon as f64;
            let d = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            positions.push(center + d * radius);
        }
    }
    let ring = |j: u32, i: u32| 2 + (j - 1) * lon + (i % lon);
    let mut triangles = Vec::new();
    for i in 0..lon {
        triangles.push([0, ring(1, i), ring(1, i + 1)]);
        triangles.push([1, ring(lat - 1, i + 1), ring(lat - 1, i)]);
        for j in 1..lat - 1 {
            let (a, b, c, d) = (
                ring(j, i),
                ring(j, i + 1),
                ring(j + 1, i),
                ring(j + 1, i + 1),
            );
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    mesh(positions, triangles)
}

/// A CCFL reflector: a parabolic trough `z = x^2 / (4 f)` over `|x| <= w`, `|y| <= l`, with
/// an `nx` x `ny` grid of quads; tilted so no coordinate is special.
fn trough(f: f64, w: f64, l: f64, nx: u32, ny: u32) -> Mesh {
    let tilt = DMat3::from_rotation_y(0.3) * DMat3::from_rotation_x(-0.2);
    let mut positions = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let x = -w + 2.0 * w * i as f64 / nx as f64;
            let y = -l + 2.0 * l * j as f64 / ny as f64;
            positions.push(tilt * DVec3::new(x, y, x * x / (4.0 * f)) + DVec3::new(0.3, -0.7, 1.1));
        }
    }
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    mesh(positions, triangles)
}

/// Two parallel quad grids (dyadic coordinates, exact in f32) sprinkled with degenerate
/// triangles: repeated corners, points, collinear triples on grid lines and floating in
/// space, and sliver triangles along grid lines (zero area in f64 and in f32).
fn degenerate_mesh() -> Mesh {
    let n = 16u32;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (layer, z) in [0.0, 1.5].into_iter().enumerate() {
        let base = positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64 * 0.25 - 2.0, j as f64 * 0.25 - 2.0, z));
            }
        }
        let at = |i: u32, j: u32| base + j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
                if (i + j + layer as u32).is_multiple_of(2) {
                    triangles.push([a, b, d]);
                    triangles.push([a, d, c]);
                } else {
                    triangles.push([a, b, c]);
                    triangles.push([b, d, c]);
                }
                // Degenerates between the real triangles.
                match (i * 7 + j * 3) % 5 {
                    0 => triangles.push([a, a, d]),
                    1 => triangles.push([b, b, b]),
                    2 => triangles.push([a, b, at((i + 2).min(n), j)]),
                    _ => {}
                }
            }
        }
    }
    // Collinear triples floating between the layers (exact in f32 too).
    for k in 0..40 {
        let base = positions.len() as u32;
        let p = DVec3::new(-2.0 + 0.125 * k as f64, -1.0 + 0.0625 * k as f64, 0.75);
        let d = DVec3::new(0.25, 0.5, 0.125);
        positions.extend([p, p + d, p + 2.0 * d]);
        triangles.push([base, base + 1, base + 2]);
        triangles.push([base + 2, base, base + 1]);
    }
    mesh(positions, triangles)
}

// ---------------------------------------------------------------------------------------
// Tests

#[test]
fn boxes() {
    let plate = Arc::new(box_mesh(
        DVec3::new(30.0, 20.0, 2.0),
        DMat3::IDENTITY,
        DVec3::ZERO,
    ));
    compare("axis-aligned box", &plate, &queries(&plate, 30_000, 1));
    let xf = DMat3::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
    let tilted = Arc::new(box_mesh(
        DVec3::new(3.1, 0.7, 1.9),
        xf,
        DVec3::new(0.37, -1.21, 0.05),
    ));
    compare("tilted box", &tilted, &queries(&tilted, 30_000, 2));
}

#[test]
fn fine_sphere() {
    let sphere = Arc::new(uv_sphere(12.5, DVec3::new(0.1, -0.2, 0.3), 256, 200));
    assert!(sphere.len() >= 100_000, "{} triangles", sphere.len());
    compare(
        "sphere (101,888 triangles)",
        &sphere,
        &queries(&sphere, 3_000, 3),
    );
}

#[test]
fn curved_reflector() {
    let reflector = Arc::new(trough(2.0, 6.0, 40.0, 120, 200));
    compare(
        "parabolic trough (48,000 triangles)",
        &reflector,
        &queries(&reflector, 4_000, 4),
    );
}

#[test]
fn degenerate_triangles() {
    let m = Arc::new(degenerate_mesh());
    let degenerate = (0..m.len() as u32)
        .filter(|&p| m.area_normal(p) == DVec3::ZERO)
        .count();
    assert!(degenerate > 300, "only {degenerate} degenerate triangles");
    compare("degenerate triangles", &m, &queries(&m, 20_000, 5));
}

#[test]
fn empty_mesh() {
    let m = Arc::new(Mesh::default());
    compare("empty mesh", &m, &queries(&m, 200, 6));
    for accel in candidates(&m) {
        let r = Ray::new(DVec3::ZERO, DVec3::X);
        assert_eq!(accel.intersect(&r, f64::INFINITY), None, "{}", accel.name());
    }
}

/// `auto` picks Embree when it loads; `embree` is Embree; inside a 2-thread pool.
#[test]
fn build_picks_backends() {
    let m = Arc::new(box_mesh(DVec3::ONE, DMat3::IDENTITY, DVec3::ZERO));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let name = |c: BackendChoice| {
        pool.install(|| accel::build(c, m.clone()))
            .map(|a| a.name())
            .map_err(|e| format!("{e:#}"))
    };
    assert_eq!(name(BackendChoice::Bvh), Ok("bvh"));
    assert_eq!(name(BackendChoice::Brute), Ok("brute"));
    if skip_embree() {
        eprintln!("BLUTRACE_SKIP_EMBREE=1: not checking that auto picks Embree");
        return;
    }
    // Fails loudly (with how to fetch it) when Embree is missing.
    embree(&m);
    assert_eq!(name(BackendChoice::Embree), Ok("embree"));
    assert_eq!(name(BackendChoice::Auto), Ok("embree"));
}

/// Every `scene.toml` under `dir`, sorted.
fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return found;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            found.extend(scene_files(&p));
        } else if p.file_name().is_some_and(|n| n == "scene.toml") {
            found.push(p);
        }
    }
    found.sort();
    found
}

/// Photon paths of a scene: each source ray, then up to `bounces` rays leaving the
/// oracle's hit in a random direction (off the surface by the scene's spawn offset, as
/// the tracer does), so the backends are compared on the rays a trace really casts.
fn scene_queries(scene: &Scene, photons: u64, bounces: usize, seed: u64) -> Vec<Query> {
    let oracle = BruteForce::new(scene.mesh.clone());
    (0..photons)
        .into_par_iter()
        .flat_map_iter(|i| {
            let mut rng = PhotonRng::new(seed, i);
            let e = scene.sources.sample(&mut rng);
            let mut ray = Ray::new(
                scene.spawn_point(e.ray.origin, e.normal, e.ray.dir),
                e.ray.dir,
            );
            let mut out = Vec::new();
            for _ in 0..=bounces {
                out.push((ray, f64::INFINITY));
                let Some(h) = oracle.intersect(&ray, f64::INFINITY) else {
                    break;
                };
                let s = scene.mesh.facet(h.prim).refine_hit(&ray, h.prim, h.t);
                let mut d = unit_sphere(&mut rng);
                if d.dot(s.normal) == 0.0 {
                    d = s.normal;
                }
                let (t, b) = orthonormal_basis(s.normal);
                debug_assert!(t.dot(b).abs() < 1e-9);
                ray = Ray::new(scene.spawn_point(s.point, s.normal, d), d);
            }
            out
        })
        .collect()
}

/// Behind the mesh's box ([`Culled`]) every backend answers as it does alone, bit for
/// bit, on the rays of the bundled scenes' photon paths and rays leaving their surfaces;
/// and the box does spare queries (on bench-box, the rays leaving the guide's front face).
#[test]
fn culled_backends_answer_as_alone() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for path in scene_files(&root) {
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e:#}"));
        let mesh = &scene.mesh;
        let mut q = scene_queries(&scene, 500, 4, 11);
        q.extend(queries(mesh, 3000, 12));
        for alone in candidates(mesh) {
            let name = alone.name();
            let culled = Culled::new(alone, mesh);
            let bare = culled.inner();
            let spared = q.iter().filter(|(r, _)| culled.culls(r)).count();
            for (r, tmax) in &q {
                assert_eq!(
                    culled.intersect(r, *tmax),
                    bare.intersect(r, *tmax),
                    "{name} {r:?}"
                );
            }
            if path.ends_with("bench-box/scene.toml") {
                assert!(
                    spared > q.len() / 20,
                    "{name}: {spared} of {} spared",
                    q.len()
                );
            }
        }
    }
}

#[test]
fn bundled_scenes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let files = scene_files(&root);
    if files.is_empty() {
        eprintln!("no scenes/**/scene.toml yet: nothing to compare");
        return;
    }
    for path in files {
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e:#}"));
        let q = scene_queries(&scene, 1_500, 4, 7);
        compare(&path.display().to_string(), &scene.mesh, &q);
    }
}
