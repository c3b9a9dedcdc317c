//! Monte Carlo error against run time: reported errors are honest, fall as 1/sqrt(N),
//! stopping rules work, and both estimators agree.

mod support;

use blutrace::accel::BackendChoice;
use blutrace::optics::surface::Estimator;
use blutrace::run::metrics::Metric;
use blutrace::run::{RunOptions, StoppedBy, TargetMetric};
use blutrace::scene::Scene;
use support::*;

fn opts(photons: u64, seed: u64) -> RunOptions {
    RunOptions {
        photons,
        seed,
        threads: Some(2),
        backend: BackendChoice::Bvh,
        ..RunOptions::default()
    }
}

/// Calibration: over independent seeds, the spread of each scalar and of every bin
/// agrees with the standard errors the runs report (a chi-square bound on the ratio of
/// the sample variance to the mean reported variance). Correlated photon streams show
/// here as a ratio that grows with the photon count.
fn assert_errors_match_spread(scene: &Scene, seeds: u64, photons: u64) {
    let runs: Vec<_> = (0..seeds)
        .map(|s| trace_opts(scene, &opts(photons, 100 + s)))
        .collect();
    let k = runs.len() as f64;
    // For each quantity: sample variance over seeds against the mean reported variance;
    // (k-1) s^2 / sigma^2 is chi-square with k-1 dof: accept the central 99.9 %.
    let (lo, hi) = (
        chi2_quantile(k - 1.0, -3.29) / (k - 1.0),
        chi2_quantile(k - 1.0, 3.29) / (k - 1.0),
    );
    let check = |name: &str, values: Vec<f64>, reported: Vec<f64>| {
        let mean = values.iter().sum::<f64>() / k;
        let s2 = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
        let sigma2 = reported.iter().map(|e| e * e).sum::<f64>() / k;
        let ratio = s2 / sigma2;
        assert!(
            ratio > lo && ratio < hi,
            "{name}: spread/reported variance ratio {ratio:.3} outside [{lo:.3}, {hi:.3}]"
        );
    };
    let summaries: Vec<_> = runs.iter().map(|r| r.summary()).collect();
    check(
        "mean flux",
        summaries.iter().map(|s| s.uniformity.mean).collect(),
        summaries.iter().map(|s| s.uniformity_stderr.mean).collect(),
    );
    check(
        "cv",
        summaries.iter().map(|s| s.uniformity.cv).collect(),
        summaries.iter().map(|s| s.uniformity_stderr.cv).collect(),
    );
    check(
        "efficiency",
        summaries.iter().map(|s| s.extraction_efficiency).collect(),
        summaries
            .iter()
            .map(|s| s.extraction_efficiency_stderr)
            .collect(),
    );
    // Per bin (exact per-photon formula), pooled over all bins: a much tighter test.
    let maps: Vec<_> = runs.iter().map(|r| r.flux_map()).collect();
    let bins = maps[0].value.len();
    let mut pooled = 0.0;
    for b in 0..bins {
        let v: Vec<f64> = maps.iter().map(|m| m.value[b]).collect();
        let mean = v.iter().sum::<f64>() / k;
        let s2 = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0);
        let sigma2 = maps.iter().map(|m| m.stderr[b].powi(2)).sum::<f64>() / k;
        pooled += (k - 1.0) * s2 / sigma2;
    }
    let dof = bins as f64 * (k - 1.0);
    let (plo, phi) = (chi2_quantile(dof, -3.29), chi2_quantile(dof, 3.29));
    assert!(
        pooled > plo && pooled < phi,
        "per-bin pooled chi-square {pooled:.0} outside [{plo:.0}, {phi:.0}] ({dof} dof)"
    );
}

#[test]
fn reported_errors_match_the_spread_over_100_seeds() {
    assert_errors_match_spread(&plate_scene("seeds"), 100, 32_768);
}

/// The same at a million photons a run on a box guide, where the PCG32 streams that shared
/// one state (before this release) spread the efficiency 2.0x its reported error.
#[test]
#[ignore = "slow: 1e8 photons"]
fn reported_errors_match_the_spread_at_a_million_photons() {
    assert_errors_match_spread(&guide_scene("seeds-1e6"), 100, 1_000_000);
}

#[test]
fn error_falls_as_one_over_sqrt_n() {
    let scene = plate_scene("sqrtn");
    let small = trace_opts(&scene, &opts(131_072, 7)).summary();
    let large = trace_opts(&scene, &opts(4 * 131_072, 7)).summary();
    // The per-bin relative error is known almost exactly: 4x photons must halve it.
    let ratio = small.mean_rel_stderr / large.mean_rel_stderr;
    assert!(
        (ratio - 2.0).abs() < 0.05,
        "per-bin error ratio {ratio:.3}, expected 2"
    );
    let ratio = small.uniformity_stderr.mean / large.uniformity_stderr.mean;
    // Jackknife errors from 32 groups are themselves uncertain by ~1/sqrt(2*31) = 13 %.
    assert!(
        (ratio - 2.0).abs() < 2.0 * 4.0 * 0.13,
        "mean-flux error ratio {ratio:.3}, expected 2"
    );
}

#[test]
fn target_error_stops_at_or_below_the_target() {
    let scene = plate_scene("target");
    let o = RunOptions {
        photons: 50_000_000,
        target_error: Some(0.004),
        target_metric: TargetMetric::Mean,
        ..opts(0, 3)
    };
    let r = trace_opts(&scene, &o);
    assert_eq!(r.stopped_by, StoppedBy::TargetError);
    let s = r.summary();
    assert!(
        s.figure_of_merit.rel_error <= 0.004,
        "stopped at {}",
        s.figure_of_merit.rel_error
    );
    assert!(s.photons < 50_000_000 && r.history.len() >= 2);
    // The previous round had not reached it (it did not stop late).
    let prev = &r.history[r.history.len() - 2];
    let mean = Metric::Mean;
    assert!(prev.stderr[mean] / prev.values[mean] > 0.004);
    assert_balanced(&r);
}

#[test]
fn photon_budget_stops_exactly() {
    let scene = plate_scene("budget");
    let r = trace_opts(&scene, &opts(300_001, 3));
    assert_eq!(r.stopped_by, StoppedBy::Photons);
    assert_eq!(r.tally.ledger.photons, 300_001);
    assert_balanced(&r);
}

#[test]
fn analog_and_weighted_estimators_agree() {
    let scene = plate_scene("estimators");
    let analog = trace_opts(&scene, &opts(400_000, 11));
    let weighted = trace_opts(
        &scene,
        &RunOptions {
            estimator: Estimator::Weighted,
            ..opts(400_000, 12)
        },
    );
    assert_balanced(&analog);
    assert_balanced(&weighted);
    let (a, w) = (analog.summary(), weighted.summary());
    let z = |x: f64, ex: f64, y: f64, ey: f64| (x - y).abs() / (ex * ex + ey * ey).sqrt();
    let ze = z(
        a.extraction_efficiency,
        a.extraction_efficiency_stderr,
        w.extraction_efficiency,
        w.extraction_efficiency_stderr,
    );
    assert!(
        ze < 4.0,
        "efficiency differs by {ze:.1} sigma: {} vs {}",
        a.extraction_efficiency,
        w.extraction_efficiency
    );
    // The whole map: sum of squared z-scores is chi-square with 100 dof.
    let (ma, mw) = (analog.flux_map(), weighted.flux_map());
    let chi2: f64 = (0..ma.value.len())
        .map(|b| z(ma.value[b], ma.stderr[b], mw.value[b], mw.stderr[b]).powi(2))
        .sum();
    let limit = chi2_quantile(ma.value.len() as f64, 3.29);
    assert!(
        chi2 < limit,
        "flux maps differ: chi-square {chi2:.1} > {limit:.1}"
    );
    // Absorption is booked where it happens in both.
    let pmma = scene.media.iter().position(|m| m.name == "pmma").unwrap();
    assert!(w.ledger.absorbed_in_medium_w["pmma"] > 0.0 && pmma > 0);
}

#[test]
fn weighted_runs_are_thread_independent_too() {
    let scene = plate_scene("wthreads");
    let one = trace_opts(
        &scene,
        &RunOptions {
            estimator: Estimator::Weighted,
            threads: Some(1),
            ..opts(50_000, 5)
        },
    );
    let two = trace_opts(
        &scene,
        &RunOptions {
            estimator: Estimator::Weighted,
            threads: Some(2),
            ..opts(50_000, 5)
        },
    );
    assert_eq!(one.tally, two.tally);
    assert_eq!(one.groups, two.groups);
}
