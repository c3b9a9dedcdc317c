//! Two-sided surfaces: a `[surfaces.*]` table of an opaque model may give another opaque
//! model for its back, the side opposite the triangles' normals.
//!
//! ```toml
//! [surfaces.reflector_sheet]
//! model = "lambert"
//! albedo = 0.95
//! back = "absorber"     # or a table: back = { model = "lambert", albedo = 0.05 }
//! ```
//!
//! A reflector sheet white on top and black below, a one-sided mirror film, a holder
//! painted inside: a photon arriving against the triangle's normal (from the side it
//! points to) meets the front model, one arriving along it the back model. The normal is
//! the triangle's as wound in its geometry file (an opaque face bounds no solid, so the
//! solids' orientation leaves it alone); `blutrace check` counts each tag's triangles by the axis their normal
//! points along, so which side is the front can be read off. Without `back` both sides
//! carry the same model. A dielectric-like face (dielectric, dots, grooves, diffuser) has
//! no back: its two sides are its two media. A `bsdf_table` gives its back as measured
//! tables (`back_file`) instead, with or without light through it.

use super::medium::Medium;
use super::opaque::OpaqueSpec;
use super::surface::{SurfaceModel, SurfaceSpec};
use crate::geometry::Mesh;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize};
use std::path::PathBuf;

/// `[surfaces.TAG]`: a surface model's table, with an optional `back`.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceEntry {
    /// The model (of the front, when `back` is given).
    #[serde(flatten)]
    pub spec: SurfaceSpec,
    /// The model of the back side.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub back: Option<OpaqueSpec>,
}

impl<'de> Deserialize<'de> for SurfaceEntry {
    /// `back` is taken out of the table and the rest read as the model's table, so the
    /// model's own fields stay checked exactly (an unknown one is an error).
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut table = toml::Table::deserialize(d)?;
        let back = table
            .remove("back")
            .map(|v| OpaqueSpec::deserialize(v).map_err(|e| D::Error::custom(format!("back: {e}"))))
            .transpose()?;
        let spec = SurfaceSpec::from_table(table).map_err(D::Error::custom)?;
        Ok(SurfaceEntry { spec, back })
    }
}

impl schemars::JsonSchema for SurfaceEntry {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "SurfaceEntry".into()
    }

    /// One closed table per model, each also taking `back` (as `deserialize` reads it).
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let mut back = generator.subschema_for::<OpaqueSpec>();
        back.insert(
            "description".into(),
            "The model of the back, which a photon arriving along the triangle's normal \
             (from behind) meets: \"absorber\" or an opaque model's table. Without it both \
             sides carry the front's model."
                .into(),
        );
        crate::scene::schema::one_of(
            "[surfaces.TAG]: the optical model of the faces tagged TAG. `model` picks the model, whose keys follow; an opaque model may give its back another (`back`).",
            SurfaceSpec::model_schemas(generator, &[("back", back)]),
        )
    }
}

impl SurfaceEntry {
    /// Check `[surfaces.TAG]` (at `at`) and build its model and its back's, if any.
    pub fn build(
        &self,
        ctx: &Ctx,
        at: &str,
        media: &[Medium],
    ) -> Result<(SurfaceModel, Option<SurfaceModel>)> {
        let front = self.spec.build(ctx, at, media)?;
        let Some(back) = &self.back else {
            return Ok((front, None));
        };
        if front.lets_light_through() {
            return Err(ctx.err(
                &format!("{at}.back"),
                format!(
                    "'{}' lets light through: light crosses it to its other side, it has no back (back is for lambert, phong, mirror or absorber)",
                    front.kind()
                ),
            ));
        }
        if let SurfaceModel::BsdfTable(t) = &front
            && t.back.is_some()
        {
            return Err(ctx.err(
                &format!("{at}.back"),
                "and back_file both say how the back scatters: give one of them",
            ));
        }
        let back = back.build(ctx, &format!("{at}.back"), media, "a surface's back")?;
        Ok((front, Some(back)))
    }

    /// The files the models read, relative to the scene file (for the content hash).
    pub fn files(&self) -> Vec<PathBuf> {
        let back = self.back.iter().flat_map(OpaqueSpec::files);
        self.spec.files().into_iter().chain(back).collect()
    }
}

/// The model a photon travelling along `dir` meets on a face of outward `normal`: the back
/// model when it comes from behind (along the normal) and the surface has one.
#[inline]
pub fn met<'a>(
    front: &'a SurfaceModel,
    back: Option<&'a SurfaceModel>,
    dir: DVec3,
    normal: DVec3,
) -> &'a SurfaceModel {
    match back {
        Some(back) if dir.dot(normal) > 0.0 => back,
        _ => front,
    }
}

/// What a surface's back is, for reports: its back model's kind, `"bsdf_table
/// (back_file)"` for a table face with tables of its own for the back, or `None` when the
/// back is the front.
pub fn back_kind(front: &SurfaceModel, back: Option<&SurfaceModel>) -> Option<String> {
    match (front, back) {
        (_, Some(b)) => Some(b.kind().to_string()),
        (SurfaceModel::BsdfTable(t), None) if t.back.is_some() => {
            Some("bsdf_table (back_file)".to_string())
        }
        _ => None,
    }
}

/// How many of tag `tag`'s triangles face each way: counts by the axis their normal
/// points along most (`"+z"`, `"-x"`, ...), in axis order, the ways no triangle faces left
/// out. A sheet's front is the side its counted normals point to.
pub fn facing(mesh: &Mesh, tag: u32) -> Vec<(&'static str, usize)> {
    const WAYS: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];
    let mut counts = [0usize; 6];
    for p in (0..mesh.len() as u32).filter(|&p| mesh.tri_tag[p as usize] == tag) {
        let n = mesh.normal(p);
        let axis = (0..3)
            .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
            .unwrap_or(0);
        counts[2 * axis + usize::from(n[axis] < 0.0)] += 1;
    }
    WAYS.into_iter()
        .zip(counts)
        .filter(|&(_, n)| n > 0)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;
    use std::path::Path;

    fn parse(text: &str) -> Result<SurfaceEntry, String> {
        toml::from_str::<BTreeMap<String, SurfaceEntry>>(text)
            .map(|mut m| m.remove("s").unwrap())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn back_parses_checks_and_round_trips() {
        let e = parse("[s]\nmodel = \"lambert\"\nalbedo = 0.9\nback = \"absorber\"\n").unwrap();
        assert!(matches!(e.back, Some(OpaqueSpec::Absorber)));
        let text = toml::to_string(&BTreeMap::from([("s", &e)])).unwrap();
        let again = parse(&text).unwrap();
        assert!(matches!(again.back, Some(OpaqueSpec::Absorber)), "{text}");
        let ctx = Ctx(Path::new("scene.toml"));
        let (front, back) = e.build(&ctx, "surfaces.s", &[]).unwrap();
        assert_eq!(front.kind(), "lambert");
        assert_eq!(back.map(|b| b.kind()), Some("absorber"));
        let plain = parse("[s]\nmodel = \"mirror\"\n").unwrap();
        assert!(plain.back.is_none());
        assert!(plain.build(&ctx, "surfaces.s", &[]).unwrap().1.is_none());
    }

    /// A wrong value of a model's key names the key (the table's line alone left the
    /// user to guess which of its keys); a missing key is named by serde itself.
    #[test]
    fn wrong_values_name_their_key() {
        let polarizer = "[s]\nmodel = \"polarizer\"\naxis = [1.0, 0.0, 0.0]\nblock_transmittance = 0.0\nblock_reflectance = 0.9\n";
        let e = parse(&format!("{polarizer}pass_transmittance = \"0.9\"\n")).unwrap_err();
        assert!(
            e.contains("pass_transmittance: invalid type: string"),
            "{e}"
        );
        let e = parse("[s]\nmodel = \"lambert\"\nalbedo = \"x\"\n").unwrap_err();
        assert!(e.contains("albedo: invalid type"), "{e}");
        let e = parse(&polarizer.replace("[1.0, 0.0, 0.0]", "[1.0, 0.0]")).unwrap_err();
        assert!(e.contains("axis: invalid length 2"), "{e}");
        let e = parse(&polarizer.replace("axis = [1.0, 0.0, 0.0]\n", "")).unwrap_err();
        assert!(
            e.contains("missing field `axis`") && !e.contains(": missing"),
            "{e}"
        );
        let e = parse("[s]\nmodel = \"dots\"\ninside = \"pmma\"\nink_albedo = 0.9\nlattice = \"hex\"\npitch_mm = 1.0\norigin = [0.0, 0.0, 0.0]\naxis = [1.0, 0.0, 0.0]\nlength_mm = 10.0\ndensity_grid = { width_mm = 1.0, v_min_mm = 0.0, values = [[\"a\"]] }\n").unwrap_err();
        assert!(e.contains("density_grid.values: invalid type"), "{e}");
        assert!(parse(&format!("{polarizer}pass_transmittance = 0.9\n")).is_ok());
    }

    /// A polarizer lets light through (with the same medium on both sides, so it has no
    /// interface): it has no back, and it is no back (the audit's third pass found both
    /// taken, a photon from behind meeting an absorber or a sheet that transmits).
    #[test]
    fn a_polarizer_has_no_back_and_is_none() {
        let ctx = Ctx(Path::new("scene.toml"));
        let sheet = "model = \"polarizer\", axis = [1.0, 0.0, 0.0], pass_transmittance = 0.9, block_transmittance = 0.0, block_reflectance = 0.9";
        let lines = "model = \"polarizer\"\naxis = [1.0, 0.0, 0.0]\npass_transmittance = 0.9\nblock_transmittance = 0.0\nblock_reflectance = 0.9\n";
        let fronted = parse(&format!("[s]\n{lines}back = \"absorber\"\n")).unwrap();
        let e = fronted
            .build(&ctx, "surfaces.s", &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("surfaces.s.back") && e.contains("'polarizer' lets light through"),
            "{e}"
        );
        let backed = parse(&format!(
            "[s]\nmodel = \"lambert\"\nalbedo = 0.9\nback = {{ {sheet} }}\n"
        ))
        .unwrap();
        let e = backed
            .build(&ctx, "surfaces.s", &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("surfaces.s.back.model") && e.contains("'polarizer' lets light through"),
            "{e}"
        );
    }

    #[test]
    fn bad_backs_name_their_field() {
        let e = parse("[s]\nmodel = \"lambert\"\nalbedo = 0.9\nback = \"black\"\n").unwrap_err();
        assert!(e.contains("back") && e.contains("\"absorber\""), "{e}");
        let e = parse("[s]\nmodel = \"lambert\"\nalbedo = 0.9\ncolour = 1\n").unwrap_err();
        assert!(e.contains("colour"), "{e}");
        let ctx = Ctx(Path::new("scene.toml"));
        let media = [
            Medium::clear("air", 1.0, 0.0),
            Medium::clear("pmma", 1.49, 0.0),
        ];
        let glass =
            parse("[s]\nmodel = \"dielectric\"\ninside = \"pmma\"\nback = \"absorber\"\n").unwrap();
        let e = glass
            .build(&ctx, "surfaces.s", &media)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("surfaces.s.back") && e.contains("no back"),
            "{e}"
        );
        let see_through = parse(
            "[s]\nmodel = \"lambert\"\nalbedo = 0.5\nback = { model = \"dielectric\", inside = \"pmma\" }\n",
        )
        .unwrap();
        let e = see_through
            .build(&ctx, "surfaces.s", &media)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("surfaces.s.back.model") && e.contains("opaque"),
            "{e}"
        );
    }

    #[test]
    fn the_side_a_photon_comes_from_picks_the_model() {
        let white = SurfaceModel::Absorber(super::super::absorber::Absorber);
        let black = SurfaceModel::Absorber(super::super::absorber::Absorber);
        let n = DVec3::Z;
        assert!(std::ptr::eq(
            met(&white, Some(&black), -DVec3::Z, n),
            &white
        ));
        assert!(std::ptr::eq(met(&white, Some(&black), DVec3::Z, n), &black));
        assert!(std::ptr::eq(met(&white, None, DVec3::Z, n), &white));
    }
}
