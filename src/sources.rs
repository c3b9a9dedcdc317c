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
//! An LED with `intensity_file` becomes an [`Emitter::MeasuredLed`]; see [`intensity`]
//! for the CSV and IES LM-63 formats and how the table is sampled.

pub mod body;
pub mod intensity;

use crate::geometry::{Ray, orthonormal_basis};
use crate::optics::sampling;
use crate::optics::surface::MediumId;
use crate::rng::PhotonRng;
use glam::DVec3;
use intensity::IntensityProfile;
use std::f64::consts::TAU;
use std::sync::Arc;

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

    /// A photon ray leaving this source.
    pub fn emit(&self, rng: &mut PhotonRng) -> Ray {
        match &self.emitter {
            Emitter::Ccfl {
                center,
                axis,
                radius,
                length,
            } => {
                // Uniform point (2 pi h1, l h2) on the tube, Lambertian direction (eq. 1).
                let (t, b) = orthonormal_basis(*axis);
                let phi = TAU * rng.uniform();
                let n = t * phi.cos() + b * phi.sin();
                let along = (rng.uniform() - 0.5) * length;
                let p = *center + *axis * along + n * *radius;
                Ray::new(p, sampling::lambertian(n, rng.uniform(), rng.uniform()))
            }
            Emitter::Led {
                center,
                normal,
                u,
                width,
                height,
                cos_exponent,
            } => {
                let v = normal.cross(*u);
                let p = *center
                    + *u * ((rng.uniform() - 0.5) * width)
                    + v * ((rng.uniform() - 0.5) * height);
                let d = sampling::cos_power(*normal, *cos_exponent, rng.uniform(), rng.uniform());
                Ray::new(p, d)
            }
            Emitter::MeasuredLed {
                center,
                normal,
                u,
                width,
                height,
                profile,
            } => {
                let v = normal.cross(*u);
                let p = *center
                    + *u * ((rng.uniform() - 0.5) * width)
                    + v * ((rng.uniform() - 0.5) * height);
                let theta = profile.sample_theta(rng.uniform());
                let d = sampling::around(*normal, theta.cos(), TAU * rng.uniform());
                Ray::new(p, d)
            }
        }
    }
}

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

    /// Move every source by `d`.
    pub fn translate(&mut self, d: DVec3) {
        for s in &mut self.list {
            match &mut s.emitter {
                Emitter::Ccfl { center, .. }
                | Emitter::Led { center, .. }
                | Emitter::MeasuredLed { center, .. } => *center += d,
            }
        }
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
    pub fn sample(&self, rng: &mut PhotonRng) -> (Ray, MediumId) {
        let u = rng.uniform();
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.list.len() - 1);
        let s = &self.list[i];
        (s.emit(rng), s.medium)
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
        };
        for i in 0..1000 {
            let mut rng = PhotonRng::new(3, i);
            let r = s.emit(&mut rng);
            let rel = r.origin - DVec3::new(1.0, 2.0, 3.0);
            let radial = DVec3::new(rel.x, 0.0, rel.z);
            assert!((radial.length() - 1.5).abs() < 1e-12);
            assert!(rel.y.abs() <= 5.0);
            assert!(r.dir.dot(radial) > 0.0);
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
        };
        let s = Sources::new(vec![led(1.0), led(3.0)]);
        assert_eq!(s.cdf, vec![0.25, 1.0]);
        assert_eq!(s.total_power(), 4.0);
    }
}
