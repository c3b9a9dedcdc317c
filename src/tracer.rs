//! The photon loop (paper section 3) and the parallel, deterministic driver around it.
//!
//! ```toml
//! [trace]
//! photons = 400000       # default photon count (CLI --photons overrides)
//! seed = 1               # default seed (CLI --seed overrides)
//! max_bounces = 100000   # surface events before a photon is killed (counted, not silent)
//! ```
//!
//! Each photon is traced along straight segments to the nearest surface, where its
//! surface model decides by Russian roulette to reflect, transmit or absorb it. It ends in
//! exactly one fate: detected, absorbed (by a named surface or medium), escaped, or killed
//! by the bounce cap. Work is split into fixed chunks of photon indices; tallies are exact
//! integer sums, so the result does not depend on the thread count.

use crate::accel::Accel;
use crate::geometry::Ray;
use crate::optics::surface::{MediumId, Outcome};
use crate::rng::PhotonRng;
use crate::scene::Scene;
use crate::tally::{ExactSum, Grid};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Photons per work unit. Fixed, so results never depend on scheduling.
pub const CHUNK: u64 = 4096;

/// How one photon ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fate {
    /// Reached the target plane.
    Detected,
    /// Absorbed by the surface with this tag index.
    AbsorbedBySurface(u32),
    /// Absorbed inside this medium (Beer-Lambert).
    AbsorbedInMedium(MediumId),
    /// Left the scene.
    Escaped,
    /// Stopped by the bounce cap.
    Killed,
}

/// Where the emitted energy went, in photon weights.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ledger {
    /// Photons emitted.
    pub photons: u64,
    /// Surface interactions (roulette events).
    pub interactions: u64,
    /// Emitted weight.
    pub emitted: ExactSum,
    /// Weight detected on the target.
    pub detected: ExactSum,
    /// Weight absorbed per surface tag.
    pub absorbed_by_surface: Vec<ExactSum>,
    /// Weight absorbed per medium.
    pub absorbed_in_medium: Vec<ExactSum>,
    /// Weight that left the scene.
    pub escaped: ExactSum,
    /// Weight stopped by the bounce cap.
    pub killed: ExactSum,
    /// Photons stopped by the bounce cap.
    pub killed_photons: u64,
}

impl Ledger {
    fn new(tags: usize, media: usize) -> Self {
        Self {
            absorbed_by_surface: vec![ExactSum::default(); tags],
            absorbed_in_medium: vec![ExactSum::default(); media],
            ..Default::default()
        }
    }

    fn record(&mut self, fate: Fate, w: f64) {
        self.emitted.add(w);
        match fate {
            Fate::Detected => self.detected.add(w),
            Fate::AbsorbedBySurface(t) => self.absorbed_by_surface[t as usize].add(w),
            Fate::AbsorbedInMedium(m) => self.absorbed_in_medium[m as usize].add(w),
            Fate::Escaped => self.escaped.add(w),
            Fate::Killed => {
                self.killed.add(w);
                self.killed_photons += 1;
            }
        }
    }

    fn merge(&mut self, o: &Ledger) {
        self.photons += o.photons;
        self.interactions += o.interactions;
        self.emitted.merge(o.emitted);
        self.detected.merge(o.detected);
        for (a, b) in self
            .absorbed_by_surface
            .iter_mut()
            .zip(&o.absorbed_by_surface)
        {
            a.merge(*b);
        }
        for (a, b) in self
            .absorbed_in_medium
            .iter_mut()
            .zip(&o.absorbed_in_medium)
        {
            a.merge(*b);
        }
        self.escaped.merge(o.escaped);
        self.killed.merge(o.killed);
        self.killed_photons += o.killed_photons;
    }

    /// Sum of all fates' weights (equals `emitted` exactly when the ledger balances).
    pub fn accounted(&self) -> ExactSum {
        let mut s = ExactSum(self.detected.0 + self.escaped.0 + self.killed.0);
        for a in self
            .absorbed_by_surface
            .iter()
            .chain(&self.absorbed_in_medium)
        {
            s.merge(*a);
        }
        s
    }
}

/// Everything a run scored.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Tally {
    /// Flux bins on the target plane (photon weights).
    pub flux: Grid,
    /// (theta, phi) bins of detected directions (photon weights).
    pub angular: Grid,
    /// Energy ledger.
    pub ledger: Ledger,
}

impl Tally {
    /// An empty tally shaped for `scene`.
    pub fn new(scene: &Scene) -> Self {
        let (flux, angular) = scene.detector.empty_grids();
        Self {
            flux,
            angular,
            ledger: Ledger::new(scene.tags.len(), scene.media.len()),
        }
    }

    /// Add another tally of the same scene.
    pub fn merge(mut self, o: &Tally) -> Self {
        self.flux.merge(&o.flux);
        self.angular.merge(&o.angular);
        self.ledger.merge(&o.ledger);
        self
    }
}

/// Traces photons of one scene through one backend.
pub struct Tracer<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The intersection backend.
    pub accel: &'a dyn Accel,
}

impl Tracer<'_> {
    /// Follow photon `index` of the run seeded `seed` to its fate, scoring into `tally`.
    pub fn trace_photon(&self, seed: u64, index: u64, tally: &mut Tally) {
        let mut rng = PhotonRng::new(seed, index);
        let (ray, medium) = self.scene.sources.sample(&mut rng);
        let (fate, events) = self.follow(ray, medium, &mut rng, tally);
        tally.ledger.photons += 1;
        tally.ledger.interactions += events;
        tally.ledger.record(fate, 1.0);
    }

    /// The photon loop: nearest event, Beer-Lambert, surface roulette, repeat.
    fn follow(
        &self,
        mut ray: Ray,
        mut medium: MediumId,
        rng: &mut PhotonRng,
        tally: &mut Tally,
    ) -> (Fate, u64) {
        let scene = self.scene;
        for bounce in 0..scene.max_bounces as u64 {
            let hit = self.accel.intersect(&ray, f64::INFINITY);
            let t_surface = hit.map_or(f64::INFINITY, |h| h.t);
            let detected = scene.detector.intersect(&ray, t_surface);
            let t_next = detected.map_or(t_surface, |(t, _)| t);
            if scene.free_path(medium, rng) < t_next {
                return (Fate::AbsorbedInMedium(medium), bounce);
            }
            if let Some((_, ab)) = detected {
                score_detection(scene, tally, ab, ray.dir);
                return (Fate::Detected, bounce);
            }
            let Some(h) = hit else {
                return (Fate::Escaped, bounce);
            };
            let surf = scene.mesh.refine_hit(&ray, h.prim, h.t);
            let tag = scene.mesh.tri_tag[h.prim as usize];
            match scene.surfaces[tag as usize].interact(&scene.media, &surf, ray.dir, medium, rng) {
                Outcome::Absorbed => return (Fate::AbsorbedBySurface(tag), bounce + 1),
                Outcome::Scattered { dir, medium: m } => {
                    ray = Ray::new(scene.spawn_point(surf.point, surf.normal, dir), dir);
                    medium = m;
                }
            }
        }
        (Fate::Killed, scene.max_bounces as u64)
    }

    /// Trace photons `start..end` in parallel. `progress` is told how many photons each
    /// finished chunk held. The result is identical for any thread count.
    pub fn run_range(
        &self,
        seed: u64,
        start: u64,
        end: u64,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Tally {
        let chunks = (end.saturating_sub(start)).div_ceil(CHUNK);
        (0..chunks)
            .into_par_iter()
            .fold(
                || Tally::new(self.scene),
                |mut tally, c| {
                    let lo = start + c * CHUNK;
                    let hi = (lo + CHUNK).min(end);
                    for i in lo..hi {
                        self.trace_photon(seed, i, &mut tally);
                    }
                    progress(hi - lo);
                    tally
                },
            )
            .reduce(|| Tally::new(self.scene), |a, b| a.merge(&b))
    }
}

fn score_detection(scene: &Scene, tally: &mut Tally, ab: [f64; 2], dir: glam::DVec3) {
    let (ix, iy) = scene.detector.flux_bin(ab);
    tally.flux.add(ix, iy, 1.0);
    let (it, ip) = scene.detector.angular_bin(dir);
    tally.angular.add(it, ip, 1.0);
}
