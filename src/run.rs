//! A traced job: run the photons, then turn the tally into physical maps, a summary and
//! output files.
//!
//! Outputs written by [`RunResult::write`]:
//! - `flux.exr`: channels `flux` (W/mm^2 per bin), `flux_stderr`, `hits`;
//! - `angular.exr`: channels `intensity` (W/sr per (theta, phi) bin), `intensity_stderr`,
//!   `hits`; x = phi, y = theta;
//! - `flux.png`: false-colour preview of the flux map;
//! - `summary.json`: run facts, energy ledger, uniformity and errors.

use crate::accel::{self, Accel, BackendChoice};
use crate::output::{self, atomic::StagedDir};
use crate::scene::Scene;
use crate::tally::mean_and_stderr;
use crate::tracer::{Tally, Tracer};
use anyhow::{Context, Result};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How to run a trace.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Photons to emit.
    pub photons: u64,
    /// Seed of the per-photon streams.
    pub seed: u64,
    /// Worker threads (None: all cores).
    pub threads: Option<usize>,
    /// Intersection backend.
    pub backend: BackendChoice,
}

/// A finished trace.
pub struct RunResult<'a> {
    /// The scene traced.
    pub scene: &'a Scene,
    /// Backend that traced it.
    pub backend: &'static str,
    /// Options used.
    pub options: RunOptions,
    /// Worker threads used.
    pub threads: usize,
    /// Everything scored.
    pub tally: Tally,
    /// Wall time of the tracing (s), excluding scene loading and BVH build.
    pub runtime_s: f64,
}

/// Trace `scene` as `options` say. `progress` receives photon counts as chunks finish.
pub fn trace<'a>(
    scene: &'a Scene,
    options: &RunOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RunResult<'a>> {
    let pool = thread_pool(options.threads)?;
    let threads = pool.current_num_threads();
    let accel: Box<dyn Accel> =
        pool.install(|| accel::build(options.backend, scene.mesh.clone()))?;
    let tracer = Tracer {
        scene,
        accel: accel.as_ref(),
    };
    let start = Instant::now();
    let tally = pool.install(|| tracer.run_range(options.seed, 0, options.photons, progress));
    Ok(RunResult {
        scene,
        backend: accel.name(),
        options: options.clone(),
        threads,
        tally,
        runtime_s: start.elapsed().as_secs_f64(),
    })
}

fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .context("cannot start worker threads")
}

/// A map of values with standard errors and photon counts, row-major (x fastest).
#[derive(Clone, Debug)]
pub struct Map {
    /// Bins along x.
    pub nx: usize,
    /// Bins along y.
    pub ny: usize,
    /// Value per bin.
    pub value: Vec<f64>,
    /// Standard error per bin.
    pub stderr: Vec<f64>,
    /// Photons scored per bin.
    pub hits: Vec<u64>,
}

impl RunResult<'_> {
    /// Power carried by one photon of unit weight (W).
    pub fn watts_per_photon(&self) -> f64 {
        self.scene.sources.total_power() / self.tally.ledger.photons.max(1) as f64
    }

    /// Target-plane irradiance (W/mm^2) per bin.
    pub fn flux_map(&self) -> Map {
        let area = self.scene.detector.bin_area();
        self.map(&self.tally.flux, |_| area)
    }

    /// Radiant intensity (W/sr) per (theta, phi) bin; x = phi, y = theta.
    pub fn angular_map(&self) -> Map {
        let g = &self.tally.angular;
        // The tally grid is (theta, phi) with theta fastest; present it with phi fastest.
        let by_theta = self.map(g, |i| self.scene.detector.angular_bin_solid_angle(i % g.nx));
        let (nt, np) = (g.nx, g.ny);
        let mut m = Map {
            nx: np,
            ny: nt,
            value: vec![0.0; nt * np],
            stderr: vec![0.0; nt * np],
            hits: vec![0; nt * np],
        };
        for ip in 0..np {
            for it in 0..nt {
                let (src, dst) = (ip * nt + it, it * np + ip);
                m.value[dst] = by_theta.value[src];
                m.stderr[dst] = by_theta.stderr[src];
                m.hits[dst] = by_theta.hits[src];
            }
        }
        m
    }

    fn map(&self, g: &crate::tally::Grid, measure: impl Fn(usize) -> f64) -> Map {
        let n = self.tally.ledger.photons;
        let total = self.scene.sources.total_power();
        let mut m = Map {
            nx: g.nx,
            ny: g.ny,
            value: Vec::new(),
            stderr: Vec::new(),
            hits: Vec::new(),
        };
        for (i, b) in g.bins.iter().enumerate() {
            let (mean, se) = b.mean_and_stderr(n);
            let k = total / measure(i);
            m.value.push(mean * k);
            m.stderr.push(se * k);
            m.hits.push(b.hits);
        }
        m
    }

    /// The run's summary.
    pub fn summary(&self) -> Summary {
        let flux = self.flux_map();
        let l = &self.tally.ledger;
        let w = self.watts_per_photon();
        let absorbed_w = self
            .scene
            .tags
            .iter()
            .zip(&l.absorbed_by_surface)
            .map(|(t, s)| (t.clone(), s.value() * w))
            .collect();
        let absorbed_in_medium_w = self
            .scene
            .media
            .iter()
            .zip(&l.absorbed_in_medium)
            .map(|(m, s)| (m.name.clone(), s.value() * w))
            .collect();
        let emitted = l.emitted.value();
        let (eff, eff_se) = mean_and_stderr(l.detected.value(), l.detected.value(), l.photons);
        let d = &self.scene.detector;
        Summary {
            scene: self.scene.name.clone(),
            scene_file: self.scene.path.display().to_string(),
            backend: self.backend.to_string(),
            seed: self.options.seed,
            photons: l.photons,
            threads: self.threads,
            runtime_s: self.runtime_s,
            photons_per_s: l.photons as f64 / self.runtime_s.max(1e-9),
            interactions_per_s: l.interactions as f64 / self.runtime_s.max(1e-9),
            ledger: LedgerSummary {
                emitted_w: emitted * w,
                detected_w: l.detected.value() * w,
                absorbed_w,
                absorbed_in_medium_w,
                escaped_w: l.escaped.value() * w,
                killed_w: l.killed.value() * w,
                killed_photons: l.killed_photons,
                interactions: l.interactions,
                balance_rel_error: (l.accounted().0 - l.emitted.0) as f64
                    / (l.emitted.0 as f64).max(1.0),
            },
            extraction_efficiency: eff,
            extraction_efficiency_stderr: eff_se,
            uniformity: Uniformity::of(&flux),
            mean_rel_stderr: mean_rel_stderr(&flux),
            detector: DetectorSummary {
                size_mm: d.size,
                bins: d.bins,
                bin_size_mm: [d.size[0] / d.bins[0] as f64, d.size[1] / d.bins[1] as f64],
                angular_bins: d.angular_bins,
            },
            warnings: self.scene.warnings.clone(),
        }
    }

    /// Write every output into `dir` atomically; returns the files written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let mut staged = StagedDir::new(dir)?;
        let flux = self.flux_map();
        let d = &self.scene.detector;
        let bin = [d.size[0] / d.bins[0] as f64, d.size[1] / d.bins[1] as f64];
        let common = [
            ("photons", self.tally.ledger.photons as f64),
            ("seed", self.options.seed as f64),
        ];
        let flux_attrs = [
            ("bin_size_x_mm", bin[0]),
            ("bin_size_y_mm", bin[1]),
            ("size_x_mm", d.size[0]),
            ("size_y_mm", d.size[1]),
            common[0],
            common[1],
        ];
        write_map_exr(
            &mut staged,
            "flux.exr",
            &flux,
            ["flux", "flux_stderr"],
            &flux_attrs,
        )?;
        let ang = self.angular_map();
        let ang_attrs = [
            ("bin_theta_deg", 90.0 / ang.ny as f64),
            ("bin_phi_deg", 360.0 / ang.nx as f64),
            common[0],
            common[1],
        ];
        write_map_exr(
            &mut staged,
            "angular.exr",
            &ang,
            ["intensity", "intensity_stderr"],
            &ang_attrs,
        )?;
        let png = staged.stage_path("flux.png");
        output::png::write_false_colour(
            &png,
            flux.nx,
            flux.ny,
            &flux.value,
            &output::png::PreviewOptions::default(),
        )?;
        let json = serde_json::to_vec_pretty(&self.summary())?;
        staged.write_bytes("summary.json", &json)?;
        staged.commit()
    }
}

fn write_map_exr(
    staged: &mut StagedDir,
    name: &str,
    m: &Map,
    names: [&str; 2],
    attrs: &[(&str, f64)],
) -> Result<()> {
    let as_f32 = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let (value, stderr) = (as_f32(&m.value), as_f32(&m.stderr));
    let hits: Vec<f32> = m.hits.iter().map(|&h| h as f32).collect();
    let path = staged.stage_path(name);
    output::exr::write_channels(
        &path,
        m.nx,
        m.ny,
        &[(names[0], &value), (names[1], &stderr), ("hits", &hits)],
        attrs,
    )
}

fn mean_rel_stderr(m: &Map) -> f64 {
    let rel: Vec<f64> = m
        .value
        .iter()
        .zip(&m.stderr)
        .filter(|(v, _)| **v > 0.0)
        .map(|(v, s)| s / v)
        .collect();
    if rel.is_empty() {
        f64::NAN
    } else {
        rel.iter().sum::<f64>() / rel.len() as f64
    }
}

/// Uniformity metrics of a flux map.
#[derive(Clone, Debug, Serialize)]
pub struct Uniformity {
    /// Mean irradiance over all bins (W/mm^2).
    pub mean: f64,
    /// RMS deviation over mean.
    pub cv: f64,
    /// Smallest bin over largest bin.
    pub min_over_max: f64,
    /// Min over max of the 9 standard points (3x3-bin spots at 1/6, 1/2, 5/6 of each side).
    pub nine_point_min_over_max: f64,
    /// As nine-point, plus the 4 points at 1/4 and 3/4 of each side.
    pub thirteen_point_min_over_max: f64,
}

impl Uniformity {
    /// Metrics of `m`'s values.
    pub fn of(m: &Map) -> Self {
        let v = &m.value;
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        let (lo, hi) = v.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        let nine = [1.0 / 6.0, 0.5, 5.0 / 6.0];
        let mut points: Vec<(f64, f64)> = nine
            .iter()
            .flat_map(|&y| nine.iter().map(move |&x| (x, y)))
            .collect();
        let spot = |pts: &[(f64, f64)]| ratio(pts.iter().map(|&(x, y)| spot_mean(m, x, y)));
        let nine_point = spot(&points);
        points.extend([(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]);
        Uniformity {
            mean,
            cv: if mean > 0.0 {
                var.sqrt() / mean
            } else {
                f64::NAN
            },
            min_over_max: if hi > 0.0 { lo / hi } else { f64::NAN },
            nine_point_min_over_max: nine_point,
            thirteen_point_min_over_max: spot(&points),
        }
    }
}

fn ratio(values: impl Iterator<Item = f64>) -> f64 {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    if hi > 0.0 { lo / hi } else { f64::NAN }
}

/// Mean of the 3x3 bins around the fractional position (fx, fy) of the map.
fn spot_mean(m: &Map, fx: f64, fy: f64) -> f64 {
    let cx = ((fx * m.nx as f64) as usize).min(m.nx - 1);
    let cy = ((fy * m.ny as f64) as usize).min(m.ny - 1);
    let (mut sum, mut n) = (0.0, 0);
    for y in cy.saturating_sub(1)..=(cy + 1).min(m.ny - 1) {
        for x in cx.saturating_sub(1)..=(cx + 1).min(m.nx - 1) {
            sum += m.value[y * m.nx + x];
            n += 1;
        }
    }
    sum / n as f64
}

/// summary.json.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Scene file path.
    pub scene_file: String,
    /// Backend used.
    pub backend: String,
    /// Seed.
    pub seed: u64,
    /// Photons emitted.
    pub photons: u64,
    /// Worker threads.
    pub threads: usize,
    /// Tracing wall time (s).
    pub runtime_s: f64,
    /// Photons per second.
    pub photons_per_s: f64,
    /// Surface interactions per second.
    pub interactions_per_s: f64,
    /// Where the energy went.
    pub ledger: LedgerSummary,
    /// Detected over emitted power.
    pub extraction_efficiency: f64,
    /// Its standard error.
    pub extraction_efficiency_stderr: f64,
    /// Uniformity of the flux map.
    pub uniformity: Uniformity,
    /// Mean over lit bins of stderr / flux.
    pub mean_rel_stderr: f64,
    /// Detector geometry.
    pub detector: DetectorSummary,
    /// Scene-loading warnings.
    pub warnings: Vec<String>,
}

/// The energy ledger in watts.
#[derive(Clone, Debug, Serialize)]
pub struct LedgerSummary {
    /// Emitted power.
    pub emitted_w: f64,
    /// Power on the target.
    pub detected_w: f64,
    /// Power absorbed per surface tag.
    pub absorbed_w: BTreeMap<String, f64>,
    /// Power absorbed per medium (Beer-Lambert).
    pub absorbed_in_medium_w: BTreeMap<String, f64>,
    /// Power that left the scene.
    pub escaped_w: f64,
    /// Power stopped by the bounce cap.
    pub killed_w: f64,
    /// Photons stopped by the bounce cap.
    pub killed_photons: u64,
    /// Surface interactions.
    pub interactions: u64,
    /// (accounted - emitted) / emitted, computed on the exact sums.
    pub balance_rel_error: f64,
}

/// Detector facts for the summary.
#[derive(Clone, Debug, Serialize)]
pub struct DetectorSummary {
    /// Size (mm).
    pub size_mm: [f64; 2],
    /// Flux bins.
    pub bins: [usize; 2],
    /// Bin size (mm).
    pub bin_size_mm: [f64; 2],
    /// Angular bins (theta, phi).
    pub angular_bins: [usize; 2],
}
