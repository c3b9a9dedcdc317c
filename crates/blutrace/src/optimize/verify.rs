//! The verification: the first and the final design re-traced with a seed no evaluation
//! used and `--verify-photons` photons.

use super::design::Design;
use super::search::Search;
use super::{Verification, VerifiedDesign};
use crate::optics::dots::Density;
use crate::run::RunOptions;
use crate::run::RunResult;
use anyhow::Result;

/// Re-trace the first and the final design; returns their runs and the verification, or
/// None with `verify_photons = 0`.
pub(super) fn verify(
    search: &Search,
    initial_density: &Density,
    final_density: &Density,
) -> Result<Option<(RunResult, RunResult, Verification)>> {
    let options = search.options;
    if options.verify_photons == 0 {
        return Ok(None);
    }
    let run_options = options.verification_run();
    let (initial_run, initial) = verify_design(search, &run_options, initial_density)?;
    let (final_run, final_design) = verify_design(search, &run_options, final_density)?;
    let verification = Verification {
        seed: run_options.seed,
        photons: options.verify_photons,
        initial,
        final_design,
    };
    Ok(Some((initial_run, final_run, verification)))
}

/// Trace one design with the verification's run options.
fn verify_design(
    search: &Search,
    run_options: &RunOptions,
    density: &Density,
) -> Result<(RunResult, VerifiedDesign)> {
    let (run, evaluation) = search.trace(density, run_options)?;
    let summary = run.summary();
    let design = VerifiedDesign {
        evaluation,
        summary,
    };
    Ok((run, design))
}
