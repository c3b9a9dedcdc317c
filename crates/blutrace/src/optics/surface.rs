//! The optical model of each tagged surface: the registry of models and the dispatch of a
//! photon to the one it hit.
//!
//! Each model has its own module with its scene-file table (a spec that checks itself and
//! builds the model, [`SurfaceSpecOf`]) and its physics ([`Surface`]), the traits of
//! [`super::model`]:
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
use super::dielectric::DielectricSpec;
use super::diffuser::{Diffuser, DiffuserSpec};
use super::dots::{Dots, DotsSpec};
use super::grooves::{Grooves, GroovesSpec};
use super::lambert::{Lambert, LambertSpec};
use super::mirror::{Mirror, MirrorSpec};
use super::phong::{Phong, PhongSpec};
use super::spectrum::Light;
use crate::geometry::SurfaceHit;
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

// Re-exported for the callers that name them along with the models (their homes are
// `optics::model`, `optics::medium` and `crate::estimator`).
pub use super::medium::{Interface, Medium, MediumId};
pub use super::model::{
    Arrival, Face, Feature, MeterLayer, MeterVertex, Outcome, Surface, SurfaceSpecOf,
};
pub use crate::estimator::Estimator;

/// Generates [`SurfaceModel`], [`SurfaceSpec`] and their dispatch from the registry.
macro_rules! surface_models {
    ($( $(#[doc = $doc:literal])* $name:literal => $Variant:ident($Model:ty, $Spec:ty), )*) => {
        /// The optical model of one tag: one variant per registered model.
        #[derive(Clone, Debug, PartialEq)]
        pub enum SurfaceModel {
            $( $(#[doc = $doc])* $Variant($Model), )*
        }

        /// A `[surfaces.TAG]` table: `model = "..."` picks the model, whose spec owns the
        /// rest of the table and its checks.
        #[derive(Clone, Debug, Deserialize, Serialize)]
        #[serde(tag = "model")]
        pub enum SurfaceSpec {
            $( $(#[doc = $doc])* #[serde(rename = $name)] $Variant($Spec), )*
        }

        impl SurfaceModel {
            /// [`SurfaceModel::interact`], also saying what part of a patterned face the
            /// photon met (ink, a groove, or the plain surface), for the per-tag hit counts.
            #[inline]
            pub fn interact_on(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
                match self {
                    $( SurfaceModel::$Variant(m) => m.interact(at, rng), )*
                }
            }

            /// What an event that met `feature` is to the luminance meter.
            #[inline]
            pub fn meter_vertex(&self, feature: Feature) -> MeterVertex {
                match self {
                    $( SurfaceModel::$Variant(m) => m.meter_vertex(feature), )*
                }
            }

            /// The density of a diffuse event's light leaving along `out` (per sr).
            pub fn meter_density(&self, at: &Arrival, feature: Feature, out: DVec3) -> f64 {
                match self {
                    $( SurfaceModel::$Variant(m) => m.meter_density(at, feature, out), )*
                }
            }

            /// An estimate of a diffuse event's light leaving along `out`, weighted by
            /// `response` of its polarization ([`Surface::meter_response`]).
            pub fn meter_response(
                &self,
                at: &Arrival,
                feature: Feature,
                out: DVec3,
                response: &dyn Fn(Option<&super::polarization::Polarization>) -> f64,
                rng: &mut PhotonRng,
            ) -> f64 {
                match self {
                    $( SurfaceModel::$Variant(m) => m.meter_response(at, feature, out, response, rng), )*
                }
            }

            /// What the model's face is to the meter's backward walk.
            pub fn meter_layer(&self) -> MeterLayer {
                match self {
                    $( SurfaceModel::$Variant(m) => m.meter_layer(), )*
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
            /// Read a `[surfaces.TAG]` table (`model` and the model's keys); an error
            /// names the key it is about (serde's `tag = "model"` reading loses it).
            pub fn from_table(mut table: toml::Table) -> Result<SurfaceSpec, String> {
                let model = table.get("model").and_then(toml::Value::as_str).map(str::to_owned);
                match model.as_deref() {
                    $( Some($name) => {
                        table.remove("model");
                        crate::spec_check::keyed::<$Spec>(&table).map(SurfaceSpec::$Variant)
                    } )*
                    _ => SurfaceSpec::deserialize(toml::Value::Table(table)).map_err(|e| e.to_string()),
                }
            }

            /// Check the table at `at` (`surfaces.TAG`, or a lamp's `sources[i].body`) and
            /// build its model.
            pub fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<SurfaceModel> {
                Ok(match self {
                    $( SurfaceSpec::$Variant(s) => SurfaceModel::$Variant(s.build(ctx, at, media)?), )*
                })
            }

            /// The files the model reads, relative to the scene file (for the content hash).
            pub fn files(&self) -> Vec<PathBuf> {
                match self {
                    $( SurfaceSpec::$Variant(s) => s.files(), )*
                }
            }

            /// One closed table per registered model, `model = "..."` required in each,
            /// with the `extra` keys every such table may carry (a surface's `back`).
            pub fn model_schemas(
                generator: &mut schemars::SchemaGenerator,
                extra: &[(&str, schemars::Schema)],
            ) -> Vec<schemars::Schema> {
                vec![$(
                    crate::scene::schema::tagged::<$Spec>(
                        generator, "model", $name, concat!($($doc),*).trim(), extra,
                    ),
                )*]
            }
        }

        impl schemars::JsonSchema for SurfaceSpec {
            fn schema_name() -> std::borrow::Cow<'static, str> {
                "SurfaceSpec".into()
            }

            fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
                crate::scene::schema::one_of(
                    "A surface model's table: `model` picks the model, whose keys follow.",
                    SurfaceSpec::model_schemas(generator, &[]),
                )
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
    /// Absorbing or reflective polarizer sheet ([`super::polarizer`]).
    "polarizer" => Polarizer(super::polarizer::Polarizer, super::polarizer::PolarizerSpec),
    /// Measured BSDF table, IS BSDF format ([`super::bsdf_table`]).
    "bsdf_table" => BsdfTable(super::bsdf_table::BsdfTable, super::bsdf_table::BsdfTableSpec),
}

impl SurfaceModel {
    /// Whether light can cross the face: a dielectric-like model, or a polarizer sheet
    /// (the same medium on both sides, so no [`SurfaceModel::interface`], yet it
    /// transmits). Such a model cannot be a lamp body or a surface's back.
    pub fn lets_light_through(&self) -> bool {
        self.interface().is_some() || matches!(self, SurfaceModel::Polarizer(_))
    }

    /// Roulette the fate of a photon of monochrome light arriving along `dir` in `medium`
    /// at `hit` (the tracer's photons carry their light: [`SurfaceModel::interact_on`]).
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
        let light = Light::MONOCHROME;
        let (pol_out, shift_out) = (
            std::cell::Cell::new(None),
            std::cell::Cell::new(DVec3::ZERO),
        );
        let at = Arrival {
            media,
            hit,
            dir,
            medium,
            est,
            light,
            pol: None,
            pol_out: &pol_out,
            shift_out: &shift_out,
        };
        self.interact_on(&at, rng).0
    }
}
