//! The polarization of a TM-25 file's rays (its Stokes flag, TM-25-13 4.7.2.6): six f32
//! columns after the fluxes and wavelength, `S1 S2 S3` then a vector `x y z`.
//!
//! Our reading (the standard's text, paywalled, was not seen; the public reference
//! implementation TM25RaySetTools reads the six columns without interpreting them): the
//! vector is the reference axis of the ray's Stokes vector, in the file's frame like the
//! ray's direction: made perpendicular to the direction it is the frame's `u`, `S1 > 0`
//! being light polarized along it, `S2 > 0` along `u` turned 45 degrees towards
//! `v = direction x u`, `S3 > 0` circular light turning from `u` towards `v` (the
//! conventions of [`crate::optics::polarization`] and of a source's `polarization` key).
//! `S0` is the ray's flux: `S1..S3` are in the flux's unit, and their degree of
//! polarization `sqrt(S1^2 + S2^2 + S3^2) / flux` must not exceed 1. Each photon the ray
//! emits starts in the ray's state; rays of a file without the flag start unpolarized.

use crate::optics::polarization::{Polarization, Stokes};
use glam::{DMat3, DVec3};

/// A ray's polarization as its file gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayStokes {
    /// `(S1, S2, S3) / S0`, `S0` the ray's flux.
    pub s: [f32; 3],
    /// The reference axis (file frame, any length; not along the ray).
    pub axis: [f32; 3],
}

/// Names of the six Stokes columns, for errors.
pub const STOKES_COLUMNS: [&str; 6] = ["S1", "S2", "S3", "Stokes x", "Stokes y", "Stokes z"];

/// Largest degree of polarization accepted: 1, with room for the f32 rounding of the
/// columns.
const MAX_DOP: f64 = 1.0 + 1e-5;

impl RayStokes {
    /// The columns `c` (`S1 S2 S3 x y z`) of a ray of direction `dir` and flux `flux`,
    /// checked: `Err((column, message))`.
    pub fn read(c: [f32; 6], dir: [f32; 3], flux: f32) -> Result<RayStokes, (usize, String)> {
        if let Some(k) = c.iter().position(|x| !x.is_finite()) {
            return Err((k, format!("must be a finite number, got {}", c[k])));
        }
        let s = if flux > 0.0 {
            [c[0] / flux, c[1] / flux, c[2] / flux]
        } else {
            [0.0; 3] // a ray of no flux is never drawn
        };
        let dop = Stokes([1.0, s[0].into(), s[1].into(), s[2].into()]).dop();
        if dop > MAX_DOP {
            return Err((
                0,
                format!(
                    "degree of polarization {dop:.6} is more than 1: S1^2 + S2^2 + S3^2 may not exceed the ray's flux squared ({flux})"
                ),
            ));
        }
        let axis = [c[3], c[4], c[5]];
        let a = DVec3::from_array(axis.map(f64::from));
        let d = DVec3::from_array(dir.map(f64::from)).normalize();
        if (a - a.dot(d) * d).length() <= 1e-6 * a.length().max(f64::MIN_POSITIVE) {
            return Err((
                3,
                format!(
                    "the reference axis ({}, {}, {}) must have a length and not lie along the ray",
                    c[3], c[4], c[5]
                ),
            ));
        }
        Ok(RayStokes { s, axis })
    }

    /// The six columns of a ray of flux `flux` (the writer's).
    pub fn columns(&self, flux: f32) -> [f32; 6] {
        let [a, b, c] = self.s.map(|x| x * flux);
        [a, b, c, self.axis[0], self.axis[1], self.axis[2]]
    }

    /// The state of a photon of this ray, placed by `rot` and travelling along the unit
    /// `d` (the placed direction).
    pub fn polarization(&self, rot: DMat3, d: DVec3) -> Polarization {
        let a = rot * DVec3::from_array(self.axis.map(f64::from));
        match (a - a.dot(d) * d).try_normalize() {
            Some(u) => Polarization {
                stokes: Stokes([1.0, self.s[0].into(), self.s[1].into(), self.s[2].into()]),
                u,
            },
            None => Polarization::unpolarized(d), // checked at reading: not reached
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{FileSpectrum, FluxUnit, RaySet, check_ray, tm25};
    use super::*;

    /// Two rays with wavelengths, polarized: linear at 30 degrees from x, and circular
    /// about an axis along y given at length 3.
    fn polarized_set() -> RaySet {
        let ray = |dir: [f32; 3], flux| check_ray([0.0; 3], dir, flux, None).unwrap();
        let (s, c) = (60f32.to_radians().sin(), 60f32.to_radians().cos());
        RaySet {
            text: Default::default(),
            rays: vec![ray([0.0, 0.0, 1.0], 2.0), ray([0.6, 0.0, 0.8], 0.5)],
            nm: vec![450.0, 550.0],
            table: Vec::new(),
            stokes: vec![
                RayStokes {
                    s: [c, s, 0.0],
                    axis: [1.0, 0.0, 0.0],
                },
                RayStokes {
                    s: [0.0, 0.0, 1.0],
                    axis: [0.0, 3.0, 0.0],
                },
            ],
            spectrum: FileSpectrum::PerRay,
            unit: FluxUnit::Watt,
            header_flux: [f64::NAN; 2],
        }
    }

    /// Written with the Stokes flag, six more columns a ray, and read back the same (the
    /// columns are `S` times the flux: exact at these fluxes, powers of 2).
    #[test]
    fn tm25_stokes_columns_round_trip() {
        let set = polarized_set();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pol.TM25RAY");
        tm25::write(&path, &set).unwrap();
        assert_eq!(std::fs::metadata(&path).unwrap().len(), 36288 + 2 * 14 * 4);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes[256 + 5 * 4], 1, "the Stokes flag (4.7.2.6) is set");
        let back = tm25::read(&path).unwrap();
        assert_eq!(back.stokes, set.stokes);
        assert_eq!(back.rays, set.rays);
        assert_eq!(back.nm, set.nm);
        // The state of a photon of the first ray, placed unturned: linear at 30 degrees
        // from x, its frame x.
        let p = back.stokes[0].polarization(DMat3::IDENTITY, DVec3::Z);
        assert_eq!(p.u, DVec3::X);
        let at30 = p.stokes_in(DVec3::Z, DVec3::new(0.75f64.sqrt(), 0.5, 0.0));
        assert!((at30.0[1] - 1.0).abs() < 1e-6, "{at30:?}");
    }

    /// A Stokes vector beyond full polarization, or an axis along the ray, is refused
    /// naming the ray, the column and its byte.
    #[test]
    fn tm25_stokes_errors_name_the_ray_and_the_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pol.TM25RAY");
        let mut set = polarized_set();
        set.stokes[1].s = [0.8, 0.8, 0.0];
        tm25::write(&path, &set).unwrap();
        let e = tm25::read(&path).unwrap_err().to_string();
        // Ray 1's S1: after 36288 header bytes, ray 0's 14 columns and ray 1's 8.
        let at = 36288 + 14 * 4 + 8 * 4;
        assert!(
            e.contains(&format!(
                "byte {at}: ray 1 S1 (4.7.2.6): degree of polarization"
            )),
            "{e}"
        );
        let mut set = polarized_set();
        set.stokes[1].axis = [0.6, 0.0, 0.8];
        tm25::write(&path, &set).unwrap();
        let e = tm25::read(&path).unwrap_err().to_string();
        assert!(
            e.contains(&format!("byte {}: ray 1 Stokes x (4.7.2.6)", at + 12)),
            "{e}"
        );
        assert!(e.contains("not lie along the ray"), "{e}");
    }
}
