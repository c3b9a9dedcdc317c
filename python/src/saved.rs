//! Runs kept outside the process: pickled (a whole run as its tallies and the rest of
//! its state, bit for bit) and read back from output folders (`Run.load`).

use crate::BlutraceError;
use crate::convert::{choice, py_to_json, run_error};
use crate::detached::detached;
use crate::maps::{Frame, Maps};
use crate::options::{ESTIMATORS, TARGET_METRICS};
use crate::scene_value::{Scene, load_scene};
use blutrace::run::metrics::{Metric, MetricValues};
use blutrace::run::{ConvergenceRow, RunOptions, RunResult, StoppedBy};
use blutrace::shard::{self, SHARD_FILE, ShardFile};
use blutrace::tally::Tally;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::path::{Path, PathBuf};

/// Every way a run stops, for reading one back by its name.
const STOPS: [StoppedBy; 5] = [
    StoppedBy::Photons,
    StoppedBy::TargetError,
    StoppedBy::Time,
    StoppedBy::Interrupted,
    StoppedBy::Unreachable,
];

/// Backend names a run reports.
const BACKEND_NAMES: [&str; 5] = ["embree", "bvh", "brute", "convex", "mixed"];

/// The state of a whole run beside its scene and tallies, as Python values (so floats,
/// NaN included, pickle exactly): backend, photons, seed, estimator, target_error,
/// target_metric, max_time, threads, runtime_s, stopped_by, history rows (photons,
/// seconds, values, stderr) and the leave-one-out metrics.
type State = (
    String,
    u64,
    u64,
    String,
    Option<f64>,
    String,
    Option<f64>,
    usize,
    f64,
    String,
    Vec<(u64, f64, Vec<f64>, Vec<f64>)>,
    Vec<Vec<f64>>,
);

fn name_of<T: PartialEq + Copy>(table: &[(&'static str, T)], v: T) -> String {
    table
        .iter()
        .find(|(_, x)| *x == v)
        .map_or("?", |(n, _)| n)
        .to_string()
}

fn stop_name(s: StoppedBy) -> String {
    serde_json::to_value(s)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

fn metric_list(v: &MetricValues) -> Vec<f64> {
    v.iter().map(|(_, x)| x).collect()
}

fn metric_values(v: &[f64]) -> PyResult<MetricValues> {
    if v.len() != Metric::ALL.len() {
        return Err(PyValueError::new_err(
            "not a pickled blutrace run: metric list",
        ));
    }
    Ok(MetricValues::from_fn(|m| v[m as usize]))
}

/// `__reduce__` of a whole (not shard) run: `restore(scene, tallies, state)`, `restore`
/// being `Run._from_state`.
pub fn reduce_whole<'py>(
    py: Python<'py>,
    run: &RunResult,
    restore: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyTuple>> {
    let tallies = serde_json::to_string(&(&run.tally, &run.groups))
        .map_err(|e| BlutraceError::new_err(e.to_string()))?;
    let o = &run.options;
    let state: State = (
        run.backend.to_string(),
        o.photons,
        o.seed,
        name_of(ESTIMATORS, o.estimator),
        o.target_error,
        name_of(TARGET_METRICS, o.target_metric),
        o.max_time_s,
        run.threads,
        run.runtime_s,
        stop_name(run.stopped_by),
        run.history
            .iter()
            .map(|r| {
                (
                    r.photons,
                    r.seconds,
                    metric_list(&r.values),
                    metric_list(&r.stderr),
                )
            })
            .collect(),
        run.leave_out.iter().map(metric_list).collect(),
    );
    let scene = Scene {
        inner: run.scene.clone(),
    };
    let args = (scene, tallies, state).into_pyobject(py)?.into_any();
    PyTuple::new(py, [restore, args])
}

/// The inverse of [`reduce_whole`].
pub fn whole_run(scene: &Scene, tallies: &str, state: &Bound<'_, PyAny>) -> PyResult<RunResult> {
    let bad = |what: &str| PyValueError::new_err(format!("not a pickled blutrace run: {what}"));
    let (tally, groups): (Tally, Vec<Tally>) =
        serde_json::from_str(tallies).map_err(|e| bad(&e.to_string()))?;
    let s: State = state.extract().map_err(|_| bad("state"))?;
    let options = RunOptions {
        photons: s.1,
        seed: s.2,
        estimator: choice("estimator", &s.3, ESTIMATORS)?,
        target_error: s.4,
        target_metric: choice("target_metric", &s.5, TARGET_METRICS)?,
        max_time_s: s.6,
        ..RunOptions::default()
    };
    let history =
        s.10.iter()
            .map(|(photons, seconds, v, e)| {
                Ok(ConvergenceRow {
                    photons: *photons,
                    seconds: *seconds,
                    values: metric_values(v)?,
                    stderr: metric_values(e)?,
                })
            })
            .collect::<PyResult<_>>()?;
    let result = RunResult {
        scene: scene.inner.clone(),
        backend: BACKEND_NAMES
            .into_iter()
            .find(|b| *b == s.0)
            .ok_or_else(|| bad("backend"))?,
        options,
        threads: s.7,
        tally,
        groups,
        runtime_s: s.8,
        stopped_by: STOPS
            .into_iter()
            .find(|x| stop_name(*x) == s.9)
            .ok_or_else(|| bad("stopped_by"))?,
        history,
        leave_out: s
            .11
            .iter()
            .map(|v| metric_values(v))
            .collect::<PyResult<_>>()?,
    };
    Ok(result)
}

/// The shard run of `file` (from `path`), checked against `scene`.
pub fn shard_run(
    py: Python<'_>,
    scene: &Scene,
    path: PathBuf,
    file: ShardFile,
) -> PyResult<RunResult> {
    let shards = vec![(path, file)];
    let scene = scene.inner.clone();
    detached(py, || {
        shard::check(&shards, &scene)?;
        let mut run = shard::merge(&shards, scene.clone())?;
        let f = &shards[0].1;
        run.options.shard = Some(f.shard);
        run.threads = f.threads;
        Ok(run)
    })?
    .map_err(run_error)
}

/// What an output folder holds.
pub enum Saved {
    /// A shard run (`shard.json`).
    Shard(Box<RunResult>),
    /// The outputs of a run: its maps, summary and history as the files hold them.
    Outputs {
        maps: Box<Maps>,
        summary: serde_json::Value,
        history: serde_json::Value,
    },
}

/// `Run.load(dir)`: the shard run of `dir/shard.json`, or the run of an output folder.
pub fn load(py: Python<'_>, dir: &Path) -> PyResult<Saved> {
    let failed = |e: anyhow::Error| BlutraceError::new_err(format!("{e:#}"));
    if dir.join(SHARD_FILE).is_file() {
        let path = dir.join(SHARD_FILE);
        let file = detached(py, || shard::read_shard(&path))?.map_err(run_error)?;
        let scene = load_scene(py, &file.scene_file)?;
        return shard_run(py, &scene, path, file).map(|r| Saved::Shard(Box::new(r)));
    }
    let path = dir.join("summary.json");
    if !path.is_file() {
        return Err(BlutraceError::new_err(format!(
            "{}: no summary.json or {SHARD_FILE}: not a blutrace output folder",
            dir.display()
        )));
    }
    let text = blutrace::input_file::read_text(&path, "summary file").map_err(failed)?;
    // Python's parser: every float of the file as the CLI wrote it, bit for bit.
    let parsed = py
        .import("json")?
        .call_method1("loads", (text,))
        .map_err(|e| {
            BlutraceError::new_err(format!("{}: not a summary file: {e}", path.display()))
        })?;
    let summary = py_to_json(&parsed)?;
    let frame = frame(&path, &summary).map_err(failed)?;
    let folder = dir.to_path_buf();
    let (maps, history) = detached(py, move || {
        Ok((
            Maps::read(&folder, frame)?,
            read_history(&folder.join("convergence.csv"))?,
        ))
    })?
    .map_err(failed)?;
    Ok(Saved::Outputs {
        maps: Box::new(maps),
        summary,
        history,
    })
}

/// The bins' places from a summary's `detector` (read from `path`).
fn frame(path: &Path, summary: &serde_json::Value) -> anyhow::Result<Frame> {
    let d = &summary["detector"];
    let pair = |key: &str| -> anyhow::Result<[f64; 2]> {
        let v: Vec<f64> = serde_json::from_value(d[key].clone())
            .map_err(|e| anyhow::anyhow!("{}: detector.{key}: {e}", path.display()))?;
        v.try_into()
            .map_err(|_| anyhow::anyhow!("{}: detector.{key}: not two numbers", path.display()))
    };
    let [nx, ny] = pair("bins")?;
    let [nt, np] = pair("angular_bins")?;
    Ok(Frame {
        bins: [nx as usize, ny as usize],
        size_mm: pair("size_mm")?,
        angular_bins: [nt as usize, np as usize],
    })
}

/// `convergence.csv` as the rows `Run.history` gives (empty without the file).
fn read_history(path: &Path) -> anyhow::Result<serde_json::Value> {
    if !path.is_file() {
        return Ok(serde_json::Value::Array(Vec::new()));
    }
    let text = blutrace::input_file::read_text(path, "convergence file")?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let cells: Vec<f64> = line
            .split(',')
            .map(|c| c.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow::anyhow!("{}: line {}: {e}", path.display(), i + 1))?;
        if cells.len() != 2 + 2 * Metric::ALL.len() {
            anyhow::bail!(
                "{}: line {}: {} columns",
                path.display(),
                i + 1,
                cells.len()
            );
        }
        let every = |k: usize| -> Vec<f64> { cells[2 + k..].iter().step_by(2).copied().collect() };
        rows.push(serde_json::json!({
            "photons": cells[0] as u64,
            "seconds": cells[1],
            "values": every(0),
            "stderr": every(1),
        }));
    }
    Ok(serde_json::Value::Array(rows))
}
