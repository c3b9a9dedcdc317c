//! What every surface model implements: its scene-file table checks itself and builds
//! the model ([`SurfaceSpecOf`]), and the model says what a photon meets at its surface
//! ([`Surface`], given the photon's [`Arrival`]). The models live in their own modules
//! and are registered in [`super::surface`].

use super::medium::{Interface, Medium, MediumId};
use super::polarization::Polarization;
use super::spectrum::{Light, Spectral};
use crate::estimator::Estimator;
use crate::geometry::{Mesh, SurfaceHit};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use std::cell::Cell;
use std::path::PathBuf;

/// A model's scene-file table: it checks itself and builds the model.
pub trait SurfaceSpecOf {
    /// The model it builds.
    type Model;

    /// Check the table at `at` (`surfaces.TAG`, or a lamp's `sources[i].body`, whose
    /// fields are named `AT.FIELD` in errors) and build the model.
    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<Self::Model>;

    /// The files the model reads (measured tables), relative to the scene file: the
    /// content hash covers their bytes, so shards of a changed table do not merge.
    fn files(&self) -> Vec<PathBuf> {
        Vec::new()
    }
}

/// A model's physics: what a photon meets at its surface.
pub trait Surface {
    /// Roulette the fate of the photon arriving as `at` says; and what part of a
    /// patterned face it met.
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature);

    /// The two media of a dielectric-like face (`None`: opaque, light stays on its side).
    fn interface(&self) -> Option<Interface> {
        None
    }

    /// What an event of this model that met `feature` is to the luminance meter's
    /// estimator ([`MeterVertex`]). By default [`MeterVertex::Unevaluated`]: the meter
    /// counts the light such an event sends out as the cone does.
    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        MeterVertex::Unevaluated
    }

    /// For a [`MeterVertex::Diffuse`] event of the photon `at` that met `feature`: the
    /// probability density (per steradian, the albedo included) that the light leaves
    /// along unit `out`, the density [`Surface::interact`] samples from.
    fn meter_density(&self, _at: &Arrival, _feature: Feature, _out: DVec3) -> f64 {
        0.0
    }

    /// For a diffuse or stochastic event of the photon `at` that met `feature`: an
    /// unbiased estimate of the density (per sr, the albedo included) that its light
    /// leaves along unit `out`, weighted by `response` of the polarization it leaves with
    /// (`None`: unpolarized, or polarization not traced). By default the density times the
    /// response of unpolarized light (a model that leaves no state depolarizes).
    fn meter_response(
        &self,
        at: &Arrival,
        feature: Feature,
        out: DVec3,
        response: &dyn Fn(Option<&Polarization>) -> f64,
        _rng: &mut PhotonRng,
    ) -> f64 {
        self.meter_density(at, feature, out) * response(None)
    }

    /// Whether the meter's backward walk crosses this model's face ([`MeterLayer`]). By
    /// default not: its peel-off ends there.
    fn meter_layer(&self) -> MeterLayer {
        MeterLayer::Not
    }

    /// Move the model's anchor points (a pattern's origin) with the scene by `by` (mm).
    fn translate(&mut self, _by: DVec3) {}

    /// Fit the model to the face it lies on and check it against the face.
    fn fit_to_face(&mut self, _ctx: &Ctx, _at: &str, _face: &Face) -> Result<()> {
        Ok(())
    }
}

/// The triangles of one tag, as a model fits itself to them.
pub struct Face<'a> {
    /// The scene's mesh.
    pub mesh: &'a Mesh,
    /// The tag's index in the mesh.
    pub tag: u32,
}

impl Face<'_> {
    /// The unit normals of the face's triangles (oriented outward by then).
    pub fn normals(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.triangles().map(|p| self.mesh.normal(p))
    }

    /// The farthest vertex of the face from `origin` (mm).
    pub fn reach(&self, origin: DVec3) -> f64 {
        self.triangles()
            .flat_map(|p| self.mesh.corners(p).map(|v| v.distance(origin)))
            .fold(0.0, f64::max)
    }

    fn triangles(&self) -> impl Iterator<Item = u32> + '_ {
        let tag = self.tag;
        (0..self.mesh.len() as u32).filter(move |&p| self.mesh.tri_tag[p as usize] == tag)
    }
}

/// A photon arriving at a surface: what every model's [`Surface::interact`] reads.
pub struct Arrival<'a> {
    /// The scene's media.
    pub media: &'a [Medium],
    /// Where it hit (point, outward unit normal).
    pub hit: &'a SurfaceHit,
    /// Its unit direction.
    pub dir: DVec3,
    /// The medium it travels in.
    pub medium: MediumId,
    /// Analog roulette or absorption by weights.
    pub est: Estimator,
    /// Its light: the optical quantities it meets are read at it ([`super::spectrum`]).
    pub light: Light,
    /// Its polarization, when the run traces it ([`super::polarization`]).
    pub pol: Option<Polarization>,
    /// Where a model that keeps polarization (interfaces, mirrors, polarizers) puts the
    /// state of the light that leaves; left `None`, the light leaves unpolarized (every
    /// diffuse model).
    pub pol_out: &'a Cell<Option<Polarization>>,
    /// Where a model that traces a thin layer (grooves) puts the offset, in the face, from
    /// the hit point to where the light's outgoing ray crosses the face (the light leaves
    /// along that line); left zero, it leaves from the hit point.
    pub shift_out: &'a Cell<DVec3>,
}

impl Arrival<'_> {
    /// The unit normal on the side the photon came from.
    #[inline]
    pub fn facing(&self) -> DVec3 {
        if self.dir.dot(self.hit.normal) < 0.0 {
            self.hit.normal
        } else {
            -self.hit.normal
        }
    }

    /// An opaque reflection: survival of the albedo (read at the photon's light) by the
    /// estimator, then a direction from `sample` back into the photon's medium (`None`:
    /// absorbed there).
    #[inline]
    pub fn reflect(
        &self,
        albedo: &Spectral,
        rng: &mut PhotonRng,
        sample: impl FnOnce(&mut PhotonRng) -> Option<DVec3>,
    ) -> Outcome {
        let Some(weight) = self.est.survive(albedo.at(self.light), rng) else {
            return Outcome::Absorbed;
        };
        match sample(rng) {
            Some(dir) => Outcome::Scattered {
                dir,
                medium: self.medium,
                weight,
            },
            None => Outcome::Absorbed,
        }
    }

    /// A lossless interface's outcome: the photon leaves along `dir` into `i`'s inside
    /// or outside medium.
    #[inline]
    pub fn lossless(&self, i: &Interface, (dir, inside): (DVec3, bool)) -> Outcome {
        Outcome::Scattered {
            dir,
            medium: if inside { i.inside } else { i.outside },
            weight: 1.0,
        }
    }

    /// The refractive indices inside and outside `i`.
    #[inline]
    pub fn indices(&self, i: &Interface) -> (f64, f64) {
        (
            self.media[i.inside as usize].index(self.light),
            self.media[i.outside as usize].index(self.light),
        )
    }
}

/// What a surface did to a photon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    /// The photon leaves in `dir`, now travelling in `medium`, its weight multiplied by
    /// `weight` (1 in analog mode; the surface's reflectance when absorption is weighted).
    Scattered {
        /// New unit direction.
        dir: DVec3,
        /// Medium the photon now travels in.
        medium: MediumId,
        /// Factor applied to the photon's weight.
        weight: f64,
    },
    /// The photon was absorbed by this surface.
    Absorbed,
}

/// What an event is to the luminance meter's estimator (the tracer's `meter`): its
/// peel-off evaluates, at every diffuse event, the light that leaves towards the meter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeterVertex {
    /// A specular event (a smooth interface, a mirror, a polarizer, a groove facet): its
    /// direction follows from the one it met, so the peel-off path goes through it.
    Specular,
    /// A diffuse event whose density the model evaluates ([`Surface::meter_density`]):
    /// the peel-off starts there.
    Diffuse,
    /// A scattering event whose density the model estimates without bias rather than
    /// evaluates ([`Surface::meter_response`]: a rough face's walk): the backward peel-off
    /// starts there; the flat-layer one counts its light in the cone.
    Stochastic,
    /// A scattering event whose density the model does not evaluate (a measured table):
    /// the light it sends out is counted in the cone.
    Unevaluated,
}

/// What a model's face is to the meter's backward walk (`tracer::meter_walk`), which
/// crosses layers the same at every point of the target from the target down to a
/// diffuse event, then moves the path sideways to the event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeterLayer {
    /// Not crossed: patterned (dots), diffuse, or not checked for the backward walk's
    /// reciprocity (measured tables): the walk ends there with nothing.
    Not,
    /// Crossed: a face the same everywhere whose events keep `n t` (a smooth interface,
    /// a mirror, a polarizer sheet).
    Flat,
    /// Crossed: a face the same everywhere (on the scale of the map's bins) whose
    /// specular events turn `n t` (a prism film's uniform grooves).
    Turning,
}

/// What part of a patterned face a hit met (see `SurfaceModel::interact_on`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// The plain surface (every unpatterned model, and dotted faces between dots).
    Plain,
    /// Ink of a dots pattern.
    Ink,
    /// A groove (or prism) of a grooves pattern.
    Groove,
}
