//! `blutrace.Run`: a finished trace with its maps as numpy arrays and their bin centres,
//! its summary and its output files; runs pickle (so any executor can carry them), shard
//! runs `merge` into one, and `Run.load` reads an output folder back.

use crate::BlutraceError;
use crate::convert::{grid, json_to_py, run_error, to_json};
use crate::detached::detached;
use crate::maps::Maps;
use crate::saved::{self, Saved};
use crate::scene_value::{Scene, load_scene};
use blutrace::run::RunResult;
use blutrace::run::metrics::Map;
use blutrace::shard::{self, ShardFile};
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A finished trace, the merge of shard runs, or a run read back from an output folder.
///
/// Maps are numpy arrays, each with its standard error (``*_stderr``) and photons per
/// bin: ``flux`` (float64, W/mm^2) and ``hits`` (uint64) have shape ``(ny, nx)``, row ``iy``
/// along the detector's ``v`` from its origin, their bin centres ``y_mm`` and ``x_mm``;
/// ``angular`` (W/sr) and ``angular_hits`` have shape ``(n_theta, n_phi)``, their bin
/// centres ``theta_deg`` and ``phi_deg``. With lumens or spectra: ``luminance`` (cd/m^2,
/// ``(ny, nx)``, within the detector's luminance cone: the normal view) and
/// ``angular_luminance`` (``(n_theta, n_phi)``); in spectral scenes ``X``, ``Y``, ``Z``
/// (lux-scaled), ``u_prime``, ``v_prime``; with polarization ``stokes`` (``(4, ny, nx)``:
/// S0..S3, W/mm^2). A map the run does not measure is None. ``summary`` is the content of
/// ``summary.json``; ``efficiency`` is ``(value, stderr)``; ``history`` the convergence
/// rows. ``write(dir)`` writes the command line's output set, all or nothing (a shard run:
/// ``shard.json``, as ``blutrace trace --shard``); ``Run.load(dir)`` reads one back.
/// Runs pickle (so any executor can return them), and ``merge`` joins shard runs.
#[pyclass(module = "blutrace", name = "Run", frozen)]
pub struct Run {
    /// The traced run; `None` for one read from an output folder.
    inner: Option<Arc<RunResult>>,
    maps: Maps,
    summary: serde_json::Value,
    history: serde_json::Value,
    /// The output folder a run was read from.
    folder: Option<PathBuf>,
}

impl Run {
    /// Wrap a result, computing its maps and summary once.
    pub fn new(result: RunResult) -> PyResult<Run> {
        let summary = to_json(&result.summary())?;
        let history = to_json(&result.history)?;
        Ok(Run {
            maps: Maps::of(&result),
            inner: Some(Arc::new(result)),
            summary,
            history,
            folder: None,
        })
    }

    /// A run read from the files of an output folder.
    pub fn loaded(
        folder: PathBuf,
        maps: Maps,
        summary: serde_json::Value,
        history: serde_json::Value,
    ) -> Run {
        Run {
            inner: None,
            maps,
            summary,
            history,
            folder: Some(folder),
        }
    }

    /// The traced run, or a `BlutraceError` saying what a loaded run cannot do.
    pub fn traced(&self, what: &str) -> PyResult<&Arc<RunResult>> {
        self.inner.as_ref().ok_or_else(|| {
            let dir = self.folder.as_deref().unwrap_or(Path::new("?"));
            BlutraceError::new_err(format!(
                "this run was read from {}: {what} needs a traced run (its files are in that folder)",
                dir.display()
            ))
        })
    }

    fn number(&self, key: &str) -> Option<f64> {
        self.summary.get(key).and_then(|v| v.as_f64())
    }
}

/// Value, standard error or hits of a map the run may lack, as numpy (None when absent).
fn part<'py>(py: Python<'py>, m: Option<&Map>, which: Part) -> PyResult<Bound<'py, PyAny>> {
    match m {
        None => Ok(py.None().into_bound(py)),
        Some(m) => match which {
            Part::Value => grid(py, m, &m.value),
            Part::Stderr => grid(py, m, &m.stderr),
            Part::Hits => grid(py, m, &m.hits),
        },
    }
}

/// A part of a map.
#[derive(Clone, Copy)]
enum Part {
    Value,
    Stderr,
    Hits,
}

/// The Stokes maps stacked as `(4, ny, nx)`.
fn stacked<'py>(
    py: Python<'py>,
    maps: Option<&[Map; 4]>,
    which: Part,
) -> PyResult<Bound<'py, PyAny>> {
    let Some(maps) = maps else {
        return Ok(py.None().into_bound(py));
    };
    let layers: Vec<Bound<'py, PyAny>> = maps
        .iter()
        .map(|m| part(py, Some(m), which))
        .collect::<PyResult<_>>()?;
    py.import("numpy")?.call_method1("stack", (layers,))
}

impl Run {
    /// `which` part of every view's luminance map, stacked `(n_views, ny, nx)`.
    fn views_part<'py>(&self, py: Python<'py>, which: Part) -> PyResult<Bound<'py, PyAny>> {
        if self.maps.luminance_views.is_empty() {
            return Ok(py.None().into_bound(py));
        }
        let layers: Vec<Bound<'py, PyAny>> = self
            .maps
            .luminance_views
            .iter()
            .map(|(m, _)| part(py, Some(m), which))
            .collect::<PyResult<_>>()?;
        py.import("numpy")?.call_method1("stack", (layers,))
    }
}

#[pymethods]
impl Run {
    /// Irradiance on the target plane (W/mm^2 per bin), float64 `(ny, nx)`; row `iy` is
    /// the `iy`-th bin along the detector's `v` from its origin, column `ix` along `u`.
    #[getter]
    fn flux<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, Some(&self.maps.flux), Part::Value)
    }

    /// Standard error of `flux` per bin (W/mm^2).
    #[getter]
    fn flux_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, Some(&self.maps.flux), Part::Stderr)
    }

    /// Photons scored per flux bin, uint64 `(ny, nx)`.
    #[getter]
    fn hits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, Some(&self.maps.flux), Part::Hits)
    }

    /// Radiant intensity (W/sr per bin), float64 `(n_theta, n_phi)`.
    #[getter]
    fn angular<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, Some(&self.maps.angular), Part::Value)
    }

    /// Standard error of `angular` per bin (W/sr).
    #[getter]
    fn angular_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, Some(&self.maps.angular), Part::Stderr)
    }

    /// Photons scored per angular bin, uint64 `(n_theta, n_phi)`.
    #[getter]
    fn angular_hits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, Some(&self.maps.angular), Part::Hits)
    }

    /// Centres of the flux map's columns (mm along the detector's `u` from its origin).
    #[getter]
    fn x_mm<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.maps.frame.centres_mm(0).into_pyarray(py).into_any()
    }

    /// Centres of the flux map's rows (mm along the detector's `v` from its origin).
    #[getter]
    fn y_mm<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.maps.frame.centres_mm(1).into_pyarray(py).into_any()
    }

    /// Centres of the angular maps' rows (degrees from the detector's normal, 0 to 90).
    #[getter]
    fn theta_deg<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.maps.frame.centres_deg(0).into_pyarray(py).into_any()
    }

    /// Centres of the angular maps' columns (azimuth in degrees from `u` towards `v`).
    #[getter]
    fn phi_deg<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.maps.frame.centres_deg(1).into_pyarray(py).into_any()
    }

    /// Luminance (cd/m^2) of the light leaving each flux bin within the detector's
    /// `luminance_cone_deg` of the normal (`luminance.exr`): the normal view, `(ny, nx)`;
    /// None without lumens or spectra.
    #[getter]
    fn luminance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.luminance.as_ref(), Part::Value)
    }

    /// Standard error of `luminance` per bin (cd/m^2).
    #[getter]
    fn luminance_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.luminance.as_ref(), Part::Stderr)
    }

    /// Photons per flux bin within the luminance cone.
    #[getter]
    fn luminance_hits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.luminance.as_ref(), Part::Hits)
    }

    /// The luminance maps of every view of the detector (`[detector] views`), stacked
    /// `(n_views, ny, nx)` (cd/m^2; the first is `luminance`); None without lumens or
    /// spectra.
    #[getter]
    fn luminance_views<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.views_part(py, Part::Value)
    }

    /// Standard errors of `luminance_views`, `(n_views, ny, nx)`.
    #[getter]
    fn luminance_views_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.views_part(py, Part::Stderr)
    }

    /// The views of `luminance_views`: `[theta_deg, phi_deg]` each (theta from the
    /// detector normal, phi from its u axis towards v).
    #[getter]
    fn views_deg(&self) -> Vec<[f64; 2]> {
        self.maps.luminance_views.iter().map(|(_, v)| *v).collect()
    }

    /// Luminance (cd/m^2, averaged over the target) per angular bin `(n_theta, n_phi)`
    /// (`angular.exr`'s `luminance.Y`); None without lumens or spectra.
    #[getter]
    fn angular_luminance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.angular_luminance.as_ref(), Part::Value)
    }

    /// Standard error of `angular_luminance` per bin (cd/m^2).
    #[getter]
    fn angular_luminance_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.angular_luminance.as_ref(), Part::Stderr)
    }

    /// CIE 1931 X per flux bin (lux-scaled, `color.exr`), spectral scenes; else None.
    #[getter(X)]
    fn x<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.xyz.as_ref().map(|m| &m[0]), Part::Value)
    }

    /// Standard error of `X`.
    #[getter(X_stderr)]
    fn x_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.xyz.as_ref().map(|m| &m[0]), Part::Stderr)
    }

    /// CIE 1931 Y per flux bin: the illuminance (lux), spectral scenes; else None.
    #[getter(Y)]
    fn y<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.xyz.as_ref().map(|m| &m[1]), Part::Value)
    }

    /// Standard error of `Y`.
    #[getter(Y_stderr)]
    fn y_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.xyz.as_ref().map(|m| &m[1]), Part::Stderr)
    }

    /// CIE 1931 Z per flux bin (lux-scaled), spectral scenes; else None.
    #[getter(Z)]
    fn z<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.xyz.as_ref().map(|m| &m[2]), Part::Value)
    }

    /// Standard error of `Z`.
    #[getter(Z_stderr)]
    fn z_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.xyz.as_ref().map(|m| &m[2]), Part::Stderr)
    }

    /// CIE 1976 u' per flux bin (NaN where no light), spectral scenes; else None.
    #[getter]
    fn u_prime<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.uv.as_ref().map(|m| &m[0]), Part::Value)
    }

    /// Standard error of `u_prime` (jackknife over the run's photon groups).
    #[getter]
    fn u_prime_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.uv.as_ref().map(|m| &m[0]), Part::Stderr)
    }

    /// CIE 1976 v' per flux bin (NaN where no light), spectral scenes; else None.
    #[getter]
    fn v_prime<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.uv.as_ref().map(|m| &m[1]), Part::Value)
    }

    /// Standard error of `v_prime`, as `u_prime_stderr`.
    #[getter]
    fn v_prime_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        part(py, self.maps.uv.as_ref().map(|m| &m[1]), Part::Stderr)
    }

    /// The Stokes maps S0..S3 (W/mm^2 per flux bin, `stokes.exr`), `(4, ny, nx)`, in the
    /// detector's frame (S0 is `flux`); None unless polarization is traced.
    #[getter]
    fn stokes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        stacked(py, self.maps.stokes.as_ref(), Part::Value)
    }

    /// Standard errors of `stokes`, `(4, ny, nx)`.
    #[getter]
    fn stokes_stderr<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        stacked(py, self.maps.stokes.as_ref(), Part::Stderr)
    }

    /// The run's summary: the content of `summary.json`.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.summary)
    }

    /// Extraction efficiency (detected over emitted power) and its standard error.
    #[getter]
    fn efficiency(&self) -> (f64, f64) {
        let get = |k| self.number(k).unwrap_or(f64::NAN);
        (
            get("extraction_efficiency"),
            get("extraction_efficiency_stderr"),
        )
    }

    /// The convergence history: one dict per round (photons, seconds, values, stderr).
    #[getter]
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.history)
    }

    /// Photons traced.
    #[getter]
    fn photons(&self) -> u64 {
        match &self.inner {
            Some(r) => r.tally.ledger.photons,
            None => self.summary["photons"].as_u64().unwrap_or(0),
        }
    }

    /// Seed of the run.
    #[getter]
    fn seed(&self) -> u64 {
        self.summary["seed"].as_u64().unwrap_or(0)
    }

    /// `(k, m)` for shard k of m, else None.
    #[getter]
    fn shard(&self) -> Option<(u64, u64)> {
        let s = self.inner.as_ref()?.options.shard?;
        Some((s.index, s.count))
    }

    /// Why the run stopped: photons, target_error, time, unreachable.
    #[getter]
    fn stopped_by<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.summary["stopped_by"])
    }

    /// Seconds of tracing (for a merge: the shards' sum).
    #[getter]
    fn runtime_s(&self) -> f64 {
        self.number("runtime_s").unwrap_or(f64::NAN)
    }

    /// The output folder a run was read from (`Run.load`), else None.
    #[getter]
    fn folder(&self) -> Option<String> {
        self.folder.as_ref().map(|f| f.display().to_string())
    }

    /// The scene traced (a run read from a folder loads its `scene_file` again).
    #[getter]
    fn scene(&self, py: Python<'_>) -> PyResult<Scene> {
        match &self.inner {
            Some(r) => Ok(Scene {
                inner: r.scene.clone(),
            }),
            None => {
                let file = self.summary["scene_file"].as_str().unwrap_or_default();
                load_scene(py, Path::new(file))
            }
        }
    }

    /// Write the command line's output set (`flux.exr`, `angular.exr`, `flux.png`,
    /// `conoscope.png`, `convergence.csv`, `convergence.png`, `summary.json`, and the
    /// colour, luminance and Stokes images when measured) into `dir`, all or nothing; a
    /// shard run writes `shard.json`, as `blutrace trace --shard` does, for `blutrace
    /// merge` or `Run.load`. Returns the files written.
    fn write(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = crate::convert::dir_arg)] dir: PathBuf,
    ) -> PyResult<Vec<String>> {
        let run = self.traced("write")?.clone();
        let files = detached(py, || {
            if run.options.shard.is_some() {
                Ok(vec![shard::write_shard(&run, &dir)?])
            } else {
                run.write(&dir)
            }
        })?
        .map_err(run_error)?;
        Ok(files.iter().map(|f| f.display().to_string()).collect())
    }

    /// Read the run an output folder holds: one `blutrace trace`, `blutrace merge` or
    /// `Run.write` made (its maps from the images, stored as float32), or a shard's folder
    /// (`shard.json`: the shard run itself, which merges as any). A folder without
    /// `summary.json` or `shard.json` is a `BlutraceError` naming it.
    #[staticmethod]
    fn load(
        py: Python<'_>,
        #[pyo3(from_py_with = crate::convert::dir_arg)] dir: PathBuf,
    ) -> PyResult<Run> {
        match saved::load(py, &dir)? {
            Saved::Shard(run) => Run::new(*run),
            Saved::Outputs {
                maps,
                summary,
                history,
            } => Ok(Run::loaded(dir, *maps, summary, history)),
        }
    }

    /// An xarray.Dataset of every map with its standard error and hits, coordinates in
    /// mm (`x_mm`, `y_mm`) and degrees (`theta_deg`, `phi_deg`), the summary's scalars
    /// as attributes. Needs xarray (`pip install blutrace[study]`).
    fn to_xarray<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let study = slf.py().import("blutrace._study")?;
        study.call_method1("run_to_xarray", (slf,))
    }

    fn _repr_html_<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let study = slf.py().import("blutrace._study")?;
        study.call_method1("run_html", (slf,))
    }

    /// A run pickles as its tallies (a shard run as its `shard.json`), or, read from a
    /// folder, as that folder.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let Some(run) = &self.inner else {
            let load = py.get_type::<Run>().getattr("load")?;
            let args = (self.folder.clone(),).into_pyobject(py)?.into_any();
            return PyTuple::new(py, [load, args]);
        };
        if run.options.shard.is_none() {
            let restore = py.get_type::<Run>().getattr("_from_state")?;
            return saved::reduce_whole(py, run, restore);
        }
        let file = ShardFile::of(run).map_err(|e| BlutraceError::new_err(e.to_string()))?;
        let json =
            serde_json::to_string(&file).map_err(|e| BlutraceError::new_err(e.to_string()))?;
        let restore = py.get_type::<Run>().getattr("_from_shard")?;
        let args = (self.scene(py)?, json).into_pyobject(py)?.into_any();
        PyTuple::new(py, [restore, args])
    }

    /// A shard run from its scene and its shard file's JSON (the inverse of pickling).
    #[staticmethod]
    fn _from_shard(py: Python<'_>, scene: &Scene, json: &str) -> PyResult<Run> {
        let file: ShardFile = serde_json::from_str(json)
            .map_err(|e| PyValueError::new_err(format!("not a blutrace shard: {e}")))?;
        Run::new(saved::shard_run(
            py,
            scene,
            PathBuf::from("the pickled shard"),
            file,
        )?)
    }

    /// A whole run from its scene, tallies and the rest of its state (unpickling).
    #[staticmethod]
    fn _from_state(scene: &Scene, tallies: &str, state: &Bound<'_, PyAny>) -> PyResult<Run> {
        Run::new(saved::whole_run(scene, tallies, state)?)
    }

    fn __repr__(&self) -> String {
        let shard = match self.shard() {
            Some((k, m)) => format!(", shard=({k}, {m})"),
            None => String::new(),
        };
        let from = match &self.folder {
            Some(f) => format!(", folder={:?}", f.display().to_string()),
            None => String::new(),
        };
        format!(
            "Run(scene={}, photons={}, seed={}{shard}{from})",
            self.summary["scene"],
            self.photons(),
            self.seed()
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
    let scene = first.get().traced("merge")?.scene.clone();
    let mut shards = Vec::with_capacity(runs.len());
    for (i, r) in runs.iter().enumerate() {
        let file = ShardFile::of(r.get().traced("merge")?).map_err(|_| {
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
    Run::new(merged)
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
