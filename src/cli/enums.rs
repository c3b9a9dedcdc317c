//! Command-line spellings of library enums (`clap::ValueEnum`), kept here so that the
//! physics modules do not depend on the command-line parser.

use crate::accel::BackendChoice;
use crate::estimator::Estimator;
use crate::optimize::Method;
use crate::run::TargetMetric;
use clap::builder::PossibleValue;

impl clap::ValueEnum for Estimator {
    fn value_variants<'a>() -> &'a [Self] {
        &[Estimator::Analog, Estimator::Weighted]
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(match self {
            Estimator::Analog => PossibleValue::new("analog").help(
                "The paper's analog tracing: absorbed or not by Russian roulette on the albedo",
            ),
            Estimator::Weighted => PossibleValue::new("weighted").help(
                "Absorption by weights: the photon always scatters and carries the albedo as a \
                 weight factor (and exp(-a t) through absorbing media); Russian roulette only \
                 once its weight is low. Unbiased, lower variance where absorption is strong",
            ),
        })
    }
}

impl clap::ValueEnum for BackendChoice {
    fn value_variants<'a>() -> &'a [Self] {
        &[
            BackendChoice::Auto,
            BackendChoice::Embree,
            BackendChoice::Bvh,
            BackendChoice::Brute,
        ]
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let (name, help) = match self {
            BackendChoice::Auto => (
                "auto",
                "The fastest backend available on this machine: Embree if its library loads, else the BVH",
            ),
            BackendChoice::Embree => (
                "embree",
                "Intel Embree 4.4, loaded at run time (an error when it cannot be loaded)",
            ),
            BackendChoice::Bvh => ("bvh", "Pure-Rust BVH (obvhs)"),
            BackendChoice::Brute => ("brute", "Every triangle for every ray: the test oracle"),
        };
        Some(PossibleValue::new(name).help(help))
    }
}

impl clap::ValueEnum for TargetMetric {
    fn value_variants<'a>() -> &'a [Self] {
        &[
            TargetMetric::Mean,
            TargetMetric::Efficiency,
            TargetMetric::Cv,
            TargetMetric::NinePoint,
            TargetMetric::ThirteenPoint,
            TargetMetric::Bin,
        ]
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let (name, help) = match self {
            TargetMetric::Mean => ("mean", "Mean irradiance over the target"),
            TargetMetric::Efficiency => ("efficiency", "Detected over emitted power"),
            TargetMetric::Cv => (
                "cv",
                "Coefficient of variation of the flux map, debiased (its noise floor removed in quadrature)",
            ),
            TargetMetric::NinePoint => ("nine-point", "9-point min/max"),
            TargetMetric::ThirteenPoint => ("thirteen-point", "13-point min/max"),
            TargetMetric::Bin => (
                "bin",
                "The mean relative standard error of the lit bins (a per-bin target)",
            ),
        };
        Some(PossibleValue::new(name).help(help))
    }
}

impl clap::ValueEnum for Method {
    fn value_variants<'a>() -> &'a [Self] {
        &[Method::NelderMead, Method::Feedback, Method::Grid]
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let (name, help) = match self {
            Method::NelderMead => (
                "nelder-mead",
                "Nelder-Mead over the density polynomial's coefficients (the paper's method)",
            ),
            Method::Feedback => (
                "feedback",
                "Damped per-strip ratio updates of a tabulated density",
            ),
            Method::Grid => (
                "grid",
                "With --vary: a scan of one or two variables on a grid of --grid-points each",
            ),
        };
        Some(PossibleValue::new(name).help(help))
    }
}
