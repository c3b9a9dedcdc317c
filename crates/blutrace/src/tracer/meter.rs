//! The luminance meter's estimator: peel-off (next-event estimation) towards each view.
//!
//! ```text
//! blutrace trace SCENE [--luminance-estimator meter|cone]   # meter: the default
//! ```
//!
//! A luminance map counts the light leaving each bin within a small cone (2 degrees) of
//! a view direction. Counting the photons that happen to leave within it (the cone
//! estimator) needs billions of photons. The meter estimator scores, at every diffuse
//! event, the light that event sends towards the meter:
//!
//! 1. a direction `out` is drawn uniformly within the view's cone;
//! 2. the direction at the event that leaves along `out` after any number of specular
//!    events at faces parallel to the target (the light guide's front, flat films,
//!    mirrors and polarizers lying flat) follows from the invariant of such events,
//!    `n t` (the index times the direction's part along the target plane): two
//!    directions, up and down;
//! 3. for each, a path is traced from the event with the same surface models and
//!    Fresnel roulette as photons (weights instead of absorption roulette, absorption and
//!    scattering media as transmittance); it counts when it reaches the target in the
//!    ambient medium through specular events only, leaving along `out` (its `n t` the
//!    event's: a path through faces that turn `n t`, a groove facet or a tilted face,
//!    does not, but one reflected by a guide's two opposite edges does);
//! 4. it scores `w p T (out.N) Omega n_d^2 / (n^2 |dir.N|)` into the bin it crosses: the
//!    photon's weight before the event, the model's density towards `dir` (per sr,
//!    albedo included), the path's throughput (polarized where the run traces
//!    polarization, through the detector's analyzer when it has one), and the Jacobian from `dir` to `out`
//!    (radiance over n^2 is kept along specular paths), in the cone count's units
//!    (`Omega` the cone's solid angle, the pdf's inverse).
//!
//! The photons' own paths are split by the same test, so nothing is counted twice or left
//! out: a photon crossing the target within a cone is counted there only when its light
//! since its last diffuse event is not what that event's peel-off scored, that is when
//! it came from the source with no diffuse event, or met an event whose density no model
//! evaluates (a rough `diffuser` face, a `bsdf_table`, volume scattering), or crosses
//! the target with an `n t` other than the one it left its last diffuse event with, or
//! in a medium other than the ambient one. Both parts are unbiased, so their sum is; it
//! agrees with the cone estimator (tested), with far less noise where diffuse events
//! under flat layers make the light (a light guide's dots).
//! Peel-off draws its random numbers from the photon's side stream
//! ([`crate::rng::PhotonRng::side_stream`]): the photons' paths, flux and every other
//! output are the same bits under either estimator.
//!
//! The convex-solid walk and its runs of total reflection call the same hooks at the
//! events they take one by one (ink, other models); their runs of total reflection keep
//! `n t` by themselves.

use super::{Hit, Photon, Tracer};
use crate::geometry::SpawnedRay;
use crate::optics::model::{Arrival, MeterLayer, MeterVertex};
use crate::optics::polarization::Polarization;
use crate::optics::sampling;
use crate::optics::spectrum::{Light, Secondaries};
use crate::optics::surface::{Estimator, Feature, MediumId, Outcome, SurfaceModel};
use crate::rng::PhotonRng;
use crate::scene::Scene;
use crate::tally::{ChunkTally, MeterHit};
use glam::DVec3;
use std::cell::Cell;

/// Most events a peel-off path takes: paths through flat layers are a few events long;
/// one caught between parallel mirrors ends here, counted as not arriving (its light is
/// then missed by at most the weight left after this many reflections).
const PEEL_EVENTS: u32 = 256;

/// How far `n t` may move at an event that keeps it (rounding of unit directions and
/// refraction in f64 is ~1e-15; an event that turns it moves it by far more).
const KEPT: f64 = 1e-9;

/// A diffuse event the meter's peel-off starts from.
pub(super) struct Vertex<'a> {
    /// The photon's arrival at the event.
    pub at: &'a Arrival<'a>,
    /// The model it met and what part of it.
    pub model: &'a SurfaceModel,
    pub feature: Feature,
    /// The photon's weight before the event.
    pub weight: f64,
    /// Where it is, as [`ChunkTally::peel_tries`] counts peel-offs.
    pub start: usize,
}

/// Peel-offs from one place that all miss the target before the place is given up for
/// the rest of the chunk (a lamp cavity's reflector seen through its own housing).
const GIVE_UP_AFTER: u32 = 256;

/// How the meter peels off in a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Walk {
    /// Forward through faces keeping `n t` (this module).
    Flat,
    /// Backward through uniform layers ([`super::meter_walk`]).
    Backward,
}

impl Walk {
    /// Backward when the scene has uniform grooves or a rough diffuser, else flat.
    pub(super) fn of(scene: &Scene) -> Walk {
        let backward = scene
            .surfaces
            .iter()
            .chain(scene.backs.iter().flatten())
            .any(|m| {
                m.meter_layer() == MeterLayer::Turning
                    || m.meter_vertex(Feature::Plain) == MeterVertex::Stochastic
            });
        if backward { Walk::Backward } else { Walk::Flat }
    }
}

impl Tracer<'_> {
    /// The index of medium `m` for `light`.
    pub(super) fn index(&self, m: MediumId, light: Light) -> f64 {
        self.scene.media[m as usize].index(light)
    }

    /// `n t`: the part of unit `dir` along the target plane times the index of medium
    /// `m`, kept by specular events at faces parallel to the target.
    pub(super) fn invariant(&self, m: MediumId, dir: DVec3, light: Light) -> DVec3 {
        let n = self.scene.detector.normal();
        (dir - dir.dot(n) * n) * self.index(m, light)
    }

    /// Whether the photon `p`, crossing the target along `dir`, is light its last
    /// diffuse event's peel-off scored (see the module header).
    pub(super) fn peeled(&self, p: &Photon, dir: DVec3) -> bool {
        let kept = || {
            self.invariant(p.medium, dir, p.light)
                .distance_squared(p.left_with)
                <= KEPT * KEPT
        };
        match self.walk {
            Walk::Flat => p.covered && p.medium == 0 && kept(),
            Walk::Backward => p.covered && p.medium == 0,
        }
    }

    /// After an event of `v.model` that met `v.feature` and ended in `outcome`: at a
    /// diffuse event, peel off towards every view and remember the `n t` the photon
    /// leaves with; an event no model evaluates leaves its light to the cone count.
    pub(super) fn meter_event(
        &self,
        p: &mut Photon,
        v: &Vertex,
        outcome: &Outcome,
        out: &mut ChunkTally,
    ) {
        let kind = match (v.model.meter_vertex(v.feature), self.walk) {
            (MeterVertex::Stochastic, Walk::Flat) => MeterVertex::Unevaluated,
            (MeterVertex::Stochastic, Walk::Backward) => MeterVertex::Diffuse,
            (kind, _) => kind,
        };
        match kind {
            // Which face turned `n t` only names the cause of covered light: uncovered
            // light has its cause already, and pays for no check.
            MeterVertex::Specular if p.covered && self.walk == Walk::Flat => {
                if let Outcome::Scattered { dir, medium, .. } = *outcome {
                    let was = self.invariant(v.at.medium, v.at.dir, p.light);
                    let now = self.invariant(medium, dir, p.light);
                    if was.distance_squared(now) > KEPT * KEPT {
                        p.turned = v.start as u32;
                    }
                }
            }
            MeterVertex::Specular if p.covered => {
                if !self.crosses(v.model.meter_layer(), v.at.hit.normal) {
                    (p.covered, p.cause) = (false, v.start as u32);
                }
            }
            MeterVertex::Specular => {}
            MeterVertex::Diffuse => {
                let tries = out.peel_tries[v.start];
                // Giving a place up moves its light to the cone count: what the
                // estimator sums stays the same (the choice depends on earlier photons
                // of the chunk only, the same for every thread count).
                let given_up = (tries[0] >= GIVE_UP_AFTER && tries[1] == 0)
                    || self.out_of_sight(v.at.hit.point);
                (p.covered, p.cause) = (false, v.start as u32);
                let (Some(rng), false) = (&mut p.peel_rng, given_up) else {
                    return;
                };
                let before = out.meter.len();
                match self.walk {
                    Walk::Flat => self.peel(v, rng, &mut out.meter),
                    Walk::Backward => {
                        self.peel_backward(v, rng, &mut out.peel_walks, &mut out.meter)
                    }
                }
                for h in &out.meter[before..] {
                    out.peeled.add(h.weight);
                }
                let tries = &mut out.peel_tries[v.start];
                tries[0] += 1;
                tries[1] += u32::from(out.meter.len() > before);
                if let Outcome::Scattered { dir, medium, .. } = *outcome {
                    (p.covered, p.turned) = (true, u32::MAX);
                    if self.walk == Walk::Flat {
                        p.left_with = self.invariant(medium, dir, p.light);
                    }
                }
            }
            MeterVertex::Unevaluated | MeterVertex::Stochastic => {
                (p.covered, p.cause) = (false, v.start as u32)
            }
        }
    }

    /// [`Tracer::meter_event`] for the convex walk's event on `model` at `surf`, met along
    /// `dir` in `medium` by `p` (of weight `before` and polarization `pol` then) that met
    /// `feature`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn walk_event(
        &self,
        p: &mut Photon,
        (model, tag): (&SurfaceModel, u32),
        surf: &crate::geometry::SurfaceHit,
        (dir, medium, pol): (DVec3, MediumId, Option<Polarization>),
        (before, feature): (f64, Feature),
        outcome: &Outcome,
        out: &mut ChunkTally,
    ) {
        let (pol_out, shift_out) = (Cell::new(None), Cell::new(DVec3::ZERO));
        let at = Arrival {
            media: &self.scene.media,
            hit: surf,
            dir,
            medium,
            est: self.estimator,
            light: p.light,
            pol,
            pol_out: &pol_out,
            shift_out: &shift_out,
        };
        let v = Vertex {
            at: &at,
            model,
            feature,
            weight: before,
            start: tag as usize,
        };
        self.meter_event(p, &v, outcome, out);
    }

    /// Whether peel-off from `x` is not worth tracing: `x` lies below the target plane
    /// and outside the target seen along any view (the target grown by 1 mm and 1 % a
    /// side, and by the slant of the most oblique view's cone over the height). Only a
    /// shortcut: the light of an event not peeled off is counted in the cone.
    fn out_of_sight(&self, x: DVec3) -> bool {
        let d = &self.scene.detector;
        let r = x - d.origin;
        let height = -r.dot(d.normal());
        if height <= 0.0 {
            return false;
        }
        let widest = d.views.iter().map(|v| v[0]).fold(0.0, f64::max) + d.luminance_cone_deg;
        let slant = height * widest.min(89.0).to_radians().tan();
        let outside = |k: usize, along: DVec3| {
            let m = 1.0 + 0.01 * d.size[k] + slant;
            let a = r.dot(along);
            a < -m || a > d.size[k] + m
        };
        outside(0, d.u) || outside(1, d.v)
    }

    /// The light the diffuse event `v` sends towards each view.
    fn peel(&self, v: &Vertex, rng: &mut PhotonRng, hits: &mut Vec<MeterHit>) {
        let d = &self.scene.detector;
        let normal = d.normal();
        let light = v.at.light;
        let (n_x, n_d) = (self.index(v.at.medium, light), self.index(0, light));
        for k in 0..d.views.len() {
            let out = in_cone(d.view_dir(k), d.luminance_cone_deg, rng);
            let Some(dirs) = directions_at(out, normal, n_d / n_x) else {
                continue;
            };
            for dir in dirs {
                let density = v.model.meter_density(v.at, v.feature, dir);
                if density <= 0.0 {
                    continue;
                }
                if let Some((bin, throughput)) = self.peel_path(v.at, dir, out, rng) {
                    let w = v.weight * density * throughput;
                    hits.push(self.meter_hit((k, bin), w, (out, dir), (n_x, light)));
                }
            }
        }
    }

    /// The meter's hit of view `k` in flux bin `bin` for light of weight `w` (the photon's
    /// weight before the event times the event's density and the path's throughput)
    /// leaving the event along `dir` in a medium of index `n_x` and crossing the target
    /// along `out`: `w` times the Jacobian from `dir` to `out` over the cone's sampling
    /// density (module header, step 4).
    pub(super) fn meter_hit(
        &self,
        (k, bin): (usize, u32),
        w: f64,
        (out, dir): (DVec3, DVec3),
        (n_x, light): (f64, Light),
    ) -> MeterHit {
        let d = &self.scene.detector;
        let normal = d.normal();
        let n_d = self.index(0, light);
        let jacobian = d.cone_solid_angle() * (n_d * n_d) / (n_x * n_x);
        let cosines = out.dot(normal) / dir.dot(normal).abs();
        // The hero's wavelength alone: the peel-off path is the hero's (its secondaries'
        // own weights are not carried along it).
        let spectral = self.scene.sources.spectral().then_some(&Secondaries::NONE);
        MeterHit::new((k as u16, bin), w * cosines * jacobian, light, spectral)
    }

    /// Trace the peel-off path leaving the event of `at` along `dir` through specular
    /// events that keep `n t`: the flux bin where it crosses the target along `out` in
    /// the ambient medium, and its throughput; `None` when it does not.
    fn peel_path(
        &self,
        at: &Arrival,
        dir: DVec3,
        out: DVec3,
        rng: &mut PhotonRng,
    ) -> Option<(u32, f64)> {
        let scene = self.scene;
        let mut p = Photon {
            ray: SpawnedRay::leaving(at.hit.point, at.hit.normal, dir, scene.spawn_eps),
            medium: at.medium,
            weight: 1.0,
            light: at.light,
            pol: scene.polarized.then(|| Polarization::unpolarized(dir)),
            absorption_depth: -1.0,
            covered: false,
            left_with: DVec3::ZERO,
            cause: 0,
            turned: u32::MAX,
            peel_rng: None,
            secondaries: Secondaries::NONE,
        };
        for _ in 0..PEEL_EVENTS {
            let true_ray = p.ray.true_ray();
            let surf = self.nearest_surface(&p, &true_ray);
            let t_surface = surf.map_or(f64::INFINITY, |h| h.surf.t);
            let detected = self.target_hit(&p, &true_ray, t_surface);
            let t_next = detected.map_or(t_surface, |(t, _)| t);
            p.weight *= self.transmittance(p.medium, p.light, t_next);
            if let Some((_, ab)) = detected {
                p.covered = true;
                p.left_with = self.invariant(0, out, p.light);
                if !self.peeled(&p, true_ray.dir) {
                    return None;
                }
                // The panel's rear polarizer, when the detector has one, as photons meet it.
                let passed = p.pol.map_or(1.0, |pol| {
                    scene.detector.analyzer_transmittance(&pol, true_ray.dir)
                });
                return Some((scene.detector.flux_index(ab) as u32, p.weight * passed));
            }
            let Hit { surf, struck } = surf?;
            let model = self.model(struck, true_ray.dir, surf.normal);
            let feature = self.path_step(&mut p, model, &surf, true_ray.dir, rng)?;
            if model.meter_vertex(feature) != MeterVertex::Specular {
                return None;
            }
        }
        None
    }

    /// One event of a peel-off path (traced either way) at `surf`, met along `dir`: `p`
    /// takes the model's outcome with weights for absorption; what part of the face it
    /// met, `None` when the path ends there.
    pub(super) fn path_step(
        &self,
        p: &mut Photon,
        model: &SurfaceModel,
        surf: &crate::geometry::SurfaceHit,
        dir: DVec3,
        rng: &mut PhotonRng,
    ) -> Option<Feature> {
        let (pol_out, shift_out) = (Cell::new(None), Cell::new(DVec3::ZERO));
        let met = Arrival {
            media: &self.scene.media,
            hit: surf,
            dir,
            medium: p.medium,
            est: Estimator::Weighted,
            light: p.light,
            pol: p.pol,
            pol_out: &pol_out,
            shift_out: &shift_out,
        };
        let (outcome, feature) = model.interact_on(&met, rng);
        let Outcome::Scattered {
            dir,
            medium,
            weight,
        } = outcome
        else {
            return None;
        };
        p.weight *= weight;
        let from = surf.point + shift_out.get();
        p.ray = SpawnedRay::leaving(from, surf.normal, dir, self.scene.spawn_eps);
        p.medium = medium;
        if p.pol.is_some() {
            p.pol = Some(pol_out.get().unwrap_or(Polarization::unpolarized(dir)));
        }
        Some(feature)
    }

    /// The fraction of light crossing `t` mm of medium `m` unabsorbed and unscattered.
    pub(super) fn transmittance(&self, m: MediumId, light: Light, t: f64) -> f64 {
        let medium = &self.scene.media[m as usize];
        let scattering = match medium.scattering.scatters() {
            true => medium.scattering.coefficient(light),
            false => 0.0,
        };
        let k = medium.absorption(light) + scattering;
        if k == 0.0 { 1.0 } else { (-k * t).exp() }
    }
}

/// A direction drawn uniformly (in solid angle) within `half_deg` of unit `axis`.
pub(super) fn in_cone(axis: DVec3, half_deg: f64, rng: &mut PhotonRng) -> DVec3 {
    // 1 - cos c without cancellation, as the cone's solid angle takes it.
    let margin = 2.0 * (half_deg.to_radians() / 2.0).sin().powi(2);
    let cos_a = 1.0 - rng.uniform() * margin;
    sampling::around(axis, cos_a, rng.uniform())
}

/// The two unit directions (up and down along `normal`) in a medium of index `n` that
/// leave along unit `out` in the ambient medium of index `n_d` through events keeping
/// `n t` (`ratio = n_d / n`); `None` when `out` lies beyond the critical angle.
fn directions_at(out: DVec3, normal: DVec3, ratio: f64) -> Option<[DVec3; 2]> {
    let t = (out - out.dot(normal) * normal) * ratio;
    let sin2 = t.length_squared();
    if sin2 >= 1.0 {
        return None;
    }
    let c = (1.0 - sin2).sqrt();
    Some([t + normal * c, t - normal * c])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_at_keep_the_invariant() {
        let n = DVec3::Z;
        let out = DVec3::new(0.3, -0.4, (1.0f64 - 0.25).sqrt());
        let [up, down] = directions_at(out, n, 1.0 / 1.49).unwrap();
        for d in [up, down] {
            assert!((d.length() - 1.0).abs() < 1e-15);
            let t = (d - d.dot(n) * n) * 1.49;
            assert!((t - (out - out.dot(n) * n)).length() < 1e-15);
        }
        assert!(up.z > 0.0 && down.z < 0.0);
        assert!(directions_at(out, n, 2.5).is_none(), "0.5 * 2.5 > 1");
    }

    #[test]
    fn cone_directions_are_uniform_in_solid_angle() {
        // The mean of cos(angle to the axis) over a uniform cone is (1 + cos c) / 2.
        let mut rng = PhotonRng::new(1, 2);
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let (n, c) = (200_000, 10.0f64);
        let mean = (0..n)
            .map(|_| in_cone(axis, c, &mut rng).dot(axis))
            .sum::<f64>()
            / n as f64;
        let want = (1.0 + c.to_radians().cos()) / 2.0;
        let spread = (1.0 - c.to_radians().cos()) / 12f64.sqrt() / (n as f64).sqrt();
        assert!(
            (mean - want).abs() < 4.0 * spread,
            "{mean} vs {want} ± {spread}"
        );
        assert!(
            (0..1000).all(|_| in_cone(axis, c, &mut rng).dot(axis) >= c.to_radians().cos() - 1e-15)
        );
    }
}
