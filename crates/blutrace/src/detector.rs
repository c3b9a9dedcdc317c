//! The fictitious target plane: a regular grid of flux bins plus an angular histogram.
//!
//! ```toml
//! [detector]
//! origin = [0.0, 0.0, 2.5]   # a corner of the target rectangle (mm)
//! u = [1.0, 0.0, 0.0]        # first in-plane axis (grid x)
//! v = [0.0, 1.0, 0.0]        # second in-plane axis (grid y); normal = u x v
//! size_mm = [300.0, 200.0]
//! bins = [100, 100]
//! angular_bins = [18, 36]    # theta over [0, 90] deg from the normal, phi over [0, 360)
//! luminance_cone_deg = 2.0   # half-angle of the luminance map's cone about each view
//! views = [[0.0, 0.0], [45.0, 0.0]]  # [theta_deg, phi_deg] of each luminance map; default the normal
//! analyzer_deg = 90.0        # optional: the panel's rear polarizer's transmission axis
//! ```
//!
//! The luminance map (cd/m², with lumens or spectra) counts the light leaving each bin
//! within `luminance_cone_deg` of the normal, as a luminance meter aimed at the panel
//! does. Default 2 degrees: a meter's lens accepts the rays from each point it sees within
//! atan(D / 2L) of its axis, 2.0 degrees for a 35 mm aperture at 500 mm, and spot meters'
//! measuring angles are of that size (Topcon BM-7: 0.1, 0.2, 1 and 2 degrees, BM-7A/BM-7AC
//! manual; Gamma Scientific GS-1160B: ±1 degree acceptance). A narrow cone sees few
//! photons: the map's errors say how many more it needs, and a map no photon fell in has
//! no value (`null`), not 0 cd/m².
//!
//! The cone is at least [`MIN_CONE_DEG`] wide: a photon is in it when its direction's
//! cosine with the normal is at least the cone's, `1 - (1 - cos c)`, and that margin
//! `1 - cos c` ≈ c²/2 must stand far above the cosine's rounding (~1e-16), or the cone is
//! a rounding artefact (at 1e-300 degrees its solid angle underflows to 0 and the map to
//! 0/0).
//!
//! `analyzer_deg = A` puts an ideal absorbing polarizer in front of the target (the
//! panel's rear polarizer): its transmission axis lies in the target plane at `A` degrees
//! from `u` towards `v`. Light along `d` meets the axis made perpendicular to `d` (as the
//! detector's frame is) and passes `(S0 + S1) / 2` of its Stokes vector in that frame
//! ([`TargetPlane::analyzer_transmittance`]); every detection is weighted by it, so the
//! flux, luminance, colour and Stokes outputs all see the analyzer, and the rest is booked
//! as `absorbed_by_analyzer_w`. An analyzer makes the scene trace polarization
//! (`[trace] polarization = false` with one is an error).
//!
//! A photon crossing the rectangle along the normal (from the back, towards the viewer)
//! is detected and stops there; one crossing the other way passes through.

use crate::geometry::Ray;
use crate::optics::polarization::{Polarization, Stokes};
use crate::spec_check::Ctx;
use anyhow::Result;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, TAU};

/// `[detector]`: the target plane as the scene file gives it.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DetectorSpec {
    /// A corner of the rectangle (mm).
    pub origin: [f64; 3],
    /// Grid-x axis.
    pub u: [f64; 3],
    /// Grid-y axis.
    pub v: [f64; 3],
    /// Width and height (mm).
    pub size_mm: [f64; 2],
    /// Flux bins.
    #[serde(default = "default_bins")]
    pub bins: [usize; 2],
    /// Angular bins (theta, phi).
    #[serde(default = "default_angular_bins")]
    pub angular_bins: [usize; 2],
    /// Half-angle (degrees) of the luminance map's cone about the normal.
    #[serde(default = "default_luminance_cone_deg")]
    pub luminance_cone_deg: f64,
    /// Transmission axis (degrees from `u` towards `v`) of an ideal absorbing polarizer
    /// in front of the target; none by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub analyzer_deg: Option<f64>,
    /// The directions a luminance meter looks from, `[theta_deg, phi_deg]` (theta from
    /// the normal, phi from u towards v): one luminance map each. Default: the normal.
    #[serde(default = "default_views")]
    pub views: Vec<[f64; 2]>,
}

fn default_views() -> Vec<[f64; 2]> {
    vec![[0.0, 0.0]]
}

fn default_luminance_cone_deg() -> f64 {
    2.0
}

fn default_bins() -> [usize; 2] {
    [100, 100]
}

fn default_angular_bins() -> [usize; 2] {
    [18, 36]
}

impl DetectorSpec {
    /// Check `[detector]` and build the target plane.
    pub fn build(&self, ctx: &Ctx) -> Result<TargetPlane> {
        let d = self;
        let u = ctx.direction("detector.u", d.u)?;
        let v = ctx.direction("detector.v", d.v)?;
        if u.dot(v).abs() > 1e-6 {
            return Err(ctx.err("detector.v", "must be perpendicular to detector.u"));
        }
        for (k, n) in d.bins.iter().chain(&d.angular_bins).enumerate() {
            let field = if k < 2 {
                "detector.bins"
            } else {
                "detector.angular_bins"
            };
            if *n == 0 || *n > 100_000 {
                return Err(ctx.err(
                    field,
                    format!("bin counts must be within 1..=100000, got {n}"),
                ));
            }
        }
        let cone = d.luminance_cone_deg;
        check_cone(cone).map_err(|e| ctx.err("detector.luminance_cone_deg", e))?;
        check_views(&d.views, cone).map_err(|e| ctx.err("detector.views", e))?;
        let analyzer = match d.analyzer_deg {
            Some(a) => {
                let (s, c) = ctx
                    .angle_deg("detector.analyzer_deg", a)?
                    .to_radians()
                    .sin_cos();
                Some(u * c + v * s)
            }
            None => None,
        };
        Ok(TargetPlane {
            analyzer,
            luminance_cone_deg: cone,
            cone_cos: cone.to_radians().cos(),
            views: d.views.clone(),
            origin: ctx.point("detector.origin", d.origin)?,
            u,
            v,
            size: [
                ctx.length("detector.size_mm[0]", d.size_mm[0])?,
                ctx.length("detector.size_mm[1]", d.size_mm[1])?,
            ],
            bins: d.bins,
            angular_bins: d.angular_bins,
        })
    }
}

/// The narrowest luminance cone (half-angle, degrees): there `1 - cos c` is 1.5e-10, so
/// the cosine's rounding (~1e-16) moves the cone's edge by a millionth of its solid
/// angle. A hundredth of the narrowest spot meter's angle (0.1 degrees, Topcon BM-7).
pub const MIN_CONE_DEG: f64 = 0.001;

/// A luminance cone's half-angle (degrees) must lie within [`MIN_CONE_DEG`] ..= 90.
fn check_cone(deg: f64) -> Result<(), String> {
    match (MIN_CONE_DEG..=90.0).contains(&deg) {
        true => Ok(()),
        false => Err(format!(
            "must be within [{MIN_CONE_DEG}, 90] degrees (a narrower cone is lost in the rounding of the directions' cosines), got {}",
            crate::spec_check::short(deg)
        )),
    }
}

/// Most luminance views a detector may have (each is a map, and a trace per scattering
/// event under the meter estimator).
pub const MAX_VIEWS: usize = 64;

/// Views must be 1..=[`MAX_VIEWS`] of finite angles whose cone stays above the plane:
/// `theta + cone <= 89` degrees (a cone reaching the plane would count light crossing it
/// sideways).
fn check_views(views: &[[f64; 2]], cone: f64) -> Result<(), String> {
    if views.is_empty() || views.len() > MAX_VIEWS {
        return Err(format!(
            "must list 1 to {MAX_VIEWS} [theta_deg, phi_deg] pairs, got {}",
            views.len()
        ));
    }
    for (i, [theta, phi]) in views.iter().enumerate() {
        let short = crate::spec_check::short;
        if !(theta.is_finite() && phi.is_finite()) {
            return Err(format!(
                "[{i}] must be finite angles, got [{}, {}]",
                short(*theta),
                short(*phi)
            ));
        }
        if !(0.0..=89.0 - cone).contains(theta) {
            return Err(format!(
                "[{i}]: theta_deg must be within [0, {}] (89 degrees less the luminance cone's {} degrees), got {}",
                short(89.0 - cone),
                short(cone),
                short(*theta)
            ));
        }
    }
    Ok(())
}

/// The target plane and its binning.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetPlane {
    /// A corner of the rectangle.
    pub origin: DVec3,
    /// Unit grid-x axis.
    pub u: DVec3,
    /// Unit grid-y axis (orthogonal to `u`).
    pub v: DVec3,
    /// Width and height (mm).
    pub size: [f64; 2],
    /// Flux bins along u and v.
    pub bins: [usize; 2],
    /// Angular bins: theta (0..90 deg) and phi (0..360 deg).
    pub angular_bins: [usize; 2],
    /// Half-angle (degrees) of the luminance map's cone about the normal.
    pub luminance_cone_deg: f64,
    /// Its cosine.
    pub cone_cos: f64,
    /// The luminance maps' views, `[theta_deg, phi_deg]` ([`DetectorSpec::views`]).
    pub views: Vec<[f64; 2]>,
    /// The unit transmission axis of the analyzer in front of the target, if any.
    pub analyzer: Option<DVec3>,
}

impl TargetPlane {
    /// Unit normal: the direction photons are detected travelling along.
    pub fn normal(&self) -> DVec3 {
        self.u.cross(self.v)
    }

    /// Set the luminance cone's half-angle to `deg` degrees, or say why not.
    pub fn set_luminance_cone(&mut self, deg: f64) -> Result<(), String> {
        check_cone(deg)?;
        check_views(&self.views, deg)?;
        self.luminance_cone_deg = deg;
        self.cone_cos = deg.to_radians().cos();
        Ok(())
    }

    /// The unit direction of view `k` (towards the viewer).
    #[inline]
    pub fn view_dir(&self, k: usize) -> DVec3 {
        // The normal view (the default) without trigonometry: every detection asks.
        if self.views[k][0] == 0.0 {
            return self.normal();
        }
        let [theta, phi] = self.views[k].map(f64::to_radians);
        let tangent = self.u * phi.cos() + self.v * phi.sin();
        (self.normal() * theta.cos() + tangent * theta.sin()).normalize()
    }

    /// The views (their indices, as a bit set) whose luminance cone holds `dir`.
    #[inline]
    pub fn cones_holding(&self, dir: DVec3) -> u64 {
        if let [[0.0, _]] = self.views[..] {
            return u64::from(dir.dot(self.normal()) >= self.cone_cos);
        }
        (0..self.views.len())
            .filter(|&k| dir.dot(self.view_dir(k)) >= self.cone_cos)
            .fold(0, |set, k| set | 1 << k)
    }

    /// Projected solid angle of view `k`'s luminance cone on the target plane,
    /// `cos(theta) pi sin^2(half-angle)` (sr): the integral of the direction's cosine
    /// with the normal over the cone, which is the cone's axis cosine times the integral
    /// of its cosine with the axis.
    pub fn cone_projected_solid_angle(&self, k: usize) -> f64 {
        let axis_cos = self.views[k][0].to_radians().cos();
        axis_cos * std::f64::consts::PI * self.luminance_cone_deg.to_radians().sin().powi(2)
    }

    /// Solid angle of the luminance cone, `2 pi (1 - cos c)` (sr), from the cone's
    /// margin `1 - cos c` computed without cancellation.
    pub fn cone_solid_angle(&self) -> f64 {
        let half = self.luminance_cone_deg.to_radians() / 2.0;
        TAU * 2.0 * half.sin().powi(2)
    }

    /// Size of one flux bin along u and v (mm).
    pub fn bin_size(&self) -> [f64; 2] {
        [
            self.size[0] / self.bins[0] as f64,
            self.size[1] / self.bins[1] as f64,
        ]
    }

    /// Area of one flux bin (mm^2).
    pub fn bin_area(&self) -> f64 {
        let [bx, by] = self.bin_size();
        bx * by
    }

    /// Area of the target rectangle (m^2).
    pub fn area_m2(&self) -> f64 {
        self.size[0] * self.size[1] * 1e-6
    }

    /// The warning of a flux map too coarse for some uniformity metrics (they are null):
    /// one bin has no spread (cv, min/max), and a side of 2 bins no distinct 9- and
    /// 13-point spots ([`crate::run::metrics::spots_apart`]).
    pub fn coarse_warning(&self) -> Option<String> {
        let [nx, ny] = self.bins;
        let apart = crate::run::metrics::spots_apart;
        let what = if nx * ny == 1 {
            "its cv, min/max and 9- and 13-point ratios are null"
        } else if !(apart(nx) && apart(ny)) {
            "its 9- and 13-point ratios are null (their 3x3-bin spots about the points at 1/6, 1/2 and 5/6 of a side of 2 bins all cover both)"
        } else {
            return None;
        };
        Some(format!(
            "detector.bins = [{nx}, {ny}]: the flux map is too coarse to measure all of its uniformity: {what}, not those of a perfectly uniform map"
        ))
    }

    /// Centre of bin `(ix, iy)` of an `nx` x `ny` grid over the target (the detector's
    /// own flux bins, or a map of another resolution).
    pub fn grid_centre(&self, [nx, ny]: [usize; 2], ix: usize, iy: usize) -> DVec3 {
        let (bx, by) = (self.size[0] / nx as f64, self.size[1] / ny as f64);
        self.origin + self.u * ((ix as f64 + 0.5) * bx) + self.v * ((iy as f64 + 0.5) * by)
    }

    /// Flux bins along the in-plane axis (u or v) closer to `axis`.
    pub fn bins_along(&self, axis: DVec3) -> usize {
        if self.u.dot(axis).abs() >= self.v.dot(axis).abs() {
            self.bins[0]
        } else {
            self.bins[1]
        }
    }

    /// Where `ray` crosses the rectangle forwards, nearer than `tmax`: distance and
    /// in-plane coordinates (mm).
    pub fn intersect(&self, ray: &Ray, tmax: f64) -> Option<(f64, [f64; 2])> {
        let n = self.normal();
        let denom = ray.dir.dot(n);
        if denom <= 0.0 {
            return None;
        }
        let t = (self.origin - ray.origin).dot(n) / denom;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        let r = ray.at(t) - self.origin;
        let (a, b) = (r.dot(self.u), r.dot(self.v));
        let inside = (0.0..self.size[0]).contains(&a) && (0.0..self.size[1]).contains(&b);
        inside.then_some((t, [a, b]))
    }

    /// The flux bin holding in-plane coordinates `ab`.
    pub fn flux_bin(&self, ab: [f64; 2]) -> (usize, usize) {
        let f = |k: usize| {
            let i = (ab[k] / self.size[k] * self.bins[k] as f64) as usize;
            i.min(self.bins[k] - 1)
        };
        (f(0), f(1))
    }

    /// Index of the flux bin holding `ab` in the flux grid (row-major, x fastest).
    pub fn flux_index(&self, ab: [f64; 2]) -> usize {
        let (ix, iy) = self.flux_bin(ab);
        iy * self.bins[0] + ix
    }

    /// Index of the angular bin of `dir` in the angular grid (theta fastest).
    pub fn angular_index(&self, dir: DVec3) -> usize {
        let (it, ip) = self.angular_bin(dir);
        ip * self.angular_bins[0] + it
    }

    /// Angular bin widths (degrees): theta, phi.
    pub fn angular_bin_deg(&self) -> [f64; 2] {
        let [nt, np] = self.angular_bins;
        [90.0 / nt as f64, 360.0 / np as f64]
    }

    /// Polar angle (degrees) at the centre of angular bin row `it`.
    pub fn theta_centre_deg(&self, it: usize) -> f64 {
        90.0 * (it as f64 + 0.5) / self.angular_bins[0] as f64
    }

    /// The (theta, phi) bin of a detected direction.
    pub fn angular_bin(&self, dir: DVec3) -> (usize, usize) {
        let (theta, phi) = self.angles(dir);
        let [nt, np] = self.angular_bins;
        let it = ((theta / FRAC_PI_2) * nt as f64) as usize;
        let ip = ((phi / TAU) * np as f64) as usize;
        (it.min(nt - 1), ip.min(np - 1))
    }

    /// Polar angle from the normal and azimuth from `u` towards `v` (radians).
    pub fn angles(&self, dir: DVec3) -> (f64, f64) {
        let theta = dir.dot(self.normal()).clamp(-1.0, 1.0).acos();
        let phi = dir.dot(self.v).atan2(dir.dot(self.u)).rem_euclid(TAU);
        (theta, phi)
    }

    /// Solid angle (sr) of angular bin row `it` (every phi bin in it has the same).
    pub fn angular_bin_solid_angle(&self, it: usize) -> f64 {
        let [nt, np] = self.angular_bins;
        let t0 = FRAC_PI_2 * it as f64 / nt as f64;
        let t1 = FRAC_PI_2 * (it + 1) as f64 / nt as f64;
        (t0.cos() - t1.cos()) * TAU / np as f64
    }

    /// Projected solid angle (sr, the integral of cos theta) of one bin in row `it`.
    pub fn angular_bin_projected_solid_angle(&self, it: usize) -> f64 {
        let [nt, np] = self.angular_bins;
        let t0 = FRAC_PI_2 * it as f64 / nt as f64;
        let t1 = FRAC_PI_2 * (it + 1) as f64 / nt as f64;
        0.5 * (t1.sin().powi(2) - t0.sin().powi(2)) * TAU / np as f64
    }

    /// The state of light detected along unit `dir` in state `pol`, past the analyzer if
    /// there is one, as `(S1, S2, S3) / S0` in the detector's frame: `u` made perpendicular
    /// to `dir` (`S1 > 0` along it), `v = dir x u` (at grazing `dir` along `u`, `v` made
    /// perpendicular instead).
    pub fn stokes_of(&self, pol: &Polarization, dir: DVec3) -> [f64; 3] {
        let frame = (self.u - self.u.dot(dir) * dir)
            .try_normalize()
            .unwrap_or_else(|| dir.cross(self.v).normalize());
        let state = match self.analyzer_axis(dir) {
            // What passes an ideal polarizer is polarized along its axis.
            Some(t) => Stokes::linear_deg(0.0).reframed(dir, t, frame),
            None => pol.stokes_in(dir, frame),
        };
        let [_, s1, s2, s3] = state.0;
        [s1, s2, s3]
    }

    /// The fraction of light along unit `dir` in state `pol` that the analyzer passes: 1
    /// without one, else `(S0 + S1) / 2` of the state referred to the analyzer's axis made
    /// perpendicular to `dir` (Malus's `cos^2` for linear light, 1/2 for unpolarized), 0
    /// for light travelling along the axis (its field is all across it). Every estimator of
    /// light on the target weights its detections by it.
    pub fn analyzer_transmittance(&self, pol: &Polarization, dir: DVec3) -> f64 {
        if self.analyzer.is_none() {
            return 1.0;
        }
        match self.analyzer_axis(dir) {
            Some(t) => (0.5 * (1.0 + pol.stokes_in(dir, t).0[1])).clamp(0.0, 1.0),
            None => 0.0,
        }
    }

    /// The analyzer's axis made perpendicular to unit `dir` (`None`: no analyzer, or
    /// `dir` along its axis).
    pub fn analyzer_axis(&self, dir: DVec3) -> Option<DVec3> {
        let a = self.analyzer?;
        (a - a.dot(dir) * dir).try_normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane() -> TargetPlane {
        TargetPlane {
            origin: DVec3::ZERO,
            u: DVec3::X,
            v: DVec3::Y,
            size: [10.0, 5.0],
            bins: [10, 5],
            angular_bins: [9, 12],
            luminance_cone_deg: 2.0,
            cone_cos: 2.0f64.to_radians().cos(),
            views: vec![[0.0, 0.0], [30.0, 90.0]],
            analyzer: None,
        }
    }

    #[test]
    fn detects_forward_crossings_only() {
        let p = plane();
        let up = Ray::new(DVec3::new(2.5, 1.5, -1.0), DVec3::Z);
        let (t, ab) = p.intersect(&up, 10.0).unwrap();
        assert_eq!(t, 1.0);
        assert_eq!(p.flux_bin(ab), (2, 1));
        let down = Ray::new(DVec3::new(2.5, 1.5, 1.0), DVec3::NEG_Z);
        assert!(p.intersect(&down, 10.0).is_none());
        let outside = Ray::new(DVec3::new(12.0, 1.5, -1.0), DVec3::Z);
        assert!(p.intersect(&outside, 10.0).is_none());
    }

    #[test]
    fn views_point_from_theta_and_phi() {
        let p = plane();
        assert!((p.view_dir(0) - DVec3::Z).length() < 1e-15);
        let oblique = p.view_dir(1);
        let want = DVec3::new(0.0, 0.5, 3f64.sqrt() / 2.0);
        assert!((oblique - want).length() < 1e-15, "{oblique}");
        assert_eq!(p.cones_holding(DVec3::Z), 1);
        assert_eq!(p.cones_holding(want), 2);
        assert_eq!(p.cones_holding(DVec3::X), 0);
    }

    #[test]
    fn cone_projected_solid_angle_integrates_the_cosine() {
        // Midpoint rule over the oblique view's cone, in polar coordinates about its axis.
        let p = plane();
        let axis = p.view_dir(1);
        let (t, b) = crate::geometry::orthonormal_basis(axis);
        let c = p.luminance_cone_deg.to_radians();
        let (na, nb) = (400, 400);
        let mut sum = 0.0;
        for i in 0..na {
            let a = c * (i as f64 + 0.5) / na as f64;
            for j in 0..nb {
                let phi = TAU * (j as f64 + 0.5) / nb as f64;
                let d = axis * a.cos() + (t * phi.cos() + b * phi.sin()) * a.sin();
                sum += d.dot(p.normal()) * a.sin() * (c / na as f64) * (TAU / nb as f64);
            }
        }
        let want = p.cone_projected_solid_angle(1);
        assert!((sum - want).abs() < 1e-6 * want, "{sum} vs {want}");
        let solid = 2.0 * std::f64::consts::PI * (1.0 - c.cos());
        assert!((p.cone_solid_angle() - solid).abs() < 1e-12 * solid);
    }

    #[test]
    fn angular_solid_angles_cover_hemisphere() {
        let p = plane();
        let total: f64 = (0..9).map(|it| p.angular_bin_solid_angle(it) * 12.0).sum();
        assert!((total - TAU).abs() < 1e-12);
        let projected: f64 = (0..9)
            .map(|it| p.angular_bin_projected_solid_angle(it) * 12.0)
            .sum();
        assert!((projected - std::f64::consts::PI).abs() < 1e-12);
    }
}
