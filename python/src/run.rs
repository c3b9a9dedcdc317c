//! `blutrace.Run`: a finished trace with its maps as numpy arrays, its summary and its
//! output files; shard runs pickle (so any executor can carry them) and `merge` into one.

use crate::BlutraceError;
use crate::convert::{grid, run_error, serialized};
use crate::detached::detached;
use crate::scene::Scene;
use blutrace::run::RunResult;
use blutrace::run::metrics::Map;
use blutrace::shard::{self, ShardFile};
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;
use std::sync::Arc;

/// A finished trace, or the merge of shard runs.
///
/// ``flux``, ``flux_stderr`` (float64, W/mm^2) and ``hits`` (uint64) have shape ``(ny, nx)``,
/// row ``iy`` along the detector's ``v`` from its origin; ``angular``, ``angular_stderr``
/// (float64, W/sr) and ``angular_hits`` have shape ``(n_theta, n_phi)``. ``summary`` is the
/// content of ``summary.json``; ``efficiency`` is ``(value, stderr)``; ``history`` the
/// convergence rows. ``write(dir)`` writes the command line's output set, all or nothing.
/// A shard run (``trace(..., shard=(k, m))``) pickles, so any executor can return it, and
/// ``merge`` joins the shards.
#[pyclass(module = "blutrace", name = "Run", frozen)]
pub struct Run {
    inner: Arc<RunResult>,
    flux: Map,
    angular: Map,
}

impl Run {
    /// Wrap a result, computing its maps once.
    pub fn new(result: RunResult) -> Run {
        Run {
            flux: result.flux_map(),
            angular: result.angular_map(),
            inner: Arc::new(result),
        }
    }
}

#[pymethods]
impl Run {
    /// Irradiance on the target plane (W/mm^2 per bin), float64 `(ny, nx)`; row `iy` is
    /// the `iy`-th bin along the detector's `v` from its origin, column `ix` along `u`.
    #[getter]
    fn flux<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid(py, &self.flux, &self.flux.value)
    }

    /// Standard error of `flux` per bin (W/mm^2).
    #[getter]
    fn flux_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid(py, &self.flux, &self.flux.stderr)
    }

    /// Photons scored per flux bin, uint64 `(ny, nx)`.
    #[getter]
    fn hits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid(py, &self.flux, &self.flux.hits)
    }

    /// Radiant intensity (W/sr per bin), float64 `(n_theta, n_phi)`.
    #[getter]
    fn angular<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid(py, &self.angular, &self.angular.value)
    }

    /// Standard error of `angular` per bin (W/sr).
    #[getter]
    fn angular_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid(py, &self.angular, &self.angular.stderr)
    }

    /// Photons scored per angular bin, uint64 `(n_theta, n_phi)`.
    #[getter]
    fn angular_hits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        grid(py, &self.angular, &self.angular.hits)
    }

    /// The run's summary: the content of `summary.json`.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialized(py, &self.inner.summary())
    }

    /// Extraction efficiency (detected over emitted power) and its standard error.
    #[getter]
    fn efficiency(&self) -> (f64, f64) {
        let s = self.inner.summary();
        (s.extraction_efficiency, s.extraction_efficiency_stderr)
    }

    /// The convergence history: one dict per round (photons, seconds, values, stderr).
    #[getter]
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialized(py, &self.inner.history)
    }

    /// Photons traced.
    #[getter]
    fn photons(&self) -> u64 {
        self.inner.tally.ledger.photons
    }

    /// Seed of the run.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.options.seed
    }

    /// `(k, m)` for shard k of m, else None.
    #[getter]
    fn shard(&self) -> Option<(u64, u64)> {
        self.inner.options.shard.map(|s| (s.index, s.count))
    }

    /// Why the run stopped: photons, target_error, time, unreachable.
    #[getter]
    fn stopped_by<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        serialized(py, &self.inner.stopped_by)
    }

    /// Seconds of tracing (for a merge: the shards' sum).
    #[getter]
    fn runtime_s(&self) -> f64 {
        self.inner.runtime_s
    }

    /// The scene traced.
    #[getter]
    fn scene(&self) -> Scene {
        Scene {
            inner: self.inner.scene.clone(),
        }
    }

    /// Write the command line's output set (`flux.exr`, `angular.exr`, `flux.png`,
    /// `conoscope.png`, `convergence.csv`, `convergence.png`, `summary.json`, and the
    /// colour images of a spectral scene) into `dir`, all or nothing;
    /// returns the files written.
    fn write(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = crate::convert::dir_arg)] dir: PathBuf,
    ) -> PyResult<Vec<String>> {
        let run = self.inner.clone();
        let files = detached(py, || run.write(&dir))?.map_err(run_error)?;
        Ok(files.iter().map(|f| f.display().to_string()).collect())
    }

    /// A shard run pickles as its scene and raw tallies (what `shard.json` holds).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let file = ShardFile::of(&self.inner).map_err(|_| {
            PyTypeError::new_err(
                "only shard runs (trace(..., shard=(k, m))) pickle; write() a whole run instead",
            )
        })?;
        let json =
            serde_json::to_string(&file).map_err(|e| BlutraceError::new_err(e.to_string()))?;
        let restore = py.get_type::<Run>().getattr("_from_shard")?;
        let args = (self.scene(), json).into_pyobject(py)?.into_any();
        PyTuple::new(py, [restore, args])
    }

    /// A shard run from its scene and its shard file's JSON (the inverse of pickling).
    #[staticmethod]
    fn _from_shard(py: Python<'_>, scene: &Scene, json: &str) -> PyResult<Run> {
        let file: ShardFile = serde_json::from_str(json)
            .map_err(|e| PyValueError::new_err(format!("not a blutrace shard: {e}")))?;
        let shards = vec![(PathBuf::from("the pickled shard"), file)];
        let scene = scene.inner.clone();
        let run = detached(py, || {
            shard::check(&shards, &scene)?;
            let mut run = shard::merge(&shards, scene.clone())?;
            let f = &shards[0].1;
            run.options.shard = Some(f.shard);
            run.threads = f.threads;
            Ok(run)
        })?
        .map_err(run_error)?;
        Ok(Run::new(run))
    }

    fn __repr__(&self) -> String {
        let shard = match self.inner.options.shard {
            Some(s) => format!(", shard=({}, {})", s.index, s.count),
            None => String::new(),
        };
        format!(
            "Run(scene={:?}, photons={}, seed={}{shard})",
            self.inner.scene.name, self.inner.tally.ledger.photons, self.inner.options.seed
        )
    }
}

/// Merge shard runs (`trace(..., shard=(k, m))`, from any process) into the run of all
/// their photons: bit for bit the maps of one run. Missing shards are a `ValueError`
/// unless `partial`.
#[pyfunction]
#[pyo3(signature = (runs, partial=false))]
pub fn merge(
    py: Python<'_>,
    #[pyo3(from_py_with = runs_arg)] runs: Vec<Bound<'_, Run>>,
    #[pyo3(from_py_with = partial_arg)] partial: bool,
) -> PyResult<Run> {
    let Some(first) = runs.first() else {
        return Err(PyValueError::new_err("merge needs at least one shard run"));
    };
    let scene = first.get().inner.scene.clone();
    let mut shards = Vec::with_capacity(runs.len());
    for (i, r) in runs.iter().enumerate() {
        let file = ShardFile::of(&r.get().inner).map_err(|_| {
            PyValueError::new_err(format!(
                "runs[{i}] is not a shard run: trace with shard=(k, m) to merge"
            ))
        })?;
        shards.push((PathBuf::from(format!("runs[{i}]")), file));
    }
    let missing =
        shard::check(&shards, &scene).map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    if !missing.is_empty() && !partial {
        let m = shards[0].1.shard.count;
        let list: Vec<String> = missing.iter().map(|k| format!("{k}/{m}")).collect();
        return Err(PyValueError::new_err(format!(
            "shards missing: {} (merge them too, or pass partial=True)",
            list.join(", ")
        )));
    }
    let merged = detached(py, || shard::merge(&shards, scene.clone()))?.map_err(run_error)?;
    Ok(Run::new(merged))
}

/// Argument `runs` of `merge`: a sequence of `Run`s.
fn runs_arg<'py>(v: &Bound<'py, PyAny>) -> PyResult<Vec<Bound<'py, Run>>> {
    crate::convert::arg(v, "runs")
}

/// Argument `partial` of `merge`: a bool.
fn partial_arg(v: &Bound<'_, PyAny>) -> PyResult<bool> {
    crate::convert::arg(v, "partial")
}

/// The channels of an OpenEXR image written by blutrace (`flux.exr`, `angular.exr`), as
/// float32 arrays `(ny, nx)` by channel name (`Y`, `stderr.Y`, `hits.Y`, ...), rows as
/// in `Run.flux` (row 0 at the detector's origin).
#[pyfunction]
pub fn read_exr<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = crate::convert::path_arg)] path: PathBuf,
) -> PyResult<Bound<'py, PyDict>> {
    let (width, height, channels, _attributes) =
        detached(py, || blutrace::output::exr::read_channels(&path))?
            .map_err(|e| BlutraceError::new_err(format!("{e:#}")))?;
    let out = PyDict::new(py);
    for (name, samples) in channels {
        let a = Array2::from_shape_vec((height, width), samples)
            .map_err(|e| BlutraceError::new_err(e.to_string()))?;
        out.set_item(name, a.into_pyarray(py))?;
    }
    Ok(out)
}
