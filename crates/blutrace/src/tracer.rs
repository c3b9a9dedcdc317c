//! The photon loop (paper section 3), traced in fixed chunks of photons (the rounds that
//! run them in parallel are `run::rounds`).
//!
//! ```toml
//! [trace]
//! photons = 400000       # default photon count (CLI --photons overrides)
//! seed = 1               # default seed (CLI --seed overrides)
//! max_bounces = 100000   # events before a photon is killed (counted, not silent)
//! ```
//!
//! Each photon is traced along straight segments to the nearest surface, where its
//! surface model decides by Russian roulette to reflect, transmit or absorb it; inside a
//! scattering medium a segment may end earlier in a scattering event (`flight`). Both
//! kinds of event count as interactions and towards `max_bounces`. It ends in
//! exactly one fate: detected, absorbed (by a named surface or medium), escaped, killed
//! by the bounce cap, or (weighted estimator only) ended by Russian roulette. Work is split
//! into fixed chunks of photon indices; tallies are exact integer sums, so the result does
//! not depend on the thread count.

mod body_boxes;
mod flight;
mod meter;
mod meter_walk;
mod solid_walk;
mod spectral;
mod tir_run;

use crate::accel::Accel;
use crate::accel::convex::ConvexSolid;
use crate::estimator::LuminanceEstimator;
use crate::geometry::{Facet, Ray, SpawnedRay, SurfaceHit};
use crate::optics::absorber::Absorber;
use crate::optics::model::Arrival;
use crate::optics::polarization::Polarization;
use crate::optics::spectrum::{Light, Secondaries};
use crate::optics::surface::{Estimator, Feature, MediumId, Outcome, SurfaceModel};
use crate::optics::two_sided;
use crate::rng::PhotonRng;
use crate::scene::Scene;
use crate::sources::body::LampBody;
use crate::tally::meter::Cause;
use crate::tally::meter::PeelWalks;
use crate::tally::{ChunkTally, Detection, ExactSum, Fate, Ledger, MeterHit};
use body_boxes::BodyBoxes;
use flight::Flight;
use solid_walk::Walks;
use std::cell::Cell;

/// The convex solid of `medium` when the convex path is on and the medium has one.
fn convex_solid(scene: &Scene, convex: bool, medium: MediumId) -> Option<&ConvexSolid> {
    scene.convex_solid(medium).filter(|_| convex)
}

/// Photons per work unit. Fixed, so results never depend on scheduling.
pub const CHUNK: u64 = 4096;

/// Weighted estimator: below this weight a photon plays Russian roulette...
const ROULETTE_BELOW: f64 = 0.1;
/// ...and survives with probability `w / ROULETTE_SURVIVOR`, then carries this weight.
const ROULETTE_SURVIVOR: f64 = 0.5;

/// Traces photons of one scene through one backend (built by [`Tracer::new`], which
/// derives the walks from the other fields, so they are fixed after it).
pub struct Tracer<'a> {
    /// The scene.
    scene: &'a Scene,
    /// The intersection backend.
    accel: &'a dyn Accel,
    /// How absorption is sampled.
    estimator: Estimator,
    /// Use the convex-solid fast path inside convex media.
    convex: bool,
    /// Every triangle of the scene's mesh as a hit on it reads it
    /// ([`crate::geometry::Mesh::facets`]).
    facets: &'a [Facet],
    /// Where photons go face to face inside a convex solid ([`solid_walk`]).
    walks: Walks<'a>,
    /// The lamp bodies of each medium and their boxes ([`body_boxes`]).
    bodies: BodyBoxes,
    /// How the luminance maps are estimated ([`meter`]); `None`: the scene has none.
    luminance: Option<LuminanceEstimator>,
    /// Which wavelengths photons of spectral sources carry ([`spectral`]).
    wavelengths: spectral::Carried,
    /// How the meter peels off ([`meter::Walk`]).
    walk: meter::Walk,
}

/// A photon in flight.
struct Photon {
    /// Where it is and where it goes (nudged off the surface it last left).
    ray: SpawnedRay,
    medium: MediumId,
    weight: f64,
    /// Its light, drawn with its emission: what it meets is read at it (the hero)...
    light: Light,
    /// ...and the other wavelengths it carries along ([`spectral`]).
    secondaries: Secondaries,
    /// Its polarization, when the scene traces it.
    pol: Option<Polarization>,
    /// Analog estimator: the optical depth of clear-medium absorption the photon has
    /// left (an Exp(1) draw, made on its first absorbing segment; negative until then).
    absorption_depth: f64,
    /// Whether the luminance meter's peel-off at its last diffuse event scored its light
    /// ([`meter`]): then its crossing of the target is not counted in the cone again.
    covered: bool,
    /// The `n t` it left its last diffuse event with ([`meter`]).
    left_with: glam::DVec3,
    /// Why no peel-off covers its light ([`crate::tally::meter::MeterTally::counted`]'s
    /// index), when `covered` is false.
    cause: u32,
    /// The last place since its diffuse event that turned its `n t` (`u32::MAX`: none).
    turned: u32,
    /// The stream its peel-offs draw from, under the meter estimator.
    peel_rng: Option<PhotonRng>,
}

impl Photon {
    /// Scale the weight by `factor` (a surface's albedo under the weighted estimator),
    /// booking the loss to `sink`.
    fn reweigh(&mut self, factor: f64, sink: &mut ExactSum) {
        let w = self.weight * factor;
        Ledger::lose(sink, self.weight, w);
        self.weight = w;
    }
}

impl<'a> Tracer<'a> {
    /// A tracer of `scene` through `accel`, with the mesh's `facets`
    /// ([`crate::geometry::Mesh::facets`]); `convex` turns the convex-solid fast path on.
    pub fn new(
        scene: &'a Scene,
        accel: &'a dyn Accel,
        estimator: Estimator,
        convex: bool,
        facets: &'a [Facet],
    ) -> Tracer<'a> {
        let bodies = BodyBoxes::new(scene);
        Tracer {
            scene,
            accel,
            estimator,
            convex,
            facets,
            walks: Walks::new(scene, convex, &bodies),
            bodies,
            luminance: scene.luminous().then_some(LuminanceEstimator::Cone),
            wavelengths: spectral::Carried::Hero,
            walk: meter::Walk::of(scene),
        }
    }

    /// Estimate the luminance maps with `e` (a tracer as built counts the cone), when the
    /// scene has them.
    pub fn luminance_estimator(mut self, e: LuminanceEstimator) -> Self {
        if self.luminance.is_some() {
            self.luminance = Some(e);
        }
        self
    }

    /// Follow photon `index` of the run seeded `seed` to its fate, scoring into `out`.
    fn trace_photon(&self, seed: u64, index: u64, out: &mut ChunkTally) {
        let mut rng = PhotonRng::new(seed, index);
        let e = self.scene.sources.sample(&mut rng);
        let (light, secondaries) = self.wavelengths.of(&e, self.scene);
        let mut p = Photon {
            ray: SpawnedRay::leaving(e.ray.origin, e.normal, e.ray.dir, self.scene.spawn_eps),
            medium: e.medium,
            weight: 1.0,
            light,
            secondaries,
            pol: self
                .scene
                .polarized
                .then(|| emitted_polarization(self.scene, &e)),
            absorption_depth: -1.0,
            covered: false,
            left_with: glam::DVec3::ZERO,
            cause: Cause::Emission.index(self.places()),
            turned: u32::MAX,
            peel_rng: (self.luminance == Some(LuminanceEstimator::Meter))
                .then(|| PhotonRng::side_stream(seed, index)),
        };
        out.ledger.photons += 1;
        out.ledger.emitted.add(1.0);
        let from = out.meter.len();
        let fate = self.follow(&mut p, &mut rng, out);
        out.ledger.end(fate, p.weight, e.source);
        crate::tally::meter::merge_photon_hits(&mut out.meter, from);
    }

    /// The photon loop: nearest event, the medium on the way, surface roulette, repeat;
    /// inside a walkable convex solid, face to face ([`solid_walk`]).
    fn follow(&self, p: &mut Photon, rng: &mut PhotonRng, out: &mut ChunkTally) -> Fate {
        let scene = self.scene;
        let mut events = 0;
        while events < scene.max_bounces {
            if let Some(solid) = self.walks.solid(p.medium) {
                match self.walk_solid(solid, p, rng, out, &mut events) {
                    Some(fate) => return fate,
                    None => continue,
                }
            }
            events += 1;
            let true_ray = p.ray.true_ray();
            let surf = self.nearest_surface(p, &true_ray);
            let t_surface = surf.map_or(f64::INFINITY, |h| h.surf.t);
            let detected = self.target_hit(p, &true_ray, t_surface);
            let t_next = detected.map_or(t_surface, |(t, _)| t);
            match self.cross_medium(p, &true_ray, t_next, rng, &mut out.ledger) {
                Flight::Absorbed => return Fate::AbsorbedInMedium(p.medium),
                Flight::Scattered { .. } => {
                    out.ledger.interactions += 1;
                    p.covered = false;
                    p.cause = Cause::Volume.index(self.places());
                    if !roulette(p, rng, &mut out.ledger) {
                        return Fate::Roulette;
                    }
                    continue;
                }
                Flight::Reached => {}
            }
            if let Some((_, ab)) = detected {
                if let Some(pol) = p.pol {
                    let passed = scene.detector.analyzer_transmittance(&pol, true_ray.dir);
                    p.reweigh(passed, &mut out.ledger.absorbed_by_analyzer);
                    out.stokes
                        .push(scene.detector.stokes_of(&pol, true_ray.dir));
                }
                let weight = p.light.detected(p.weight);
                let secondaries = p.detected_secondaries(scene);
                out.detections
                    .push(detection(scene, ab, true_ray.dir, weight, p, secondaries));
                self.count_in_cones(p, (ab, true_ray.dir), (weight, &secondaries), out);
                return Fate::Detected;
            }
            let Some(Hit { surf, struck }) = surf else {
                return Fate::Escaped;
            };
            let model = self.model(struck, true_ray.dir, surf.normal);
            let (pol_out, shift_out) = (Cell::new(None), Cell::new(glam::DVec3::ZERO));
            let at = Arrival {
                media: &scene.media,
                hit: &surf,
                dir: true_ray.dir,
                medium: p.medium,
                est: self.estimator,
                light: p.light,
                pol: p.pol,
                pol_out: &pol_out,
                shift_out: &shift_out,
            };
            let before = p.weight;
            let (outcome, feature) = model.interact_on(&at, rng);
            struck.count(&mut out.ledger, feature);
            if self.luminance == Some(LuminanceEstimator::Meter) {
                let v = meter::Vertex {
                    at: &at,
                    model,
                    feature,
                    weight: before,
                    start: struck.start(self.scene),
                };
                self.meter_event(p, &v, &outcome, out);
            }
            match outcome {
                Outcome::Absorbed => return struck.absorbed(),
                Outcome::Scattered {
                    dir,
                    medium,
                    weight,
                } => {
                    p.reweigh(weight, struck.sink(&mut out.ledger));
                    p.scattered_by(model, feature, scene, self.estimator);
                    let from = surf.point + shift_out.get();
                    p.ray = SpawnedRay::leaving(from, surf.normal, dir, scene.spawn_eps);
                    p.medium = medium;
                    if p.pol.is_some() {
                        // A model that keeps no state leaves the light unpolarized.
                        p.pol = Some(pol_out.get().unwrap_or(Polarization::unpolarized(dir)));
                    }
                }
            }
            if !roulette(p, rng, &mut out.ledger) {
                return Fate::Roulette;
            }
        }
        Fate::Killed
    }

    /// Count the photon `p` crossing the target at `ab` along `dir` with detected weight
    /// `weight` in the luminance cones holding `dir`: every one under the cone estimator,
    /// and under the meter's only when no peel-off scored its light.
    fn count_in_cones(
        &self,
        p: &Photon,
        (ab, dir): ([f64; 2], glam::DVec3),
        (weight, secondaries): (f64, &Secondaries),
        out: &mut ChunkTally,
    ) {
        let Some(mode) = self.luminance else {
            return;
        };
        if mode == LuminanceEstimator::Meter && self.peeled(p, dir) {
            return;
        }
        let d = &self.scene.detector;
        let cones = d.cones_holding(dir);
        if cones == 0 {
            return;
        }
        let (bin, spectral) = (d.flux_index(ab) as u32, self.scene.sources.spectral());
        let cause = match (p.covered, p.turned) {
            (false, _) => p.cause,
            (true, u32::MAX) => Cause::TurnedInWalk.index(self.places()),
            (true, turned) => turned,
        };
        for k in (0..d.views.len()).filter(|k| cones >> k & 1 == 1) {
            let hit = MeterHit::new(
                (k as u16, bin),
                weight,
                p.light,
                spectral.then_some(secondaries),
            );
            out.meter.push(hit);
            out.counted[cause as usize].add(weight);
        }
    }

    /// The places a peel-off may start from: every tag, then every lamp body.
    fn places(&self) -> usize {
        self.scene.tags.len() + self.scene.sources.list.len()
    }

    /// The surface or lamp body `p` reaches first along `true_ray` (its path from its
    /// true position).
    fn nearest_surface(&self, p: &Photon, true_ray: &Ray) -> Option<Hit> {
        let mesh = self.nearest_triangle(p, true_ray).map(|surf| Hit {
            struck: Struck::Surface(self.facets[surf.prim as usize].tag),
            surf,
        });
        let t_mesh = mesh.map_or(f64::INFINITY, |h| h.surf.t);
        self.nearest_body(p, t_mesh).or(mesh)
    }

    /// Where `true_ray` crosses the target plane before `t_surface`, if it does. Inside a
    /// convex solid that lies wholly on one side of the target it cannot.
    fn target_hit(&self, p: &Photon, true_ray: &Ray, t_surface: f64) -> Option<(f64, [f64; 2])> {
        match self.convex_solid(p) {
            Some(solid) if solid.clear_of_target => None,
            _ => self.scene.detector.intersect(true_ray, t_surface),
        }
    }

    /// The convex solid `p` travels in, when the fast path is on and its medium has one.
    fn convex_solid(&self, p: &Photon) -> Option<&ConvexSolid> {
        convex_solid(self.scene, self.convex, p.medium)
    }

    /// The triangle `p` reaches first along `true_ray`.
    fn nearest_triangle(&self, p: &Photon, true_ray: &Ray) -> Option<SurfaceHit> {
        let scene = self.scene;
        match self.convex_solid(p) {
            // The convex path needs no nudge and no refinement: it intersects the exact
            // f64 face planes from the true position.
            Some(solid) => solid.exit(&scene.mesh, true_ray).map(|h| SurfaceHit {
                t: h.t,
                prim: h.prim,
                point: true_ray.at(h.t),
                normal: self.facets[h.prim as usize].normal,
            }),
            None => self
                .accel
                .intersect(&p.ray.search, f64::INFINITY)
                .map(|h| p.ray.refine_hit(&self.facets[h.prim as usize], h.prim, h.t)),
        }
    }

    /// The nearest lamp body in `p`'s medium that `p` meets before distance `t_max`.
    /// Bodies are intersected exactly along the search ray (which starts a spawn offset
    /// off the surface `p` left, so a photon leaving a body never meets it again at
    /// distance ~0); distances are measured from the true position, as for triangles.
    fn nearest_body(&self, p: &Photon, t_max: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        // The search ray starts one spawn offset off the true position, so a body within
        // `t_max` of the true position lies within `t_max + eps` along the search ray.
        let reach = t_max + 2.0 * self.scene.spawn_eps;
        for i in self.bodies.near(p.medium, &p.ray.search, reach) {
            let Some(h) = self.body(i).hit(&p.ray.search, reach) else {
                continue;
            };
            let point = p.ray.search.at(h.t);
            let t = (point - p.ray.from).length();
            if t < best.map_or(t_max, |b| b.surf.t) {
                let surf = SurfaceHit {
                    t,
                    prim: NO_TRIANGLE,
                    point,
                    normal: h.normal,
                };
                let struck = if h.front {
                    Struck::Body(i)
                } else {
                    Struck::BodyBack(i)
                };
                best = Some(Hit { surf, struck });
            }
        }
        best
    }

    /// The body of source `i` (one that has a body).
    fn body(&self, i: u32) -> &LampBody {
        let body = self.scene.sources.list[i as usize].body.as_ref();
        body.expect("only sources with bodies are listed")
    }

    /// The surface model a photon travelling along `dir` meets at a hit of normal `normal`
    /// (a two-sided surface's back when it comes from behind).
    fn model(&self, struck: Struck, dir: glam::DVec3, normal: glam::DVec3) -> &SurfaceModel {
        match struck {
            Struck::Surface(tag) => {
                let t = tag as usize;
                let back = self.scene.backs[t].as_ref();
                two_sided::met(&self.scene.surfaces[t], back, dir, normal)
            }
            Struck::Body(i) => &self.body(i).model,
            Struck::BodyBack(_) => &SurfaceModel::Absorber(Absorber),
        }
    }

    /// The medium along `true_ray` up to the next event at `t`. Clear media: Beer-Lambert
    /// (analog: absorbed or not; weighted: the weight attenuated and the loss booked to
    /// the medium). Scattering media: a free flight ([`flight::fly`]) that may end in a
    /// scattering event, after which `p` travels on from the scattering point.
    fn cross_medium(
        &self,
        p: &mut Photon,
        true_ray: &Ray,
        t: f64,
        rng: &mut PhotonRng,
        ledger: &mut Ledger,
    ) -> Flight {
        let medium = &self.scene.media[p.medium as usize];
        let sink = &mut ledger.absorbed_in_medium[p.medium as usize];
        if medium.scattering.scatters() {
            let eps = self.scene.spawn_eps;
            p.enters_scattering(medium);
            let (w, light, dir) = (&mut p.weight, p.light, true_ray.dir);
            let flight = flight::fly(medium, self.estimator, w, light, dir, t, eps, rng, sink);
            // The secondaries cross what the hero did: the whole segment, or up to its
            // scattering event.
            match flight {
                Flight::Reached => p.crossed(p.medium, t, self.scene, self.estimator),
                Flight::Scattered { t, .. } => p.crossed(p.medium, t, self.scene, self.estimator),
                Flight::Absorbed => {}
            }
            if let Flight::Scattered { t, dir } = flight {
                // Inside the medium, clear of surfaces: the search needs no nudge.
                p.ray = SpawnedRay::unnudged(Ray::new(true_ray.at(t), dir));
                // Volume scattering depolarizes (a stand-in: Mie scattering polarizes).
                p.pol = p.pol.map(|_| Polarization::unpolarized(dir));
            }
            return flight;
        }
        if absorb_clear(p, medium.absorption(p.light), t, self.estimator, rng, sink) {
            Flight::Absorbed
        } else {
            p.crossed(p.medium, t, self.scene, self.estimator);
            Flight::Reached
        }
    }

    /// Trace chunk `index` (photons `index*CHUNK .. min(+CHUNK, end)`) of the run seeded
    /// `seed`: the same tally whichever thread traces it, and whenever.
    pub fn trace_chunk(&self, seed: u64, index: u64, end: u64) -> ChunkTally {
        let lo = index * CHUNK;
        let hi = (lo + CHUNK).min(end);
        let mut out = ChunkTally {
            index,
            detections: Vec::new(),
            stokes: Vec::new(),
            meter: Vec::new(),
            peel_tries: vec![[0; 2]; self.places()],
            peel_walks: PeelWalks::default(),
            peeled: ExactSum::default(),
            counted: vec![ExactSum::default(); self.places() + Cause::ALL.len()],
            ledger: Ledger::new(
                self.scene.tags.len(),
                self.scene.media.len(),
                self.scene.sources.list.len(),
            ),
        };
        for i in lo..hi {
            self.trace_photon(seed, i, &mut out);
        }
        out.ledger.sum_detected();
        out.peel_walks = PeelWalks::default(); // scratch: not shipped
        out
    }
}

/// The `prim` of a hit on a lamp body, which is no triangle of the mesh.
const NO_TRIANGLE: u32 = u32::MAX;

/// What a photon's segment ends on.
#[derive(Clone, Copy, Debug)]
enum Struck {
    /// A triangle with this tag.
    Surface(u32),
    /// The body of the source with this index.
    Body(u32),
    /// The absorbing back of an LED's one-sided body.
    BodyBack(u32),
}

impl Struck {
    /// The fate of a photon absorbed there.
    fn absorbed(self) -> Fate {
        match self {
            Struck::Surface(tag) => Fate::AbsorbedBySurface(tag),
            Struck::Body(i) | Struck::BodyBack(i) => Fate::AbsorbedBySource(i),
        }
    }

    /// Count the interaction: per tag (and whether it met the tag's pattern) on a surface,
    /// only in the total on a lamp body.
    fn count(self, ledger: &mut Ledger, feature: Feature) {
        match self {
            Struck::Surface(tag) => ledger.hit(tag, feature != Feature::Plain),
            Struck::Body(_) | Struck::BodyBack(_) => ledger.interactions += 1,
        }
    }

    /// Where a peel-off from it starts, as [`ChunkTally::peel_tries`] counts them.
    fn start(self, scene: &Scene) -> usize {
        match self {
            Struck::Surface(tag) => tag as usize,
            Struck::Body(i) | Struck::BodyBack(i) => scene.tags.len() + i as usize,
        }
    }

    /// The ledger entry that books what is absorbed there.
    fn sink(self, ledger: &mut Ledger) -> &mut ExactSum {
        match self {
            Struck::Surface(tag) => &mut ledger.absorbed_by_surface[tag as usize],
            Struck::Body(i) | Struck::BodyBack(i) => &mut ledger.absorbed_by_source[i as usize],
        }
    }
}

/// A hit and what was struck.
#[derive(Clone, Copy, Debug)]
struct Hit {
    surf: SurfaceHit,
    struck: Struck,
}

/// Beer-Lambert along `t` through a clear medium absorbing `a` per mm (analog: true when
/// the photon is absorbed; weighted: its weight attenuated and the loss booked to `sink`).
/// A photon leaving the scene inside an absorbing medium (t infinite: the black surround
/// the physics and stability tests use to catch leaks) is absorbed there, under both
/// estimators.
fn absorb_clear(
    p: &mut Photon,
    a: f64,
    t: f64,
    estimator: Estimator,
    rng: &mut PhotonRng,
    sink: &mut ExactSum,
) -> bool {
    if a == 0.0 {
        return false;
    }
    match estimator {
        Estimator::Analog => {
            // Absorption is memoryless: one exponential depth per photon, spent
            // segment by segment (a t each), has the law of a fresh free path per
            // segment, without a logarithm and a random draw on every segment.
            if p.absorption_depth < 0.0 {
                p.absorption_depth = -(1.0 - rng.uniform()).ln();
            }
            let spent = a * t;
            if spent > p.absorption_depth {
                return true;
            }
            p.absorption_depth -= spent;
            false
        }
        Estimator::Weighted => {
            // exp(-a t) at any length, to infinity included.
            let w = if t.is_finite() {
                p.weight * (-a * t).exp()
            } else {
                0.0
            };
            Ledger::lose(sink, p.weight, w);
            p.weight = w;
            false
        }
    }
}

/// The state a photon leaves its source `e.source` in: its own (a ray file's ray's), else
/// the source's, in the frame of its u axis made perpendicular to the photon's direction,
/// or unpolarized.
fn emitted_polarization(scene: &Scene, e: &crate::sources::Emission) -> Polarization {
    if let Some(pol) = e.pol {
        return pol;
    }
    let d = e.ray.dir;
    let source = &scene.sources.list[e.source];
    let frame = source.emitter.u_axis();
    match (
        source.polarization,
        (frame - frame.dot(d) * d).try_normalize(),
    ) {
        (Some(stokes), Some(u)) => Polarization { stokes, u },
        _ => Polarization::unpolarized(d),
    }
}

/// Russian roulette on low weights (weighted estimator only): false when the photon dies.
fn roulette(p: &mut Photon, rng: &mut PhotonRng, ledger: &mut Ledger) -> bool {
    if p.weight >= ROULETTE_BELOW {
        return true;
    }
    if rng.uniform() * ROULETTE_SURVIVOR < p.weight {
        Ledger::lose(&mut ledger.roulette, p.weight, ROULETTE_SURVIVOR);
        p.weight = ROULETTE_SURVIVOR;
        true
    } else {
        false
    }
}

/// The detection of `p` (scoring `weight`, its `secondaries` drawn) crossing the target
/// at `ab` along `dir`.
fn detection(
    scene: &Scene,
    ab: [f64; 2],
    dir: glam::DVec3,
    weight: f64,
    p: &Photon,
    secondaries: Secondaries,
) -> Detection {
    let d = &scene.detector;
    Detection {
        flux_bin: d.flux_index(ab) as u32,
        angular_bin: d.angular_index(dir) as u32,
        weight,
        light: p.light,
        secondaries,
    }
}

/// For the tracer's tests: chunks 0 and 7 (seed 5) of the bundled scene `name`, traced
/// by a tracer as built (BVH backend, convex path on) and changed by `base`, and by one
/// changed by `base` then `alter`, are the same bits (ledgers and detections); returns
/// the first tracer's chunks.
#[cfg(test)]
fn assert_same_chunks(
    name: &str,
    estimator: Estimator,
    base: impl Fn(&mut Tracer),
    alter: impl FnOnce(&mut Tracer),
) -> Vec<ChunkTally> {
    assert_same_chunks_of(&bundled(name), estimator, base, alter)
}

/// The bundled scene `name`, for the tracer's tests.
#[cfg(test)]
fn bundled(name: &str) -> Scene {
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("scenes");
    Scene::load(&root.join(name).join("scene.toml")).unwrap()
}

/// [`assert_same_chunks`] of a loaded `scene` (Stokes vectors compared too).
#[cfg(test)]
fn assert_same_chunks_of(
    scene: &Scene,
    estimator: Estimator,
    base: impl Fn(&mut Tracer),
    alter: impl FnOnce(&mut Tracer),
) -> Vec<ChunkTally> {
    let name = &scene.name;
    let accel = crate::accel::build(crate::accel::BackendChoice::Bvh, scene.mesh.clone()).unwrap();
    let facets = scene.mesh.facets();
    let mut built = Tracer::new(scene, accel.as_ref(), estimator, true, &facets);
    let mut altered = Tracer::new(scene, accel.as_ref(), estimator, true, &facets);
    base(&mut built);
    base(&mut altered);
    alter(&mut altered);
    [0, 7]
        .map(|chunk| {
            let (a, b) = (
                built.trace_chunk(5, chunk, u64::MAX),
                altered.trace_chunk(5, chunk, u64::MAX),
            );
            let what = format!("{name} {estimator:?} chunk {chunk}");
            assert_eq!(a.ledger, b.ledger, "{what}");
            assert_eq!(a.detections, b.detections, "{what}");
            assert_eq!(a.stokes, b.stokes, "{what}");
            assert_eq!(a.meter, b.meter, "{what}");
            assert_eq!((a.peeled, &a.counted), (b.peeled, &b.counted), "{what}");
            a
        })
        .into()
}
