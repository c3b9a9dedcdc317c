//! The mesh's bounding box in front of a backend: a ray that starts beyond one of the
//! box's faces and does not turn back towards it misses every triangle, so the backend
//! is not asked. Photons leaving a scene's outermost faces (a light guide's front face
//! towards the target above it, its far edge) are such rays; on the box guide of
//! `blutrace bench` they are one of a photon's two queries, and asking a backend costs
//! the call and its root-node tests.
//!
//! ```toml
//! # nothing to set: `accel::build` puts every backend behind the box
//! ```
//!
//! The box is grown by four f32 epsilons of the mesh's largest coordinate, eight times the
//! rounding of a vertex to f32 (the precision Embree and the BVH intersect in), so a ray
//! beyond it is beyond every triangle as any backend sees it: the answers are the
//! backend's own, bit for bit (`tests/backends.rs`). The pad is a quarter of the spawn
//! offset ([`crate::geometry::spawn_epsilon`], sixteen epsilons of an extent at least the
//! mesh's), so a photon spawned off an outermost face starts outside the box.

use super::{Accel, Hit};
use crate::geometry::{Aabb, Mesh, Ray};

/// A backend behind the padded bounding box of its mesh.
pub struct Culled {
    inner: Box<dyn Accel>,
    bounds: Aabb,
}

impl Culled {
    /// `inner`, answering for `mesh`, behind `mesh`'s padded box.
    pub fn new(inner: Box<dyn Accel>, mesh: &Mesh) -> Self {
        let b = mesh.bounds();
        let pad = 4.0 * f32::EPSILON as f64 * b.max_abs_coordinate().max(1.0);
        Self {
            inner,
            bounds: b.grown(pad),
        }
    }

    /// True when `ray` is spared the backend: it starts beyond a face of the box and
    /// does not turn back.
    pub fn culls(&self, ray: &Ray) -> bool {
        self.bounds.left_behind_by(ray)
    }

    /// The backend behind the box.
    pub fn inner(&self) -> &dyn Accel {
        self.inner.as_ref()
    }
}

impl Accel for Culled {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn intersect(&self, ray: &Ray, tmax: f64) -> Option<Hit> {
        if self.culls(ray) {
            return None;
        }
        self.inner.intersect(ray, tmax)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::brute::BruteForce;
    use glam::DVec3;
    use std::sync::Arc;

    /// One triangle in the plane z = 1 over x, y in [0, 1].
    fn plate() -> Arc<Mesh> {
        Arc::new(Mesh {
            positions: vec![
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(1.0, 0.0, 1.0),
                DVec3::new(0.0, 1.0, 1.0),
            ],
            triangles: vec![[0, 1, 2]],
            tri_tag: vec![0],
        })
    }

    #[test]
    fn culls_only_rays_leaving_the_box() {
        let mesh = plate();
        let culled = Culled::new(Box::new(BruteForce::new(mesh.clone())), &mesh);
        let ray = |o: [f64; 3], d: [f64; 3]| Ray::new(DVec3::from(o), DVec3::from(d).normalize());
        // Above the plate, going up or sideways: left behind.
        assert!(culled.culls(&ray([0.2, 0.2, 1.001], [0.0, 0.0, 1.0])));
        assert!(culled.culls(&ray([0.2, 0.2, 1.001], [1.0, 0.0, 0.0])));
        // Above it, coming down: asked, and it hits.
        let down = ray([0.2, 0.2, 1.001], [0.0, 0.0, -1.0]);
        assert!(!culled.culls(&down));
        assert_eq!(
            culled.intersect(&down, f64::INFINITY).map(|h| h.prim),
            Some(0)
        );
        // Beside the box but heading for it across two faces: asked.
        let across = ray([-0.5, 0.5, 0.0], [1.0, 0.0, 2.0]);
        assert!(!culled.culls(&across));
        assert!(culled.intersect(&across, f64::INFINITY).is_some());
        // Within the pad of the plane (a vertex rounded to f32 may lie there): asked.
        let pad = 4.0 * f32::EPSILON as f64;
        assert!(!culled.culls(&ray([0.2, 0.2, 1.0 + pad / 2.0], [0.0, 0.0, 1.0])));
        assert!(culled.culls(&ray([0.2, 0.2, 1.0 + 2.0 * pad], [0.0, 0.0, 1.0])));
    }

    #[test]
    fn an_empty_mesh_is_never_asked() {
        let mesh = Arc::new(Mesh::default());
        let culled = Culled::new(Box::new(BruteForce::new(mesh.clone())), &mesh);
        for dir in [DVec3::X, -DVec3::Y, DVec3::ONE.normalize()] {
            assert!(culled.culls(&Ray::new(DVec3::ZERO, dir)));
        }
    }
}
