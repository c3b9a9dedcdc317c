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
        let pad = 8.0 * f32::EPSILON * (mesh.bounds().max_abs_coordinate() as f32).max(1.0);
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

impl Accel for ObvhsBvh {
    fn name(&self) -> &'static str {
        "bvh"
    }

    fn intersect(&self, ray: &Ray, tmax: f64) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let o = ray.origin;
        let d = ray.dir;
        let ob = ObRay::new(
            vec3a(o.x as f32, o.y as f32, o.z as f32),
            vec3a(d.x as f32, d.y as f32, d.z as f32),
            0.0,
            f32::INFINITY,
        );
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
