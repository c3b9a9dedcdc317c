//! A hand-written minimal kernel for box-guide scenes (`scenes/bench-box`): the
//! speed-of-light reference `blutrace bench` measures blutrace against, and an independent
//! implementation of the same physics that `tests/bench_reference.rs` checks blutrace
//! with.
//!
//! Built from the loaded scene ([`BoxScene::from_scene`], which refuses any scene not of
//! that shape), it traces with analytic axis-aligned planes in `f32` and its own random
//! numbers, and shares no tracing code with blutrace. The physics is blutrace's, analog
//! estimator:
//! - the LED strip emits from a uniform point of its rectangle, Lambertian;
//! - guide faces: unpolarized Fresnel `(Rs + Rp) / 2` in cosine form, total internal
//!   reflection, Snell refraction; reflect or refract by roulette on R;
//! - the dotted face: a point inside a dot (square lattice, dot at the cell centre, radius
//!   from the density at the cell centre) meets Lambertian ink, albedo roulette, back to
//!   the side the photon came from; elsewhere the dielectric face;
//! - the sheet: albedo roulette, Lambertian back to the side the photon came from;
//! - the strip's body: its front Lambertian (or absorbing), its back absorbing;
//! - the guide's bulk: Beer-Lambert absorption;
//! - the target plane: a photon crossing it along its normal before any surface is
//!   detected and scored in its flux bin; one meeting nothing escapes;
//! - every surface or body hit is an interaction; after `max_bounces` the photon is killed.
//!
//! Where it is cheaper than blutrace's general path without changing the physics: the
//! guide's exit is the nearest of three planes ahead; a photon inside the guide never
//! tests the target (it lies outside); Beer-Lambert draws one exponential optical depth
//! per photon and spends it along the guide segments (the same law, by the exponential's
//! lack of memory, as a draw per segment); Lambertian directions by Malley's method (a
//! uniform point of the unit disc lifted to the hemisphere: no trigonometry); refraction
//! at an axis-aligned face scales the tangential components by `n1/n2` and sets the
//! normal one to `cos t`.
//!
//! Why `f32` is safe here: positions in the recentred scene (within 70 mm of the origin
//! for bench-box) round to 4 nm; every hit puts the photon exactly on its plane, so
//! rounding only random-walks the in-plane coordinates, about 0.1 um after a thousand
//! bounces, against dot radii of 60 um and more. Directions and Fresnel terms in `f32`
//! move R by about 1e-7 and 24-bit uniforms quantize a roulette by 6e-8 (the exponential
//! depth stops at 16.6, a tail of 6e-8): all far below the statistical errors a run can
//! reach (1e-3 at the agreement test's 262,144 photons, 1e-5 at 1e10).
//!
//! Random numbers: xoshiro128++ (Blackman and Vigna, "Scrambled linear pseudorandom
//! number generators", ACM TOMS 47, 2021), 24-bit uniforms; photon `i` of seed `s` starts
//! from a SplitMix64 hash of `(s, i)`, so results depend on seed and index only, never on
//! threads.

use super::box_scene::{AaRect, Body, BoxScene};
use anyhow::Result;
use blutrace::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;

/// Photons per work unit, as blutrace's.
const CHUNK: u64 = 4096;

/// cos 30 degrees: detections closer to the normal are counted apart.
const COS_30: f32 = 0.866_025_4;

/// What a traced batch of photons did: fates (each photon has exactly one), interactions
/// and the flux bins.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Photons traced.
    pub photons: u64,
    /// Reached the target plane.
    pub detected: u64,
    /// Of those, the ones within 30 degrees of its normal (a coarse angular check).
    pub detected_near_normal: u64,
    /// Absorbed by the ink of the dots.
    pub absorbed_by_ink: u64,
    /// Absorbed by the sheet.
    pub absorbed_by_sheet: u64,
    /// Absorbed in the guide's bulk.
    pub absorbed_in_medium: u64,
    /// Absorbed by the strip's body.
    pub absorbed_by_source: u64,
    /// Left the scene.
    pub escaped: u64,
    /// Stopped by the bounce cap.
    pub killed: u64,
    /// Surface and body interactions.
    pub interactions: u64,
    /// Sum over photons of the square of their interaction counts (for errors).
    pub interactions_sq: u128,
    /// Detected photons per flux bin (row-major, x fastest, as blutrace's grid).
    pub flux: Vec<u64>,
}

impl Counts {
    fn new(bins: usize) -> Self {
        Self {
            flux: vec![0; bins],
            ..Default::default()
        }
    }

    fn merge(mut self, o: Counts) -> Counts {
        self.photons += o.photons;
        self.detected += o.detected;
        self.detected_near_normal += o.detected_near_normal;
        self.absorbed_by_ink += o.absorbed_by_ink;
        self.absorbed_by_sheet += o.absorbed_by_sheet;
        self.absorbed_in_medium += o.absorbed_in_medium;
        self.absorbed_by_source += o.absorbed_by_source;
        self.escaped += o.escaped;
        self.killed += o.killed;
        self.interactions += o.interactions;
        self.interactions_sq += o.interactions_sq;
        self.flux.iter_mut().zip(&o.flux).for_each(|(a, b)| *a += b);
        self
    }

    /// Photons with any fate: equals `photons` (the ledger closes).
    pub fn fates(&self) -> u64 {
        self.detected
            + self.absorbed_by_ink
            + self.absorbed_by_sheet
            + self.absorbed_in_medium
            + self.absorbed_by_source
            + self.escaped
            + self.killed
    }
}

/// How one photon ended.
enum Fate {
    /// In this flux bin, within 30 degrees of the normal or not.
    Detected(usize, bool),
    Ink,
    Sheet,
    Medium,
    Source,
    Escaped,
    Killed,
}

/// What a photon in air meets first.
#[derive(Clone, Copy)]
enum Struck {
    Guide(usize),
    Sheet,
    Body,
}

/// The reference kernel of one box-guide scene.
pub struct Reference {
    s: BoxScene,
    inv_pitch: f32,
}

impl Reference {
    /// The kernel for `scene`, or an error saying why it is not a box-guide scene.
    pub fn new(scene: &Scene) -> Result<Reference> {
        let s = BoxScene::from_scene(scene)?;
        Ok(Reference {
            inv_pitch: 1.0 / s.dots.pitch,
            s,
        })
    }

    /// The scene as the kernel reads it.
    pub fn scene(&self) -> &BoxScene {
        &self.s
    }

    /// Trace photons `0..photons` of `seed` in parallel (on the current rayon pool), in
    /// fixed chunks; the counts do not depend on the thread count.
    pub fn trace(&self, seed: u64, photons: u64) -> Counts {
        let bins = self.s.target.bins[0] * self.s.target.bins[1];
        (0..photons.div_ceil(CHUNK))
            .into_par_iter()
            .fold(
                || Counts::new(bins),
                |mut c, k| {
                    for i in k * CHUNK..((k + 1) * CHUNK).min(photons) {
                        self.trace_photon(seed, i, &mut c);
                    }
                    c
                },
            )
            .reduce(|| Counts::new(bins), Counts::merge)
    }

    fn trace_photon(&self, seed: u64, index: u64, c: &mut Counts) {
        let mut rng = Rng::new(seed, index);
        let (fate, n) = self.follow(&mut rng);
        c.photons += 1;
        c.interactions += u64::from(n);
        c.interactions_sq += u128::from(n) * u128::from(n);
        match fate {
            Fate::Detected(bin, near_normal) => {
                c.detected += 1;
                c.detected_near_normal += u64::from(near_normal);
                c.flux[bin] += 1;
            }
            Fate::Ink => c.absorbed_by_ink += 1,
            Fate::Sheet => c.absorbed_by_sheet += 1,
            Fate::Medium => c.absorbed_in_medium += 1,
            Fate::Source => c.absorbed_by_source += 1,
            Fate::Escaped => c.escaped += 1,
            Fate::Killed => c.killed += 1,
        }
    }

    /// One photon from emission to its fate; also its number of interactions.
    ///
    /// One function on purpose: split into steps over a photon struct (the same
    /// arithmetic, the same counts) it ran 20 % slower, and this is the speed of light.
    fn follow(&self, rng: &mut Rng) -> (Fate, u32) {
        let s = &self.s;
        let strip = &s.strip;
        let mut p = point_on(&strip.rect, rng);
        let mut d = lambertian(strip.rect.axis, strip.facing, rng);
        // Optical depth left before the guide's bulk absorbs the photon.
        let mut depth = -(1.0 - rng.uniform()).ln();
        let mut inside = false;
        for n in 0..s.max_bounces {
            if inside {
                let (t, face) = self.exit(p, d);
                let tau = s.absorption * t;
                if tau > depth {
                    return (Fate::Medium, n);
                }
                depth -= tau;
                p = self.on_face(p + d * t, face);
                let (k, out) = (face / 2, side(face));
                if face == s.dots.face && self.ink(p) {
                    if rng.uniform() >= s.dots.ink_albedo {
                        return (Fate::Ink, n + 1);
                    }
                    d = lambertian(k, -out, rng);
                } else if let Some((eta, cos_t)) = fresnel(d[k].abs(), s.n_guide, s.n_air, rng) {
                    d *= eta;
                    d[k] = out * cos_t;
                    inside = false;
                } else {
                    d[k] = -d[k];
                }
                continue;
            }
            let (t, struck) = self.nearest_in_air(p, d);
            if let Some(bin) = self.detected(p, d, t) {
                let g = &s.target;
                let near_normal = d[g.rect.axis] * g.normal_sign > COS_30;
                return (Fate::Detected(bin, near_normal), n);
            }
            let Some(struck) = struck else {
                return (Fate::Escaped, n);
            };
            let from = p;
            match struck {
                Struck::Guide(face) => {
                    p = self.on_face(p + d * t, face);
                    let (k, out) = (face / 2, side(face));
                    if face == s.dots.face && self.ink(p) {
                        if rng.uniform() >= s.dots.ink_albedo {
                            return (Fate::Ink, n + 1);
                        }
                        d = lambertian(k, out, rng);
                    } else if let Some((eta, cos_t)) = fresnel(d[k].abs(), s.n_air, s.n_guide, rng)
                    {
                        d *= eta;
                        d[k] = -out * cos_t;
                        inside = true;
                    } else {
                        d[k] = -d[k];
                    }
                }
                Struck::Sheet => {
                    let k = s.sheet.axis;
                    p = on_plane(p + d * t, &s.sheet);
                    if rng.uniform() >= s.sheet_albedo {
                        return (Fate::Sheet, n + 1);
                    }
                    d = lambertian(k, -d[k].signum(), rng);
                }
                Struck::Body => {
                    let r = &strip.rect;
                    p = on_plane(p + d * t, r);
                    let front = (from[r.axis] - r.at) * strip.facing > 0.0;
                    match strip.body {
                        Body::Lambert(albedo) if front && rng.uniform() < albedo => {
                            d = lambertian(r.axis, strip.facing, rng);
                        }
                        _ => return (Fate::Source, n + 1),
                    }
                }
            }
        }
        (Fate::Killed, s.max_bounces)
    }

    /// Where a photon inside the guide leaves it: distance and face (`2 axis + side`).
    #[inline]
    fn exit(&self, p: Vec3, d: Vec3) -> (f32, usize) {
        let (mut best, mut face) = (f32::INFINITY, 0);
        for k in 0..3 {
            let (bound, f) = if d[k] > 0.0 {
                (self.s.hi[k], 2 * k + 1)
            } else if d[k] < 0.0 {
                (self.s.lo[k], 2 * k)
            } else {
                continue;
            };
            let t = ((bound - p[k]) / d[k]).max(0.0);
            if t < best {
                (best, face) = (t, f);
            }
        }
        (best, face)
    }

    /// Where a photon in air enters the guide (slabs): distance and face.
    #[inline]
    fn entry(&self, p: Vec3, d: Vec3) -> Option<(f32, usize)> {
        let (lo, hi) = (self.s.lo, self.s.hi);
        let (mut t0, mut t1, mut face) = (f32::NEG_INFINITY, f32::INFINITY, 0);
        for k in 0..3 {
            let (near, far, f) = if d[k] > 0.0 {
                ((lo[k] - p[k]) / d[k], (hi[k] - p[k]) / d[k], 2 * k)
            } else if d[k] < 0.0 {
                ((hi[k] - p[k]) / d[k], (lo[k] - p[k]) / d[k], 2 * k + 1)
            } else if p[k] < lo[k] || p[k] > hi[k] {
                return None;
            } else {
                continue;
            };
            if near > t0 {
                (t0, face) = (near, f);
            }
            t1 = t1.min(far);
        }
        (t0 > 0.0 && t0 <= t1).then_some((t0, face))
    }

    /// The surface a photon in air meets first (guide, sheet or the strip's body), with
    /// its distance (infinite when none).
    #[inline]
    fn nearest_in_air(&self, p: Vec3, d: Vec3) -> (f32, Option<Struck>) {
        let s = &self.s;
        let (mut t, mut struck) = match self.entry(p, d) {
            Some((t, face)) => (t, Some(Struck::Guide(face))),
            None => (f32::INFINITY, None),
        };
        if let Some(ts) = s.sheet.hit(p, d)
            && ts < t
        {
            (t, struck) = (ts, Some(Struck::Sheet));
        }
        if s.strip.body != Body::Transparent
            && let Some(tb) = s.strip.rect.hit(p, d)
            && tb < t
        {
            (t, struck) = (tb, Some(Struck::Body));
        }
        (t, struck)
    }

    /// The flux bin of a photon in air crossing the target along its normal nearer than
    /// `t_surface`.
    #[inline]
    fn detected(&self, p: Vec3, d: Vec3, t_surface: f32) -> Option<usize> {
        let g = &self.s.target;
        if d[g.rect.axis] * g.normal_sign <= 0.0 {
            return None;
        }
        let t = g.rect.hit(p, d).filter(|&t| t < t_surface)?;
        let q = p + d * t - g.origin;
        let bin = |(k, sign): (usize, f32), size: f32, n: usize| {
            ((sign * q[k] / size * n as f32) as usize).min(n - 1)
        };
        Some(bin(g.v, g.size[1], g.bins[1]) * g.bins[0] + bin(g.u, g.size[0], g.bins[0]))
    }

    /// True when `p` on the dotted face lies inside a dot.
    #[inline(always)]
    fn ink(&self, p: Vec3) -> bool {
        let dots = &self.s.dots;
        let r = p - dots.origin;
        let (qa, qc) = (r.dot(dots.axis), r.dot(dots.across));
        let (i, j) = (floor(qa * self.inv_pitch), floor(qc * self.inv_pitch));
        let col = (i - dots.col0).clamp(0, dots.r2.len() as i32 - 1) as usize;
        let (dx, dy) = (
            qa - (i as f32 + 0.5) * dots.pitch,
            qc - (j as f32 + 0.5) * dots.pitch,
        );
        dx * dx + dy * dy < dots.r2[col]
    }

    /// `p` put exactly on the plane of the guide's face `face`.
    #[inline]
    fn on_face(&self, mut p: Vec3, face: usize) -> Vec3 {
        let k = face / 2;
        p[k] = if face % 2 == 1 {
            self.s.hi[k]
        } else {
            self.s.lo[k]
        };
        p
    }
}

/// The outward normal's sign along its axis of the guide's face `face`.
#[inline]
fn side(face: usize) -> f32 {
    if face % 2 == 1 { 1.0 } else { -1.0 }
}

/// The largest integer not above `x` (within the face's few thousand cells): without
/// the libm call `f32::floor` makes on baseline x86-64.
#[inline]
fn floor(x: f32) -> i32 {
    let i = x as i32;
    i - i32::from(x < i as f32)
}

/// `p` put exactly on the plane of `r`.
#[inline]
fn on_plane(mut p: Vec3, r: &AaRect) -> Vec3 {
    p[r.axis] = r.at;
    p
}

/// A uniform point of `r`.
fn point_on(r: &AaRect, rng: &mut Rng) -> Vec3 {
    let (k1, k2) = AaRect::others(r.axis);
    let mut p = Vec3::ZERO;
    p[r.axis] = r.at;
    p[k1] = r.lo[0] + rng.uniform() * (r.hi[0] - r.lo[0]);
    p[k2] = r.lo[1] + rng.uniform() * (r.hi[1] - r.lo[1]);
    p
}

/// A Lambertian direction about the axis `k` with sign `sign` (Malley's method).
#[inline]
fn lambertian(k: usize, sign: f32, rng: &mut Rng) -> Vec3 {
    let (k1, k2) = AaRect::others(k);
    loop {
        let (a, b) = (2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
        let r2 = a * a + b * b;
        if r2 < 1.0 {
            let mut d = Vec3::ZERO;
            (d[k], d[k1], d[k2]) = (sign * (1.0 - r2).sqrt(), a, b);
            return d;
        }
    }
}

/// Fresnel roulette from index `n1` into `n2` at incidence cosine `cos_i`: `None` when
/// reflected (always under total internal reflection), else `(n1/n2, cos t)` of the
/// refracted direction.
#[inline]
fn fresnel(cos_i: f32, n1: f32, n2: f32, rng: &mut Rng) -> Option<(f32, f32)> {
    let eta = n1 / n2;
    let cos2_t = (1.0 - eta) * (1.0 + eta) + eta * eta * cos_i * cos_i;
    if cos2_t <= 0.0 {
        return None;
    }
    let cos_t = cos2_t.sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    let r = 0.5 * (rs * rs + rp * rp);
    (rng.uniform() >= r).then_some((eta, cos_t))
}

/// xoshiro128++ with a per-photon start.
struct Rng([u32; 4]);

impl Rng {
    fn new(seed: u64, index: u64) -> Self {
        let a = splitmix64(splitmix64(seed) ^ index);
        let b = splitmix64(a ^ 0xD1B5_4A32_D192_ED03);
        let s = [a as u32, (a >> 32) as u32, b as u32, (b >> 32) as u32];
        Rng(if s == [0; 4] { [1, 0, 0, 0] } else { s })
    }

    #[inline]
    fn next_u32(&mut self) -> u32 {
        let s = &mut self.0;
        let out = s[0].wrapping_add(s[3]).rotate_left(7).wrapping_add(s[0]);
        let t = s[1] << 9;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(11);
        out
    }

    /// A uniform number in `[0, 1)` with 24 random bits.
    #[inline]
    fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// SplitMix64's finalizer (Steele, Lea and Flood 2014): a bijective 64-bit mixer.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn bench_box() -> Scene {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes/bench-box");
        Scene::load(&dir.join("scene.toml")).unwrap()
    }

    #[test]
    fn every_photon_has_one_fate_for_any_thread_count() {
        let r = Reference::new(&bench_box()).unwrap();
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let three = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let a = one.install(|| r.trace(5, 20_000));
        let b = three.install(|| r.trace(5, 20_000));
        assert_eq!(a, b);
        assert_eq!(a.fates(), 20_000);
        assert_eq!(a.flux.iter().sum::<u64>(), a.detected);
        assert!(a.detected > 0 && a.absorbed_by_ink > 0 && a.escaped > 0);
    }

    #[test]
    fn reads_the_scene() {
        let r = Reference::new(&bench_box()).unwrap();
        let s = r.scene();
        let size = s.hi - s.lo - Vec3::new(120.0, 80.0, 3.0);
        assert!(size.abs().max_element() < 1e-4, "{size}");
        assert_eq!((s.n_guide, s.n_air, s.absorption), (1.49, 1.0, 0.0003));
        assert_eq!(
            (s.dots.face, s.dots.pitch, s.dots.ink_albedo),
            (4, 0.5, 0.9)
        );
        assert_eq!((s.sheet.axis, s.sheet_albedo), (2, 0.96));
        assert_eq!(s.strip.body, Body::Lambert(0.8));
        assert_eq!((s.target.bins, s.target.normal_sign), ([120, 80], 1.0));
        // Dot radius at the lit edge: d = 0.05 + 0.2 u + 0.4 u^2 at u = 0.25 / 120.
        let u = 0.25 / 120.0;
        let d = 0.05 + 0.2 * u + 0.4 * u * u;
        let r2 = s.dots.r2[(-s.dots.col0) as usize];
        assert!((f64::from(r2) - d * 0.25 / std::f64::consts::PI).abs() < 1e-8);
    }

    #[test]
    fn refuses_other_scenes_saying_why() {
        let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
        for (scene, why) in [
            ("notebook14", "square lattice"),
            ("edge-holder", "more than one part"),
            ("direct-lit", "scatters"),
            ("test/slab", "no dotted face"),
        ] {
            let s = Scene::load(&dir.join(scene).join("scene.toml")).unwrap();
            let e = Reference::new(&s).err().expect("refused").to_string();
            assert!(
                e.contains("box-guide scenes") && e.contains(why),
                "{scene}: {e}"
            );
        }
    }

    #[test]
    fn fresnel_matches_the_closed_form_at_normal_incidence() {
        // R0 = ((n - 1)/(n + 1))^2: the share of reflections over many draws.
        let mut rng = Rng::new(1, 2);
        let n = 200_000;
        let reflected = (0..n)
            .filter(|_| fresnel(1.0, 1.0, 1.49, &mut rng).is_none())
            .count();
        let r0 = (0.49f64 / 2.49).powi(2);
        let se = (r0 * (1.0 - r0) / n as f64).sqrt();
        assert!((reflected as f64 / n as f64 - r0).abs() < 4.0 * se);
        assert!(
            fresnel(0.5, 1.49, 1.0, &mut rng).is_none(),
            "beyond critical"
        );
    }
}
