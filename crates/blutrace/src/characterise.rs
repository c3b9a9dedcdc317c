//! `blutrace bsdf`: characterise a part of a scene into an IS BSDF table
//! ([`crate::optics::bsdf_table`]), so a system can trace the part as one face.
//!
//! ```toml
//! # the part: a tagged face, e.g. the bead-filled plate's back of scenes/direct-lit
//! [surfaces.diffuser_back]
//! model = "dielectric"
//! inside = "pc"          # a scattering medium: the part is the whole plate
//! ```
//!
//! The part is the tagged face, flat, lit from the side its normal points to. When its
//! model lets light into a medium bounded by a parallel face of the scene (a plate, a
//! film), the part is that slab, with its volume scattering and absorption and the other
//! face's model; else the face alone. Collimated photons arrive at each angle of
//! incidence (and sample rotation) at points spread over the face, and are followed
//! through an infinite slab of the part's thickness (the models see the point they hit,
//! so patterned faces are averaged over their pattern) until they leave it: back on the
//! lit side (BRDF), out of the far face (BTDF, or into the face's medium when there is no
//! far face), or absorbed. Each leaving direction is counted in its cell of the table's
//! grid ([`crate::optics::bsdf_table::sample`]); a cell's BSDF is its share of the power
//! over its projected solid angle, the TIS the whole share. What the table cannot keep:
//! where the light left (the lateral spread inside the part), the part's edges.

use crate::estimator::Estimator;
use crate::geometry::SurfaceHit;
use crate::optics::bsdf_table::MAX_U_AXIS_COS;
use crate::optics::bsdf_table::format::{Block, ScatterType, Section};
use crate::optics::bsdf_table::sample::{Frame, Grid, Incidence, incidence};
use crate::optics::medium::MediumId;
use crate::optics::spectrum::Light;
use crate::optics::surface::{Outcome, SurfaceModel};
use crate::rng::PhotonRng;
use crate::scene::Scene;
use anyhow::{Result, bail};
use glam::DVec3;
use rayon::prelude::*;

/// Events one photon may meet in the part before it is counted as lost.
pub const MAX_EVENTS: usize = 100_000;

/// The angles of incidence characterised unless asked otherwise (degrees; `blutrace
/// bsdf --aoi`'s default).
pub const DEFAULT_AOI_DEG: [f64; 10] = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0];

/// What to characterise and on which grid.
#[derive(Clone, Debug)]
pub struct Options {
    /// The tag of the face the light arrives at.
    pub tag: String,
    /// Photons per (rotation, AOI).
    pub photons: u64,
    /// Angles of incidence (degrees, increasing, in [0, 90)).
    pub aoi_deg: Vec<f64>,
    /// Sample rotations (degrees); one: a plane-symmetric table (the part taken as
    /// isotropic), several: asymmetric.
    pub rotations_deg: Vec<f64>,
    /// Radial step (degrees): nodes 0, step, ... up to 180.
    pub radial_step_deg: f64,
    /// Azimuth step (degrees).
    pub azimuth_step_deg: f64,
    /// The direction of sample rotation 0 (`None`: as `bsdf_table`'s default).
    pub u_axis: Option<[f64; 3]>,
    /// Seed of the photons' random numbers.
    pub seed: u64,
}

/// The fates of the photons of one (rotation, AOI).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fates {
    /// Reflected (left on the lit side).
    pub reflected: f64,
    /// Transmitted.
    pub transmitted: f64,
    /// Absorbed in the part.
    pub absorbed: f64,
    /// Still inside after [`MAX_EVENTS`] events.
    pub lost: f64,
}

/// A characterised part.
#[derive(Clone, Debug)]
pub struct Characterised {
    /// What the part was found to be (for the file's comments and the report).
    pub part: String,
    /// The BRDF and BTDF sections (a type no photon took is left out: an opaque part
    /// has no BTDF, so its table needs no `inside`).
    pub sections: Vec<Section>,
    /// Per (rotation, AOI), rotation-major: fractions of the photons.
    pub fates: Vec<Fates>,
}

/// The part as found in the scene: the lit face, its normal and the far face.
struct Part<'a> {
    scene: &'a Scene,
    front: &'a SurfaceModel,
    /// Triangles of the lit face and their cumulative areas.
    tris: Vec<u32>,
    cum_area: Vec<f64>,
    /// Outward unit normal of the lit face.
    n: DVec3,
    /// The medium in front of it.
    outside: MediumId,
    /// The slab behind it: its medium, thickness (mm), far face's model and a triangle.
    slab: Option<(MediumId, f64, &'a SurfaceModel, u32)>,
    /// The tangent of sample rotation 0.
    u: DVec3,
}

impl<'a> Part<'a> {
    fn find(scene: &'a Scene, opts: &Options) -> Result<Part<'a>> {
        let Some(tag) = scene.tags.iter().position(|t| *t == opts.tag) else {
            bail!(
                "no tag {:?} in the scene (its tags: {})",
                opts.tag,
                scene.tags.join(", ")
            );
        };
        let mesh = &scene.mesh;
        let tris: Vec<u32> = (0..mesh.len() as u32)
            .filter(|&p| mesh.tri_tag[p as usize] as usize == tag)
            .collect();
        if tris.is_empty() {
            bail!("tag {:?} has no triangles", opts.tag);
        }
        let n = tris
            .iter()
            .map(|&p| mesh.area_normal(p))
            .sum::<DVec3>()
            .normalize_or_zero();
        if n == DVec3::ZERO || tris.iter().any(|&p| mesh.normal(p).dot(n) < 0.9999) {
            bail!(
                "tag {:?} is not one flat face: characterise a flat face",
                opts.tag
            );
        }
        let mut total = 0.0;
        let cum_area = tris
            .iter()
            .map(|&p| {
                total += mesh.area_normal(p).length();
                total
            })
            .collect();
        let front = &scene.surfaces[tag];
        let outside = front.interface().map_or(0, |i| i.outside);
        let origin = mesh.corners(tris[0])[0];
        let slab = front
            .interface()
            .and_then(|i| far_face(scene, tag, i.inside, n, origin));
        let u =
            opts.u_axis
                .map(unit_axis)
                .unwrap_or(if n.x.abs() > 0.9 { DVec3::Y } else { DVec3::X });
        if u.dot(n).abs() > MAX_U_AXIS_COS {
            bail!(
                "--u-axis {:?} lies (nearly) along the normal {:?} of tag {:?}: it must lie in the face",
                u.to_array(),
                n.to_array(),
                opts.tag
            );
        }
        let u = u - u.dot(n) * n;
        Ok(Part {
            scene,
            front,
            tris,
            cum_area,
            n,
            outside,
            slab,
            u: u.normalize(),
        })
    }

    fn describe(&self, tag: &str) -> String {
        let media = &self.scene.media;
        match self.slab {
            Some((m, d, _, p)) => format!(
                "the slab of {} behind tag {tag} ({}), {d} mm thick, far face tag {} ({})",
                media[m as usize].name,
                self.front.kind(),
                self.scene.tags[self.scene.mesh.tri_tag[p as usize] as usize],
                self.scene.surfaces[self.scene.mesh.tri_tag[p as usize] as usize].kind()
            ),
            None => format!("the face tag {tag} ({}) alone", self.front.kind()),
        }
    }

    /// A point on the lit face, uniform over its area.
    fn point(&self, rng: &mut PhotonRng) -> (DVec3, u32) {
        let total = *self.cum_area.last().unwrap_or(&0.0);
        let k = self
            .cum_area
            .partition_point(|&c| c < rng.uniform() * total)
            .min(self.tris.len() - 1);
        let [a, b, c] = self.scene.mesh.corners(self.tris[k]);
        let (mut s, mut t) = (rng.uniform(), rng.uniform());
        if s + t > 1.0 {
            (s, t) = (1.0 - s, 1.0 - t);
        }
        (a + s * (b - a) + t * (c - a), self.tris[k])
    }

    /// Follow one photon arriving along `d`: `Some((true, dir))` reflected,
    /// `Some((false, dir))` transmitted, `None` absorbed; `Err(())` lost.
    fn walk(
        &self,
        d: DVec3,
        rng: &mut PhotonRng,
    ) -> std::result::Result<Option<(bool, DVec3)>, ()> {
        let (start, prim) = self.point(rng);
        let media = &self.scene.media;
        let (mut p, mut dir, mut medium) = (start, d, self.outside);
        let mut at_front = true;
        for _ in 0..MAX_EVENTS {
            let (model, normal, prim) = match (at_front, self.slab) {
                (true, _) => (self.front, self.n, prim),
                (false, Some((_, _, far, fp))) => (far, -self.n, fp),
                (false, None) => return Err(()),
            };
            let hit = SurfaceHit {
                t: 0.0,
                prim,
                point: p,
                normal,
            };
            match model.interact(media, &hit, dir, medium, Estimator::Analog, rng) {
                Outcome::Absorbed => return Ok(None),
                Outcome::Scattered {
                    dir: nd,
                    medium: nm,
                    ..
                } => {
                    (dir, medium) = (nd, nm);
                }
            }
            let away = dir.dot(normal) > 0.0;
            match (at_front, away, self.slab) {
                (true, true, _) => return Ok(Some((true, dir))),
                (false, true, _) | (true, false, None) => return Ok(Some((false, dir))),
                _ => {}
            }
            let Some((m, thick, _, _)) = self.slab else {
                return Err(());
            };
            match self.fly(&mut p, &mut dir, &media[m as usize], start, thick, rng) {
                Some(front) => at_front = front,
                None => return Ok(None),
            }
        }
        Err(())
    }

    /// Fly from `p` along `dir` inside the slab (front plane through `start`, thickness
    /// `thick`) until it reaches a face: `Some(true)` the front, `Some(false)` the far
    /// face, `None` absorbed on the way.
    fn fly(
        &self,
        p: &mut DVec3,
        dir: &mut DVec3,
        medium: &crate::optics::medium::Medium,
        start: DVec3,
        thick: f64,
        rng: &mut PhotonRng,
    ) -> Option<bool> {
        let light = Light::MONOCHROME;
        let (mu_a, mu_s) = (
            medium.absorption(light),
            medium.scattering.coefficient(light),
        );
        let mu_t = mu_a + mu_s;
        for _ in 0..MAX_EVENTS {
            let h = (*p - start).dot(self.n).clamp(-thick, 0.0);
            let dz = dir.dot(self.n);
            let (to_front, t_face) = if dz > 0.0 {
                (true, -h / dz)
            } else {
                (false, (thick + h) / (-dz).max(1e-300))
            };
            let s = if mu_t > 0.0 {
                -(1.0 - rng.uniform()).ln() / mu_t
            } else {
                f64::INFINITY
            };
            if s >= t_face {
                *p += t_face * *dir;
                return Some(to_front);
            }
            *p += s * *dir;
            if rng.uniform() * mu_t < mu_a {
                return None;
            }
            *dir = medium
                .scattering
                .scatter(*dir, light, rng.uniform(), rng.uniform());
        }
        None
    }
}

/// The face parallel to and facing away from the lit one (normal `n`, through `origin`)
/// that bounds the medium `inside` of tag `tag`, nearest behind it: its medium,
/// distance, model and a triangle.
fn far_face(
    scene: &Scene,
    tag: usize,
    inside: MediumId,
    n: DVec3,
    origin: DVec3,
) -> Option<(MediumId, f64, &SurfaceModel, u32)> {
    let mesh = &scene.mesh;
    (0..mesh.len() as u32)
        .filter(|&p| {
            let t = mesh.tri_tag[p as usize] as usize;
            t != tag
                && mesh.normal(p).dot(n) < -0.9999
                && scene.surfaces[t]
                    .interface()
                    .is_some_and(|i| i.inside == inside)
        })
        .map(|p| (p, (origin - mesh.corners(p)[0]).dot(n)))
        .filter(|&(_, d)| d > 1e-9)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(p, d)| {
            (
                inside,
                d,
                &scene.surfaces[mesh.tri_tag[p as usize] as usize],
                p,
            )
        })
}

/// Nodes `0, step, 2 step, ...` up to `max` (and `max` itself when `closed`).
fn nodes(step: f64, max: f64, closed: bool) -> Vec<f64> {
    let n = (max / step - 1e-9).floor() as usize;
    let mut v: Vec<f64> = (0..=n).map(|i| i as f64 * step).collect();
    if closed && v.last().is_some_and(|&l| l < max - 1e-9) {
        v.push(max);
    }
    v
}

/// The unit vector along `u` (finite and non-zero, as [`check`] makes sure), scaled
/// first so that no component's square overflows or underflows.
fn unit_axis(u: [f64; 3]) -> DVec3 {
    let u = DVec3::from_array(u);
    (u / u.abs().max_element()).normalize()
}

/// Check the options' grids and axis.
fn check(opts: &Options) -> Result<()> {
    if opts.photons == 0 {
        bail!("--photons must be at least 1");
    }
    let inc = |v: &[f64]| v.windows(2).all(|w| w[0] < w[1]);
    if opts.aoi_deg.is_empty()
        || !inc(&opts.aoi_deg)
        || opts.aoi_deg.iter().any(|a| !(0.0..90.0).contains(a))
    {
        bail!(
            "--aoi: angles of incidence must increase within [0, 90), got {:?}",
            opts.aoi_deg
        );
    }
    if opts.rotations_deg.is_empty()
        || !inc(&opts.rotations_deg)
        || opts.rotations_deg.iter().any(|a| !(0.0..360.0).contains(a))
    {
        bail!(
            "--rotations: must increase within [0, 360), got {:?}",
            opts.rotations_deg
        );
    }
    if let Some(u) = opts.u_axis
        && (u.iter().any(|c| !c.is_finite()) || u == [0.0; 3])
    {
        bail!("--u-axis: must be a finite, non-zero direction, got {u:?}");
    }
    for (flag, s) in [
        ("--radial-step", opts.radial_step_deg),
        ("--azimuth-step", opts.azimuth_step_deg),
    ] {
        if !(0.1..=90.0).contains(&s) {
            bail!("{flag}: must be within [0.1, 90] degrees, got {s}");
        }
    }
    Ok(())
}

/// Characterise the part of `scene` at `opts.tag` into a BRDF and a BTDF section.
pub fn characterise(scene: &Scene, opts: &Options) -> Result<Characterised> {
    characterise_until(scene, opts, &|_| false)
}

/// [`characterise`], asking `stop` before each (rotation, AOI) with the number of
/// incidences done (for a progress report): `Err` ("interrupted") as soon as it says yes
/// (a caller's Ctrl-C; an incidence takes a few seconds at most).
pub fn characterise_until(
    scene: &Scene,
    opts: &Options,
    stop: &dyn Fn(usize) -> bool,
) -> Result<Characterised> {
    check(opts)?;
    let part = Part::find(scene, opts)?;
    let symmetric = opts.rotations_deg.len() == 1;
    let radial = nodes(opts.radial_step_deg, 180.0, true);
    let azimuth = nodes(
        opts.azimuth_step_deg,
        if symmetric { 180.0 } else { 360.0 },
        symmetric,
    );
    let grid = Grid::new(&radial, &azimuth, symmetric);
    let mut blocks = (Vec::new(), Vec::new());
    let mut fates = Vec::new();
    for (ri, rot) in opts.rotations_deg.iter().enumerate() {
        for (ai, aoi) in opts.aoi_deg.iter().enumerate() {
            let done = ri * opts.aoi_deg.len() + ai;
            if stop(done) {
                bail!("interrupted");
            }
            let stream = done as u64;
            let (r, t, f) = one_incidence(&part, &grid, (*rot, *aoi), opts, stream);
            blocks.0.push(r);
            blocks.1.push(t);
            fates.push(f);
        }
    }
    let section = |scatter, blocks| Section {
        channel: None,
        scatter,
        plane_symmetric: symmetric,
        rotations: opts.rotations_deg.clone(),
        aoi: opts.aoi_deg.clone(),
        azimuth: azimuth.clone(),
        radial: radial.clone(),
        blocks,
    };
    Ok(Characterised {
        part: part.describe(&opts.tag),
        sections: [
            section(ScatterType::Brdf, blocks.0),
            section(ScatterType::Btdf, blocks.1),
        ]
        .into_iter()
        .filter(|s| s.blocks.iter().any(|b| b.tis > 0.0))
        .collect(),
        fates,
    })
}

/// Counts of one scatter type per cell, `[azimuth][radial]`, and the photons counted.
type Counts = (Vec<Vec<f64>>, f64);

/// The BRDF and BTDF blocks and the fates at sample rotation `rot` and AOI `aoi`
/// (degrees); `stream` keeps each incidence's photons independent.
fn one_incidence(
    part: &Part,
    grid: &Grid,
    (rot, aoi): (f64, f64),
    opts: &Options,
    stream: u64,
) -> (Block, Block, Fates) {
    let (rot, theta) = (rot.to_radians(), aoi.to_radians());
    let v = part.n.cross(part.u);
    let m = rot.cos() * part.u + rot.sin() * v;
    let t = m.cross(part.n);
    let d = (-theta.cos() * part.n + theta.sin() * t).normalize();
    let inc = incidence(d, part.n, part.u);
    let frames = [
        Frame::new(ScatterType::Brdf, &inc),
        Frame::new(ScatterType::Btdf, &inc),
    ];
    let empty = || vec![vec![0.0; grid.n_radial()]; grid.az_lo.len()];
    let chunk = 4096u64;
    let n_chunks = opts.photons.div_ceil(chunk);
    let zero = || ([(empty(), 0.0), (empty(), 0.0)], Fates::default());
    let (counts, fates) = (0..n_chunks)
        .into_par_iter()
        .map(|c| {
            let mut acc = zero();
            for i in c * chunk..((c + 1) * chunk).min(opts.photons) {
                let mut rng = PhotonRng::new(opts.seed ^ (stream << 48), i);
                tally(part, grid, &frames, &inc, &mut rng, &mut acc);
            }
            acc
        })
        .reduce(zero, |mut a, b| {
            for k in 0..2 {
                add(&mut a.0[k], &b.0[k]);
            }
            a.1.reflected += b.1.reflected;
            a.1.transmitted += b.1.transmitted;
            a.1.absorbed += b.1.absorbed;
            a.1.lost += b.1.lost;
            a
        });
    let n = opts.photons as f64;
    let block = |k: usize| Block {
        tis: counts[k].1 / n,
        line: 0,
        values: to_bsdf(grid, &frames[k], &counts[k].0, n),
    };
    let f = Fates {
        reflected: fates.reflected / n,
        transmitted: fates.transmitted / n,
        absorbed: fates.absorbed / n,
        lost: fates.lost / n,
    };
    (block(0), block(1), f)
}

fn add(a: &mut Counts, b: &Counts) {
    for (ra, rb) in a.0.iter_mut().zip(&b.0) {
        for (x, y) in ra.iter_mut().zip(rb) {
            *x += y;
        }
    }
    a.1 += b.1;
}

/// Follow one photon and count it.
fn tally(
    part: &Part,
    grid: &Grid,
    frames: &[Frame; 2],
    inc: &Incidence,
    rng: &mut PhotonRng,
    acc: &mut ([Counts; 2], Fates),
) {
    match part.walk(inc.d, rng) {
        Err(()) => acc.1.lost += 1.0,
        Ok(None) => acc.1.absorbed += 1.0,
        Ok(Some((reflected, w))) => {
            let k = if reflected {
                acc.1.reflected += 1.0;
                0
            } else {
                acc.1.transmitted += 1.0;
                1
            };
            let (r, phi) = frames[k].angles(w);
            if let Some((ia, ir)) = grid.cell_of(r, phi) {
                acc.0[k].0[ia][ir] += 1.0;
            }
            acc.0[k].1 += 1.0;
        }
    }
}

/// BSDF values from cell counts of `n` photons: each cell's share over its projected
/// solid angle in `frame`.
fn to_bsdf(grid: &Grid, frame: &Frame, counts: &[Vec<f64>], n: f64) -> Vec<Vec<f64>> {
    counts
        .iter()
        .enumerate()
        .map(|(ia, row)| {
            row.iter()
                .enumerate()
                .map(|(ir, c)| {
                    let psa = grid.projected_solid_angle(frame, ia, ir, 16);
                    if *c > 0.0 && psa > 0.0 {
                        c / n / psa
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}
