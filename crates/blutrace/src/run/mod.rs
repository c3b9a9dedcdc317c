//! A traced job: photons in rounds until a stopping rule holds, then maps, metrics with
//! errors, a convergence history and the output files.
//!
//! ```text
//! blutrace trace SCENE [--photons N] [--target-error E [--target-metric M]] [--max-time S]
//!                      [--estimator analog|weighted]
//! ```
//!
//! Tracing proceeds in rounds of whole photon groups; after each round the metrics and
//! their standard errors are evaluated and a row is added to the convergence history.
//! The run stops at the first of: `--photons` reached, the target metric's relative
//! standard error at or below `--target-error`, or `--max-time` seconds spent.
//!
//! Outputs written by [`RunResult::write`]:
//! - `flux.exr`, `angular.exr`: irradiance (W/mm^2 per bin) and radiant intensity (W/sr
//!   per (theta, phi) bin) as grey images with their errors and hit counts as layers, and
//!   the run's facts as header attributes (see the `images` module);
//! - `flux.png`: false-colour preview of the flux map;
//! - `convergence.csv`, `convergence.png`: metrics and errors against photons and time;
//! - `summary.json`: run facts, energy ledger, uniformity and errors.

mod color_images;
mod images;
pub mod mesh_build;
pub mod metrics;
mod rounds;
pub mod summary;

use crate::accel::{self, BackendChoice};
use crate::estimator::LuminanceEstimator;
use crate::optics::surface::Estimator;
use crate::output::atomic::{OutputSet, SetDir};
use crate::scene::{Scene, SharedScene};
use crate::tally::Tally;
use crate::tracer::{CHUNK, Tracer};
use anyhow::{Context, Result, bail};
pub use mesh_build::MeshBuildCache;
use metrics::{GROUPS, Map, Metric, MetricValues};
use rounds::Rounds;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The metric a `--target-error` refers to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TargetMetric {
    /// Mean irradiance over the target.
    #[default]
    Mean,
    /// Detected over emitted power.
    Efficiency,
    /// Coefficient of variation of the flux map, debiased (its noise floor removed in
    /// quadrature): the raw cv of a short run is mostly noise, and its error would say
    /// nothing of the backlight's.
    Cv,
    /// 9-point min/max.
    NinePoint,
    /// 13-point min/max.
    ThirteenPoint,
    /// The mean relative standard error of the lit bins (a per-bin target).
    Bin,
}

impl TargetMetric {
    /// The metric this target refers to.
    pub fn metric(self) -> Metric {
        match self {
            TargetMetric::Mean => Metric::Mean,
            TargetMetric::Efficiency => Metric::Efficiency,
            TargetMetric::Cv => Metric::CvDebiased,
            TargetMetric::NinePoint => Metric::NinePoint,
            TargetMetric::ThirteenPoint => Metric::ThirteenPoint,
            TargetMetric::Bin => Metric::MeanRelStderr,
        }
    }
}

/// How to run a trace.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Photons to emit at most.
    pub photons: u64,
    /// Seed of the per-photon streams.
    pub seed: u64,
    /// Worker threads (None: all cores).
    pub threads: Option<usize>,
    /// Intersection backend.
    pub backend: BackendChoice,
    /// How absorption is sampled.
    pub estimator: Estimator,
    /// How the luminance maps are estimated.
    pub luminance_estimator: LuminanceEstimator,
    /// Stop once the target metric's relative standard error is at or below this.
    pub target_error: Option<f64>,
    /// The metric `target_error` refers to.
    pub target_metric: TargetMetric,
    /// Stop after about this many seconds of tracing.
    pub max_time_s: Option<f64>,
    /// Trace only this shard of the photon indices `0..photons`.
    pub shard: Option<Shard>,
    /// Use the convex-solid fast path where a scene allows it.
    pub convex: bool,
    /// Ends the run early when requested.
    pub interrupt: Interrupt,
}

/// Most shards one run may be split into: far more than any cluster job, few enough that
/// a merge's bookkeeping of them is small (a shard file claiming more is damaged).
pub const MAX_SHARDS: u64 = 1 << 20;

/// Shard `index` of `count`: a contiguous run of whole chunks of the photon indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Shard {
    /// Which shard, from 0.
    pub index: u64,
    /// How many shards in all.
    pub count: u64,
}

impl Shard {
    /// Parse `K/M` (K from 0 to M-1).
    pub fn parse(s: &str) -> Result<Shard> {
        let (k, m) = s
            .split_once('/')
            .with_context(|| format!("'{s}': expected K/M, e.g. 0/4"))?;
        let (index, count): (u64, u64) = (
            k.trim()
                .parse()
                .with_context(|| format!("'{s}': K is not a number"))?,
            m.trim()
                .parse()
                .with_context(|| format!("'{s}': M is not a number"))?,
        );
        if count == 0 || index >= count || count > MAX_SHARDS {
            bail!("'{s}': need 0 <= K < M <= {MAX_SHARDS}");
        }
        Ok(Shard { index, count })
    }

    /// The photon indices this shard traces out of `0..photons` (in u128, so no count
    /// up to `u64::MAX` overflows).
    pub fn range(&self, photons: u64) -> (u64, u64) {
        let chunks = u128::from(photons.div_ceil(CHUNK));
        let (k, m) = (u128::from(self.index), u128::from(self.count));
        let at = |chunk: u128| (chunk * u128::from(CHUNK)).min(u128::from(photons)) as u64;
        (at(chunks * k / m), at(chunks * (k + 1) / m))
    }
}

impl RunOptions {
    /// The photon indices this run traces.
    pub fn photon_range(&self) -> (u64, u64) {
        self.shard
            .map_or((0, self.photons), |s| s.range(self.photons))
    }
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            photons: 400_000,
            seed: 1,
            threads: None,
            backend: BackendChoice::Auto,
            estimator: Estimator::Analog,
            luminance_estimator: LuminanceEstimator::Meter,
            target_error: None,
            target_metric: TargetMetric::Mean,
            max_time_s: None,
            shard: None,
            convex: true,
            interrupt: Interrupt::default(),
        }
    }
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StoppedBy {
    /// The photon budget was spent.
    Photons,
    /// The target error was reached.
    TargetError,
    /// The time budget was spent (checked after every chunk).
    Time,
    /// Interrupted ([`Interrupt::request`], Ctrl-C): the outputs hold what was traced.
    Interrupted,
    /// The target error cannot be reached: the target metric's error was still 0/0
    /// (nothing detected) after [`UNREACHABLE_AFTER`] photons.
    Unreachable,
}

/// Photons after which a target metric whose relative error is still 0/0 (no photon
/// detected, so neither the metric nor its error is defined) stops a `--target-error` run
/// as [`StoppedBy::Unreachable`] instead of tracing on to the photon cap: about 1e6, where
/// a detector that catches one photon in 3e5 has caught one with 95 % probability.
pub const UNREACHABLE_AFTER: u64 = 1 << 20;

/// A request to end a run early, shared between the run and whoever may ask (a signal
/// handler, a GUI's stop button): the run stops after the chunk it is absorbing and its
/// result holds every photon traced so far.
#[derive(Clone, Debug, Default)]
pub struct Interrupt(Arc<AtomicBool>);

impl Interrupt {
    /// Ask the runs holding this interrupt to stop.
    pub fn request(&self) {
        self.0.store(true, Ordering::Release);
    }

    /// Whether a stop was asked for.
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Acquire)
    }
}

/// The error of a search whose trace was interrupted ([`Interrupt::request`]) before its
/// design was fully traced: a partly traced design has fewer photons than the others and
/// is not compared with them, so callers stop and keep what was finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Interrupted {}

/// Whether `e` is (or wraps) an [`Interrupted`].
pub fn is_interrupted(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<Interrupted>())
}

/// One row of the convergence history, taken after a round.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergenceRow {
    /// Photons traced so far.
    pub photons: u64,
    /// Tracing seconds so far.
    pub seconds: f64,
    /// Metric values.
    pub values: MetricValues,
    /// Their standard errors.
    pub stderr: MetricValues,
}

/// A finished trace: it owns what it reports, so it can be kept, moved to another
/// thread or handed to a caller that outlives the scene's other holders.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// The scene traced.
    pub scene: Arc<Scene>,
    /// Backend that traced it.
    pub backend: &'static str,
    /// Options used.
    pub options: RunOptions,
    /// Worker threads used.
    pub threads: usize,
    /// Everything scored.
    pub tally: Tally,
    /// Per-group tallies (chunk `c` in group `c mod GROUPS`), for jackknife errors.
    pub groups: Vec<Tally>,
    /// Wall time of the tracing (s), excluding scene loading and BVH build.
    pub runtime_s: f64,
    /// Why it stopped.
    pub stopped_by: StoppedBy,
    /// Metrics and errors after each round.
    pub history: Vec<ConvergenceRow>,
    /// Every metric with each group holding photons left out in turn, after the last
    /// round (for jackknife errors of any function of the metrics).
    pub leave_out: Vec<MetricValues>,
}

/// Most memory (bytes) a run's tallies may take: the run's own flux and angular grids and
/// one copy per jackknife group. Bins beyond it are refused before anything is traced.
pub const TALLY_BUDGET_BYTES: u64 = 4 << 30;

/// Bytes the tallies of a run of `scene` take (see [`TALLY_BUDGET_BYTES`]).
pub fn tally_bytes(scene: &Scene) -> u64 {
    let d = &scene.detector;
    let bins = (d.bins[0] * d.bins[1] + d.angular_bins[0] * d.angular_bins[1]) as u64;
    // Spectral scenes tally X, Y, Z beside the radiant weight; with lumens or spectra
    // the luminance cone's grid holds one more set of flux bins.
    let grids = if scene.sources.spectral() { 4 } else { 1 };
    let luminous = scene.sources.spectral() || scene.sources.luminous_efficacy().is_some();
    let cone = if luminous {
        (d.bins[0] * d.bins[1]) as u64
    } else {
        0
    };
    (bins * grids + cone)
        * std::mem::size_of::<crate::tally::BinStats>() as u64
        * (GROUPS as u64 + 1)
}

/// [`tally_bytes`], or an error when over the budget.
pub fn check_tally_budget(scene: &Scene) -> Result<u64> {
    let bytes = tally_bytes(scene);
    if bytes > TALLY_BUDGET_BYTES {
        bail!(
            "{}: detector.bins and detector.angular_bins need {:.1} GiB of tallies ({} copies \
             of every bin, for the jackknife groups); at most {} GiB: use fewer bins",
            scene.path.display(),
            bytes as f64 / (1u64 << 30) as f64,
            GROUPS + 1,
            TALLY_BUDGET_BYTES >> 30
        );
    }
    Ok(bytes)
}

/// Most worker threads a run accepts: far more than any node has cores (results do not
/// depend on the count), few enough that starting them cannot exhaust the machine.
pub const MAX_THREADS: usize = 1024;

/// What a run tells its observer while it traces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Progress {
    /// A chunk of this many photons was added to the tallies.
    Chunk(u64),
    /// A round ended: its convergence row was recorded.
    Round {
        /// Photons traced so far.
        photons: u64,
        /// The `--target-error` metric's relative standard error now (NaN without a
        /// target, or while it is undefined).
        rel_error: f64,
    },
}

/// Trace `scene` (a [`Scene`], `&Scene` or `Arc<Scene>`: see [`SharedScene`]) as
/// `options` say. `progress` hears of every chunk and round.
pub fn trace(
    scene: impl SharedScene,
    options: &RunOptions,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RunResult> {
    trace_reusing(scene, options, &mut MeshBuildCache::default(), progress)
}

/// [`trace`], reusing `builds`' backend and triangle records when the last run's mesh was
/// this scene's (and leaving this run's there for the next).
pub fn trace_reusing(
    scene: impl SharedScene,
    options: &RunOptions,
    builds: &mut MeshBuildCache,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<RunResult> {
    let shared = scene.shared();
    let scene = shared.as_ref();
    if let Some(e) = options.target_error
        && !(e > 0.0 && e.is_finite())
    {
        bail!("option `target_error` must be a positive number, got {e}");
    }
    if let Some(t) = options.max_time_s
        && !(t > 0.0 && t.is_finite())
    {
        bail!("option `max_time` must be a finite number of seconds > 0, got {t}");
    }
    if options.photons == 0 {
        bail!("option `photons` must be at least 1: a run of no photons has nothing to report");
    }
    if let Some(n) = options.threads
        && !(1..=MAX_THREADS).contains(&n)
    {
        bail!("option `threads` must be within 1..={MAX_THREADS}, got {n}");
    }
    check_tally_budget(scene)?;
    let [nx, ny] = scene.detector.bins;
    let (one_bin, spots) = (
        nx * ny == 1,
        metrics::spots_apart(nx) && metrics::spots_apart(ny),
    );
    let undefined = match options.target_metric {
        TargetMetric::Cv => one_bin,
        TargetMetric::NinePoint | TargetMetric::ThirteenPoint => one_bin || !spots,
        _ => false,
    };
    if options.target_error.is_some() && undefined {
        let m = options.target_metric.metric().name();
        bail!(
            "{}: detector.bins is [{nx}, {ny}]: a map this coarse has no {m} (a one-bin map has \
             no spread, the 9- and 13-point spots of a side of 2 bins all cover both), so \
             option `target_metric` {m} can never reach a relative error",
            scene.path.display()
        );
    }
    if options.shard.is_some() && (options.target_error.is_some() || options.max_time_s.is_some()) {
        bail!(
            "a shard traces a fixed photon range: option `target_error` and option `max_time` do not apply"
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.unwrap_or(0))
        .build()
        .context("cannot start worker threads")?;
    let built = builds.get(&scene.mesh, options.backend, || {
        pool.install(|| accel::build(options.backend, scene.mesh.clone()))
    })?;
    let accel = built.accel.as_ref();
    let tracer = Tracer::new(
        scene,
        accel,
        options.estimator,
        options.convex,
        &built.facets,
    )
    .luminance_estimator(options.luminance_estimator);
    let mut state = Rounds::new(scene, options.photon_range());
    let start = Instant::now();
    let stopped_by = state.run(&pool, &tracer, scene, options, start, progress);
    Ok(RunResult {
        scene: shared.clone(),
        backend: accel.name(),
        options: options.clone(),
        threads: pool.current_num_threads(),
        tally: state.total,
        groups: state.groups,
        runtime_s: start.elapsed().as_secs_f64(),
        stopped_by,
        history: state.history,
        leave_out: state.leave_out,
    })
}

/// Relative standard error of a metric (the per-bin metric is already relative).
fn relative_error(m: Metric, value: f64, stderr: f64) -> f64 {
    match m {
        Metric::MeanRelStderr => value,
        _ if value != 0.0 && value.is_finite() => stderr / value.abs(),
        _ => f64::INFINITY,
    }
}

/// Every file `blutrace trace` and `merge` write.
pub const OUTPUT_NAMES: &[&str] = &[
    "flux.exr",
    "angular.exr",
    "flux.png",
    "conoscope.png",
    "convergence.csv",
    "convergence.png",
    "summary.json",
];

impl RunResult {
    /// Target-plane irradiance (W/mm^2) per bin.
    pub fn flux_map(&self) -> Map {
        metrics::flux_map(&self.scene, &self.tally)
    }

    /// Radiant intensity (W/sr) per (theta, phi) bin; x = phi, y = theta.
    pub fn angular_map(&self) -> Map {
        metrics::angular_map(&self.scene, &self.tally)
    }

    /// Power carried by one photon of unit weight (W).
    pub fn watts_per_photon(&self) -> f64 {
        self.scene.sources.total_power() / self.tally.ledger.photons.max(1) as f64
    }

    /// The last convergence row (metrics and errors of the whole run).
    pub fn final_row(&self) -> Option<&ConvergenceRow> {
        self.history.last()
    }

    /// Write every output into `dir` as one set ([`OutputSet`]): the folder holds the
    /// previous set until the new one is complete; returns the files written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let set = OutputSet::new(dir, OUTPUT_NAMES, &self.scene.inputs)?;
        self.write_into(&set)?;
        set.commit()
    }

    /// Write every output into `staged`, a folder of an output set.
    pub fn write_into(&self, staged: &SetDir) -> Result<()> {
        let flux = self.flux_map();
        images::write_flux_exr(self, staged, &flux)?;
        images::write_angular_exr(self, staged)?;
        color_images::write_color_images(self, staged)?;
        images::write_luminance_map(self, staged)?;
        images::write_stokes_exr(self, staged)?;
        staged.write_with("flux.png", |png| images::write_flux_png(self, png, &flux))?;
        staged.write_with("conoscope.png", |png| {
            images::write_conoscope_png(self, png)
        })?;
        staged.write_bytes(
            "convergence.csv",
            summary::convergence_csv(&self.history).as_bytes(),
        )?;
        staged.write_with("convergence.png", |chart| {
            summary::write_convergence_png(chart, &self.scene.name, &self.history)
        })?;
        let json = serde_json::to_vec_pretty(&self.summary())?;
        staged.write_bytes("summary.json", &json)?;
        Ok(())
    }
}
