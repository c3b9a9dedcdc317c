//! The solid shapes of lamp bodies: what light returning to a lamp meets.
//!
//! A CCFL's body is its glass tube, an exact closed cylinder (side and end discs); an LED's
//! is its emitting rectangle (one-sided: the emitting side faces the scene, the back is the
//! package) or, when the scene gives a depth, a box package behind that rectangle. Shapes
//! are intersected analytically in f64, beside the mesh, never meshed.
//!
//! Rays are tested as the mesh backends test them: from the photon's search ray, which
//! starts a spawn offset off the surface it left (emitted photons included), so a photon
//! leaving a body never meets that body again at distance ~0.

use crate::geometry::{Aabb, Ray};
use glam::DVec3;

/// The shape of one lamp body.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyShape {
    /// A closed cylinder: side of radius `radius` and two end discs.
    Cylinder {
        /// Centre of the tube.
        center: DVec3,
        /// Unit axis.
        axis: DVec3,
        /// Radius (mm).
        radius: f64,
        /// Half the length (mm).
        half_length: f64,
    },
    /// A rectangle that is met from its front (normal) side by the body's surface model
    /// and from its back by the package, which absorbs.
    Rectangle(Rect),
    /// A box package: the rectangle as its front face, `depth` deep behind it.
    Package {
        /// The front face.
        front: Rect,
        /// Depth behind the front face, along `-normal` (mm).
        depth: f64,
    },
}

/// A rectangle in space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Centre.
    pub center: DVec3,
    /// Unit normal of the front side.
    pub normal: DVec3,
    /// Unit in-plane direction of the width.
    pub u: DVec3,
    /// Half the width along `u` (mm).
    pub half_width: f64,
    /// Half the height along `normal x u` (mm).
    pub half_height: f64,
}

/// Where a ray meets a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyHit {
    /// Distance along the ray (mm).
    pub t: f64,
    /// Unit outward normal of the body there.
    pub normal: DVec3,
    /// False where the ray met the back of a one-sided rectangle (absorbed).
    pub front: bool,
}

impl BodyShape {
    /// The first point in `(0, t_max)` where `ray` enters the body, if any. A ray starting
    /// on or outside the surface and moving away never hits it.
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<BodyHit> {
        let hit = match self {
            BodyShape::Cylinder {
                center,
                axis,
                radius,
                half_length,
            } => cylinder_entry(ray, *center, *axis, *radius, *half_length),
            BodyShape::Rectangle(r) => rect_hit(ray, r),
            BodyShape::Package { front, depth } => package_entry(ray, front, *depth),
        }?;
        (hit.t > 0.0 && hit.t < t_max).then_some(hit)
    }

    /// The interval of `n . p` over the points `p` of the body, `n` any vector: its
    /// support in both directions (what a plane or a box needs to know of it).
    pub fn support(&self, n: DVec3) -> (f64, f64) {
        match self {
            BodyShape::Cylinder {
                center,
                axis,
                radius,
                half_length,
            } => {
                // The end discs, of radius r across unit axis a, reach r |n - (a.n) a|
                // beyond their centres, which lie half_length |a.n| off the centre.
                let a = axis.dot(n);
                let across = (n.length_squared() - a * a).max(0.0).sqrt();
                let (mid, reach) = (center.dot(n), radius * across + half_length * a.abs());
                (mid - reach, mid + reach)
            }
            BodyShape::Rectangle(r) => r.support(n),
            BodyShape::Package { front, depth } => {
                let (lo, hi) = front.support(n);
                let back = -depth * front.normal.dot(n);
                (lo + back.min(0.0), hi + back.max(0.0))
            }
        }
    }

    /// An axis-aligned box holding the whole body: the tube's support along the three
    /// axes; the rectangle's corners, and for a package those corners moved `depth` back.
    pub fn bounds(&self) -> Aabb {
        match self {
            BodyShape::Cylinder { .. } => {
                let [x, y, z] = [DVec3::X, DVec3::Y, DVec3::Z].map(|n| self.support(n));
                Aabb {
                    min: DVec3::new(x.0, y.0, z.0),
                    max: DVec3::new(x.1, y.1, z.1),
                }
            }
            BodyShape::Rectangle(r) => Aabb::of(r.corners()),
            BodyShape::Package { front, depth } => {
                let back = front.normal * -*depth;
                Aabb::of(front.corners().into_iter().flat_map(|c| [c, c + back]))
            }
        }
    }

    /// Move the body by `d`.
    pub fn translate(&mut self, d: DVec3) {
        match self {
            BodyShape::Cylinder { center, .. } => *center += d,
            BodyShape::Rectangle(r) | BodyShape::Package { front: r, .. } => r.center += d,
        }
    }
}

impl Rect {
    fn v(&self) -> DVec3 {
        self.normal.cross(self.u)
    }

    /// The interval of `n . p` over the rectangle's points.
    fn support(&self, n: DVec3) -> (f64, f64) {
        let reach =
            self.half_width * self.u.dot(n).abs() + self.half_height * self.v().dot(n).abs();
        let mid = self.center.dot(n);
        (mid - reach, mid + reach)
    }

    fn corners(&self) -> [DVec3; 4] {
        let (u, v) = (self.u * self.half_width, self.v() * self.half_height);
        let c = self.center;
        [c - u - v, c + u - v, c + u + v, c - u + v]
    }

    /// True when `p` (on the rectangle's plane) lies within its edges.
    fn contains(&self, p: DVec3) -> bool {
        let rel = p - self.center;
        rel.dot(self.u).abs() <= self.half_width && rel.dot(self.v()).abs() <= self.half_height
    }
}

/// The rectangle's plane crossed within its edges, from the side the ray starts on.
fn rect_hit(ray: &Ray, r: &Rect) -> Option<BodyHit> {
    let s = r.normal.dot(ray.origin - r.center);
    let dn = r.normal.dot(ray.dir);
    if s * dn >= 0.0 {
        return None; // moving away from the plane, along it, or starting on it
    }
    let t = -s / dn;
    r.contains(ray.at(t)).then_some(BodyHit {
        t,
        normal: r.normal,
        front: s > 0.0,
    })
}

/// One slab of a convex body: the ray's parameter interval between two parallel planes
/// `lo <= x . n <= hi`, with the outward normal at each end.
struct Slab {
    t_in: f64,
    t_out: f64,
    n_in: DVec3,
}

fn slab(ray: &Ray, n: DVec3, lo: f64, hi: f64) -> Option<Slab> {
    let (o, d) = (ray.origin.dot(n), ray.dir.dot(n));
    if d == 0.0 {
        return (lo..=hi).contains(&o).then_some(Slab {
            t_in: f64::NEG_INFINITY,
            t_out: f64::INFINITY,
            n_in: n,
        });
    }
    let (t_lo, t_hi) = ((lo - o) / d, (hi - o) / d);
    Some(if d > 0.0 {
        Slab {
            t_in: t_lo,
            t_out: t_hi,
            n_in: -n,
        }
    } else {
        Slab {
            t_in: t_hi,
            t_out: t_lo,
            n_in: n,
        }
    })
}

/// The entry into the intersection of slabs (a convex body), if the ray enters it ahead.
fn enter(slabs: impl IntoIterator<Item = Option<Slab>>) -> Option<BodyHit> {
    let mut t_in = f64::NEG_INFINITY;
    let mut t_out = f64::INFINITY;
    let mut normal = DVec3::ZERO;
    for s in slabs {
        let s = s?;
        if s.t_in > t_in {
            (t_in, normal) = (s.t_in, s.n_in);
        }
        t_out = t_out.min(s.t_out);
    }
    (t_in <= t_out && t_in > 0.0).then_some(BodyHit {
        t: t_in,
        normal,
        front: true,
    })
}

/// Entry into a closed cylinder: the infinite tube's interval intersected with the slab
/// between the end discs.
fn cylinder_entry(ray: &Ray, c: DVec3, axis: DVec3, r: f64, h: f64) -> Option<BodyHit> {
    let o = ray.origin - c;
    let (o_perp, d_perp) = (o - axis * o.dot(axis), ray.dir - axis * ray.dir.dot(axis));
    let a = d_perp.length_squared();
    let b = o_perp.dot(d_perp);
    let cc = o_perp.length_squared() - r * r;
    if cc > 0.0 && (b >= 0.0 || b * b < a * cc) {
        // Outside the tube and moving away from it, or passing it by: no square root.
        return None;
    }
    let tube = if a == 0.0 {
        (cc <= 0.0).then_some(Slab {
            t_in: f64::NEG_INFINITY,
            t_out: f64::INFINITY,
            n_in: DVec3::ZERO,
        })
    } else {
        let disc = b * b - a * cc;
        (disc >= 0.0).then(|| {
            // Stable roots of a t^2 + 2 b t + cc = 0.
            let q = -(b + b.signum() * disc.sqrt());
            let (t0, t1) = if q == 0.0 {
                (0.0, 0.0)
            } else {
                (q / a, cc / q)
            };
            let t_in = t0.min(t1);
            Slab {
                t_in,
                t_out: t0.max(t1),
                n_in: (o_perp + d_perp * t_in) / r,
            }
        })
    };
    let ends = slab(ray, axis, c.dot(axis) - h, c.dot(axis) + h);
    enter([tube, ends])
}

/// Entry into a box package: three slabs, the front face at the rectangle.
fn package_entry(ray: &Ray, f: &Rect, depth: f64) -> Option<BodyHit> {
    let (n, u, v) = (f.normal, f.u, f.v());
    let front = f.center.dot(n);
    let (cu, cv) = (f.center.dot(u), f.center.dot(v));
    enter([
        slab(ray, n, front - depth, front),
        slab(ray, u, cu - f.half_width, cu + f.half_width),
        slab(ray, v, cv - f.half_height, cv + f.half_height),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Mesh, intersect_triangle, orthonormal_basis};
    use crate::rng::PhotonRng;
    use std::f64::consts::TAU;

    fn tube() -> BodyShape {
        BodyShape::Cylinder {
            center: DVec3::new(1.0, -2.0, 0.5),
            axis: DVec3::new(0.0, 0.6, 0.8),
            radius: 1.2,
            half_length: 3.0,
        }
    }

    fn unit(rng: &mut PhotonRng) -> DVec3 {
        let z = 2.0 * rng.uniform() - 1.0;
        let phi = TAU * rng.uniform();
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    /// A fine closed mesh of the same cylinder, wound outward.
    fn tube_mesh(n: usize) -> Mesh {
        let BodyShape::Cylinder {
            center,
            axis,
            radius,
            half_length,
        } = tube()
        else {
            unreachable!()
        };
        let (t, b) = orthonormal_basis(axis);
        let ring = |k: usize, s: f64| {
            let phi = TAU * k as f64 / n as f64;
            center + axis * s + (t * phi.cos() + b * phi.sin()) * radius
        };
        let mut positions = vec![center - axis * half_length, center + axis * half_length];
        for k in 0..n {
            positions.push(ring(k, -half_length));
            positions.push(ring(k, half_length));
        }
        let mut triangles = Vec::new();
        for k in 0..n {
            let (a0, a1) = (2 + 2 * k as u32, 3 + 2 * k as u32);
            let (b0, b1) = (2 + 2 * ((k + 1) % n) as u32, 3 + 2 * ((k + 1) % n) as u32);
            triangles.extend([[a0, b0, b1], [a0, b1, a1], [0, b0, a0], [1, a1, b1]]);
        }
        let tri_tag = vec![0; triangles.len()];
        Mesh {
            positions,
            triangles,
            tri_tag,
        }
    }

    #[test]
    fn cylinder_matches_a_fine_mesh_from_outside() {
        let mesh = tube_mesh(4096);
        let body = tube();
        let mut rng = PhotonRng::new(4, 0);
        let mut hits = 0;
        for _ in 0..4000 {
            let origin = unit(&mut rng) * 6.0 + DVec3::new(1.0, -2.0, 0.5);
            let target = DVec3::new(1.0, -2.0, 0.5) + unit(&mut rng) * 3.0;
            let ray = Ray::new(origin, (target - origin).normalize());
            let want = (0..mesh.len() as u32)
                .filter_map(|p| intersect_triangle(&ray, mesh.corners(p), f64::INFINITY))
                .fold(f64::INFINITY, f64::min);
            let got = body.hit(&ray, f64::INFINITY);
            match got {
                Some(h) => {
                    hits += 1;
                    // A 4096-gon is within sag = r (1 - cos(pi/n)) of the circle: along
                    // the ray that is sag / cos, at most sqrt(2 r sag) when grazing.
                    let sag = 1.2 * (1.0 - (std::f64::consts::PI / 4096.0).cos());
                    let cos = h.normal.dot(ray.dir).abs();
                    let tol = 2.0 * (sag / cos).min((2.0 * 1.2 * sag).sqrt());
                    assert!((h.t - want).abs() < tol, "t {} vs mesh {want}", h.t);
                    assert!(h.normal.dot(ray.dir) < 0.0);
                    assert!((h.normal.length() - 1.0).abs() < 1e-12);
                }
                None => assert!(want.is_infinite() || grazes(&ray, &body, want)),
            }
        }
        assert!(hits > 1000, "only {hits} hits");
    }

    /// A mesh hit the analytic body misses must graze it (within the facets' sag).
    fn grazes(ray: &Ray, body: &BodyShape, t: f64) -> bool {
        let BodyShape::Cylinder {
            center,
            axis,
            radius,
            ..
        } = body
        else {
            return false;
        };
        let rel = ray.at(t) - *center;
        (rel - *axis * rel.dot(*axis)).length() > radius - 1e-5
    }

    #[test]
    fn rays_leaving_the_surface_never_hit_it() {
        let body = tube();
        let mut rng = PhotonRng::new(5, 0);
        let BodyShape::Cylinder {
            center,
            axis,
            radius,
            half_length,
        } = body.clone()
        else {
            unreachable!()
        };
        let (t, b) = orthonormal_basis(axis);
        for _ in 0..20_000 {
            let phi = TAU * rng.uniform();
            let n = t * phi.cos() + b * phi.sin();
            let p = center + axis * ((rng.uniform() - 0.5) * 2.0 * half_length) + n * radius;
            let mut d = unit(&mut rng);
            if d.dot(n) < 0.0 {
                d = -d;
            }
            assert_eq!(body.hit(&Ray::new(p, d), f64::INFINITY), None);
            // Coming back towards the point from outside hits it there.
            let back = Ray::new(p + d * 2.0, -d);
            let h = body.hit(&back, f64::INFINITY).expect("returning ray hits");
            assert!((h.t - 2.0).abs() < 1e-9, "t = {}", h.t);
        }
    }

    #[test]
    fn end_discs_close_the_tube() {
        let body = BodyShape::Cylinder {
            center: DVec3::ZERO,
            axis: DVec3::Z,
            radius: 1.0,
            half_length: 2.0,
        };
        let h = body
            .hit(&Ray::new(DVec3::new(0.3, 0.2, 5.0), -DVec3::Z), 10.0)
            .unwrap();
        assert_eq!((h.t, h.normal), (3.0, DVec3::Z));
        // Parallel to the axis outside the radius: a miss.
        assert_eq!(
            body.hit(&Ray::new(DVec3::new(1.5, 0.0, 5.0), -DVec3::Z), 10.0),
            None
        );
        // Beyond t_max: a miss.
        assert_eq!(
            body.hit(&Ray::new(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z), 2.5),
            None
        );
    }

    fn led() -> Rect {
        Rect {
            center: DVec3::new(0.0, 0.0, 0.0),
            normal: DVec3::X,
            u: DVec3::Y,
            half_width: 1.5,
            half_height: 0.2,
        }
    }

    #[test]
    fn rectangle_has_a_front_and_a_back() {
        let r = BodyShape::Rectangle(led());
        let d = DVec3::new(-1.0, 0.1, 0.0).normalize();
        let front = r.hit(&Ray::new(DVec3::new(2.0, 0.0, 0.0), d), 9.0).unwrap();
        assert!(front.front && (front.t - 2.0 / d.x.abs()).abs() < 1e-12);
        let back = r
            .hit(&Ray::new(DVec3::new(-2.0, 0.0, 0.0), -d), 9.0)
            .unwrap();
        assert!(!back.front);
        // Starting on the plane (an emitted photon) and outside its edges: misses.
        assert_eq!(r.hit(&Ray::new(DVec3::ZERO, DVec3::X), 9.0), None);
        assert_eq!(
            r.hit(&Ray::new(DVec3::new(2.0, 0.0, 0.5), -DVec3::X), 9.0),
            None
        );
    }

    #[test]
    fn package_is_a_box_behind_the_rectangle() {
        let p = BodyShape::Package {
            front: led(),
            depth: 0.6,
        };
        let h = p
            .hit(&Ray::new(DVec3::new(-0.3, 0.0, 5.0), -DVec3::Z), 9.0)
            .unwrap();
        assert!((h.t - 4.8).abs() < 1e-12 && h.normal == DVec3::Z);
        let f = p
            .hit(&Ray::new(DVec3::new(3.0, 0.0, 0.0), -DVec3::X), 9.0)
            .unwrap();
        assert!((f.t - 3.0).abs() < 1e-12 && f.normal == DVec3::X && f.front);
        assert_eq!(
            p.hit(&Ray::new(DVec3::new(-0.7, 0.0, 5.0), -DVec3::Z), 9.0),
            None
        );
    }

    #[test]
    fn bounds_are_the_tightest_box() {
        // A fine mesh of the tube has its vertices on the surface: inside the box, and
        // reaching its faces to within the mesh's chord error.
        let mesh = tube_mesh(4096);
        let b = tube().bounds();
        let fit = Aabb::of(mesh.positions.iter().copied());
        assert!(fit.min.cmpge(b.min - 1e-12).all() && fit.max.cmple(b.max + 1e-12).all());
        assert!((fit.min - b.min).max_element() < 1e-6, "{fit:?} {b:?}");
        assert!((b.max - fit.max).max_element() < 1e-6, "{fit:?} {b:?}");
        let r = led();
        let p = BodyShape::Package {
            front: r,
            depth: 0.6,
        };
        let rect = BodyShape::Rectangle(r).bounds();
        let want = (DVec3::new(0.0, -1.5, -0.2), DVec3::new(0.0, 1.5, 0.2));
        assert_eq!((rect.min, rect.max), want);
        let pb = p.bounds();
        assert_eq!((pb.min, pb.max), (DVec3::new(-0.6, -1.5, -0.2), want.1));
    }

    /// A package's support is that of its eight corners, and a tube's box is its support
    /// along the axes: the support is what the bounds and the placement checks share.
    #[test]
    fn support_is_the_extreme_of_the_shape() {
        let front = Rect {
            normal: DVec3::new(0.6, 0.0, 0.8),
            u: DVec3::Y,
            ..led()
        };
        let package = BodyShape::Package { front, depth: 0.7 };
        let back = front.normal * -0.7;
        let corners: Vec<DVec3> = front
            .corners()
            .into_iter()
            .flat_map(|c| [c, c + back])
            .collect();
        for n in [DVec3::X, DVec3::new(-0.3, 2.0, 0.5), -front.normal] {
            let (lo, hi) = package.support(n);
            let dots = corners.iter().map(|c| c.dot(n));
            let (clo, chi) = dots.fold((f64::MAX, f64::MIN), |(a, b), d| (a.min(d), b.max(d)));
            assert!((lo - clo).abs() < 1e-12 && (hi - chi).abs() < 1e-12, "{n}");
        }
        let b = tube().bounds();
        for (i, n) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
            assert_eq!(tube().support(n), (b.min[i], b.max[i]));
        }
        // The tube along its own axis reaches half its length, across it its radius.
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let c = DVec3::new(1.0, -2.0, 0.5).dot(axis);
        assert_eq!(tube().support(axis), (c - 3.0, c + 3.0));
    }
}
