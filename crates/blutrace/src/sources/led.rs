//! A flat LED emitter: a rectangle of uniform exitance, its directions cos^m about its
//! normal or drawn from a measured intensity table ([`super::intensity`]).
//!
//! ```toml
//! [[sources]]
//! type = "led"
//! center = [0.0, 0.0, 0.0]
//! normal = [1.0, 0.0, 0.0]
//! u = [0.0, 1.0, 0.0]        # direction of the width
//! width_mm = 3.0
//! height_mm = 0.6
//! power_w = 0.1
//! lumens = 30.0              # optional: luminous flux, for luminance outputs
//! cos_exponent = 1.0         # 1 = Lambertian
//! # intensity_file = "led.ies"  # instead of cos_exponent: a measured I(theta) table
//! # package_depth_mm = 0.8      # a box package behind the rectangle (its body)
//! ```

use super::array::ArraySpec;
use super::body::BodySpec;
use super::body_shape::{BodyShape, Rect};
use super::intensity::IntensityProfile;
use crate::geometry::Ray;
use crate::optics::medium::air;
use crate::optics::sampling;
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `[[sources]]` with `type = "led"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LedSpec {
    /// Name for reports.
    pub name: Option<String>,
    /// Centre of the emitting rectangle (mm).
    pub center: [f64; 3],
    /// Emitting normal.
    pub normal: [f64; 3],
    /// Width direction.
    pub u: [f64; 3],
    /// Width (mm).
    pub width_mm: f64,
    /// Height (mm).
    pub height_mm: f64,
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
    /// cos^m exponent (1 = Lambertian, 0 = isotropic over the hemisphere); default 1.
    /// Not with `intensity_file`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cos_exponent: Option<f64>,
    /// Measured intensity table, `.csv` or `.ies` (relative to the scene file); see
    /// [`super::intensity`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity_file: Option<PathBuf>,
    /// Medium in front of the emitter.
    #[serde(default = "air")]
    pub medium: String,
    /// What light returning to the LED meets ([`super::body`]).
    #[serde(default)]
    pub body: BodySpec,
    /// Depth of a box package behind the emitting rectangle (mm); without it the body
    /// is the rectangle itself.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub package_depth_mm: Option<f64>,
    /// A row of copies of this source ([`mod@super::array`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<ArraySpec>,
}

impl LedSpec {
    /// Check the LED's rectangle and angular profile (`at` names the entry, `sources[i]`;
    /// an `intensity_file` is read relative to the scene file) and build it.
    pub fn led(&self, ctx: &Ctx, at: &str) -> Result<FlatLed> {
        let f = |k: &str| format!("{at}.{k}");
        let normal = ctx.direction(&f("normal"), self.normal)?;
        let u = ctx.direction(&f("u"), self.u)?;
        if u.dot(normal).abs() > 1e-6 {
            return Err(ctx.err(&f("u"), "must be perpendicular to normal"));
        }
        let (center, width, height) = (
            ctx.point(&f("center"), self.center)?,
            ctx.length(&f("width_mm"), self.width_mm)?,
            ctx.length(&f("height_mm"), self.height_mm)?,
        );
        let profile = match (&self.intensity_file, self.cos_exponent) {
            (Some(_), Some(_)) => {
                return Err(ctx.err(
                    &f("intensity_file"),
                    "give either cos_exponent or intensity_file, not both",
                ));
            }
            (Some(file), None) => {
                let dir = ctx.0.parent().unwrap_or(Path::new("."));
                let profile = IntensityProfile::read(&dir.join(file))
                    .map_err(|e| ctx.err(&f("intensity_file"), e))?;
                LedProfile::Measured(Arc::new(profile))
            }
            (None, m) => {
                LedProfile::CosPower(ctx.non_negative(&f("cos_exponent"), m.unwrap_or(1.0))?)
            }
        };
        Ok(FlatLed {
            center,
            normal,
            u,
            width,
            height,
            profile,
        })
    }
}

/// How an LED's intensity falls off from its normal.
#[derive(Clone, Debug, PartialEq)]
pub enum LedProfile {
    /// `I(theta) ~ cos^m theta`, exponent m (1: Lambertian).
    CosPower(f64),
    /// A measured, rotationally symmetric table.
    Measured(Arc<IntensityProfile>),
}

/// A flat rectangle of uniform exitance (an LED die or window).
#[derive(Clone, Debug, PartialEq)]
pub struct FlatLed {
    /// Centre of the rectangle.
    pub center: DVec3,
    /// Unit emitting normal.
    pub normal: DVec3,
    /// Unit width direction (in the plane).
    pub u: DVec3,
    /// Width along `u` (mm).
    pub width: f64,
    /// Height along `normal x u` (mm).
    pub height: f64,
    /// The intensity's fall-off from the normal.
    pub profile: LedProfile,
}

impl FlatLed {
    /// A photon leaving the LED: a uniform point on the rectangle (two uniforms, width
    /// first), then a direction from the profile.
    pub fn emit(&self, rng: &mut PhotonRng) -> (Ray, DVec3) {
        let v = self.normal.cross(self.u);
        let p = self.center
            + self.u * ((rng.uniform() - 0.5) * self.width)
            + v * ((rng.uniform() - 0.5) * self.height);
        let d = match &self.profile {
            LedProfile::CosPower(m) => {
                sampling::cos_power(self.normal, *m, rng.uniform(), rng.uniform())
            }
            LedProfile::Measured(profile) => {
                let theta = profile.sample_theta(rng.uniform());
                sampling::around(self.normal, theta.cos(), rng.uniform())
            }
        };
        (Ray::new(p, d), self.normal)
    }

    /// The emitting rectangle.
    pub fn rect(&self) -> Rect {
        Rect {
            center: self.center,
            normal: self.normal,
            u: self.u,
            half_width: 0.5 * self.width,
            half_height: 0.5 * self.height,
        }
    }

    /// The point at `(s, t)` in `[-0.5, 0.5]^2` of the rectangle (along the width, the
    /// height) and the normal there.
    pub fn surface_point(&self, s: f64, t: f64) -> (DVec3, DVec3) {
        let v = self.normal.cross(self.u);
        let p = self.center + self.u * (s * self.width) + v * (t * self.height);
        (p, self.normal)
    }

    /// The rectangle as a body shape.
    pub fn shape(&self) -> BodyShape {
        BodyShape::Rectangle(self.rect())
    }

    /// The distance (mm) from `p` to the rectangle.
    pub fn distance(&self, p: DVec3) -> f64 {
        let r = self.rect();
        let rel = p - r.center;
        let v = r.normal.cross(r.u);
        let du = (rel.dot(r.u).abs() - r.half_width).max(0.0);
        let dv = (rel.dot(v).abs() - r.half_height).max(0.0);
        rel.dot(r.normal).hypot(du.hypot(dv))
    }
}
