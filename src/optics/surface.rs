//! The optical model of each tagged surface: the registry of models and the dispatch of a
//! photon to the one it hit.
//!
//! Each model has its own module with its scene-file table (a spec that checks itself and
//! builds the model, [`SurfaceSpecOf`]) and its physics ([`Surface`]):
//! [`super::dielectric`], [`super::dots`], [`super::grooves`], [`super::diffuser`],
//! [`super::phong`], [`super::lambert`], [`super::mirror`] and [`super::absorber`]. The
//! one list below registers them: adding a model is its module and one line there, which
//! gives it its `model = "..."` name in `[surfaces.*]` (and in a lamp's `body` when it is
//! opaque), its variant of [`SurfaceModel`] and [`SurfaceSpec`], and its dispatch.
//!
//! ```toml
//! [surfaces.lgp_front]
//! model = "dielectric"   # the registered name picks the model; the rest is its spec's
//! inside = "pmma"
//! ```
//!
//! Opaque models (phong, lambert, mirror, absorber, dot ink) reflect back to the side
//! the photon came from; a dielectric sends it to the other side's medium. Procedural
//! `grooves` (V-grooves, prism films) and rough `diffuser` faces are dielectric
//! interfaces too.

use super::absorber::{Absorber, AbsorberSpec};
use super::dielectric::{self, DielectricSpec};
use super::diffuser::{Diffuser, DiffuserSpec};
use super::dots::{Dots, DotsSpec};
use super::grooves::{Grooves, GroovesSpec};
use super::lambert::{self, Lambert, LambertSpec};
use super::mirror::{Mirror, MirrorSpec};
use super::phong::{Phong, PhongSpec};
use crate::geometry::{Mesh, SurfaceHit};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

// Re-exported for the callers that name them along with the models (their homes are
// `optics::medium` and `crate::estimator`).
pub use super::medium::{Interface, Medium, MediumId};
pub use crate::estimator::Estimator;

/// Generates [`SurfaceModel`], [`SurfaceSpec`] and their dispatch from the registry.
macro_rules! surface_models {
    ($( $(#[$doc:meta])* $name:literal => $Variant:ident($Model:ty, $Spec:ty), )*) => {
        /// The optical model of one tag: one variant per registered model.
        #[derive(Clone, Debug, PartialEq)]
        pub enum SurfaceModel {
            $( $(#[$doc])* $Variant($Model), )*
        }

        /// A `[surfaces.TAG]` table: `model = "..."` picks the model, whose spec owns the
        /// rest of the table and its checks.
        #[derive(Clone, Debug, Deserialize, Serialize)]
        #[serde(tag = "model")]
        pub enum SurfaceSpec {
            $( $(#[$doc])* #[serde(rename = $name)] $Variant($Spec), )*
        }

        impl SurfaceModel {
            /// [`SurfaceModel::interact`], also saying what part of a patterned face the
            /// photon met (ink, a groove, or the plain surface), for the per-tag hit counts.
            #[inline]
            pub fn interact_on(
                &self,
                media: &[Medium],
                hit: &SurfaceHit,
                dir: DVec3,
                medium: MediumId,
                est: Estimator,
                rng: &mut PhotonRng,
            ) -> (Outcome, Feature) {
                let at = Arrival { media, hit, dir, medium, est };
                match self {
                    $( SurfaceModel::$Variant(m) => m.interact(&at, rng), )*
                }
            }

            /// The model's name in the scene file.
            pub fn kind(&self) -> &'static str {
                match self {
                    $( SurfaceModel::$Variant(_) => $name, )*
                }
            }

            /// The interface of a dielectric-like model (`None`: opaque).
            pub fn interface(&self) -> Option<Interface> {
                match self {
                    $( SurfaceModel::$Variant(m) => m.interface(), )*
                }
            }

            /// Move the model's anchor points with the scene by `by` (mm).
            pub fn translate(&mut self, by: DVec3) {
                match self {
                    $( SurfaceModel::$Variant(m) => m.translate(by), )*
                }
            }

            /// Fit the model to its `face` and check it against the face (`at`: its table,
            /// `surfaces.TAG`, for messages); runs after the faces are oriented.
            pub fn fit_to_face(&mut self, ctx: &Ctx, at: &str, face: &Face) -> Result<()> {
                match self {
                    $( SurfaceModel::$Variant(m) => m.fit_to_face(ctx, at, face), )*
                }
            }
        }

        impl SurfaceSpec {
            /// Check the table at `at` (`surfaces.TAG`, or a lamp's `sources[i].body`) and
            /// build its model.
            pub fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<SurfaceModel> {
                match self {
                    $( SurfaceSpec::$Variant(s) => s.build(ctx, at, media), )*
                }
            }

            /// The files the model reads, relative to the scene file (for the content hash).
            pub fn files(&self) -> Vec<PathBuf> {
                match self {
                    $( SurfaceSpec::$Variant(s) => s.files(), )*
                }
            }
        }
    };
}

// The registry: one line per model.
surface_models! {
    /// Smooth dielectric interface ([`super::dielectric`]).
    "dielectric" => Dielectric(Interface, DielectricSpec),
    /// Dielectric interface with printed Lambertian ink dots ([`super::dots`]).
    "dots" => Dots(Dots, DotsSpec),
    /// Dielectric interface carrying procedural V-grooves or prisms ([`super::grooves`]).
    "grooves" => Grooves(Grooves, GroovesSpec),
    /// Rough (diffusing) dielectric interface ([`super::diffuser`]).
    "diffuser" => Diffuser(Diffuser, DiffuserSpec),
    /// Phong reflector ([`super::phong`]).
    "phong" => Phong(Phong, PhongSpec),
    /// Lambertian scatterer ([`super::lambert`]).
    "lambert" => Lambert(Lambert, LambertSpec),
    /// Specular mirror ([`super::mirror`]).
    "mirror" => Mirror(Mirror, MirrorSpec),
    /// Black absorber ([`super::absorber`]).
    "absorber" => Absorber(Absorber, AbsorberSpec),
}

/// A model's scene-file table: it checks itself and builds the model.
pub trait SurfaceSpecOf {
    /// Check the table at `at` (`surfaces.TAG`, or a lamp's `sources[i].body`, whose
    /// fields are named `AT.FIELD` in errors) and build the model.
    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<SurfaceModel>;

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

    /// An opaque reflection: survival of the albedo by the estimator, then a direction
    /// from `sample` back into the photon's medium (`None`: absorbed there).
    #[inline]
    pub fn reflect(
        &self,
        albedo: f64,
        rng: &mut PhotonRng,
        sample: impl FnOnce(&mut PhotonRng) -> Option<DVec3>,
    ) -> Outcome {
        let Some(weight) = self.est.survive(albedo, rng) else {
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

    /// A Lambertian direction back into the photon's side.
    #[inline]
    pub fn lambertian(&self, rng: &mut PhotonRng) -> Option<DVec3> {
        Some(lambert::direction(self.facing(), rng))
    }

    /// Fresnel roulette at the smooth interface `i`.
    #[inline]
    pub fn smooth(&self, i: &Interface, rng: &mut PhotonRng) -> Outcome {
        let (dir, medium) = dielectric::scatter(self.media, i, self.hit.normal, self.dir, rng);
        Outcome::Scattered {
            dir,
            medium,
            weight: 1.0,
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
            self.media[i.inside as usize].n,
            self.media[i.outside as usize].n,
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

/// What part of a patterned face a hit met (see [`SurfaceModel::interact_on`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// The plain surface (every unpatterned model, and dotted faces between dots).
    Plain,
    /// Ink of a dots pattern.
    Ink,
    /// A groove (or prism) of a grooves pattern.
    Groove,
}

impl SurfaceModel {
    /// Roulette the fate of a photon arriving along `dir` in `medium` at `hit`.
    #[inline]
    pub fn interact(
        &self,
        media: &[Medium],
        hit: &SurfaceHit,
        dir: DVec3,
        medium: MediumId,
        est: Estimator,
        rng: &mut PhotonRng,
    ) -> Outcome {
        self.interact_on(media, hit, dir, medium, est, rng).0
    }
}
