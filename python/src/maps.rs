//! The maps of a run (each value with its standard error and photons per bin) and the
//! bin centres they lie on: computed by the library's own functions from a traced run,
//! or read back from the images of an output folder (`Run.load`).

use anyhow::{Context, Result};
use blutrace::run::RunResult;
use blutrace::run::metrics::{self, Map, color, cone, stokes};
use std::path::Path;

/// Where the bins lie: the detector's flux grid and angular grid.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Flux bins along u and v.
    pub bins: [usize; 2],
    /// Size of the target along u and v (mm).
    pub size_mm: [f64; 2],
    /// Angular bins: theta, phi.
    pub angular_bins: [usize; 2],
}

impl Frame {
    /// Centres of the flux bins along u (`axis` 0) or v (1), in mm from the detector's
    /// origin.
    pub fn centres_mm(&self, axis: usize) -> Vec<f64> {
        let (n, size) = (self.bins[axis], self.size_mm[axis]);
        (0..n).map(|i| (i as f64 + 0.5) * size / n as f64).collect()
    }

    /// Centres of the angular bins: theta (`axis` 0, from the normal, 0 to 90) or phi
    /// (1, from u towards v, 0 to 360), in degrees.
    pub fn centres_deg(&self, axis: usize) -> Vec<f64> {
        let (n, span) = (self.angular_bins[axis], [90.0, 360.0][axis]);
        (0..n).map(|i| span * (i as f64 + 0.5) / n as f64).collect()
    }
}

/// Every map a run has; the optional ones are `None` when the run does not measure them.
#[derive(Clone, Debug)]
pub struct Maps {
    /// The bins' places.
    pub frame: Frame,
    /// Irradiance (W/mm^2), `(ny, nx)`.
    pub flux: Map,
    /// Radiant intensity (W/sr), `(n_theta, n_phi)`.
    pub angular: Map,
    /// Luminance within the detector's cone (cd/m^2) per flux bin: the normal view.
    pub luminance: Option<Map>,
    /// Per view of the detector (`[detector] views`, the first = `luminance`), its
    /// luminance map (cd/m^2) and its `[theta_deg, phi_deg]`; empty without lumens or
    /// spectra.
    pub luminance_views: Vec<(Map, [f64; 2])>,
    /// Luminance averaged over the target (cd/m^2) per angular bin.
    pub angular_luminance: Option<Map>,
    /// CIE 1931 X, Y, Z per flux bin (lux-scaled), spectral scenes.
    pub xyz: Option<[Map; 3]>,
    /// CIE 1976 u', v' per flux bin, spectral scenes.
    pub uv: Option<[Map; 2]>,
    /// Stokes S0..S3 irradiance per flux bin (W/mm^2), when polarization is traced.
    pub stokes: Option<[Map; 4]>,
}

impl Maps {
    /// The maps of a traced run, from the functions the command line's images use.
    pub fn of(run: &RunResult) -> Maps {
        let (scene, t) = (&*run.scene, &run.tally);
        let d = &scene.detector;
        Maps {
            frame: Frame {
                bins: d.bins,
                size_mm: d.size,
                angular_bins: d.angular_bins,
            },
            flux: run.flux_map(),
            angular: run.angular_map(),
            luminance: cone::luminance_cone_map(scene, t, 0),
            luminance_views: (0..d.views.len())
                .filter_map(|k| Some((cone::luminance_cone_map(scene, t, k)?, d.views[k])))
                .collect(),
            angular_luminance: metrics::luminance_map(scene, t),
            xyz: color::xyz_maps(scene, t),
            uv: color::uv_prime_maps(scene, t, &run.groups),
            stokes: stokes::stokes_maps(scene, t),
        }
    }

    /// The maps of an output folder, from its images (stored as float32; `frame` from
    /// its `summary.json`).
    pub fn read(dir: &Path, frame: Frame) -> Result<Maps> {
        let needed = |name: &str| -> Result<Image> {
            Image::read(&dir.join(name))?.with_context(|| format!("{}: no {name}", dir.display()))
        };
        let (flux, angular) = (needed("flux.exr")?, needed("angular.exr")?);
        let luminance = Image::read(&dir.join("luminance.exr"))?;
        let color = Image::read(&dir.join("color.exr"))?;
        let stokes = Image::read(&dir.join("stokes.exr"))?;
        let xyz = match &color {
            Some(c) => Some([
                c.map("X", "stderr.X", "hits")?,
                c.map("Y", "stderr.Y", "hits")?,
                c.map("Z", "stderr.Z", "hits")?,
            ]),
            None => None,
        };
        // Files written before color.exr held the errors of u', v' have none (NaN).
        let uv_err = |c: &Image, n: &'static str| if c.has(n) { n } else { "" };
        let uv = match &color {
            Some(c) => Some([
                c.map("u_prime", uv_err(c, "stderr.u_prime"), "hits")?,
                c.map("v_prime", uv_err(c, "stderr.v_prime"), "hits")?,
            ]),
            None => None,
        };
        let stokes = match &stokes {
            Some(s) => Some([
                s.map("S0", "stderr.S0", "hits")?,
                s.map("S1", "stderr.S1", "hits")?,
                s.map("S2", "stderr.S2", "hits")?,
                s.map("S3", "stderr.S3", "hits")?,
            ]),
            None => None,
        };
        let luminance_views = read_views(dir, luminance.as_ref())?;
        let angular_luminance = if angular.has("luminance.Y") {
            Some(angular.map("luminance.Y", "luminance_stderr.Y", "hits.Y")?)
        } else {
            None
        };
        Ok(Maps {
            frame,
            flux: flux.map("Y", "stderr.Y", "hits.Y")?,
            angular: angular.map("Y", "stderr.Y", "hits.Y")?,
            luminance: luminance
                .map(|l| l.map("Y", "stderr.Y", "hits.Y"))
                .transpose()?,
            luminance_views,
            angular_luminance,
            xyz,
            uv,
            stokes,
        })
    }
}

/// The luminance maps of every view in `dir`: `first` (`luminance.exr`), then
/// `luminance-view-K.exr` for K = 1, 2, ... while they exist; each view's angles from its
/// header (NaN in files written before views).
fn read_views(dir: &Path, first: Option<&Image>) -> Result<Vec<(Map, [f64; 2])>> {
    let Some(first) = first else {
        return Ok(Vec::new());
    };
    let mut views = vec![(first.map("Y", "stderr.Y", "hits.Y")?, first.view())];
    for k in 1.. {
        let Some(image) = Image::read(&dir.join(format!("luminance-view-{k}.exr")))? else {
            break;
        };
        views.push((image.map("Y", "stderr.Y", "hits.Y")?, image.view()));
    }
    Ok(views)
}

/// An EXR image of an output folder, its channels by name.
struct Image {
    path: std::path::PathBuf,
    width: usize,
    height: usize,
    channels: Vec<(String, Vec<f32>)>,
    attributes: Vec<(String, blutrace::output::exr::Attribute)>,
}

impl Image {
    /// The image at `path`, `None` when there is none.
    fn read(path: &Path) -> Result<Option<Image>> {
        if !path.is_file() {
            return Ok(None);
        }
        let (width, height, channels, attributes) = blutrace::output::exr::read_channels(path)?;
        Ok(Some(Image {
            path: path.to_path_buf(),
            width,
            height,
            channels,
            attributes,
        }))
    }

    /// A luminance map's view `[theta_deg, phi_deg]` from its header (NaN when absent).
    fn view(&self) -> [f64; 2] {
        ["view_theta_deg", "view_phi_deg"].map(|key| {
            self.attributes
                .iter()
                .find(|(n, _)| n == key)
                .and_then(|(_, a)| match a {
                    blutrace::output::exr::Attribute::Text(t) => t.parse().ok(),
                    _ => None,
                })
                .unwrap_or(f64::NAN)
        })
    }

    fn has(&self, name: &str) -> bool {
        self.channels.iter().any(|(n, _)| n == name)
    }

    fn channel(&self, name: &str) -> Result<Vec<f64>> {
        let (_, samples) = self
            .channels
            .iter()
            .find(|(n, _)| n == name)
            .with_context(|| format!("{}: no channel {name}", self.path.display()))?;
        Ok(samples.iter().map(|&x| f64::from(x)).collect())
    }

    /// The map of channels `value`, `stderr` (NaN when "") and `hits`.
    fn map(&self, value: &str, stderr: &str, hits: &str) -> Result<Map> {
        let n = self.width * self.height;
        Ok(Map {
            nx: self.width,
            ny: self.height,
            value: self.channel(value)?,
            stderr: if stderr.is_empty() {
                vec![f64::NAN; n]
            } else {
                self.channel(stderr)?
            },
            hits: self.channel(hits)?.iter().map(|&h| h as u64).collect(),
        })
    }
}
