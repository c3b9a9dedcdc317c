//! The reference kernel as it was before issue 35 made it faster
//! ([`super::reference`] is the current one): the same physics and the same scene
//! reading, kept so that `blutrace bench` can time both in the same run and the README can
//! state blutrace's ratio to each, measured on one machine under one load. Not a test
//! oracle (that is the current kernel's job); its code is frozen on purpose: a speed
//! change here would move the baseline the README compares with.
//!
//! Where its time went, as profiled for issue 35 (the current kernel's header gives what
//! each fix bought): the nearest face inside the guide chosen by selects over a runtime
//! axis, so the position's dependency chain waits for the comparisons; glam's `Vec3`
//! indexed by that runtime axis (a match per access); a division per plane and step; the
//! dot lookup's float-integer conversions and pitch multiplications ahead of a branch
//! mispredicted at every dot hit.

use super::box_scene::{AaRect, Body, BoxScene};
use super::reference::Counts;
use anyhow::Result;
use blutrace::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;

/// Photons per work unit, as blutrace's.
const CHUNK: u64 = 4096;

/// cos 30 degrees: detections closer to the normal are counted apart.
const COS_30: f32 = 0.866_025_4;

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

/// The reference kernel of one box-guide scene, as before issue 35.
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
