//! The meter's backward peel-off: through prism films and from rough diffusers.
//!
//! ```toml
//! [surfaces.diffuser_top]   # a rough face: its walk's density is estimated
//! model = "diffuser"
//! inside = "pet"
//! roughness = 0.6
//!
//! [surfaces.bef1_top]       # uniform prisms: the walk crosses them
//! model = "grooves"
//! relief = "raised"
//! inside = "pet"
//! apex_deg = 90.0
//! pitch_mm = 0.05
//! origin = [0.0, 0.0, 1.1]
//! axis = [1.0, 0.0, 0.0]
//! ```
//!
//! A prism film's facets turn `n t`, so no direction at an event below it is known to
//! leave along a view: the flat-layer peel-off ([`super::meter`]) cannot cross it. Scenes
//! with uniform grooves or a rough diffuser peel off backwards instead, at every diffuse
//! event (and at a diffuser's, whose density its model estimates):
//!
//! 1. a direction `out` is drawn within the view's cone, and a path is traced from the
//!    target point over the event along `-out`, with the photons' own models and
//!    roulette, through the faces that are the same at every point of the target
//!    ([`MeterLayer`]) and parallel to it (films, their grooves, smooth interfaces,
//!    mirrors), until it meets the event's own face; a path that meets anything else
//!    (a dotted face, another diffuser, a film's edge), or leaves upwards, scores nothing;
//! 2. by reciprocity the path's reversed direction at that face is drawn with the
//!    density with which light leaving the event along it reaches the view (the Fresnel
//!    roulette is the same both ways; the radiance n^2 law is the Jacobian
//!    `n_d^2 (out.N) / (n^2 |dir.N|)` of the flat-layer estimator), and the path carries
//!    the detector's response backwards (its polarization as the reversed light's, turned
//!    into the forward light's by [`crate::optics::polarization::response`]);
//! 3. the layers being the same everywhere, the path is moved sideways to start at the
//!    event: it scores the event's density along that direction (weighted by the
//!    response) into the bin its moved crossing of the target lies in.
//!
//! Photons are split the same way: one crossing the target within a cone is counted
//! there only when its path since its last diffuse event crossed such faces alone.
//!
//! What this leaves out: the layers' ends. A path within its sideways travel (about the
//! stack's height times the tangent of its slant, under a millimetre in the bundled
//! stacks) of a film's edge is moved as if the film went on; uniform grooves are met at
//! the phase the moved path has, not the one the event's own light would meet (a map's
//! bin spans many pitches).

use super::meter::{Vertex, Walk, in_cone};
use super::tir_run::{Skipped, TirRun};
use super::{Photon, Tracer};
use crate::geometry::{Ray, SpawnedRay};
use crate::optics::model::MeterLayer;
use crate::optics::polarization::{Polarization, Stokes, response};
use crate::optics::spectrum::{Light, Secondaries};
use crate::rng::PhotonRng;
use crate::tally::MeterHit;
use crate::tally::meter::{PeelWalk, PeelWalks};
use glam::DVec3;

/// Events a backward walk takes before it is given up (counted as reaching nothing).
const WALK_EVENTS: u32 = 256;

/// How parallel to the target a face must be for the backward walk to cross it.
const PARALLEL: f64 = 1e-9;

impl Tracer<'_> {
    /// Whether the backward walk crosses `model`'s face met at unit `normal`.
    pub(super) fn crosses(&self, layer: MeterLayer, normal: DVec3) -> bool {
        let n = self.scene.detector.normal();
        layer != MeterLayer::Not && normal.dot(n).abs() >= 1.0 - PARALLEL
    }

    /// After a run of total reflections ([`super::tir_run`]): the backward walk crosses
    /// neither the dotted face (a pattern) nor faces not parallel to the target, so a
    /// photon whose run met them is no longer covered.
    pub(super) fn meter_run(&self, p: &mut Photon, run: &TirRun, s: &Skipped) {
        if !p.covered || self.walk != Walk::Backward {
            return;
        }
        if s.periods > 0 {
            (p.covered, p.cause) = (false, run.dotted_tag);
        } else if !self.crosses(MeterLayer::Flat, run.axis()) {
            (p.covered, p.cause) = (false, run.plain_tag);
        }
    }

    /// The light the event `v` sends towards each view, by backward walks (the chunk's,
    /// reused: [`PeelWalks`]).
    pub(super) fn peel_backward(
        &self,
        v: &Vertex,
        rng: &mut PhotonRng,
        pool: &mut PeelWalks,
        hits: &mut Vec<MeterHit>,
    ) {
        let d = &self.scene.detector;
        for k in 0..d.views.len() {
            let walk = self.pooled_walk(v, k, rng, pool);
            if walk.weight == 0.0 {
                continue;
            }
            let r = v.at.hit.point + walk.shift - d.origin;
            let ab = [r.dot(d.u), r.dot(d.v)];
            if !(0.0..d.size[0]).contains(&ab[0]) || !(0.0..d.size[1]).contains(&ab[1]) {
                continue;
            }
            let respond = |s: Option<&Polarization>| match (&walk.importance, s) {
                (Some(i), Some(s)) => response(i, s, walk.dir),
                _ => 1.0,
            };
            let density = v
                .model
                .meter_response(v.at, v.feature, walk.dir, &respond, rng);
            if density == 0.0 {
                continue;
            }
            let light = v.at.light;
            let n_x = self.index(walk.medium, light);
            let w = v.weight * density * walk.weight;
            let bin = d.flux_index(ab) as u32;
            hits.push(self.meter_hit((k, bin), w, (walk.out, walk.dir), (n_x, light)));
        }
    }

    /// The walk the event `v`'s peel-off towards view `k` uses: the next of the chunk's
    /// walks of its place, drawn (from the event's stream) when there are fewer than
    /// [`PeelWalks::SIZE`].
    fn pooled_walk(
        &self,
        v: &Vertex,
        k: usize,
        rng: &mut PhotonRng,
        pool: &mut PeelWalks,
    ) -> PeelWalk {
        let (list, uses) = pool.slot(v.start * self.scene.detector.views.len() + k);
        let i = *uses as usize % PeelWalks::SIZE;
        *uses += 1;
        if i == list.len() {
            list.push(self.draw_walk(v, k, rng));
        }
        list[i]
    }

    /// A backward walk towards view `k` from a point drawn uniformly in the target's
    /// middle half (each way): the walk stands for every event of its place, so it
    /// starts away from the layers' ends, and at a random phase of any periodic
    /// structure it meets (a fixed start would meet prisms at one phase only).
    fn draw_walk(&self, v: &Vertex, k: usize, rng: &mut PhotonRng) -> PeelWalk {
        let d = &self.scene.detector;
        let (a, b) = (0.25 + 0.5 * rng.uniform(), 0.25 + 0.5 * rng.uniform());
        let start = d.origin + d.u * (a * d.size[0]) + d.v * (b * d.size[1]);
        let out = in_cone(d.view_dir(k), d.luminance_cone_deg, rng);
        self.walk_back(start, out, v, rng).unwrap_or(PeelWalk {
            out,
            shift: DVec3::ZERO,
            dir: out,
            medium: 0,
            weight: 0.0,
            importance: None,
        })
    }

    /// The path from the target point `start` along `-out` down to the face of the
    /// event `v`, through the layers the backward walk crosses.
    fn walk_back(
        &self,
        start: DVec3,
        out: DVec3,
        v: &Vertex,
        rng: &mut PhotonRng,
    ) -> Option<PeelWalk> {
        let scene = self.scene;
        let mut p = self.walker(start, -out, v.at.light);
        for _ in 0..WALK_EVENTS {
            let ray = p.ray.true_ray();
            let surf = self.nearest_surface(&p, &ray);
            let t_surface = surf.as_ref().map_or(f64::INFINITY, |h| h.surf.t);
            if self.target_hit(&p, &ray, t_surface).is_some() {
                return None; // back through the target: light from above it
            }
            let super::Hit { surf, struck } = surf?;
            p.weight *= self.transmittance(p.medium, p.light, surf.t);
            if struck.start(scene) == v.start {
                return Some(PeelWalk {
                    out,
                    shift: start - surf.point,
                    dir: -ray.dir,
                    medium: p.medium,
                    weight: p.weight,
                    importance: p.pol,
                });
            }
            let model = self.model(struck, ray.dir, surf.normal);
            if !self.crosses(model.meter_layer(), surf.normal) {
                return None;
            }
            self.path_step(&mut p, model, &surf, ray.dir, rng)?;
        }
        None
    }

    /// The backward walker leaving the target at `start` along unit `dir` in the ambient
    /// medium, carrying the detector's response: unpolarized, or the analyzer's (half
    /// the power, linear along its axis; none along the axis), as photons meet it.
    fn walker(&self, start: DVec3, dir: DVec3, light: Light) -> Photon {
        let scene = self.scene;
        let (weight, pol) = match (scene.polarized, scene.detector.analyzer_axis(-dir)) {
            (false, _) => (1.0, None),
            (true, Some(u)) => {
                let stokes = Stokes([1.0, 1.0, 0.0, 0.0]);
                (0.5, Some(Polarization { stokes, u }))
            }
            (true, None) if scene.detector.analyzer.is_some() => (0.0, None),
            (true, None) => (1.0, Some(Polarization::unpolarized(dir))),
        };
        Photon {
            ray: SpawnedRay::unnudged(Ray::new(start, dir)),
            medium: 0,
            weight,
            light,
            pol,
            absorption_depth: -1.0,
            covered: false,
            left_with: DVec3::ZERO,
            cause: 0,
            turned: u32::MAX,
            peel_rng: None,
            secondaries: Secondaries::NONE,
        }
    }
}
