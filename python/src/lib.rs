//! `blutrace._native`: the blutrace library as a Python extension module (pyo3). The
//! Python package `blutrace` (`python/blutrace/`) re-exports everything here; its
//! docstrings and type stubs (`__init__.pyi`) are the user's reference.
//!
//! - `scene_value`: the `Scene` value, which runs and optimizations hand back; `scene`: its
//!   methods (load, key paths, check, trace, optimize, characterise);
//! - `options`: the spellings and checks of arguments the calls share;
//! - `run`: `Run` (numpy maps and their bin centres, summary, write, pickling) and `merge`;
//! - `maps`: a run's maps, computed by the library or read from an output folder;
//! - `saved`: runs pickled whole, and read back from output folders (`Run.load`);
//! - `optimization`: `Optimization`, the outcome of `Scene.optimize`;
//! - `characterisation`: `Characterisation`, a part as a BSDF table (`Scene.characterise`);
//! - `detached`: long work on a thread of its own, with the GIL released, Ctrl-C
//!   honoured and panics turned into exceptions;
//! - `convert`: TOML and JSON values to and from Python objects, and argument checks.

mod characterisation;
mod convert;
mod detached;
mod maps;
mod optimization;
mod options;
mod progress;
mod run;
mod saved;
mod scene;
mod scene_value;

use pyo3::create_exception;
use pyo3::prelude::*;

// The exceptions are `blutrace.BlutraceError` and `blutrace.SceneError` (their module is the
// package users import, not the extension module inside it), as tracebacks print them.
create_exception!(
    blutrace,
    BlutraceError,
    pyo3::exceptions::PyException,
    "Base class of blutrace's errors (a run or a write that failed, an internal error)."
);
create_exception!(
    blutrace,
    SceneError,
    BlutraceError,
    "A scene file, or a file it names, is wrong: the message names the file and the field."
);

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("BlutraceError", py.get_type::<BlutraceError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add_class::<scene_value::Scene>()?;
    m.add_class::<run::Run>()?;
    m.add_class::<optimization::Optimization>()?;
    m.add_class::<characterisation::Characterisation>()?;
    m.add_function(wrap_pyfunction!(run::merge, m)?)?;
    m.add_function(wrap_pyfunction!(run::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_on_worker, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// Panic on a worker thread, as a bug in the library would: the test suite checks that it
/// raises `BlutraceError` and leaves the interpreter running.
#[pyfunction]
fn _panic_on_worker(py: Python<'_>) -> PyResult<()> {
    detached::detached(py, || -> anyhow::Result<()> {
        panic!("a deliberate panic")
    })?
    .map_err(convert::run_error)
}
