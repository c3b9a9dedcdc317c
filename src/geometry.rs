//! Triangle meshes, rays and the one exact ray/triangle routine every backend shares.
//!
//! All geometry is held in f64 millimetres. A scene is one [`Mesh`]: a vertex list, a
//! triangle list and, per triangle, the index of its material tag. Acceleration backends
//! may work in f32 internally, but the distance they report is refined here, in f64, on
//! the primitive they found (see [`Mesh::refine_hit`]), so no backend decides physics.

use glam::DVec3;

/// A ray: origin and unit direction, in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
}

impl Ray {
    /// A ray from `origin` along the unit vector `dir`.
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        Self { origin, dir }
    }

    /// The point at distance `t` along the ray.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: DVec3,
    /// Maximum corner.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (grows from nothing).
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// Grow the box to hold `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// True when nothing was added.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Largest absolute coordinate of the box (0 for an empty box).
    pub fn max_abs_coordinate(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.min.abs().max(self.max.abs()).max_element()
        }
    }

    /// Length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }
}

/// A triangle soup with one material tag index per triangle.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions (mm).
    pub positions: Vec<DVec3>,
    /// Vertex indices, three per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Index into the scene's tag list, one per triangle.
    pub tri_tag: Vec<u32>,
}

/// A hit refined in f64 on one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the ray (mm).
    pub t: f64,
    /// The triangle hit.
    pub prim: u32,
    /// The hit point, on the triangle's plane.
    pub point: DVec3,
    /// The triangle's unit geometric normal (winding order: counter-clockwise is front).
    pub normal: DVec3,
}

impl Mesh {
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True when the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The three corners of triangle `prim`.
    pub fn corners(&self, prim: u32) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[prim as usize];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }

    /// Unnormalized normal (twice the area, right-hand winding).
    pub fn area_normal(&self, prim: u32) -> DVec3 {
        let [a, b, c] = self.corners(prim);
        (b - a).cross(c - a)
    }

    /// Unit geometric normal; zero for a degenerate triangle.
    pub fn normal(&self, prim: u32) -> DVec3 {
        self.area_normal(prim).normalize_or_zero()
    }

    /// Bounding box of all vertices used by triangles.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for tri in &self.triangles {
            for &v in tri {
                b.grow(self.positions[v as usize]);
            }
        }
        b
    }

    /// Append another mesh, offsetting its indices.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
        self.tri_tag.extend_from_slice(&other.tri_tag);
    }

    /// Exact (f64) intersection of `ray` with triangle `prim` within `(0, tmax)`.
    pub fn intersect_triangle(&self, ray: &Ray, prim: u32, tmax: f64) -> Option<f64> {
        intersect_triangle(ray, self.corners(prim), tmax)
    }

    /// Turn a backend's (distance, primitive) into a full hit, recomputing the distance
    /// in f64 against the triangle's plane so every backend yields the same point.
    pub fn refine_hit(&self, ray: &Ray, prim: u32, t_backend: f64) -> SurfaceHit {
        let [a, _, _] = self.corners(prim);
        let normal = self.normal(prim);
        let denom = normal.dot(ray.dir);
        let t_plane = if denom.abs() > 1e-300 {
            normal.dot(a - ray.origin) / denom
        } else {
            t_backend
        };
        let t = if t_plane.is_finite() && t_plane > 0.0 {
            t_plane
        } else {
            t_backend
        };
        SurfaceHit {
            t,
            prim,
            point: ray.at(t),
            normal,
        }
    }
}

/// Möller–Trumbore in f64, two-sided. Returns the distance of a hit in `(0, tmax)`.
///
/// Edges are inclusive (barycentrics >= 0), so a ray through a shared edge of a closed
/// mesh hits at least one of the two triangles: no leaks at seams.
pub fn intersect_triangle(ray: &Ray, [v0, v1, v2]: [DVec3; 3], tmax: f64) -> Option<f64> {
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t < tmax).then_some(t)
}

/// An orthonormal basis (t, b, n) around the unit vector `n` (Duff et al. 2017).
pub fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = DVec3::new(b, sign + n.y * n.y * a, -n.y);
    (t, bt)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tri() -> [DVec3; 3] {
        [DVec3::ZERO, DVec3::X, DVec3::Y]
    }

    #[test]
    fn hits_inside_and_misses_outside() {
        let down = DVec3::NEG_Z;
        let inside = Ray::new(DVec3::new(0.2, 0.2, 1.0), down);
        assert_eq!(intersect_triangle(&inside, unit_tri(), 10.0), Some(1.0));
        let outside = Ray::new(DVec3::new(0.8, 0.8, 1.0), down);
        assert_eq!(intersect_triangle(&outside, unit_tri(), 10.0), None);
        let behind = Ray::new(DVec3::new(0.2, 0.2, -1.0), down);
        assert_eq!(intersect_triangle(&behind, unit_tri(), 10.0), None);
        assert_eq!(intersect_triangle(&inside, unit_tri(), 0.5), None);
    }

    #[test]
    fn shared_edge_is_hit_by_one_side_at_least() {
        let quad = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let t1 = [quad[0], quad[1], quad[2]];
        let t2 = [quad[0], quad[2], quad[3]];
        let ray = Ray::new(DVec3::new(0.5, 0.5, 1.0), DVec3::NEG_Z);
        let hits = [t1, t2]
            .iter()
            .filter(|t| intersect_triangle(&ray, **t, 10.0).is_some())
            .count();
        assert!(hits >= 1);
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            DVec3::X,
            DVec3::NEG_Z,
            DVec3::new(0.3, -0.4, 0.866).normalize(),
        ] {
            let (t, b) = orthonormal_basis(n);
            assert!((t.length() - 1.0).abs() < 1e-12);
            assert!((b.length() - 1.0).abs() < 1e-12);
            assert!(t.dot(n).abs() < 1e-12 && b.dot(n).abs() < 1e-12 && t.dot(b).abs() < 1e-12);
        }
    }
}
