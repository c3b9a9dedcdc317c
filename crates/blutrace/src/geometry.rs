//! Triangle meshes, rays and the one exact ray/triangle routine every backend shares.
//!
//! All geometry is held in f64 millimetres. A scene is one [`Mesh`]: a vertex list, a
//! triangle list and, per triangle, the index of its material tag. Acceleration backends
//! may work in f32 internally, but the distance they report is refined here, in f64, on
//! the primitive they found (see [`Facet::refine_hit`]), so no backend decides physics.

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

/// The spawn offset for a scene whose coordinates reach `extent` mm: a few f32 ulps
/// there, so single-precision backends never re-hit the surface a ray leaves.
pub fn spawn_epsilon(extent: f64) -> f64 {
    16.0 * f32::EPSILON as f64 * extent.max(1.0)
}

/// The start of a ray leaving a surface at `point` (unit `normal`) along `dir`: nudged
/// `eps` off the surface to the side `dir` goes. One rule for all backends.
pub fn spawn_origin(point: DVec3, normal: DVec3, dir: DVec3, eps: f64) -> DVec3 {
    point + normal * eps.copysign(dir.dot(normal))
}

/// A ray leaving a surface (pbrt's `SpawnRay`): where the photon really is, and the
/// search ray a backend is asked about, nudged off the surface so single-precision
/// backends do not re-hit it. The nudge is applied here and taken off here
/// ([`SpawnedRay::refine_hit`]): distances are measured from the true position, so
/// nudges never add up over thousands of bounces in a thin guide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpawnedRay {
    /// Where the photon really is (on the surface it left, or where it was emitted).
    pub from: DVec3,
    /// The search ray: same direction, from `from` nudged off the surface.
    pub search: Ray,
}

impl SpawnedRay {
    /// A ray that left no surface (an emitted photon): no nudge.
    pub fn unnudged(ray: Ray) -> Self {
        Self {
            from: ray.origin,
            search: ray,
        }
    }

    /// A ray leaving a surface at `point` (unit `normal`) along `dir`, nudged `eps`
    /// ([`spawn_origin`]).
    pub fn leaving(point: DVec3, normal: DVec3, dir: DVec3, eps: f64) -> Self {
        Self {
            from: point,
            search: Ray::new(spawn_origin(point, normal, dir, eps), dir),
        }
    }

    /// The ray from the true position.
    pub fn true_ray(&self) -> Ray {
        Ray::new(self.from, self.search.dir)
    }

    /// [`Facet::refine_hit`] of the search ray's hit, but with distance and point measured
    /// along the true path: the backend's triangle `prim`, at `t_backend` along the search
    /// ray. Where the true path meets the triangle's plane outside the triangle (the
    /// nudged ray went past an edge the true path does not), the nudged ray's point is
    /// kept: a point off the triangle could lie outside a closed solid and leak.
    pub fn refine_hit(&self, facet: &Facet, prim: u32, t_backend: f64) -> SurfaceHit {
        let (pos, ray) = (self.from, &self.search);
        let lead = (ray.origin - pos).length();
        let exact = facet.refine_hit(&Ray::new(pos, ray.dir), prim, t_backend + lead);
        if exact.t > lead && facet.contains(exact.point) {
            return exact;
        }
        let nudged = facet.refine_hit(ray, prim, t_backend);
        SurfaceHit {
            t: (nudged.point - pos).length(),
            ..nudged
        }
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

    /// The box holding `points` ([`Aabb::EMPTY`] when there are none).
    pub fn of(points: impl IntoIterator<Item = DVec3>) -> Aabb {
        let mut b = Aabb::EMPTY;
        points.into_iter().for_each(|p| b.grow(p));
        b
    }

    /// Grow the box to hold `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The box grown by `pad` on every side.
    pub fn grown(&self, pad: f64) -> Aabb {
        Aabb {
            min: self.min - DVec3::splat(pad),
            max: self.max + DVec3::splat(pad),
        }
    }

    /// True when the two boxes share a point (faces included).
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && self.max.cmpge(other.min).all()
    }

    /// True when `p` lies in the box (faces included).
    pub fn contains_point(&self, p: DVec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
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

    /// True when `ray` starts beyond one of the box's faces and does not turn back
    /// towards it, so it cannot meet the box (a quick sufficient test: a ray that misses
    /// the box otherwise, passing it by, is not caught). NaN coordinates compare false.
    pub fn left_behind_by(&self, ray: &Ray) -> bool {
        let zero = DVec3::ZERO;
        let below = ray.origin.cmplt(self.min) & ray.dir.cmple(zero);
        let above = ray.origin.cmpgt(self.max) & ray.dir.cmpge(zero);
        (below | above).any()
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
#[derive(Clone, Debug, Default, PartialEq)]
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
        Aabb::of(
            self.triangles
                .iter()
                .flatten()
                .map(|&v| self.positions[v as usize]),
        )
    }

    /// True when `p`, a point on the plane of triangle `prim`, lies inside it (edges
    /// included).
    pub fn contains(&self, prim: u32, p: DVec3) -> bool {
        in_triangle(self.corners(prim), p)
    }

    /// Exact (f64) intersection of `ray` with triangle `prim` within `(0, tmax)`.
    pub fn intersect_triangle(&self, ray: &Ray, prim: u32, tmax: f64) -> Option<f64> {
        intersect_triangle(ray, self.corners(prim), tmax)
    }

    /// What the shared refinement reads of triangle `prim` ([`Facet`]).
    pub fn facet(&self, prim: u32) -> Facet {
        Facet {
            corners: self.corners(prim),
            normal: self.normal(prim),
            tag: self.tri_tag[prim as usize],
        }
    }

    /// The [`Facet`] of every triangle, for a run to look up at every hit.
    pub fn facets(&self) -> Vec<Facet> {
        (0..self.len() as u32).map(|p| self.facet(p)).collect()
    }
}

/// One triangle as a hit on it is refined and scored: its corners, unit geometric
/// normal and tag, side by side. On a mesh too large for the cache a hit then costs one
/// memory access (two adjacent lines) instead of a chain of them (vertex indices, then
/// the vertices, the normal, the tag); that chain was most of the refinement's time on a
/// 540k-triangle mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Facet {
    /// The three corners ([`Mesh::corners`]).
    pub corners: [DVec3; 3],
    /// Unit geometric normal ([`Mesh::normal`]; zero for a degenerate triangle).
    pub normal: DVec3,
    /// The triangle's tag (index into the scene's tag list).
    pub tag: u32,
}

impl Facet {
    /// True when `p`, a point on the facet's plane, lies inside it (edges included).
    pub fn contains(&self, p: DVec3) -> bool {
        in_triangle(self.corners, p)
    }

    /// Turn a backend's hit on this facet (triangle `prim`, at `t_backend` along `ray`)
    /// into a full hit, recomputing the distance in f64 against the facet's plane so
    /// every backend yields the same point.
    pub fn refine_hit(&self, ray: &Ray, prim: u32, t_backend: f64) -> SurfaceHit {
        let (a, normal) = (self.corners[0], self.normal);
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

/// True when `p`, a point on the plane of the triangle with corners `[a, b, c]`, lies
/// inside it (edges included).
fn in_triangle([a, b, c]: [DVec3; 3], p: DVec3) -> bool {
    let n = (b - a).cross(c - a);
    [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0)
}

/// The watertight ray/triangle test of Woop, Benthin & Wald (JCGT 2(1), 2013) in f64,
/// two-sided. Returns the distance of a hit in `(0, tmax)`.
///
/// The triangle is sheared into the ray's frame (the ray becomes the +z axis through the
/// origin); each of its three 2-D edge functions is computed from the two end points of
/// that edge alone, so two triangles sharing an edge evaluate it to exactly opposite
/// values. Edges are inclusive, so a ray through a shared edge or vertex of a closed mesh
/// hits at least one of the triangles around it: no leaks at seams. (Möller–Trumbore,
/// used before, is not watertight: about 2 % of rays aimed at shared edges slipped through.)
pub fn intersect_triangle(ray: &Ray, [v0, v1, v2]: [DVec3; 3], tmax: f64) -> Option<f64> {
    let d = ray.dir;
    let ad = d.abs();
    let kz = if ad.x > ad.y {
        if ad.x > ad.z { 0 } else { 2 }
    } else if ad.y > ad.z {
        1
    } else {
        2
    };
    let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sz = 1.0 / d[kz];
    let (sx, sy) = (d[kx] * sz, d[ky] * sz);
    let [a, b, c] = [v0 - ray.origin, v1 - ray.origin, v2 - ray.origin];
    let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
    let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
    let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    // Rounding leaves each edge function with an error below about 30 eps r s (r: the
    // largest coordinate relative to the ray origin, s: the largest sheared 2-D one), so a
    // projected area below 128 eps r s is no area: a zero-area triangle, or a ray in the
    // triangle's plane. Its edge functions are noise that can agree in sign: no hit.
    let det = u + v + w;
    let r = a.abs().max(b.abs()).max(c.abs()).max_element();
    let s = [ax, ay, bx, by, cx, cy]
        .into_iter()
        .fold(0.0, |m: f64, x| m.max(x.abs()));
    if !det.is_finite() || det.abs() <= 128.0 * f64::EPSILON * r * s {
        return None;
    }
    let t = (u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz])) / det;
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
    fn rays_aimed_at_a_shared_edge_never_slip_through() {
        // Random parallelograms (two triangles sharing the diagonal b-c) of sizes 1e-3..1e3
        // up to 1 m from the origin; rays from nearby aimed at random points of the diagonal.
        // Möller–Trumbore misses both triangles for about 2 % of these rays.
        let mut rng = crate::rng::PhotonRng::new(5, 0);
        let mut u = || rng.uniform();
        for _ in 0..20_000 {
            let scale = 10f64.powf(6.0 * u() - 3.0);
            let off = DVec3::new(u(), u(), u()) * 1000.0;
            let mut p = || off + DVec3::new(u(), u(), u()) * scale;
            let (a, b, c) = (p(), p(), p());
            let target = b + (c - b) * u();
            let from = target + (DVec3::new(u(), u(), u()) - 0.5) * 3.0 * scale;
            let ray = Ray::new(from, (target - from).normalize());
            let hit = |t| intersect_triangle(&ray, t, f64::INFINITY).is_some();
            assert!(
                hit([a, b, c]) || hit([b, b + c - a, c]),
                "{ray:?} slipped through"
            );
        }
    }

    #[test]
    fn refine_from_the_true_position_undoes_the_nudge() {
        // A unit square at z = 1 (two triangles); a photon at z = 0 whose search ray was
        // nudged 1e-3 up: distance and point come from the true position.
        let mesh = Mesh {
            positions: vec![
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(1.0, 0.0, 1.0),
                DVec3::new(1.0, 1.0, 1.0),
                DVec3::new(0.0, 1.0, 1.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            tri_tag: vec![0, 0],
        };
        let dir = DVec3::new(0.3, 0.1, 1.0).normalize();
        let pos = DVec3::new(0.5, 0.1, 0.0);
        let nudged = Ray::new(pos + DVec3::Z * 1e-3, dir);
        let t = mesh.intersect_triangle(&nudged, 0, f64::INFINITY).unwrap();
        let spawned = SpawnedRay {
            from: pos,
            search: nudged,
        };
        let hit = spawned.refine_hit(&mesh.facet(0), 0, t);
        assert!((hit.t - 1.0 / dir.z).abs() < 1e-12 && (hit.point.z - 1.0).abs() < 1e-12);
        assert!(mesh.contains(0, hit.point) && !mesh.contains(1, hit.point));
        // The true path meets the plane outside triangle 1: the nudged point is kept.
        let far = SpawnedRay {
            from: DVec3::new(2.0, 0.1, 0.0),
            search: nudged,
        };
        let far = far.refine_hit(&mesh.facet(1), 1, t);
        assert_eq!(far.point, mesh.facet(1).refine_hit(&nudged, 1, t).point);
    }

    #[test]
    fn zero_area_triangles_are_never_hit() {
        // Collinear corners: the edge functions are rounding noise; no garbage hit.
        let tri = [
            DVec3::new(-1.25, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
            DVec3::new(-0.75, 1.0, 0.0),
        ];
        let ray = Ray::new(
            DVec3::new(-2.537329442529172, -0.47424324513580396, 0.3939844163561048),
            DVec3::new(
                0.8669757166883915,
                0.48145414016835075,
                -0.12866630323205894,
            ),
        );
        assert_eq!(intersect_triangle(&ray, tri, f64::INFINITY), None);
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
