//! `blutrace trace` and `blutrace merge`: run a scene (or one shard of it), merge shards,
//! and print the run's report.

use super::enums;
use super::{default_out, scene_path, word};
use anyhow::{Result, bail};
use blutrace::accel::BackendChoice;
use blutrace::estimator::{Estimator, LuminanceEstimator};
use blutrace::output::atomic::check_dest;
use blutrace::run::metrics::cone::LuminanceMapSummary;
use blutrace::run::{self, Progress, RunOptions, Shard, StoppedBy, TargetMetric};
use blutrace::scene::Scene;
use blutrace::shard;
use indicatif::{ProgressBar, ProgressState, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub(super) struct TraceArgs {
    /// Scene file (or a folder holding scene.toml).
    scene: PathBuf,
    /// Photons to emit at most (default: the scene's [trace] photons, or 1e9 with
    /// --target-error or --max-time).
    #[arg(long, visible_alias = "max-photons", value_parser = blutrace::count::parse_photons)]
    photons: Option<u64>,
    /// Stop when the relative standard error of --target-metric is at or below this.
    #[arg(long, value_parser = blutrace::count::parse_finite)]
    target_error: Option<f64>,
    /// The metric --target-error refers to.
    #[arg(long, value_parser = enums::target_metric(), default_value = "mean")]
    target_metric: TargetMetric,
    /// Stop after about this many seconds of tracing.
    #[arg(long, value_parser = blutrace::count::parse_finite)]
    max_time: Option<f64>,
    /// Analog roulette (the paper's) or absorption by weights.
    #[arg(long, value_parser = enums::estimator(), default_value = "analog")]
    estimator: Estimator,
    /// How the luminance maps are estimated: the meter's peel-off (default) or the cone
    /// count.
    #[arg(long, value_parser = enums::luminance_estimator(), default_value = "meter")]
    luminance_estimator: LuminanceEstimator,
    /// Seed of the per-photon random streams (default: the scene's [trace] seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Intersection backend.
    #[arg(long, value_parser = enums::backend(), default_value = "auto")]
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
    /// Half-angle (degrees) of the luminance map's cone about the detector normal,
    /// instead of the scene's detector.luminance_cone_deg (default 2, a luminance meter's
    /// acceptance). Not with --shard: set it in the scene file, so shards and merge agree.
    #[arg(long, value_parser = blutrace::count::parse_finite)]
    luminance_cone_deg: Option<f64>,
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

/// `blutrace trace`; `quiet`: no progress bar.
pub(super) fn trace(args: TraceArgs, quiet: bool) -> Result<ExitCode> {
    // First, so an interrupt while the scene loads is one too.
    let interrupt = super::stop_on_signals();
    let mut scene = Scene::load(&scene_path(&args.scene))?;
    if let Some(cone) = args.luminance_cone_deg {
        if args.shard.is_some() {
            bail!(
                "option `luminance_cone_deg` cannot be given with option `shard`: set detector.luminance_cone_deg in the scene file, so every shard and the merge use the same cone"
            );
        }
        scene
            .detector
            .set_luminance_cone(cone)
            .map_err(|e| anyhow::anyhow!("option `luminance_cone_deg` {e}"))?;
    }
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
        luminance_estimator: args.luminance_estimator,
        target_error: args.target_error,
        target_metric: args.target_metric,
        max_time_s: args.max_time,
        shard: args.shard,
        convex: !args.no_convex,
        interrupt,
    };
    let out = args.out.unwrap_or_else(|| default_out(&scene.name));
    // A folder the run could not replace is refused before tracing, not after.
    let names = if args.shard.is_some() {
        &[shard::SHARD_FILE][..]
    } else {
        run::OUTPUT_NAMES
    };
    check_dest(&out, names, &scene.inputs)?;
    let (first, last) = options.photon_range();
    let bar = progress_bar(
        &options,
        last - first,
        open_ended && args.photons.is_none(),
        quiet,
    );
    let result = run::trace(&scene, &options, &|p| match p {
        Progress::Chunk(n) => bar.inc(n),
        Progress::Round { rel_error, .. } => bar.set_message(target_message(&options, rel_error)),
    })?;
    bar.finish_and_clear();
    if let Some(sh) = args.shard {
        let (first, last) = options.photon_range();
        let file = shard::write_shard(&result, &out)?;
        say!(
            "shard      {}/{}: photons {first}..{last} of {} in {:.2} s",
            sh.index,
            sh.count,
            options.photons,
            result.runtime_s
        );
        say!("wrote      {}", file.display());
        return Ok(exit_code(result.stopped_by));
    }
    let files = result.write(&out)?;
    print_report(&result.summary(), &files);
    print_stop_note(&options, &result);
    Ok(exit_code(result.stopped_by))
}

/// 130 (128 + SIGINT, as a shell reports) for an interrupted run, whose outputs were
/// written all the same.
fn exit_code(stopped_by: StoppedBy) -> ExitCode {
    match stopped_by {
        StoppedBy::Interrupted => ExitCode::from(130),
        _ => ExitCode::SUCCESS,
    }
}

/// Why an open-ended run ended, when it is not the reason asked for.
fn print_stop_note(o: &RunOptions, r: &run::RunResult) {
    let target = o.target_error.map(|e| (e, word(&o.target_metric)));
    match (r.stopped_by, target) {
        (StoppedBy::Interrupted, _) => say!(
            "note       interrupted: the outputs hold the {} photons traced before it",
            r.tally.ledger.photons
        ),
        (StoppedBy::Unreachable, Some((e, m))) => say!(
            "note       target error {e} of {m} cannot be reached: nothing was detected in {} photons, so the metric and its error are 0/0",
            r.tally.ledger.photons
        ),
        (StoppedBy::Photons | StoppedBy::Time, Some((e, m))) => {
            let rel = r.summary().figure_of_merit.rel_error;
            say!(
                "note       target error {e} of {m} not reached: its relative error is {} after {} photons{}",
                err(rel, 3, false),
                r.tally.ledger.photons,
                if o.target_metric == TargetMetric::Cv {
                    " (of the debiased cv: a map uniform within its noise has no cv to resolve)"
                } else {
                    ""
                }
            )
        }
        _ => {}
    }
}

/// The progress bar on a terminal: photons, elapsed time and a rounded rate; against the
/// photon budget when that is what ends the run (`open_ended`: a stopping rule and no
/// --photons), else the time against --max-time and the target metric's error against
/// --target-error.
fn progress_bar(o: &RunOptions, photons: u64, open_ended: bool, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let template = if open_ended {
        "{spinner} {pos} photons  {elapsed}{limit}  {rate}  {msg}"
    } else {
        "{bar:40} {pos}/{len} photons  {elapsed} elapsed  {rate}  eta {eta}  {msg}"
    };
    let max_time = o.max_time_s;
    let style = ProgressStyle::with_template(template)
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .with_key("rate", |s: &ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{} photons/s", three_digits(s.per_sec()));
        })
        .with_key(
            "limit",
            move |_: &ProgressState, w: &mut dyn std::fmt::Write| {
                if let Some(t) = max_time {
                    let _ = write!(w, " of {t} s");
                }
            },
        );
    let bar = ProgressBar::new(photons).with_style(style);
    bar.set_message(target_message(o, f64::NAN));
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// `rel. error 0.034 (target 0.01) of mean`, as the last round left it.
fn target_message(o: &RunOptions, rel_error: f64) -> String {
    match o.target_error {
        Some(target) => format!(
            "rel. error {} (target {target}) of {}",
            if rel_error.is_finite() {
                format!("{rel_error:.3}")
            } else {
                "-".into()
            },
            word(&o.target_metric)
        ),
        None => String::new(),
    }
}

/// A rate with three significant digits (`123000`, `1.23e+06` past a million).
fn three_digits(x: f64) -> String {
    if !x.is_finite() || x <= 0.0 {
        "-".into()
    } else if x < 1e6 {
        let digits = (2 - x.log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.2e}")
    }
}

fn print_report(s: &run::summary::Summary, files: &[PathBuf]) {
    let l = &s.ledger;
    let (u, e) = (&s.uniformity, &s.uniformity_stderr);
    let absorbed =
        l.absorbed_w.values().sum::<f64>() + l.absorbed_in_medium_w.values().sum::<f64>();
    let lamps = l.absorbed_by_source_w.values().sum::<f64>();
    say!("scene      {} ({})", s.scene, s.scene_file);
    say!(
        "traced     {} photons, seed {}, backend {}, estimator {}, {} threads; stopped by {}",
        s.photons,
        s.seed,
        s.backend,
        word(&s.estimator),
        s.threads,
        word(&s.stopped_by)
    );
    say!(
        "time       {:.2} s  ({:.0} photons/s, {:.0} interactions/s)",
        s.runtime_s,
        s.photons_per_s,
        s.interactions_per_s
    );
    say!(
        "ledger     emitted {:.4} W = detected {:.4} + absorbed {:.4} + lamp bodies {:.4} + analyzer {:.4} + escaped {:.4} + killed {:.4} + roulette {:.4}  (balance error {:.1e})",
        l.emitted_w,
        l.detected_w,
        absorbed,
        lamps,
        l.absorbed_by_analyzer_w,
        l.escaped_w,
        l.killed_w,
        l.roulette_w,
        l.balance_rel_error
    );
    if l.detected_by_source_w.len() > 1 {
        let parts: Vec<String> = l
            .detected_by_source_w
            .iter()
            .map(|d| format!("{} {:.4} ± {:.4}", d.source, d.w, d.stderr_w))
            .collect();
        say!("by source  detected W: {}", parts.join(", "));
    }
    say!(
        "efficiency {:.4} ± {:.4} of the emitted power reaches the target",
        s.extraction_efficiency,
        s.extraction_efficiency_stderr
    );
    say!(
        "flux       mean {:.4e} ± {} W/mm²",
        u.mean,
        err(e.mean, 1, true)
    );
    say!(
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
    let chunk = blutrace::tracer::CHUNK;
    if l.detected_w == 0.0 {
        eprintln!("warning: {}", run::summary::NO_LIGHT);
    } else if s.photons < 2 * chunk {
        say!(
            "note       errors of the map's metrics (jackknife over chunks of {chunk} photons) need at least {} photons; this run traced {}",
            2 * chunk,
            s.photons
        );
    }
    say!(
        "noise      mean relative stderr per bin {:.3}; figure of merit 1/(err²·t) = {} ({})",
        s.mean_rel_stderr,
        err(s.figure_of_merit.per_s, 3, true),
        word(&s.figure_of_merit.metric)
    );
    if let Some(lum) = &s.luminance {
        say!(
            "luminance  on-axis {:.1} ± {:.1} cd/m² (sources at {:.0} lm/W)",
            lum.on_axis_cd_m2,
            lum.on_axis_stderr_cd_m2,
            lum.efficacy_lm_per_w
        );
    }
    if let Some(m) = &s.luminance_map {
        print_luminance_map(m, s.luminance_estimator, s.photons);
        for v in s.luminance_views.iter().skip(1) {
            print_luminance_map(v, s.luminance_estimator, s.photons);
        }
    }
    if let Some(c) = &s.color {
        print_colour(c);
    }
    if let Some(p) = &s.polarization {
        print_polarization(p);
    }
    for f in files {
        say!("wrote      {}", f.display());
    }
}

/// The colour line of a spectral run: the target's chromaticity, CCT and 13-point
/// colour non-uniformity (noise removed), each with its error, as summary.json has them.
fn print_colour(c: &blutrace::run::metrics::color::ColorSummary) {
    let num = |e: &blutrace::run::metrics::Estimate, digits: usize| {
        format!(
            "{} ± {}",
            err(e.value, digits, false),
            err(e.stderr, digits, false)
        )
    };
    say!(
        "colour     x {}, y {}, CCT {} K, Δu'v' 13-point {} (debiased)",
        num(&c.x, 4),
        num(&c.y, 4),
        num(&c.cct_k, 0),
        num(&c.delta_uv_13pt_debiased, 4)
    );
}

/// The polarization line of a run that traces it: the target light's normalised Stokes
/// vector and degree of polarization, each with its error, as summary.json has them.
fn print_polarization(p: &blutrace::run::metrics::stokes::PolarizationSummary) {
    let num = |e: &blutrace::run::metrics::Estimate| {
        format!("{} ± {}", err(e.value, 4, false), err(e.stderr, 4, false))
    };
    say!(
        "polarized  S1/S0 {}, S2/S0 {}, S3/S0 {}, degree {} (detector frame, S1 > 0 along u)",
        num(&p.s1),
        num(&p.s2),
        num(&p.s3),
        num(&p.dop)
    );
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

/// `blutrace merge`. An interrupt before the merged set is written ends it with nothing
/// written (the inputs and any previous set untouched), exit 130; the set itself is
/// written all-or-nothing.
pub(super) fn merge(args: MergeArgs) -> Result<ExitCode> {
    let interrupt = super::stop_on_signals();
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
    let mut inputs: Vec<PathBuf> = args.shards.clone();
    inputs.extend(scene.inputs.iter().cloned());
    check_dest(&args.out, run::OUTPUT_NAMES, &inputs)?;
    let result = shard::merge(&shards, &scene)?;
    if interrupt.requested() {
        eprintln!("interrupted before the merged outputs were written: nothing written");
        return Ok(ExitCode::from(130));
    }
    let files = result.write(&args.out)?;
    print_report(&result.summary(), &files);
    Ok(ExitCode::SUCCESS)
}

/// The luminance map of one view: its numbers, and a note when it is mostly noise or
/// the meter's peel-off could not reach most of its light.
fn print_luminance_map(m: &LuminanceMapSummary, estimator: LuminanceEstimator, photons: u64) {
    let num = |x: f64, digits: usize| err(x, digits, false);
    let view = match m.view_deg {
        [0.0, _] => "the normal".to_string(),
        [theta, phi] => format!("theta {theta}° phi {phi}°"),
    };
    let how = match estimator {
        LuminanceEstimator::Cone => "cone count".to_string(),
        LuminanceEstimator::Meter if m.cone_counted_fraction.is_finite() => format!(
            "meter, {:.1}% by peel-off",
            100.0 * (1.0 - m.cone_counted_fraction)
        ),
        LuminanceEstimator::Meter => "meter".to_string(),
    };
    say!(
        "luminance  map within {}° of {view} ({how}): mean {} ± {} cd/m², 13-point min/max {} ± {}, cv {} (noise floor {})",
        m.cone_deg,
        num(m.mean_cd_m2.value, 1),
        err(m.mean_cd_m2.stderr, 1, false),
        num(m.thirteen_point_min_over_max.value, 3),
        err(m.thirteen_point_min_over_max.stderr, 3, false),
        num(m.cv.value, 3),
        num(m.cv_noise_floor, 3)
    );
    let needed = match m.photons_needed.is_finite() {
        true => format!("about {:.1e} photons", m.photons_needed),
        false => "more photons".to_string(),
    };
    if m.photons_in_cone == 0 {
        say!(
            "note       no photon left the target within the {}° cone in {photons} photons: the luminance map measured nothing (null in summary.json, not 0 cd/m²); a noise floor of 0.1 needs {needed}, or widen --luminance-cone-deg",
            m.cone_deg,
        );
        return;
    }
    if estimator == LuminanceEstimator::Meter && m.cone_counted_fraction > 0.5 {
        let cause = m.cone_counted_mostly.as_deref().unwrap_or("?");
        say!(
            "note       the meter's peel-off reached only {:.0}% of this light: {cause} kept it from the rest, which is counted in the cone",
            100.0 * (1.0 - m.cone_counted_fraction)
        );
    }
    if m.cv_noise_floor > 0.3 {
        say!(
            "note       the luminance map is mostly noise at this photon count: a noise floor of 0.1 needs {needed}, or widen --luminance-cone-deg"
        );
    }
}
