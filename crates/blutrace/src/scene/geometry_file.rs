//! One geometry file and its placement in the scene: format, units, up axis, rotation,
//! translation and tag.
//!
//! ```toml
//! [[geometry]]
//! file = "reflector.glb"        # .obj, .gltf/.glb, .stl or .ply, relative to this file
//! units = "m"                   # "mm" | "cm" | "m" | "in"; default: "m" for glTF (its
//!                               # specification), "mm" for OBJ, STL and PLY (no units)
//! up = "y"                      # the file's axis that points to blutrace's +z (the viewer
//!                               # side); default: "y" for glTF (its specification), else "z"
//! scale = 1.0                   # extra uniform factor, after units
//! rotate_deg = [0.0, 0.0, 90.0] # about x, then y, then z (right-handed, degrees)
//! # matrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0],
//! #           [0.0, 0.0, 0.0, 1.0]] # row-major 4 x 4, instead of rotate_deg
//! translate = [0.0, 0.0, 0.0]   # mm, last
//! tag = "reflector"             # one tag for every triangle (required for STL and PLY)
//! ```
//!
//! A file point `p` (after the file's own glTF node transforms) lands in the scene at
//! `translate + R (scale * U (units * p))`: first units to millimetres, then the up axis
//! (`up = "y"` turns +90 degrees about x, so the file's +y becomes +z and its +z becomes
//! -y, as Blender's glTF importer does), then `scale`, then `R` (`rotate_deg`, or `matrix`),
//! then `translate`. Multiples of 90 degrees are exact. A `matrix` that mirrors the part
//! (negative determinant) keeps faces outward by reversing their winding; a singular one
//! is refused; one that shears or stretches unevenly is accepted with a warning.

pub use super::meshio::Format;
use super::meshio::{ReadCache, TaggedTriangles};
use crate::spec_check::Ctx;
pub use crate::transform::Units;
use crate::transform::{affine_matrix, rotation_deg, rotation_x};
use anyhow::Result;
use glam::{DMat3, DMat4};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One geometry file and its placement.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GeometrySpec {
    /// Path to an `.obj`, `.gltf`, `.glb`, `.stl` or `.ply` file.
    pub file: PathBuf,
    /// Length unit of the file's numbers (default: the format's, see the module docs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Units>,
    /// The file's axis that points to blutrace's +z (default: the format's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<UpAxis>,
    /// Extra uniform scale, after units.
    #[serde(default = "one")]
    pub scale: f64,
    /// Rotation about x, then y, then z (degrees), after units, up and scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate_deg: Option<[f64; 3]>,
    /// Row-major 4 x 4 affine matrix, instead of `rotate_deg`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<[[f64; 4]; 4]>,
    /// Translation (mm), applied last.
    #[serde(default)]
    pub translate: [f64; 3],
    /// One tag for every triangle of the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tag: Option<String>,
}

fn one() -> f64 {
    1.0
}

/// Which axis of a file points to blutrace's +z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    /// The file's +z (no turn).
    Z,
    /// The file's +y (turned +90 degrees about x).
    Y,
}

/// The units a format's specification prescribes, else millimetres.
fn default_units(format: Format) -> Units {
    match format {
        Format::Gltf => Units::M,
        _ => Units::Mm,
    }
}

/// The up axis a format's specification prescribes, else z.
fn default_up(format: Format) -> UpAxis {
    match format {
        Format::Gltf => UpAxis::Y,
        _ => UpAxis::Z,
    }
}

/// Where a file's triangles go: the transform and whether it mirrors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// File coordinates to scene millimetres.
    pub transform: DMat4,
    /// The transform mirrors (negative determinant): windings are reversed to stay outward.
    pub mirrors: bool,
}

impl GeometrySpec {
    /// The placement of file `i` of the scene, checked; `warnings` gets what is legal but
    /// suspicious.
    pub fn placement(
        &self,
        ctx: &Ctx,
        i: usize,
        format: Format,
        warnings: &mut Vec<String>,
    ) -> Result<Placement> {
        let field = |f: &str| format!("geometry[{i}].{f}");
        let scale = ctx.positive(&field("scale"), self.scale)?;
        let shift = ctx.point(&field("translate"), self.translate)?;
        let units = self.units.unwrap_or(default_units(format)).mm();
        let up = match self.up.unwrap_or(default_up(format)) {
            UpAxis::Z => DMat3::IDENTITY,
            UpAxis::Y => rotation_x(90.0),
        };
        let turn = match (self.rotate_deg, self.matrix) {
            (Some(_), Some(_)) => {
                return Err(ctx.err(&field("matrix"), "give rotate_deg or matrix, not both"));
            }
            (Some(r), None) => {
                let r = ctx.angles_deg(&field("rotate_deg"), r)?;
                DMat4::from_mat3(rotation_deg(r))
            }
            (None, Some(m)) => checked_matrix(ctx, &field("matrix"), m, warnings)?,
            (None, None) => DMat4::IDENTITY,
        };
        let transform =
            DMat4::from_translation(shift) * turn * DMat4::from_mat3(up * (scale * units));
        Ok(Placement {
            transform,
            mirrors: transform.determinant() < 0.0,
        })
    }

    /// Read the file at `path` (this spec's `file`, resolved) into scene millimetres, with
    /// tags from the file or from `tag` (through `reads`: a file read before is copied).
    pub fn load(
        &self,
        ctx: &Ctx,
        i: usize,
        path: &Path,
        warnings: &mut Vec<String>,
        reads: &ReadCache,
    ) -> Result<TaggedTriangles> {
        let format = Format::of(path).ok_or_else(|| {
            ctx.err(
                &format!("geometry[{i}].file"),
                format!(
                    "{}: unknown geometry format (expected .obj, .gltf, .glb, .stl or .ply)",
                    path.display()
                ),
            )
        })?;
        if format.untagged() && self.tag.is_none() {
            return Err(ctx.err(
                &format!("geometry[{i}].tag"),
                format!(
                    "{} carries no material names: give tag = \"...\" to name its surface",
                    path.display()
                ),
            ));
        }
        if let Some(tag) = &self.tag
            && tag.trim().is_empty()
        {
            return Err(ctx.err(&format!("geometry[{i}].tag"), "must not be empty"));
        }
        let placement = self.placement(ctx, i, format, warnings)?;
        let mut tris = reads
            .load(path, format, placement.transform, self.tag.as_deref())
            .map_err(|e| ctx.err(&format!("geometry[{i}].file"), format!("{e:#}")))?;
        if placement.mirrors {
            tris.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        }
        warnings.append(&mut tris.warnings);
        if let (Some(tag), Some(own)) = (&self.tag, &tris.own_tags) {
            warnings.push(format!(
                "{}: tag = \"{tag}\" replaces the file's own material names ({})",
                path.display(),
                own.join(", ")
            ));
        }
        Ok(tris)
    }
}

/// A user's 4 x 4 row-major matrix as a transform: finite, affine, not singular; a warning
/// when it is not a rotation times a uniform scale.
fn checked_matrix(
    ctx: &Ctx,
    field: &str,
    m: [[f64; 4]; 4],
    warnings: &mut Vec<String>,
) -> Result<DMat4> {
    let t = affine_matrix(ctx, field, m)?;
    let lin = DMat3::from_mat4(t);
    let cols = [lin.x_axis, lin.y_axis, lin.z_axis];
    let size = cols.iter().map(|c| c.length()).fold(0.0, f64::max);
    if lin.determinant().abs() <= 1e-12 * size.powi(3) {
        return Err(ctx.err(field, "is singular: it flattens the part"));
    }
    let scale2 = cols[0].length_squared();
    let rigid = cols
        .iter()
        .all(|c| (c.length_squared() - scale2).abs() <= 1e-9 * scale2)
        && [(0, 1), (0, 2), (1, 2)]
            .iter()
            .all(|&(a, b)| cols[a].dot(cols[b]).abs() <= 1e-9 * scale2);
    if !rigid {
        warnings.push(format!(
            "{}: {field} shears or stretches the part unevenly (not a rotation times a \
             uniform scale): its shape changes",
            ctx.0.display()
        ));
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn spec() -> GeometrySpec {
        toml::from_str("file = \"a.obj\"").unwrap()
    }

    fn place(s: &GeometrySpec, format: Format) -> (Result<Placement>, Vec<String>) {
        let mut w = Vec::new();
        let p = s.placement(&Ctx(Path::new("scene.toml")), 0, format, &mut w);
        (p, w)
    }

    #[test]
    fn quarter_turns_are_exact() {
        let mut s = spec();
        s.rotate_deg = Some([90.0, -90.0, 270.0]);
        let t = place(&s, Format::Obj).0.unwrap().transform;
        for c in t.to_cols_array() {
            assert!(c == 0.0 || c.abs() == 1.0, "{c}");
        }
        // x then y then z: (1, 2, 3) -> x: (1, -3, 2) -> y(-90): (-2, -3, 1) -> z(270): (-3, 2, 1)
        assert_eq!(
            t.transform_point3(DVec3::new(1.0, 2.0, 3.0)),
            DVec3::new(-3.0, 2.0, 1.0)
        );
    }

    #[test]
    fn gltf_defaults_are_y_up_metres() {
        let (p, _) = place(&spec(), Format::Gltf);
        let t = p.unwrap().transform;
        // glTF (x, y, z) m -> blutrace (x, -z, y) mm.
        assert_eq!(
            t.transform_point3(DVec3::new(0.001, 0.002, 0.003)),
            DVec3::new(1.0, -3.0, 2.0)
        );
        let (p, _) = place(&spec(), Format::Stl);
        assert_eq!(p.unwrap().transform, DMat4::IDENTITY);
    }

    #[test]
    fn order_is_units_up_scale_rotate_translate() {
        let mut s = spec();
        s.units = Some(Units::Cm);
        s.up = Some(UpAxis::Y);
        s.scale = 2.0;
        s.rotate_deg = Some([0.0, 0.0, 90.0]);
        s.translate = [1.0, 0.0, 0.0];
        let t = place(&s, Format::Obj).0.unwrap().transform;
        // (1, 0, 0) cm -> 10 mm -> up: (10, 0, 0) -> x2: (20, 0, 0) -> z 90: (0, 20, 0) -> +x
        assert_eq!(
            t.transform_point3(DVec3::new(1.0, 0.0, 0.0)),
            DVec3::new(1.0, 20.0, 0.0)
        );
    }

    #[test]
    fn matrix_equals_rotate_deg() {
        let mut a = spec();
        a.rotate_deg = Some([30.0, 45.0, -60.0]);
        let ta = place(&a, Format::Obj).0.unwrap().transform;
        let mut b = spec();
        let rows = ta.transpose().to_cols_array_2d();
        b.matrix = Some(rows);
        let (pb, w) = place(&b, Format::Obj);
        assert!(w.is_empty(), "{w:?}");
        assert!(pb.unwrap().transform.abs_diff_eq(ta, 1e-15));
    }

    #[test]
    fn bad_matrices() {
        let mut s = spec();
        s.matrix = Some([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let e = place(&s, Format::Obj).0.unwrap_err().to_string();
        assert!(
            e.contains("geometry[0].matrix") && e.contains("singular"),
            "{e}"
        );
        s.matrix = Some([
            [1.0, 0.5, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let (p, w) = place(&s, Format::Obj);
        assert!(p.is_ok() && w[0].contains("shears"), "{w:?}");
        s.matrix = Some([
            [-1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        assert!(place(&s, Format::Obj).0.unwrap().mirrors);
        s.matrix.as_mut().unwrap()[3][0] = 1.0;
        let e = place(&s, Format::Obj).0.unwrap_err().to_string();
        assert!(e.contains("last row"), "{e}");
        s.matrix.as_mut().unwrap()[1][2] = f64::NAN;
        let e = place(&s, Format::Obj).0.unwrap_err().to_string();
        assert!(e.contains("geometry[0].matrix[1][2]"), "{e}");
        s.matrix = None;
        s.rotate_deg = Some([0.0, f64::NAN, 0.0]);
        let e = place(&s, Format::Obj).0.unwrap_err().to_string();
        assert!(e.contains("geometry[0].rotate_deg[1]"), "{e}");
    }

    #[test]
    fn unknown_units_and_axes_are_refused_by_the_format() {
        for bad in ["units = \"furlong\"", "up = \"x\""] {
            let e = toml::from_str::<GeometrySpec>(&format!("file = \"a.stl\"\n{bad}"))
                .unwrap_err()
                .to_string();
            assert!(e.contains("unknown variant"), "{e}");
        }
    }
}
