//! Light sources, sampled in proportion to power: one module per source type with its
//! scene-file entry, its checks and its emission ([`ccfl`]: a Lambertian tube; [`led`]: a
//! flat emitter, cos^m or a measured table from [`intensity`]; [`rayfile`]: rays from a
//! TM-25 or text ray file), and what every source
//! has besides: a name, its power, the medium it emits into, an optional lamp body
//! ([`body`], shaped by [`body_shape`]) and a row of copies ([`mod@array`]).
//!
//! ```toml
//! [[sources]]
//! type = "ccfl"              # or "led", "rayfile"; the type's own keys: see `ccfl`, `led`, `rayfile`
//! name = "left_upper"        # for reports (default: the type and the entry's index)
//! power_w = 1.0              # radiant power (W)
//! lumens = 300.0             # optional: luminous flux, for luminance outputs
//! spectrum = "cie-led-b5"    # optional: the emission spectrum (see `spectrum`)
//! medium = "air"             # what the source emits into
//! body = { model = "lambert", albedo = 0.5 }   # what returning light meets: see `body`
//! array = { count = 4, pitch_mm = 10.0, direction = [0.0, 1.0, 0.0] }   # a row
//! ```

pub mod array;
pub mod body;
pub mod body_shape;
pub mod ccfl;
pub mod intensity;
pub mod led;
pub mod polarization;
pub mod rayfile;
pub mod spectrum;

use crate::geometry::Ray;
use crate::optics::medium::{Medium, MediumId, medium_id};
use crate::optics::polarization::Polarization;
use crate::optics::spectrum::{Light, Secondaries};
use crate::rng::PhotonRng;
use crate::spec_check::Ctx;
use anyhow::Result;
use body::{BodySpec, LampBody};
use body_shape::{BodyShape, Rect};
use ccfl::{CcflSpec, Tube};
use glam::DVec3;
use led::{FlatLed, LedSpec};
use rayfile::{RayFileEmitter, RayFileSpec};
use serde::{Deserialize, Serialize};
use spectrum::{EmissionSpectrum, SpectrumSpec};
use std::path::PathBuf;
use std::sync::Arc;

/// `[[sources]]`: a light source in the scene file.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum SourceSpec {
    /// Cold-cathode fluorescent lamp: a Lambertian cylinder ([`ccfl`]).
    Ccfl(CcflSpec),
    /// Flat LED emitter ([`led`]).
    Led(LedSpec),
    /// Rays from a TM-25 or text ray file ([`rayfile`]).
    Rayfile(RayFileSpec),
}

impl<'de> Deserialize<'de> for SourceSpec {
    /// `type` picks the source, whose spec reads the rest of the table: an error names
    /// the key it is about (serde's `tag = "type"` reading loses it).
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use crate::spec_check::keyed;
        use serde::de::Error;
        let mut table = toml::Table::deserialize(d)?;
        let kind = match table.remove("type") {
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(D::Error::custom(format!(
                    "type: expected \"ccfl\", \"led\" or \"rayfile\", got {other}"
                )));
            }
            None => return Err(D::Error::missing_field("type")),
        };
        match kind.as_str() {
            "ccfl" => keyed(&table).map(SourceSpec::Ccfl),
            "led" => keyed(&table).map(SourceSpec::Led),
            "rayfile" => keyed(&table).map(SourceSpec::Rayfile),
            other => Err(format!(
                "unknown variant `{other}`, expected one of `ccfl`, `led`, `rayfile` in `type`"
            )),
        }
        .map_err(D::Error::custom)
    }
}

impl schemars::JsonSchema for SourceSpec {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "SourceSpec".into()
    }

    /// One closed table per `type`, as `deserialize` reads them.
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        use crate::scene::schema::{one_of, tagged};
        let choices = vec![
            tagged::<CcflSpec>(
                generator,
                "type",
                "ccfl",
                "Cold-cathode fluorescent lamp: a Lambertian cylinder.",
                &[],
            ),
            tagged::<LedSpec>(
                generator,
                "type",
                "led",
                "Flat LED emitter with a cos^m profile or a measured intensity table.",
                &[],
            ),
            tagged::<RayFileSpec>(
                generator,
                "type",
                "rayfile",
                "Rays from a TM-25 or text ray file.",
                &[],
            ),
        ];
        one_of("[[sources]]: a light source; `type` picks it.", choices)
    }
}

/// What every source entry gives besides its emitting shape.
struct Common<'a> {
    name: &'a Option<String>,
    power_w: Option<f64>,
    lumens: Option<f64>,
    spectrum: Option<&'a SpectrumSpec>,
    polarization: Option<&'a polarization::SourcePolarizationSpec>,
    medium: &'a str,
    body: &'a BodySpec,
    package_depth_mm: Option<f64>,
}

impl SourceSpec {
    /// The entry's row, if it has one.
    pub fn array(&self) -> Option<&array::ArraySpec> {
        match self {
            SourceSpec::Ccfl(s) => s.array.as_ref(),
            SourceSpec::Led(s) => s.array.as_ref(),
            SourceSpec::Rayfile(s) => s.array.as_ref(),
        }
    }

    /// The files the source reads, relative to the scene file (its measured intensity
    /// table or ray file, its spectrum file, its body's tables): the content hash covers
    /// their bytes, as it does surface models' tables.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = match self {
            SourceSpec::Led(s) => s.intensity_file.iter().cloned().collect(),
            SourceSpec::Ccfl(_) => Vec::new(),
            SourceSpec::Rayfile(s) => vec![s.file.clone()],
        };
        let common = self.common();
        files.extend(
            common
                .spectrum
                .and_then(SpectrumSpec::file)
                .map(PathBuf::from),
        );
        if let BodySpec::Opaque(body) = common.body {
            files.extend(body.files());
        }
        files
    }

    /// The type's name in the scene file.
    pub fn kind(&self) -> &'static str {
        match self {
            SourceSpec::Ccfl(_) => "ccfl",
            SourceSpec::Led(_) => "led",
            SourceSpec::Rayfile(_) => "rayfile",
        }
    }

    /// Whether the entry gives a polarization (then the scene traces it, unless told not to).
    pub fn is_polarized(&self) -> bool {
        self.common().polarization.is_some()
    }

    /// Whether the entry gives an emission spectrum (then the scene is spectral).
    pub fn has_spectrum(&self) -> bool {
        self.common().spectrum.is_some()
    }

    fn common(&self) -> Common<'_> {
        match self {
            SourceSpec::Ccfl(s) => Common {
                name: &s.name,
                power_w: Some(s.power_w),
                lumens: s.lumens,
                spectrum: s.spectrum.as_ref(),
                polarization: s.polarization.as_ref(),
                medium: &s.medium,
                body: &s.body,
                package_depth_mm: None,
            },
            SourceSpec::Led(s) => Common {
                name: &s.name,
                power_w: Some(s.power_w),
                lumens: s.lumens,
                spectrum: s.spectrum.as_ref(),
                polarization: s.polarization.as_ref(),
                medium: &s.medium,
                body: &s.body,
                package_depth_mm: s.package_depth_mm,
            },
            SourceSpec::Rayfile(s) => Common {
                name: &s.name,
                power_w: s.power_w,
                lumens: s.lumens,
                spectrum: s.spectrum.as_ref(),
                polarization: s.polarization.as_ref(),
                medium: &s.medium,
                body: &s.body,
                package_depth_mm: s.package_depth_mm,
            },
        }
    }

    /// Check entry `i` of `[[sources]]` and build the source (a measured LED's
    /// `intensity_file` is relative to the scene file).
    pub fn build(&self, ctx: &Ctx, i: usize, media: &[Medium]) -> Result<Source> {
        let at = format!("sources[{i}]");
        let f = |k: &str| format!("{at}.{k}");
        let common = self.common();
        let emitter = match self {
            SourceSpec::Ccfl(s) => Emitter::Ccfl(s.tube(ctx, &at)?),
            SourceSpec::Led(s) => Emitter::Led(s.led(ctx, &at)?),
            SourceSpec::Rayfile(s) => Emitter::RayFile(s.emitter(ctx, &at)?),
        };
        let depth = common
            .package_depth_mm
            .map(|d| ctx.length(&f("package_depth_mm"), d))
            .transpose()?;
        let spectrum = match (common.spectrum, emitter.own_spectrum()) {
            (Some(_), Some(_)) => {
                return Err(ctx.err(
                    &f("spectrum"),
                    "the ray file gives the rays' wavelengths: remove spectrum",
                ));
            }
            (Some(s), None) => Some(s.build(ctx, &f("spectrum"))?),
            (None, Some(own)) => Some(own.map_err(|e| ctx.err(&f("file"), e))?),
            (None, None) => None,
        };
        if spectrum.is_some() && common.lumens.is_some() {
            return Err(ctx.err(
                &f("lumens"),
                "follows from the spectrum (683 lm/W times its V-weighted fraction); give lumens only for a source without one",
            ));
        }
        let body = common
            .body
            .model(ctx, &f("body"), media)?
            .map(|model| LampBody::new(&emitter, model, depth));
        Ok(Source {
            name: match common.name {
                Some(n) => ctx.name(&f("name"), n)?.to_owned(),
                None => format!("{}{i}", self.kind()),
            },
            power_w: match common.power_w {
                Some(p) => ctx.positive(&f("power_w"), p)?,
                None => emitter.file_power_w().ok_or_else(|| {
                    ctx.err(
                        &f("power_w"),
                        "missing: the ray file gives luminous flux only",
                    )
                })?,
            },
            lumens: ctx.optional_positive(&f("lumens"), common.lumens)?,
            spectrum: spectrum.map(Arc::new),
            polarization: common
                .polarization
                .map(|p| p.build(ctx, &f("polarization")))
                .transpose()?,
            emitter,
            medium: medium_id(ctx, &f("medium"), common.medium, media)?,
            body,
        })
    }
}

/// The emitting shape of a source and how it emits.
#[derive(Clone, Debug, PartialEq)]
pub enum Emitter {
    /// A Lambertian tube (a CCFL).
    Ccfl(Tube),
    /// A flat rectangle, cos^m or a measured profile (an LED die or window).
    Led(FlatLed),
    /// Rays from a ray file, drawn in proportion to flux.
    RayFile(RayFileEmitter),
}

impl Emitter {
    /// A photon leaving the emitter: its ray and the emitting surface's normal.
    pub fn emit(&self, rng: &mut PhotonRng) -> (Ray, DVec3) {
        let (ray, normal, _, _) = self.emit_own(rng);
        (ray, normal)
    }

    /// [`Emitter::emit`], with the photon's own wavelength (nm) and polarization when the
    /// emitter gives them (a ray file's ray), else `None` (the source's spectrum and
    /// polarization, if any, give them).
    pub fn emit_own(&self, rng: &mut PhotonRng) -> (Ray, DVec3, Option<f64>, Option<Polarization>) {
        match self {
            Emitter::Ccfl(t) => {
                let (ray, n) = t.emit(rng);
                (ray, n, None, None)
            }
            Emitter::Led(l) => {
                let (ray, n) = l.emit(rng);
                (ray, n, None, None)
            }
            Emitter::RayFile(r) => r.emit_polarized(rng),
        }
    }

    /// Whether the emitter gives its photons their polarization (a ray file with Stokes
    /// columns).
    pub fn polarized(&self) -> bool {
        matches!(self, Emitter::RayFile(r) if !r.set.stokes.is_empty())
    }

    /// The spectrum the emitter itself gives (a ray file's table or wavelengths; `Err`:
    /// they have no power within 360-830 nm).
    fn own_spectrum(&self) -> Option<Result<EmissionSpectrum>> {
        match self {
            Emitter::RayFile(r) => r.set.emission_spectrum(),
            Emitter::Ccfl(_) | Emitter::Led(_) => None,
        }
    }

    /// The radiant power the emitter itself gives (a ray file's total radiant flux).
    fn file_power_w(&self) -> Option<f64> {
        match self {
            Emitter::RayFile(r) if r.set.unit == rayfile::FluxUnit::Watt => {
                Some(r.set.total_flux())
            }
            _ => None,
        }
    }

    /// The axis a source's `polarization` is given against: an LED's `u`, a tube's axis,
    /// a ray file's placed x axis.
    pub fn u_axis(&self) -> DVec3 {
        match self {
            Emitter::Ccfl(t) => t.axis,
            Emitter::Led(l) => l.u,
            Emitter::RayFile(r) => r.front.u,
        }
    }

    /// The centre of the emitting surface.
    pub fn center(&self) -> DVec3 {
        match self {
            Emitter::Ccfl(t) => t.center,
            Emitter::Led(l) => l.center,
            Emitter::RayFile(r) => r.front.center,
        }
    }

    fn translate(&mut self, d: DVec3) {
        match self {
            Emitter::Ccfl(t) => t.center += d,
            Emitter::Led(l) => l.center += d,
            Emitter::RayFile(r) => r.translate(d),
        }
    }

    /// A deterministic grid of `n x n` points on the emitting surface, each with the
    /// surface's unit outward normal there (for placement checks, not for tracing).
    pub fn surface_grid(&self, n: usize) -> Vec<(DVec3, DVec3)> {
        let f = |k: usize| (k as f64 + 0.5) / n as f64 - 0.5;
        let mut out = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                out.push(match self {
                    Emitter::Ccfl(t) => t.surface_point(f(i), f(j)),
                    Emitter::Led(l) => l.surface_point(f(i), f(j)),
                    Emitter::RayFile(r) => r.window().surface_point(f(i), f(j)),
                });
            }
        }
        out
    }

    /// The emitting surface as a body shape: the tube, or the LED's rectangle (a lamp's
    /// default body, and what placement checks test parts against).
    pub fn shape(&self) -> BodyShape {
        match self {
            Emitter::Ccfl(t) => t.shape(),
            Emitter::Led(l) => l.shape(),
            Emitter::RayFile(r) => r.shape(),
        }
    }

    /// The distance (mm) from `p` to the emitting surface (the tube's side, or the
    /// rectangle).
    pub fn surface_distance(&self, p: DVec3) -> f64 {
        match self {
            Emitter::Ccfl(t) => t.distance(p),
            Emitter::Led(l) => l.distance(p),
            Emitter::RayFile(r) => r.window().distance(p),
        }
    }

    /// Why copies of this emitter `pitch` mm apart along the unit `d` would overlap, if
    /// they would (tubes; LED rectangles may touch).
    pub fn copies_overlap(&self, d: DVec3, pitch: f64) -> Option<String> {
        match self {
            Emitter::Ccfl(t) => t.copies_overlap(d, pitch),
            Emitter::Led(_) | Emitter::RayFile(_) => None,
        }
    }

    /// An LED's emitting rectangle, or a ray file's front (`None` for a CCFL).
    pub fn rect(&self) -> Option<Rect> {
        match self {
            Emitter::Ccfl(_) => None,
            Emitter::Led(l) => Some(l.rect()),
            Emitter::RayFile(r) => Some(r.front),
        }
    }
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
    /// Its emission spectrum (`None`: monochrome light).
    pub spectrum: Option<Arc<EmissionSpectrum>>,
    /// The state its light starts in, in the frame of [`Emitter::u_axis`] (`None`:
    /// unpolarized).
    pub polarization: Option<crate::optics::polarization::Stokes>,
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
    /// Its light (see [`crate::optics::spectrum`]): the hero wavelength...
    pub light: Light,
    /// Its polarization when its emitter gives it (a ray file's Stokes columns), else
    /// the source's `polarization`, if any, gives it.
    pub pol: Option<Polarization>,
    /// ...and the others it carries along the hero's path.
    pub secondaries: Secondaries,
}

impl Source {
    /// The centre of the emitter.
    pub fn anchor(&self) -> DVec3 {
        self.emitter.center()
    }

    /// Move the source (and its body) by `d`.
    pub fn translate(&mut self, d: DVec3) {
        self.emitter.translate(d);
        if let Some(b) = &mut self.body {
            b.shape.translate(d);
        }
    }

    /// Luminous flux (lm): from its spectrum, or as the scene gives it.
    pub fn luminous_flux(&self) -> Option<f64> {
        match &self.spectrum {
            Some(s) => Some(self.power_w * s.efficacy_lm_per_w()),
            None => self.lumens,
        }
    }

    /// A photon leaving this source: its ray and the emitting surface's normal.
    pub fn emit(&self, rng: &mut PhotonRng) -> (Ray, DVec3) {
        self.emitter.emit(rng)
    }
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
        check_spectra(ctx, &list, &entry)?;
        Ok(Self::new(list))
    }

    /// Whether the sources have spectra (then every one has).
    pub fn spectral(&self) -> bool {
        self.list.iter().any(|s| s.spectrum.is_some())
    }

    /// Move every source (and its body) by `d`.
    pub fn translate(&mut self, d: DVec3) {
        self.list.iter_mut().for_each(|s| s.translate(d));
    }

    /// Luminous efficacy of the radiation (lm/W) when every source gives its lumens or
    /// its spectrum.
    pub fn luminous_efficacy(&self) -> Option<f64> {
        let lumens: Option<f64> = self.list.iter().map(Source::luminous_flux).sum();
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
        let (ray, normal, own_nm, pol) = s.emitter.emit_own(rng);
        let (light, secondaries) = match (own_nm, &s.spectrum) {
            (Some(nm), _) => (Light::at_nm(nm), Secondaries::NONE),
            (None, Some(sp)) => {
                let u = rng.uniform();
                (Light::at_nm(sp.sample(u)), Secondaries::deferred(u, i))
            }
            (None, None) => (Light::MONOCHROME, Secondaries::NONE),
        };
        Emission {
            ray,
            normal,
            medium: s.medium,
            source: i,
            light,
            pol,
            secondaries,
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

/// Either every source has a spectrum (its `spectrum` key, or a ray file's wavelengths)
/// or none has: a photon of a monochrome source has no colour to add to a spectral one's.
/// `entry[k]` is the `[[sources]]` entry of source `k`.
fn check_spectra(ctx: &Ctx, list: &[Source], entry: &[usize]) -> Result<()> {
    let has = |s: &Source| s.spectrum.is_some();
    let (Some(with), Some(without)) =
        (list.iter().position(has), list.iter().position(|s| !has(s)))
    else {
        return Ok(());
    };
    let (with, without) = (entry[with], entry[without]);
    Err(ctx.err(
        &format!("sources[{without}].spectrum"),
        format!("missing: sources[{with}] has a spectrum (or a ray file with wavelengths), so every source needs one (a monochrome source has no colour to add)"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(extra: &str) -> Result<SourceSpec, String> {
        let text = format!(
            "type = \"led\"\ncenter = [0.0, 0.0, 0.0]\nnormal = [1.0, 0.0, 0.0]\nu = [0.0, 1.0, 0.0]\nwidth_mm = 1.0\nheight_mm = 1.0\npower_w = 1.0\n{extra}"
        );
        toml::from_str::<SourceSpec>(&text).map_err(|e| e.to_string())
    }

    /// A wrong value of a source's key names the key (serde's `type`-tagged reading lost
    /// it: `invalid type: string "30", expected f64`, or `expected struct Keys`), and a
    /// polarization angle past a thousand turns is refused as rotations are.
    #[test]
    fn wrong_source_values_name_their_key() {
        let e = parse("polarization = { linear_deg = \"30\" }\n").unwrap_err();
        assert!(
            e.contains("polarization.linear_deg: invalid type: string"),
            "{e}"
        );
        let e = parse("polarization = true\n").unwrap_err();
        assert!(
            e.contains("polarization: invalid type: boolean `true`, expected a table"),
            "{e}"
        );
        assert!(!e.contains("struct Keys"), "{e}");
        let e = parse("lumens = \"x\"\n").unwrap_err();
        assert!(e.contains("lumens: invalid type"), "{e}");
        let e = parse("").unwrap();
        assert_eq!(e.kind(), "led");
        let e = toml::from_str::<SourceSpec>("type = \"lde\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown variant `lde`"), "{e}");
        let e = toml::from_str::<SourceSpec>("power_w = 1.0\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing field `type`"), "{e}");

        let ctx = crate::spec_check::Ctx(std::path::Path::new("scene.toml"));
        let pol = |deg: f64| {
            polarization::SourcePolarizationSpec::Linear { linear_deg: deg }
                .build(&ctx, "sources[0].polarization")
        };
        let e = format!("{:#}", pol(1e300).unwrap_err());
        assert!(
            e.contains("sources[0].polarization.linear_deg: must be within ±3.6e5 degrees"),
            "{e}"
        );
        assert!(pol(-3.6e5).is_ok() && pol(30.0).is_ok());
    }

    #[test]
    fn sources_are_picked_by_power() {
        let led = |p: f64| Source {
            name: "l".into(),
            power_w: p,
            lumens: None,
            spectrum: None,
            polarization: None,
            emitter: Emitter::Led(FlatLed {
                center: DVec3::ZERO,
                normal: DVec3::Z,
                u: DVec3::X,
                width: 1.0,
                height: 1.0,
                profile: led::LedProfile::CosPower(1.0),
            }),
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
            Emitter::Ccfl(Tube {
                center: DVec3::new(1.0, 2.0, 3.0),
                axis: tilted,
                radius: 1.5,
                length: 10.0,
            }),
            Emitter::Led(FlatLed {
                center: DVec3::new(-4.0, 0.5, 2.0),
                normal: tilted,
                u: tilted.any_orthonormal_vector(),
                width: 3.0,
                height: 1.0,
                profile: led::LedProfile::CosPower(1.0),
            }),
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
