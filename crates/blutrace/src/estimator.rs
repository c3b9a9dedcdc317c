//! How absorption is sampled: analog Russian roulette (the paper's) or weights.
//!
//! Chosen per run (`blutrace trace --estimator analog|weighted`); the surface models and
//! the tracer's medium absorption both follow it.

use crate::rng::PhotonRng;

/// How surface absorption is sampled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Estimator {
    /// The paper's analog tracing: absorbed or not by Russian roulette on the albedo.
    #[default]
    Analog,
    /// Absorption by weights: the photon always scatters and carries the albedo as a
    /// weight factor (and exp(-a t) through absorbing media); Russian roulette only once
    /// its weight is low. Unbiased, lower variance where absorption is strong.
    Weighted,
}

impl Estimator {
    /// A reflection that keeps `albedo` of the photon: `None` when it is absorbed, else
    /// the factor on its weight (roulette in analog mode, the albedo when weighted).
    pub fn survive(self, albedo: f64, rng: &mut PhotonRng) -> Option<f64> {
        match self {
            Estimator::Analog => (rng.uniform() < albedo).then_some(1.0),
            Estimator::Weighted => (albedo > 0.0).then_some(albedo),
        }
    }
}

/// How the luminance maps are estimated (`blutrace trace --luminance-estimator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LuminanceEstimator {
    /// The luminance meter's estimator: at every diffuse event, the light that leaves
    /// towards each view through the specular layers above it (peel-off, the tracer's
    /// `meter`), and the cone count for the light no peel-off reaches. Unbiased.
    #[default]
    Meter,
    /// Count the photons that happen to leave within each view's cone.
    Cone,
}

impl LuminanceEstimator {
    /// Its name on the command line and in outputs.
    pub fn name(self) -> &'static str {
        match self {
            LuminanceEstimator::Meter => "meter",
            LuminanceEstimator::Cone => "cone",
        }
    }
}
