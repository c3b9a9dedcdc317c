//! The optical model of each tagged surface and its Russian roulette.
//!
//! ```toml
//! [media.pmma]
//! n = 1.49
//! absorption_per_mm = 0.0002   # Beer-Lambert coefficient (natural log), 0 = lossless
//!
//! [surfaces.lgp]               # a tag used by the geometry files
//! model = "dielectric"         # Fresnel/Snell/TIR between `inside` and `outside`
//! inside = "pmma"              # medium the face normal points away from
//! outside = "air"              # default "air" (n = 1)
//!
//! [surfaces.lamp_reflector]
//! model = "phong"              # reflectance, specular fraction, cos^exponent lobe
//! reflectance = 0.95
//! specular = 0.8
//! exponent = 100.0
//!
//! [surfaces.ink_sheet]
//! model = "lambert"
//! albedo = 0.9
//!
//! [surfaces.silver]
//! model = "mirror"
//! reflectance = 0.97
//!
//! [surfaces.housing]
//! model = "absorber"
//! ```
//!
//! Opaque models (phong, lambert, mirror, absorber, dot ink) reflect back to the side
//! the photon came from; a dielectric sends it to the other side's medium. Procedural
//! `grooves` (V-grooves, prism films) and rough `diffuser` faces are dielectric
//! interfaces too: see [`super::grooves`] and [`super::diffuser`] for their files and
//! models.

use super::dots::DotPattern;
use super::grooves::GroovePattern;
use super::{diffuser, fresnel, sampling};
use crate::geometry::SurfaceHit;
use crate::rng::PhotonRng;
use glam::DVec3;

/// Index of a medium in the scene's medium table (0 is the ambient medium, air).
pub type MediumId = u16;

/// A homogeneous optical medium.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    /// Name from the scene file.
    pub name: String,
    /// Refractive index.
    pub n: f64,
    /// Beer-Lambert absorption coefficient (1/mm).
    pub absorption_per_mm: f64,
}

/// The two media either side of a dielectric face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// The medium behind the face (the normal points away from it).
    pub inside: MediumId,
    /// The medium in front of the face.
    pub outside: MediumId,
}

/// A Phong reflector (lamp reflector, reflector sheet).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    /// Total reflectance (diffuse + specular).
    pub reflectance: f64,
    /// Fraction of the reflected energy in the specular lobe.
    pub specular: f64,
    /// Phong exponent of the specular lobe.
    pub exponent: f64,
}

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

/// How surface absorption is sampled.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Estimator {
    /// The paper's analog tracing: absorbed or not by Russian roulette on the albedo.
    #[default]
    Analog,
    /// Absorption by weights: the photon always scatters and carries the albedo as a
    /// weight factor (and exp(-a t) through absorbing media); Russian roulette only once
    /// its weight is low. Unbiased, lower variance where absorption is strong.
    Weighted,
}

/// A reflection that keeps `albedo` of the photon: roulette (analog) or a weight factor.
fn survive(albedo: f64, est: Estimator, rng: &mut PhotonRng) -> Option<f64> {
    match est {
        Estimator::Analog => (rng.uniform() < albedo).then_some(1.0),
        Estimator::Weighted => (albedo > 0.0).then_some(albedo),
    }
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
        // Normal on the side the photon came from.
        let facing = if dir.dot(hit.normal) < 0.0 {
            hit.normal
        } else {
            -hit.normal
        };
        let reflect =
            |albedo: f64, rng: &mut PhotonRng, sample: &dyn Fn(&mut PhotonRng) -> Option<DVec3>| {
                let Some(weight) = survive(albedo, est, rng) else {
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
        let lambert =
            |rng: &mut PhotonRng| Some(sampling::lambertian(facing, rng.uniform(), rng.uniform()));
        match self {
            SurfaceModel::Dielectric(i) => dielectric(media, i, hit.normal, dir, rng),
            SurfaceModel::Dots {
                interface,
                pattern,
                ink_albedo,
            } => {
                if pattern.covers(hit.point) {
                    reflect(*ink_albedo, rng, &lambert)
                } else {
                    dielectric(media, interface, hit.normal, dir, rng)
                }
            }
            SurfaceModel::Grooves { interface, pattern } => {
                let n = (
                    media[interface.inside as usize].n,
                    media[interface.outside as usize].n,
                );
                match pattern.scatter(n, hit.point, hit.normal, dir, rng) {
                    Some((dir, inside)) => Outcome::Scattered {
                        dir,
                        medium: if inside {
                            interface.inside
                        } else {
                            interface.outside
                        },
                        weight: 1.0,
                    },
                    None => dielectric(media, interface, hit.normal, dir, rng),
                }
            }
            SurfaceModel::Diffuser {
                interface,
                roughness,
            } => {
                let n = (
                    media[interface.inside as usize].n,
                    media[interface.outside as usize].n,
                );
                let (dir, inside) = diffuser::scatter(*roughness, n, hit.normal, dir, rng);
                Outcome::Scattered {
                    dir,
                    medium: if inside {
                        interface.inside
                    } else {
                        interface.outside
                    },
                    weight: 1.0,
                }
            }
            SurfaceModel::Phong(p) => reflect(p.reflectance, rng, &|rng| {
                phong_direction(p, facing, dir, rng)
            }),
            SurfaceModel::Lambert { albedo } => reflect(*albedo, rng, &lambert),
            SurfaceModel::Mirror { reflectance } => {
                reflect(*reflectance, rng, &|_| Some(fresnel::reflect(dir, facing)))
            }
            SurfaceModel::Absorber => Outcome::Absorbed,
        }
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

/// Fresnel roulette at a smooth interface with outward unit `normal`.
fn dielectric(
    media: &[Medium],
    iface: &Interface,
    normal: DVec3,
    dir: DVec3,
    rng: &mut PhotonRng,
) -> Outcome {
    let entering = dir.dot(normal) < 0.0;
    let (from, to, facing) = if entering {
        (iface.outside, iface.inside, normal)
    } else {
        (iface.inside, iface.outside, -normal)
    };
    let (n1, n2) = (media[from as usize].n, media[to as usize].n);
    let cos_i = -dir.dot(facing);
    let r = fresnel::reflectance(cos_i, n1, n2);
    if r >= 1.0 || rng.uniform() < r {
        return Outcome::Scattered {
            dir: fresnel::reflect(dir, facing),
            medium: from,
            weight: 1.0,
        };
    }
    match fresnel::refract(dir, facing, n1, n2) {
        Some(t) => Outcome::Scattered {
            dir: t,
            medium: to,
            weight: 1.0,
        },
        None => Outcome::Scattered {
            dir: fresnel::reflect(dir, facing),
            medium: from,
            weight: 1.0,
        },
    }
}

/// A reflected direction from the Phong BRDF, given that the photon is reflected: diffuse
/// with probability `1 - specular`, else in the cos^n lobe around the mirror direction. A
/// lobe direction below the surface carries no BRDF value: `None` (absorbed there).
fn phong_direction(p: &Phong, facing: DVec3, dir: DVec3, rng: &mut PhotonRng) -> Option<DVec3> {
    if rng.uniform() >= p.specular {
        return Some(sampling::lambertian(facing, rng.uniform(), rng.uniform()));
    }
    let mirror = fresnel::reflect(dir, facing);
    let out = sampling::cos_power(mirror, p.exponent, rng.uniform(), rng.uniform());
    (out.dot(facing) > 0.0).then_some(out)
}
