//! Ray packets: `rtcIntersect4/8/16` over the same committed scene as `rtcIntersect1`.
//!
//! `RTCRayHitN` (rtcore_ray.h, Embree 4.4, with `RTC_GEOMETRY_INSTANCE_ARRAY`) is the
//! single-ray record in structure-of-arrays form: each field becomes an array of N lanes,
//! in the same order, `RTCRayN` first, then `RTCHitN`. Field k of the ray starts at byte
//! 4 N k, field k of the hit at 48 N + 4 N k; the packet is aligned to 4 N bytes (16, 32,
//! 64). For N = 8:
//!
//! | struct       | size | fields (byte offset)                                                |
//! |--------------|------|---------------------------------------------------------------------|
//! | `RTCRay8`    | 384  | org_x\[8\] 0, org_y 32, org_z 64, tnear 96, dir_x 128, dir_y 160, dir_z 192, time 224, tfar 256, mask 288, id 320, flags 352 (align 32) |
//! | `RTCHit8`    | 288  | Ng_x\[8\] 0, Ng_y 32, Ng_z 64, u 96, v 128, primID 160, geomID 192, instID\[1\]\[8\] 224, instPrimID\[1\]\[8\] 256 (align 32) |
//! | `RTCRayHit8` | 672  | ray 0, hit 384                                                      |
//!
//! The `valid` mask is N `int`s (-1: trace this lane, 0: leave it untouched), aligned like
//! the packet. Each lane is filled from, and read back into, the single-ray record of
//! `rtcIntersect1` ([`Accel::intersect`](super::Accel::intersect)), so both paths convert
//! rays and distances the same way.
//!
//! Whether the library traces a width natively (one SIMD lane per ray) or splits it is
//! `RTC_DEVICE_PROPERTY_NATIVE_RAY{4,8,16}_SUPPORTED`: a build without packet kernels
//! loops over `rtcIntersect1` (Embree's `rtcIntersect8` falls back to that), and a CPU
//! without AVX (AVX-512) has no native 8 (16) wide kernels.

use super::ffi::*;
use super::{EmbreeAccel, Hit};
use crate::geometry::Ray;
use std::ffi::{c_uint, c_void};
use std::ptr;

/// `RTCRayNt<N>` (rtcore_ray.h).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
struct RayN<const N: usize> {
    org_x: [f32; N],
    org_y: [f32; N],
    org_z: [f32; N],
    tnear: [f32; N],
    dir_x: [f32; N],
    dir_y: [f32; N],
    dir_z: [f32; N],
    time: [f32; N],
    tfar: [f32; N],
    mask: [c_uint; N],
    id: [c_uint; N],
    flags: [c_uint; N],
}

/// `RTCHitNt<N>` (rtcore_ray.h, with `RTC_GEOMETRY_INSTANCE_ARRAY`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
#[allow(non_snake_case)]
struct HitN<const N: usize> {
    Ng_x: [f32; N],
    Ng_y: [f32; N],
    Ng_z: [f32; N],
    u: [f32; N],
    v: [f32; N],
    primID: [c_uint; N],
    geomID: [c_uint; N],
    instID: [[c_uint; N]; MAX_INSTANCE_LEVEL_COUNT],
    instPrimID: [[c_uint; N]; MAX_INSTANCE_LEVEL_COUNT],
}

/// `RTCRayHit4/8/16`: 64-aligned, which is at least the 4 N bytes each width needs. The
/// members carry no alignment of their own, so `hit` sits right after `ray`, at 48 N (a
/// multiple of 4 N), as in the header.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
struct RayHitN<const N: usize> {
    ray: RayN<N>,
    hit: HitN<N>,
}

/// The `valid` argument, aligned like the packet.
#[repr(C, align(64))]
struct Valid<const N: usize>([i32; N]);

const _: () = {
    use std::mem::{align_of, offset_of, size_of};
    assert!(size_of::<RayN<8>>() == 384 && size_of::<HitN<8>>() == 288);
    assert!(offset_of!(RayN<8>, tnear) == 96 && offset_of!(RayN<8>, dir_x) == 128);
    assert!(offset_of!(RayN<8>, tfar) == 256 && offset_of!(RayN<8>, flags) == 352);
    assert!(offset_of!(HitN<8>, u) == 96 && offset_of!(HitN<8>, primID) == 160);
    assert!(offset_of!(HitN<8>, geomID) == 192 && offset_of!(HitN<8>, instID) == 224);
    assert!(offset_of!(HitN<8>, instPrimID) == 256);
    assert!(offset_of!(RayHitN<4>, hit) == 192 && size_of::<HitN<4>>() == 144);
    assert!(offset_of!(RayHitN<8>, hit) == 384);
    assert!(offset_of!(RayHitN<16>, hit) == 768 && size_of::<HitN<16>>() == 576);
    assert!(align_of::<RayHitN<16>>() == 64 && align_of::<Valid<16>>() == 64);
};

mod sealed {
    pub trait Sealed {}
}

/// A packet width Embree has an entry point for: `Lanes<4>`, `Lanes<8>`, `Lanes<16>`.
pub trait PacketWidth: sealed::Sealed {
    /// Index of the entry point (`rtcIntersect4`, `8`, `16`).
    #[doc(hidden)]
    const ENTRY: usize;
}

/// The width of a ray packet, as a type ([`EmbreeAccel::intersect_packet`]).
pub struct Lanes<const N: usize>;

impl sealed::Sealed for Lanes<4> {}
impl sealed::Sealed for Lanes<8> {}
impl sealed::Sealed for Lanes<16> {}
impl PacketWidth for Lanes<4> {
    const ENTRY: usize = 0;
}
impl PacketWidth for Lanes<8> {
    const ENTRY: usize = 1;
}
impl PacketWidth for Lanes<16> {
    const ENTRY: usize = 2;
}

impl<const N: usize> RayHitN<N> {
    /// Every lane zero, and no hit.
    fn empty() -> Self {
        let none = [RTC_INVALID_GEOMETRY_ID; N];
        Self {
            ray: RayN {
                org_x: [0.0; N],
                org_y: [0.0; N],
                org_z: [0.0; N],
                tnear: [0.0; N],
                dir_x: [0.0; N],
                dir_y: [0.0; N],
                dir_z: [0.0; N],
                time: [0.0; N],
                tfar: [0.0; N],
                mask: [0; N],
                id: [0; N],
                flags: [0; N],
            },
            hit: HitN {
                Ng_x: [0.0; N],
                Ng_y: [0.0; N],
                Ng_z: [0.0; N],
                u: [0.0; N],
                v: [0.0; N],
                primID: none,
                geomID: none,
                instID: [none; MAX_INSTANCE_LEVEL_COUNT],
                instPrimID: [none; MAX_INSTANCE_LEVEL_COUNT],
            },
        }
    }

    /// Lane `i` := the single-ray record `r` (Embree's `RayHitK::set`).
    fn set(&mut self, i: usize, r: &RTCRayHit) {
        let (ray, hit) = (&mut self.ray, &mut self.hit);
        ray.org_x[i] = r.ray.org_x;
        ray.org_y[i] = r.ray.org_y;
        ray.org_z[i] = r.ray.org_z;
        ray.tnear[i] = r.ray.tnear;
        ray.dir_x[i] = r.ray.dir_x;
        ray.dir_y[i] = r.ray.dir_y;
        ray.dir_z[i] = r.ray.dir_z;
        ray.time[i] = r.ray.time;
        ray.tfar[i] = r.ray.tfar;
        ray.mask[i] = r.ray.mask;
        ray.id[i] = r.ray.id;
        ray.flags[i] = r.ray.flags;
        hit.Ng_x[i] = r.hit.Ng_x;
        hit.Ng_y[i] = r.hit.Ng_y;
        hit.Ng_z[i] = r.hit.Ng_z;
        hit.u[i] = r.hit.u;
        hit.v[i] = r.hit.v;
        hit.primID[i] = r.hit.primID;
        hit.geomID[i] = r.hit.geomID;
        for l in 0..MAX_INSTANCE_LEVEL_COUNT {
            hit.instID[l][i] = r.hit.instID[l];
            hit.instPrimID[l][i] = r.hit.instPrimID[l];
        }
    }

    /// Lane `i` as a single-ray record (Embree's `RayHitK::get`).
    fn get(&self, i: usize) -> RTCRayHit {
        let (ray, hit) = (&self.ray, &self.hit);
        RTCRayHit {
            ray: RTCRay {
                org_x: ray.org_x[i],
                org_y: ray.org_y[i],
                org_z: ray.org_z[i],
                tnear: ray.tnear[i],
                dir_x: ray.dir_x[i],
                dir_y: ray.dir_y[i],
                dir_z: ray.dir_z[i],
                time: ray.time[i],
                tfar: ray.tfar[i],
                mask: ray.mask[i],
                id: ray.id[i],
                flags: ray.flags[i],
            },
            hit: RTCHit {
                Ng_x: hit.Ng_x[i],
                Ng_y: hit.Ng_y[i],
                Ng_z: hit.Ng_z[i],
                u: hit.u[i],
                v: hit.v[i],
                primID: hit.primID[i],
                geomID: hit.geomID[i],
                instID: std::array::from_fn(|l| hit.instID[l][i]),
                instPrimID: std::array::from_fn(|l| hit.instPrimID[l][i]),
            },
        }
    }
}

/// Which packet widths the library traces natively on this CPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NativePackets {
    /// `RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED`.
    pub ray4: bool,
    /// `RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED`.
    pub ray8: bool,
    /// `RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED`.
    pub ray16: bool,
}

impl std::fmt::Display for NativePackets {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let yes = |b: bool| if b { "native" } else { "emulated" };
        write!(
            f,
            "4 {}, 8 {}, 16 {}",
            yes(self.ray4),
            yes(self.ray8),
            yes(self.ray16)
        )
    }
}

impl EmbreeAccel {
    /// The packet widths this library traces natively here (its device properties).
    pub fn native_packets(&self) -> NativePackets {
        let p = |prop| self.device.property(prop) == 1;
        NativePackets {
            ray4: p(RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED),
            ray8: p(RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED),
            ray16: p(RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED),
        }
    }

    /// Nearest hits of up to N queries `(ray, tmax)` in one `rtcIntersectN` call: lane i
    /// answers `queries[i]` exactly as [`Accel::intersect`](super::Accel::intersect) would
    /// (the same record per lane); lanes past the queries, and queries with an empty or
    /// NaN segment, are masked off and answer `None`.
    ///
    /// # Panics
    /// When there are more than N queries.
    pub fn intersect_packet<const N: usize>(&self, queries: &[(Ray, f64)]) -> [Option<Hit>; N]
    where
        Lanes<N>: PacketWidth,
    {
        assert!(
            queries.len() <= N,
            "{} queries for {N} lanes",
            queries.len()
        );
        let mut valid = Valid([0i32; N]);
        let mut rh = RayHitN::<N>::empty();
        for (i, (ray, tmax)) in queries.iter().enumerate() {
            if tmax.is_nan() || *tmax <= 0.0 {
                continue;
            }
            rh.set(i, &Self::ray_hit(ray, *tmax));
            valid.0[i] = -1;
        }
        // SAFETY: local, aligned, fully initialised records of the width's own layout.
        unsafe { self.intersect_packet_raw::<N>(&valid, &mut rh) };
        std::array::from_fn(|i| {
            let r = rh.get(i);
            if valid.0[i] == 0 || r.hit.geomID == RTC_INVALID_GEOMETRY_ID {
                return None;
            }
            debug_assert!(r.hit.geomID == 0 && r.hit.primID < self.triangles);
            Some(Hit {
                t: f64::from(r.ray.tfar),
                prim: r.hit.primID,
            })
        })
    }

    /// Runs `rtcIntersectN` on `rh` for the lanes `valid` marks.
    ///
    /// # Safety
    /// `rh` must hold a valid ray in every lane marked -1.
    unsafe fn intersect_packet_raw<const N: usize>(&self, valid: &Valid<N>, rh: &mut RayHitN<N>)
    where
        Lanes<N>: PacketWidth,
    {
        let f = self.device.api.intersect_n[<Lanes<N> as PacketWidth>::ENTRY];
        // SAFETY: the entry point of exactly this width; both records are aligned to 64
        // >= 4 N bytes and laid out as the header's (checked above); a committed scene
        // (thread-safe queries); null args are allowed.
        unsafe {
            f(
                valid.0.as_ptr(),
                self.scene.raw,
                (rh as *mut RayHitN<N>).cast::<c_void>(),
                ptr::null_mut(),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::accel;
    use super::*;
    use crate::accel::Accel;
    use crate::geometry::Mesh;
    use crate::rng::PhotonRng;
    use glam::DVec3;

    /// A closed, irregular mesh (a jittered sphere) whose hits have distinct normals, u, v
    /// and primIDs, so a lane or field out of place changes some record.
    fn lumpy_sphere() -> Mesh {
        let (lon, lat) = (24u32, 12u32);
        let mut rng = PhotonRng::new(3, 0);
        let mut positions = vec![DVec3::Z, DVec3::NEG_Z];
        for j in 1..lat {
            for i in 0..lon {
                let th = std::f64::consts::PI * f64::from(j) / f64::from(lat);
                let ph = std::f64::consts::TAU * f64::from(i) / f64::from(lon);
                let r = 1.0 + 0.1 * rng.uniform();
                positions.push(r * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
            }
        }
        let v = |j: u32, i: u32| 2 + (j - 1) * lon + i % lon;
        let mut triangles = Vec::new();
        for i in 0..lon {
            triangles.push([0, v(1, i), v(1, i + 1)]);
            triangles.push([1, v(lat - 1, i + 1), v(lat - 1, i)]);
            for j in 1..lat - 1 {
                triangles.push([v(j, i), v(j + 1, i), v(j + 1, i + 1)]);
                triangles.push([v(j, i), v(j + 1, i + 1), v(j, i + 1)]);
            }
        }
        let tri_tag = vec![0; triangles.len()];
        Mesh {
            positions,
            triangles,
            tri_tag,
        }
    }

    /// Random rays from inside the sphere, from outside at it, and away from it (misses).
    fn rays(n: usize) -> Vec<(Ray, f64)> {
        let mut rng = PhotonRng::new(5, 0);
        let mut unit = || {
            let z = 2.0 * rng.uniform() - 1.0;
            let (s, c) = (std::f64::consts::TAU * rng.uniform()).sin_cos();
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * c, r * s, z)
        };
        (0..n)
            .map(|k| {
                let (p, d) = (unit(), unit());
                match k % 3 {
                    0 => (Ray::new(0.5 * p, d), f64::INFINITY),
                    1 => (Ray::new(3.0 * p, (0.3 * d - p).normalize()), f64::INFINITY),
                    _ => (Ray::new(3.0 * p, p), f64::INFINITY),
                }
            })
            .collect()
    }

    /// Every field of every lane equals, bit for bit, the record `rtcIntersect1` leaves
    /// for the same ray: hit normals, u, v, primID, tfar. A lane or field read from the
    /// wrong place changes them.
    fn packets_equal_single_rays<const N: usize>(accel: &EmbreeAccel)
    where
        Lanes<N>: PacketWidth,
    {
        let queries = rays(3 * N * 50 + 5);
        let bits = |r: &RTCRayHit| {
            let h = &r.hit;
            (
                [r.ray.tfar, h.Ng_x, h.Ng_y, h.Ng_z, h.u, h.v].map(f32::to_bits),
                [h.primID, h.geomID, h.instID[0], h.instPrimID[0]],
            )
        };
        let (mut hits, mut misses) = (0, 0);
        for (c, chunk) in queries.chunks(N).enumerate() {
            let mut valid = Valid([0i32; N]);
            let mut rh = RayHitN::<N>::empty();
            // Every fourth packet leaves its odd lanes off.
            let lanes: Vec<usize> = (0..chunk.len())
                .filter(|i| c % 4 != 3 || i % 2 == 0)
                .collect();
            for &i in &lanes {
                rh.set(i, &EmbreeAccel::ray_hit(&chunk[i].0, chunk[i].1));
                valid.0[i] = -1;
            }
            // SAFETY: local, aligned, initialised records.
            unsafe { accel.intersect_packet_raw::<N>(&valid, &mut rh) };
            for i in 0..N {
                let got = rh.get(i);
                let Some((ray, tmax)) = chunk.get(i).filter(|_| lanes.contains(&i)) else {
                    // Untouched: still the empty record.
                    assert_eq!(bits(&got), bits(&RayHitN::<N>::empty().get(i)), "lane {i}");
                    continue;
                };
                let mut one = EmbreeAccel::ray_hit(ray, *tmax);
                // SAFETY: a local, aligned, initialised record.
                unsafe { accel.intersect_raw(&mut one) };
                assert_eq!(bits(&got), bits(&one), "packet {c} lane {i} of {N}");
                if one.hit.geomID == 0 {
                    hits += 1;
                } else {
                    misses += 1;
                }
            }
        }
        assert!(hits > 100 && misses > 50, "{hits} hits, {misses} misses");
    }

    #[test]
    fn packet_records_equal_single_ray_records() {
        let Some(accel) = accel(lumpy_sphere()) else {
            return;
        };
        packets_equal_single_rays::<4>(&accel);
        packets_equal_single_rays::<8>(&accel);
        packets_equal_single_rays::<16>(&accel);
        eprintln!("native packets: {}", accel.native_packets());
    }

    /// The library writes nothing past our packet, and its answers land in the lanes
    /// asked: a ray that hits in lane i alone is reported in lane i alone.
    #[test]
    fn library_writes_within_our_packet_and_lane() {
        let Some(accel) = accel(lumpy_sphere()) else {
            return;
        };
        #[repr(C)]
        struct Guarded {
            rh: RayHitN<16>,
            guard: [u32; 64],
        }
        let hit = (Ray::new(DVec3::ZERO, DVec3::X), f64::INFINITY);
        let miss = (
            Ray::new(DVec3::splat(3.0), DVec3::ONE.normalize()),
            f64::INFINITY,
        );
        for lane in 0..16 {
            let mut queries = vec![miss; 16];
            queries[lane] = hit;
            let mut g = Guarded {
                rh: RayHitN::empty(),
                guard: [0xDEAD_BEEF; 64],
            };
            let valid = Valid([-1i32; 16]);
            for (i, q) in queries.iter().enumerate() {
                g.rh.set(i, &EmbreeAccel::ray_hit(&q.0, q.1));
            }
            // SAFETY: a local, aligned record with room to spare.
            unsafe { accel.intersect_packet_raw::<16>(&valid, &mut g.rh) };
            assert!(
                g.guard.iter().all(|&w| w == 0xDEAD_BEEF),
                "wrote past RTCRayHit16"
            );
            for i in 0..16 {
                let r = g.rh.get(i);
                assert_eq!(r.hit.geomID == 0, i == lane, "lane {i}, hit sent in {lane}");
            }
            let got = accel.intersect_packet::<16>(&queries);
            assert_eq!(got[lane], accel.intersect(&hit.0, hit.1));
            assert!(
                got.iter()
                    .enumerate()
                    .all(|(i, h)| h.is_some() == (i == lane))
            );
        }
    }

    #[test]
    fn partial_and_empty_segments_answer_like_single_rays() {
        let Some(accel) = accel(lumpy_sphere()) else {
            return;
        };
        let out = Ray::new(DVec3::ZERO, DVec3::Z);
        let queries = [
            (out, f64::INFINITY),
            (out, 0.5),
            (out, 0.0),
            (out, f64::NAN),
            (out, -1.0),
        ];
        let got = accel.intersect_packet::<8>(&queries);
        for (i, q) in queries.iter().enumerate() {
            assert_eq!(got[i], accel.intersect(&q.0, q.1), "query {i}");
        }
        assert!(got[0].is_some() && got[1..].iter().all(Option::is_none));
        assert_eq!(accel.intersect_packet::<4>(&[]), [None; 4]);
        let empty = self::accel(Mesh::default()).expect("loaded above");
        assert_eq!(empty.intersect_packet::<8>(&queries), [None; 8]);
    }

    #[test]
    #[should_panic(expected = "9 queries for 8 lanes")]
    fn too_many_queries_panic() {
        let Some(accel) = accel(lumpy_sphere()) else {
            panic!("9 queries for 8 lanes (Embree skipped)");
        };
        let q = (Ray::new(DVec3::ZERO, DVec3::Z), f64::INFINITY);
        accel.intersect_packet::<8>(&[q; 9]);
    }
}
