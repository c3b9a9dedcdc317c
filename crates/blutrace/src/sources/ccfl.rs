//! A CCFL tube: a cylinder of uniform Lambertian radiance (the paper's section 3.1).
//!
//! ```toml
//! [[sources]]
//! type = "ccfl"
//! name = "left_upper"
//! center = [-2.5, 0.0, 1.5]
//! axis = [0.0, 1.0, 0.0]
//! radius_mm = 1.0
//! length_mm = 200.0
//! power_w = 1.0
//! body = { model = "lambert", albedo = 0.5 }   # what returning light meets: see `body`
//! ```

use super::array::ArraySpec;
use super::body::BodySpec;
use super::body_shape::BodyShape;
use crate::geometry::{Ray, orthonormal_basis};
use crate::optics::medium::air;
use crate::optics::sampling;
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// `[[sources]]` with `type = "ccfl"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CcflSpec {
    /// Name for reports.
    pub name: Option<String>,
    /// Centre of the tube (mm).
    pub center: [f64; 3],
    /// Tube axis.
    pub axis: [f64; 3],
    /// Radius (mm).
    pub radius_mm: f64,
    /// Length (mm).
    pub length_mm: f64,
    /// Radiant power (W).
    pub power_w: f64,
    /// Luminous flux (lm), for luminance outputs.
    pub lumens: Option<f64>,
    /// The state of the emitted light ([`super::polarization`]); unpolarized without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<super::polarization::SourcePolarizationSpec>,
    /// Emission spectrum ([`super::spectrum`]); without it the source is monochrome.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectrum: Option<super::spectrum::SpectrumSpec>,
    /// Medium around the tube.
    #[serde(default = "air")]
    pub medium: String,
    /// What light returning to the tube meets ([`super::body`]).
    #[serde(default)]
    pub body: BodySpec,
    /// A row of copies of this source ([`mod@super::array`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<ArraySpec>,
}

impl CcflSpec {
    /// Check the tube's shape (`at` names the entry, `sources[i]`) and build it.
    pub fn tube(&self, ctx: &Ctx, at: &str) -> Result<Tube> {
        let f = |k: &str| format!("{at}.{k}");
        Ok(Tube {
            center: ctx.point(&f("center"), self.center)?,
            axis: ctx.direction(&f("axis"), self.axis)?,
            radius: ctx.length(&f("radius_mm"), self.radius_mm)?,
            length: ctx.length(&f("length_mm"), self.length_mm)?,
        })
    }
}

/// A cylinder of uniform Lambertian radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct Tube {
    /// Centre of the tube.
    pub center: DVec3,
    /// Unit axis.
    pub axis: DVec3,
    /// Radius (mm).
    pub radius: f64,
    /// Length (mm).
    pub length: f64,
}

impl Tube {
    /// A photon leaving the tube: a uniform point `(2 pi h1, l h2)` on it and a
    /// Lambertian direction about the outward normal there (the paper's eq. 1).
    pub fn emit(&self, rng: &mut PhotonRng) -> (Ray, DVec3) {
        let (t, b) = orthonormal_basis(self.axis);
        let (cos_p, sin_p) = sampling::turn(rng.uniform());
        let n = t * cos_p + b * sin_p;
        let along = (rng.uniform() - 0.5) * self.length;
        let p = self.center + self.axis * along + n * self.radius;
        (
            Ray::new(p, sampling::lambertian(n, rng.uniform(), rng.uniform())),
            n,
        )
    }

    /// The point at `(s, t)` in `[-0.5, 0.5]^2` of the tube's surface (around, along) and
    /// the outward normal there.
    pub fn surface_point(&self, s: f64, t: f64) -> (DVec3, DVec3) {
        let (a, b) = orthonormal_basis(self.axis);
        let phi = TAU * (s + 0.5);
        let normal = a * phi.cos() + b * phi.sin();
        (
            self.center + self.axis * (t * self.length) + normal * self.radius,
            normal,
        )
    }

    /// Why copies of this tube `pitch` mm apart along the unit `d` would overlap, if
    /// they would.
    pub fn copies_overlap(&self, d: DVec3, pitch: f64) -> Option<String> {
        let (across, along) = (
            pitch * d.cross(self.axis).length(),
            pitch * d.dot(self.axis).abs(),
        );
        (across < 2.0 * self.radius && along < self.length).then(|| {
            format!(
                "the tubes overlap: their axes are {across} mm apart across the tube (less than the diameter {}) and {along} mm along it (less than the length)",
                2.0 * self.radius
            )
        })
    }

    /// The tube as a body shape.
    pub fn shape(&self) -> BodyShape {
        BodyShape::Cylinder {
            center: self.center,
            axis: self.axis,
            radius: self.radius,
            half_length: 0.5 * self.length,
        }
    }

    /// The distance (mm) from `p` to the tube's surface (its side, or beyond its ends).
    pub fn distance(&self, p: DVec3) -> f64 {
        let rel = p - self.center;
        let along = rel.dot(self.axis);
        let radial = (rel - self.axis * along).length() - self.radius;
        let beyond = (along.abs() - 0.5 * self.length).max(0.0);
        radial.hypot(beyond)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_lie_on_the_tube_and_leave_outwards() {
        let tube = Tube {
            center: DVec3::new(1.0, 2.0, 3.0),
            axis: DVec3::Y,
            radius: 1.5,
            length: 10.0,
        };
        for i in 0..1000 {
            let mut rng = PhotonRng::new(3, i);
            let (r, n) = tube.emit(&mut rng);
            let rel = r.origin - DVec3::new(1.0, 2.0, 3.0);
            let radial = DVec3::new(rel.x, 0.0, rel.z);
            assert!((radial.length() - 1.5).abs() < 1e-12);
            assert!(rel.y.abs() <= 5.0);
            assert!(r.dir.dot(radial) > 0.0);
            assert!((n - radial / 1.5).length() < 1e-12);
        }
    }
}
