//! Pure-Rust BVH backend on the `obvhs` crate (compressed wide BVH8, SIMD traversal).
//!
//! Boxes and traversal are f32 (boxes padded by a few ulps so flat faces are never
//! culled by rounding); the per-triangle test is the shared f64 routine, so this backend
//! agrees with the brute-force oracle triangle for triangle.

use super::{Accel, Hit};
use crate::geometry::{Mesh, Ray};
use glam::{Vec3A, vec3a};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray as ObRay, RayHit},
};
use std::sync::Arc;
use std::time::Duration;

/// A triangle's padded f32 box, the primitive the BVH is built over.
struct PaddedTriangle(Aabb);

impl obvhs::Boundable for PaddedTriangle {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// BVH over the scene mesh built by obvhs.
pub struct ObvhsBvh {
    mesh: Arc<Mesh>,
    bvh: Option<CwBvh>,
}

impl ObvhsBvh {
    /// Build the BVH over `mesh`.
    pub fn new(mesh: Arc<Mesh>) -> Self {
        // Boxes are padded by four spawn offsets: rays start that close to a face, and the
        // f32 slab test (after CWBVH quantization) must never cull the face they are about
        // to hit. Found by the hit-for-hit test against brute force.
        let pad = 4.0 * crate::geometry::spawn_epsilon(mesh.bounds().max_abs_coordinate()) as f32;
        let prims: Vec<PaddedTriangle> = (0..mesh.len() as u32)
            .map(|p| padded_box(&mesh, p, pad))
            .collect();
        let bvh = (!prims.is_empty()).then(|| {
            build_cwbvh(
                &prims,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        });
        Self { mesh, bvh }
    }
}

fn padded_box(mesh: &Mesh, prim: u32, pad: f32) -> PaddedTriangle {
    let mut min = Vec3A::splat(f32::INFINITY);
    let mut max = Vec3A::splat(f32::NEG_INFINITY);
    for c in mesh.corners(prim) {
        let v = c.as_vec3().into();
        min = min.min(v);
        max = max.max(v);
    }
    PaddedTriangle(Aabb::new(min - Vec3A::splat(pad), max + Vec3A::splat(pad)))
}

/// The ray in f32 for traversal. The inverse direction is computed exactly (in f64,
/// clamped to the f32 range) rather than by obvhs's `safe_inverse`, which replaces any
/// component below f32::EPSILON by 1/EPSILON and can then cull the boxes of flat faces
/// for rays that run nearly parallel to an axis.
fn f32_ray(ray: &Ray) -> ObRay {
    let v = |d: glam::DVec3| vec3a(d.x as f32, d.y as f32, d.z as f32);
    let inv = |c: f64| (1.0 / c).clamp(-(f32::MAX as f64), f32::MAX as f64) as f32;
    let d = ray.dir;
    ObRay {
        origin: v(ray.origin),
        direction: v(d),
        inv_direction: vec3a(inv(d.x), inv(d.y), inv(d.z)),
        tmin: 0.0,
        tmax: f32::INFINITY,
    }
}

impl Accel for ObvhsBvh {
    fn name(&self) -> &'static str {
        "bvh"
    }

    fn intersect(&self, ray: &Ray, tmax: f64) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let ob = f32_ray(ray);
        let mut best: Option<Hit> = None;
        let mut hit = RayHit::none();
        bvh.ray_traverse(ob, &mut hit, |_, id| {
            let prim = bvh.primitive_indices[id];
            let limit = best.map_or(tmax, |h| h.t);
            match self.mesh.intersect_triangle(ray, prim, limit) {
                Some(t) => {
                    best = Some(Hit { t, prim });
                    // Widen by an ulp so the f32 traversal never prunes an f64-nearer tie.
                    (t as f32).next_up()
                }
                None => f32::INFINITY,
            }
        });
        best
    }
}
