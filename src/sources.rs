//! Light sources: CCFL tubes and flat LED emitters, sampled in proportion to power.
//!
//! ```toml
//! [[sources]]
//! type = "ccfl"              # Lambertian cylinder, the paper's section 3.1
//! name = "left_upper"
//! center = [-2.5, 0.0, 1.5]
//! axis = [0.0, 1.0, 0.0]
//! radius_mm = 1.0
//! length_mm = 200.0
//! power_w = 1.0
//! body = { model = "lambert", albedo = 0.5 }   # what returning light meets: see `body`
//!
//! [[sources]]
//! type = "led"               # flat rectangle emitting cos^m about its normal
//! center = [0.0, 0.0, 0.0]
//! normal = [1.0, 0.0, 0.0]
//! u = [0.0, 1.0, 0.0]        # direction of the width
//! width_mm = 3.0
//! height_mm = 0.6
//! power_w = 0.1
//! lumens = 30.0              # optional: luminous flux, for luminance outputs
//! cos_exponent = 1.0         # 1 = Lambertian
//! # intensity_file = "led.ies"  # instead of cos_exponent: a measured I(theta) table
//! ```
//!
//! Any entry may stand for a row of identical sources (`array = { count, pitch_mm,
//! direction }`, see [`mod@array`]).
//!
//! An LED with `intensity_file` becomes an [`Emitter::MeasuredLed`]; see [`intensity`]
//! for the CSV and IES LM-63 formats and how the table is sampled.

pub mod array;
pub mod body;
pub mod body_shape;
pub mod intensity;

use crate::geometry::{Ray, orthonormal_basis};
use crate::optics::medium::{Medium, MediumId, air, medium_id};
use crate::optics::sampling;
use crate::optics::spectrum::Light;
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use body::{BodySpec, LampBody};
use body_shape::{BodyShape, Rect};
use glam::DVec3;
use intensity::IntensityProfile;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `[[sources]]`: a light source in the scene file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum SourceSpec {
    /// Cold-cathode fluorescent lamp: a Lambertian cylinder.
    Ccfl {
        /// Name for reports.
        name: Option<String>,
        /// Centre of the tube.
        center: [f64; 3],
        /// Tube axis.
        axis: [f64; 3],
        /// Radius (mm).
        radius_mm: f64,
        /// Length (mm).
        length_mm: f64,
        /// Radiant power (W).
        power_w: f64,
        /// Luminous flux (lm), for luminance outputs.
        lumens: Option<f64>,
        /// Medium around the tube.
        #[serde(default = "air")]
        medium: String,
        /// What light returning to the tube meets ([`body`]).
        #[serde(default)]
        body: BodySpec,
        /// A row of copies of this source ([`mod@array`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        array: Option<array::ArraySpec>,
    },
    /// Flat LED emitter.
    Led {
        /// Name for reports.
        name: Option<String>,
        /// Centre of the emitting rectangle.
        center: [f64; 3],
        /// Emitting normal.
        normal: [f64; 3],
        /// Width direction.
        u: [f64; 3],
        /// Width (mm).
        width_mm: f64,
        /// Height (mm).
        height_mm: f64,
        /// Radiant power (W).
        power_w: f64,
        /// Luminous flux (lm), for luminance outputs.
        lumens: Option<f64>,
        /// cos^m exponent (1 = Lambertian, 0 = isotropic over the hemisphere); default 1.
        /// Not with `intensity_file`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cos_exponent: Option<f64>,
        /// Measured intensity table, `.csv` or `.ies` (relative to the scene file); see
        /// [`crate::sources::intensity`].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        intensity_file: Option<PathBuf>,
        /// Medium in front of the emitter.
        #[serde(default = "air")]
        medium: String,
        /// What light returning to the LED meets ([`body`]).
        #[serde(default)]
        body: BodySpec,
        /// Depth of a box package behind the emitting rectangle (mm); without it the body
        /// is the rectangle itself.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        package_depth_mm: Option<f64>,
        /// A row of copies of this source ([`mod@array`]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        array: Option<array::ArraySpec>,
    },
}

impl SourceSpec {
    /// The entry's row, if it has one.
    pub fn array(&self) -> Option<&array::ArraySpec> {
        match self {
            SourceSpec::Ccfl { array, .. } | SourceSpec::Led { array, .. } => array.as_ref(),
        }
    }

    /// The files the source reads, relative to the scene file (its measured intensity
    /// table): the content hash covers their bytes, as it does surface models' tables.
    pub fn files(&self) -> Vec<PathBuf> {
        match self {
            SourceSpec::Led {
                intensity_file: Some(f),
                ..
            } => vec![f.clone()],
            _ => Vec::new(),
        }
    }

    /// Check entry `i` of `[[sources]]` and build the source (a measured LED's
    /// `intensity_file` is relative to the scene file).
    pub fn build(&self, ctx: &Ctx, i: usize, media: &[Medium]) -> Result<Source> {
        let f = |k: &str| format!("sources[{i}].{k}");
        let (name, power_w, lumens, medium, body, depth) = match self {
            SourceSpec::Ccfl {
                name,
                power_w,
                lumens,
                medium,
                body,
                ..
            } => (name, power_w, lumens, medium, body, None),
            SourceSpec::Led {
                name,
                power_w,
                lumens,
                medium,
                body,
                package_depth_mm,
                ..
            } => (name, power_w, lumens, medium, body, *package_depth_mm),
        };
        let emitter = self.emitter(ctx, i)?;
        let depth = depth
            .map(|d| ctx.length(&f("package_depth_mm"), d))
            .transpose()?;
        let body = body
            .model(ctx, &f("body"), media)?
            .map(|model| LampBody::new(&emitter, model, depth));
        let kind = if matches!(self, SourceSpec::Ccfl { .. }) {
            "ccfl"
        } else {
            "led"
        };
        Ok(Source {
            name: match name {
                Some(n) => ctx.name(&f("name"), n)?.to_owned(),
                None => format!("{kind}{i}"),
            },
            power_w: ctx.positive(&f("power_w"), *power_w)?,
            lumens: ctx.optional_positive(&f("lumens"), *lumens)?,
            emitter,
            medium: medium_id(ctx, &f("medium"), medium, media)?,
            body,
        })
    }

    /// Check the emitting shape of entry `i` and build it.
    fn emitter(&self, ctx: &Ctx, i: usize) -> Result<Emitter> {
        let f = |k: &str| format!("sources[{i}].{k}");
        Ok(match self {
            SourceSpec::Ccfl {
                center,
                axis,
                radius_mm,
                length_mm,
                ..
            } => Emitter::Ccfl {
                center: ctx.point(&f("center"), *center)?,
                axis: ctx.direction(&f("axis"), *axis)?,
                radius: ctx.length(&f("radius_mm"), *radius_mm)?,
                length: ctx.length(&f("length_mm"), *length_mm)?,
            },
            SourceSpec::Led {
                center,
                normal,
                u,
                width_mm,
                height_mm,
                cos_exponent,
                intensity_file,
                ..
            } => {
                let n = ctx.direction(&f("normal"), *normal)?;
                let u = ctx.direction(&f("u"), *u)?;
                if u.dot(n).abs() > 1e-6 {
                    return Err(ctx.err(&f("u"), "must be perpendicular to normal"));
                }
                let (center, width, height) = (
                    ctx.point(&f("center"), *center)?,
                    ctx.length(&f("width_mm"), *width_mm)?,
                    ctx.length(&f("height_mm"), *height_mm)?,
                );
                match (intensity_file, cos_exponent) {
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
                        Emitter::MeasuredLed {
                            center,
                            normal: n,
                            u,
                            width,
                            height,
                            profile: Arc::new(profile),
                        }
                    }
                    (None, m) => Emitter::Led {
                        center,
                        normal: n,
                        u,
                        width,
                        height,
                        cos_exponent: ctx.non_negative(&f("cos_exponent"), m.unwrap_or(1.0))?,
                    },
                }
            }
        })
    }
}

/// The emitting shape of a source.
#[derive(Clone, Debug, PartialEq)]
pub enum Emitter {
    /// Cylinder of uniform Lambertian radiance (a CCFL).
    Ccfl {
        /// Centre of the tube.
        center: DVec3,
        /// Unit axis.
        axis: DVec3,
        /// Radius (mm).
        radius: f64,
        /// Length (mm).
        length: f64,
    },
    /// Flat rectangle with a cos^m intensity profile (an LED die or window).
    Led {
        /// Centre of the rectangle.
        center: DVec3,
        /// Unit emitting normal.
        normal: DVec3,
        /// Unit width direction (in the plane).
        u: DVec3,
        /// Width along `u` (mm).
        width: f64,
        /// Height along `normal x u` (mm).
        height: f64,
        /// Exponent m of the cos^m profile.
        cos_exponent: f64,
    },
    /// Flat rectangle with a measured, rotationally symmetric intensity profile.
    MeasuredLed {
        /// Centre of the rectangle.
        center: DVec3,
        /// Unit emitting normal.
        normal: DVec3,
        /// Unit width direction (in the plane).
        u: DVec3,
        /// Width along `u` (mm).
        width: f64,
        /// Height along `normal x u` (mm).
        height: f64,
        /// Relative intensity by angle from the normal.
        profile: Arc<IntensityProfile>,
    },
}

/// One source.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// Name for reports.
    pub name: String,
    /// Radiant power (W).
    pub power_w: f64,
    /// Luminous flux (lm), when the scene gives it.
    pub lumens: Option<f64>,
    /// Shape and angular profile.
    pub emitter: Emitter,
    /// Medium the source emits into.
    pub medium: MediumId,
    /// What returning light meets (`None`: the lamp is transparent).
    pub body: Option<LampBody>,
}

/// A photon leaving a source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Where it starts (on the emitting surface) and where it goes.
    pub ray: Ray,
    /// The emitting surface's unit outward normal there: emitted photons start a spawn
    /// offset off it, as scattered ones do, so they never meet their own lamp.
    pub normal: DVec3,
    /// The medium it starts in.
    pub medium: MediumId,
    /// The index of the source that emitted it.
    pub source: usize,
    /// Its light (see [`crate::optics::spectrum`]).
    pub light: Light,
}

impl Source {
    /// The centre of the emitter.
    pub fn anchor(&self) -> DVec3 {
        match &self.emitter {
            Emitter::Ccfl { center, .. }
            | Emitter::Led { center, .. }
            | Emitter::MeasuredLed { center, .. } => *center,
        }
    }

    /// Move the source (and its body) by `d`.
    pub fn translate(&mut self, d: DVec3) {
        match &mut self.emitter {
            Emitter::Ccfl { center, .. }
            | Emitter::Led { center, .. }
            | Emitter::MeasuredLed { center, .. } => *center += d,
        }
        if let Some(b) = &mut self.body {
            b.shape.translate(d);
        }
    }

    /// A photon leaving this source: its ray and the emitting surface's normal.
    pub fn emit(&self, rng: &mut PhotonRng) -> (Ray, DVec3) {
        match &self.emitter {
            Emitter::Ccfl {
                center,
                axis,
                radius,
                length,
            } => {
                // Uniform point (2 pi h1, l h2) on the tube, Lambertian direction (eq. 1).
                let (t, b) = orthonormal_basis(*axis);
                let (cos_p, sin_p) = sampling::turn(rng.uniform());
                let n = t * cos_p + b * sin_p;
                let along = (rng.uniform() - 0.5) * length;
                let p = *center + *axis * along + n * *radius;
                (
                    Ray::new(p, sampling::lambertian(n, rng.uniform(), rng.uniform())),
                    n,
                )
            }
            Emitter::Led {
                center,
                normal,
                u,
                width,
                height,
                cos_exponent,
            } => {
                let p = rectangle_point(*center, *normal, *u, (*width, *height), rng);
                let d = sampling::cos_power(*normal, *cos_exponent, rng.uniform(), rng.uniform());
                (Ray::new(p, d), *normal)
            }
            Emitter::MeasuredLed {
                center,
                normal,
                u,
                width,
                height,
                profile,
            } => {
                let p = rectangle_point(*center, *normal, *u, (*width, *height), rng);
                let theta = profile.sample_theta(rng.uniform());
                let d = sampling::around(*normal, theta.cos(), rng.uniform());
                (Ray::new(p, d), *normal)
            }
        }
    }
}

impl Emitter {
    /// A deterministic grid of `n x n` points on the emitting surface, each with the
    /// surface's unit outward normal there (for placement checks, not for tracing).
    pub fn surface_grid(&self, n: usize) -> Vec<(DVec3, DVec3)> {
        let f = |k: usize| (k as f64 + 0.5) / n as f64 - 0.5;
        let mut out = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                out.push(match self {
                    Emitter::Ccfl {
                        center,
                        axis,
                        radius,
                        length,
                    } => {
                        let (t, b) = orthonormal_basis(*axis);
                        let phi = TAU * (f(i) + 0.5);
                        let normal = t * phi.cos() + b * phi.sin();
                        (*center + *axis * (f(j) * length) + normal * *radius, normal)
                    }
                    Emitter::Led { .. } | Emitter::MeasuredLed { .. } => {
                        let r = self.rect().expect("an LED has a rectangle");
                        let v = r.normal.cross(r.u);
                        let (width, height) = (2.0 * r.half_width, 2.0 * r.half_height);
                        (
                            r.center + r.u * (f(i) * width) + v * (f(j) * height),
                            r.normal,
                        )
                    }
                });
            }
        }
        out
    }

    /// The emitting surface as a body shape: the tube, or the LED's rectangle (a lamp's
    /// default body, and what placement checks test parts against).
    pub fn shape(&self) -> BodyShape {
        match self {
            Emitter::Ccfl {
                center,
                axis,
                radius,
                length,
            } => BodyShape::Cylinder {
                center: *center,
                axis: *axis,
                radius: *radius,
                half_length: 0.5 * length,
            },
            Emitter::Led { .. } | Emitter::MeasuredLed { .. } => {
                BodyShape::Rectangle(self.rect().expect("an LED has a rectangle"))
            }
        }
    }

    /// The distance (mm) from `p` to the emitting surface (the tube's side, or the
    /// rectangle).
    pub fn surface_distance(&self, p: DVec3) -> f64 {
        if let Emitter::Ccfl {
            center,
            axis,
            radius,
            length,
        } = self
        {
            let rel = p - *center;
            let along = rel.dot(*axis);
            let radial = (rel - *axis * along).length() - radius;
            let beyond = (along.abs() - 0.5 * length).max(0.0);
            return radial.hypot(beyond);
        }
        let r = self.rect().expect("an LED has a rectangle");
        let rel = p - r.center;
        let v = r.normal.cross(r.u);
        let du = (rel.dot(r.u).abs() - r.half_width).max(0.0);
        let dv = (rel.dot(v).abs() - r.half_height).max(0.0);
        rel.dot(r.normal).hypot(du.hypot(dv))
    }

    /// An LED's emitting rectangle (`None` for a CCFL): the one place the LED kinds'
    /// shared fields are unpacked.
    pub fn rect(&self) -> Option<Rect> {
        match self {
            Emitter::Ccfl { .. } => None,
            Emitter::Led {
                center,
                normal,
                u,
                width,
                height,
                ..
            }
            | Emitter::MeasuredLed {
                center,
                normal,
                u,
                width,
                height,
                ..
            } => Some(Rect {
                center: *center,
                normal: *normal,
                u: *u,
                half_width: 0.5 * width,
                half_height: 0.5 * height,
            }),
        }
    }
}

/// A uniform point on the emitting rectangle of an LED: centred at `center`, `width` along
/// the unit `u`, `height` along `normal x u`. Both LED kinds start their photons here
/// (two uniforms, width first); they differ only in the direction.
fn rectangle_point(
    center: DVec3,
    normal: DVec3,
    u: DVec3,
    (width, height): (f64, f64),
    rng: &mut PhotonRng,
) -> DVec3 {
    let v = normal.cross(u);
    center + u * ((rng.uniform() - 0.5) * width) + v * ((rng.uniform() - 0.5) * height)
}

/// Largest total source power (W): a backlight's lamps draw watts; the bound keeps every
/// ledger sum finite (two sources of 1.7e308 W would overflow it).
pub const MAX_TOTAL_POWER_W: f64 = 1e9;

/// All sources of a scene with the cumulative power table used to pick one per photon.
#[derive(Clone, Debug, PartialEq)]
pub struct Sources {
    /// The sources.
    pub list: Vec<Source>,
    cdf: Vec<f64>,
}

impl Sources {
    /// Build the table; total power must be positive.
    pub fn new(list: Vec<Source>) -> Self {
        let total: f64 = list.iter().map(|s| s.power_w).sum();
        let mut acc = 0.0;
        let cdf = list
            .iter()
            .map(|s| {
                acc += s.power_w;
                acc / total
            })
            .collect();
        Self { list, cdf }
    }

    /// Check the scene file's `[[sources]]` entries and build the sources.
    pub fn build(ctx: &Ctx, specs: &[SourceSpec], media: &[Medium]) -> Result<Sources> {
        if specs.is_empty() {
            return Err(ctx.err("sources", "the scene needs at least one [[sources]] entry"));
        }
        let (mut list, mut entry) = (Vec::with_capacity(specs.len()), Vec::new());
        for (i, s) in specs.iter().enumerate() {
            let row = array::replicate(ctx, i, s.build(ctx, i, media)?, s.array())?;
            entry.extend(std::iter::repeat_n(i, row.len()));
            list.extend(row);
        }
        for (k, s) in list.iter().enumerate() {
            if let Some(j) = list[..k].iter().position(|o| o.name == s.name) {
                let (i, j) = (entry[k], entry[j]);
                return Err(ctx.err(
                    &format!("sources[{i}].name"),
                    format!("'{}' is already the name of sources[{j}] (or one of its row); names must be unique (the ledger books each lamp body's absorption by name)", s.name),
                ));
            }
        }
        let total: f64 = list.iter().map(|s| s.power_w).sum();
        if total > MAX_TOTAL_POWER_W {
            return Err(ctx.err(
                "sources",
                format!("total power_w {total:e} W exceeds {MAX_TOTAL_POWER_W:e} W"),
            ));
        }
        Ok(Self::new(list))
    }

    /// Move every source (and its body) by `d`.
    pub fn translate(&mut self, d: DVec3) {
        self.list.iter_mut().for_each(|s| s.translate(d));
    }

    /// Luminous efficacy of the radiation (lm/W) when every source gives its lumens.
    pub fn luminous_efficacy(&self) -> Option<f64> {
        let lumens: Option<f64> = self.list.iter().map(|s| s.lumens).sum();
        lumens.map(|lm| lm / self.total_power())
    }

    /// Total radiant power (W).
    pub fn total_power(&self) -> f64 {
        self.list.iter().map(|s| s.power_w).sum()
    }

    /// Pick a source in proportion to power and emit a photon from it.
    pub fn sample(&self, rng: &mut PhotonRng) -> Emission {
        let u = rng.uniform();
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.list.len() - 1);
        let s = &self.list[i];
        let (ray, normal) = s.emit(rng);
        Emission {
            ray,
            normal,
            medium: s.medium,
            source: i,
            light: Light::MONOCHROME,
        }
    }

    /// The sources with an opaque body, by index.
    pub fn bodies(&self) -> impl Iterator<Item = (usize, &Source, &LampBody)> {
        self.list
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.body.as_ref().map(|b| (i, s, b)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ccfl_points_lie_on_the_tube_and_leave_outwards() {
        let s = Source {
            name: "t".into(),
            power_w: 1.0,
            lumens: None,
            emitter: Emitter::Ccfl {
                center: DVec3::new(1.0, 2.0, 3.0),
                axis: DVec3::Y,
                radius: 1.5,
                length: 10.0,
            },
            medium: 0,
            body: None,
        };
        for i in 0..1000 {
            let mut rng = PhotonRng::new(3, i);
            let (r, n) = s.emit(&mut rng);
            let rel = r.origin - DVec3::new(1.0, 2.0, 3.0);
            let radial = DVec3::new(rel.x, 0.0, rel.z);
            assert!((radial.length() - 1.5).abs() < 1e-12);
            assert!(rel.y.abs() <= 5.0);
            assert!(r.dir.dot(radial) > 0.0);
            assert!((n - radial / 1.5).length() < 1e-12);
        }
    }

    #[test]
    fn sources_are_picked_by_power() {
        let led = |p: f64| Source {
            name: "l".into(),
            power_w: p,
            lumens: None,
            emitter: Emitter::Led {
                center: DVec3::ZERO,
                normal: DVec3::Z,
                u: DVec3::X,
                width: 1.0,
                height: 1.0,
                cos_exponent: 1.0,
            },
            medium: 0,
            body: None,
        };
        let s = Sources::new(vec![led(1.0), led(3.0)]);
        assert_eq!(s.cdf, vec![0.25, 1.0]);
        assert_eq!(s.total_power(), 4.0);
    }

    /// The emitting shape's support holds every point of a fine grid on the surface, and
    /// the grid's extremes come within a grid cell of its ends: neither too narrow (the
    /// placement check would miss a cut) nor loose.
    #[test]
    fn the_emitting_shapes_support_bounds_the_surface() {
        let tilted = DVec3::new(0.3, 1.0, -0.2).normalize();
        let emitters = [
            Emitter::Ccfl {
                center: DVec3::new(1.0, 2.0, 3.0),
                axis: tilted,
                radius: 1.5,
                length: 10.0,
            },
            Emitter::Led {
                center: DVec3::new(-4.0, 0.5, 2.0),
                normal: tilted,
                u: tilted.any_orthonormal_vector(),
                width: 3.0,
                height: 1.0,
                cos_exponent: 1.0,
            },
        ];
        let dirs = [DVec3::X, DVec3::new(0.2, -3.0, 0.7), tilted, -tilted * 2.0];
        for e in &emitters {
            let grid = e.surface_grid(200);
            for n in dirs {
                let (lo, hi) = e.shape().support(n);
                let (glo, ghi) = grid.iter().fold((f64::MAX, f64::MIN), |(a, b), (p, _)| {
                    (a.min(n.dot(*p)), b.max(n.dot(*p)))
                });
                let tol = 1e-12 * (lo.abs() + hi.abs());
                let cell = 0.01 * (hi - lo) + 1e-9;
                assert!(
                    lo - tol <= glo && ghi <= hi + tol,
                    "{e:?} {n}: grid outside"
                );
                assert!(glo - lo < cell && hi - ghi < cell, "{e:?} {n}: loose");
            }
        }
    }
}
