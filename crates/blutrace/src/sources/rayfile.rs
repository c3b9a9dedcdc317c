//! Ray files as sources: a measured or simulated LED given as rays (start point,
//! direction, flux, optionally a wavelength), in the IES TM-25-13 binary format
//! ([`tm25`]) or as plain text ([`text`]), placed in the scene like a geometry file and
//! sampled with replacement in proportion to flux ([`RayFileEmitter`]).
//!
//! ```toml
//! [[sources]]
//! type = "rayfile"
//! file = "led.TM25RAY"        # .TM25RAY (any case): TM-25-13; anything else: text rows
//!                             # "x y z kx ky kz flux [nm]" ('#' starts a comment)
//! units = "mm"                # the file's length unit: mm (default, TM-25's) | cm | m | in
//! rotate_deg = [0.0, 90.0, 0.0]  # about x, then y, then z (or matrix = 4 x 4 rows, rigid)
//! translate = [-0.3, 9.0, 0.275] # mm, last
//! # power_w = 0.03            # default: the file's total radiant flux (W)
//! # spectrum = "cie-led-b5"   # only for a file without wavelengths
//! body = { model = "lambert", albedo = 0.8 }   # as for LEDs (see `body`)
//! # package_depth_mm = 0.6
//! ```
//!
//! A file point `p` lands at `translate + R (units * p)`, a direction `k` at `R k`. The
//! file's +z is the lamp's axis (TM-25 files put the emitting side towards +z): the lamp's
//! body is the rectangle spanning the start points across that axis at the back-most
//! start point (every ray starts on or in front of it), with `package_depth_mm` a box
//! behind it; it is also what placement checks test parts against, and the emitted
//! photons' spawn offset is along the axis, as an LED's is along its normal.
//!
//! Wavelengths: a TM-25 file with a wavelength per ray (spectral data identifier 2), a
//! single wavelength (1), or a text file with an `nm` column gives each photon its ray's
//! wavelength; its colour (luminous efficacy, lumens) is the flux-weighted 1 nm histogram
//! of the rays' wavelengths, linear between bins. A TM-25 file with one spectral table
//! for all rays (3) draws each photon's wavelength from the table. A TM-25 file with
//! several spectral tables and a spectrum index per ray (4: a white LED whose colour
//! changes over angle) draws each photon's wavelength from its ray's table, the same way;
//! its colour is the mixture of the tables weighted by the flux of the rays using each.
//! A file without wavelengths is monochrome unless the entry gives `spectrum = ...`.
//! Wavelengths must lie within 360-830 nm, the CIE observer's range (a table's part
//! outside it is dropped).
//!
//! Rays are stored as f32, in the file's own frame: within a package (a few mm) an f32
//! position resolves 0.1 nm, and the placement (rotation, translation) is applied in f64 at
//! emission, so a lamp 500 mm from the origin loses nothing. A ray costs 28 bytes and its
//! alias-table cell 8: 20M rays take 720 MB; a wavelength per ray adds 4 bytes, a spectral
//! table index per ray 2 (a u16: at most [`MAX_TABLES`] tables).

mod emitter;
pub mod stokes;
pub mod text;
pub mod tm25;

pub use emitter::{Alias, RayFileEmitter, RayFileSummary};
pub use stokes::RayStokes;

use super::array::ArraySpec;
use super::body::BodySpec;
use super::spectrum::{EmissionSpectrum, SpectrumSpec, VISIBLE_NM};
use crate::color::Spectrum;
use crate::input_file::MAX_INPUT_BYTES;
use crate::optics::medium::air;
use crate::sources::MAX_TOTAL_POWER_W;
use crate::spec_check::{Ctx, short};
use crate::transform::{Units, affine_matrix, rotation_deg};
use anyhow::{Result, bail};
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `[[sources]]` with `type = "rayfile"`.
#[derive(Clone, Debug, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RayFileSpec {
    /// Name for reports.
    pub name: Option<String>,
    /// The ray file, relative to the scene file.
    pub file: PathBuf,
    /// The file's length unit (default mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Units>,
    /// Rotation about x, then y, then z (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate_deg: Option<[f64; 3]>,
    /// Row-major 4 x 4 rigid transform, instead of `rotate_deg`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<[[f64; 4]; 4]>,
    /// Translation (mm), applied last.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Radiant power (W); default: the file's total radiant flux.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub power_w: Option<f64>,
    /// Luminous flux (lm), for luminance outputs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lumens: Option<f64>,
    /// The state of the emitted light ([`super::polarization`]); unpolarized without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<super::polarization::SourcePolarizationSpec>,
    /// Emission spectrum, for a file without wavelengths ([`super::spectrum`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectrum: Option<SpectrumSpec>,
    /// Medium the rays start in.
    #[serde(default = "air")]
    pub medium: String,
    /// What light returning to the lamp meets ([`super::body`]).
    #[serde(default)]
    pub body: BodySpec,
    /// Depth of a box package behind the start points (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub package_depth_mm: Option<f64>,
    /// A row of copies of this source ([`mod@super::array`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub array: Option<ArraySpec>,
}

/// The nine description fields of TM-25-13 (4.7.3.1 to 4.7.3.9).
pub const TEXT_FIELDS: usize = 9;

/// Names of the text fields, for reports.
pub const TEXT_FIELD_NAMES: [&str; TEXT_FIELDS] = [
    "light source",
    "manufacturer",
    "model creator",
    "ray file creator",
    "equipment or software",
    "camera",
    "operation",
    "additional information",
    "data reference",
];

/// One ray, in the file's frame: 28 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StoredRay {
    /// Start point (file units).
    pub pos: [f32; 3],
    /// Unit direction.
    pub dir: [f32; 3],
    /// Flux (W, or lm for a luminous-only TM-25 file).
    pub flux: f32,
}

/// What a ray file says of wavelengths.
#[derive(Clone, Debug, PartialEq)]
pub enum FileSpectrum {
    /// Nothing.
    None,
    /// One wavelength (nm) for every ray.
    Single(f64),
    /// A wavelength per ray ([`RaySet::nm`]).
    PerRay,
    /// One spectral table `[nm, relative power]` for every ray.
    Table(Vec<[f64; 2]>),
    /// Several spectral tables; each ray's wavelength is drawn from the one
    /// [`RaySet::table`] names.
    Tables(Vec<Vec<[f64; 2]>>),
}

/// Most spectral tables a ray set may hold with [`FileSpectrum::Tables`]: a ray's table
/// is stored as a u16.
pub const MAX_TABLES: usize = u16::MAX as usize + 1;

/// The unit of the rays' flux.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FluxUnit {
    /// Radiant flux (W).
    Watt,
    /// Luminous flux only (lm).
    Lumen,
}

/// A ray file's content.
#[derive(Clone, PartialEq)]
pub struct RaySet {
    /// The nine text fields ([`TEXT_FIELD_NAMES`]; empty for a text file).
    pub text: [String; TEXT_FIELDS],
    /// The rays.
    pub rays: Vec<StoredRay>,
    /// The rays' wavelengths (nm) when [`FileSpectrum::PerRay`], else empty.
    pub nm: Vec<f32>,
    /// The rays' spectral tables (0-based positions in [`FileSpectrum::Tables`]) when the
    /// set has several, else empty.
    pub table: Vec<u16>,
    /// The rays' polarization when the file gives it (TM-25's Stokes columns, see
    /// [`stokes`]), else empty.
    pub stokes: Vec<RayStokes>,
    /// What the file says of wavelengths.
    pub spectrum: FileSpectrum,
    /// The flux's unit.
    pub unit: FluxUnit,
    /// The header's total radiant (W) and luminous (lm) flux (TM-25; NaN when not given).
    pub header_flux: [f64; 2],
}

impl std::fmt::Debug for RaySet {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match &self.spectrum {
            FileSpectrum::Tables(t) => write!(
                f,
                "RaySet({} rays, {:?}, Tables({} tables))",
                self.rays.len(),
                self.unit,
                t.len()
            ),
            spectrum => write!(
                f,
                "RaySet({} rays, {:?}, {spectrum:?})",
                self.rays.len(),
                self.unit
            ),
        }
    }
}

/// Check one ray: `Err((column, why))` with column 0-5 for x..kz, 6 the flux, 7 the
/// wavelength; the direction is normalized.
pub fn check_ray(
    pos: [f32; 3],
    dir: [f32; 3],
    flux: f32,
    nm: Option<f32>,
) -> Result<StoredRay, (usize, String)> {
    if let Some(k) = pos.iter().position(|x| !x.is_finite()) {
        return Err((k, format!("must be a finite number, got {}", pos[k])));
    }
    if let Some(k) = dir.iter().position(|x| !x.is_finite()) {
        return Err((3 + k, format!("must be a finite number, got {}", dir[k])));
    }
    let d = DVec3::from_array(dir.map(f64::from));
    if d.length() < 1e-6 {
        return Err((
            3,
            format!(
                "the direction ({}, {}, {}) has no length",
                dir[0], dir[1], dir[2]
            ),
        ));
    }
    if !(flux.is_finite() && flux >= 0.0) {
        return Err((
            6,
            format!("must be finite and >= 0, got {}", short(f64::from(flux))),
        ));
    }
    if let Some(w) = nm
        && !(VISIBLE_NM.0..=VISIBLE_NM.1).contains(&(w as f64))
    {
        return Err((
            7,
            format!(
                "must be within {}-{} nm, got {w}",
                VISIBLE_NM.0, VISIBLE_NM.1
            ),
        ));
    }
    Ok(StoredRay {
        pos,
        dir: d.normalize().to_array().map(|x| x as f32),
        flux,
    })
}

impl RaySet {
    /// Read a ray file: TM-25-13 for a `.tm25ray` extension (any case), else text rows.
    pub fn read(path: &Path) -> Result<RaySet> {
        let tm25 = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("tm25ray"));
        if tm25 {
            tm25::read(path)
        } else {
            text::read(path)
        }
    }

    /// The sum of the rays' flux.
    pub fn total_flux(&self) -> f64 {
        self.rays.iter().map(|r| r.flux as f64).sum()
    }

    /// The smallest and largest wavelength the file gives (nm).
    pub fn wavelength_range(&self) -> Option<(f64, f64)> {
        match &self.spectrum {
            FileSpectrum::None => None,
            FileSpectrum::Single(nm) => Some((*nm, *nm)),
            FileSpectrum::PerRay => self.nm.iter().fold(None, |r, &w| {
                let w = w as f64;
                Some(r.map_or((w, w), |(a, b): (f64, f64)| (a.min(w), b.max(w))))
            }),
            FileSpectrum::Table(rows) => Some((rows[0][0], rows[rows.len() - 1][0])),
            FileSpectrum::Tables(tables) => tables.iter().fold(None, |r, rows| {
                let (a, b) = (rows[0][0], rows[rows.len() - 1][0]);
                Some(r.map_or((a, b), |(lo, hi): (f64, f64)| (lo.min(a), hi.max(b))))
            }),
        }
    }

    /// The start points' bounding box in the file's frame (file units).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.rays
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), r| {
                let p = DVec3::from_array(r.pos.map(f64::from));
                (lo.min(p), hi.max(p))
            })
    }

    /// The file's own spectrum: its table; the mixture of its tables, each weighted by the
    /// flux of the rays using it; or the flux-weighted 1 nm histogram of its rays'
    /// wavelengths (`None`: no wavelengths; `Err`: no power within 360-830 nm).
    pub fn emission_spectrum(&self) -> Option<Result<EmissionSpectrum>> {
        let spectrum = match &self.spectrum {
            FileSpectrum::None => return None,
            FileSpectrum::Table(rows) => {
                return Some(
                    table_spectrum(rows)
                        .map_err(|e| anyhow::anyhow!("the file's spectral table: {e}")),
                );
            }
            FileSpectrum::Tables(_) => {
                return Some(self.table_spectra().and_then(|spectra| {
                    let mut flux = vec![0.0; spectra.len()];
                    for (r, &t) in self.rays.iter().zip(&self.table) {
                        if let Some(f) = flux.get_mut(t as usize) {
                            *f += r.flux as f64;
                        }
                    }
                    let parts: Vec<_> = flux.iter().copied().zip(&spectra).collect();
                    EmissionSpectrum::mixture(&parts).ok_or_else(|| {
                        anyhow::anyhow!("the rays of the file's spectral tables carry no flux")
                    })
                }));
            }
            FileSpectrum::Single(nm) => histogram(std::iter::once((*nm, 1.0))),
            FileSpectrum::PerRay => histogram(
                self.nm
                    .iter()
                    .zip(&self.rays)
                    .map(|(&w, r)| (w as f64, r.flux as f64)),
            ),
        };
        Some(spectrum.and_then(|s| {
            EmissionSpectrum::new(&s).ok_or_else(|| {
                anyhow::anyhow!("the file's spectrum has no power within 360-830 nm")
            })
        }))
    }

    /// With [`FileSpectrum::Tables`], that every ray has a table index and every index
    /// names one of the tables (what the reader checks of a file; a set built in code may
    /// not hold it).
    pub fn check_table_indices(&self) -> Result<()> {
        let FileSpectrum::Tables(tables) = &self.spectrum else {
            return Ok(());
        };
        if self.table.len() != self.rays.len() {
            bail!(
                "{} rays but {} spectral table indices",
                self.rays.len(),
                self.table.len()
            );
        }
        if let Some(i) = self.table.iter().position(|&t| t as usize >= tables.len()) {
            bail!(
                "ray {i}: spectral table {} of {}",
                self.table[i] as usize + 1,
                tables.len()
            );
        }
        Ok(())
    }

    /// The emission spectrum of each of the set's tables ([`FileSpectrum::Tables`]; empty
    /// for any other), as [`FileSpectrum::Table`]'s: `Err` names a table without power
    /// within 360-830 nm (numbered from 1, as TM-25 does).
    pub fn table_spectra(&self) -> Result<Vec<EmissionSpectrum>> {
        let FileSpectrum::Tables(tables) = &self.spectrum else {
            return Ok(Vec::new());
        };
        tables
            .iter()
            .enumerate()
            .map(|(k, rows)| {
                table_spectrum(rows).map_err(|e| anyhow::anyhow!("spectral table {}: {e}", k + 1))
            })
            .collect()
    }
}

/// A spectral table's emission spectrum: linear between rows, kept within 360-830 nm.
pub fn table_spectrum(rows: &[[f64; 2]]) -> Result<EmissionSpectrum> {
    let s = Spectrum::from_rows(rows).map_err(|e| anyhow::anyhow!("{e}"))?;
    EmissionSpectrum::new(&s)
        .ok_or_else(|| anyhow::anyhow!("the table has no power within 360-830 nm"))
}

/// A spectrum of `(nm, flux)` pairs binned at 1 nm (nearest), linear between bins.
fn histogram(pairs: impl Iterator<Item = (f64, f64)>) -> Result<Spectrum> {
    let first = VISIBLE_NM.0 as i64 - 1;
    let mut bins = vec![0.0; (VISIBLE_NM.1 - VISIBLE_NM.0) as usize + 3];
    let last = bins.len() as i64 - 1;
    for (nm, flux) in pairs {
        bins[(nm.round() as i64 - first).clamp(0, last) as usize] += flux;
    }
    let rows: Vec<[f64; 2]> = bins
        .iter()
        .enumerate()
        .map(|(k, &v)| [(first + k as i64) as f64, v])
        .collect();
    Spectrum::from_rows(&rows).map_err(|e| anyhow::anyhow!("{e}"))
}

/// The length of `path` if it is a regular file of at most [`MAX_INPUT_BYTES`].
fn checked_len(path: &Path) -> Result<u64> {
    let meta = std::fs::metadata(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read ray file: {e}", path.display()))?;
    if !meta.is_file() || meta.len() > MAX_INPUT_BYTES {
        bail!(
            "{}: cannot read ray file: not a regular file of at most {} GiB",
            path.display(),
            MAX_INPUT_BYTES >> 30
        );
    }
    Ok(meta.len())
}

impl RayFileSpec {
    /// Check the entry (`at` names it, `sources[i]`), read its file and build the emitter.
    pub fn emitter(&self, ctx: &Ctx, at: &str) -> Result<RayFileEmitter> {
        let f = |k: &str| format!("{at}.{k}");
        let dir = ctx.0.parent().unwrap_or(Path::new("."));
        let set = RaySet::read(&dir.join(&self.file))
            .map_err(|e| ctx.err(&f("file"), format!("{e:#}")))?;
        self.check_flux(ctx, at, &set)?;
        let (rot, shift) = self.placement(ctx, at)?;
        let scale = self.units.unwrap_or(Units::Mm).mm();
        RayFileEmitter::new(self.file.clone(), Arc::new(set), rot, scale, shift)
            .map_err(|e| ctx.err(&f("file"), format!("{}: {e:#}", self.file.display())))
    }

    /// The rays' total flux must be positive and finite; without `power_w` it is the
    /// source's radiant power, which must stay within [`MAX_TOTAL_POWER_W`] (with it, the
    /// flux only weighs the rays against each other, at any scale).
    fn check_flux(&self, ctx: &Ctx, at: &str, set: &RaySet) -> Result<()> {
        let total = set.total_flux();
        let why = if !(total > 0.0 && total.is_finite()) {
            "nothing to emit"
        } else if self.power_w.is_none() && set.unit == FluxUnit::Watt && total > MAX_TOTAL_POWER_W
        {
            &format!(
                "too large for the source's power (at most {MAX_TOTAL_POWER_W:e} W): give power_w, and the rays' flux only weighs them against each other"
            )
        } else {
            return Ok(());
        };
        Err(ctx.err(
            &format!("{at}.file"),
            format!(
                "{}: the rays' total flux is {} {}, {why}",
                self.file.display(),
                short(total),
                match set.unit {
                    FluxUnit::Watt => "W",
                    FluxUnit::Lumen => "lm",
                }
            ),
        ))
    }

    /// The rotation and translation, checked (a matrix must be rigid: a rotation,
    /// possibly mirrored, so directions stay unit and the flux per area unchanged).
    fn placement(&self, ctx: &Ctx, at: &str) -> Result<(DMat3, DVec3)> {
        let f = |k: &str| format!("{at}.{k}");
        let shift = ctx.point(&f("translate"), self.translate)?;
        match (self.rotate_deg, self.matrix) {
            (Some(_), Some(_)) => Err(ctx.err(&f("matrix"), "give rotate_deg or matrix, not both")),
            (Some(r), None) => Ok((rotation_deg(ctx.angles_deg(&f("rotate_deg"), r)?), shift)),
            (None, Some(m)) => {
                let t = affine_matrix(ctx, &f("matrix"), m)?;
                let rot = DMat3::from_mat4(t);
                let ortho = (rot.transpose() * rot - DMat3::IDENTITY)
                    .to_cols_array()
                    .iter()
                    .all(|x| x.abs() < 1e-6);
                if !ortho {
                    return Err(ctx.err(&f("matrix"), "must be a rotation (orthonormal columns): a ray file cannot be stretched or sheared"));
                }
                let moved = ctx.point(&f("matrix"), t.w_axis.truncate().to_array())?;
                Ok((rot, shift + moved))
            }
            (None, None) => Ok((DMat3::IDENTITY, shift)),
        }
    }
}

#[cfg(test)]
mod tests;
