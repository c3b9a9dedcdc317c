//! The optical model of each tagged surface and its Russian roulette.
//!
//! Each model has its own module with its scene-file entry, its checks and its physics:
//! [`super::dielectric`], [`super::dots`], [`super::grooves`], [`super::diffuser`],
//! [`super::phong`], [`super::lambert`], [`super::mirror`] and [`super::absorber`]. Here
//! they meet as one [`SurfaceModel`] per tag, and [`SurfaceModel::interact`] sends a
//! photon to the one it hit.
//!
//! Opaque models (phong, lambert, mirror, absorber, dot ink) reflect back to the side
//! the photon came from; a dielectric sends it to the other side's medium. Procedural
//! `grooves` (V-grooves, prism films) and rough `diffuser` faces are dielectric
//! interfaces too.

use super::dots::DotPattern;
use super::grooves::GroovePattern;
use super::phong::Phong;
use super::{dielectric, diffuser, lambert, mirror};
use crate::geometry::SurfaceHit;
use crate::rng::PhotonRng;
use glam::DVec3;

// Re-exported for the callers that name them along with the models (their homes are
// `optics::medium` and `crate::estimator`).
pub use super::medium::{Interface, Medium, MediumId};
pub use crate::estimator::Estimator;

/// The optical model of one tag.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceModel {
    /// Smooth dielectric interface.
    Dielectric(Interface),
    /// Dielectric interface with printed Lambertian ink dots.
    Dots {
        /// The interface outside the dots.
        interface: Interface,
        /// The dot layout.
        pattern: DotPattern,
        /// Albedo of the ink (the rest is absorbed).
        ink_albedo: f64,
    },
    /// Dielectric interface carrying procedural V-grooves or prisms (see
    /// [`super::grooves`]).
    Grooves {
        /// The two media either side of the relief.
        interface: Interface,
        /// The groove layout.
        pattern: GroovePattern,
    },
    /// Rough (diffusing) dielectric interface (see [`super::diffuser`]).
    Diffuser {
        /// The two media either side.
        interface: Interface,
        /// GGX roughness alpha (0: smooth).
        roughness: f64,
    },
    /// Phong reflector.
    Phong(Phong),
    /// Lambertian scatterer.
    Lambert {
        /// Diffuse reflectance.
        albedo: f64,
    },
    /// Specular mirror.
    Mirror {
        /// Reflectance.
        reflectance: f64,
    },
    /// Black absorber.
    Absorber,
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

    /// [`SurfaceModel::interact`], also saying what part of a patterned face the photon
    /// met (ink, a groove, or the plain surface), for the per-tag hit counts.
    pub fn interact_on(
        &self,
        media: &[Medium],
        hit: &SurfaceHit,
        dir: DVec3,
        medium: MediumId,
        est: Estimator,
        rng: &mut PhotonRng,
    ) -> (Outcome, Feature) {
        // Normal on the side the photon came from.
        let facing = if dir.dot(hit.normal) < 0.0 {
            hit.normal
        } else {
            -hit.normal
        };
        let reflect =
            |albedo: f64, rng: &mut PhotonRng, sample: &dyn Fn(&mut PhotonRng) -> Option<DVec3>| {
                let Some(weight) = est.survive(albedo, rng) else {
                    return Outcome::Absorbed;
                };
                match sample(rng) {
                    Some(dir) => Outcome::Scattered {
                        dir,
                        medium,
                        weight,
                    },
                    None => Outcome::Absorbed,
                }
            };
        let lambert = |rng: &mut PhotonRng| Some(lambert::direction(facing, rng));
        // A lossless interface: the photon leaves into `inside` or `outside`.
        let lossless = |i: &Interface, (dir, inside): (DVec3, bool)| Outcome::Scattered {
            dir,
            medium: if inside { i.inside } else { i.outside },
            weight: 1.0,
        };
        let smooth = |i: &Interface, rng: &mut PhotonRng| {
            let (dir, medium) = dielectric::scatter(media, i, hit.normal, dir, rng);
            Outcome::Scattered {
                dir,
                medium,
                weight: 1.0,
            }
        };
        let indices = |i: &Interface| (media[i.inside as usize].n, media[i.outside as usize].n);
        let plain = match self {
            SurfaceModel::Dielectric(i) => smooth(i, rng),
            SurfaceModel::Dots {
                interface,
                pattern,
                ink_albedo,
            } => {
                if pattern.meets_ink(hit.point, rng) {
                    return (reflect(*ink_albedo, rng, &lambert), Feature::Ink);
                }
                smooth(interface, rng)
            }
            SurfaceModel::Grooves { interface, pattern } => {
                match pattern.scatter_met(indices(interface), hit.point, hit.normal, dir, rng) {
                    Some((d, inside, met)) => {
                        let feature = if met { Feature::Groove } else { Feature::Plain };
                        return (lossless(interface, (d, inside)), feature);
                    }
                    None => smooth(interface, rng),
                }
            }
            SurfaceModel::Diffuser {
                interface,
                roughness,
            } => {
                let out = diffuser::scatter(*roughness, indices(interface), hit.normal, dir, rng);
                lossless(interface, out)
            }
            SurfaceModel::Phong(p) => {
                reflect(p.reflectance, rng, &|rng| p.direction(facing, dir, rng))
            }
            SurfaceModel::Lambert { albedo } => reflect(*albedo, rng, &lambert),
            SurfaceModel::Mirror { reflectance } => {
                reflect(*reflectance, rng, &|_| Some(mirror::direction(dir, facing)))
            }
            SurfaceModel::Absorber => Outcome::Absorbed,
        };
        (plain, Feature::Plain)
    }

    /// Short model name for reports.
    pub fn kind(&self) -> &'static str {
        match self {
            SurfaceModel::Dielectric(_) => "dielectric",
            SurfaceModel::Dots { .. } => "dots",
            SurfaceModel::Grooves { .. } => "grooves",
            SurfaceModel::Diffuser { .. } => "diffuser",
            SurfaceModel::Phong(_) => "phong",
            SurfaceModel::Lambert { .. } => "lambert",
            SurfaceModel::Mirror { .. } => "mirror",
            SurfaceModel::Absorber => "absorber",
        }
    }

    /// The interface of a dielectric-like model.
    pub fn interface(&self) -> Option<Interface> {
        match self {
            SurfaceModel::Dielectric(i)
            | SurfaceModel::Dots { interface: i, .. }
            | SurfaceModel::Grooves { interface: i, .. }
            | SurfaceModel::Diffuser { interface: i, .. } => Some(*i),
            _ => None,
        }
    }
}
