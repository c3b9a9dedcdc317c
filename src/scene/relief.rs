//! Validation of the procedural surface-relief models: `grooves` (V-grooves and prism
//! films, [`crate::optics::grooves`]) and `diffuser` (rough faces,
//! [`crate::optics::diffuser`]). Every error names the file and the field.

use super::config::SurfaceSpec;
use super::{Ctx, interface};
use crate::geometry::Mesh;
use crate::optics::dots::Density;
use crate::optics::gradation::Gradation;
use crate::optics::grooves::GroovePattern;
use crate::optics::surface::{Medium, SurfaceModel};
use anyhow::Result;

/// Largest accepted diffuser roughness (GGX alpha; a facet tilt of 76 deg at a quarter of
/// the peak density). Rougher faces are not surface diffusers any more.
pub const MAX_ROUGHNESS: f64 = 4.0;

/// Build a `grooves` or `diffuser` surface; `None` for any other model.
pub(super) fn build(
    ctx: &Ctx,
    tag: &str,
    spec: &SurfaceSpec,
    media: &[Medium],
) -> Result<Option<SurfaceModel>> {
    let f = |k: &str| format!("surfaces.{tag}.{k}");
    Ok(Some(match spec {
        SurfaceSpec::Grooves {
            inside,
            outside,
            relief,
            apex_deg,
            tilt_deg,
            pitch_mm,
            origin,
            axis,
            length_mm,
            density,
            density_table,
            x_unit,
            mirror,
        } => {
            let pitch = ctx.positive(&f("pitch_mm"), *pitch_mm)?;
            let apex = ctx.finite(&f("apex_deg"), *apex_deg)?;
            if !(apex > 0.0 && apex < 180.0) {
                return Err(ctx.err(
                    &f("apex_deg"),
                    format!("must be within (0, 180) degrees, got {apex}"),
                ));
            }
            let tilt = ctx.finite(&f("tilt_deg"), *tilt_deg)?;
            let limit = (0.5 * apex).min(90.0 - 0.5 * apex);
            if tilt.abs() >= limit {
                return Err(ctx.err(
                    &f("tilt_deg"),
                    format!(
                        "must be within (-{limit}, {limit}) for apex_deg = {apex}, got {tilt}: both facets must lean \
                         away from the apex (base angles 90 - apex/2 +- tilt within (0, 90) degrees)"
                    ),
                ));
            }
            let (fill, field) = match (density, density_table) {
                (Some(c), None) => (Density::Polynomial(c.clone()), f("density")),
                (None, Some(k)) => (Density::Table(k.clone()), f("density_table")),
                (None, None) => (Density::Polynomial(vec![1.0]), f("density")),
                (Some(_), Some(_)) => {
                    return Err(ctx.err(
                        &f("density"),
                        "give either density (polynomial) or density_table, not both",
                    ));
                }
            };
            if let Some(problem) = fill.problem() {
                return Err(ctx.err(&field, problem));
            }
            let mut gradation = Gradation {
                density: fill,
                length: 1.0,
                x_unit: *x_unit,
                mirror: *mirror,
            };
            match length_mm {
                Some(l) => gradation.length = ctx.positive(&f("length_mm"), *l)?,
                None if !gradation.is_constant() || *mirror => {
                    return Err(ctx.err(
                        &f("length_mm"),
                        "missing: needed when the fill varies along axis or mirror = true",
                    ));
                }
                None => {}
            }
            if let Some((u, v)) = gradation.first_outside(0.0, 1.0) {
                return Err(ctx.err(
                    &field,
                    format!(
                        "fill f(x) = {v:.4} at {u:.3} mm from the origin is outside [0, 1] \
                         (the fraction of each pitch taken by its groove)"
                    ),
                ));
            }
            let angles = GroovePattern::base_angles(apex.to_radians(), tilt.to_radians());
            SurfaceModel::Grooves {
                interface: interface(ctx, tag, inside, outside, media)?,
                pattern: GroovePattern::new(
                    *relief,
                    pitch,
                    angles,
                    ctx.point(&f("origin"), *origin)?,
                    ctx.direction(&f("axis"), *axis)?,
                    gradation,
                ),
            }
        }
        SurfaceSpec::Diffuser {
            inside,
            outside,
            roughness,
        } => {
            let alpha = ctx.non_negative(&f("roughness"), *roughness)?;
            if alpha > MAX_ROUGHNESS {
                return Err(ctx.err(
                    &f("roughness"),
                    format!("must be at most {MAX_ROUGHNESS} (GGX alpha), got {alpha}"),
                ));
            }
            SurfaceModel::Diffuser {
                interface: interface(ctx, tag, inside, outside, media)?,
                roughness: alpha,
            }
        }
        _ => return Ok(None),
    }))
}

/// Check every groove pattern's face is flat with `axis` in it (the profile is traced in
/// the plane of `axis` and the face normal), and make `axis` exactly perpendicular to the
/// face normal. Runs after the faces are oriented.
pub(super) fn finish_groove_patterns(
    ctx: &Ctx,
    mesh: &Mesh,
    tags: &[String],
    surfaces: &mut [SurfaceModel],
) -> Result<()> {
    for (tag_id, s) in surfaces.iter_mut().enumerate() {
        let SurfaceModel::Grooves { pattern, .. } = s else {
            continue;
        };
        let tag = &tags[tag_id];
        let mut normal = None;
        for (p, _) in mesh
            .tri_tag
            .iter()
            .enumerate()
            .filter(|(_, t)| **t as usize == tag_id)
        {
            let n = mesh.normal(p as u32);
            let first = *normal.get_or_insert(n);
            if n.dot(first).abs() < 1.0 - 1e-9 {
                return Err(ctx.err(
                    &format!("surfaces.{tag}"),
                    "model grooves needs flat faces: the tag's triangles are not all parallel",
                ));
            }
        }
        let Some(n) = normal else { continue };
        if pattern.axis.dot(n).abs() > 1e-6 {
            return Err(ctx.err(
                &format!("surfaces.{tag}.axis"),
                "must lie in the face (it is not perpendicular to the face normal)",
            ));
        }
        pattern.axis = (pattern.axis - n * pattern.axis.dot(n)).normalize();
    }
    Ok(())
}
