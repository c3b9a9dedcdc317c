//! Units and placement transforms that geometry files and ray files share: length units,
//! `rotate_deg` rotations (exact at multiples of 90 degrees) and `matrix` affine
//! transforms, checked.

use crate::spec_check::Ctx;
use anyhow::Result;
use glam::{DMat3, DMat4, DVec3};
use serde::{Deserialize, Serialize};

/// Length units of a geometry file or ray file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    /// Millimetres.
    Mm,
    /// Centimetres.
    Cm,
    /// Metres.
    M,
    /// Inches.
    In,
}

impl Units {
    /// Millimetres per unit (exact).
    pub fn mm(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Cm => 10.0,
            Units::M => 1000.0,
            Units::In => 25.4,
        }
    }
}

/// A scene file's row-major 4 x 4 `matrix` (at `field`) as an affine transform: every
/// entry finite, the last row [0, 0, 0, 1]. Geometry files and ray files are placed by it.
pub(crate) fn affine_matrix(ctx: &Ctx, field: &str, m: [[f64; 4]; 4]) -> Result<DMat4> {
    for (r, row) in m.iter().enumerate() {
        for (c, x) in row.iter().enumerate() {
            ctx.finite(&format!("{field}[{r}][{c}]"), *x)?;
        }
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(ctx.err(
            field,
            "the last row must be [0, 0, 0, 1] (an affine transform)",
        ));
    }
    // glam stores columns: the transpose of the row-major rows.
    Ok(DMat4::from_cols_array_2d(&m).transpose())
}

/// Sine and cosine of an angle in degrees, exact at multiples of 90.
fn sin_cos_deg(a: f64) -> (f64, f64) {
    let quarter = a / 90.0;
    if quarter == quarter.round() {
        const SC: [(f64, f64); 4] = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)];
        return SC[(quarter.round() as i64).rem_euclid(4) as usize];
    }
    a.to_radians().sin_cos()
}

/// The rotation by `r` degrees about x, then y, then z (right-handed; exact at multiples
/// of 90 degrees): what `rotate_deg` means for geometry files and ray files alike.
pub fn rotation_deg(r: DVec3) -> DMat3 {
    rotation_z(r.z) * rotation_y(r.y) * rotation_x(r.x)
}

/// The rotation by `deg` degrees about x (exact at multiples of 90).
pub(crate) fn rotation_x(deg: f64) -> DMat3 {
    let (s, c) = sin_cos_deg(deg);
    DMat3::from_cols(DVec3::X, DVec3::new(0.0, c, s), DVec3::new(0.0, -s, c))
}

fn rotation_y(deg: f64) -> DMat3 {
    let (s, c) = sin_cos_deg(deg);
    DMat3::from_cols(DVec3::new(c, 0.0, -s), DVec3::Y, DVec3::new(s, 0.0, c))
}

fn rotation_z(deg: f64) -> DMat3 {
    let (s, c) = sin_cos_deg(deg);
    DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z)
}
