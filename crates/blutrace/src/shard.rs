//! Sharded runs with exact merging: one run of N photons split over processes or nodes.
//!
//! ```text
//! blutrace trace SCENE --photons N --shard K/M --out DIR_K   # writes DIR_K/shard.json
//! blutrace merge DIR_0 ... DIR_{M-1} --out DIR [--partial]    # writes the usual outputs
//! ```
//!
//! Shard K of M traces exactly the photon indices a single run of N photons would give it
//! (whole chunks, the same per-photon random streams). Tallies are exact integer sums,
//! and chunk `c` always scores into jackknife group `c mod 32`, so merging all M shards
//! gives tallies bit-identical to the single run. Shards must agree on the scene (content
//! hash), seed, photon count, shard count and estimator; missing shards are an error unless
//! `--partial` is given, which merges what is there and says what is missing.

use crate::estimator::LuminanceEstimator;
use crate::optics::surface::Estimator;
use crate::output::atomic::OutputSet;
use crate::run::metrics::ScoredBins;
use crate::run::{ConvergenceRow, MAX_SHARDS, RunOptions, RunResult, Shard, StoppedBy, metrics};
use crate::scene::{Scene, SharedScene};
use crate::tally::Tally;
use crate::tracer::CHUNK;
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// File name of a shard's raw tallies inside its output folder.
pub const SHARD_FILE: &str = "shard.json";
const FORMAT: &str = "blutrace-shard";
/// 2: the ledger books lamp bodies (`absorbed_by_source`) and counts hits per tag
/// (`hits_by_tag`, `feature_hits_by_tag`); 3: and the detections per source
/// (`detected_by_source`).
const FORMAT_VERSION: u32 = 3;

/// A shard's raw tallies and what identifies the run it belongs to.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShardFile {
    /// Always "blutrace-shard".
    pub format: String,
    /// Format version.
    pub version: u32,
    /// Scene name.
    pub scene: String,
    /// Scene file, absolute (shards written before 0.1 hold the path given to `trace`).
    pub scene_file: PathBuf,
    /// [`Scene::content_hash`], hex.
    pub scene_hash: String,
    /// Seed of the run.
    pub seed: u64,
    /// Photons of the whole run.
    pub photons: u64,
    /// This shard.
    pub shard: Shard,
    /// Photon indices traced: `[first, last)`.
    pub range: [u64; 2],
    /// Estimator used.
    pub estimator: Estimator,
    /// How the luminance maps were estimated (absent in older shards: the cone).
    #[serde(default = "cone")]
    pub luminance_estimator: LuminanceEstimator,
    /// Backend used.
    pub backend: String,
    /// Tracing seconds.
    pub runtime_s: f64,
    /// Worker threads the shard used.
    pub threads: usize,
    /// Per-group tallies (their sum is the shard's tally).
    pub groups: Vec<Tally>,
}

impl ShardFile {
    /// The shard file of `result`, a shard run (`RunOptions::shard` set), held in memory:
    /// what [`write_shard`] writes, and what a caller that keeps shards as values (the
    /// Python package) hands to [`check`] and [`merge`].
    pub fn of(result: &RunResult) -> Result<ShardFile> {
        let o = &result.options;
        let shard = o.shard.context("not a shard run")?;
        let (first, last) = o.photon_range();
        Ok(ShardFile {
            format: FORMAT.into(),
            version: FORMAT_VERSION,
            scene: result.scene.name.clone(),
            // Absolute, so `merge` finds it from any folder.
            scene_file: std::path::absolute(&result.scene.path)
                .unwrap_or_else(|_| result.scene.path.clone()),
            scene_hash: format!("{:016x}", result.scene.content_hash()),
            seed: o.seed,
            photons: o.photons,
            shard,
            range: [first, last],
            estimator: o.estimator,
            luminance_estimator: o.luminance_estimator,
            backend: result.backend.to_string(),
            runtime_s: result.runtime_s,
            threads: result.threads,
            groups: result.groups.clone(),
        })
    }
}

/// Write `result` (a shard run) as `dir/shard.json`, atomically.
pub fn write_shard(result: &RunResult, dir: &Path) -> Result<PathBuf> {
    let file = ShardFile::of(result)?;
    let staged = OutputSet::new(dir, &[SHARD_FILE], &result.scene.inputs)?;
    let path = staged.write_bytes(SHARD_FILE, &serde_json::to_vec(&file)?)?;
    staged.commit()?;
    Ok(path)
}

/// Read a shard file, or `dir/shard.json` when given a folder.
pub fn read_shard(path: &Path) -> Result<ShardFile> {
    let path = if path.is_dir() {
        path.join(SHARD_FILE)
    } else {
        path.to_path_buf()
    };
    let text = crate::input_file::read_text(&path, "shard file")?;
    check_shapes(&path, &text)?;
    let f: ShardFile = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}: not a shard file: {e}", path.display()))?;
    if f.format != FORMAT || f.version != FORMAT_VERSION {
        bail!(
            "{}: format {} version {}, expected {FORMAT} version {FORMAT_VERSION}",
            path.display(),
            f.format,
            f.version
        );
    }
    let sh = f.shard;
    if sh.count == 0 || sh.index >= sh.count || sh.count > MAX_SHARDS {
        bail!(
            "{}: shard: {}/{} is no shard of a run (need 0 <= K < M <= {MAX_SHARDS})",
            path.display(),
            sh.index,
            sh.count
        );
    }
    Ok(f)
}

/// The grid shapes of a shard file's groups, read before the tallies: a run's groups all
/// have its detector's shape, so a file whose groups differ (each of which may claim up
/// to [`crate::tally::MAX_GRID_BINS`] bins) is refused before any grid is allocated.
fn check_shapes(path: &Path, text: &str) -> Result<()> {
    #[derive(Deserialize, PartialEq, Debug)]
    struct Dims {
        nx: usize,
        ny: usize,
    }
    #[derive(Deserialize, PartialEq, Debug)]
    struct Shape {
        flux: Dims,
        angular: Dims,
    }
    #[derive(Deserialize)]
    struct Shapes {
        groups: Vec<Shape>,
    }
    // A file that does not parse says why in the full parse that follows.
    let Ok(s) = serde_json::from_str::<Shapes>(text) else {
        return Ok(());
    };
    if s.groups.len() != metrics::GROUPS {
        bail!(
            "{}: {} groups, expected {}",
            path.display(),
            s.groups.len(),
            metrics::GROUPS
        );
    }
    if let Some(k) = s.groups.iter().position(|g| *g != s.groups[0]) {
        bail!(
            "{}: groups[{k}]: its grids' shape differs from groups[0]'s: a damaged or edited shard file",
            path.display()
        );
    }
    Ok(())
}

/// The error of tallies whose sum leaves the counters' range.
fn overflow(p: &Path, group: usize) -> String {
    format!(
        "{}: groups[{group}]: the tallies add up past what any run holds: a damaged or edited shard file",
        p.display()
    )
}

/// Check that `shards` belong to one run of `scene` and say which shards are missing.
pub fn check(shards: &[(PathBuf, ShardFile)], scene: &Scene) -> Result<Vec<u64>> {
    let (p0, first) = shards.first().context("no shards to merge")?;
    let hash = format!("{:016x}", scene.content_hash());
    let mut seen = vec![None::<&Path>; first.shard.count as usize];
    for (p, s) in shards {
        let same = |what: &str, a: String, b: String| -> Result<()> {
            if a != b {
                bail!(
                    "{}: {what} is {a}, but {} has {b}: shards of different runs",
                    p.display(),
                    p0.display()
                );
            }
            Ok(())
        };
        same("scene hash", s.scene_hash.clone(), first.scene_hash.clone())?;
        same("seed", s.seed.to_string(), first.seed.to_string())?;
        same(
            "photon count",
            s.photons.to_string(),
            first.photons.to_string(),
        )?;
        same(
            "shard count",
            s.shard.count.to_string(),
            first.shard.count.to_string(),
        )?;
        same(
            "estimator",
            format!("{:?}", s.estimator),
            format!("{:?}", first.estimator),
        )?;
        same(
            "luminance estimator",
            s.luminance_estimator.name().into(),
            first.luminance_estimator.name().into(),
        )?;
        if s.scene_hash != hash {
            bail!(
                "{}: traced a scene with hash {}, but {} now hashes to {hash}: the scene changed",
                p.display(),
                s.scene_hash,
                scene.path.display()
            );
        }
        if [s.range[0], s.range[1]] != {
            let r = s.shard.range(s.photons);
            [r.0, r.1]
        } {
            bail!(
                "{}: photon range {:?} is not shard {}/{}'s",
                p.display(),
                s.range,
                s.shard.index,
                s.shard.count
            );
        }
        match seen[s.shard.index as usize].replace(p) {
            Some(other) => bail!(
                "shard {}/{} given twice: {} and {}",
                s.shard.index,
                s.shard.count,
                other.display(),
                p.display()
            ),
            None => continue,
        }
    }
    Ok((0..first.shard.count)
        .filter(|&k| seen[k as usize].is_none())
        .collect())
}

/// Merge checked shards of `scene` into one result, as a single run would have produced.
pub fn merge(shards: &[(PathBuf, ShardFile)], scene: impl SharedScene) -> Result<RunResult> {
    let shared = scene.shared();
    let scene = shared.as_ref();
    let first = &shards.first().context("no shards to merge")?.1;
    let empty = Tally::new(scene);
    let mut groups = vec![empty.clone(); metrics::GROUPS];
    for (p, s) in shards {
        if s.groups.len() != groups.len() {
            bail!(
                "{}: {} groups, expected {}",
                p.display(),
                s.groups.len(),
                groups.len()
            );
        }
        for (k, sg) in s.groups.iter().enumerate() {
            if let Some(why) = sg.inconsistency(&empty, group_photons(s, k)) {
                bail!(
                    "{}: groups[{k}]: {why}: a damaged or edited shard file",
                    p.display()
                );
            }
        }
        for (k, (g, sg)) in groups.iter_mut().zip(&s.groups).enumerate() {
            g.checked_merge(sg).with_context(|| overflow(p, k))?;
        }
    }
    let mut total = Tally::new(scene);
    for (k, g) in groups.iter().enumerate() {
        total
            .checked_merge(g)
            .with_context(|| overflow(Path::new("the shards"), k))?;
    }
    let runtime_s: f64 = shards.iter().map(|(_, s)| s.runtime_s).sum();
    let e = metrics::estimates(scene, &total, &groups, &ScoredBins::of(&groups));
    let row = ConvergenceRow {
        photons: total.ledger.photons,
        seconds: runtime_s,
        values: e.values,
        stderr: e.stderr,
    };
    let backends: Vec<&str> = shards.iter().map(|(_, s)| s.backend.as_str()).collect();
    Ok(RunResult {
        scene: shared.clone(),
        backend: backend_name(&backends),
        options: RunOptions {
            photons: first.photons,
            seed: first.seed,
            estimator: first.estimator,
            luminance_estimator: first.luminance_estimator,
            ..RunOptions::default()
        },
        // The threads of one shard (the most any used): each shard is its own process, so
        // a sum would be no machine's; runtime_s sums the shards' times (CPU-like).
        threads: shards.iter().map(|(_, s)| s.threads).max().unwrap_or(1),
        tally: total,
        groups,
        runtime_s,
        stopped_by: StoppedBy::Photons,
        history: vec![row],
        leave_out: e.leave_out,
    })
}

/// Photons of group `k` in shard `s`: chunk `c` of its range scores into group
/// `c mod GROUPS`; the chunks at the range's ends may be cut short (in closed form, so
/// any range a file claims costs nothing to check).
fn group_photons(s: &ShardFile, k: usize) -> u64 {
    let [first, last] = s.range.map(u128::from);
    let (g, k, chunk) = (metrics::GROUPS as u128, k as u128, u128::from(CHUNK));
    let (c0, c1) = (first / chunk, last.div_ceil(chunk));
    // Chunks c < x with c = k (mod g).
    let below = |x: u128| if x > k { (x - k - 1) / g + 1 } else { 0 };
    let mut n = (below(c1) - below(c0)) * chunk;
    if c1 > c0 && (c1 - 1) % g == k {
        n -= c1 * chunk - last;
    }
    if c1 > c0 && c0 % g == k {
        n -= first - c0 * chunk;
    }
    n as u64
}

fn backend_name(names: &[&str]) -> &'static str {
    let all = |n: &str| names.iter().all(|b| *b == n);
    ["embree", "bvh", "brute", "convex"]
        .into_iter()
        .find(|n| all(n))
        .unwrap_or("mixed")
}

/// The luminance estimator of a shard written before there was a choice.
fn cone() -> LuminanceEstimator {
    LuminanceEstimator::Cone
}
