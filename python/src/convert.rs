//! Values between Rust and Python: TOML (scene files) and JSON (reports) to Python
//! objects and back, numpy maps, argument checks and the mapping of library errors to
//! exceptions.

use crate::{BlutraceError, SceneError};
use blutrace::run::metrics::Map;
use numpy::ndarray::Array2;
use numpy::{Element, IntoPyArray};
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;

/// A TOML value as a Python object (tables are dicts, arrays lists, datetimes strings).
pub fn toml_to_py<'py>(py: Python<'py>, v: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        toml::Value::String(s) => s.into_bound_py_any(py)?,
        toml::Value::Integer(i) => i.into_bound_py_any(py)?,
        toml::Value::Float(x) => x.into_bound_py_any(py)?,
        toml::Value::Boolean(b) => b.into_bound_py_any(py)?,
        toml::Value::Datetime(d) => d.to_string().into_bound_py_any(py)?,
        toml::Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(toml_to_py(py, x)?)?;
            }
            list.into_any()
        }
        toml::Value::Table(t) => {
            let dict = PyDict::new(py);
            for (k, x) in t {
                dict.set_item(k, toml_to_py(py, x)?)?;
            }
            dict.into_any()
        }
    })
}

/// A Python value as TOML: bool, int, float, str, list or tuple, dict with str keys, numpy
/// arrays and scalars (as their `tolist()`); anything else is a `TypeError`.
pub fn py_to_toml(v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v
            .extract()
            .map_err(|_| PyValueError::new_err(format!("{v} does not fit a 64-bit integer")))?;
        return Ok(toml::Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v.try_iter()?;
        let mut out = Vec::new();
        for x in items {
            out.push(py_to_toml(&x?)?);
        }
        return Ok(toml::Value::Array(out));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("table key {k} is not a str")))?;
            t.insert(key, py_to_toml(&x)?);
        }
        return Ok(toml::Value::Table(t));
    }
    // numpy arrays and scalars: their Python values (nested lists, bool, int, float).
    if v.hasattr("tolist")? {
        let plain = v.call_method0("tolist")?;
        if plain.hasattr("tolist")? {
            return Err(PyTypeError::new_err(format!(
                "cannot write a {} into a scene file (its tolist() is no list or number)",
                v.get_type().name()?
            )));
        }
        return py_to_toml(&plain);
    }
    // Other numbers: integers through __index__, else a float.
    if v.hasattr("__index__")? {
        return Ok(toml::Value::Integer(
            v.call_method0("__index__")?.extract()?,
        ));
    }
    if v.hasattr("__float__")? {
        return Ok(toml::Value::Float(v.call_method0("__float__")?.extract()?));
    }
    Err(PyTypeError::new_err(format!(
        "cannot write a {} into a scene file (use a number, bool, str, list or dict)",
        v.get_type().name()?
    )))
}

/// A JSON value as a Python object (null is None).
pub fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value as J;
    Ok(match v {
        J::Null => py.None().into_bound(py),
        J::Bool(b) => b.into_bound_py_any(py)?,
        J::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.into_bound_py_any(py)?,
            (None, Some(u), _) => u.into_bound_py_any(py)?,
            (None, None, Some(x)) => x.into_bound_py_any(py)?,
            (None, None, None) => n.to_string().into_bound_py_any(py)?,
        },
        J::String(s) => s.into_bound_py_any(py)?,
        J::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(json_to_py(py, x)?)?;
            }
            list.into_any()
        }
        J::Object(o) => {
            let dict = PyDict::new(py);
            for (k, x) in o {
                dict.set_item(k, json_to_py(py, x)?)?;
            }
            dict.into_any()
        }
    })
}

/// A Python object of JSON's kinds (what `json.loads` gives) as a JSON value; floats keep
/// every bit (serde_json's own parser may round the last one), NaN becomes null.
pub fn py_to_json(v: &Bound<'_, PyAny>) -> PyResult<serde_json::Value> {
    use serde_json::Value as J;
    if v.is_none() {
        return Ok(J::Null);
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(J::Bool(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(match v.extract::<i64>() {
            Ok(i) => J::from(i),
            Err(_) => J::from(v.extract::<u64>()?),
        });
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(serde_json::Number::from_f64(v.extract()?).map_or(J::Null, J::Number));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(J::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut o = serde_json::Map::new();
        for (k, x) in d.iter() {
            o.insert(k.extract()?, py_to_json(&x)?);
        }
        return Ok(J::Object(o));
    }
    let items: PyResult<Vec<_>> = v.try_iter()?.map(|x| py_to_json(&x?)).collect();
    Ok(J::Array(items?))
}

/// Anything serializable as the JSON value the CLI writes of it.
pub fn to_json(v: &impl serde::Serialize) -> PyResult<serde_json::Value> {
    serde_json::to_value(v).map_err(|e| BlutraceError::new_err(e.to_string()))
}

/// A `ny x nx` grid (row-major, row `iy` at the `iy`-th bin from the origin) as a numpy
/// array of shape `(ny, nx)`.
pub fn grid<'py, T: Element + Clone>(
    py: Python<'py>,
    m: &Map,
    values: &[T],
) -> PyResult<Bound<'py, PyAny>> {
    let a = Array2::from_shape_vec((m.ny, m.nx), values.to_vec())
        .map_err(|e| BlutraceError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

/// A count argument (photons, seeds): a Python int, or a float holding a whole number
/// (`1e6`), at least `min`; else a `ValueError` naming the argument.
pub fn count(v: &Bound<'_, PyAny>, name: &str, min: u64) -> PyResult<u64> {
    let bad = || {
        PyValueError::new_err(format!(
            "{name} must be a whole number >= {min}, got {}",
            v.repr().map_or("?".into(), |r| r.to_string())
        ))
    };
    if v.is_instance_of::<PyBool>() {
        return Err(bad());
    }
    let n: u64 = if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        if !(x.fract() == 0.0 && (0.0..1.8e19).contains(&x)) {
            return Err(bad());
        }
        x as u64
    } else {
        let i: i128 = v
            .call_method0("__index__")
            .and_then(|i| i.extract())
            .map_err(|_| bad())?;
        u64::try_from(i).map_err(|_| bad())?
    };
    if n < min {
        return Err(bad());
    }
    Ok(n)
}

/// Argument `name` as a `T`; a value of the wrong type or shape raises the exception it
/// would (`TypeError`, `ValueError`), its message naming the argument.
pub fn arg<'a, 'py, T>(v: &'a Bound<'py, PyAny>, name: &str) -> PyResult<T>
where
    T: FromPyObject<'a, 'py>,
    T::Error: Into<PyErr>,
{
    v.extract::<T>().map_err(|e| named(v.py(), name, e.into()))
}

/// Argument `path`: a file's path (str or path-like).
pub fn path_arg(v: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    arg(v, "path")
}

/// Argument `dir`: a folder's path (str or path-like).
pub fn dir_arg(v: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    arg(v, "dir")
}

/// `e` with its message prefixed by the argument it is about, its type kept.
pub fn named(py: Python<'_>, name: &str, e: PyErr) -> PyErr {
    PyErr::from_type(e.get_type(py), format!("{name}: {}", e.value(py)))
}

/// One of `choices` (spelling, value), or a `ValueError` listing them.
pub fn choice<T: Copy>(name: &str, given: &str, choices: &[(&'static str, T)]) -> PyResult<T> {
    lookup(name, given, choices).map(|(_, v)| *v)
}

/// Argument `name`, a str naming one of `choices`, as the table spells it: a `&'static
/// str`, so a signature keeps its literal default (`from_py_with` of a spelling argument).
pub fn spelling<T>(
    v: &Bound<'_, PyAny>,
    name: &str,
    choices: &[(&'static str, T)],
) -> PyResult<&'static str> {
    let given: String = arg(v, name)?;
    lookup(name, &given, choices).map(|(s, _)| *s)
}

/// The entry of `choices` spelled `given`, or a `ValueError` listing them.
fn lookup<'c, T>(
    name: &str,
    given: &str,
    choices: &'c [(&'static str, T)],
) -> PyResult<&'c (&'static str, T)> {
    choices.iter().find(|(s, _)| *s == given).ok_or_else(|| {
        let names: Vec<String> = choices.iter().map(|(s, _)| format!("'{s}'")).collect();
        PyValueError::new_err(format!(
            "{name} must be one of {}, got '{given}'",
            names.join(", ")
        ))
    })
}

/// A scene error (loading, editing): `SceneError` with the file and field in its message.
pub fn scene_error(e: anyhow::Error) -> PyErr {
    SceneError::new_err(format!("{e:#}"))
}

/// A run's or a search's error: a `ValueError` when it is about an option (the library
/// names them "option `name`", the keyword of the Python call), else a `BlutraceError`.
pub fn run_error(e: anyhow::Error) -> PyErr {
    let msg = format!("{e:#}");
    if msg.contains("option `") {
        PyValueError::new_err(msg)
    } else {
        BlutraceError::new_err(msg)
    }
}
