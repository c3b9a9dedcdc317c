//! A ray file's emission: an alias table over the rays' flux (one uniform number picks a
//! ray, O(1) per photon), and the placement from the file's frame into the scene.

use super::{FileSpectrum, RaySet};
use crate::geometry::Ray;
use crate::optics::polarization::Polarization;
use crate::rng::PhotonRng;
use crate::sources::body_shape::{BodyShape, Rect};
use crate::sources::led::{FlatLed, LedProfile};
use crate::sources::spectrum::EmissionSpectrum;
use anyhow::Result;
use glam::{DMat3, DVec3};
use std::path::PathBuf;
use std::sync::Arc;

/// Walker's alias table (Vose's construction): cell `i` keeps itself with probability
/// `keep[i]`, else gives `alias[i]`; each cell is picked with probability 1/n.
#[derive(Clone, Debug, PartialEq)]
pub struct Alias {
    keep: Vec<f32>,
    alias: Vec<u32>,
}

impl Alias {
    /// The table for drawing index `i` with probability `w[i] / sum(w)` (`w` finite,
    /// non-negative, not all zero, at most 2^32 entries).
    pub fn new(w: impl ExactSizeIterator<Item = f64> + Clone) -> Alias {
        let n = w.len();
        let total: f64 = w.clone().sum();
        let mut scaled: Vec<f64> = w.map(|x| x * n as f64 / total).collect();
        let (mut small, mut large): (Vec<u32>, Vec<u32>) =
            (0..n as u32).partition(|&i| scaled[i as usize] < 1.0);
        let mut keep = vec![1.0f32; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
            keep[s as usize] = scaled[s as usize] as f32;
            alias[s as usize] = l;
            scaled[l as usize] -= 1.0 - scaled[s as usize];
            if scaled[l as usize] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left holds probability 1 up to rounding: it keeps itself.
        Alias { keep, alias }
    }

    /// The index drawn by one uniform number `u` in [0, 1).
    #[inline]
    pub fn sample(&self, u: f64) -> usize {
        let n = self.keep.len();
        let x = u * n as f64;
        let i = (x as usize).min(n - 1);
        if ((x - i as f64) as f32) < self.keep[i] {
            i
        } else {
            self.alias[i] as usize
        }
    }

    /// The probability of drawing index `i` (for tests and reports).
    pub fn probability(&self, i: usize) -> f64 {
        let n = self.keep.len() as f64;
        let mut p = self.keep[i] as f64;
        for (j, &a) in self.alias.iter().enumerate() {
            if a as usize == i && j != i {
                p += 1.0 - self.keep[j] as f64;
            }
        }
        p / n
    }
}

/// A ray file placed in the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RayFileEmitter {
    /// The file as the scene names it.
    pub file: PathBuf,
    /// Its rays, in the file's frame.
    pub set: Arc<RaySet>,
    alias: Arc<Alias>,
    /// The spectra of [`FileSpectrum::Tables`], by table (else empty).
    spectra: Arc<Vec<EmissionSpectrum>>,
    rot: DMat3,
    scale: f64,
    shift: DVec3,
    /// The lamp's front: the start points' extent across the axis, at the back-most one.
    pub front: Rect,
}

impl RayFileEmitter {
    /// Place `set` (read from `file`): `rot` turns the file's axes, `scale` makes its
    /// lengths mm, `shift` moves it (mm). `Err`: a spectral table without power within
    /// 360-830 nm, or rays whose table indices do not match the tables (what the reader
    /// rejects).
    pub fn new(
        file: PathBuf,
        set: Arc<RaySet>,
        rot: DMat3,
        scale: f64,
        shift: DVec3,
    ) -> Result<Self> {
        let spectra = set.table_spectra()?;
        set.check_table_indices()?;
        let alias = Arc::new(Alias::new(set.rays.iter().map(|r| r.flux as f64)));
        let (lo, hi) = set.bounds();
        let mid = DVec3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), lo.z);
        let front = Rect {
            center: shift + rot * (mid * scale),
            normal: (rot * DVec3::Z).normalize(),
            u: (rot * DVec3::X).normalize(),
            half_width: 0.5 * (hi.x - lo.x) * scale,
            half_height: 0.5 * (hi.y - lo.y) * scale,
        };
        Ok(Self {
            file,
            set,
            alias,
            spectra: Arc::new(spectra),
            rot,
            scale,
            shift,
            front,
        })
    }

    /// A photon leaving the file: a ray drawn in proportion to flux (one uniform), its
    /// placed ray, the lamp's axis (the spawn offset's direction) and its wavelength, if
    /// the file gives one per ray (with spectral tables per ray, one more uniform draws it
    /// from the ray's table, as the source's spectrum draws a table's for all rays).
    pub fn emit(&self, rng: &mut PhotonRng) -> (Ray, DVec3, Option<f64>) {
        let (ray, normal, nm, _) = self.emit_polarized(rng);
        (ray, normal, nm)
    }

    /// [`RayFileEmitter::emit`], with the ray's polarization when the file gives it
    /// ([`super::stokes`]).
    pub fn emit_polarized(
        &self,
        rng: &mut PhotonRng,
    ) -> (Ray, DVec3, Option<f64>, Option<Polarization>) {
        let i = self.alias.sample(rng.uniform());
        let r = &self.set.rays[i];
        let p = self.shift + self.rot * (DVec3::from_array(r.pos.map(f64::from)) * self.scale);
        let d = (self.rot * DVec3::from_array(r.dir.map(f64::from))).normalize();
        let nm = match &self.set.spectrum {
            FileSpectrum::PerRay => Some(self.set.nm[i] as f64),
            FileSpectrum::Single(nm) => Some(*nm),
            FileSpectrum::Tables(_) => {
                Some(self.spectra[self.set.table[i] as usize].sample(rng.uniform()))
            }
            FileSpectrum::None | FileSpectrum::Table(_) => None,
        };
        let pol = self.set.stokes.get(i).map(|s| s.polarization(self.rot, d));
        (Ray::new(p, d), self.front.normal, nm, pol)
    }

    /// The probability that a photon starts from ray `i`.
    pub fn probability(&self, i: usize) -> f64 {
        self.alias.probability(i)
    }

    /// Move it by `d` (mm).
    pub fn translate(&mut self, d: DVec3) {
        self.shift += d;
        self.front.center += d;
    }

    /// The front rectangle as a flat emitter's window (its profile is not used): the
    /// rectangle's grid, distance and shape.
    pub fn window(&self) -> FlatLed {
        FlatLed {
            center: self.front.center,
            normal: self.front.normal,
            u: self.front.u,
            width: 2.0 * self.front.half_width,
            height: 2.0 * self.front.half_height,
            profile: LedProfile::CosPower(1.0),
        }
    }

    /// The front rectangle as a body shape.
    pub fn shape(&self) -> BodyShape {
        BodyShape::Rectangle(self.front)
    }

    /// The start points' bounding box in the scene (mm): the box of the file's, placed.
    pub fn scene_bounds(&self) -> (DVec3, DVec3) {
        let (lo, hi) = self.set.bounds();
        (0..8).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), k| {
            let c = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let p = self.shift + self.rot * (c * self.scale);
            (a.min(p), b.max(p))
        })
    }
}

/// What `check` shows of a ray file source.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RayFileSummary {
    /// The file as the scene names it.
    pub file: String,
    /// Its non-empty TM-25 text fields, by name.
    pub text: Vec<(String, String)>,
    /// Number of rays.
    pub rays: usize,
    /// Total flux of the rays and its unit ("W" or "lm").
    pub total_flux: f64,
    /// "W" or "lm".
    pub flux_unit: &'static str,
    /// The start points' bounds in the file's frame (file units) and in the scene (mm).
    pub bounds_file: [[f64; 3]; 2],
    /// The placed bounds (mm).
    pub bounds_scene_mm: [[f64; 3]; 2],
    /// What the file says of wavelengths.
    pub spectrum: String,
}

impl RayFileEmitter {
    /// The summary `check` prints.
    pub fn summary(&self) -> RayFileSummary {
        let s = &self.set;
        let text = super::TEXT_FIELD_NAMES
            .iter()
            .zip(&s.text)
            .filter(|(_, t)| !t.is_empty())
            .map(|(n, t)| (n.to_string(), t.clone()))
            .collect();
        let (lo, hi) = s.bounds();
        let (slo, shi) = self.scene_bounds();
        let range = s
            .wavelength_range()
            .map_or(String::new(), |(a, b)| format!(", {a}-{b} nm"));
        let spectrum = match &s.spectrum {
            FileSpectrum::None => "none (monochrome unless the entry gives spectrum)".to_string(),
            FileSpectrum::Single(nm) => format!("one wavelength, {nm} nm"),
            FileSpectrum::PerRay => format!("a wavelength per ray{range}"),
            FileSpectrum::Table(rows) => {
                format!("one table of {} rows for every ray{range}", rows.len())
            }
            FileSpectrum::Tables(tables) => {
                format!(
                    "{} spectral tables, one per ray by index{range}",
                    tables.len()
                )
            }
        };
        RayFileSummary {
            file: self.file.display().to_string(),
            text,
            rays: s.rays.len(),
            total_flux: s.total_flux(),
            flux_unit: match s.unit {
                super::FluxUnit::Watt => "W",
                super::FluxUnit::Lumen => "lm",
            },
            bounds_file: [lo.to_array(), hi.to_array()],
            bounds_scene_mm: [slo.to_array(), shi.to_array()],
            spectrum,
        }
    }
}
