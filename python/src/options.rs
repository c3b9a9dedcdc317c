//! The spellings and checks of arguments that `trace`, `optimize` and `characterise` share.

use crate::convert::count;
use blutrace::accel::BackendChoice;
use blutrace::estimator::{Estimator, LuminanceEstimator};
use blutrace::run::{self, TargetMetric};
use blutrace::scene::Scene as RustScene;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Spellings of the estimators, as on the command line.
pub const ESTIMATORS: &[(&str, Estimator)] = &[
    ("analog", Estimator::Analog),
    ("weighted", Estimator::Weighted),
];

/// Spellings of the luminance maps' estimators.
pub const LUMINANCE_ESTIMATORS: &[(&str, LuminanceEstimator)] = &[
    ("meter", LuminanceEstimator::Meter),
    ("cone", LuminanceEstimator::Cone),
];

/// Spellings of the intersection backends.
pub const BACKENDS: &[(&str, BackendChoice)] = &[
    ("auto", BackendChoice::Auto),
    ("embree", BackendChoice::Embree),
    ("bvh", BackendChoice::Bvh),
    ("brute", BackendChoice::Brute),
];

/// Spellings of the target metrics.
pub const TARGET_METRICS: &[(&str, TargetMetric)] = &[
    ("mean", TargetMetric::Mean),
    ("efficiency", TargetMetric::Efficiency),
    ("cv", TargetMetric::Cv),
    ("nine-point", TargetMetric::NinePoint),
    ("thirteen-point", TargetMetric::ThirteenPoint),
    ("bin", TargetMetric::Bin),
];

/// `threads=n` checked: 1..=MAX_THREADS.
pub fn threads_arg(t: &Bound<'_, PyAny>) -> PyResult<usize> {
    let n = count(t, "threads", 1)?;
    if n > run::MAX_THREADS as u64 {
        return Err(PyValueError::new_err(format!(
            "threads must be within 1..={}, got {n}",
            run::MAX_THREADS
        )));
    }
    Ok(n as usize)
}

/// Argument `tag` checked: the index of a tag of `scene`, else a `ValueError` listing them
/// (the same for every call that names a part by its tag).
pub fn tag_arg(scene: &RustScene, tag: &str) -> PyResult<usize> {
    scene.tags.iter().position(|t| t == tag).ok_or_else(|| {
        PyValueError::new_err(format!(
            "tag: no tag '{tag}' in {} (its tags: {})",
            scene.path.display(),
            scene.tags.join(", ")
        ))
    })
}
