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
//! How it is fast (issue 35; single-threaded user CPU seconds on bench-box, interleaved
//! A/B rounds of 2-4 million photons, medians; the kernel before it is kept as
//! [`super::reference_before`]). Most of a photon's 13.5 interactions are total internal
//! reflections inside the guide (12.3 guide steps, 2.1 air steps, 5.6 dotted-face hits
//! of which 1.2 land in a dot, per photon), so the guide step is the kernel:
//! - its nearest face is chosen by branches into per-axis code (`face::<K>`), not by
//!   selects or a runtime axis index: the branches are predicted (most steps cross the
//!   thickness), so the position's dependency chain does not wait for the comparisons,
//!   and positions and directions are arrays indexed by constants, in registers (glam's
//!   `Vec3` indexed by a runtime axis is a match per access): 1.23x;
//! - the direction's reciprocal is kept with it (a reflection negates one lane), so a step
//!   costs no division: 1.06x;
//! - the dot lookup works in cell units from the cell's centre and finds the cell by
//!   rounding in float arithmetic (no float-integer conversions): its answer is a branch
//!   mispredicted at every dot hit, which waits for the lookup: 1.05x for the cell units,
//!   1.10x more for the rounding;
//! - photons are counted per chunk in a small tally (fate counters in an array), and
//!   the run of guide steps is a loop of its own: about 1.06x together.
//!
//! Then, for the 2x (1.58-1.74x above; A/B rounds of 2-4 million photons, each
//! change against the build before it):
//! - a photon moving towards the plain face across the thickness from the dotted one,
//!   totally reflected there (no draw: the cosine alone decides), takes both steps to
//!   the dotted face as one (`there_and_back`): 1.07x;
//! - and takes them as a run: with total reflection at both faces (the same cosine), its
//!   landings on the dotted face lie at path lengths `back + j period` until one lands
//!   in a dot, so the dot lookups are independent of each other and run back to back
//!   instead of one per link of the position's chain (`run`), the run's
//!   length bounded beforehand by the sides, the optical depth left and the bounce cap,
//!   without a division or a libm `floor`/`ceil` call (x86-64's baseline has no rounding
//!   instruction: 4.6 % of the profile before): 1.17x with the step of two;
//! - a photon in air stands on the surface it last met, moving away from it: that
//!   surface is not tested (the guide is convex, the sheet and the strip flat, so the
//!   test could only say "no"): 1.05-1.08x;
//! - an air step takes one reciprocal of the direction for all its planes and finds the
//!   guide's entry by slabs without branches but the answer's: 1.03x.
//!
//! Together 1.90-2.00x the old kernel single-threaded (interleaved rounds in one run);
//! see the README's bench section for the last measurement.
//!
//! Measured and not kept, because they bought nothing measurable: Fresnel's roulette
//! without its two divisions (1.00x, twice); one reciprocal for all the planes of an air
//! step (before the entry test lost its branches); walking the guide as three
//! independent billiards (the hits along each axis are periodic between changes of
//! direction, positions computed only at the dotted face); a Lambertian direction
//! without rejection (radius `sqrt(u)`, the angle in an octant by Taylor series placed by
//! three random bits, no branch: 1.00x); emission points and Lambertian directions built
//! in registers instead of lane by lane at runtime indices (1.00x); starting runs at the
//! dotted face as well as at the plain one (0.94x).
//! Not costs: the per-photon generator start (a generator per chunk instead: within 2 %),
//! `ln` per photon (0.3 % of the profile), the chunk loop and its counting (2 %).
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

use super::box_scene::{AaRect, Body, BoxScene, Dots};
use anyhow::Result;
use blutrace::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;
use rng::{Rng, splitmix64};

mod counts;
mod rng;

pub use counts::Counts;

/// Photons per work unit, as blutrace's.
const CHUNK: u64 = 4096;

/// cos 30 degrees: detections closer to the normal are counted apart.
const COS_30: f32 = 0.866_025_4;

/// How one photon ended: the index of its counter in [`Tally::fates`], and the flux bin
/// and near-normal flag of a detection.
#[derive(Clone, Copy)]
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

/// One side of the guide's dielectric faces, from index `n1` into `n2`, with the
/// constants of its Fresnel roulette.
#[derive(Clone, Copy, Debug)]
struct Interface {
    n1: f32,
    n2: f32,
    /// `n1 / n2`.
    eta: f32,
    /// `(1 - eta) (1 + eta)`: `cos^2 t = this + eta^2 cos^2 i`.
    one_minus_eta2: f32,
    /// `eta^2`.
    eta2: f32,
}

impl Interface {
    fn new(n1: f32, n2: f32) -> Self {
        let eta = n1 / n2;
        Interface {
            n1,
            n2,
            eta,
            one_minus_eta2: (1.0 - eta) * (1.0 + eta),
            eta2: eta * eta,
        }
    }

    /// Total internal reflection at incidence cosine `cos_i` (where [`Interface::refract`]
    /// reflects without a draw).
    #[inline(always)]
    fn reflects(&self, cos_i: f32) -> bool {
        self.one_minus_eta2 + self.eta2 * cos_i * cos_i <= 0.0
    }

    /// Fresnel roulette at incidence cosine `cos_i`: `None` when reflected (always under
    /// total internal reflection, without a draw), else `cos t` of the refracted
    /// direction.
    #[inline(always)]
    fn refract(&self, cos_i: f32, rng: &mut Rng) -> Option<f32> {
        let cos2_t = self.one_minus_eta2 + self.eta2 * cos_i * cos_i;
        if cos2_t <= 0.0 {
            return None;
        }
        let cos_t = cos2_t.sqrt();
        let rs = (self.n1 * cos_i - self.n2 * cos_t) / (self.n1 * cos_i + self.n2 * cos_t);
        let rp = (self.n2 * cos_i - self.n1 * cos_t) / (self.n2 * cos_i + self.n1 * cos_t);
        (rng.uniform() >= 0.5 * (rs * rs + rp * rp)).then_some(cos_t)
    }
}

/// A photon's run inside the guide: where it left (position, direction), its fate if it
/// ended there, its interactions so far.
type Leg = (Vec3, Vec3, Option<Fate>, u32);

/// A photon inside the guide: position, direction, its reciprocal (updated with it, so a
/// step costs no division), interactions so far. Plain arrays indexed by constants: they
/// stay in registers.
struct Guided {
    p: [f32; 3],
    d: [f32; 3],
    inv: [f32; 3],
    n: u32,
}

/// The dot lattice in cell units: `(p - origin) . axis` is the position along the
/// pattern in cells from a cell's centre (the pattern's origin moved half a cell on both
/// axes).
struct Cells {
    origin: Vec3,
    axis: Vec3,
    across: Vec3,
    col0: i32,
    /// Squared dot radius per column, in cells squared.
    r2: Vec<f32>,
}

impl Cells {
    fn new(dots: &Dots) -> Self {
        let per_cell = 1.0 / dots.pitch;
        Cells {
            origin: dots.origin + 0.5 * dots.pitch * (dots.axis + dots.across),
            axis: dots.axis * per_cell,
            across: dots.across * per_cell,
            col0: dots.col0,
            r2: dots.r2.iter().map(|r2| r2 * per_cell * per_cell).collect(),
        }
    }
}

/// Per-chunk counters, in registers and a few cache lines while a chunk is traced.
struct Tally {
    /// Photons per fate, in [`Fate`]'s order (detected first).
    fates: [u64; 7],
    near_normal: u64,
    interactions: u64,
    interactions_sq: u128,
}

/// The reference kernel of one box-guide scene.
pub struct Reference {
    s: BoxScene,
    /// Air into the guide, and the guide into air.
    enter: Interface,
    leave: Interface,
    /// The dots in cell units.
    cells: Cells,
    /// Flux bins per mm along the target's u and v, signed as its axes.
    bins_per_mm: [f32; 2],
    /// The guide's thickness along z.
    thick: f32,
    /// The sign along z of a photon moving towards the plain face across from the dotted
    /// one (0 when the dots are not on a z face: no shortcut).
    plain_side: f32,
    /// The dotted face's z (when it is a z face).
    dotted_at: f32,
    /// `1 / (2 thick)`, and the absorption's reciprocal (mm).
    per_two_thick: f32,
    /// See `per_two_thick`.
    per_absorption: f32,
}

impl Reference {
    /// The kernel for `scene`, or an error saying why it is not a box-guide scene.
    pub fn new(scene: &Scene) -> Result<Reference> {
        let s = BoxScene::from_scene(scene)?;
        let g = &s.target;
        Ok(Reference {
            enter: Interface::new(s.n_air, s.n_guide),
            leave: Interface::new(s.n_guide, s.n_air),
            cells: Cells::new(&s.dots),
            bins_per_mm: [
                g.u.1 * g.bins[0] as f32 / g.size[0],
                g.v.1 * g.bins[1] as f32 / g.size[1],
            ],
            thick: s.hi[2] - s.lo[2],
            per_two_thick: 0.5 / (s.hi[2] - s.lo[2]),
            per_absorption: 1.0 / s.absorption,
            dotted_at: if s.dots.face == 5 { s.hi[2] } else { s.lo[2] },
            plain_side: match s.dots.face {
                4 => 1.0,
                5 => -1.0,
                _ => 0.0,
            },
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
        let key = splitmix64(seed);
        (0..photons.div_ceil(CHUNK))
            .into_par_iter()
            .fold(
                || Counts::new(bins),
                |mut c, k| {
                    self.trace_chunk(key, k * CHUNK..((k + 1) * CHUNK).min(photons), &mut c);
                    c
                },
            )
            .reduce(|| Counts::new(bins), Counts::merge)
    }

    fn trace_chunk(&self, key: u64, photons: std::ops::Range<u64>, c: &mut Counts) {
        let mut t = Tally {
            fates: [0; 7],
            near_normal: 0,
            interactions: 0,
            interactions_sq: 0,
        };
        for i in photons {
            let mut rng = Rng::new(key, i);
            let (fate, n) = self.follow(&mut rng);
            t.interactions += u64::from(n);
            t.interactions_sq += u128::from(n) * u128::from(n);
            let slot = match fate {
                Fate::Detected(bin, near) => {
                    c.flux[bin] += 1;
                    t.near_normal += u64::from(near);
                    0
                }
                Fate::Ink => 1,
                Fate::Sheet => 2,
                Fate::Medium => 3,
                Fate::Source => 4,
                Fate::Escaped => 5,
                Fate::Killed => 6,
            };
            t.fates[slot] += 1;
        }
        let f = t.fates;
        c.photons += f.iter().sum::<u64>();
        c.detected += f[0];
        c.absorbed_by_ink += f[1];
        c.absorbed_by_sheet += f[2];
        c.absorbed_in_medium += f[3];
        c.absorbed_by_source += f[4];
        c.escaped += f[5];
        c.killed += f[6];
        c.detected_near_normal += t.near_normal;
        c.interactions += t.interactions;
        c.interactions_sq += t.interactions_sq;
    }

    /// One photon from emission to its fate; also its number of interactions `n`.
    ///
    /// The photon alternates between air steps (this loop) and a run of steps inside the
    /// guide ([`Reference::in_guide`]), which is where most interactions happen.
    fn follow(&self, rng: &mut Rng) -> (Fate, u32) {
        let s = &self.s;
        let strip = &s.strip;
        let mut p = point_on(&strip.rect, rng);
        let mut d = Vec3::from_array(lambertian(strip.rect.axis, strip.facing, rng));
        // Optical depth left before the guide's bulk absorbs the photon.
        let mut depth = -(1.0 - rng.uniform()).ln();
        let mut n = 0;
        // The surface the photon stands on, moving away from it: it cannot meet it next.
        let mut on = Struck::Body;
        while n < s.max_bounces {
            let inv = d.recip();
            let (t, struck) = self.nearest_in_air(p, d, inv, on);
            if let Some(bin) = self.detected(p, d, inv, t) {
                let g = &s.target;
                let near_normal = d[g.rect.axis] * g.normal_sign > COS_30;
                return (Fate::Detected(bin, near_normal), n);
            }
            let Some(struck) = struck else {
                return (Fate::Escaped, n);
            };
            let from = p;
            p += d * t;
            on = struck;
            match struck {
                Struck::Guide(face) => {
                    let k = face / 2;
                    p[k] = if face % 2 == 1 { s.hi[k] } else { s.lo[k] };
                    let out = side(face);
                    if face == s.dots.face && self.ink(p.to_array()) {
                        if rng.uniform() >= s.dots.ink_albedo {
                            return (Fate::Ink, n + 1);
                        }
                        d = Vec3::from_array(lambertian(k, out, rng));
                    } else if let Some(cos_t) = self.enter.refract(d[k].abs(), rng) {
                        d *= self.enter.eta;
                        d[k] = -out * cos_t;
                        let (q, e, fate, m) = self.in_guide(p, d, &mut depth, n + 1, rng);
                        if let Some(fate) = fate {
                            return (fate, m);
                        }
                        (p, d, n, on) = (q, e, m, Struck::Guide(0));
                        continue;
                    } else {
                        d[k] = -d[k];
                    }
                }
                Struck::Sheet => {
                    let k = s.sheet.axis;
                    p[k] = s.sheet.at;
                    if rng.uniform() >= s.sheet_albedo {
                        return (Fate::Sheet, n + 1);
                    }
                    d = Vec3::from_array(lambertian(k, -d[k].signum(), rng));
                }
                Struck::Body => {
                    let r = &strip.rect;
                    p[r.axis] = r.at;
                    let front = (from[r.axis] - r.at) * strip.facing > 0.0;
                    match strip.body {
                        Body::Lambert(albedo) if front && rng.uniform() < albedo => {
                            d = Vec3::from_array(lambertian(r.axis, strip.facing, rng));
                        }
                        _ => return (Fate::Source, n + 1),
                    }
                }
            }
            n += 1;
        }
        (Fate::Killed, s.max_bounces)
    }

    /// Steps of a photon inside the guide, from `n` interactions, until it leaves (its
    /// position, direction and interactions, no fate) or ends (its fate).
    #[inline(always)]
    fn in_guide(&self, p: Vec3, d: Vec3, depth: &mut f32, n: u32, rng: &mut Rng) -> Leg {
        let mut g = Guided {
            p: p.to_array(),
            d: d.to_array(),
            inv: d.recip().to_array(),
            n,
        };
        let (lo, hi) = (self.s.lo.to_array(), self.s.hi.to_array());
        while g.n < self.s.max_bounces {
            let t: [f32; 3] = std::array::from_fn(|k| {
                let bound = if g.d[k] > 0.0 { hi[k] } else { lo[k] };
                // An axis along which the photon does not move never bounds the step.
                if g.d[k] == 0.0 {
                    f32::INFINITY
                } else {
                    ((bound - g.p[k]) * g.inv[k]).max(0.0)
                }
            });
            // The nearest face (the lowest axis on ties), tested by branches, not
            // selects: they are predicted (most steps cross the thickness), so the
            // position's dependency chain does not wait for the comparisons.
            let end = if t[2] < t[0] && t[2] < t[1] {
                // Towards the plain face across from the dotted one, totally reflected
                // there, and back at the dotted face before any side: a run of landings
                // on the dotted face ([`Reference::run`]).
                let back = t[2] + self.thick * g.inv[2].abs();
                if g.d[2] * self.plain_side > 0.0
                    && self.leave.reflects(g.d[2].abs())
                    && back < t[0]
                    && back < t[1]
                    && g.n + 1 < self.s.max_bounces
                {
                    self.run(&mut g, t[2], back, t[0].min(t[1]), depth, rng)
                } else {
                    self.face::<2>(&mut g, t[2], t[2], depth, rng)
                }
            } else if t[0] <= t[1] {
                self.face::<0>(&mut g, t[0], t[0], depth, rng)
            } else {
                self.face::<1>(&mut g, t[1], t[1], depth, rng)
            };
            if let Some(end) = end {
                return (Vec3::from_array(g.p), Vec3::from_array(g.d), end, g.n);
            }
        }
        let (p, d) = (Vec3::from_array(g.p), Vec3::from_array(g.d));
        (p, d, Some(Fate::Killed), self.s.max_bounces)
    }

    /// A photon inside the guide moves `step` to its face along axis `K` and meets it:
    /// `None` when it stays inside, `Some(None)` when it refracts out, `Some(fate)` when
    /// it ends. `run` is the path length absorption is drawn along (`step`, or the last
    /// leg of a step of two).
    #[inline(always)]
    fn face<const K: usize>(
        &self,
        g: &mut Guided,
        step: f32,
        run: f32,
        depth: &mut f32,
        rng: &mut Rng,
    ) -> Option<Option<Fate>> {
        let s = &self.s;
        let tau = s.absorption * run;
        if tau > *depth {
            return Some(Some(Fate::Medium));
        }
        *depth -= tau;
        let up = g.d[K] > 0.0;
        for j in 0..3 {
            g.p[j] = if j == K {
                if up { s.hi[K] } else { s.lo[K] }
            } else {
                g.p[j] + g.d[j] * step
            };
        }
        g.n += 1;
        let out = if up { 1.0 } else { -1.0 };
        if 2 * K + usize::from(up) == s.dots.face && self.ink(g.p) {
            if rng.uniform() >= s.dots.ink_albedo {
                return Some(Some(Fate::Ink));
            }
            g.d = lambertian(K, -out, rng);
            g.inv = g.d.map(|x| 1.0 / x);
        } else if let Some(cos_t) = self.leave.refract(g.d[K].abs(), rng) {
            g.d = g.d.map(|x| x * self.leave.eta);
            g.d[K] = out * cos_t;
            return Some(None);
        } else {
            g.d[K] = -g.d[K];
            g.inv[K] = -g.inv[K];
        }
        None
    }

    /// A photon inside the guide moving towards the plain face across the thickness from
    /// the dotted one, totally reflected there (no draw), meets the dotted face at `back`:
    /// the two interactions in one step, the same as two calls of [`Reference::face`]
    /// (1.07x).
    #[inline(always)]
    fn there_and_back(
        &self,
        g: &mut Guided,
        there: f32,
        back: f32,
        depth: &mut f32,
        rng: &mut Rng,
    ) -> Option<Option<Fate>> {
        let tau = self.s.absorption * there;
        if tau > *depth {
            return Some(Some(Fate::Medium));
        }
        *depth -= tau;
        g.n += 1;
        g.d[2] = -g.d[2];
        g.inv[2] = -g.inv[2];
        self.face::<2>(g, back, back - there, depth, rng)
    }

    /// A photon inside the guide moving towards the plain face (`there` away), totally
    /// reflected there: its run of landings on the dotted face, at path lengths
    /// `back + j period`, all totally reflected (the same cosine at both faces) until one
    /// lands in a dot, or the next would be beyond a side (`side` away), past the optical
    /// depth left or past the bounce cap. The landings have no draws and depend on
    /// nothing but `j`, so the dot lookups run back to back, not one per step of a chain
    /// (1.17x with the step of two, [`Reference::there_and_back`]). The photon then stands on its last landing, as
    /// after two calls of [`Reference::face`] per landing: in a dot it meets the ink,
    /// otherwise it moves on towards the plain face.
    #[inline(always)]
    fn run(
        &self,
        g: &mut Guided,
        there: f32,
        back: f32,
        side: f32,
        depth: &mut f32,
        rng: &mut Rng,
    ) -> Option<Option<Fate>> {
        let s = &self.s;
        let period = 2.0 * self.thick * g.inv[2].abs();
        let per_period = g.d[2].abs() * self.per_two_thick;
        let landing = |j: u32| back + j as f32 * period;
        // Landings within `x` periods of the first: `x + 1` rounded down (the conversion
        // saturates), perhaps one too many, which the loop below takes back (as it does
        // rounding's).
        let within = |x: f32| (x as u32).saturating_add(1);
        // Landing j is interaction `n + 2 j + 2`, at most the cap.
        let mut count = ((s.max_bounces - g.n) / 2).min(within((side - back) * per_period));
        if s.absorption > 0.0 {
            count = count.min(within((*depth * self.per_absorption - back) * per_period));
        }
        while count > 0
            && (landing(count - 1) >= side || s.absorption * landing(count - 1) > *depth)
        {
            count -= 1;
        }
        if count == 0 {
            return self.there_and_back(g, there, back, depth, rng);
        }
        let c = &self.cells;
        let r = Vec3::new(g.p[0], g.p[1], self.dotted_at) + Vec3::new(g.d[0], g.d[1], 0.0) * back
            - c.origin;
        let hop = Vec3::new(g.d[0], g.d[1], 0.0) * period;
        let (w0, z0) = (r.dot(c.axis), r.dot(c.across));
        let (dw, dz) = (hop.dot(c.axis), hop.dot(c.across));
        let (mut j, mut jf) = (0, 0.0);
        let inked = loop {
            if j == count {
                break false;
            }
            if self.in_dot(w0 + jf * dw, z0 + jf * dz) {
                break true;
            }
            j += 1;
            jf += 1.0;
        };
        let last = if inked { j } else { j - 1 };
        let run = landing(last);
        *depth -= s.absorption * run;
        g.n += 2 * (last + 1);
        g.p = [g.p[0] + g.d[0] * run, g.p[1] + g.d[1] * run, self.dotted_at];
        if inked {
            if rng.uniform() >= s.dots.ink_albedo {
                return Some(Some(Fate::Ink));
            }
            g.d = lambertian(2, self.plain_side, rng);
            g.inv = g.d.map(|x| 1.0 / x);
        }
        None
    }

    /// Where a photon in air enters the guide (slabs, `inv` the direction's reciprocal):
    /// distance and face. Without branches but the answer's: an axis the photon does not
    /// move along gives infinite slab distances, which never bound it when it lies
    /// between the faces and empty it otherwise.
    #[inline]
    fn entry(&self, p: Vec3, d: Vec3, inv: Vec3) -> Option<(f32, usize)> {
        let (a, b) = ((self.s.lo - p) * inv, (self.s.hi - p) * inv);
        let (near, far) = (a.min(b), a.max(b));
        let (t0, t1) = (near.max_element(), far.min_element());
        if !(t0 > 0.0 && t0 <= t1) {
            return None;
        }
        // The lowest axis on ties.
        let k = if near.x == t0 {
            0
        } else if near.y == t0 {
            1
        } else {
            2
        };
        Some((t0, 2 * k + usize::from(d[k] < 0.0)))
    }

    /// The surface a photon in air meets first (guide, sheet or the strip's body), with
    /// its distance (infinite when none). The photon stands on `on`, moving away from it,
    /// so it cannot meet it (the guide is convex, the others are flat): it is not tested.
    #[inline]
    fn nearest_in_air(&self, p: Vec3, d: Vec3, inv: Vec3, on: Struck) -> (f32, Option<Struck>) {
        let s = &self.s;
        let (mut t, mut struck) = match (!matches!(on, Struck::Guide(_)))
            .then(|| self.entry(p, d, inv))
            .flatten()
        {
            Some((t, face)) => (t, Some(Struck::Guide(face))),
            None => (f32::INFINITY, None),
        };
        if !matches!(on, Struck::Sheet)
            && let Some(ts) = hit(&s.sheet, p, d, inv)
            && ts < t
        {
            (t, struck) = (ts, Some(Struck::Sheet));
        }
        if s.strip.body != Body::Transparent
            && !matches!(on, Struck::Body)
            && let Some(tb) = hit(&s.strip.rect, p, d, inv)
            && tb < t
        {
            (t, struck) = (tb, Some(Struck::Body));
        }
        (t, struck)
    }

    /// The flux bin of a photon in air crossing the target along its normal nearer than
    /// `t_surface`.
    #[inline]
    fn detected(&self, p: Vec3, d: Vec3, inv: Vec3, t_surface: f32) -> Option<usize> {
        let g = &self.s.target;
        if d[g.rect.axis] * g.normal_sign <= 0.0 {
            return None;
        }
        let t = hit(&g.rect, p, d, inv).filter(|&t| t < t_surface)?;
        let q = p + d * t - g.origin;
        let bin = |k: usize, per_mm: f32, n: usize| ((q[k] * per_mm) as usize).min(n - 1);
        let [nu, nv] = g.bins;
        Some(bin(g.v.0, self.bins_per_mm[1], nv) * nu + bin(g.u.0, self.bins_per_mm[0], nu))
    }

    /// True when `p` on the dotted face lies inside a dot.
    ///
    /// In cell units, from the cell's centre: `w`, the position along the pattern less
    /// half a cell, is `dx` off its nearest integer (the column, as `floor(w + 1/2)`), by
    /// the float-rounding trick (adding `1.5 * 2^23` rounds to an integer, whose bits
    /// are the column): no float-integer conversions, and no multiplication by the pitch,
    /// between the position and the branch on the answer, which is mispredicted whenever
    /// a dot is hit (and so waits for it). A point exactly on a cell edge (a tie) may
    /// take either cell.
    #[inline(always)]
    fn ink(&self, p: [f32; 3]) -> bool {
        let c = &self.cells;
        let r = Vec3::from_array(p) - c.origin;
        self.in_dot(r.dot(c.axis), r.dot(c.across))
    }

    /// True when the point `(w, z)` of the pattern in cell units ([`Cells`]) lies inside
    /// a dot.
    #[inline(always)]
    fn in_dot(&self, w: f32, z: f32) -> bool {
        let c = &self.cells;
        let (rw, rz) = ((w + ROUND) - ROUND, (z + ROUND) - ROUND);
        let column = (w + ROUND).to_bits() as i32 - ROUND.to_bits() as i32;
        let col = (column - c.col0).clamp(0, c.r2.len() as i32 - 1) as usize;
        let (dx, dy) = (w - rw, z - rz);
        dx * dx + dy * dy < c.r2[col]
    }
}

/// `1.5 * 2^23`: added to an `f32` of magnitude below `2^22`, rounds it to an integer
/// held in the low mantissa bits.
const ROUND: f32 = 12_582_912.0;

/// The outward normal's sign along its axis of the guide's face `face`.
#[inline]
fn side(face: usize) -> f32 {
    if face % 2 == 1 { 1.0 } else { -1.0 }
}

/// [`AaRect::hit`] with the direction's reciprocal `inv`: no division.
#[inline]
fn hit(r: &AaRect, p: Vec3, d: Vec3, inv: Vec3) -> Option<f32> {
    let (k1, k2) = AaRect::others(r.axis);
    let t = (r.at - p[r.axis]) * inv[r.axis];
    if !(t > 0.0 && t.is_finite()) {
        return None;
    }
    let (a, b) = (p[k1] + d[k1] * t, p[k2] + d[k2] * t);
    (a >= r.lo[0] && a <= r.hi[0] && b >= r.lo[1] && b <= r.hi[1]).then_some(t)
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
fn lambertian(k: usize, sign: f32, rng: &mut Rng) -> [f32; 3] {
    let (k1, k2) = AaRect::others(k);
    loop {
        let (a, b) = (2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
        let r2 = a * a + b * b;
        if r2 < 1.0 {
            let mut d = [0.0; 3];
            (d[k], d[k1], d[k2]) = (sign * (1.0 - r2).sqrt(), a, b);
            return d;
        }
    }
}

#[cfg(test)]
mod tests;
