//! Runs of total internal reflection across a box guide: many of a photon's events in one
//! step, where nothing random can happen.
//!
//! Most of a photon's events in an edge-lit guide are total internal reflections between
//! its plain face and its dotted face (on `scenes/bench-box`, 12 of 13.5). A photon moving
//! towards the plain face at a cosine that both faces reflect totally (no draw: the cosine
//! alone decides) comes back to the dotted face with its direction unchanged, one
//! period `2 thick / cos` further along; it lands at path lengths `first + 2 j h`
//! (`h = thick / cos`) until a landing falls in a dot, a side face comes first, the
//! optical depth it has left runs out or the bounce cap nears. Each of those landings
//! asks only "in a dot?", and the questions do not depend on each other, so they are
//! asked back to back here instead of one per link of the walk's chain of positions.
//! Measured (single-thread CPU time, interleaved rounds, the same flux maps): bench-box
//! 1.11x with the walk's ink test, 1.20x with `DotPattern::first_covered`'s; about half of
//! its photons' events are taken in runs.
//!
//! The run takes only the periods whose every step the walk would take without a random
//! number: both reflections total, the landing out of the ink, the absorption not
//! reaching the photon's optical depth (analog) or its weight not falling to the
//! roulette's threshold (weighted), with a margin of one period, and the bounce cap not
//! reached (margin of two events). The period that ends it, and everything after, is
//! the walk's, so the physics and the random numbers are the walk's; only the rounding of
//! positions (each landing computed from the run's start, not from the landing before)
//! and, under the weighted estimator, of the weight (one attenuation for the run) differ.
//! Taken where the medium's solid is an axis-aligned box whose faces across one axis are
//! a smooth dielectric face and a dotted one with a lattice column table
//! (`placement = "lattice"`, density along the axis), each with one tag, the photon
//! inside both interfaces.
//!
//! ```toml
//! [surfaces.lgp_front]
//! model = "dielectric"
//! [surfaces.lgp_back]
//! model = "dots"        # placement = "lattice" (the default), density along the axis
//! ```

use crate::accel::convex::ConvexSolid;
use crate::geometry::Ray;
use crate::optics::dot_placement::ColumnRadii;
use crate::optics::dots::DotPattern;
use crate::optics::fresnel;
use crate::optics::medium::{Interface, MediumId};
use crate::optics::polarization::{self, Polarization, Stokes};
use crate::optics::spectrum::{Light, Spectral};
use crate::optics::surface::SurfaceModel;
use crate::scene::Scene;
use glam::DVec3;

/// A box guide's two faces across its thickness axis, as a run reads them.
#[derive(Clone, Debug)]
pub(super) struct TirRun<'a> {
    /// The thickness axis.
    k: usize,
    /// +1 when the plain face is the high one along `k`, else -1.
    plain_sign: f64,
    /// The plain and the dotted face's coordinate along `k`.
    plain_at: f64,
    dotted_at: f64,
    /// Their distance.
    thick: f64,
    /// The box's corners (the side faces bound a run).
    lo: DVec3,
    hi: DVec3,
    /// The faces' tags.
    pub(super) plain_tag: u32,
    pub(super) dotted_tag: u32,
    /// Refractive indices inside and outside the plain and the dotted face.
    plain_n: [Spectral; 2],
    dotted_n: [Spectral; 2],
    pattern: &'a DotPattern,
    radii: ColumnRadii,
}

/// What a run skips: whole periods (a reflection at each face), then, when the next
/// landing is in a dot, the reflection at the plain face before it; and the path length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Skipped {
    pub(super) periods: u32,
    pub(super) to_ink: bool,
    pub(super) length: f64,
}

impl TirRun<'_> {
    /// The unit thickness axis: the faces' normal (up to sign).
    pub(super) fn axis(&self) -> DVec3 {
        let mut a = DVec3::ZERO;
        a[self.k] = 1.0;
        a
    }
}

impl Skipped {
    /// Reflections at the plain face.
    pub(super) fn plain_hits(&self) -> u32 {
        self.periods + u32::from(self.to_ink)
    }

    /// Events: every reflection.
    pub(super) fn events(&self) -> u32 {
        2 * self.periods + u32::from(self.to_ink)
    }
}

impl<'a> TirRun<'a> {
    /// The polarization `pol` of light along unit `dir` (before the run) after the run
    /// `s`: each total reflection retards p against s by the same angle at its face, and
    /// every reflection's s direction is `dir x axis` (up to sign, which a Stokes frame
    /// does not see), so the run turns `(S2, S3)` by the sum of its reflections' angles.
    pub(super) fn retard(&self, pol: &mut Polarization, dir: DVec3, s: &Skipped, light: Light) {
        let axis = DVec3::AXES[self.k];
        let frame = polarization::s_axis(dir, axis, pol.u);
        let cos = dir[self.k].abs();
        let angle = |n: &[Spectral; 2]| {
            let m = polarization::fresnel_reflection(cos, n[0].at(light), n[1].at(light)).0;
            m[2][3].atan2(m[2][2])
        };
        let turn = f64::from(s.plain_hits()) * angle(&self.plain_n)
            + f64::from(s.periods) * angle(&self.dotted_n);
        let [s0, s1, s2, s3] = pol.stokes_in(dir, frame).0;
        let (sin, cos) = turn.sin_cos();
        pol.stokes = Stokes([s0, s1, cos * s2 + sin * s3, cos * s3 - sin * s2]);
        pol.u = frame;
    }

    /// The run of `solid`, the solid of medium `medium` in `scene`, when it has one.
    pub(super) fn of(scene: &'a Scene, solid: &ConvexSolid, medium: MediumId) -> Option<Self> {
        let b = solid.axis_faces()?;
        (0..3).find_map(|k| {
            let (lo, hi) = (b.lo_face[k]?, b.hi_face[k]?);
            let exact = |(_, n): (u32, DVec3)| n.abs() == DVec3::AXES[k];
            if !(exact(lo) && exact(hi)) {
                return None;
            }
            let tag = |(prim, _): (u32, DVec3)| scene.mesh.tri_tag[prim as usize];
            let model = |f| &scene.surfaces[tag(f) as usize];
            let (plain, dotted, plain_sign) = match (model(lo), model(hi)) {
                (SurfaceModel::Dielectric(_), SurfaceModel::Dots(_)) => (lo, hi, -1.0),
                (SurfaceModel::Dots(_), SurfaceModel::Dielectric(_)) => (hi, lo, 1.0),
                _ => return None,
            };
            let (SurfaceModel::Dielectric(plain_iface), SurfaceModel::Dots(dots)) =
                (model(plain), model(dotted))
            else {
                return None;
            };
            let inside = plain_iface.inside == medium && dots.interface.inside == medium;
            let radii = dots.pattern.column_radii().filter(|_| inside)?;
            let n =
                |i: &Interface| [i.inside, i.outside].map(|m| scene.media[m as usize].n.clone());
            let at = |f: (u32, DVec3)| if f == lo { b.lo[k] } else { b.hi[k] };
            Some(TirRun {
                k,
                plain_sign,
                plain_at: at(plain),
                dotted_at: at(dotted),
                thick: b.hi[k] - b.lo[k],
                lo: b.lo,
                hi: b.hi,
                plain_tag: tag(plain),
                dotted_tag: tag(dotted),
                plain_n: n(plain_iface),
                dotted_n: n(&dots.interface),
                pattern: &dots.pattern,
                radii,
            })
        })
    }

    /// Move `ray` (a photon of light `light` inside the guide) over the whole periods it
    /// can take without a random number, to its last landing on the dotted face, leaving
    /// its direction as it is; or, when a landing within them is in a dot, to the plain
    /// face before that landing, reflected towards it. `reach`: the path length the
    /// photon may travel before its absorption depth is spent (or its weight falls to the
    /// roulette's threshold); `events_left`: events before the bounce cap. `None` when no
    /// period is taken (the ray is unchanged).
    #[inline]
    pub(super) fn skip(
        &self,
        ray: &mut Ray,
        light: Light,
        reach: f64,
        events_left: u32,
    ) -> Option<Skipped> {
        let (o, d, k) = (ray.origin.to_array(), ray.dir.to_array(), self.k);
        if d[k] * self.plain_sign <= 0.0 || !self.reflects(d[k].abs(), light) {
            return None;
        }
        let h = self.thick / d[k].abs();
        let first = (self.plain_at - o[k]) / d[k] + h;
        // Landings must come before a side face and leave a period of depth to spare.
        let limit = self.side_distance(&o, &d).min(reach - 2.0 * h);
        let periods_by_events = events_left.saturating_sub(2) / 2;
        // (A NaN limit takes no period either.)
        let room = first < limit;
        if !room || periods_by_events == 0 {
            return None;
        }
        // Landing j (from 0) lies at first + 2 j h < limit.
        let by_length = ((limit - first) / (2.0 * h)).min(f64::from(u32::MAX - 1)) as u32 + 1;
        let most = by_length.min(periods_by_events);
        let landing = |j: u32| first + 2.0 * h * f64::from(j);
        // The division may round the count one too high.
        let most = if landing(most - 1) < limit {
            most
        } else {
            most - 1
        };
        let mut start = ray.at(first);
        start[k] = self.dotted_at;
        let mut step = ray.dir * (2.0 * h);
        step[k] = 0.0;
        let j = self.pattern.first_covered(start, step, most, &self.radii);
        if j < most {
            // Landing j is in a dot: take the reflection at the plain face before it too,
            // and leave the photon on its way to the dot.
            let length = landing(j) - h;
            ray.origin = ray.at(length);
            ray.origin[k] = self.plain_at;
            ray.dir[k] = -ray.dir[k];
            return Some(Skipped {
                periods: j,
                to_ink: true,
                length,
            });
        }
        if j == 0 {
            return None;
        }
        let length = landing(j - 1);
        ray.origin = ray.at(length);
        ray.origin[k] = self.dotted_at;
        Some(Skipped {
            periods: j,
            to_ink: false,
            length,
        })
    }

    /// Whether an index either side of a face varies with wavelength (then total
    /// reflection does too: a photon's secondary wavelengths end at a run).
    pub(super) fn dispersive(&self) -> bool {
        self.plain_n
            .iter()
            .chain(&self.dotted_n)
            .any(Spectral::is_spectral)
    }

    /// Both faces reflect totally at incidence cosine `cos` (`fresnel::roulette`'s test).
    fn reflects(&self, cos: f64, light: Light) -> bool {
        let tir = |[n1, n2]: &[Spectral; 2]| {
            fresnel::cos_transmitted(cos, n1.at(light), n2.at(light)).is_none()
        };
        tir(&self.plain_n) && tir(&self.dotted_n)
    }

    /// The distance along `d` from `o` to the nearest side face (the faces along the two
    /// axes other than the thickness).
    fn side_distance(&self, o: &[f64; 3], d: &[f64; 3]) -> f64 {
        let (lo, hi) = (self.lo.to_array(), self.hi.to_array());
        let mut t = f64::INFINITY;
        for a in (0..3).filter(|&a| a != self.k) {
            if d[a] > 0.0 {
                t = t.min((hi[a] - o[a]) / d[a]);
            } else if d[a] < 0.0 {
                t = t.min((lo[a] - o[a]) / d[a]);
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::surface::Estimator;
    use crate::rng::PhotonRng;
    use crate::tally::{ChunkTally, ExactSum, Ledger};
    use crate::tracer::{Tracer, assert_same_chunks};

    fn scene(name: &str) -> Scene {
        let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
        Scene::load(&root.join("scenes").join(name).join("scene.toml")).unwrap()
    }

    /// The guide of `scene` (the medium with a run) and its run.
    fn guide(scene: &Scene) -> (&ConvexSolid, TirRun<'_>) {
        (0..scene.media.len() as MediumId)
            .find_map(|m| {
                let solid = scene.convex_solid(m)?;
                Some((solid, TirRun::of(scene, solid, m)?))
            })
            .expect("a box guide with a run")
    }

    /// Where the walk's own machinery (the solid's exit, the faces' tags, total reflection
    /// by `fresnel::cos_transmitted`, the ink test) takes `ray` in one step, if it meets
    /// the face of `tag` and reflects there without a random number (and the path length):
    /// `Err(true)` when it lands in a dot, `Err(false)` when another face, or refraction,
    /// comes first.
    fn walk_step(
        scene: &Scene,
        solid: &ConvexSolid,
        run: &TirRun,
        ray: &Ray,
        tag: u32,
    ) -> Result<(Ray, f64), bool> {
        let h = solid.exit(&scene.mesh, ray).unwrap();
        let normal = scene.mesh.normal(h.prim);
        let point = ray.at(h.t);
        if scene.mesh.tri_tag[h.prim as usize] != tag {
            return Err(false);
        }
        let n = if tag == run.plain_tag {
            &run.plain_n
        } else {
            &run.dotted_n
        };
        let at = |s: &Spectral| s.at(Light::MONOCHROME);
        if fresnel::cos_transmitted(ray.dir.dot(normal), at(&n[0]), at(&n[1])).is_some() {
            return Err(false);
        }
        if tag == run.dotted_tag && run.pattern.covers_tabled(point, &run.radii) {
            return Err(true);
        }
        Ok((Ray::new(point, fresnel::reflect(ray.dir, normal)), h.t))
    }

    /// [`walk_step`] to the plain face, then to the dotted one.
    fn walk_period(
        scene: &Scene,
        solid: &ConvexSolid,
        run: &TirRun,
        ray: &Ray,
    ) -> Result<(Ray, f64), bool> {
        let (up, t) = walk_step(scene, solid, run, ray, run.plain_tag)?;
        let (down, u) = walk_step(scene, solid, run, &up, run.dotted_tag)?;
        Ok((down, t + u))
    }

    /// A ray from a uniform point of the guide's dotted face, or of its inside, in a
    /// uniform direction.
    fn random_ray(run: &TirRun, rng: &mut PhotonRng) -> Ray {
        let mut o =
            run.lo + (run.hi - run.lo) * DVec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        if rng.uniform() < 0.5 {
            o[run.k] = run.dotted_at;
        }
        let d = crate::optics::sampling::around(DVec3::Z, 2.0 * rng.uniform() - 1.0, rng.uniform());
        Ray::new(o, d)
    }

    /// On bench-box and notebook14, every reflection a run takes is one the walk takes
    /// without a random number, the run ends where the walk would be (to 1e-9 mm, the same
    /// direction), and it stops only where the walk's next step lands in a dot or its next
    /// period meets a side face or refraction: the run neither skips a dot nor stops short.
    #[test]
    fn a_run_takes_the_walks_periods_and_no_more() {
        for name in ["bench-box", "notebook14"] {
            let scene = scene(name);
            let (solid, run) = guide(&scene);
            let mut rng = PhotonRng::new(3, 0);
            let (mut taken, mut runs, mut in_ink) = (0, 0, 0);
            for _ in 0..20_000 {
                let ray = random_ray(&run, &mut rng);
                let mut skipped = ray;
                let s = run.skip(&mut skipped, Light::MONOCHROME, f64::INFINITY, u32::MAX);
                let (mut walked, mut length) = (ray, 0.0);
                let s = s.map(|s| (s, s.periods));
                for _ in 0..s.map_or(0, |s| s.1) {
                    let period = walk_period(&scene, solid, &run, &walked);
                    let (next, t) = period.expect("a period the walk takes");
                    (walked, length) = (next, length + t);
                }
                let Some((s, _)) = s else {
                    assert_eq!(skipped, ray, "{name}: no run moves nothing");
                    continue;
                };
                if s.to_ink {
                    let step = walk_step(&scene, solid, &run, &walked, run.plain_tag);
                    let (next, t) = step.expect("the reflection before the dot");
                    (walked, length) = (next, length + t);
                }
                assert!(
                    skipped.origin.distance(walked.origin) < 1e-9,
                    "{name}: {skipped:?} {walked:?}"
                );
                assert_eq!(skipped.dir, walked.dir, "{name}");
                assert!((s.length - length).abs() < 1e-9, "{name}");
                // The walk's next step lands in the dot, or its next period is not one a
                // run takes (a side face or refraction).
                let next = match s.to_ink {
                    true => walk_step(&scene, solid, &run, &walked, run.dotted_tag).map(|_| ()),
                    false => walk_period(&scene, solid, &run, &walked).map(|_| ()),
                };
                assert_eq!(next, Err(s.to_ink), "{name}: the run stopped short");
                in_ink += u32::from(s.to_ink);
                (taken, runs) = (taken + s.periods, runs + 1);
            }
            // Not vacuous: many runs, most several periods long, many ending in a dot.
            assert!(
                runs > 2000 && taken > runs && in_ink > runs / 4,
                "{name}: {runs} {taken} {in_ink}"
            );
        }
    }

    /// A run leaves a period of optical depth and two events to spare.
    #[test]
    fn a_run_stops_before_the_depth_and_the_bounce_cap() {
        let scene = scene("bench-box");
        let (_, run) = guide(&scene);
        let mut rng = PhotonRng::new(4, 0);
        for _ in 0..20_000 {
            let ray = random_ray(&run, &mut rng);
            let reach = 200.0 * rng.uniform();
            let events = (rng.uniform() * 12.0) as u32;
            let mut moved = ray;
            if let Some(s) = run.skip(&mut moved, Light::MONOCHROME, reach, events) {
                let h = run.thick / ray.dir[run.k].abs();
                assert!(s.length + 2.0 * h < reach, "{s:?} {reach}");
                assert!(s.events() + 2 <= events, "{s:?} {events}");
            }
        }
        let mut ray = Ray::new(
            (run.lo + run.hi) / 2.0,
            DVec3::new(0.6, 0.0, 0.8 * run.plain_sign),
        );
        ray.origin[run.k] = run.dotted_at;
        assert_eq!(
            run.skip(&mut ray, Light::MONOCHROME, f64::INFINITY, 1000),
            None,
            "refracts"
        );
    }

    /// With polarization traced, runs turn the state as the walk's reflections do, one
    /// by one: the same chunks, every Stokes vector within 1e-9 of the walk's.
    #[test]
    fn polarized_runs_turn_the_state_as_the_walk_does() {
        for name in ["bench-box", "notebook14"] {
            let mut scene = scene(name);
            scene.polarized = true;
            let accel =
                crate::accel::build(crate::accel::BackendChoice::Bvh, scene.mesh.clone()).unwrap();
            let facets = scene.mesh.facets();
            let runs = Tracer::new(&scene, accel.as_ref(), Estimator::Analog, true, &facets);
            assert!(
                runs.walks.runs.iter().any(Option::is_some),
                "{name}: no run"
            );
            let mut stepwise =
                Tracer::new(&scene, accel.as_ref(), Estimator::Analog, true, &facets);
            stepwise.walks.runs.iter_mut().for_each(|r| *r = None);
            for c in [0, 7] {
                let [a, b] = [&runs, &stepwise].map(|t| t.trace_chunk(5, c, u64::MAX));
                assert_eq!(a.ledger, b.ledger, "{name} chunk {c}");
                assert_eq!(a.detections, b.detections, "{name} chunk {c}");
                for (x, y) in a.stokes.iter().zip(&b.stokes) {
                    assert!((0..3).all(|k| (x[k] - y[k]).abs() < 1e-9), "{x:?} {y:?}");
                }
                assert!(a.stokes.iter().any(|x| x[2] != 0.0 || x[1] != 0.0));
            }
        }
    }

    /// Traced chunks are the walk's with runs and without: the same fates, interactions,
    /// hits per tag and detections. The runs round positions differently (each landing
    /// from the run's start), by about 1e-13 mm, so a fate could differ only for a landing
    /// that close to a dot's edge; none of these photons has one.
    #[test]
    fn runs_give_the_walks_chunks() {
        for name in ["bench-box", "notebook14"] {
            assert_same_chunks(
                name,
                Estimator::Analog,
                |_| {},
                |stepwise: &mut Tracer| {
                    let runs = &mut stepwise.walks.runs;
                    assert!(runs.iter().any(Option::is_some), "{name}: no run");
                    runs.iter_mut().for_each(|r| *r = None);
                },
            );
        }
    }

    /// Chunks 0 and 7 (seed 5) of bundled scene `name` under the weighted estimator, with
    /// runs and without.
    fn weighted_chunks(name: &str) -> [[ChunkTally; 2]; 2] {
        let scene = scene(name);
        let accel =
            crate::accel::build(crate::accel::BackendChoice::Bvh, scene.mesh.clone()).unwrap();
        let facets = scene.mesh.facets();
        let runs = Tracer::new(&scene, accel.as_ref(), Estimator::Weighted, true, &facets);
        let mut stepwise = Tracer::new(&scene, accel.as_ref(), Estimator::Weighted, true, &facets);
        stepwise.walks.runs.iter_mut().for_each(|r| *r = None);
        [0, 7].map(|c| [&runs, &stepwise].map(|t| t.trace_chunk(5, c, u64::MAX)))
    }

    /// Under the weighted estimator a run books a whole run's absorption at once, where
    /// the walk books it step by step (the same first and last weight), so weights round
    /// differently: the same counts, bins and fates, every sum within 1e-9 of the walk's,
    /// every detection's weight within 1e-8 of it. (Positions round differently too, by
    /// about 1e-11 mm after a run of 30 periods; round lamp tubes and reflectors can grow
    /// that to 1e-7 mm in a photon's excursion into a lamp cavity, and a grazing path of
    /// hundreds of mm after it changes the weight's attenuation by about 5e-10, as seen
    /// on notebook14 with runs through side faces, which were dropped.)
    #[test]
    fn weighted_runs_give_the_walks_chunks_to_rounding() {
        for name in ["bench-box", "notebook14"] {
            for [a, b] in weighted_chunks(name) {
                let (x, y) = (&a.ledger, &b.ledger);
                let counts = |l: &Ledger| {
                    let tags = (l.hits_by_tag.clone(), l.feature_hits_by_tag.clone());
                    (l.photons, l.interactions, l.killed_photons, tags)
                };
                assert_eq!(counts(x), counts(y), "{name}");
                let sums = |l: &Ledger| {
                    let fates = [l.emitted, l.escaped, l.killed, l.roulette, l.detected.sum];
                    let lists = [
                        &l.absorbed_by_surface,
                        &l.absorbed_in_medium,
                        &l.absorbed_by_source,
                    ];
                    let all = fates
                        .into_iter()
                        .chain(lists.into_iter().flatten().copied());
                    all.map(ExactSum::value).collect::<Vec<_>>()
                };
                for (u, v) in sums(x).into_iter().zip(sums(y)) {
                    assert!((u - v).abs() < 1e-9, "{name}: {u} {v}");
                }
                let medium: f64 = x.absorbed_in_medium.iter().map(|s| s.value()).sum();
                assert!(
                    medium > 1e-3,
                    "{name}: the runs' absorption is booked: {medium}"
                );
                assert_eq!(a.detections.len(), b.detections.len(), "{name}");
                for (d, e) in a.detections.iter().zip(&b.detections) {
                    assert_eq!((d.flux_bin, d.angular_bin), (e.flux_bin, e.angular_bin));
                    let relative = (d.weight - e.weight).abs() / e.weight;
                    assert!(relative < 1e-8, "{name}: {} {}", d.weight, e.weight);
                }
            }
        }
    }

    /// No run on a guide whose faces it cannot take: a wedge, and a stochastic screen
    /// (whose ink test draws random numbers).
    #[test]
    fn no_run_where_a_period_is_not_deterministic() {
        let wedge = scene("wedge-ccfl");
        let runs = (0..wedge.media.len() as MediumId)
            .filter_map(|m| TirRun::of(&wedge, wedge.convex_solid(m)?, m));
        assert_eq!(runs.count(), 0);
        let mut box_scene = scene("bench-box");
        for model in &mut box_scene.surfaces {
            if let SurfaceModel::Dots(d) = model {
                d.pattern.placement = crate::optics::dots::Placement::Stochastic;
            }
        }
        let solid = box_scene.convex_solid(1).unwrap().clone();
        assert!(TirRun::of(&box_scene, &solid, 1).is_none());
    }
}
