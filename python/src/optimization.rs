//! `Scene.optimize` and its outcome, `blutrace.Optimization`: the dot-density searches
//! (Nelder-Mead, feedback) and, with `vary`, the search over numbers of the scene file,
//! with the command line's options as keywords.

use crate::convert::{arg, choice, count, json_to_py, py_to_json, run_error, to_json};
use crate::detached::{Waited, detached, wait_detached};
use crate::options::{BACKENDS, ESTIMATORS, tag_arg, threads_arg};
use crate::scene_value::Scene;
use blutrace::optics::dots::Placement;
use blutrace::optimize::ObjectiveSpec;
use blutrace::optimize::layout::VarySpec;
use blutrace::optimize::{
    LayoutResult, Method, OptimizeOptions, OptimizeResult, optimize, optimize_layout,
};
use blutrace::scene::Scene as RustScene;
use pyo3::exceptions::{PyKeyboardInterrupt, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyTuple};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc;

/// Spellings of the methods.
const METHODS: &[(&str, Method)] = &[
    ("nelder-mead", Method::NelderMead),
    ("feedback", Method::Feedback),
    ("grid", Method::Grid),
];

/// What a search found.
enum Outcome {
    Density(Box<OptimizeResult>),
    Layout(Box<LayoutResult>),
}

/// The outcome of ``Scene.optimize``.
///
/// ``scene`` is the optimized scene (``optimized.toml``), ``history`` one dict per iteration
/// or evaluated design, ``summary`` the content of ``optimize.json``, ``interrupted`` whether
/// Ctrl-C ended the search early (the outcome is then that of the designs traced before
/// it); ``write(dir)`` writes what ``blutrace optimize`` writes. A value the search could
/// not define (a metric of a design that put no light on the target) is None.
/// It pickles (its reports and the files `write` writes), so an executor can return it.
#[pyclass(module = "blutrace", name = "Optimization", frozen)]
pub struct Optimization {
    /// The search's outcome; `None` for one unpickled, which keeps its files instead.
    outcome: Option<Arc<Outcome>>,
    scene: Scene,
    summary: serde_json::Value,
    history: serde_json::Value,
    interrupted: bool,
    method: Method,
    /// The files `write` writes (path within its folder, bytes), of an unpickled one.
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl Optimization {
    fn new(outcome: Outcome, scene: Scene) -> PyResult<Optimization> {
        let (summary, history, interrupted, method) = match &outcome {
            Outcome::Density(r) => (
                to_json(&**r)?,
                to_json(&r.history)?,
                r.interrupted,
                r.method,
            ),
            Outcome::Layout(r) => (
                to_json(&**r)?,
                to_json(&r.history)?,
                r.interrupted,
                r.method,
            ),
        };
        Ok(Optimization {
            outcome: Some(Arc::new(outcome)),
            scene,
            summary,
            history,
            interrupted,
            method,
            files: Vec::new(),
        })
    }
}

/// Write `outcome`'s files into `dir`.
fn write_outcome(outcome: &Outcome, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    match outcome {
        Outcome::Density(r) => r.write(dir),
        Outcome::Layout(r) => r.write(dir),
    }
}

/// Every file under `dir`, as (path within it, bytes).
fn files_under(
    dir: &Path,
    within: &Path,
    out: &mut Vec<(PathBuf, Vec<u8>)>,
) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir.join(within))? {
        let entry = entry?;
        let rel = within.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            files_under(dir, &rel, out)?;
        } else {
            out.push((rel, std::fs::read(entry.path())?));
        }
    }
    Ok(())
}

#[pymethods]
impl Optimization {
    /// The optimized scene (the file `optimized.toml` holds; file paths absolute).
    #[getter]
    fn scene(&self) -> Scene {
        self.scene.clone()
    }

    /// One dict per iteration (density searches) or evaluated design (`vary`), as
    /// `history.csv` lists them.
    #[getter]
    fn history<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.history)
    }

    /// Everything the search reports: the content of `optimize.json`.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.summary)
    }

    /// Whether Ctrl-C stopped the search early (its outcome is the best design so far).
    #[getter]
    fn interrupted(&self) -> bool {
        self.interrupted
    }

    /// Write what `blutrace optimize` writes into `dir`, all or nothing; returns the files
    /// and folders written.
    fn write(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = crate::convert::dir_arg)] dir: PathBuf,
    ) -> PyResult<Vec<String>> {
        let written = match &self.outcome {
            Some(outcome) => {
                let outcome = outcome.clone();
                detached(py, || write_outcome(&outcome, &dir))?.map_err(run_error)?
            }
            None => {
                let reads = &self.scene.inner.inputs;
                let files = &self.files;
                detached(py, || {
                    let mut top = Vec::new();
                    for (rel, bytes) in files {
                        let path = dir.join(rel);
                        if let Some(parent) = path.parent() {
                            std::fs::create_dir_all(parent)?;
                        }
                        blutrace::output::atomic::write_file(&path, bytes, reads)?;
                        let first = dir.join(
                            rel.components()
                                .next()
                                .map_or(rel.as_path(), |c| Path::new(c.as_os_str())),
                        );
                        if !top.contains(&first) {
                            top.push(first);
                        }
                    }
                    Ok(top)
                })?
                .map_err(run_error)?
            }
        };
        Ok(written.iter().map(|f| f.display().to_string()).collect())
    }

    /// It pickles as its scene, reports and the files `write` writes.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let files = match &self.outcome {
            None => self.files.clone(),
            Some(outcome) => {
                let outcome = outcome.clone();
                detached(py, move || {
                    let tmp = std::env::temp_dir().join(format!(
                        "blutrace-pickle-{}-{:x}",
                        std::process::id(),
                        Arc::as_ptr(&outcome) as usize
                    ));
                    let _ = std::fs::remove_dir_all(&tmp);
                    let kept = write_outcome(&outcome, &tmp).and_then(|_| {
                        let mut files = Vec::new();
                        files_under(&tmp, Path::new(""), &mut files)?;
                        Ok(files)
                    });
                    let _ = std::fs::remove_dir_all(&tmp);
                    kept
                })?
                .map_err(run_error)?
            }
        };
        let files: Vec<(PathBuf, Bound<'py, PyBytes>)> = files
            .iter()
            .map(|(p, b)| (p.clone(), PyBytes::new(py, b)))
            .collect();
        let state = (
            self.scene.clone(),
            // As Python objects: pickle keeps every bit of their floats.
            json_to_py(py, &self.summary)?,
            json_to_py(py, &self.history)?,
            self.interrupted,
            name_of_method(self.method),
            files,
        );
        let restore = py.get_type::<Optimization>().getattr("_restore")?;
        let args = (state,).into_pyobject(py)?.into_any();
        PyTuple::new(py, [restore, args])
    }

    /// The inverse of pickling.
    #[staticmethod]
    fn _restore(state: &Bound<'_, PyAny>) -> PyResult<Optimization> {
        let (scene, summary, history, interrupted, method, files): State<'_> = state.extract()?;
        let scene: Scene = scene.cast::<Scene>()?.borrow().clone();
        Ok(Optimization {
            outcome: None,
            scene,
            summary: py_to_json(&summary)?,
            history: py_to_json(&history)?,
            interrupted,
            method: choice("method", &method, METHODS)?,
            files,
        })
    }

    fn __repr__(&self) -> String {
        let n = self.history.as_array().map_or(0, Vec::len);
        format!(
            "Optimization(method='{}', steps={n}, scene={:?})",
            name_of_method(self.method),
            self.scene.inner.name
        )
    }
}

/// What an optimization pickles as: the optimized scene, summary and history (as Python
/// objects), interrupted, the method's name and the files `write` writes.
type State<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    bool,
    String,
    Vec<(PathBuf, Vec<u8>)>,
);

/// The spelling of `m` in [`METHODS`].
fn name_of_method(m: Method) -> String {
    METHODS
        .iter()
        .find(|(_, x)| *x == m)
        .map_or("?", |(n, _)| n)
        .to_string()
}

/// `scene.optimize(method, vary, **options)`.
pub fn optimize_scene(
    py: Python<'_>,
    scene: &Arc<RustScene>,
    method: Option<&str>,
    vary: Option<&Bound<'_, PyDict>>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Optimization> {
    let method = choice("method", method.unwrap_or("nelder-mead"), METHODS)?;
    let mut o = OptimizeOptions::for_method(method);
    o.seed = scene.default_seed;
    if let Some(vary) = vary {
        for (key, range) in vary.iter() {
            let key: String = arg(&key, "vary keys")?;
            let (lo, hi): (f64, f64) = range.extract().map_err(|_| {
                PyValueError::new_err(format!("vary[{key:?}] must be a (min, max) pair"))
            })?;
            let spec: VarySpec = format!("{key}={lo:?}..{hi:?}")
                .parse()
                .map_err(PyValueError::new_err)?;
            o.vary.push(spec);
        }
    }
    let mut progress = None;
    if let Some(kwargs) = kwargs {
        for (k, v) in kwargs.iter() {
            let k: String = k.extract()?;
            set_option(&mut o, &k, &v, &mut progress)?;
        }
    }
    // A tag the scene lacks is the same ValueError as `characterise`'s.
    if let Some(tag) = &o.tag {
        tag_arg(scene, tag)?;
    }
    let reporter = crate::progress::reporter(py, progress.as_ref(), 0)?;
    let (tx, rx) = mpsc::channel::<(String, serde_json::Value)>();
    let shared = scene.clone();
    let options = o.clone();
    let work = move || -> anyhow::Result<Outcome> {
        if options.vary.is_empty() {
            let r = optimize(&shared, &options, &mut |r| {
                let _ = tx.send((r.to_string(), serde_json::to_value(r).unwrap_or_default()));
            })?;
            Ok(Outcome::Density(Box::new(r)))
        } else {
            let r = optimize_layout(&shared, &options, &mut |r, names| {
                let result = match (&r.result, &r.rejected) {
                    (Some(e), _) => e.to_string(),
                    (None, Some(why)) => format!("not traced: {why}"),
                    (None, None) => String::new(),
                };
                let line = format!(
                    "eval {:>4}  {}  {result}",
                    r.evaluation,
                    r.assignment(names)
                );
                let _ = tx.send((line, serde_json::to_value(r).unwrap_or_default()));
            })?;
            Ok(Outcome::Layout(Box::new(r)))
        }
    };
    let drain = |py: Python<'_>| -> PyResult<()> {
        while let Ok((line, record)) = rx.try_recv() {
            crate::progress::event(py, &reporter, &line, &record)?;
        }
        Ok(())
    };
    let Waited { stopped, outcome } = wait_detached(py, &o.interrupt, work, drain);
    // Ctrl-C: the search returns the designs traced before it, as the CLI writes them.
    let found = matches!(outcome, Ok(Ok(_)));
    if let Some(e) = stopped.filter(|e| !(found && e.is_instance_of::<PyKeyboardInterrupt>(py))) {
        return Err(e);
    }
    drain(py)?;
    let outcome = outcome?.map_err(|e| {
        if blutrace::run::is_interrupted(&e) {
            PyKeyboardInterrupt::new_err("interrupted before the first design was traced")
        } else {
            run_error(e)
        }
    })?;
    let toml_text = match &outcome {
        Outcome::Density(r) => r.optimized_toml(),
        Outcome::Layout(r) => r.optimized_toml(),
    }
    .map_err(run_error)?;
    let optimized = Scene::from_toml(py, toml_text, scene.path.clone())?;
    Optimization::new(outcome, optimized)
}

/// Set option `key` of `o` from a keyword argument (`progress` is kept aside).
fn set_option<'py>(
    o: &mut OptimizeOptions,
    key: &str,
    v: &Bound<'py, PyAny>,
    progress: &mut Option<Bound<'py, PyAny>>,
) -> PyResult<()> {
    let f = |name: &str| -> PyResult<f64> {
        v.extract::<f64>()
            .map_err(|_| PyValueError::new_err(format!("{name} must be a number")))
    };
    let opt = |v: &Bound<'py, PyAny>| !v.is_none();
    match key {
        "progress" => *progress = opt(v).then(|| v.clone()),
        "objective" => {
            let s: String = arg(v, key)?;
            o.objective = s.parse::<ObjectiveSpec>().map_err(PyValueError::new_err)?;
        }
        "grid_points" => o.grid_points = count(v, key, 2)? as usize,
        "photons" => o.photons = count(v, key, 1)?,
        "seed" => o.seed = count(v, key, 0)?,
        "max_iter" => o.max_iter = count(v, key, 0)? as usize,
        "target_cv" => o.target_cv = opt(v).then(|| f(key)).transpose()?,
        "degree" => {
            o.degree = opt(v)
                .then(|| count(v, key, 0))
                .transpose()?
                .map(|d| d as usize)
        }
        "min_density" => o.min_density = f(key)?,
        "max_density" => o.max_density = opt(v).then(|| f(key)).transpose()?,
        "tag" => o.tag = opt(v).then(|| arg(v, key)).transpose()?,
        "initial_step" => o.initial_step = f(key)?,
        "simplex_tol" => o.simplex_tol = f(key)?,
        "alpha" => o.alpha = f(key)?,
        "smoothing" => o.smoothing = f(key)?,
        "dims" => o.dims = count(v, key, 1)? as usize,
        "cells" => o.cells = opt(v).then(|| arg(v, key)).transpose()?,
        "strips" => {
            o.strips = opt(v)
                .then(|| count(v, key, 1))
                .transpose()?
                .map(|s| s as usize)
        }
        "edge_margin_mm" => o.edge_margin_mm = f(key)?,
        "verify_photons" => o.verify_photons = count(v, key, 0)?,
        "verify_seed" => o.verify_seed = opt(v).then(|| count(v, key, 0)).transpose()?,
        "threads" => o.threads = opt(v).then(|| threads_arg(v)).transpose()?,
        "estimator" => o.estimator = choice(key, &arg::<String>(v, key)?, ESTIMATORS)?,
        "backend" => o.backend = choice(key, &arg::<String>(v, key)?, BACKENDS)?,
        "export_placement" => {
            o.export_placement = if opt(v) {
                let name: String = arg(v, key)?;
                let printable: Vec<(&str, Placement)> = Placement::ALL
                    .iter()
                    .copied()
                    .filter(|(_, p)| p.printable())
                    .collect();
                Some(choice(key, &name, &printable)?)
            } else {
                None
            }
        }
        _ => {
            return Err(PyTypeError::new_err(format!(
                "optimize() got an unexpected keyword argument '{key}'"
            )));
        }
    }
    Ok(())
}
