//! Command-line spellings of library enums (`clap::ValueEnum`), kept here so that the
//! physics modules do not depend on the command-line parser.

use crate::estimator::Estimator;
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
