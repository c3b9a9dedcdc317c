//! A rough dielectric face: a surface diffuser (e.g. the bead-coated face of a diffuser
//! sheet), never meshed.
//!
//! ```toml
//! [surfaces.diffuser_top]
//! model = "diffuser"
//! inside = "pet"
//! outside = "air"     # default
//! roughness = 0.5     # GGX alpha, >= 0 (0: a smooth dielectric face)
//! ```
//!
//! ## Model
//! The face is a random micro-surface with the GGX (Trowbridge-Reitz) distribution of
//! facet normals of roughness `alpha` (facet slopes have density
//! `1 / (pi alpha^2 (1 + |slope|^2 / alpha^2)^2)`: `alpha` is the slope at which it falls
//! to a quarter, `alpha = 0.5` is a facet tilt of 27 deg). At each hit:
//!
//! 1. the facet the photon meets is drawn from the distribution of facet normals *visible*
//!    from its direction (Heitz 2018, exact for GGX: it includes Smith's masking on the
//!    way in and weights facets by their projected area);
//! 2. Fresnel roulette at that facet's normal: reflection, refraction or total internal
//!    reflection, exactly as at a smooth face;
//! 3. if the new direction points back into the mean surface (it would meet the rough
//!    surface again), steps 1-2 repeat from the medium it is now in (up to 64 times, then
//!    a mirror reflection at the mean plane). This is the height-free random walk of
//!    multiple scattering (Heitz et al. 2016 without the height field): shadowing on the
//!    way out is not otherwise applied.
//!
//! The face is lossless (every photon is reflected or transmitted: the ledger stays
//! exact) and `alpha -> 0` gives back the smooth Fresnel interface.

pub mod density;

use super::fresnel;
use super::medium::{Interface, Medium, air};
use super::model::{Arrival, Feature, MeterLayer, MeterVertex, Outcome, Surface, SurfaceSpecOf};
use super::polarization::{Polarization, fresnel_roulette};
use crate::geometry::orthonormal_basis;
use crate::rng::PhotonRng;
use crate::spec_check::{Ctx, short};
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// Largest accepted diffuser roughness (GGX alpha; a facet tilt of 76 deg at a quarter of
/// the peak density). Rougher faces are not surface diffusers any more.
pub const MAX_ROUGHNESS: f64 = 4.0;

/// `[surfaces.TAG]` with `model = "diffuser"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiffuserSpec {
    /// Medium behind the face.
    pub inside: String,
    /// Medium in front of the face.
    #[serde(default = "air")]
    pub outside: String,
    /// GGX roughness alpha (0: smooth).
    pub roughness: f64,
}

/// A rough dielectric face: its interface and GGX roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuser {
    /// The two media either side.
    pub interface: Interface,
    /// GGX roughness alpha (0: smooth).
    pub roughness: f64,
}

impl Surface for Diffuser {
    #[inline]
    fn interact(&self, at: &Arrival, rng: &mut PhotonRng) -> (Outcome, Feature) {
        let i = &self.interface;
        let mut pol = at.pol;
        let (normal, indices) = (at.hit.normal, at.indices(i));
        let out = scatter_carrying(self.roughness, indices, normal, at.dir, pol.as_mut(), rng);
        at.pol_out.set(pol);
        (at.lossless(i, out), Feature::Plain)
    }

    fn interface(&self) -> Option<Interface> {
        Some(self.interface)
    }

    /// A rough face's walk has no closed-form density: the meter estimates it
    /// ([`density`]); a smooth one is a plain interface.
    fn meter_vertex(&self, _feature: Feature) -> MeterVertex {
        match self.roughness > 0.0 {
            true => MeterVertex::Stochastic,
            false => MeterVertex::Specular,
        }
    }

    fn meter_layer(&self) -> MeterLayer {
        match self.roughness > 0.0 {
            true => MeterLayer::Not,
            false => MeterLayer::Flat,
        }
    }

    fn meter_response(
        &self,
        at: &Arrival,
        _feature: Feature,
        out: DVec3,
        response: &dyn Fn(Option<&Polarization>) -> f64,
        rng: &mut PhotonRng,
    ) -> f64 {
        let face = density::Face {
            alpha: self.roughness,
            indices: at.indices(&self.interface),
            normal: at.hit.normal,
        };
        face.exit_density(at.dir, at.pol, out, response, rng)
    }
}

impl SurfaceSpecOf for DiffuserSpec {
    /// Check `[surfaces.TAG]` and build its model: the interface and the roughness.
    type Model = Diffuser;

    fn build(&self, ctx: &Ctx, at: &str, media: &[Medium]) -> Result<Diffuser> {
        let field = format!("{at}.roughness");
        let alpha = ctx.non_negative(&field, self.roughness)?;
        if alpha > MAX_ROUGHNESS {
            return Err(ctx.err(
                &field,
                format!(
                    "must be at most {MAX_ROUGHNESS} (GGX alpha), got {}",
                    short(alpha)
                ),
            ));
        }
        Ok(Diffuser {
            interface: Interface::build(ctx, at, &self.inside, &self.outside, media)?,
            roughness: alpha,
        })
    }
}

/// Micro-facet events at one hit before the model gives up (mirror at the mean plane).
pub const MAX_EVENTS: usize = 64;

/// A GGX facet normal visible from `wi` (unit, pointing away from the surface, on the
/// side of the unit mean normal `n`), with density `D_wi(m)`, from two uniforms.
pub fn sample_visible_normal(n: DVec3, wi: DVec3, alpha: f64, u1: f64, u2: f64) -> DVec3 {
    if alpha == 0.0 {
        return n;
    }
    let (t, b) = orthonormal_basis(n);
    let wl = DVec3::new(wi.dot(t), wi.dot(b), wi.dot(n).max(0.0));
    // Stretch to the unit-roughness configuration.
    let vh = DVec3::new(alpha * wl.x, alpha * wl.y, wl.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        DVec3::X
    };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = TAU * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    // Unstretch.
    let ne = DVec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-9)).normalize();
    (t * ne.x + b * ne.y + n * ne.z).normalize()
}

/// Scatter a photon arriving along unit `dir` at a rough face with outward unit mean
/// normal `normal` (pointing from `inside`, index `n_inside`, to `outside`): its new
/// direction and whether it leaves into the inside medium.
pub fn scatter(
    alpha: f64,
    indices: (f64, f64),
    normal: DVec3,
    dir: DVec3,
    rng: &mut PhotonRng,
) -> (DVec3, bool) {
    scatter_carrying(alpha, indices, normal, dir, None, rng)
}

/// [`scatter`], carrying `pol` (when polarization is traced) through every facet's
/// Fresnel event.
pub fn scatter_carrying(
    alpha: f64,
    (n_inside, n_outside): (f64, f64),
    normal: DVec3,
    dir: DVec3,
    mut pol: Option<&mut Polarization>,
    rng: &mut PhotonRng,
) -> (DVec3, bool) {
    let mut inside = dir.dot(normal) > 0.0;
    let mut d = dir;
    for _ in 0..MAX_EVENTS {
        let facing = if inside { -normal } else { normal };
        if d.dot(facing) >= 0.0 {
            return (d, inside);
        }
        let (n1, n2) = if inside {
            (n_inside, n_outside)
        } else {
            (n_outside, n_inside)
        };
        let m = sample_visible_normal(facing, -d, alpha, rng.uniform(), rng.uniform());
        if -d.dot(m) <= 0.0 {
            continue; // a facet seen edge-on (rounding): draw another
        }
        match fresnel_roulette(d, m, (n1, n2), pol.as_deref_mut(), rng) {
            Some(t) => {
                d = t;
                inside = !inside;
            }
            None => d = fresnel::reflect(d, m).normalize(),
        }
    }
    let facing = if inside { -normal } else { normal };
    if d.dot(facing) < 0.0 {
        if let Some(p) = pol {
            *p = super::polarization::mirrored(p, d, facing);
        }
        d = fresnel::reflect(d, facing);
    }
    (d, inside)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir_at(theta_deg: f64, down: bool) -> DVec3 {
        let t = theta_deg.to_radians();
        DVec3::new(t.sin(), 0.0, if down { -t.cos() } else { t.cos() })
    }

    #[test]
    fn zero_roughness_is_the_smooth_interface() {
        let n = 100_000;
        let dir = dir_at(30.0, true);
        let mut reflected = 0;
        for i in 0..n {
            let mut rng = PhotonRng::new(5, i);
            let (d, inside) = scatter(0.0, (1.5, 1.0), DVec3::Z, dir, &mut rng);
            if inside {
                let t = fresnel::refract(dir, DVec3::Z, 1.0, 1.5).unwrap();
                assert!((d - t).length() < 1e-12);
            } else {
                assert!((d - fresnel::reflect(dir, DVec3::Z)).length() < 1e-12);
                reflected += 1;
            }
        }
        let r = fresnel::reflectance(30f64.to_radians().cos(), 1.0, 1.5);
        let got = reflected as f64 / n as f64;
        let sigma = (r * (1.0 - r) / n as f64).sqrt();
        assert!((got - r).abs() < 4.0 * sigma, "R {r}, got {got}");
    }

    #[test]
    fn every_photon_leaves_on_the_side_of_its_medium() {
        for alpha in [0.1, 0.5, 1.0, 3.0] {
            for i in 0..20_000u64 {
                let mut rng = PhotonRng::new(6, i);
                let theta = 89.0 * rng.uniform();
                let from_inside = i % 2 == 0;
                let dir = dir_at(theta, !from_inside);
                let (d, inside) = scatter(alpha, (1.58, 1.0), DVec3::Z, dir, &mut rng);
                assert!((d.length() - 1.0).abs() < 1e-9);
                assert_eq!(inside, d.z < 0.0, "alpha {alpha}: {dir:?} -> {d:?}");
            }
        }
    }

    #[test]
    fn roughness_spreads_the_transmitted_light() {
        // Normal incidence from air into n = 1.58: smooth, every transmitted photon goes
        // straight on; rougher faces spread it more (mean cosine falls).
        let mean_cos = |alpha: f64| {
            let (mut sum, mut k) = (0.0, 0);
            for i in 0..40_000u64 {
                let mut rng = PhotonRng::new(7, i);
                let (d, inside) = scatter(alpha, (1.58, 1.0), DVec3::Z, DVec3::NEG_Z, &mut rng);
                if inside {
                    sum += -d.z;
                    k += 1;
                }
            }
            sum / k as f64
        };
        let (c0, c1, c2) = (mean_cos(0.0), mean_cos(0.3), mean_cos(1.0));
        assert!((c0 - 1.0).abs() < 1e-12);
        assert!(c1 < 0.99 && c2 < c1 - 0.05, "{c0} {c1} {c2}");
    }

    #[test]
    fn visible_normals_face_the_viewer() {
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        let wi = (n + DVec3::new(0.8, 0.1, 0.0)).normalize();
        for i in 0..10_000 {
            let u1 = (i as f64 + 0.5) / 10_000.0;
            let m = sample_visible_normal(n, wi, 0.7, u1, (i as f64 * 0.618).fract());
            assert!(m.dot(wi) >= -1e-12 && m.dot(n) > 0.0);
        }
    }
}
