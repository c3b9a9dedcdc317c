//! `blutrace.Scene`: a loaded, validated scene as a value (copy, get and set by key path),
//! and the calls that use it: check, trace, optimize, characterise.

use crate::characterisation::{self, Characterisation};
use crate::convert::{
    self, arg, choice, count, py_to_toml, run_error, scene_error, spelling, toml_to_py,
};
use crate::detached::{detached, run_detached};
use crate::optimization::{self, Optimization};
use crate::options::{BACKENDS, ESTIMATORS, LUMINANCE_ESTIMATORS, TARGET_METRICS, threads_arg};
use crate::progress;
use crate::run::Run;
use crate::scene_value::{Scene, load_scene};
use blutrace::run::{self, Interrupt, Progress, RunOptions, Shard};
use blutrace::scene::{Scene as RustScene, key_path};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

#[pymethods]
impl Scene {
    /// Load and validate a scene: a scene file or a folder holding `scene.toml`.
    #[staticmethod]
    fn load(
        py: Python<'_>,
        #[pyo3(from_py_with = convert::path_arg)] path: PathBuf,
    ) -> PyResult<Scene> {
        load_scene(py, &path)
    }

    /// A scene from the text of a scene file; its geometry paths are relative to `path`'s
    /// folder (the file it stands for).
    #[staticmethod]
    pub fn from_toml(
        py: Python<'_>,
        #[pyo3(from_py_with = text_arg)] text: String,
        #[pyo3(from_py_with = convert::path_arg)] path: PathBuf,
    ) -> PyResult<Scene> {
        let doc: toml::Value = toml::from_str(&text)
            .map_err(|e| scene_error(anyhow::anyhow!("{}: {e}", path.display())))?;
        let scene = detached(py, || RustScene::from_source(doc, &path))?.map_err(scene_error)?;
        Ok(Scene {
            inner: Arc::new(scene),
        })
    }

    /// The scene file as TOML text (the file as written, with any `set` applied).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(self.inner.source()).map_err(|e| scene_error(e.into()))
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The scene file (geometry paths are relative to its folder).
    #[getter]
    fn path(&self) -> String {
        self.inner.path.display().to_string()
    }

    /// Non-fatal findings of loading.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    /// The scene file's `[trace] photons`.
    #[getter]
    fn default_photons(&self) -> u64 {
        self.inner.default_photons
    }

    /// The scene file's `[trace] seed`.
    #[getter]
    fn default_seed(&self) -> u64 {
        self.inner.default_seed
    }

    /// The content hash shards of one run agree on (hex): the physics, not the name.
    #[getter]
    fn content_hash(&self) -> String {
        format!("{:016x}", self.inner.content_hash())
    }

    /// The value at a key path such as `sources.0.center.2`; with `*` for every element of
    /// an array, the one value they all hold, or the list of their values (in order) when
    /// they differ.
    fn get<'py>(&self, py: Python<'py>, key: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let key: String = arg(key, "key")?;
        let doc = self.inner.source();
        let places = key_path::resolve(doc, &key).map_err(|e| {
            PyValueError::new_err(format!("{}: {key}: {e:#}", self.inner.path.display()))
        })?;
        let values: Vec<toml::Value> = places
            .iter()
            .map(|p| key_path::get(doc, p).clone())
            .collect();
        match &values[..] {
            [first, rest @ ..] if rest.iter().all(|v| v == first) => toml_to_py(py, first),
            _ => toml_to_py(py, &toml::Value::Array(values)),
        }
    }

    /// Set the value at a key path (every element a `*` names): the scene is loaded again
    /// from the edited file, so every check runs (a `SceneError` leaves it unchanged).
    fn set(
        &mut self,
        py: Python<'_>,
        key: &Bound<'_, PyAny>,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let key: String = arg(key, "key")?;
        let value = py_to_toml(value).map_err(|e| convert::named(py, &key, e))?;
        key_path::resolve(self.inner.source(), &key).map_err(|e| {
            PyValueError::new_err(format!("{}: {key}: {e:#}", self.inner.path.display()))
        })?;
        let scene = self.inner.clone();
        let edited = detached(py, || scene.with(&key, value))?.map_err(scene_error)?;
        self.inner = Arc::new(edited);
        Ok(())
    }

    /// An independent copy (a `set` on either leaves the other as it is).
    fn copy(&self) -> Scene {
        self.clone()
    }

    fn __copy__(&self) -> Scene {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Scene {
        self.clone()
    }

    /// The scene file as a dict (the file as written, with any `set` applied).
    #[getter]
    fn source<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        toml_to_py(py, self.inner.source())
    }

    /// What `blutrace check --json` prints: geometry, tallies, sources, media, warnings.
    fn check<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let scene = self.inner.clone();
        let report = detached(py, || {
            blutrace::scene::check_report::check_json(&scene, &scene.path)
        })?
        .map_err(scene_error)?;
        convert::json_to_py(py, &report)
    }

    /// Trace the scene and return the `Run`.
    ///
    /// ``photons`` defaults to the scene's ``[trace] photons`` (1e9 as a cap when
    /// ``target_error`` or ``max_time`` is given) and ``seed`` to its ``[trace] seed``;
    /// ``threads`` defaults to all cores (results do not depend on it); ``estimator`` is
    /// "analog" or "weighted"; ``target_error`` stops once the relative standard error of
    /// ``target_metric`` ("mean", "efficiency", "cv", "nine-point", "thirteen-point", "bin") is
    /// at or below it; ``max_time`` stops after about that many seconds; ``progress`` is True
    /// (a tqdm bar when tqdm is installed, else a line on stderr) or a callable
    /// ``(photons_done, photons_total)``; ``shard=(k, m)`` traces only shard k of m of the
    /// photons, for ``merge``; ``luminance_estimator`` is "meter" (peel-off towards each
    /// view, the default) or "cone" (the photons that leave within the cone).
    #[pyo3(signature = (photons=None, seed=None, threads=None, estimator="analog",
        target_error=None, target_metric="mean", max_time=None, progress=None, shard=None,
        backend="auto", luminance_estimator="meter"))]
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        py: Python<'_>,
        photons: Option<&Bound<'_, PyAny>>,
        seed: Option<&Bound<'_, PyAny>>,
        threads: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = estimator_arg)] estimator: &str,
        target_error: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = target_metric_arg)] target_metric: &str,
        max_time: Option<&Bound<'_, PyAny>>,
        progress: Option<&Bound<'_, PyAny>>,
        shard: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = backend_arg)] backend: &str,
        #[pyo3(from_py_with = luminance_estimator_arg)] luminance_estimator: &str,
    ) -> PyResult<Run> {
        let target_error: Option<f64> = target_error.map(|v| arg(v, "target_error")).transpose()?;
        let max_time: Option<f64> = max_time.map(|v| arg(v, "max_time")).transpose()?;
        let open_ended = target_error.is_some() || max_time.is_some();
        let photons = match photons {
            Some(p) => count(p, "photons", 1)?,
            None if open_ended => 1_000_000_000,
            None => self.inner.default_photons,
        };
        let shard = shard.map(shard_arg).transpose()?;
        let options = RunOptions {
            photons,
            seed: seed.map_or(Ok(self.inner.default_seed), |s| count(s, "seed", 0))?,
            threads: threads.map(|t| threads_arg(t)).transpose()?,
            backend: choice("backend", backend, BACKENDS)?,
            estimator: choice("estimator", estimator, ESTIMATORS)?,
            luminance_estimator: choice(
                "luminance_estimator",
                luminance_estimator,
                LUMINANCE_ESTIMATORS,
            )?,
            target_error,
            target_metric: choice("target_metric", target_metric, TARGET_METRICS)?,
            max_time_s: max_time,
            shard,
            convex: true,
            interrupt: Interrupt::default(),
        };
        let (first, last) = options.photon_range();
        let reporter = progress::reporter(py, progress, last - first)?;
        let done = AtomicU64::new(0);
        let scene = self.inner.clone();
        let traced = run_detached(
            py,
            &options.interrupt,
            || {
                run::trace(scene, &options, &|p| {
                    if let Progress::Chunk(n) = p {
                        done.fetch_add(n, Ordering::Relaxed);
                    }
                })
            },
            |py| progress::update(py, &reporter, done.load(Ordering::Relaxed)),
        );
        // An interrupt or error of the trace outranks one of the progress display.
        let closed = progress::close(py, &reporter, done.load(Ordering::Relaxed));
        let run = Run::new(traced?.map_err(run_error)?)?;
        closed?;
        Ok(run)
    }

    /// Optimize the dot density ("nelder-mead", the default, or "feedback"), or with
    /// ``vary={"key": (lo, hi)}`` the numbers those key paths name ("nelder-mead" or
    /// "grid"). The options are those of ``blutrace optimize`` with underscores: ``photons`` (1e6 per design), ``seed``,
    /// ``max_iter``, ``target_cv``, ``objective`` ("cv", "thirteen-point", "efficiency",
    /// "delta-uv-13pt" in spectral scenes, or a mix "cv=1,delta-uv-13pt=20"), ``grid_points``, ``degree``, ``min_density``, ``max_density``,
    /// ``tag``, ``initial_step``, ``simplex_tol``, ``alpha``, ``smoothing``, ``dims``, ``cells``,
    /// ``strips``, ``edge_margin_mm``, ``verify_photons`` (1e7; 0 for none), ``verify_seed``,
    /// ``threads``, ``estimator``, ``backend``, ``export_placement``; ``progress`` is True (one
    /// line per iteration on stderr) or a callable taking each iteration's record (a dict).
    /// Ctrl-C stops the search: it returns the outcome of the designs traced before it, with
    /// ``interrupted`` True (before the first design, ``KeyboardInterrupt`` is raised).
    #[pyo3(signature = (method=None, vary=None, *, objective=None, grid_points=None, photons=None, seed=None, max_iter=None, target_cv=None, degree=None, min_density=None, max_density=None, tag=None, initial_step=None, simplex_tol=None, alpha=None, smoothing=None, dims=None, cells=None, strips=None, edge_margin_mm=None, verify_photons=None, verify_seed=None, threads=None, estimator=None, backend=None, export_placement=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn optimize<'py>(
        &self,
        py: Python<'py>,
        method: Option<&Bound<'py, PyAny>>,
        vary: Option<&Bound<'py, PyAny>>,
        objective: Option<&Bound<'py, PyAny>>,
        grid_points: Option<&Bound<'py, PyAny>>,
        photons: Option<&Bound<'py, PyAny>>,
        seed: Option<&Bound<'py, PyAny>>,
        max_iter: Option<&Bound<'py, PyAny>>,
        target_cv: Option<&Bound<'py, PyAny>>,
        degree: Option<&Bound<'py, PyAny>>,
        min_density: Option<&Bound<'py, PyAny>>,
        max_density: Option<&Bound<'py, PyAny>>,
        tag: Option<&Bound<'py, PyAny>>,
        initial_step: Option<&Bound<'py, PyAny>>,
        simplex_tol: Option<&Bound<'py, PyAny>>,
        alpha: Option<&Bound<'py, PyAny>>,
        smoothing: Option<&Bound<'py, PyAny>>,
        dims: Option<&Bound<'py, PyAny>>,
        cells: Option<&Bound<'py, PyAny>>,
        strips: Option<&Bound<'py, PyAny>>,
        edge_margin_mm: Option<&Bound<'py, PyAny>>,
        verify_photons: Option<&Bound<'py, PyAny>>,
        verify_seed: Option<&Bound<'py, PyAny>>,
        threads: Option<&Bound<'py, PyAny>>,
        estimator: Option<&Bound<'py, PyAny>>,
        backend: Option<&Bound<'py, PyAny>>,
        export_placement: Option<&Bound<'py, PyAny>>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Optimization> {
        let method: Option<String> = method.map(|m| arg(m, "method")).transpose()?;
        let vary: Option<Bound<'_, PyDict>> = vary.map(|v| arg(v, "vary")).transpose()?;
        let (method, vary) = (method.as_deref(), vary.as_ref());
        // The options given, by name: those left out keep the method's defaults.
        let given = PyDict::new(py);
        for (name, value) in [
            ("photons", photons),
            ("seed", seed),
            ("max_iter", max_iter),
            ("target_cv", target_cv),
            ("objective", objective),
            ("grid_points", grid_points),
            ("degree", degree),
            ("min_density", min_density),
            ("max_density", max_density),
            ("tag", tag),
            ("initial_step", initial_step),
            ("simplex_tol", simplex_tol),
            ("alpha", alpha),
            ("smoothing", smoothing),
            ("dims", dims),
            ("cells", cells),
            ("strips", strips),
            ("edge_margin_mm", edge_margin_mm),
            ("verify_photons", verify_photons),
            ("verify_seed", verify_seed),
            ("threads", threads),
            ("estimator", estimator),
            ("backend", backend),
            ("export_placement", export_placement),
            ("progress", progress),
        ] {
            if let Some(v) = value {
                given.set_item(name, v)?;
            }
        }
        optimization::optimize_scene(py, &self.inner, method, vary, Some(&given))
    }

    /// Scenes are equal when their scene files (with any `set` applied) and every file
    /// they name are: `scene == scene.copy()`, and a scene differs once `set` changes it.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        match other.cast::<Scene>() {
            Ok(o) => {
                let o = &o.borrow().inner;
                self.inner.source() == o.source()
                    && self.inner.content_hash() == o.content_hash()
                    && self.inner.path == o.path
            }
            Err(_) => false,
        }
    }

    fn _repr_html_<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let study = slf.py().import("blutrace._study")?;
        study.call_method1("scene_html", (slf,))
    }

    /// Characterise a part of the scene into an IS BSDF table, as ``blutrace bsdf`` does:
    /// the flat face tagged ``tag``, lit from the side its normal points to (or the slab
    /// behind it, when its model lets light into a medium bounded by a parallel face).
    /// ``photons`` per incidence (1e6), ``aoi`` the angles of incidence in degrees (0, 10,
    /// ..., 80, 85), ``rotations`` the sample rotations (one: a plane-symmetric table),
    /// ``radial_step`` and ``azimuth_step`` the table's cells (2 and 10 degrees),
    /// ``u_axis`` the direction of rotation 0 on the face, ``seed`` (1); ``progress`` as
    /// ``trace``'s, over the photons of all incidences (reported an incidence at a time).
    /// Releases the GIL; Ctrl-C stops it before the next incidence. A bad argument (an
    /// unknown tag included) or a part that is not one flat face raises ``ValueError``, an
    /// argument of a wrong type ``TypeError``.
    #[pyo3(signature = (tag, photons=None, aoi=None, rotations=None, radial_step=2.0,
        azimuth_step=10.0, u_axis=None, seed=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn characterise(
        &self,
        py: Python<'_>,
        tag: &Bound<'_, PyAny>,
        photons: Option<&Bound<'_, PyAny>>,
        aoi: Option<&Bound<'_, PyAny>>,
        rotations: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = characterisation::radial_step)] radial_step: f64,
        #[pyo3(from_py_with = characterisation::azimuth_step)] azimuth_step: f64,
        u_axis: Option<&Bound<'_, PyAny>>,
        seed: Option<&Bound<'_, PyAny>>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Characterisation> {
        let tag: String = arg(tag, "tag")?;
        let args = characterisation::Args {
            tag: &tag,
            photons,
            aoi: aoi.map_or_else(
                || Ok(blutrace::characterise::DEFAULT_AOI_DEG.to_vec()),
                |v| arg(v, "aoi"),
            )?,
            rotations: rotations.map_or_else(|| Ok(vec![0.0]), |v| arg(v, "rotations"))?,
            radial_step,
            azimuth_step,
            u_axis: u_axis.map(|v| arg(v, "u_axis")).transpose()?,
            seed,
            progress,
        };
        characterisation::characterise_scene(py, &self.inner, args)
    }

    /// A scene pickles as its scene file's text and path (`from_toml` restores it).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let cls = py.get_type::<Scene>();
        let from_toml = cls.getattr("from_toml")?;
        // Absolute, so a worker started in another folder finds the geometry files.
        let path =
            std::path::absolute(&self.inner.path).unwrap_or_else(|_| self.inner.path.clone());
        let args = (self.to_toml()?, path);
        PyTuple::new(py, [from_toml, args.into_pyobject(py)?.into_any()])
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene(name={:?}, path={:?})",
            self.inner.name,
            self.inner.path.display().to_string()
        )
    }
}

/// Argument `text` of `from_toml`: a scene file's text.
fn text_arg(v: &Bound<'_, PyAny>) -> PyResult<String> {
    arg(v, "text")
}

/// Argument `estimator`: one of [`ESTIMATORS`].
fn estimator_arg(v: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    spelling(v, "estimator", ESTIMATORS)
}

/// Argument `target_metric`: one of [`TARGET_METRICS`].
fn target_metric_arg(v: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    spelling(v, "target_metric", TARGET_METRICS)
}

/// Argument `luminance_estimator`: one of [`LUMINANCE_ESTIMATORS`].
fn luminance_estimator_arg(v: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    spelling(v, "luminance_estimator", LUMINANCE_ESTIMATORS)
}

/// Argument `backend`: one of [`BACKENDS`].
fn backend_arg(v: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    spelling(v, "backend", BACKENDS)
}

/// `shard=(k, m)` checked: 0 <= k < m <= MAX_SHARDS.
fn shard_arg(v: &Bound<'_, PyAny>) -> PyResult<Shard> {
    let bad = || {
        PyValueError::new_err(format!(
            "shard must be (k, m) with 0 <= k < m <= {}, got {}",
            run::MAX_SHARDS,
            v.repr().map_or("?".into(), |r| r.to_string())
        ))
    };
    let (index, count): (i64, i64) = v.extract().map_err(|_| bad())?;
    if !(0 <= index && index < count && count as u64 <= run::MAX_SHARDS) {
        return Err(bad());
    }
    Ok(Shard {
        index: index as u64,
        count: count as u64,
    })
}
