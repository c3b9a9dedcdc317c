//! The groove profile and the exact ray tracing through its layer (the model is described
//! in [`super`]).

use crate::optics::density::Gradation;
use crate::optics::fresnel;
use crate::optics::polarization::{Polarization, fresnel_roulette};
use crate::rng::PhotonRng;
use crate::rounding::floor_i64;
use glam::DVec3;

/// Cells a photon's path may cross in the groove layer at one surface hit before the
/// model falls back to the smooth mean plane.
pub const MAX_CELLS: usize = 1 << 16;
/// Reflections and refractions in the groove layer at one surface hit before the model
/// falls back to the smooth mean plane.
pub const MAX_EVENTS: usize = 1000;

/// Which way the V profile stands off the mean plane.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Relief {
    /// V notches cut into the `inside` medium (filled with the `outside` one).
    Cut,
    /// Prisms of the `inside` medium standing out into the `outside` one.
    Raised,
}

/// A groove pattern on a flat face.
#[derive(Clone, Debug, PartialEq)]
pub struct GroovePattern {
    /// Notches or prisms.
    pub relief: Relief,
    /// Groove pitch (mm).
    pub pitch: f64,
    /// Base angle of the facet on the `-axis` side of the apex (radians).
    pub base_lo: f64,
    /// Base angle of the facet on the `+axis` side of the apex (radians).
    pub base_hi: f64,
    /// Where `s = 0` (a point on the lamp edge).
    pub origin: DVec3,
    /// Unit in-face direction across the grooves.
    pub axis: DVec3,
    /// Fill fraction of each pitch, graded along `axis`.
    pub fill: Gradation,
    /// Depth (cut) or height (raised) of the deepest groove (mm): the layer's thickness.
    pub max_depth: f64,
}

/// One cell of the profile: lands and a V.
#[derive(Clone, Copy, Debug)]
struct Cell {
    /// Vertices `(s, z)`: cell start, V start, apex, V end, cell end.
    v: [(f64, f64); 5],
}

/// A crossing of the profile by a ray in the layer.
struct Crossing {
    t: f64,
    cell: i64,
    seg: usize,
    /// Unit normal of the segment, `(s, z)`, towards the outside medium.
    normal: (f64, f64),
}

impl GroovePattern {
    /// A pattern with its derived depth; angles in radians. The caller has checked the
    /// parameters (`GroovesSpec::build`, in `spec.rs`).
    pub fn new(
        relief: Relief,
        pitch: f64,
        (base_lo, base_hi): (f64, f64),
        origin: DVec3,
        axis: DVec3,
        fill: Gradation,
    ) -> Self {
        let mut p = Self {
            relief,
            pitch,
            base_lo,
            base_hi,
            origin,
            axis,
            fill,
            max_depth: 0.0,
        };
        p.max_depth = p.deepest();
        p
    }

    /// Base angles `(a_lo, a_hi)` (radians) from the apex angle and tilt (radians).
    pub fn base_angles(apex: f64, tilt: f64) -> (f64, f64) {
        let half = std::f64::consts::FRAC_PI_2 - 0.5 * apex;
        (half + tilt, half - tilt)
    }

    /// Depth (or height) of a groove filling the fraction `fill` of its pitch (mm).
    fn depth_for(&self, fill: f64) -> f64 {
        fill.clamp(0.0, 1.0) * self.pitch / (1.0 / self.base_lo.tan() + 1.0 / self.base_hi.tan())
    }

    /// Index of the cell holding `s` (mm along `axis` from `origin`).
    fn cell_index(&self, s: f64) -> i64 {
        floor_i64(s / self.pitch)
    }

    /// Fill fraction of cell `k` (the polynomial at its centre, clamped to `[0, 1]`).
    fn cell_fill(&self, k: i64) -> f64 {
        self.fill.at((k as f64 + 0.5) * self.pitch).clamp(0.0, 1.0)
    }

    /// The deepest groove anywhere (cells beyond the span repeat its end values).
    fn deepest(&self) -> f64 {
        let f = if self.fill.is_constant() {
            self.cell_fill(0)
        } else {
            let last = (self.fill.length / self.pitch).ceil() as i64;
            (-1..=last + 1)
                .map(|k| self.cell_fill(k))
                .fold(0.0, f64::max)
        };
        self.depth_for(f)
    }

    fn cell(&self, k: i64) -> Cell {
        let p = self.pitch;
        let lo = k as f64 * p;
        let centre = lo + 0.5 * p;
        let w = self.cell_fill(k) * p;
        let h = w / (1.0 / self.base_lo.tan() + 1.0 / self.base_hi.tan());
        let s_l = centre - 0.5 * w;
        let s_a = (s_l + h / self.base_lo.tan()).min(centre + 0.5 * w);
        let z_a = match self.relief {
            Relief::Cut => -h,
            Relief::Raised => h,
        };
        Cell {
            v: [
                (lo, 0.0),
                (s_l, 0.0),
                (s_a, z_a),
                (centre + 0.5 * w, 0.0),
                (lo + p, 0.0),
            ],
        }
    }

    #[cfg(test)]
    /// Height `z` of the profile at `s` (negative in cut notches), for tests and plots.
    fn profile_height(&self, s: f64) -> f64 {
        let c = self.cell(self.cell_index(s));
        for w in c.v.windows(2) {
            let ((s0, z0), (s1, z1)) = (w[0], w[1]);
            if s >= s0 && s <= s1 && s1 > s0 {
                return z0 + (z1 - z0) * (s - s0) / (s1 - s0);
            }
        }
        0.0
    }

    /// The layer the relief occupies, `(z_lo, z_hi)` relative to the mean plane.
    fn layer(&self) -> (f64, f64) {
        match self.relief {
            Relief::Cut => (-self.max_depth, 0.0),
            Relief::Raised => (0.0, self.max_depth),
        }
    }

    /// The first profile segment the 2-D ray `(s, z) + (ds, dz) t` crosses with
    /// `t_min < t <= t_exit`, skipping segment `skip`. `Err` when the cell budget runs out.
    #[allow(clippy::too_many_arguments)]
    fn first_crossing(
        &self,
        (s, z): (f64, f64),
        (ds, dz): (f64, f64),
        t_min: f64,
        t_exit: f64,
        skip: Option<(i64, usize)>,
        budget: &mut usize,
    ) -> Result<Option<Crossing>, ()> {
        let p = self.pitch;
        let step = if ds > 0.0 {
            1
        } else if ds < 0.0 {
            -1
        } else {
            0
        };
        let mut k = self.cell_index(s);
        loop {
            if *budget == 0 {
                return Err(());
            }
            *budget -= 1;
            let cell = self.cell(k);
            let mut best: Option<Crossing> = None;
            for seg in 0..4 {
                if skip == Some((k, seg)) {
                    continue;
                }
                let ((s0, z0), (s1, z1)) = (cell.v[seg], cell.v[seg + 1]);
                let (es, ez) = (s1 - s0, z1 - z0);
                if es <= 0.0 {
                    continue; // an empty land or a groove of zero fill
                }
                let denom = ds * ez - dz * es;
                if denom == 0.0 {
                    continue;
                }
                let (ws, wz) = (s0 - s, z0 - z);
                let t = (ws * ez - wz * es) / denom;
                let u = (ws * dz - wz * ds) / denom;
                if !(-1e-12..=1.0 + 1e-12).contains(&u) || t <= t_min || t > t_exit {
                    // (`t_exit` carries a rounding allowance: lands lie on the layer's
                    // boundary.)
                    continue;
                }
                if best.as_ref().is_none_or(|b| t < b.t) {
                    let len = es.hypot(ez);
                    best = Some(Crossing {
                        t,
                        cell: k,
                        seg,
                        normal: (-ez / len, es / len),
                    });
                }
            }
            if best.is_some() {
                return Ok(best);
            }
            let cell_end = if step > 0 {
                (k + 1) as f64 * p
            } else {
                k as f64 * p
            };
            if step == 0 || (cell_end - s) / ds >= t_exit {
                return Ok(None);
            }
            k += step;
        }
    }

    /// Trace a photon that met the mean plane at `point` (outward unit face normal
    /// `normal`, pointing from `inside` to `outside`) along unit `dir`, through the exact
    /// V profile of the layer: its direction as it leaves the layer and whether it leaves
    /// into the inside medium. `None` when the path needs more than [`MAX_CELLS`] cells
    /// or [`MAX_EVENTS`] events (the caller then uses the smooth mean plane).
    pub fn scatter(
        &self,
        indices: (f64, f64),
        point: DVec3,
        normal: DVec3,
        dir: DVec3,
        rng: &mut PhotonRng,
    ) -> Option<(DVec3, bool)> {
        self.scatter_met(indices, point, normal, dir, None, rng)
            .map(|(d, inside, _, _)| (d, inside))
    }

    /// [`GroovePattern::scatter`], also saying whether the path met a facet of a groove
    /// (`false`: it met only the flat land between grooves), and how far along `axis`
    /// from `point` its outgoing ray crosses the mean plane (where the light leaves from:
    /// the line it really leaves along, so that the reversed light, rewound along that
    /// line, re-enters the layer where it left; tracing reversed paths backwards, as the
    /// luminance meter does, meets the relief as photons do); `pol`, when polarization is
    /// traced, is carried through every facet's Fresnel event.
    pub fn scatter_met(
        &self,
        (n_inside, n_outside): (f64, f64),
        point: DVec3,
        normal: DVec3,
        dir: DVec3,
        mut pol: Option<&mut Polarization>,
        rng: &mut PhotonRng,
    ) -> Option<(DVec3, bool, bool, f64)> {
        let mut met = false;
        let axis = self.axis;
        let (ds0, dz0) = (dir.dot(axis), dir.dot(normal));
        if dz0 == 0.0 {
            return None;
        }
        let (z_lo, z_hi) = self.layer();
        let mut inside = dz0 > 0.0;
        // Rewind to where the straight path entered the layer.
        let t_back = if inside { -z_lo / dz0 } else { -z_hi / dz0 };
        let s_hit = (point - self.origin).dot(axis);
        let mut at = (s_hit - ds0 * t_back, -dz0 * t_back);
        let mut d = dir;
        let mut skip = None;
        let mut budget = MAX_CELLS;
        for _ in 0..MAX_EVENTS {
            let (ds, dz) = (d.dot(axis), d.dot(normal));
            let t_exit = if dz > 0.0 {
                (z_hi - at.1) / dz
            } else if dz < 0.0 {
                (z_lo - at.1) / dz
            } else {
                f64::INFINITY
            }
            .max(0.0);
            // Lands lie exactly on the layer's boundary: allow for rounding in `t_exit`.
            let t_exit = t_exit * (1.0 + 1e-9) + 1e-12 * self.pitch;
            let t_min = if skip.is_none() {
                -1e-9 * self.pitch
            } else {
                0.0
            };
            let Some(c) = self
                .first_crossing(at, (ds, dz), t_min, t_exit, skip, &mut budget)
                .ok()?
            else {
                // Left the layer; a missed crossing (a ray exactly through a vertex) could
                // leave side and direction inconsistent: the direction decides.
                let shift = at.0 - ds * at.1 / dz - s_hit;
                return (dz != 0.0).then_some((d, dz < 0.0, met, shift));
            };
            // Segments 1 and 2 are the V's facets, 0 and 3 the lands either side.
            met |= c.seg == 1 || c.seg == 2;
            at = (at.0 + ds * c.t, at.1 + dz * c.t);
            skip = Some((c.cell, c.seg));
            let m = axis * c.normal.0 + normal * c.normal.1;
            let towards_outside = d.dot(m) > 0.0;
            if towards_outside != inside {
                // Crossing from the side we did not think it was on (rounding at a
                // vertex): no interface event, just take the geometric side.
                inside = !towards_outside;
                continue;
            }
            let (n1, n2, facing) = if inside {
                (n_inside, n_outside, -m)
            } else {
                (n_outside, n_inside, m)
            };
            match fresnel_roulette(d, facing, (n1, n2), pol.as_deref_mut(), rng) {
                Some(t) => {
                    d = t;
                    inside = !inside;
                }
                None => d = fresnel::reflect(d, facing).normalize(),
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::density::{Density, XUnit};

    fn pattern(relief: Relief, apex_deg: f64, tilt_deg: f64, fill: Gradation) -> GroovePattern {
        GroovePattern::new(
            relief,
            0.05,
            GroovePattern::base_angles(apex_deg.to_radians(), tilt_deg.to_radians()),
            DVec3::ZERO,
            DVec3::X,
            fill,
        )
    }

    #[test]
    fn grooves_take_the_fill_fraction_and_depth_of_their_cell() {
        let fill = Gradation {
            density: Density::Polynomial(vec![0.1, 0.8]),
            length: 10.0,
            x_unit: XUnit::Normalized,
            mirror: false,
        };
        let p = pattern(Relief::Cut, 110.0, 10.0, fill.clone());
        // Deterministic scan of two cells: grooved length over the pitch is the fill.
        for k in [3i64, 150] {
            let n = 100_000;
            let lo = k as f64 * p.pitch;
            let cut = (0..n)
                .filter(|i| p.profile_height(lo + p.pitch * (*i as f64 + 0.5) / n as f64) < 0.0)
                .count();
            let f = fill.at((k as f64 + 0.5) * p.pitch);
            assert!((cut as f64 / n as f64 - f).abs() < 1e-4, "cell {k}");
            let deepest = (0..n)
                .map(|i| -p.profile_height(lo + p.pitch * i as f64 / n as f64))
                .fold(0.0, f64::max);
            let (a, b) = (45f64.to_radians(), 25f64.to_radians());
            let want = f * p.pitch / (1.0 / a.tan() + 1.0 / b.tan());
            assert!(
                (deepest - want).abs() < 2e-5 * p.pitch,
                "cell {k}: {deepest} vs {want}"
            );
        }
        assert!((p.max_depth - p.depth_for(0.9)).abs() < 1e-3 * p.max_depth);
    }

    #[test]
    fn positive_tilt_steepens_the_facet_on_the_minus_axis_side() {
        let p = pattern(Relief::Cut, 110.0, 10.0, Gradation::constant(1.0));
        assert!((p.base_lo.to_degrees() - 45.0).abs() < 1e-9);
        assert!((p.base_hi.to_degrees() - 25.0).abs() < 1e-9);
        // Full fill, cut: the profile falls at 45 deg from the cell start, rises at 25.
        let s = 0.01 * p.pitch;
        assert!((p.profile_height(s) + s).abs() < 1e-12);
        let e = p.pitch - s;
        assert!((p.profile_height(e) + s * 25f64.to_radians().tan()).abs() < 1e-12);
    }

    #[test]
    fn bef_prisms_retro_reflect_normal_light_by_two_total_reflections() {
        // 90 deg prisms, n = 1.58 (critical angle 39.3 deg < 45): light going straight up
        // out of the film comes straight back down, wherever it meets the prisms.
        let p = pattern(Relief::Raised, 90.0, 0.0, Gradation::constant(1.0));
        for i in 0..200 {
            let mut rng = PhotonRng::new(1, i);
            let x = p.pitch * (i as f64 + 0.37) / 200.0 * 7.0;
            let point = DVec3::new(x, 0.3, 0.0);
            let (d, inside) = p
                .scatter((1.58, 1.0), point, DVec3::Z, DVec3::Z, &mut rng)
                .unwrap();
            assert!(inside, "x = {x}");
            assert!((d - DVec3::NEG_Z).length() < 1e-9, "x = {x}: {d:?}");
        }
    }

    /// Where near-normal light from under full 90 degree prisms (pitch `p`, `s0` its
    /// point on the base, `(ds, dz)` its direction in the profile's plane) leaves the
    /// base again after its total reflections (one or two): plane geometry, by hand.
    fn retro_exit(p: f64, s0: f64, (mut ds, mut dz): (f64, f64)) -> f64 {
        let k = (s0 / p).floor() * p;
        let (mut s, mut z) = (s0, 0.0);
        for _ in 0..2 {
            // Facet lo: z = s - k (normal (-1, 1)); facet hi: z = k + p - s (normal (1, 1)).
            let t_lo = (s - k - z) / (dz - ds);
            let t_hi = (k + p - s - z) / (dz + ds);
            let ahead = |t: f64| if t > 1e-12 { t } else { f64::INFINITY };
            let (t_lo, t_hi) = (ahead(t_lo), ahead(t_hi));
            if dz < 0.0 && -z / dz < t_lo.min(t_hi) {
                break; // down through the base first
            }
            let (t, n) = if t_lo < t_hi {
                (t_lo, (-1.0, 1.0))
            } else {
                (t_hi, (1.0, 1.0))
            };
            (s, z) = (s + ds * t, z + dz * t);
            let dot = ds * n.0 + dz * n.1; // |n|^2 = 2
            (ds, dz) = (ds - dot * n.0, dz - dot * n.1);
        }
        s - ds * z / dz
    }

    #[test]
    fn light_leaves_along_its_outgoing_ray_where_that_ray_meets_the_face() {
        // Near-normal light under BEF prisms comes back by two total reflections (no
        // roulette), leaving the base a fraction of a pitch from where it entered: the
        // model says where, and the reversed light, sent back from there, retraces it.
        let p = pattern(Relief::Raised, 90.0, 0.0, Gradation::constant(1.0));
        let mut rng = PhotonRng::new(2, 9);
        let mut moved = 0.0f64;
        for i in 0..500 {
            let tilt = 3f64.to_radians() * (2.0 * rng.uniform() - 1.0);
            let a = DVec3::new(tilt.sin(), 0.0, tilt.cos());
            let point = DVec3::new(p.pitch * (3.0 + 30.0 * rng.uniform()), 0.3, 0.0);
            let (d, inside, _, shift) = p
                .scatter_met((1.58, 1.0), point, DVec3::Z, a, None, &mut rng)
                .unwrap();
            let want = retro_exit(p.pitch, point.x, (a.x, a.z)) - point.x;
            assert!(
                inside && (shift - want).abs() < 1e-9 * p.pitch,
                "path {i}: {shift} vs {want}"
            );
            moved = moved.max(shift.abs());
            let back = point + DVec3::X * shift;
            let (d2, _, _, shift2) = p
                .scatter_met((1.58, 1.0), back, DVec3::Z, -d, None, &mut rng)
                .unwrap();
            assert!((d2 + a).length() < 1e-9, "path {i}: {d2:?} vs {:?}", -a);
            assert!(
                (back.x + shift2 - point.x).abs() < 1e-9 * p.pitch,
                "path {i}"
            );
        }
        assert!(moved > 0.3 * p.pitch, "{moved}");
    }

    #[test]
    fn lamp_facing_facet_totally_reflects_guided_light_towards_the_front() {
        // A cut 45/25 deg groove on a guide's back face (normal -z, guide above): light
        // travelling along +x, 2 deg towards the back face, meets the 45 deg facet at
        // 47 deg incidence (beyond the PMMA critical angle) or, between grooves, the land.
        let p = pattern(Relief::Cut, 110.0, 10.0, Gradation::constant(0.8));
        let beta = 2f64.to_radians();
        let dir = DVec3::new(beta.cos(), 0.0, -beta.sin());
        let facet = {
            let a = p.base_lo;
            // Facet normal towards the notch: +axis and out of the guide (-z).
            DVec3::new(a.sin(), 0.0, -a.cos())
        };
        let via_facet = fresnel::reflect(dir, -facet);
        let via_land = DVec3::new(beta.cos(), 0.0, beta.sin());
        let (mut n_facet, mut n_land) = (0, 0);
        for i in 0..400 {
            let mut rng = PhotonRng::new(2, i);
            let point = DVec3::new(p.pitch * (i as f64 + 0.5) / 40.0, 0.0, 0.0);
            let (d, inside) = p
                .scatter((1.49, 1.0), point, DVec3::NEG_Z, dir, &mut rng)
                .unwrap();
            assert!(inside, "TIR everywhere: the photon stays in the guide");
            if (d - via_facet).length() < 1e-9 {
                n_facet += 1;
            } else if (d - via_land).length() < 1e-9 {
                n_land += 1;
            } else {
                panic!("unexpected direction {d:?} at {point:?}");
            }
        }
        // Rising 2 deg through the layer, a ray crosses several pitches before it could
        // reach a land: it always meets a lamp-facing facet first.
        assert_eq!((n_facet, n_land), (400, 0));
        // The facet sends the light up towards the front face, slightly backwards.
        assert!(via_facet.z > 0.99 && via_facet.x < 0.0);
    }

    #[test]
    fn lossless_layer_conserves_photons_and_keeps_side_and_direction_consistent() {
        let p = pattern(Relief::Raised, 90.0, 0.0, Gradation::constant(0.7));
        let mut fallback = 0;
        for i in 0..20_000u64 {
            let mut rng = PhotonRng::new(3, i);
            let u = rng.uniform();
            let dir = crate::optics::sampling::around(DVec3::Z, 2.0 * u - 1.0, rng.uniform());
            if dir.z == 0.0 {
                continue;
            }
            let point = DVec3::new(rng.uniform(), rng.uniform(), 0.0);
            match p.scatter((1.58, 1.0), point, DVec3::Z, dir, &mut rng) {
                Some((d, inside)) => {
                    assert!((d.length() - 1.0).abs() < 1e-9);
                    assert_eq!(inside, d.z < 0.0, "{dir:?} -> {d:?}");
                }
                None => fallback += 1,
            }
        }
        assert!(fallback < 5, "{fallback} fallbacks");
    }

    /// Brute force reference: the same roulette against every segment of the cells
    /// `k0 - 400 ..= k0 + 400` around the hit, nearest crossing first.
    fn reference(
        p: &GroovePattern,
        (n_in, n_out): (f64, f64),
        point: DVec3,
        normal: DVec3,
        dir: DVec3,
        rng: &mut PhotonRng,
    ) -> (DVec3, bool) {
        let axis = p.axis;
        let k0 = p.cell_index((point - p.origin).dot(axis));
        let segs: Vec<_> = (k0 - 400..=k0 + 400)
            .flat_map(|k| {
                let c = p.cell(k);
                (0..4).map(move |j| (c.v[j], c.v[j + 1]))
            })
            .filter(|(a, b)| b.0 > a.0)
            .collect();
        let (z_lo, z_hi) = p.layer();
        let dz0 = dir.dot(normal);
        let mut inside = dz0 > 0.0;
        let t_back = if inside { -z_lo / dz0 } else { -z_hi / dz0 };
        let mut at = (
            (point - p.origin).dot(axis) - dir.dot(axis) * t_back,
            -dz0 * t_back,
        );
        let (mut d, mut skip) = (dir, usize::MAX);
        loop {
            let (ds, dz) = (d.dot(axis), d.dot(normal));
            let t_min = if skip == usize::MAX { -1e-9 } else { 0.0 };
            let mut best: Option<(f64, usize)> = None;
            for (i, ((s0, z0), (s1, z1))) in segs.iter().enumerate() {
                let (es, ez) = (s1 - s0, z1 - z0);
                let denom = ds * ez - dz * es;
                if i == skip || denom == 0.0 {
                    continue;
                }
                let (ws, wz) = (s0 - at.0, z0 - at.1);
                let t = (ws * ez - wz * es) / denom;
                let u = (ws * dz - wz * ds) / denom;
                if (-1e-12..=1.0 + 1e-12).contains(&u) && t > t_min && best.is_none_or(|b| t < b.0)
                {
                    best = Some((t, i));
                }
            }
            let Some((t, i)) = best else {
                return (d, dz < 0.0);
            };
            at = (at.0 + ds * t, at.1 + dz * t);
            skip = i;
            let ((s0, z0), (s1, z1)) = segs[i];
            let len = (s1 - s0).hypot(z1 - z0);
            let m = axis * (-(z1 - z0) / len) + normal * ((s1 - s0) / len);
            if (d.dot(m) > 0.0) != inside {
                inside = d.dot(m) <= 0.0;
                continue;
            }
            let (n1, n2, facing) = if inside {
                (n_in, n_out, -m)
            } else {
                (n_out, n_in, m)
            };
            let r = fresnel::reflectance(-d.dot(facing), n1, n2);
            if r >= 1.0 || rng.uniform() < r {
                d = fresnel::reflect(d, facing).normalize();
            } else if let Some(t) = fresnel::refract(d, facing, n1, n2) {
                d = t;
                inside = !inside;
            } else {
                d = fresnel::reflect(d, facing).normalize();
            }
        }
    }

    #[test]
    fn cell_walk_matches_brute_force_over_all_segments() {
        // Graded asymmetric grooves, both reliefs, both face orientations, rays from every
        // direction: the same random numbers give the same photon, event for event.
        let fill = Gradation {
            density: Density::Polynomial(vec![0.1, 0.4]),
            length: 20.0,
            x_unit: XUnit::Normalized,
            mirror: false,
        };
        for relief in [Relief::Cut, Relief::Raised] {
            let p = GroovePattern::new(
                relief,
                0.25,
                GroovePattern::base_angles(110f64.to_radians(), 10f64.to_radians()),
                DVec3::ZERO,
                DVec3::X,
                fill.clone(),
            );
            let mut differ = 0;
            for i in 0..4000u64 {
                let mut rng = PhotonRng::new(3, i);
                let cos_t = 2.0 * rng.uniform() - 1.0;
                let turn = rng.uniform();
                let axis = DVec3::new(0.3, 0.1, 1.0).normalize();
                let dir = crate::optics::sampling::around(axis, cos_t, turn);
                let point = DVec3::new(1.0 + 18.0 * rng.uniform(), 0.0, 0.0);
                let normal = if i % 2 == 0 { DVec3::NEG_Z } else { DVec3::Z };
                let (mut r1, mut r2) = (PhotonRng::new(77, i), PhotonRng::new(77, i));
                let Some(a) = p.scatter((1.49, 1.0), point, normal, dir, &mut r1) else {
                    continue;
                };
                let b = reference(&p, (1.49, 1.0), point, normal, dir, &mut r2);
                if (a.0 - b.0).length() > 1e-6 || a.1 != b.1 {
                    differ += 1;
                }
            }
            // (A ray within 1e-3 of grazing can outrun the reference's 800 cells.)
            assert!(differ <= 2, "{relief:?}: {differ} of 4000 differ");
        }
    }
}
