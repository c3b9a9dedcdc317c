//! The colour of the detected light: CIE 1931 X, Y, Z per flux bin and per angular bin,
//! tallied beside the radiant weights when the scene's sources have spectra.
//!
//! A detected photon of weight w and wavelength λ scores w x̄(λ), w ȳ(λ), w z̄(λ) (the
//! 2-degree observer, [`crate::sources::spectrum::cmf_at`]); one that carried several
//! wavelengths scores them all, each by its own throughput
//! ([`crate::optics::spectrum::Secondaries::xyz`]). Sampling λ from the sources' spectra
//! makes the sums unbiased estimates of ∫ E(λ) x̄(λ) dλ etc. per unit radiant power. Like every tally they are exact fixed-point sums with per-photon sums of
//! squares, so they merge, split and shard as the radiant ones do.

use super::{BinStats, Detection, Grid, Sign};
use serde::{Deserialize, Serialize};

/// X, Y, Z per flux bin and per angular bin.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ColorTally {
    /// X, Y, Z on the target plane, shaped as the flux grid.
    pub flux: [Grid; 3],
    /// X, Y, Z per (theta, phi) bin, shaped as the angular grid.
    pub angular: [Grid; 3],
}

/// One detection's X, Y, Z, each scored alone into a bin (rounded to fixed point once).
pub type ScoredXyz = [BinStats; 3];

impl ColorTally {
    /// Empty, shaped as `flux` and `angular`.
    pub fn new(flux: &Grid, angular: &Grid) -> Self {
        let like = |g: &Grid| std::array::from_fn(|_| Grid::new(g.nx, g.ny));
        Self {
            flux: like(flux),
            angular: like(angular),
        }
    }

    /// Each detection's X, Y, Z.
    pub fn scored(detections: &[Detection]) -> Vec<ScoredXyz> {
        detections
            .iter()
            .map(|d| {
                let xyz = d.secondaries.xyz(d.light, d.weight);
                std::array::from_fn(|k| {
                    let mut one = BinStats::default();
                    one.add(xyz[k]);
                    one
                })
            })
            .collect()
    }

    /// Add `detections`, whose X, Y, Z are `scored`.
    pub fn absorb(&mut self, detections: &[Detection], scored: &[ScoredXyz]) {
        for (d, xyz) in detections.iter().zip(scored) {
            for (k, one) in xyz.iter().enumerate() {
                self.flux[k].bins[d.flux_bin as usize].merge(one);
                self.angular[k].bins[d.angular_bin as usize].merge(one);
            }
        }
    }

    /// Every grid, flux first.
    fn grids(&self) -> impl Iterator<Item = &Grid> {
        self.flux.iter().chain(&self.angular)
    }

    /// The grids' shapes.
    pub fn shape(&self) -> Vec<(usize, usize, usize)> {
        self.grids().map(|g| (g.nx, g.ny, g.bins.len())).collect()
    }

    /// Whether a bin holds negative weight or more than `photons` photons.
    pub fn has_bad_bin(&self, photons: u64) -> bool {
        self.grids().any(|g| {
            g.bins
                .iter()
                .any(|b| b.sum.0 < 0 || b.sumsq.0 < 0 || b.hits > photons)
        })
    }

    /// Add `o` (or take it out).
    pub fn merge_signed(&mut self, o: &ColorTally, sign: Sign) {
        for (a, b) in self.flux.iter_mut().zip(&o.flux) {
            a.merge_signed(b, sign);
        }
        for (a, b) in self.angular.iter_mut().zip(&o.angular) {
            a.merge_signed(b, sign);
        }
    }

    /// Add `o`, or `None` past the counters' range.
    pub fn checked_merge(&mut self, o: &ColorTally) -> Option<()> {
        for (a, b) in self.flux.iter_mut().zip(&o.flux) {
            a.checked_merge(b)?;
        }
        for (a, b) in self.angular.iter_mut().zip(&o.angular) {
            a.checked_merge(b)?;
        }
        Some(())
    }
}
