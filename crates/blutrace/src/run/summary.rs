//! `summary.json`, `convergence.csv` and `convergence.png`.

use super::metrics::color::{ColorSummary, color_summary};
use super::metrics::cone::{LuminanceMapSummary, luminance_map_summary};
use super::metrics::stokes::{PolarizationSummary, polarization_summary};
use super::metrics::{Metric, MetricValues, Metrics, Uniformity};
use super::{ConvergenceRow, RunResult, StoppedBy, TargetMetric, relative_error};
use crate::optics::surface::Estimator;
use crate::output::plot::{Chart, Scale, Series, write_chart};
use anyhow::Result;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

/// Version of the summary.json layout: 2 added the versions, renamed
/// `figure_of_merit.efficiency` to `figure_of_merit.per_s` and made `luminance.by_theta` a
/// list of objects.
pub const SCHEMA_VERSION: u32 = 2;

/// summary.json.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Version of this file's layout (bumped when a key changes meaning or name).
    pub schema_version: u32,
    /// The blutrace that wrote it.
    pub blutrace_version: &'static str,
    /// Scene name.
    pub scene: String,
    /// Scene file path.
    pub scene_file: String,
    /// Backend used.
    pub backend: String,
    /// Estimator used.
    pub estimator: Estimator,
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
    /// What ended the run.
    pub stopped_by: StoppedBy,
    /// Where the energy went.
    pub ledger: LedgerSummary,
    /// Detected over emitted power.
    pub extraction_efficiency: f64,
    /// Its standard error.
    pub extraction_efficiency_stderr: f64,
    /// Uniformity of the flux map.
    pub uniformity: Uniformity,
    /// Standard errors of the uniformity metrics (jackknife over photon groups).
    pub uniformity_stderr: Uniformity,
    /// The cv a perfectly uniform source would show at this photon count.
    pub cv_noise_floor: f64,
    /// cv with the noise floor removed in quadrature.
    pub cv_debiased: f64,
    /// Its standard error.
    pub cv_debiased_stderr: f64,
    /// Mean over lit bins of stderr / flux.
    pub mean_rel_stderr: f64,
    /// Monte Carlo efficiency of the run.
    pub figure_of_merit: FigureOfMerit,
    /// Luminance, when the sources give their lumens or spectra.
    pub luminance: Option<LuminanceSummary>,
    /// The luminance map's mean and uniformity within the detector's luminance cone, when
    /// the sources give their lumens or spectra ([`super::metrics::cone`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub luminance_map: Option<LuminanceMapSummary>,
    /// How the luminance maps were estimated ([`crate::estimator::LuminanceEstimator`]).
    pub luminance_estimator: crate::estimator::LuminanceEstimator,
    /// Every view's luminance map summary, when the detector has several views
    /// (`luminance_map` is the first's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub luminance_views: Vec<LuminanceMapSummary>,
    /// The target light's colour and colour uniformity, when the sources have spectra
    /// ([`super::metrics::color`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub color: Option<ColorSummary>,
    /// The target light's polarization, when it is traced ([`super::metrics::stokes`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polarization: Option<PolarizationSummary>,
    /// Detector geometry.
    pub detector: DetectorSummary,
    /// Scene-loading warnings, then the run's ([`NO_LIGHT`]).
    pub warnings: Vec<String>,
}

/// The warning of a run that put no light on the target.
pub const NO_LIGHT: &str = "no photon reached the target: the flux map has no uniformity (its cv, cv_debiased, noise floor and min/max ratios are null), not a perfectly uniform one";

/// `efficiency = 1 / (rel_error^2 * runtime_s)`: how fast a run buys accuracy. Comparable
/// between backends and estimators on the same scene and metric.
#[derive(Clone, Debug, Serialize)]
pub struct FigureOfMerit {
    /// The metric whose error is used.
    pub metric: TargetMetric,
    /// Its relative standard error.
    pub rel_error: f64,
    /// `1 / (rel_error^2 * runtime_s)` (1/s): how fast the run buys accuracy.
    pub per_s: f64,
}

/// Luminance of the target (cd/m^2, averaged over its area) against viewing angle.
#[derive(Clone, Debug, Serialize)]
pub struct LuminanceSummary {
    /// Luminous efficacy of the sources (lm/W), total lumens over total watts.
    pub efficacy_lm_per_w: f64,
    /// On-axis luminance: the first theta row.
    pub on_axis_cd_m2: f64,
    /// Its standard error.
    pub on_axis_stderr_cd_m2: f64,
    /// Luminance per theta row, averaged over phi.
    pub by_theta: Vec<ThetaLuminance>,
}

/// Luminance of one theta row of the angular bins.
#[derive(Clone, Debug, Serialize)]
pub struct ThetaLuminance {
    /// Centre of the row (degrees from the detector normal).
    pub theta_deg: f64,
    /// Luminance averaged over phi and over the target (cd/m^2).
    pub cd_m2: f64,
    /// Its standard error (cd/m^2).
    pub stderr_cd_m2: f64,
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
    /// Power absorbed per source by its lamp body (0 for transparent bodies).
    pub absorbed_by_source_w: BTreeMap<String, f64>,
    /// Power on the target per source, in source order (it adds up to `detected_w`).
    pub detected_by_source_w: Vec<SourceDetected>,
    /// Power the detector's analyzer absorbed (`[detector] analyzer_deg`; 0 without).
    pub absorbed_by_analyzer_w: f64,
    /// Power that left the scene.
    pub escaped_w: f64,
    /// Power stopped by the bounce cap.
    pub killed_w: f64,
    /// Photons stopped by the bounce cap.
    pub killed_photons: u64,
    /// Net power removed by Russian roulette (weighted estimator; zero on average).
    pub roulette_w: f64,
    /// Surface interactions.
    pub interactions: u64,
    /// Surface interactions per tag (every tag; they add up to `interactions`).
    pub hits_by_tag: BTreeMap<String, u64>,
    /// Of the hits on each dots tag, those that met ink: `ink_hits / hits` is the
    /// pattern's per-hit ink fraction (the density `d` for independent hits).
    pub ink_hits_by_tag: BTreeMap<String, u64>,
    /// Of the hits on each grooves tag, those whose path met a groove facet.
    pub groove_hits_by_tag: BTreeMap<String, u64>,
    /// (accounted - emitted) / emitted, computed on the exact sums.
    pub balance_rel_error: f64,
}

/// The power one source puts on the target.
#[derive(Clone, Debug, Serialize)]
pub struct SourceDetected {
    /// The source's name.
    pub source: String,
    /// Power on the target (W).
    pub w: f64,
    /// Its standard error (W), from the per-photon sums of squares.
    pub stderr_w: f64,
}

/// Detector facts for the summary.
#[derive(Clone, Debug, Serialize)]
pub struct DetectorSummary {
    /// The corner the bins count from (mm, in the scene file's frame, as written there).
    pub origin_mm: [f64; 3],
    /// The direction of the first bin index (unit vector).
    pub u: [f64; 3],
    /// The direction of the second bin index (unit vector).
    pub v: [f64; 3],
    /// Size (mm).
    pub size_mm: [f64; 2],
    /// Flux bins.
    pub bins: [usize; 2],
    /// Bin size (mm).
    pub bin_size_mm: [f64; 2],
    /// Angular bins (theta, phi).
    pub angular_bins: [usize; 2],
}

impl RunResult {
    /// The run's summary.
    pub fn summary(&self) -> Summary {
        let metrics = Metrics::of(&self.scene, &self.tally);
        let se = self
            .final_row()
            .map_or(MetricValues::splat(f64::NAN), |r| r.stderr);
        let l = &self.tally.ledger;
        let w = self.watts_per_photon();
        let named = |names: &[String], sums: &[crate::tally::ExactSum]| {
            names
                .iter()
                .zip(sums)
                .map(|(t, s)| (t.clone(), s.value() * w))
                .collect()
        };
        let media: Vec<String> = self.scene.media.iter().map(|m| m.name.clone()).collect();
        let sources: Vec<String> = self
            .scene
            .sources
            .list
            .iter()
            .map(|s| s.name.clone())
            .collect();
        let (eff, eff_se) = l.detected.mean_and_stderr(l.photons);
        let d = &self.scene.detector;
        let target = self.options.target_metric;
        let rel = relative_error(
            target.metric(),
            metrics.values()[target.metric()],
            se[target.metric()],
        );
        let runtime = self.runtime_s.max(1e-9);
        Summary {
            schema_version: SCHEMA_VERSION,
            blutrace_version: env!("CARGO_PKG_VERSION"),
            scene: self.scene.name.clone(),
            scene_file: self.scene.path.display().to_string(),
            backend: self.backend.to_string(),
            estimator: self.options.estimator,
            seed: self.options.seed,
            photons: l.photons,
            threads: self.threads,
            runtime_s: self.runtime_s,
            photons_per_s: l.photons as f64 / runtime,
            interactions_per_s: l.interactions as f64 / runtime,
            stopped_by: self.stopped_by,
            ledger: LedgerSummary {
                emitted_w: l.emitted.value() * w,
                detected_w: l.detected.sum.value() * w,
                absorbed_w: named(&self.scene.tags, &l.absorbed_by_surface),
                absorbed_in_medium_w: named(&media, &l.absorbed_in_medium),
                absorbed_by_source_w: named(&sources, &l.absorbed_by_source),
                detected_by_source_w: sources
                    .iter()
                    .zip(&l.detected_by_source)
                    .map(|(name, b)| SourceDetected {
                        source: name.clone(),
                        w: b.sum.value() * w,
                        stderr_w: b.mean_and_stderr(l.photons).1 * self.scene.sources.total_power(),
                    })
                    .collect(),
                absorbed_by_analyzer_w: l.absorbed_by_analyzer.value() * w,
                escaped_w: l.escaped.value() * w,
                killed_w: l.killed.value() * w,
                killed_photons: l.killed_photons,
                roulette_w: l.roulette.value() * w,
                interactions: l.interactions,
                hits_by_tag: self
                    .scene
                    .tags
                    .iter()
                    .cloned()
                    .zip(l.hits_by_tag.clone())
                    .collect(),
                ink_hits_by_tag: self.feature_hits("dots"),
                groove_hits_by_tag: self.feature_hits("grooves"),
                balance_rel_error: (l.accounted().0 - l.emitted.0) as f64
                    / (l.emitted.0 as f64).max(1.0),
            },
            extraction_efficiency: eff,
            extraction_efficiency_stderr: eff_se,
            uniformity: metrics.uniformity,
            uniformity_stderr: Uniformity {
                mean: se[Metric::Mean],
                cv: se[Metric::Cv],
                min_over_max: se[Metric::MinOverMax],
                nine_point_min_over_max: se[Metric::NinePoint],
                thirteen_point_min_over_max: se[Metric::ThirteenPoint],
            },
            cv_noise_floor: metrics.cv_noise_floor,
            cv_debiased: metrics.cv_debiased,
            cv_debiased_stderr: se[Metric::CvDebiased],
            mean_rel_stderr: metrics.mean_rel_stderr,
            figure_of_merit: FigureOfMerit {
                metric: target,
                rel_error: rel,
                per_s: 1.0 / (rel * rel * runtime),
            },
            luminance: super::metrics::luminance_by_theta(&self.scene, &self.tally).map(|rows| {
                LuminanceSummary {
                    efficacy_lm_per_w: self.scene.sources.luminous_efficacy().unwrap_or(f64::NAN),
                    on_axis_cd_m2: rows[0][1],
                    on_axis_stderr_cd_m2: rows[0][2],
                    by_theta: rows
                        .iter()
                        .map(|&[theta_deg, cd_m2, stderr_cd_m2]| ThetaLuminance {
                            theta_deg,
                            cd_m2,
                            stderr_cd_m2,
                        })
                        .collect(),
                }
            }),
            luminance_map: luminance_map_summary(&self.scene, &self.tally, &self.groups, 0),
            luminance_estimator: self.options.luminance_estimator,
            luminance_views: match d.views.len() {
                1 => Vec::new(),
                n => (0..n)
                    .filter_map(|k| {
                        luminance_map_summary(&self.scene, &self.tally, &self.groups, k)
                    })
                    .collect(),
            },
            color: color_summary(&self.scene, &self.tally, &self.groups),
            polarization: polarization_summary(&self.tally, &self.groups),
            detector: DetectorSummary {
                origin_mm: (d.origin + self.scene.offset).to_array(),
                u: d.u.to_array(),
                v: d.v.to_array(),
                size_mm: d.size,
                bins: d.bins,
                bin_size_mm: d.bin_size(),
                angular_bins: d.angular_bins,
            },
            warnings: self
                .scene
                .warnings
                .iter()
                .cloned()
                .chain((!metrics.has_light()).then(|| NO_LIGHT.to_string()))
                .collect(),
        }
    }
}

impl RunResult {
    /// The ledger's pattern hits on the tags whose model is `kind` ("dots", "grooves").
    fn feature_hits(&self, kind: &str) -> BTreeMap<String, u64> {
        let l = &self.tally.ledger;
        self.scene
            .tags
            .iter()
            .zip(&self.scene.surfaces)
            .zip(&l.feature_hits_by_tag)
            .filter(|((_, m), _)| m.kind() == kind)
            .map(|((t, _), &n)| (t.clone(), n))
            .collect()
    }
}

/// The convergence history as CSV: photons, seconds, then each metric and its stderr.
pub fn convergence_csv(history: &[ConvergenceRow]) -> String {
    let mut s = String::from("photons,seconds");
    for n in Metric::ALL.map(Metric::name) {
        let _ = write!(s, ",{n},{n}_stderr");
    }
    s.push('\n');
    for r in history {
        let _ = write!(s, "{},{:.6}", r.photons, r.seconds);
        for ((_, v), (_, e)) in r.values.iter().zip(r.stderr.iter()) {
            let _ = write!(s, ",{v:.9e},{e:.9e}");
        }
        s.push('\n');
    }
    s
}

/// Relative error against run time of the scene named `scene`, with the 1/sqrt(t)
/// reference line; see [`convergence_chart`].
pub fn write_convergence_png(path: &Path, scene: &str, history: &[ConvergenceRow]) -> Result<()> {
    write_chart(path, &convergence_chart(scene, history))
}

/// The chart of `convergence.png`: relative standard errors against tracing time and the
/// 1/sqrt(t) line through the first round's error of the mean flux, over the rounds' time
/// span only. Each axis is logarithmic when its data span at least a decade, else linear
/// (two rounds of a short run span a factor of two, which a log axis would pad to decades).
/// The title names the scene, `scene`, as the maps' titles do.
pub fn convergence_chart(scene: &str, history: &[ConvergenceRow]) -> Chart {
    let shown = [
        (Metric::Mean, "mean flux"),
        (Metric::Efficiency, "efficiency"),
        (Metric::Cv, "cv"),
        (Metric::ThirteenPoint, "13-point"),
        (Metric::MeanRelStderr, "bin (mean)"),
    ];
    let mut series: Vec<Series> = shown
        .iter()
        .map(|&(m, label)| Series {
            label: label.to_string(),
            points: history
                .iter()
                .map(|r| (r.seconds, relative_error(m, r.values[m], r.stderr[m])))
                .collect(),
            dashed: false,
            markers: true,
        })
        .collect();
    let x_scale = scale_for(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let y_scale = scale_for(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)));
    let mean = Metric::Mean;
    let first = history
        .iter()
        .find(|r| r.seconds > 0.0 && r.stderr[mean] > 0.0);
    let t_end = history.last().map_or(0.0, |r| r.seconds);
    if let Some(first) = first.filter(|f| t_end > f.seconds) {
        let e0 = first.stderr[mean] / first.values[mean];
        // Enough points to draw the curve on linear axes too.
        let n = 32;
        let points = (0..=n)
            .map(|k| {
                let t = first.seconds * (t_end / first.seconds).powf(k as f64 / n as f64);
                (t, e0 * (first.seconds / t).sqrt())
            })
            .collect();
        series.push(Series {
            label: "1/sqrt(t)".into(),
            points,
            dashed: true,
            markers: false,
        });
    }
    Chart {
        title: format!("{scene}: Monte Carlo error against run time"),
        x_label: "tracing time (s)".into(),
        y_label: "relative standard error".into(),
        x_scale,
        y_scale,
        series,
    }
}

/// Log10 when the positive finite `values` span at least a factor of ten, else linear.
fn scale_for(values: impl Iterator<Item = f64>) -> Scale {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if hi >= 10.0 * lo {
        Scale::Log10
    } else {
        Scale::Linear
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn history(seconds: &[f64]) -> Vec<ConvergenceRow> {
        seconds
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                let n = (k + 1) as f64;
                ConvergenceRow {
                    photons: 4096 * (k as u64 + 1),
                    seconds: t,
                    values: MetricValues::splat(1.0),
                    stderr: MetricValues::splat(0.01 / n.sqrt()),
                }
            })
            .collect()
    }

    fn time_range(chart: &Chart) -> (f64, f64) {
        let t = chart
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0));
        t.fold((f64::INFINITY, 0.0), |(lo, hi), t| (lo.min(t), hi.max(t)))
    }

    #[test]
    fn two_rounds_of_a_short_run_get_linear_axes_over_the_run() {
        let chart = convergence_chart("box", &history(&[1.5, 2.0]));
        assert_eq!(chart.title, "box: Monte Carlo error against run time");
        assert_eq!(chart.x_scale, Scale::Linear);
        // The errors (0.007 to 1 here: the bins' error is a relative error itself) do
        // span decades.
        assert_eq!(chart.y_scale, Scale::Log10);
        let (lo, hi) = time_range(&chart);
        assert_eq!(
            (lo, hi),
            (1.5, 2.0),
            "the reference line stays within the run"
        );
        let reference = chart.series.last().unwrap();
        assert_eq!(reference.label, "1/sqrt(t)");
        let (t, e) = reference.points[reference.points.len() - 1];
        assert!((e - 0.01 * (1.5f64 / t).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn runs_over_decades_get_log_axes_spanning_the_data() {
        let times: Vec<f64> = (0..12).map(|k| 0.1 * 2f64.powi(k)).collect();
        let chart = convergence_chart("box", &history(&times));
        assert_eq!(chart.x_scale, Scale::Log10);
        let (lo, hi) = time_range(&chart);
        assert_eq!((lo, hi), (0.1, times[11]));
        // One round: no reference line, nothing beyond the data.
        let chart = convergence_chart("box", &history(&[2.0]));
        assert_eq!(chart.series.len(), 5);
        assert_eq!(time_range(&chart), (2.0, 2.0));
    }
}
