//! The luminance meter's estimator against the cone count: every bundled scene with a
//! luminance map traced with each, the same photons, interleaved rounds; the map's
//! noise floor and the figure of merit `1 / (floor^2 * seconds)` of each.

use anyhow::Result;
use blutrace::estimator::LuminanceEstimator;
use blutrace::run::metrics::median;
use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
use std::path::Path;

/// One scene's row for one estimator.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LuminanceRow {
    /// The scene folder.
    pub scene: String,
    /// The estimator.
    pub estimator: LuminanceEstimator,
    /// Photons traced.
    pub photons: u64,
    /// Tracing seconds (median of the rounds).
    pub seconds: f64,
    /// The luminance map's noise floor (its cv from noise alone).
    pub noise_floor: f64,
    /// The map mean's relative standard error.
    pub mean_rel_error: f64,
    /// The fraction of the map the cone count scored (1 under the cone estimator).
    pub cone_counted: f64,
    /// `1 / (noise_floor^2 * seconds)`.
    pub fom_map: f64,
}

/// The rows for the scene folders `dirs` that have a luminance map, `photons` each (at
/// most the scene's own count), medians of `repeat` rounds.
pub fn luminance_table(
    dirs: &[&Path],
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<Vec<LuminanceRow>> {
    let scenes: Vec<(String, Scene)> = dirs
        .iter()
        .map(|d| Ok((d.display().to_string(), Scene::load(&d.join("scene.toml"))?)))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .filter(|(_, s)| s.luminous())
        .collect();
    let estimators = [LuminanceEstimator::Cone, LuminanceEstimator::Meter];
    let mut seconds = vec![vec![Vec::new(); 2]; scenes.len()];
    let mut last = vec![vec![None; 2]; scenes.len()];
    for _ in 0..repeat.max(1) {
        for (i, (_, scene)) in scenes.iter().enumerate() {
            for (k, e) in estimators.iter().enumerate() {
                let o = RunOptions {
                    photons: photons.min(scene.default_photons),
                    seed: 1,
                    threads,
                    luminance_estimator: *e,
                    ..RunOptions::default()
                };
                let r = run::trace(scene, &o, &|_| {})?;
                seconds[i][k].push(r.runtime_s);
                last[i][k] = Some((o.photons, r.summary()));
            }
        }
    }
    let mut rows = Vec::new();
    for (i, (name, _)) in scenes.iter().enumerate() {
        for (k, e) in estimators.iter().enumerate() {
            let (photons, s) = last[i][k].take().expect("traced");
            let m = s
                .luminance_map
                .expect("a luminous scene has a luminance map");
            let t = median(std::mem::take(&mut seconds[i][k]));
            rows.push(LuminanceRow {
                scene: name.clone(),
                estimator: *e,
                photons,
                seconds: t,
                noise_floor: m.cv_noise_floor,
                mean_rel_error: m.mean_cd_m2.stderr / m.mean_cd_m2.value,
                cone_counted: m.cone_counted_fraction,
                fom_map: 1.0 / (m.cv_noise_floor.powi(2) * t),
            });
        }
    }
    Ok(rows)
}
