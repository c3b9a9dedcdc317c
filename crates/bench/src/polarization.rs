//! The cost of polarized transport: each scene traced with the averaged Fresnel
//! (`[trace] polarization = false`, bench-box's setting) and polarized (Stokes vectors,
//! exact Fresnel: the default of every scene with a dielectric face), the same photons,
//! interleaved rounds.

use anyhow::Result;
use blutrace::run::metrics::median;
use blutrace::run::{self, RunOptions};
use blutrace::scene::Scene;
use std::path::Path;

/// One scene's row: photons/s without and with polarization, and their ratio.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PolarizationRow {
    /// The scene folder.
    pub scene: String,
    /// Photons/s with the averaged Fresnel (polarization off).
    pub averaged_per_s: f64,
    /// Photons/s with polarization traced.
    pub polarized_per_s: f64,
    /// `polarized_per_s / averaged_per_s`.
    pub ratio: f64,
}

/// The table for the scene folders `dirs`: `photons` each, medians of `repeat` rounds.
pub fn polarization_table(
    dirs: &[&Path],
    photons: u64,
    threads: Option<usize>,
    repeat: usize,
) -> Result<Vec<PolarizationRow>> {
    let mut pairs = Vec::new();
    for dir in dirs {
        let averaged = Scene::load(&dir.join("scene.toml"))?;
        let mut polarized = averaged.clone();
        polarized.polarized = true;
        let mut off = averaged;
        off.polarized = false;
        pairs.push((dir.display().to_string(), [off, polarized]));
    }
    let o = RunOptions {
        photons,
        seed: 1,
        threads,
        ..RunOptions::default()
    };
    let mut rates = vec![[Vec::new(), Vec::new()]; pairs.len()];
    for _ in 0..repeat.max(1) {
        for (p, (_, scenes)) in pairs.iter().enumerate() {
            for (k, scene) in scenes.iter().enumerate() {
                rates[p][k].push(run::trace(scene, &o, &|_| {})?.summary().photons_per_s);
            }
        }
    }
    Ok(pairs
        .iter()
        .zip(rates)
        .map(|((scene, _), [off, on])| {
            let (averaged_per_s, polarized_per_s) = (median(off), median(on));
            PolarizationRow {
                scene: scene.clone(),
                averaged_per_s,
                polarized_per_s,
                ratio: polarized_per_s / averaged_per_s,
            }
        })
        .collect())
}
