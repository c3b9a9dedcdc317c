//! `blutrace trace` and `blutrace merge`: run a scene (or one shard of it), merge shards,
//! and print the run's report.

use super::{default_out, scene_path};
use crate::accel::BackendChoice;
use crate::estimator::Estimator;
use crate::output::atomic::check_dest;
use crate::run::{self, RunOptions, Shard, TargetMetric};
use crate::scene::Scene;
use crate::shard;
use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(super) struct TraceArgs {
    /// Scene file (or a folder holding scene.toml).
    scene: PathBuf,
    /// Photons to emit at most (default: the scene's [trace] photons, or 1e9 with
    /// --target-error or --max-time).
    #[arg(long, visible_alias = "max-photons")]
    photons: Option<u64>,
    /// Stop when the relative standard error of --target-metric is at or below this.
    #[arg(long)]
    target_error: Option<f64>,
    /// The metric --target-error refers to.
    #[arg(long, value_enum, default_value = "mean")]
    target_metric: TargetMetric,
    /// Stop after about this many seconds of tracing.
    #[arg(long)]
    max_time: Option<f64>,
    /// Analog roulette (the paper's) or absorption by weights.
    #[arg(long, value_enum, default_value = "analog")]
    estimator: Estimator,
    /// Seed of the per-photon random streams (default: the scene's [trace] seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Intersection backend.
    #[arg(long, value_enum, default_value = "auto")]
    backend: BackendChoice,
    /// Output folder (default: out/<scene name>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Trace only shard K of M of the photon indices and write its raw tallies
    /// (shard.json) for `blutrace merge`.
    #[arg(long, value_name = "K/M", value_parser = Shard::parse)]
    shard: Option<Shard>,
    /// Do not use the convex-solid fast path (every ray goes through the backend).
    #[arg(long)]
    no_convex: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
pub(super) struct MergeArgs {
    /// Shard output folders (or their shard.json files).
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Output folder for the merged results.
    #[arg(long)]
    out: PathBuf,
    /// Merge even if some shards are missing (the result then has fewer photons).
    #[arg(long)]
    partial: bool,
    /// Scene file to use (default: the one recorded in the shards).
    #[arg(long)]
    scene: Option<PathBuf>,
}

pub(super) fn trace(args: TraceArgs) -> Result<()> {
    let scene = Scene::load(&scene_path(&args.scene))?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    let open_ended = args.target_error.is_some() || args.max_time.is_some();
    let options = RunOptions {
        photons: args.photons.unwrap_or(if open_ended {
            1_000_000_000
        } else {
            scene.default_photons
        }),
        seed: args.seed.unwrap_or(scene.default_seed),
        threads: args.threads,
        backend: args.backend,
        estimator: args.estimator,
        target_error: args.target_error,
        target_metric: args.target_metric,
        max_time_s: args.max_time,
        shard: args.shard,
        convex: !args.no_convex,
    };
    let out = args.out.unwrap_or_else(|| default_out(&scene.name));
    // A folder the run could not replace is refused before tracing, not after.
    let names = if args.shard.is_some() {
        &[shard::SHARD_FILE][..]
    } else {
        run::OUTPUT_NAMES
    };
    check_dest(&out, names)?;
    let (first, last) = options.photon_range();
    let bar = progress_bar(last - first, args.quiet);
    let result = run::trace(&scene, &options, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    if let Some(sh) = args.shard {
        let (first, last) = options.photon_range();
        let file = shard::write_shard(&result, &out)?;
        println!(
            "shard      {}/{}: photons {first}..{last} of {} in {:.2} s",
            sh.index, sh.count, options.photons, result.runtime_s
        );
        println!("wrote      {}", file.display());
        return Ok(());
    }
    let files = result.write(&out)?;
    print_report(&result.summary(), &files);
    Ok(())
}

fn progress_bar(photons: u64, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template("{bar:40} {pos}/{len} photons  {per_sec}  eta {eta}")
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    ProgressBar::new(photons).with_style(style)
}

fn print_report(s: &run::summary::Summary, files: &[PathBuf]) {
    let l = &s.ledger;
    let (u, e) = (&s.uniformity, &s.uniformity_stderr);
    let absorbed =
        l.absorbed_w.values().sum::<f64>() + l.absorbed_in_medium_w.values().sum::<f64>();
    let lamps = l.absorbed_by_source_w.values().sum::<f64>();
    println!("scene      {} ({})", s.scene, s.scene_file);
    println!(
        "traced     {} photons, seed {}, backend {}, estimator {:?}, {} threads; stopped by {:?}",
        s.photons, s.seed, s.backend, s.estimator, s.threads, s.stopped_by
    );
    println!(
        "time       {:.2} s  ({:.0} photons/s, {:.0} interactions/s)",
        s.runtime_s, s.photons_per_s, s.interactions_per_s
    );
    println!(
        "ledger     emitted {:.4} W = detected {:.4} + absorbed {:.4} + lamp bodies {:.4} + escaped {:.4} + killed {:.4} + roulette {:.4}  (balance error {:.1e})",
        l.emitted_w,
        l.detected_w,
        absorbed,
        lamps,
        l.escaped_w,
        l.killed_w,
        l.roulette_w,
        l.balance_rel_error
    );
    println!(
        "efficiency {:.4} ± {:.4} of the emitted power reaches the target",
        s.extraction_efficiency, s.extraction_efficiency_stderr
    );
    println!(
        "flux       mean {:.4e} ± {} W/mm²",
        u.mean,
        err(e.mean, 1, true)
    );
    println!(
        "uniformity cv {:.3} ± {} (noise floor {:.3}, debiased {:.3}), min/max {:.3} ± {}, 9-pt {:.3} ± {}, 13-pt {:.3} ± {}",
        u.cv,
        err(e.cv, 3, false),
        s.cv_noise_floor,
        s.cv_debiased,
        u.min_over_max,
        err(e.min_over_max, 3, false),
        u.nine_point_min_over_max,
        err(e.nine_point_min_over_max, 3, false),
        u.thirteen_point_min_over_max,
        err(e.thirteen_point_min_over_max, 3, false)
    );
    let chunk = crate::tracer::CHUNK;
    if l.detected_w == 0.0 {
        println!(
            "note       no photon reached the target: the map and its uniformity metrics are empty"
        );
    } else if s.photons < 2 * chunk {
        println!(
            "note       errors of the map's metrics (jackknife over chunks of {chunk} photons) need at least {} photons; this run traced {}",
            2 * chunk,
            s.photons
        );
    }
    println!(
        "noise      mean relative stderr per bin {:.3}; figure of merit 1/(err²·t) = {} ({:?})",
        s.mean_rel_stderr,
        err(s.figure_of_merit.per_s, 3, true),
        s.figure_of_merit.metric
    );
    if let Some(lum) = &s.luminance {
        println!(
            "luminance  on-axis {:.1} ± {:.1} cd/m² (sources at {:.0} lm/W)",
            lum.on_axis_cd_m2, lum.on_axis_stderr_cd_m2, lum.efficacy_lm_per_w
        );
    }
    for f in files {
        println!("wrote      {}", f.display());
    }
}

/// An error estimate with `digits` decimals (scientific with `sci`), or `n/a` when the
/// run was too short to estimate it.
fn err(e: f64, digits: usize, sci: bool) -> String {
    match (e.is_finite(), sci) {
        (false, _) => "n/a".into(),
        (true, true) => format!("{e:.digits$e}"),
        (true, false) => format!("{e:.digits$}"),
    }
}

pub(super) fn merge(args: MergeArgs) -> Result<()> {
    let shards = args
        .shards
        .iter()
        .map(|p| Ok((p.clone(), shard::read_shard(p)?)))
        .collect::<Result<Vec<_>>>()?;
    let scene_file = match &args.scene {
        Some(p) => scene_path(p),
        None => shards[0].1.scene_file.clone(),
    };
    let scene = Scene::load(&scene_file)?;
    let missing = shard::check(&shards, &scene)?;
    if !missing.is_empty() {
        let count = shards[0].1.shard.count;
        let list: Vec<String> = missing.iter().map(|k| format!("{k}/{count}")).collect();
        if !args.partial {
            anyhow::bail!(
                "shards missing: {} (merge them too, or pass --partial)",
                list.join(", ")
            );
        }
        eprintln!(
            "warning: merging {} of {count} shards; missing {}: the result has fewer photons",
            shards.len(),
            list.join(", ")
        );
    }
    check_dest(&args.out, run::OUTPUT_NAMES)?;
    let result = shard::merge(&shards, &scene)?;
    let files = result.write(&args.out)?;
    print_report(&result.summary(), &files);
    Ok(())
}
