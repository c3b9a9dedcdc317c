//! An opaque surface model named in a scene file by a keyword or a table: what a lamp body
//! carries (`body = ...`, [`crate::sources::body`]) and what the back of a surface carries
//! (`back = ...`, [`super::two_sided`]).
//!
//! ```toml
//! back = "absorber"                             # every photon that meets it ends there
//! back = { model = "lambert", albedo = 0.05 }   # or "phong", "mirror", "absorber"
//! ```
//!
//! Any registered model whose light stays on its side may stand here, with the fields it
//! has in `[surfaces.*]`; one that lets light through (a dielectric, dots, grooves, a
//! diffuser, a polarizer) is refused, naming the field.

use super::absorber::Absorber;
use super::medium::Medium;
use super::surface::{SurfaceModel, SurfaceSpec};
use crate::spec_check::Ctx;
use anyhow::Result;
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};
use std::fmt;
use std::path::PathBuf;

/// `"absorber"` or an opaque surface model's table.
#[derive(Clone, Debug, Default)]
pub enum OpaqueSpec {
    /// Every photon that meets it is absorbed.
    #[default]
    Absorber,
    /// A registered model whose light stays on its side, with its `[surfaces.*]` fields.
    Model(Box<SurfaceSpec>),
}

impl Serialize for OpaqueSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            OpaqueSpec::Absorber => s.serialize_str("absorber"),
            OpaqueSpec::Model(m) => m.serialize(s),
        }
    }
}

impl schemars::JsonSchema for OpaqueSpec {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "OpaqueSpec".into()
    }

    /// What `OpaqueVisitor` reads: `"absorber"` or a model's table.
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let model = generator.subschema_for::<SurfaceSpec>();
        crate::scene::schema::one_of(
            "An opaque surface model: \"absorber\" (every photon that meets it ends there) or a table of a model that keeps light on its side (lambert, phong, mirror, absorber), with its [surfaces.*] keys.",
            vec![schemars::json_schema!({ "const": "absorber" }), model],
        )
    }
}

impl<'de> Deserialize<'de> for OpaqueSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(OpaqueVisitor)
    }
}

/// Reads `"absorber"` or a table with `model`, with serde's own message for a bad table
/// (an unknown model or field names itself).
pub(crate) struct OpaqueVisitor;

impl<'de> Visitor<'de> for OpaqueVisitor {
    type Value = OpaqueSpec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("\"absorber\" or a table such as { model = \"lambert\", albedo = 0.45 }")
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<OpaqueSpec, E> {
        match v {
            "absorber" => Ok(OpaqueSpec::Absorber),
            other => Err(E::invalid_value(de::Unexpected::Str(other), &self)),
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<OpaqueSpec, A::Error> {
        SurfaceSpec::deserialize(de::value::MapAccessDeserializer::new(map))
            .map(|s| OpaqueSpec::Model(Box::new(s)))
    }
}

impl OpaqueSpec {
    /// Check the table at `at` and build its model; `what` says what must be opaque (for
    /// the message when the model lets light through: "a lamp body").
    pub fn build(&self, ctx: &Ctx, at: &str, media: &[Medium], what: &str) -> Result<SurfaceModel> {
        let spec = match self {
            OpaqueSpec::Absorber => return Ok(SurfaceModel::Absorber(Absorber)),
            OpaqueSpec::Model(spec) => spec,
        };
        let model = spec.build(ctx, at, media)?;
        if model.lets_light_through() {
            return Err(ctx.err(
                &format!("{at}.model"),
                format!(
                    "'{}' lets light through; {what} is opaque: lambert, phong, mirror or absorber",
                    model.kind()
                ),
            ));
        }
        Ok(model)
    }

    /// The files the model reads, relative to the scene file (for the content hash).
    pub fn files(&self) -> Vec<PathBuf> {
        match self {
            OpaqueSpec::Absorber => Vec::new(),
            OpaqueSpec::Model(spec) => spec.files(),
        }
    }
}
