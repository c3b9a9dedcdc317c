//! Lamp bodies: what light returning to a lamp meets.
//!
//! ```toml
//! [[sources]]
//! type = "ccfl"
//! # ...
//! body = { model = "lambert", albedo = 0.45 }   # the tube's phosphor coat, diffuse
//! # body = "absorber"      # the default: every photon that comes back ends there
//! # body = "transparent"   # no body (for scenes that mesh the lamp themselves)
//! # body = { model = "mirror", reflectance = 0.9 }   # or "phong", as [surfaces.*]
//!
//! [[sources]]
//! type = "led"
//! # ...
//! body = { model = "lambert", albedo = 0.6 }
//! package_depth_mm = 0.6   # optional: a box package behind the emitting rectangle
//! ```
//!
//! A body is an opaque surface model ([`crate::optics::surface::SurfaceModel`]: lambert,
//! phong, mirror or absorber, with the same fields as in `[surfaces.*]`) on an exact
//! analytic shape ([`super::body_shape`]): a CCFL's closed cylinder (its emitting surface
//! with end discs); an LED's emitting rectangle, whose back (the package) absorbs; or,
//! with `package_depth_mm`, a box package whose every face carries the body's model.
//! What a body absorbs is booked to its source (`absorbed_by_source_w` in summary.json).
//!
//! A stand-in, not the lamp's optics: the body is a single opaque surface. A CCFL's glass
//! wall, its Fresnel reflections and the light that the phosphor re-emits are left out, as
//! are an LED's silicone dome, its lead frame and the die's own reflectance map.

use super::Emitter;
use super::body_shape::{BodyHit, BodyShape};
use crate::geometry::Ray;
use crate::optics::medium::Medium;
use crate::optics::opaque::{OpaqueSpec, OpaqueVisitor};
use crate::optics::surface::SurfaceModel;
use crate::spec_check::Ctx;
use anyhow::Result;
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};
use std::fmt;

/// A source's `body`: `"transparent"`, or an opaque surface model
/// ([`OpaqueSpec`]: `"absorber"`, the default, or a model's table).
#[derive(Clone, Debug)]
pub enum BodySpec {
    /// No body: returning light passes through the lamp.
    Transparent,
    /// An opaque surface model on the body.
    Opaque(OpaqueSpec),
}

impl Default for BodySpec {
    /// Every photon that meets the body is absorbed.
    fn default() -> Self {
        BodySpec::Opaque(OpaqueSpec::Absorber)
    }
}

impl Serialize for BodySpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            BodySpec::Transparent => s.serialize_str("transparent"),
            BodySpec::Opaque(o) => o.serialize(s),
        }
    }
}

impl schemars::JsonSchema for BodySpec {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "BodySpec".into()
    }

    /// What `BodyVisitor` reads: `"transparent"`, or what [`OpaqueSpec`] reads.
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let opaque = generator.subschema_for::<OpaqueSpec>();
        crate::scene::schema::one_of(
            "What light returning to the lamp meets: \"absorber\" (the default), \"transparent\" (no body, for scenes that mesh the lamp themselves) or an opaque model's table.",
            vec![schemars::json_schema!({ "const": "transparent" }), opaque],
        )
    }
}

impl<'de> Deserialize<'de> for BodySpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(BodyVisitor)
    }
}

/// Reads `"transparent"`, or what [`OpaqueSpec`] reads.
struct BodyVisitor;

impl<'de> Visitor<'de> for BodyVisitor {
    type Value = BodySpec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(
            "\"absorber\", \"transparent\" or a table such as { model = \"lambert\", albedo = 0.45 }",
        )
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<BodySpec, E> {
        match v {
            "transparent" => Ok(BodySpec::Transparent),
            "absorber" => Ok(BodySpec::Opaque(OpaqueSpec::Absorber)),
            other => Err(E::invalid_value(de::Unexpected::Str(other), &self)),
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<BodySpec, A::Error> {
        OpaqueVisitor.visit_map(map).map(BodySpec::Opaque)
    }
}

impl BodySpec {
    /// Check `sources[i].body` (at `at`) and build its surface model (`None`:
    /// transparent): an opaque one, light stays outside the lamp.
    pub fn model(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<Option<SurfaceModel>> {
        match self {
            BodySpec::Transparent => Ok(None),
            BodySpec::Opaque(o) => o.build(ctx, at, media, "a lamp body").map(Some),
        }
    }
}

/// An opaque lamp body: its shape and the surface model light meets there.
#[derive(Clone, Debug, PartialEq)]
pub struct LampBody {
    /// The exact shape.
    pub shape: BodyShape,
    /// The opaque model of its (front) surface.
    pub model: SurfaceModel,
}

impl LampBody {
    /// The body of `emitter`: its tube, its emitting rectangle, or a box package
    /// `package_depth` deep behind that rectangle.
    pub fn new(emitter: &Emitter, model: SurfaceModel, package_depth: Option<f64>) -> Self {
        let shape = match (emitter.rect(), package_depth) {
            (Some(front), Some(depth)) => BodyShape::Package { front, depth },
            _ => emitter.shape(),
        };
        Self { shape, model }
    }

    /// Where `ray` first enters the body within `(0, t_max)`.
    pub fn hit(&self, ray: &Ray, t_max: f64) -> Option<BodyHit> {
        self.shape.hit(ray, t_max)
    }

    /// A description for `check`: shape and model.
    pub fn describe(&self) -> String {
        let shape = match &self.shape {
            BodyShape::Cylinder {
                radius,
                half_length,
                ..
            } => format!(
                "closed cylinder r = {radius} mm, {} mm long",
                2.0 * half_length
            ),
            BodyShape::Rectangle(r) => format!(
                "emitting rectangle {} x {} mm, back absorbs",
                2.0 * r.half_width,
                2.0 * r.half_height
            ),
            BodyShape::Package { front, depth } => format!(
                "box package {} x {} x {depth} mm",
                2.0 * front.half_width,
                2.0 * front.half_height
            ),
        };
        let model = match &self.model {
            SurfaceModel::Lambert(l) => format!("lambert, albedo {}", l.albedo),
            SurfaceModel::Mirror(m) => format!("mirror, reflectance {}", m.reflectance),
            SurfaceModel::Phong(p) => format!(
                "phong, reflectance {}, specular {}, exponent {}",
                p.reflectance, p.specular, p.exponent
            ),
            other => other.kind().to_string(),
        };
        format!("{shape}; {model}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::surface::SurfaceSpec;

    #[derive(Deserialize, Serialize)]
    struct Holder {
        body: BodySpec,
    }

    fn parse(s: &str) -> Result<BodySpec, String> {
        toml::from_str::<Holder>(s)
            .map(|h| h.body)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn keywords_and_tables_parse_and_round_trip() {
        assert!(matches!(
            parse(r#"body = "absorber""#),
            Ok(BodySpec::Opaque(OpaqueSpec::Absorber))
        ));
        assert!(matches!(
            parse(r#"body = "transparent""#),
            Ok(BodySpec::Transparent)
        ));
        let b = parse(r#"body = { model = "lambert", albedo = 0.45 }"#).unwrap();
        let BodySpec::Opaque(OpaqueSpec::Model(spec)) = &b else {
            panic!("{b:?}")
        };
        let SurfaceSpec::Lambert(l) = spec.as_ref() else {
            panic!("{b:?}")
        };
        assert_eq!(l.albedo.constant(), Some(0.45));
        let text = toml::to_string(&Holder { body: b }).unwrap();
        let again = parse(&text).unwrap();
        assert!(
            matches!(&again, BodySpec::Opaque(OpaqueSpec::Model(s)) if matches!(**s, SurfaceSpec::Lambert(_))),
            "{again:?}"
        );
    }

    #[test]
    fn bad_bodies_say_what_is_allowed() {
        let e = parse(r#"body = "black""#).unwrap_err();
        assert!(e.contains("\"absorber\", \"transparent\""), "{e}");
        let e = parse(r#"body = { model = "velvet" }"#).unwrap_err();
        assert!(e.contains("velvet") && e.contains("lambert"), "{e}");
        let e = parse(r#"body = { model = "lambert", albedo = 0.4, colour = 1 }"#).unwrap_err();
        assert!(e.contains("colour"), "{e}");
    }

    #[test]
    fn albedo_is_checked_at_the_body_field() {
        let b = parse(r#"body = { model = "lambert", albedo = 1.5 }"#).unwrap();
        let e = b
            .model(&Ctx(std::path::Path::new("s.toml")), "sources[2].body", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("s.toml: sources[2].body.albedo"), "{e}");
    }

    /// Any registered model may be a body's, as long as light stays outside the lamp.
    #[test]
    fn a_body_that_lets_light_through_is_refused() {
        let media = [
            Medium::clear("air", 1.0, 0.0),
            Medium::clear("pmma", 1.49, 0.0),
        ];
        let ctx = Ctx(std::path::Path::new("s.toml"));
        let b = parse(r#"body = { model = "dielectric", inside = "pmma" }"#).unwrap();
        let e = b
            .model(&ctx, "sources[0].body", &media)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("sources[0].body.model") && e.contains("lamp body is opaque"),
            "{e}"
        );
        let b = parse(r#"body = { model = "mirror", reflectance = 0.9 }"#).unwrap();
        let m = b.model(&ctx, "sources[0].body", &media).unwrap().unwrap();
        assert_eq!(m.kind(), "mirror");
    }
}
