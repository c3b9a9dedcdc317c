//! Command-line spellings of library enums, with their help: one table per enum, turned
//! into a clap value parser (`#[arg(value_parser = enums::backend())]`), so the library's
//! types stay free of the command-line parser.

use blutrace::accel::BackendChoice;
use blutrace::estimator::{Estimator, LuminanceEstimator};
use blutrace::optimize::Method;
use blutrace::run::TargetMetric;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};

/// A spelling on the command line, its help and the value it stands for.
type Choice<T> = (&'static str, &'static str, T);

const ESTIMATORS: &[Choice<Estimator>] = &[
    (
        "analog",
        "The paper's analog tracing: absorbed or not by Russian roulette on the albedo",
        Estimator::Analog,
    ),
    (
        "weighted",
        "Absorption by weights: the photon always scatters and carries the albedo as a weight \
         factor (and exp(-a t) through absorbing media); Russian roulette only once its weight \
         is low. Unbiased, lower variance where absorption is strong",
        Estimator::Weighted,
    ),
];

const LUMINANCE_ESTIMATORS: &[Choice<LuminanceEstimator>] = &[
    (
        "meter",
        "Peel-off: at every diffuse event, the light it sends towards each view through the \
         flat specular layers above it, and the cone count for the rest. Unbiased; converges \
         at ordinary photon counts",
        LuminanceEstimator::Meter,
    ),
    (
        "cone",
        "Count the photons that happen to leave within each view's cone (for cross-checks)",
        LuminanceEstimator::Cone,
    ),
];

const BACKENDS: &[Choice<BackendChoice>] = &[
    (
        "auto",
        "The fastest backend available on this machine: Embree if its library loads, else the BVH",
        BackendChoice::Auto,
    ),
    (
        "embree",
        "Intel Embree 4.4, loaded at run time (an error when it cannot be loaded)",
        BackendChoice::Embree,
    ),
    ("bvh", "Pure-Rust BVH (obvhs)", BackendChoice::Bvh),
    (
        "brute",
        "Every triangle for every ray: the test oracle",
        BackendChoice::Brute,
    ),
];

const TARGET_METRICS: &[Choice<TargetMetric>] = &[
    (
        "mean",
        "Mean irradiance over the target",
        TargetMetric::Mean,
    ),
    (
        "efficiency",
        "Detected over emitted power",
        TargetMetric::Efficiency,
    ),
    (
        "cv",
        "Coefficient of variation of the flux map, debiased (its noise floor removed in quadrature)",
        TargetMetric::Cv,
    ),
    ("nine-point", "9-point min/max", TargetMetric::NinePoint),
    (
        "thirteen-point",
        "13-point min/max",
        TargetMetric::ThirteenPoint,
    ),
    (
        "bin",
        "The mean relative standard error of the lit bins (a per-bin target)",
        TargetMetric::Bin,
    ),
];

const METHODS: &[Choice<Method>] = &[
    (
        "nelder-mead",
        "Nelder-Mead over the density polynomial's coefficients (the paper's method)",
        Method::NelderMead,
    ),
    (
        "feedback",
        "Damped per-strip ratio updates of a tabulated density",
        Method::Feedback,
    ),
    (
        "grid",
        "With --vary: a scan of one or two variables on a grid of --grid-points each",
        Method::Grid,
    ),
];

/// A parser accepting the spellings of `table` (listed with their help by `--help`).
fn choices<T: Copy + Send + Sync + 'static>(
    table: &'static [Choice<T>],
) -> impl TypedValueParser<Value = T> {
    let values = table
        .iter()
        .map(|(n, h, _)| PossibleValue::new(*n).help(*h));
    PossibleValuesParser::new(values).map(move |s| {
        table
            .iter()
            .find(|(n, _, _)| *n == s)
            .map(|c| c.2)
            .expect("the parser passes only listed spellings")
    })
}

/// `--luminance-estimator`.
pub(super) fn luminance_estimator() -> impl TypedValueParser<Value = LuminanceEstimator> {
    choices(LUMINANCE_ESTIMATORS)
}

/// `--estimator`.
pub(super) fn estimator() -> impl TypedValueParser<Value = Estimator> {
    choices(ESTIMATORS)
}

/// `--backend`.
pub(super) fn backend() -> impl TypedValueParser<Value = BackendChoice> {
    choices(BACKENDS)
}

/// `--target-metric`.
pub(super) fn target_metric() -> impl TypedValueParser<Value = TargetMetric> {
    choices(TARGET_METRICS)
}

/// `--method`.
pub(super) fn method() -> impl TypedValueParser<Value = Method> {
    choices(METHODS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value of each enum has exactly one spelling.
    #[test]
    fn every_value_has_one_spelling() {
        fn check<T: PartialEq + std::fmt::Debug>(table: &[Choice<T>], all: &[T]) {
            for v in all {
                let n = table.iter().filter(|c| c.2 == *v).count();
                assert_eq!(n, 1, "{v:?}");
            }
            assert_eq!(table.len(), all.len());
        }
        check(ESTIMATORS, &[Estimator::Analog, Estimator::Weighted]);
        check(
            LUMINANCE_ESTIMATORS,
            &[LuminanceEstimator::Meter, LuminanceEstimator::Cone],
        );
        check(
            BACKENDS,
            &[
                BackendChoice::Auto,
                BackendChoice::Embree,
                BackendChoice::Bvh,
                BackendChoice::Brute,
            ],
        );
        check(
            METHODS,
            &[Method::NelderMead, Method::Feedback, Method::Grid],
        );
        assert_eq!(TARGET_METRICS.len(), 6);
    }
}
