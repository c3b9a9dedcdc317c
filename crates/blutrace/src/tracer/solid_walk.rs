//! Face to face inside a convex solid: the photon loop when nothing but the solid's own
//! faces can end a segment.
//!
//! A photon in a light guide spends most of its events bouncing between the guide's
//! faces. Where the medium has a [`ConvexSolid`] (the convex path), the solid lies clear
//! of the target, no lamp body sits in that medium and the medium does not scatter, the
//! general loop's tests for bodies, the target and the backend cannot change anything:
//! here the photon goes from exit face to exit face until it leaves the medium or meets
//! its fate. The two faces a guide is made of are taken without the general dispatch:
//! a smooth dielectric face (`model = "dielectric"`) and a dotted one (`model = "dots"`)
//! with its refractive indices looked up once; every other model goes through
//! [`SurfaceModel::interact_on`].
//!
//! The same physics and the same random numbers, in the same order, as the general
//! loop: traced chunks are identical bit for bit with the walk on and off (tested, with
//! runs off). In a box guide, runs of total reflection ([`super::tir_run`]) take many
//! steps at once, rounding positions differently.
//! Measured (single-thread CPU time, interleaved runs): 21 % more photons/s on
//! bench-box, 4 % on notebook14 (its photons spend more of their events in the lamp
//! cavities). Where values live matters more here than the arithmetic: a direction
//! passed by value to a function that is not inlined is stored as 16 + 8 bytes and read
//! back by the next dot product as 8 + 16, which stalls store forwarding. With the
//! Fresnel roulette called that way the walk was 15 % slower than the general loop; it
//! and `Smooth::leave` are inlined.

use super::body_boxes::BodyBoxes;
use super::tir_run::TirRun;
use super::{Photon, ROULETTE_BELOW, Tracer, absorb_clear, convex_solid, roulette};
use crate::accel::convex::ConvexSolid;
use crate::estimator::{Estimator, LuminanceEstimator};
use crate::geometry::{Ray, SpawnedRay, SurfaceHit};
use crate::optics::dot_placement::ColumnRadii;
use crate::optics::dots::DotPattern;
use crate::optics::fresnel;
use crate::optics::lambert;
use crate::optics::medium::{Interface, MediumId};
use crate::optics::model::Arrival;
use crate::optics::polarization::{Polarization, fresnel_roulette};
use crate::optics::spectrum::{Light, Spectral};
use crate::optics::surface::{Feature, Outcome, SurfaceModel};
use crate::rng::PhotonRng;
use crate::scene::Scene;
use crate::tally::{ChunkTally, Fate};
use glam::DVec3;
use std::cell::Cell;

/// A tag's surface model as the walk takes it.
#[derive(Clone, Debug)]
pub(super) enum Face<'a> {
    /// A smooth dielectric face: its interface and the indices behind and in front.
    Smooth(Smooth),
    /// A dotted face: ink where a dot is, else the smooth face. `radii`: the pattern's
    /// column table, when it has one.
    Dotted {
        smooth: Smooth,
        pattern: &'a DotPattern,
        radii: Option<ColumnRadii>,
        ink_albedo: Spectral,
    },
    /// Any other model, through [`SurfaceModel::interact_on`].
    Other,
}

/// A smooth interface with its two refractive indices.
#[derive(Clone, Debug)]
pub(super) struct Smooth {
    iface: Interface,
    n_inside: Spectral,
    n_outside: Spectral,
}

/// What the walk needs of a scene: each tag's face and, per medium, the solid to walk.
pub(super) struct Walks<'a> {
    faces: Vec<Face<'a>>,
    solids: Vec<Option<&'a ConvexSolid>>,
    /// Per medium, its solid's runs of total reflection ([`super::tir_run`]).
    pub(super) runs: Vec<Option<TirRun<'a>>>,
}

impl<'a> Walks<'a> {
    /// The walks of `scene` (none when the convex path is off).
    pub(super) fn new(scene: &'a Scene, convex: bool, bodies: &BodyBoxes) -> Walks<'a> {
        let n = |m: MediumId| scene.media[m as usize].n.clone();
        let smooth = |iface: &Interface| Smooth {
            iface: *iface,
            n_inside: n(iface.inside),
            n_outside: n(iface.outside),
        };
        let faces = scene
            .surfaces
            .iter()
            .map(|model| match model {
                SurfaceModel::Dielectric(i) => Face::Smooth(smooth(i)),
                SurfaceModel::Dots(d) => Face::Dotted {
                    smooth: smooth(&d.interface),
                    pattern: &d.pattern,
                    radii: d.pattern.column_radii(),
                    ink_albedo: d.ink_albedo.clone(),
                },
                _ => Face::Other,
            })
            .collect();
        let walkable = |m: usize| {
            let solid = convex_solid(scene, convex, m as MediumId)?;
            let clear = solid.clear_of_target && !scene.media[m].scattering.scatters();
            (clear && !bodies.any_in(m as MediumId)).then_some(solid)
        };
        let solids: Vec<_> = (0..scene.media.len()).map(walkable).collect();
        let runs = solids
            .iter()
            .enumerate()
            .map(|(m, s)| TirRun::of(scene, (*s)?, m as MediumId))
            .collect();
        Walks {
            faces,
            solids,
            runs,
        }
    }

    /// The solid to walk in medium `m`, if any.
    pub(super) fn solid(&self, m: MediumId) -> Option<&'a ConvexSolid> {
        self.solids[m as usize]
    }
}

impl Tracer<'_> {
    /// Follow `p` from face to face of `solid` until it leaves the solid's medium
    /// (`None`, `p` set up to go on in the general loop) or meets its fate, counting
    /// events in `events` as the general loop does.
    pub(super) fn walk_solid(
        &self,
        solid: &ConvexSolid,
        p: &mut Photon,
        rng: &mut PhotonRng,
        out: &mut ChunkTally,
        events: &mut u32,
    ) -> Option<Fate> {
        let scene = self.scene;
        let (medium, absorption) = (p.medium, scene.media[p.medium as usize].absorption(p.light));
        let mut ray = p.ray.true_ray();
        let run = self.walks.runs[medium as usize].as_ref();
        while *events < scene.max_bounces {
            if let Some(run) = run {
                self.take_run(run, p, &mut ray, (medium, absorption), out, events);
            }
            *events += 1;
            let exit = solid.exit(&scene.mesh, &ray);
            let t = exit.map_or(f64::INFINITY, |h| h.t);
            let sink = &mut out.ledger.absorbed_in_medium[medium as usize];
            if absorb_clear(p, absorption, t, self.estimator, rng, sink) {
                return Some(Fate::AbsorbedInMedium(medium));
            }
            p.crossed(medium, t, scene, self.estimator);
            let Some(h) = exit else {
                return Some(Fate::Escaped);
            };
            let facet = &self.facets[h.prim as usize];
            let tag = facet.tag;
            let surf = SurfaceHit {
                t: h.t,
                prim: h.prim,
                point: ray.at(h.t),
                normal: facet.normal,
            };
            let metered = self.luminance == Some(LuminanceEstimator::Meter);
            // The state before the event, which the meter's peel-off reads.
            let pol_before = if metered { p.pol } else { None };
            let (light, before) = (p.light, p.weight);
            let (outcome, feature, shift) =
                self.face_step(tag, &surf, (ray.dir, medium, light), &mut p.pol, rng);
            out.ledger.hit(tag, feature != Feature::Plain);
            if metered {
                let model = &scene.surfaces[tag as usize];
                let event = (before, feature);
                self.walk_event(
                    p,
                    (model, tag),
                    &surf,
                    (ray.dir, medium, pol_before),
                    event,
                    &outcome,
                    out,
                );
            }
            let Outcome::Scattered {
                dir,
                medium: next,
                weight,
            } = outcome
            else {
                return Some(Fate::AbsorbedBySurface(tag));
            };
            p.reweigh(weight, &mut out.ledger.absorbed_by_surface[tag as usize]);
            let model = &scene.surfaces[tag as usize];
            p.scattered_by(model, feature, scene, self.estimator);
            let from = surf.point + shift;
            ray = Ray::new(from, dir);
            if !roulette(p, rng, &mut out.ledger) {
                return Some(Fate::Roulette);
            }
            if next != medium {
                p.ray = SpawnedRay::leaving(from, surf.normal, dir, scene.spawn_eps);
                p.medium = next;
                return None;
            }
        }
        None
    }

    /// The periods of total reflection `p` (on `ray`, in medium `medium` absorbing
    /// `absorption` per mm) can take at once ([`TirRun::skip`]), booked as the walk
    /// would: an event and a plain hit per reflection, the path's absorption spent
    /// (analog: its optical depth; weighted: its weight, the loss booked to the medium).
    #[inline]
    fn take_run(
        &self,
        run: &TirRun,
        p: &mut Photon,
        ray: &mut Ray,
        (medium, absorption): (MediumId, f64),
        out: &mut ChunkTally,
        events: &mut u32,
    ) {
        let reach = match (self.estimator, absorption) {
            (_, 0.0) => f64::INFINITY,
            // The depth is drawn on the first absorbing step: none yet, no run.
            (Estimator::Analog, a) if p.absorption_depth < 0.0 => -a,
            (Estimator::Analog, a) => p.absorption_depth / a,
            // Weighted: the path before the weight falls to the roulette's threshold.
            (Estimator::Weighted, a) => (p.weight / ROULETTE_BELOW).ln() / a,
        };
        let left = self.scene.max_bounces - *events;
        let dir = ray.dir;
        let Some(s) = run.skip(ray, p.light, reach, left) else {
            return;
        };
        if let Some(pol) = &mut p.pol {
            run.retard(pol, dir, &s, p.light);
        }
        self.meter_run(p, run, &s);
        if p.secondaries.live() {
            if run.dispersive() {
                p.secondaries.end();
            }
            p.crossed(medium, s.length, self.scene, self.estimator);
        }
        *events += s.events();
        out.ledger.plain_hits(run.plain_tag, s.plain_hits().into());
        out.ledger.plain_hits(run.dotted_tag, s.periods.into());
        if absorption != 0.0 {
            match self.estimator {
                Estimator::Analog => p.absorption_depth -= absorption * s.length,
                Estimator::Weighted => {
                    // One booking for the run: the walk's per-step bookings telescope to
                    // the same first and last weight.
                    let sink = &mut out.ledger.absorbed_in_medium[medium as usize];
                    p.reweigh((-absorption * s.length).exp(), sink);
                }
            }
        }
    }

    /// The face of tag `tag` met at `surf` along `dir` by a photon in `medium`: what
    /// [`SurfaceModel::interact_on`] does (and returns), the guide's two faces taken
    /// directly.
    /// `pol`, the photon's polarization when it is traced, becomes the light's that leaves;
    /// the offset returned moves where it leaves from (`Arrival::shift_out`).
    fn face_step(
        &self,
        tag: u32,
        surf: &SurfaceHit,
        (dir, medium, light): (DVec3, MediumId, Light),
        pol: &mut Option<Polarization>,
        rng: &mut PhotonRng,
    ) -> (Outcome, Feature, DVec3) {
        // As interact_on and dielectric::scatter decide it (NaN counts as leaving).
        let entering = dir.dot(surf.normal) < 0.0;
        match &self.walks.faces[tag as usize] {
            Face::Smooth(s) if !entering => (
                s.leave(surf.normal, dir, light, pol, rng),
                Feature::Plain,
                DVec3::ZERO,
            ),
            Face::Dotted {
                smooth,
                pattern,
                radii,
                ink_albedo,
            } if !entering => {
                let ink_met = match radii {
                    Some(r) => pattern.covers_tabled(surf.point, r),
                    None => pattern.meets_ink(surf.point, rng),
                };
                if ink_met {
                    let albedo = ink_albedo.at(light);
                    let outcome = ink(albedo, -surf.normal, medium, self.estimator, rng);
                    carry(pol, &outcome, None);
                    return (outcome, Feature::Ink, DVec3::ZERO);
                }
                (
                    smooth.leave(surf.normal, dir, light, pol, rng),
                    Feature::Plain,
                    DVec3::ZERO,
                )
            }
            _ => {
                let (pol_out, shift_out) = (Cell::new(None), Cell::new(DVec3::ZERO));
                let at = Arrival {
                    media: &self.scene.media,
                    hit: surf,
                    dir,
                    medium,
                    est: self.estimator,
                    light,
                    pol: *pol,
                    pol_out: &pol_out,
                    shift_out: &shift_out,
                };
                // No back to choose: a solid's faces are interfaces, which have none
                // (`optics::two_sided`).
                let (outcome, feature) = self.scene.surfaces[tag as usize].interact_on(&at, rng);
                carry(pol, &outcome, pol_out.get());
                (outcome, feature, shift_out.get())
            }
        }
    }
}

/// The polarization `pol` (when traced) of light scattered as `outcome`: `kept`, the
/// state a model gave it, or unpolarized (as the general loop sets it).
fn carry(pol: &mut Option<Polarization>, outcome: &Outcome, kept: Option<Polarization>) {
    if let (Some(p), Outcome::Scattered { dir, .. }) = (pol.as_mut(), outcome) {
        *p = kept.unwrap_or(Polarization::unpolarized(*dir));
    }
}

impl Smooth {
    /// `optics::dielectric::scatter` for a photon leaving through the face (`dir` not
    /// against the outward `normal`): Fresnel roulette from inside to outside.
    // Always inlined: see the module header (store forwarding).
    #[inline(always)]
    fn leave(
        &self,
        normal: DVec3,
        dir: DVec3,
        light: Light,
        pol: &mut Option<Polarization>,
        rng: &mut PhotonRng,
    ) -> Outcome {
        let facing = -normal;
        let (n1, n2) = (self.n_inside.at(light), self.n_outside.at(light));
        let (dir, medium) = match fresnel_roulette(dir, facing, (n1, n2), pol.as_mut(), rng) {
            Some(t) => (t, self.iface.outside),
            None => (fresnel::reflect(dir, facing), self.iface.inside),
        };
        Outcome::Scattered {
            dir,
            medium,
            weight: 1.0,
        }
    }
}

/// Ink of albedo `albedo` met from the side `facing` points to: albedo roulette (or
/// weight), then a Lambertian direction back into `medium`.
// Always inlined, as `Smooth::leave` is: its direction goes straight into the next ray.
#[inline(always)]
fn ink(
    albedo: f64,
    facing: DVec3,
    medium: MediumId,
    estimator: Estimator,
    rng: &mut PhotonRng,
) -> Outcome {
    match estimator.survive(albedo, rng) {
        Some(weight) => Outcome::Scattered {
            dir: lambert::direction(facing, rng),
            medium,
            weight,
        },
        None => Outcome::Absorbed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracer::{Tracer, assert_same_chunks};

    /// Chunks traced with the walk and without it (the general loop all the way, on the
    /// same convex path) are the same bits: ledgers and detections. (Runs of total
    /// reflection, which round positions differently, are off: `tir_run` tests them.)
    #[test]
    fn the_walk_is_the_general_loop_bit_for_bit() {
        let no_runs = |t: &mut Tracer| t.walks.runs.iter_mut().for_each(|r| *r = None);
        for name in ["bench-box", "notebook14", "wedge-ccfl"] {
            for estimator in [Estimator::Analog, Estimator::Weighted] {
                let chunks = assert_same_chunks(name, estimator, no_runs, |general| {
                    let walks = &mut general.walks.solids;
                    assert!(walks.iter().any(Option::is_some), "{name}: nothing to walk");
                    walks.iter_mut().for_each(|s| *s = None);
                });
                for c in &chunks {
                    assert!(c.ledger.interactions > 3 * c.ledger.photons, "{name}");
                }
            }
        }
    }

    /// The same under the luminance meter's estimator: the walk calls its hooks at the
    /// same events, so the meter's hits and their causes are the same bits too.
    #[test]
    fn the_walk_peels_off_as_the_general_loop_does() {
        let meter = |t: &mut Tracer| {
            t.walks.runs.iter_mut().for_each(|r| *r = None);
            t.luminance = Some(LuminanceEstimator::Meter);
        };
        for name in ["notebook14", "notebook14-color"] {
            let chunks = assert_same_chunks(name, Estimator::Analog, meter, |general| {
                general.walks.solids.iter_mut().for_each(|s| *s = None);
            });
            assert!(chunks.iter().all(|c| c.meter.len() > 1000), "{name}");
        }
    }

    /// The same with polarization traced: the walk carries the state exactly as the
    /// general loop does (Stokes vectors of every detection equal too; runs off, as above).
    #[test]
    fn the_polarized_walk_is_the_general_loop_bit_for_bit() {
        for name in ["bench-box", "notebook14"] {
            let mut scene = crate::tracer::bundled(name);
            scene.polarized = true;
            let no_runs = |t: &mut Tracer| t.walks.runs.iter_mut().for_each(|r| *r = None);
            let chunks = crate::tracer::assert_same_chunks_of(
                &scene,
                Estimator::Analog,
                no_runs,
                |general| general.walks.solids.iter_mut().for_each(|s| *s = None),
            );
            assert!(chunks.iter().all(|c| c.stokes.len() == c.detections.len()));
            assert!(chunks.iter().any(|c| c.stokes.iter().any(|s| s[0] != 0.0)));
        }
    }
}
